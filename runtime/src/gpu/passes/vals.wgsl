//! include: vpl.wgsl val.wgsl
// Virtual area lights on the GPU (Dong et al. §5–6): k-means of the VPLs into M VALs by
// d = w_x·Δx/D + w_α·Δα/π, restarted each frame from VAL k = VPL ⌊k·N/M⌋ of the lights'
// merged sequence (the list holds it dealt out for interleaving: vpl.wgsl's dealt_position).
// runtime::cpu::val is the CPU twin (same order of every sum, so the same VALs).
//   cumulate (Weinzierl-Heigl's seeds) the VPLs' cumulative importance r + g + b, in one
//           workgroup: 64 contiguous chunks, as runtime::cpu::val::importance_cdf
//   init    centres from the restart VPLs, or from the Halton points warped by the cumulative
//           importance
//   assign  each live VPL's nearest centre (ties to the lower index) → the mapping C; a VPL of
//           zero flux (an RSM sample that found nothing) maps to NONE and joins no VAL
//   converge stops the iterations once the assignment repeats itself (the paper iterates to
//           convergence; the iteration count is a maximum)
//   update  each VAL's centre: mean position and normalised mean normal of its VPLs, summed
//           in VPL order (an empty VAL keeps its centre)
//   finish  each VAL's VPL count, flux and bounding rectangle in the plane normal to it

// As runtime::gpu::layout::ValFrame.
struct ValFrame {
    vpl_count: u32,
    val_count: u32,
    // Interleaving subsets B (1: none).
    subsets: u32,
    // 0 restart (Dong et al.), 1 Halton seeds warped by flux (Weinzierl-Heigl).
    seeding: u32,
    w_x: f32,
    w_alpha: f32,
    // Weight of the flux term; splat radius over D (0: every centre).
    w_f: f32,
    splat: f32,
    // 1: a warm start that seeds again the VALs that held no VPL last frame (the paper's
    // initialisation "whenever there are no RSM-pixels assigned to a cluster").
    reseed: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

@group(0) @binding(0) var<uniform> frame: ValFrame;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
// Per VAL: centre (xyz), normal (xyz), mean flux of its VPLs (rgb) at 3k, 3k + 1, 3k + 2.
@group(0) @binding(2) var<storage, read_write> centres: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> mapping: array<u32>;
@group(0) @binding(4) var<storage, read_write> vals: array<Val>;
// 1 / D, D the VPLs' bounding-box diagonal: uploaded when the CPU has the VPLs, else computed
// by `scale` (RSM VPLs stay on the GPU).
@group(0) @binding(6) var<storage, read_write> inv_scale: array<f32, 1>;
// Convergence: 0 VPLs whose VAL changed in this iteration's assignment, 1 done (the mapping
// stopped changing: every later iteration would repeat the last), 2 updates run, 3 VALs that
// hold VPLs.
@group(0) @binding(7) var<storage, read_write> state: array<atomic<u32>, 4>;
// The VPLs' inclusive cumulative importance (seeding 1).
@group(0) @binding(8) var<storage, read_write> cdf: array<f32>;

var<workgroup> wg_lo: array<vec3<f32>, WG_LINEAR>;
var<workgroup> wg_hi: array<vec3<f32>, WG_LINEAR>;

// A VPL that carries light: an RSM sample that found no surface gives one of zero flux, which
// takes no part in the clustering (runtime::cpu::val::is_live).
fn live(v: Vpl) -> bool {
    return any(v.flux != vec3<f32>(0.0));
}

// One workgroup: 1 / D over the live VPLs, as runtime::cpu::val::scale_of gives it (1 for none).
@compute @workgroup_size(WG_LINEAR)
fn scale(@builtin(local_invocation_index) li: u32) {
    var lo = vec3<f32>(3.4e38);
    var hi = vec3<f32>(-3.4e38);
    for (var i = li; i < frame.vpl_count; i += WG_LINEAR) {
        if live(vpls[i]) {
            lo = min(lo, vpls[i].position);
            hi = max(hi, vpls[i].position);
        }
    }
    wg_lo[li] = lo;
    wg_hi[li] = hi;
    workgroupBarrier();
    for (var o = WG_LINEAR / 2u; o > 0u; o >>= 1u) {
        if li < o {
            wg_lo[li] = min(wg_lo[li], wg_lo[li + o]);
            wg_hi[li] = max(wg_hi[li], wg_hi[li + o]);
        }
        workgroupBarrier();
    }
    if li == 0u {
        var d = 1.0;
        if wg_lo[0].x <= wg_hi[0].x {
            d = max(length(wg_hi[0] - wg_lo[0]), 1e-30);
        }
        inv_scale[0] = 1.0 / d;
    }
}

var<workgroup> wg_total: array<f32, WG_LINEAR>;

fn importance(v: Vpl) -> f32 {
    return v.flux.x + v.flux.y + v.flux.z;
}

@compute @workgroup_size(WG_LINEAR)
fn cumulate(@builtin(local_invocation_index) li: u32) {
    let n = frame.vpl_count;
    let chunk = max((n + WG_LINEAR - 1u) / WG_LINEAR, 1u);
    let first = li * chunk;
    let last = min(first + chunk, n);
    var total = 0.0;
    for (var i = first; i < last; i++) {
        total += importance(vpls[i]);
    }
    wg_total[li] = total;
    workgroupBarrier();
    var base = 0.0;
    for (var t = 0u; t < li; t++) {
        base += wg_total[t];
    }
    var run = base;
    for (var i = first; i < last; i++) {
        run += importance(vpls[i]);
        cdf[i] = run;
    }
}

fn set_centre(k: u32, v: Vpl) {
    centres[3u * k] = vec4<f32>(v.position, 0.0);
    centres[3u * k + 1u] = vec4<f32>(v.normal, 0.0);
    centres[3u * k + 2u] = vec4<f32>(v.flux, 0.0);
}

@compute @workgroup_size(WG_LINEAR)
fn init(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x;
    let n = frame.vpl_count;
    let m = frame.val_count;
    if k >= m || n == 0u {
        return;
    }
    // A warm start keeps every VAL that held VPLs last frame (`vals` holds last frame's).
    if frame.reseed == 1u && vals[k].position.w > 0.0 {
        return;
    }
    if frame.seeding == 1u {
        // The first VPL whose cumulative importance exceeds h2(k) × the total.
        let target_ = f32(reverseBits(k)) * 2.3283064e-10 * cdf[n - 1u];
        var lo = 0u;
        var hi = n;
        while lo < hi {
            let mid = (lo + hi) / 2u;
            if cdf[mid] <= target_ {
                lo = mid + 1u;
            } else {
                hi = mid;
            }
        }
        set_centre(k, vpls[min(lo, n - 1u)]);
        return;
    }
    // ⌊k·N/M⌋ of the merged sequence without overflowing 32 bits, read through the deal; a
    // dead VPL there gives way to the next live one of the sequence.
    let j = k * (n / m) + (k * (n % m)) / m;
    var at = dealt_position(j, n);
    for (var s = 0u; s < n; s++) {
        let i = dealt_position((j + s) % n, n);
        if live(vpls[i]) {
            at = i;
            break;
        }
    }
    set_centre(k, vpls[at]);
}

fn distance(v: Vpl, k: u32) -> f32 {
    let dx = length(v.position - centres[3u * k].xyz) * inv_scale[0];
    let da = acos(clamp(dot(v.normal, centres[3u * k + 1u].xyz), -1.0, 1.0)) / PI;
    var d = frame.w_x * dx + frame.w_alpha * da;
    if frame.w_f > 0.0 {
        let f = centres[3u * k + 2u].xyz;
        let sum = length(v.flux) + length(f);
        if sum > 0.0 {
            d += frame.w_f * (length(v.flux - f) / sum);
        }
    }
    return d;
}

// Whether centre k's splat reaches VPL v.
fn in_splat(v: Vpl, k: u32) -> bool {
    return length(v.position - centres[3u * k].xyz) * inv_scale[0] <= frame.splat;
}

@compute @workgroup_size(WG_LINEAR)
fn assign(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= frame.vpl_count || atomicLoad(&state[1]) != 0u {
        return;
    }
    let v = vpls[i];
    if !live(v) {
        mapping[i] = NONE;
        return;
    }
    var best = 3.4e38;
    var at = 0u;
    var splat_best = 3.4e38;
    var splat_at = NONE;
    for (var k = 0u; k < frame.val_count; k++) {
        let d = distance(v, k);
        if d < best {
            best = d;
            at = k;
        }
        if frame.splat > 0.0 && in_splat(v, k) && d < splat_best {
            splat_best = d;
            splat_at = k;
        }
    }
    if splat_at != NONE {
        at = splat_at;
    }
    if mapping[i] != at {
        atomicAdd(&state[0], 1u);
    }
    mapping[i] = at;
}

// After each iteration's assignment: done when it changed nothing (the first always counts as
// a change: the mapping held last frame's), else one more update runs.
@compute @workgroup_size(1)
fn converge() {
    if atomicLoad(&state[1]) != 0u {
        return;
    }
    if atomicLoad(&state[2]) > 0u && atomicLoad(&state[0]) == 0u {
        atomicStore(&state[1], 1u);
    } else {
        atomicAdd(&state[2], 1u);
    }
    atomicStore(&state[0], 0u);
}

// One workgroup per VAL: lane t sums the VPLs i ≡ t (mod WG_LINEAR) in increasing i, then the
// lanes fold in a fixed tree (t += t + o for o = WG_LINEAR/2 … 1), the order the CPU twin
// (runtime::cpu::val::lane_sums) follows: the same bits, N / WG_LINEAR steps per lane instead
// of N per VAL.
var<workgroup> wg_done: u32;
var<workgroup> wg_a: array<vec3<f32>, WG_LINEAR>;
var<workgroup> wg_b: array<vec3<f32>, WG_LINEAR>;
var<workgroup> wg_c: array<vec3<f32>, WG_LINEAR>;
var<workgroup> wg_count: array<u32, WG_LINEAR>;
var<workgroup> wg_rect: array<vec4<f32>, WG_LINEAR>;

// Folds the lanes of wg_a, wg_b, wg_count (and wg_rect by min/max) into lane 0.
fn fold(li: u32) {
    workgroupBarrier();
    for (var o = WG_LINEAR / 2u; o > 0u; o >>= 1u) {
        if li < o {
            wg_a[li] += wg_a[li + o];
            wg_b[li] += wg_b[li + o];
            wg_c[li] += wg_c[li + o];
            wg_count[li] += wg_count[li + o];
            let r = wg_rect[li];
            let q = wg_rect[li + o];
            wg_rect[li] = vec4<f32>(min(r.x, q.x), max(r.y, q.y), min(r.z, q.z), max(r.w, q.w));
        }
        workgroupBarrier();
    }
}

@compute @workgroup_size(WG_LINEAR)
fn update(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let k = wg.x;
    if li == 0u {
        wg_done = atomicLoad(&state[1]);
    }
    let done = workgroupUniformLoad(&wg_done);
    if k >= frame.val_count || done != 0u {
        return;
    }
    var p = vec3<f32>(0.0);
    var nrm = vec3<f32>(0.0);
    var flux = vec3<f32>(0.0);
    var count = 0u;
    for (var i = li; i < frame.vpl_count; i += WG_LINEAR) {
        if mapping[i] == k {
            p += vpls[i].position;
            nrm += vpls[i].normal;
            flux += vpls[i].flux;
            count++;
        }
    }
    wg_a[li] = p;
    wg_b[li] = nrm;
    wg_c[li] = flux;
    wg_count[li] = count;
    wg_rect[li] = vec4<f32>(0.0);
    fold(li);
    if li == 0u && wg_count[0] > 0u {
        let c = f32(wg_count[0]);
        centres[3u * k] = vec4<f32>(wg_a[0] / c, 0.0);
        let l = length(wg_b[0]);
        if l > 0.0 {
            centres[3u * k + 1u] = vec4<f32>(wg_b[0] / l, 0.0);
        }
        centres[3u * k + 2u] = vec4<f32>(wg_c[0] / c, 0.0);
    }
}

@compute @workgroup_size(WG_LINEAR)
fn finish(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let k = wg.x;
    if k >= frame.val_count {
        return;
    }
    let c = centres[3u * k].xyz;
    let nrm = centres[3u * k + 1u].xyz;
    let tb = basis(nrm);
    var count = 0u;
    var flux = vec3<f32>(0.0);
    var moment = 0.0;
    var rect = vec4<f32>(1e38, -1e38, 1e38, -1e38);
    for (var i = li; i < frame.vpl_count; i += WG_LINEAR) {
        if mapping[i] == k {
            let q = vpls[i].position - c;
            let s = dot(q, tb[0]);
            let t = dot(q, tb[1]);
            rect = vec4<f32>(min(rect.x, s), max(rect.y, s), min(rect.z, t), max(rect.w, t));
            flux += vpls[i].flux;
            moment += s * s + t * t;
            count++;
        }
    }
    wg_a[li] = flux;
    wg_b[li] = vec3<f32>(moment, 0.0, 0.0);
    wg_c[li] = vec3<f32>(0.0);
    wg_count[li] = count;
    wg_rect[li] = rect;
    fold(li);
    if li != 0u {
        return;
    }
    count = wg_count[0];
    rect = wg_rect[0];
    if count == 0u {
        rect = vec4<f32>(0.0);
    }
    if count > 0u {
        atomicAdd(&state[3], 1u);
    }
    var v: Val;
    v.position = vec4<f32>(c, f32(count));
    v.normal = vec4<f32>(nrm, (rect.y - rect.x) * (rect.w - rect.z));
    // The disk of the same second moment: A = 2π·mean(s² + t²).
    var area = 0.0;
    if count > 0u {
        area = 2.0 * PI * (wg_b[0].x / f32(count));
    }
    v.flux = vec4<f32>(wg_a[0], area);
    v.rect = rect;
    vals[k] = v;
}

// The VPLs sorted by VAL and, within a VAL, by interleaving subset j = i mod B (B = the
// interleaving block's pixels, 1 without interleaving), each bucket in VPL order, for a gather
// that computes each VAL's visibility once per pixel and lights a pixel with its subset:
// M·B + 1 offsets (bucket k·B + j), then the VPL indices.
@group(0) @binding(5) var<storage, read_write> order: array<u32>;

fn buckets() -> u32 {
    return frame.val_count * frame.subsets;
}

@compute @workgroup_size(WG_LINEAR)
fn bucket_counts(@builtin(global_invocation_id) id: vec3<u32>) {
    let b = id.x;
    if b >= buckets() {
        return;
    }
    let k = b / frame.subsets;
    let j = b % frame.subsets;
    var c = 0u;
    for (var i = j; i < frame.vpl_count; i += frame.subsets) {
        if mapping[i] == k {
            c++;
        }
    }
    order[b] = c;
}

@compute @workgroup_size(1)
fn offsets() {
    var run = 0u;
    let n = buckets();
    for (var b = 0u; b < n; b++) {
        let c = order[b];
        order[b] = run;
        run += c;
    }
    order[n] = run;
}

@compute @workgroup_size(WG_LINEAR)
fn scatter(@builtin(global_invocation_id) id: vec3<u32>) {
    let b = id.x;
    let n = buckets();
    if b >= n {
        return;
    }
    let k = b / frame.subsets;
    let j = b % frame.subsets;
    var at = n + 1u + order[b];
    for (var i = j; i < frame.vpl_count; i += frame.subsets) {
        if mapping[i] == k {
            order[at] = i;
            at++;
        }
    }
}

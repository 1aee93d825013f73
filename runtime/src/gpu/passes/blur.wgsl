//! include: val.wgsl vpl.wgsl face.wgsl ratio.wgsl
// Interleaving's other half: the interleaved indirect irradiance (val_gather.wgsl) blurred over
// the b × b block (or, with blur_tent, a tent over (2b − 1)², by rows: cs_tent_rows) where the
// geometry agrees (Laine et al.: positions closer than a fraction of the scene, normals closer
// than a cosine), times albedo / π, added onto the image so far (`previous`: ping-pong, 32-bit
// float targets are not blendable everywhere). A compute pass, as the gathers (shade.wgsl's
// cs_gates_indirect says why).

@group(0) @binding(0) var<uniform> gather: ValGather;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_albedo: texture_2d<f32>;
@group(0) @binding(6) var previous: texture_2d<f32>;
@group(0) @binding(12) var indirect: texture_2d<f32>;
@group(0) @binding(13) var composed: texture_storage_2d<rgba32float, write>;
// Interleaved gates: at the pixels whose block holds too few taps that agree with them (w 1),
// the light of the subsets of the taps that do not, which they walked themselves (starved.wgsl's
// cs_starved_sums); a 1 × 1 texture of zeros for the other modes.
@group(0) @binding(14) var starved_sums: texture_2d<f32>;
// Interleaved walks with the ratio estimator (gather.ratio): the unshadowed far light at the
// pixels that unshadowed.wgsl sums it at (ratio.wgsl's grid), in pixel order; a 1 × 1 texture
// for the other modes.
@group(0) @binding(15) var unshadowed: texture_2d<f32>;

// Whether a tap that does not agree gives way to a copy of its subset (InterleaveParams::fill,
// gather.blur_fill): fixed with the pipeline, InterleaveBlur making one each way, so that a blur
// without it runs none of blur_copy's code. On llvmpipe its mere presence, never taken, made
// the loop over the taps 3.5× as long (e2m3's hall at 512², 1,024 VPLs, the tent: blur +
// compose 0.97–0.98 → 0.27–0.28 s; the same image, bit for bit).
override BLUR_FILL: u32 = 1u;

// The tent in two passes (InterleaveParams::tent_rows): cs_tent_rows sums each pixel's row of
// its window, the 2b − 1 taps that agree with that pixel, each weighed by the tent's factor
// along x, and the compose sums its column of those rows, each weighed by the factor along y:
// 2 (2b − 1) taps a pixel where the one pass reads (2b − 1)². A row whose pixel does not agree
// with the composed pixel (a silhouette, a table's leg, a door's edge) is not taken: the
// compose reads that row's taps itself against its own surface, as the one pass does, so that
// what differs from the one pass is only a tap that agrees with its row's pixel and not with
// the composed one (or the other way round). Fixed with the pipeline, as BLUR_FILL; the fill
// keeps the one pass (each tap's copies are found against the composed pixel).
override BLUR_TENT_ROWS: u32 = 0u;
// The rows (cs_tent_rows): light × weight and the weight, and the unshadowed light × weight;
// written there, read by the compose.
@group(0) @binding(16) var rows_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(17) var rows_unshadowed_out: texture_storage_2d<r32float, write>;
@group(0) @binding(18) var rows: texture_2d<f32>;
@group(0) @binding(19) var rows_unshadowed: texture_2d<f32>;

// Taps summed: light × weight and the weight, and the unshadowed light × weight.
struct Taps {
    sum: vec4<f32>,
    unshadowed: f32,
}

@compute @workgroup_size(8, 8)
fn cs_tent_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(g_position)) {
        return;
    }
    let px = vec2<i32>(id.xy);
    let b = i32(gather.block);
    let size = vec2<i32>(textureDimensions(indirect));
    let pos = textureLoad(g_position, px, 0);
    var r = Taps(vec4<f32>(0.0), 0.0);
    // Where the window does not fit the image the compose takes the box and reads no rows.
    if pos.w != 0.0 && all(size >= vec2<i32>(2 * b - 1)) {
        let n = normalize(textureLoad(g_normal, px, 0).xyz);
        r = tent_row(px.y, clamp(px.x, b - 1, size.x - b), pos.xyz, n);
    }
    textureStore(rows_out, px, r.sum);
    textureStore(rows_unshadowed_out, px, vec4<f32>(r.unshadowed, 0.0, 0.0, 0.0));
}

// Row y of the tent's window centred on column cx: the taps that agree with surface p (normal
// n), each weighed b − |x − cx|.
fn tent_row(y: i32, cx: i32, p: vec3<f32>, n: vec3<f32>) -> Taps {
    let b = i32(gather.block);
    let bu = gather.block;
    let size = vec2<u32>(textureDimensions(indirect));
    let ay = i32(deinterleave_axis(u32(y), bu, size.y));
    let lo = cx - (b - 1);
    var rx = vec2<u32>(u32(lo) % bu, u32(lo) / bu);
    var r = Taps(vec4<f32>(0.0), 0.0);
    for (var x = lo; x < cx + b; x++) {
        let ax = i32(axis_run_place(rx, size.x / bu, size.x % bu));
        rx = axis_run_next(rx, bu);
        let tap = vec2<i32>(x, y);
        if !blur_agrees(tap, p, n) {
            continue;
        }
        let w = f32(b - abs(x - cx));
        let l = textureLoad(indirect, select(tap, vec2<i32>(ax, ay), gather.deinterleaved == 1u), 0);
        r.sum += vec4<f32>(w * l.xyz, w);
        r.unshadowed += w * l.w;
    }
    return r;
}

// The tent's window (rows lo.y..hi.y, centred on `centre`) of the pixel px (surface p, normal
// n), summed from cs_tent_rows's rows.
fn tent_by_rows(px: vec2<i32>, centre: vec2<i32>, lo: i32, hi: i32, p: vec3<f32>, n: vec3<f32>) -> Taps {
    let b = i32(gather.block);
    var t = Taps(vec4<f32>(0.0), 0.0);
    for (var y = lo; y < hi; y++) {
        let at = vec2<i32>(px.x, y);
        var r: Taps;
        if blur_agrees(at, p, n) {
            r = Taps(textureLoad(rows, at, 0), textureLoad(rows_unshadowed, at, 0).x);
        } else {
            r = tent_row(y, centre.x, p, n);
        }
        let w = f32(b - abs(y - centre.y));
        t.sum += w * r.sum;
        t.unshadowed += w * r.unshadowed;
    }
    return t;
}

@compute @workgroup_size(8, 8)
fn cs_compose(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(previous)) {
        textureStore(composed, id.xy, compose(vec2<i32>(id.xy)));
    }
}

fn compose(px: vec2<i32>) -> vec4<f32> {
    let before = textureLoad(previous, px, 0);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return before;
    }
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    let b = i32(gather.block);
    let size = vec2<i32>(textureDimensions(indirect));
    // A starved pixel (w 1) walked the subsets of the taps that do not agree itself: each
    // agreeing tap's subset (its light × B) once, and those; it fills none.
    let walked = textureLoad(starved_sums, min(px, vec2<i32>(textureDimensions(starved_sums)) - 1), 0);
    // The tent's window of (2b − 1)², centred on the pixel moved inside the image so that it
    // holds every subset (as the box's block); the box where the image is too small for it.
    let tent = gather.blur_tent == 1u && walked.w != 1.0 && all(size >= vec2<i32>(2 * b - 1));
    let centre = clamp(px, vec2<i32>(b - 1), size - vec2<i32>(b));
    let block = select(interleave_block_around(px, b, size), vec4<i32>(centre - (b - 1), centre + b), tent);
    let lo = block.xy;
    let hi = block.zw;
    // Where a pixel lies in the deinterleaved target (vpl.wgsl's deinterleave_axis), stepped
    // along each axis instead of divided at every tap: on llvmpipe the divisions were 40 % of
    // the pass (e2m3's hall at 512², 4,096 VPLs, blur + compose 137 → 83 ms; the same image,
    // bit for bit).
    let bu = gather.block;
    let q = vec2<u32>(size) / bu;
    let m = vec2<u32>(size) % bu;
    let deint = gather.deinterleaved == 1u;
    var ry = vec2<u32>(u32(lo.y) % bu, u32(lo.y) / bu);
    let fill = BLUR_FILL == 1u && gather.blur_fill == 1u && walked.w != 1.0;
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    // The ratio estimator: the taps' subsets' unshadowed far light (the gather's w).
    var unshadowed_sum = 0.0;
    let by_rows = BLUR_TENT_ROWS == 1u && tent && !fill;
    if by_rows {
        let t = tent_by_rows(px, centre, lo.y, hi.y, pos.xyz, n);
        sum = t.sum.xyz;
        weight = t.sum.w;
        unshadowed_sum = t.unshadowed;
    }
    // By rows, the taps are summed above: the loop runs no row.
    for (var y = select(lo.y, hi.y, by_rows); y < hi.y; y++) {
        let ay = i32(axis_run_place(ry, q.y, m.y));
        ry = axis_run_next(ry, bu);
        var rx = vec2<u32>(u32(lo.x) % bu, u32(lo.x) / bu);
        for (var x = lo.x; x < hi.x; x++) {
            let ax = i32(axis_run_place(rx, q.x, m.x));
            rx = axis_run_next(rx, bu);
            let tap = vec2<i32>(x, y);
            var at = select(tap, vec2<i32>(ax, ay), deint);
            if !blur_agrees(tap, pos.xyz, n) {
                if !fill {
                    continue;
                }
                let copy = blur_copy(px, tap, pos.xyz, n, size);
                if copy.x == NO_COPY {
                    continue;
                }
                // A block's side away, a deinterleaved pixel away (vpl.wgsl's layout).
                at = select(tap + copy * b, vec2<i32>(ax, ay) + copy, deint);
            }
            let d = abs(tap - centre);
            let w = select(1.0, f32((b - d.x) * (b - d.y)), tent);
            let l = textureLoad(indirect, at, 0);
            sum += w * l.xyz;
            unshadowed_sum += w * l.w;
            weight += w;
        }
    }
    var e = select(sum / max(weight, 1.0), sum / f32(gather.subsets) + walked.xyz, walked.w == 1.0);
    // The ratio estimator (Heitz et al. 2018): the pixel's own unshadowed far light times the
    // share s of their unshadowed light that the taps' walks found visible (their light is
    // their subset's × B, w their subset's alone), so that where every VPL is visible the pixel
    // gets its exact light, whichever subsets its taps held. Weighed against the average by s
    // itself: where most of the light is shadowed, the pixel's unshadowed light over the taps'
    // is mostly the change of the shadowed VPLs' across the block, which the share would carry
    // onto the little light that passes (the ratio alone tripled the error of e2m3's `lit`
    // under its second lamp, weighed it took a third of that back; README). Not at a starved
    // pixel (its own walks hold no unshadowed light), nor where the taps' subsets hold no far
    // light.
    if gather.ratio == 1u && walked.w != 1.0 && unshadowed_sum > 0.0 {
        let stride = i32(max(gather.ratio_stride, 1u));
        let u = ratio_unshadowed(unshadowed, px, pos.xyz, n, stride, vec2<i32>(textureDimensions(g_position)));
        let s = min((sum.x + sum.y + sum.z) / (unshadowed_sum * f32(gather.subsets)), 1.0);
        e = mix(e, u * s, s);
    }
    return vec4<f32>(before.xyz + albedo / PI * e, 1.0);
}

// Whether tap t's surface agrees with p (normal n) by the blur's test (vpl.wgsl). The
// G-buffer's normals are unit already (gbuffer.wgsl): normalized again at every tap they cost
// the tent on llvmpipe 14 % of its pass (e2m3's hall at 512², 1,024 VPLs: 263–268 → 226–234
// ms; Crytek Sponza's gallery the same to an MSE of 8e-9, a few taps at the cosine's edge).
fn blur_agrees(t: vec2<i32>, p: vec3<f32>, n: vec3<f32>) -> bool {
    let qp = textureLoad(g_position, t, 0);
    let qn = textureLoad(g_normal, t, 0).xyz;
    return blur_surfaces_agree(qp, qn, p, n, gather.blur_distance, gather.blur_normal);
}

const NO_COPY: i32 = 99;

// Of the copies of tap t's VPL subset one block away (t + o·b, o each of the 4 steps along
// an axis to a neighbouring block), the step o to the one nearest pixel px that agrees with it
// (surface p, normal n) and lies inside the target; NO_COPY where none does. The diagonal
// steps too gained less over 10 cameras: 1.5 blocks away is farther than the light is alike
// (Crytek Sponza's gallery +3.6 % indirect MSE with them, −2.4 % without; README).
fn blur_copy(px: vec2<i32>, t: vec2<i32>, p: vec3<f32>, n: vec3<f32>, size: vec2<i32>) -> vec2<i32> {
    let b = i32(gather.block);
    var steps = array<vec2<i32>, 4>(vec2<i32>(0, -1), vec2<i32>(-1, 0), vec2<i32>(1, 0), vec2<i32>(0, 1));
    var best = vec2<i32>(NO_COPY);
    var best_d2 = 1 << 30;
    for (var k = 0; k < 4; k++) {
        let c = t + steps[k] * b;
        let d = c - px;
        let d2 = dot(d, d);
        if any(c < vec2<i32>(0)) || any(c >= size) || d2 >= best_d2 {
            continue;
        }
        if blur_agrees(c, p, n) {
            best = steps[k];
            best_d2 = d2;
        }
    }
    return best;
}

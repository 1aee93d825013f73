//! include: globals.wgsl vpl.wgsl
// Interleaved gates' starved pixels (starved.rs): the pixels whose blur block holds too few
// taps that agree with them, or whose agreeing taps found no light, reserve a (pixel, subset)
// pair for each VPL subset of the taps that do not agree; shade.wgsl's cs_starved_walks walks
// them, a pair an invocation; cs_starved_sums adds each pixel's up for blur.wgsl.

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_normal: texture_2d<f32>;
// cs_starved_sums' output.
@group(0) @binding(25) var out_image: texture_storage_2d<rgba32float, write>;

// Starved pixels: x the blur's distance (m), y its normals' cosine, z the fewest taps of a
// pixel's b × b block that must agree with it (blur.wgsl's test) before it walks the subsets of
// those that do not itself; w 1: a pixel whose agreeing taps found no light, where others
// did, walks them too.
@group(0) @binding(26) var<uniform> starved_params: vec4<f32>;
// The first gather's indirect target (deinterleaved), for w's test.
@group(0) @binding(32) var starved_indirect: texture_2d<f32>;
// x (pixel, subset) pairs reserved, y pixels whose pairs did not fit (the frame is rendered
// again with room for x), z starved pixels, w the pairs written, those of the pixels whose
// runs fit the list (cs_starved_args sets it for the walks).
@group(0) @binding(27) var<storage, read_write> starved_count: array<atomic<u32>, 4>;
// Two lists of the list's capacity each. The first, in pixel order (a starved pixel's pairs a
// run): x the pair's place in the second (before cs_starved_order, its rank among its
// subset's pairs), w its pixel × 256 + its subset. The second, in subset order (the pairs of
// subset 0, then of 1, …), which the walks read: xyz the pair's light so far (f32 bits), w as
// the first's.
@group(0) @binding(28) var<storage, read_write> starved_pairs: array<vec4<u32>>;
// A pixel each: x its first pair, y its pairs (NOT_STARVED: not starved).
@group(0) @binding(29) var<storage, read_write> starved_runs: array<vec2<u32>>;
// cs_starved_walks' dispatch: workgroups in x, y, z.
@group(0) @binding(30) var<storage, read_write> starved_args: array<u32, 3>;
// A subset each: its pairs (cs_starved_pairs counts them), then the first place of its pairs in
// the second list (cs_starved_args).
@group(0) @binding(33) var<storage, read_write> starved_subsets: array<atomic<u32>, 256>;

// The pairs a list holds.
fn starved_capacity() -> u32 {
    return arrayLength(&starved_pairs) / 2u;
}

const NOT_STARVED: u32 = 0xffffffffu;

// Whether tap q's surface agrees with p (normal n) by the blur's test (vpl.wgsl; the
// G-buffer's normals are unit already, as blur.wgsl's blur_agrees reads them).
fn blur_agrees(q: vec2<i32>, p: vec3<f32>, n: vec3<f32>) -> bool {
    let qp = textureLoad(g_position, q, 0);
    let qn = textureLoad(g_normal, q, 0).xyz;
    return blur_surfaces_agree(qp, qn, p, n, starved_params.x, starved_params.y);
}

// Interleaved gates' second gather. The blur averages a pixel's block where the geometry
// agrees, each tap lit by one of the b² VPL subsets; where few taps agree (a door jamb, a strip
// along a wall) it averages a handful of subsets, and where a few VPLs light the place those
// may hold none of them. A pixel whose block holds fewer than starved_params.z agreeing taps
// (or, with starved_params.w, whose agreeing taps found no light at all where the others
// found some: the strip the blur would leave black) walks, itself, the subsets of the taps that
// do not agree, and blur.wgsl adds them to the agreeing taps' subsets: every VPL counted once.
//
// Five passes, so that a starved pixel's walks spread over as many invocations as it has
// subsets to walk: one invocation walking all of them (up to 63 subsets, every VPL of each)
// held up its whole warp, and the few starved pixels' warps held up the frame (3.7–274× the
// frame on an NVIDIA H200). cs_starved_pairs: each pixel tests its block; a starved one
// reserves a run of (pixel, subset) pairs, one per subset of the taps that do not agree, in the
// block's order. cs_starved_args: the walks' dispatch from the pairs' count. cs_starved_walks:
// an invocation a pair walks its subset's VPLs (in batches on a software rasterizer, each
// adding to the pair's light). cs_starved_sums: in pixel order, xyz a starved pixel's pairs'
// light summed, w 1 there, 0 elsewhere (blur.wgsl reads it).
//
// Between the dispatch and the walks, cs_starved_order copies the pairs into subset order, so
// that neighbouring invocations walk the same VPLs to nearby pixels (a pixel's run, in pixel
// order, puts a different subset on each lane: every lane's walk from another VPL).
@compute @workgroup_size(8, 8)
fn cs_starved_pairs(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(g_position);
    if any(id.xy >= size) {
        return;
    }
    let pixel = id.x + id.y * size.x;
    starved_runs[pixel] = vec2<u32>(0u, NOT_STARVED);
    let px = vec2<i32>(id.xy);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return;
    }
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let bu = max(globals.interleave_block, 1u);
    let dark_test = starved_params.w == 1.0;
    // Dark pixels alone (no count of taps, or one the pixel meets by itself): a pixel that
    // found light and agrees with itself is one of its own agreeing taps, so it is not dark,
    // and the block need not be read (the same answer as the loop below, without 64 taps
    // read at every lit pixel); any other pixel reads its taps' surfaces only where they found
    // light (dark_block), and the loop below runs at the dark ones alone.
    let dark_only = dark_test && starved_params.z <= 1.0;
    if dark_only {
        let own = textureLoad(starved_indirect, deinterleaved(px, bu, size), 0).xyz;
        if own.x + own.y + own.z > 0.0 && blur_agrees(px, pos.xyz, n) {
            return;
        }
    }
    let block = interleave_block_around(px, i32(bu), vec2<i32>(size));
    if dark_only && !dark_block(block, bu, size, pos.xyz, n) {
        return;
    }
    // The taps that do not agree, a bit each in the block's order (b ≤ 16: 256 bits).
    var away = array<u32, 8>();
    var agree = 0.0;
    var missing = 0u;
    // The agreeing taps' light and the others', where w asks for them.
    var found = 0.0;
    var others = 0.0;
    var t = 0u;
    for (var y = block.y; y < block.w; y++) {
        for (var x = block.x; x < block.z; x++) {
            let q = vec2<i32>(x, y);
            if blur_agrees(q, pos.xyz, n) {
                agree += 1.0;
                if dark_test {
                    let at = deinterleaved(q, bu, size);
                    let l = textureLoad(starved_indirect, at, 0).xyz;
                    found += l.x + l.y + l.z;
                }
            } else if interleave_subset(q, bu) < globals.vpl_count {
                away[t / 32u] |= 1u << (t % 32u);
                missing += 1u;
                if dark_test {
                    let l = textureLoad(starved_indirect, deinterleaved(q, bu, size), 0).xyz;
                    others += l.x + l.y + l.z;
                }
            }
            t += 1u;
        }
    }
    // Dark: the agreeing taps found no light and some other tap did. A block where no tap
    // found any (every VPL subset tried once nearby) is taken for indirect shadow and walks
    // nothing more (the pillared hall's side room, seed 2: 7,794 → 1,113 walking pixels,
    // black where lit 0.01 → 0.00 %).
    let dark = dark_test && found <= 0.0 && others > 0.0;
    if agree >= starved_params.z && !(dark && missing > 0u) {
        return;
    }
    let first = atomicAdd(&starved_count[0], missing);
    if first + missing > starved_capacity() {
        atomicAdd(&starved_count[1], 1u);
        return;
    }
    atomicAdd(&starved_count[2], 1u);
    var k = first;
    t = 0u;
    for (var y = block.y; y < block.w; y++) {
        for (var x = block.x; x < block.z; x++) {
            if (away[t / 32u] & (1u << (t % 32u))) != 0u {
                let j = interleave_subset(vec2<i32>(x, y), bu);
                let rank = atomicAdd(&starved_subsets[j], 1u);
                starved_pairs[k] = vec4<u32>(rank, 0u, 0u, pixel * 256u + j);
                k += 1u;
            }
            t += 1u;
        }
    }
    starved_runs[pixel] = vec2<u32>(first, missing);
}

// Whether a pixel (surface p, normal n) is dark in its blur block (x0, y0, x1, y1): no tap that
// agrees with it found light, and a tap that does not agree did (the loop of cs_starved_pairs
// with the dark test alone, the same answer). A tap that found no light counts for neither, so
// its surface is not read; the first agreeing tap with light ends it. In a block where no tap
// found light (indirect shadow) a pixel reads the 64 taps' light alone, where it read their
// positions and normals too (e2m3's hall at 512², 1,024 VPLs, no pixel dark: the pass 139–155 →
// 28–31 ms on lavapipe; the pillared hall's side room 231–233 → 158–207 ms; the same images).
fn dark_block(block: vec4<i32>, bu: u32, size: vec2<u32>, p: vec3<f32>, n: vec3<f32>) -> bool {
    var others = false;
    for (var y = block.y; y < block.w; y++) {
        for (var x = block.x; x < block.z; x++) {
            let q = vec2<i32>(x, y);
            let l = textureLoad(starved_indirect, deinterleaved(q, bu, size), 0).xyz;
            if l.x + l.y + l.z <= 0.0 {
                continue;
            }
            if blur_agrees(q, p, n) {
                return false;
            }
            others = others || interleave_subset(q, bu) < globals.vpl_count;
        }
    }
    return others;
}

// The walks' dispatch from the pairs written (those of the pixels whose runs fit the list),
// their count for the walks, and each subset's first place in the second list.
@compute @workgroup_size(1)
fn cs_starved_args() {
    var pairs = 0u;
    for (var j = 0u; j < 256u; j++) {
        let count = atomicLoad(&starved_subsets[j]);
        atomicStore(&starved_subsets[j], pairs);
        pairs += count;
    }
    atomicStore(&starved_count[3], pairs);
    let groups = (pairs + STARVED_WALKS_GROUP - 1u) / STARVED_WALKS_GROUP;
    // At most 65,535 workgroups along an axis (WebGPU's default limit).
    let x = min(groups, 65535u);
    starved_args[0] = x;
    starved_args[1] = select(1u, (groups + x - 1u) / x, x > 0u);
    starved_args[2] = 1u;
}

// The pairs copied into subset order (the second list), each pair of the first told its place
// there; dispatched as the walks.
@compute @workgroup_size(STARVED_WALKS_GROUP)
fn cs_starved_order(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * STARVED_WALKS_GROUP;
    if k >= atomicLoad(&starved_count[3]) {
        return;
    }
    let pair = starved_pairs[k];
    let place = atomicLoad(&starved_subsets[pair.w % 256u]) + pair.x;
    starved_pairs[starved_capacity() + place] = vec4<u32>(0u, 0u, 0u, pair.w);
    starved_pairs[k].x = place;
}

@compute @workgroup_size(8, 8)
fn cs_starved_sums(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(g_position);
    if any(id.xy >= size) {
        return;
    }
    let run = starved_runs[id.x + id.y * size.x];
    var out = vec4<f32>(0.0);
    if run.y != NOT_STARVED {
        var sum = vec3<f32>(0.0);
        let second = starved_capacity();
        for (var k = run.x; k < run.x + run.y; k++) {
            sum += bitcast<vec3<f32>>(starved_pairs[second + starved_pairs[k].x].xyz);
        }
        out = vec4<f32>(sum, 1.0);
    }
    textureStore(out_image, id.xy, out);
}

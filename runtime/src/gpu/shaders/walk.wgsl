// The walks a gather runs from a pixel (shade.wgsl's passes include it): the gate shape and the
// voxel walk's kind fixed with a pipeline, the pixel's end of the voxel walk, a VPL walked, a
// pixel's VPLs walked with the roulette (a VPL's light less the near field's share: far.wgsl).
// It reads the including pass's globals, vpls, g_normal, g_albedo, grid, vpl_ends and
// vpl_cluster (and what grid.wgsl, portals.wgsl and sight.wgsl read); no bindings of its own.

// The face's own normal at pixel px (the G-buffer's encode_face_normal).
fn face_normal(px: vec2<i32>) -> vec3<f32> {
    let e = vec2<f32>(textureLoad(g_normal, px, 0).w, textureLoad(g_albedo, px, 0).w);
    return decode_face_normal(e);
}

// The gate shape: fixed when a pipeline is made (the interleaved indirect pass has one per
// shape, runtime::gpu::passes::shade), or GATE_SHAPE_AT_RUNTIME: the level's. llvmpipe runs
// both sides of a branch on a value read at run time, under masks: with the shape read from
// the level every VPL's voxel walk also ran the portal walk's code (LibreQuake e2m3's hall,
// 512 x 512, 4,096 VPLs: indirect pass 1,363 -> 818 ms; with no walk at all, 632 -> 167 ms).
override GATE_SHAPE: u32 = 3u;
const GATE_SHAPE_AT_RUNTIME: u32 = 3u;

// The voxel walk along the true segment with the closed voxels' triangles (1) or between ends
// off the surfaces, closed voxels blocking (0): fixed with the interleaved pass's pipeline, or
// SIGHT_TRIANGLES_AT_RUNTIME: the frame's (grid.triangles).
override SIGHT_TRIANGLES: u32 = 2u;
const SIGHT_TRIANGLES_AT_RUNTIME: u32 = 2u;

fn sight_triangles() -> bool {
    if SIGHT_TRIANGLES != SIGHT_TRIANGLES_AT_RUNTIME {
        return SIGHT_TRIANGLES == 1u;
    }
    return grid.triangles != 0u;
}

// The voxel walk between ends off the surfaces passes closed voxels on their planes (1) or not
// (0): fixed with the interleaved pass's pipeline, so that a walk without them runs none of
// their code (it cost that walk 10-20 % of its pass on an H200), or SIGHT_PLANES_AT_RUNTIME:
// the frame's grid.planes. The renderer uploads the planes for it.
override SIGHT_PLANES: u32 = 2u;
const SIGHT_PLANES_AT_RUNTIME: u32 = 2u;

fn sight_planes() -> bool {
    if SIGHT_PLANES != SIGHT_PLANES_AT_RUNTIME {
        return SIGHT_PLANES == 1u && !sight_triangles();
    }
    return grid.planes != 0u && !sight_triangles();
}

fn gate_shape() -> u32 {
    if GATE_SHAPE != GATE_SHAPE_AT_RUNTIME {
        return GATE_SHAPE;
    }
    return grid.shape;
}

// The walks' Russian roulette (globals.walk_roulette = s > 0) at p: the unshadowed light of
// the whole of subset j (of `subsets`) there, summed over its channels; a VPL under s times
// it is walked by chance (walk_range). Summed once, in a pixel's first batch, so that the cut
// does not depend on the batching (summed in every batch, it cost e2m3's hall 1.2 s of 3.7 at
// 16,384 VPLs on lavapipe), but for the ratio estimator's (shade.wgsl's portal_gather). 0
// when off. With the ratio estimator (globals.ratio) the near field's share left out: the
// subset's unshadowed far light, as the walks weigh it.
fn roulette_total(p: vec3<f32>, n: vec3<f32>, j: u32, subsets: u32) -> f32 {
    let ratio = globals.ratio == 1u;
    if globals.walk_roulette <= 0.0 {
        return 0.0;
    }
    // near_share is 0 at a radius of 0: the whole light, as without the ratio.
    let r = select(0.0, near_radius(p), ratio);
    var total = 0.0;
    for (var k = j; k < globals.vpl_count; k += subsets) {
        let l = far_light(vpls[k], p, n, r);
        total += l.x + l.y + l.z;
    }
    return total;
}

// The roulette's numbers for pixel px: a hash (PCG, O'Neill) of the seed and the pixel's
// 8 × 8 tile of the deinterleaved target (8 b × 8 b pixels), which roulette_unit shifts a Weyl
// sequence by. The tile's lanes (a workgroup) walk or skip a VPL together, for a GPU's warps,
// where one lane's walk holds up the others (on lavapipe's 8 lanes it changed nothing). The
// blur averages pixels of 64 tiles.
fn roulette_hash(px: vec2<i32>) -> u32 {
    let t = px / i32(8u * max(globals.interleave_block, 1u));
    var h = (u32(t.x) * 73856093u) ^ (u32(t.y) * 19349663u) ^ globals.walk_seed;
    for (var r = 0; r < 2; r++) {
        let state = h * 747796405u + 2891336453u;
        let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
        h = (word >> 22u) ^ word;
    }
    return h;
}

// A uniform number in [0, 1) for VPL k at a pixel whose roulette_hash is h: the Weyl sequence
// k times the golden ratio, mod 1, shifted by h. Each VPL's number is uniform; a pixel's VPLs'
// numbers spread evenly over [0, 1), so the weak VPLs it walks number about what they should.
fn roulette_unit(h: u32, k: u32) -> f32 {
    return f32((k * 2654435769u + h) >> 8u) * (1.0 / 16777216.0);
}

// The voxel walk's end at p (off its face, or a hair off it along the true segment; w = 0:
// no open voxel near), the same for every VPL; unused by the portal walk.
fn walk_end_at(px: vec2<i32>, p: vec3<f32>) -> vec4<f32> {
    var at_p = vec4<f32>(0.0);
    if gate_shape() == GATE_VOXELS {
        let n_face = face_normal(px);
        at_p = sight_end(p, n_face, sight_planes());
        if sight_triangles() {
            at_p = vec4<f32>(sight_true_end(p, n_face), at_p.w);
        }
    }
    return at_p;
}

// The light at pixel px's p (normal n, cluster `here`, walk end at_p) of VPLs first,
// first + step, … below end, each that the walk finds visible; a VPL whose light sums under
// `cut` (the roulette's share of roulette_total; 0: none) is walked with probability (its
// light / cut) and counts 1 / that probability. The VPLs nearer p than the near field's
// radius (near_radius) count by the share near_share leaves them: cs_near_field walks them at
// the pixel itself for the rest. w: the unshadowed light, summed over its channels, of the
// VPLs walked, each weighed as its light (the ratio estimator's share of visible light: 1
// where every VPL walked is visible, with the roulette too).
fn walk_range(px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, here: u32, at_p: vec4<f32>, first: u32, end: u32, step: u32, cut: f32) -> vec4<f32> {
    var sum = vec3<f32>(0.0);
    var walked = 0.0;
    let h = roulette_hash(px);
    let r = near_radius(p);
    for (var k = first; k < end; k += step) {
        let v = vpls[k];
        let to_v = v.position - p;
        let near = near_share(dot(to_v, to_v), r);
        if near >= 1.0 {
            continue;
        }
        var l = vpl_light(v, p, n, globals.g_max) * (1.0 - near);
        if all(l == vec3<f32>(0.0)) {
            continue;
        }
        let y = l.x + l.y + l.z;
        if y < cut {
            let keep = y / cut;
            if roulette_unit(h, k) >= keep {
                continue;
            }
            l /= keep;
        }
        walked += l.x + l.y + l.z;
        if walk_visible(k, v, p, here, at_p) {
            sum += l;
        }
    }
    return vec4<f32>(sum, walked);
}

// Whether VPL k (v) lights p (cluster `here`, walk end at_p): the voxel walk or the portal
// walk.
fn walk_visible(k: u32, v: Vpl, p: vec3<f32>, here: u32, at_p: vec4<f32>) -> bool {
    if gate_shape() == GATE_VOXELS {
        let at_v = vpl_ends[k];
        // Either end where the bake knows nothing: unoccluded.
        if at_v.w == 0.0 || at_p.w == 0.0 {
            return true;
        }
        if sight_triangles() {
            return sight_clear_lists(sight_true_end(v.position, v.normal), at_p.xyz);
        }
        return sight_clear(at_v.xyz, at_p.xyz, sight_planes());
    }
    let ca = vpl_cluster[k];
    return ca == NONE || here == NONE || ca == here
        || portal_walk(v.position, ca, p, here) == WALK_VISIBLE;
}

//! include: globals.wgsl lights.wgsl shadow_lookup.wgsl vpl.wgsl gates.wgsl portals.wgsl sight.wgsl
// Deferred shading: direct light from point and spot lights with shadow-map PCF (3 × 3, a contact
// test at thin walls' joins: shadow_lookup.wgsl), and
// the indirect sum over VPLs without visibility (SHADE_ALL), through the gates of a baked
// level per pixel (SHADE_GATES_PER_PIXEL) or by clustered light lists (SHADE_GATES_CLUSTERED),
// or none (SHADE_DIRECT: direct light only), into a linear HDR target.
//
// Radiometry as the CPU reference: L = ρ/π · I · falloff · cos θ / d² for lights, and
// ρ/π · Φ/π · min(cos θ_v cos θ_x / d², g_max) for VPLs.

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(3) var<storage, read> shadow_mats: array<mat4x4<f32>>;
@group(0) @binding(4) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_normal: texture_2d<f32>;
@group(0) @binding(7) var g_albedo: texture_2d<f32>;

// Gate visibility: a pixel's cluster is in the G-buffer (position.w). SHADE_GATES_PER_PIXEL
// tests every VPL with a chain of at most 2 gate disks; SHADE_GATES_CLUSTERED walks the light
// list of the pixel's geometry cluster that the clusters.wgsl passes built.

@group(0) @binding(8) var<uniform> grid: Grid;
@group(0) @binding(9) var<storage, read> voxel_words: array<u32>;
@group(0) @binding(10) var<storage, read> gates: array<Gate>;
// Offsets (clusters + 1) into this same array, then the gate indices.
@group(0) @binding(11) var<storage, read> cluster_gates: array<u32>;

// As runtime::gpu::layout::GeometryCluster (clusters.wgsl writes them).
struct GeometryCluster {
    // x tile x, y tile y, z depth slice, w visibility cluster.
    key: vec4<u32>,
    lo: vec4<f32>,
    hi: vec4<f32>,
    // x first entry, y entries, z entries needed, w unused.
    list: vec4<u32>,
};

@group(0) @binding(12) var<storage, read> pixel_cluster: array<u32>;
@group(0) @binding(13) var<storage, read> geometry_clusters: array<GeometryCluster>;
// (VPL, gates) of disks: gates (g0 + 1) | (g1 + 1) << 16, 0 for none (portals keep no lists).
@group(0) @binding(14) var<storage, read> light_entries: array<vec2<u32>>;
// The portals (portals.wgsl).
@group(0) @binding(15) var<storage, read> portal_words: array<u32>;
// Each VPL's visibility cluster (clusters.wgsl's vpl_clusters).
@group(0) @binding(16) var<storage, read> vpl_cluster: array<u32>;
// LightCluster (DIRECT_LIGHTCLUSTER): each cluster's visibility (layer k / 4, channel k % 4)
// and each light's cluster (NONE: culled, not shaded).
@group(0) @binding(17) var lc_visibility: texture_2d_array<f32>;
@group(0) @binding(18) var<storage, read> lc_light_cluster: array<u32>;
// SHADE_VPL_CLUSTERS: the VPLs' clusters' visibility and each VPL's cluster (NONE: no flux).
@group(0) @binding(19) var vpl_lc_visibility: texture_2d_array<f32>;
@group(0) @binding(20) var<storage, read> vpl_lc_cluster: array<u32>;
// Walks in batches (cs_gates_indirect): the sum of the batches before, in the
// (deinterleaved) layout of the indirect target.
@group(0) @binding(21) var earlier_batches: texture_2d<f32>;
// The level's open voxels and their bricks' clearance, for the voxel walk (sight.wgsl).
@group(0) @binding(22) var<storage, read> sight_words: array<u32>;
// The closed voxels' triangle lists and planes (sight.wgsl).
@group(0) @binding(31) var<storage, read> sight_extra: array<u32>;
// Each VPL's end of the voxel walk (sight_ends.wgsl), for cs_gates_indirect.
@group(0) @binding(23) var<storage, read> vpl_ends: array<vec4<f32>>;

// SHADE_VPL_CLUSTERS: the VPLs first, first + step, … (every VPL, or an interleaving subset),
// each shadowed by its cluster's PCSS visibility at px; the sum × step.
fn gather_vpl_clusters(p: vec3<f32>, n: vec3<f32>, px: vec2<i32>, first: u32, step: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var j = first; j < globals.vpl_count; j += step) {
        let c = vpl_lc_cluster[j];
        if c == NONE {
            continue;
        }
        let l = vpl_light(vpls[j], p, n, globals.g_max);
        if any(l > vec3<f32>(0.0)) {
            sum += l * textureLoad(vpl_lc_visibility, px, i32(c / 4u), 0)[c % 4u];
        }
    }
    return sum * f32(step);
}

// Light i's visibility at pixel px (p, shading normal n, face normal nf): its shadow maps, or
// its cluster's PCSS.
fn direct_visibility(i: u32, l: Light, p: vec3<f32>, n: vec3<f32>, nf: vec3<f32>, px: vec2<i32>) -> f32 {
    if globals.direct_mode == DIRECT_LIGHTCLUSTER {
        let c = lc_light_cluster[i];
        if c == NONE {
            return 0.0;
        }
        return textureLoad(lc_visibility, px, i32(c / 4u), 0)[c % 4u];
    }
    return shadow(l, p, n, nf);
}

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

// Whether the light of a VPL at a (cluster ca) reaches b (cluster cb) through a chain of at
// most grid.max_hops gate disks (GateLevel::visible with disks). Portals and voxels walk in
// cs_gates_indirect, gates-per-pixel too (GpuMode::as_run).
fn through_gates(a: vec3<f32>, ca: u32, b: vec3<f32>, cb: u32) -> bool {
    if ca == cb || ca == NONE || cb == NONE {
        return true;
    }
    for (var i = cluster_gates[ca]; i < cluster_gates[ca + 1u]; i++) {
        let g = gates[cluster_gates[i]];
        if !crosses(a, b, g) {
            continue;
        }
        let c = other_side(g, ca);
        if c == cb {
            return true;
        }
        if grid.max_hops < 2u {
            continue;
        }
        for (var j = cluster_gates[c]; j < cluster_gates[c + 1u]; j++) {
            let h = gates[cluster_gates[j]];
            if other_side(h, c) == cb && crosses(a, b, h) {
                return true;
            }
        }
    }
    return false;
}

// The shading pass (a compute pass, as every pass over the frame's pixels: cs_gates_indirect
// says why).
@compute @workgroup_size(8, 8)
fn cs_shade(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(g_position)) {
        textureStore(out_image, id.xy, shade(vec2<i32>(id.xy)));
    }
}

fn shade(px: vec2<i32>) -> vec4<f32> {
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let p = pos.xyz;
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    // The face's normal, for the shadow maps' contact test (decoded once, not per light).
    let nf = face_normal(px);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < globals.light_count; i++) {
        let l = lights[i];
        let to_light = l.position.xyz - p;
        let d2 = dot(to_light, to_light);
        if d2 <= 0.0 {
            continue;
        }
        let w = to_light * inverseSqrt(d2);
        let cos_x = dot(n, w);
        if cos_x <= 0.0 {
            continue;
        }
        var intensity = l.intensity.xyz;
        if l.position.w == LIGHT_SPOT {
            let angle = acos(clamp(dot(l.direction.xyz, -w), -1.0, 1.0));
            intensity *= spot_falloff(angle, l.intensity.w, l.direction.w);
        }
        if all(intensity == vec3<f32>(0.0)) {
            continue;
        }
        radiance += albedo / PI * intensity * cos_x / d2 * direct_visibility(i, l, p, n, nf, px);
    }
    // One loop per mode: a software rasterizer (lavapipe) runs a loop that carries another
    // mode's branch several times slower.
    let mode = globals.shade_mode;
    if mode == SHADE_ALL {
        radiance += albedo / PI * gather_all(p, n);
    } else if mode == SHADE_GATES_PER_PIXEL {
        radiance += albedo / PI * gather_per_pixel(p, n, decode_cluster(pos.w));
    } else if mode == SHADE_VPL_CLUSTERS && globals.interleave_block <= 1u {
        radiance += albedo / PI * gather_vpl_clusters(p, n, px, 0u, 1u);
    } else if mode == SHADE_GATES_CLUSTERED && globals.interleave_block <= 1u && gate_shape() == GATE_DISKS {
        radiance += albedo / PI * clustered_gather(px, p, n, decode_cluster(pos.w));
    }
    return vec4<f32>(radiance, 1.0);
}

// SHADE_GATES_CLUSTERED with disks (portals and voxels walk in portal_gather, from
// cs_gates_indirect): the VPL light at p through its geometry cluster's list (without albedo / π). An
// entry with gates is tested here, per pixel; a VPL whose light passes by several chains
// counts once (a list is ordered by (VPL mod B, VPL)). With interleaving (B = b² subsets) the
// pixel takes only its subset's run of the list, found by binary search, and the sum is × B.
fn clustered_gather(px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, here: u32) -> vec3<f32> {
    let b = max(globals.interleave_block, 1u);
    let subsets = b * b;
    let j = interleave_subset(px, b);
    let width = textureDimensions(g_position).x;
    let gc = pixel_cluster[u32(px.x) + u32(px.y) * width];
    if gc == NONE {
        return vec3<f32>(0.0);
    }
    let list = geometry_clusters[gc].list;
    var first = list.x;
    var end = list.x + list.y;
    if subsets > 1u {
        first = subset_start(first, end, subsets, j);
        end = subset_start(first, end, subsets, j + 1u);
    }
    var sum = vec3<f32>(0.0);
    var last = NONE;
    for (var e = first; e < end; e++) {
        let entry = light_entries[e];
        if entry.x == last {
            continue;
        }
        let v = vpls[entry.x];
        let l = vpl_light(v, p, n, globals.g_max);
        if all(l == vec3<f32>(0.0)) {
            continue;
        }
        let g0 = entry.y & 0xffffu;
        if g0 != 0u && !crosses(v.position, p, gates[g0 - 1u]) {
            continue;
        }
        let g1 = entry.y >> 16u;
        if g1 != 0u && !crosses(v.position, p, gates[g1 - 1u]) {
            continue;
        }
        last = entry.x;
        sum += l;
    }
    return sum * f32(subsets);
}

// Portals or voxels: the VPLs of subset j (VPL mod B = j), each walked from its cluster to p
// (portals) or through the open voxels (voxels), × B; of them, batch `batch` of
// globals.walk_batch (0: all in one).
// Returns the light × B (xyz) and the subset's unshadowed light for the walks' roulette (w:
// roulette_total), which batch 0 sums and the later batches take as `total_before`.
fn portal_gather(px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, here: u32, j: u32, subsets: u32, batch: u32, total_before: f32) -> vec4<f32> {
    var first = j;
    var end = globals.vpl_count;
    if globals.walk_batch > 0u {
        first = j + batch * globals.walk_batch * subsets;
        end = min(end, first + globals.walk_batch * subsets);
    }
    var total = total_before;
    if batch == 0u {
        total = roulette_total(p, n, j, subsets);
    }
    let cut = globals.walk_roulette * total;
    let lit = walk_range(px, p, n, here, walk_end_at(px, p), first, end, subsets, cut);
    return vec4<f32>(lit * f32(subsets), total);
}

// The walks' Russian roulette (globals.walk_roulette = s > 0) at p: the unshadowed light of
// the whole of subset j (of `subsets`) there, summed over its channels; a VPL under s times
// it is walked by chance (walk_range). Summed once, in a pixel's first batch, so that the cut
// does not depend on the batching (summed in every batch, it cost e2m3's hall 1.2 s of 3.7 at
// 16,384 VPLs on lavapipe). 0 when off.
fn roulette_total(p: vec3<f32>, n: vec3<f32>, j: u32, subsets: u32) -> f32 {
    if globals.walk_roulette <= 0.0 {
        return 0.0;
    }
    var total = 0.0;
    for (var k = j; k < globals.vpl_count; k += subsets) {
        let l = vpl_light(vpls[k], p, n, globals.g_max);
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
// light / cut) and counts 1 / that probability.
fn walk_range(px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, here: u32, at_p: vec4<f32>, first: u32, end: u32, step: u32, cut: f32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    let triangles = sight_triangles();
    let planes = sight_planes();
    let h = roulette_hash(px);
    for (var k = first; k < end; k += step) {
        let v = vpls[k];
        var l = vpl_light(v, p, n, globals.g_max);
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
        if gate_shape() == GATE_VOXELS {
            let at_v = vpl_ends[k];
            // Either end where the bake knows nothing: unoccluded.
            let known = at_v.w != 0.0 && at_p.w != 0.0;
            if known && triangles
                && !sight_clear_lists(sight_true_end(v.position, v.normal), at_p.xyz) {
                continue;
            }
            if known && !triangles && !sight_clear(at_v.xyz, at_p.xyz, planes) {
                continue;
            }
        } else {
            let ca = vpl_cluster[k];
            if ca != NONE && here != NONE && ca != here
                && portal_walk(v.position, ca, p, here) != WALK_VISIBLE {
                continue;
            }
        }
        sum += l;
    }
    return sum;
}

// The first entry of [first, end) whose VPL is in subset j or later (VPL mod B >= j).
fn subset_start(first: u32, end: u32, subsets: u32, j: u32) -> u32 {
    var lo = first;
    var hi = end;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if light_entries[mid].x % subsets < j {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Interleaved clustered gates: a pixel's subset's irradiance × B alone (no albedo / π), into
// the indirect target that blur.wgsl composes, deinterleaved: the invocation at s shades the
// pixel that s holds, so that a GPU's neighbouring lanes walk the same VPLs.
//
// A compute pass, not a fullscreen draw: the same loop ran 30× slower as a fragment shader on
// an NVIDIA H200 (examples/fragment_vs_compute.rs; data-centre GPUs rasterize on a few of
// their units) and as fast on lavapipe.
//
// Walks on a software rasterizer run a pixel's VPLs in batches, a dispatch each
// (walk_batch_index.x is the batch), each adding its light to the batches' before (read from
// earlier_batches): llvmpipe ends a shader invocation's loops after 65,535 iterations in all,
// which a pixel walking hundreds of VPLs reaches, losing the light of the rest.
@group(0) @binding(24) var<uniform> walk_batch_index: vec4<u32>;
// The pass's output (every compute entry point here writes it).
@group(0) @binding(25) var out_image: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn cs_gates_indirect(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(g_position)) {
        return;
    }
    let batch = walk_batch_index.x;
    // w: the walks' roulette's total for the pixel's subset, from its first batch (the blur
    // reads xyz alone).
    var sum = vec4<f32>(0.0);
    if batch > 0u {
        sum = textureLoad(earlier_batches, vec2<i32>(id.xy), 0);
    }
    let s = interleaved_surface(vec2<f32>(id.xy) + 0.5);
    if s.position.w != 0.0 {
        let here = decode_cluster(s.position.w);
        if gate_shape() != GATE_DISKS {
            let b = max(globals.interleave_block, 1u);
            let j = interleave_subset(s.px, b);
            let g = portal_gather(s.px, s.position.xyz, s.normal, here, j, b * b, batch, sum.w);
            sum = vec4<f32>(sum.xyz + g.xyz, g.w);
        } else {
            sum = vec4<f32>(sum.xyz + clustered_gather(s.px, s.position.xyz, s.normal, here), 0.0);
        }
    }
    textureStore(out_image, id.xy, sum);
}

// Interleaved gates' second gather, the walks (starved.rs; starved.wgsl makes the pairs and
// sums them): an invocation a (pixel, subset) pair walks its subset's VPLs (in batches on a
// software rasterizer, each adding to the pair's light).
// The pairs reserved (x) and those written, which the walks take (w, from cs_starved_args).
@group(0) @binding(27) var<storage, read_write> starved_count: array<atomic<u32>, 4>;
// Two lists of the capacity each (starved.wgsl); the walks read the second, in subset order: a
// pair each, xyz its light so far (f32 bits), w its pixel × 256 + its subset.
@group(0) @binding(28) var<storage, read_write> starved_pairs: array<vec4<u32>>;

@compute @workgroup_size(STARVED_WALKS_GROUP)
fn cs_starved_walks(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * STARVED_WALKS_GROUP;
    if k >= atomicLoad(&starved_count[3]) {
        return;
    }
    let at = arrayLength(&starved_pairs) / 2u + k;
    let pair = starved_pairs[at];
    let size = textureDimensions(g_position);
    let pixel = pair.w / 256u;
    let j = pair.w % 256u;
    let px = vec2<i32>(i32(pixel % size.x), i32(pixel / size.x));
    let pos = textureLoad(g_position, px, 0);
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let bu = max(globals.interleave_block, 1u);
    let subsets = bu * bu;
    // This batch's walks of subset j: the earlier batches' skipped.
    var first = j;
    var end = globals.vpl_count;
    let wb = globals.walk_batch;
    if wb > 0u {
        first = j + walk_batch_index.x * wb * subsets;
        end = min(end, first + wb * subsets);
    }
    // The frame's walk roulette, as in the first gather: a VPL under its share of the subset's
    // unshadowed light walked by chance and weighted up (the share's total made again in each
    // of lavapipe's batches; once on a GPU, which runs one).
    let cut = globals.walk_roulette * roulette_total(pos.xyz, n, j, subsets);
    let lit = walk_range(px, pos.xyz, n, decode_cluster(pos.w), walk_end_at(px, pos.xyz), first, end, subsets, cut);
    let sum = bitcast<vec3<f32>>(pair.xyz) + lit;
    starved_pairs[at] = vec4<u32>(bitcast<vec3<u32>>(sum), pair.w);
}

// The pixel that the invocation at place `frag` of the deinterleaved target shades, and its
// G-buffer surface (w 0: none).
struct Surface {
    px: vec2<i32>,
    position: vec4<f32>,
    normal: vec3<f32>,
};

fn interleaved_surface(frag: vec2<f32>) -> Surface {
    let b = max(globals.interleave_block, 1u);
    var s: Surface;
    s.px = interleaved(vec2<i32>(frag.xy), b, textureDimensions(g_position));
    s.position = textureLoad(g_position, s.px, 0);
    s.normal = normalize(textureLoad(g_normal, s.px, 0).xyz);
    return s;
}

// Interleaved VPL clusters: as cs_gates_indirect, each pixel its subset of the VPLs.
@compute @workgroup_size(8, 8)
fn cs_vpl_clusters_indirect(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(g_position)) {
        return;
    }
    let s = interleaved_surface(vec2<f32>(id.xy) + 0.5);
    var sum = vec3<f32>(0.0);
    if s.position.w != 0.0 {
        let b = max(globals.interleave_block, 1u);
        let j = interleave_subset(s.px, b);
        sum = gather_vpl_clusters(s.position.xyz, s.normal, s.px, j, b * b);
    }
    textureStore(out_image, id.xy, vec4<f32>(sum, 1.0));
}

// SHADE_ALL: every VPL, no visibility.
fn gather_all(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < globals.vpl_count; j++) {
        sum += vpl_light(vpls[j], p, n, globals.g_max);
    }
    return sum;
}

// SHADE_GATES_PER_PIXEL: every VPL through the gate disks, brute force.
fn gather_per_pixel(p: vec3<f32>, n: vec3<f32>, here: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < globals.vpl_count; j++) {
        let v = vpls[j];
        let l = vpl_light(v, p, n, globals.g_max);
        if any(l > vec3<f32>(0.0)) && through_gates(v.position, cluster_at(v.position, v.normal), p, here) {
            sum += l;
        }
    }
    return sum;
}

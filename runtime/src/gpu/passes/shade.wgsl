//! include: globals.wgsl lights.wgsl shadow_lookup.wgsl vpl.wgsl gates.wgsl portals.wgsl sight.wgsl far.wgsl walk.wgsl near.wgsl
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
// Returns the light × B (xyz) and w: with the ratio estimator (globals.ratio) the unshadowed
// far light of the VPLs walked (walk_range's w, the blur's share's denominator), which each
// batch adds to `before` (the earlier batches'); else the subset's unshadowed light for the
// walks' roulette (roulette_total), which batch 0 sums and the later batches take as `before`.
// With the ratio the roulette's total is summed again in each batch (lavapipe's; a GPU runs
// one): where every VPL walked is visible the share is then 1, as without the roulette, where
// the subset's whole unshadowed light against the roulette's weighed walks made it noisy
// (the empty box's known answer: relative MSE 7.9e-7 instead of 7e-14).
fn portal_gather(px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, here: u32, j: u32, subsets: u32, batch: u32, before: f32) -> vec4<f32> {
    var first = j;
    var end = globals.vpl_count;
    if globals.walk_batch > 0u {
        first = j + batch * globals.walk_batch * subsets;
        end = min(end, first + globals.walk_batch * subsets);
    }
    let ratio = globals.ratio == 1u;
    var total = before;
    if batch == 0u || ratio {
        total = roulette_total(p, n, j, subsets);
    }
    let cut = globals.walk_roulette * total;
    let lit = walk_range(px, p, n, here, walk_end_at(px, p), first, end, subsets, cut);
    return vec4<f32>(lit.xyz * f32(subsets), select(total, before + lit.w, ratio));
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
    // w: portal_gather's (the walks' roulette's total for the pixel's subset, from its first
    // batch; with the ratio estimator the walked VPLs' unshadowed light, which the blur reads).
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
    let lit = walk_range(px, pos.xyz, n, decode_cluster(pos.w), walk_end_at(px, pos.xyz), first, end, subsets, cut).xyz;
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

// The near field (globals.near_scale > 0; GatesParams::near_scale): each pixel walks the VPLs
// nearer it than near_radius itself — every one, not its subset's — and adds their light
// (× albedo / π, × near_share) onto the image so far, unblurred; walk_range takes the rest of
// their light in the interleaved gathers. A VPL beside a crease lights the other face in a spot about as wide as
// its distance: interleaved, one pixel in b² takes it and the blur spreads it over the block
// (the light's own room's creases held most of the interleaving's error).
//
// Three entry points: cs_near_marks, once, a workgroup an 8 × 8 tile of pixels, marks in
// near_tiles the VPLs within the tile's largest radius of the box of its surface points (a bit
// each, NEAR_WORDS words: at most 32,768 VPLs); cs_near_field, a workgroup a tile, tests the
// marked ones in VPL order, walks those within its own radius and adds their light to
// near_sums; cs_near_compose adds near_sums (× albedo / π) onto the image so far
// (earlier_batches). cs_near_field runs in rounds (walk_batch_index.x: 0 the first, 1 a later
// one): a tile walks at most walk_batch_index.y of its marked VPLs a round (all of them but on
// a software rasterizer, whose loop limit a pixel would reach), and a tile that has more left
// puts itself on the next round's list, whose dispatch is indirect: the first round a
// dispatch over every tile, each later one over the tiles left, so that a round costs what it
// walks (rounds over every tile, a run of the VPL list each, cost e2m3's hall at 512², 1,024
// VPLs 14 dispatches and 343-413 ms where 170 walk). The marks apart, so that a round has no
// barrier (lavapipe runs a workgroup's barriers as coroutine switches).
const NEAR_WORDS: u32 = 1024u;
// The marks: each tile's ⌈VPLs / 32⌉ words, tile after tile in rows of ⌈width / 8⌉.
@group(0) @binding(34) var<storage, read_write> near_tiles: array<u32>;
// Each pixel's near light so far (xyz), in rows of the frame's width.
@group(0) @binding(35) var<storage, read_write> near_sums: array<vec4<f32>>;
// The rounds' lists of tiles (record_near rotates three): words 0-2 an indirect dispatch's
// workgroups (x, y, z), word 3 the slots used, then a slot's tile and the VPL it starts from;
// slot 0 is the round's control workgroup. This round's (near_in), the next round's, which this
// one appends to (near_out), and the one after (near_spare), which this one empties.
const NEAR_LIST_HEAD: u32 = 4u;
// The workgroups of a row of a later round's dispatch (the most a dimension may hold).
const NEAR_ROUND_ROW: u32 = 65535u;
@group(0) @binding(36) var<storage, read> near_in: array<u32>;
@group(0) @binding(37) var<storage, read_write> near_out: array<atomic<u32>>;
@group(0) @binding(38) var<storage, read_write> near_spare: array<u32>;
var<workgroup> near_lo: array<vec4<f32>, 64>;
var<workgroup> near_hi: array<vec4<f32>, 64>;
var<workgroup> near_marks: array<atomic<u32>, NEAR_WORDS>;

@compute @workgroup_size(8, 8)
fn cs_near_marks(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) tile: vec3<u32>,
) {
    let size = textureDimensions(g_position);
    let inside = all(id.xy < size);
    let pos = textureLoad(g_position, vec2<i32>(min(id.xy, size - 1u)), 0);
    // The box's corners (w: the radius), reduced over the tile.
    let point = inside && pos.w != 0.0;
    near_lo[li] = select(vec4<f32>(3.4e38, 3.4e38, 3.4e38, 0.0), vec4<f32>(pos.xyz, 0.0), point);
    near_hi[li] = select(vec4<f32>(-3.4e38, -3.4e38, -3.4e38, 0.0), vec4<f32>(pos.xyz, near_radius(pos.xyz)), point);
    let words = (globals.vpl_count + 31u) / 32u;
    for (var w = li; w < words; w += 64u) {
        atomicStore(&near_marks[w], 0u);
    }
    for (var half = 32u; half > 0u; half /= 2u) {
        workgroupBarrier();
        if li < half {
            near_lo[li] = min(near_lo[li], near_lo[li + half]);
            near_hi[li] = max(near_hi[li], near_hi[li + half]);
        }
    }
    workgroupBarrier();
    let lo = near_lo[0].xyz;
    let hi = near_hi[0];
    // A hair wider than the pixels' own test, so that rounding never drops one of theirs.
    let r2 = hi.w * hi.w * 1.01;
    for (var k = li; k < globals.vpl_count; k += 64u) {
        let v = vpls[k].position;
        let c = clamp(v, lo, hi.xyz);
        if dot(v - c, v - c) <= r2 {
            atomicOr(&near_marks[k / 32u], 1u << (k % 32u));
        }
    }
    workgroupBarrier();
    let at = (tile.x + tile.y * ((size.x + 7u) / 8u)) * words;
    for (var w = li; w < words; w += 64u) {
        near_tiles[at + w] = atomicLoad(&near_marks[w]);
    }
}

@compute @workgroup_size(8, 8)
fn cs_near_field(
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
) {
    let size = textureDimensions(g_position);
    let tiles_x = (size.x + 7u) / 8u;
    var tile = wg.x + wg.y * tiles_x;
    var first = 0u;
    if walk_batch_index.x == 0u {
        if tile == 0u && li == 0u {
            near_round_reset();
        }
    } else {
        // A later round: workgroup 0 resets the round after next's list, the others each walk
        // a tile of this round's list from where the round before stopped.
        let slot = wg.x + NEAR_ROUND_ROW * wg.y;
        if slot == 0u {
            if li == 0u {
                near_round_reset();
            }
            return;
        }
        if slot >= near_in[3] {
            return;
        }
        tile = near_in[NEAR_LIST_HEAD + 2u * slot];
        first = near_in[NEAR_LIST_HEAD + 2u * slot + 1u];
    }
    let words = (globals.vpl_count + 31u) / 32u;
    let at = tile * words;
    let run = near_run(at, first, words, walk_batch_index.y);
    if li == 0u && run.x < globals.vpl_count {
        near_round_append(tile, run.x);
    }
    let id = vec2<u32>(tile % tiles_x, tile / tiles_x) * 8u + lid.xy;
    if any(id >= size) || run.y == 0u {
        return;
    }
    let px = vec2<i32>(id);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return;
    }
    let p = pos.xyz;
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let here = decode_cluster(pos.w);
    let at_p = walk_end_at(px, p);
    let r = near_radius(p);
    var sum = vec3<f32>(0.0);
    for (var w = first / 32u; w < (run.x + 31u) / 32u; w++) {
        var bits = near_word(at, w, first);
        while bits != 0u {
            let k = w * 32u + firstTrailingBit(bits);
            bits &= bits - 1u;
            if k >= run.x {
                break;
            }
            let v = vpls[k];
            let to_v = v.position - p;
            let near = near_share(dot(to_v, to_v), r);
            if near <= 0.0 {
                continue;
            }
            let l = vpl_light(v, p, n, globals.g_max) * near;
            if any(l != vec3<f32>(0.0)) && walk_visible(k, v, p, here, at_p) {
                sum += l;
            }
        }
    }
    let i = id.x + id.y * size.x;
    near_sums[i] = vec4<f32>(near_sums[i].xyz + sum, 0.0);
}

@compute @workgroup_size(8, 8)
fn cs_near_compose(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(g_position);
    if any(id.xy >= size) {
        return;
    }
    let px = vec2<i32>(id.xy);
    let before = textureLoad(earlier_batches, px, 0);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    let sum = near_sums[id.x + id.y * size.x].xyz;
    textureStore(out_image, id.xy, vec4<f32>(before.xyz + albedo / PI * sum, before.w));
}

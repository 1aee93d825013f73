//! include: vpl.wgsl gates.wgsl
// Clustered shading with gates (section V of the visibility-gates paper, after Olsson et al.):
// the compute passes between the G-buffer and the gather.
// runtime::cpu::clustered is the CPU twin; the tests hold the two equal.
//
// Unique clusters:
//   depths        view depth per pixel and the visible range (near, far)
//   tile_count    per 16 × 16 workgroup = screen tile: the pixels' keys (exponential depth
//                 slice, visibility cluster) sorted in shared memory, the distinct keys counted
//   scan_tiles    one workgroup: each tile's first geometry cluster, the total, the dispatch
//                 size of the light assignment
//   tile_clusters the tiles again: each distinct key becomes a geometry cluster with the box of
//                 its pixels' points; each pixel gets its geometry cluster's index
// Light assignment:
//   vpl_clusters  each VPL's visibility cluster (through its normal side)
//   assign        per geometry cluster: every VPL of the same cluster (or with a cluster
//                 outside every cluster) goes on the list; for one of another cluster, each
//                 chain of at most 2 gates leading to this cluster whose first disk's cone from
//                 the VPL meets the cluster's bounding sphere adds (VPL, chain). Lists are
//                 counted first, then filled in VPL order into one pool; a list that does not
//                 fit is flagged, never cut. A list is ordered by (VPL mod B, VPL) for B
//                 interleaving subsets, so that a pixel finds its subset's run. Portals keep no
//                 lists (empty): the shading pass walks every VPL of a pixel's subset (a list
//                 would hold nearly all of them: a cull through the portals' bounds was
//                 measured to cost more than it saves).

// As runtime::gpu::layout::ClusterFrame.
struct ClusterFrame {
    eye: vec3<f32>,
    // Interleaving subsets B: a list is ordered by (VPL mod B, VPL).
    subsets: u32,
    // Unit view axis.
    forward: vec3<f32>,
    pad1: f32,
    width: u32,
    height: u32,
    // Tile side (px, 1..=WG_TILE).
    tile_px: u32,
    // 1..=256.
    depth_slices: u32,
    tiles_x: u32,
    tiles_y: u32,
    vpl_count: u32,
    // Light-entry pool capacity.
    capacity: u32,
};

// As runtime::gpu::layout::GeometryCluster.
struct GeometryCluster {
    // x tile x, y tile y, z depth slice, w visibility cluster (NONE: outside every one).
    key: vec4<u32>,
    // xyz box minimum (m).
    lo: vec4<f32>,
    // xyz box maximum (m).
    hi: vec4<f32>,
    // x first entry, y entries, z entries needed (> y only when the pool overflowed).
    list: vec4<u32>,
};

@group(0) @binding(0) var<uniform> frame: ClusterFrame;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> pixel_depth: array<f32>;
// Bits of the nearest and farthest visible depth (positive floats order as their bits).
@group(0) @binding(3) var<storage, read_write> depth_range: array<atomic<u32>, 2>;
// Distinct keys per tile; after scan_tiles each tile's first geometry cluster, then the total.
@group(0) @binding(4) var<storage, read_write> tile_clusters_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> pixel_cluster: array<u32>;
@group(0) @binding(6) var<storage, read_write> clusters: array<GeometryCluster>;
// 0 entries used (or needed), 1 lists that did not fit, 2 geometry clusters, 3 pixels and 4 VPLs
// outside every visibility cluster (their light is not occluded), 5–7 unused.
@group(0) @binding(7) var<storage, read_write> counter: array<atomic<u32>, 8>;
@group(0) @binding(8) var<uniform> grid: Grid;
@group(0) @binding(9) var<storage, read> voxel_words: array<u32>;
@group(0) @binding(10) var<storage, read> gates: array<Gate>;
// Offsets (clusters + 1) into this same array, then the gate indices.
@group(0) @binding(11) var<storage, read> cluster_gates: array<u32>;
@group(0) @binding(12) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(13) var<storage, read_write> vpl_cluster: array<u32>;
@group(0) @binding(14) var<storage, read_write> entries: array<vec2<u32>>;
// Workgroups of the light assignment: x, y (65,535 per row), 1.
@group(0) @binding(15) var<storage, read_write> dispatch: array<u32, 3>;

const EMPTY: u32 = NONE;
// A key: depth slice << CLUSTER_BITS | visibility cluster (NONE → CLUSTER_MASK, sorting last as
// on the CPU).

// ---- depths ----

var<workgroup> wg_near: atomic<u32>;
var<workgroup> wg_far: atomic<u32>;

@compute @workgroup_size(WG_TILE, WG_TILE)
fn depths(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if li == 0u {
        atomicStore(&wg_near, EMPTY);
        atomicStore(&wg_far, 0u);
    }
    workgroupBarrier();
    if id.x < frame.width && id.y < frame.height {
        let pos = textureLoad(g_position, vec2<i32>(id.xy), 0);
        var d = -1.0;
        if pos.w != 0.0 {
            if decode_cluster(pos.w) == NONE {
                atomicAdd(&counter[3], 1u);
            }
            d = max(dot(pos.xyz - frame.eye, frame.forward), 1e-6);
            atomicMin(&wg_near, bitcast<u32>(d));
            atomicMax(&wg_far, bitcast<u32>(d));
        }
        pixel_depth[id.x + id.y * frame.width] = d;
    }
    workgroupBarrier();
    if li == 0u {
        let near = atomicLoad(&wg_near);
        if near != EMPTY {
            atomicMin(&depth_range[0], near);
            atomicMax(&depth_range[1], atomicLoad(&wg_far));
        }
    }
}

// The exponential depth slice of view depth d, as runtime::cpu::clustered::assign.
fn slice_of(d: f32) -> u32 {
    let near = bitcast<f32>(atomicLoad(&depth_range[0]));
    let far = bitcast<f32>(atomicLoad(&depth_range[1]));
    var ratio = 1.0;
    if far > near {
        ratio = log(far / near);
    }
    let t = clamp(log(max(d, near) / near) / ratio, 0.0, 1.0);
    return min(u32(t * f32(frame.depth_slices)), frame.depth_slices - 1u);
}

// ---- distinct keys of a tile ----

var<workgroup> keys: array<u32, 256>;
var<workgroup> owner: array<u32, 256>;
var<workgroup> scan: array<u32, 256>;
// Each thread's (pixel's) local geometry cluster, and each local cluster's key.
var<workgroup> local_of: array<u32, 256>;
var<workgroup> local_key: array<u32, 256>;

// Sorts the tile's keys (bitonic, with their pixels), numbers the distinct ones in key order
// and returns how many there are. Call from uniform control flow.
fn sort_tile(tile: vec2<u32>, lid: vec2<u32>, li: u32) -> u32 {
    let side = frame.tile_px;
    let px = tile * side + lid;
    var key = EMPTY;
    if lid.x < side && lid.y < side && px.x < frame.width && px.y < frame.height {
        let pos = textureLoad(g_position, vec2<i32>(px), 0);
        if pos.w != 0.0 {
            let c = min(decode_cluster(pos.w), CLUSTER_MASK);
            key = (slice_of(pixel_depth[px.x + px.y * frame.width]) << CLUSTER_BITS) | c;
        }
    }
    keys[li] = key;
    owner[li] = li;
    workgroupBarrier();
    for (var k = 2u; k <= 256u; k <<= 1u) {
        for (var j = k >> 1u; j > 0u; j >>= 1u) {
            let p = li ^ j;
            if p > li {
                let a = keys[li];
                let b = keys[p];
                let up = (li & k) == 0u;
                if (up && a > b) || (!up && a < b) {
                    keys[li] = b;
                    keys[p] = a;
                    let o = owner[li];
                    owner[li] = owner[p];
                    owner[p] = o;
                }
            }
            workgroupBarrier();
        }
    }
    let mine = keys[li];
    let first = mine != EMPTY && (li == 0u || keys[li - 1u] != mine);
    scan[li] = select(0u, 1u, first);
    workgroupBarrier();
    for (var o = 1u; o < 256u; o <<= 1u) {
        var v = scan[li];
        if li >= o {
            v += scan[li - o];
        }
        workgroupBarrier();
        scan[li] = v;
        workgroupBarrier();
    }
    if mine == EMPTY {
        local_of[owner[li]] = EMPTY;
    } else {
        local_of[owner[li]] = scan[li] - 1u;
        if first {
            local_key[scan[li] - 1u] = mine;
        }
    }
    return workgroupUniformLoad(&scan[255]);
}

fn tile_index(tile: vec2<u32>) -> u32 {
    return tile.x + tile.y * frame.tiles_x;
}

@compute @workgroup_size(WG_TILE, WG_TILE)
fn tile_count(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let n = sort_tile(wg.xy, lid.xy, li);
    if li == 0u {
        tile_clusters_of[tile_index(wg.xy)] = n;
    }
}

var<workgroup> chunk_sums: array<u32, 256>;

@compute @workgroup_size(WG_WIDE)
fn scan_tiles(@builtin(local_invocation_index) li: u32) {
    let tiles = frame.tiles_x * frame.tiles_y;
    let per = (tiles + 255u) / 256u;
    let start = min(li * per, tiles);
    let end = min(start + per, tiles);
    var sum = 0u;
    for (var i = start; i < end; i++) {
        sum += tile_clusters_of[i];
    }
    chunk_sums[li] = sum;
    workgroupBarrier();
    for (var o = 1u; o < 256u; o <<= 1u) {
        var v = chunk_sums[li];
        if li >= o {
            v += chunk_sums[li - o];
        }
        workgroupBarrier();
        chunk_sums[li] = v;
        workgroupBarrier();
    }
    var run = chunk_sums[li] - sum;
    for (var i = start; i < end; i++) {
        let c = tile_clusters_of[i];
        tile_clusters_of[i] = run;
        run += c;
    }
    if li == 255u {
        let total = chunk_sums[255];
        tile_clusters_of[tiles] = total;
        atomicStore(&counter[2], total);
        dispatch[0] = min(total, 65535u);
        dispatch[1] = (total + 65534u) / 65535u;
        dispatch[2] = 1u;
    }
}

// Order-preserving bits of a float (for atomic min / max of any sign) and back.
fn ordered(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn unordered(u: u32) -> f32 {
    return bitcast<f32>(select(~u, u & 0x7fffffffu, (u & 0x80000000u) != 0u));
}

var<workgroup> boxes: array<atomic<u32>, 1536>;

@compute @workgroup_size(WG_TILE, WG_TILE)
fn tile_clusters(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let n = sort_tile(wg.xy, lid.xy, li);
    let base = tile_clusters_of[tile_index(wg.xy)];
    if li < n {
        for (var k = 0u; k < 3u; k++) {
            atomicStore(&boxes[li * 6u + k], EMPTY);
            atomicStore(&boxes[li * 6u + 3u + k], 0u);
        }
    }
    workgroupBarrier();
    let side = frame.tile_px;
    let px = wg.xy * side + lid.xy;
    let inside = lid.x < side && lid.y < side && px.x < frame.width && px.y < frame.height;
    let l = local_of[li];
    if inside {
        var gc = NONE;
        if l != EMPTY {
            gc = base + l;
            let p = textureLoad(g_position, vec2<i32>(px), 0).xyz;
            for (var k = 0u; k < 3u; k++) {
                atomicMin(&boxes[l * 6u + k], ordered(p[k]));
                atomicMax(&boxes[l * 6u + 3u + k], ordered(p[k]));
            }
        }
        pixel_cluster[px.x + px.y * frame.width] = gc;
    }
    workgroupBarrier();
    if li < n {
        let key = local_key[li];
        var c = key & CLUSTER_MASK;
        if c == CLUSTER_MASK {
            c = NONE;
        }
        var g: GeometryCluster;
        g.key = vec4<u32>(wg.x, wg.y, key >> CLUSTER_BITS, c);
        for (var k = 0u; k < 3u; k++) {
            g.lo[k] = unordered(atomicLoad(&boxes[li * 6u + k]));
            g.hi[k] = unordered(atomicLoad(&boxes[li * 6u + 3u + k]));
        }
        g.lo.w = 0.0;
        g.hi.w = 0.0;
        g.list = vec4<u32>(0u);
        clusters[base + li] = g;
    }
}

// ---- light assignment ----

@compute @workgroup_size(WG_LINEAR)
fn vpl_clusters(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < frame.vpl_count {
        let v = vpls[id.x];
        let c = cluster_at(v.position, v.normal);
        vpl_cluster[id.x] = c;
        if c == NONE {
            atomicAdd(&counter[4], 1u);
        }
    }
}

// Whether the cone from `apex` through the sphere (dc, dr) — which holds the cone through the
// disk — meets the sphere (c, r), within the slack, as runtime::cpu::clustered::cone_meets_sphere.
const CONE_SLACK: f32 = 1e-4;

fn cone_meets_sphere(apex: vec3<f32>, dc: vec3<f32>, dr: f32, c: vec3<f32>, r: f32) -> bool {
    let axis = dc - apex;
    let la = length(axis);
    let ls = length(c - apex);
    if la <= dr || ls <= r || la <= 0.0 {
        return true;
    }
    let half = asin(clamp(dr / la, 0.0, 1.0));
    let spread = asin(clamp(r / ls, 0.0, 1.0));
    let angle = acos(clamp(dot(axis / la, (c - apex) / ls), -1.0, 1.0));
    return angle - (half + spread) <= CONE_SLACK;
}

// The entries of VPL j for a geometry cluster of visibility cluster cb and sphere (s, r);
// written from `at` when `write`. Returns how many.
fn vpl_entries(j: u32, cb: u32, s: vec3<f32>, r: f32, write: bool, at: u32) -> u32 {
    let ca = vpl_cluster[j];
    if ca == NONE || cb == NONE || ca == cb {
        if write {
            entries[at] = vec2<u32>(j, 0u);
        }
        return 1u;
    }
    let a = vpls[j].position;
    var n = 0u;
    for (var i = cluster_gates[ca]; i < cluster_gates[ca + 1u]; i++) {
        let gi = cluster_gates[i];
        let g = gates[gi];
        let c1 = other_side(g, ca);
        if c1 == ca || (c1 != cb && grid.max_hops < 2u) {
            continue;
        }
        if !cone_meets_sphere(a, g.centre, g.radius * grid.oversize, s, r) {
            continue;
        }
        if c1 == cb {
            if write {
                entries[at + n] = vec2<u32>(j, gi + 1u);
            }
            n++;
            continue;
        }
        for (var k = cluster_gates[c1]; k < cluster_gates[c1 + 1u]; k++) {
            let hk = cluster_gates[k];
            if other_side(gates[hk], c1) == cb {
                if write {
                    entries[at + n] = vec2<u32>(j, (gi + 1u) | ((hk + 1u) << 16u));
                }
                n++;
            }
        }
    }
    return n;
}

var<workgroup> wg_count: u32;
var<workgroup> wg_total: atomic<u32>;
var<workgroup> wg_base: u32;
var<workgroup> part: array<u32, 64>;

@compute @workgroup_size(WG_LINEAR)
fn assign(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if li == 0u {
        wg_count = atomicLoad(&counter[2]);
        atomicStore(&wg_total, 0u);
    }
    let count = workgroupUniformLoad(&wg_count);
    let cid = wg.x + wg.y * 65535u;
    if cid >= count {
        return;
    }
    let gc = clusters[cid];
    let s = (gc.lo.xyz + gc.hi.xyz) * 0.5;
    let r = length(gc.hi.xyz - s);
    let cb = gc.key.w;
    let vpl_count = frame.vpl_count;
    // Count.
    var mine = 0u;
    for (var j = li; j < vpl_count; j += 64u) {
        mine += vpl_entries(j, cb, s, r, false, 0u);
    }
    atomicAdd(&wg_total, mine);
    workgroupBarrier();
    if li == 0u {
        let total = atomicLoad(&wg_total);
        let base = atomicAdd(&counter[0], total);
        let fits = base <= frame.capacity && total <= frame.capacity - base;
        clusters[cid].list = vec4<u32>(base, select(0u, total, fits), total, 0u);
        if !fits {
            atomicAdd(&counter[1], 1u);
        }
        wg_base = select(NONE, base, fits);
    }
    let base = workgroupUniformLoad(&wg_base);
    if base == NONE {
        return;
    }
    // Fill in the order (VPL mod B, VPL), 64 places at a time: place m is VPL
    // (m mod per)·B + m / per, per = ⌈VPLs / B⌉ (the list of a subset is one run).
    var run = 0u;
    let subsets = max(frame.subsets, 1u);
    let per = (vpl_count + subsets - 1u) / subsets;
    let chunks = (per * subsets + 63u) / 64u;
    for (var c = 0u; c < chunks; c++) {
        let m = c * 64u + li;
        let j = (m % per) * subsets + m / per;
        var k = 0u;
        if j < vpl_count && m < per * subsets {
            k = vpl_entries(j, cb, s, r, false, 0u);
        }
        part[li] = k;
        workgroupBarrier();
        for (var o = 1u; o < 64u; o <<= 1u) {
            var v = part[li];
            if li >= o {
                v += part[li - o];
            }
            workgroupBarrier();
            part[li] = v;
            workgroupBarrier();
        }
        if k > 0u {
            vpl_entries(j, cb, s, r, true, base + run + part[li] - k);
        }
        run += part[63];
        workgroupBarrier();
    }
}

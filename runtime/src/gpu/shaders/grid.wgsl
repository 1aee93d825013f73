//! include: face.wgsl
// The level's voxel→cluster grid and the visibility cluster of a surface point;
// runtime::cpu::gates::GateLevel::cluster_at is its CPU twin. Its functions read two bindings
// that the including pass declares: `grid: Grid` (uniform) and `voxel_words: array<u32>`
// (storage, read).

// As runtime::gpu::layout::Grid.
struct Grid {
    origin: vec3<f32>,
    voxel_size: f32,
    // Voxels per axis (0: no level).
    dims: vec3<u32>,
    // Bytes per stored value (1, 2 or 4).
    value_bytes: u32,
    // Gate disks are this many times their baked radius.
    oversize: f32,
    // Gates a VPL's light may pass (1 or 2).
    max_hops: u32,
    // GATE_DISKS, GATE_PORTALS (walked) or GATE_VOXELS (the voxel walk).
    shape: u32,
    // Portals a walk may pass before it is given up.
    max_walk: u32,
    // The voxel walk: 1 along the true segment with the closed voxels' triangles, 0 between
    // ends off the surfaces.
    triangles: u32,
    // The walk between ends off the surfaces: 1 passing a closed voxel where the segment meets
    // neither of its planes (runtime::cpu::sight_planes), 0 blocking at every closed voxel.
    planes: u32,
    pad1: u32,
    pad2: u32,
};

// Grid.shape's values (runtime::cpu::gates::GateShape).
const GATE_DISKS: u32 = 0u;
const GATE_PORTALS: u32 = 1u;
const GATE_VOXELS: u32 = 2u;

fn cluster_of(p: vec3<f32>) -> u32 {
    let v = (p - grid.origin) / grid.voxel_size;
    if any(v < vec3<f32>(0.0)) || any(v >= vec3<f32>(grid.dims)) {
        return NONE;
    }
    let c = vec3<u32>(v);
    let i = c.x + grid.dims.x * (c.y + grid.dims.y * c.z);
    let bytes = grid.value_bytes;
    if bytes == 4u {
        return voxel_words[i];
    }
    if bytes == 2u {
        let x = (voxel_words[i / 2u] >> ((i % 2u) * 16u)) & 0xffffu;
        return select(x, NONE, x == 0xffffu);
    }
    let x = (voxel_words[i / 4u] >> ((i % 4u) * 8u)) & 0xffu;
    return select(x, NONE, x == 0xffu);
}

// The cluster of the empty voxel a surface point faces: 0.5, 1.5 and 2.5 voxels along its
// normal; in a corner, the nearest voxel with a cluster to the point one voxel out among the
// 27 around it in front of the surface; then the point itself (GateLevel::cluster_at).
fn cluster_at(p: vec3<f32>, n: vec3<f32>) -> u32 {
    let vs = grid.voxel_size;
    var c = cluster_of(p + n * (0.5 * vs));
    if c == NONE {
        c = cluster_of(p + n * (1.5 * vs));
    }
    if c == NONE {
        c = cluster_of(p + n * (2.5 * vs));
    }
    if c == NONE {
        let q = p + n * vs;
        let base = floor((q - grid.origin) / vs);
        var best = 3.4e38;
        for (var dz = -1; dz <= 1; dz++) {
            for (var dy = -1; dy <= 1; dy++) {
                for (var dx = -1; dx <= 1; dx++) {
                    let v = base + vec3<f32>(f32(dx), f32(dy), f32(dz));
                    let centre = grid.origin + (v + 0.5) * vs;
                    let k = cluster_of(centre);
                    let d2 = dot(centre - q, centre - q);
                    if k != NONE && dot(centre - p, n) > 0.0 && d2 < best {
                        best = d2;
                        c = k;
                    }
                }
            }
        }
    }
    if c == NONE {
        c = cluster_of(p);
    }
    return c;
}

// The G-buffer keeps a surface's cluster in position.w: 0 no surface, 1 outside every
// cluster, 2 + c cluster c (exact in f32 below 2^24).
fn encode_cluster(c: u32) -> f32 {
    return f32(c + 1u) + 1.0;
}

fn decode_cluster(w: f32) -> u32 {
    return u32(w - 1.0) - 1u;
}

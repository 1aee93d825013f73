// The level's voxel→cluster grid and the visibility cluster of a surface point. Prepended to
// the shaders that need it (WGSL has no includes); runtime::gates::GateLevel::cluster_at is its
// CPU twin.

const NONE: u32 = 0xffffffffu;

struct Grid {
    // xyz origin (m), w voxel size (m).
    origin: vec4<f32>,
    // xyz dims, w bytes per stored value (1, 2 or 4; dims 0: no level).
    dims: vec4<u32>,
    // x disk oversize factor, y max hops (1 or 2), z, w unused.
    params: vec4<f32>,
};

@group(0) @binding(8) var<uniform> grid: Grid;
@group(0) @binding(9) var<storage, read> voxel_words: array<u32>;

fn cluster_of(p: vec3<f32>) -> u32 {
    let v = (p - grid.origin.xyz) / grid.origin.w;
    if any(v < vec3<f32>(0.0)) || any(v >= vec3<f32>(grid.dims.xyz)) {
        return NONE;
    }
    let c = vec3<u32>(v);
    let i = c.x + grid.dims.x * (c.y + grid.dims.y * c.z);
    let bytes = grid.dims.w;
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

// The cluster of the empty space a surface point faces: half a voxel, then 1.5 voxels along
// its normal, then the point itself.
fn cluster_at(p: vec3<f32>, n: vec3<f32>) -> u32 {
    let vs = grid.origin.w;
    var c = cluster_of(p + n * (0.5 * vs));
    if c == NONE {
        c = cluster_of(p + n * (1.5 * vs));
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

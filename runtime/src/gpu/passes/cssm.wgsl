// Convolution soft shadow maps (Annen et al.; Dong et al. §4.1–4.2) from the VALs' paraboloid
// distance maps: per VAL the farthest surface its map sees (its depth range), then the
// Fourier basis images of the normalised depth z — sin(c_k z), cos(c_k z) for k = 1..K, the
// same times z, and z — in one mip-mapped RGBA16F array (layer g·M + k for group g of VAL k),
// mip-mapped by 2 × 2 averages. runtime::cpu::cssm holds the expansion's CPU side.
//   ranges     per VAL: the largest finite distance in its map
//   basis      level 0 of every group
//   downsample level l from level l − 1, every layer at once

// Distance maps are cleared to 1e30 where no surface is.
const NO_SURFACE: f32 = 1e29;

// As runtime::gpu::layout::CssmFrame.
struct CssmFrame {
    val_count: u32,
    // Fourier terms K.
    terms: u32,
    // Basis groups G = ⌈K/2⌉.
    groups: u32,
    map_size: u32,
    // Side of the mip level being written (texels).
    level_size: u32,
    pad0: u32,
    pad1: vec2<u32>,
};

@group(0) @binding(0) var<uniform> cssm: CssmFrame;
@group(0) @binding(1) var maps: texture_2d_array<f32>;
@group(0) @binding(2) var<storage, read_write> ranges: array<f32>;
@group(0) @binding(3) var basis_out: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(4) var basis_in: texture_2d_array<f32>;

var<workgroup> wg_max: array<f32, WG_WIDE>;

@compute @workgroup_size(WG_WIDE)
fn ranges_of(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let k = wg.x;
    let size = cssm.map_size;
    var m = 0.0;
    for (var i = li; i < size * size; i += WG_WIDE) {
        let d = textureLoad(maps, vec2<u32>(i % size, i / size), k, 0).x;
        if d < NO_SURFACE {
            m = max(m, d);
        }
    }
    wg_max[li] = m;
    workgroupBarrier();
    for (var o = WG_WIDE / 2u; o > 0u; o >>= 1u) {
        if li < o {
            wg_max[li] = max(wg_max[li], wg_max[li + o]);
        }
        workgroupBarrier();
    }
    if li == 0u {
        ranges[k] = max(wg_max[0], 1e-30);
    }
}

@compute @workgroup_size(WG_CSSM, WG_CSSM, 1)
fn basis(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = cssm.map_size;
    if id.x >= size || id.y >= size {
        return;
    }
    let m = cssm.val_count;
    let k = id.z;
    let d = textureLoad(maps, id.xy, k, 0).x;
    // Depth in [0, CSSM_DEPTH_SCALE], empty texels at CSSM_EMPTY_DEPTH: a guard band.
    let z = select(CSSM_EMPTY_DEPTH, clamp(d / ranges[k], 0.0, 1.0) * CSSM_DEPTH_SCALE, d < NO_SURFACE);
    let groups = cssm.groups;
    for (var g = 0u; g < groups; g++) {
        let c1 = PI * f32(4u * g + 1u);
        let c2 = PI * f32(4u * g + 3u);
        var b = vec4<f32>(sin(c1 * z), cos(c1 * z), sin(c2 * z), cos(c2 * z));
        if 2u * g + 2u > cssm.terms {
            b = vec4<f32>(b.xy, 0.0, 0.0);
        }
        textureStore(basis_out, id.xy, g * m + k, b);
        textureStore(basis_out, id.xy, (groups + g) * m + k, z * b);
    }
    textureStore(basis_out, id.xy, 2u * groups * m + k, vec4<f32>(z, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(WG_CSSM, WG_CSSM, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = cssm.level_size;
    if id.x >= size || id.y >= size {
        return;
    }
    let l = id.z;
    let s = 2u * id.xy;
    let a = textureLoad(basis_in, s, l, 0) + textureLoad(basis_in, s + vec2<u32>(1u, 0u), l, 0)
        + textureLoad(basis_in, s + vec2<u32>(0u, 1u), l, 0)
        + textureLoad(basis_in, s + vec2<u32>(1u, 1u), l, 0);
    textureStore(basis_out, id.xy, l, 0.25 * a);
}

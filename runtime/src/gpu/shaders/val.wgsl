// A virtual area light, as runtime::cpu::val::Val (64 bytes), and the tangent frame of a normal, as
// runtime::vpl::basis (Duff et al. 2017), the texel of a paraboloid map, and the constants of
// the VAL gather and its blur.
struct Val {
    // xyz centre (m), w VPL count.
    position: vec4<f32>,
    // xyz unit normal, w area (m²).
    normal: vec4<f32>,
    // rgb flux (W).
    flux: vec4<f32>,
    // s min, s max, t min, t max about the centre, in the frame of basis(normal).
    rect: vec4<f32>,
};

fn basis(n: vec3<f32>) -> mat2x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        vec3<f32>(b, s + n.y * n.y * a, -n.y),
    );
}

// The texel of paraboloid map (side `size`) that direction `local` (in the map's frame,
// z along its normal, z > 0) falls in.
fn paraboloid_texel(local: vec3<f32>, size: f32) -> vec2<i32> {
    let dir = local / length(local);
    let uv = dir.xy / (1.0 + dir.z);
    return vec2<i32>(vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5) * size);
}

// As runtime::gpu::layout::ValGather.
struct ValGather {
    vpl_count: u32,
    val_count: u32,
    // VAL map side (texels).
    map_size: u32,
    // Fourier terms K (val-cssm).
    terms: u32,
    // 1/m².
    g_max: f32,
    // Hard lookups: normal offset and bias (texels).
    normal_offset: f32,
    bias: f32,
    // VAL centre offset along its normal (m).
    centre_offset: f32,
    // val-cssm: receiver offset (normalised depth), sharpening s, normal offset (texels).
    receiver_offset: f32,
    sharpness: f32,
    cssm_normal_offset: f32,
    // 1: the blur weights its taps by a tent over (2b − 1)² pixels, 0: the box of b × b.
    blur_tent: u32,
    // Interleaving block side b (1: none) and subsets B = b².
    block: u32,
    subsets: u32,
    // Layout of the interleaved indirect target: 0 pixel order, 1 deinterleaved.
    deinterleaved: u32,
    // Blur: 1 where a tap that does not agree gives way to its subset's nearest copy a block
    // away that does (blur.wgsl), 0 where it is left out.
    blur_fill: u32,
    // Blur thresholds: distance (m) and normal cosine.
    blur_distance: f32,
    blur_normal: f32,
    // Interleaved walks, the ratio estimator: 1 where the blur scales the pixel's unshadowed
    // far light by its taps' visible share, 0 where it averages their light.
    ratio: u32,
    // Its grid stride (px; 1: every pixel).
    ratio_stride: u32,
};

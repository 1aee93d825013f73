// Per-frame constants of the G-buffer and shading passes, as runtime::gpu::layout::Globals.
struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // Geometry-term clamp g_max (1/m²).
    g_max: f32,
    // Shadow lookups: normal offset and bias, in texels.
    shadow_normal_offset: f32,
    shadow_bias: f32,
    // Interleaving block of clustered gates (<= 1: none).
    interleave_block: u32,
    vpl_count: u32,
    light_count: u32,
    // SHADE_ALL, SHADE_DIRECT, SHADE_GATES_PER_PIXEL or SHADE_GATES_CLUSTERED.
    shade_mode: u32,
    // Shadow map layer side (texels).
    shadow_size: u32,
    // DIRECT_PER_LIGHT or DIRECT_LIGHTCLUSTER.
    direct_mode: u32,
    // Portals: VPLs of a pixel's subset walked a draw (0: all in one draw).
    walk_batch: u32,
    // Portals and voxels: Russian roulette on the walks, a share of a pixel's light (0: off).
    walk_roulette: f32,
    walk_seed: u32,
    // Interleaved walks: the VPLs nearer a pixel than this times its distance from the eye are
    // walked at the pixel itself (shade.wgsl's cs_near_field), not in its subset (0: none).
    near_scale: f32,
    // Interleaved walks, the ratio estimator: 1 where the blur scales each pixel's unshadowed far
    // light by its taps' visible share (blur.wgsl's compose), 0 where it averages their light.
    ratio: u32,
    // The ratio estimator's grid: the unshadowed far light summed at every this many pixels
    // across and down (1: every pixel; ratio.wgsl).
    ratio_stride: u32,
    pad2: u32,
};

// A virtual area light, as runtime::val::Val (64 bytes), and the tangent frame of a normal, as
// runtime::vpl::basis (Duff et al. 2017). Put in front of the shaders that use them.
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

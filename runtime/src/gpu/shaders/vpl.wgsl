// A virtual point light, as runtime::vpl::Vpl (48 bytes), and the gather term every indirect
// pass shares.

struct Vpl {
    position: vec3<f32>,
    pad0: f32,
    normal: vec3<f32>,
    pad1: f32,
    flux: vec3<f32>,
    pad2: f32,
};


// Interleaved sampling: the VPL subset of pixel px in blocks of side b (VPL i lights the
// pixels of subset i mod b²; blur.wgsl blurs over the block).
fn interleave_subset(px: vec2<i32>, b: u32) -> u32 {
    return u32(px.x) % b + b * (u32(px.y) % b);
}

// The light of VPL v at p (normal n) without albedo / π, as runtime::vpl::gather_one:
// Φ/π · min(cos θ_v cos θ_x / d², g_max); zero behind either surface.
fn vpl_light(v: Vpl, p: vec3<f32>, n: vec3<f32>, g_max: f32) -> vec3<f32> {
    let d = v.position - p;
    let d2 = dot(d, d);
    if d2 <= 0.0 {
        return vec3<f32>(0.0);
    }
    let w = d * inverseSqrt(d2);
    let cos_x = dot(n, w);
    let cos_v = -dot(v.normal, w);
    if cos_x <= 0.0 || cos_v <= 0.0 {
        return vec3<f32>(0.0);
    }
    return v.flux / PI * min(cos_x * cos_v / d2, g_max);
}

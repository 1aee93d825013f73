//! include: vpl.wgsl
// VPLs from reflective shadow maps (Dong et al. §6): the RSM of each light (its G-buffer from
// the light: position, normal turned to the light, albedo; cube faces for point lights) is
// fetched at N Halton-distributed texels, point sampled. The CPU computes each sample's texel
// and power (intensity towards it × the solid angle its share of the map covers); a sample that
// finds no surface gives a VPL of zero flux, so N stays N.

// As runtime::gpu::layout::RsmSample.
struct RsmSample {
    // x layer, y texel x, z texel y, w unused.
    texel: vec4<u32>,
    // rgb power (W), w unused.
    power: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> samples: array<RsmSample>;
@group(0) @binding(1) var<storage, read_write> vpls: array<Vpl>;
@group(0) @binding(2) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(4) var rsm_albedo: texture_2d_array<f32>;

@compute @workgroup_size(WG_LINEAR)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&samples) {
        return;
    }
    let s = samples[i];
    let t = vec2<i32>(s.texel.yz);
    let layer = i32(s.texel.x);
    let p = textureLoad(rsm_position, t, layer, 0);
    var v: Vpl;
    v.position = p.xyz;
    if p.w > 0.0 {
        v.normal = normalize(textureLoad(rsm_normal, t, layer, 0).xyz);
        v.flux = textureLoad(rsm_albedo, t, layer, 0).xyz * s.power.xyz;
    } else {
        v.normal = vec3<f32>(0.0, 1.0, 0.0);
        v.flux = vec3<f32>(0.0);
    }
    v.pad0 = 0.0;
    v.pad1 = 0.0;
    v.pad2 = 0.0;
    vpls[i] = v;
}

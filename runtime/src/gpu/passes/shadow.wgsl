// Shadow maps: each layer of a 2D array holds, per texel, the distance from its light to the
// nearest surface (cube faces for point lights, one layer per spot). R32Float, cleared to a
// large value.

struct ShadowView {
    view_proj: mat4x4<f32>,
    light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> shadow_view: ShadowView;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

@vertex
fn vs(@location(0) position: vec3<f32>) -> VsOut {
    var o: VsOut;
    // The matrix takes the point relative to the light (ShadowView::view_proj).
    o.clip = shadow_view.view_proj * vec4<f32>(position - shadow_view.light.xyz, 1.0);
    o.world = position;
    return o;
}

@fragment
fn fs(i: VsOut) -> @location(0) f32 {
    return length(i.world - shadow_view.light.xyz);
}

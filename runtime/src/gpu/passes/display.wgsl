// The frame for a screen: the linear HDR image times 2^exposure, clamped to [0, 1] and
// sRGB-encoded into an rgba8unorm texture (egui's native textures hold sRGB-encoded values in
// Rgba8Unorm). The same arithmetic as `HdrImage::to_srgb8` on the CPU.

struct Display {
    scale: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

@group(0) @binding(0) var<uniform> u: Display;
@group(0) @binding(1) var hdr: texture_2d<f32>;
@group(0) @binding(2) var out: texture_storage_2d<rgba8unorm, write>;

// hdr.rs `srgb_encode`: non-finite to 0, clamped, the sRGB curve.
fn encode(v: f32) -> f32 {
    var x = v;
    if !(x == x) || abs(x) > 3.0e38 {
        x = 0.0;
    }
    x = clamp(x, 0.0, 1.0);
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(8, 8)
fn cs_display(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(out);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let c = textureLoad(hdr, vec2<i32>(id.xy), 0).rgb * u.scale;
    textureStore(out, vec2<i32>(id.xy), vec4<f32>(encode(c.r), encode(c.g), encode(c.b), 1.0));
}

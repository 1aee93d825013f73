//! include: val.wgsl vpl.wgsl fullscreen.wgsl
// Interleaving's other half: the interleaved indirect irradiance (val_gather.wgsl) blurred over
// the b × b block where the geometry agrees (Laine et al.: positions closer than a fraction of
// the scene, normals closer than a cosine), times albedo / π, added onto the image so far
// (`previous`: ping-pong, 32-bit float targets are not blendable everywhere).

@group(0) @binding(0) var<uniform> gather: ValGather;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_albedo: texture_2d<f32>;
@group(0) @binding(6) var previous: texture_2d<f32>;
@group(0) @binding(12) var indirect: texture_2d<f32>;

@fragment
fn fs_compose(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(frag.xy);
    let before = textureLoad(previous, px, 0);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return before;
    }
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    let b = i32(gather.block);
    let size = vec2<i32>(textureDimensions(indirect));
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    for (var dy = -b / 2; dy < b - b / 2; dy++) {
        for (var dx = -b / 2; dx < b - b / 2; dx++) {
            let q = px + vec2<i32>(dx, dy);
            if any(q < vec2<i32>(0)) || any(q >= size) {
                continue;
            }
            let qp = textureLoad(g_position, q, 0);
            if qp.w == 0.0 {
                continue;
            }
            let qn = normalize(textureLoad(g_normal, q, 0).xyz);
            if length(qp.xyz - pos.xyz) > gather.blur_distance || dot(qn, n) < gather.blur_normal {
                continue;
            }
            let at = select(q, deinterleaved(q, gather.block, vec2<u32>(size)), gather.deinterleaved == 1u);
            sum += textureLoad(indirect, at, 0).xyz;
            weight += 1.0;
        }
    }
    return vec4<f32>(before.xyz + albedo / PI * sum / max(weight, 1.0), 1.0);
}

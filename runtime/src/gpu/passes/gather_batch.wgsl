//! include: vpl.wgsl val.wgsl
// Indirect light of one batch of VPLs with their paraboloid shadow maps (mode
// per-vpl-shadow-maps), added to the image so far (`previous`, ping-pong: 32-bit float targets
// are not blendable everywhere). The gather term is vpl.wgsl's vpl_light.

// As runtime::gpu::layout::Batch.
struct Batch {
    first: u32,
    count: u32,
    // Map side (texels).
    map_size: u32,
    pad0: u32,
    // 1/m².
    g_max: f32,
    // Texels.
    normal_offset: f32,
    bias: f32,
    pad1: f32,
};

@group(0) @binding(0) var<uniform> batch: Batch;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var maps: texture_2d_array<f32>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_albedo: texture_2d<f32>;
@group(0) @binding(6) var previous: texture_2d<f32>;
// The image with this batch (a compute pass, as shade.wgsl's cs_gates_indirect says why).
@group(0) @binding(7) var out_image: texture_storage_2d<rgba32float, write>;

fn visibility(layer: u32, v: Vpl, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = f32(batch.map_size);
    let tb = basis(v.normal);
    let dist = length(p - v.position);
    // A texel spans about 4/size rad at the map's centre.
    let texel = dist * 4.0 / size;
    let q = p + n * texel * batch.normal_offset - v.position;
    let local = vec3<f32>(dot(q, tb[0]), dot(q, tb[1]), dot(q, v.normal));
    let d = length(local);
    if local.z <= 0.0 || d <= 0.0 {
        return 0.0;
    }
    let c = paraboloid_texel(local, size);
    let ref_dist = d - texel * batch.bias;
    var lit = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let t = clamp(c + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(i32(size) - 1));
            lit += select(0.0, 1.0, textureLoad(maps, t, i32(layer), 0).x >= ref_dist);
        }
    }
    return lit / 9.0;
}

@compute @workgroup_size(8, 8)
fn cs(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(previous)) {
        textureStore(out_image, id.xy, gather_batch(vec2<i32>(id.xy)));
    }
}

fn gather_batch(px: vec2<i32>) -> vec4<f32> {
    let before = textureLoad(previous, px, 0);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return before;
    }
    let p = pos.xyz;
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    var radiance = vec3<f32>(0.0);
    for (var k = 0u; k < batch.count; k++) {
        let v = vpls[batch.first + k];
        let l = vpl_light(v, p, n, batch.g_max);
        if any(l > vec3<f32>(0.0)) {
            radiance += albedo / PI * l * visibility(k, v, p, n);
        }
    }
    return vec4<f32>(before.xyz + radiance, 1.0);
}

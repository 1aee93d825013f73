//! include: globals.wgsl grid.wgsl
// G-buffer pass: world position (w: the visibility cluster it faces, 0 where
// no surface is, see encode_cluster), shading normal on the side of the face that the camera
// sees (surfaces are two-sided), linear albedo (material × texture, the texture an sRGB layer
// of one array, sampled nearest with repeat as the CPU reference does); the face's normal in
// normal.w and albedo.w (encode_face_normal). Depth test less.

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var albedo_maps: texture_2d_array<f32>;
@group(0) @binding(2) var albedo_sampler: sampler;
@group(0) @binding(8) var<uniform> grid: Grid;
@group(0) @binding(9) var<storage, read> voxel_words: array<u32>;

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    // xy texture coordinates, z texture layer (< 0: none).
    @location(3) uv_layer: vec3<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) uv_layer: vec3<f32>,
};

@vertex
fn vs(v: VsIn) -> VsOut {
    var o: VsOut;
    o.clip = globals.view_proj * vec4<f32>(v.position, 1.0);
    o.world = v.position;
    o.normal = v.normal;
    o.albedo = v.albedo;
    o.uv_layer = v.uv_layer;
    return o;
}

struct GOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
};

@fragment
fn fs(i: VsOut) -> GOut {
    // Two-sided, as the CPU tracer: the triangle's own normal turned towards the camera, the
    // shading normal turned to its side. (Turning the shading normal itself to the camera
    // disagrees where a mesh's normals lean far from its faces — Crytek Sponza's arches, up to
    // 90° —, and those pixels took their light from the other hemisphere.) The face's normal
    // comes from the position's screen derivatives, which a 2 × 2 quad takes from one triangle.
    let to_eye = globals.eye.xyz - i.world;
    var ng = cross(dpdx(i.world), dpdy(i.world));
    if dot(ng, ng) <= 0.0 {
        ng = to_eye;
    }
    if dot(ng, to_eye) < 0.0 {
        ng = -ng;
    }
    var n = normalize(i.normal);
    if dot(n, ng) < 0.0 {
        n = -n;
    }
    var o: GOut;
    o.position = vec4<f32>(i.world, encode_cluster(cluster_at(i.world, n)));
    let face = encode_face_normal(normalize(ng));
    o.normal = vec4<f32>(n, face.x);
    var albedo = i.albedo;
    if i.uv_layer.z >= 0.0 {
        let layer = i32(i.uv_layer.z + 0.5);
        albedo *= textureSampleLevel(albedo_maps, albedo_sampler, i.uv_layer.xy, layer, 0.0).xyz;
    }
    o.albedo = vec4<f32>(albedo, face.y);
    return o;
}

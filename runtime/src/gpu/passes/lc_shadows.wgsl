//! include: lights.wgsl lc.wgsl pcss.wgsl
// LightCluster's shadows: each cluster's cube shadow map as 6 tiles of one depth atlas (a
// depth-only draw per tile), then each cluster's PCSS visibility at every pixel (see light_cluster.wgsl
// for the whole method). Read-only: the clustering passes wrote what is bound here.

@group(0) @binding(0) var<uniform> frame: LcFrame;
// Each cluster's centre (xyz) and disk radius (w).
@group(0) @binding(1) var<storage, read> clusters: array<vec4<f32>>;
// Each cluster's reach (m, as f32 bits).
@group(0) @binding(2) var<storage, read> reach: array<u32>;
// light_cluster.wgsl's args: word 3 the clusters.
@group(0) @binding(3) var<storage, read> args: array<u32>;
@group(0) @binding(4) var atlas: texture_depth_2d;
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_normal: texture_2d<f32>;
// Four clusters a texel: cluster k in layer k / 4, channel k % 4.
@group(0) @binding(7) var visibility: texture_storage_2d_array<rgba8unorm, write>;
// Each cluster's extent (m, as f32 bits).
@group(0) @binding(8) var<storage, read> extent: array<u32>;
// The lights (VPLs: their normals) and each cluster's centre light.
@group(0) @binding(9) var<storage, read> lights: array<Light>;
@group(0) @binding(10) var<storage, read> centres: array<u32>;

// Tile `tile` (cluster tile / 6, face tile % 6) of the atlas, drawn into its own viewport:
// reversed depth without a far plane, near / (distance along the face's axis).
@vertex
fn vs_atlas(@location(0) position: vec3<f32>, @location(1) tile: u32) -> @builtin(position) vec4<f32> {
    let v = face_view(tile % 6u, position - clusters[tile / 6u].xyz);
    return vec4<f32>(v.x, v.y, frame.near_m, v.z);
}

// Distance from cluster k's centre to the nearest surface along direction `dir` (its texel's
// depth along the face's axis, over dir's cosine to that axis); "very far" where none.
fn stored_distance(k: u32, dir: vec3<f32>) -> f32 {
    let f = face_of(dir);
    let v = face_view(f, dir);
    let depth = textureLoad(atlas, atlas_texel(6u * k + f, v.xy / v.z), 0);
    if depth <= 0.0 {
        return 3.4e38;
    }
    return frame.near_m / depth * length(dir) / v.z;
}

// Cluster k's visibility at p (normal n): PCSS (Fernando 2005) with the cluster as a disk of
// its radius at its centre — the blocker search over the cone from p to the disk (see
// `nearest`; at most 45° off), the penumbra width from the blockers' mean distance, PCF over
// it. Radius 0: one hard lookup.
fn pcss(k: u32, p: vec3<f32>, n: vec3<f32>, px: vec2<u32>) -> f32 {
    let c = clusters[k];
    let dist = length(p - c.xyz);
    if dist <= 1e-6 || dist > bitcast<f32>(reach[k]) {
        return 1.0;
    }
    // Every light of the cluster lies within its extent of the centre: below p's plane by
    // more than that, none lights p (any visibility will do).
    if dot(n, c.xyz - p) < -bitcast<f32>(extent[k]) {
        return 1.0;
    }
    let size = f32(frame.map_size);
    // A cube texel's footprint at distance d is at most 2·d / size.
    let q = p + n * (2.0 * dist / size) * frame.normal_offset;
    let cone = pcss_cone(q - c.xyz, px);
    let dr = cone.dr;
    let bias = 2.0 / size * frame.bias;
    let radius = select(c.w, bitcast<f32>(extent[k]), frame.disk_extent == 1u);
    // VPLs light their front: directions behind the centre's surface carry no light.
    var axis = vec3<f32>(0.0);
    if frame.hemisphere == 1u {
        axis = lights[centres[k]].direction.xyz;
    }
    if radius <= 0.0 {
        return select(0.0, 1.0, stored_distance(k, cone.w0) >= dr * (1.0 - bias));
    }
    let search = pcss_search(radius, dr);
    var sum = 0.0;
    var found = 0.0;
    for (var i = 0u; i < frame.blocker_samples; i++) {
        let s = pcss_sample(cone, i, frame.blocker_samples, true, search);
        if dot(s.w, axis) < 0.0 {
            continue;
        }
        let z = stored_distance(k, s.w);
        let zr = plane_distance(c.xyz, s.w, q, n, dr);
        if z < zr * (1.0 - bias) && in_cone(s.o, z, radius, dr) {
            sum += z;
            found += 1.0;
        }
    }
    if found == 0.0 {
        return 1.0;
    }
    let width = pcss_penumbra(radius, dr, max(sum / found, 1e-4));
    var lit = 0.0;
    var taken = 0.0;
    for (var i = 0u; i < frame.filter_samples; i++) {
        let s = pcss_sample(cone, i, frame.filter_samples, false, width);
        if dot(s.w, axis) < 0.0 {
            continue;
        }
        let zr = plane_distance(c.xyz, s.w, q, n, dr);
        lit += select(0.0, 1.0, stored_distance(k, s.w) >= zr * (1.0 - bias));
        taken += 1.0;
    }
    return select(1.0, lit / taken, taken > 0.0);
}

@compute @workgroup_size(8, 8)
fn pcss_pass(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.width || id.y >= frame.height {
        return;
    }
    let px = vec2<i32>(id.xy);
    let pos = textureLoad(g_position, px, 0);
    var out = vec4<f32>(1.0);
    if pos.w != 0.0 {
        let n = normalize(textureLoad(g_normal, px, 0).xyz);
        for (var j = 0u; j < 4u; j++) {
            let k = 4u * id.z + j;
            if k < args[3] {
                out[j] = pcss(k, pos.xyz, n, id.xy);
            }
        }
    }
    textureStore(visibility, px, i32(id.z), out);
}

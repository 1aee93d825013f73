// LightCluster's per-frame constants and its cube faces, shared by light_cluster.wgsl and
// lc_shadows.wgsl. face_view and atlas_texel read the `frame` binding (LcFrame).

struct LcFrame {
    eye: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    // cos, sin of the horizontal half field of view, then of the vertical.
    half_fov: vec4<f32>,
    light_count: u32,
    max_clusters: u32,
    map_size: u32,
    tiles_per_row: u32,
    min_distance_m: f32,
    distance_scale: f32,
    range_scale: f32,
    near_m: f32,
    far_m: f32,
    normal_offset: f32,
    bias: f32,
    blocker_samples: u32,
    filter_samples: u32,
    width: u32,
    height: u32,
    vertex_count: u32,
    // A cluster's disk: 0 its minimum distance (the paper), 1 its lights' extent.
    disk_extent: u32,
    // 1: the emitters are VPLs, lighting their normal's hemisphere (their normal is the
    // light's `direction`).
    hemisphere: u32,
    pad1: u32,
    pad2: u32,
};

// The six 90° cube faces (axis, up), as runtime::gpu::passes::shadow_maps::CUBE_FACES.
fn face_axes(f: u32) -> array<vec3<f32>, 2> {
    switch f {
        case 0u: { return array(vec3(1.0, 0.0, 0.0), vec3(0.0, -1.0, 0.0)); }
        case 1u: { return array(vec3(-1.0, 0.0, 0.0), vec3(0.0, -1.0, 0.0)); }
        case 2u: { return array(vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0)); }
        case 3u: { return array(vec3(0.0, -1.0, 0.0), vec3(0.0, 0.0, -1.0)); }
        case 4u: { return array(vec3(0.0, 0.0, 1.0), vec3(0.0, -1.0, 0.0)); }
        default: { return array(vec3(0.0, 0.0, -1.0), vec3(0.0, -1.0, 0.0)); }
    }
}

// The face whose frustum holds direction d.
fn face_of(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x > 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y > 0.0);
    }
    return select(5u, 4u, d.z > 0.0);
}

// Face f's view of offset `rel` from its centre: (x, y, depth along the axis): x / depth and
// y / depth are the face's NDC (camera::look_to and a 90° camera::perspective).
fn face_view(f: u32, rel: vec3<f32>) -> vec3<f32> {
    let a = face_axes(f);
    let s = normalize(cross(a[0], a[1]));
    let u = cross(s, a[0]);
    return vec3<f32>(dot(s, rel), dot(u, rel), dot(a[0], rel));
}

// The atlas texel of tile `tile` at face NDC `ndc`.
fn atlas_texel(tile: u32, ndc: vec2<f32>) -> vec2<i32> {
    let s = i32(frame.map_size);
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let t = clamp(vec2<i32>(uv * f32(s)), vec2<i32>(0), vec2<i32>(s - 1));
    let col = i32(tile % frame.tiles_per_row);
    let row = i32(tile / frame.tiles_per_row);
    return vec2<i32>(col * s, row * s) + t;
}


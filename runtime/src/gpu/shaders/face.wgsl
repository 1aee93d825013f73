// The G-buffer keeps the face's own normal (turned to the camera) octahedral-encoded in
// normal.w and albedo.w: the voxel walk starts off the face, whatever the shading normal, and
// the ratio estimator's grid (ratio.wgsl) tests its pixels against the face's plane.
fn encode_face_normal(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z < 0.0 {
        return (1.0 - abs(p.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
    }
    return p;
}

fn decode_face_normal(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e.x, e.y, 1.0 - abs(e.x) - abs(e.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return normalize(n);
}

// A VPL's light without visibility less the near field's share, and the near field's radius
// and share: what the interleaved walks (walk.wgsl) and the ratio estimator's unshadowed light
// (unshadowed.wgsl) leave to the near field (shade.wgsl's cs_near_field). It reads the
// including pass's globals and vpls; no bindings of its own.

// The ratio estimator's unshadowed far light at p (normal n) from VPLs [first, end)
// (unshadowed.wgsl).
fn far_unshadowed(p: vec3<f32>, n: vec3<f32>, first: u32, end: u32) -> vec3<f32> {
    let r = near_radius(p);
    var sum = vec3<f32>(0.0);
    for (var k = first; k < end; k++) {
        sum += far_light(vpls[k], p, n, r);
    }
    return sum;
}

// VPL v's light at p (normal n) without visibility, less the near field's share at radius r
// (all of it at r = 0).
fn far_light(v: Vpl, p: vec3<f32>, n: vec3<f32>, r: f32) -> vec3<f32> {
    let to_v = v.position - p;
    return vpl_light(v, p, n, globals.g_max) * (1.0 - near_share(dot(to_v, to_v), r));
}

// The near field's radius at p (m; 0: none): globals.near_scale times p's distance from the
// eye, a few interleaving blocks' width on a surface there facing the camera
// (GatesParams::near_scale).
fn near_radius(p: vec3<f32>) -> f32 {
    return globals.near_scale * length(p - globals.eye.xyz);
}

// The near field's share of the light of a VPL at squared distance d2 from a pixel whose
// radius is r: 1 within r / 2, 0 from r on, smoothly between; the interleaved gathers take the
// rest. A hard edge drew the radius's circles on the walls where the subsets hold few VPLs
// (the viewer's 32 on a software rasterizer), the blurred far light beside the exact near
// one.
fn near_share(d2: f32, r: f32) -> f32 {
    if r <= 0.0 {
        return 0.0;
    }
    return 1.0 - smoothstep(0.5 * r, r, sqrt(d2));
}

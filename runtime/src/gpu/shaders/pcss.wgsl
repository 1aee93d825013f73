// PCSS's pieces (Fernando 2005), shared by LightCluster's cube maps (lc_shadows.wgsl) and the
// imperfect shadow maps of val-ism (ism_gather.wgsl): the receiver-plane distance, Vogel
// disks turned per pixel, and the cone from a receiver to a disk light.

// Distance from `c` along unit `w` to the receiver's plane (through q, normal n): what a
// lookup in direction w compares with, so that a sloped receiver does not shadow itself.
// `fallback` where w runs along or away from the plane.
fn plane_distance(c: vec3<f32>, w: vec3<f32>, q: vec3<f32>, n: vec3<f32>, fallback: f32) -> f32 {
    let den = dot(w, n);
    if den > -1e-3 {
        return fallback;
    }
    return dot(q - c, n) / den;
}

// Point i of n of a Vogel (golden-angle) disk of unit radius, turned by `turn` (rad); point 0
// at the centre where `centre` (the blocker search: the ray to the disk's centre is always
// looked at).
fn vogel(i: u32, n: u32, turn: f32, centre: bool) -> vec2<f32> {
    let r = sqrt((f32(i) + select(0.5, 0.0, centre)) / f32(n));
    let a = f32(i) * 2.39996323 + turn;
    return r * vec2<f32>(cos(a), sin(a));
}

// Interleaved gradient noise (Jimenez 2014): a per-pixel turn of the sample disks.
fn pixel_noise(px: vec2<u32>) -> f32 {
    let p = vec2<f32>(px);
    return fract(52.9829189 * fract(0.06711056 * p.x + 0.00583715 * p.y));
}

// Whether the surface at distance `z` along direction w0 + offset `o` (tangent units)
// occludes part of the disk of radius `radius` seen from a receiver at distance `dr`: it lies
// in the cone from the receiver to the disk.
fn in_cone(o: vec2<f32>, z: f32, radius: f32, dr: f32) -> bool {
    return z < dr && length(o) * dr * z <= radius * (dr - z);
}

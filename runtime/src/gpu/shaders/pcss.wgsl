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

// A receiver's view of a disk light: the unit direction w0 from the disk's centre to the
// (offset) receiver at distance dr, a tangent frame (t1, t2) about it, and the pixel's turn of
// the sample disks.
struct PcssCone {
    w0: vec3<f32>,
    dr: f32,
    t1: vec3<f32>,
    turn: f32,
    t2: vec3<f32>,
};

// The cone of a receiver at offset `dq` from the disk's centre, for pixel `px`.
fn pcss_cone(dq: vec3<f32>, px: vec2<u32>) -> PcssCone {
    var c: PcssCone;
    c.dr = length(dq);
    c.w0 = dq / c.dr;
    c.t1 = normalize(cross(c.w0, select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(c.w0.y) > 0.9)));
    c.t2 = cross(c.w0, c.t1);
    c.turn = 6.2831853 * pixel_noise(px);
    return c;
}

// The blocker search's half-width (tangent units) for a disk of `radius`: blockers are looked
// for no nearer the centre than the radius (nearer is inside the light) nor than a quarter of
// the way — the search cone widens as 1 / that distance, and a sparse search of a wide cone
// misses the narrow cone a far blocker casts.
fn pcss_search(radius: f32, dr: f32) -> f32 {
    let nearest = min(max(radius, 0.25 * dr), 0.5 * dr);
    return min(radius * (dr - nearest) / (dr * nearest), 1.0);
}

// The penumbra's half-width (tangent units) from the blockers' mean distance zb: (z_r − z_b)
// / z_b times the disk, over the receiver's distance.
fn pcss_penumbra(radius: f32, dr: f32, zb: f32) -> f32 {
    return min(radius * max(dr - zb, 0.0) / (dr * zb), 1.0);
}

// Sample i of n of the cone: its tangent offset `o` (a Vogel disk of half-width `width`; the
// centre ray first for the blocker search) and unit direction.
struct PcssSample {
    o: vec2<f32>,
    w: vec3<f32>,
};

fn pcss_sample(c: PcssCone, i: u32, n: u32, search: bool, width: f32) -> PcssSample {
    var s: PcssSample;
    s.o = vogel(i, n, c.turn, search) * width;
    s.w = normalize(c.w0 + c.t1 * s.o.x + c.t2 * s.o.y);
    return s;
}

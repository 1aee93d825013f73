//! include: grid.wgsl
// A gate disk and the segment-through-disk test; runtime::cpu::gates::segment_crosses_disk is
// its CPU twin. `crosses` reads the including pass's `grid` (the oversize factor).

// As runtime::gpu::layout::Gate.
struct Gate {
    centre: vec3<f32>,
    radius: f32,
    normal: vec3<f32>,
    pad0: f32,
    // The two visibility clusters it joins.
    clusters: vec2<u32>,
    pad1: vec2<u32>,
};

// Whether the segment a→b passes through gate g's disk (radius × the oversize factor).
fn crosses(a: vec3<f32>, b: vec3<f32>, g: Gate) -> bool {
    let d = b - a;
    let den = dot(d, g.normal);
    if abs(den) <= 1.1920929e-7 * length(d) {
        return false;
    }
    let t = dot(g.centre - a, g.normal) / den;
    if t < 0.0 || t > 1.0 {
        return false;
    }
    let q = a + d * t - g.centre;
    let r = g.radius * grid.oversize;
    return dot(q, q) <= r * r;
}

fn other_side(g: Gate, c: u32) -> u32 {
    return select(g.clusters.x, g.clusters.y, g.clusters.x == c);
}

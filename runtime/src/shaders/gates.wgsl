// The level's gate disks and each cluster's gate list, and the segment-through-disk test.
// Prepended after grid.wgsl; runtime::gates::segment_crosses_disk is its CPU twin.

struct Gate {
    // xyz centre (m), w radius (m).
    centre: vec4<f32>,
    // xyz unit normal.
    normal: vec4<f32>,
    // xy the two clusters.
    clusters: vec4<u32>,
};

@group(0) @binding(10) var<storage, read> gates: array<Gate>;
// Offsets (clusters + 1) into this same array, then the gate indices.
@group(0) @binding(11) var<storage, read> cluster_gates: array<u32>;

// Whether the segment a→b passes through gate g's disk (radius × the oversize factor).
fn crosses(a: vec3<f32>, b: vec3<f32>, g: Gate) -> bool {
    let d = b - a;
    let den = dot(d, g.normal.xyz);
    if abs(den) <= 1.1920929e-7 * length(d) {
        return false;
    }
    let t = dot(g.centre.xyz - a, g.normal.xyz) / den;
    if t < 0.0 || t > 1.0 {
        return false;
    }
    let q = a + d * t - g.centre.xyz;
    let r = g.centre.w * grid.params.x;
    return dot(q, q) <= r * r;
}

fn other_side(g: Gate, c: u32) -> u32 {
    return select(g.clusters.x, g.clusters.y, g.clusters.x == c);
}

// Imperfect shadow maps (Ritschel et al. 2008), shared by their construction (ism_maps.wgsl)
// and their lookups (ism_gather.wgsl): the constants, and the maps' layout — map k of side s
// is the s² words from k·s² of one atlas buffer, a texel the emitter's nearest distance (m) in
// a paraboloid direction (Brabec et al.) as the bits of !f32 (0: nothing seen), so that
// atomicMax keeps the nearest point. `ism_distance` reads the `atlas` binding.

// As runtime::gpu::layout::IsmFrame.
struct IsmFrame {
    // Maps (one per emitter), their side, points in all, scene triangles.
    emitters: u32,
    map_size: u32,
    points: u32,
    triangles: u32,
    // 0: the emitters are VPLs, 1: VALs. Seed of the points.
    kind: u32,
    seed: u32,
    // Interleaving block side b and subsets b².
    block: u32,
    subsets: u32,
    // Radius of a point's surfel (m: its share of the scene's area as a disk, times
    // √coverage), the largest splat radius (texels), VAL centre offset (m),
    // geometry-term clamp of VPLs (1/m²).
    point_radius: f32,
    max_splat: f32,
    centre_offset: f32,
    g_max: f32,
    // Lookups: depth bias and normal offset (texels); PCSS samples (0 blocker samples: hard).
    bias: f32,
    normal_offset: f32,
    blocker_samples: u32,
    filter_samples: u32,
    // val-ism: 1 the paper's form factor at the disk's centre, 5 the disk as 5 parts.
    disk_parts: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

// Texel (x, y) of map k's word.
fn ism_index(k: u32, t: vec2<u32>, s: u32) -> u32 {
    return k * s * s + t.y * s + t.x;
}

// The continuous paraboloid coordinates (in texels) of direction `local` (z > 0) in a map of
// side s.
fn ism_coords(local: vec3<f32>, s: f32) -> vec2<f32> {
    let dir = local / length(local);
    let uv = dir.xy / (1.0 + dir.z);
    return vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5) * s;
}

// Texels a radian spans at a direction of cosine `cos_t` to the map's axis:
// d(tan(θ/2))/dθ = 1 / (1 + cos θ), in uv over [−1, 1] of s texels.
fn ism_texels_per_rad(cos_t: f32, s: f32) -> f32 {
    return 0.5 * s / (1.0 + cos_t);
}

// The world direction of texel centre `t` (continuous texel coordinates) of a map of side s
// with frame (tb, n): the inverse of ism_coords.
fn ism_texel_direction(t: vec2<f32>, s: f32, tb: mat2x3<f32>, n: vec3<f32>) -> vec3<f32> {
    let u = t.x / s * 2.0 - 1.0;
    let v = 1.0 - t.y / s * 2.0;
    let r2 = min(u * u + v * v, 1.0);
    let z = (1.0 - r2) / (1.0 + r2);
    return normalize(tb[0] * (u * (1.0 + z)) + tb[1] * (v * (1.0 + z)) + n * z);
}

fn ism_encode(d: f32) -> u32 {
    return ~bitcast<u32>(d);
}

fn ism_decode(w: u32) -> f32 {
    if w == 0u {
        return 3.4e38;
    }
    return bitcast<f32>(~w);
}

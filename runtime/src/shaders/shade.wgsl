// Deferred shading: direct light from point and spot lights with shadow-map PCF (3 × 3), and
// the indirect sum over VPLs without visibility (mode 0, none) or through the gates of a baked
// level (mode 2), into a linear HDR target.
//
// Radiometry as the CPU reference: L = ρ/π · I · falloff · cos θ / d² for lights, and
// ρ/π · Φ/π · min(cos θ_v cos θ_x / d², g_max) for VPLs.

const PI: f32 = 3.14159265358979;

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    params: vec4<f32>,
    counts: vec4<u32>,
};

struct Light {
    // xyz position (m), w kind (0 point, 1 spot).
    position: vec4<f32>,
    // rgb intensity (W/sr), w beam half-angle (rad).
    intensity: vec4<f32>,
    // xyz unit axis, w cutoff half-angle (rad).
    direction: vec4<f32>,
    // x first shadow layer, y layers, z, w unused.
    layers: vec4<u32>,
};

struct Vpl {
    position: vec3<f32>,
    pad0: f32,
    normal: vec3<f32>,
    pad1: f32,
    flux: vec3<f32>,
    pad2: f32,
};

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(3) var<storage, read> shadow_mats: array<mat4x4<f32>>;
@group(0) @binding(4) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_normal: texture_2d<f32>;
@group(0) @binding(7) var g_albedo: texture_2d<f32>;

// Gate visibility (mode 2), brute force per fragment and VPL: the clusters of both through
// their normal side, then a chain of at most 2 gate disks the segment passes through.
struct Grid {
    // xyz origin (m), w voxel size (m).
    origin: vec4<f32>,
    // xyz dims, w bytes per stored value (1, 2 or 4).
    dims: vec4<u32>,
    // x disk oversize factor, y max hops (1 or 2), z, w unused.
    params: vec4<f32>,
};

struct Gate {
    // xyz centre (m), w radius (m).
    centre: vec4<f32>,
    // xyz unit normal.
    normal: vec4<f32>,
    // xy the two clusters.
    clusters: vec4<u32>,
};

@group(0) @binding(8) var<uniform> grid: Grid;
@group(0) @binding(9) var<storage, read> voxel_words: array<u32>;
@group(0) @binding(10) var<storage, read> gates: array<Gate>;
// Offsets (clusters + 1) into this same array, then the gate indices.
@group(0) @binding(11) var<storage, read> cluster_gates: array<u32>;

const NONE: u32 = 0xffffffffu;

fn cluster_of(p: vec3<f32>) -> u32 {
    let v = (p - grid.origin.xyz) / grid.origin.w;
    if any(v < vec3<f32>(0.0)) || any(v >= vec3<f32>(grid.dims.xyz)) {
        return NONE;
    }
    let c = vec3<u32>(v);
    let i = c.x + grid.dims.x * (c.y + grid.dims.y * c.z);
    let bytes = grid.dims.w;
    if bytes == 4u {
        return voxel_words[i];
    }
    if bytes == 2u {
        let x = (voxel_words[i / 2u] >> ((i % 2u) * 16u)) & 0xffffu;
        return select(x, NONE, x == 0xffffu);
    }
    let x = (voxel_words[i / 4u] >> ((i % 4u) * 8u)) & 0xffu;
    return select(x, NONE, x == 0xffu);
}

fn cluster_at(p: vec3<f32>, n: vec3<f32>) -> u32 {
    let vs = grid.origin.w;
    var c = cluster_of(p + n * (0.5 * vs));
    if c == NONE {
        c = cluster_of(p + n * (1.5 * vs));
    }
    if c == NONE {
        c = cluster_of(p);
    }
    return c;
}

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

fn through_gates(a: vec3<f32>, ca: u32, b: vec3<f32>, cb: u32) -> bool {
    if ca == cb || ca == NONE || cb == NONE {
        return true;
    }
    for (var i = cluster_gates[ca]; i < cluster_gates[ca + 1u]; i++) {
        let g = gates[cluster_gates[i]];
        if !crosses(a, b, g) {
            continue;
        }
        let c = other_side(g, ca);
        if c == cb {
            return true;
        }
        if grid.params.y < 1.5 {
            continue;
        }
        for (var j = cluster_gates[c]; j < cluster_gates[c + 1u]; j++) {
            let h = gates[cluster_gates[j]];
            if other_side(h, c) == cb && crosses(a, b, h) {
                return true;
            }
        }
    }
    return false;
}

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn spot_falloff(angle: f32, beam: f32, cutoff: f32) -> f32 {
    if angle <= beam {
        return 1.0;
    }
    if angle >= cutoff || cutoff <= beam {
        return 0.0;
    }
    return (cutoff - angle) / (cutoff - beam);
}

// Visibility of `p` (normal `n`) from light `l`: 3 × 3 PCF of distance comparisons.
fn shadow(l: Light, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = f32(globals.counts.w);
    let d = p - l.position.xyz;
    let dist = length(d);
    var layer = l.layers.x;
    // Texel footprint at this distance: 90° faces span 2·dist, spots 2·dist·tan(cutoff).
    var span = 2.0 * dist;
    if l.position.w < 0.5 {
        let a = abs(d);
        if a.x >= a.y && a.x >= a.z {
            layer += select(1u, 0u, d.x > 0.0);
        } else if a.y >= a.z {
            layer += select(3u, 2u, d.y > 0.0);
        } else {
            layer += select(5u, 4u, d.z > 0.0);
        }
    } else {
        span = 2.0 * dist * tan(min(l.direction.w, 1.5));
    }
    let texel = span / size;
    let q = p + n * texel * globals.params.y;
    let clip = shadow_mats[layer] * vec4<f32>(q, 1.0);
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let c = vec2<i32>(uv * size);
    let ref_dist = length(q - l.position.xyz) - texel * globals.params.z;
    var lit = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let t = clamp(c + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(i32(size) - 1));
            let stored = textureLoad(shadow_maps, t, i32(layer), 0).x;
            lit += select(0.0, 1.0, stored >= ref_dist);
        }
    }
    return lit / 9.0;
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(frag.xy);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let p = pos.xyz;
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < globals.counts.y; i++) {
        let l = lights[i];
        let to_light = l.position.xyz - p;
        let d2 = dot(to_light, to_light);
        if d2 <= 0.0 {
            continue;
        }
        let w = to_light * inverseSqrt(d2);
        let cos_x = dot(n, w);
        if cos_x <= 0.0 {
            continue;
        }
        var intensity = l.intensity.xyz;
        if l.position.w > 0.5 {
            let angle = acos(clamp(dot(l.direction.xyz, -w), -1.0, 1.0));
            intensity *= spot_falloff(angle, l.intensity.w, l.direction.w);
        }
        if all(intensity == vec3<f32>(0.0)) {
            continue;
        }
        radiance += albedo / PI * intensity * cos_x / d2 * shadow(l, p, n);
    }
    if globals.counts.z == 0u || globals.counts.z == 2u {
        let g_max = globals.params.x;
        let gated = globals.counts.z == 2u;
        var here = NONE;
        if gated {
            here = cluster_at(p, n);
        }
        for (var j = 0u; j < globals.counts.x; j++) {
            let v = vpls[j];
            let d = v.position - p;
            let d2 = dot(d, d);
            if d2 <= 0.0 {
                continue;
            }
            let w = d * inverseSqrt(d2);
            let cos_x = dot(n, w);
            let cos_v = -dot(v.normal, w);
            if cos_x <= 0.0 || cos_v <= 0.0 {
                continue;
            }
            if gated && !through_gates(v.position, cluster_at(v.position, v.normal), p, here) {
                continue;
            }
            let g = min(cos_x * cos_v / d2, g_max);
            radiance += albedo / PI * v.flux / PI * g;
        }
    }
    return vec4<f32>(radiance, 1.0);
}

//! include: vpl.wgsl val.wgsl ism.wgsl pcss.wgsl
// Indirect light through imperfect shadow maps, into an indirect target that blur.wgsl
// composes (each pixel lights itself with its interleaving subset: emitter i lights subset
// i mod b², the paper's round robin over the split G-buffer's tiles):
//   cs_vpl  mode per-vpl-ism (Ritschel et al.): every VPL's point light through one hard
//           lookup of its ISM
//   cs_val  mode val-ism (Weinzierl-Heigl §6): every VAL as a disk of its area A_c — the
//           point-to-disk form factor cos θx·cos θc / (π‖x − c‖² + A_c) in place of the point
//           light's — through PCSS on its ISM, the disk's radius √(A_c/π) sizing the blocker
//           search and the penumbra

@group(0) @binding(0) var<uniform> frame: IsmFrame;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read> vals: array<Val>;
@group(0) @binding(3) var<storage, read> emitters: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> atlas: array<u32>;
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_normal: texture_2d<f32>;
// The indirect target (compute passes, as shade.wgsl's cs_gates_indirect says why).
@group(0) @binding(7) var out_image: texture_storage_2d<rgba32float, write>;

// Distance from emitter k to the nearest surface along unit direction w ("very far" behind
// its plane or where nothing was seen).
fn ism_distance(k: u32, w: vec3<f32>) -> f32 {
    let n = emitters[2u * k + 1u].xyz;
    let tb = basis(n);
    let local = vec3<f32>(dot(w, tb[0]), dot(w, tb[1]), dot(w, n));
    if local.z <= 0.0 {
        return 3.4e38;
    }
    let s = frame.map_size;
    let t = clamp(vec2<i32>(floor(ism_coords(local, f32(s)))), vec2<i32>(0), vec2<i32>(i32(s) - 1));
    return ism_decode(atlas[ism_index(k, vec2<u32>(t), s)]);
}

// Radians a texel spans towards p from emitter k (at distance `dist`).
fn texel_angle(k: u32, p: vec3<f32>, dist: f32) -> f32 {
    let n = emitters[2u * k + 1u].xyz;
    let cos_t = clamp(dot(p - emitters[2u * k].xyz, n) / max(dist, 1e-30), 0.0, 1.0);
    return 1.0 / ism_texels_per_rad(cos_t, f32(frame.map_size));
}

// The relative depth bias of a lookup at p (normal n) towards emitter c: `frame.bias`
// texels, slope-scaled up to 4× — a point's splat stands for its neighbours' depths, which a
// receiver seen at a grazing angle spreads over more depth per texel.
fn slope_bias(texel: f32, c: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let cos_r = dot(n, normalize(c - p));
    return texel * frame.bias * clamp(1.0 / max(cos_r, 1e-3), 1.0, 4.0);
}

// Hard visibility of p (normal n) from emitter k: one texel, a normal offset and a bias of
// `frame` texels.
fn ism_hard(k: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let c = emitters[2u * k].xyz;
    let dist = length(p - c);
    if dist <= 0.0 {
        return 1.0;
    }
    let texel = texel_angle(k, p, dist);
    let q = p + n * (dist * texel * frame.normal_offset);
    let dr = length(q - c);
    let w = (q - c) / dr;
    return select(0.0, 1.0, ism_distance(k, w) >= dr * (1.0 - slope_bias(texel, c, p, n)));
}

// PCSS visibility of p (normal n) from VAL k as a disk of `radius` (Weinzierl-Heigl §6, with
// LightCluster's cone-bounded blocker search and receiver-plane depths): the blockers' mean
// distance over the cone from p to the disk, the penumbra (z_r − z_b)/z_b scaled by the disk,
// PCF over it. Radius 0 or no samples: one hard lookup.
fn ism_pcss(k: u32, p: vec3<f32>, n: vec3<f32>, radius: f32, px: vec2<u32>) -> f32 {
    if radius <= 0.0 || frame.blocker_samples == 0u {
        return ism_hard(k, p, n);
    }
    let c = emitters[2u * k].xyz;
    let dist = length(p - c);
    if dist <= 0.0 {
        return 1.0;
    }
    let texel = texel_angle(k, p, dist);
    let q = p + n * (dist * texel * frame.normal_offset);
    let cone = pcss_cone(q - c, px);
    let dr = cone.dr;
    let bias = slope_bias(texel, c, p, n);
    let search = pcss_search(radius, dr);
    var sum = 0.0;
    var found = 0.0;
    for (var i = 0u; i < frame.blocker_samples; i++) {
        let s = pcss_sample(cone, i, frame.blocker_samples, true, search);
        let z = ism_distance(k, s.w);
        let zr = plane_distance(c, s.w, q, n, dr);
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
    for (var i = 0u; i < frame.filter_samples; i++) {
        let s = pcss_sample(cone, i, frame.filter_samples, false, width);
        let zr = plane_distance(c, s.w, q, n, dr);
        lit += select(0.0, 1.0, ism_distance(k, s.w) >= zr * (1.0 - bias));
    }
    return lit / f32(max(frame.filter_samples, 1u));
}

// The irradiance at p (normal n) of a Lambertian disk of flux Φ, area A, centre c, normal m:
// Φ/π · min(cos θx·cos θc / (‖x − c‖² + A/π), g_max) (Wallace et al.'s point-to-disk form
// factor, clamped as every VPL's term is; A → 0 gives the point light's term).
// runtime::cpu::ism::disk_irradiance is its twin.
fn disk_light(flux: vec3<f32>, area: f32, c: vec3<f32>, m: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let d = c - p;
    let d2 = dot(d, d);
    if d2 <= 0.0 {
        return vec3<f32>(0.0);
    }
    let w = d * inverseSqrt(d2);
    let cos_x = dot(n, w);
    let cos_c = -dot(m, w);
    if cos_x <= 0.0 || cos_c <= 0.0 {
        return vec3<f32>(0.0);
    }
    return flux / PI * min(cos_x * cos_c / (d2 + area / PI), frame.g_max);
}

// The same disk as 5 parts of a fifth of its area and flux each — its centre and 4 on the
// ring at ¾ of its radius — each by the form factor: the centre's cosine no longer stands for
// the whole disk near it (runtime::cpu::ism::disk_irradiance_parts).
fn disk_light_parts(flux: vec3<f32>, area: f32, c: vec3<f32>, m: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if frame.disk_parts <= 1u || area <= 0.0 {
        return disk_light(flux, area, c, m, p, n);
    }
    let tb = basis(m);
    let r = 0.75 * sqrt(area / PI);
    let f = flux * 0.2;
    let a = area * 0.2;
    var sum = disk_light(f, a, c, m, p, n);
    sum += disk_light(f, a, c + tb[0] * r, m, p, n);
    sum += disk_light(f, a, c - tb[0] * r, m, p, n);
    sum += disk_light(f, a, c + tb[1] * r, m, p, n);
    sum += disk_light(f, a, c - tb[1] * r, m, p, n);
    return sum;
}

struct Pixel {
    p: vec3<f32>,
    n: vec3<f32>,
    j: u32,
    found: bool,
};

fn pixel(px: vec2<i32>) -> Pixel {
    var s: Pixel;
    let pos = textureLoad(g_position, px, 0);
    s.found = pos.w != 0.0;
    s.p = pos.xyz;
    s.n = normalize(textureLoad(g_normal, px, 0).xyz);
    s.j = interleave_subset(px, frame.block);
    return s;
}

@compute @workgroup_size(8, 8)
fn cs_vpl(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(g_position)) {
        textureStore(out_image, id.xy, gather_vpl(id.xy));
    }
}

fn gather_vpl(px: vec2<u32>) -> vec4<f32> {
    let s = pixel(vec2<i32>(px));
    if !s.found {
        return vec4<f32>(0.0);
    }
    var sum = vec3<f32>(0.0);
    for (var i = s.j; i < frame.emitters; i += frame.subsets) {
        let light = vpl_light(vpls[i], s.p, s.n, frame.g_max);
        if any(light > vec3<f32>(0.0)) {
            sum += light * ism_hard(i, s.p, s.n);
        }
    }
    return vec4<f32>(sum * f32(frame.subsets), 1.0);
}

@compute @workgroup_size(8, 8)
fn cs_val(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(g_position)) {
        textureStore(out_image, id.xy, gather_val(id.xy));
    }
}

fn gather_val(px: vec2<u32>) -> vec4<f32> {
    let s = pixel(vec2<i32>(px));
    if !s.found {
        return vec4<f32>(0.0);
    }
    var sum = vec3<f32>(0.0);
    for (var k = s.j; k < frame.emitters; k += frame.subsets) {
        let v = vals[k];
        let area = max(v.flux.w, 0.0);
        let light = disk_light_parts(v.flux.xyz, area, v.position.xyz, v.normal.xyz, s.p, s.n);
        if any(light > vec3<f32>(0.0)) {
            sum += light * ism_pcss(k, s.p, s.n, sqrt(area / PI), px);
        }
    }
    return vec4<f32>(sum * f32(frame.subsets), 1.0);
}

//! include: vpl.wgsl val.wgsl
// Indirect light with the visibility of virtual area lights (Dong et al. §4): every VPL lights
// every pixel, seen through the shadow map of its VAL C(i): L(x) = Σ_i L_i(x)·V_C(i)(x), added
// as irradiance into an indirect target, which blur.wgsl composes onto the image so far. Mode
// val-hard (cs_hard) tests one texel of the VAL's paraboloid distance map
// (hard shadows: the banding baseline); val-cssm (cs_cssm) filters its Fourier basis
// (convolution soft shadow maps). A receiver in the negative half-space of a VAL is fully
// visible, as in the paper. Interleaved sampling: a pixel of a b × b block lights itself with
// one subset of the VPLs (i mod b² = its place in the block), and blur.wgsl blurs over the
// block where the geometry agrees.

@group(0) @binding(0) var<uniform> gather: ValGather;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var maps: texture_2d_array<f32>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
// M·B + 1 offsets, then the VPL indices sorted by VAL and subset (vals.wgsl's order).
@group(0) @binding(7) var<storage, read> order: array<u32>;
@group(0) @binding(8) var<storage, read> vals: array<Val>;
// The indirect target (compute passes, as shade.wgsl's cs_gates_indirect: 30× faster than a
// fullscreen draw on a data-centre GPU, as fast on lavapipe).
@group(0) @binding(12) var indirect_out: texture_storage_2d<rgba32float, write>;

// Hard visibility of p (normal n) from VAL k.
fn val_visibility(k: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = f32(gather.map_size);
    let nv = vals[k].normal.xyz;
    let c = vals[k].position.xyz + nv * gather.centre_offset;
    let tb = basis(nv);
    // A texel spans about 4/size rad at the map's centre.
    let texel = length(p - c) * 4.0 / size;
    let q = p + n * texel * gather.normal_offset - c;
    let local = vec3<f32>(dot(q, tb[0]), dot(q, tb[1]), dot(q, nv));
    let d = length(local);
    if local.z <= 0.0 || d <= 0.0 {
        return 1.0;
    }
    let t = clamp(paraboloid_texel(local, size), vec2<i32>(0), vec2<i32>(i32(size) - 1));
    return select(0.0, 1.0, textureLoad(maps, t, i32(k), 0).x >= d - texel * gather.bias);
}

// Light at p (normal n) of the VPLs of VAL k in interleaving subset j, without albedo / π
// and visibility.
fn val_light(k: u32, j: u32, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let bucket = k * gather.subsets + j;
    let first = gather.val_count * gather.subsets + 1u;
    var part = vec3<f32>(0.0);
    for (var e = order[bucket]; e < order[bucket + 1u]; e++) {
        part += vpl_light(vpls[order[first + e]], p, n, gather.g_max);
    }
    return part;
}

struct Surface {
    p: vec3<f32>,
    n: vec3<f32>,
    // This pixel's interleaving subset.
    j: u32,
    found: bool,
};

fn surface(px: vec2<i32>) -> Surface {
    var s: Surface;
    let pos = textureLoad(g_position, px, 0);
    s.found = pos.w != 0.0;
    s.p = pos.xyz;
    s.n = normalize(textureLoad(g_normal, px, 0).xyz);
    let b = gather.block;
    s.j = interleave_subset(px, b);
    return s;
}

fn bucket_empty(k: u32, j: u32) -> bool {
    let bucket = k * gather.subsets + j;
    return order[bucket] == order[bucket + 1u];
}

// Mode val-hard: the irradiance (× B, this pixel's subset standing for all) of the VPLs, VAL
// by VAL: its visibility once, then its VPLs.
@compute @workgroup_size(8, 8)
fn cs_hard(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(g_position)) {
        textureStore(indirect_out, id.xy, hard(vec2<i32>(id.xy)));
    }
}

fn hard(px: vec2<i32>) -> vec4<f32> {
    let s = surface(px);
    if !s.found {
        return vec4<f32>(0.0);
    }
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < gather.val_count; k++) {
        if bucket_empty(k, s.j) {
            continue;
        }
        let vis = val_visibility(k, s.p, s.n);
        if vis > 0.0 {
            sum += val_light(k, s.j, s.p, s.n) * vis;
        }
    }
    return vec4<f32>(sum * f32(gather.subsets), 1.0);
}

// ---- mode val-cssm: the VAL's visibility from its Fourier basis (cssm.wgsl) ----

@group(0) @binding(9) var basis_tex: texture_2d_array<f32>;
@group(0) @binding(10) var basis_sampler: sampler;
@group(0) @binding(11) var<storage, read> ranges: array<f32>;

// 2 Σ_k [cos(c_k d)·S_k − sin(c_k d)·C_k] / c_k over the basis groups from `base` (0: the
// basis, G: the basis times z), filtered at `lod` around `uv`.
fn series(base: u32, k: u32, uv: vec2<f32>, lod: f32, d: f32) -> f32 {
    let m = gather.val_count;
    let terms = gather.terms;
    var s = 0.0;
    for (var g = 0u; 2u * g < terms; g++) {
        let b = textureSampleLevel(basis_tex, basis_sampler, uv, i32((base + g) * m + k), lod);
        let c1 = PI * f32(4u * g + 1u);
        s += (cos(c1 * d) * b.x - sin(c1 * d) * b.y) / c1;
        if 2u * g + 2u <= terms {
            let c2 = PI * f32(4u * g + 3u);
            s += (cos(c2 * d) * b.z - sin(c2 * d) * b.w) / c2;
        }
    }
    return 2.0 * s;
}

// Soft visibility of p (normal n) from VAL k (Dong et al. §4.2): the average blocker depth
// over the VAL's extent seen from p, the penumbra p·cos β = (d − z_avg)·Δ / z_avg, the kernel
// α = atan(p·cos β / d) of size α/π in the map, the filtered Fourier shadow test there,
// sharpened by s about ½ and clamped (runtime::cpu::cssm::visibility).
fn cssm_visibility(k: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = f32(gather.map_size);
    let val = vals[k];
    let nv = val.normal.xyz;
    let c = val.position.xyz + nv * gather.centre_offset;
    let tb = basis(nv);
    let texel = length(p - c) * 4.0 / size;
    // A filtered kernel spans depths of the receiver's own surface in front of it, the more
    // the more grazing the VAL sees it: a normal offset of its own, slope-scaled up to 2×.
    // (A receiver at the VAL's centre has no direction to it: no grazing, not a NaN.)
    let to_c = c - p;
    let len_c = length(to_c);
    let cos_c = select(1.0, dot(n, to_c) / len_c, len_c > 0.0);
    let grazing = clamp(1.0 / max(cos_c, 1e-3), 1.0, 2.0);
    let q = p + n * texel * gather.cssm_normal_offset * grazing - c;
    let local = vec3<f32>(dot(q, tb[0]), dot(q, tb[1]), dot(q, nv));
    let dist = length(local);
    if local.z <= 0.0 || dist <= 0.0 {
        return 1.0;
    }
    let range = ranges[k];
    let d = clamp(dist / range - gather.receiver_offset, 0.0, 1.0) * CSSM_DEPTH_SCALE;
    let dir = local / dist;
    let puv = dir.xy / (1.0 + dir.z);
    let uv = vec2<f32>(puv.x * 0.5 + 0.5, 0.5 - puv.y * 0.5);
    let groups = (gather.terms + 1u) / 2u;
    // The sender's size Δ: the side of the square of its rectangle's area.
    let sender = sqrt(max(val.normal.w, 0.0));
    // Blocker search over the VAL's extent seen from p: foreshortened by the angle between the
    // VAL's normal and p (√cos of it, one axis of the rectangle shrinking); the paper's
    // atan(Δ / d) ignores it (measured: this is closer to the reference everywhere, 0.2–11 %).
    let search = atan(sender * sqrt(max(dir.z, 0.0)) / dist) / PI;
    let lod_s = log2(max(search * size, 1.0));
    let blockers = 0.5 - series(0u, k, uv, lod_s, d);
    // Fewer than 2 % blocked: lit (an early-out that also drops the Fourier series' ringing;
    // measured against none: 1.6–2.4 % lower MSE on the Cornell box, the same in the four rooms).
    if blockers <= 0.02 {
        return 1.0;
    }
    let z_sum = 0.5 * textureSampleLevel(basis_tex, basis_sampler, uv, i32(2u * groups * gather.val_count + k), lod_s).x
        - series(groups, k, uv, lod_s, d);
    // A receiver within 1e-4 of the range from the VAL (d < 1e-4) keeps z_avg at 1e-4 of the
    // range, not at d = 0 (an infinite penumbra, or 0/0 for a VAL of no area).
    let z_avg = clamp(z_sum / blockers, 1e-4, max(d, 1e-4)) * range / CSSM_DEPTH_SCALE;
    let penumbra = max(dist - z_avg, 0.0) * sender / z_avg;
    let alpha = atan(penumbra / dist);
    let lod = log2(max(alpha / PI * size, 1.0));
    // The sharpening divided by the guard band's scale keeps the step's slope per metre.
    return clamp(0.5 + gather.sharpness / CSSM_DEPTH_SCALE * series(0u, k, uv, lod, d), 0.0, 1.0);
}

@compute @workgroup_size(8, 8)
fn cs_cssm(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(g_position)) {
        textureStore(indirect_out, id.xy, cssm(vec2<i32>(id.xy)));
    }
}

fn cssm(px: vec2<i32>) -> vec4<f32> {
    let s = surface(px);
    if !s.found {
        return vec4<f32>(0.0);
    }
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < gather.val_count; k++) {
        if bucket_empty(k, s.j) {
            continue;
        }
        let vis = cssm_visibility(k, s.p, s.n);
        if vis > 0.0 {
            sum += val_light(k, s.j, s.p, s.n) * vis;
        }
    }
    return vec4<f32>(sum * f32(gather.subsets), 1.0);
}

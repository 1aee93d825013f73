// Indirect light with the visibility of virtual area lights (Dong et al. §4): every VPL lights
// every pixel, seen through the shadow map of its VAL C(i): L(x) = Σ_i L_i(x)·V_C(i)(x), added
// to the image so far (`previous`, ping-pong). Mode val-hard tests one texel of the VAL's
// paraboloid distance map (hard shadows: the banding baseline). A receiver in the negative
// half-space of a VAL is fully visible, as in the paper. vpl.wgsl and val.wgsl come first.

const PI: f32 = 3.14159265358979;

struct ValGather {
    // x VPLs, y VALs, z map size (texels), w unused.
    counts: vec4<u32>,
    // x g_max (1/m²), y normal offset (texels), z bias (texels), w VAL centre offset (m).
    params: vec4<f32>,
};

@group(0) @binding(0) var<uniform> gather: ValGather;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var maps: texture_2d_array<f32>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_albedo: texture_2d<f32>;
@group(0) @binding(6) var previous: texture_2d<f32>;
// M + 1 offsets, then the VPL indices sorted by VAL (vals.wgsl's order).
@group(0) @binding(7) var<storage, read> order: array<u32>;
@group(0) @binding(8) var<storage, read> vals: array<Val>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// Hard visibility of p (normal n) from VAL k.
fn val_visibility(k: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = f32(gather.counts.z);
    let nv = vals[k].normal.xyz;
    let c = vals[k].position.xyz + nv * gather.params.w;
    let tb = basis(nv);
    // A texel spans about 4/size rad at the map's centre.
    let texel = length(p - c) * 4.0 / size;
    let q = p + n * texel * gather.params.y - c;
    let local = vec3<f32>(dot(q, tb[0]), dot(q, tb[1]), dot(q, nv));
    let d = length(local);
    if local.z <= 0.0 || d <= 0.0 {
        return 1.0;
    }
    let t = clamp(paraboloid_texel(local, size), vec2<i32>(0), vec2<i32>(i32(size) - 1));
    return select(0.0, 1.0, textureLoad(maps, t, i32(k), 0).x >= d - texel * gather.params.z);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(frag.xy);
    let before = textureLoad(previous, px, 0);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return before;
    }
    let p = pos.xyz;
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let albedo = textureLoad(g_albedo, px, 0).xyz;
    // VAL by VAL: its visibility once, then its VPLs.
    let m = gather.counts.y;
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < m; k++) {
        let first = order[k];
        let last = order[k + 1u];
        if first == last {
            continue;
        }
        let vis = val_visibility(k, p, n);
        if vis <= 0.0 {
            continue;
        }
        var part = vec3<f32>(0.0);
        for (var j = first; j < last; j++) {
            let v = vpls[order[m + 1u + j]];
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
            part += v.flux / PI * min(cos_x * cos_v / d2, gather.params.x);
        }
        sum += part * vis;
    }
    return vec4<f32>(before.xyz + albedo / PI * sum, 1.0);
}

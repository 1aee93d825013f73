// A virtual point light, as runtime::vpl::Vpl (48 bytes), and the gather term every indirect
// pass shares.

struct Vpl {
    position: vec3<f32>,
    pad0: f32,
    normal: vec3<f32>,
    pad1: f32,
    flux: vec3<f32>,
    pad2: f32,
};


// Interleaved sampling: the VPL subset of pixel px in blocks of side b (VPL i lights the
// pixels of subset i mod b²; blur.wgsl blurs over the block).
fn interleave_subset(px: vec2<i32>, b: u32) -> u32 {
    return u32(px.x) % b + b * (u32(px.y) % b);
}

// The list's order (runtime::vpl_order, whose functions these twin): the lights' merged
// sequence dealt out bit-reversed, so that each subset holds a run of it. dealt_position(s, n)
// is where the sequence's entry s lies in the list of n.
fn order_rev(c: u32, bits: u32) -> u32 {
    return select(0u, reverseBits(c) >> (32u - max(bits, 1u)), bits > 0u);
}

// The entries dealt before place c: c and the earlier places rev(x) < r that give two.
fn order_start(c: u32, bits: u32, r: u32) -> u32 {
    var doubled = 0u;
    for (var i = 0u; i < bits; i++) {
        if ((c >> i) & 1u) == 0u {
            continue;
        }
        let f = order_rev((c >> (i + 1u)) << (i + 1u), bits);
        let p = 1u << (bits - i);
        if r > f {
            doubled += min((r - f + p - 1u) / p, 1u << i);
        }
    }
    return c + doubled;
}

fn dealt_position(s: u32, n: u32) -> u32 {
    let bits = firstLeadingBit(n);
    let r = n - (1u << bits);
    var lo = 0u;
    var hi = (1u << bits) - 1u;
    while lo < hi {
        let mid = lo + (hi - lo + 1u) / 2u;
        if order_start(mid, bits, r) <= s {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    let q = order_rev(lo, bits);
    return select(q + (1u << bits), q, order_start(lo, bits, r) == s);
}

// The blur's b × b block around px in an image of `size` pixels, moved inside it at its edges
// (not clipped: a block holds every one of the b² VPL subsets, so that the few VPLs that light
// a place reach the pixels on the image's border too): lo in xy, hi (past the end) in zw.
fn interleave_block_around(px: vec2<i32>, b: i32, size: vec2<i32>) -> vec4<i32> {
    let lo = clamp(px - vec2<i32>(b / 2), vec2<i32>(0), max(size - vec2<i32>(b), vec2<i32>(0)));
    return vec4<i32>(lo, min(lo + vec2<i32>(b), size));
}

// The blur's test (Laine et al.): a tap's surface (position qp, w 0 where there is none;
// normal qn) agrees with the pixel's (p, n) when nearer than `distance` and its normal within
// cosine `cosine`. blur.wgsl averages the taps that agree; starved.wgsl's starved pixels count
// them by the same rule.
fn blur_surfaces_agree(qp: vec4<f32>, qn: vec3<f32>, p: vec3<f32>, n: vec3<f32>, distance: f32, cosine: f32) -> bool {
    return qp.w != 0.0 && length(qp.xyz - p) <= distance && dot(qn, n) >= cosine;
}

// The deinterleaved layout (Segovia et al.) of an n-pixel axis: the pixels x ≡ r (mod b) side
// by side, residue after residue, so that neighbouring fragments light with one VPL subset and
// walk alike (a GPU runs 32 neighbours in lockstep; interleaved, each took another path). A
// bijection of [0, n) for every n: residues below n mod b hold one pixel more.
fn deinterleave_axis(x: u32, b: u32, n: u32) -> u32 {
    let q = n / b;
    let m = n % b;
    let r = x % b;
    return r * q + min(r, m) + x / b;
}

// deinterleave_axis along a run of pixels without dividing at each (blur.wgsl's taps): the
// state (x mod b, x / b) of pixel x, stepped to x + 1, and where x lies given q = n / b and
// m = n % b.
fn axis_run_next(rk: vec2<u32>, b: u32) -> vec2<u32> {
    if rk.x + 1u == b {
        return vec2<u32>(0u, rk.y + 1u);
    }
    return vec2<u32>(rk.x + 1u, rk.y);
}

fn axis_run_place(rk: vec2<u32>, q: u32, m: u32) -> u32 {
    return rk.x * q + min(rk.x, m) + rk.y;
}

fn interleave_axis(s: u32, b: u32, n: u32) -> u32 {
    let q = n / b;
    let m = n % b;
    let wide = m * (q + 1u);
    if s < wide {
        return (s % (q + 1u)) * b + s / (q + 1u);
    }
    return ((s - wide) % q) * b + m + (s - wide) / q;
}

// Where pixel px lies in the deinterleaved target of size n, and which pixel a position of it
// holds.
fn deinterleaved(px: vec2<i32>, b: u32, n: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(vec2<u32>(deinterleave_axis(u32(px.x), b, n.x), deinterleave_axis(u32(px.y), b, n.y)));
}

fn interleaved(s: vec2<i32>, b: u32, n: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(vec2<u32>(interleave_axis(u32(s.x), b, n.x), interleave_axis(u32(s.y), b, n.y)));
}

// The light of VPL v at p (normal n) without albedo / π, as runtime::vpl::gather_one:
// Φ/π · min(cos θ_v cos θ_x / d², g_max); zero behind either surface.
fn vpl_light(v: Vpl, p: vec3<f32>, n: vec3<f32>, g_max: f32) -> vec3<f32> {
    let d = v.position - p;
    let d2 = dot(d, d);
    if d2 <= 0.0 {
        return vec3<f32>(0.0);
    }
    let w = d * inverseSqrt(d2);
    let cos_x = dot(n, w);
    let cos_v = -dot(v.normal, w);
    if cos_x <= 0.0 || cos_v <= 0.0 {
        return vec3<f32>(0.0);
    }
    return v.flux / PI * min(cos_x * cos_v / d2, g_max);
}

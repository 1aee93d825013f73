// The direct light's shadow-map lookups (shade.wgsl). Reads the pass's `globals`,
// `shadow_mats` and `shadow_maps` bindings.
//
// A receiver is looked up at q, its point moved along its shading normal by
// `shadow_normal_offset` texels: 3 × 3 PCF of distance comparisons, less `shadow_bias` texels.
// That bias lit every receiver within about a texel behind a zero-thickness wall, and the taps
// past a thin wall's edge see the surface that runs on past it (a floor under a wall, an outer
// wall that a dividing wall meets) lit on the far side at the receiver's own distance: a
// dotted line of light along every such join, on the dark side. So where the taps disagree, or
// all are lit but the own texel holds a surface nearer than the receiver (a receiver
// millimetres behind a wall it meets, which the bias lit), the receiver's own texel is tested
// against the receiver's plane along that texel's ray
// (receiver-plane depth: the plane through q with the face's normal, its distance per texel
// solved from two tangent steps), with no bias but the plane's own change over half a texel:
// shadowed there by a surface within CONTACT_TEXELS of the receiver, and behind that surface's
// plane as its texel and its neighbours along both diagonals give it (one alone took a wall
// meeting a lit floor for an occluder now and then), it is in a contact shadow, whole.

// Occluder-to-receiver distance within which a shadowed own texel shadows the receiver whole
// (2 and 8 gave the same images within 1 %). [Units: texels]
const CONTACT_TEXELS: f32 = 4.0;
// Largest change of the receiver's plane's distance per texel kept (a plane seen edge-on from
// the light has an unbounded one). [Units: texels per texel]
const MAX_PLANE_SLOPE: f32 = 8.0;

// Point x, relative to the layer's light (x − light: ShadowView::view_proj), in layer
// `layer`'s texels (continuous: texel (i, j) spans [i, i + 1) × [j, j + 1)).
fn shadow_texels(layer: u32, x: vec3<f32>, size: f32) -> vec2<f32> {
    let clip = shadow_mats[layer] * vec4<f32>(x, 1.0);
    let ndc = clip.xyz / clip.w;
    return vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size;
}

// Below, every point is relative to the layer's light (the light at the origin: a level
// kilometres from the world's origin keeps the precision its receiver plane and occluder
// points need).

// The receiver's plane (through q, normal nf) in layer `layer`'s texels: `to_tangents` takes a
// texel offset to steps along its tangents `t1`, `t2` (world, a texel `texel` long), and
// `slope` is how its distance from the light changes per texel. `ok` is false where the plane
// is seen edge-on from the light (and the rest unset).
struct ReceiverPlane {
    t1: vec3<f32>,
    t2: vec3<f32>,
    to_tangents: mat2x2<f32>,
    slope: vec2<f32>,
    ok: bool,
};

fn receiver_plane(layer: u32, q: vec3<f32>, f: vec2<f32>, nf: vec3<f32>, texel: f32, size: f32) -> ReceiverPlane {
    var r: ReceiverPlane;
    let up = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(nf.y) > 0.9);
    r.t1 = normalize(cross(nf, up)) * texel;
    r.t2 = cross(nf, r.t1);
    // The texel offsets of one step along each tangent.
    let m = mat2x2<f32>(shadow_texels(layer, q + r.t1, size) - f, shadow_texels(layer, q + r.t2, size) - f);
    let det = determinant(m);
    r.ok = abs(det) > 1e-4;
    if r.ok {
        r.to_tangents = mat2x2<f32>(vec2<f32>(m[1].y, -m[0].y), vec2<f32>(-m[1].x, m[0].x)) * (1.0 / det);
        // slope · m[k] = e[k], the distance's change along tangent k.
        let d = length(q);
        let e = vec2<f32>(length(q + r.t1), length(q + r.t2)) - d;
        let s = e * r.to_tangents;
        r.slope = clamp(s, vec2<f32>(-MAX_PLANE_SLOPE * texel), vec2<f32>(MAX_PLANE_SLOPE * texel));
    }
    return r;
}

// The surface stored at texel t (texel centre offset `at` from q's point f): its point, on the
// texel's ray through the receiver's plane.
fn stored_point(q: vec3<f32>, r: ReceiverPlane, at: vec2<f32>, stored: f32) -> vec3<f32> {
    let ab = r.to_tangents * at;
    let on_plane = q + r.t1 * ab.x + r.t2 * ab.y;
    return normalize(on_plane) * stored;
}

// Whether q lies behind the plane through the occluder's points o, ox and oy, seen from the
// light (at the origin).
fn behind(q: vec3<f32>, o: vec3<f32>, ox: vec3<f32>, oy: vec3<f32>) -> bool {
    var n_o = cross(ox - o, oy - o);
    if dot(n_o, -o) < 0.0 {
        n_o = -n_o;
    }
    return dot(q - o, n_o) < 0.0;
}

// The distance stored at texel t of layer `layer` (clamped to the layer).
fn shadow_stored(layer: u32, t: vec2<i32>, last: vec2<i32>) -> f32 {
    return textureLoad(shadow_maps, clamp(t, vec2<i32>(0), last), i32(layer), 0).x;
}

// Visibility of p (shading normal n, face normal nf) from light l, in [0, 1].
fn shadow(l: Light, p: vec3<f32>, n: vec3<f32>, nf: vec3<f32>) -> f32 {
    let size = f32(globals.shadow_size);
    let d = p - l.position.xyz;
    let dist = length(d);
    var layer = l.layers.x;
    // Texel footprint at this distance: 90° faces span 2·dist, a spot's layer 2·dist·tan(cutoff).
    var span = 2.0 * dist;
    // Six layers: the cube faces of a point light or of a spot too wide for one frustum.
    if l.layers.y == 6u {
        let a = abs(d);
        if a.x >= a.y && a.x >= a.z {
            layer += select(1u, 0u, d.x > 0.0);
        } else if a.y >= a.z {
            layer += select(3u, 2u, d.y > 0.0);
        } else {
            layer += select(5u, 4u, d.z > 0.0);
        }
    } else {
        span = 2.0 * dist * tan(l.direction.w);
    }
    let texel = span / size;
    // q relative to the light, as every point below.
    let q = p - l.position.xyz + n * texel * globals.shadow_normal_offset;
    let f = shadow_texels(layer, q, size);
    let q_dist = length(q);
    let c = vec2<i32>(floor(f));
    let last = vec2<i32>(i32(size) - 1);
    let ref_dist = q_dist - texel * globals.shadow_bias;
    var lit = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let t = clamp(c + vec2<i32>(dx, dy), vec2<i32>(0), last);
            let stored = textureLoad(shadow_maps, t, i32(layer), 0).x;
            lit += select(0.0, 1.0, stored >= ref_dist);
        }
    }
    if lit == 0.0 {
        return 0.0;
    }
    // Some taps lit, or all of them: the receiver's own texel, against its plane, may be a
    // contact shadow (all taps lit: a receiver within the bias behind a zero-thickness wall,
    // where a side wall or the ceiling meets it).
    let r = receiver_plane(layer, q, f, nf, texel, size);
    let at = vec2<f32>(c) + 0.5 - f;
    let own = shadow_stored(layer, c, last);
    let own_plane = q_dist + dot(r.slope, at);
    let rounding = 0.5 * (abs(r.slope.x) + abs(r.slope.y));
    // Nearer than the receiver's plane there, or than the receiver itself: a receiver
    // millimetres behind a zero-thickness wall that meets it (under a texel, the bias's reach)
    // sees the wall at its own texel nearer than itself but not than its plane's rounding.
    let nearer = own < own_plane - rounding || own < q_dist;
    if r.ok && nearer && own > own_plane - CONTACT_TEXELS * texel {
        // Only behind the occluder's own plane, from its texel and the nearer-valued neighbour
        // along each axis, and from the opposite ones too: a surface meeting the receiver on
        // the lit side of a crease hides the receiver's plane past the crease, not the
        // receiver.
        let zx = vec2<f32>(shadow_stored(layer, c + vec2<i32>(1, 0), last), shadow_stored(layer, c - vec2<i32>(1, 0), last));
        let zy = vec2<f32>(shadow_stored(layer, c + vec2<i32>(0, 1), last), shadow_stored(layer, c - vec2<i32>(0, 1), last));
        let sx = select(-1.0, 1.0, abs(zx.x - own) < abs(zx.y - own));
        let sy = select(-1.0, 1.0, abs(zy.x - own) < abs(zy.y - own));
        // The stored distance one texel along (k, 0) or (0, k).
        let zxk = select(zx.y, zx.x, sx > 0.0);
        let zyk = select(zy.y, zy.x, sy > 0.0);
        let zx_back = select(zx.x, zx.y, sx > 0.0);
        let zy_back = select(zy.x, zy.y, sy > 0.0);
        let o = stored_point(q, r, at, own);
        let ox = stored_point(q, r, at + vec2<f32>(sx, 0.0), zxk);
        let oy = stored_point(q, r, at + vec2<f32>(0.0, sy), zyk);
        let ox_back = stored_point(q, r, at - vec2<f32>(sx, 0.0), zx_back);
        let oy_back = stored_point(q, r, at - vec2<f32>(0.0, sy), zy_back);
        if behind(q, o, ox, oy) && behind(q, o, ox_back, oy_back) {
            return 0.0;
        }
    }
    return lit / 9.0;
}

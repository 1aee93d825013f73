//! include: grid.wgsl
// The portal walk (runtime::cpu::gates::GateLevel::walk is its CPU twin): from a in cluster ca
// the segment to b leaves each cluster through the portal of it that it crosses first (plane
// hit inside the coverage mask, going out), until it is in cb. It reads the including pass's
// `grid` (voxel size, walk limit) and `portal_words: array<u32>` (GateLevel::portal_words:
// [clusters, record base, portals], each cluster's root node, the nodes of each cluster's
// hierarchy of portal boxes, index lists, 20-word records, masks). A step descends, nearer
// child first, into the boxes the segment meets before the nearest portal found so far.

const WALK_BLOCKED: u32 = 0u;
const WALK_VISIBLE: u32 = 1u;
const WALK_LIMIT: u32 = 2u;

fn pw(i: u32) -> u32 {
    return portal_words[i];
}

fn pv(i: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(vec3<u32>(portal_words[i], portal_words[i + 1u], portal_words[i + 2u]));
}

// Whether mask cell (x, y) of record r is set (false outside the mask).
fn portal_cell(r: u32, x: f32, y: f32) -> bool {
    let w = pw(r + 7u);
    let h = pw(r + 11u);
    if !(x >= 0.0 && y >= 0.0 && x < f32(w) && y < f32(h)) {
        return false;
    }
    let k = u32(y) * w + u32(x);
    return ((pw(pw(r + 15u) + k / 32u) >> (k % 32u)) & 1u) == 1u;
}

// Whether the point q of record r's plane falls in a set mask cell or within EDGE_SLACK cells
// of one (vgate::Portal::covers; PORTAL_RECORD and EDGE_SLACK are injected from Rust).

fn portal_covers(r: u32, q: vec3<f32>) -> bool {
    let rel = q - pv(r);
    let cell = bitcast<f32>(pw(r + 3u));
    let x = dot(rel, pv(r + 8u)) / cell;
    let y = dot(rel, pv(r + 12u)) / cell;
    let e = EDGE_SLACK;
    let i = floor(x);
    let j = floor(y);
    if portal_cell(r, i, j) {
        return true;
    }
    // Off a cell's edge by more than the slack, the neighbours' cells cannot count.
    if x - i > e && x - i < 1.0 - e && y - j > e && y - j < 1.0 - e {
        return false;
    }
    return portal_cell(r, floor(x - e), floor(y))
        || portal_cell(r, floor(x + e), floor(y)) || portal_cell(r, floor(x), floor(y - e))
        || portal_cell(r, floor(x), floor(y + e));
}

// The reciprocal of d per axis, 0 on an axis it does not move along (portal_walk::inverse).
fn inverse(d: vec3<f32>) -> vec3<f32> {
    let safe = select(d, vec3<f32>(1.0), abs(d) < vec3<f32>(1e-30));
    return select(1.0 / safe, vec3<f32>(0.0), abs(d) < vec3<f32>(1e-30));
}

// Whether a + d·t for some t in [t0, t1] lies in the box [lo, hi], inv = inverse(d)
// (portal_walk::segment_box), the three slabs at once: on an axis d does not move along, a
// inside the slab.
fn segment_box(a: vec3<f32>, inv: vec3<f32>, t0: f32, t1: f32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let moves = inv != vec3<f32>(0.0);
    if any(!moves & ((a < lo) | (a > hi))) {
        return false;
    }
    let ta = (lo - a) * inv;
    let tb = (hi - a) * inv;
    let tn = select(vec3<f32>(t0), min(ta, tb), moves);
    let tf = select(vec3<f32>(t1), max(ta, tb), moves);
    return max(t0, max(tn.x, max(tn.y, tn.z))) <= min(t1, min(tf.x, min(tf.y, tf.z)));
}

// The portal of cluster c that a + d·t leaves it through first for t in [t0, t_end] (plane
// crossed going out, inside the mask), other than `last`: (bits of t, portal index), index
// NONE for none (portal_walk::GateLevel::first_exit).
//
// Two loops, as sight.wgsl's walks: the inner descends the boxes to the next leaf the segment
// meets before the nearest portal found so far, the outer tests that leaf's portals. On
// lavapipe, which runs a loop's every branch under masks, the portals' tests inside the
// descent cost every node visited.
fn first_exit(a: vec3<f32>, d: vec3<f32>, inv: vec3<f32>, c: u32, t0: f32, t_end: f32, last: u32) -> vec2<u32> {
    let len = length(d);
    let records = pw(1u);
    var best_t = t_end;
    var best = NONE;
    var stack: array<u32, PORTAL_STACK>;
    var top = 0u;
    let root = pw(3u + c);
    if root != NONE {
        stack[0] = root;
        top = 1u;
    }
    loop {
        // The next leaf: its portals' indices [first, end).
        var leaf = false;
        var first = 0u;
        var end = 0u;
        while top > 0u {
            top--;
            let node = stack[top];
            if !segment_box(a, inv, t0, best_t, pv(node), pv(node + 3u)) {
                continue;
            }
            let kind = pw(node + 7u);
            first = pw(node + 6u);
            if kind < PORTAL_INNER {
                leaf = true;
                end = first + kind;
                break;
            }
            // The nearer child last, so that it is taken first.
            let up = d[kind - PORTAL_INNER] >= 0.0;
            stack[top] = first + select(0u, PORTAL_NODE, up);
            stack[top + 1u] = first + select(PORTAL_NODE, 0u, up);
            top += 2u;
        }
        if !leaf {
            break;
        }
        for (var k = first; k < end; k++) {
            let pi = pw(k);
            let r = records + pi * PORTAL_RECORD;
            let n = pv(r + 4u) * select(1.0, -1.0, pw(r + 17u) == c);
            let den = dot(d, n);
            if pi == last || den <= 1.1920929e-7 * len {
                continue;
            }
            let t = dot(pv(r) - a, n) / den;
            if t < t0 || t > t_end || (best != NONE && t >= best_t) {
                continue;
            }
            if portal_covers(r, a + d * t) {
                best_t = t;
                best = pi;
            }
        }
    }
    return vec2<u32>(bitcast<u32>(best_t), best);
}

fn portal_walk(a: vec3<f32>, ca: u32, b: vec3<f32>, cb: u32) -> u32 {
    if ca == cb {
        return WALK_VISIBLE;
    }
    let d = b - a;
    let len = length(d);
    if !(len > 0.0) || ca >= pw(0u) || cb >= pw(0u) {
        return WALK_BLOCKED;
    }
    let slack = 1.5 * grid.voxel_size / len;
    let inv = inverse(d);
    let records = pw(1u);
    var c = ca;
    var t0 = -slack;
    var last = NONE;
    for (var step = 0u; step < grid.max_walk; step++) {
        let hit = first_exit(a, d, inv, c, t0, 1.0 + slack, last);
        let best = hit.y;
        if best == NONE {
            return WALK_BLOCKED;
        }
        let r = records + best * PORTAL_RECORD;
        let other = select(pw(r + 16u), pw(r + 17u), pw(r + 16u) == c);
        if other == cb {
            return WALK_VISIBLE;
        }
        c = other;
        t0 = bitcast<f32>(hit.x);
        last = best;
    }
    return WALK_LIMIT;
}

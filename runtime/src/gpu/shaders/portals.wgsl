//! include: grid.wgsl
// The portal walk (runtime::cpu::gates::GateLevel::walk is its CPU twin): from a in cluster ca
// the segment to b leaves each cluster through the portal of it that it crosses first (plane
// hit inside the coverage mask, going out), until it is in cb. It reads the including pass's
// `grid` (voxel size, walk limit) and `portal_words: array<u32>` (GateLevel::portal_words:
// [clusters, record base, portals], offsets, each cluster's groups of portals by neighbour with
// their boxes, index lists, 20-word records, masks). A group's portals are tested only where
// the segment meets its box.

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
// (portal_walk::segment_box).
fn segment_box(a: vec3<f32>, inv: vec3<f32>, t0: f32, t1: f32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    var near = t0;
    var far = t1;
    for (var k = 0; k < 3; k++) {
        if inv[k] == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return false;
            }
            continue;
        }
        let ta = (lo[k] - a[k]) * inv[k];
        let tb = (hi[k] - a[k]) * inv[k];
        near = max(near, min(ta, tb));
        far = min(far, max(ta, tb));
    }
    return near <= far;
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
        var best_t = 3.4e38;
        var best = NONE;
        var best_other = NONE;
        for (var gi = pw(3u + c); gi < pw(4u + c); gi += PORTAL_GROUP) {
            let t1 = select(1.0 + slack, best_t, best != NONE);
            if !segment_box(a, inv, t0, t1, pv(gi), pv(gi + 3u)) {
                continue;
            }
            let other = pw(gi + 6u);
            for (var k = pw(gi + 7u); k < pw(gi + 8u); k++) {
                let pi = pw(k);
                let r = records + pi * PORTAL_RECORD;
                let n = pv(r + 4u) * select(1.0, -1.0, pw(r + 17u) == c);
                let den = dot(d, n);
                if pi == last || den <= 1.1920929e-7 * len {
                    continue;
                }
                let t = dot(pv(r) - a, n) / den;
                if t < t0 || t > 1.0 + slack || t >= best_t {
                    continue;
                }
                if portal_covers(r, a + d * t) {
                    best_t = t;
                    best = pi;
                    best_other = other;
                }
            }
        }
        if best == NONE {
            return WALK_BLOCKED;
        }
        if best_other == cb {
            return WALK_VISIBLE;
        }
        c = best_other;
        t0 = best_t;
        last = best;
    }
    return WALK_LIMIT;
}

// The voxel walk (runtime::cpu::sight::VoxelSight is its CPU twin): whether the segment between
// a VPL and a surface point crosses open voxels alone. It reads the including pass's
// `sight_words: array<u32>` (VoxelSight::words' base: [nx, ny, nz, bricks x, y, z, offset of
// the clearances, triangle tests a walk, origin xyz (m), voxel edge (m), offsets in
// sight_extra of the closed voxels' marks, list offsets, triangle indices and corners (0: no
// lists), of the planes' counts and planes (0: none), a true end's offset (voxels)], the open
// bits 32 a word, each brick's
// chessboard distance in bricks to the nearest brick holding a closed voxel, a byte each) and
// `sight_extra: array<u32>` (its extra, a binding of its own so that each fits the storage
// binding limit: a word 0, the triangle lists (runtime::cpu::sight_triangles::ClosedTriangles)
// and the planes (runtime::cpu::sight_planes::ClosedPlanes)). A step crosses the cube of bricks that a brick's
// clearance proves open, one open voxel, or a closed voxel whose planes the segment meets
// neither of, or (with the lists) where it hits no listed triangle; with the lists the segment
// runs between the surface points themselves, each a hair off its surface
// (runtime::cpu::sight_triangles).

// SIGHT_BRICK (voxels along a brick's side) and SIGHT_BITS (VoxelSight's header words) are
// injected from runtime::cpu::sight.

fn sight_dims() -> vec3<i32> {
    return vec3<i32>(i32(sight_words[0]), i32(sight_words[1]), i32(sight_words[2]));
}

// Whether voxel v is open (false outside the grid).
fn sight_open(v: vec3<i32>) -> bool {
    let dims = sight_dims();
    if any(v < vec3<i32>(0)) || any(v >= dims) {
        return false;
    }
    let i = u32(v.x + dims.x * (v.y + dims.y * v.z));
    return ((sight_words[SIGHT_BITS + i / 32u] >> (i % 32u)) & 1u) == 1u;
}

// Point p (m) in voxel coordinates.
fn sight_voxels(p: vec3<f32>) -> vec3<f32> {
    let origin = bitcast<vec3<f32>>(vec3<u32>(sight_words[8], sight_words[9], sight_words[10]));
    return (p - origin) / bitcast<f32>(sight_words[11]);
}

// The true segment's end at surface point p (normal n), in voxel coordinates
// (VoxelSight::true_end): a hair off the surface, the header's word 18
// (sight_triangles::true_end_offset: more than 1e-3 voxels far from the origin).
fn sight_true_end(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return sight_voxels(p) + n * bitcast<f32>(sight_words[18]);
}

// Word w of listed triangle t as a float (runtime::cpu::sight_triangles::TRIANGLE_WORDS a
// triangle: its plane's normal and offset, its first corner, its two edges).
fn sight_tri(t: u32, w: u32) -> f32 {
    return bitcast<f32>(sight_extra[sight_words[15] + 13u * t + w]);
}

fn sight_tri3(t: u32, w: u32) -> vec3<f32> {
    return vec3<f32>(sight_tri(t, w), sight_tri(t, w + 1u), sight_tri(t, w + 2u));
}

// Whether segment a-b hits listed triangle t strictly between its ends: the ends on either side
// of its plane, then Möller-Trumbore (runtime::cpu::sight_triangles::hits).
fn sight_hits(t: u32, a: vec3<f32>, b: vec3<f32>) -> bool {
    let n = sight_tri3(t, 0u);
    let plane = sight_tri(t, 3u);
    if (dot(n, a) - plane) * (dot(n, b) - plane) >= 0.0 {
        return false;
    }
    let c0 = sight_tri3(t, 4u);
    let e1 = sight_tri3(t, 7u);
    let e2 = sight_tri3(t, 10u);
    let d = b - a;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if abs(det) < 1e-12 {
        return false;
    }
    let s = a - c0;
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let w = dot(d, q) / det;
    let h = dot(e2, q) / det;
    return u >= 0.0 && w >= 0.0 && u + w <= 1.0 && h > 1e-4 && h < 1.0 - 1e-4;
}

// The list of closed voxel i (its index in the grid): its id, and [first, end) of the triangle
// indices; id 0xffffffff where it has none (ClosedTriangles::list).
fn sight_list(i: u32) -> vec3<u32> {
    let marks_at = sight_words[12];
    if marks_at == 0u {
        return vec3<u32>(0xffffffffu, 0u, 0u);
    }
    let mask = sight_extra[marks_at + 2u * (i / 32u)];
    let bit = 1u << (i % 32u);
    if (mask & bit) == 0u {
        return vec3<u32>(0xffffffffu, 0u, 0u);
    }
    let k = sight_extra[marks_at + 2u * (i / 32u) + 1u] + countOneBits(mask & (bit - 1u));
    // The list packed: its start in the indices (high 24 bits), its length less one (low 8);
    // a voxel whose list overflowed (255 + 1 entries) blocks (LIST_MAX).
    let id = sight_extra[sight_words[13] + k];
    let len = (id & 0xffu) + 1u;
    if len > 255u {
        return vec3<u32>(0xffffffffu, 0u, 0u);
    }
    return vec3<u32>(id, id >> 8u, (id >> 8u) + len);
}

// The closed voxels' planes (runtime::cpu::sight_planes::ClosedPlanes), where the words carry
// them: header words 16 and 17 hold the offsets of the closed voxels counted before each block
// of 256 voxels and of the planes: a word per closed voxel in voxel order (kind 0: it blocks;
// 1: a plane; 2: the place of its two plane words, from word 17's offset), then the pairs. The
// plane words of closed voxel i (its index in the grid; kind 0 in the second: one plane), found
// by its rank among the closed voxels: its block's count and the open bits' words before
// it in the block.
fn sight_plane_words(i: u32) -> vec2<u32> {
    let block = i / 256u;
    var rank = sight_extra[sight_words[16] + block];
    for (var w = block * 8u; w < i / 32u; w++) {
        rank += countOneBits(~sight_words[SIGHT_BITS + w]);
    }
    rank += countOneBits(~sight_words[SIGHT_BITS + i / 32u] & ((1u << (i % 32u)) - 1u));
    let planes_at = sight_words[17];
    let own = sight_extra[planes_at + rank];
    if (own & 3u) == 2u {
        let at = planes_at + (own >> 2u);
        return vec2<u32>(sight_extra[at], sight_extra[at + 1u]);
    }
    return vec2<u32>(own, 0u);
}

// Plane word w decoded (sight_planes::decode): the unit normal (octahedral, 8 + 8 bits) and
// the offset from the voxel's centre (14 bits in ±1 voxel); its kind is w's low two bits.
fn sight_plane(w: u32) -> vec4<f32> {
    let f = vec3<f32>(vec3<u32>((w >> 2u) & 0xffu, (w >> 10u) & 0xffu, w >> 18u))
        / vec3<f32>(255.0, 255.0, 16383.0) * 2.0 - 1.0;
    let z = 1.0 - abs(f.x) - abs(f.y);
    let t = max(-z, 0.0);
    let n = normalize(vec3<f32>(f.x - t * sign(f.x), f.y - t * sign(f.y), z));
    return vec4<f32>(n, f.z);
}

// How near a segment may come to a plane before it meets it (sight_planes::PLANE_FIT + 1e-3).
const SIGHT_PLANE_TOL: f32 = 0.051;

// Whether the walk's segment r (r.a + t r.d, t in [0, 1]) passes closed voxel v (index i) on
// its planes: inside the voxel it comes within the fit of neither plane's patch
// (sight_planes::passes).
fn sight_planes_pass(i: u32, v: vec3<i32>, r: SightRay) -> bool {
    let words = sight_plane_words(i);
    if (words.x & 3u) == 0u {
        return false;
    }
    let c = vec3<f32>(v) + 0.5;
    let t0 = (c - 0.5 - r.a) * r.inv;
    let t1 = (c + 0.5 - r.a) * r.inv;
    let tn = select(vec3<f32>(-3.4e38), min(t0, t1), r.moves);
    let tf = select(vec3<f32>(3.4e38), max(t0, t1), r.moves);
    let lo = max(max(tn.x, max(tn.y, tn.z)), 0.0);
    let hi = min(min(tf.x, min(tf.y, tf.z)), 1.0);
    let p0 = r.a + r.d * lo - c;
    let p1 = r.a + r.d * max(hi, lo) - c;
    return sight_plane_passed(words.x, words.y, p0, p1)
        && ((words.y & 3u) == 0u || sight_plane_passed(words.y, words.x, p0, p1));
}

// Whether segment p0 → p1 (relative to the voxel's centre) stays clear of the patch of plane
// word w, whose voxel's other plane word is o (kind 0: none).
fn sight_plane_passed(w: u32, o: u32, p0: vec3<f32>, p1: vec3<f32>) -> bool {
    let p = sight_plane(w);
    let s0 = dot(p.xyz, p0) - p.w;
    let s1 = dot(p.xyz, p1) - p.w;
    if (s0 > SIGHT_PLANE_TOL && s1 > SIGHT_PLANE_TOL)
        || (s0 < -SIGHT_PLANE_TOL && s1 < -SIGHT_PLANE_TOL) {
        return true;
    }
    let kind = w & 3u;
    if kind < 2u || (o & 3u) == 0u {
        return false;
    }
    // The part of the segment within the fit of the plane, and whether it reaches the patch's
    // side of the other plane there.
    var ta = 0.0;
    var tb = 1.0;
    if abs(s0 - s1) >= 1e-6 {
        let x = (s0 - SIGHT_PLANE_TOL) / (s0 - s1);
        let y = (s0 + SIGHT_PLANE_TOL) / (s0 - s1);
        ta = clamp(min(x, y), 0.0, 1.0);
        tb = clamp(max(x, y), 0.0, 1.0);
    }
    let side = select(-1.0, 1.0, kind == 2u);
    let q = sight_plane(o);
    let oa = dot(q.xyz, p0 + (p1 - p0) * ta) - q.w;
    let ob = dot(q.xyz, p0 + (p1 - p0) * tb) - q.w;
    return max(side * oa, side * ob) < -SIGHT_PLANE_TOL;
}

// Whether point x (voxel coordinates) in closed voxel v lies farther than the fit from both
// its planes, where it has planes (sight_planes::clear_of).
fn sight_clear_of_planes(v: vec3<i32>, x: vec3<f32>) -> bool {
    let dims = sight_dims();
    if any(v < vec3<i32>(0)) || any(v >= dims) {
        return false;
    }
    let words = sight_plane_words(u32(v.x + dims.x * (v.y + dims.y * v.z)));
    if (words.x & 3u) == 0u {
        return false;
    }
    let y = x - (vec3<f32>(v) + 0.5);
    let p = sight_plane(words.x);
    let q = sight_plane(words.y);
    return abs(dot(p.xyz, y) - p.w) > SIGHT_PLANE_TOL
        && ((words.y & 3u) == 0u || abs(dot(q.xyz, y) - q.w) > SIGHT_PLANE_TOL);
}

// An open voxel's point off surface point p (normal n), in voxel coordinates; w = 0: no open
// voxel near, where the bake knows nothing (VoxelSight::end). With `planes` (the words must
// carry them), first 0.3 voxels off the surface where that point is open or clear of its
// closed voxel's planes (VoxelSight::end_with; sight_planes::END_PLANES_OFFSET_VOXELS).
fn sight_end(p: vec3<f32>, n: vec3<f32>, planes: bool) -> vec4<f32> {
    let q = sight_voxels(p);
    if planes {
        let s = q + n * 0.3;
        let v = vec3<i32>(floor(s));
        if sight_open(v) || sight_clear_of_planes(v, s) {
            return vec4<f32>(s, 1.0);
        }
    }
    // END_OFFSETS_VOXELS: 1.25, 2.25, 3.25.
    for (var k = 0; k < 3; k++) {
        let s = q + n * (1.25 + f32(k));
        if sight_open(vec3<i32>(floor(s))) {
            return vec4<f32>(s, 1.0);
        }
    }
    let out = q + n;
    let base = vec3<i32>(floor(out));
    var best = vec4<f32>(0.0);
    var best_d2 = 3.4e38;
    for (var dz = -1; dz <= 1; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let v = base + vec3<i32>(dx, dy, dz);
                let centre = vec3<f32>(v) + 0.5;
                let d2 = dot(centre - out, centre - out);
                if sight_open(v) && dot(centre - q, n) > 0.0 && d2 < best_d2 {
                    best_d2 = d2;
                    best = vec4<f32>(centre, 1.0);
                }
            }
        }
    }
    return best;
}

// The segment a → b (voxel coordinates) as the walks step along it: d = b − a, the axes it
// moves along and up, 1 / d on them (0 elsewhere), the voxel holding b.
struct SightRay {
    a: vec3<f32>,
    d: vec3<f32>,
    inv: vec3<f32>,
    end: vec3<i32>,
    moves: vec3<bool>,
    up: vec3<bool>,
};

fn sight_ray(a: vec3<f32>, b: vec3<f32>) -> SightRay {
    let d = b - a;
    let moves = d != vec3<f32>(0.0);
    let inv = select(vec3<f32>(0.0), 1.0 / select(vec3<f32>(1.0), d, moves), moves);
    return SightRay(a, d, inv, vec3<i32>(floor(b)), moves, d > vec3<f32>(0.0));
}

// The walk's step from the box lo..hi of voxels (v within it) that it crossed: w 1 where the
// box holds the end voxel or the segment ends in it, else xyz the voxel it enters.
fn sight_next(v: vec3<i32>, lo: vec3<i32>, hi: vec3<i32>, r: SightRay) -> vec4<i32> {
    if all(r.end >= lo) && all(r.end <= hi) {
        return vec4<i32>(v, 1);
    }
    let face = select(vec3<f32>(lo), vec3<f32>(hi + 1), r.up);
    let t = select(vec3<f32>(3.4e38), (face - r.a) * r.inv, r.moves);
    let te = min(t.x, min(t.y, t.z));
    if te >= 1.0 {
        return vec4<i32>(v, 1);
    }
    var across = vec3<bool>(false, false, true);
    if t.x <= t.y && t.x <= t.z {
        across = vec3<bool>(true, false, false);
    } else if t.y <= t.z {
        across = vec3<bool>(false, true, false);
    }
    let inside = clamp(vec3<i32>(floor(r.a + r.d * te)), lo, hi);
    return vec4<i32>(select(inside, select(lo - 1, hi + 1, r.up), across), 0);
}

// How sight_march ended (x of its result).
const MARCH_CLEAR: u32 = 0u;
const MARCH_BLOCKED: u32 = 1u;
const MARCH_CLOSED: u32 = 2u;

// The walks' march from voxel *v, a step each (*step counts them, up to `most`), through the
// cubes of bricks that a brick's clearance proves open and through open voxels: x MARCH_CLEAR
// where it reaches the end, MARCH_BLOCKED where it leaves the grid or runs out of steps,
// MARCH_CLOSED at a closed voxel (*v, y its index), its step not yet counted.
//
// A loop of its own, the closed voxel's test after it (sight_clear, sight_clear_lists): on a
// CPU's SIMD lanes (lavapipe) a branch runs for every lane under a mask, so a closed voxel's
// planes or triangles tested inside the march cost every step their price (e2m3's hall, the
// fast setting: the walks' pass 3.6× as long as with every closed voxel blocking).
fn sight_march(r: SightRay, v: ptr<function, vec3<i32>>, step: ptr<function, u32>, most: u32) -> vec2<u32> {
    let dims = sight_dims();
    let bricks = vec3<i32>(i32(sight_words[3]), i32(sight_words[4]), i32(sight_words[5]));
    let clear_at = sight_words[6];
    for (; *step < most; *step += 1u) {
        let at = *v;
        if any(at < vec3<i32>(0)) || any(at >= dims) {
            return vec2<u32>(MARCH_BLOCKED, 0u);
        }
        let brick = at / SIGHT_BRICK;
        let k = u32(brick.x + bricks.x * (brick.y + bricks.y * brick.z));
        let c = i32((sight_words[clear_at + k / 4u] >> (8u * (k % 4u))) & 0xffu);
        var lo = at;
        var hi = at;
        if c > 0 {
            lo = (brick - (c - 1)) * SIGHT_BRICK;
            hi = (brick + c) * SIGHT_BRICK - 1;
        } else {
            let i = u32(at.x + dims.x * (at.y + dims.y * at.z));
            if ((sight_words[SIGHT_BITS + i / 32u] >> (i % 32u)) & 1u) == 0u {
                return vec2<u32>(MARCH_CLOSED, i);
            }
        }
        let next = sight_next(at, lo, hi, r);
        if next.w != 0 {
            return vec2<u32>(MARCH_CLEAR, 0u);
        }
        *v = next.xyz;
    }
    return vec2<u32>(MARCH_BLOCKED, 0u);
}

// Whether the segment a → b (voxel coordinates) crosses open voxels alone, or also closed ones
// whose planes it meets neither of with `planes` (the words must carry them; VoxelSight::clear
// with Closed::Blocks or Closed::Planes, step for step; sight_clear_lists is the walk with the
// triangles, a function of its own so that a pipeline without them runs none of their code).
fn sight_clear(a: vec3<f32>, b: vec3<f32>, planes: bool) -> bool {
    let r = sight_ray(a, b);
    let dims = sight_dims();
    let most = u32(dims.x + dims.y + dims.z + 1);
    var v = vec3<i32>(floor(a));
    var step = 0u;
    loop {
        let m = sight_march(r, &v, &step, most);
        if m.x != MARCH_CLOSED {
            return m.x == MARCH_CLEAR;
        }
        if !(planes && sight_planes_pass(m.y, v, r)) {
            return false;
        }
        step++;
        let next = sight_next(v, v, v, r);
        if next.w != 0 {
            return true;
        }
        v = next.xyz;
    }
    return false;
}

// Whether the segment a → b (voxel coordinates) crosses open voxels, or closed ones whose listed
// triangles it misses (VoxelSight::clear with the lists, step for step; each list entry read
// counts a step, as the twin's). As sight_clear: the march, then the closed voxel's list.
fn sight_clear_lists(a: vec3<f32>, b: vec3<f32>) -> bool {
    let r = sight_ray(a, b);
    let dims = sight_dims();
    let refs_at = sight_words[14];
    // List entries the walk may still read, the last list read whole, the last two triangles
    // tested (runtime::cpu::sight_triangles::WalkTests).
    var left = sight_words[7];
    var passed = 0xffffffffu;
    var last0 = 0xffffffffu;
    var last1 = 0xffffffffu;
    let most = u32(dims.x + dims.y + dims.z + 1) + left;
    var v = vec3<i32>(floor(a));
    var step = 0u;
    loop {
        let m = sight_march(r, &v, &step, most);
        if m.x != MARCH_CLOSED {
            return m.x == MARCH_CLEAR;
        }
        // The closed voxel's lookup is a step, each entry of its list one more.
        step++;
        let found = sight_list(m.y);
        if found.x == 0xffffffffu || (found.x != passed && left == 0u) {
            return false;
        }
        if found.x != passed {
            for (var e = found.y; e < found.z; e++) {
                if step >= most || left == 0u {
                    return false;
                }
                left -= 1u;
                step++;
                let t = sight_extra[refs_at + e];
                if t != last0 && t != last1 {
                    last1 = last0;
                    last0 = t;
                    if sight_hits(t, a, b) {
                        return false;
                    }
                }
            }
            passed = found.x;
        }
        let next = sight_next(v, v, v, r);
        if next.w != 0 {
            return true;
        }
        v = next.xyz;
    }
    return false;
}

// Whether light passes between surface points a (normal na) and b (normal nb): with
// `triangles`, the walk along the segment between them, each end a hair off its surface,
// through the closed voxels whose listed triangles it misses (VoxelSight::visible); else the
// walk between their ends off the surfaces, every closed voxel blocking or passed on its planes
// with `planes` (VoxelSight::visible_off_surfaces). Unoccluded when either has no open voxel
// near.
fn voxel_sight(
    a: vec3<f32>,
    na: vec3<f32>,
    b: vec3<f32>,
    nb: vec3<f32>,
    triangles: bool,
    planes: bool,
) -> bool {
    let x = sight_end(a, na, planes && !triangles);
    let y = sight_end(b, nb, planes && !triangles);
    if x.w == 0.0 || y.w == 0.0 {
        return true;
    }
    if triangles {
        return sight_clear_lists(sight_true_end(a, na), sight_true_end(b, nb));
    }
    return sight_clear(x.xyz, y.xyz, planes);
}

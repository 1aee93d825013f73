use super::*;

/// A small xorshift for the random cases.
struct Rng(u64);

impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn v(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f()) * (hi - lo) + lo
    }
}

/// Whether segment `a`–`b` crosses triangle `t` within the closed voxel `v` (sampled finely
/// along the segment: a sign change of the triangle's plane between samples inside the
/// voxel, at a point inside the triangle).
fn hits_in_voxel(t: &[Vec3; 3], v: IVec3, a: Vec3, b: Vec3) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let inside_box = |p: Vec3| p.cmpge(v.as_vec3()).all() && p.cmple(v.as_vec3() + 1.0).all();
    let steps = 4000;
    let s = |p: Vec3| n.dot(p - t[0]);
    for k in 0..steps {
        let (p, q) = (
            a + (b - a) * (k as f32 / steps as f32),
            a + (b - a) * ((k + 1) as f32 / steps as f32),
        );
        if s(p) * s(q) > 0.0 || !inside_box(p) {
            continue;
        }
        let x = p + (q - p) * (s(p) / (s(p) - s(q))).clamp(0.0, 1.0);
        let edge = |i: usize| (t[(i + 1) % 3] - t[i]).cross(x - t[i]).dot(n) >= 0.0;
        if edge(0) && edge(1) && edge(2) {
            return true;
        }
    }
    false
}

fn planes_of(v: IVec3, tris: &[[Vec3; 3]]) -> Option<[Option<Plane>; 2]> {
    let [p, q] = fit(v, tris);
    (p != NONE).then(|| [decode(p), decode(q)])
}

#[test]
fn a_plane_word_holds_the_normal_and_offset_within_the_fit() {
    let mut r = Rng(7);
    for _ in 0..2000 {
        let n = (r.v(-1.0, 1.0)).normalize_or(Vec3::Y);
        let off = r.f() * 1.6 - 0.8;
        let p = decode(encode(n, off, WHOLE)).expect("a plane");
        // Over the voxel (corners within √3/2 of its centre) the planes part by less than
        // the fit.
        for k in 0..8 {
            let x = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32) - 0.5;
            assert!(
                (p.at(x) - (n.dot(x) - off)).abs() < 0.5 * PLANE_FIT,
                "{n} {off}"
            );
        }
    }
    assert_eq!(decode(encode(Vec3::Z, 0.0, WHOLE) & !3), None);
}

#[test]
fn a_door_jamb_passes_a_segment_beyond_its_edge_and_blocks_one_into_it() {
    // Voxel (0, 0, 0); a wall's face z = 0.55 for x < 0.7 and the jamb's face x = 0.7 for
    // z > 0.55 (the wall's material at x < 0.7, 0.55 < z): a convex corner.
    let v = IVec3::ZERO;
    let tris = [
        [
            Vec3::new(-3.0, -3.0, 0.55),
            Vec3::new(0.7, -3.0, 0.55),
            Vec3::new(0.7, 3.0, 0.55),
        ],
        [
            Vec3::new(0.7, -3.0, 0.55),
            Vec3::new(0.7, 3.0, 0.55),
            Vec3::new(0.7, -3.0, 3.0),
        ],
    ];
    let p = planes_of(v, &tris).expect("two planes");
    assert!(p[0].is_some() && p[1].is_some());
    // Below the wall's face and right of the jamb's: the corner's outside.
    let (a, b) = (Vec3::new(1.5, 0.5, 0.4), Vec3::new(0.75, 0.5, -0.2));
    assert!(!hits_in_voxel(&tris[0], v, a, b) && !hits_in_voxel(&tris[1], v, a, b));
    assert!(passes(p, v, a, b - a));
    // Through the jamb's face above the wall's.
    let (a, b) = (Vec3::new(1.5, 0.5, 0.9), Vec3::new(0.2, 0.5, 0.8));
    assert!(hits_in_voxel(&tris[1], v, a, b));
    assert!(!passes(p, v, a, b - a));
    // The whole planes (no patch sides) would block the first: the jamb's plane extends
    // below the wall's face.
    let whole = p.map(|q| q.map(|q| Plane { kind: WHOLE, ..q }));
    let (a, b) = (Vec3::new(1.5, 0.5, 0.4), Vec3::new(0.5, 0.5, -0.1));
    assert!(passes(p, v, a, b - a) && !passes(whole, v, a, b - a));
    // Three planes: the voxel blocks.
    let third = [
        Vec3::new(-3.0, 0.3, -3.0),
        Vec3::new(3.0, 0.3, -3.0),
        Vec3::new(0.0, 0.3, 3.0),
    ];
    assert_eq!(planes_of(v, &[tris[0], tris[1], third]), None);
    // A point clear of both planes may start a walk; one on a plane may not.
    assert!(clear_of(p, v, Vec3::new(0.9, 0.5, 0.2)));
    assert!(!clear_of(p, v, Vec3::new(0.72, 0.5, 0.9)));
}

#[test]
fn no_segment_that_hits_a_triangle_inside_the_voxel_passes_it() {
    let mut r = Rng(0x5eed);
    let v = IVec3::new(3, -2, 5);
    let c = v.as_vec3() + 0.5;
    let (mut hit, mut passed) = (0, 0);
    for case in 0..3000 {
        // One to three triangles through the voxel: a flat wall cut in two, a fold (a
        // corner), or a random sheet; some slightly bent (a column's facets).
        let kind = case % 3;
        let n = r.v(-1.0, 1.0).normalize_or(Vec3::X);
        let u = n.any_orthonormal_vector();
        let w = n.cross(u);
        let o = c + n * (r.f() - 0.5) * 0.8;
        let bend = if case % 2 == 0 { 0.0 } else { 0.03 };
        let mut tris = vec![
            [o - u * 3.0 - w * 3.0, o + u * 3.0 - w * 3.0, o + w * 3.0],
            [
                o + u * 3.0 - w * 3.0,
                o + u * 3.0 + w * 3.0 + n * bend,
                o + w * 3.0,
            ],
        ];
        if kind == 1 {
            // A fold along the line o + t·w at a random angle.
            let m = (n + u * (r.f() * 4.0 - 2.0)).normalize();
            tris = vec![
                [o - w * 3.0, o + w * 3.0, o - u * 3.0],
                [o - w * 3.0, o + w * 3.0, o + m * 3.0],
            ];
        } else if kind == 2 {
            tris.push([c + r.v(-1.5, 1.5), c + r.v(-1.5, 1.5), c + r.v(-1.5, 1.5)]);
        }
        let Some(p) = planes_of(v, &tris) else {
            continue;
        };
        for _ in 0..20 {
            let (a, b) = (c + r.v(-1.5, 1.5), c + r.v(-1.5, 1.5));
            let hits = tris.iter().any(|t| hits_in_voxel(t, v, a, b));
            let through = passes(p, v, a, b - a);
            assert!(!(hits && through), "case {case}: {tris:?} {a} {b}");
            hit += u32::from(hits);
            passed += u32::from(through);
        }
    }
    // The cases mean something: many hit, many pass.
    assert!(hit > 5000 && passed > 5000, "{hit} hit, {passed} passed");
}

#[test]
fn the_table_holds_a_word_per_closed_voxel_and_the_pairs_after_them() {
    use visgate_formats::vgate::GridMeta;
    // A 4³ grid of 1 m voxels; voxel (1, 1, 1) holds a fold (two planes), voxel (2, 1, 1)
    // one plane, (0, 0, 0) no triangle; the rest are open.
    let grid = GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 1.0,
        dims: [4, 4, 4],
    };
    let tris = [
        [
            Vec3::new(1.5, 1.2, 1.0),
            Vec3::new(1.5, 1.2, 2.0),
            Vec3::new(1.0, 1.2, 1.5),
        ],
        [
            Vec3::new(1.5, 1.2, 1.0),
            Vec3::new(1.5, 1.2, 2.0),
            Vec3::new(1.5, 1.9, 1.5),
        ],
        [
            Vec3::new(2.6, 1.1, 1.1),
            Vec3::new(2.6, 1.9, 1.1),
            Vec3::new(2.6, 1.5, 1.9),
        ],
    ];
    let closed = [IVec3::ZERO, IVec3::new(1, 1, 1), IVec3::new(2, 1, 1)];
    let open = |v: IVec3| !closed.contains(&v);
    let lists = ClosedTriangles::new(&grid, open, &tris);
    let mut words = vec![0u32; 2];
    for i in 0..64 {
        if open(voxel_of(i, IVec3::splat(4))) {
            words[i / 32] |= 1 << (i % 32);
        }
    }
    let planes = ClosedPlanes::new(IVec3::splat(4), &words, &lists);
    assert_eq!(planes.voxels(), 3);
    assert_eq!(planes.counts(), [1, 1]);
    let index = |v: IVec3| (v.x + 4 * (v.y + 4 * v.z)) as usize;
    assert_eq!(planes.of(0, &words), None);
    let fold = planes.of(index(closed[1]), &words).expect("two planes");
    assert!(fold.iter().all(Option::is_some));
    let wall = planes.of(index(closed[2]), &words).expect("a plane");
    assert!(wall[0].is_some_and(|p| p.normal.x.abs() > 0.99) && wall[1].is_none());
    // A word per closed voxel, then the pair.
    let (w, at) = planes.words(100);
    assert_eq!(at, [100, 101]);
    assert_eq!(w.len(), 1 + 3 + 2);
    assert_eq!(w[1 + 1] & 3, PAIR);
    assert_eq!((w[1 + 1] >> 2) as usize, 3);
}

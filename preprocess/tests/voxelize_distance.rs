//! Stages 2 and 4: conservative voxelization and the exact distance transform.

use glam::{DVec3, Vec3};
use visgate_formats::vgate::Resolution;
use visgate_preprocess::BakeError;
use visgate_preprocess::distance::squared_distance;
use visgate_preprocess::voxelize::{grid_for, tri_box_overlap, voxelize};
use visgate_scenes::Builtin;

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn v(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.f() - 0.5, self.f() - 0.5, self.f() - 0.5) * s
    }
}

#[test]
fn tri_box_overlap_is_true_whenever_a_point_of_the_triangle_is_in_the_box() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..4000 {
        let c = rng.v(2.0);
        let h = 0.1 + rng.f() * 0.4;
        let tri = [rng.v(3.0), rng.v(3.0), rng.v(3.0)];
        let overlap = tri_box_overlap(c, h, tri);
        let mut inside = false;
        for i in 0..=20 {
            for j in 0..=(20 - i) {
                let (a, b) = (i as f64 / 20.0, j as f64 / 20.0);
                let p = tri[0] + (tri[1] - tri[0]) * a + (tri[2] - tri[0]) * b;
                inside |= ((p - c).abs().max_element()) < h;
            }
        }
        if inside {
            assert!(
                overlap,
                "a point of {tri:?} is in the box at {c} ± {h}, but no overlap"
            );
            hits += 1;
        } else if !overlap {
            misses += 1;
        }
    }
    assert!(
        hits > 100 && misses > 100,
        "the sweep must cover both cases: {hits} hits, {misses} misses"
    );
    // A triangle lying exactly on a face of the box touches it (closed box).
    let face = [
        DVec3::new(-1.0, 0.5, -1.0),
        DVec3::new(1.0, 0.5, -1.0),
        DVec3::new(0.0, 0.5, 1.0),
    ];
    assert!(tri_box_overlap(DVec3::ZERO, 0.5, face));
    assert!(!tri_box_overlap(DVec3::ZERO, 0.49, face));
}

fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> [[Vec3; 3]; 2] {
    [[a, b, c], [a, c, d]]
}

/// A zero-thickness closed cube of side `s` at `o`, plus a far triangle that widens the grid
/// so there is outside space around the cube.
fn paper_cube(o: Vec3, s: f32) -> Vec<[Vec3; 3]> {
    let p = |x: f32, y: f32, z: f32| o + Vec3::new(x, y, z) * s;
    let mut t = Vec::new();
    t.extend(quad(
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(1., 1., 0.),
        p(0., 1., 0.),
    ));
    t.extend(quad(
        p(0., 0., 1.),
        p(1., 0., 1.),
        p(1., 1., 1.),
        p(0., 1., 1.),
    ));
    t.extend(quad(
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(1., 0., 1.),
        p(0., 0., 1.),
    ));
    t.extend(quad(
        p(0., 1., 0.),
        p(1., 1., 0.),
        p(1., 1., 1.),
        p(0., 1., 1.),
    ));
    t.extend(quad(
        p(0., 0., 0.),
        p(0., 1., 0.),
        p(0., 1., 1.),
        p(0., 0., 1.),
    ));
    t.extend(quad(
        p(1., 0., 0.),
        p(1., 1., 0.),
        p(1., 1., 1.),
        p(1., 0., 1.),
    ));
    t.push([
        o - Vec3::splat(s),
        o - Vec3::splat(s) + Vec3::X * 0.01,
        o - Vec3::splat(s) + Vec3::Y * 0.01,
    ]);
    t.push([
        o + Vec3::splat(2.0 * s),
        o + Vec3::splat(2.0 * s) - Vec3::X * 0.01,
        o + Vec3::splat(2.0 * s) - Vec3::Y * 0.01,
    ]);
    t
}

fn bounds(tris: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in tris {
        for p in t {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
    }
    (lo, hi)
}

/// Flood fill of empty voxels with 26-connectivity (the most permissive: if it does not leak,
/// nothing does).
fn reach26(dims: [u32; 3], solid: &[bool], from: [usize; 3]) -> Vec<bool> {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let idx = |x: usize, y: usize, z: usize| x + nx * (y + ny * z);
    let mut seen = vec![false; solid.len()];
    let start = idx(from[0], from[1], from[2]);
    assert!(!solid[start], "the seed is solid");
    seen[start] = true;
    let mut stack = vec![from];
    while let Some([x, y, z]) = stack.pop() {
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (a, b, c) = (x as i64 + dx, y as i64 + dy, z as i64 + dz);
                    if a < 0 || b < 0 || c < 0 || a >= nx as i64 || b >= ny as i64 || c >= nz as i64
                    {
                        continue;
                    }
                    let i = idx(a as usize, b as usize, c as usize);
                    if !solid[i] && !seen[i] {
                        seen[i] = true;
                        stack.push([a as usize, b as usize, c as usize]);
                    }
                }
            }
        }
    }
    seen
}

#[test]
fn walls_thinner_than_a_voxel_do_not_leak_at_any_resolution_or_offset() {
    let mut rng = Rng(42);
    for res in [8u32, 12, 16, 23, 32, 47, 64] {
        for _ in 0..4 {
            let o = Vec3::new(rng.f() as f32, rng.f() as f32, rng.f() as f32) * 3.0;
            let tris = paper_cube(o, 1.0);
            let meta =
                grid_for(bounds(&tris), Resolution::LongestAxisVoxels(res), 1 << 30).expect("grid");
            let g = voxelize(meta, &tris);
            let cell = |p: Vec3| -> [usize; 3] {
                std::array::from_fn(|a| ((p[a] - meta.origin_m[a]) / meta.voxel_size_m) as usize)
            };
            let inside = cell(o + Vec3::splat(0.5));
            if g.solid[meta.index(inside.map(|c| c as u32))] {
                continue; // at 8 voxels the cube's inside can be all wall
            }
            let seen = reach26(meta.dims, &g.solid, inside);
            let outside = cell(o - Vec3::splat(0.5));
            assert!(
                !seen[meta.index(outside.map(|c| c as u32))],
                "res {res}, cube at {o}: the inside reaches the outside"
            );
        }
    }
}

#[test]
fn the_grid_border_is_solid_and_a_room_is_empty_inside() {
    let scene = Builtin::EmptyBox.scene().expect("scene");
    let tris: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    for res in [16u32, 32, 64] {
        let meta = grid_for(
            scene.static_bounds().expect("bounds"),
            Resolution::LongestAxisVoxels(res),
            1 << 30,
        )
        .expect("grid");
        let g = voxelize(meta, &tris);
        let [nx, ny, nz] = meta.dims.map(|d| d as usize);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    if x == 0 || y == 0 || z == 0 || x == nx - 1 || y == ny - 1 || z == nz - 1 {
                        assert!(g.solid[x + nx * (y + ny * z)], "border voxel not solid");
                    }
                }
            }
        }
        // The room is 4 × 3 × 4 m inside 0.2 m walls: the empty component around its centre
        // fills nearly 48 m³, less at most one layer of voxels on each face (conservative
        // walls). (The insides of the thick walls are separate, enclosed voids.)
        let vs = f64::from(meta.voxel_size_m);
        let centre: [usize; 3] = std::array::from_fn(|a| {
            ((([2.0f32, 1.5, 2.0][a]) - meta.origin_m[a]) / meta.voxel_size_m) as usize
        });
        let room = reach26(meta.dims, &g.solid, centre);
        let empty = room.iter().filter(|&&r| r).count() as f64 * vs.powi(3);
        let shell = 2.0 * (4.0 * 3.0 + 4.0 * 3.0 + 4.0 * 4.0) * vs;
        assert!(
            empty <= 48.0 + 1e-9 && empty >= 48.0 - 1.01 * shell,
            "res {res}: {empty} m³ empty"
        );
        let longest = meta.dims.iter().max().copied().unwrap_or(0);
        assert_eq!(longest, res + 2, "res {res}: dims {:?}", meta.dims);
    }
}

#[test]
fn bad_resolutions_are_refused_before_allocating() {
    let b = (Vec3::ZERO, Vec3::new(10.0, 5.0, 3.0));
    for r in [0u32, 7, 2049] {
        assert!(matches!(
            grid_for(b, Resolution::LongestAxisVoxels(r), u64::MAX),
            Err(BakeError::Param(_))
        ));
    }
    for s in [0.0f32, -1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            grid_for(b, Resolution::VoxelSizeM(s), u64::MAX),
            Err(BakeError::Param(_))
        ));
    }
    let e = grid_for(b, Resolution::VoxelSizeM(1e-4), 16 << 30).expect_err("too large");
    assert!(matches!(e, BakeError::TooLarge { .. }));
    assert!(e.to_string().contains("GiB"), "{e}");
    let flat = (Vec3::ONE, Vec3::ONE);
    assert!(matches!(
        grid_for(flat, Resolution::LongestAxisVoxels(64), u64::MAX),
        Err(BakeError::Param(_))
    ));
    // A plane (a single ground quad, one wall) is refused as flat, naming the axis; a thin
    // level (a 1 km ground with a metre of relief) is not.
    let plane = (Vec3::new(-5.0, 2.0, 0.0), Vec3::new(5.0, 2.0, 10.0));
    let e = grid_for(plane, Resolution::LongestAxisVoxels(128), u64::MAX).expect_err("flat");
    assert!(matches!(e, BakeError::Flat { axis: 'y', .. }), "{e:?}");
    assert!(e.to_string().contains("10.00 x 0.00 x 10.00 m"), "{e}");
    let thin = (Vec3::ZERO, Vec3::new(1000.0, 1.0, 1000.0));
    assert!(grid_for(thin, Resolution::LongestAxisVoxels(128), u64::MAX).is_ok());
    let ok = grid_for(b, Resolution::VoxelSizeM(0.5), u64::MAX).expect("grid");
    assert_eq!(ok.dims, [22, 12, 8]);
}

#[test]
fn distance_transform_equals_brute_force() {
    let mut rng = Rng(7);
    for (dims, density) in [
        ([1u32, 1, 1], 0.5),
        ([9, 1, 1], 0.2),
        ([7, 5, 3], 0.1),
        ([12, 9, 7], 0.05),
        ([16, 16, 16], 0.01),
        ([5, 6, 7], 0.0),
    ] {
        let n = dims.iter().product::<u32>() as usize;
        let solid: Vec<bool> = (0..n).map(|_| rng.f() < density).collect();
        let d = squared_distance(dims, &solid);
        let [nx, ny, _] = dims.map(|d| d as usize);
        let coords = |i: usize| [i % nx, (i / nx) % ny, i / (nx * ny)];
        let solids: Vec<[usize; 3]> = (0..n).filter(|&i| solid[i]).map(coords).collect();
        for (i, &di) in d.iter().enumerate() {
            let c = coords(i);
            let brute = solids
                .iter()
                .map(|s| {
                    (0..3)
                        .map(|a| (s[a] as i64 - c[a] as i64).pow(2) as u64)
                        .sum::<u64>()
                })
                .min();
            match brute {
                Some(b) => assert_eq!(di, b, "dims {dims:?} voxel {c:?}"),
                None => assert!(di > 1 << 40, "no solid voxel: distance must be 'infinite'"),
            }
        }
    }
}

/// Every voxel of the grid tested against every triangle, with the border ring solid and a hit
/// in the ring moved to the first voxel inside (as `voxelize` documents).
fn voxelize_brute_force(meta: visgate_formats::vgate::GridMeta, tris: &[[Vec3; 3]]) -> Vec<bool> {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let size = f64::from(meta.voxel_size_m);
    let half = 0.5 * size * (1.0 + 1e-9);
    let origin = Vec3::from(meta.origin_m).as_dvec3();
    let mut solid = vec![false; nx * ny * nz];
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let c = origin + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * size;
                let ring = x == 0 || y == 0 || z == 0 || x == nx - 1 || y == ny - 1 || z == nz - 1;
                let i = |x: usize, y: usize, z: usize| x + nx * (y + ny * z);
                if ring {
                    solid[i(x, y, z)] = true;
                }
                if tris
                    .iter()
                    .any(|t| tri_box_overlap(c, half, t.map(|p| p.as_dvec3())))
                {
                    let (x, y, z) = (x.clamp(1, nx - 2), y.clamp(1, ny - 2), z.clamp(1, nz - 2));
                    solid[i(x, y, z)] = true;
                }
            }
        }
    }
    solid
}

#[test]
fn voxelize_marks_exactly_the_voxels_every_triangle_touches() {
    // Random triangles of every size (slivers and triangles larger than the grid among them),
    // axis-aligned quads lying on voxel faces, and a paper cube, each at three resolutions:
    // the column walk tests only voxels near each triangle's plane and row, and must mark
    // exactly what testing every voxel marks.
    let mut rng = Rng(0x0bad_cafe_f00d_1234);
    let mut tris: Vec<[Vec3; 3]> = (0..60)
        .map(|k| {
            let c = rng.v(8.0);
            let s = [0.05, 0.6, 3.0, 12.0][k % 4];
            [c + rng.v(s), c + rng.v(s), c + rng.v(s)].map(|p| p.as_vec3())
        })
        .collect();
    // A sliver: two vertices a hair apart.
    let a = rng.v(6.0).as_vec3();
    tris.push([
        a,
        a + Vec3::new(1e-4, 0.0, 0.0),
        a + Vec3::new(3.0, 2.5, -1.0),
    ]);
    tris.extend(quad(
        Vec3::new(-4.0, -4.0, 0.0),
        Vec3::new(4.0, -4.0, 0.0),
        Vec3::new(4.0, 4.0, 0.0),
        Vec3::new(-4.0, 4.0, 0.0),
    ));
    tris.extend(paper_cube(Vec3::new(1.0, -2.0, 1.5), 2.0));
    for n in [16, 29, 40] {
        let meta = grid_for(bounds(&tris), Resolution::LongestAxisVoxels(n), 1 << 30)
            .expect("a grid of n voxels");
        let fast = voxelize(meta, &tris).solid;
        let slow = voxelize_brute_force(meta, &tris);
        let differ = fast.iter().zip(&slow).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{differ} voxels differ at {n}");
        assert!(
            slow.iter().filter(|&&s| s).count() > 1000,
            "a test that marks something"
        );
    }
}

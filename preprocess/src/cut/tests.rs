use super::*;

#[test]
fn a_tall_slot_is_cut_whole_and_the_rooms_beside_it_are_not() {
    // 20 × 30 × 20 voxels of 0.1 m: a wall at z = 10 with a slot x 9..12 (0.3 m wide), y
    // 2..28 (2.6 m tall); the gate at the slot's middle, radius 0.15 m, normal +z.
    let meta = GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 0.1,
        dims: [20, 30, 20],
    };
    let n = 20 * 30 * 20;
    let empty: Vec<bool> = (0..n as u32)
        .map(|i| {
            let [x, y, z] = meta.coords(i);
            let wall = z == 10 && !((9..12).contains(&x) && (2..28).contains(&y));
            let border = x == 0 || y == 0 || z == 0 || x == 19 || y == 29 || z == 19;
            !wall && !border
        })
        .collect();
    // Largest ball: 1 in the slot, 5 in the rooms (a stand-in for the distance field).
    let radius: Vec<u16> = (0..n as u32)
        .map(|i| {
            let [_, _, z] = meta.coords(i);
            if !empty[i as usize] {
                0
            } else if z == 10 {
                1
            } else {
                5
            }
        })
        .collect();
    let g = GateDisk {
        centre: Vec3::new(1.05, 1.5, 1.05),
        normal: Vec3::Z,
        radius: 0.15,
        clusters: [0, 1],
        seg_edge: 0,
        path_index: 0,
    };
    let mut cut = empty.clone();
    let sight = crate::sightline::Sight {
        meta: &meta,
        empty: &empty,
        clearance_vx: Some(&radius),
    }
    .packed();
    let space = Space {
        cells: sight.cells(),
        radius_vx: &radius,
    };
    for i in gate_cut(&meta, space, &g) {
        cut[i] = false;
    }
    // Every slot voxel is cut, top to bottom; nothing off the plane is.
    for y in 2..28 {
        for x in 9..12 {
            assert!(!cut[meta.index([x, y, 10])], "slot voxel ({x}, {y}) kept");
        }
    }
    let removed = empty.iter().zip(&cut).filter(|(e, c)| **e && !**c).count();
    assert_eq!(removed, 3 * 26);
}

#[test]
fn the_runs_covariance_is_the_voxels_covariance() {
    // Random runs about a random first run, some wholly before its start: the closed-form
    // sums against the voxels' points one at a time.
    let mut next = crate::xorshift32(0xc0fa_0001);
    for case in 0..50 {
        let runs: Vec<(i64, i64, i64, i64)> = (0..1 + case % 9)
            .map(|_| {
                let a = i64::from(next() % 300);
                let m = i64::from(next() % (1 + 40 * (case % 3)));
                (i64::from(next() % 50), i64::from(next() % 70), a, a + m)
            })
            .collect();
        let pts: Vec<glam::DVec3> = runs
            .iter()
            .flat_map(|&(y, z, a, b)| {
                (a..=b).map(move |x| glam::DVec3::new(x as f64, y as f64, z as f64))
            })
            .collect();
        let Some(cov) = covariance(&runs) else {
            assert!(pts.len() < 8, "case {case}: {} voxels", pts.len());
            continue;
        };
        let mean = pts.iter().sum::<glam::DVec3>() / pts.len() as f64;
        for i in 0..3 {
            for j in 0..3 {
                let want = pts
                    .iter()
                    .map(|p| (p[i] - mean[i]) * (p[j] - mean[j]))
                    .sum::<f64>()
                    / pts.len() as f64;
                let got = f64::from(cov.col(j)[i]);
                assert!(
                    (got - want).abs() <= 1e-4 * (1.0 + want.abs()),
                    "case {case} ({i}, {j}): {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn the_next_unseen_voxel_is_found_across_words_and_never_past_the_range() {
    let meta = GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 1.0,
        dims: [64, 2, 2],
    };
    let mut flood = Flood::new(&meta);
    // Seen: 3..=70 and 130..=255 (the grid's last voxel).
    (3..=70).chain(130..256).for_each(|i| {
        flood.insert(i);
    });
    assert_eq!(flood.next_unseen(0, 10), 0);
    assert_eq!(flood.next_unseen(3, 200), 71, "across a word's end");
    assert_eq!(flood.next_unseen(5, 60), 61, "none in range: one past it");
    assert_eq!(flood.next_unseen(130, 255), 256, "seen to the grid's end");
    assert_eq!(flood.next_unseen(100, 140), 100);
    flood.forget();
    assert_eq!(flood.next_unseen(5, 60), 5);
}

#[test]
fn the_scanline_fill_finds_the_breadth_first_floods_voxels() {
    // Random grids, from sparse to dense, accepted voxels in a ball around a random start
    // (the cuts' floods are bounded so) or anywhere: the same set, every voxel once.
    let mut next = crate::xorshift32(0x5eed_1234);
    let meta = GridMeta {
        origin_m: [-1.0, 0.5, 2.0],
        voxel_size_m: 0.25,
        // 7,296 voxels, a whole number of the bitset's words: a run that ends the grid ends it.
        dims: [24, 16, 19],
    };
    let n = meta.dims.iter().product::<u32>() as usize;
    let mut flood = Flood::new(&meta);
    let mut found = 0;
    for density in [20u32, 45, 60, 75, 90, 100] {
        for _ in 0..12 {
            let open: Vec<bool> = (0..n).map(|_| next() % 100 < density).collect();
            let from = Vec3::from(meta.voxel_to_world(meta.coords(next() % n as u32)));
            // A quarter unbounded: runs then reach the rows' ends, the grid's last voxel.
            let reach = match next() % 4 {
                0 => f32::INFINITY,
                _ => 0.25 * (4 + next() % 12) as f32,
            };
            let keep = |i: usize, p: Vec3| open[i] && (p - from).length() <= reach;
            let mut bfs = flood.run(&meta, from, keep);
            let mut fill = flood.spans(&meta, from, keep);
            assert!(flood.touched.is_empty() && flood.seen.iter().all(|&w| w == 0));
            bfs.sort_unstable();
            fill.sort_unstable();
            assert_eq!(fill, bfs, "density {density}");
            found += fill.len();
        }
    }
    // Floods of every size ran, not only the start voxel.
    assert!(found > 5000, "{found}");
}

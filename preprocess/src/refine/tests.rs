use super::*;

fn meta(dims: [u32; 3], voxel: f32) -> GridMeta {
    GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: voxel,
        dims,
    }
}

/// The flood one round at a time over every voxel: each voxel off the outer layer without
/// a cluster that `open` holds takes the cluster of its lowest-index neighbour that had one
/// before the round.
fn flood_by_scan(
    dims: [u32; 3],
    cluster: &mut [u32],
    open: &[bool],
    rounds: usize,
    conn: Conn,
) -> u64 {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut given = 0;
    for _ in 0..rounds {
        let before = cluster.to_vec();
        for j in 0..cluster.len() {
            let (x, y, z) = (j % nx, (j / nx) % ny, j / (nx * ny));
            let inner = x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz;
            if !inner || before[j] != u32::MAX || !open[j] {
                continue;
            }
            // Ascending index: z, then y, then x offsets.
            let found = (0..27).filter(|&k| k != 13).find_map(|k| {
                let o = [k % 3, (k / 3) % 3, k / 9];
                let steps = o.iter().filter(|&&c| c != 1).count();
                let n = (x + o[0] - 1) + nx * ((y + o[1] - 1) + ny * (z + o[2] - 1));
                let c = before[n];
                ((conn == Conn::C26 || steps == 1) && c != u32::MAX).then_some(c)
            });
            if let Some(c) = found {
                cluster[j] = c;
                given += 1;
            }
        }
    }
    given
}

#[test]
fn the_floods_on_bits_give_what_a_scan_of_every_voxel_a_round_gives() {
    // Rows shorter and longer than a word; a few seeds of three clusters in open space
    // with scattered closed voxels, flooded for several rounds (the later rounds look only
    // at the rows beside the round before's).
    let mut next = crate::xorshift32(0x0f10_0d5e);
    for dims in [[9, 7, 8], [70, 6, 5], [130, 5, 6]] {
        let [nx, ..] = dims.map(|d| d as usize);
        let n = dims.iter().product::<u32>() as usize;
        for conn in [Conn::C6, Conn::C26] {
            let open: Vec<bool> = (0..n).map(|_| next() % 100 < 80).collect();
            let start: Vec<u32> = (0..n)
                .map(|_| {
                    if next() % 100 < 2 {
                        next() % 3
                    } else {
                        u32::MAX
                    }
                })
                .collect();
            for rounds in [1, 3, 40] {
                let mut expect = start.clone();
                let want = flood_by_scan(dims, &mut expect, &open, rounds, conn);
                let mut got = start.clone();
                let mut has = row_bits(nx, &got, |&c| c != u32::MAX);
                let bits = row_bits(nx, &open, |&o| o);
                let given = flood(&meta(dims, 1.0), &mut got, (&mut has, &bits), rounds, conn);
                assert_eq!(got, expect, "{dims:?} {conn:?} {rounds}");
                assert_eq!(given, want);
                assert_eq!(has, row_bits(nx, &got, |&c| c != u32::MAX), "has kept up");
                assert!(want > 0);
            }
        }
    }
}

#[test]
fn the_first_round_on_bits_finds_what_a_scan_of_every_voxel_finds() {
    // Rows shorter than, as long as and longer than a 64-bit word; a sparse pseudo-random
    // cluster grid.
    for dims in [[5, 4, 6], [64, 3, 4], [70, 5, 3], [130, 4, 4]] {
        let [nx, ny, nz] = dims.map(|d| d as usize);
        let cluster: Vec<u32> = (0..nx * ny * nz)
            .map(|i| {
                let h = (i as u32).wrapping_mul(2_654_435_761) >> 24;
                if h < 40 { h % 3 } else { u32::MAX }
            })
            .collect();
        for conn in [Conn::C6, Conn::C26] {
            let expect: Vec<u32> = (0..cluster.len())
                .filter(|&j| {
                    let (x, y, z) = (j % nx, (j / nx) % ny, j / (nx * ny));
                    let inner = x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny;
                    inner && z + 1 < nz && cluster[j] == u32::MAX && {
                        (0..27).filter(|&k| k != 13).any(|k| {
                            let o = [k % 3, (k / 3) % 3, k / 9];
                            let steps = o.iter().filter(|&&c| c != 1).count();
                            let p = [x + o[0] - 1, y + o[1] - 1, z + o[2] - 1];
                            (conn == Conn::C26 || steps == 1)
                                && cluster[p[0] + nx * (p[1] + ny * p[2])] != u32::MAX
                        })
                    }
                })
                .map(|j| j as u32)
                .collect();
            assert!(!expect.is_empty());
            assert_eq!(beside_a_cluster(dims, &cluster, conn), expect, "{dims:?}");
        }
    }
}

#[test]
fn a_thin_wall_keeps_each_side_its_cluster_and_the_shell_follows() {
    // Coarse 6³ voxels of 2 m: empty inside, the x = 3 layer solid (the wall, which the
    // fine grid resolves thinner), clusters 0 left and 1 right.
    let cm = meta([6; 3], 2.0);
    let mut ce = vec![false; 216];
    let mut cc = vec![u32::MAX; 216];
    for z in 1..5 {
        for y in 1..5 {
            for x in 1..5 {
                let i = cm.index([x, y, z]);
                if x != 3 {
                    ce[i] = true;
                    cc[i] = u32::from(x > 3);
                }
            }
        }
    }
    // Fine 12³ voxels of 1 m: the wall is the x = 7 layer only.
    let fm = meta([12; 3], 1.0);
    let mut fe = vec![false; 1728];
    for z in 2..10 {
        for y in 2..10 {
            for x in 2..10 {
                fe[fm.index([x, y, z])] = x != 7;
            }
        }
    }
    let coarse = Coarse {
        meta: &cm,
        empty: &ce,
        voxel_cluster: &cc,
    };
    let (c, n) = refine(&fm, &mut fe, &coarse);
    assert_eq!(n.unreached, 0);
    assert!(n.flooded > 0, "x = 6 lies in the coarse wall");
    for z in 2..10 {
        for y in 2..10 {
            for x in 2..10 {
                let got = c[fm.index([x, y, z])];
                match x {
                    7 => assert!(got <= 1, "the wall is shell"),
                    _ => assert_eq!(got, u32::from(x > 7), "{x} {y} {z}"),
                }
            }
        }
    }
    // The shell reaches two voxels into the solid around the room, no further.
    assert_ne!(c[fm.index([1, 5, 5])], u32::MAX);
    assert_eq!(c[fm.index([0, 5, 5])], u32::MAX, "the outer layer");
    assert!(n.shell > 0);
}

#[test]
fn space_the_coarse_grid_closed_keeps_no_cluster_and_is_counted_and_dropped() {
    let cm = meta([4; 3], 2.0);
    let ce = vec![false; 64];
    let cc = vec![u32::MAX; 64];
    let fm = meta([8; 3], 1.0);
    let mut fe = vec![false; 512];
    fe[fm.index([3, 3, 3])] = true;
    fe[fm.index([4, 3, 3])] = true;
    let coarse = Coarse {
        meta: &cm,
        empty: &ce,
        voxel_cluster: &cc,
    };
    let (c, n) = refine(&fm, &mut fe, &coarse);
    assert_eq!(
        (n.from_coarse, n.flooded, n.unreached, n.shell),
        (0, 0, 2, 0)
    );
    assert!(c.iter().all(|&x| x == u32::MAX));
    assert!(fe.iter().all(|&e| !e), "dropped from the kept space");
}

#[test]
fn the_floods_stop_four_coarse_voxels_deep_and_what_is_past_them_is_dropped() {
    // Coarse voxels of 2 m, one empty column at x = 1 (cluster 0); the fine grid's 1 m
    // tube runs on along x, in coarse voxels that are solid (a crack only it resolves).
    let cm = meta([12, 4, 4], 2.0);
    let mut ce = vec![false; 12 * 16];
    let mut cc = vec![u32::MAX; 12 * 16];
    ce[cm.index([1, 1, 1])] = true;
    cc[cm.index([1, 1, 1])] = 0;
    let fm = meta([24, 8, 8], 1.0);
    let mut fe = vec![false; 24 * 64];
    for x in 2..22 {
        fe[fm.index([x, 3, 3])] = true;
    }
    let coarse = Coarse {
        meta: &cm,
        empty: &ce,
        voxel_cluster: &cc,
    };
    let (c, n) = refine(&fm, &mut fe, &coarse);
    // Two fine voxels in the coarse one; each flood (across faces, then across edges and
    // corners) 4 × 2 fine voxels on; the last two of the tube past both, dropped.
    assert_eq!((n.from_coarse, n.flooded, n.unreached), (2, 16, 2));
    for x in 2..22 {
        let i = fm.index([x, 3, 3]);
        assert_eq!(fe[i], x < 20, "{x}");
        // Dropped, the last two are solid: the shell's.
        assert_eq!(c[i], 0, "{x}");
    }
}

#[test]
fn a_coarse_voxel_takes_the_cluster_most_of_its_finer_partition_voxels_have() {
    // Partition voxels of 1 m (8³), level voxels of 2 m (4³): each level voxel holds 2³
    // partition voxels.
    let pm = meta([8; 3], 1.0);
    let mut pe = vec![false; 512];
    let mut pc = vec![u32::MAX; 512];
    let mut set = |c: [u32; 3], cluster: u32| {
        pe[pm.index(c)] = true;
        pc[pm.index(c)] = cluster;
    };
    // Level voxel (1,1,1) holds partition voxels 2..4: five of cluster 7, three of 2.
    for (k, c) in (0..8u32)
        .map(|k| [2 + k % 2, 2 + (k / 2) % 2, 2 + k / 4])
        .enumerate()
    {
        set(c, if k < 5 { 7 } else { 2 });
    }
    // Level voxel (2,1,1): two of 4, two of 3, the rest solid: a tie, the lower wins.
    set([4, 2, 2], 4);
    set([5, 2, 2], 4);
    set([4, 3, 2], 3);
    set([5, 3, 2], 3);
    // Level voxel (1,2,1) holds no empty partition voxel: the flood gives it its
    // neighbour's cluster.
    let lm = meta([4; 3], 2.0);
    let mut le = vec![false; 64];
    for c in [[1, 1, 1], [2, 1, 1], [1, 2, 1]] {
        le[lm.index(c)] = true;
    }
    let coarse = Coarse {
        meta: &pm,
        empty: &pe,
        voxel_cluster: &pc,
    };
    assert_eq!(samples_per_axis(&lm, &pm), 2);
    let (c, n) = refine(&lm, &mut le, &coarse);
    assert_eq!(c[lm.index([1, 1, 1])], 7);
    assert_eq!(c[lm.index([2, 1, 1])], 3);
    assert_eq!(c[lm.index([1, 2, 1])], 7);
    assert_eq!((n.from_coarse, n.flooded, n.unreached), (2, 1, 0));
}

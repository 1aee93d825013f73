//! The baked `.vgate` file: round trips, and every corruption gives a typed error.

use proptest::prelude::*;
use visgate_formats::GeometryHash;
use visgate_formats::VgateError;
use visgate_formats::vgate::*;

/// A small but complete level shaped like two rooms joined by a doorway: a skeleton line
/// along x, two clusters, one gate, and grids that map every voxel.
fn two_room_level(nx: u32) -> BakedLevel {
    let grid = GridMeta {
        origin_m: [-0.2, -0.2, -0.2],
        voxel_size_m: 0.1,
        dims: [nx, 6, 5],
    };
    let nodes: Vec<SkeletonNode> = (1..nx - 1)
        .map(|x| SkeletonNode {
            voxel: [x, 3, 2],
            position_m: grid.voxel_to_world([x, 3, 2]),
            radius_m: 0.2,
        })
        .collect();
    let n = nodes.len() as u32;
    let edges = (0..n - 1).map(|i| [i, i + 1]).collect();
    let mid = n / 2;
    let segmented = SegmentedSkeleton {
        nodes: vec![
            SegNode {
                skeleton_node: 0,
                kind: SegNodeKind::Topology,
            },
            SegNode {
                skeleton_node: mid,
                kind: SegNodeKind::Coverage,
            },
            SegNode {
                skeleton_node: n - 1,
                kind: SegNodeKind::Topology,
            },
        ],
        edges: vec![
            SegEdge {
                nodes: [0, 1],
                path: (0..=mid).collect(),
            },
            SegEdge {
                nodes: [1, 2],
                path: (mid..n).collect(),
            },
        ],
    };
    let voxels = grid.voxel_count().expect("fits") as usize;
    let mut voxel_cluster = vec![NONE; voxels];
    for z in 1..4 {
        for y in 1..5 {
            for x in 1..nx - 1 {
                let i = grid.index([x, y, z]);
                voxel_cluster[i] = u32::from(x - 1 > mid);
            }
        }
    }
    let gate_x = nodes[mid as usize].position_m;
    BakedLevel {
        info: BakeInfo {
            params: BakeParams::default(),
            geometry_hash: GeometryHash([7; 16]),
            grid,
            sight_grid: grid,
            tool_version: "test".into(),
        },
        topology: Topology {
            skeleton: Skeleton { nodes, edges },
            segmented,
            node_cluster: vec![0, 0, 1],
            clusters: vec![
                Cluster {
                    seed: 0,
                    bounds_min_m: [0.0; 3],
                    bounds_max_m: [1.0; 3],
                },
                Cluster {
                    seed: 2,
                    bounds_min_m: [1.0; 3],
                    bounds_max_m: [2.0; 3],
                },
            ],
            gates: vec![Gate {
                centre_m: gate_x,
                normal: [1.0, 0.0, 0.0],
                radius_m: 0.2,
                clusters: [0, 1],
                seg_edge: 1,
            }],
            portals: vec![Portal {
                clusters: [0, 1],
                origin_m: [gate_x[0], gate_x[1] - 0.2, gate_x[2] - 0.2],
                normal: [1.0, 0.0, 0.0],
                u: [0.0, 1.0, 0.0],
                v: [0.0, 0.0, 1.0],
                cell_m: 0.1,
                size: [4, 4],
                mask: vec![0b0110_1111_1111_0110],
                faces: 12,
            }],
        },
        open: VoxelBits::from_fn(voxel_cluster.len(), |i| voxel_cluster[i] != NONE),
        voxel_cluster: VoxelValues::pack(&voxel_cluster),
    }
}

#[test]
fn write_then_read_gives_the_same_level() {
    let level = two_room_level(12);
    let bytes = level.to_bytes().expect("encodes");
    assert_eq!(&bytes[..8], &MAGIC);
    let back = BakedLevel::from_bytes(&bytes).expect("decodes");
    assert_eq!(back, level);
    // Deterministic: the same level encodes to the same bytes.
    assert_eq!(level.to_bytes().expect("encodes"), bytes);
    // And through a file.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("l.vgate");
    level.write(&path).expect("writes");
    assert_eq!(BakedLevel::read(&path).expect("reads"), level);
    assert!(!dir.path().join("l.vgate.partial").exists());
}

#[test]
fn grids_are_stored_in_the_smallest_type_that_holds_them() {
    assert_eq!(VoxelValues::pack(&[0, 3, NONE]).elem(), Elem::U8);
    assert_eq!(VoxelValues::pack(&[0, 254, NONE]).elem(), Elem::U8);
    assert_eq!(VoxelValues::pack(&[255, NONE]).elem(), Elem::U16);
    assert_eq!(VoxelValues::pack(&[65534]).elem(), Elem::U16);
    assert_eq!(VoxelValues::pack(&[65535]).elem(), Elem::U32);
    assert_eq!(VoxelValues::pack(&[NONE, NONE]).elem(), Elem::U8);
    for values in [vec![0, 254, NONE], vec![255, NONE, 7], vec![70000, NONE, 0]] {
        let packed = VoxelValues::pack(&values);
        let back: Vec<u32> = (0..values.len())
            .map(|i| packed.get(i).expect("in range"))
            .collect();
        assert_eq!(back, values);
    }
}

/// The kind and byte length of the voxel→cluster section of an encoded level.
fn cluster_section(bytes: &[u8]) -> (SectionKind, u64) {
    let header = BakedLevel::read_header(bytes).expect("header");
    let s = header.sections[1];
    (s.kind, s.len)
}

#[test]
fn the_cluster_grid_is_stored_as_runs_where_that_is_smaller_and_reads_back_dense() {
    // Two rooms: a few long runs.
    let level = two_room_level(40);
    let bytes = level.to_bytes().expect("encodes");
    let (kind, len) = cluster_section(&bytes);
    let voxels = level.voxel_cluster.len() as u64;
    assert_eq!(kind, SectionKind::VoxelClusterRuns);
    assert!(len < voxels / 4, "{len} bytes of runs for {voxels} voxels");
    assert_eq!(BakedLevel::from_bytes(&bytes).expect("decodes"), level);
    // Every voxel its own value (a checkerboard of two clusters): dense is smaller.
    let mut noisy = level.clone();
    let values: Vec<u32> = (0..voxels as u32).map(|i| i % 2).collect();
    noisy.voxel_cluster = VoxelValues::pack(&values);
    let bytes = noisy.to_bytes().expect("encodes");
    assert_eq!(cluster_section(&bytes), (SectionKind::VoxelCluster, voxels));
    assert_eq!(BakedLevel::from_bytes(&bytes).expect("decodes"), noisy);
}

/// A file of `header` (its grid and its voxel→cluster section's kind and element type) and
/// the two sections, with every offset, length and checksum right: what a writer that got the
/// contents wrong would write.
fn file_of(mut header: Header, [topology, clusters, open]: [&[u8]; 3]) -> Vec<u8> {
    let blobs = [topology, clusters, open];
    for (s, b) in header.sections.iter_mut().zip(blobs) {
        s.len = b.len() as u64;
        s.crc32 = crc32fast::hash(b);
    }
    let mut hb: Vec<u8> = Vec::new();
    for _ in 0..8 {
        let mut at = (16 + hb.len() + 4) as u64;
        for s in &mut header.sections {
            s.offset = at;
            at += s.len;
        }
        let next = postcard::to_allocvec(&header).expect("header bytes");
        if next == hb {
            break;
        }
        hb = next;
    }
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(hb.len() as u32).to_le_bytes());
    out.extend_from_slice(&hb);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    blobs.iter().for_each(|b| out.extend_from_slice(b));
    out
}

#[test]
fn runs_that_do_not_add_up_to_the_grid_are_refused_even_with_a_right_checksum() {
    let bytes = two_room_level(40).to_bytes().expect("encodes");
    let header = BakedLevel::read_header(&bytes).expect("header");
    let [t, c, o] = [0, 1, 2].map(|k| {
        let s = header.sections[k];
        &bytes[s.offset as usize..(s.offset + s.len) as usize]
    });
    let first = u32::from_le_bytes(c[..4].try_into().expect("4 bytes"));
    for (what, n) in [("longer", first + 1), ("empty", 0)] {
        let mut runs = c.to_vec();
        runs[..4].copy_from_slice(&n.to_le_bytes());
        let e = BakedLevel::from_bytes(&file_of(header.clone(), [t, &runs, o]))
            .expect_err(what)
            .to_string();
        assert!(e.contains("runs"), "{what}: {e}");
    }
    // A few runs that declare a grid of 2^33 voxels (the header's grid made to match) are
    // refused, not allocated.
    let mut huge = header.clone();
    huge.info.grid.dims = [1 << 11, 1 << 11, 1 << 11];
    let runs: Vec<u8> = (0..2)
        .flat_map(|_| [u32::MAX.to_le_bytes().to_vec(), vec![0]].concat())
        .chain([2u32.to_le_bytes().to_vec(), vec![0]].concat())
        .collect();
    let e = BakedLevel::from_bytes(&file_of(huge, [t, &runs, o]))
        .expect_err("huge")
        .to_string();
    assert!(e.contains("u32"), "{e}");
}

#[test]
fn open_voxels_that_do_not_fit_the_sight_grid_are_refused_even_with_a_right_checksum() {
    let level = two_room_level(40);
    let bytes = level.to_bytes().expect("encodes");
    let header = BakedLevel::read_header(&bytes).expect("header");
    let [t, c, o] = [0, 1, 2].map(|k| {
        let s = header.sections[k];
        &bytes[s.offset as usize..(s.offset + s.len) as usize]
    });
    // A word short, a word more, and a bit set past the grid's last voxel.
    let short = &o[..o.len() - 8];
    let long = [o, &[0u8; 8][..]].concat();
    let voxels = level.info.sight_grid.voxel_count().expect("voxels");
    assert_ne!(voxels % 64, 0, "the fixture's grid must end inside a word");
    let mut stray = o.to_vec();
    let last = stray.len() - 1;
    stray[last] |= 0x80;
    for (what, blob) in [
        ("short", short),
        ("long", &long[..]),
        ("stray bit", &stray[..]),
    ] {
        let e = BakedLevel::from_bytes(&file_of(header.clone(), [t, c, blob]))
            .expect_err(what)
            .to_string();
        assert!(e.contains("open voxels"), "{what}: {e}");
    }
    // A sight grid of its own: the open bits follow it, not the level's grid.
    let mut finer = level.clone();
    let g = finer.info.grid;
    finer.info.sight_grid = GridMeta {
        voxel_size_m: g.voxel_size_m / 2.0,
        dims: g.dims.map(|d| d * 2),
        ..g
    };
    assert!(
        finer.to_bytes().is_err(),
        "bits of the level's grid, a finer sight grid"
    );
    let n = finer.info.sight_grid.voxel_count().expect("voxels") as usize;
    finer.open = VoxelBits::from_fn(n, |i| i % 5 != 0);
    let back = BakedLevel::from_bytes(&finer.to_bytes().expect("encodes")).expect("decodes");
    assert_eq!(back, finer);
}

#[test]
fn every_truncation_of_a_real_file_is_an_error() {
    let bytes = two_room_level(12).to_bytes().expect("encodes");
    for len in 0..bytes.len() {
        match BakedLevel::from_bytes(&bytes[..len]) {
            Err(VgateError::Truncated { .. }) => {}
            Err(e) => panic!("truncation to {len} bytes gave {e:?}, expected Truncated"),
            Ok(_) => panic!("truncation to {len} of {} bytes was accepted", bytes.len()),
        }
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(
        BakedLevel::from_bytes(&longer),
        Err(VgateError::Length(_))
    ));
}

#[test]
fn every_single_byte_flip_of_a_real_file_is_an_error() {
    let bytes = two_room_level(12).to_bytes().expect("encodes");
    for i in 0..bytes.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut b = bytes.clone();
            b[i] ^= flip;
            if let Ok(level) = BakedLevel::from_bytes(&b) {
                panic!("byte {i} ^ {flip:#x} was accepted: {:?}", level.info);
            }
        }
    }
}

fn patch_version(bytes: &mut [u8], v: u32) {
    bytes[8..12].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn wrong_magic_and_other_versions_are_named() {
    let bytes = two_room_level(10).to_bytes().expect("encodes");
    let mut b = bytes.clone();
    b[0] = b'X';
    assert!(matches!(
        BakedLevel::from_bytes(&b),
        Err(VgateError::BadMagic)
    ));
    assert!(matches!(
        BakedLevel::from_bytes(b"PK\x03\x04 a zip file"),
        Err(VgateError::BadMagic)
    ));
    let mut b = bytes.clone();
    patch_version(&mut b, FORMAT_VERSION + 1);
    let e = BakedLevel::from_bytes(&b).expect_err("newer");
    assert!(matches!(e, VgateError::NewerVersion { found, .. } if found == FORMAT_VERSION + 1));
    assert!(e.to_string().contains("newer"));
    let mut b = bytes;
    patch_version(&mut b, OLDEST_READ_VERSION - 1);
    let e = BakedLevel::from_bytes(&b).expect_err("older");
    assert!(matches!(e, VgateError::OldVersion { .. }), "{e}");
    assert!(e.to_string().contains("re-bake"), "{e}");
}

#[test]
fn the_open_voxels_are_stored_as_runs_where_smaller_and_a_format_6_file_still_reads() {
    let level = two_room_level(40);
    let bytes = level.to_bytes().expect("encodes");
    let header = BakedLevel::read_header(&bytes).expect("header");
    let open = header.sections[2];
    assert_eq!(open.kind, SectionKind::OpenVoxelRuns);
    assert!(open.len < level.open.len().div_ceil(64) * 8, "{open:?}");
    // Format 6 wrote the words as they are, and nothing else differs: read as before.
    let [t, c] = [0, 1].map(|k| {
        let s = header.sections[k];
        &bytes[s.offset as usize..(s.offset + s.len) as usize]
    });
    let words: Vec<u8> = level
        .open
        .words()
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect();
    let mut dense = header.clone();
    dense.sections[2].kind = SectionKind::OpenVoxels;
    let mut file = file_of(dense, [t, c, &words]);
    patch_version(&mut file, 6);
    // The header's checksum covers the version: patched, the file is checked again.
    let hlen = u32::from_le_bytes(file[12..16].try_into().expect("4 bytes")) as usize;
    let crc = crc32fast::hash(&file[..16 + hlen]);
    file[16 + hlen..20 + hlen].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(BakedLevel::from_bytes(&file).expect("format 6"), level);
}

/// Each way a writer could get the structure wrong is caught by the reader, with its own
/// error, even when the checksums are right.
#[test]
fn indices_out_of_range_and_lengths_that_disagree_are_errors() {
    type Mutate = fn(&mut BakedLevel);
    let cases: [(&str, Mutate); 15] = [
        ("skeleton edge", |l| l.topology.skeleton.edges[0] = [0, 999]),
        ("self edge", |l| l.topology.skeleton.edges[0] = [1, 1]),
        ("segmented node", |l| {
            l.topology.segmented.nodes[0].skeleton_node = 999
        }),
        ("segmented edge", |l| {
            l.topology.segmented.edges[0].nodes = [0, 9]
        }),
        ("segmented path", |l| {
            l.topology.segmented.edges[0].path.push(999)
        }),
        ("node→cluster", |l| l.topology.node_cluster[0] = 5),
        ("node→cluster length", |l| {
            l.topology.node_cluster.pop();
        }),
        ("gate clusters", |l| l.topology.gates[0].clusters = [0, 0]),
        ("gate radius", |l| l.topology.gates[0].radius_m = f32::NAN),
        ("portal clusters", |l| {
            l.topology.portals[0].clusters = [1, 7]
        }),
        ("portal mask length", |l| l.topology.portals[0].mask.push(0)),
        ("portal normal", |l| {
            l.topology.portals[0].normal = [0.0, 2.0, 0.0]
        }),
        ("voxel_cluster value", |l| {
            l.voxel_cluster = VoxelValues::pack(&vec![3; 300])
        }),
        ("voxel_cluster length", |l| {
            l.voxel_cluster = VoxelValues::pack(&[0; 17])
        }),
        ("node voxel", |l| {
            l.topology.skeleton.nodes[0].voxel = [99, 0, 0]
        }),
    ];
    for (what, mutate) in cases {
        let mut level = two_room_level(10);
        mutate(&mut level);
        assert!(level.to_bytes().is_err(), "{what}: the writer accepted it");
        let e = BakedLevel::from_bytes(&level.encode_unchecked())
            .expect_err(what)
            .to_string();
        assert!(e.contains("corrupt"), "{what}: {e}");
    }
}

#[test]
fn a_level_baked_from_other_geometry_is_refused_as_stale() {
    let level = two_room_level(10);
    level
        .check_geometry(GeometryHash([7; 16]))
        .expect("same geometry");
    let e = level
        .check_geometry(GeometryHash([8; 16]))
        .expect_err("stale");
    assert!(e.to_string().contains("re-bake"), "{e}");
}

#[test]
fn skeleton_cycles_count_independent_loops() {
    let mut level = two_room_level(10);
    assert_eq!(level.skeleton_cycles(), 0);
    let n = level.topology.skeleton.nodes.len() as u32;
    level.topology.skeleton.edges.push([0, n - 1]);
    assert_eq!(level.skeleton_cycles(), 1);
}

fn arb_level() -> impl Strategy<Value = BakedLevel> {
    (
        2u32..9,
        1u32..5,
        1u32..4,
        1usize..40,
        1usize..6,
        any::<u64>(),
    )
        .prop_flat_map(|(nx, ny, nz, n_nodes, n_clusters, seed)| {
            let voxels = (nx * ny * nz) as usize;
            let node = 0..n_nodes as u32;
            let cluster = 0..n_clusters as u32;
            (
                proptest::collection::vec(
                    ((0..nx, 0..ny, 0..nz), -1e3f32..1e3, 0f32..10.0),
                    n_nodes,
                ),
                proptest::collection::vec((node.clone(), node.clone()), 0..60).prop_map(|v| {
                    v.into_iter()
                        .filter(|(a, b)| a != b)
                        .map(|(a, b)| [a, b])
                        .collect::<Vec<_>>()
                }),
                proptest::collection::vec((node.clone(), 0u8..3, cluster.clone()), 1..12),
                proptest::collection::vec(prop_oneof![Just(NONE), cluster.clone()], voxels),
                proptest::collection::vec(
                    (cluster.clone(), cluster.clone(), 0f32..3.0, -1f32..1.0),
                    0..8,
                ),
                Just((nx, ny, nz, seed, n_clusters)),
            )
        })
        .prop_map(
            |(nodes, edges, seg, vcluster, gates, (nx, ny, nz, seed, n_clusters))| {
                let grid = GridMeta {
                    origin_m: [1.5, -2.0, 0.25],
                    voxel_size_m: 0.05,
                    dims: [nx, ny, nz],
                };
                let n_seg = seg.len() as u32;
                let seg_edges: Vec<SegEdge> = (0..n_seg.saturating_sub(1))
                    .map(|i| SegEdge {
                        nodes: [i, i + 1],
                        path: vec![seg[i as usize].0, seg[i as usize + 1].0],
                    })
                    .collect();
                let kinds = [
                    SegNodeKind::Topology,
                    SegNodeKind::Curvature,
                    SegNodeKind::Coverage,
                ];
                let gates = if seg_edges.is_empty() {
                    vec![]
                } else {
                    gates
                        .into_iter()
                        .filter(|(a, b, _, _)| a != b)
                        .enumerate()
                        .map(|(i, (a, b, r, t))| {
                            let (s, c) = t.sin_cos();
                            Gate {
                                centre_m: [t, r, -t],
                                normal: [c, s, 0.0],
                                radius_m: r,
                                clusters: [a, b],
                                seg_edge: (i % seg_edges.len()) as u32,
                            }
                        })
                        .collect()
                };
                BakedLevel {
                    info: BakeInfo {
                        params: BakeParams {
                            alpha: (seed % 100) as f32 / 100.0,
                            persistence: Some((seed % 7) as u32),
                            ..Default::default()
                        },
                        geometry_hash: GeometryHash(
                            ((seed as u128) << 64 | seed as u128).to_le_bytes(),
                        ),
                        grid,
                        sight_grid: grid,
                        tool_version: format!("v{seed}"),
                    },
                    topology: Topology {
                        skeleton: Skeleton {
                            nodes: nodes
                                .iter()
                                .map(|&((x, y, z), p, r)| SkeletonNode {
                                    voxel: [x, y, z],
                                    position_m: [p, -p, p * 0.5],
                                    radius_m: r,
                                })
                                .collect(),
                            edges,
                        },
                        segmented: SegmentedSkeleton {
                            nodes: seg
                                .iter()
                                .map(|&(s, k, _)| SegNode {
                                    skeleton_node: s,
                                    kind: kinds[k as usize],
                                })
                                .collect(),
                            edges: seg_edges,
                        },
                        node_cluster: seg.iter().map(|&(_, _, c)| c).collect(),
                        clusters: (0..n_clusters as u32)
                            .map(|i| Cluster {
                                seed: i % n_seg,
                                bounds_min_m: [i as f32; 3],
                                bounds_max_m: [i as f32 + 1.0; 3],
                            })
                            .collect(),
                        gates,
                        portals: vec![],
                    },
                    open: VoxelBits::from_fn(vcluster.len(), |i| vcluster[i] != NONE),
                    voxel_cluster: VoxelValues::pack(&vcluster),
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn any_valid_level_round_trips_exactly(level in arb_level()) {
        let bytes = level.to_bytes().expect("a valid level encodes");
        let back = BakedLevel::from_bytes(&bytes).expect("and decodes");
        prop_assert_eq!(back, level);
    }
}

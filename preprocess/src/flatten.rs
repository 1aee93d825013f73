//! Stage 10, flatten: every empty voxel gets its visibility cluster, and each cluster its box.
//!
//! In order: skeleton nodes that lie past a gate of their cluster move across it; each voxel
//! takes its nearest node's cluster, or the other side's where it lies past a gate near that
//! node; the gates cut the empty space into pieces and a piece whose nodes are all of one
//! cluster takes it whole; a voxel that sees neither its cluster's seed nor its own segmented
//! node (when that is of its cluster) takes the cluster of the nearest voxel that does
//! (sightline.rs); then the clusters' boxes.

use glam::Vec3;
use rayon::prelude::*;
use visgate_formats::vgate::{Cluster, GridMeta};

use crate::clusters::{GateDisk, skeleton_clusters};
use crate::counters::FlattenCounts;
use crate::graph::SkeletonGraph;
use crate::neighbourhood::{Conn, grid_components};
use crate::segment::Segmented;

/// What the flatten reads: the grid, the empty space and its largest balls, the nearest-node
/// grid, the skeleton and its clusters, the gates.
pub struct FlattenInput<'a> {
    /// The grid.
    pub meta: &'a GridMeta,
    /// Empty voxels.
    pub empty: &'a [bool],
    /// Each voxel's largest-ball radius, whole voxels (saturated).
    pub radius_vx: &'a [u16],
    /// Each voxel's nearest skeleton node (`u32::MAX`: none).
    pub voxel_node: &'a [u32],
    /// The skeleton graph (its nodes' voxels).
    pub graph: &'a SkeletonGraph,
    /// Each skeleton node's position. [Units: m]
    pub position: &'a [Vec3],
    /// The segmented skeleton.
    pub seg: &'a Segmented,
    /// Each segmented node's cluster.
    pub node_cluster: &'a [u32],
    /// Each cluster's seed (a segmented node).
    pub seeds_of: &'a [u32],
    /// The stored gates.
    pub gates: &'a [GateDisk],
}

/// Every voxel's cluster (`u32::MAX`: none), the clusters, and the stage's counts for the
/// report.
pub struct Flattened {
    /// Visibility cluster per voxel.
    pub voxel_cluster: Vec<u32>,
    /// The clusters with their boxes.
    pub clusters: Vec<Cluster>,
    /// Nodes moved across gates, voxels moved to their piece and by sight, pieces (the grid's
    /// bytes are the caller's to fill in).
    pub counts: FlattenCounts,
}

/// The flatten stage (see the module notes).
pub fn flatten(input: &FlattenInput) -> Flattened {
    let cluster_gates = gates_by_cluster(input.gates, input.seeds_of.len());
    let (skel_cluster, nodes_moved) = nodes_across_gates(input, &cluster_gates);
    let mut voxel_cluster = assign_voxels(input, &cluster_gates, &skel_cluster);
    let sight = crate::sightline::Sight {
        meta: input.meta,
        empty: input.empty,
        clearance_vx: Some(input.radius_vx),
    }
    .packed();
    let pieces = join_pieces(input, &sight, &skel_cluster, &mut voxel_cluster);
    let meta = input.meta;
    let seed_at: Vec<[u32; 3]> = input
        .seeds_of
        .iter()
        .map(|&seed| meta.coords(input.graph.voxels[seed_node(input, seed)]))
        .collect();
    // A voxel also stays where it sees the segmented node its skeleton line ends at, when that
    // node is of its cluster: the seed of a long cluster hides behind a column from the part of
    // a gap that is the cluster's, and the gap would be cut along the seed's shadow instead of
    // the gate.
    let anchor = |i: usize| -> Option<(u32, [u32; 3])> {
        let n = *input.voxel_node.get(i)?;
        if n == u32::MAX {
            return None;
        }
        let s = input.seg.node_segment[n as usize] as usize;
        let node = input.seg.skeleton.nodes[s].skeleton_node as usize;
        Some((input.node_cluster[s], meta.coords(input.graph.voxels[node])))
    };
    let voxels_by_sight =
        crate::sightline::clusters_by_sight(&sight, &mut voxel_cluster, &seed_at, &anchor);
    let clusters = cluster_boxes(input, &voxel_cluster);
    Flattened {
        voxel_cluster,
        clusters,
        counts: FlattenCounts {
            nodes_moved_across_gates: nodes_moved,
            voxels_moved_to_their_piece: pieces.voxels_moved,
            voxels_moved_by_sight: voxels_by_sight,
            pieces: pieces.pieces,
            pieces_of_several_clusters: pieces.of_several,
            voxel_cluster_bytes: 0,
        },
    }
}

/// The skeleton node of segmented node `seed` (a cluster's seed).
fn seed_node(input: &FlattenInput, seed: u32) -> usize {
    input.seg.skeleton.nodes[seed as usize].skeleton_node as usize
}

/// The gates of each cluster (indices into `gates`).
fn gates_by_cluster(gates: &[GateDisk], clusters: usize) -> Vec<Vec<usize>> {
    let mut cluster_gates: Vec<Vec<usize>> = vec![Vec::new(); clusters];
    for (i, g) in gates.iter().enumerate() {
        for c in g.clusters {
            cluster_gates[c as usize].push(i);
        }
    }
    cluster_gates
}

/// -1 on the side of the gate's normal that `c` lies on (the normal points from clusters[0]'s
/// side to clusters[1]'s), 1 on the other.
fn own_side(g: &GateDisk, c: u32) -> f32 {
    if g.clusters[0] == c { -1.0 } else { 1.0 }
}

/// The cluster on `g`'s other side from `c`.
fn other_side(g: &GateDisk, c: u32) -> u32 {
    g.clusters[(g.clusters[0] == c) as usize]
}

/// Each skeleton node's cluster, where a node that lies past a gate of its own cluster within
/// the gate's reach (a doorway's end node a little inside the next room, when the narrowest
/// place lies beyond the segmented node) takes the cluster on the gate's other side; and how
/// many moved.
fn nodes_across_gates(input: &FlattenInput, cluster_gates: &[Vec<usize>]) -> (Vec<u32>, usize) {
    let (seg, gates, vs) = (input.seg, input.gates, input.meta.voxel_size_m);
    let mut skel_cluster =
        skeleton_clusters(&seg.skeleton, &seg.node_segment, input.node_cluster, gates);
    let across = |c: u32, p: Vec3| -> Option<u32> {
        cluster_gates[c as usize].iter().find_map(|&gi| {
            let g = &gates[gi];
            let beyond = (p - g.centre).dot(g.normal) * own_side(g, c) < -0.5 * vs;
            let near = (p - g.centre).length() <= g.radius + vs;
            (beyond && near).then(|| other_side(g, c))
        })
    };
    let moved = (0..skel_cluster.len())
        .filter_map(|n| across(skel_cluster[n], input.position[n]).map(|c| (n, c)))
        .collect::<Vec<_>>();
    for &(n, c) in &moved {
        skel_cluster[n] = c;
    }
    (skel_cluster, moved.len())
}

/// Each voxel's cluster: its nearest node's, or, where it lies past a gate of that cluster
/// that the node lies near on its own side, the gate's other cluster, so that cluster borders
/// follow the gates' planes (a doorway node's voxels would otherwise reach sideways into the
/// rooms).
fn assign_voxels(
    input: &FlattenInput,
    cluster_gates: &[Vec<usize>],
    skel_cluster: &[u32],
) -> Vec<u32> {
    let (meta, gates, vs) = (input.meta, input.gates, input.meta.voxel_size_m);
    // The gates of its cluster each node lies near, on its own side: only those can cut
    // through its voxels.
    let node_gates: Vec<Vec<usize>> = (0..skel_cluster.len())
        .into_par_iter()
        .map(|n| {
            let c = skel_cluster[n];
            cluster_gates[c as usize]
                .iter()
                .copied()
                .filter(|&gi| {
                    let g = &gates[gi];
                    let side_n = (input.position[n] - g.centre).dot(g.normal) * own_side(g, c);
                    side_n > -0.5 * vs && side_n <= g.radius + vs
                })
                .collect()
        })
        .collect();
    input
        .voxel_node
        .par_iter()
        .enumerate()
        .map(|(v, &n)| {
            if n == u32::MAX {
                return u32::MAX;
            }
            let c = skel_cluster[n as usize];
            let near = &node_gates[n as usize];
            if near.is_empty() {
                return c;
            }
            let p = Vec3::from(meta.voxel_to_world(meta.coords(v as u32)));
            for &gi in near {
                let g = &gates[gi];
                if (p - g.centre).dot(g.normal) * own_side(g, c) < -0.5 * vs {
                    return other_side(g, c);
                }
            }
            c
        })
        .collect()
}

/// What [`join_pieces`] did.
struct Pieces {
    pieces: u32,
    of_several: usize,
    voxels_moved: u64,
}

/// The gates cut the empty space: its pieces (6-connected, each gate's cut removed: cut.rs)
/// whose skeleton nodes all lie in one cluster take that cluster whole, so a room's voxels that
/// reached a doorway's node sideways join the room. Pieces that hold nodes of several clusters
/// (a gate in open space that does not close its opening) keep the per-voxel rule.
fn join_pieces(
    input: &FlattenInput,
    sight: &crate::sightline::PackedSight,
    skel_cluster: &[u32],
    voxel_cluster: &mut [u32],
) -> Pieces {
    let (meta, empty) = (input.meta, input.empty);
    let space = crate::cut::Space {
        cells: sight.cells(),
        radius_vx: input.radius_vx,
    };
    // The cut voxels, a bit each.
    let mut cut = vec![0u64; empty.len().div_ceil(64)];
    // Gates are independent: flooded in parallel, a few dozen at a time (a cut can hold a
    // whole plane of a 512³ grid).
    for gates in input.gates.chunks(64) {
        let cuts: Vec<Vec<usize>> = gates
            .par_iter()
            .map_init(
                || crate::cut::Flood::new(meta),
                |scratch, g| crate::cut::gate_cut_with(scratch, meta, space, g),
            )
            .collect();
        for i in cuts.into_iter().flatten() {
            cut[i / 64] |= 1 << (i % 64);
        }
    }
    // The pieces as labelled runs: a label per voxel would be 4 bytes a voxel.
    let uncut = |i: usize| empty[i] && cut[i / 64] & (1 << (i % 64)) == 0;
    let piece = grid_components(meta.dims, uncut, Conn::C6);
    drop(cut);
    // Cluster of each piece's nodes: u32::MAX none yet, u32::MAX - 1 several.
    let mut piece_cluster = vec![u32::MAX; piece.count as usize];
    for (n, &v) in input.graph.voxels.iter().enumerate() {
        let Some(p) = piece.label(v as usize) else {
            continue;
        };
        let pc = &mut piece_cluster[p as usize];
        *pc = match *pc {
            u32::MAX => skel_cluster[n],
            c if c == skel_cluster[n] => c,
            _ => u32::MAX - 1,
        };
    }
    let voxels_moved = voxel_cluster
        .par_chunks_mut(meta.dims[0] as usize)
        .enumerate()
        .map(|(r, row)| {
            let mut moved = 0u64;
            for (a, b, p) in piece.row(r) {
                let pc = piece_cluster[p as usize];
                if pc >= u32::MAX - 1 {
                    continue;
                }
                for c in &mut row[a as usize..=b as usize] {
                    if *c != u32::MAX && *c != pc {
                        *c = pc;
                        moved += 1;
                    }
                }
            }
            moved
        })
        .sum::<u64>();
    Pieces {
        pieces: piece.count,
        of_several: piece_cluster.iter().filter(|&&c| c == u32::MAX - 1).count(),
        voxels_moved,
    }
}

/// Each cluster with the box of its empty voxels (reduced over z slabs); a cluster's box holds
/// at least its seed's voxel.
fn cluster_boxes(input: &FlattenInput, voxel_cluster: &[u32]) -> Vec<Cluster> {
    let h = 0.5 * input.meta.voxel_size_m;
    let boxes = cluster_bounds_m(input.meta, input.empty, voxel_cluster, input.seeds_of.len());
    input
        .seeds_of
        .iter()
        .zip(boxes)
        .map(|(&seed, found)| {
            // No empty voxel of its own: the seed's voxel.
            let p = input.position[seed_node(input, seed)];
            let (lo, hi) = found.unwrap_or(((p - h).to_array(), (p + h).to_array()));
            Cluster {
                seed,
                bounds_min_m: lo,
                bounds_max_m: hi,
            }
        })
        .collect()
}

/// The bounds (minimum and maximum corner, metres) of each of `clusters` clusters' empty
/// voxels; `None` for a cluster without any.
pub fn cluster_bounds_m(
    meta: &GridMeta,
    empty: &[bool],
    voxel_cluster: &[u32],
    clusters: usize,
) -> Vec<Option<([f32; 3], [f32; 3])>> {
    let h = 0.5 * meta.voxel_size_m;
    let (lo, hi) = voxel_bounds(meta, empty, voxel_cluster, clusters);
    lo.iter()
        .zip(&hi)
        .map(|(lo, hi)| {
            (lo[0] != u32::MAX).then(|| {
                let (a, b) = (meta.voxel_to_world(*lo), meta.voxel_to_world(*hi));
                (a.map(|x| x - h), b.map(|x| x + h))
            })
        })
        .collect()
}

/// The voxel bounds (min, max corner) of each of `clusters` clusters' empty voxels; a cluster
/// without any keeps `u32::MAX` as its minimum.
fn voxel_bounds(
    meta: &GridMeta,
    empty: &[bool],
    voxel_cluster: &[u32],
    clusters: usize,
) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let nc = clusters;
    let slab = (meta.dims[0] * meta.dims[1]) as usize;
    voxel_cluster
        .par_chunks(slab)
        .zip(empty.par_chunks(slab))
        .enumerate()
        .fold(
            || (vec![[u32::MAX; 3]; nc], vec![[0u32; 3]; nc]),
            |(mut lo, mut hi), (z, (cs, es))| {
                for (i, (&c, &e)) in cs.iter().zip(es).enumerate() {
                    if c == u32::MAX || !e {
                        continue;
                    }
                    let v = [i as u32 % meta.dims[0], i as u32 / meta.dims[0], z as u32];
                    for a in 0..3 {
                        lo[c as usize][a] = lo[c as usize][a].min(v[a]);
                        hi[c as usize][a] = hi[c as usize][a].max(v[a]);
                    }
                }
                (lo, hi)
            },
        )
        .reduce(
            || (vec![[u32::MAX; 3]; nc], vec![[0u32; 3]; nc]),
            |(mut lo, mut hi), (l2, h2)| {
                for c in 0..nc {
                    for a in 0..3 {
                        lo[c][a] = lo[c][a].min(l2[c][a]);
                        hi[c][a] = hi[c][a].max(h2[c][a]);
                    }
                }
                (lo, hi)
            },
        )
}

//! Clusters whose nodes see each other. The greedy growth (IV.B.2) compares only the radii of
//! neighbouring nodes, so a hall with a row of columns is one cluster that wraps them: its
//! nodes on either side of a column do not see each other, light passes the columns inside
//! the cluster, and the voxels the columns hide from the cluster's seed are given away to a
//! neighbour (sightline.rs) — a side room's cluster then reaches through its doorway into the
//! hall, and a wall no longer stops its light.
//!
//! Here each cluster is cut into groups whose segmented nodes all see each other along a line
//! of empty voxels (a clique of the sight graph), each grown through the cluster's own edges
//! from its widest node left over, so that every group is connected. A cluster whose nodes see
//! each other stays as it is, and so does its seed; the groups cut from it become new
//! clusters, seeded at their widest node. The gates then fall between the groups (between the
//! columns), where the paper's quasi-convexity wants them.

use std::collections::VecDeque;

use visgate_formats::vgate::{GridMeta, SegmentedSkeleton};

use crate::sightline::Sight;

/// What the split reads: the grid and its empty voxels, the segmented skeleton, the voxel of
/// each skeleton node and the max-ball radius of each.
pub struct SplitInput<'a> {
    /// The grid.
    pub meta: &'a GridMeta,
    /// Kept empty voxels.
    pub empty: &'a [bool],
    /// Each voxel's clearance in whole voxels (the max-ball radii), if known: sight lines are
    /// then proved clear a stretch at a time where the space is wide (same answers).
    pub clearance_vx: Option<&'a [u16]>,
    /// The segmented skeleton.
    pub seg: &'a SegmentedSkeleton,
    /// Each skeleton node's voxel (an index into the grid).
    pub node_voxel: &'a [u32],
    /// Each skeleton node's max-ball radius. [Units: m]
    pub radius: &'a [f32],
}

/// The clusters split so that each one's segmented nodes see each other: every segmented
/// node's cluster and each cluster's seed (the clusters cut off come after `seeds`' own).
pub fn split_unseen(
    input: &SplitInput,
    node_cluster: &[u32],
    seeds: &[u32],
) -> (Vec<u32>, Vec<u32>) {
    let seg = input.seg;
    let n = seg.nodes.len();
    let voxel = |s: u32| {
        let node = seg.nodes[s as usize].skeleton_node as usize;
        input.meta.coords(input.node_voxel[node])
    };
    let rad = |s: u32| input.radius[seg.nodes[s as usize].skeleton_node as usize];
    let sight = Sight {
        meta: input.meta,
        empty: input.empty,
        clearance_vx: input.clearance_vx,
    };
    // Both ways: a line through voxel corners takes other voxels backwards.
    let see = |a: u32, b: u32| {
        let (va, vb) = (voxel(a), voxel(b));
        a == b || (sight.sees(va, vb) && sight.sees(vb, va))
    };
    let mut adj = vec![Vec::new(); n];
    for e in &seg.edges {
        let [a, b] = e.nodes;
        if a != b && node_cluster[a as usize] == node_cluster[b as usize] {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    // Nodes by decreasing radius (then id), as the greedy growth takes them.
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| rad(b).total_cmp(&rad(a)).then(a.cmp(&b)));
    let mut out = node_cluster.to_vec();
    let mut out_seeds = seeds.to_vec();
    let mut placed = vec![false; n];
    // A node that was tried for the group being grown (`tried[x] == group's first node`).
    let mut tried = vec![u32::MAX; n];
    // Each cluster's nodes, in that order.
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); seeds.len()];
    for &s in &order {
        members[node_cluster[s as usize] as usize].push(s);
    }
    for c in 0..seeds.len() as u32 {
        // The cluster's own seed first, so that an unsplit cluster keeps it.
        let starts = std::iter::once(seeds[c as usize]).chain(members[c as usize].iter().copied());
        for start in starts {
            if placed[start as usize] {
                continue;
            }
            let id = if start == seeds[c as usize] {
                c
            } else {
                out_seeds.push(start);
                out_seeds.len() as u32 - 1
            };
            let mut group = vec![start];
            placed[start as usize] = true;
            tried[start as usize] = start;
            out[start as usize] = id;
            let mut queue = VecDeque::from([start]);
            while let Some(m) = queue.pop_front() {
                for &nb in &adj[m as usize] {
                    if placed[nb as usize] || tried[nb as usize] == start {
                        continue;
                    }
                    tried[nb as usize] = start;
                    if group.iter().all(|&g| see(g, nb)) {
                        placed[nb as usize] = true;
                        out[nb as usize] = id;
                        group.push(nb);
                        queue.push_back(nb);
                    }
                }
            }
        }
    }
    (out, out_seeds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use visgate_formats::vgate::{SegEdge, SegNode, SegNodeKind};

    fn node(skeleton_node: u32) -> SegNode {
        SegNode {
            skeleton_node,
            kind: SegNodeKind::Topology,
        }
    }

    fn edge(a: u32, b: u32) -> SegEdge {
        SegEdge {
            nodes: [a, b],
            path: vec![a, b],
        }
    }

    /// A 9 × 1 × 9 room with a 3 × 1 × 3 column in its middle, and a ring of eight nodes
    /// around the column, one cluster.
    fn ring() -> (GridMeta, Vec<bool>, SegmentedSkeleton, Vec<u32>) {
        let meta = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims: [9, 1, 9],
        };
        let mut empty = vec![true; 81];
        for z in 3..6 {
            for x in 3..6 {
                empty[meta.index([x, 0, z])] = false;
            }
        }
        let ring = [
            [1, 1],
            [4, 1],
            [7, 1],
            [7, 4],
            [7, 7],
            [4, 7],
            [1, 7],
            [1, 4],
        ];
        let node_voxel: Vec<u32> = ring
            .iter()
            .map(|&[x, z]| meta.index([x, 0, z]) as u32)
            .collect();
        let seg = SegmentedSkeleton {
            nodes: (0..8).map(node).collect(),
            edges: (0..8).map(|i| edge(i, (i + 1) % 8)).collect(),
        };
        (meta, empty, seg, node_voxel)
    }

    /// The ring as one cluster seeded at node 0, split.
    fn split_ring(
        meta: &GridMeta,
        empty: &[bool],
        seg: &SegmentedSkeleton,
        node_voxel: &[u32],
    ) -> (Vec<u32>, Vec<u32>, usize) {
        let radius = vec![1.0; 8];
        let input = SplitInput {
            meta,
            empty,
            clearance_vx: None,
            seg,
            node_voxel,
            radius: &radius,
        };
        let (cluster, seeds) = split_unseen(&input, &[0; 8], &[0]);
        let added = seeds.len() - 1;
        (cluster, seeds, added)
    }

    #[test]
    fn a_cluster_around_a_column_is_cut_into_groups_that_see_each_other() {
        let (meta, empty, seg, node_voxel) = ring();
        let (cluster, seeds, added) = split_ring(&meta, &empty, &seg, &node_voxel);
        assert!(
            added >= 2,
            "a ring needs three groups at least, got {seeds:?}"
        );
        assert_eq!(seeds[0], 0, "the seed stays in its cluster");
        for a in 0..8u32 {
            for b in 0..8u32 {
                if cluster[a as usize] == cluster[b as usize] {
                    let (va, vb) = (node_voxel[a as usize], node_voxel[b as usize]);
                    assert!(
                        Sight {
                            meta: &meta,
                            empty: &empty,
                            clearance_vx: None
                        }
                        .sees(meta.coords(va), meta.coords(vb)),
                        "{a} {b}"
                    );
                }
            }
        }
        // Every group is connected along the ring (its members are consecutive).
        for c in 0..seeds.len() as u32 {
            let runs = (0..8)
                .filter(|&i| cluster[i] == c && cluster[(i + 7) % 8] != c)
                .count();
            assert_eq!(runs, 1, "cluster {c} of {cluster:?} is not one run");
        }
    }

    #[test]
    fn a_cluster_that_sees_itself_is_kept_whole() {
        let (meta, _, seg, node_voxel) = ring();
        let empty = vec![true; 81];
        let (cluster, seeds, added) = split_ring(&meta, &empty, &seg, &node_voxel);
        assert_eq!((added, seeds), (0, vec![0]));
        assert_eq!(cluster, vec![0; 8]);
    }
}

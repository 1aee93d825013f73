//! Stages 8–9: visibility clusters (the greedy construction of IV.B.2) and visibility gates
//! (IV.C).
//!
//! **Clusters.** The segmented nodes are taken by decreasing max-ball radius. An unclustered
//! node starts a cluster and goes on a stack. A node popped from the stack joins the cluster;
//! its segmented neighbours that are not curvature nodes and whose radius differs from its own
//! by at most `α` times the largest radius in the cluster go on the stack, and so do the nodes
//! inside its max ball reachable from it through nodes inside that ball. Each cluster is a
//! connected part of the segmented skeleton.
//!
//! **Gates.** Every segmented edge whose two ends lie in different clusters gets a disk
//! separating them. The paper's rule (`Midpoint`) puts it at the middle of the edge, orthogonal
//! to it, with the smaller of the two max-ball radii. A segmented edge is a straight shortcut
//! of a skeleton line that may pass far from the narrow place between two rooms, so the
//! default rule (`Narrowest`) puts the disk at the skeleton node of smallest max ball along the
//! original line (the doorway), orthogonal to the line there, with that node's radius.
//!
//! **Voxels.** A skeleton node takes the cluster of its segmented node (the nearer end of its
//! line), except on a line that crosses a gate: there the nodes before the gate take the
//! first end's cluster and the others the second's, so the clusters of the voxels change
//! where the gate is — at the doorway.

use glam::Vec3;
use visgate_formats::vgate::{GatePlacement, SegNodeKind, SegmentedSkeleton};

/// Parameters of [`clusters`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterParams {
    /// Growth tolerance α: a neighbour joins when its radius differs by at most α × the
    /// cluster's largest radius. [Limit: 0..=1] [Units: ratio]
    pub alpha: f32,
}

/// Cluster of every segmented node, and each cluster's seed (a segmented node), in creation
/// order.
pub fn clusters(
    seg: &SegmentedSkeleton,
    position: &[Vec3],
    radius: &[f32],
    params: &ClusterParams,
) -> (Vec<u32>, Vec<u32>) {
    let n = seg.nodes.len();
    let pos = |s: u32| position[seg.nodes[s as usize].skeleton_node as usize];
    let rad = |s: u32| radius[seg.nodes[s as usize].skeleton_node as usize];
    let mut adj = vec![Vec::new(); n];
    for e in &seg.edges {
        let [a, b] = e.nodes;
        if a != b {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    adj.iter_mut().for_each(|l| {
        l.sort_unstable();
        l.dedup();
    });
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| rad(b).total_cmp(&rad(a)).then(a.cmp(&b)));
    let mut cluster = vec![u32::MAX; n];
    let mut seeds = Vec::new();
    for &start in &order {
        if cluster[start as usize] != u32::MAX {
            continue;
        }
        let c = seeds.len() as u32;
        seeds.push(start);
        let mut max_r = rad(start);
        let mut stack = vec![start];
        while let Some(m) = stack.pop() {
            if cluster[m as usize] != u32::MAX {
                continue;
            }
            cluster[m as usize] = c;
            max_r = max_r.max(rad(m));
            for &nb in &adj[m as usize] {
                if cluster[nb as usize] == u32::MAX
                    && seg.nodes[nb as usize].kind != SegNodeKind::Curvature
                    && (rad(nb) - rad(m)).abs() <= params.alpha * max_r
                {
                    stack.push(nb);
                }
            }
            // Nodes inside m's max ball, reachable through nodes inside it.
            let (pm, rm) = (pos(m), rad(m));
            let mut inside = vec![m];
            let mut k = 0;
            while k < inside.len() {
                for &nb in &adj[inside[k] as usize] {
                    if !inside.contains(&nb) && (pos(nb) - pm).length() <= rm {
                        inside.push(nb);
                        if cluster[nb as usize] == u32::MAX {
                            stack.push(nb);
                        }
                    }
                }
                k += 1;
            }
        }
    }
    (cluster, seeds)
}

/// Cluster of every skeleton node: that of its segmented node, split at the gates (see the
/// module notes).
pub fn skeleton_clusters(
    seg: &SegmentedSkeleton,
    node_segment: &[u32],
    node_cluster: &[u32],
    gates: &[GateDisk],
) -> Vec<u32> {
    let mut out: Vec<u32> = node_segment
        .iter()
        .map(|&s| node_cluster[s as usize])
        .collect();
    for g in gates {
        let path = &seg.edges[g.seg_edge as usize].path;
        for (i, &n) in path.iter().enumerate() {
            out[n as usize] = if i < g.path_index {
                g.clusters[0]
            } else {
                g.clusters[1]
            };
        }
    }
    // Segmented nodes keep their own cluster.
    for (s, n) in seg.nodes.iter().enumerate() {
        out[n.skeleton_node as usize] = node_cluster[s];
    }
    out
}

/// A gate before it is written: centre, unit normal, radius, the two clusters, its edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateDisk {
    /// Centre (same units as the positions).
    pub centre: Vec3,
    /// Unit normal, along the skeleton.
    pub normal: Vec3,
    /// Radius.
    pub radius: f32,
    /// The two clusters it joins (from the edge's first end to its second).
    pub clusters: [u32; 2],
    /// The segmented edge.
    pub seg_edge: u32,
    /// Where along the edge's path it sits: path nodes before this index lie on the side of
    /// the edge's first end, the others on the side of its second.
    pub path_index: usize,
}

/// One gate per segmented edge whose ends lie in different clusters.
pub fn gates(
    seg: &SegmentedSkeleton,
    adjacency: &[Vec<u32>],
    node_cluster: &[u32],
    position: &[Vec3],
    radius: &[f32],
    placement: GatePlacement,
) -> Vec<GateDisk> {
    let mut out = Vec::new();
    for (ei, e) in seg.edges.iter().enumerate() {
        let [a, b] = e.nodes;
        let (ca, cb) = (node_cluster[a as usize], node_cluster[b as usize]);
        if ca == cb {
            continue;
        }
        let (na, nb) = (
            seg.nodes[a as usize].skeleton_node as usize,
            seg.nodes[b as usize].skeleton_node as usize,
        );
        let along = (position[nb] - position[na]).normalize_or_zero();
        let path = &e.path;
        let (centre, normal, r, k) = match placement {
            GatePlacement::Midpoint => {
                // The path node nearest half the path's length splits its voxels.
                let mut s = vec![0f32; path.len()];
                for i in 1..path.len() {
                    s[i] = s[i - 1]
                        + (position[path[i] as usize] - position[path[i - 1] as usize]).length();
                }
                let half = s[path.len() - 1] * 0.5;
                let k = (0..path.len())
                    .min_by(|&i, &j| (s[i] - half).abs().total_cmp(&(s[j] - half).abs()))
                    .unwrap_or(0);
                (
                    (position[na] + position[nb]) * 0.5,
                    along,
                    radius[na].min(radius[nb]),
                    k,
                )
            }
            GatePlacement::Narrowest => {
                // The path, extended by up to 3 skeleton nodes past each end: when an end is
                // a doorway node of its own cluster, the narrowest place may lie just beyond.
                let beyond = |from: u32, avoid: u32| -> Vec<u32> {
                    let (mut prev, mut cur) = (avoid, from);
                    let mut out = Vec::new();
                    for _ in 0..3 {
                        if adjacency[cur as usize].len() != 2 {
                            break;
                        }
                        match adjacency[cur as usize].iter().find(|&&n| n != prev) {
                            Some(&n) => {
                                out.push(n);
                                prev = cur;
                                cur = n;
                            }
                            None => break,
                        }
                    }
                    out
                };
                let last = path.len() - 1;
                let pre = if last > 0 {
                    beyond(path[0], path[1])
                } else {
                    Vec::new()
                };
                let post = if last > 0 {
                    beyond(path[last], path[last - 1])
                } else {
                    Vec::new()
                };
                let ext: Vec<u32> = pre
                    .iter()
                    .rev()
                    .chain(path.iter())
                    .chain(post.iter())
                    .copied()
                    .collect();
                // Smallest radius; among equals the one nearest the middle of the path.
                let mid = pre.len() as f32 + last as f32 * 0.5;
                let i = (0..ext.len())
                    .min_by(|&i, &j| {
                        radius[ext[i] as usize]
                            .total_cmp(&radius[ext[j] as usize])
                            .then(((i as f32 - mid).abs()).total_cmp(&(j as f32 - mid).abs()))
                            .then(i.cmp(&j))
                    })
                    .unwrap_or(0);
                let k = i.saturating_sub(pre.len()).min(path.len());
                let lo = ext[i.saturating_sub(2)];
                let hi = ext[(i + 2).min(ext.len() - 1)];
                let t = (position[hi as usize] - position[lo as usize]).normalize_or_zero();
                let t = if t == Vec3::ZERO { along } else { t };
                (position[ext[i] as usize], t, radius[ext[i] as usize], k)
            }
        };
        let normal = if normal == Vec3::ZERO {
            Vec3::X
        } else {
            normal
        };
        out.push(GateDisk {
            centre,
            normal,
            radius: r,
            clusters: [ca, cb],
            seg_edge: ei as u32,
            path_index: k,
        });
    }
    out
}

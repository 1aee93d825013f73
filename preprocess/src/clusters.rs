//! Stages 8–9: visibility clusters (the greedy construction of IV.B.2) and visibility gates
//! (IV.C).
//!
//! **Clusters.** The segmented nodes are taken by decreasing max-ball radius. An unclustered
//! node starts a cluster and goes on a stack. A node popped from the stack joins the cluster;
//! its segmented neighbours that are not curvature nodes and whose radius differs by at most `α`
//! times the largest radius in the cluster — from the popped node's ([`AlphaRule::PoppedNode`])
//! or from that largest radius ([`AlphaRule::ClusterMax`]; the paper leaves it open) — go on
//! the stack, and so do the nodes
//! inside its max ball reachable from it through nodes inside that ball. Each cluster is a
//! connected part of the segmented skeleton.
//!
//! **Gates.** Every segmented edge whose two ends lie in different clusters gets a disk
//! separating them. The paper's rule (`Midpoint`) puts it at the middle of the edge, orthogonal
//! to it, with the smaller of the two max-ball radii. A segmented edge is a straight shortcut
//! of a skeleton line that may pass far from the narrow place between two rooms, so the
//! default rule (`Narrowest`) puts the disk at the skeleton node of smallest max ball along the
//! original line or just past its ends (the doorway) — the middle of the run of nodes as narrow
//! as it — orthogonal to the line over that run (or over about one radius each way), with that
//! node's radius.
//!
//! **Slivers.** A cluster between two gates that face each other closer than the opening is
//! wide (a doorway in a thin wall, or a node just before it) is a slab, and its voxels would
//! reach sideways into the rooms; it is merged into the wider of its two neighbours when that
//! one is wider by more than α ([`find_sliver`]), and the gates are placed again.
//!
//! **Voxels.** A skeleton node takes the cluster of its segmented node (the nearer end of its
//! line), except on a line that crosses a gate: there the nodes before the gate take the
//! first end's cluster and the others the second's, so the clusters of the voxels change
//! where the gate is — at the doorway. The bake then settles voxels against the gates' planes
//! (see `bake`'s flatten stage).

use glam::Vec3;
use visgate_formats::vgate::{AlphaRule, GatePlacement, SegNodeKind, SegmentedSkeleton};

/// Parameters of [`clusters`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterParams {
    /// Growth tolerance α: a neighbour joins when its radius differs by at most α × the
    /// cluster's largest radius. [Limit: 0..=1] [Units: ratio]
    pub alpha: f32,
    /// What α compares.
    pub rule: AlphaRule,
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
    // The radius a neighbour's is compared with.
    let to = |m: u32, max_r: f32| match params.rule {
        AlphaRule::PoppedNode => rad(m),
        AlphaRule::ClusterMax => max_r,
    };
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| rad(b).total_cmp(&rad(a)).then(a.cmp(&b)));
    let mut cluster = vec![u32::MAX; n];
    let mut seeds = Vec::new();
    // Membership of the current max-ball walk: `in_ball[x] == m` while walking node m's ball
    // (each node is walked once), so the test is O(1) instead of a scan of the walk.
    let mut in_ball = vec![u32::MAX; n];
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
                    && (rad(nb) - to(m, max_r)).abs() <= params.alpha * max_r
                {
                    stack.push(nb);
                }
            }
            // Nodes inside m's max ball, reachable through nodes inside it.
            let (pm, rm) = (pos(m), rad(m));
            let mut inside = vec![m];
            in_ball[m as usize] = m;
            let mut k = 0;
            while k < inside.len() {
                for &nb in &adj[inside[k] as usize] {
                    if in_ball[nb as usize] != m && (pos(nb) - pm).length() <= rm {
                        in_ball[nb as usize] = m;
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

/// How far past a segmented edge's ends the narrowest place is searched for, at least: also
/// every node within the end node's max ball. [Units: nodes]
const BEYOND_SEARCH: usize = 3;
/// How far past the ends a run of equally narrow nodes is followed. [Units: nodes]
const BEYOND_RUN: usize = 16;

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
                let k = path_middle(path, position);
                (
                    (position[na] + position[nb]) * 0.5,
                    along,
                    radius[na].min(radius[nb]),
                    k,
                )
            }
            GatePlacement::Narrowest => narrowest(path, adjacency, position, radius, along),
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

/// The path node nearest half the path's length (it splits its voxels).
fn path_middle(path: &[u32], position: &[Vec3]) -> usize {
    let mut s = vec![0f32; path.len()];
    for i in 1..path.len() {
        s[i] = s[i - 1] + (position[path[i] as usize] - position[path[i - 1] as usize]).length();
    }
    let half = s[path.len() - 1] * 0.5;
    (0..path.len())
        .min_by(|&i, &j| (s[i] - half).abs().total_cmp(&(s[j] - half).abs()))
        .unwrap_or(0)
}

/// The nodes past skeleton node `from` away from `avoid`, along a line (nodes of two
/// neighbours), [`BEYOND_RUN`] at most.
fn beyond(adjacency: &[Vec<u32>], from: u32, avoid: u32) -> Vec<u32> {
    let (mut prev, mut cur) = (avoid, from);
    let mut out = Vec::new();
    for _ in 0..BEYOND_RUN {
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
}

/// A gate at the narrowest place of `path` (centre, normal, radius and the path's node):
/// on the path or just past its ends, the middle of the run as narrow, facing along the run
/// (or the line over about one radius each way; `along` where that gives no direction).
fn narrowest(
    path: &[u32],
    adjacency: &[Vec<u32>],
    position: &[Vec3],
    radius: &[f32],
    along: Vec3,
) -> (Vec3, Vec3, f32, usize) {
    // The path, extended past each end: when an end is a doorway node of its own cluster, the
    // narrowest place may lie just beyond.
    let last = path.len() - 1;
    let (pre, post) = if last > 0 {
        (
            beyond(adjacency, path[0], path[1]),
            beyond(adjacency, path[last], path[last - 1]),
        )
    } else {
        (Vec::new(), Vec::new())
    };
    let ext: Vec<u32> = pre
        .iter()
        .rev()
        .chain(path.iter())
        .chain(post.iter())
        .copied()
        .collect();
    // Smallest radius on the path or just past its ends (within the end's max ball, or 3
    // nodes); among equals the one nearest the middle of the path.
    let mid = pre.len() as f32 + last as f32 * 0.5;
    let within = |beyond: &[u32], end: u32| -> usize {
        let (p, r) = (position[end as usize], radius[end as usize]);
        beyond
            .iter()
            .take_while(|&&n| (position[n as usize] - p).length() <= r)
            .count()
            .max(BEYOND_SEARCH.min(beyond.len()))
    };
    let window =
        pre.len() - within(&pre, path[0])..pre.len() + path.len() + within(&post, path[last]);
    let i = window
        .min_by(|&i, &j| {
            radius[ext[i] as usize]
                .total_cmp(&radius[ext[j] as usize])
                .then(((i as f32 - mid).abs()).total_cmp(&(j as f32 - mid).abs()))
                .then(i.cmp(&j))
        })
        .unwrap_or(0);
    // The middle of the run of nodes as narrow as it (within 2 %): the middle of a doorway's
    // passage rather than one of its faces.
    let r_min = radius[ext[i] as usize] * 1.02;
    let narrow = |j: usize| radius[ext[j] as usize] <= r_min;
    let (mut s, mut e) = (i, i);
    while s > 0 && narrow(s - 1) {
        s -= 1;
    }
    while e + 1 < ext.len() && narrow(e + 1) {
        e += 1;
    }
    let i = (s + e) / 2;
    let k = i.saturating_sub(pre.len()).min(path.len());
    let t = run_direction(&ext, i, (s, e), position, radius);
    let t = if t == Vec3::ZERO { along } else { t };
    (position[ext[i] as usize], t, radius[ext[i] as usize], k)
}

/// The direction of the line `ext` at its node `i`, averaged over the disk's own size, so
/// that a line that dips through a low doorway does not tilt the disk: along the narrow run
/// `s..=e` itself where it is long enough to give a direction (a doorway's passage), else over
/// about one radius each way.
fn run_direction(
    ext: &[u32],
    i: usize,
    (s, e): (usize, usize),
    position: &[Vec3],
    radius: &[f32],
) -> Vec3 {
    let (r_i, p_i) = (radius[ext[i] as usize], position[ext[i] as usize]);
    let reach = |step: isize| -> u32 {
        let mut j = i as isize;
        loop {
            let next = j + step;
            if next < 0 || next >= ext.len() as isize {
                break;
            }
            j = next;
            let far = (position[ext[j as usize] as usize] - p_i).length() >= r_i;
            if far && (j - i as isize).abs() >= 2 {
                break;
            }
        }
        ext[j as usize]
    };
    let run =
        (position[ext[e] as usize] - p_i).length() + (position[ext[s] as usize] - p_i).length();
    let (lo, hi) = if run >= 0.5 * r_i {
        (ext[s], ext[e])
    } else {
        (reach(-1), reach(1))
    };
    (position[hi as usize] - position[lo as usize]).normalize_or_zero()
}

/// Gates of a sliver face each other within this angle's cosine (45°).
const SLIVER_COS: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// A *sliver*: a cluster with two gates to two other clusters that face each other (normals
/// within 45°), lie one behind the other along the normal (the line between their centres
/// within 45° of it) and closer together than the smaller gate's radius — a cluster shallower than its opening is wide, as
/// when a doorway in a thin wall, or a node just before it, makes a cluster of its own. Its
/// voxels would be slabs reaching sideways into the rooms. Returns the first sliver (lowest
/// cluster id) and the neighbour to merge it into: across one of those two gates, the one
/// whose nodes have the largest max ball (the room), ties to the lower id — provided that
/// ball is larger than the sliver's by more than `alpha` of it (the clustering tolerance).
pub fn find_sliver(gates: &[GateDisk], cluster_radius: &[f32], alpha: f32) -> Option<(u32, u32)> {
    let n = cluster_radius.len();
    let mut of: Vec<Vec<(usize, u32)>> = vec![Vec::new(); n];
    for (i, g) in gates.iter().enumerate() {
        of[g.clusters[0] as usize].push((i, g.clusters[1]));
        of[g.clusters[1] as usize].push((i, g.clusters[0]));
    }
    for (x, list) in of.iter().enumerate() {
        for (k, &(gi, a)) in list.iter().enumerate() {
            for &(gj, b) in &list[k + 1..] {
                let (p, q) = (&gates[gi], &gates[gj]);
                // Facing each other (within 45°), one behind the other along the normal (not
                // side by side), closer than the smaller opening is wide: a slab across a
                // doorway.
                let d = q.centre - p.centre;
                let facing = p.normal.dot(q.normal).abs() >= SLIVER_COS;
                let stacked = d.dot(p.normal).abs() >= SLIVER_COS * d.length();
                if a == b || !facing || !stacked || d.length() >= p.radius.min(q.radius) {
                    continue;
                }
                let into = if cluster_radius[b as usize] > cluster_radius[a as usize]
                    || (cluster_radius[b as usize] == cluster_radius[a as usize] && b < a)
                {
                    b
                } else {
                    a
                };
                // Only a slab markedly narrower than the space it joins (by more than the
                // clustering tolerance) merges: the corner of a uniform corridor does not.
                let (rx, ri) = (cluster_radius[x], cluster_radius[into as usize]);
                if ri - rx > alpha * ri {
                    return Some((x as u32, into));
                }
            }
        }
    }
    None
}

/// A cluster too small to stand alone: its largest max ball is below `min_radius`. Returns the
/// smallest such cluster that has a gate (ties to the lower id) and the neighbour across its
/// widest gate (ties to the lower id) to merge it into.
pub fn find_small(
    gates: &[GateDisk],
    cluster_radius: &[f32],
    min_radius: f32,
) -> Option<(u32, u32)> {
    let mut best: Option<(u32, u32, f32)> = None;
    for (x, &r) in cluster_radius.iter().enumerate() {
        if r >= min_radius || best.is_some_and(|(b, _, _)| cluster_radius[b as usize] <= r) {
            continue;
        }
        let widest = gates
            .iter()
            .filter_map(|g| match g.clusters {
                [a, b] if a as usize == x && b != a => Some((b, g.radius)),
                [a, b] if b as usize == x && a != b => Some((a, g.radius)),
                _ => None,
            })
            .max_by(|p, q| p.1.total_cmp(&q.1).then(q.0.cmp(&p.0)));
        if let Some((into, _)) = widest {
            best = Some((x as u32, into, r));
        }
    }
    best.map(|(x, into, _)| (x, into))
}

/// Merges cluster `from` into `into`: relabels the segmented nodes, drops `from`'s seed and
/// renumbers the clusters after it, so ids stay dense and in creation order.
pub fn merge_cluster(node_cluster: &mut [u32], seeds: &mut Vec<u32>, from: u32, into: u32) {
    for c in node_cluster.iter_mut() {
        if *c == from {
            *c = into;
        }
        if *c > from {
            *c -= 1;
        }
    }
    seeds.remove(from as usize);
}

/// Largest max-ball radius among each cluster's segmented nodes.
pub fn cluster_radius(
    seg: &SegmentedSkeleton,
    node_cluster: &[u32],
    radius: &[f32],
    clusters: usize,
) -> Vec<f32> {
    let mut out = vec![0f32; clusters];
    for (s, &c) in node_cluster.iter().enumerate() {
        let r = radius[seg.nodes[s].skeleton_node as usize];
        out[c as usize] = out[c as usize].max(r);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gate(centre: [f32; 3], normal: [f32; 3], radius: f32, clusters: [u32; 2]) -> GateDisk {
        GateDisk {
            centre: Vec3::from(centre),
            normal: Vec3::from(normal).normalize(),
            radius,
            clusters,
            seg_edge: 0,
            path_index: 0,
        }
    }

    #[test]
    fn a_doorway_slab_merges_into_the_wider_room_and_a_corridor_corner_does_not() {
        // Rooms 0 (r 1.4) and 2 (r 1.5) either side of doorway cluster 1 (r 0.5), gates 0.2 m
        // apart facing each other.
        let gates = [
            gate([4.0, 1.0, 2.0], [1.0, 0.0, 0.0], 0.5, [0, 1]),
            gate([4.2, 1.0, 2.0], [1.0, 0.1, 0.0], 0.5, [1, 2]),
        ];
        assert_eq!(find_sliver(&gates, &[1.4, 0.5, 1.5], 0.2), Some((1, 2)));
        // The same clusters, all as wide: nothing merges.
        assert_eq!(find_sliver(&gates, &[0.5, 0.5, 0.5], 0.2), None);
        // The corner of a uniform corridor (the ring's, as baked at 96): its two gates look
        // like a slab, but the corner is as wide as the legs, so it stays.
        let corner = [
            gate([7.1, 1.2, 6.76], [-0.45, 0.0, 0.89], 0.67, [0, 1]),
            gate([6.76, 1.2, 7.1], [-0.89, 0.0, 0.45], 0.67, [1, 2]),
        ];
        assert_eq!(find_sliver(&corner, &[0.67, 0.67, 0.67], 0.2), None);
        // Two gates side by side in one plane are no slab, whatever the widths.
        let side_by_side = [
            gate([4.0, 1.0, 2.0], [1.0, 0.0, 0.0], 0.5, [0, 1]),
            gate([4.0, 1.0, 2.3], [1.0, 0.0, 0.0], 0.5, [1, 2]),
        ];
        assert_eq!(find_sliver(&side_by_side, &[1.4, 0.5, 1.5], 0.2), None);
        // Gates far apart (a corridor between rooms): nothing merges.
        let far = [
            gate([4.0, 1.0, 2.0], [1.0, 0.0, 0.0], 0.5, [0, 1]),
            gate([6.0, 1.0, 2.0], [1.0, 0.0, 0.0], 0.5, [1, 2]),
        ];
        assert_eq!(find_sliver(&far, &[1.4, 0.5, 1.5], 0.2), None);
    }

    #[test]
    fn a_slowly_narrowing_corridor_is_one_cluster_against_the_popped_node_and_not_against_the_max()
    {
        // 15 segmented nodes in a row, 2 m apart (no ball holds a neighbour), radii 1.0 … 0.3.
        let n = 15u32;
        let seg = SegmentedSkeleton {
            nodes: (0..n)
                .map(|i| visgate_formats::vgate::SegNode {
                    skeleton_node: i,
                    kind: SegNodeKind::Coverage,
                })
                .collect(),
            edges: (0..n - 1)
                .map(|i| visgate_formats::vgate::SegEdge {
                    nodes: [i, i + 1],
                    path: vec![i, i + 1],
                })
                .collect(),
        };
        let position: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(2.0 * i as f32, 0.0, 0.0))
            .collect();
        let radius: Vec<f32> = (0..n).map(|i| 1.0 - 0.05 * i as f32).collect();
        let count = |rule| {
            let params = ClusterParams { alpha: 0.2, rule };
            clusters(&seg, &position, &radius, &params).1.len()
        };
        assert_eq!(count(AlphaRule::PoppedNode), 1);
        // Within 20 % of each cluster's widest: 1.0–0.8, 0.75–0.6, 0.55–0.45, 0.4–0.35, 0.3.
        assert_eq!(count(AlphaRule::ClusterMax), 5);
    }

    #[test]
    fn a_cluster_too_small_to_stand_alone_merges_across_its_widest_gate() {
        // Rooms 0 (2 m balls) and 2 (1.5 m) joined through a slab 1 (0.2 m) by gates of 1.0
        // and 0.5 m, and a thin 3 (0.25 m) off room 2 by a 0.1 m gate.
        let gates = [
            gate([0.0; 3], [1.0, 0.0, 0.0], 1.0, [0, 1]),
            gate([1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.5, [1, 2]),
            gate([2.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.1, [3, 2]),
        ];
        let radius = [2.0, 0.2, 1.5, 0.25];
        // The smallest goes first, across its widest gate; then the next.
        assert_eq!(find_small(&gates, &radius, 0.3), Some((1, 0)));
        assert_eq!(find_small(&gates, &radius, 0.22), Some((1, 0)));
        assert_eq!(
            find_small(&gates, &[2.0, 0.4, 1.5, 0.25], 0.3),
            Some((3, 2))
        );
        // None below the size, and a cluster without gates stays.
        assert_eq!(find_small(&gates, &radius, 0.2), None);
        assert_eq!(find_small(&gates[..1], &[2.0, 3.0, 1.5, 0.25], 0.3), None);
    }

    #[test]
    fn merging_keeps_cluster_ids_dense() {
        let mut node_cluster = vec![0, 1, 2, 3, 1];
        let mut seeds = vec![10, 11, 12, 13];
        merge_cluster(&mut node_cluster, &mut seeds, 1, 3);
        assert_eq!(node_cluster, vec![0, 2, 1, 2, 2]);
        assert_eq!(seeds, vec![10, 12, 13]);
    }
}

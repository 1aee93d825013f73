//! Stage 7, segment: keep the few skeleton nodes that carry its topology and geometry (IV.B.1).
//!
//! 1. **Topology nodes**: every node whose degree is not 2 (ends and junctions). A component
//!    that is a bare loop has none; its widest node (largest radius, then lowest id) becomes
//!    one so the loop has an extremity.
//! 2. **Lines**: the chains of degree-2 nodes between two topology nodes `L1 … Lk`.
//! 3. **Curvature nodes**: on a line, `curv(n) = dist(n, L1Lk) / maxball(n)`, the distance from
//!    `n` to the straight line through the extrema (the paper's; or, with
//!    [`CurvatureTo::Segment`], to the segment between them, which also keeps a node where the
//!    line bends back past an end) over its max-ball radius. If the largest
//!    curvature exceeds 1, that node becomes a curvature node and both halves are processed
//!    again, recursively.
//! 4. **Coverage nodes**: on the lines left, every node must lie in the max ball of one of the
//!    two extrema. Otherwise the least covered node (largest `min(|n − L1| / r1, |n − Lk| / rk)`)
//!    becomes a coverage node, and both halves are processed again.
//! 5. **Narrowing nodes** (visgate's addition): on the lines left, the narrowest node whose
//!    max ball is below `narrowing_ratio` times both end balls is kept, recursively. At coarse
//!    resolutions the two rooms' end balls can cover their doorway, and without this the two
//!    rooms would be one straight edge of similar balls — one cluster.
//!
//! The segmented skeleton keeps the classified nodes; each final line becomes an edge that
//! remembers its path of skeleton nodes. Every skeleton node maps to the nearest extremity of
//! its line, by length along the line.

use glam::Vec3;
use visgate_formats::vgate::{CurvatureTo, SegEdge, SegNode, SegNodeKind, SegmentedSkeleton};

/// Parameters of [`segment`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentParams {
    /// A line node whose curvature exceeds this is kept (the paper uses 1). [Units: ratio]
    pub curvature_limit: f32,
    /// A line node whose max ball is smaller than this fraction of both end balls is kept as
    /// a narrowing node (0 turns the rule off). [Limit: 0..1] [Units: ratio]
    pub narrowing_ratio: f32,
    /// What the curvature measures the distance to.
    pub curvature_to: CurvatureTo,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            curvature_limit: 1.0,
            narrowing_ratio: 0.6,
            curvature_to: CurvatureTo::Line,
        }
    }
}

/// The result of [`segment`].
#[derive(Debug, Clone, PartialEq)]
pub struct Segmented {
    /// The segmented skeleton.
    pub skeleton: SegmentedSkeleton,
    /// For every skeleton node, its segmented node (the nearest extremity of its line).
    pub node_segment: Vec<u32>,
}

/// Segments a skeleton graph given by sorted adjacency lists, node positions and max-ball
/// radii (same units as the positions). With `attach` (from [`crate::simplify`]), a node
/// attached to another is no part of the graph: it takes the segmented node of the node it is
/// attached to.
pub fn segment(
    adjacency: &[Vec<u32>],
    attach: Option<&[u32]>,
    position: &[Vec3],
    radius: &[f32],
    params: &SegmentParams,
) -> Segmented {
    let removed = |i: usize| attach.is_some_and(|a| a[i] as usize != i);
    let mut kind: Vec<Option<SegNodeKind>> = adjacency
        .iter()
        .enumerate()
        .map(|(i, a)| (a.len() != 2 && !removed(i)).then_some(SegNodeKind::Topology))
        .collect();
    mark_bare_loops(adjacency, &removed, radius, &mut kind);
    let lines = topology_lines(adjacency, &kind);
    // Curvature, then coverage, then narrowing, splitting recursively.
    let curvature = |line: &[u32]| curvature_split(line, position, radius, params);
    let coverage = |line: &[u32]| coverage_split(line, position, radius);
    let narrowing = |line: &[u32]| narrowing_split(line, radius, params.narrowing_ratio);
    let lines = split_lines(lines, &curvature, SegNodeKind::Curvature, &mut kind);
    let lines = split_lines(lines, &coverage, SegNodeKind::Coverage, &mut kind);
    let lines = split_lines(lines, &narrowing, SegNodeKind::Narrowing, &mut kind);
    assemble(&kind, lines, position, attach)
}

/// Gives each bare loop (a component without a topology node) one: its widest node.
fn mark_bare_loops(
    adjacency: &[Vec<u32>],
    removed: &dyn Fn(usize) -> bool,
    radius: &[f32],
    kind: &mut [Option<SegNodeKind>],
) {
    let n = adjacency.len();
    let mut seen = vec![false; n];
    for start in 0..n {
        if seen[start] || removed(start) {
            continue;
        }
        let mut comp = vec![start as u32];
        seen[start] = true;
        let mut k = 0;
        while k < comp.len() {
            for &b in &adjacency[comp[k] as usize] {
                if !seen[b as usize] {
                    seen[b as usize] = true;
                    comp.push(b);
                }
            }
            k += 1;
        }
        if comp.iter().all(|&c| kind[c as usize].is_none()) {
            let widest = comp
                .iter()
                .copied()
                .max_by(|&a, &b| {
                    radius[a as usize]
                        .total_cmp(&radius[b as usize])
                        .then(b.cmp(&a))
                })
                .unwrap_or(start as u32);
            kind[widest as usize] = Some(SegNodeKind::Topology);
        }
    }
}

/// The lines between topology nodes, each walked once (from its lower end, in order).
fn topology_lines(adjacency: &[Vec<u32>], kind: &[Option<SegNodeKind>]) -> Vec<Vec<u32>> {
    let mut lines: Vec<Vec<u32>> = Vec::new();
    let mut used_first_step = std::collections::BTreeSet::new();
    for t in 0..adjacency.len() as u32 {
        if kind[t as usize].is_none() {
            continue;
        }
        for &first in &adjacency[t as usize] {
            let key = (t.min(first), t.max(first));
            if kind[first as usize].is_some() {
                // Two adjacent topology nodes: a line without interior.
                if used_first_step.insert(key) {
                    lines.push(vec![t, first]);
                }
                continue;
            }
            if used_first_step.contains(&key) {
                continue;
            }
            let mut line = vec![t, first];
            let (mut prev, mut cur) = (t, first);
            while kind[cur as usize].is_none() {
                let a = &adjacency[cur as usize];
                let next = if a[0] == prev { a[1] } else { a[0] };
                prev = cur;
                cur = next;
                line.push(cur);
            }
            let last = line.len() - 1;
            used_first_step.insert(key);
            used_first_step.insert((
                line[last].min(line[last - 1]),
                line[last].max(line[last - 1]),
            ));
            lines.push(line);
        }
    }
    lines
}

/// Where a line bends most beyond the curvature limit: the interior node farthest from the
/// chord (or its line) in units of its ball's radius.
fn curvature_split(
    line: &[u32],
    position: &[Vec3],
    radius: &[f32],
    params: &SegmentParams,
) -> Option<usize> {
    let (a, b) = (
        position[line[0] as usize],
        position[line[line.len() - 1] as usize],
    );
    let mut best: Option<(f32, usize)> = None;
    for (k, &m) in line.iter().enumerate().take(line.len() - 1).skip(1) {
        let r = radius[m as usize].max(f32::MIN_POSITIVE);
        let p = position[m as usize];
        let d = match params.curvature_to {
            CurvatureTo::Segment => segment_distance(p, a, b),
            CurvatureTo::Line => line_distance(p, a, b),
        };
        let c = d / r;
        if c > params.curvature_limit && best.is_none_or(|(bc, _)| c > bc) {
            best = Some((c, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Where a line leaves both its ends' balls farthest: the interior node whose distance to the
/// nearer end, in units of that end's radius, is largest above 1.
fn coverage_split(line: &[u32], position: &[Vec3], radius: &[f32]) -> Option<usize> {
    let (f, l) = (line[0] as usize, line[line.len() - 1] as usize);
    let mut best: Option<(f32, usize)> = None;
    for (k, &m) in line.iter().enumerate().take(line.len() - 1).skip(1) {
        let p = position[m as usize];
        let cf = (p - position[f]).length() / radius[f].max(f32::MIN_POSITIVE);
        let cl = (p - position[l]).length() / radius[l].max(f32::MIN_POSITIVE);
        let c = cf.min(cl);
        if c > 1.0 && best.is_none_or(|(bc, _)| c > bc) {
            best = Some((c, k));
        }
    }
    best.map(|(_, k)| k)
}

/// A line's narrowest interior node narrower than `ratio` of its narrower end.
fn narrowing_split(line: &[u32], radius: &[f32], ratio: f32) -> Option<usize> {
    let ends = radius[line[0] as usize].min(radius[line[line.len() - 1] as usize]);
    (1..line.len() - 1)
        .filter(|&k| radius[line[k] as usize] < ratio * ends)
        .min_by(|&a, &b| {
            radius[line[a] as usize]
                .total_cmp(&radius[line[b] as usize])
                .then(a.cmp(&b))
        })
}

/// Splits `lines` at the nodes `pick` chooses, recursively, marking them `label`.
fn split_lines(
    lines: Vec<Vec<u32>>,
    pick: &dyn Fn(&[u32]) -> Option<usize>,
    label: SegNodeKind,
    kind: &mut [Option<SegNodeKind>],
) -> Vec<Vec<u32>> {
    let mut done = Vec::new();
    let mut stack: Vec<Vec<u32>> = lines.into_iter().rev().collect();
    while let Some(line) = stack.pop() {
        match (line.len() > 2).then(|| pick(&line)).flatten() {
            Some(k) => {
                kind[line[k] as usize] = Some(label);
                let (a, b) = (line[..=k].to_vec(), line[k..].to_vec());
                stack.push(b);
                stack.push(a);
            }
            None => done.push(line),
        }
    }
    done
}

/// The segmented skeleton: its nodes in skeleton order, an edge per line, and each skeleton
/// node's segmented node (an interior node the nearer end by arc length; a removed node its
/// attachment's).
fn assemble(
    kind: &[Option<SegNodeKind>],
    lines: Vec<Vec<u32>>,
    position: &[Vec3],
    attach: Option<&[u32]>,
) -> Segmented {
    let mut seg_id = vec![u32::MAX; kind.len()];
    let mut nodes = Vec::new();
    for (i, k) in kind.iter().enumerate() {
        if let Some(k) = k {
            seg_id[i] = nodes.len() as u32;
            nodes.push(SegNode {
                skeleton_node: i as u32,
                kind: *k,
            });
        }
    }
    let mut node_segment = seg_id.clone();
    let mut edges = Vec::with_capacity(lines.len());
    for line in lines {
        let (f, l) = (line[0], line[line.len() - 1]);
        // Arc length from the first end; each interior node takes the nearer end.
        let mut s = vec![0f32; line.len()];
        for k in 1..line.len() {
            s[k] =
                s[k - 1] + (position[line[k] as usize] - position[line[k - 1] as usize]).length();
        }
        let total = s[line.len() - 1];
        for k in 1..line.len() - 1 {
            node_segment[line[k] as usize] = if s[k] <= total - s[k] {
                seg_id[f as usize]
            } else {
                seg_id[l as usize]
            };
        }
        edges.push(SegEdge {
            nodes: [seg_id[f as usize], seg_id[l as usize]],
            path: line,
        });
    }
    if let Some(attach) = attach {
        for (i, &a) in attach.iter().enumerate() {
            if a as usize != i {
                node_segment[i] = node_segment[a as usize];
            }
        }
    }
    Segmented {
        skeleton: SegmentedSkeleton { nodes, edges },
        node_segment,
    }
}

/// Distance from `p` to the segment `[a, b]`.
pub fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}

/// Distance from `p` to the straight line through `a` and `b` (to `a` if they coincide).
pub fn line_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 { (p - a).dot(ab) / l2 } else { 0.0 };
    (p - (a + ab * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain(n: usize) -> Vec<Vec<u32>> {
        (0..n)
            .map(|i| {
                let mut a = Vec::new();
                if i > 0 {
                    a.push(i as u32 - 1);
                }
                if i + 1 < n {
                    a.push(i as u32 + 1);
                }
                a
            })
            .collect()
    }

    #[test]
    fn a_straight_line_of_wide_balls_keeps_its_ends_only() {
        let adj = chain(10);
        let pos: Vec<Vec3> = (0..10).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let s = segment(&adj, None, &pos, &[10.0; 10], &SegmentParams::default());
        assert_eq!(s.skeleton.nodes.len(), 2);
        assert_eq!(s.skeleton.edges.len(), 1);
        assert_eq!(s.skeleton.edges[0].path.len(), 10);
        assert_eq!(s.node_segment[3], 0);
        assert_eq!(s.node_segment[6], 1);
    }

    #[test]
    fn a_line_that_bends_back_past_its_end_is_curved_to_the_segment_and_not_to_the_line() {
        // A hook: 0..=10 along x, then back along z = 1 to x = 3; radii 4 (no coverage node).
        let mut pos: Vec<Vec3> = (0..=10).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        pos.extend((3..=10).rev().map(|i| Vec3::new(i as f32, 0.0, 1.0)));
        let adj = chain(pos.len());
        let radius = vec![4.0; pos.len()];
        let kinds = |curvature_to| {
            let p = SegmentParams {
                curvature_to,
                ..SegmentParams::default()
            };
            let s = segment(&adj, None, &pos, &radius, &p);
            s.skeleton
                .nodes
                .iter()
                .filter(|n| n.kind == SegNodeKind::Curvature)
                .count()
        };
        // To the line through (0,0,0) and (3,0,1), no node is farther than 2.2: curvature ≤ 0.55.
        assert_eq!(kinds(CurvatureTo::Line), 0);
        // To the segment, (10,0,0) is 7.07 away from its end: curvature 1.77.
        assert!(kinds(CurvatureTo::Segment) >= 1);
    }

    #[test]
    fn a_bend_makes_a_curvature_node_and_thin_balls_coverage_nodes() {
        // An L: 0..=5 along x, then 6..=10 along z; radii 1.
        let adj = chain(11);
        let pos: Vec<Vec3> = (0..11)
            .map(|i| {
                if i <= 5 {
                    Vec3::new(i as f32, 0.0, 0.0)
                } else {
                    Vec3::new(5.0, 0.0, (i - 5) as f32)
                }
            })
            .collect();
        let s = segment(&adj, None, &pos, &[1.0; 11], &SegmentParams::default());
        let corner = s.skeleton.nodes.iter().find(|n| n.skeleton_node == 5);
        assert_eq!(corner.map(|n| n.kind), Some(SegNodeKind::Curvature));
        assert!(
            s.skeleton
                .nodes
                .iter()
                .any(|n| n.kind == SegNodeKind::Coverage)
        );
        // Every line node lies within an end's ball.
        for e in &s.skeleton.edges {
            let (f, l) = (e.path[0] as usize, e.path[e.path.len() - 1] as usize);
            for &m in &e.path {
                let p = pos[m as usize];
                assert!((p - pos[f]).length() <= 1.0 + 1e-6 || (p - pos[l]).length() <= 1.0 + 1e-6);
            }
        }
    }
}

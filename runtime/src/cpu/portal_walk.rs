//! The portal walk (CPU side; portals.wgsl is the GPU twin): from a point in one visibility
//! cluster, the segment to a point of another leaves each cluster it is in through the portal
//! of that cluster it crosses first, until it reaches the other point's cluster.
//!
//! A cluster's portals (the planar pieces of its interfaces, up to ~900 of them on a large
//! cluster of Crytek Sponza) sit in a bounding-volume hierarchy of their open cells' boxes: a
//! step descends, nearer child first, only into boxes that the segment meets before the
//! nearest portal found so far, so it costs a few box tests, not a test of every piece. The
//! boxes are padded well past the masks' edge slack, so the walk's answer is the same with or
//! without them.

use glam::Vec3;
use visgate_formats::vgate::Portal;

use super::gates::{GateLevel, Walk};

/// A node of a cluster's portal hierarchy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PortalNode {
    /// Box corners (padded). [Units: m]
    pub bounds: [Vec3; 2],
    /// What the box holds.
    pub kind: NodeKind,
}

/// An inner node's children or a leaf's portals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// Children `first` and `first + 1` (node indices), split along `axis` (the first child
    /// holds the lower centres).
    Inner {
        /// Index of the first child.
        first: u32,
        /// 0, 1 or 2 (x, y, z).
        axis: u32,
    },
    /// Portal indices `indices[first..first + count]`.
    Leaf {
        /// Into [`PortalBvh::indices`].
        first: u32,
        /// 1..=[`LEAF_PORTALS`].
        count: u32,
    },
}

/// Every cluster's portal hierarchy, in one node array.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PortalBvh {
    /// Each cluster's root node (`u32::MAX`: the cluster has no portal).
    pub roots: Vec<u32>,
    /// The nodes; children are adjacent.
    pub nodes: Vec<PortalNode>,
    /// Portal indices of the leaves.
    pub indices: Vec<u32>,
}

/// Padding of a portal's box: a hundredth of a mask cell (ten times the masks' edge slack), and
/// a millionth of the coordinates' size for the rounding of far-off levels.
fn pad(p: &Portal, corner: Vec3) -> f32 {
    p.cell_m * 0.01 + corner.abs().max_element() * 1e-6
}

/// The box of the open cells of `p` (its mask's rectangle if no cell is open), padded.
pub fn portal_bounds(p: &Portal) -> [Vec3; 2] {
    let (mut i0, mut j0, mut i1, mut j1) = (u32::MAX, u32::MAX, 0, 0);
    for j in 0..p.size[1] {
        for i in 0..p.size[0] {
            if p.cell(i64::from(i), i64::from(j)) {
                (i0, j0, i1, j1) = (i0.min(i), j0.min(j), i1.max(i + 1), j1.max(j + 1));
            }
        }
    }
    if i0 == u32::MAX {
        (i0, j0, i1, j1) = (0, 0, p.size[0], p.size[1]);
    }
    let (o, u, v) = (Vec3::from(p.origin_m), Vec3::from(p.u), Vec3::from(p.v));
    let at = |i: u32, j: u32| o + (u * i as f32 + v * j as f32) * p.cell_m;
    let corners = [at(i0, j0), at(i1, j0), at(i0, j1), at(i1, j1)];
    let lo = corners.iter().copied().fold(Vec3::INFINITY, Vec3::min);
    let hi = corners.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
    let e = pad(p, lo.abs().max(hi.abs()));
    [lo - e, hi + e]
}

/// Portals per leaf at most.
pub const LEAF_PORTALS: usize = 4;

/// Depth of a hierarchy at most (median splits halve a node: 2^30 portals would fit), the size
/// of the walk's stack.
pub const MAX_DEPTH: usize = 31;

impl PortalBvh {
    /// The hierarchies of `clusters` clusters' portals: each node's portals split at the median
    /// of their centres along the longest axis of the centres until a leaf holds at most
    /// [`LEAF_PORTALS`].
    pub fn new(portals: &[Portal], clusters: usize) -> PortalBvh {
        let bounds: Vec<[Vec3; 2]> = portals.iter().map(portal_bounds).collect();
        let mut of_cluster = vec![Vec::new(); clusters];
        for (i, p) in portals.iter().enumerate() {
            for c in p.clusters {
                if let Some(l) = of_cluster.get_mut(c as usize) {
                    l.push(i as u32);
                }
            }
        }
        let mut bvh = PortalBvh::default();
        for list in of_cluster {
            if list.is_empty() {
                bvh.roots.push(u32::MAX);
                continue;
            }
            bvh.roots.push(bvh.nodes.len() as u32);
            bvh.nodes.push(hull(&list, &bounds));
            bvh.split(bvh.nodes.len() - 1, list, &bounds);
        }
        bvh
    }

    /// Makes node `at` (whose box is set) hold `list`: a leaf, or two children that split it.
    fn split(&mut self, at: usize, mut list: Vec<u32>, bounds: &[[Vec3; 2]]) {
        if list.len() <= LEAF_PORTALS {
            let first = self.indices.len() as u32;
            let count = list.len() as u32;
            self.indices.extend(list);
            self.nodes[at].kind = NodeKind::Leaf { first, count };
            return;
        }
        let centre = |i: u32| (bounds[i as usize][0] + bounds[i as usize][1]) * 0.5;
        let [lo, hi] = list
            .iter()
            .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &i| {
                [lo.min(centre(i)), hi.max(centre(i))]
            });
        let axis = (hi - lo).max_position();
        list.sort_by(|&x, &y| centre(x)[axis].total_cmp(&centre(y)[axis]).then(x.cmp(&y)));
        let rest = list.split_off(list.len() / 2);
        let first = self.nodes.len() as u32;
        self.nodes[at].kind = NodeKind::Inner {
            first,
            axis: axis as u32,
        };
        self.nodes.push(hull(&list, bounds));
        self.nodes.push(hull(&rest, bounds));
        self.split(first as usize, list, bounds);
        self.split(first as usize + 1, rest, bounds);
    }

    /// The depth of the deepest leaf (a root alone: 1).
    pub fn depth(&self) -> usize {
        fn depth(b: &PortalBvh, n: u32) -> usize {
            match b.nodes[n as usize].kind {
                NodeKind::Leaf { .. } => 1,
                NodeKind::Inner { first, .. } => 1 + depth(b, first).max(depth(b, first + 1)),
            }
        }
        self.roots
            .iter()
            .filter(|&&r| r != u32::MAX)
            .map(|&r| depth(self, r))
            .max()
            .unwrap_or(0)
    }
}

/// The box of `list`'s portals, as a node without children yet.
fn hull(list: &[u32], bounds: &[[Vec3; 2]]) -> PortalNode {
    let bounds = list
        .iter()
        .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &i| {
            [lo.min(bounds[i as usize][0]), hi.max(bounds[i as usize][1])]
        });
    PortalNode {
        bounds,
        kind: NodeKind::Leaf { first: 0, count: 0 },
    }
}

/// The reciprocal of a direction per axis for [`segment_box`] (0 on an axis it does not move
/// along).
pub fn inverse(d: Vec3) -> Vec3 {
    Vec3::from_array(
        d.to_array()
            .map(|x| if x.abs() < 1e-30 { 0.0 } else { 1.0 / x }),
    )
}

/// Whether `a + d·t` for some t in [t0, t1] lies in the box `[lo, hi]` (slab test; an axis the
/// segment runs along needs `a` inside the slab), with `inv` = [`inverse`]`(d)`. portals.wgsl's
/// `segment_box` is its twin.
pub fn segment_box(a: Vec3, inv: Vec3, (t0, t1): (f32, f32), [lo, hi]: [Vec3; 2]) -> bool {
    let (mut near, mut far) = (t0, t1);
    for k in 0..3 {
        if inv[k] == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (ta, tb) = ((lo[k] - a[k]) * inv[k], (hi[k] - a[k]) * inv[k]);
        near = near.max(ta.min(tb));
        far = far.min(ta.max(tb));
    }
    near <= far
}

impl GateLevel {
    /// The portal walk: from `a` in cluster `ca`, the segment to `b` leaves each cluster it is
    /// in through the portal of that cluster it crosses first (its plane hit inside its mask,
    /// going out), until it is in `cb`. Endpoints may lie up to 1.5 voxels on the far side of
    /// a portal's plane (the planes fit voxel faces). At most `max_walk` portals.
    pub fn walk(&self, a: Vec3, ca: u32, b: Vec3, cb: u32, max_walk: u32) -> Walk {
        if ca == cb {
            return Walk::Visible(0);
        }
        let d = b - a;
        let len = d.length();
        if len <= 0.0 || !len.is_finite() {
            return Walk::Blocked;
        }
        let slack = 1.5 * self.voxel_size() / len;
        let inv = inverse(d);
        let (mut c, mut t0, mut last) = (ca, -slack, usize::MAX);
        for step in 0..max_walk {
            let Some((t, pi)) = self.first_exit(a, d, inv, c, (t0, 1.0 + slack), last) else {
                return Walk::Blocked;
            };
            let p = &self.baked().topology.portals[pi];
            let other = if p.clusters[0] == c {
                p.clusters[1]
            } else {
                p.clusters[0]
            };
            if other == cb {
                return Walk::Visible(step + 1);
            }
            (c, t0, last) = (other, t, pi);
        }
        Walk::Limit
    }

    /// The portal of cluster `c` that `a + d·t` leaves it through first for t in `range`
    /// (plane crossed going out, inside the mask), other than `last`: (t, portal index).
    fn first_exit(
        &self,
        a: Vec3,
        d: Vec3,
        inv: Vec3,
        c: u32,
        (t0, t_end): (f32, f32),
        last: usize,
    ) -> Option<(f32, usize)> {
        let portals = &self.baked().topology.portals;
        let bvh = self.portal_bvh();
        let len = d.length();
        let mut best: Option<(f32, usize)> = None;
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut top = 0;
        if let Some(&root) = bvh.roots.get(c as usize).filter(|&&r| r != u32::MAX) {
            stack[0] = root;
            top = 1;
        }
        while top > 0 {
            top -= 1;
            let node = bvh.nodes[stack[top] as usize];
            let t1 = best.map_or(t_end, |(bt, _)| bt);
            if !segment_box(a, inv, (t0, t1), node.bounds) {
                continue;
            }
            let (first, count) = match node.kind {
                NodeKind::Inner { first, axis } => {
                    // The nearer child last, so that it is taken first.
                    let up = d[axis as usize] >= 0.0;
                    stack[top] = first + u32::from(up);
                    stack[top + 1] = first + u32::from(!up);
                    top += 2;
                    continue;
                }
                NodeKind::Leaf { first, count } => (first as usize, count as usize),
            };
            for &pi in &bvh.indices[first..first + count] {
                let pi = pi as usize;
                let p = &portals[pi];
                let out = if p.clusters[0] == c { 1.0 } else { -1.0 };
                let n = Vec3::from(p.normal) * out;
                let den = d.dot(n);
                if pi == last || den <= f32::EPSILON * len {
                    continue;
                }
                let t = (Vec3::from(p.origin_m) - a).dot(n) / den;
                if t < t0 || t > t_end || best.is_some_and(|(bt, _)| bt <= t) {
                    continue;
                }
                if p.covers((a + d * t).to_array()) {
                    best = Some((t, pi));
                }
            }
        }
        best
    }

    /// The portals packed into words for portals.wgsl: `[clusters, record base, portals]`,
    /// each cluster's root node (absolute offset; `u32::MAX` for none), the nodes
    /// ([`NODE_WORDS`] each: box minimum, box maximum, then for an inner node the absolute
    /// offset of its first child and `INNER | axis`, for a leaf the absolute offset of its
    /// first portal index and its count), the portal indices, then [`PORTAL_RECORD_WORDS`]
    /// words per portal (origin, cell, normal, width, u, height, v, mask offset, the two
    /// clusters, two zeros) and the masks.
    pub fn portal_words(&self) -> Vec<u32> {
        let portals = &self.baked().topology.portals;
        let bvh = self.portal_bvh();
        let clusters = bvh.roots.len() as u32;
        let nodes_at = 3 + clusters;
        let index_at = nodes_at + NODE_WORDS * bvh.nodes.len() as u32;
        let records = index_at + bvh.indices.len() as u32;
        let mut w = vec![clusters, records, portals.len() as u32];
        w.extend(bvh.roots.iter().map(|&r| {
            if r == u32::MAX {
                r
            } else {
                nodes_at + NODE_WORDS * r
            }
        }));
        let f = |v: Vec3| v.to_array().map(f32::to_bits);
        for n in &bvh.nodes {
            w.extend(f(n.bounds[0]));
            w.extend(f(n.bounds[1]));
            w.extend(match n.kind {
                NodeKind::Inner { first, axis } => [nodes_at + NODE_WORDS * first, INNER | axis],
                NodeKind::Leaf { first, count } => [index_at + first, count],
            });
        }
        w.extend(&bvh.indices);
        let mut mask_at = records + PORTAL_RECORD_WORDS * portals.len() as u32;
        for p in portals {
            let f = |v: [f32; 3]| v.map(f32::to_bits);
            w.extend(f(p.origin_m));
            w.push(p.cell_m.to_bits());
            w.extend(f(p.normal));
            w.push(p.size[0]);
            w.extend(f(p.u));
            w.push(p.size[1]);
            w.extend(f(p.v));
            w.extend([mask_at, p.clusters[0], p.clusters[1], 0, 0]);
            mask_at += p.mask.len() as u32;
        }
        for p in portals {
            w.extend(&p.mask);
        }
        w
    }
}

/// Words per hierarchy node in [`GateLevel::portal_words`].
pub const NODE_WORDS: u32 = 8;

/// The flag of an inner node in its last word ([`GateLevel::portal_words`]).
pub const INNER: u32 = 1 << 31;

/// Words per portal record in [`GateLevel::portal_words`].
pub const PORTAL_RECORD_WORDS: u32 = 20;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_finds_boxes_on_the_segment_only() {
        let b = [Vec3::new(1.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0)];
        let x = Vec3::X * 4.0;
        assert!(segment_box(Vec3::ZERO, inverse(x), (0.0, 1.0), b));
        assert!(!segment_box(Vec3::ZERO, inverse(x), (0.0, 0.2), b));
        assert!(!segment_box(Vec3::ZERO, inverse(x), (0.6, 1.0), b));
        // Along an axis: inside the slab or not.
        assert!(!segment_box(
            Vec3::new(0.0, 2.0, 0.0),
            inverse(x),
            (0.0, 1.0),
            b
        ));
        assert!(segment_box(
            Vec3::new(1.5, -3.0, 0.0),
            inverse(Vec3::Y * 4.0),
            (0.0, 1.0),
            b
        ));
        // Diagonal past a corner.
        assert!(!segment_box(
            Vec3::new(0.0, 2.5, 0.0),
            inverse(Vec3::new(4.0, -1.0, 0.0)),
            (0.0, 1.0),
            b
        ));
    }
}

/// A pixel–VPL pair of a view whose surfaces face each other, with both ends' visibility
/// clusters and the exact answer (a shadow ray between them).
#[derive(Debug, Clone, Copy)]
pub struct FacingPair {
    /// The pixel's surface point. [Units: m]
    pub point: Vec3,
    /// Its face's normal (facing the camera).
    pub point_normal: Vec3,
    /// Its visibility cluster.
    pub here: u32,
    /// The VPL's position. [Units: m]
    pub vpl: Vec3,
    /// Its normal (on its lit side).
    pub vpl_normal: Vec3,
    /// Its visibility cluster.
    pub there: u32,
    /// Whether the shadow ray between them is clear.
    pub exact: bool,
}

impl FacingPair {
    /// The pair's VPL end.
    pub fn vpl_end(&self) -> super::gates::End {
        super::gates::End {
            position: self.vpl,
            normal: self.vpl_normal,
            cluster: Some(self.there),
        }
    }

    /// The pair's pixel end.
    pub fn point_end(&self) -> super::gates::End {
        super::gates::End {
            position: self.point,
            normal: self.point_normal,
            cluster: Some(self.here),
        }
    }
}

/// Calls `f` with every pixel–VPL pair of `view` (pixel centres) whose surfaces face each other
/// and both lie in a cluster of `gates`: what the portal walk is held to against shadow rays
/// (tests/portals.rs, examples/portal_agreement.rs).
pub fn facing_pairs(
    tracer: &super::tracer::Tracer,
    gates: &GateLevel,
    view: &crate::camera::View,
    vpls: &[crate::vpl::Vpl],
    mut f: impl FnMut(&FacingPair),
) {
    let [w, h] = view.size;
    for y in 0..h {
        for x in 0..w {
            let dir = view.ray_dir(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(s) = tracer.trace(view.eye, dir) else {
                continue;
            };
            let Some(here) = gates.cluster_at(s.position, s.normal) else {
                continue;
            };
            let from = s.position + s.geometric_normal * tracer.epsilon_m;
            for v in vpls {
                let (vp, vn) = (Vec3::from(v.position), Vec3::from(v.normal));
                let to = vp - s.position;
                if to.dot(s.normal) <= 0.0 || (-to).dot(vn) <= 0.0 {
                    continue;
                }
                let Some(there) = gates.cluster_at(vp, vn) else {
                    continue;
                };
                f(&FacingPair {
                    point: s.position,
                    point_normal: s.geometric_normal,
                    here,
                    vpl: vp,
                    vpl_normal: vn,
                    there,
                    exact: !tracer.occluded(from, vp + vn * tracer.epsilon_m),
                });
            }
        }
    }
}

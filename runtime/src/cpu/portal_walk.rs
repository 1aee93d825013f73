//! The portal walk (CPU side; portals.wgsl is the GPU twin): from a point in one visibility
//! cluster, the segment to a point of another leaves each cluster it is in through the portal
//! of that cluster it crosses first, until it reaches the other point's cluster.
//!
//! A cluster's portals are grouped by the neighbour they lead to, each group with the box of
//! its portals' open cells: the walk tests a group's portals only where the segment meets the
//! box (a slab test), so a step costs a few box tests, not a test of every piece of every
//! interface of the cluster. The box is padded well past the masks' edge slack, so the walk's
//! answer is the same with or without it.

use glam::Vec3;
use visgate_formats::vgate::Portal;

use super::gates::{GateLevel, Walk};

/// The portals of one cluster that lead to one neighbour, and the box of their open cells.
#[derive(Debug, Clone, PartialEq)]
pub struct PortalGroup {
    /// The neighbour cluster.
    pub neighbour: u32,
    /// Box corners (padded). [Units: m]
    pub bounds: [Vec3; 2],
    /// Indices into the level's portals.
    pub portals: Vec<usize>,
}

/// Padding of a group's box: a hundredth of a mask cell (ten times the masks' edge slack), and
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

/// Portals per group at most: an interface of many planar pieces is split into groups of
/// nearby pieces, each with its own box, so that a walk tests the pieces near its segment.
pub const GROUP_PORTALS: usize = 8;

/// Each cluster's portal groups (of `clusters`): per neighbour, in increasing order, its
/// portals split at the median of their centres along the longest axis until a group holds at
/// most [`GROUP_PORTALS`].
pub fn portal_groups(portals: &[Portal], clusters: usize) -> Vec<Vec<PortalGroup>> {
    let bounds: Vec<[Vec3; 2]> = portals.iter().map(portal_bounds).collect();
    let mut by_pair: Vec<std::collections::BTreeMap<u32, Vec<usize>>> =
        vec![Default::default(); clusters];
    for (i, p) in portals.iter().enumerate() {
        for (k, &c) in p.clusters.iter().enumerate() {
            if let Some(m) = by_pair.get_mut(c as usize) {
                m.entry(p.clusters[1 - k]).or_default().push(i);
            }
        }
    }
    by_pair
        .into_iter()
        .map(|m| {
            let mut groups = Vec::new();
            for (neighbour, list) in m {
                split_group(neighbour, list, &bounds, &mut groups);
            }
            groups
        })
        .collect()
}

/// `list`'s portals as groups of at most [`GROUP_PORTALS`], split at the median along the
/// longest axis of their centres, appended to `out`.
fn split_group(
    neighbour: u32,
    mut list: Vec<usize>,
    bounds: &[[Vec3; 2]],
    out: &mut Vec<PortalGroup>,
) {
    let hull = |l: &[usize]| {
        l.iter()
            .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &i| {
                [lo.min(bounds[i][0]), hi.max(bounds[i][1])]
            })
    };
    if list.len() <= GROUP_PORTALS {
        out.push(PortalGroup {
            neighbour,
            bounds: hull(&list),
            portals: list,
        });
        return;
    }
    let centre = |i: usize| (bounds[i][0] + bounds[i][1]) * 0.5;
    let [lo, hi] = list
        .iter()
        .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &i| {
            [lo.min(centre(i)), hi.max(centre(i))]
        });
    let axis = (hi - lo).max_position();
    list.sort_by(|&x, &y| centre(x)[axis].total_cmp(&centre(y)[axis]).then(x.cmp(&y)));
    let rest = list.split_off(list.len() / 2);
    split_group(neighbour, list, bounds, out);
    split_group(neighbour, rest, bounds, out);
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
        let portals = &self.baked().topology.portals;
        let d = b - a;
        let len = d.length();
        if len <= 0.0 || !len.is_finite() {
            return Walk::Blocked;
        }
        let slack = 1.5 * self.voxel_size() / len;
        let inv = inverse(d);
        let (mut c, mut t0, mut last) = (ca, -slack, usize::MAX);
        for step in 0..max_walk {
            let mut best: Option<(f32, usize, u32)> = None;
            for g in self.portal_groups(c) {
                let t1 = best.map_or(1.0 + slack, |(bt, _, _)| bt);
                if !segment_box(a, inv, (t0, t1), g.bounds) {
                    continue;
                }
                for &pi in &g.portals {
                    let p = &portals[pi];
                    let out = if p.clusters[0] == c { 1.0 } else { -1.0 };
                    let n = Vec3::from(p.normal) * out;
                    let den = d.dot(n);
                    if pi == last || den <= f32::EPSILON * len {
                        continue;
                    }
                    let t = (Vec3::from(p.origin_m) - a).dot(n) / den;
                    if t < t0 || t > 1.0 + slack || best.is_some_and(|(bt, _, _)| bt <= t) {
                        continue;
                    }
                    if p.covers((a + d * t).to_array()) {
                        best = Some((t, pi, g.neighbour));
                    }
                }
            }
            let Some((t, pi, other)) = best else {
                return Walk::Blocked;
            };
            if other == cb {
                return Walk::Visible(step + 1);
            }
            (c, t0, last) = (other, t, pi);
        }
        Walk::Limit
    }

    /// The portals packed into words for portals.wgsl: `[clusters, record base, portals]`,
    /// `clusters + 1` absolute offsets of each cluster's first group, the groups
    /// ([`GROUP_WORDS`] each: box minimum, box maximum, neighbour, absolute offsets of the
    /// first and past the last of its portal indices, a zero), the portal indices, then
    /// [`PORTAL_RECORD_WORDS`] words per portal (origin, cell, normal, width, u, height, v,
    /// mask offset, the two clusters, two zeros) and the masks.
    pub fn portal_words(&self) -> Vec<u32> {
        let portals = &self.baked().topology.portals;
        let groups = self.all_portal_groups();
        let clusters = groups.len() as u32;
        let group_count: usize = groups.iter().map(Vec::len).sum();
        let index_at = 3 + clusters + 1 + GROUP_WORDS * group_count as u32;
        let index_len: usize = groups.iter().flatten().map(|g| g.portals.len()).sum();
        let records = index_at + index_len as u32;
        let mut w = vec![clusters, records, portals.len() as u32];
        let mut at = 3 + clusters + 1;
        for l in groups {
            w.push(at);
            at += GROUP_WORDS * l.len() as u32;
        }
        w.push(at);
        let f = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut first = index_at;
        for g in groups.iter().flatten() {
            let end = first + g.portals.len() as u32;
            w.extend(f(g.bounds[0]));
            w.extend(f(g.bounds[1]));
            w.extend([g.neighbour, first, end, 0]);
            first = end;
        }
        for g in groups.iter().flatten() {
            w.extend(g.portals.iter().map(|&i| i as u32));
        }
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

/// Words per portal group in [`GateLevel::portal_words`].
pub const GROUP_WORDS: u32 = 10;

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

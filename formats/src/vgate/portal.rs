//! Portals: the true openings between adjacent visibility clusters (the cure the
//! visibility-gates paper names in section VI: "polygons instead of disks… perfect manifolds
//! separating clusters"). A portal is a planar piece of the interface where the empty voxels
//! of one cluster touch those of another, stored as its plane and a coverage mask in the
//! plane's frame: a point of the plane is in the opening when its mask cell is set.

use serde::{Deserialize, Serialize};

/// A planar piece of the interface between two clusters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Portal {
    /// The two clusters: `clusters[0]` behind the plane, `clusters[1]` on its normal's side.
    pub clusters: [u32; 2],
    /// The mask's corner (cell (0, 0)'s minimum), a point of the plane, metres.
    pub origin_m: [f32; 3],
    /// Unit normal, from `clusters[0]` to `clusters[1]`.
    pub normal: [f32; 3],
    /// Unit axis of the mask's columns (perpendicular to the normal).
    pub u: [f32; 3],
    /// Unit axis of the mask's rows (`normal × u`).
    pub v: [f32; 3],
    /// Edge of a mask cell, metres. [Limit: > 0]
    pub cell_m: f32,
    /// Mask cells along u and v. [Limit: each >= 1, product <= 2^20]
    pub size: [u32; 2],
    /// Coverage bits, row-major (u fastest), 32 per word, bit k of word k / 32 at k % 32.
    pub mask: Vec<u32>,
    /// Interface voxel faces this piece covers.
    pub faces: u32,
}

/// How far outside an open mask cell a point still counts as in it. [Units: cells]
pub const EDGE_SLACK: f32 = 1e-3;

/// Largest number of mask cells a portal may have.
pub const MAX_MASK_CELLS: u64 = 1 << 20;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Portal {
    /// Mask words for `size`.
    pub fn words_for(size: [u32; 2]) -> usize {
        (size[0] as usize * size[1] as usize).div_ceil(32)
    }

    /// Whether mask cell (i, j) is set (false outside the mask).
    pub fn cell(&self, i: i64, j: i64) -> bool {
        let (w, h) = (i64::from(self.size[0]), i64::from(self.size[1]));
        if i < 0 || j < 0 || i >= w || j >= h {
            return false;
        }
        let k = (j * w + i) as usize;
        self.mask
            .get(k / 32)
            .is_some_and(|m| m >> (k % 32) & 1 == 1)
    }

    /// Whether the point `p` of the plane (or its projection onto it) falls in the opening: in
    /// an open cell, or within [`EDGE_SLACK`] cells of one (so that a point on a cell's edge,
    /// as a VPL on a doorway's jamb is, counts the same at every scale of the level).
    pub fn covers(&self, p: [f32; 3]) -> bool {
        let d = self.offset(p);
        let x = dot(d, self.u) / self.cell_m;
        let y = dot(d, self.v) / self.cell_m;
        if !(x.is_finite() && y.is_finite()) {
            return false;
        }
        let e = EDGE_SLACK;
        let (i, j) = (x.floor(), y.floor());
        if self.cell(i as i64, j as i64) {
            return true;
        }
        // Off a cell's edge by more than the slack, the neighbours' cells cannot count.
        if x - i > e && x - i < 1.0 - e && y - j > e && y - j < 1.0 - e {
            return false;
        }
        [(-e, 0.0), (e, 0.0), (0.0, -e), (0.0, e)]
            .iter()
            .any(|(dx, dy)| self.cell((x + dx).floor() as i64, (y + dy).floor() as i64))
    }

    /// Signed distance of `p` from the plane, along the normal, metres.
    pub fn distance(&self, p: [f32; 3]) -> f32 {
        dot(self.offset(p), self.normal)
    }

    fn offset(&self, p: [f32; 3]) -> [f32; 3] {
        std::array::from_fn(|a| p[a] - self.origin_m[a])
    }

    /// Set mask cells.
    pub fn open_cells(&self) -> u64 {
        self.mask.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// Checks the portal against a level of `clusters` clusters; a message says what is wrong.
    pub fn check(&self, clusters: usize) -> Result<(), String> {
        if self.clusters.iter().any(|&c| c as usize >= clusters)
            || self.clusters[0] == self.clusters[1]
        {
            return Err(format!(
                "clusters {:?} ({clusters} clusters)",
                self.clusters
            ));
        }
        let unit = |a: [f32; 3]| (dot(a, a) - 1.0).abs() < 1e-3;
        let finite = self
            .origin_m
            .iter()
            .chain(&self.normal)
            .chain(&self.u)
            .chain(&self.v)
            .all(|x| x.is_finite());
        if !finite || !unit(self.normal) || !unit(self.u) || !unit(self.v) {
            return Err("plane or frame not finite and unit".into());
        }
        if !(self.cell_m.is_finite() && self.cell_m > 0.0) {
            return Err(format!("mask cell {} m", self.cell_m));
        }
        let cells = u64::from(self.size[0]) * u64::from(self.size[1]);
        if self.size.contains(&0) || cells > MAX_MASK_CELLS {
            return Err(format!("mask size {:?}", self.size));
        }
        if self.mask.len() != Self::words_for(self.size) {
            return Err(format!(
                "mask of {} words for {:?} cells",
                self.mask.len(),
                self.size
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covers_reads_the_cell_under_a_point() {
        let mut p = Portal {
            clusters: [0, 1],
            origin_m: [1.0, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
            u: [0.0, 1.0, 0.0],
            v: [0.0, 0.0, 1.0],
            cell_m: 0.5,
            size: [3, 2],
            mask: vec![0],
            faces: 1,
        };
        // Cell (2, 1): k = 5.
        p.mask[0] = 1 << 5;
        assert!(p.covers([1.0, 1.2, 0.7]));
        assert!(!p.covers([1.0, 0.2, 0.7]));
        assert!(!p.covers([1.0, 1.6, 0.7]));
        assert!(!p.covers([1.0, -0.1, 0.1]));
        assert_eq!(p.distance([3.0, 9.0, 9.0]), 2.0);
        assert!(p.check(2).is_ok());
        assert!(p.check(1).is_err());
        p.mask.push(0);
        assert!(p.check(2).is_err());
    }
}

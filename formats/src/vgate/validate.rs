//! The format's rules, checked on every level read and before every level written.

use super::{BakedLevel, Topology};
use crate::error::VgateError;

impl BakedLevel {
    /// Checks every length, index and value against the format's rules.
    pub fn validate(&self) -> Result<(), VgateError> {
        self.check_grids()?;
        let t = &self.topology;
        check_skeleton(t, self.info.grid.dims)?;
        check_segmented(t)?;
        check_clusters_and_gates(t)?;
        if let Some(m) = self.voxel_cluster.max_value()
            && m as usize >= t.clusters.len()
        {
            return oob(format!(
                "voxel_cluster value {m} ({} clusters)",
                t.clusters.len()
            ));
        }
        Ok(())
    }

    /// The level's grid and sight grid (finite, positive, not overflowing), the voxel→cluster
    /// grid's and the open voxels' lengths.
    fn check_grids(&self) -> Result<(), VgateError> {
        let g = &self.info.grid;
        for (what, g) in [("", g), ("sight ", &self.info.sight_grid)] {
            if !(g.voxel_size_m.is_finite() && g.voxel_size_m > 0.0) {
                return bad(format!("{what}voxel size {} m", g.voxel_size_m));
            }
            if g.origin_m.iter().any(|x| !x.is_finite()) || g.dims.contains(&0) {
                return bad(format!(
                    "{what}grid origin {:?} / dims {:?}",
                    g.origin_m, g.dims
                ));
            }
        }
        let voxels = g
            .voxel_count()
            .ok_or_else(|| VgateError::BadValue(format!("grid dims {:?} overflow", g.dims)))?;
        let sight_voxels = self.info.sight_grid.voxel_count().ok_or_else(|| {
            VgateError::BadValue(format!(
                "sight grid dims {:?} overflow",
                self.info.sight_grid.dims
            ))
        })?;
        if self.voxel_cluster.len() as u64 != voxels {
            return Err(VgateError::Length(format!(
                "voxel_cluster grid has {} values but the grid has {voxels} voxels",
                self.voxel_cluster.len()
            )));
        }
        if self.open.len() != sight_voxels {
            return Err(VgateError::Length(format!(
                "the open voxels hold {} bits but the sight grid has {sight_voxels} voxels",
                self.open.len()
            )));
        }
        Ok(())
    }
}

/// An index out of range.
fn oob(what: String) -> Result<(), VgateError> {
    Err(VgateError::IndexOutOfRange(what))
}

/// A value outside its rules.
fn bad(what: String) -> Result<(), VgateError> {
    Err(VgateError::BadValue(what))
}

/// The skeleton's nodes (voxels in the grid of `dims`, finite positions and radii ≥ 0) and
/// edges (between two of its nodes).
fn check_skeleton(t: &Topology, dims: [u32; 3]) -> Result<(), VgateError> {
    let n_nodes = t.skeleton.nodes.len();
    for (i, n) in t.skeleton.nodes.iter().enumerate() {
        if (0..3).any(|a| n.voxel[a] >= dims[a]) {
            return oob(format!(
                "skeleton node {i} voxel {:?} outside the grid",
                n.voxel
            ));
        }
        if n.position_m.iter().any(|x| !x.is_finite())
            || !(n.radius_m.is_finite() && n.radius_m >= 0.0)
        {
            return bad(format!("skeleton node {i} position/radius"));
        }
    }
    for (i, e) in t.skeleton.edges.iter().enumerate() {
        if e.iter().any(|&v| v as usize >= n_nodes) || e[0] == e[1] {
            return oob(format!("skeleton edge {i} {e:?} ({n_nodes} nodes)"));
        }
    }
    Ok(())
}

/// The segmented skeleton's nodes and edges (their paths through the skeleton), and the
/// node→cluster map (one cluster a segmented node).
fn check_segmented(t: &Topology) -> Result<(), VgateError> {
    let n_nodes = t.skeleton.nodes.len();
    let n_seg = t.segmented.nodes.len();
    let n_clusters = t.clusters.len();
    for (i, s) in t.segmented.nodes.iter().enumerate() {
        if s.skeleton_node as usize >= n_nodes {
            return oob(format!(
                "segmented node {i} → skeleton node {}",
                s.skeleton_node
            ));
        }
    }
    for (i, e) in t.segmented.edges.iter().enumerate() {
        if e.nodes.iter().any(|&v| v as usize >= n_seg) {
            return oob(format!("segmented edge {i} {:?} ({n_seg} nodes)", e.nodes));
        }
        if let Some(p) = e.path.iter().find(|&&p| p as usize >= n_nodes) {
            return oob(format!(
                "segmented edge {i} path node {p} ({n_nodes} nodes)"
            ));
        }
    }
    if t.node_cluster.len() != n_seg {
        return Err(VgateError::Length(format!(
            "node→cluster has {} entries for {n_seg} segmented nodes",
            t.node_cluster.len()
        )));
    }
    if let Some(c) = t.node_cluster.iter().find(|&&c| c as usize >= n_clusters) {
        return oob(format!("node→cluster value {c} ({n_clusters} clusters)"));
    }
    Ok(())
}

/// The clusters (a segmented seed, finite bounds), the gates (two clusters, a segmented
/// edge, a finite centre, a unit normal, a radius ≥ 0) and the portals (their own rules).
fn check_clusters_and_gates(t: &Topology) -> Result<(), VgateError> {
    let n_seg = t.segmented.nodes.len();
    let n_clusters = t.clusters.len();
    for (i, c) in t.clusters.iter().enumerate() {
        if c.seed as usize >= n_seg {
            return oob(format!(
                "cluster {i} seed {} ({n_seg} segmented nodes)",
                c.seed
            ));
        }
        if c.bounds_min_m
            .iter()
            .chain(&c.bounds_max_m)
            .any(|x| !x.is_finite())
        {
            return bad(format!("cluster {i} bounds"));
        }
    }
    for (i, gt) in t.gates.iter().enumerate() {
        if gt.clusters.iter().any(|&c| c as usize >= n_clusters) || gt.clusters[0] == gt.clusters[1]
        {
            return oob(format!(
                "gate {i} clusters {:?} ({n_clusters} clusters)",
                gt.clusters
            ));
        }
        if gt.seg_edge as usize >= t.segmented.edges.len() {
            return oob(format!("gate {i} segmented edge {}", gt.seg_edge));
        }
        let len2: f32 = gt.normal.iter().map(|x| x * x).sum();
        if gt.centre_m.iter().any(|x| !x.is_finite())
            || !(gt.radius_m.is_finite() && gt.radius_m >= 0.0)
            || (len2 - 1.0).abs().is_nan()
            || (len2 - 1.0).abs() >= 1e-3
        {
            return bad(format!("gate {i} centre/normal/radius"));
        }
    }
    for (i, p) in t.portals.iter().enumerate() {
        p.check(n_clusters)
            .or_else(|e| bad(format!("portal {i}: {e}")))?;
    }
    Ok(())
}

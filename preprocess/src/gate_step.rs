//! Stage 9, gates: the clusters' slivers merged into their neighbours, then the gates of both
//! placement rules (the chosen one is stored; the report compares the two).

use glam::Vec3;
use serde_json::{Value, json};
use visgate_formats::vgate::GatePlacement;

use crate::clusters::{GateDisk, cluster_radius, find_sliver, find_small, gates, merge_cluster};
use crate::segment::Segmented;

/// What the gate step reads: the segmented skeleton, the skeleton graph's adjacency and each
/// skeleton node's position and largest-ball radius.
pub struct GateInput<'a> {
    /// The segmented skeleton.
    pub seg: &'a Segmented,
    /// The skeleton graph's adjacency lists.
    pub adjacency: &'a [Vec<u32>],
    /// Each skeleton node's position. [Units: m]
    pub position: &'a [Vec3],
    /// Each skeleton node's largest-ball radius. [Units: m]
    pub radius: &'a [f32],
}

/// The clusters after merging slivers, and the gates of both rules.
pub struct GateStep {
    /// Each segmented node's cluster.
    pub node_cluster: Vec<u32>,
    /// Each cluster's seed.
    pub seeds_of: Vec<u32>,
    /// The gates at the narrowest place and at the midpoint, in the same order.
    pub narrowest: Vec<GateDisk>,
    /// See `narrowest`.
    pub midpoint: Vec<GateDisk>,
    /// Clusters merged as slivers.
    pub slivers_merged: u64,
    /// Clusters merged because no ball of `min_radius` fits in them.
    pub small_merged: u64,
}

impl GateStep {
    /// The gates of `rule`.
    pub fn chosen(&self, rule: GatePlacement) -> &[GateDisk] {
        match rule {
            GatePlacement::Narrowest => &self.narrowest,
            GatePlacement::Midpoint => &self.midpoint,
        }
    }

    /// The report's comparison of the two rules, gate by gate.
    pub fn placements_json(&self) -> Vec<Value> {
        self.narrowest
            .iter()
            .zip(&self.midpoint)
            .map(|(n, m)| {
                json!({
                    "clusters": n.clusters,
                    "narrowest": {
                        "centre_m": n.centre.to_array(), "normal": n.normal.to_array(), "radius_m": n.radius,
                    },
                    "midpoint": {
                        "centre_m": m.centre.to_array(), "normal": m.normal.to_array(), "radius_m": m.radius,
                    },
                    "apart_m": (n.centre - m.centre).length(),
                })
            })
            .collect()
    }
}

/// Merges the slivers of the clusters (`node_cluster`, `seeds_of`, greedy growth's) with
/// clustering threshold `alpha`, then the clusters whose largest ball is below `min_radius`
/// (same units as the radii; 0 merges none) into their widest neighbours, then places the
/// gates by both rules.
pub fn gate_step(
    input: &GateInput,
    mut node_cluster: Vec<u32>,
    mut seeds_of: Vec<u32>,
    alpha: f32,
    min_radius: f32,
) -> GateStep {
    let seg = &input.seg.skeleton;
    let gates_by = |placement: GatePlacement, node_cluster: &[u32]| {
        gates(
            seg,
            input.adjacency,
            node_cluster,
            input.position,
            input.radius,
            placement,
        )
    };
    let (mut slivers_merged, mut small_merged) = (0u64, 0u64);
    loop {
        // Slivers (then small clusters) are found with the narrowest-place gates whatever rule
        // is stored, so both rules see the same clusters.
        let g = gates_by(GatePlacement::Narrowest, &node_cluster);
        let cr = cluster_radius(seg, &node_cluster, input.radius, seeds_of.len());
        let (from, into) = if let Some(m) = find_sliver(&g, &cr, alpha) {
            slivers_merged += 1;
            m
        } else if let Some(m) = find_small(&g, &cr, min_radius) {
            small_merged += 1;
            m
        } else {
            break;
        };
        merge_cluster(&mut node_cluster, &mut seeds_of, from, into);
    }
    GateStep {
        narrowest: gates_by(GatePlacement::Narrowest, &node_cluster),
        midpoint: gates_by(GatePlacement::Midpoint, &node_cluster),
        node_cluster,
        seeds_of,
        slivers_merged,
        small_merged,
    }
}

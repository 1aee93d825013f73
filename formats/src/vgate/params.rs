//! The parameters a level was baked with, as the file records them.

use serde::{Deserialize, Serialize};

use super::GridMeta;
use crate::scene::GeometryHash;

/// How the bake's resolution was given.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Resolution {
    /// Voxels on the longest axis of the static bounds.
    LongestAxisVoxels(u32),
    /// Voxel edge length, metres.
    VoxelSizeM(f32),
}

/// Where a gate sits on its segmented edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GatePlacement {
    /// At the narrowest point of the original skeleton line between the two nodes.
    Narrowest,
    /// At the middle of the segmented edge (the paper's rule, IV.C).
    Midpoint,
}

/// What the max-ball radius of an empty voxel measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum MaxBall {
    /// The ball contained in the empty space (the paper's, IV.B): the distance from the voxel's
    /// centre to the nearest solid voxel's surface.
    Contained,
    /// The distance to the nearest solid voxel's centre: up to half a voxel larger.
    SolidCentre,
}

/// What α compares in the cluster growth of IV.B.2 ("radius of maximal balls does not differ
/// more than α % of the maximal radius contained in the cluster").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum AlphaRule {
    /// A neighbour joins when `|r(neighbour) − r(popped node)| ≤ α · r_max(cluster)`: a slowly
    /// narrowing corridor can grow one cluster without end.
    PoppedNode,
    /// A neighbour joins when `r_max(cluster) − r(neighbour) ≤ α · r_max(cluster)` (and a wider
    /// neighbour by no more than α · r_max): every node within α of the cluster's widest.
    ClusterMax,
}

/// What a line node's curvature measures its distance to (IV.B.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CurvatureTo {
    /// The infinite straight line through the line's extrema (the paper's).
    Line,
    /// The segment between the extrema: larger where a line bends back past its ends.
    Segment,
}

/// The bake parameters a file was made with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BakeParams {
    /// Grid resolution.
    pub resolution: Resolution,
    /// Cluster growth tolerance α of IV.B.2. [Limit: [0, 1]]
    pub alpha: f32,
    /// Thinning persistence; `None` asks the bake to pick one for the grid (2 + ⌈n/64⌉ for n
    /// voxels on the longest axis). A baked file always stores the value used. [Units: thinning
    /// steps]
    pub persistence: Option<u32>,
    /// Empty components smaller than this, holding no camera or light, are dropped. [Units: vx]
    pub min_component_voxels: u64,
    /// Gate placement rule.
    pub gate_placement: GatePlacement,
    /// What the max-ball radius measures.
    pub max_ball: MaxBall,
    /// What the cluster growth's α compares.
    pub alpha_rule: AlphaRule,
    /// What curvature measures the distance to.
    pub curvature_to: CurvatureTo,
    /// Whether a leaking closed scene was baked anyway.
    pub allow_leaks: bool,
    /// Edge of a portal's coverage-mask cell. [Limit: [0.25, 8]] [Units: voxels]
    pub portal_cell_voxels: f32,
    /// Skeleton cycles through gaps whose largest contained ball is smaller than this are
    /// opened and skeleton branches as thin pruned before the segmentation, so that the
    /// partition does not depend on which cracks the resolution opens; 0 keeps the whole
    /// skeleton (the paper's). `None` asks the bake for 0.1 m (gaps under 20 cm wide) or
    /// 1/256 of the level's longest extent, whichever is smaller; a baked file stores the
    /// value used. [Limit: [0, 10]] [Units: m, contained ball's radius]
    pub min_gap_m: Option<f32>,
    /// The skeleton, clusters and gates are made on a grid of this voxel size when it differs
    /// from the level's by more than 1 %, and each voxel of the level then takes the cluster of
    /// its space: the partition stays that of this scale at any resolution (a level coarser
    /// than it takes the cluster most of its share of the finer grid has). 0 partitions the
    /// level's own grid. `None` asks the bake for the finest of 1/128, 1/256, … of the level's
    /// longest extent that reaches 0.125 m (else the least whole multiple of the level's voxel
    /// that does), or 1/128 of the level's longest extent if that is smaller,
    /// or on a coarser level a whole fraction of its voxel
    /// (`visgate_preprocess::bake::default_partition_voxel`); a baked file stores the value
    /// used ([`BakeParams::separate_partition_voxel`] reads it). [Limit: [0, 10]] [Units: m]
    pub partition_voxel_m: Option<f32>,
    /// A cluster whose largest max ball is smaller than this is merged into the neighbour
    /// across its widest gate: a roof slab, a crack or a niche where nobody stands is no room
    /// of its own. 0 (and `None`, the default) merges none; a baked file stores the value
    /// used. [Limit: [0, 10]] [Units: m, max-ball radius]
    pub min_cluster_ball_m: Option<f32>,
    /// Voxel edge of the open-voxel grid the voxel walk reads (a bit a voxel), when finer
    /// than the level's voxels: openings narrow by up to a voxel at each edge (the
    /// voxelization is conservative), so a finer grid passes more of the light that passes
    /// there. 0 takes the level's grid. `None` asks the bake for the level's voxel or 1/512 of
    /// the level's longest extent, whichever is smaller; a baked file stores the value used.
    /// [Limit: [0, 10]] [Units: m]
    pub sight_voxel_m: Option<f32>,
}

impl BakeParams {
    /// The voxel of the grid the partition was made on, when that is not the level's grid of
    /// `level_voxel_m` voxels: more than 1 % coarser (refined onto it), or finer (a coarse
    /// bake: each of its voxels given the cluster most of its share of that grid has). `None`:
    /// the level's own grid (a partition voxel of 0, or within 1 % of the level's).
    pub fn separate_partition_voxel(&self, level_voxel_m: f32) -> Option<f32> {
        let pv = self.partition_voxel_m.unwrap_or(0.0);
        let own = pv <= 1.01 * level_voxel_m && pv >= level_voxel_m / 1.01;
        (pv > 0.0 && !own).then_some(pv)
    }
}

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            resolution: Resolution::LongestAxisVoxels(128),
            alpha: 0.2,
            persistence: None,
            min_component_voxels: 64,
            gate_placement: GatePlacement::Narrowest,
            max_ball: MaxBall::SolidCentre,
            alpha_rule: AlphaRule::PoppedNode,
            curvature_to: CurvatureTo::Line,
            allow_leaks: false,
            portal_cell_voxels: 1.0,
            min_gap_m: None,
            partition_voxel_m: None,
            min_cluster_ball_m: None,
            sight_voxel_m: None,
        }
    }
}

/// What a file was baked from and with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BakeInfo {
    /// The parameters used.
    pub params: BakeParams,
    /// Hash of the static geometry it was baked from.
    pub geometry_hash: GeometryHash,
    /// The voxel grid.
    pub grid: GridMeta,
    /// The grid of the open voxels ([`super::BakedLevel::open`]): the level's, or a finer
    /// one over the same bounds ([`BakeParams::sight_voxel_m`]).
    pub sight_grid: GridMeta,
    /// visgate version that baked it (informative).
    pub tool_version: String,
}

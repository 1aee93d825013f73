//! What each stage counts, typed (after Recast's build context, whose timers and counters are
//! named fields rather than strings): a stage returns its result and one of these, and the
//! [`BakeContext`](crate::bake::BakeContext) files it in the report under the stage's name.
//! Every field is documented with its units; the JSON report carries them as they are named
//! here.

use serde::Serialize;

use crate::betti::Betti;

/// Stage 1, load.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoadCounts {
    /// Static triangles.
    pub triangles: usize,
}

/// Stage 2, voxelize.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VoxelizeCounts {
    /// Grid dimensions, border included. [Units: voxels]
    pub dims: [u32; 3],
    /// Voxel edge. [Units: m]
    pub voxel_size_m: f32,
    /// Solid voxels.
    pub solid_voxels: u64,
}

/// The sight grid: the open voxels the voxel walk reads.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SightCounts {
    /// Grid dimensions, border included. [Units: voxels]
    pub dims: [u32; 3],
    /// Voxel edge. [Units: m]
    pub voxel_size_m: f32,
    /// Voxels the voxelization left open.
    pub open_voxels: u64,
    /// Bytes the open voxels take (a bit each).
    pub bytes: u64,
}

/// Stage 3, empty space.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EmptyCounts {
    /// Kept empty voxels.
    pub empty_voxels: u64,
    /// Empty components found.
    pub components: usize,
    /// Components kept.
    pub kept: usize,
    /// Leaks found (a closed scene whose kept space reaches its bounds).
    pub leaks: usize,
    /// Solid objects floating in the empty space, hung to the nearest solid.
    pub hung_objects: usize,
}

/// Stage 4, distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DistanceCounts {
    /// The largest max ball. [Units: voxels]
    pub largest_radius_vx: f64,
}

/// Stage 5, thin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ThinCounts {
    /// Voxels added back where persistence had shortened an end.
    pub ends_extended_by: u64,
    /// Skeleton voxels.
    pub skeleton_voxels: usize,
    /// Thinning steps.
    pub steps: u32,
    /// Voxels kept as persistent 1D isthmuses.
    pub constrained: u64,
    /// Border voxels examined over all steps.
    pub voxels_examined: u64,
    /// Persistence used. [Units: steps]
    pub persistence: u32,
}

/// Stage 6, skeleton graph.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SkeletonCounts {
    /// Graph nodes (skeleton voxels).
    pub nodes: usize,
    /// Graph edges.
    pub edges: usize,
    /// 26-adjacencies dropped to a spanning forest inside each 2 × 2 × 2 cube.
    pub shortcuts_dropped: u64,
    /// Independent cycles.
    pub cycles: u64,
    /// Connected components.
    pub components: u64,
}

/// Stage 7, segment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SegmentCounts {
    /// Segmented nodes.
    pub nodes: u64,
    /// … of which topology nodes (degree ≠ 2).
    pub topology: u64,
    /// … curvature nodes.
    pub curvature: u64,
    /// … coverage nodes.
    pub coverage: u64,
    /// … narrowing nodes.
    pub narrowing: u64,
    /// Segmented edges.
    pub edges: usize,
    /// Skeleton cycles opened at a gap narrower than the minimum gap ([`crate::simplify`]).
    pub thin_cycles_opened: u64,
    /// Skeleton nodes pruned with them (thin branches and what was left of opened cycles).
    pub nodes_pruned: u64,
    /// The minimum gap. [Units: m]
    pub min_gap_m: f32,
}

/// Stage 8, clusters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClusterCounts {
    /// Clusters after the split.
    pub clusters: usize,
    /// Clusters the greedy growth made.
    pub grown: usize,
    /// Clusters split off where their nodes did not see each other.
    pub split_off_unseen: usize,
    /// The growth tolerance used. [Units: ratio]
    pub alpha: f32,
}

/// Stage 9, gates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GateCounts {
    /// Gates of the chosen placement.
    pub gates: usize,
    /// Clusters merged as slivers.
    pub slivers_merged: u64,
    /// Clusters merged because they hold no ball of the smallest cluster ball.
    pub small_merged: u64,
    /// Clusters after merging.
    pub clusters: usize,
}

/// Stage 10, flatten.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FlattenCounts {
    /// Skeleton nodes that lay past a gate of their cluster and took the other side's.
    pub nodes_moved_across_gates: usize,
    /// Voxels that took the cluster of their piece of the cut empty space.
    pub voxels_moved_to_their_piece: u64,
    /// Voxels that saw neither their cluster's seed nor their own node and took a neighbour's.
    pub voxels_moved_by_sight: u64,
    /// Pieces of the empty space cut by the gates.
    pub pieces: u32,
    /// Pieces holding nodes of several clusters.
    pub pieces_of_several_clusters: usize,
    /// The voxel→cluster grid in memory (the file stores it as runs where smaller). [Units:
    /// bytes]
    pub voxel_cluster_bytes: u64,
}

/// Stage 11, portals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PortalCounts {
    /// Portals (planar pieces of the interfaces).
    pub portals: usize,
    /// Voxel faces between two clusters.
    pub interface_faces: u64,
    /// Interface faces no portal covers (0 unless the bake is wrong).
    pub faces_no_portal_covers: u64,
    /// Interface faces farther than 1.5 voxels from every plane of their pair.
    pub faces_off_every_plane: u64,
    /// Cells of all the portals' coverage masks.
    pub mask_cells: u64,
}

/// Stage 12, topology check.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TopologyCounts {
    /// The kept empty space's components, cycles and cavities.
    pub empty: Betti,
    /// The skeleton's.
    pub skeleton: Betti,
}

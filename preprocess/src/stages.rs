//! The bake's stages as functions of plain structs that carry what they need (the grid's
//! metadata included), each returning its result and its counts for the report; `bake()`
//! calls them in order through the [`BakeContext`](crate::bake::BakeContext), which times
//! them.

use glam::Vec3;
use rayon::prelude::*;
use visgate_formats::Scene;
use visgate_formats::vgate::{
    BakeInfo, BakeParams, BakedLevel, Gate, GridMeta, MaxBall, SegNodeKind, Skeleton, SkeletonNode,
    Topology, VoxelBits, VoxelValues,
};

use crate::bake::{BakeContext, scene_seeds};
use crate::betti::{Betti, betti};
use crate::clusters::{ClusterParams, clusters};
use crate::convex::{SplitInput, split_unseen};
use crate::counters::{
    ClusterCounts, DistanceCounts, EmptyCounts, FlattenCounts, GateCounts, LoadCounts,
    PortalCounts, SegmentCounts, SkeletonCounts, ThinCounts, TopologyCounts, VoxelizeCounts,
};
use crate::empty::{EmptySpace, EmptySpaceParams, empty_space};
use crate::gate_step::{GateInput, GateStep, gate_step};
use crate::graph::{SkeletonGraph, nearest_node, skeleton_graph};
use crate::portals::Portals;
use crate::segment::{SegmentParams, Segmented, segment};
use crate::simplify::simplify;
use crate::thin::{ThinParams, Thinned, extend_ends, thin};
use crate::voxelize::SolidGrid;
use crate::{BakeError, distance};

/// A stage's result and its counts for the report.
pub type Counted<T, C> = (T, C);

/// The static geometry.
pub struct Loaded {
    /// Every static triangle. [Units: m]
    pub triangles: Vec<[Vec3; 3]>,
    /// Their bounds. [Units: m]
    pub bounds: (Vec3, Vec3),
    /// The scene's static geometry hash (stored, so that a runtime refuses another scene).
    pub hash: visgate_formats::scene::GeometryHash,
}

/// Stage 1: the scene's static triangles; a scene without any is refused.
pub fn load(scene: &Scene) -> Result<Counted<Loaded, LoadCounts>, BakeError> {
    let triangles: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    let bounds = scene.static_bounds().ok_or(BakeError::NoGeometry)?;
    if triangles.is_empty() {
        return Err(BakeError::NoGeometry);
    }
    let counts = LoadCounts {
        triangles: triangles.len(),
    };
    let hash = scene.static_geometry_hash();
    Ok((
        Loaded {
            triangles,
            bounds,
            hash,
        },
        counts,
    ))
}

/// Stage 2: the solid voxels of `triangles` on `meta`, and how many.
pub fn voxelize(
    meta: GridMeta,
    triangles: &[[Vec3; 3]],
) -> Result<Counted<(SolidGrid, u64), VoxelizeCounts>, BakeError> {
    let solid = crate::voxelize::voxelize(meta, triangles);
    let n = solid.solid_count();
    let counts = VoxelizeCounts {
        dims: meta.dims,
        voxel_size_m: meta.voxel_size_m,
        solid_voxels: n,
    };
    Ok(((solid, n), counts))
}

/// Stage 3: the empty space to keep (see [`crate::empty`]).
pub fn empty(
    scene: &Scene,
    meta: &GridMeta,
    solid: &[bool],
    triangles: &[[Vec3; 3]],
    params: &BakeParams,
    locate_inside_leaks: bool,
) -> Result<Counted<EmptySpace, EmptyCounts>, BakeError> {
    let es = empty_space(
        meta,
        solid,
        triangles,
        &scene_seeds(scene),
        &EmptySpaceParams {
            min_component_voxels: params.min_component_voxels,
            closed: scene.closed,
            allow_leaks: params.allow_leaks,
            locate_inside_leaks,
        },
    )?;
    let counts = EmptyCounts {
        empty_voxels: es.empty_voxels,
        components: es.components.len(),
        kept: es.components.iter().filter(|c| c.kept).count(),
        leaks: es.leaks.len(),
        hung_objects: es.threads.len(),
    };
    Ok((es, counts))
}

/// The squared distance of every voxel to the nearest voxel that is not kept empty.
pub struct DistanceField {
    /// Grid dimensions.
    pub dims: [u32; 3],
    /// Squared distance per voxel. [Units: voxels²]
    pub dist2: Vec<u64>,
    /// How a max ball is measured.
    pub max_ball: MaxBall,
}

impl DistanceField {
    /// The max-ball radius of voxel `i`. [Units: voxels]
    pub fn radius_vx(&self, i: usize) -> f64 {
        distance::radius_vx(self.dist2[i], self.max_ball)
    }

    /// The max-ball radii of `voxels`. [Units: voxels]
    pub fn radii_vx(&self, voxels: &[u32]) -> Vec<f64> {
        voxels.iter().map(|&v| self.radius_vx(v as usize)).collect()
    }

    /// Each voxel's largest ball in whole voxels (2 bytes a voxel), for the gates' cuts and
    /// as the sight lines' clearance.
    pub fn whole_radii(&self) -> Vec<u16> {
        self.dist2
            .par_iter()
            .map(|&d| distance::radius_vx(d, self.max_ball).min(f64::from(u16::MAX)) as u16)
            .collect()
    }
}

/// Stage 4: the exact squared distance transform of the kept empty space.
pub fn distance(
    meta: &GridMeta,
    es: &EmptySpace,
    max_ball: MaxBall,
) -> Counted<DistanceField, DistanceCounts> {
    let not_empty: Vec<bool> = es.empty.iter().map(|&e| !e).collect();
    let dist2 = distance::transform(meta.dims, &not_empty, max_ball);
    drop(not_empty);
    let max_r = es
        .empty
        .iter()
        .zip(&dist2)
        .filter(|(e, _)| **e)
        .map(|(_, d)| *d)
        .max()
        .unwrap_or(0);
    let counts = DistanceCounts {
        largest_radius_vx: distance::radius_vx(max_r, max_ball),
    };
    let field = DistanceField {
        dims: meta.dims,
        dist2,
        max_ball,
    };
    (field, counts)
}

/// Stage 5: the curvilinear skeleton: thinning with persistence, ends re-extended.
pub fn skeletonize(
    es: &EmptySpace,
    field: &DistanceField,
    persistence: u32,
    cx: &BakeContext,
) -> Counted<Thinned, ThinCounts> {
    let mut thinned = thin(
        field.dims,
        &es.empty,
        &field.dist2,
        &ThinParams { persistence },
        &|done, _| cx.advance(done),
    );
    let extended = extend_ends(field.dims, &es.empty, &field.dist2, &mut thinned.skeleton);
    let counts = ThinCounts {
        ends_extended_by: extended,
        skeleton_voxels: thinned.skeleton.len(),
        steps: thinned.steps,
        constrained: thinned.constrained,
        voxels_examined: thinned.border_visits,
        persistence,
    };
    (thinned, counts)
}

/// The skeleton as a graph, with each empty voxel's nearest node and each node's place and
/// max ball.
pub struct SkeletonStage {
    /// The graph.
    pub graph: SkeletonGraph,
    /// Each voxel's nearest skeleton node.
    pub voxel_node: Vec<u32>,
    /// Each node's voxel centre. [Units: m]
    pub position: Vec<Vec3>,
    /// Each node's max-ball radius. [Units: m]
    pub radius: Vec<f32>,
    /// Independent cycles of the graph.
    pub cycles: u64,
    /// Connected components of the graph.
    pub components: u64,
}

/// Stage 6: the skeleton graph and the nearest-node grid (independent: side by side);
/// `skeleton_radius_vx` is the max-ball radius of each skeleton voxel (the distance field is
/// gone by then: the nearest-node search needs its memory).
pub fn skeleton(
    meta: &GridMeta,
    es: &EmptySpace,
    thinned: &Thinned,
    skeleton_radius_vx: &[f64],
) -> Counted<SkeletonStage, SkeletonCounts> {
    let (graph, voxel_node): (SkeletonGraph, Vec<u32>) = rayon::join(
        || skeleton_graph(meta.dims, &thinned.skeleton),
        || nearest_node(meta.dims, &es.empty, &thinned.skeleton),
    );
    let vs = meta.voxel_size_m;
    let position = graph
        .voxels
        .iter()
        .map(|&v| Vec3::from(meta.voxel_to_world(meta.coords(v))))
        .collect();
    // The graph's nodes are the skeleton voxels, in the same order.
    debug_assert_eq!(graph.voxels, thinned.skeleton);
    let radius = skeleton_radius_vx.iter().map(|&r| r as f32 * vs).collect();
    let cycles = graph.cycles();
    let components = petgraph::algo::connected_components(&graph.graph) as u64;
    let counts = SkeletonCounts {
        nodes: graph.voxels.len(),
        edges: graph.graph.edge_count(),
        shortcuts_dropped: graph.shortcuts_dropped,
        cycles,
        components,
    };
    let stage = SkeletonStage {
        graph,
        voxel_node,
        position,
        radius,
        cycles,
        components,
    };
    (stage, counts)
}

/// The segmented skeleton, its adjacency lists and its node counts by kind (all, topology,
/// curvature, coverage, narrowing).
pub struct SegmentStage {
    /// The segmentation.
    pub seg: Segmented,
    /// The skeleton graph's sorted adjacency lists, without the pruned nodes and opened edges.
    pub adjacency: Vec<Vec<u32>>,
    /// Nodes: all, topology, curvature, coverage, narrowing.
    pub counts: [u64; 5],
}

/// Stage 7: segmentation (IV.B.1) of the skeleton graph without its thin gaps
/// ([`crate::simplify`]).
pub fn segmentation(
    meta: &GridMeta,
    sk: &SkeletonStage,
    params: &BakeParams,
) -> Counted<SegmentStage, SegmentCounts> {
    let min_gap_m = params.min_gap_m.unwrap_or(0.0);
    let measured = measured_radius(min_gap_m, meta, params.max_ball);
    let simple = simplify(&sk.graph.adjacency(), &sk.radius, measured);
    let seg_params = SegmentParams {
        curvature_to: params.curvature_to,
        ..SegmentParams::default()
    };
    let seg = segment(
        &simple.adjacency,
        Some(&simple.attach),
        &sk.position,
        &sk.radius,
        &seg_params,
    );
    let adjacency = simple.adjacency;
    let count_kind =
        |k: SegNodeKind| seg.skeleton.nodes.iter().filter(|n| n.kind == k).count() as u64;
    let n = [
        seg.skeleton.nodes.len() as u64,
        count_kind(SegNodeKind::Topology),
        count_kind(SegNodeKind::Curvature),
        count_kind(SegNodeKind::Coverage),
        count_kind(SegNodeKind::Narrowing),
    ];
    let counts = SegmentCounts {
        nodes: n[0],
        topology: n[1],
        curvature: n[2],
        coverage: n[3],
        narrowing: n[4],
        edges: seg.skeleton.edges.len(),
        thin_cycles_opened: simple.cycles_opened,
        nodes_pruned: simple.nodes_removed,
        min_gap_m,
    };
    let stage = SegmentStage {
        seg,
        adjacency,
        counts: n,
    };
    (stage, counts)
}

/// A contained ball's radius `r` as the max-ball rule measures it: a solid-centre radius is up
/// to half a voxel larger, so that the same crack is measured alike at every resolution.
fn measured_radius(r: f32, meta: &GridMeta, max_ball: MaxBall) -> f32 {
    match max_ball {
        MaxBall::SolidCentre if r > 0.0 => r + 0.5 * meta.voxel_size_m,
        _ => r,
    }
}

/// Stages 8 and 9: the greedy clusters (IV.B.2) split where their nodes do not see each other,
/// then the gates (both rules) after merging slivers; with the clusters' account (grown, split
/// off, merged as slivers or too small).
pub fn clusters_and_gates(
    meta: &GridMeta,
    es: &EmptySpace,
    radius_vx: &[u16],
    sk: &SkeletonStage,
    sg: &SegmentStage,
    params: &BakeParams,
    cx: &mut BakeContext,
) -> Result<(GateStep, [u64; 3]), BakeError> {
    let (node_cluster, seeds_of, grown, split_off) = cx.stage("clusters", 0, |_| {
        let (grown, grown_seeds) = clusters(
            &sg.seg.skeleton,
            &sk.position,
            &sk.radius,
            &ClusterParams {
                alpha: params.alpha,
                rule: params.alpha_rule,
            },
        );
        let input = SplitInput {
            meta,
            empty: &es.empty,
            clearance_vx: Some(radius_vx),
            seg: &sg.seg.skeleton,
            node_voxel: &sk.graph.voxels,
            radius: &sk.radius,
        };
        let (node_cluster, seeds) = split_unseen(&input, &grown, &grown_seeds);
        let added = seeds.len() - grown_seeds.len();
        let counts = ClusterCounts {
            clusters: seeds.len(),
            grown: grown_seeds.len(),
            split_off_unseen: added,
            alpha: params.alpha,
        };
        Ok((
            (node_cluster, seeds, grown_seeds.len() as u64, added as u64),
            counts,
        ))
    })?;
    cx.stage("gates", 0, |_| {
        let input = GateInput {
            seg: &sg.seg,
            adjacency: &sg.adjacency,
            position: &sk.position,
            radius: &sk.radius,
        };
        // Compared with the radii as measured, unlike the minimum gap: at a coarse grid a
        // solid-centre radius of one voxel may hold much less, and correcting by half a voxel
        // merged real rooms.
        let min_radius = params.min_cluster_ball_m.unwrap_or(0.0);
        let step = gate_step(&input, node_cluster, seeds_of, params.alpha, min_radius);
        let counts = GateCounts {
            gates: step.chosen(params.gate_placement).len(),
            slivers_merged: step.slivers_merged,
            small_merged: step.small_merged,
            clusters: step.seeds_of.len(),
        };
        let account = [grown, split_off, step.slivers_merged + step.small_merged];
        Ok(((step, account), counts))
    })
}

/// Stage 10: the level: each voxel's cluster (the flatten stage, [`crate::flatten`]), the
/// skeleton, the gates of the chosen rule; its portals come next.
pub fn flatten(
    meta: &GridMeta,
    es: &EmptySpace,
    radius_vx: &[u16],
    sk: &SkeletonStage,
    sg: &SegmentStage,
    step: &GateStep,
    info: BakeInfo,
) -> Counted<(BakedLevel, Vec<u32>), FlattenCounts> {
    let chosen = step.chosen(info.params.gate_placement);
    let flat = crate::flatten::flatten(&crate::flatten::FlattenInput {
        meta,
        empty: &es.empty,
        radius_vx,
        voxel_node: &sk.voxel_node,
        graph: &sk.graph,
        position: &sk.position,
        seg: &sg.seg,
        node_cluster: &step.node_cluster,
        seeds_of: &step.seeds_of,
        gates: chosen,
    });
    let skeleton = Skeleton {
        nodes: sk
            .graph
            .voxels
            .iter()
            .enumerate()
            .map(|(i, &v)| SkeletonNode {
                voxel: meta.coords(v),
                position_m: sk.position[i].to_array(),
                radius_m: sk.radius[i],
            })
            .collect(),
        edges: sk.graph.edges(),
    };
    let gates = chosen
        .iter()
        .map(|g| Gate {
            centre_m: g.centre.to_array(),
            normal: g.normal.to_array(),
            radius_m: g.radius,
            clusters: g.clusters,
            seg_edge: g.seg_edge,
        })
        .collect();
    let level = BakedLevel {
        info,
        topology: Topology {
            skeleton,
            segmented: sg.seg.skeleton.clone(),
            node_cluster: step.node_cluster.clone(),
            clusters: flat.clusters,
            gates,
            portals: Vec::new(),
        },
        voxel_cluster: VoxelValues::pack(&flat.voxel_cluster),
        // The level grid's open voxels: the bake sets them (the partition may run on a grid
        // of its own).
        open: VoxelBits::default(),
    };
    let counts = FlattenCounts {
        voxel_cluster_bytes: level.voxel_cluster.elem().size() * es.empty.len() as u64,
        ..flat.counts
    };
    ((level, flat.voxel_cluster), counts)
}

/// Stage 11: the portals: the interfaces between clusters, made planar ([`crate::portals`]);
/// `partition_voxel_m` is the voxel of the grid the clusters were made on (its staircases set
/// how far an interface may spread about its plane).
pub fn portals(
    meta: &GridMeta,
    es: &EmptySpace,
    voxel_cluster: &[u32],
    cell_voxels: f32,
    partition_voxel_m: f32,
) -> Counted<Portals, PortalCounts> {
    let spread_m = crate::portals::PLANAR_SPREAD_VOXELS * partition_voxel_m;
    let found = crate::portals::portals(meta, &es.empty, voxel_cluster, cell_voxels, spread_m);
    let cells: u64 = found
        .portals
        .iter()
        .map(|p| u64::from(p.size[0]) * u64::from(p.size[1]))
        .sum();
    let counts = PortalCounts {
        portals: found.portals.len(),
        interface_faces: found.interface_faces,
        faces_no_portal_covers: found.uncovered,
        faces_off_every_plane: found.off_plane,
        mask_cells: cells,
    };
    (found, counts)
}

/// Stage 12: the topology of the empty space and of the skeleton, counted independently of the
/// graph (components, cycles, cavities).
pub fn topology_check(
    meta: &GridMeta,
    es: &EmptySpace,
    thinned: &Thinned,
) -> Counted<[Betti; 2], TopologyCounts> {
    let mut skel = vec![false; es.empty.len()];
    thinned
        .skeleton
        .iter()
        .for_each(|&i| skel[i as usize] = true);
    let (empty, skeleton) = rayon::join(|| betti(meta.dims, &es.empty), || betti(meta.dims, &skel));
    let counts = TopologyCounts { empty, skeleton };
    ([empty, skeleton], counts)
}

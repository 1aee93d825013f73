//! The whole bake: a [`Scene`] and [`BakeParams`] → a [`BakedLevel`] and a [`BakeReport`].
//!
//! Every stage is timed and counted in the report; a progress callback hears about the long
//! ones. The result depends only on the scene and the parameters — not on the number of
//! threads — so re-baking reproduces the file byte for byte.

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use serde_json::{Value, json};
use visgate_formats::Scene;
use visgate_formats::scene::Light;
use visgate_formats::vgate::{
    BakeInfo, BakeParams, BakedLevel, Gate, SegNodeKind, Skeleton, SkeletonNode, Topology,
    VoxelValues,
};

use crate::clusters::{ClusterParams, clusters};
use crate::empty::{EmptySpace, EmptySpaceParams, Seed, empty_space};
use crate::graph::{SkeletonGraph, nearest_node, skeleton_graph};
use crate::neighbourhood::betti;
use crate::segment::{SegmentParams, Segmented, segment};
use crate::thin::{ThinParams, Thinned, extend_ends, thin};
use crate::voxelize::{SolidGrid, grid_for, voxelize};
use crate::{BakeError, distance};

pub use crate::report::{BakeReport, StageReport, Summary};

/// What the progress callback hears.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// A stage starts; `total` is the amount of work its `Advance` counts towards (0: unknown).
    Start {
        /// Stage name.
        stage: &'static str,
        /// Units of work.
        total: u64,
    },
    /// Work done so far in the current stage.
    Advance(u64),
    /// The current stage ended.
    Finish,
}

/// Options of [`bake`] beyond the stored parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeOptions {
    /// Refuse grids that would need more memory than this. [Units: bytes]
    pub memory_limit_bytes: u64,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            memory_limit_bytes: 16 << 30,
        }
    }
}

/// The persistence used when none is given: it grows with the grid so that wall noise of a
/// fixed size in metres is pruned at any resolution: `2 + ceil(longest axis / 64)` steps.
pub fn auto_persistence(dims: [u32; 3]) -> u32 {
    2 + dims.iter().max().copied().unwrap_or(0).div_ceil(64)
}

/// Intermediate grids, for debug exports.
#[derive(Debug, Clone)]
pub struct BakeGrids {
    /// Solid voxels as voxelized.
    pub solid: SolidGrid,
    /// Kept empty voxels.
    pub empty: Vec<bool>,
    /// Skeleton voxels, ascending grid index.
    pub skeleton: Vec<u32>,
}

/// A finished bake.
#[derive(Debug, Clone)]
pub struct Baked {
    /// The level, ready to write.
    pub level: BakedLevel,
    /// What happened.
    pub report: BakeReport,
    /// Grids for debug exports.
    pub grids: BakeGrids,
    /// Where a closed scene baked with `allow_leaks` leaks (also in the report).
    pub openings: Vec<crate::leak::LeakPath>,
}

struct Clock<'a> {
    stages: Vec<StageReport>,
    stage: &'static str,
    t: Instant,
    progress: &'a (dyn Fn(Progress) + Sync),
}

impl Clock<'_> {
    fn start(&mut self, stage: &'static str, total: u64) {
        (self.progress)(Progress::Start { stage, total });
        self.stage = stage;
        self.t = Instant::now();
    }
    fn end(&mut self, counts: Value) {
        (self.progress)(Progress::Finish);
        self.stages.push(StageReport {
            name: self.stage,
            seconds: self.t.elapsed().as_secs_f64(),
            counts,
        });
    }
}

/// Peak resident set size of this process (Linux `VmHWM`), bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn check_params(p: &BakeParams) -> Result<(), BakeError> {
    if !(p.alpha.is_finite() && (0.0..=1.0).contains(&p.alpha)) {
        return Err(BakeError::Param(format!(
            "alpha {} must be in 0..=1 (a fraction: 0.2 = 20 %)",
            p.alpha
        )));
    }
    if !(p.portal_cell_voxels.is_finite() && (0.25..=8.0).contains(&p.portal_cell_voxels)) {
        return Err(BakeError::Param(format!(
            "portal cell {} voxels must be in 0.25..=8 (the mask's resolution, in voxels)",
            p.portal_cell_voxels
        )));
    }
    if let Some(persistence) = p.persistence
        && persistence > 10_000
    {
        return Err(BakeError::Param(format!(
            "persistence {} steps is more than any grid needs (at most 10000)",
            persistence
        )));
    }
    Ok(())
}

/// Seeds of the scene: camera eyes and light positions.
pub fn scene_seeds(scene: &Scene) -> Vec<Seed> {
    let mut seeds: Vec<Seed> = scene
        .cameras
        .iter()
        .map(|c| Seed {
            what: format!("camera '{}'", c.name),
            position_m: c.eye.to_array(),
        })
        .collect();
    for (i, l) in scene.lights.iter().enumerate() {
        let (kind, p) = match l {
            Light::Point { position, .. } => ("point light", position),
            Light::Spot { position, .. } => ("spot light", position),
        };
        seeds.push(Seed {
            what: format!("{kind} {i}"),
            position_m: p.to_array(),
        });
    }
    seeds
}

/// Bakes `scene` (see the crate docs for the stages).
pub fn bake(
    scene: &Scene,
    params: &BakeParams,
    options: &BakeOptions,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Baked, BakeError> {
    check_params(params)?;
    let total = Instant::now();
    let mut clock = Clock {
        stages: Vec::new(),
        stage: "",
        t: Instant::now(),
        progress,
    };
    // 1. Static triangles.
    clock.start("load static meshes", 0);
    let triangles: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    let bounds = scene.static_bounds().ok_or(BakeError::NoGeometry)?;
    if triangles.is_empty() {
        return Err(BakeError::NoGeometry);
    }
    let hash = scene.static_geometry_hash();
    clock.end(json!({ "triangles": triangles.len() }));

    // 2. Voxelize.
    let meta = grid_for(bounds, params.resolution, options.memory_limit_bytes)?;
    clock.start("voxelize", 0);
    let solid = voxelize(meta, &triangles);
    let solid_voxels = solid.solid_count();
    clock.end(json!({ "dims": meta.dims, "voxel_size_m": meta.voxel_size_m, "solid_voxels": solid_voxels }),
    );
    let mut params = params.clone();
    let persistence = params
        .persistence
        .unwrap_or_else(|| auto_persistence(meta.dims));
    params.persistence = Some(persistence);

    // 3. Empty space.
    clock.start("empty space", 0);
    let seeds = scene_seeds(scene);
    let es: EmptySpace = empty_space(
        &meta,
        &solid.solid,
        &triangles,
        &seeds,
        &EmptySpaceParams {
            min_component_voxels: params.min_component_voxels,
            closed: scene.closed,
            allow_leaks: params.allow_leaks,
        },
    )?;
    clock.end(json!({
        "empty_voxels": es.empty_voxels,
        "components": es.components.len(),
        "kept": es.components.iter().filter(|c| c.kept).count(),
        "leaks": es.leaks.len(),
        "hung_objects": es.threads.len(),
    }));

    // 4. Distance.
    clock.start("distance", 0);
    let not_empty: Vec<bool> = es.empty.iter().map(|&e| !e).collect();
    let dist2 = distance::transform(meta.dims, &not_empty, params.max_ball);
    drop(not_empty);
    let max_r = es
        .empty
        .iter()
        .zip(&dist2)
        .filter(|(e, _)| **e)
        .map(|(_, d)| *d)
        .max()
        .unwrap_or(0);
    clock.end(json!({ "largest_radius_vx": distance::radius_vx(max_r, params.max_ball) }));

    // 5. Thin.
    clock.start("thin", es.empty_voxels);
    let mut thinned: Thinned = thin(
        meta.dims,
        &es.empty,
        &dist2,
        &ThinParams { persistence },
        &|done, _| progress(Progress::Advance(done)),
    );
    let extended = extend_ends(meta.dims, &es.empty, &dist2, &mut thinned.skeleton);
    clock.end(json!({
        "ends_extended_by": extended,
        "skeleton_voxels": thinned.skeleton.len(),
        "steps": thinned.steps,
        "constrained": thinned.constrained,
        "voxels_examined": thinned.border_visits,
        "persistence": persistence,
    }));

    // 6. Skeleton graph and nearest-node grid.
    clock.start("skeleton graph", 0);
    // The graph and the nearest-node search are independent: run them side by side.
    let (sg, voxel_node): (SkeletonGraph, Vec<u32>) = rayon::join(
        || skeleton_graph(meta.dims, &thinned.skeleton),
        || nearest_node(meta.dims, &es.empty, &thinned.skeleton),
    );
    let vs = meta.voxel_size_m;
    let position: Vec<Vec3> = sg
        .voxels
        .iter()
        .map(|&v| Vec3::from(meta.voxel_to_world(meta.coords(v))))
        .collect();
    let radius: Vec<f32> = sg
        .voxels
        .iter()
        .map(|&v| distance::radius_vx(dist2[v as usize], params.max_ball) as f32 * vs)
        .collect();
    let cycles = sg.cycles();
    let components = petgraph::algo::connected_components(&sg.graph) as u64;
    clock.end(json!({
        "nodes": sg.voxels.len(),
        "edges": sg.graph.edge_count(),
        "shortcuts_dropped": sg.shortcuts_dropped,
        "cycles": cycles,
        "components": components,
    }));
    // Each voxel's largest ball in whole voxels, kept (2 bytes a voxel) for the gates' cuts.
    let radius_vx: Vec<u16> = dist2
        .par_iter()
        .map(|&d| distance::radius_vx(d, params.max_ball).min(f64::from(u16::MAX)) as u16)
        .collect();
    drop(dist2);

    // 7. Segment.
    clock.start("segment", 0);
    let adjacency = sg.adjacency();
    let seg_params = SegmentParams {
        curvature_to: params.curvature_to,
        ..SegmentParams::default()
    };
    let seg: Segmented = segment(&adjacency, &position, &radius, &seg_params);
    let count_kind =
        |k: SegNodeKind| seg.skeleton.nodes.iter().filter(|n| n.kind == k).count() as u64;
    let seg_counts = [
        seg.skeleton.nodes.len() as u64,
        count_kind(SegNodeKind::Topology),
        count_kind(SegNodeKind::Curvature),
        count_kind(SegNodeKind::Coverage),
        count_kind(SegNodeKind::Narrowing),
    ];
    clock.end(json!({
        "nodes": seg_counts[0], "topology": seg_counts[1], "curvature": seg_counts[2],
        "coverage": seg_counts[3], "narrowing": seg_counts[4], "edges": seg.skeleton.edges.len(),
    }));

    // 8. Clusters.
    clock.start("clusters", 0);
    let (node_cluster, seeds_of) = clusters(
        &seg.skeleton,
        &position,
        &radius,
        &ClusterParams {
            alpha: params.alpha,
            rule: params.alpha_rule,
        },
    );
    let greedy_clusters = seeds_of.len();
    clock.end(json!({ "clusters": greedy_clusters, "alpha": params.alpha }));

    // 9. Gates (both rules; the chosen one is stored), after merging slivers.
    clock.start("gates", 0);
    let step = crate::gate_step::gate_step(
        &crate::gate_step::GateInput {
            seg: &seg,
            adjacency: &adjacency,
            position: &position,
            radius: &radius,
        },
        node_cluster,
        seeds_of,
        params.alpha,
    );
    let chosen = step.chosen(params.gate_placement);
    let gate_placements = step.placements_json();
    let (node_cluster, seeds_of) = (&step.node_cluster, &step.seeds_of);
    clock.end(json!({
        "gates": chosen.len(),
        "slivers_merged": step.slivers_merged,
        "clusters": seeds_of.len(),
    }));

    // 10. Flatten.
    clock.start("flatten", 0);
    let n_voxels = es.empty.len();
    let flat = crate::flatten::flatten(&crate::flatten::FlattenInput {
        meta: &meta,
        empty: &es.empty,
        radius_vx: &radius_vx,
        voxel_node: &voxel_node,
        graph: &sg,
        position: &position,
        seg: &seg,
        node_cluster,
        seeds_of,
        gates: chosen,
    });
    drop(radius_vx);
    let skeleton = Skeleton {
        nodes: sg
            .voxels
            .iter()
            .enumerate()
            .map(|(i, &v)| SkeletonNode {
                voxel: meta.coords(v),
                position_m: position[i].to_array(),
                radius_m: radius[i],
            })
            .collect(),
        edges: sg.edges(),
    };
    let gates_out: Vec<Gate> = chosen
        .iter()
        .map(|g| Gate {
            centre_m: g.centre.to_array(),
            normal: g.normal.to_array(),
            radius_m: g.radius,
            clusters: g.clusters,
            seg_edge: g.seg_edge,
        })
        .collect();
    let mut level = BakedLevel {
        info: BakeInfo {
            params: params.clone(),
            geometry_hash: hash,
            grid: meta,
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
        },
        topology: Topology {
            skeleton,
            segmented: seg.skeleton.clone(),
            node_cluster: node_cluster.clone(),
            clusters: flat.clusters,
            gates: gates_out,
            portals: Vec::new(),
        },
        voxel_node: VoxelValues::pack(&voxel_node),
        voxel_cluster: VoxelValues::pack(&flat.voxel_cluster),
    };
    let mut counts = flat.counts;
    counts["voxel_node_bytes"] = json!(level.voxel_node.elem().size() * n_voxels as u64);
    counts["voxel_cluster_bytes"] = json!(level.voxel_cluster.elem().size() * n_voxels as u64);
    clock.end(counts);
    clock.start("portals", 0);
    let found = crate::portals::portals(
        &meta,
        &es.empty,
        &flat.voxel_cluster,
        params.portal_cell_voxels,
    );
    clock.end(json!({
        "portals": found.portals.len(),
        "interface_faces": found.interface_faces,
        "faces_no_portal_covers": found.uncovered,
        "faces_off_every_plane": found.off_plane,
        "mask_cells": found.portals.iter().map(|p| u64::from(p.size[0]) * u64::from(p.size[1])).sum::<u64>(),
    }));
    let uncovered = found.uncovered;
    level.topology.portals = found.portals;

    // Topology check, counted independently of the graph.
    clock.start("topology check", 0);
    let mut skel = vec![false; n_voxels];
    thinned
        .skeleton
        .iter()
        .for_each(|&i| skel[i as usize] = true);
    let (empty_topology, skeleton_topology) =
        rayon::join(|| betti(meta.dims, &es.empty), || betti(meta.dims, &skel));
    clock.end(json!({ "empty": empty_topology, "skeleton": skeleton_topology }));

    let summary = Summary {
        voxels: n_voxels as u64,
        solid_voxels,
        empty_voxels: es.empty_voxels,
        skeleton_nodes: sg.voxels.len() as u64,
        segmented_nodes: seg_counts,
        clusters: level.topology.clusters.len() as u64,
        gates: level.topology.gates.len() as u64,
        portals: level.topology.portals.len() as u64,
        uncovered_interface_faces: uncovered,
        cycles,
        components,
    };
    let report = BakeReport {
        scene: scene.name.clone(),
        params,
        grid: meta,
        threads: rayon::current_num_threads(),
        stages: clock.stages,
        total_seconds: total.elapsed().as_secs_f64(),
        peak_memory_bytes: peak_memory_bytes(),
        summary,
        empty_topology,
        skeleton_topology,
        empty_space: json!({
            "components": es.components,
            "leaks": es.leaks,
            "openings": es.openings,
            "hung_objects": es.threads,
            "seeds_outside_grid": es.seeds_outside,
        }),
        gate_placements,
    };
    Ok(Baked {
        level,
        report,
        openings: es.openings,
        grids: BakeGrids {
            solid,
            empty: es.empty,
            skeleton: thinned.skeleton,
        },
    })
}

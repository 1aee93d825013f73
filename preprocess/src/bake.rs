//! The whole bake: a [`Scene`] and [`BakeParams`] → a [`BakedLevel`] and a [`BakeReport`].
//!
//! Every stage is timed and counted in the report; a progress callback hears about the long
//! ones. The result depends only on the scene and the parameters — not on the number of
//! threads — so re-baking reproduces the file byte for byte.

use std::time::Instant;

use serde::Serialize;
use serde_json::{Value, json};
use visgate_formats::Scene;
use visgate_formats::scene::GeometryHash;
use visgate_formats::scene::Light;
use visgate_formats::vgate::{BakeInfo, BakeParams, BakedLevel, GridMeta, Resolution, VoxelValues};

use crate::BakeError;
use crate::empty::EmptySpace;
use crate::empty::Seed;
pub use crate::memory::peak_memory_bytes;
use crate::memory::{StagePeak, process_cpu_seconds};
use crate::scale::level_scaled;
pub use crate::scale::{
    COARSE_MAX_M, COARSE_PARTS, MIN_GAP_M, MIN_GAP_PARTS, PARTITION_PARTS, PARTITION_VOXEL_M,
    default_partition_voxel,
};
use crate::sight_grid::sight_grid;
use crate::stages;
use crate::thin::Thinned;
use crate::voxelize::{SolidGrid, grid_for, voxelize};

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
    /// Keep the voxelized solid grid to the end, for the debug exports ([`BakeGrids::solid`]);
    /// otherwise it is dropped once the empty space is found (1 byte a voxel: 35 MB at 512³).
    pub keep_solid_grid: bool,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            memory_limit_bytes: 16 << 30,
            keep_solid_grid: true,
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
    /// Solid voxels as voxelized, when [`BakeOptions::keep_solid_grid`] asked for them.
    pub solid: Option<SolidGrid>,
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

/// The bake's context, after Recast's `rcContext`: the progress callback and the stages'
/// scoped timers, whose reports make the bake report's stage table.
pub struct BakeContext<'a> {
    stages: Vec<StageReport>,
    progress: &'a (dyn Fn(Progress) + Sync),
}

impl<'a> BakeContext<'a> {
    /// A context that tells `progress` about the stages.
    pub fn new(progress: &'a (dyn Fn(Progress) + Sync)) -> BakeContext<'a> {
        BakeContext {
            stages: Vec::new(),
            progress,
        }
    }

    /// Runs stage `name` timed (`total`: the units of work its [`BakeContext::advance`] counts
    /// towards, 0 for unknown): `f` gives its result and its counts for the report.
    pub fn stage<T, C: Serialize>(
        &mut self,
        name: &'static str,
        total: u64,
        f: impl FnOnce(&mut Self) -> Result<(T, C), BakeError>,
    ) -> Result<T, BakeError> {
        (self.progress)(Progress::Start { stage: name, total });
        let peak = StagePeak::start();
        let cpu = process_cpu_seconds();
        let t = Instant::now();
        let (out, counts) = f(self)?;
        (self.progress)(Progress::Finish);
        self.stages.push(StageReport {
            name,
            seconds: t.elapsed().as_secs_f64(),
            peak_memory_bytes: peak.finish(),
            cpu_seconds: cpu.zip(process_cpu_seconds()).map(|(a, b)| b - a),
            counts: serde_json::to_value(counts).unwrap_or(Value::Null),
        });
        Ok(out)
    }

    /// Work done so far in the current stage.
    pub fn advance(&self, done: u64) {
        (self.progress)(Progress::Advance(done));
    }

    /// The stages run so far, in order.
    pub fn into_stages(self) -> Vec<StageReport> {
        self.stages
    }
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
    if let Some(g) = p.min_gap_m
        && !(g.is_finite() && (0.0..=10.0).contains(&g))
    {
        return Err(BakeError::Param(format!(
            "minimum gap {g} m must be in 0..=10 (the radius of the largest ball a gap holds, metres; \
             0 keeps every gap)"
        )));
    }
    if let Some(v) = p.min_cluster_ball_m
        && !(v.is_finite() && (0.0..=10.0).contains(&v))
    {
        return Err(BakeError::Param(format!(
            "smallest cluster ball {v} m must be in 0..=10 (a radius in metres; 0 merges none)"
        )));
    }
    if let Some(v) = p.partition_voxel_m
        && !(v.is_finite() && (0.0..=10.0).contains(&v))
    {
        return Err(BakeError::Param(format!(
            "partition voxel {v} m must be in 0..=10 (0 partitions the level's own grid)"
        )));
    }
    // No upper bound: one coarser than the level's voxel walks the level's own grid, as 0 does
    // (a level in the wrong units, kilometres long, asks for metres).
    if let Some(v) = p.sight_voxel_m
        && !(v.is_finite() && v >= 0.0)
    {
        return Err(BakeError::Param(format!(
            "sight voxel {v} m must be a finite number >= 0 (0 walks the level's own grid)"
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

/// How a camera's seed is named (`camera 'main'`): the bake's report lists seeds by name.
const CAMERA_SEED: &str = "camera '";

/// Whether seed `what` (a [`Seed::what`], as the report lists it) is a camera's, not a light's.
pub fn is_camera_seed(what: &str) -> bool {
    what.starts_with(CAMERA_SEED)
}

/// Seeds of the scene: camera eyes and light positions.
pub fn scene_seeds(scene: &Scene) -> Vec<Seed> {
    let mut seeds: Vec<Seed> = scene
        .cameras
        .iter()
        .map(|c| Seed {
            what: format!("{CAMERA_SEED}{}'", c.name),
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
    let mut cx = BakeContext::new(progress);
    let input = cx.stage("load static meshes", 0, |_| stages::load(scene))?;
    let meta = grid_for(input.bounds, params.resolution, options.memory_limit_bytes)?;
    let (solid, solid_voxels) =
        cx.stage("voxelize", 0, |_| stages::voxelize(meta, &input.triangles))?;
    let mut params = level_scaled(params, input.bounds, meta.voxel_size_m);
    let (sight_grid, open) = cx.stage("sight grid", 0, |_| {
        sight_grid(&input, &meta, &params, options)
    })?;
    let pm = partition_grid(input.bounds, &meta, &params, options)?;
    // A bare mesh's openings are looked for on the partition grid where that is coarser: on
    // the level's finer grid the search costs seconds and hundreds of MiB
    // (empty::INSIDE_LEAK_MAX_VOXELS).
    let locate = !pm.is_some_and(|p| p.voxel_size_m > meta.voxel_size_m);
    let mut es = cx.stage("empty space", 0, |_| {
        stages::empty(
            scene,
            &meta,
            &solid.solid,
            &input.triangles,
            &params,
            locate,
        )
    })?;
    let solid = options.keep_solid_grid.then_some(solid);
    let part = match pm {
        None => partition(&mut cx, &meta, &es, input.hash, &mut params)?,
        Some(pm) => {
            let fine = (&meta, &mut es);
            refined_partition(&mut cx, scene, &input, fine, &pm, &mut params)?
        }
    };
    let Partition {
        mut level,
        voxel_cluster,
        thinned,
        skeleton_counts,
        segmented_counts,
        cluster_account,
        placements,
        grid: partition_grid,
    } = part;
    // The grid the partition was made on, and its empty space.
    let (part_meta, part_es) = partition_grid
        .as_ref()
        .map_or((&meta, &es), |(g, e)| (g, e));
    let found = cx.stage("portals", 0, |_| {
        Ok(stages::portals(
            &meta,
            &es,
            &voxel_cluster,
            params.portal_cell_voxels,
            // The coarser of the two grids' staircases.
            part_meta.voxel_size_m.max(meta.voxel_size_m),
        ))
    })?;
    drop(voxel_cluster);
    level.info.sight_grid = sight_grid;
    level.open = open;
    let uncovered = found.uncovered;
    level.topology.portals = found.portals;
    let [empty_topology, skeleton_topology] = cx.stage("topology check", 0, |_| {
        Ok(stages::topology_check(part_meta, part_es, &thinned))
    })?;
    let summary = Summary {
        voxels: es.empty.len() as u64,
        solid_voxels,
        empty_voxels: es.empty_voxels,
        skeleton_nodes: skeleton_counts[0],
        segmented_nodes: segmented_counts,
        clusters: level.topology.clusters.len() as u64,
        clusters_grown_split_merged: cluster_account,
        gates: level.topology.gates.len() as u64,
        portals: level.topology.portals.len() as u64,
        uncovered_interface_faces: uncovered,
        cycles: skeleton_counts[1],
        components: skeleton_counts[2],
    };
    let stages = cx.into_stages();
    // A bare mesh's inside and openings: the level grid's, or the partition grid's where that
    // looked for them.
    let (inside, openings, inside_unlocated) = inside_leaks(&es, part_es);
    let report = BakeReport {
        scene: scene.name.clone(),
        params,
        grid: meta,
        threads: rayon::current_num_threads(),
        stages,
        total_seconds: total.elapsed().as_secs_f64(),
        peak_memory_bytes: peak_memory_bytes(),
        summary,
        empty_topology,
        skeleton_topology,
        empty_space: empty_space_json(&es, inside, &openings, inside_unlocated),
        gate_placements: placements,
    };
    // The skeleton's voxels on the level's grid: the thinning's, or the refined nodes' where
    // the partition ran on a coarser grid.
    let skeleton = match partition_grid {
        None => thinned.skeleton,
        Some(_) => node_voxels(&meta, &level.topology.skeleton.nodes),
    };
    Ok(Baked {
        level,
        report,
        openings,
        grids: BakeGrids {
            solid,
            skeleton,
            empty: es.empty,
        },
    })
}

/// The report's account of the empty space: its components, leaks and openings, a bare
/// mesh's inside, the hung objects, the seeds outside the grid and whether the faces were
/// read turned.
fn empty_space_json(
    es: &EmptySpace,
    inside: Option<crate::inside::Inside>,
    openings: &[crate::leak::LeakPath],
    inside_unlocated: bool,
) -> serde_json::Value {
    json!({
        "components": es.components,
        "leaks": es.leaks,
        "openings": openings,
        "inside_m": inside.map(|s| s.position_m),
        "inside_leaks_not_looked_for": inside_unlocated,
        "hung_objects": es.threads,
        "seeds_outside_grid": es.seeds_outside,
        "faces_turned": es.faces_turned,
    })
}

/// The voxels of `nodes` on `meta`'s grid, sorted, each once.
fn node_voxels(meta: &GridMeta, nodes: &[visgate_formats::vgate::SkeletonNode]) -> Vec<u32> {
    let mut v: Vec<u32> = nodes.iter().map(|n| meta.index(n.voxel) as u32).collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// What the partition's stages made: the level on the grid they ran on, each voxel's cluster
/// and the counts the summary reads.
struct Partition {
    level: BakedLevel,
    voxel_cluster: Vec<u32>,
    thinned: Thinned,
    /// Skeleton nodes, cycles, components.
    skeleton_counts: [u64; 3],
    segmented_counts: [u64; 5],
    cluster_account: [u64; 3],
    placements: Vec<Value>,
    /// The partition grid and its empty space, when it is not the level's grid.
    grid: Option<(GridMeta, EmptySpace)>,
}

/// The point of a bare mesh's inside and its openings, from the level's grid `es` or, where
/// that did not look for them (its inside reaches the bounds and has no point), from the
/// partition grid's `part` (the same as `es` where there is none); and whether the grid they
/// come from did not look either (too large). A partition grid that finds its inside sealed
/// (its coarser voxels close a crack) says nothing.
fn inside_leaks(
    es: &EmptySpace,
    part: &EmptySpace,
) -> (
    Option<crate::inside::Inside>,
    Vec<crate::leak::LeakPath>,
    bool,
) {
    let unsearched = |e: &EmptySpace| e.inside_at_bounds && e.inside.is_none();
    let from = if unsearched(es) { part } else { es };
    let unlocated = unsearched(from);
    (from.inside, from.openings.clone(), unlocated)
}

/// The partition grid: the level's bounds at [`BakeParams::partition_voxel_m`], when that
/// differs from the level's voxels (by more than 1 %; coarser, or finer for a coarse bake);
/// `None` partitions the level's grid (also for a partition voxel of 0).
pub(crate) fn partition_grid(
    bounds: (glam::Vec3, glam::Vec3),
    meta: &GridMeta,
    params: &BakeParams,
    options: &BakeOptions,
) -> Result<Option<GridMeta>, BakeError> {
    let Some(size) = params.separate_partition_voxel(meta.voxel_size_m) else {
        return Ok(None);
    };
    let pm = grid_for(
        bounds,
        Resolution::VoxelSizeM(size),
        options.memory_limit_bytes,
    )?;
    Ok(Some(pm))
}

/// The partition made on the partition grid `pm` (voxelized and its empty space found anew)
/// and refined onto the level's grid and empty space `fine` ([`crate::refine`]).
fn refined_partition(
    cx: &mut BakeContext,
    scene: &Scene,
    input: &stages::Loaded,
    fine: (&GridMeta, &mut EmptySpace),
    pm: &GridMeta,
    params: &mut BakeParams,
) -> Result<Partition, BakeError> {
    let (meta, es) = fine;
    let pes = cx.stage("partition grid: voxelize, empty space", 0, |_| {
        let s = voxelize(*pm, &input.triangles);
        let locate = pm.voxel_size_m > meta.voxel_size_m;
        stages::empty(scene, pm, &s.solid, &input.triangles, params, locate)
    })?;
    let mut part = partition(cx, pm, &pes, input.hash, params)?;
    let voxel_cluster = cx.stage("refine", 0, |_| {
        let c = crate::refine::Coarse {
            meta: pm,
            empty: &pes.empty,
            voxel_cluster: &part.voxel_cluster,
        };
        let (voxel_cluster, counts) = crate::refine::refine(meta, &mut es.empty, &c);
        es.empty_voxels -= counts.unreached;
        Ok((voxel_cluster, counts))
    })?;
    crate::refine::carry_level(meta, &es.empty, &voxel_cluster, &mut part.level);
    part.level.voxel_cluster = VoxelValues::pack(&voxel_cluster);
    part.level.info.params = params.clone();
    part.voxel_cluster = voxel_cluster;
    part.grid = Some((*pm, pes));
    Ok(part)
}

/// Stages 4–10 on grid `meta` with its empty space: distance, thinning, skeleton graph,
/// segmentation, clusters, gates and the voxels' clusters. Sets the persistence in `params`
/// when it was left to the bake.
fn partition(
    cx: &mut BakeContext,
    meta: &GridMeta,
    es: &EmptySpace,
    hash: GeometryHash,
    params: &mut BakeParams,
) -> Result<Partition, BakeError> {
    let persistence = params
        .persistence
        .unwrap_or_else(|| auto_persistence(meta.dims));
    params.persistence = Some(persistence);
    let field = cx.stage("distance", 0, |_| {
        Ok(stages::distance(meta, es, params.max_ball))
    })?;
    let thinned = cx.stage("thin", es.empty_voxels, |cx| {
        Ok(stages::skeletonize(es, &field, persistence, cx))
    })?;
    let radius_vx = field.whole_radii();
    let skeleton_radius_vx = field.radii_vx(&thinned.skeleton);
    drop(field);
    let mut sk = cx.stage("skeleton graph", 0, |_| {
        Ok(stages::skeleton(meta, es, &thinned, &skeleton_radius_vx))
    })?;
    let sg = cx.stage("segment", 0, |_| {
        Ok(stages::segmentation(meta, &sk, params))
    })?;
    let (step, cluster_account) =
        stages::clusters_and_gates(meta, es, &radius_vx, &sk, &sg, params, cx)?;
    let info = BakeInfo {
        params: params.clone(),
        geometry_hash: hash,
        grid: *meta,
        // The bake sets the level's sight grid and its open voxels at its end.
        sight_grid: *meta,
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let (level, voxel_cluster) = cx.stage("flatten", 0, |_| {
        Ok(stages::flatten(meta, es, &radius_vx, &sk, &sg, &step, info))
    })?;
    // The per-voxel grids are done with as soon as their last stage is: at 512³ each is
    // 70–140 MB, and the stages after them would otherwise hold them to the end.
    drop(radius_vx);
    drop(std::mem::take(&mut sk.voxel_node));
    Ok(Partition {
        level,
        voxel_cluster,
        thinned,
        skeleton_counts: [sk.graph.voxels.len() as u64, sk.cycles, sk.components],
        segmented_counts: sg.counts,
        cluster_account,
        placements: step.placements_json(),
        grid: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bare_mesh_s_openings_come_from_the_grid_that_looked_for_them() {
        use crate::inside::Inside;
        let space = |at_bounds: bool, point: Option<[f32; 3]>| EmptySpace {
            empty: Vec::new(),
            empty_voxels: 0,
            components: Vec::new(),
            leaks: Vec::new(),
            openings: Vec::new(),
            inside: point.map(|p| Inside {
                voxel: 0,
                position_m: p,
                enclosed: true,
            }),
            inside_at_bounds: at_bounds,
            threads: Vec::new(),
            seeds_outside: Vec::new(),
            faces_turned: false,
        };
        let point = |r: (Option<Inside>, Vec<crate::leak::LeakPath>, bool)| {
            (r.0.map(|s| s.position_m), r.2)
        };
        let (fine, coarse) = ([1.0; 3], [2.0; 3]);
        // Looked for on the level's grid: its point.
        let searched = space(true, Some(fine));
        assert_eq!(
            point(inside_leaks(&searched, &searched)),
            (Some(fine), false)
        );
        // Left to the partition grid: its point; sealed there, nothing and no warning.
        let left = space(true, None);
        let part = space(true, Some(coarse));
        assert_eq!(point(inside_leaks(&left, &part)), (Some(coarse), false));
        assert_eq!(
            point(inside_leaks(&left, &space(false, None))),
            (None, false)
        );
        // Looked for on neither (too large): said so.
        assert_eq!(point(inside_leaks(&left, &left)), (None, true));
        // Sealed on the level's grid: nothing to say.
        let sealed = space(false, None);
        assert_eq!(point(inside_leaks(&sealed, &part)), (None, false));
    }
}

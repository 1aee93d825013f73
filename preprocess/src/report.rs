//! What a bake reports: each stage's time and counts, the summary, and the text printed at
//! its end.

use serde::Serialize;
use serde_json::Value;
use visgate_formats::vgate::{BakeParams, GridMeta, Resolution};

use crate::betti::Betti;

/// One timed stage.
#[derive(Debug, Clone, Serialize)]
pub struct StageReport {
    /// Stage name.
    pub name: &'static str,
    /// Wall time. [Units: s]
    pub seconds: f64,
    /// The process's largest resident memory seen while the stage ran (sampled every few
    /// milliseconds: see [`crate::memory`]), where the OS tells. [Units: bytes]
    pub peak_memory_bytes: Option<u64>,
    /// The process's CPU time while the stage ran, every thread's (where the OS tells: see
    /// [`crate::memory::process_cpu_seconds`]); over [`StageReport::seconds`], the cores it kept
    /// busy. [Units: s]
    pub cpu_seconds: Option<f64>,
    /// What it produced.
    pub counts: Value,
}

/// Headline counts of a bake.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Grid voxels (border included).
    pub voxels: u64,
    /// Solid voxels after voxelization.
    pub solid_voxels: u64,
    /// Kept empty voxels (what the skeleton describes).
    pub empty_voxels: u64,
    /// Skeleton nodes.
    pub skeleton_nodes: u64,
    /// Segmented nodes: all, then topology / curvature / coverage / narrowing.
    pub segmented_nodes: [u64; 5],
    /// Visibility clusters.
    pub clusters: u64,
    /// Clusters the greedy growth made, split off where their nodes did not see each other,
    /// and merged (as slivers or too small): `clusters = grown + split off − merged`.
    pub clusters_grown_split_merged: [u64; 3],
    /// Visibility gates.
    pub gates: u64,
    /// Portals (planar pieces of the interfaces between clusters).
    pub portals: u64,
    /// Interface faces no portal covers (0 unless the bake is wrong).
    pub uncovered_interface_faces: u64,
    /// Independent cycles of the skeleton graph.
    pub cycles: u64,
    /// Components of the skeleton graph.
    pub components: u64,
}

/// Everything a bake measured.
#[derive(Debug, Clone, Serialize)]
pub struct BakeReport {
    /// Scene name.
    pub scene: String,
    /// Parameters used (resolved).
    pub params: BakeParams,
    /// The grid.
    pub grid: GridMeta,
    /// Rayon threads.
    pub threads: usize,
    /// Stages in order.
    pub stages: Vec<StageReport>,
    /// Total wall time. [Units: s]
    pub total_seconds: f64,
    /// Peak resident memory of the process, where the OS tells. [Units: bytes]
    pub peak_memory_bytes: Option<u64>,
    /// Headline counts.
    pub summary: Summary,
    /// Topology of the kept empty space, counted independently of the skeleton.
    pub empty_topology: Betti,
    /// Topology of the skeleton voxels, counted the same way.
    pub skeleton_topology: Betti,
    /// Empty components and their fate, leaks, hung objects.
    pub empty_space: Value,
    /// Gates under both placement rules, to compare.
    pub gate_placements: Vec<Value>,
}

/// `bytes` in MiB, for the timing tree.
fn mib(bytes: u64) -> String {
    format!("{:.0} MiB", bytes as f64 / (1 << 20) as f64)
}

impl BakeReport {
    /// The timing tree and summary, as printed at the end of a bake.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let g = &self.grid;
        s += &format!(
            "bake of {} — {:.2} s on {} thread(s), peak memory {}\n",
            self.scene,
            self.total_seconds,
            self.threads,
            self.peak_memory_bytes
                .map(mib)
                .unwrap_or_else(|| "unknown".into())
        );
        for (i, st) in self.stages.iter().enumerate() {
            let branch = if i + 1 == self.stages.len() {
                "└─"
            } else {
                "├─"
            };
            // The cores it kept busy, where the stage is long enough for the OS's 10 ms ticks.
            let cores = st
                .cpu_seconds
                .filter(|_| st.seconds >= 0.05)
                .map(|c| format!("{:.1} cores", c / st.seconds))
                .unwrap_or_default();
            let line = format!(
                "{branch} {:<18} {:>8.3} s {:>5.1} %  {:>9}  {cores}",
                st.name,
                st.seconds,
                100.0 * st.seconds / self.total_seconds.max(1e-9),
                st.peak_memory_bytes.map(mib).unwrap_or_default()
            );
            s += line.trim_end();
            s += "\n";
        }
        let m = &self.summary;
        let res = match self.params.resolution {
            Resolution::LongestAxisVoxels(n) => format!("{n} on the longest axis"),
            Resolution::VoxelSizeM(v) => format!("{v} m voxels"),
        };
        s += &format!(
            "grid {} x {} x {} ({res}), voxel {:.4} m\n",
            g.dims[0], g.dims[1], g.dims[2], g.voxel_size_m
        );
        s += &format!(
            "voxels {}  solid {}  empty (kept) {}\n",
            m.voxels, m.solid_voxels, m.empty_voxels
        );
        s += &self.sight_line();
        s += &format!(
            "skeleton nodes {}  segmented nodes {} (topology {}, curvature {}, coverage {}, narrowing {})\n",
            m.skeleton_nodes,
            m.segmented_nodes[0],
            m.segmented_nodes[1],
            m.segmented_nodes[2],
            m.segmented_nodes[3],
            m.segmented_nodes[4]
        );
        let [grown, split, merged] = m.clusters_grown_split_merged;
        s += &format!(
            "clusters {}  gates {}  portals {}  cycles {}  components {}  (alpha {} against {:?}, \
             persistence {}, gates at {:?}, max ball {:?}, curvature to {:?})\n\
             clusters: {grown} grown, {split} split off where their nodes did not see each other, \
             {merged} merged as slivers or as too small to stand alone\n",
            m.clusters,
            m.gates,
            m.portals,
            m.cycles,
            m.components,
            self.params.alpha,
            self.params.alpha_rule,
            self.params.persistence.unwrap_or(0),
            self.params.gate_placement,
            self.params.max_ball,
            self.params.curvature_to
        );
        let v = self.grid.voxel_size_m;
        s += &format!(
            "partition: {}; gaps under {} m left out of it\n",
            match self.params.separate_partition_voxel(v) {
                Some(pv) if pv > v => format!(
                    "made on a {pv:.3} m grid (its topology below), each {v:.4} m voxel given \
                     the cluster of its space"
                ),
                Some(pv) => format!(
                    "made on a finer {pv:.4} m grid (its topology below), each {v:.3} m voxel \
                     given the cluster most of its share of it has"
                ),
                None => "made on the level's grid".to_string(),
            },
            three_figures(self.params.min_gap_m.unwrap_or(0.0))
        );
        let (e, k) = (&self.empty_topology, &self.skeleton_topology);
        s += &format!(
            "topology: empty space {} components / {} cycles / {} cavities, skeleton {} / {} / {}{}\n",
            e.components,
            e.cycles,
            e.cavities,
            k.components,
            k.cycles,
            k.cavities,
            if (e.components, e.cycles) == (k.components, k.cycles) {
                " (preserved)"
            } else {
                " (CHANGED)"
            }
        );
        s
    }
}

impl BakeReport {
    /// The sight grid's line of the summary: its voxels and size, from its stage's counts
    /// (empty where the stage did not run).
    fn sight_line(&self) -> String {
        let Some(c) = self.stages.iter().find(|s| s.name == "sight grid") else {
            return String::new();
        };
        let dims: Vec<u64> = c.counts["dims"]
            .as_array()
            .map(|d| d.iter().filter_map(|x| x.as_u64()).collect())
            .unwrap_or_default();
        let (Some(v), &[x, y, z]) = (c.counts["voxel_size_m"].as_f64(), &dims[..]) else {
            return String::new();
        };
        format!(
            "sight grid {x} x {y} x {z}, voxel {v:.4} m (the voxel walk's: --sight-voxel), {:.1} MB \
             of bits\n",
            c.counts["bytes"].as_f64().unwrap_or(0.0) / 1e6
        )
    }
}

/// `x` with three decimals, or three significant figures where it is under 0.1 (a level
/// modelled small: gaps under 0.00015 m read "0.000").
fn three_figures(x: f32) -> String {
    let decimals = if x > 0.0 && x < 0.1 {
        (2 - x.log10().floor() as i32).clamp(3, 9) as usize
    } else {
        3
    };
    format!("{x:.decimals$}")
}

//! Gate visibility (section V of the visibility-gates paper), the CPU side: a baked level's
//! voxel→cluster grid and gates, the visibility cluster of a surface point (the cluster of the
//! empty space it faces), and the gate test — a VPL lights a point of another cluster only if
//! the segment between them passes through the disk of a gate between the two clusters (the
//! point lies in the cone from the VPL through the disk).
//!
//! Beyond the paper, each a parameter: disks oversized by a factor (the paper's suggested fix
//! for darkening), and light through a chain of up to K gates (the paper stops at neighbouring
//! clusters, K = 1).

use glam::Vec3;
use visgate_formats::vgate::GridMeta;
use visgate_formats::{BakedLevel, Scene};

use crate::RenderError;

/// How light passes gates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateParams {
    /// Gate disks are this many times their baked radius. [Limit: > 0] [Units: ratio]
    pub oversize: f32,
    /// Gates a VPL's light may pass on its way, in a chain through intermediate clusters.
    /// [Limit: 1..=16]
    pub max_hops: u32,
}

impl Default for GateParams {
    fn default() -> Self {
        GateParams {
            oversize: 1.0,
            max_hops: 2,
        }
    }
}

/// A baked level checked against its scene, ready for gate tests.
pub struct GateLevel {
    grid: GridMeta,
    level: BakedLevel,
    /// Gates of each cluster, as indices into the level's gates.
    cluster_gates: Vec<Vec<usize>>,
}

impl GateLevel {
    /// Takes `level` for `scene`; refuses a level baked from other static geometry.
    pub fn new(level: BakedLevel, scene: &Scene) -> Result<GateLevel, RenderError> {
        if level.info.geometry_hash != scene.static_geometry_hash() {
            return Err(RenderError::Param(format!(
                "the level was baked from other static geometry than scene '{}' (hash {} vs \
                 {}): re-bake it with `visgate bake`",
                scene.name,
                level.info.geometry_hash,
                scene.static_geometry_hash()
            )));
        }
        let clusters = level.topology.clusters.len();
        let mut cluster_gates = vec![Vec::new(); clusters];
        for (i, g) in level.topology.gates.iter().enumerate() {
            for c in g.clusters {
                if let Some(list) = cluster_gates.get_mut(c as usize) {
                    list.push(i);
                }
            }
        }
        Ok(GateLevel {
            grid: level.info.grid,
            level,
            cluster_gates,
        })
    }

    /// Number of visibility clusters.
    pub fn cluster_count(&self) -> usize {
        self.cluster_gates.len()
    }

    /// Number of gates.
    pub fn gate_count(&self) -> usize {
        self.level.topology.gates.len()
    }

    fn cluster_of_voxel(&self, p: Vec3) -> Option<u32> {
        let v = self.grid.world_to_voxel(p.to_array())?;
        self.level
            .voxel_cluster
            .get(self.grid.index(v))
            .filter(|&c| c != u32::MAX)
    }

    /// The visibility cluster of a surface point: that of the empty space it faces, looked up
    /// half a voxel and then 1.5 voxels along its normal, then at the point itself (the bake's
    /// grid reaches two voxels into the solid).
    pub fn cluster_at(&self, p: Vec3, n: Vec3) -> Option<u32> {
        let vs = self.grid.voxel_size_m;
        [0.5, 1.5, 0.0]
            .iter()
            .find_map(|&k| self.cluster_of_voxel(p + n * (k * vs)))
    }

    /// Whether light from `a` (cluster `ca`) reaches `b` (cluster `cb`) through the gates: same
    /// cluster, or the segment passes through a chain of at most `max_hops` gate disks that
    /// leads from `ca` to `cb`.
    pub fn visible(&self, a: Vec3, ca: u32, b: Vec3, cb: u32, params: &GateParams) -> bool {
        if ca == cb {
            return true;
        }
        let gates = &self.level.topology.gates;
        let mut frontier = vec![ca];
        let mut seen = vec![ca];
        for _ in 0..params.max_hops {
            let mut next = Vec::new();
            for &c in &frontier {
                for &gi in self.cluster_gates.get(c as usize).into_iter().flatten() {
                    let g = &gates[gi];
                    let other = if g.clusters[0] == c {
                        g.clusters[1]
                    } else {
                        g.clusters[0]
                    };
                    if seen.contains(&other)
                        || !segment_crosses_disk(
                            a,
                            b,
                            Vec3::from(g.centre_m),
                            Vec3::from(g.normal),
                            g.radius_m * params.oversize,
                        )
                    {
                        continue;
                    }
                    if other == cb {
                        return true;
                    }
                    seen.push(other);
                    next.push(other);
                }
            }
            if next.is_empty() {
                break;
            }
            frontier = next;
        }
        false
    }
}

/// Whether segment `a`–`b` crosses the disk of `centre`, unit `normal` and `radius`.
pub fn segment_crosses_disk(a: Vec3, b: Vec3, centre: Vec3, normal: Vec3, radius: f32) -> bool {
    let d = b - a;
    let den = d.dot(normal);
    if den.abs() <= f32::EPSILON * d.length() || radius.is_nan() || radius < 0.0 {
        return false;
    }
    let t = (centre - a).dot(normal) / den;
    if !(0.0..=1.0).contains(&t) {
        return false;
    }
    (a + d * t - centre).length_squared() <= radius * radius
}

//! LightCluster's settings: the clustering, each cluster's disk, the cube faces, the PCSS
//! sampling, and where the direct light takes its shadows from.

use crate::RenderError;
use crate::cpu::lightcluster::LightClusterParams;

use super::light_cluster::MAX_LC_CLUSTERS;

/// PCSS sampling of each cluster's visibility.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PcssParams {
    /// Blocker-search samples. [Limit: 1..=64]
    pub blocker_samples: u32,
    /// Filter (PCF) samples. [Limit: 1..=128]
    pub filter_samples: u32,
}

impl Default for PcssParams {
    fn default() -> Self {
        PcssParams {
            blocker_samples: 16,
            filter_samples: 32,
        }
    }
}

impl PcssParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        if !(1..=64).contains(&self.blocker_samples) || !(1..=128).contains(&self.filter_samples) {
            return Err(RenderError::Param(format!(
                "PCSS blocker samples {} must be 1..=64 and filter samples {} 1..=128",
                self.blocker_samples, self.filter_samples
            )));
        }
        Ok(())
    }
}

/// The disk each cluster's soft shadow is cast from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LcDisk {
    /// Radius: the cluster's minimum distance (the paper). A cluster of one light is a disk
    /// too, and a disk wider than the room around its lights reaches through ceilings.
    MinDistance,
    /// Radius: the cluster's farthest light from its centre (0 for a light alone: its hard
    /// shadow).
    #[default]
    Extent,
}

/// LightCluster's settings on the GPU.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightClusterGpuParams {
    /// The clustering (its `max_clusters` at most [`MAX_LC_CLUSTERS`]).
    pub clustering: LightClusterParams,
    /// Each cluster's disk.
    pub disk: LcDisk,
    /// Side of each cluster's cube face. [Units: texels] [Limit: 16..=2048]
    pub map_size: u32,
    /// PCSS sampling.
    pub pcss: PcssParams,
}

impl Default for LightClusterGpuParams {
    fn default() -> Self {
        LightClusterGpuParams {
            clustering: LightClusterParams::default(),
            disk: LcDisk::default(),
            map_size: 256,
            pcss: PcssParams::default(),
        }
    }
}

impl LightClusterGpuParams {
    /// The settings in a few words, for reports.
    pub fn describe(&self) -> String {
        let c = &self.clustering;
        format!(
            "{} m × (1 + {}·d), ≤ {} clusters, {}² faces",
            c.min_distance_m, c.distance_scale, c.max_clusters, self.map_size
        )
    }

    /// Checks every limit.
    pub fn check(&self) -> Result<(), RenderError> {
        self.clustering.check()?;
        let bad = |what: String| Err(RenderError::Param(format!("LightCluster: {what}")));
        if self.clustering.max_clusters > MAX_LC_CLUSTERS {
            return bad(format!(
                "at most {MAX_LC_CLUSTERS} clusters (max clusters {})",
                self.clustering.max_clusters
            ));
        }
        if !(16..=2048).contains(&self.map_size) {
            return bad(format!(
                "cube face size {} must be 16..=2048 texels",
                self.map_size
            ));
        }
        self.pcss.check()
    }

    /// (tiles per row, rows) of the shadow atlas.
    pub fn atlas_tiles(&self) -> (u32, u32) {
        let tiles = 6 * self.clustering.max_clusters;
        let per_row = (tiles as f64).sqrt().ceil() as u32;
        (per_row, tiles.div_ceil(per_row))
    }
}

/// The direct lights' visibility.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum DirectLight {
    /// Each light's own shadow maps, 3 × 3 PCF (the reference of LightCluster's paper).
    #[default]
    PerLight,
    /// LightCluster: a soft shadow per cluster of lights.
    LightCluster(LightClusterGpuParams),
}

impl DirectLight {
    /// The shading pass's `Globals::direct_mode`: one of the `DIRECT_*` constants.
    pub fn shader_id(&self) -> u32 {
        match self {
            DirectLight::PerLight => crate::gpu::shaders::DIRECT_PER_LIGHT,
            DirectLight::LightCluster(_) => crate::gpu::shaders::DIRECT_LIGHTCLUSTER,
        }
    }
}

//! The scene as the GPU holds it: its geometry, lights, albedo maps, the level's gate tables
//! and the placeholders bound where a mode has none.

use glam::Vec3;

use super::geometry::Geometry;
use super::passes::clustered_gates::LevelBuffers;
use visgate_formats::Light as SceneLight;

/// The scene as the GPU holds it.
pub struct SceneGpu {
    /// Triangles.
    pub geometry: Geometry,
    /// The lights (they move freely: shadow maps and RSMs are made per frame).
    pub lights: Vec<SceneLight>,
    /// Near plane (1e-4 of the first scene's diagonal). [Units: m]
    pub near_m: f32,
    /// Far distance of the lights' shadow and paraboloid maps, at least (4 diagonals; the
    /// camera has no far plane): [`SceneGpu::light_far_m`] reaches farther lights. [Units: m]
    pub far_m: f32,
    /// The first scene's bounds. [Units: m]
    pub bounds: (Vec3, Vec3),
    /// The first scene's bounding diagonal (LightCluster's light ranges). [Units: m]
    pub diagonal_m: f32,
    /// Albedo textures as one array.
    pub albedo_maps: wgpu::TextureView,
    /// Nearest, repeating.
    pub albedo_sampler: wgpu::Sampler,
    /// The baked level's gate tables.
    pub level: Option<LevelBuffers>,
    /// Bound where a mode has no level or no light lists.
    pub no_level: wgpu::Buffer,
    /// A grid of no voxels (the lights' views need no clusters).
    pub no_grid: wgpu::Buffer,
    /// Bound where LightCluster's visibility is not (1 texel, 1 layer).
    pub no_visibility: wgpu::Texture,
}

impl SceneGpu {
    /// The level's voxel words, or a placeholder.
    pub fn voxel_words(&self) -> &wgpu::Buffer {
        self.level
            .as_ref()
            .map_or(&self.no_level, |l| &l.voxel_words)
    }
}

impl SceneGpu {
    /// Far distance of the lights' shadow and paraboloid maps now: [`SceneGpu::far_m`], or, for
    /// a light farther out (a sun placed as a far spot stands 9.5 diagonals away), the distance
    /// from it to the far corner of the scene's bounds and a little more; else the geometry
    /// beyond the far plane would cast no shadow. [Units: m]
    pub fn light_far_m(&self) -> f32 {
        let (lo, hi) = self.bounds;
        let reach = |p: Vec3| (p - lo).abs().max((p - hi).abs()).length() * 1.01;
        (self.lights.iter())
            .map(|l| reach(l.position()))
            .fold(self.far_m, f32::max)
    }
}

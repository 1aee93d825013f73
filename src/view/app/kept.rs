//! What the viewer keeps across runs: its state as saved, taken back, and saved when it
//! changes.

use glam::Vec3;
use visgate_runtime::gpu::{NEAR_FIELD_MAX, RATIO_STRIDE_MAX};

use super::ViewerApp;
use crate::view::camera::FlyCamera;
use crate::view::state::{self, SavedView};

impl ViewerApp {
    /// What the next run takes back.
    pub(super) fn saved(&self) -> SavedView {
        let (c, g, v, p) = (
            &self.camera,
            &self.settings.gates.gates,
            &self.settings.vals,
            &self.settings.per_vpl,
        );
        let l = &self.layers;
        SavedView {
            mode: self.start.mode.to_string(),
            vpls: self.vpl_count,
            rsm: self.start.rsm,
            exposure: self.exposure,
            moving_scale: self.moving_scale,
            camera: [c.eye.x, c.eye.y, c.eye.z, c.yaw, c.pitch, c.fov_x, c.speed],
            layers: [
                l.clusters, l.gates, l.skeleton, l.vpls, l.indirect, l.geometry, l.lists,
            ],
            settings: [
                g.max_hops as f32,
                g.oversize,
                v.vals.count as f32,
                v.vals.iterations as f32,
                v.interleave.block as f32,
                v.map_size as f32,
                p.map_size as f32,
                p.batch as f32,
            ],
            gate_shape: Some(SavedView::shape_name(g.shape)),
            closed_voxel_triangles: g.triangles,
            closed_voxel_planes: g.planes,
            disks: false,
            voxels: false,
            vals_layer: l.vals,
            walk_roulette: Some(self.settings.gates.walk_roulette.to_string()),
            near_field: Some(self.settings.gates.near_field),
            ratio: Some(self.settings.gates.ratio),
            ratio_stride: Some(self.settings.gates.ratio_stride),
        }
    }

    /// Takes back the camera, exposure and settings of a saved state.
    pub(super) fn restore(&mut self, s: &SavedView) {
        let c = s.camera;
        self.camera = FlyCamera::from_parts(Vec3::new(c[0], c[1], c[2]), c[3], c[4], c[5], c[6]);
        self.exposure = s.exposure;
        self.moving_scale = s.moving_scale;
        let [hops, oversize, vals, iterations, block, val_map, map, batch] = s.settings;
        let (g, v, p) = (
            &mut self.settings.gates.gates,
            &mut self.settings.vals,
            &mut self.settings.per_vpl,
        );
        g.max_hops = hops as u32;
        g.shape = s.shape();
        g.triangles = s.closed_voxel_triangles;
        g.planes = s.closed_voxel_planes;
        g.oversize = oversize;
        v.vals.count = vals as u32;
        v.vals.iterations = iterations as u32;
        v.interleave.block = block as u32;
        v.map_size = val_map as u32;
        p.map_size = map as u32;
        p.batch = batch as u32;
        self.settings.gates.interleave = self.settings.vals.interleave;
        // A share this build refuses (a file edited by hand) keeps the run's own.
        if let Some(r) = s.walk_roulette.as_deref().and_then(|t| t.parse().ok()) {
            self.settings.gates.walk_roulette = r;
        }
        // Likewise a near field out of its limits.
        if let Some(k) = s.near_field.filter(|k| (0.0..=NEAR_FIELD_MAX).contains(k)) {
            self.settings.gates.near_field = k;
        }
        if let Some(r) = s.ratio {
            self.settings.gates.ratio = r;
        }
        if let Some(n) = s.ratio_stride.filter(|n| *n <= RATIO_STRIDE_MAX) {
            self.settings.gates.ratio_stride = n;
        }
    }

    /// Saves the state when it changed, at most once a second (and at exit).
    pub(super) fn keep_state(&mut self, now: bool) {
        if !self.start.persist {
            return;
        }
        let s = self.saved();
        let due = self.last_saved.as_ref().is_none_or(|(last, t)| {
            *last != s && (now || t.elapsed() > std::time::Duration::from_secs(1))
        });
        if due {
            state::save(&self.start.scene.name, s.clone());
            self.last_saved = Some((s, std::time::Instant::now()));
        }
    }
}

//! What the viewer keeps across runs, per scene: the method and its settings (the gates' walk
//! roulette among them), the VPLs, the
//! exposure, the layers and the camera — in `$XDG_CONFIG_HOME/visgate/viewer.json` (else
//! `~/.config/…`). Scripted runs (`--screenshot`, `--benchmark`) and `--fresh` neither read
//! nor write it, so that they stay reproducible.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use visgate_runtime::cpu::gates::GateShape;

/// Serde's default for a setting that is on unless a file says otherwise.
fn on() -> bool {
    true
}

/// The viewer's state for one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedView {
    pub mode: String,
    pub vpls: u32,
    pub rsm: bool,
    pub exposure: f32,
    pub moving_scale: f32,
    /// Eye (m), yaw, pitch, horizontal field of view (rad), speed (m/s).
    pub camera: [f32; 7],
    /// Clusters, gates, skeleton, VPLs, indirect, geometry clusters, list lengths.
    pub layers: [bool; 7],
    /// Hops, oversize, VALs, iterations, interleave block, VAL map, per-VPL map, batch.
    pub settings: [f32; 8],
    /// The gate shape: `voxels`, `portal` or `disk` (absent in older files: [`Self::shape`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gate_shape: Option<String>,
    /// The voxel walk with the closed voxels' triangles (absent in older files: off).
    #[serde(default)]
    pub closed_voxel_triangles: bool,
    /// The voxel walk passing closed voxels on their planes (absent in older files: on, the
    /// default).
    #[serde(default = "on")]
    pub closed_voxel_planes: bool,
    /// Older files: gates as disks (read, no longer written).
    #[serde(default, skip_serializing)]
    pub disks: bool,
    /// Older files: gates as the voxel walk (read, no longer written).
    #[serde(default, skip_serializing)]
    pub voxels: bool,
    /// The VAL layer (absent in older files: off).
    #[serde(default)]
    pub vals_layer: bool,
    /// The gates' walk roulette, `auto` or a share (absent in older files: the run's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walk_roulette: Option<String>,
    /// The gates' near field, in blur blocks (absent in older files: the run's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub near_field: Option<f32>,
    /// The gates' ratio estimator (absent in older files: the run's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio: Option<bool>,
    /// The ratio estimator's grid stride (absent in older files: the run's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_stride: Option<u32>,
}

impl SavedView {
    /// The gate shape kept: the one named, or in a file from before it was named, disks or the
    /// voxel walk where that was chosen and else today's default — such a file cannot tell
    /// the portals chosen from the portals that were the default then.
    pub fn shape(&self) -> GateShape {
        match self.gate_shape.as_deref() {
            Some("portal") => GateShape::Portal,
            Some("disk") => GateShape::Disk,
            Some("voxels") => GateShape::Voxels,
            _ if self.disks => GateShape::Disk,
            _ => GateShape::default(),
        }
    }

    /// `shape`'s name in the file.
    pub fn shape_name(shape: GateShape) -> String {
        match shape {
            GateShape::Voxels => "voxels",
            GateShape::Portal => "portal",
            GateShape::Disk => "disk",
        }
        .to_string()
    }
}

/// The state file: one entry per scene name.
fn path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|s| !s.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
    Some(base.join("visgate").join("viewer.json"))
}

fn read_all(p: &std::path::Path) -> BTreeMap<String, SavedView> {
    std::fs::read_to_string(p)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_default()
}

/// The saved state of scene `name`, if any (an unreadable file counts as none).
pub fn load(name: &str) -> Option<SavedView> {
    read_all(&path()?).remove(name)
}

/// Saves `state` for scene `name`; says where a failure happened, without failing the viewer.
pub fn save(name: &str, state: SavedView) {
    if let Some(p) = path() {
        save_to(&p, name, state);
    }
}

/// Saves `state` for scene `name` into the state file `p`, keeping the other scenes'.
fn save_to(p: &std::path::Path, name: &str, state: SavedView) {
    let mut all = read_all(p);
    all.insert(name.to_string(), state);
    let written = p
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .and_then(|()| {
            let text = serde_json::to_string_pretty(&all).map_err(std::io::Error::other)?;
            std::fs::write(p, text)
        });
    if let Err(e) = written {
        tracing::warn!("cannot save the viewer's state to {}: {e}", p.display());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_of_several_scenes_live_in_one_file_and_a_broken_file_counts_as_none() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("visgate").join("viewer.json");
        let state = |mode: &str| SavedView {
            mode: mode.into(),
            vpls: 256,
            rsm: true,
            exposure: -1.0,
            moving_scale: 0.5,
            camera: [1.0, 2.0, 3.0, 0.5, -0.2, 1.2, 4.0],
            layers: [true, false, true, false, true, false, true],
            settings: [2.0, 1.5, 30.0, 8.0, 4.0, 128.0, 256.0, 32.0],
            gate_shape: (mode == "gates").then(|| SavedView::shape_name(GateShape::Disk)),
            closed_voxel_triangles: mode == "gates",
            closed_voxel_planes: mode != "gates",
            disks: false,
            voxels: false,
            vals_layer: mode == "val-ism",
            walk_roulette: (mode == "gates").then(|| "0.1".into()),
            near_field: (mode == "gates").then_some(2.0),
            ratio: (mode == "gates").then_some(false),
            ratio_stride: (mode == "gates").then_some(3),
        };
        save_to(&p, "a", state("gates"));
        save_to(&p, "b", state("val-cssm"));
        let all = read_all(&p);
        assert_eq!(all.get("a"), Some(&state("gates")));
        assert_eq!(all.get("b"), Some(&state("val-cssm")));
        assert_eq!(all["a"].shape(), GateShape::Disk);
        assert!(all["a"].closed_voxel_triangles && !all["b"].closed_voxel_triangles);
        // A file from before the triangles: off.
        let mut json: serde_json::Value = serde_json::to_value(state("gates")).expect("json");
        json.as_object_mut()
            .expect("object")
            .remove("closed_voxel_triangles");
        json.as_object_mut()
            .expect("object")
            .remove("closed_voxel_planes");
        let older: SavedView = serde_json::from_value(json).expect("an older state");
        assert!(!older.closed_voxel_triangles && older.closed_voxel_planes);
        assert!(!all["a"].closed_voxel_planes && all["b"].closed_voxel_planes);
        // The roulette as the runtime reads it back; a file from before it: none (the run's).
        use visgate_runtime::gpu::WalkRoulette;
        for r in [
            WalkRoulette::Auto,
            WalkRoulette::Share(0.05),
            WalkRoulette::Share(0.0),
        ] {
            assert_eq!(r.to_string().parse::<WalkRoulette>().ok(), Some(r));
        }
        // A file from before a field was kept: the state read without it.
        let older = |field: &str| -> SavedView {
            let mut json = serde_json::to_value(state("gates")).expect("json");
            json.as_object_mut().expect("object").remove(field);
            serde_json::from_value(json).expect("an older state")
        };
        assert_eq!(all["a"].walk_roulette.as_deref(), Some("0.1"));
        assert_eq!(older("walk_roulette").walk_roulette, None);
        // The near field likewise.
        assert_eq!(all["a"].near_field, Some(2.0));
        assert_eq!(older("near_field").near_field, None);
        // And the ratio estimator.
        assert_eq!(all["a"].ratio, Some(false));
        assert_eq!(older("ratio").ratio, None);
        // And its grid.
        assert_eq!(all["a"].ratio_stride, Some(3));
        assert_eq!(older("ratio_stride").ratio_stride, None);
        // A file from before the shape was named: disks and voxels as chosen, else today's
        // default.
        let old = |disks: bool, voxels: bool| SavedView {
            gate_shape: None,
            disks,
            voxels,
            ..state("gates")
        };
        assert_eq!(old(true, false).shape(), GateShape::Disk);
        assert_eq!(old(false, true).shape(), GateShape::Voxels);
        assert_eq!(old(false, false).shape(), GateShape::Voxels);
        let text = serde_json::to_string(&old(true, false)).expect("json");
        assert!(!text.contains("disks"), "{text}");
        for shape in [GateShape::Portal, GateShape::Disk, GateShape::Voxels] {
            let s = SavedView {
                gate_shape: Some(SavedView::shape_name(shape)),
                ..state("gates")
            };
            assert_eq!(s.shape(), shape);
        }
        std::fs::write(&p, "{ not json").expect("write");
        assert!(read_all(&p).is_empty());
    }
}

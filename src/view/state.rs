//! What the viewer keeps across runs, per scene: the method and its settings, the VPLs, the
//! exposure, the layers and the camera — in `$XDG_CONFIG_HOME/visgate/viewer.json` (else
//! `~/.config/…`). Scripted runs (`--screenshot`, `--benchmark`) and `--fresh` neither read
//! nor write it, so that they stay reproducible.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

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
    /// Gates as disks rather than portals (absent in older files: portals).
    #[serde(default)]
    pub disks: bool,
    /// Gates as the voxel walk (absent in older files: not).
    #[serde(default)]
    pub voxels: bool,
    /// The VAL layer (absent in older files: off).
    #[serde(default)]
    pub vals_layer: bool,
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
            disks: mode == "gates",
            voxels: false,
            vals_layer: mode == "val-ism",
        };
        save_to(&p, "a", state("gates"));
        save_to(&p, "b", state("val-cssm"));
        let all = read_all(&p);
        assert_eq!(all.get("a"), Some(&state("gates")));
        assert_eq!(all.get("b"), Some(&state("val-cssm")));
        std::fs::write(&p, "{ not json").expect("write");
        assert!(read_all(&p).is_empty());
    }
}

//! Camera paths for the benchmark: recorded in the viewer (the panel's "record camera path"),
//! saved as JSON, and played back with `visgate view --benchmark N --benchmark-path FILE`, so
//! that methods and commits are compared on a walk a user chose.
//!
//! The file: `{"scene": NAME, "cameras": [{"eye": [x, y, z], "target": [x, y, z],
//! "fov_deg": F}, …]}` (metres, the horizontal field of view in degrees, as a scene file's
//! cameras).

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use visgate_formats::Camera;

/// A camera of the file.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Key {
    eye: [f32; 3],
    target: [f32; 3],
    fov_deg: f32,
}

#[derive(Debug, Serialize, Deserialize)]
struct PathFile {
    #[serde(default)]
    scene: String,
    cameras: Vec<Key>,
}

/// The cameras of path file `file`: two at least, finite, each looking somewhere.
pub fn read(file: &Path) -> Result<Vec<Camera>> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("camera path {}", file.display()))?;
    let p: PathFile = serde_json::from_str(&text).with_context(|| {
        format!(
            "camera path {}: not a path file ({{\"cameras\": [{{\"eye\": [x, y, z], \
             \"target\": [x, y, z], \"fov_deg\": F}}, …]}}, as the viewer's \"record camera \
             path\" writes)",
            file.display()
        )
    })?;
    if p.cameras.len() < 2 {
        bail!(
            "camera path {}: {} camera(s); a path needs two at least",
            file.display(),
            p.cameras.len()
        );
    }
    p.cameras
        .iter()
        .enumerate()
        .map(|(i, k)| {
            let (eye, target) = (Vec3::from(k.eye), Vec3::from(k.target));
            let fine = eye.is_finite() && target.is_finite() && eye.distance(target) > 0.0;
            if !(fine && k.fov_deg > 0.0 && k.fov_deg < 180.0) {
                bail!(
                    "camera path {}: camera {i} is not a view (eye {eye}, target {target}, \
                     fov {}°: finite, apart, 0 < fov < 180)",
                    file.display(),
                    k.fov_deg
                );
            }
            Ok(Camera {
                name: format!("path {i}"),
                eye,
                target,
                up: Vec3::Y,
                fov_x_rad: k.fov_deg.to_radians(),
            })
        })
        .collect()
}

/// Writes `cameras` as a path file of scene `scene`.
pub fn write(file: &Path, scene: &str, cameras: &[Camera]) -> Result<()> {
    let p = PathFile {
        scene: scene.to_string(),
        cameras: cameras
            .iter()
            .map(|c| Key {
                eye: c.eye.to_array(),
                target: c.target.to_array(),
                fov_deg: c.fov_x_rad.to_degrees(),
            })
            .collect(),
    };
    let text = serde_json::to_string_pretty(&p)?;
    std::fs::write(file, text).with_context(|| format!("camera path {}", file.display()))
}

/// A path being recorded: a camera at most every [`Recorder::STEP`], and only where the view
/// changed.
#[derive(Default)]
pub struct Recorder {
    /// The cameras so far.
    pub cameras: Vec<Camera>,
    last: Option<Instant>,
}

impl Recorder {
    /// The least time between two recorded cameras.
    pub const STEP: Duration = Duration::from_millis(250);

    /// Takes `c` if a step has passed since the last camera and the view moved.
    pub fn push(&mut self, c: Camera, now: Instant) {
        if self
            .last
            .is_some_and(|t| now.duration_since(t) < Recorder::STEP)
        {
            return;
        }
        let moved = self.cameras.last().is_none_or(|p| {
            let scale = p.eye.distance(p.target).max(1e-6);
            p.eye.distance(c.eye) > 1e-4 * scale
                || (p.target - p.eye)
                    .normalize()
                    .dot((c.target - c.eye).normalize())
                    < 1.0 - 1e-7
                || (p.fov_x_rad - c.fov_x_rad).abs() > 1e-5
        });
        if moved {
            self.cameras.push(c);
            self.last = Some(now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(x: f32) -> Camera {
        Camera {
            name: String::new(),
            eye: Vec3::new(x, 1.0, 2.0),
            target: Vec3::new(x, 1.0, 0.0),
            up: Vec3::Y,
            fov_x_rad: 1.2,
        }
    }

    #[test]
    fn a_recorded_path_keeps_moving_views_a_step_apart_and_reads_back() {
        let mut r = Recorder::default();
        let t = Instant::now();
        r.push(cam(0.0), t);
        r.push(cam(1.0), t + Duration::from_millis(100)); // too soon
        r.push(cam(0.0), t + Duration::from_millis(300)); // did not move
        r.push(cam(1.0), t + Duration::from_millis(400));
        r.push(cam(3.0), t + Duration::from_millis(700));
        let xs: Vec<f32> = r.cameras.iter().map(|c| c.eye.x).collect();
        assert_eq!(xs, vec![0.0, 1.0, 3.0]);
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("p.json");
        write(&file, "test", &r.cameras).expect("write");
        let back = read(&file).expect("read");
        assert_eq!(back.len(), 3);
        for (a, b) in back.iter().zip(&r.cameras) {
            assert_eq!((a.eye, a.target), (b.eye, b.target));
            assert!((a.fov_x_rad - b.fov_x_rad).abs() < 1e-6);
        }
    }

    #[test]
    fn a_broken_path_file_is_refused_with_what_is_wrong() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("p.json");
        let err = |text: &str| {
            std::fs::write(&file, text).expect("write");
            format!("{:#}", read(&file).expect_err("refused"))
        };
        assert!(err("{").contains("not a path file"));
        let one = r#"{"cameras": [{"eye": [0,0,0], "target": [0,0,-1], "fov_deg": 60}]}"#;
        assert!(err(one).contains("two at least"));
        let same = r#"{"cameras": [{"eye": [0,0,0], "target": [0,0,0], "fov_deg": 60},
            {"eye": [0,0,0], "target": [0,0,-1], "fov_deg": 60}]}"#;
        assert!(err(same).contains("camera 0 is not a view"));
        assert!(
            format!(
                "{:#}",
                read(&dir.path().join("none.json")).expect_err("absent")
            )
            .contains("none.json")
        );
    }
}

//! The viewer's benchmark: a camera path — recorded in the viewer (`--benchmark-path`), else
//! through the scene's cameras (in order, eye and target linear between them; with fewer than
//! two, a turn about the level's framing) — played at a
//! fixed step, each frame's pass times written as CSV rows `frame,pass,gpu_ms,cpu_wall_ms`,
//! so that methods and commits are compared on the same walk.

use std::fmt::Write as _;
use std::path::PathBuf;

use glam::Vec3;
use visgate_formats::{Camera, Scene};
use visgate_runtime::gpu::PassTimes;

use super::camera::FlyCamera;

/// A benchmark run: its path, its frames so far, where the CSV goes.
pub struct Bench {
    path: Vec<Camera>,
    /// Frames to render.
    pub frames: u32,
    /// Frames rendered.
    pub done: u32,
    out: PathBuf,
    csv: String,
    totals: Vec<f64>,
}

impl Bench {
    /// A benchmark of `frames` frames through `path` (a recorded one), else `scene`'s
    /// cameras, writing `out`.
    pub fn new(scene: &Scene, frames: u32, out: PathBuf, path: Option<Vec<Camera>>) -> Bench {
        let path = if let Some(p) = path.filter(|p| p.len() >= 2) {
            p
        } else if scene.cameras.len() >= 2 {
            scene.cameras.clone()
        } else {
            let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
            let f = FlyCamera::framing(lo, hi);
            let c = (lo + hi) * 0.5;
            (0..=8)
                .map(|k| {
                    let a = k as f32 / 8.0 * std::f32::consts::TAU;
                    let r = f.eye - c;
                    let eye = c + Vec3::new(
                        r.x * a.cos() - r.z * a.sin(),
                        r.y,
                        r.x * a.sin() + r.z * a.cos(),
                    );
                    Camera {
                        name: format!("turn {k}"),
                        eye,
                        target: c,
                        up: Vec3::Y,
                        fov_x_rad: f.fov_x,
                    }
                })
                .collect()
        };
        Bench {
            path,
            frames,
            done: 0,
            out,
            csv: String::from("frame,pass,gpu_ms,cpu_wall_ms\n"),
            totals: Vec::new(),
        }
    }

    /// The camera of frame `i`.
    pub fn camera(&self, i: u32) -> Camera {
        let segs = (self.path.len() - 1).max(1) as f32;
        let u = i as f32 / (self.frames.max(2) - 1) as f32 * segs;
        let k = (u.floor() as usize).min(self.path.len().saturating_sub(2));
        let (a, b) = (&self.path[k], &self.path[(k + 1).min(self.path.len() - 1)]);
        let t = (u - k as f32).clamp(0.0, 1.0);
        Camera {
            name: format!("benchmark {i}"),
            eye: a.eye.lerp(b.eye, t),
            target: a.target.lerp(b.target, t),
            up: Vec3::Y,
            fov_x_rad: a.fov_x_rad + (b.fov_x_rad - a.fov_x_rad) * t,
        }
    }

    /// Records frame `done`'s times.
    pub fn record(&mut self, t: &PassTimes) {
        let ms = |x: Option<f64>| x.map_or(String::new(), |v| format!("{:.4}", v * 1e3));
        for (name, gpu, cpu) in t.by_name() {
            let _ = writeln!(self.csv, "{},{name},{},{}", self.done, ms(gpu), ms(cpu));
        }
        let total = t.gpu_total().unwrap_or(t.frame_s);
        let _ = writeln!(
            self.csv,
            "{},frame,{},{:.4}",
            self.done,
            ms(t.gpu_total()),
            t.frame_s * 1e3
        );
        self.totals.push(total * 1e3);
        self.done += 1;
    }

    /// Writes the CSV and says what the frames took.
    pub fn finish(&self) -> std::io::Result<String> {
        std::fs::write(&self.out, &self.csv)?;
        let mut t = self.totals.clone();
        t.sort_by(f64::total_cmp);
        let median = t.get(t.len() / 2).copied().unwrap_or(0.0);
        let mean = t.iter().sum::<f64>() / t.len().max(1) as f64;
        Ok(format!(
            "benchmark: {} frames, frame time mean {mean:.2} ms, median {median:.2} ms, max {:.2} ms; wrote {}",
            t.len(),
            t.last().copied().unwrap_or(0.0),
            self.out.display()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_path_runs_through_the_scene_cameras_from_the_first_to_the_last() {
        let mut scene = visgate_scenes::Builtin::FourRooms.scene().expect("scene");
        let cam = |x: f32| Camera {
            name: format!("{x}"),
            eye: Vec3::new(x, 1.0, 0.0),
            target: Vec3::new(x, 1.0, -1.0),
            up: Vec3::Y,
            fov_x_rad: 1.0,
        };
        scene.cameras = vec![cam(0.0), cam(2.0), cam(6.0)];
        let b = Bench::new(&scene, 5, PathBuf::from("x.csv"), None);
        let xs: Vec<f32> = (0..5).map(|i| b.camera(i).eye.x).collect();
        assert_eq!(xs, vec![0.0, 1.0, 2.0, 4.0, 6.0]);
        // One camera: a turn about the level, back where it started.
        scene.cameras.truncate(1);
        let b = Bench::new(&scene, 9, PathBuf::from("x.csv"), None);
        assert!(b.camera(0).eye.distance(b.camera(8).eye) < 1e-3);
        assert!(b.camera(0).eye.distance(b.camera(4).eye) > 1.0);
    }
}

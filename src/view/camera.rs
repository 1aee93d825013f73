//! The viewer's fly camera: position, yaw and pitch, moved in metres per second so that a 4 m
//! room and a 300 m level both feel right (the default speed follows the level's size).

use glam::Vec3;
use visgate_formats::Camera;

/// A fly camera: looks along `forward()` from `eye`, +Y up.
#[derive(Debug, Clone, PartialEq)]
pub struct FlyCamera {
    /// Position. [Units: m]
    pub eye: Vec3,
    /// Rotation about +Y, 0 looking along −Z. [Units: rad]
    pub yaw: f32,
    /// Elevation, ±1.55 at most. [Units: rad]
    pub pitch: f32,
    /// Full horizontal field of view. [Units: rad]
    pub fov_x: f32,
    /// Flying speed. [Units: m/s]
    pub speed: f32,
    /// The scene camera it was made from, returned as is until it moves or turns (so that a
    /// scene camera renders exactly as `visgate render` renders it).
    origin: Option<Camera>,
}

/// Pitch stays short of straight up or down, where yaw loses its meaning.
const MAX_PITCH: f32 = 1.55;

impl FlyCamera {
    /// The camera a scene camera describes, flying at `speed` m/s.
    pub fn from_camera(c: &Camera, speed: f32) -> FlyCamera {
        let d = (c.target - c.eye).normalize_or(Vec3::NEG_Z);
        FlyCamera {
            eye: c.eye,
            yaw: (-d.x).atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            fov_x: c.fov_x_rad,
            speed,
            origin: Some(c.clone()),
        }
    }

    /// A camera at `eye` (m) with yaw and pitch (rad), field of view (rad) and speed (m/s).
    pub fn from_parts(eye: Vec3, yaw: f32, pitch: f32, fov_x: f32, speed: f32) -> FlyCamera {
        FlyCamera {
            eye,
            yaw,
            pitch: pitch.clamp(-MAX_PITCH, MAX_PITCH),
            fov_x,
            speed,
            origin: None,
        }
    }

    /// Seeing the whole of the box `lo..hi` from above one corner, at a speed that crosses it
    /// in about ten seconds.
    pub fn framing(lo: Vec3, hi: Vec3) -> FlyCamera {
        let (c, size) = ((lo + hi) * 0.5, hi - lo);
        let eye = c + Vec3::new(size.x * 0.5, size.y * 0.6, size.z * 0.5) * 1.6;
        FlyCamera::from_camera(
            &Camera {
                name: "level".into(),
                eye,
                target: c,
                up: Vec3::Y,
                fov_x_rad: 70f32.to_radians(),
            },
            Self::speed_for(lo, hi),
        )
    }

    /// The default speed for a level of these bounds: its diagonal in ten seconds.
    pub fn speed_for(lo: Vec3, hi: Vec3) -> f32 {
        ((hi - lo).length() / 10.0).max(1e-6)
    }

    /// The unit direction it looks along.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sy * cp, sp, -cy * cp)
    }

    /// Moves it for `dt` seconds: `local` is (right, up, forward) in −1..1 each.
    pub fn fly(&mut self, local: Vec3, dt: f32) {
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let step = right * local.x + Vec3::Y * local.y + f * local.z;
        self.eye += step * self.speed * dt;
        self.origin = None;
    }

    /// Turns it by a mouse drag of `dx`, `dy` pixels (`rad_per_px` each).
    pub fn look(&mut self, dx: f32, dy: f32, rad_per_px: f32) {
        self.yaw -= dx * rad_per_px;
        self.pitch = (self.pitch - dy * rad_per_px).clamp(-MAX_PITCH, MAX_PITCH);
        self.origin = None;
    }

    /// Turns it about `pivot` by a drag of `dx`, `dy` pixels, keeping its distance and
    /// looking at the pivot.
    pub fn orbit(&mut self, pivot: Vec3, dx: f32, dy: f32, rad_per_px: f32) {
        let dist = self.eye.distance(pivot);
        let d = (pivot - self.eye).normalize_or(self.forward());
        self.yaw = (-d.x).atan2(-d.z);
        self.pitch = d.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH);
        self.look(dx, dy, rad_per_px);
        self.eye = pivot - self.forward() * dist;
    }

    /// The scene camera it is (what the renderer takes).
    pub fn camera(&self) -> Camera {
        if let Some(c) = &self.origin
            && c.fov_x_rad == self.fov_x
            && c.eye == self.eye
        {
            return c.clone();
        }
        Camera {
            name: "viewer".into(),
            eye: self.eye,
            target: self.eye + self.forward(),
            up: Vec3::Y,
            fov_x_rad: self.fov_x,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_camera_comes_back_as_it_went_in() {
        let c = Camera {
            name: "c".into(),
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(4.0, 1.0, -2.0),
            up: Vec3::Y,
            fov_x_rad: 1.2,
        };
        let mut f = FlyCamera::from_camera(&c, 2.0);
        // Untouched, it is the scene camera itself (renders as `visgate render` does).
        assert_eq!(f.camera(), c);
        // Turned by nothing, it is the same direction from its yaw and pitch.
        f.look(0.0, 0.0, 0.01);
        let back = f.camera();
        let want = (c.target - c.eye).normalize();
        assert!((back.target - back.eye).distance(want) < 1e-5, "{back:?}");
        assert_eq!(back.fov_x_rad, 1.2);
    }

    #[test]
    fn flying_moves_metres_per_second_along_the_view_and_looking_stops_short_of_the_pole() {
        let mut f = FlyCamera::from_camera(
            &Camera {
                name: "c".into(),
                eye: Vec3::ZERO,
                target: Vec3::X,
                up: Vec3::Y,
                fov_x_rad: 1.0,
            },
            3.0,
        );
        f.fly(Vec3::new(0.0, 0.0, 1.0), 0.5);
        assert!(
            f.eye.distance(Vec3::new(1.5, 0.0, 0.0)) < 1e-5,
            "{:?}",
            f.eye
        );
        f.fly(Vec3::new(1.0, 0.0, 0.0), 1.0);
        // Right of +X with +Y up is +Z.
        assert!(
            f.eye.distance(Vec3::new(1.5, 0.0, 3.0)) < 1e-5,
            "{:?}",
            f.eye
        );
        f.look(0.0, -1e6, 0.01);
        assert!(f.pitch <= MAX_PITCH && f.forward().is_finite());
        // Orbiting keeps the distance to the pivot and looks at it.
        let pivot = Vec3::new(1.0, 0.5, 2.0);
        let d0 = f.eye.distance(pivot);
        f.orbit(pivot, 40.0, 10.0, 0.01);
        assert!((f.eye.distance(pivot) - d0).abs() < 1e-4);
        assert!(f.forward().dot((pivot - f.eye).normalize()) > 0.9999);
        let framing = FlyCamera::framing(Vec3::ZERO, Vec3::new(10.0, 3.0, 10.0));
        assert!((framing.speed - Vec3::new(10.0, 3.0, 10.0).length() / 10.0).abs() < 1e-5);
        // It looks at the box's centre.
        let to_centre = (Vec3::new(5.0, 1.5, 5.0) - framing.eye).normalize();
        assert!(framing.forward().dot(to_centre) > 0.999);
    }
}

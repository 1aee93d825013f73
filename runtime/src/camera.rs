//! The pinhole camera shared by the GPU passes and the CPU reference: look-at, full horizontal
//! field of view, pixel (0, 0) at the top left, pixel centres at half-integers.

use glam::{Vec2, Vec3};
use visgate_formats::Camera;

use crate::RenderError;

/// A camera fixed to an image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Eye position. [Units: m]
    pub eye: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit right vector (image +x).
    pub right: Vec3,
    /// Unit up vector (image −y).
    pub up: Vec3,
    /// Full horizontal field of view. [Units: rad]
    pub fov_x_rad: f32,
    /// Image size in pixels.
    pub size: [u32; 2],
}

impl View {
    /// The view of `camera` on a `size` image; errors on a degenerate camera or size.
    pub fn new(camera: &Camera, size: [u32; 2]) -> Result<View, RenderError> {
        if size[0] == 0 || size[1] == 0 || size[0] > 16384 || size[1] > 16384 {
            return Err(RenderError::Param(format!(
                "image size {}x{} must be 1..=16384 on each side",
                size[0], size[1]
            )));
        }
        let forward = (camera.target - camera.eye).normalize_or_zero();
        let right = forward.cross(camera.up).normalize_or_zero();
        if forward == Vec3::ZERO || right == Vec3::ZERO || !forward.is_finite() {
            return Err(RenderError::Param(format!(
                "camera '{}' has its target on its eye or its up along its view",
                camera.name
            )));
        }
        if !(camera.fov_x_rad > 0.0 && camera.fov_x_rad < std::f32::consts::PI) {
            return Err(RenderError::Param(format!(
                "camera '{}' field of view {} rad must lie in (0, π)",
                camera.name, camera.fov_x_rad
            )));
        }
        Ok(View {
            eye: camera.eye,
            forward,
            right,
            up: right.cross(forward),
            fov_x_rad: camera.fov_x_rad,
            size,
        })
    }

    /// Half-extents of the image plane at distance 1.
    pub fn tan_half(&self) -> Vec2 {
        let tx = (0.5 * self.fov_x_rad).tan();
        Vec2::new(tx, tx * self.size[1] as f32 / self.size[0] as f32)
    }

    /// Unit direction through image point `p` (pixels, (0, 0) the top-left corner).
    pub fn ray_dir(&self, p: Vec2) -> Vec3 {
        let t = self.tan_half();
        let ndc = Vec2::new(
            2.0 * p.x / self.size[0] as f32 - 1.0,
            1.0 - 2.0 * p.y / self.size[1] as f32,
        );
        (self.forward + self.right * ndc.x * t.x + self.up * ndc.y * t.y).normalize()
    }
}

/// Right-handed view matrix looking along unit `forward` (to −z), `up` roughly up.
pub fn look_to(eye: Vec3, forward: Vec3, up: Vec3) -> glam::Mat4 {
    let f = forward.normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    glam::Mat4::from_cols(
        glam::Vec4::new(s.x, u.x, -f.x, 0.0),
        glam::Vec4::new(s.y, u.y, -f.y, 0.0),
        glam::Vec4::new(s.z, u.z, -f.z, 0.0),
        glam::Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// Perspective to wgpu clip space (depth 0 at `near`, 1 at `far`) with image-plane half
/// extents `tan_x`, `tan_y` at distance 1.
pub fn perspective(tan_x: f32, tan_y: f32, near: f32, far: f32) -> glam::Mat4 {
    let a = far / (near - far);
    glam::Mat4::from_cols(
        glam::Vec4::new(1.0 / tan_x, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 1.0 / tan_y, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, a, -1.0),
        glam::Vec4::new(0.0, 0.0, near * a, 0.0),
    )
}

/// Perspective to wgpu clip space with reversed depth and no far plane: depth `near / d` at
/// view distance `d` (1 at `near`, → 0 far away), for a depth test "greater" cleared to 0.
/// Float depth is densest near 0, so precision follows distance; nothing is clipped far away.
pub fn perspective_reversed_infinite(tan_x: f32, tan_y: f32, near: f32) -> glam::Mat4 {
    glam::Mat4::from_cols(
        glam::Vec4::new(1.0 / tan_x, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 1.0 / tan_y, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
        glam::Vec4::new(0.0, 0.0, near, 0.0),
    )
}

impl View {
    /// View-projection to wgpu clip space matching [`View::ray_dir`] at pixel centres, with
    /// reversed depth and no far plane ([`perspective_reversed_infinite`]).
    pub fn view_proj(&self, near: f32) -> glam::Mat4 {
        let t = self.tan_half();
        perspective_reversed_infinite(t.x, t.y, near) * look_to(self.eye, self.forward, self.up)
    }
}

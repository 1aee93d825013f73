//! Scenes the runtime tests build: quads of one albedo, a floor, a closed box, and the
//! built-in four rooms scaled with its light.

#![allow(dead_code)] // each test file uses its own subset

use glam::{Vec2, Vec3};
use visgate_formats::scene::ImportReport;
use visgate_formats::{Camera, Light, Material, Mesh, Scene};
use visgate_scenes::Builtin;

/// A scene of quads (each `[a, b, c, d]`, counter-clockwise) of one albedo.
pub fn quads(quads: &[[Vec3; 4]], albedo: f32, lights: Vec<Light>) -> Scene {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut triangles = Vec::new();
    for q in quads {
        let n = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
        let base = positions.len() as u32;
        positions.extend_from_slice(q);
        normals.extend([n; 4]);
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base, base + 2, base + 3]);
    }
    let material = vec![0; triangles.len()];
    Scene {
        name: "test".into(),
        source: None,
        closed: false,
        meshes: vec![Mesh {
            name: "quads".into(),
            entry: 0,
            is_static: true,
            uvs: vec![Vec2::ZERO; positions.len()],
            positions,
            normals,
            triangles,
            material,
        }],
        materials: vec![Material {
            name: "white".into(),
            albedo: Vec3::splat(albedo),
            texture: None,
        }],
        textures: Vec::new(),
        lights,
        cameras: Vec::new(),
        report: ImportReport::default(),
        animation: Default::default(),
    }
}

/// The floor square of half-size `r` at height 0, facing +y.
pub fn floor(r: f32) -> [Vec3; 4] {
    [
        Vec3::new(-r, 0.0, -r),
        Vec3::new(-r, 0.0, r),
        Vec3::new(r, 0.0, r),
        Vec3::new(r, 0.0, -r),
    ]
}

/// The six inner faces of the box `[-r, r]³`.
pub fn closed_box(r: f32) -> Vec<[Vec3; 4]> {
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * r;
    vec![
        [
            c(-1., -1., -1.),
            c(-1., -1., 1.),
            c(1., -1., 1.),
            c(1., -1., -1.),
        ],
        [
            c(-1., 1., -1.),
            c(1., 1., -1.),
            c(1., 1., 1.),
            c(-1., 1., 1.),
        ],
        [
            c(-1., -1., -1.),
            c(-1., 1., -1.),
            c(-1., 1., 1.),
            c(-1., -1., 1.),
        ],
        [
            c(1., -1., -1.),
            c(1., -1., 1.),
            c(1., 1., 1.),
            c(1., 1., -1.),
        ],
        [
            c(-1., -1., -1.),
            c(1., -1., -1.),
            c(1., 1., -1.),
            c(-1., 1., -1.),
        ],
        [
            c(-1., -1., 1.),
            c(-1., 1., 1.),
            c(1., 1., 1.),
            c(1., -1., 1.),
        ],
    ]
}

/// The built-in four rooms and its first camera, every length (cameras too: a bake keeps the
/// empty space that holds them) × `scale` and the lights' intensities × `scale²`, so that the
/// image is the same at any scale.
pub fn scaled_four_rooms(scale: f32) -> (Scene, Camera) {
    let mut s = Builtin::FourRooms.scene().expect("scene");
    for m in &mut s.meshes {
        m.positions.iter_mut().for_each(|p| *p *= scale);
    }
    for l in &mut s.lights {
        let (Light::Point {
            position,
            intensity,
        }
        | Light::Spot {
            position,
            intensity,
            ..
        }) = l;
        *position *= scale;
        *intensity *= scale * scale;
    }
    for c in &mut s.cameras {
        c.eye *= scale;
        c.target *= scale;
    }
    let cam = s.cameras.first().cloned().expect("a camera");
    (s, cam)
}

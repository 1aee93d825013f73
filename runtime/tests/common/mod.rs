//! Scenes the runtime tests build: quads of one albedo, a floor, a closed box, the built-in
//! four rooms scaled with its light, and a floor under a wide blocker with VPLs above it.

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
    placed_four_rooms(scale, Vec3::ZERO)
}

/// The four rooms scaled by `scale` (as [`scaled_four_rooms`]), then moved by `offset`
/// (metres), and its first camera.
pub fn placed_four_rooms(scale: f32, offset: Vec3) -> (Scene, Camera) {
    let mut s = Builtin::FourRooms.scene().expect("scene");
    for m in &mut s.meshes {
        m.positions
            .iter_mut()
            .for_each(|p| *p = *p * scale + offset);
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
        *position = *position * scale + offset;
        *intensity *= scale * scale;
    }
    for c in &mut s.cameras {
        c.eye = c.eye * scale + offset;
        c.target = c.target * scale + offset;
    }
    let cam = s.cameras.first().cloned().expect("a camera");
    (s, cam)
}

/// A 10 m floor, a 3 × 10 m blocker 1 m above its middle strip, 256 VPLs 2.5 m up facing
/// down over the blocker, and a low camera looking along the strip.
pub fn blocker_scene() -> (Scene, Vec<visgate_runtime::vpl::Vpl>, Camera) {
    let blocker = [
        Vec3::new(-1.5, 1.0, -5.0),
        Vec3::new(1.5, 1.0, -5.0),
        Vec3::new(1.5, 1.0, 5.0),
        Vec3::new(-1.5, 1.0, 5.0),
    ];
    let scene = quads(&[floor(5.0), blocker], 0.5, vec![]);
    let vpls = (0..256)
        .map(|i| {
            let p = Vec3::new(
                -1.0 + (i % 8) as f32 * 2.0 / 7.0,
                2.5,
                -4.0 + (i / 8) as f32 * 8.0 / 31.0,
            );
            visgate_runtime::vpl::Vpl::new(p, Vec3::NEG_Y, Vec3::splat(0.05))
        })
        .collect();
    let cam = Camera {
        name: "low".into(),
        eye: Vec3::new(0.0, 0.5, -4.5),
        target: Vec3::new(0.0, 0.0, 0.0),
        up: Vec3::Y,
        fov_x_rad: 70f32.to_radians(),
    };
    (scene, vpls, cam)
}

/// Over the floor pixels of [`blocker_scene`] (found by ray casting from `cam` at the images'
/// size), the red channel of each image under the blocker's middle (|x| < 0.8) and in the open
/// (|x| > 3): `[under, open]` per image.
pub fn under_and_open(
    scene: &Scene,
    cam: &Camera,
    images: &[&visgate_runtime::hdr::HdrImage],
) -> Vec<[Vec<f32>; 2]> {
    let (w, h) = (images[0].width, images[0].height);
    let view = visgate_runtime::camera::View::new(cam, [w, h]).expect("view");
    let tracer = visgate_runtime::cpu::tracer::Tracer::new(scene);
    let mut out = vec![[Vec::new(), Vec::new()]; images.len()];
    for y in 0..h {
        for x in 0..w {
            let dir = view.ray_dir(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = tracer.trace(view.eye, dir) else {
                continue;
            };
            if hit.position.y.abs() > 1e-3 {
                continue;
            }
            let side = match hit.position.x.abs() {
                a if a < 0.8 => 0,
                a if a > 3.0 => 1,
                _ => continue,
            };
            for (o, img) in out.iter_mut().zip(images) {
                o[side].push(img.at(x, y).x);
            }
        }
    }
    out
}

/// Built-in scene `b` and its one-bounce light-path VPLs from `paths` paths (seed 3).
pub fn vpls_of(b: Builtin, paths: u32) -> (Scene, Vec<visgate_runtime::vpl::Vpl>) {
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let scene = b.scene().expect("scene");
    let tracer = visgate_runtime::cpu::tracer::Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths,
            bounces: 1,
            seed: 3,
        },
    )
    .expect("vpls");
    (scene, vpls)
}

/// 64 VPLs in one plane (a floor patch 2.1 m square, facing up): VALs of zero area in one
/// plane.
pub fn coplanar_vpls() -> Vec<visgate_runtime::vpl::Vpl> {
    (0..64)
        .map(|i| {
            visgate_runtime::vpl::Vpl::new(
                Vec3::new(1.0 + (i % 8) as f32 * 0.3, 0.0, 1.0 + (i / 8) as f32 * 0.3),
                Vec3::Y,
                Vec3::splat(0.1),
            )
        })
        .collect()
}

//! The whole bake on the built-in scenes (known answers), at the extremes of scale and
//! resolution, on bad input, and byte-for-byte reproducibility across thread counts.

use std::path::Path;

use glam::{Vec2, Vec3};
use visgate_formats::Scene;
use visgate_formats::desc::{CameraDesc, SceneDesc};
use visgate_formats::import::{ImportedModel, RawMesh};
use visgate_formats::vgate::{BakeParams, BakedLevel, GatePlacement, GridMeta, NONE, Resolution};
use visgate_preprocess::BakeError;
use visgate_preprocess::bake::{BakeOptions, Baked, bake};
use visgate_preprocess::voxelize::BAKE_BYTES_PER_VOXEL;
use visgate_scenes::level::{BoxLevel, cbox};
use visgate_scenes::{Builtin, Opening};

// Recorded again with format 6: the open voxels of the sight grid (a bit a voxel, at 1/512 of
// the level by default: 512 voxels on these levels' longest axis) and its grid in the header;
// nothing else changed (the portal agreement figures in tests/portals.rs did not move). The
// third bake is the pillared hall at 128 partitioned on its 64 grid. Recorded again when the
// sight grid was voxelized thin (crate::separating): its open bits alone changed, same sizes.
// Recorded again with format 7, whose open voxels are stored as runs of words: the same levels
// (read back equal to format 6's files), 28-32 % fewer bytes.
// Recorded again when a coarse bake was partitioned on a finer grid: the first two, at 64,
// are partitioned on their 128 grids since.
const RECORDED_AJAR_DOOR: (&str, u64, usize) = ("ajar-door", 0x57b0_42e3_4471_9e83, 2_353_098);
const RECORDED_PILLARED_HALL: (&str, u64, usize) =
    ("pillared-hall", 0x77f3_650a_7b71_1d41, 2_657_551);
const RECORDED_PILLARED_HALL_REFINED: (&str, u64, usize) =
    ("pillared-hall", 0x3be3_cfe9_a947_77a0, 2_687_793);

fn params(res: u32) -> BakeParams {
    BakeParams {
        resolution: Resolution::LongestAxisVoxels(res),
        ..BakeParams::default()
    }
}

fn bake_scene(scene: &Scene, p: &BakeParams) -> Result<Baked, BakeError> {
    bake(scene, p, &BakeOptions::default(), &|_| {})
}

fn distance_to_box(p: Vec3, b: &Opening) -> f32 {
    let lo = Vec3::from(b.min_m);
    let hi = Vec3::from(b.max_m);
    (p.clamp(lo, hi) - p).length()
}

/// Cluster of the empty voxel at `p`, if any.
fn cluster_at(level: &BakedLevel, p: Vec3) -> Option<u32> {
    let g = &level.info.grid;
    let v = (p - Vec3::from(g.origin_m)) / g.voxel_size_m;
    let v = [v.x as u32, v.y as u32, v.z as u32];
    level
        .voxel_cluster
        .get(g.index(v))
        .filter(|&c| c != u32::MAX)
}

fn custom(name: &str, model: ImportedModel, closed: bool, eye: [f64; 3], mpu: f64) -> Scene {
    let mut desc = SceneDesc::for_mesh_file(Path::new(&format!("{name}.obj")));
    desc.metres_per_unit = mpu;
    desc.closed = closed;
    desc.cameras = vec![CameraDesc {
        name: "main".into(),
        eye,
        target: [eye[0] + 1.0, eye[1], eye[2]],
        up: None,
        fov_deg: 60.0,
    }];
    Scene::assemble(&desc, vec![model], Path::new(name)).expect("assemble")
}

fn model_of(level: &BoxLevel) -> ImportedModel {
    ImportedModel {
        meshes: level.meshes(),
        materials: visgate_scenes::level::MATERIALS
            .iter()
            .map(|(n, a)| visgate_formats::Material {
                name: (*n).into(),
                albedo: Vec3::from(*a),
                texture: None,
            })
            .collect(),
        ..Default::default()
    }
}

fn raw(name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> ImportedModel {
    let n = positions.len();
    ImportedModel {
        meshes: vec![RawMesh {
            name: name.into(),
            normals: vec![Vec3::Y; n],
            uvs: vec![Vec2::ZERO; n],
            positions,
            triangles,
            material: 0,
        }],
        materials: vec![visgate_formats::Material {
            name: "grey".into(),
            albedo: Vec3::splat(0.5),
            texture: None,
        }],
        ..Default::default()
    }
}

/// A 4 × 3 × 4 m room of zero-thickness walls with `windows` 0.6 m square holes — the first in
/// its +x wall centred at (4, 1.5, 2), the second in its -z wall (on the bounds) centred at
/// (2, 1.5, 0) — and a ground from x = 4 to 8 m outside it.
fn room_with_windows(windows: u32) -> ImportedModel {
    let mut pos: Vec<Vec3> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut quad = |p: [Vec3; 4]| {
        let n = pos.len() as u32;
        pos.extend(p);
        tris.extend([[n, n + 1, n + 2], [n, n + 2, n + 3]]);
    };
    let v = Vec3::new;
    // Floor, ceiling, -x, -z, +z walls; the ground outside.
    quad([v(0., 0., 0.), v(0., 0., 4.), v(4., 0., 4.), v(4., 0., 0.)]);
    quad([v(0., 3., 0.), v(4., 3., 0.), v(4., 3., 4.), v(0., 3., 4.)]);
    quad([v(0., 0., 0.), v(0., 3., 0.), v(0., 3., 4.), v(0., 0., 4.)]);
    quad([v(0., 0., 4.), v(0., 3., 4.), v(4., 3., 4.), v(4., 0., 4.)]);
    quad([v(4., 0., 0.), v(4., 0., 4.), v(8., 0., 4.), v(8., 0., 0.)]);
    // The +x wall, around the window (y 1.2..1.8, z 1.7..2.3) or whole.
    let wall = |y0: f32, y1: f32, z0: f32, z1: f32| {
        [v(4., y0, z0), v(4., y0, z1), v(4., y1, z1), v(4., y1, z0)]
    };
    if windows >= 2 {
        let w = |x0: f32, x1: f32, y0: f32, y1: f32| {
            [v(x0, y0, 0.), v(x1, y0, 0.), v(x1, y1, 0.), v(x0, y1, 0.)]
        };
        quad(w(0.0, 4.0, 0.0, 1.2));
        quad(w(0.0, 4.0, 1.8, 3.0));
        quad(w(0.0, 1.7, 1.2, 1.8));
        quad(w(2.3, 4.0, 1.2, 1.8));
    } else {
        quad([v(0., 0., 0.), v(4., 0., 0.), v(4., 3., 0.), v(0., 3., 0.)]);
    }
    if windows >= 1 {
        quad(wall(0.0, 1.2, 0.0, 4.0));
        quad(wall(1.8, 3.0, 0.0, 4.0));
        quad(wall(1.2, 1.8, 0.0, 1.7));
        quad(wall(1.2, 1.8, 2.3, 4.0));
    } else {
        quad(wall(0.0, 3.0, 0.0, 4.0));
    }
    raw("room", pos, tris)
}

/// Asserts that opening `o`, found on a grid of `res` voxels over [`room_with_windows`]'s
/// 8 m, lies within a voxel of its first window (y 1.2 … 1.8, z 1.7 … 2.3 m in the plane x = 4).
fn assert_at_the_window(o: &visgate_preprocess::leak::LeakPath, res: u32) {
    let vx = 8.0 / res as f32;
    let p = Vec3::from(o.opening_m);
    let (lo, hi) = (Vec3::new(4.0, 1.2, 1.7), Vec3::new(4.0, 1.8, 2.3));
    assert!(
        p.cmpge(lo - vx).all() && p.cmple(hi + vx).all(),
        "at {res}: opening {p} not within a voxel of the window: {}",
        o.describe()
    );
}

mod bare;
mod known;
mod leaks;
mod recorded;
mod scale;

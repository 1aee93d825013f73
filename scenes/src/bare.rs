//! What a bare mesh file needs to be looked at. An OBJ or glTF on its own carries no light and
//! no camera, so every render of it is black (or refused for want of a camera). Such a scene
//! gets a point light and a camera named `inside` at one place: the centre of the
//! level's largest empty ball, inside its largest room, where a level's light belongs (the
//! caller finds it: `visgate_preprocess::ball`, from the scene alone, so that every render of
//! it looks from one place, with a baked level or without), else the enclosed point farthest
//! from the geometry found by rays; the camera looks level, the way whose view holds the most
//! of the level (of 64 horizontal directions, the one whose rays within its 35° half-field
//! reach farthest by the mean of their cubes), so that its first picture is neither a wall a
//! metre away nor a room's corner. Where it gets both, the camera then steps back, half-way to
//! the geometry behind it, and looks past the light: a camera at the light sees every surface
//! lit and no shadow, as a flash photograph does, and no visibility method differs there. The
//! light's intensity gives the walls around it about 2 W/m² (`I = 2 d²` W/sr, `d` the mean
//! distance to them). Where the mesh has materials that glow (a lamp's emissive surface, which
//! lights nothing in visgate), the light goes to them instead: a point light a hundredth of the
//! level's size in front of each glowing material's surface (its area-weighted centre, off
//! along its area-weighted normal), giving the walls around it its share by area of about
//! 2 W/m²; a material whose faces point every way (a closed bulb) gets none; the camera then
//! stays at the place.

use glam::Vec3;
use visgate_formats::{Camera, Light, Scene};

/// Name of the camera [`light_a_bare_scene`] adds.
pub const INSIDE_CAMERA: &str = "inside";

/// Directions a point is probed along: the 26 of a voxel's neighbours.
pub fn probe_directions() -> Vec<Vec3> {
    let mut out = Vec::with_capacity(26);
    for z in -1..=1 {
        for y in -1..=1 {
            for x in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out.push(Vec3::new(x as f32, y as f32, z as f32).normalize());
                }
            }
        }
    }
    out
}

/// Horizontal directions the camera may look along. [Units: count]
const LOOK_DIRECTIONS: usize = 64;

/// Of [`LOOK_DIRECTIONS`], those on either side of a view's centre that its rays span: the
/// camera's 70° across, 35° a side. [Units: count]
const LOOK_SPAN: usize = 6;

/// The horizontal direction from `eye` whose view holds the most of the level: of 64
/// directions, the one whose rays within 35° of it (the camera's field) reach farthest, by the
/// mean of their cubed lengths (the volume of the view's cone) weighted by a tent over the
/// field; `reach(p, d)` is how far the ray from `p` along `d` goes before it meets the
/// geometry, `None` where it escapes: through a window to the void, which shows nothing of the
/// level, so it counts as 0. Cubed, a doorway onto the next room outweighs the far corner of
/// the camera's own room, which a plain mean over a narrower window chose (a room's corner is
/// its farthest point from its centre: the first picture of the ajar door's bare OBJ was two
/// walls meeting). Ties go to the first, +X.
fn deepest_look(eye: Vec3, reach: &dyn Fn(Vec3, Vec3) -> Option<f32>) -> Vec3 {
    let n = LOOK_DIRECTIONS;
    let dirs: Vec<Vec3> = (0..n)
        .map(|i| {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            Vec3::new(a.cos(), 0.0, a.sin())
        })
        .collect();
    let volume: Vec<f32> = dirs
        .iter()
        .map(|&d| reach(eye, d).map_or(0.0, |t| t * t * t))
        .collect();
    // Weighted by a tent over the field, so that what it holds most of sits in its middle.
    let score = |i: usize| -> f32 {
        (0..=2 * LOOK_SPAN)
            .map(|k| {
                (LOOK_SPAN + 1).abs_diff(k.abs_diff(LOOK_SPAN)) as f32
                    * volume[(i + n + k - LOOK_SPAN) % n]
            })
            .sum()
    };
    let best = (0..n).fold(0, |b, i| if score(i) > score(b) { i } else { b });
    dirs[best]
}

/// Gives `scene` a light where it has none and a camera where it has none (see the module
/// notes); says what it added, or `None` when it needed nothing (or has no geometry).
/// `probe(p)` is the nearest and the mean distance to the geometry along
/// [`probe_directions`] from `p`, `None` where a ray escapes; `reach(p, d)` the distance along
/// one ray, `None` where it escapes. The place is `ball`, the centre of the level's largest
/// empty ball, or without one the enclosed point of a 7³ lattice over the bounds farthest from
/// the geometry (a point inside a closed solid is near its walls).
pub fn light_a_bare_scene(
    scene: &mut Scene,
    ball: Option<Vec3>,
    probe: &dyn Fn(Vec3) -> Option<(f32, f32)>,
    reach: &dyn Fn(Vec3, Vec3) -> Option<f32>,
) -> Option<String> {
    let (no_light, no_camera) = (scene.lights.is_empty(), scene.cameras.is_empty());
    if !no_light && !no_camera {
        return None;
    }
    let (lo, hi) = scene.bounds()?;
    // A plane (a ground alone, one wall) has no inside to stand in: look at it from its
    // front, lit from the eye (the bake refuses it as flat; the reference renders it).
    let flat = flat_view(scene, lo, hi);
    let (at, from) = match (flat, ball) {
        (Some((eye, _)), _) => (
            eye,
            "off the flat level on the side its faces face, looking at its centre",
        ),
        (None, Some(p)) => (p, "the centre of the level's largest empty ball"),
        (None, None) => {
            const N: usize = 7;
            let lattice = (0..N * N * N).map(|i| {
                let t = Vec3::new((i % N) as f32, ((i / N) % N) as f32, (i / (N * N)) as f32);
                lo + (hi - lo) * (t + 0.5) / N as f32
            });
            let best = lattice
                .filter_map(|p| probe(p).map(|(near, _)| (near, p)))
                .max_by(|a, b| a.0.total_cmp(&b.0));
            match best {
                Some((_, p)) => (p, "the enclosed point farthest from the geometry"),
                None => ((lo + hi) * 0.5, "the centre of the scene's bounds"),
            }
        }
    };
    // Walls at the mean distance around it get about 2 W/m² (a flat level: its centre).
    let mean = match flat {
        Some((eye, centre)) => eye.distance(centre),
        None => probe(at).map_or(0.1 * (hi - lo).length(), |(_, mean)| mean),
    };
    // What goes at `at`, and the lamps' lights, which go elsewhere.
    let (mut here, mut lamps_said) = (Vec::new(), None);
    if no_light {
        let lamps = glowing_surfaces(scene, 0.01 * (hi - lo).length());
        lamps_said = light_the_lamps(scene, &lamps, probe, mean);
        if lamps_said.is_none() {
            let intensity = 2.0 * mean * mean;
            scene.lights.push(Light::Point {
                position: at,
                intensity: Vec3::splat(intensity),
            });
            here.push(format!("a point light of {intensity:.3} W/sr"));
        }
    }
    // Whether the light just placed stands at `at` (not at the lamps).
    let light_here = !here.is_empty();
    let mut behind = None;
    if no_camera {
        let along = flat.map_or_else(|| deepest_look(at, reach), |(eye, centre)| centre - eye);
        // A camera at the light sees no shadow: where the light is ours, it steps back.
        behind = (flat.is_none() && light_here)
            .then(|| step_back(at, along, reach))
            .flatten();
        let eye = behind.map_or(at, |step| at - along * step);
        scene.cameras.push(Camera {
            name: INSIDE_CAMERA.into(),
            eye,
            target: eye + along,
            up: Vec3::Y,
            fov_x_rad: 70f32.to_radians(),
        });
        here.push(format!("a camera '{INSIDE_CAMERA}'"));
    }
    let at_str = |p: Vec3| format!("({:.3}, {:.3}, {:.3}) m", p.x, p.y, p.z);
    let here = match (behind, here.as_slice()) {
        (_, []) => None,
        (Some(step), [light, camera]) => Some(format!(
            "{light} at {}, {from}, and {camera} at {}, {step:.2} m behind it, looking past it",
            at_str(at),
            at_str(scene.cameras.last().map_or(at, |c| c.eye))
        )),
        _ => Some(format!("{} at {}, {from}", here.join(" and "), at_str(at))),
    };
    let said: Vec<String> = lamps_said.into_iter().chain(here).collect();
    Some(format!(
        "the scene has no {}: {} (give [[light]]s and [[camera]]s in a scene TOML that names the \
         mesh to choose your own)",
        match (no_light, no_camera) {
            (true, true) => "light and no camera",
            (true, false) => "light",
            _ => "camera",
        },
        said.join(" and ")
    ))
}

/// The fraction of the way to the geometry behind a camera at the light that it steps back
/// ([`step_back`]). [Units: ratio]
const STEP_BACK_SHARE: f32 = 0.5;

/// The least step back worth taking: nearer, the light is still a headlight. [Units: m]
const STEP_BACK_MIN_M: f32 = 0.25;

/// How far a camera at the light `at`, looking along `along`, steps back so that it sees the
/// light's shadows: [`STEP_BACK_SHARE`] of the way to the geometry behind it; `None` where
/// that is under [`STEP_BACK_MIN_M`] or the ray behind escapes (a window to the void at its
/// back: it would stand outside the level).
fn step_back(at: Vec3, along: Vec3, reach: &dyn Fn(Vec3, Vec3) -> Option<f32>) -> Option<f32> {
    let step = STEP_BACK_SHARE * reach(at, -along)?;
    (step >= STEP_BACK_MIN_M).then_some(step)
}

/// Where bounds `lo`–`hi` are flat along an axis (`visgate_formats::geom::flat_axis`, as the
/// bake refuses them), an eye to see the plane from and its centre:
/// on the side the most triangle area faces, half the plane's longest side off it; off a
/// ground (flat along y) also half that back along −z, looking down at 45° (straight down
/// would leave the camera's up, +y, along its view).
fn flat_view(scene: &Scene, lo: Vec3, hi: Vec3) -> Option<(Vec3, Vec3)> {
    let extent = hi - lo;
    let longest = extent.max_element();
    let axis = Vec3::AXES[visgate_formats::geom::flat_axis(extent.as_dvec3())?];
    let facing: f32 = scene
        .meshes
        .iter()
        .flat_map(|m| {
            m.triangles.iter().map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                (b - a).cross(c - a).dot(axis)
            })
        })
        .sum();
    let side = if facing < 0.0 { -axis } else { axis };
    let centre = 0.5 * (lo + hi);
    let back = if axis == Vec3::Y {
        -Vec3::Z
    } else {
        Vec3::ZERO
    };
    Some((centre + 0.5 * longest * (side + back), centre))
}

/// Lights `lamps` (a point light in front of each, the walls around it getting its share by
/// area of about 2 W/m², at `mean` metres where its rays escape) and says so; `None` where
/// there are none.
fn light_the_lamps(
    scene: &mut Scene,
    lamps: &[Lamp],
    probe: &dyn Fn(Vec3) -> Option<(f32, f32)>,
    mean: f32,
) -> Option<String> {
    let first = lamps.first()?;
    let area: f32 = lamps.iter().map(|l| l.area).sum();
    let mut total = 0.0;
    for l in lamps {
        let d = probe(l.position).map_or(mean, |(_, m)| m);
        let i = 2.0 * d * d * l.area / area;
        total += i;
        scene.lights.push(Light::Point {
            position: l.position,
            intensity: Vec3::splat(i),
        });
    }
    Some(format!(
        "{} point light(s) of {total:.3} W/sr in all at its glowing surfaces (material '{}' at \
         ({:.3}, {:.3}, {:.3}) m{})",
        lamps.len(),
        first.material,
        first.position.x,
        first.position.y,
        first.position.z,
        if lamps.len() > 1 { ", …" } else { "" }
    ))
}

/// A glowing material's surface, as a lamp.
struct Lamp {
    material: String,
    /// A little in front of the surface's area-weighted centre. [Units: m]
    position: Vec3,
    /// The surface's area. [Units: m²]
    area: f32,
}

/// The glowing materials' surfaces of `scene` (its static and dynamic meshes), each as a lamp
/// `offset` metres in front of it; none for a material whose faces' normals cancel to under
/// half their area (a closed bulb: a light at its centre would light nothing).
fn glowing_surfaces(scene: &Scene, offset: f32) -> Vec<Lamp> {
    let mut lamps = Vec::new();
    for &m in &scene.report.glowing_materials {
        let (mut area, mut centre, mut normal) = (0.0f32, Vec3::ZERO, Vec3::ZERO);
        for mesh in &scene.meshes {
            for (t, &tm) in mesh.triangles.iter().zip(&mesh.material) {
                if tm != m {
                    continue;
                }
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let n = 0.5 * (b - a).cross(c - a);
                let ta = n.length();
                area += ta;
                centre += ta * (a + b + c) / 3.0;
                normal += n;
            }
        }
        if area > 0.0 && normal.length() > 0.5 * area {
            lamps.push(Lamp {
                material: scene.materials[m as usize].name.clone(),
                position: centre / area + normal.normalize() * offset,
                area,
            });
        }
    }
    lamps
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How far a ray from `p` inside the box `lo..hi` goes along `d` before it meets a face.
    fn to_the_box(lo: Vec3, hi: Vec3) -> impl Fn(Vec3, Vec3) -> Option<f32> {
        move |p: Vec3, d: Vec3| {
            let t = (0..3)
                .filter(|&a| d[a] != 0.0)
                .map(|a| if d[a] > 0.0 { hi[a] - p[a] } else { p[a] - lo[a] } / d[a].abs())
                .fold(f32::INFINITY, f32::min);
            t.is_finite().then_some(t)
        }
    }

    /// Inside the box `lo..hi` every ray hits a wall: the nearest is the distance to the
    /// nearest face, the mean a stand-in.
    fn in_the_box(lo: Vec3, hi: Vec3) -> impl Fn(Vec3) -> Option<(f32, f32)> {
        move |p: Vec3| {
            let near = (p - lo).min(hi - p).min_element();
            (near > 0.0).then_some((near, 2.0 * near))
        }
    }

    #[test]
    fn the_camera_looks_level_the_way_that_sees_deepest() {
        // A corridor-like room 8 m long in x, 2 m wide in z; from its centre the deepest view
        // is along ±x (the window around +x reaches 4.2 m on average, a diagonal 3.1 m).
        let (lo, hi) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(8.0, 3.0, 2.0));
        let reach = to_the_box(lo, hi);
        let eye = Vec3::new(4.0, 1.5, 1.0);
        let d = deepest_look(eye, &reach);
        assert!(d.y == 0.0 && d.x.abs() > 0.999, "{d}");
        // Off-centre towards +x, it looks back along -x, the longer way.
        let d = deepest_look(Vec3::new(6.5, 1.5, 1.0), &reach);
        assert!(d.x < -0.999, "{d}");
        // Rotated: 2 m in x, 8 m in z: along ±z.
        let reach = to_the_box(lo, Vec3::new(2.0, 3.0, 8.0));
        let d = deepest_look(Vec3::new(1.0, 1.5, 4.0), &reach);
        assert!(d.z.abs() > 0.999, "{d}");
        // A window to the void at -z: it looks the other way, into the room.
        let open = |p: Vec3, d: Vec3| if d.z < -0.9 { None } else { reach(p, d) };
        let d = deepest_look(Vec3::new(1.0, 1.5, 4.0), &open);
        assert!(d.z > 0.999, "{d}");
    }

    #[test]
    fn from_a_rooms_centre_the_camera_looks_through_its_doorway_not_into_a_corner() {
        // A 4 × 4 m room with a 1 m doorway in its +x wall (z 2.5–3.5) onto a second room as
        // large: from the first room's centre the farthest walls are its corners, 2.8 m away,
        // but the view that holds the most looks through the doorway.
        let (room, both) = (
            to_the_box(Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)),
            to_the_box(Vec3::ZERO, Vec3::new(8.0, 3.0, 4.0)),
        );
        let reach = |p: Vec3, d: Vec3| {
            let t = room(p, d)?;
            let q = p + d * t;
            let through = (q.x - 4.0).abs() < 1e-4 && (2.5..3.5).contains(&q.z);
            if through { both(p, d) } else { Some(t) }
        };
        let d = deepest_look(Vec3::new(2.0, 1.5, 2.0), &reach);
        let angle = d.z.atan2(d.x).to_degrees();
        // The doorway spans 14°–37° from the centre; the corners lie at ±45° and ±135°.
        assert!((10.0..=40.0).contains(&angle), "{d} ({angle}°)");
        // Without the doorway, a corner: the room alone gives nothing better.
        let d = deepest_look(Vec3::new(2.0, 1.5, 2.0), &room);
        assert!((d.x.abs() - d.z.abs()).abs() < 1e-3, "{d}");
    }

    #[test]
    fn a_scene_gets_only_what_it_lacks_at_the_enclosed_point_farthest_from_its_walls() {
        let mut scene = crate::Builtin::EmptyBox.scene().expect("builtin");
        let (lo, hi) = scene.bounds().expect("bounds");
        let probe = in_the_box(lo, hi);
        let reach = to_the_box(lo, hi);
        assert!(light_a_bare_scene(&mut scene, None, &probe, &reach).is_none());
        let lights = scene.lights.clone();
        scene.cameras.clear();
        let said = light_a_bare_scene(&mut scene, None, &probe, &reach).expect("a camera");
        assert!(
            said.contains("no camera") && !said.contains("point light"),
            "{said}"
        );
        assert_eq!(scene.lights, lights);
        assert_eq!(scene.cameras.len(), 1);
        scene.lights.clear();
        scene.cameras.clear();
        let said = light_a_bare_scene(&mut scene, None, &probe, &reach).expect("both");
        assert!(said.contains("no light and no camera"), "{said}");
        let [Light::Point { position, .. }] = scene.lights[..] else {
            panic!("one point light: {:?}", scene.lights);
        };
        // The lattice point nearest the box's centre is the farthest from every face.
        let c = (lo + hi) * 0.5;
        assert!((position - c).abs().max_element() < (hi - lo).max_element() / 7.0);
        // The camera stands half-way from the light to the wall behind it, looking past it.
        let cam = &scene.cameras[0];
        let along = (cam.target - cam.eye).normalize();
        let behind = reach(position, -along).expect("a wall behind");
        assert!((cam.eye - (position - along * behind * 0.5)).length() < 1e-4);
        assert!(said.contains("behind it, looking past it"), "{said}");
        // With a light of its own, the camera stands where the light would: at the place.
        scene.cameras.clear();
        light_a_bare_scene(&mut scene, None, &probe, &reach).expect("a camera");
        assert_eq!(scene.cameras[0].eye, position);
    }

    #[test]
    fn a_flat_scene_is_seen_from_the_side_its_faces_face() {
        // A 10 × 6 m ground alone, its two triangles wound to face up (+y): every ray from
        // it escapes and it has no inside, so the light and the camera sat in its plane and the
        // render was black. They go 5 m above it and 5 m back along −z, looking at its centre.
        let mut scene = crate::Builtin::EmptyBox.scene().expect("builtin");
        scene.lights.clear();
        scene.cameras.clear();
        scene.meshes.truncate(1);
        let ground = &mut scene.meshes[0];
        ground.positions = vec![
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 6.0),
            Vec3::new(10.0, 1.0, 6.0),
            Vec3::new(10.0, 1.0, 0.0),
        ];
        ground.normals = vec![Vec3::Y; 4];
        ground.uvs = vec![glam::Vec2::ZERO; 4];
        ground.triangles = vec![[0, 1, 2], [0, 2, 3]];
        ground.material = vec![0, 0];
        let escape = |_: Vec3| None;
        let said = light_a_bare_scene(&mut scene, None, &escape, &|_, _| None).expect("said");
        assert!(said.contains("off the flat level"), "{said}");
        let (eye, centre) = (Vec3::new(5.0, 6.0, -2.0), Vec3::new(5.0, 1.0, 3.0));
        let cam = &scene.cameras[0];
        assert!(
            cam.eye.distance(eye) < 1e-5 && cam.target.distance(centre) < 1e-5,
            "{cam:?}"
        );
        let Light::Point {
            position,
            intensity,
        } = scene.lights[0]
        else {
            panic!("{:?}", scene.lights[0]);
        };
        // 2 W/m² at the centre, 7.07 m away.
        assert!(position.distance(eye) < 1e-5, "{position}");
        assert!((intensity.x - 2.0 * 50.0).abs() < 1e-3, "{intensity}");
        // Wound the other way, it is seen from below.
        for t in &mut scene.meshes[0].triangles {
            t.swap(1, 2);
        }
        let (lo, hi) = scene.bounds().expect("bounds");
        let (below, _) = flat_view(&scene, lo, hi).expect("flat");
        assert!(
            (below - Vec3::new(5.0, -4.0, -2.0)).length() < 1e-5,
            "{below}"
        );
        // Bounds with any depth are not flat.
        assert!(flat_view(&scene, lo, hi + Vec3::Y * 0.01).is_none());
    }

    #[test]
    fn a_bare_scenes_light_goes_to_its_glowing_surfaces() {
        use visgate_formats::{Material, Mesh};
        let mut scene = crate::Builtin::EmptyBox.scene().expect("builtin");
        let (lo, hi) = scene.bounds().expect("bounds");
        let probe = in_the_box(lo, hi);
        let reach = to_the_box(lo, hi);
        scene.lights.clear();
        let glowing = |scene: &mut Scene, name: &str, positions: Vec<Vec3>, tris: Vec<[u32; 3]>| {
            let m = scene.materials.len() as u32;
            scene.materials.push(Material {
                name: name.into(),
                albedo: Vec3::ONE,
                texture: None,
            });
            scene.meshes.push(Mesh {
                name: name.into(),
                entry: 0,
                is_static: true,
                normals: vec![Vec3::Y; positions.len()],
                uvs: vec![glam::Vec2::ZERO; positions.len()],
                positions,
                material: vec![m; tris.len()],
                triangles: tris,
            });
            scene.report.glowing_materials.push(m);
        };
        // A closed 20 cm bulb glows all round: no lamp there (a light inside would light
        // nothing).
        let corner = Vec3::new(2.0, 1.5, 2.0);
        let cube = (0..8)
            .map(|i| {
                corner + 0.2 * Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)
            })
            .collect();
        let faces = vec![
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
        ];
        glowing(&mut scene, "bulb", cube, faces);
        assert!(glowing_surfaces(&scene, 0.1).is_empty());
        // A 1 m² panel under the ceiling, wound to face down, glows: the one light goes in
        // front of it.
        let y = hi.y - 0.01;
        let panel = [(1.0, 1.0), (2.0, 1.0), (2.0, 2.0), (1.0, 2.0)]
            .map(|(x, z)| Vec3::new(x, y, z))
            .to_vec();
        glowing(&mut scene, "panel", panel, vec![[0, 1, 2], [0, 2, 3]]);
        let said = light_a_bare_scene(&mut scene, None, &probe, &reach).expect("a light");
        // Only the light was missing, and it is not at the enclosed point.
        assert!(
            said.contains("material 'panel'") && !said.contains("enclosed point"),
            "{said}"
        );
        let [Light::Point { position, .. }] = scene.lights[..] else {
            panic!("one point light: {:?}", scene.lights);
        };
        // Its centre, a hundredth of the room's diagonal below it.
        let below = 0.01 * (hi - lo).length();
        assert!(
            (position - Vec3::new(1.5, y - below, 1.5)).length() < 1e-4,
            "{position}"
        );
    }
}

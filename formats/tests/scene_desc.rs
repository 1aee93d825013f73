//! The scene description: unknown keys, limits, conversions.

use std::path::Path;

use visgate_formats::desc::{LightDesc, SceneDesc, UpAxis};
use visgate_formats::{Light, Scene, SceneError};

const FULL: &str = r#"
name = "demo"
up = "z"
metres_per_unit = 0.01
closed = true

[[mesh]]
path = "rooms.obj"
static = false
translate = [1, 2, 3]
rotate_deg = [0, 0, 90]
scale = [1, 2, 1]

[[material]]
name = "floor"
albedo = [0.5, 0.4, 0.3]

[[light]]
type = "point"
position = [100, 200, 300]
intensity = [1, 2, 3]

[[light]]
type = "spot"
position = [0, 0, 250]
direction = [0, 0, -1]
intensity = [10, 10, 10]
cutoff_deg = 30
beam_deg = 20

[[camera]]
name = "main"
eye = [0, -500, 170]
target = [0, 0, 170]
fov_deg = 60
"#;

fn parse(text: &str) -> Result<SceneDesc, SceneError> {
    SceneDesc::from_toml(text, Path::new("level.toml"))
}

fn err(text: &str) -> String {
    match parse(text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn full_description_parses_with_every_field() {
    let d = parse(FULL).expect("parses");
    assert_eq!(d.up, UpAxis::Z);
    assert_eq!(d.metres_per_unit, 0.01);
    assert!(d.closed);
    assert_eq!(d.meshes.len(), 1);
    assert!(!d.meshes[0].is_static);
    assert_eq!(d.lights.len(), 2);
    assert!(matches!(d.lights[1], LightDesc::Spot(_)));
    assert_eq!(d.cameras[0].name, "main");
    // The TOML we write reads back the same.
    let again = parse(&d.to_toml()).expect("round trip");
    assert_eq!(again, d);
}

#[test]
fn unknown_keys_are_errors_naming_the_key_and_the_file() {
    for (text, key) in [
        ("colour = 1\n", "colour"),
        ("[[mesh]]\npath = \"a.obj\"\nstatik = true\n", "statik"),
        (
            "[[light]]\ntype = \"point\"\nposition = [0,0,0]\nintensity = [1,1,1]\nradius = 2\n",
            "radius",
        ),
        (
            "[[light]]\ntype = \"spot\"\nposition = [0,0,0]\ndirection = [0,-1,0]\nintensity = [1,1,1]\ncutoff_deg = 20\nbeam_deg = 10\nangle = 3\n",
            "angle",
        ),
        (
            "[[camera]]\nname = \"a\"\neye = [0,0,0]\ntarget = [1,0,0]\nfov_deg = 60\nfovy = 3\n",
            "fovy",
        ),
        (
            "[[material]]\nname = \"a\"\nalbedo = [0,0,0]\nroughness = 1\n",
            "roughness",
        ),
    ] {
        let e = err(text);
        assert!(e.contains(key), "error does not name '{key}': {e}");
        assert!(
            e.contains("level.toml"),
            "error does not name the file: {e}"
        );
    }
}

#[test]
fn values_outside_their_limits_are_errors_not_clamped() {
    let cases = [
        ("metres_per_unit = 0\n", "metres_per_unit"),
        ("metres_per_unit = -1\n", "metres_per_unit"),
        ("metres_per_unit = nan\n", "metres_per_unit"),
        ("[[mesh]]\npath = \"a.obj\"\nscale = 0\n", "zero scale"),
        (
            "[[material]]\nname = \"a\"\nalbedo = [1.5, 0, 0]\n",
            "albedo",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0,0,0]\nintensity = [-1,1,1]\n",
            "intensity",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0,inf,0]\nintensity = [1,1,1]\n",
            "position",
        ),
        (
            "[[light]]\ntype = \"spot\"\nposition = [0,0,0]\ndirection = [0,-1,0]\nintensity = [1,1,1]\ncutoff_deg = 20\nbeam_deg = 30\n",
            "beam_deg",
        ),
        (
            "[[light]]\ntype = \"spot\"\nposition = [0,0,0]\ndirection = [0,-1,0]\nintensity = [1,1,1]\ncutoff_deg = 95\nbeam_deg = 30\n",
            "cutoff_deg",
        ),
        (
            "[[light]]\ntype = \"spot\"\nposition = [0,0,0]\nintensity = [1,1,1]\ncutoff_deg = 20\nbeam_deg = 10\n",
            "target or a direction",
        ),
        (
            "[[light]]\ntype = \"spot\"\nposition = [0,0,0]\ntarget = [0,0,0]\nintensity = [1,1,1]\ncutoff_deg = 20\nbeam_deg = 10\n",
            "target",
        ),
        ("[[light]]\ntype = \"area\"\nposition = [0,0,0]\n", "area"),
        (
            "[[camera]]\nname = \"a\"\neye = [0,0,0]\ntarget = [1,0,0]\nfov_deg = 180\n",
            "fov_deg",
        ),
        (
            "[[camera]]\nname = \"a\"\neye = [0,0,0]\ntarget = [0,0,0]\nfov_deg = 60\n",
            "eye and target",
        ),
        (
            "[[camera]]\nname = \"a\"\neye = [0,0,0]\ntarget = [1,0,0]\nfov_deg = 60\n[[camera]]\nname = \"a\"\neye = [0,0,0]\ntarget = [1,0,0]\nfov_deg = 60\n",
            "two cameras",
        ),
    ];
    for (text, what) in cases {
        let e = err(text);
        assert!(
            e.contains(what),
            "error for {text:?} does not mention '{what}': {e}"
        );
    }
}

fn write_obj(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).expect("write obj");
}

const TRI_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn z_up_centimetre_scene_is_converted_once_to_y_up_metres() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_obj(
        dir.path(),
        "rooms.obj",
        "v 0 0 0\nv 100 0 0\nv 0 100 0\nv 0 0 100\nf 1 2 3\nf 1 2 4\n",
    );
    let text = FULL
        .replace("static = false\n", "")
        .replace(
            "translate = [1, 2, 3]\nrotate_deg = [0, 0, 90]\nscale = [1, 2, 1]\n",
            "",
        )
        .replace(
            "[[material]]\nname = \"floor\"\nalbedo = [0.5, 0.4, 0.3]\n",
            "",
        );
    let path = dir.path().join("level.toml");
    std::fs::write(&path, text).expect("write toml");
    let scene = Scene::load(&path, &Default::default()).expect("loads");
    let (lo, hi) = scene.bounds().expect("bounds");
    // z-up (x, y, z) → y-up (x, z, −y), cm → m.
    assert!(
        (hi.x - 1.0).abs() < 1e-6 && (hi.y - 1.0).abs() < 1e-6,
        "{lo} {hi}"
    );
    assert!((lo.z + 1.0).abs() < 1e-6 && hi.z.abs() < 1e-6, "{lo} {hi}");
    match scene.lights[0] {
        Light::Point {
            position,
            intensity,
        } => {
            assert!(
                (position - glam::Vec3::new(1.0, 3.0, -2.0)).length() < 1e-5,
                "{position}"
            );
            assert_eq!(intensity, glam::Vec3::new(1.0, 2.0, 3.0));
        }
        _ => panic!("expected a point light"),
    }
    match scene.lights[1] {
        Light::Spot {
            direction,
            cutoff_rad,
            ..
        } => {
            assert!(
                (direction - glam::Vec3::NEG_Y).length() < 1e-6,
                "{direction}"
            );
            assert!((cutoff_rad - 30f32.to_radians()).abs() < 1e-6);
        }
        _ => panic!("expected a spot light"),
    }
    let cam = &scene.cameras[0];
    assert!(
        (cam.up - glam::Vec3::Y).length() < 1e-6,
        "default up follows the scene's up axis"
    );
    assert!(
        (cam.eye - glam::Vec3::new(0.0, 1.7, 5.0)).length() < 1e-5,
        "{}",
        cam.eye
    );
}

#[test]
fn a_sun_in_a_scene_file_is_placed_as_a_far_spot_in_metres_and_world_axes() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A 100 × 100 × 100 cm corner, z up; a sun shining down (−z) at 2 W/m², and a moved mesh.
    write_obj(
        dir.path(),
        "rooms.obj",
        "v 0 0 0\nv 100 0 0\nv 0 100 0\nv 0 0 100\nf 1 2 3\nf 1 2 4\n",
    );
    let toml = "up = \"z\"\nmetres_per_unit = 0.01\n[[mesh]]\npath = \"rooms.obj\"\n\
                translate = [100, 0, 0]\n[[sun]]\ndirection = [0, 0, -3]\nirradiance = [2, 2, 2]\n";
    let path = dir.path().join("sun.toml");
    std::fs::write(&path, toml).expect("write toml");
    let scene = Scene::load(&path, &Default::default()).expect("loads");
    let (lo, hi) = scene.static_bounds().expect("bounds");
    let centre = 0.5 * (lo + hi);
    let Light::Spot {
        position,
        direction,
        intensity,
        ..
    } = scene.lights[0]
    else {
        panic!("{:?}", scene.lights)
    };
    // Down is −y in the world; the spot 9.5 diagonals above the moved mesh's centre.
    assert!(
        (direction - glam::Vec3::NEG_Y).length() < 1e-6,
        "{direction}"
    );
    let up = position - centre;
    assert!(
        (up.normalize() - glam::Vec3::Y).length() < 1e-5
            && (up.length() - 9.5 * (hi - lo).length()).abs() < 1e-4,
        "{position} over {centre}"
    );
    assert!((centre.x - 1.5).abs() < 1e-5, "{centre}");
    let e = intensity / up.length_squared();
    assert!(
        (e - glam::Vec3::splat(2.0)).abs().max_element() < 1e-5,
        "{e}"
    );
    let said = scene.report.warnings.join("\n");
    assert!(said.contains("sun 'sun 1' (irradiance 2.000"), "{said}");
    // A sun with no direction, or an unknown key, is refused by name.
    for (bad, what) in [
        (
            "[[sun]]\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n",
            "sun 1",
        ),
        (
            "[[sun]]\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\nlux = 3\n",
            "lux",
        ),
    ] {
        let e = err(&format!("[[mesh]]\npath = \"a.obj\"\n{bad}"));
        assert!(e.contains(what), "{bad:?}: {e}");
    }
}

#[test]
fn mesh_transform_applies_scale_then_rotation_then_translation() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_obj(dir.path(), "t.obj", TRI_OBJ);
    let toml = "[[mesh]]\npath = \"t.obj\"\ntranslate = [10, 0, 0]\nrotate_deg = [0, 0, 90]\nscale = [2, 1, 1]\n";
    let path = dir.path().join("s.toml");
    std::fs::write(&path, toml).expect("write");
    let scene = Scene::load(&path, &Default::default()).expect("loads");
    let m = &scene.meshes[0];
    // (1,0,0) → scale (2,0,0) → rotate 90° about Z (0,2,0) → translate (10,2,0).
    let has = |p: glam::Vec3| m.positions.iter().any(|q| (*q - p).length() < 1e-5);
    assert!(has(glam::Vec3::new(10.0, 2.0, 0.0)), "{:?}", m.positions);
    assert!(has(glam::Vec3::new(9.0, 0.0, 0.0)), "{:?}", m.positions);
}

#[test]
fn material_override_replaces_albedo_and_unknown_names_are_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_obj(
        dir.path(),
        "t.obj",
        "mtllib t.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    std::fs::write(dir.path().join("t.mtl"), "newmtl red\nKd 1 0 0\n").expect("write mtl");
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        "[[mesh]]\npath = \"t.obj\"\n[[material]]\nname = \"red\"\nalbedo = [0.2, 0.3, 0.4]\n",
    )
    .expect("write");
    let scene = Scene::load(&path, &Default::default()).expect("loads");
    assert_eq!(scene.materials[0].albedo, glam::Vec3::new(0.2, 0.3, 0.4));
    std::fs::write(
        &path,
        "[[mesh]]\npath = \"t.obj\"\n[[material]]\nname = \"blue\"\nalbedo = [0.2, 0.3, 0.4]\n",
    )
    .expect("write");
    let e = Scene::load(&path, &Default::default())
        .expect_err("unknown material")
        .to_string();
    assert!(e.contains("blue") && e.contains("red"), "{e}");
}

#[test]
fn a_scene_with_no_meshes_is_an_empty_scene_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("s.toml");
    std::fs::write(&path, "closed = true\n").expect("write");
    let e = Scene::load(&path, &Default::default()).expect_err("empty");
    assert!(matches!(e, SceneError::Empty { .. }), "{e}");
}

#[test]
fn dynamic_meshes_and_lights_follow_their_keys_and_orbits() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_obj(dir.path(), "t.obj", TRI_OBJ);
    let toml = r#"
[[mesh]]
path = "t.obj"

[[mesh]]
path = "t.obj"
static = false
animate = [{ t = 1, translate = [0, 0, 0] }, { t = 3, translate = [4, 0, 0], rotate_deg = [0, 0, 90] }]

[[light]]
type = "point"
position = [0, 2, 0]
intensity = [1, 1, 1]
orbit = { centre = [0, 2, 0], radius = 2, period_s = 4 }

[[light]]
type = "spot"
position = [0, 3, 0]
target = [0, 0, 0]
intensity = [1, 1, 1]
cutoff_deg = 30
beam_deg = 20
animate = [{ t = 0, position = [0, 3, 0] }, { t = 2, position = [2, 3, 0], target = [2, 0, 0] }]
"#;
    let path = dir.path().join("s.toml");
    std::fs::write(&path, toml).expect("write");
    let scene = Scene::load(&path, &Default::default()).expect("loads");
    assert!(scene.is_animated());
    let near = |a: glam::Vec3, b: glam::Vec3| (a - b).length() < 1e-5;
    // Before the first key the mesh holds it; halfway it has moved 2 m and turned 45°.
    let at0 = scene.at(0.0);
    assert_eq!(at0.meshes[1].positions, scene.meshes[1].positions);
    let at2 = scene.at(2.0);
    let p = at2.meshes[1].positions[1]; // (1, 0, 0) at rest
    let r = 45f32.to_radians();
    assert!(near(p, glam::Vec3::new(2.0 + r.cos(), r.sin(), 0.0)), "{p}");
    // After the last key it holds that: (1,0,0) turned 90° and moved 4 m.
    assert!(near(
        scene.at(9.0).meshes[1].positions[1],
        glam::Vec3::new(4.0, 1.0, 0.0)
    ));
    // Static meshes never move, so the hash of the static geometry stays.
    assert_eq!(at2.meshes[0].positions, scene.meshes[0].positions);
    assert_eq!(at2.static_geometry_hash(), scene.static_geometry_hash());
    // The orbit: a quarter period turns the light 90° about +Y.
    let pos = |s: &Scene, i: usize| match s.lights[i] {
        Light::Point { position, .. } | Light::Spot { position, .. } => position,
    };
    assert!(near(pos(&scene.at(0.0), 0), glam::Vec3::new(2.0, 2.0, 0.0)));
    assert!(near(pos(&scene.at(1.0), 0), glam::Vec3::new(0.0, 2.0, 2.0)));
    // The keyed spot moves and re-aims at its (interpolated) target.
    let s1 = scene.at(1.0);
    assert!(near(pos(&s1, 1), glam::Vec3::new(1.0, 3.0, 0.0)));
    if let Light::Spot { direction, .. } = s1.lights[1] {
        assert!(near(direction, glam::Vec3::NEG_Y), "{direction}");
    }
}

#[test]
fn bad_animations_are_errors_naming_what_to_fix() {
    let base = "[[mesh]]\npath = \"m.obj\"\n";
    let e = err(&format!(
        "{base}animate = [{{ t = 0, translate = [1, 0, 0] }}]\n"
    ));
    assert!(e.contains("static = false"), "{e}");
    let e = err(&format!(
        "{base}static = false\nanimate = [{{ t = 1 }}, {{ t = 1 }}]\n"
    ));
    assert!(e.contains("increase"), "{e}");
    let e = err(&format!(
        "{base}static = false\norbit = {{ centre = [0, 0, 0], radius = 1, period_s = 0 }}\n"
    ));
    assert!(e.contains("period_s > 0"), "{e}");
    let e = err(&format!(
        "{base}static = false\norbit = {{ centre = [0, 0, 0], radius = 1, period_s = 2 }}\nanimate = [{{ t = 0 }}]\n"
    ));
    assert!(e.contains("not both"), "{e}");
    let e = err(
        "[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\nanimate = [{ t = 0, position = [0, 0, 0] }, { t = nan, position = [0, 0, 0] }]\n",
    );
    assert!(e.contains("key 2"), "{e}");
}

#[test]
fn a_light_line_makes_evenly_spaced_point_lights() {
    let text = r#"
[[light]]
type = "point"
position = [0, 3, 0]
intensity = [5, 5, 5]

[[light_line]]
from = [0, 2, 0]
to = [8, 2, 4]
count = 5
intensity = [1, 0.5, 0.25]
"#;
    let desc = SceneDesc::from_toml(text, Path::new("lines.toml")).expect("parse");
    assert!(desc.light_lines.is_empty(), "made into lights when read");
    assert_eq!(desc.lights.len(), 6);
    let at: Vec<[f64; 3]> = desc.lights[1..]
        .iter()
        .map(|l| match l {
            LightDesc::Point(p) => {
                assert_eq!(p.intensity, [1.0, 0.5, 0.25]);
                p.position
            }
            LightDesc::Spot(_) => panic!("a line makes point lights"),
        })
        .collect();
    assert_eq!(
        at,
        [
            [0.0, 2.0, 0.0],
            [2.0, 2.0, 1.0],
            [4.0, 2.0, 2.0],
            [6.0, 2.0, 3.0],
            [8.0, 2.0, 4.0]
        ]
    );
    // One light sits at `from`; none, or a negative intensity, is refused with the line named.
    let one = text.replace("count = 5", "count = 1");
    let desc = SceneDesc::from_toml(&one, Path::new("lines.toml")).expect("parse");
    assert_eq!(desc.lights.len(), 2);
    let none = text.replace("count = 5", "count = 0");
    let e = SceneDesc::from_toml(&none, Path::new("lines.toml")).expect_err("refused");
    assert!(e.to_string().contains("light_line 1: count = 0"), "{e}");
    let dark = text.replace("[1, 0.5, 0.25]", "[1, -0.5, 0.25]");
    let e = SceneDesc::from_toml(&dark, Path::new("lines.toml")).expect_err("refused");
    assert!(e.to_string().contains("light_line 1: intensity"), "{e}");
}

//! A bare glTF file brings the lights (`KHR_lights_punctual`) and cameras its nodes place,
//! converted to visgate's units; what visgate cannot use is skipped with a warning.

use std::path::{Path, PathBuf};

use glam::Vec3;
use visgate_formats::import::ImportOptions;
use visgate_formats::{Light, Scene};

/// A glTF of one triangle (an external buffer) with `nodes`, `extra` top-level members (lights,
/// cameras) and the root nodes `roots`.
fn gltf(dir: &Path, nodes: &str, extra: &str, roots: &str) -> PathBuf {
    let mut bin = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 3.0, 0.0] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    std::fs::write(dir.join("t.bin"), &bin).expect("bin");
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{roots}}}],
        "nodes":[{{"mesh":0,"name":"wall"}},{nodes}],
        "meshes":[{{"name":"wall","primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "buffers":[{{"uri":"t.bin","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[4,3,0]}}]
        {extra}}}"#
    );
    let p = dir.join("t.gltf");
    std::fs::write(&p, json).expect("gltf");
    p
}

/// A spot light's position, direction, intensity, cutoff and beam (panics on a point light).
fn spot(light: &Light) -> (Vec3, Vec3, Vec3, f32, f32) {
    match *light {
        Light::Spot {
            position,
            direction,
            intensity,
            cutoff_rad,
            beam_rad,
        } => (position, direction, intensity, cutoff_rad, beam_rad),
        Light::Point { .. } => panic!("not a spot: {light:?}"),
    }
}

const LIGHTS: &str = r#","extensionsUsed":["KHR_lights_punctual"],
    "extensions":{"KHR_lights_punctual":{"lights":[
      {"name":"lamp","type":"point","color":[1.0,0.5,0.25],"intensity":683.0},
      {"name":"spot","type":"spot","intensity":1366.0,"spot":{"innerConeAngle":0.0,"outerConeAngle":0.5}},
      {"name":"sun","type":"directional","intensity":3.0}]}}"#;

#[test]
fn lights_are_placed_by_their_nodes_and_read_in_watts_per_steradian() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A parent node moved 2 m up holds the lamp 1 m along x; the spot turned 90° about x (its
    // −Z onto −Y: it points down); the sun's node at the root.
    let nodes = r#"{"name":"rig","translation":[0,2,0],"children":[2]},
        {"name":"lamp node","translation":[1,0,0],"extensions":{"KHR_lights_punctual":{"light":0}}},
        {"translation":[1,2,1],"rotation":[-0.70710677,0,0,0.70710677],
         "extensions":{"KHR_lights_punctual":{"light":1}}},
        {"extensions":{"KHR_lights_punctual":{"light":2}}}"#;
    let p = gltf(dir.path(), nodes, LIGHTS, "[0,1,3,4]");
    let scene = Scene::load(&p, &ImportOptions::default()).expect("loads");
    assert_eq!(scene.lights.len(), 3, "{:?}", scene.lights);
    let Light::Point {
        position,
        intensity,
    } = scene.lights[0]
    else {
        panic!("{:?}", scene.lights[0])
    };
    assert!(
        (position - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-6,
        "{position}"
    );
    // 683 cd of colour (1, 0.5, 0.25): 1 W/sr in red.
    assert!(
        (intensity - Vec3::new(1.0, 0.5, 0.25)).length() < 1e-6,
        "{intensity}"
    );
    let (position, direction, intensity, cutoff_rad, beam_rad) = spot(&scene.lights[1]);
    assert!(
        (position - Vec3::new(1.0, 2.0, 1.0)).length() < 1e-6,
        "{position}"
    );
    assert!((direction - Vec3::NEG_Y).length() < 1e-5, "{direction}");
    assert!(
        (intensity - Vec3::splat(2.0)).length() < 1e-6,
        "{intensity}"
    );
    assert!((cutoff_rad - 0.5).abs() < 1e-6, "{cutoff_rad}");
    assert!(beam_rad > 0.0 && beam_rad < 1e-3, "{beam_rad}");
    // The sun, unrotated (its light along −Z), as a spot 9.5 diagonals of the wall's box (0,
    // 0, 0)–(4, 3, 0) from its centre, back along its light: 47.5 m; 3 lux of white light is
    // 3 / 683 W/m² there, so 3 / 683 · 47.5² W/sr; its full beam covers the box.
    let (position, direction, intensity, cutoff_rad, beam_rad) = spot(&scene.lights[2]);
    assert!(
        (position - Vec3::new(2.0, 1.5, 47.5)).length() < 1e-4,
        "{position}"
    );
    assert!((direction - Vec3::NEG_Z).length() < 1e-6, "{direction}");
    let irradiance = intensity / (position - Vec3::new(2.0, 1.5, 0.0)).length_squared();
    assert!(
        (irradiance - Vec3::splat(3.0 / 683.0)).abs().max_element() < 1e-7,
        "{irradiance}"
    );
    assert!(
        beam_rad >= (2.5f32 / 47.5).asin() && cutoff_rad > beam_rad,
        "{beam_rad}"
    );
    let said = scene.report.warnings.join("\n");
    assert!(
        said.contains("sun 'sun' (irradiance 0.004 0.004 0.004 W/m²) placed as a spot light at (2.0, 1.5, 47.5) m"),
        "{said}"
    );
    // No other light of the file is named as misplaced (the suns are placed after that check;
    // their distance is held under it in sun.rs's unit test).
    assert!(!said.contains("outside"), "{said}");
}

#[test]
fn a_sun_is_placed_for_its_irradiance_in_metres_whatever_the_file_s_units() {
    let dir = tempfile::tempdir().expect("tempdir");
    let nodes = r#"{"rotation":[-0.70710677,0,0,0.70710677],
        "extensions":{"KHR_lights_punctual":{"light":2}}}"#;
    let p = gltf(dir.path(), nodes, LIGHTS, "[0,1]");
    // Read in centimetres, the wall is 5 cm across: the sun, now pointing down, 47.5 cm above
    // its centre, gives the same 3 / 683 W/m² there.
    let options = ImportOptions {
        bare: visgate_formats::load::BareMesh {
            metres_per_unit: Some(0.01),
            ..Default::default()
        },
        ..ImportOptions::default()
    };
    let scene = Scene::load(&p, &options).expect("loads");
    let (position, direction, intensity, _, _) = spot(&scene.lights[0]);
    let centre = Vec3::new(0.02, 0.015, 0.0);
    assert!((direction - Vec3::NEG_Y).length() < 1e-5, "{direction}");
    assert!(
        (position - (centre + Vec3::Y * 0.475)).length() < 1e-5,
        "{position}"
    );
    let irradiance = intensity / (position - centre).length_squared();
    assert!(
        (irradiance - Vec3::splat(3.0 / 683.0)).abs().max_element() < 1e-7,
        "{irradiance}"
    );
}

#[test]
fn perspective_cameras_are_read_with_a_horizontal_field_of_view() {
    let dir = tempfile::tempdir().expect("tempdir");
    // One camera 1.6 m up at z = 5 looking along −z; a second of the same name turned 90°
    // about y (looking along −x); an orthographic one.
    let nodes = r#"{"camera":0,"translation":[1,1.6,5]},
        {"camera":1,"translation":[3,1.6,2],"rotation":[0,0.70710677,0,0.70710677]},
        {"name":"plan","camera":2}"#;
    let cameras = r#","cameras":[
        {"name":"hall","type":"perspective","perspective":{"yfov":0.9,"aspectRatio":2.0,"znear":0.1}},
        {"name":"hall","type":"perspective","perspective":{"yfov":0.9,"znear":0.1}},
        {"type":"orthographic","orthographic":{"xmag":1,"ymag":1,"znear":0.1,"zfar":10}}]"#;
    let p = gltf(dir.path(), nodes, cameras, "[0,1,2,3]");
    let scene = Scene::load(&p, &ImportOptions::default()).expect("loads");
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["hall", "hall 2"]);
    let (a, b) = (&scene.cameras[0], &scene.cameras[1]);
    assert!((a.eye - Vec3::new(1.0, 1.6, 5.0)).length() < 1e-6);
    assert!(((a.target - a.eye).normalize() - Vec3::NEG_Z).length() < 1e-6);
    assert!((a.up - Vec3::Y).length() < 1e-6);
    let fov = |aspect: f32| 2.0 * ((0.45f32).tan() * aspect).atan();
    assert!((a.fov_x_rad - fov(2.0)).abs() < 1e-5, "{}", a.fov_x_rad);
    // No aspect ratio: 16:9.
    assert!(
        (b.fov_x_rad - fov(16.0 / 9.0)).abs() < 1e-5,
        "{}",
        b.fov_x_rad
    );
    assert!(((b.target - b.eye).normalize() - Vec3::NEG_X).length() < 1e-5);
    let said = scene.report.warnings.join("\n");
    assert!(
        said.contains("orthographic camera 'plan' skipped"),
        "{said}"
    );
}

#[test]
fn a_scene_toml_says_when_it_leaves_its_gltfs_lights_and_cameras_unread() {
    let dir = tempfile::tempdir().expect("tempdir");
    let nodes = r#"{"extensions":{"KHR_lights_punctual":{"light":0}}},{"camera":0}"#;
    let extra = format!(
        r#"{LIGHTS},"cameras":[{{"type":"perspective","perspective":{{"yfov":0.9,"znear":0.1}}}}]"#
    );
    gltf(dir.path(), nodes, &extra, "[0,1,2]");
    let toml = dir.path().join("level.toml");
    std::fs::write(&toml, "[[mesh]]\npath = \"t.gltf\"\n").expect("toml");
    let scene = Scene::load(&toml, &ImportOptions::default()).expect("loads");
    assert!(scene.lights.is_empty() && scene.cameras.is_empty());
    let said = scene.report.warnings.join("\n");
    assert!(
        said.contains("place 1 light(s), which a scene TOML does not read"),
        "{said}"
    );
    assert!(said.contains("place 1 camera(s)"), "{said}");
    // With lights and a camera of its own, the TOML is not told about the file's.
    std::fs::write(
        &toml,
        "[[mesh]]\npath = \"t.gltf\"\n[[light]]\ntype = \"point\"\nposition = [1, 1, 1]\n\
         intensity = [1, 1, 1]\n[[camera]]\nname = \"c\"\neye = [1, 1, 3]\ntarget = [1, 1, 0]\n\
         fov_deg = 60\n",
    )
    .expect("toml");
    let scene = Scene::load(&toml, &ImportOptions::default()).expect("loads");
    let said = scene.report.warnings.join("\n");
    assert!(!said.contains("does not read"), "{said}");
}

#[test]
fn glowing_materials_in_a_scene_without_lights_are_told_to_need_a_light() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(
        d.join("lamp.mtl"),
        "newmtl bulb\nKd 1 1 1\nKe 10 10 8\nnewmtl wall\nKd 0.5 0.5 0.5\nKe 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        d.join("lamp.obj"),
        "mtllib lamp.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl bulb\nf 1 2 3\n\
         usemtl wall\nf 1 2 4\n",
    )
    .expect("obj");
    let said = |p: &Path| {
        Scene::load(p, &ImportOptions::default())
            .expect("loads")
            .report
            .warnings
            .join("\n")
    };
    let obj = said(&d.join("lamp.obj"));
    assert!(obj.contains("material 'bulb' glows"), "{obj}");
    assert!(!obj.contains("'wall'"), "{obj}");
    // A glTF's emissive factor glows too; with a light of its own, nothing is said.
    let nodes = r#"{"extensions":{"KHR_lights_punctual":{"light":0}}}"#;
    let glow = r#","materials":[{"name":"panel","emissiveFactor":[1,1,1]}]"#;
    let p = gltf(d, r#"{"name":"empty"}"#, glow, "[0]");
    assert!(said(&p).contains("material 'panel' glows"), "{}", said(&p));
    let p = gltf(d, nodes, &format!("{LIGHTS}{glow}"), "[0,1]");
    assert!(!said(&p).contains("glows"), "{}", said(&p));
}

#[test]
fn a_scene_toml_leaves_a_gltf_object_out_by_its_node_name() {
    // The wall's triangle placed twice: as the node "wall" and, 500 m off, as "SkyDome" (the
    // object's name in Blender; its mesh is still "wall").
    let dir = tempfile::tempdir().expect("tempdir");
    let nodes = r#"{"mesh":0,"name":"SkyDome","translation":[500,0,0]}"#;
    gltf(dir.path(), nodes, "", "[0,1]");
    let toml = |leave_out: &str| {
        let path = dir.path().join("s.toml");
        let text = format!("[[mesh]]\npath = \"t.gltf\"\nleave_out = [{leave_out}]\n");
        std::fs::write(&path, text).expect("toml");
        Scene::load(&path, &ImportOptions::default())
    };
    assert_eq!(toml("").expect("load").static_triangles().count(), 2);
    let left = toml("\"SkyDome\"").expect("load");
    let tris: Vec<[Vec3; 3]> = left.static_triangles().collect();
    assert_eq!(tris.len(), 1);
    assert!(tris[0].iter().all(|p| p.x <= 4.0), "{tris:?}");
    let e = toml("\"Sphere\"").expect_err("no such object").to_string();
    assert!(
        e.contains("its objects are") && e.contains("'SkyDome'"),
        "{e}"
    );
}

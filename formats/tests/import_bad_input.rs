//! Every bad mesh input gives a clear typed error or a counted warning, never a panic.

use std::path::{Path, PathBuf};

use visgate_formats::import::{ImportOptions, import_file, import_obj};
use visgate_formats::{Scene, SceneError};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write");
    p
}

fn load(path: &Path) -> Result<Scene, SceneError> {
    Scene::load(path, &ImportOptions::default())
}

#[test]
fn missing_files_are_io_errors_naming_the_file() {
    for name in ["nope.obj", "nope.glb", "nope.toml"] {
        let e = load(Path::new(name)).expect_err("missing");
        assert!(matches!(e, SceneError::Io { .. }), "{e}");
        assert!(e.to_string().contains(name), "{e}");
    }
    // A scene whose mesh is missing names the mesh file.
    let dir = tempfile::tempdir().expect("tempdir");
    let toml = write(dir.path(), "s.toml", b"[[mesh]]\npath = \"gone.obj\"\n");
    let e = load(&toml).expect_err("missing mesh").to_string();
    assert!(e.contains("gone.obj"), "{e}");
    // The OS's words once, as `error: {e:#}` prints the chain: the error is its own last link.
    let e = load(&toml).expect_err("missing mesh");
    assert!(std::error::Error::source(&e).is_none(), "{e}");
    // A folder named like a mesh is said to be one.
    std::fs::create_dir(dir.path().join("room.obj")).expect("mkdir");
    let folder = write(dir.path(), "f.toml", b"[[mesh]]\npath = \"room.obj\"\n");
    let e = load(&folder).expect_err("a folder").to_string();
    assert!(
        e.contains("room.obj: cannot read: a folder, not a mesh file"),
        "{e}"
    );
}

#[test]
fn unknown_extension_is_an_error_listing_what_is_read() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = write(dir.path(), "mesh.fbx", b"binary");
    let e = load(&p).expect_err("unknown type").to_string();
    assert!(e.contains(".obj") && e.contains(".glb"), "{e}");
    // The formats levels come in are told how to become one visgate reads.
    assert!(
        e.contains("Convert it to glTF") && e.contains("FBX2glTF"),
        "{e}"
    );
    for (name, hint) in [
        ("level.BLEND", "File > Export > glTF 2.0"),
        ("level.dae", "Import it into Blender"),
        ("e1m1.bsp", "BSP-to-OBJ"),
    ] {
        let e = load(&write(dir.path(), name, b"x"))
            .expect_err(name)
            .to_string();
        assert!(e.contains(hint), "{name}: {e}");
    }
    let e = load(&write(dir.path(), "notes.txt", b"x"))
        .expect_err("txt")
        .to_string();
    assert!(e.ends_with("(.obj, .gltf, .glb)"), "{e}");
}

#[test]
fn broken_obj_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (i, text) in [
        "v 0 0 zero\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn a b c\nf 1 2 3\n",
    ]
    .iter()
    .enumerate()
    {
        let p = write(dir.path(), &format!("b{i}.obj"), text.as_bytes());
        let e = load(&p).expect_err("broken obj");
        assert!(matches!(e, SceneError::Obj { .. }), "{text:?}: {e}");
        assert!(e.to_string().contains(&format!("b{i}.obj")), "{e}");
    }
}

#[test]
fn obj_index_out_of_range_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = write(
        dir.path(),
        "oob.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
    );
    let e = load(&p).expect_err("out of range").to_string();
    assert!(e.contains("out of"), "{e}");
}

#[test]
fn nan_or_inf_coordinates_are_errors_naming_the_mesh() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (i, bad) in ["nan", "inf", "-inf", "NaN"].iter().enumerate() {
        let text = format!("o pillar_{i}\nv 0 0 0\nv 1 {bad} 0\nv 0 1 0\nf 1 2 3\n");
        let p = write(dir.path(), &format!("n{i}.obj"), text.as_bytes());
        let e = load(&p).expect_err("non-finite");
        assert!(matches!(e, SceneError::NonFinite { .. }), "{bad}: {e}");
        assert!(e.to_string().contains(&format!("pillar_{i}")), "{e}");
    }
}

#[test]
fn degenerate_triangles_are_dropped_and_counted_in_a_warning() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n\
                f 1 2 3\n\
                f 1 1 2\n\
                f 1 2 4\n\
                f 3 3 3\n";
    let p = write(dir.path(), "d.obj", text.as_bytes());
    let scene = load(&p).expect("loads");
    assert_eq!(scene.triangle_count(), 1);
    assert_eq!(scene.report.triangles_read, 4);
    assert_eq!(scene.report.degenerate_dropped, 3);
    assert!(
        scene
            .report
            .warnings
            .iter()
            .any(|w| w.contains("3 degenerate")),
        "{:?}",
        scene.report.warnings
    );
}

#[test]
fn a_texture_that_fails_to_decode_is_a_warning_and_falls_back_to_the_albedo() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), "bad.png", b"\x89PNG but not really");
    write(
        dir.path(),
        "t.mtl",
        b"newmtl m\nKd 0.3 0.6 0.9\nmap_Kd bad.png\n\nnewmtl n\nKd 1 1 1\nmap_Kd missing.png\n",
    );
    let p = write(
        dir.path(),
        "t.obj",
        b"mtllib t.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl n\nf 1 3 2\n",
    );
    let scene = load(&p).expect("loads despite bad textures");
    assert_eq!(scene.report.textures_failed, 2);
    let m = scene
        .materials
        .iter()
        .find(|m| m.name == "m")
        .expect("material m");
    assert_eq!(m.texture, None);
    assert_eq!(m.albedo, glam::Vec3::new(0.3, 0.6, 0.9));
    assert!(scene.report.warnings.iter().any(|w| w.contains("bad.png")));
    assert!(
        scene
            .report
            .warnings
            .iter()
            .any(|w| w.contains("missing.png"))
    );
}

#[test]
fn a_good_texture_is_decoded() {
    let dir = tempfile::tempdir().expect("tempdir");
    let img = image::RgbaImage::from_pixel(4, 2, image::Rgba([10, 20, 30, 255]));
    img.save(dir.path().join("ok.png")).expect("save png");
    write(dir.path(), "t.mtl", b"newmtl m\nKd 1 1 1\nmap_Kd ok.png\n");
    let p = write(dir.path(), "t.obj", b"mtllib t.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    let scene = load(&p).expect("loads");
    assert_eq!(scene.textures.len(), 1);
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (4, 2));
    assert_eq!(&scene.textures[0].rgba8[..4], &[10, 20, 30, 255]);
    assert_eq!(scene.materials[0].texture, Some(0));
}

#[test]
fn a_texture_larger_than_the_gpu_draws_is_filtered_down_at_load() {
    // A 2048 × 1024 texture, its left half black and white stripes a texel wide, its right
    // half white: 1024 × 512 after the load, as the GPU's texture array draws it, the stripes
    // averaged to grey (filtered, not sampled) and the white kept.
    let dir = tempfile::tempdir().expect("tempdir");
    let img = image::RgbaImage::from_fn(2048, 1024, |x, _| {
        let v = if x < 1024 && x % 2 == 0 { 0 } else { 255 };
        image::Rgba([v, v, v, 255])
    });
    img.save(dir.path().join("big.png")).expect("save png");
    write(dir.path(), "t.mtl", b"newmtl m\nKd 1 1 1\nmap_Kd big.png\n");
    let p = write(dir.path(), "t.obj", b"mtllib t.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    let scene = load(&p).expect("loads");
    let t = &scene.textures[0];
    assert_eq!(
        (t.width, t.height, t.rgba8.len()),
        (1024, 512, 1024 * 512 * 4)
    );
    assert_eq!(scene.report.textures_fitted, 1);
    let at = |x: usize| t.rgba8[4 * (100 * 1024 + x)];
    for x in [0, 300, 511] {
        assert!((126..=129).contains(&at(x)), "{x}: {}", at(x));
    }
    assert_eq!((at(512), at(1023)), (255, 255));
}

#[test]
fn a_texture_written_with_options_or_in_quotes_is_found_and_mapped() {
    // Blender's OBJ exporter writes a scaled, moved mapping as `-s` and `-o` before the file;
    // other tools quote a name with spaces. tobj kept the options in the file name, and the
    // texture was "not loaded".
    let dir = tempfile::tempdir().expect("tempdir");
    let img = image::RgbaImage::from_pixel(2, 2, image::Rgba([10, 20, 30, 255]));
    img.save(dir.path().join("floor tiles.png"))
        .expect("save png");
    write(
        dir.path(),
        "t.mtl",
        b"newmtl tiled\nKd 1 1 1\nmap_Kd -o 0.5 0 0 -s 4 2 1 -bm 0.5 floor tiles.png\n\
          newmtl quoted\nKd 1 1 1\nmap_Kd \"floor tiles.png\"\n",
    );
    let p = write(
        dir.path(),
        "t.obj",
        b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
          usemtl tiled\nf 1/1 2/2 3/3\nusemtl quoted\nf 1/1 3/3 2/2\n",
    );
    let scene = load(&p).expect("loads");
    assert_eq!(
        scene.report.textures_failed, 0,
        "{:?}",
        scene.report.warnings
    );
    assert!(scene.materials.iter().all(|m| m.texture == Some(0)));
    // uv × (4, 2) + (0.5, 0), v then flipped: (1, 0) → (4.5, 1), (0, 1) → (0.5, −1).
    let tiled = &scene.meshes[0];
    // The vertex at x = 1, and the other one off the origin (the bare file is read Z up).
    let uv = |m: &visgate_formats::Mesh, x: f32| {
        let i = (m.positions.iter())
            .position(|&q| q.x == x && q.length() > 0.0)
            .expect("vertex");
        m.uvs[i]
    };
    assert_eq!(uv(tiled, 1.0), glam::Vec2::new(4.5, 1.0));
    assert_eq!(uv(tiled, 0.0), glam::Vec2::new(0.5, -1.0));
    // No options: the coordinates as the file has them.
    assert_eq!(uv(&scene.meshes[1], 1.0), glam::Vec2::new(1.0, 1.0));
}

#[test]
fn a_missing_material_library_is_a_warning() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = write(
        dir.path(),
        "t.obj",
        b"mtllib gone.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let scene = load(&p).expect("loads");
    assert!(
        scene
            .report
            .warnings
            .iter()
            .any(|w| w.contains("material library"))
    );
    assert_eq!(scene.triangle_count(), 1);
}

#[test]
fn objects_naming_a_material_their_library_lacks_are_named_in_a_note() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), "m.mtl", b"newmtl known\nKd 0.2 0.4 0.6\n");
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let text = format!(
        "mtllib m.mtl\n{tri}o early\nf 1 2 3\no good\nusemtl known\nf 1 2 3\n\
         o typo\nusemtl knwon\nf 1 2 3\n"
    );
    let scene = load(&write(dir.path(), "t.obj", text.as_bytes())).expect("loads");
    let notes: Vec<_> = (scene.report.warnings.iter())
        .filter(|w| w.contains("no material of its material library"))
        .collect();
    assert_eq!(notes.len(), 1, "{:?}", scene.report.warnings);
    assert!(
        notes[0].contains("2 objects ('early', 'typo')"),
        "{}",
        notes[0]
    );
    assert!(!notes[0].contains("'good'"), "{}", notes[0]);
    assert_eq!(scene.triangle_count(), 3);
    // A bare OBJ, without a library, has nothing to name.
    let bare = load(&write(
        dir.path(),
        "bare.obj",
        format!("{tri}f 1 2 3\n").as_bytes(),
    ));
    let warnings = bare.expect("loads").report.warnings;
    assert!(
        !warnings.iter().any(|w| w.contains("material library")),
        "{warnings:?}"
    );
}

#[test]
fn an_obj_without_triangles_is_an_empty_scene() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (i, text) in [
        "",
        "# nothing\n",
        "v 0 0 0\nv 1 0 0\n",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    ]
    .iter()
    .enumerate()
    {
        let p = write(dir.path(), &format!("e{i}.obj"), text.as_bytes());
        let e = load(&p).expect_err("empty");
        assert!(matches!(e, SceneError::Empty { .. }), "{text:?}: {e}");
    }
}

#[test]
fn face_normals_are_computed_when_the_file_has_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = write(
        dir.path(),
        "n.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 0 -1\nf 1 2 3\n",
    );
    let scene = load(&p).expect("loads");
    for n in &scene.meshes[0].normals {
        assert!((*n - glam::Vec3::Y).length() < 1e-6, "{n}");
    }
}

/// A minimal glTF with an external buffer of 3 positions and the given u16 indices.
fn gltf_with(dir: &Path, name: &str, positions: [[f32; 3]; 3], indices: &[u16]) -> PathBuf {
    let mut bin = Vec::new();
    for p in positions {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let ioff = bin.len();
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    std::fs::write(dir.join(format!("{name}.bin")), &bin).expect("bin");
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"name":"node","translation":[0,5,0]}}],
        "meshes":[{{"name":"wall","primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"uri":"{name}.bin","byteLength":{blen}}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":{ioff},"byteLength":{ilen}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":{icount},"type":"SCALAR"}}]}}"#,
        blen = bin.len(),
        ilen = indices.len() * 2,
        icount = indices.len(),
    );
    write(dir, &format!("{name}.gltf"), json.as_bytes())
}

#[test]
fn gltf_node_transforms_apply_and_normals_are_computed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = gltf_with(
        dir.path(),
        "ok",
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
    );
    let scene = load(&p).expect("loads");
    assert_eq!(scene.triangle_count(), 1);
    let (lo, hi) = scene.bounds().expect("bounds");
    assert_eq!((lo.y, hi.y), (5.0, 6.0));
    assert!((scene.meshes[0].normals[0] - glam::Vec3::Z).length() < 1e-6);
}

#[test]
fn gltf_index_out_of_range_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = gltf_with(
        dir.path(),
        "oob",
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 7],
    );
    let e = load(&p).expect_err("out of range");
    assert!(
        matches!(e, SceneError::IndexOutOfRange { index: 7, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("wall"), "{e}");
}

#[test]
fn gltf_nan_coordinates_are_errors_naming_the_mesh() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = gltf_with(
        dir.path(),
        "nan",
        [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
    );
    let e = load(&p).expect_err("nan");
    assert!(matches!(e, SceneError::NonFinite { .. }), "{e}");
    assert!(e.to_string().contains("wall"), "{e}");
}

#[test]
fn broken_gltf_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, bytes) in [
        ("a.gltf", &b"{ not json"[..]),
        ("b.glb", &b"glTF\x02\x00\x00\x00garbage"[..]),
        ("c.gltf", &br#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":5}}]}]}"#[..]),
    ] {
        let p = write(dir.path(), name, bytes);
        let e = load(&p).expect_err("broken gltf");
        assert!(matches!(e, SceneError::Gltf { .. }), "{name}: {e}");
        assert!(e.to_string().contains(name), "{e}");
    }
    // A buffer file that is missing.
    let p = gltf_with(
        dir.path(),
        "nobuf",
        [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
    );
    std::fs::remove_file(dir.path().join("nobuf.bin")).expect("rm");
    assert!(matches!(load(&p), Err(SceneError::Gltf { .. })));
}

#[test]
fn a_gltf_with_compressed_meshes_names_the_extensions_not_broken() {
    let dir = tempfile::tempdir().expect("tempdir");
    // As gltfpack writes one: meshopt buffers and quantized vertices, both required.
    let json = r#"{"asset":{"version":"2.0"},
        "extensionsUsed":["EXT_meshopt_compression","KHR_mesh_quantization","KHR_lights_punctual"],
        "extensionsRequired":["EXT_meshopt_compression","KHR_mesh_quantization"]}"#;
    let p = write(dir.path(), "packed.gltf", json.as_bytes());
    let e = load(&p).expect_err("compressed");
    let m = e.to_string();
    assert!(matches!(e, SceneError::GltfExtensions { .. }), "{m}");
    // Quantized vertices are read (tests/gltf_quantized.rs): the compression alone is named.
    assert!(
        m.contains("packed.gltf: needs the glTF extension EXT_meshopt_compression, which")
            && m.contains("(meshoptimizer-compressed buffers)")
            && m.contains("Write the file out without it")
            && m.contains("gltfpack without -c")
            && !m.contains("KHR_mesh_quantization")
            && !m.contains("broken"),
        "{m}"
    );
    // Draco, as Blender writes it with compression on.
    let draco = json
        .replace("EXT_meshopt_compression", "KHR_draco_mesh_compression")
        .replace(",\"KHR_mesh_quantization\"]}", "]}");
    let p = write(dir.path(), "draco.gltf", draco.as_bytes());
    let m = load(&p).expect_err("draco").to_string();
    assert!(
        m.contains("extension KHR_draco_mesh_compression, which") && m.contains("Draco"),
        "{m}"
    );
    // An extension required and read (the lights) is no error of this kind.
    let lights = r#"{"asset":{"version":"2.0"},"extensionsRequired":["KHR_lights_punctual"],
        "extensionsUsed":["KHR_lights_punctual"]}"#;
    let p = write(dir.path(), "lights.gltf", lights.as_bytes());
    assert!(!matches!(load(&p), Err(SceneError::GltfExtensions { .. })));
}

#[test]
fn import_file_never_panics_on_random_bytes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut x: u64 = 0x9e3779b97f4a7c15;
    for i in 0..200 {
        let len = (i * 7) % 300;
        let bytes: Vec<u8> = (0..len)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                if i % 2 == 0 {
                    b"vf 0123456789./-\n"[(x % 17) as usize]
                } else {
                    x as u8
                }
            })
            .collect();
        // import_file turns a parser's panic into an error, so the OBJ path (tobj and our own
        // checks) is called directly here: a panic in it fails this test.
        let p = write(dir.path(), &format!("r{i}.obj"), &bytes);
        let _ = import_obj(&p, &ImportOptions::default());
        for ext in ["gltf", "glb"] {
            let p = write(dir.path(), &format!("r{i}.{ext}"), &bytes);
            let _ = import_file(&p, &ImportOptions::default());
        }
    }
}

//! A level exported from another tool as a bare glTF file comes with its lights and cameras:
//! `visgate export gltf` writes a scene that way (as .gltf + .bin, or one .glb), and given bare it reads back as the same
//! scene — the same lights, cameras and image.

mod support;

use std::path::Path;

use support::{stderr, stdout, visgate, visgate_warn};

fn s(p: &Path) -> &str {
    p.to_str().expect("utf8")
}

/// The CPU reference of `scene` from `camera`, as linear RGB.
fn render(scene: &str, camera: &str, out: &Path) -> Vec<f32> {
    let o = visgate(&[
        "render",
        scene,
        "--camera",
        camera,
        "--size",
        "48x36",
        "--vpls",
        "256",
        "-o",
        s(out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    image::open(out).expect("exr").to_rgb32f().into_raw()
}

/// `scene` and `file` (its export) give `camera` the same lit image (relative MSE < 1e-6).
fn same_image(scene: &str, file: &str, camera: &str, dir: &Path) {
    let a = render(scene, camera, &dir.join("a.exr"));
    let b = render(file, camera, &dir.join("b.exr"));
    let mean = a.iter().sum::<f32>() / a.len() as f32;
    let mse = a.iter().zip(&b).map(|(x, y)| (x - y).powi(2)).sum::<f32>() / a.len() as f32;
    assert!(mean > 1e-3, "mean {mean}");
    assert!(
        mse / (mean * mean) < 1e-6,
        "relative MSE {}",
        mse / (mean * mean)
    );
}

#[test]
fn a_scene_exported_as_gltf_reads_back_bare_with_its_lights_and_cameras() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gltf = dir.path().join("level").join("four-rooms.gltf");
    let o = visgate(&["export", "gltf", "builtin:four-rooms", s(&gltf)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("2 lights, 1 cameras"), "{}", stdout(&o));
    assert!(gltf.with_extension("bin").is_file());
    let o = visgate(&["inspect", "--json", s(&gltf)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(
        (&v["point_lights"], &v["spot_lights"]),
        (&1.into(), &1.into()),
        "{v}"
    );
    // The same image from the built-in and from its glTF given bare: the point light and the
    // spot in W/sr through candela, the camera through glTF's vertical field of view.
    same_image("builtin:four-rooms", s(&gltf), "main", dir.path());
}

#[test]
fn a_scene_exported_as_one_glb_file_reads_back_the_same() {
    let dir = tempfile::tempdir().expect("tempdir");
    let glb = dir.path().join("sun-window.glb");
    let o = visgate(&["export", "gltf", "builtin:sun-window", s(&glb)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!glb.with_extension("bin").exists());
    same_image("builtin:sun-window", s(&glb), "window", dir.path());
}

#[test]
fn export_gltf_refuses_an_output_that_is_not_gltf_or_glb() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = visgate_warn(&[
        "export",
        "gltf",
        "builtin:four-rooms",
        s(&dir.path().join("x.fbx")),
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("must end in .gltf") && stderr(&o).contains(".glb"),
        "{}",
        stderr(&o)
    );
}

//! Glass: a material that lets light through is rendered opaque by visgate, so a window's pane
//! would block the light that passes it. Mostly see-through materials are left out of the
//! level and said; partly see-through ones are kept and said.

use std::path::Path;

use visgate_formats::Scene;
use visgate_formats::import::ImportOptions;

fn load(p: &Path) -> Scene {
    Scene::load(p, &ImportOptions::default()).expect("loads")
}

#[test]
fn an_obj_s_glass_is_left_out_and_tinted_glass_kept_both_said() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(
        d.join("room.mtl"),
        "newmtl wall\nKd 0.5 0.5 0.5\nd 1\nnewmtl glass\nKd 0.9 0.9 0.9\nd 0.1\n\
         newmtl tinted\nKd 0.5 0.5 0.5\nTr 0.3\n",
    )
    .expect("mtl");
    std::fs::write(
        d.join("room.obj"),
        "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 0\n\
         usemtl wall\nf 1 2 3\nusemtl glass\nf 1 2 4\nf 2 5 4\nusemtl tinted\nf 1 3 4\n",
    )
    .expect("obj");
    let scene = load(&d.join("room.obj"));
    assert_eq!(scene.triangle_count(), 2, "the wall and the tinted pane");
    let said = scene.report.warnings.join("\n");
    assert!(
        said.contains("material 'glass' is see-through (opacity 0.10)")
            && said.contains("its 2 triangles (glass?) are left out of the level")
            && said.contains("`d 1` in the MTL"),
        "{said}"
    );
    // `Tr` is transparency: 0.3 is opacity 0.7, kept.
    assert!(
        said.contains("material 'tinted' is partly see-through (opacity 0.70)")
            && said.contains("its triangle blocks light as walls do"),
        "{said}"
    );
    assert!(!said.contains("'wall'"), "{said}");
}

#[test]
fn a_gltf_s_blended_or_transmitting_glass_is_left_out_and_opaque_or_masked_materials_are_not() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let mut bin = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    std::fs::write(d.join("panes.bin"), &bin).expect("bin");
    let prim = |m: usize| format!(r#"{{"attributes":{{"POSITION":0}},"material":{m}}}"#);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0}}],
        "meshes":[{{"name":"panes","primitives":[{},{},{},{},{}]}}],
        "materials":[
          {{"name":"wall"}},
          {{"name":"window","alphaMode":"BLEND","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.2]}}}},
          {{"name":"leaves","alphaMode":"MASK","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.2]}}}},
          {{"name":"faded","alphaMode":"BLEND","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,1]}}}},
          {{"name":"pane","extensions":{{"KHR_materials_transmission":{{"transmissionFactor":0.95}}}}}}],
        "extensionsUsed":["KHR_materials_transmission"],
        "buffers":[{{"uri":"panes.bin","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}]}}"#,
        prim(0),
        prim(1),
        prim(2),
        prim(3),
        prim(4)
    );
    std::fs::write(d.join("panes.gltf"), json).expect("gltf");
    let scene = load(&d.join("panes.gltf"));
    assert_eq!(scene.triangle_count(), 3, "all but the window and the pane");
    let said = scene.report.warnings.join("\n");
    assert!(
        said.contains("material 'window' is see-through (opacity 0.20)")
            && said.contains("alphaMode OPAQUE"),
        "{said}"
    );
    // Glass as Blender exports a Principled BSDF's transmission.
    assert!(
        said.contains("material 'pane' is see-through (opacity 0.05)"),
        "{said}"
    );
    // A cut-out (MASK) is kept and drawn whole, and said so; an alpha of 1 is opaque.
    assert!(
        said.contains("material 'leaves' is cut out by an alpha mask")
            && said.contains("its 1 triangle is drawn whole and opaque"),
        "{said}"
    );
    assert!(!said.contains("'faded'"), "{said}");
}

#[test]
fn an_obj_s_alpha_masked_materials_are_kept_and_said_once() {
    // Crytek Sponza's MTL as McGuire ships it cuts its leaves, plant and chains out with
    // map_d; visgate draws them whole. One note names them, however many there are; a masked
    // material that is also glass is left out as glass and not named again.
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(
        d.join("court.mtl"),
        "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl leaf\nKd 0.3 0.5 0.2\nmap_d leaf_mask.tga\n\
         newmtl chain\nmap_d chain_mask.tga\nnewmtl veil\nd 0.2\nmap_d veil_mask.tga\n",
    )
    .expect("mtl");
    std::fs::write(
        d.join("court.obj"),
        "mtllib court.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 0\n\
         usemtl wall\nf 1 2 3\nusemtl leaf\nf 1 2 4\nf 2 5 4\nusemtl chain\nf 1 3 4\n\
         usemtl veil\nf 2 3 4\n",
    )
    .expect("obj");
    let scene = load(&d.join("court.obj"));
    assert_eq!(scene.triangle_count(), 4, "all but the veil");
    let said = scene.report.warnings.join("\n");
    assert_eq!(said.matches("alpha mask").count(), 1, "{said}");
    assert!(
        said.contains("materials 'leaf', 'chain' are cut out by an alpha mask")
            && said.contains("their 3 triangles are drawn whole and opaque")
            && said.contains("`d 0.4` in the MTL"),
        "{said}"
    );
    assert!(said.contains("material 'veil' is see-through"), "{said}");
}

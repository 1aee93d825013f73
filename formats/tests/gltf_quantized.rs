//! KHR_mesh_quantization, as gltfpack writes it by default: positions as integers that the
//! node's scale brings back to metres, normals as normalized bytes, texture coordinates as
//! integers that the material's KHR_texture_transform scales back. The gltf crate refused such
//! a file ("Unsupported extension"), and visgate after it named the extension; it reads it.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use visgate_formats::Scene;
use visgate_formats::import::ImportOptions;

/// One triangle, its positions of component type `pos_type` (5123: unsigned shorts, 5122:
/// normalized signed shorts) holding `pos`, under a node that scales by `scale` and moves by
/// (1, 0, 0); normals (0, 0, 1) as normalized bytes; texture coordinates (0, 0), (1024, 0),
/// (0, 1024) as unsigned shorts, which the material's texture transform scales by 1 / 1024
/// and offsets by (0.25, 0).
fn quantized(dir: &Path, pos_type: u32, pos: [[i32; 3]; 3], scale: f32) -> PathBuf {
    let mut bin = Vec::new();
    // Positions, 3 shorts padded to 8 bytes each (a vertex attribute's 4-byte alignment).
    for p in pos {
        for c in p {
            bin.extend_from_slice(&(c as u16).to_le_bytes());
        }
        bin.extend_from_slice(&[0, 0]);
    }
    // Normals, 3 bytes padded to 4.
    for _ in 0..3 {
        bin.extend_from_slice(&[0, 0, 127, 0]);
    }
    for uv in [[0u16, 0], [1024, 0], [0, 1024]] {
        for c in uv {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    std::fs::write(dir.join("packed.bin"), &bin).expect("bin");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]))
        .save(dir.join("albedo.png"))
        .expect("png");
    let normalized = pos_type == 5122;
    let lo = [0, 1, 2].map(|i| pos.iter().map(|p| p[i]).min().unwrap_or(0));
    let max = [0, 1, 2].map(|i| pos.iter().map(|p| p[i]).max().unwrap_or(0));
    let json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"gltfpack 0.21"}},
        "extensionsUsed":["KHR_mesh_quantization","KHR_texture_transform"],
        "extensionsRequired":["KHR_mesh_quantization"],
        "scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"translation":[1,0,0],"scale":[{scale},{scale},{scale}]}}],
        "meshes":[{{"name":"packed","primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2}},"material":0}}]}}],
        "materials":[{{"name":"brick","pbrMetallicRoughness":{{"baseColorTexture":{{"index":0,
            "extensions":{{"KHR_texture_transform":{{"offset":[0.25,0],"scale":[0.0009765625,0.0009765625]}}}}}}}}}}],
        "textures":[{{"source":0}}],"images":[{{"uri":"albedo.png"}}],
        "buffers":[{{"uri":"packed.bin","byteLength":{blen}}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":24,"byteStride":8,"target":34962}},
                       {{"buffer":0,"byteOffset":24,"byteLength":12,"byteStride":4,"target":34962}},
                       {{"buffer":0,"byteOffset":36,"byteLength":12,"target":34962}}],
        "accessors":[{{"bufferView":0,"componentType":{pos_type},"normalized":{normalized},"count":3,"type":"VEC3","min":{lo:?},"max":{max:?}}},
                     {{"bufferView":1,"componentType":5120,"normalized":true,"count":3,"type":"VEC3"}},
                     {{"bufferView":2,"componentType":5123,"count":3,"type":"VEC2"}}]}}"#,
        blen = bin.len(),
    );
    let path = dir.join("packed.gltf");
    std::fs::write(&path, json).expect("gltf");
    path
}

/// The texture coordinates that [`quantized`]'s transform makes.
const UVS: [Vec2; 3] = [
    Vec2::new(0.25, 0.0),
    Vec2::new(1.25, 0.0),
    Vec2::new(0.25, 1.0),
];

/// [`quantized`]'s triangle in centimetres: unsigned shorts under a node scale of 0.01.
fn centimetre_triangle(dir: &Path) -> PathBuf {
    quantized(dir, 5123, [[0, 0, 0], [200, 0, 0], [0, 300, 0]], 0.01)
}

#[test]
fn a_quantized_gltf_reads_as_its_floats() {
    let dir = tempfile::tempdir().expect("tempdir");
    let want = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(1.0, 3.0, 0.0),
    ];
    // Unsigned shorts in centimetres (a node scale of 0.01), and normalized signed shorts
    // (32,767 is 1) under a scale of 3.
    for (kind, pos, scale) in [
        (5123, [[0, 0, 0], [200, 0, 0], [0, 300, 0]], 0.01),
        (5122, [[0, 0, 0], [21845, 0, 0], [0, 32767, 0]], 3.0),
    ] {
        let path = quantized(dir.path(), kind, pos, scale);
        let scene = Scene::load(&path, &ImportOptions::default()).expect("loads");
        assert_eq!(scene.triangle_count(), 1, "{kind}");
        let mesh = &scene.meshes[0];
        for (got, want) in mesh.positions.iter().zip(want) {
            assert!(got.distance(want) < 1e-3, "{kind}: {got} against {want}");
        }
        for n in &mesh.normals {
            assert!(n.distance(Vec3::Z) < 1e-6, "{kind}: {n}");
        }
        for (got, want) in mesh.uvs.iter().zip(UVS) {
            assert!(got.distance(want) < 1e-6, "{kind}: {got} against {want}");
        }
        assert!(scene.materials[0].texture.is_some(), "{kind}");
        let said = scene.report.warnings.join("\n");
        assert!(!said.contains("quantiz"), "{said}");
    }
}

#[test]
fn a_quantized_accessor_past_its_buffer_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = centimetre_triangle(dir.path());
    let json = std::fs::read_to_string(&path).expect("gltf");
    // Ten vertices where the view holds three.
    let json = json.replacen(
        r#""count":3,"type":"VEC3","min""#,
        r#""count":10,"type":"VEC3","min""#,
        1,
    );
    std::fs::write(&path, json).expect("gltf");
    match Scene::load(&path, &ImportOptions::default()) {
        Ok(_) => panic!("loaded an accessor past its buffer"),
        Err(e) => assert!(e.to_string().contains("packed.gltf"), "{e}"),
    }
}

/// A base colour texture is read on the coordinate set it names: its `texCoord`, or its
/// KHR_texture_transform's override (gltfpack and Blender write a second set for lightmaps).
#[test]
fn the_base_colour_texture_is_read_on_the_coordinate_set_it_names() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = centimetre_triangle(dir.path());
    let json = std::fs::read_to_string(&path).expect("gltf");
    let second = json.replacen(r#""TEXCOORD_0":2"#, r#""TEXCOORD_1":2"#, 1);
    let named = r#""baseColorTexture":{"index":0,"texCoord":1,"#;
    let overridden = r#""KHR_texture_transform":{"texCoord":1,"#;
    for (how, text) in [
        (
            "texCoord",
            second.replacen(r#""baseColorTexture":{"index":0,"#, named, 1),
        ),
        (
            "the transform's texCoord",
            second.replacen(r#""KHR_texture_transform":{"#, overridden, 1),
        ),
    ] {
        assert_ne!(text, second, "{how}: the fixture changed");
        std::fs::write(&path, text).expect("gltf");
        let scene = Scene::load(&path, &ImportOptions::default()).expect("loads");
        let uvs = &scene.meshes[0].uvs;
        assert_eq!(uvs.len(), 3, "{how}: the second set was not read");
        for (got, want) in uvs.iter().zip(UVS) {
            assert!(got.distance(want) < 1e-6, "{how}: {got} against {want}");
        }
    }
}

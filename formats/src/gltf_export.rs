//! Writing a scene as a glTF file (`visgate export gltf`): its meshes, albedos, lights
//! (`KHR_lights_punctual`) and cameras, so that it opens in Blender or another engine as visgate
//! sees it — and reads back, given bare, as the same scene ([`crate::gltf_nodes`] is the
//! inverse: W/sr are written as candela, × 683; a camera's horizontal field of view as a
//! vertical one at [`DEFAULT_ASPECT`]; a spot's beam as its inner cone, just inside the outer
//! one where they are equal, as glTF wants it smaller). Textures are not written (each material
//! keeps its albedo) and the scene is posed at one time (light and mesh motion not written).

use glam::{DMat3, DQuat, Quat, Vec3};
use serde_json::{Value, json};

use crate::gltf_nodes::{DEFAULT_ASPECT, LUMENS_PER_WATT};
use crate::scene::{Light, Scene};

/// glTF's buffer view targets and component types.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The glTF JSON of `scene` and its binary buffer; the JSON refers to the buffer as
/// `bin_file_name` (beside it), or, with `None`, as a GLB's own binary chunk ([`to_glb`]).
pub fn to_gltf(scene: &Scene, bin_file_name: Option<&str>) -> (String, Vec<u8>) {
    let mut out = Writer::default();
    for mesh in &scene.meshes {
        out.mesh(mesh);
    }
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            json!({"name": m.name, "pbrMetallicRoughness": {
                "baseColorFactor": [m.albedo.x, m.albedo.y, m.albedo.z, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0}})
        })
        .collect();
    let lights: Vec<Value> = scene
        .lights
        .iter()
        .enumerate()
        .map(|(k, l)| out.light(k, l))
        .collect();
    let cameras: Vec<Value> = scene
        .cameras
        .iter()
        .enumerate()
        .map(|(k, c)| out.camera(k, c))
        .collect();
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "visgate"},
        "scene": 0,
        "scenes": [{"nodes": (0..out.nodes.len()).collect::<Vec<_>>()}],
        "nodes": out.nodes, "meshes": out.meshes, "materials": materials,
        "buffers": [match bin_file_name {
            Some(uri) => json!({"uri": uri, "byteLength": out.bin.len()}),
            None => json!({"byteLength": out.bin.len()}),
        }],
        "bufferViews": out.views, "accessors": out.accessors,
    });
    if !cameras.is_empty() {
        doc["cameras"] = json!(cameras);
    }
    if !lights.is_empty() {
        doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    }
    let text = serde_json::to_string_pretty(&doc).expect("a JSON value always serializes");
    (text, out.bin)
}

/// `scene` as one GLB file: the 12-byte header, the JSON chunk (padded with spaces) and the
/// binary chunk (padded with zeros), each 4-byte aligned.
pub fn to_glb(scene: &Scene) -> Vec<u8> {
    let (json, bin) = to_gltf(scene, None);
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin;
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    let word = |out: &mut Vec<u8>, w: u32| out.extend_from_slice(&w.to_le_bytes());
    out.extend_from_slice(b"glTF");
    word(&mut out, 2);
    word(&mut out, total as u32);
    word(&mut out, json.len() as u32);
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    word(&mut out, bin.len() as u32);
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// The document's arrays as they fill.
#[derive(Default)]
struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
}

impl Writer {
    /// A buffer view of `bytes` (4-byte aligned); its index.
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(),
                               "byteLength": bytes.len(), "target": target}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// An accessor; its index.
    fn accessor(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// A mesh and its node: one primitive per material, sharing the vertices.
    fn mesh(&mut self, mesh: &crate::scene::Mesh) {
        let floats = |v: &[Vec3]| -> Vec<u8> {
            v.iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect()
        };
        let lo = mesh.positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
        let hi = mesh
            .positions
            .iter()
            .fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
        let n = mesh.positions.len();
        let pv = self.view(&floats(&mesh.positions), ARRAY_BUFFER);
        let nv = self.view(&floats(&mesh.normals), ARRAY_BUFFER);
        let position = self.accessor(json!({"bufferView": pv, "componentType": FLOAT,
            "count": n, "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()}));
        let normal = self.accessor(json!({"bufferView": nv, "componentType": FLOAT,
            "count": n, "type": "VEC3"}));
        let mut materials: Vec<u32> = mesh.material.clone();
        materials.sort_unstable();
        materials.dedup();
        let mut primitives = Vec::new();
        for m in materials {
            let indices: Vec<u8> = mesh
                .triangles
                .iter()
                .zip(&mesh.material)
                .filter(|&(_, &tm)| tm == m)
                .flat_map(|(t, _)| t.iter().flat_map(|i| i.to_le_bytes()))
                .collect();
            let count = indices.len() / 4;
            let iv = self.view(&indices, ELEMENT_ARRAY_BUFFER);
            let ia = self.accessor(json!({"bufferView": iv, "componentType": UNSIGNED_INT,
                "count": count, "type": "SCALAR"}));
            primitives.push(
                json!({"attributes": {"POSITION": position, "NORMAL": normal},
                                   "indices": ia, "material": m}),
            );
        }
        self.meshes
            .push(json!({"name": mesh.name, "primitives": primitives}));
        self.nodes
            .push(json!({"name": mesh.name, "mesh": self.meshes.len() - 1}));
    }

    /// Light `k` as a `KHR_lights_punctual` light, placed by a node.
    fn light(&mut self, k: usize, l: &Light) -> Value {
        // glTF states a colour (≤ 1) and an intensity: the brightest channel is the intensity.
        let colour = |i: Vec3| {
            let peak = i.max_element();
            let c = if peak > 0.0 { i / peak } else { Vec3::ONE };
            (c.to_array(), peak * LUMENS_PER_WATT)
        };
        let name = format!("light {}", k + 1);
        let (light, position, rotation) = match *l {
            Light::Point {
                position,
                intensity,
            } => {
                let (c, i) = colour(intensity);
                let light = json!({"name": name, "type": "point", "color": c, "intensity": i});
                (light, position, Quat::IDENTITY)
            }
            Light::Spot {
                position,
                direction,
                intensity,
                cutoff_rad,
                beam_rad,
            } => {
                let (c, i) = colour(intensity);
                let spot = json!({"innerConeAngle": beam_rad.min(cutoff_rad * 0.999),
                                  "outerConeAngle": cutoff_rad});
                let light = json!({"name": name, "type": "spot", "color": c, "intensity": i,
                                   "spot": spot});
                (
                    light,
                    position,
                    Quat::from_rotation_arc(Vec3::NEG_Z, direction),
                )
            }
        };
        self.nodes
            .push(json!({"name": name, "translation": position.to_array(),
            "rotation": rotation.to_array(),
            "extensions": {"KHR_lights_punctual": {"light": k}}}));
        light
    }

    /// Camera `k` as a perspective glTF camera, placed by a node.
    fn camera(&mut self, k: usize, c: &crate::scene::Camera) -> Value {
        let (eye, target, up) = (c.eye.as_dvec3(), c.target.as_dvec3(), c.up.as_dvec3());
        // The camera's frame: right, up, back (glTF's camera looks along −Z, +Y up).
        let forward = (target - eye).normalize();
        let right = forward
            .cross(up)
            .try_normalize()
            .unwrap_or_else(|| forward.any_orthonormal_vector());
        let frame = DMat3::from_cols(right, right.cross(forward), -forward);
        let rotation = DQuat::from_mat3(&frame).normalize().as_quat();
        let yfov = 2.0 * ((0.5 * c.fov_x_rad).tan() / DEFAULT_ASPECT).atan();
        self.nodes
            .push(json!({"name": c.name, "translation": eye.to_array(),
                               "rotation": rotation.to_array(), "camera": k}));
        json!({"name": c.name, "type": "perspective",
               "perspective": {"yfov": yfov, "aspectRatio": DEFAULT_ASPECT, "znear": 0.01}})
    }
}

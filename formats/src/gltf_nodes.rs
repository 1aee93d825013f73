//! The lights and cameras a glTF file places in its node tree, read as a scene TOML would
//! state them, so that a level exported from Blender, Unreal or Godot as a bare glTF/GLB file
//! comes with its author's lights and views.
//!
//! - **Lights** (`KHR_lights_punctual`): point and spot lights at their node's world position,
//!   a spot along its node's −Z. glTF states luminous intensity (candela, lm/sr); visgate's
//!   lights are radiometric, so `I [W/sr] = colour × intensity [cd] / 683 lm/W` (the luminous
//!   efficacy at 555 nm, the definition of the candela). A spot's `outerConeAngle` is where its
//!   intensity reaches 0 and its `innerConeAngle` the edge of full intensity; between them glTF
//!   leaves the falloff to the engine and visgate's is linear in angle. `range` is not read (the
//!   light falls off with the inverse square everywhere).
//! - **Suns** (directional lights): irradiance `E [W/m²] = colour × illuminance [lux] / 683`,
//!   along the node's −Z; the scene places each as a far spot light ([`crate::sun`]).
//! - **Cameras**: perspective cameras at their node's world position, looking along its −Z with
//!   its +Y up; glTF gives the vertical field of view and visgate the horizontal one, so
//!   `fov_x = 2 atan(tan(yfov / 2) · aspect)` with the camera's aspect ratio, or 16:9 where it
//!   gives none. Orthographic cameras are skipped with a warning.
//!
//! Everything stays in the file's units and axes: the scene applies its up axis and units to
//! them as to the meshes.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::desc::{CameraDesc, LightDesc, PointLightDesc, SpotLightDesc};
use crate::import::ImportedModel;

/// Lumens per watt at 555 nm: candela → W/sr.
pub const LUMENS_PER_WATT: f32 = 683.0;
/// Aspect ratio assumed for a glTF camera that gives none.
pub const DEFAULT_ASPECT: f32 = 16.0 / 9.0;
/// Narrowest full-intensity half-angle a spot keeps (glTF's inner cone may be 0, visgate's
/// beam must be above it). [Units: degrees]
const MIN_BEAM_DEG: f32 = 0.01;

/// Reads the lights and cameras of `scene`'s node tree into `out`, in the file's node order
/// (depth first, children in order), cameras' names made unique.
pub(crate) fn read_nodes(path: &Path, scene: &gltf::Scene, out: &mut ImportedModel) {
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        read_node(path, &node, world, out);
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    unique_camera_names(&mut out.cameras);
}

/// Reads `node`'s light and camera, if any, placed by its world matrix `world`, into `out`.
fn read_node(path: &Path, node: &gltf::Node, world: Mat4, out: &mut ImportedModel) {
    let at = world.transform_point3(Vec3::ZERO);
    let along = |v: Vec3| world.transform_vector3(v).normalize_or_zero();
    let node_name = || {
        node.name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {}", node.index()))
    };
    if let Some(light) = node.light() {
        let name = light.name().map(str::to_string).unwrap_or_else(node_name);
        let intensity =
            (Vec3::from(light.color()) * light.intensity() / LUMENS_PER_WATT).to_array();
        let position = at.as_dvec3().to_array();
        match light.kind() {
            gltf::khr_lights_punctual::Kind::Point => {
                out.lights.push(LightDesc::Point(PointLightDesc {
                    position,
                    intensity,
                    animate: vec![],
                    orbit: None,
                }));
            }
            gltf::khr_lights_punctual::Kind::Spot { .. } if along(Vec3::NEG_Z) == Vec3::ZERO => {
                out.warnings.push(format!(
                    "{}: spot light '{name}' skipped: its node's transform has no direction (a \
                     zero scale)",
                    path.display()
                ));
            }
            gltf::khr_lights_punctual::Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let cutoff_deg = outer_cone_angle.to_degrees().min(90.0);
                out.lights.push(LightDesc::Spot(SpotLightDesc {
                    position,
                    target: None,
                    direction: Some(along(Vec3::NEG_Z).as_dvec3().to_array()),
                    intensity,
                    cutoff_deg,
                    beam_deg: inner_cone_angle
                        .to_degrees()
                        .clamp(MIN_BEAM_DEG.min(cutoff_deg), cutoff_deg),
                    animate: vec![],
                    orbit: None,
                }));
            }
            gltf::khr_lights_punctual::Kind::Directional if along(Vec3::NEG_Z) == Vec3::ZERO => {
                out.warnings.push(format!(
                    "{}: directional light '{name}' skipped: its node's transform has no \
                     direction (a zero scale)",
                    path.display()
                ));
            }
            gltf::khr_lights_punctual::Kind::Directional => out.suns.push(crate::sun::SunDesc {
                name: Some(name),
                direction: along(Vec3::NEG_Z).as_dvec3().to_array(),
                irradiance: intensity,
            }),
        }
    }
    if let Some(camera) = node.camera() {
        let name = camera.name().map(str::to_string).unwrap_or_else(node_name);
        match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let aspect = p.aspect_ratio().unwrap_or(DEFAULT_ASPECT);
                let fov_x = 2.0 * ((0.5 * p.yfov()).tan() * aspect).atan();
                if !(fov_x > 0.0 && fov_x < std::f32::consts::PI)
                    || along(Vec3::NEG_Z) == Vec3::ZERO
                    || along(Vec3::Y) == Vec3::ZERO
                {
                    out.warnings.push(format!(
                        "{}: camera '{name}' skipped: its field of view (yfov {} rad, aspect \
                         {aspect}) or its node's transform (a zero scale) makes no view",
                        path.display(),
                        p.yfov()
                    ));
                    return;
                }
                let eye = at.as_dvec3();
                out.cameras.push(CameraDesc {
                    name,
                    eye: eye.to_array(),
                    target: (eye + along(Vec3::NEG_Z).as_dvec3()).to_array(),
                    up: Some(along(Vec3::Y).as_dvec3().to_array()),
                    fov_deg: fov_x.to_degrees(),
                });
            }
            gltf::camera::Projection::Orthographic(_) => {
                out.warnings.push(format!(
                    "{}: orthographic camera '{name}' skipped: visgate's cameras are \
                     perspective",
                    path.display()
                ));
            }
        }
    }
}

/// Gives cameras that share a name a suffix (`name 2`, `name 3`, …): `--camera` picks by name.
fn unique_camera_names(cameras: &mut [CameraDesc]) {
    let mut seen = std::collections::HashMap::<String, u32>::new();
    for c in cameras.iter_mut() {
        let n = seen.entry(c.name.clone()).or_insert(0);
        *n += 1;
        if *n > 1 {
            c.name = format!("{} {}", c.name, n);
        }
    }
}

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
//! - **Suns** (directional lights): visgate has no light at infinity, so a bare file's sun is
//!   placed as a spot light far along its direction ([`suns_as_spots`]): on the line through
//!   the level's centre, [`SUN_DISTANCE_DIAGONALS`] of its box's diagonals away (within the
//!   distance at which a light is named as misplaced), its full beam just covering the box,
//!   intensity set so that the irradiance at the centre is the sun's, `E [W/m²] = colour ×
//!   illuminance [lux] / 683`. Its rays are then parallel within 3° and its irradiance within
//!   about ±11 % across the level (the inverse square from the near side to the far one); the
//!   load says where it went.
//! - **Cameras**: perspective cameras at their node's world position, looking along its −Z with
//!   its +Y up; glTF gives the vertical field of view and visgate the horizontal one, so
//!   `fov_x = 2 atan(tan(yfov / 2) · aspect)` with the camera's aspect ratio, or 16:9 where it
//!   gives none. Orthographic cameras are skipped with a warning.
//!
//! Everything stays in the file's units and axes: the scene applies its up axis and units to
//! them as to the meshes.

use std::path::Path;

use glam::{DVec3, Mat4, Vec3};

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
            gltf::khr_lights_punctual::Kind::Directional => out.suns.push(Sun {
                name,
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

/// A directional light as the file states it: where its light goes and how strong it is.
#[derive(Debug, Clone, PartialEq)]
pub struct Sun {
    /// The light's name (or its node's).
    pub name: String,
    /// Unit direction its light travels, in the file's axes.
    pub direction: [f64; 3],
    /// Irradiance on a surface facing it, W/m² per RGB channel (colour × lux / 683).
    pub irradiance: [f32; 3],
}

/// How far from the level's centre a sun's spot stands, in diagonals of the level's box: under
/// [`crate::placement::FAR_DIAGONALS`], at which a light is named as misplaced.
pub const SUN_DISTANCE_DIAGONALS: f64 = 9.5;

/// The suns of `models` as spot lights (see the module notes), in the files' units and axes,
/// and a line for each saying where it went; none without geometry. `metres_per_unit` makes
/// the spot's intensity give the sun's irradiance in metres.
pub fn suns_as_spots(
    models: &[ImportedModel],
    metres_per_unit: f64,
    path: &Path,
) -> (Vec<LightDesc>, Vec<String>) {
    let points = models
        .iter()
        .flat_map(|m| &m.meshes)
        .flat_map(|m| &m.positions)
        .map(|p| p.as_dvec3());
    let Some((lo, hi)) = points.fold(None, |b: Option<(DVec3, DVec3)>, p| {
        Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
    }) else {
        return (Vec::new(), Vec::new());
    };
    let (centre, diagonal) = (0.5 * (lo + hi), (hi - lo).length().max(1e-9));
    let distance = SUN_DISTANCE_DIAGONALS * diagonal;
    // The box's bounding sphere seen from the spot, and a little more.
    let beam_deg = (0.5 * diagonal / distance).asin().to_degrees() as f32 * 1.05;
    let metres = distance * metres_per_unit;
    let mut notes = Vec::new();
    let spots = (models.iter().flat_map(|m| &m.suns))
        .map(|sun| {
            let dir = DVec3::from(sun.direction).normalize();
            let position = centre - dir * distance;
            let intensity = Vec3::from(sun.irradiance) * (metres * metres) as f32;
            notes.push(format!(
                "{}: directional light '{}' (irradiance {:.3} {:.3} {:.3} W/m²) placed as a \
                 spot light {:.0} units from the level's centre, at ({:.1}, {:.1}, {:.1}) in \
                 the file's units and axes, aimed along its direction: visgate has no light at \
                 infinity; its rays are parallel within 3° and its irradiance within about \
                 ±11 % across the level",
                path.display(),
                sun.name,
                sun.irradiance[0],
                sun.irradiance[1],
                sun.irradiance[2],
                distance,
                position.x,
                position.y,
                position.z
            ));
            LightDesc::Spot(SpotLightDesc {
                position: position.to_array(),
                target: None,
                direction: Some(dir.to_array()),
                intensity: intensity.to_array(),
                cutoff_deg: beam_deg * 1.1,
                beam_deg,
                animate: vec![],
                orbit: None,
            })
        })
        .collect();
    (spots, notes)
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

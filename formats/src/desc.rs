//! The scene description: a TOML file a user writes by hand.
//!
//! ```toml
//! name = "two rooms"          # optional; defaults to the file's stem
//! up = "y"                    # "y" (default) or "z": the up axis of every coordinate in this file
//! metres_per_unit = 1.0       # default 1.0; 0.01 for a level modelled in centimetres
//! closed = true               # the level is meant to be sealed (the bake reports leaks)
//!
//! [[mesh]]
//! path = "rooms.obj"          # OBJ, glTF or GLB, relative to this file
//! static = true               # default true; dynamic meshes are lit but not baked
//! translate = [0, 0, 0]       # scene units
//! rotate_deg = [0, 90, 0]     # Euler angles in degrees, applied about X, then Y, then Z
//! scale = 1.0                 # a number or [sx, sy, sz]
//!
//! [[material]]                # overrides a material of the meshes, by name
//! name = "floor"
//! albedo = [0.8, 0.8, 0.8]    # linear diffuse albedo in [0, 1]; replaces the texture
//!
//! [[light]]
//! type = "point"
//! position = [2, 2.7, 2]
//! intensity = [8, 8, 8]       # radiant intensity, W/sr per RGB channel
//!
//! [[light]]
//! type = "spot"
//! position = [1, 2, 1]
//! target = [1, 0, 1]          # or direction = [0, -1, 0]
//! intensity = [20, 20, 20]    # W/sr on the axis
//! cutoff_deg = 30             # half-angle where the light reaches 0
//! beam_deg = 20               # half-angle of full intensity (<= cutoff); linear in angle between
//!
//! [[mesh]]                    # a dynamic mesh may move: keyframes (linear, held outside)
//! path = "box.obj"
//! static = false
//! animate = [{ t = 0, translate = [1, 0, 1] }, { t = 4, translate = [3, 0, 1], rotate_deg = [0, 90, 0] }]
//!
//! [[light]]                   # a light may move too: keyframes, or an orbit about the up axis
//! type = "point"
//! position = [4, 2.5, 4]
//! intensity = [8, 8, 8]
//! orbit = { centre = [4, 2.5, 4], radius = 1.5, period_s = 8 }
//!
//! [[camera]]
//! name = "main"
//! eye = [0.5, 1.6, 0.5]
//! target = [4, 1.2, 2]
//! up = [0, 1, 0]              # default: the scene's up axis
//! fov_deg = 70                # full horizontal angle
//! ```
//!
//! Every unknown key is an error that names the key and the file. The conventions are those of
//! Mitsuba 3 (see DESIGN.md), so that an independent renderer can check visgate's images.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// The up axis that a scene file's coordinates use. visgate converts everything to +Y up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    /// +Y up (visgate's own convention, glTF's and most OBJ exporters').
    #[default]
    Y,
    /// +Z up (Blender, Quake, 3ds Max): converted with (x, y, z) → (x, z, −y).
    Z,
}

/// A uniform or per-axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f64),
    /// One factor per axis.
    PerAxis([f64; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

impl Scale {
    /// The factor on each axis.
    pub fn as_vec(&self) -> [f64; 3] {
        match *self {
            Scale::Uniform(s) => [s; 3],
            Scale::PerAxis(v) => v,
        }
    }
}

fn default_true() -> bool {
    true
}

fn default_mpu() -> f64 {
    1.0
}

/// The whole scene description, as written in TOML.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// Display name; defaults to the file's stem.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Up axis of every coordinate in the file.
    #[serde(default)]
    pub up: UpAxis,
    /// Metres per scene unit. [Limit: > 0, finite]
    #[serde(default = "default_mpu")]
    pub metres_per_unit: f64,
    /// Whether the level is meant to be sealed: the bake reports where its empty space leaks.
    #[serde(default)]
    pub closed: bool,
    /// The meshes, in order.
    #[serde(default, rename = "mesh")]
    pub meshes: Vec<MeshDesc>,
    /// Material overrides, matched by material name.
    #[serde(default, rename = "material", skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<MaterialOverride>,
    /// Primary lights.
    #[serde(default, rename = "light")]
    pub lights: Vec<LightDesc>,
    /// Rows of equal point lights (torches along an arcade), made into `lights` when read.
    #[serde(default, rename = "light_line", skip_serializing_if = "Vec::is_empty")]
    pub light_lines: Vec<LightLineDesc>,
    /// Named cameras.
    #[serde(default, rename = "camera")]
    pub cameras: Vec<CameraDesc>,
    /// Suns: directional lights, each placed as a far spot light (`crate::sun`).
    #[serde(default, rename = "sun", skip_serializing_if = "Vec::is_empty")]
    pub suns: Vec<crate::sun::SunDesc>,
}

/// One mesh file placed in the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    /// OBJ, glTF or GLB file, relative to the scene file.
    pub path: PathBuf,
    /// Static meshes are baked and occlude; dynamic ones are only lit.
    #[serde(rename = "static", default = "default_true")]
    pub is_static: bool,
    /// Translation in scene units.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Euler angles in degrees, applied about X, then Y, then Z.
    #[serde(default)]
    pub rotate_deg: [f64; 3],
    /// Scale applied before rotation. [Limit: finite, non-zero]
    #[serde(default)]
    pub scale: Scale,
    /// Keyframes of a dynamic mesh's translation and rotation (they replace `translate` and
    /// `rotate_deg` at their times). [Limit: only with static = false]
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub animate: Vec<MeshKey>,
    /// A dynamic mesh's translation moves on a circle about the up axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit: Option<Orbit>,
    /// Objects of the file left out of the scene by name — an OBJ's object or group, a glTF
    /// node (the object as Blender names it; its mesh's name where the node has none): a sky
    /// dome, a helper left in the export, which would size the bake's grid. [Limit: each
    /// names an object of the file]
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub leave_out: Vec<String>,
}

/// A keyframe of a dynamic mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshKey {
    /// Time. [Units: s] [Limit: finite, increasing along the keys]
    pub t: f64,
    /// Translation at this time, scene units.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Euler angles at this time, degrees, applied about X, then Y, then Z.
    #[serde(default)]
    pub rotate_deg: [f64; 3],
}

/// A keyframe of a light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightKey {
    /// Time. [Units: s] [Limit: finite, increasing along the keys]
    pub t: f64,
    /// Position at this time, scene units.
    pub position: [f64; 3],
    /// A spot's target at this time (else its own `target`, or it keeps its direction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<[f64; 3]>,
}

/// Motion on a circle about the scene's up axis: at time t the point is
/// `centre + radius·(cos φ, 0, sin φ)` (in the plane normal to the up axis), φ = 2π·t/period +
/// phase.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    /// Centre, scene units.
    pub centre: [f64; 3],
    /// Radius, scene units. [Limit: ≥ 0, finite]
    pub radius: f64,
    /// Time of one turn. [Units: s] [Limit: > 0, finite]
    pub period_s: f64,
    /// Angle at t = 0. [Units: degrees]
    #[serde(default)]
    pub phase_deg: f64,
}

/// Replaces a material's diffuse albedo (and drops its texture).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    /// Name of the material in the mesh files.
    pub name: String,
    /// Linear diffuse albedo. [Limit: each channel in [0, 1]]
    pub albedo: [f32; 3],
}

/// A primary light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum LightDesc {
    /// Isotropic point light.
    Point(PointLightDesc),
    /// Spot light with Mitsuba's linear-in-angle falloff.
    Spot(SpotLightDesc),
}

/// `count` equal point lights evenly spaced from `from` to `to` (both ends included; one light
/// sits at `from`): many lights at once, as a level's torches or lamps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightLineDesc {
    /// First light's position, scene units.
    pub from: [f64; 3],
    /// Last light's position, scene units.
    pub to: [f64; 3],
    /// Lights on the line. [Limit: 1..=65536]
    pub count: u32,
    /// Radiant intensity of each, W/sr per RGB channel. [Limit: >= 0, finite]
    pub intensity: [f32; 3],
}

/// Most lights one `light_line` makes.
pub const MAX_LINE_LIGHTS: u32 = 65_536;

impl LightLineDesc {
    /// The line's point lights, or what is wrong with it.
    fn lights(&self) -> Result<Vec<LightDesc>, String> {
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        if !(finite(&self.from) && finite(&self.to)) {
            return Err("from and to must be finite".into());
        }
        if !(1..=MAX_LINE_LIGHTS).contains(&self.count) {
            return Err(format!(
                "count = {} must be 1..={MAX_LINE_LIGHTS}",
                self.count
            ));
        }
        if self.intensity.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
            return Err(format!(
                "intensity {:?} W/sr must be finite and >= 0",
                self.intensity
            ));
        }
        let steps = f64::from(self.count.max(2) - 1);
        Ok((0..self.count)
            .map(|k| {
                let t = f64::from(k) / steps;
                LightDesc::Point(PointLightDesc {
                    position: std::array::from_fn(|a| {
                        self.from[a] + (self.to[a] - self.from[a]) * t
                    }),
                    intensity: self.intensity,
                    animate: vec![],
                    orbit: None,
                })
            })
            .collect())
    }
}

/// An isotropic point light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightDesc {
    /// Position in scene units.
    pub position: [f64; 3],
    /// Radiant intensity, W/sr per RGB channel. [Limit: >= 0, finite]
    pub intensity: [f32; 3],
    /// Keyframes of its position.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub animate: Vec<LightKey>,
    /// Its position moves on a circle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit: Option<Orbit>,
}

/// A spot light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpotLightDesc {
    /// Position in scene units.
    pub position: [f64; 3],
    /// A point the spot aims at (give this or `direction`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<[f64; 3]>,
    /// The axis direction (give this or `target`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
    /// Radiant intensity on the axis, W/sr per RGB channel. [Limit: >= 0, finite]
    pub intensity: [f32; 3],
    /// Half-angle at which the intensity reaches 0. [Limit: (0, 90]] [Units: degrees]
    pub cutoff_deg: f32,
    /// Half-angle of full intensity. [Limit: (0, cutoff_deg]] [Units: degrees]
    pub beam_deg: f32,
    /// Keyframes of its position (and target).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub animate: Vec<LightKey>,
    /// Its position moves on a circle (keeping its direction, or its target).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit: Option<Orbit>,
}

/// A named look-at camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Name used by `--camera`.
    pub name: String,
    /// Eye position in scene units.
    pub eye: [f64; 3],
    /// Point looked at, in scene units.
    pub target: [f64; 3],
    /// Up vector; defaults to the scene's up axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<[f64; 3]>,
    /// Full horizontal field of view. [Limit: (0, 180)] [Units: degrees]
    pub fov_deg: f32,
}

impl SceneDesc {
    /// A description of one bare mesh file: static, no lights, no cameras, open.
    pub fn for_mesh_file(path: &Path) -> Self {
        SceneDesc {
            name: path.file_stem().map(|s| s.to_string_lossy().into_owned()),
            up: UpAxis::Y,
            metres_per_unit: 1.0,
            closed: false,
            meshes: vec![MeshDesc {
                path: path.file_name().map(PathBuf::from).unwrap_or_default(),
                is_static: true,
                translate: [0.0; 3],
                rotate_deg: [0.0; 3],
                scale: Scale::Uniform(1.0),
                animate: vec![],
                orbit: None,
                leave_out: vec![],
            }],
            materials: vec![],
            lights: vec![],
            light_lines: vec![],
            cameras: vec![],
            suns: vec![],
        }
    }

    /// Parses and validates a description from TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &Path) -> Result<Self, SceneError> {
        let mut desc: SceneDesc = toml::from_str(text).map_err(|e| SceneError::Parse {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?;
        desc.expand_light_lines(file)?;
        desc.validate(file)?;
        Ok(desc)
    }

    /// Replaces every `[[light_line]]` by its point lights (after the listed lights);
    /// `file` names the scene in errors.
    pub fn expand_light_lines(&mut self, file: &Path) -> Result<(), SceneError> {
        for (i, line) in std::mem::take(&mut self.light_lines).iter().enumerate() {
            let lights = line.lights().map_err(|what| SceneError::Invalid {
                file: file.to_path_buf(),
                what: format!("light_line {}: {what}", i + 1),
            })?;
            self.lights.extend(lights);
        }
        Ok(())
    }

    /// Reads, parses and validates a scene TOML file.
    pub fn read(file: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(file).map_err(|error| SceneError::Io {
            file: file.to_path_buf(),
            error,
        })?;
        Self::from_toml(&text, file)
    }

    /// Writes the description as TOML.
    pub fn to_toml(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        toml::to_string_pretty(self).unwrap_or_else(|e| format!("# could not serialise: {e}\n"))
    }
}

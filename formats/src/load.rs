//! Loading a scene: a scene TOML (its meshes imported and assembled: transforms, up axis,
//! units, material overrides, animation tracks) or a bare mesh file. The one module that uses
//! both the scene types (`scene`) and the importers (`import`), so neither depends on the
//! other's loading.

use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};

use crate::desc::{LightDesc, SceneDesc, UpAxis};
use crate::error::SceneError;
use crate::import::{self, ImportOptions, ImportedModel};
use crate::scene::{
    Animation, Camera, FileKind, ImportReport, Light, LightTrack, Mesh, MeshTrack, Scene,
    SceneSpace, local_matrix, parent_dir,
};

/// The longest a bare mesh may be, read in metres, before it is read in smaller units
/// ([`bare_mesh_units`]): longer than any indoor level. [Units: m]
pub const BARE_LEVEL_MAX_M: f64 = 1000.0;

/// Metres per unit of a bare mesh (no scene file, so no stated units) whose longest extent is
/// `longest` of its units: metres, unless that makes a level longer than [`BARE_LEVEL_MAX_M`];
/// then centimetres (Crytek Sponza's OBJ and GLB, Unreal, Maya and 3ds Max exports), or
/// millimetres where centimetres still do (a level under 100 m modelled in millimetres is
/// read in centimetres, 10× too large: the warning says which units were read). glTF states
/// metres, but exporters write centimetres there too, so a glTF file is read the same way. A
/// scene TOML's `metres_per_unit` chooses.
pub fn bare_mesh_units(longest: f64) -> f64 {
    [1.0, 0.01]
        .into_iter()
        .find(|m| longest * m <= BARE_LEVEL_MAX_M)
        .unwrap_or(0.001)
}

/// The longest side of the box around every vertex of `models`, in their own units (`None`:
/// no finite vertex).
fn longest_extent(models: &[ImportedModel]) -> Option<f64> {
    let mut points = models
        .iter()
        .flat_map(|m| &m.meshes)
        .flat_map(|m| &m.positions)
        .filter(|p| p.is_finite());
    let first = *points.next()?;
    let (lo, hi) = points.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    Some((hi - lo).max_element() as f64)
}

/// What a user reads when a bare mesh is not read in metres.
fn units_warning(path: &Path, longest: f64, metres_per_unit: f64) -> String {
    let unit = if metres_per_unit == 0.01 {
        "centimetres"
    } else {
        "millimetres"
    };
    format!(
        "{}: a bare mesh states no units, and in metres its longest side ({longest:.0} units) \
         would make a {:.1} km level: read in {unit} ({:.1} m). To choose the units, name the \
         mesh in a scene TOML with `metres_per_unit` (README, Scenes)",
        path.display(),
        longest / 1000.0,
        longest * metres_per_unit,
    )
}

impl Scene {
    /// Loads a scene TOML, or a bare OBJ/glTF/GLB file as one static mesh with no lights, in
    /// the units [`bare_mesh_units`] picks from its size.
    pub fn load(path: &Path, options: &ImportOptions) -> Result<Scene, SceneError> {
        let start = Instant::now();
        let (mut desc, base, bare) = match FileKind::of(path) {
            Some(FileKind::SceneToml) => (SceneDesc::read(path)?, parent_dir(path), false),
            Some(FileKind::Obj | FileKind::Gltf) => {
                (SceneDesc::for_mesh_file(path), parent_dir(path), true)
            }
            _ => {
                return Err(SceneError::UnknownFileType {
                    file: path.to_path_buf(),
                });
            }
        };
        let models = desc
            .meshes
            .iter()
            .map(|m| import::import_file(&base.join(&m.path), options))
            .collect::<Result<Vec<_>, _>>()?;
        let mut units_note = None;
        if bare && let Some(longest) = longest_extent(&models) {
            desc.metres_per_unit = bare_mesh_units(longest);
            if desc.metres_per_unit != 1.0 {
                let note = units_warning(path, longest, desc.metres_per_unit);
                tracing::warn!("{note}");
                units_note = Some(note);
            }
        }
        let mut scene = Scene::assemble(&desc, models, path)?;
        scene.report.warnings.extend(units_note);
        scene.report.load_seconds = start.elapsed().as_secs_f64();
        Ok(scene)
    }

    /// Builds a scene from a description and its already imported models (one per
    /// `[[mesh]]`, in order); `file` names the scene in errors. Applies the mesh transforms,
    /// the scene's up axis and units, and the material overrides.
    pub fn assemble(
        desc: &SceneDesc,
        models: Vec<ImportedModel>,
        file: &Path,
    ) -> Result<Scene, SceneError> {
        // A description built in code may still hold its light lines.
        let mut expanded;
        let desc = if desc.light_lines.is_empty() {
            desc
        } else {
            expanded = desc.clone();
            expanded.expand_light_lines(file)?;
            &expanded
        };
        if models.len() != desc.meshes.len() {
            return Err(SceneError::Invalid {
                file: file.to_path_buf(),
                what: format!(
                    "{} meshes described but {} imported",
                    desc.meshes.len(),
                    models.len()
                ),
            });
        }
        let to_world = SceneSpace::new(desc.up, desc.metres_per_unit);
        let mut scene = Scene {
            name: desc.name.clone().unwrap_or_else(|| {
                file.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "scene".into())
            }),
            source: Some(file.to_path_buf()),
            closed: desc.closed,
            meshes: vec![],
            materials: vec![],
            textures: vec![],
            lights: vec![],
            cameras: vec![],
            report: ImportReport::default(),
            animation: Animation::default(),
        };
        for (entry, (mdesc, model)) in desc.meshes.iter().zip(models).enumerate() {
            let local = local_matrix(
                DVec3::from(mdesc.scale.as_vec()),
                DVec3::from(mdesc.rotate_deg),
                DVec3::from(mdesc.translate),
            );
            let m = to_world.matrix * local;
            if !mdesc.animate.is_empty() || mdesc.orbit.is_some() {
                scene.animation.meshes.push(MeshTrack {
                    entry,
                    space: to_world.matrix,
                    scale: DVec3::from(mdesc.scale.as_vec()),
                    rotate_deg: DVec3::from(mdesc.rotate_deg),
                    rest: m,
                    keys: mdesc
                        .animate
                        .iter()
                        .map(|k| (k.t, DVec3::from(k.translate), DVec3::from(k.rotate_deg)))
                        .collect(),
                    orbit: mdesc.orbit.clone(),
                    up: desc.up,
                });
            }
            let normal_m = m.inverse().transpose();
            let flip = m.determinant() < 0.0;
            let mat_base = scene.materials.len() as u32;
            let tex_base = scene.textures.len() as u32;
            scene.report.triangles_read += model.triangles_read;
            scene.report.degenerate_dropped += model.degenerate_dropped;
            scene.report.textures_failed += model.textures_failed;
            scene.report.warnings.extend(model.warnings);
            scene.textures.extend(model.textures);
            scene
                .materials
                .extend(model.materials.into_iter().map(|mut mat| {
                    mat.texture = mat.texture.map(|t| t + tex_base);
                    mat
                }));
            for raw in model.meshes {
                let positions = raw
                    .positions
                    .iter()
                    .map(|p| m.transform_point3(p.as_dvec3()).as_vec3())
                    .collect();
                let normals = raw
                    .normals
                    .iter()
                    .map(|n| {
                        normal_m
                            .transform_vector3(n.as_dvec3())
                            .normalize_or_zero()
                            .as_vec3()
                    })
                    .collect();
                let triangles = raw
                    .triangles
                    .iter()
                    .map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
                    .collect::<Vec<_>>();
                let material = vec![raw.material + mat_base; triangles.len()];
                scene.meshes.push(Mesh {
                    name: raw.name,
                    entry,
                    is_static: mdesc.is_static,
                    positions,
                    normals,
                    uvs: raw.uvs,
                    triangles,
                    material,
                });
            }
        }
        for o in &desc.materials {
            let mut found = false;
            for mat in scene.materials.iter_mut().filter(|m| m.name == o.name) {
                mat.albedo = Vec3::from(o.albedo);
                mat.texture = None;
                found = true;
            }
            if !found {
                let mut known: Vec<&str> =
                    scene.materials.iter().map(|m| m.name.as_str()).collect();
                known.sort_unstable();
                known.dedup();
                return Err(SceneError::UnknownMaterial {
                    file: file.to_path_buf(),
                    name: o.name.clone(),
                    known: known.join(", "),
                });
            }
        }
        for (li, l) in desc.lights.iter().enumerate() {
            let (animate, orbit, target) = match l {
                LightDesc::Point(p) => (&p.animate, &p.orbit, None),
                LightDesc::Spot(s) => (&s.animate, &s.orbit, s.target),
            };
            if !animate.is_empty() || orbit.is_some() {
                scene.animation.lights.push(LightTrack {
                    light: li,
                    space: to_world,
                    keys: animate
                        .iter()
                        .map(|k| (k.t, DVec3::from(k.position), k.target.map(DVec3::from)))
                        .collect(),
                    orbit: orbit.clone(),
                    target: target.map(DVec3::from),
                    up: desc.up,
                });
            }
            scene.lights.push(match l {
                LightDesc::Point(p) => Light::Point {
                    position: to_world.point(p.position),
                    intensity: Vec3::from(p.intensity),
                },
                LightDesc::Spot(s) => {
                    let pos = DVec3::from(s.position);
                    let dir = match (s.target, s.direction) {
                        (Some(t), _) => DVec3::from(t) - pos,
                        (None, Some(d)) => DVec3::from(d),
                        (None, None) => DVec3::NEG_Y,
                    };
                    Light::Spot {
                        position: to_world.point(s.position),
                        direction: to_world.direction(dir),
                        intensity: Vec3::from(s.intensity),
                        cutoff_rad: s.cutoff_deg.to_radians(),
                        beam_rad: s.beam_deg.to_radians(),
                    }
                }
            });
        }
        for c in &desc.cameras {
            let up = match c.up {
                Some(u) => DVec3::from(u),
                None => match desc.up {
                    UpAxis::Y => DVec3::Y,
                    UpAxis::Z => DVec3::Z,
                },
            };
            scene.cameras.push(Camera {
                name: c.name.clone(),
                eye: to_world.point(c.eye),
                target: to_world.point(c.target),
                up: to_world.direction(up),
                fov_x_rad: c.fov_deg.to_radians(),
            });
        }
        if scene.triangle_count() == 0 {
            return Err(SceneError::Empty {
                file: file.to_path_buf(),
            });
        }
        Ok(scene)
    }
}

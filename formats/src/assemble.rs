//! A scene from its description and its imported models: each mesh placed in the world (the
//! mesh transforms, the scene's up axis and units), the material overrides, the lights with
//! their animation tracks, the cameras and the suns.

use std::path::Path;

use glam::{DVec3, Vec3};

use crate::desc::{LightDesc, MeshDesc, SceneDesc, UpAxis};
use crate::error::SceneError;
use crate::import::ImportedModel;
use crate::scene::{
    Animation, Camera, ImportReport, Light, LightTrack, Mesh, MeshTrack, Scene, SceneSpace,
    local_matrix,
};

impl Scene {
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
            scene.add_model(entry, mdesc, model, to_world, desc.up);
        }
        scene.override_materials(desc, file)?;
        scene.add_lights(desc, to_world);
        scene.add_cameras(desc, to_world);
        if scene.triangle_count() == 0 {
            return Err(SceneError::Empty {
                file: file.to_path_buf(),
            });
        }
        let far = crate::placement::far_from_origin(&scene);
        for w in crate::placement::far_placements(&scene, desc)
            .into_iter()
            .chain(far)
        {
            tracing::warn!("{}: {w}", file.display());
            scene.report.warnings.push(w);
        }
        scene.add_suns(desc, to_world, file);
        Ok(scene)
    }

    /// Adds `model`, the import of mesh entry `entry` (`mdesc`), placed in the world: its
    /// transform after the scene's space, its materials and textures after those already in,
    /// its triangles turned where the transform mirrors, its animation track.
    fn add_model(
        &mut self,
        entry: usize,
        mdesc: &MeshDesc,
        model: ImportedModel,
        to_world: SceneSpace,
        up: UpAxis,
    ) {
        let local = local_matrix(
            DVec3::from(mdesc.scale.as_vec()),
            DVec3::from(mdesc.rotate_deg),
            DVec3::from(mdesc.translate),
        );
        let m = to_world.matrix * local;
        if !mdesc.animate.is_empty() || mdesc.orbit.is_some() {
            self.animation.meshes.push(MeshTrack {
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
                up,
            });
        }
        let normal_m = m.inverse().transpose();
        let flip = m.determinant() < 0.0;
        let mat_base = self.materials.len() as u32;
        let tex_base = self.textures.len() as u32;
        let report = &mut self.report;
        report.triangles_read += model.triangles_read;
        report.degenerate_dropped += model.degenerate_dropped;
        report.textures_failed += model.textures_failed;
        report.textures_fitted += model.textures_fitted;
        report.concave_polygons += model.concave_polygons as u64;
        (report.glowing_materials).extend(model.emissive.iter().map(|m| m + mat_base));
        report.warnings.extend(model.warnings);
        self.textures.extend(model.textures);
        self.materials
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
            self.meshes.push(Mesh {
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

    /// The description's material overrides (an albedo, no texture); a name no material has
    /// is an error that lists the names there are.
    fn override_materials(&mut self, desc: &SceneDesc, file: &Path) -> Result<(), SceneError> {
        for o in &desc.materials {
            let mut found = false;
            for mat in self.materials.iter_mut().filter(|m| m.name == o.name) {
                mat.albedo = Vec3::from(o.albedo);
                mat.texture = None;
                found = true;
            }
            if !found {
                let mut known: Vec<&str> = self.materials.iter().map(|m| m.name.as_str()).collect();
                known.sort_unstable();
                known.dedup();
                return Err(SceneError::UnknownMaterial {
                    file: file.to_path_buf(),
                    name: o.name.clone(),
                    known: known.join(", "),
                });
            }
        }
        Ok(())
    }

    /// The description's point and spot lights in the world, with their animation tracks (a
    /// spot aims at its target, else along its direction, else down).
    fn add_lights(&mut self, desc: &SceneDesc, to_world: SceneSpace) {
        for (li, l) in desc.lights.iter().enumerate() {
            let (animate, orbit, target) = match l {
                LightDesc::Point(p) => (&p.animate, &p.orbit, None),
                LightDesc::Spot(s) => (&s.animate, &s.orbit, s.target),
            };
            if !animate.is_empty() || orbit.is_some() {
                self.animation.lights.push(LightTrack {
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
            self.lights.push(match l {
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
    }

    /// The description's cameras in the world (up: the camera's own, else the scene's axis).
    fn add_cameras(&mut self, desc: &SceneDesc, to_world: SceneSpace) {
        for c in &desc.cameras {
            let up = match c.up {
                Some(u) => DVec3::from(u),
                None => match desc.up {
                    UpAxis::Y => DVec3::Y,
                    UpAxis::Z => DVec3::Z,
                },
            };
            self.cameras.push(Camera {
                name: c.name.clone(),
                eye: to_world.point(c.eye),
                target: to_world.point(c.target),
                up: to_world.direction(up),
                fov_x_rad: c.fov_deg.to_radians(),
            });
        }
    }

    /// Suns last, as far spots over the static geometry (crate::sun): their lights' indices
    /// follow the stated lights', which the animation tracks name. The scene has triangles, so
    /// it has bounds.
    fn add_suns(&mut self, desc: &SceneDesc, to_world: SceneSpace, file: &Path) {
        let bounds = (self.static_bounds().or_else(|| self.bounds())).unwrap_or_default();
        for (i, sun) in desc.suns.iter().enumerate() {
            let dir = to_world.direction(DVec3::from(sun.direction));
            let light = crate::sun::sun_spot(bounds, dir, Vec3::from(sun.irradiance));
            let name = (sun.name.clone()).unwrap_or_else(|| format!("sun {}", i + 1));
            let note = crate::sun::placed_note(file, &name, sun.irradiance, &light);
            tracing::warn!("{note}");
            self.report.warnings.push(note);
            self.lights.push(light);
        }
    }
}

//! Mesh import: OBJ through tobj, glTF/GLB through gltf, into plain meshes in file units.
//!
//! Both importers check every vertex for NaN/Inf (an error naming the mesh), every index
//! against the vertex count (an error), drop zero-area triangles (counted, and one warning per
//! file), compute face normals where the file has none, and decode diffuse textures with the
//! `image` crate; a texture that fails to decode is a warning and its material falls back to
//! the albedo.

use std::collections::HashMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::error::SceneError;
pub use crate::import_gltf::import_gltf;
use crate::scene::{FileKind, Material, Texture};

/// Albedo of a triangle with no material: Mitsuba's default diffuse reflectance.
pub const DEFAULT_ALBEDO: f32 = 0.5;

/// Import settings.
#[derive(Debug, Clone, Copy)]
pub struct ImportOptions {
    /// Decode diffuse textures (the bake does not need them).
    pub load_textures: bool,
    /// How a bare mesh file is read where the user says it (a scene TOML states its own).
    pub bare: crate::load::BareMesh,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            load_textures: true,
            bare: crate::load::BareMesh::default(),
        }
    }
}

/// One mesh as read from a file, in the file's own units and axes.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMesh {
    /// An OBJ's object or group name, a glTF node's (its mesh's where the node has none).
    pub name: String,
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position (zero where the file has none).
    pub uvs: Vec<Vec2>,
    /// Non-degenerate triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Index into the model's materials.
    pub material: u32,
}

/// Everything one mesh file holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportedModel {
    /// Meshes, in file order.
    pub meshes: Vec<RawMesh>,
    /// Materials referenced by the meshes.
    pub materials: Vec<Material>,
    /// Decoded textures referenced by the materials.
    pub textures: Vec<Texture>,
    /// Triangles in the file after fan triangulation.
    pub triangles_read: u64,
    /// Zero-area triangles dropped.
    pub degenerate_dropped: u64,
    /// Textures that failed to decode.
    pub textures_failed: u64,
    /// Warnings, in order.
    pub warnings: Vec<String>,
    /// Point and spot lights the file places (glTF's `KHR_lights_punctual`), in its units and
    /// axes ([`crate::gltf_nodes`]); none from an OBJ.
    pub lights: Vec<crate::desc::LightDesc>,
    /// Perspective cameras the file places (glTF), in its units and axes.
    pub cameras: Vec<crate::desc::CameraDesc>,
    /// Directional lights the file places (glTF), in its axes: a bare file's become far spot
    /// lights ([`crate::sun`]).
    pub suns: Vec<crate::sun::SunDesc>,
    /// Indices of the materials that glow (an OBJ's `Ke`, a glTF's emissive factor above 0):
    /// visgate lights by point and spot lights alone, so they add no light of their own.
    pub emissive: Vec<u32>,
    /// The materials that let light through, with their opacity under 1 (an MTL's `d`, or 1 −
    /// its `Tr`; a glTF's base colour alpha where its alpha mode is BLEND, or 1 − its
    /// `KHR_materials_transmission` factor): glass.
    pub see_through: Vec<(u32, f32)>,
    /// The materials cut out by an alpha mask (an MTL's `map_d`; a glTF's alphaMode MASK, or
    /// BLEND with a base colour texture and an opaque factor): drawn whole and opaque.
    pub alpha_masked: Vec<u32>,
    /// Textures filtered down to `scene::MAX_TEXTURE_TEXELS` at import.
    pub textures_fitted: u64,
    /// An OBJ's concave polygons, ear-clipped where tobj would have fanned them (polygons.rs).
    pub concave_polygons: usize,
}

/// Opacity under which a see-through material's surfaces are left out of the level (glass):
/// visgate renders every surface opaque and diffuse, so a window's pane would block all the
/// light that passes it. [Units: ratio]
pub const SEE_THROUGH_OPACITY: f32 = 0.5;

/// Imports an OBJ, glTF or GLB file, chosen by its extension.
pub fn import_file(path: &Path, options: &ImportOptions) -> Result<ImportedModel, SceneError> {
    if !path.is_file() {
        let (kind, words) = if path.is_dir() {
            (
                std::io::ErrorKind::InvalidInput,
                "a folder, not a mesh file",
            )
        } else {
            (std::io::ErrorKind::NotFound, "no such file")
        };
        return Err(SceneError::Io {
            file: path.to_path_buf(),
            error: std::io::Error::new(kind, words),
        });
    }
    let import = match FileKind::of(path) {
        Some(FileKind::Obj) => import_obj,
        Some(FileKind::Gltf) => import_gltf,
        _ => {
            return Err(SceneError::UnknownFileType {
                file: path.to_path_buf(),
            });
        }
    };
    // The parsers are third-party code and some malformed files make them panic (gltf-json
    // 1.4 indexes accessors before checking them): turn that into an error, never a crash.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| import(path, options))).unwrap_or_else(
        |panic| {
            let why = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown reason");
            let message = format!("the file is malformed (the parser failed: {why})");
            Err(match FileKind::of(path) {
                Some(FileKind::Gltf) => SceneError::Gltf {
                    file: path.to_path_buf(),
                    message,
                },
                _ => SceneError::Obj {
                    file: path.to_path_buf(),
                    reason: tobj::LoadError::GenericFailure,
                },
            })
        },
    )
}

fn tobj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        // Polygons are triangulated in polygons.rs: tobj fans them, wrong where concave.
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    }
}

/// Imports an OBJ file and its MTL libraries (relative to the OBJ).
pub fn import_obj(path: &Path, options: &ImportOptions) -> Result<ImportedModel, SceneError> {
    let file = std::fs::File::open(path).map_err(|error| SceneError::Io {
        file: path.to_path_buf(),
        error,
    })?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut reader = std::io::BufReader::with_capacity(1 << 20, file);
    import_obj_reader(path, &mut reader, &dir, options, |mtl| {
        tobj::load_mtl(dir.join(mtl))
    })
}

/// Imports OBJ text from memory; `mtl` supplies the text of each material library it names.
pub fn import_obj_str(
    name: &Path,
    obj: &str,
    mtl: impl Fn(&Path) -> Option<String>,
) -> Result<ImportedModel, SceneError> {
    let mut reader = std::io::Cursor::new(obj.as_bytes());
    let options = ImportOptions {
        load_textures: false,
        ..ImportOptions::default()
    };
    import_obj_reader(name, &mut reader, Path::new("."), &options, |lib| {
        let text = mtl(lib).ok_or(tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut std::io::Cursor::new(text.as_bytes()))
    })
}

fn import_obj_reader(
    path: &Path,
    reader: &mut impl BufRead,
    dir: &Path,
    options: &ImportOptions,
    mtl_loader: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<ImportedModel, SceneError> {
    let (models, materials) =
        tobj::load_obj_buf(reader, &tobj_options(), mtl_loader).map_err(|reason| {
            SceneError::Obj {
                file: path.to_path_buf(),
                reason,
            }
        })?;
    let mut out = ImportedModel::default();
    let materials = materials.unwrap_or_else(|e| {
        out.warnings.push(format!(
            "{}: material library not loaded ({e}); using albedo {DEFAULT_ALBEDO}",
            path.display()
        ));
        vec![]
    });
    // Each material's diffuse map statement (its options, `-s`, `-o`, …, and quotes off the
    // file: mtl_map), whose scale and offset map the coordinates, and its texture's file.
    let maps: Vec<_> = (materials.iter())
        .map(|m| m.diffuse_texture.as_deref().map(crate::mtl_map::parse))
        .collect();
    let files: Vec<Option<PathBuf>> = (maps.iter())
        .map(|m| Some(dir.join(m.as_ref()?.file.replace('\\', "/"))))
        .collect();
    let textures = load_textures(files.iter().flatten(), options.load_textures, &mut out);
    for (m, file) in materials.iter().zip(&files) {
        if m.emissive.is_some_and(|e| e.iter().any(|&c| c > 0.0)) {
            out.emissive.push(out.materials.len() as u32);
        }
        let tr = m
            .unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok());
        let opacity = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
        if opacity < 1.0 {
            out.see_through
                .push((out.materials.len() as u32, opacity.max(0.0)));
        }
        if m.dissolve_texture.is_some() {
            out.alpha_masked.push(out.materials.len() as u32);
        }
        let texture = file.as_ref().and_then(|f| textures.get(f).copied());
        out.materials.push(Material {
            name: m.name.clone(),
            albedo: Vec3::from(m.diffuse.unwrap_or([DEFAULT_ALBEDO; 3])),
            texture,
        });
    }
    let mut default_material = None;
    let library = out.materials.len();
    // The objects whose material the library lacks (tobj gives them none, without a word).
    let mut unmatched = Vec::new();
    for model in models {
        let mesh = &model.mesh;
        let n = mesh.positions.len() / 3;
        let positions: Vec<Vec3> = mesh
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let normals = if mesh.normals.len() == mesh.positions.len() {
            Some(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]).normalize_or_zero())
                    .collect(),
            )
        } else {
            None
        };
        let map = mesh.material_id.and_then(|id| maps.get(id)?.as_ref());
        let uvs = if mesh.texcoords.len() == n * 2 {
            Some(
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|c| map.map_or(Vec2::new(c[0], c[1]), |m| m.map(Vec2::new(c[0], c[1]))))
                    // OBJ's v runs up the image; visgate's texture rows run down.
                    .map(|uv| Vec2::new(uv.x, 1.0 - uv.y))
                    .collect(),
            )
        } else {
            None
        };
        let material = match mesh.material_id {
            Some(id) if id < library => id as u32,
            _ => {
                // tobj splits an object at each `usemtl`: its name once.
                if unmatched.last() != Some(&model.name) {
                    unmatched.push(model.name.clone());
                }
                default_index(&mut default_material, &mut out)
            }
        };
        let (triangles, concave) =
            crate::polygons::triangulate(&positions, &mesh.indices, &mesh.face_arities);
        out.concave_polygons += concave;
        let indices = triangles.iter().map(|&i| i as u64);
        let raw = build_mesh(
            path,
            model.name.clone(),
            positions,
            normals,
            uvs,
            indices,
            material,
            &mut out,
        )?;
        if !raw.triangles.is_empty() {
            out.meshes.push(raw);
        }
    }
    if library > 0 && !unmatched.is_empty() {
        out.warnings.push(unmatched_note(path, &unmatched));
    }
    finish_warnings(path, &mut out);
    Ok(out)
}

/// The index of the OBJ's default material (albedo [`DEFAULT_ALBEDO`]), added at its first
/// use.
fn default_index(default: &mut Option<u32>, out: &mut ImportedModel) -> u32 {
    *default.get_or_insert_with(|| {
        out.materials.push(Material {
            name: "default".into(),
            albedo: Vec3::splat(DEFAULT_ALBEDO),
            texture: None,
        });
        out.materials.len() as u32 - 1
    })
}

/// The note of the OBJ objects that name no material of their library (a `usemtl` the MTL
/// lacks, or none before them), with the first few names.
fn unmatched_note(path: &Path, objects: &[String]) -> String {
    let shown: Vec<_> = objects.iter().take(3).map(|n| format!("'{n}'")).collect();
    let more = match objects.len() - shown.len() {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    let (count, verb) = match objects.len() {
        1 => ("1 object".to_string(), "names"),
        n => (format!("{n} objects"), "name"),
    };
    format!(
        "{}: {count} ({}{more}) {verb} no material of its material library (a `usemtl` the \
         MTL lacks, or none before them): drawn with albedo {DEFAULT_ALBEDO}; check the \
         material names in the OBJ and the MTL",
        path.display(),
        shown.join(", ")
    )
}

/// Whether a triangle has exactly zero area. The cross product is computed in f64, where the
/// products of f32 coordinate differences are exact, so this is an exact test for collinear
/// (or repeated) corners rather than a tolerance.
pub fn is_degenerate(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    (b - a).cross(c - a) == glam::DVec3::ZERO
}

/// Validates and assembles one mesh: finite vertices, indices in range, degenerate triangles
/// dropped, face normals where the file has none.
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_mesh(
    path: &Path,
    name: String,
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    indices: impl Iterator<Item = u64>,
    material: u32,
    out: &mut ImportedModel,
) -> Result<RawMesh, SceneError> {
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(SceneError::NonFinite {
            file: path.to_path_buf(),
            mesh: name,
            vertex,
        });
    }
    let n = positions.len();
    let indices: Vec<u64> = indices.collect();
    if let Some(&index) = indices.iter().find(|&&i| i >= n as u64) {
        return Err(SceneError::IndexOutOfRange {
            file: path.to_path_buf(),
            mesh: name,
            index,
            vertices: n,
        });
    }
    out.triangles_read += (indices.len() / 3) as u64;
    let mut triangles = Vec::with_capacity(indices.len() / 3);
    for t in indices.chunks_exact(3) {
        let t = [t[0] as u32, t[1] as u32, t[2] as u32];
        if is_degenerate(
            positions[t[0] as usize],
            positions[t[1] as usize],
            positions[t[2] as usize],
        ) {
            out.degenerate_dropped += 1;
        } else {
            triangles.push(t);
        }
    }
    let normals = normals.filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
    let uvs = uvs
        .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()))
        .unwrap_or_else(|| vec![Vec2::ZERO; n]);
    match normals {
        Some(normals) => Ok(RawMesh {
            name,
            positions,
            normals,
            uvs,
            triangles,
            material,
        }),
        None => {
            // Face normals: one vertex per triangle corner.
            let mut p = Vec::with_capacity(triangles.len() * 3);
            let mut nn = Vec::with_capacity(triangles.len() * 3);
            let mut uv = Vec::with_capacity(triangles.len() * 3);
            for t in &triangles {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let fnorm = (b - a).cross(c - a).normalize_or_zero();
                for &i in t {
                    p.push(positions[i as usize]);
                    nn.push(fnorm);
                    uv.push(uvs[i as usize]);
                }
            }
            let tris = (0..triangles.len() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect();
            Ok(RawMesh {
                name,
                positions: p,
                normals: nn,
                uvs: uv,
                triangles: tris,
                material,
            })
        }
    }
}

pub(crate) fn finish_warnings(path: &Path, out: &mut ImportedModel) {
    leave_out_see_through(path, out);
    say_alpha_masked(path, out);
    if out.degenerate_dropped > 0 {
        out.warnings.push(format!(
            "{}: dropped {} degenerate (zero-area) triangles of {}",
            path.display(),
            out.degenerate_dropped,
            out.triangles_read
        ));
    }
    for w in &out.warnings {
        tracing::warn!("{w}");
    }
}

/// Leaves the meshes of the materials more see-through than [`SEE_THROUGH_OPACITY`] out of
/// `out` (a window's glass, which would block its light), and says so for each see-through
/// material, left out or kept opaque.
fn leave_out_see_through(path: &Path, out: &mut ImportedModel) {
    for &(material, opacity) in &out.see_through {
        let name = &out.materials[material as usize].name;
        let mine = |m: &RawMesh| m.material == material;
        let triangles: usize = out
            .meshes
            .iter()
            .filter(|m| mine(m))
            .map(|m| m.triangles.len())
            .sum();
        if triangles == 0 {
            continue;
        }
        let (its, block, are) = match triangles {
            1 => ("its triangle".to_string(), "blocks", "is"),
            n => (format!("its {n} triangles"), "block", "are"),
        };
        let note = if opacity < SEE_THROUGH_OPACITY {
            out.meshes.retain(|m| !mine(m));
            format!(
                "{}: material '{name}' is see-through (opacity {opacity:.2}), and visgate \
                 renders every surface opaque: {its} (glass?) {are} left out of the level, so \
                 that light and sight pass there. To keep its surfaces as walls, make the \
                 material opaque (`d 1` in the MTL; in a glTF alphaMode OPAQUE and no \
                 transmission)",
                path.display()
            )
        } else {
            format!(
                "{}: material '{name}' is partly see-through (opacity {opacity:.2}); visgate \
                 renders it opaque, so {its} {block} light as walls do \
                 (under opacity {SEE_THROUGH_OPACITY} they would be left out)",
                path.display()
            )
        };
        out.warnings.push(note);
    }
}

/// Says, once for the file, which materials an alpha mask cuts out (leaves, chains, fences,
/// grates) that it keeps: visgate reads no mask, so their triangles are drawn whole and block
/// light and sight as solid quads, in the bake and in every render alike.
fn say_alpha_masked(path: &Path, out: &mut ImportedModel) {
    let mut names = Vec::new();
    let mut triangles = 0;
    for &material in &out.alpha_masked {
        let mine: usize = (out.meshes.iter())
            .filter(|m| m.material == material)
            .map(|m| m.triangles.len())
            .sum();
        if mine > 0 {
            names.push(format!("'{}'", out.materials[material as usize].name));
            triangles += mine;
        }
    }
    let Some(first) = names.first() else {
        return;
    };
    let (which, are) = match names.len() {
        1 => (format!("material {first} is"), "its"),
        n if n <= 4 => (format!("materials {} are", names.join(", ")), "their"),
        n => (
            format!("{n} materials ({}, …) are", names[..3].join(", ")),
            "their",
        ),
    };
    let (tris, drawn) = match triangles {
        1 => ("triangle", "is"),
        _ => ("triangles", "are"),
    };
    out.warnings.push(format!(
        "{}: {which} cut out by an alpha mask (an MTL's map_d, a glTF's alphaMode MASK), which \
         visgate does not read: {are} {triangles} {tris} {drawn} drawn whole and opaque, so \
         leaves, chains or grates block light and sight as solid quads, in the bake and every \
         render alike. To let light through them instead, mark the material see-through (`d \
         0.4` in the MTL; in a glTF alphaMode BLEND with a base colour alpha under 0.5) and \
         visgate leaves them out",
        path.display()
    ));
}

/// A texture decoded and fitted (`Texture::fitted`: whether it was filtered down), or why not.
pub(crate) type Decoded = Result<(Texture, bool), String>;

/// The texture file at `path`, decoded and fitted.
fn decode_file(path: &Path) -> Decoded {
    let img = image::open(path).map_err(|e| e.to_string())?;
    let rgba = img.to_rgba8();
    let (w, h) = (rgba.width(), rgba.height());
    Ok(Texture::fitted(
        path.display().to_string(),
        w,
        h,
        rgba.into_raw(),
    ))
}

/// Each of `paths` decoded once, all in parallel (a level's textures one at a time took most
/// of its load: twenty 4K textures 2.9 s on 2 cores, 1.6 s so), kept in `out` in path order or
/// said where one fails; each path's texture. Nothing where `enabled` is false.
fn load_textures<'a>(
    paths: impl Iterator<Item = &'a PathBuf>,
    enabled: bool,
    out: &mut ImportedModel,
) -> HashMap<PathBuf, u32> {
    let mut paths: Vec<&PathBuf> = paths.filter(|_| enabled).collect();
    paths.sort();
    paths.dedup();
    let decoded: Vec<Decoded> = paths.par_iter().map(|p| decode_file(p)).collect();
    let mut index = HashMap::new();
    for (path, decoded) in paths.into_iter().zip(decoded) {
        match decoded {
            Ok(texture) => {
                index.insert(path.clone(), out.keep_texture(texture));
            }
            Err(e) => {
                out.textures_failed += 1;
                out.warnings.push(format!(
                    "texture {} not loaded ({e}); its materials use their albedo",
                    path.display()
                ));
            }
        }
    }
    index
}

impl ImportedModel {
    /// Keeps a decoded texture (`Texture::fitted`'s, counted where it was filtered down);
    /// its index.
    pub(crate) fn keep_texture(&mut self, (texture, fitted): (Texture, bool)) -> u32 {
        self.textures_fitted += u64::from(fitted);
        self.textures.push(texture);
        self.textures.len() as u32 - 1
    }
}

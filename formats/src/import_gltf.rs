//! glTF 2.0 import (`.gltf` with external or embedded buffers, or `.glb`) through the `gltf`
//! crate: its images as textures, its materials, and its default scene's node hierarchy
//! walked with the node transforms applied; the checks are import.rs's.

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};
use rayon::prelude::*;

use crate::error::SceneError;
use crate::gltf_quantized::{self, QUANTIZATION};
use crate::import::{
    DEFAULT_ALBEDO, Decoded, ImportOptions, ImportedModel, RawMesh, SEE_THROUGH_OPACITY,
    build_mesh, finish_warnings,
};
use crate::scene::{Material, Texture};

/// Where the file at `path` requires extensions that the gltf crate does not read, the
/// error that names them and what they are; `None` where it requires none such or cannot be
/// read without validation either (the crate's own error then stands).
fn unread_extensions(path: &Path) -> Option<SceneError> {
    let bytes = std::fs::read(path).ok()?;
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).ok()?;
    let read = gltf::json::extensions::ENABLED_EXTENSIONS;
    let extensions: Vec<String> = gltf
        .extensions_required()
        .filter(|e| !read.contains(e) && *e != QUANTIZATION)
        .map(str::to_string)
        .collect();
    let what = |e: &String| match e.as_str() {
        "KHR_draco_mesh_compression" => "Draco-compressed meshes",
        "EXT_meshopt_compression" => "meshoptimizer-compressed buffers",
        "KHR_texture_basisu" => "KTX2 / Basis Universal textures",
        _ => "not read by the gltf crate",
    };
    let what: Vec<&str> = extensions.iter().map(what).collect();
    (!extensions.is_empty()).then(|| SceneError::GltfExtensions {
        file: path.to_path_buf(),
        what: what.join("; "),
        extensions,
    })
}

/// Imports a glTF 2.0 file (`.gltf` with external or embedded buffers, or `.glb`), walking
/// the default scene's node hierarchy and applying node transforms.
pub fn import_gltf(path: &Path, options: &ImportOptions) -> Result<ImportedModel, SceneError> {
    let gerr = |e: gltf::Error| SceneError::Gltf {
        file: path.to_path_buf(),
        message: e.to_string(),
    };
    // A file that requires KHR_mesh_quantization validates without it (gltf_quantized).
    let opened = gltf::Gltf::open(path)
        .or_else(|e| gltf_quantized::open(path).ok_or(e))
        .map_err(|e| unread_extensions(path).unwrap_or_else(|| gerr(e)));
    let gltf::Gltf { document, blob } = opened?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(gerr)?;
    let mut out = ImportedModel::default();
    let file = File {
        path,
        buffers: &buffers,
    };
    let image_texture = textures(&document, &file, base, options, &mut out);
    let uv_maps = materials(&document, &image_texture, &mut out);
    let default_material = out.materials.len() as u32;
    let mut needs_default = false;

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    // Lights and cameras in the file's node order, on a walk of their own: the mesh walk below
    // pops a stack, and its order is the one the meshes (and baked levels' hashes) keep.
    if let Some(s) = &scene {
        crate::gltf_nodes::read_nodes(path, s, &mut out);
    }
    let mut stack: Vec<(gltf::Node, Mat4)> = match &scene {
        Some(s) => s.nodes().map(|n| (n, Mat4::IDENTITY)).collect(),
        None => vec![],
    };
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        for child in node.children() {
            stack.push((child, world));
        }
        let Some(mesh) = node.mesh() else { continue };
        let mname = mesh
            .name()
            .or(node.name())
            .map(str::to_string)
            .unwrap_or_else(|| format!("mesh {}", mesh.index()));
        // The object as a modelling tool names it (Blender's object, a game engine's actor):
        // the node, or its mesh where the node has no name.
        let object = node.name().unwrap_or(&mname);
        for prim in mesh.primitives() {
            let material = prim.material().index().map(|i| i as u32);
            let placed = Placed {
                name: &mname,
                object,
                world,
                material: material.unwrap_or(default_material),
                uv_map: material.map_or(UvMap::default(), |m| {
                    uv_maps.get(m as usize).copied().unwrap_or_default()
                }),
            };
            // A primitive read (not skipped) without a material takes the default one.
            let Some(raw) = primitive(&file, &prim, &placed, &mut out)? else {
                continue;
            };
            needs_default |= material.is_none();
            if !raw.triangles.is_empty() {
                out.meshes.push(raw);
            }
        }
    }
    if needs_default {
        out.materials.push(Material {
            name: "default".into(),
            albedo: Vec3::splat(DEFAULT_ALBEDO),
            texture: None,
        });
    }
    finish_warnings(path, &mut out);
    Ok(out)
}

/// The file being read: its path (for messages) and its buffers.
struct File<'a> {
    path: &'a Path,
    buffers: &'a [gltf::buffer::Data],
}

/// Where a primitive goes: its mesh's name, its node's world transform, its material.
struct Placed<'a> {
    /// The mesh's name (its node's where it has none), as the warnings name it.
    name: &'a str,
    /// The object's: the node's name, or the mesh's ([`RawMesh::name`]).
    object: &'a str,
    world: Mat4,
    material: u32,
    /// How its material's base colour texture maps it.
    uv_map: UvMap,
}

/// How a material's base colour texture is mapped: the coordinate set it reads (its
/// `texCoord`, or KHR_texture_transform's override) and the transform, if any.
#[derive(Debug, Clone, Copy, Default)]
struct UvMap {
    set: u32,
    transform: Option<Mat3>,
}

/// The file's images as textures, each image's texture index (`None` where textures are not
/// loaded or it failed: a warning, and its materials use their albedo).
fn textures(
    document: &gltf::Document,
    file: &File,
    base: &Path,
    options: &ImportOptions,
    out: &mut ImportedModel,
) -> Vec<Option<u32>> {
    let mut image_texture: Vec<Option<u32>> = Vec::new();
    if !options.load_textures {
        return document.images().map(|_| None).collect();
    }
    // Decoded and fitted in parallel, as an OBJ's (import.rs's load_textures).
    let images: Vec<gltf::Image> = document.images().collect();
    let decoded: Vec<(String, Decoded)> = (images.par_iter())
        .map(|image| {
            let name = match image.source() {
                gltf::image::Source::Uri { uri, .. } => uri.to_string(),
                gltf::image::Source::View { .. } => {
                    format!("image {} (embedded)", image.index())
                }
            };
            let decoded = gltf::image::Data::from_source(image.source(), Some(base), file.buffers)
                .map_err(|e| e.to_string())
                .and_then(|d| gltf_image_rgba8(&d).map(|px| (d.width, d.height, px)))
                .map(|(w, h, px)| Texture::fitted(name.clone(), w, h, px));
            (name, decoded)
        })
        .collect();
    for (name, decoded) in decoded {
        match decoded {
            Ok(texture) => image_texture.push(Some(out.keep_texture(texture))),
            Err(e) => {
                out.textures_failed += 1;
                out.warnings.push(format!(
                    "{}: texture '{name}' not loaded ({e}); its materials use their albedo",
                    file.path.display()
                ));
                image_texture.push(None);
            }
        }
    }
    image_texture
}

/// The file's materials: the base colour (or the specular-glossiness diffuse where the base
/// colour is left white) and its texture; an emissive one is noted as glowing. Returns how
/// each material's base colour texture is mapped (its coordinate set; its
/// KHR_texture_transform, with which gltfpack scales its quantized coordinates back).
fn materials(
    document: &gltf::Document,
    image_texture: &[Option<u32>],
    out: &mut ImportedModel,
) -> Vec<UvMap> {
    let mut uv_maps = Vec::new();
    for m in document.materials() {
        if m.emissive_factor().iter().any(|&c| c > 0.0) {
            out.emissive.push(out.materials.len() as u32);
        }
        let pbr = m.pbr_metallic_roughness();
        let base_color = pbr.base_color_factor();
        // Glass: blended under an alpha below 1, or transmitting (KHR_materials_transmission,
        // as Blender exports a Principled BSDF's transmission).
        let blended = m.alpha_mode() == gltf::material::AlphaMode::Blend;
        let alpha = if blended { base_color[3] } else { 1.0 };
        let transmits = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let opacity = alpha.min(1.0 - transmits).max(0.0);
        if opacity < 1.0 {
            (out.see_through).push((out.materials.len() as u32, opacity));
        }
        // Cut out by its texture's alpha: a mask, or a blend whose factor is opaque enough to
        // be kept (glass is left out above).
        let masked = match m.alpha_mode() {
            gltf::material::AlphaMode::Mask => true,
            gltf::material::AlphaMode::Blend => {
                opacity >= SEE_THROUGH_OPACITY && pbr.base_color_texture().is_some()
            }
            gltf::material::AlphaMode::Opaque => false,
        };
        if masked {
            out.alpha_masked.push(out.materials.len() as u32);
        }
        let mut uv_map = pbr.base_color_texture().map_or(UvMap::default(), |t| {
            let transform = t.texture_transform();
            UvMap {
                set: (transform.as_ref().and_then(|t| t.tex_coord())).unwrap_or(t.tex_coord()),
                transform: transform.map(|t| gltf_quantized::uv_transform(&t)),
            }
        });
        let mut texture = pbr
            .base_color_texture()
            .map(|t| t.texture().source().index());
        let mut albedo = Vec3::new(base_color[0], base_color[1], base_color[2]);
        if let Some(sg) = m.pbr_specular_glossiness() {
            let d = sg.diffuse_factor();
            if base_color == [1.0; 4] {
                albedo = Vec3::new(d[0], d[1], d[2]);
            }
            if let (None, Some(t)) = (texture, sg.diffuse_texture()) {
                texture = Some(t.texture().source().index());
                uv_map.set = t.tex_coord();
            }
        }
        out.materials.push(Material {
            name: m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0))),
            albedo,
            texture: texture.and_then(|i| image_texture.get(i).copied().flatten()),
        });
        uv_maps.push(uv_map);
    }
    uv_maps
}

/// One primitive as a mesh in the world (strips and fans as lists, turned where the transform
/// mirrors); `None`, with a warning, where it is not triangles or has no positions.
fn primitive(
    file: &File,
    prim: &gltf::Primitive,
    placed: &Placed,
    out: &mut ImportedModel,
) -> Result<Option<RawMesh>, SceneError> {
    let (path, mname, world) = (file.path, placed.name, placed.world);
    let mode = prim.mode();
    if !matches!(
        mode,
        gltf::mesh::Mode::Triangles
            | gltf::mesh::Mode::TriangleStrip
            | gltf::mesh::Mode::TriangleFan
    ) {
        out.warnings.push(format!(
            "{}: mesh '{mname}' has a {mode:?} primitive, which is not triangles; skipped",
            path.display()
        ));
        return Ok(None);
    }
    let reader = prim.reader(|b| file.buffers.get(b.index()).map(|d| d.0.as_slice()));
    let attribute = |semantic: gltf::Semantic| prim.get(&semantic);
    let Some(pos) = attribute(gltf::Semantic::Positions) else {
        out.warnings.push(format!(
            "{}: mesh '{mname}' has a primitive without positions; skipped",
            path.display()
        ));
        return Ok(None);
    };
    let quantized = |e: String| SceneError::Gltf {
        file: path.to_path_buf(),
        message: format!("mesh '{mname}': {e}"),
    };
    // Floats through the crate's readers; quantized integers (KHR_mesh_quantization) read here.
    let floats = |a: &gltf::Accessor, uv| gltf_quantized::crate_reads(a, uv);
    // The crate's readers asked only for what they read: a debug build asserts the type.
    let positions: Vec<[f32; 3]> = match floats(&pos, false) {
        true => (reader.read_positions().into_iter().flatten()).collect(),
        false => gltf_quantized::read(&pos, file.buffers).map_err(quantized)?,
    };
    let normal_m = world.inverse().transpose();
    let positions: Vec<Vec3> = (positions.into_iter())
        .map(|p| world.transform_point3(Vec3::from(p)))
        .collect();
    let normals = match attribute(gltf::Semantic::Normals) {
        Some(a) if floats(&a, false) => reader.read_normals().map(Iterator::collect),
        Some(a) => Some(gltf_quantized::read::<3>(&a, file.buffers).map_err(quantized)?),
        None => None,
    };
    let normals = normals.map(|n: Vec<[f32; 3]>| {
        (n.into_iter())
            .map(|n| {
                normal_m
                    .transform_vector3(Vec3::from(n))
                    .normalize_or_zero()
            })
            .collect::<Vec<_>>()
    });
    let set = placed.uv_map.set;
    let uvs = match attribute(gltf::Semantic::TexCoords(set)) {
        Some(a) if floats(&a, true) => {
            (reader.read_tex_coords(set)).map(|it| it.into_f32().collect())
        }
        Some(a) => Some(gltf_quantized::read::<2>(&a, file.buffers).map_err(quantized)?),
        None => None,
    };
    let uvs = uvs.map(|uv: Vec<[f32; 2]>| {
        let t = placed.uv_map.transform.unwrap_or(Mat3::IDENTITY);
        (uv.into_iter())
            .map(|uv| t.transform_point2(Vec2::from(uv)))
            .collect::<Vec<_>>()
    });
    let list: Vec<u64> = match reader.read_indices() {
        Some(ix) => ix.into_u32().map(u64::from).collect(),
        None => (0..positions.len() as u64).collect(),
    };
    let list = match mode {
        gltf::mesh::Mode::TriangleStrip => strip_to_list(&list),
        gltf::mesh::Mode::TriangleFan => fan_to_list(&list),
        _ => list,
    };
    let list = if world.determinant() < 0.0 {
        list.chunks_exact(3)
            .flat_map(|t| [t[0], t[2], t[1]])
            .collect()
    } else {
        list
    };
    let raw = build_mesh(
        path,
        mname.to_string(),
        positions,
        normals,
        uvs,
        list.into_iter(),
        placed.material,
        out,
    )?;
    // Errors above name the mesh; the level knows it as its object.
    Ok(Some(RawMesh {
        name: placed.object.to_string(),
        ..raw
    }))
}

/// An image's pixels as RGBA8 (grey and grey-alpha spread, RGB made opaque).
fn gltf_image_rgba8(d: &gltf::image::Data) -> Result<Vec<u8>, String> {
    use gltf::image::Format;
    let px = &d.pixels;
    Ok(match d.format {
        Format::R8G8B8A8 => px.clone(),
        Format::R8G8B8 => px
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        Format::R8G8 => px
            .chunks_exact(2)
            .flat_map(|c| [c[0], c[0], c[0], c[1]])
            .collect(),
        Format::R8 => px.iter().flat_map(|&c| [c, c, c, 255]).collect(),
        other => return Err(format!("pixel format {other:?} is not supported")),
    })
}

/// A triangle strip's indices as a list (every other triangle turned back).
fn strip_to_list(ix: &[u64]) -> Vec<u64> {
    let mut out = Vec::new();
    for i in 2..ix.len() {
        if i % 2 == 0 {
            out.extend([ix[i - 2], ix[i - 1], ix[i]]);
        } else {
            out.extend([ix[i - 1], ix[i - 2], ix[i]]);
        }
    }
    out
}

/// A triangle fan's indices as a list.
fn fan_to_list(ix: &[u64]) -> Vec<u64> {
    let mut out = Vec::new();
    for i in 2..ix.len() {
        out.extend([ix[0], ix[i - 1], ix[i]]);
    }
    out
}

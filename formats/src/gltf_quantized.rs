//! `KHR_mesh_quantization`: vertex attributes stored as 8- or 16-bit integers, as gltfpack
//! writes them by default (positions as integers that the node's transform scales back,
//! normals as normalized bytes, texture coordinates as integers that the material's
//! `KHR_texture_transform` scales back). The gltf crate validates such a file away
//! ("Unsupported extension") and its readers take positions and normals as floats only, so
//! visgate opens the file with the extension taken out of its required list and reads these
//! accessors itself, dequantized as the extension's specification has it.

use std::path::Path;

use glam::{Mat3, Vec2};
use gltf::accessor::DataType;

/// The extension this module reads.
pub(crate) const QUANTIZATION: &str = "KHR_mesh_quantization";

/// The file at `path` opened with [`QUANTIZATION`] taken out of its required extensions and
/// then validated; `None` where it does not require it or does not validate without it (the
/// first error then stands).
pub(crate) fn open(path: &Path) -> Option<gltf::Gltf> {
    let bytes = std::fs::read(path).ok()?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(&bytes).ok()?;
    let mut root = document.into_json();
    let before = root.extensions_required.len();
    root.extensions_required.retain(|e| e != QUANTIZATION);
    if root.extensions_required.len() == before {
        return None;
    }
    let document = gltf::Document::from_json(root).ok()?;
    Some(gltf::Gltf { document, blob })
}

/// Whether the gltf crate's readers take accessor `a` as it is: floats (or, for texture
/// coordinates, `uv`, also normalized unsigned bytes and shorts).
pub(crate) fn crate_reads(a: &gltf::Accessor, uv: bool) -> bool {
    match a.data_type() {
        DataType::F32 => true,
        DataType::U8 | DataType::U16 => uv && a.normalized(),
        _ => false,
    }
}

/// Accessor `a`'s elements, each of its first `N` components as a float: a normalized integer
/// as the extension maps it (c / 127 for a signed byte, at least −1; c / 255 unsigned; c /
/// 32767 and c / 65535 for shorts), another as its value. An error for a sparse accessor, a
/// component count under `N`, or bytes past the end of its buffer.
pub(crate) fn read<const N: usize>(
    a: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<[f32; N]>, String> {
    if a.sparse().is_some() {
        return Err(format!("accessor {} is sparse", a.index()));
    }
    let dims = a.dimensions().multiplicity();
    if dims < N {
        return Err(format!(
            "accessor {} has {dims} components, not {N}",
            a.index()
        ));
    }
    let Some(view) = a.view() else {
        return Ok(vec![[0.0; N]; a.count()]);
    };
    let data = &buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("accessor {}'s buffer is missing", a.index()))?
        .0;
    let (kind, normalized) = (a.data_type(), a.normalized());
    let size = kind.size();
    let stride = view.stride().unwrap_or(size * dims);
    let start = view.offset() + a.offset();
    let component = |at: usize| -> Option<f32> {
        let b = data.get(at..at + size)?;
        Some(match kind {
            DataType::I8 => dequantize(f32::from(b[0] as i8), normalized, 127.0, true),
            DataType::U8 => dequantize(f32::from(b[0]), normalized, 255.0, false),
            DataType::I16 => {
                let c = f32::from(i16::from_le_bytes([b[0], b[1]]));
                dequantize(c, normalized, 32767.0, true)
            }
            DataType::U16 => {
                let c = f32::from(u16::from_le_bytes([b[0], b[1]]));
                dequantize(c, normalized, 65535.0, false)
            }
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        })
    };
    (0..a.count())
        .map(|i| {
            let mut out = [0.0; N];
            for (j, o) in out.iter_mut().enumerate() {
                *o = component(start + i * stride + j * size).ok_or_else(|| {
                    format!("accessor {} reads past the end of its buffer", a.index())
                })?;
            }
            Ok(out)
        })
        .collect()
}

/// Integer component `c`, mapped to [−1, 1] or [0, 1] by `max` where `normalized`.
fn dequantize(c: f32, normalized: bool, max: f32, signed: bool) -> f32 {
    match (normalized, signed) {
        (false, _) => c,
        (true, true) => (c / max).max(-1.0),
        (true, false) => c / max,
    }
}

/// A material's base colour `KHR_texture_transform` as a matrix on texture coordinates
/// (translation × rotation × scale, as the extension's specification composes them).
pub(crate) fn uv_transform(t: &gltf::texture::TextureTransform) -> Mat3 {
    affine(t.offset(), t.rotation(), t.scale())
}

/// [`uv_transform`] of these values.
fn affine([ox, oy]: [f32; 2], rotation: f32, [sx, sy]: [f32; 2]) -> Mat3 {
    let (s, c) = rotation.sin_cos();
    let translation = Mat3::from_translation(Vec2::new(ox, oy));
    // The specification's GLSL, column by column: mat3(cos, sin, 0, −sin, cos, 0, 0, 0, 1).
    let rotation = Mat3::from_cols_array(&[c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0]);
    translation * rotation * Mat3::from_scale(Vec2::new(sx, sy))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_dequantize_as_the_extension_has_them() {
        assert_eq!(dequantize(-128.0, true, 127.0, true), -1.0);
        assert_eq!(dequantize(127.0, true, 127.0, true), 1.0);
        assert_eq!(dequantize(65535.0, true, 65535.0, false), 1.0);
        assert_eq!(dequantize(300.0, false, 65535.0, false), 300.0);
    }

    #[test]
    fn the_texture_transform_composes_as_the_specification_s_glsl() {
        // A quarter turn takes (1, 0) to (cos, sin) = (0, 1) (the GLSL's first column), then
        // scales before it and offsets after.
        let m = affine([0.5, 0.0], std::f32::consts::FRAC_PI_2, [2.0, 2.0]);
        let uv = m.transform_point2(Vec2::new(1.0, 0.0));
        assert!(uv.distance(Vec2::new(0.5, 2.0)) < 1e-6, "{uv}");
    }
}

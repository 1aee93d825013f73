//! Image error metrics against a reference: MSE, relative MSE, FLIP (NVIDIA's perceptual
//! difference, LDR version, on the sRGB pictures at one exposure) and per-pixel maps.

use glam::Vec3;

use crate::RenderError;
use crate::hdr::HdrImage;

/// Errors of an image against a reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageErrors {
    /// Mean over pixels and channels of `(a − r)²`. [Units: radiance²]
    pub mse: f64,
    /// Mean over pixels and channels of `(a − r)² / (r² + ε)`, `ε = 1e-2 · mean(r)²`.
    pub rel_mse: f64,
    /// Mean of the reference. [Units: radiance]
    pub reference_mean: f64,
    /// Mean of the image. [Units: radiance]
    pub image_mean: f64,
}

fn same_size(a: &HdrImage, r: &HdrImage) -> Result<(), RenderError> {
    if (a.width, a.height) != (r.width, r.height) {
        return Err(RenderError::Param(format!(
            "images differ in size: {}x{} vs {}x{}",
            a.width, a.height, r.width, r.height
        )));
    }
    Ok(())
}

/// MSE and relative MSE of `a` against reference `r`.
pub fn errors(a: &HdrImage, r: &HdrImage) -> Result<ImageErrors, RenderError> {
    same_size(a, r)?;
    let n = (a.pixels.len() * 3).max(1) as f64;
    // Mean over pixels and channels.
    let mean = |img: &HdrImage| {
        img.pixels
            .iter()
            .map(|p| (p.x + p.y + p.z) as f64)
            .sum::<f64>()
            / n
    };
    let (mean_r, mean_a) = (mean(r), mean(a));
    let eps = 1e-2 * mean_r * mean_r + f64::MIN_POSITIVE;
    let (mut mse, mut rel) = (0f64, 0f64);
    for (p, q) in a.pixels.iter().zip(&r.pixels) {
        for k in 0..3 {
            let d = (p[k] - q[k]) as f64;
            mse += d * d;
            rel += d * d / ((q[k] as f64).powi(2) + eps);
        }
    }
    Ok(ImageErrors {
        mse: mse / n,
        rel_mse: rel / n,
        reference_mean: mean_r,
        image_mean: mean_a,
    })
}

/// Per-pixel absolute error, averaged over channels.
pub fn abs_error_map(a: &HdrImage, r: &HdrImage) -> Result<Vec<f32>, RenderError> {
    same_size(a, r)?;
    Ok(a.pixels
        .iter()
        .zip(&r.pixels)
        .map(|(p, q)| ((*p - *q).abs()).dot(Vec3::ONE) / 3.0)
        .collect())
}

/// LDR-FLIP of `a` against reference `r`, both tone mapped at `exposure_stops`: the mean
/// (FLIP's recommended single number, 0 = identical, 1 = maximal) and the per-pixel map.
pub fn flip(
    a: &HdrImage,
    r: &HdrImage,
    exposure_stops: f32,
) -> Result<(f32, Vec<f32>), RenderError> {
    same_size(a, r)?;
    let to_flip = |img: &HdrImage| {
        let rgb = img.to_srgb8(exposure_stops);
        nv_flip::FlipImageRgb8::with_data(img.width, img.height, rgb.as_raw())
    };
    let map = nv_flip::flip(to_flip(r), to_flip(a), nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let pool = nv_flip::FlipPool::from_image(&map);
    Ok((pool.mean(), map.to_vec()))
}

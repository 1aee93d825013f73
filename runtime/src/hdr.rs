//! Linear HDR images: EXR in and out (comparison), sRGB PNG out (looking), a false-colour map.
//!
//! PNG output is tone mapped by exposure only (`2^stops`), clamped, then sRGB-encoded: no curve
//! hides an error.

use std::path::Path;

use glam::Vec3;
use image::{ImageBuffer, Rgb, Rgb32FImage, RgbImage};

use crate::RenderError;

/// A linear RGB image, row 0 at the top. [Units: W/(m²·sr) per channel]
#[derive(Debug, Clone, PartialEq)]
pub struct HdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Vec3>,
}

impl HdrImage {
    /// A black image.
    pub fn new(width: u32, height: u32) -> HdrImage {
        HdrImage {
            width,
            height,
            pixels: vec![Vec3::ZERO; (width * height) as usize],
        }
    }

    /// Pixel at `(x, y)`.
    pub fn at(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Mean of all pixels.
    pub fn mean(&self) -> Vec3 {
        let s: glam::DVec3 = self.pixels.iter().map(|p| p.as_dvec3()).sum();
        (s / self.pixels.len().max(1) as f64).as_vec3()
    }

    /// Writes a 32-bit float EXR.
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        let buf: Rgb32FImage = ImageBuffer::from_fn(self.width, self.height, |x, y| {
            Rgb(self.at(x, y).to_array())
        });
        buf.save(path).map_err(|e| RenderError::io(path, e))
    }

    /// Reads an EXR (or any float image `image` reads) as linear RGB.
    pub fn read(path: &Path) -> Result<HdrImage, RenderError> {
        let img = image::open(path).map_err(|e| RenderError::io(path, e))?;
        let f = img.to_rgb32f();
        Ok(HdrImage {
            width: f.width(),
            height: f.height(),
            pixels: f.pixels().map(|p| Vec3::from(p.0)).collect(),
        })
    }

    /// The sRGB 8-bit picture at `exposure_stops`.
    pub fn to_srgb8(&self, exposure_stops: f32) -> RgbImage {
        let k = 2f32.powf(exposure_stops);
        ImageBuffer::from_fn(self.width, self.height, |x, y| {
            let c = self.at(x, y) * k;
            Rgb(c.to_array().map(|v| (srgb_encode(v) * 255.0 + 0.5) as u8))
        })
    }

    /// Writes the sRGB PNG at `exposure_stops`.
    pub fn write_png(&self, path: &Path, exposure_stops: f32) -> Result<(), RenderError> {
        self.to_srgb8(exposure_stops)
            .save(path)
            .map_err(|e| RenderError::io(path, e))
    }

    /// Writes EXR or PNG by the path's extension.
    pub fn write(&self, path: &Path, exposure_stops: f32) -> Result<(), RenderError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref()
        {
            Some("exr") => self.write_exr(path),
            Some("png") => self.write_png(path, exposure_stops),
            _ => Err(RenderError::Param(format!(
                "{}: write .exr (linear radiance) or .png (sRGB)",
                path.display()
            ))),
        }
    }
}

/// sRGB encoding of a linear value, clamped to [0, 1].
pub fn srgb_encode(v: f32) -> f32 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A false-colour picture of per-pixel values in `[0, max]` (black → blue → green → yellow →
/// red → white).
pub fn false_colour(values: &[f32], width: u32, height: u32, max: f32) -> RgbImage {
    const STOPS: [[f32; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    ImageBuffer::from_fn(width, height, |x, y| {
        let v = values[(y * width + x) as usize];
        let t = if max > 0.0 && v.is_finite() {
            (v / max).clamp(0.0, 1.0) * 5.0
        } else {
            0.0
        };
        let i = (t.floor() as usize).min(4);
        let f = t - i as f32;
        let c: [f32; 3] = std::array::from_fn(|k| STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f);
        Rgb(c.map(|v| (v * 255.0 + 0.5) as u8))
    })
}

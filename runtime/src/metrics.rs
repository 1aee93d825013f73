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
    /// Mean over pixels and channels of `(a − r)² / (r² + ε)`, `ε = 1e-2 · mean(r)²` (where
    /// the reference is black, `1e-2 · mean(a)²`: finite, and 0 where both are black).
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
    // A black reference (a view its light does not reach) divided by ε alone gave 1e297.
    let scale = if mean_r > 0.0 { mean_r } else { mean_a };
    let eps = 1e-2 * scale * scale + f64::MIN_POSITIVE;
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

/// How an image's indirect light (the image less the direct light) compares with the
/// reference's: the failures a mean error hides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IndirectErrors {
    /// Mean indirect radiance over the reference's (1: no energy lost or gained).
    pub energy_ratio: f64,
    /// Of the pixels whose reference indirect light is at least a tenth of its mean, the share
    /// where the image's is under a tenth of the reference's there: black where it is lit.
    /// Pixels whose reference samples saw more than one surface are left out
    /// ([`IndirectMap::leave_out_mixed`]).
    pub black_where_lit: f64,
    /// [`IndirectErrors::black_where_lit`] over every pixel, the mixed ones too.
    pub black_where_lit_all: f64,
    /// The pixels [`IndirectErrors::black_where_lit`] is a share of: lit, not mixed (a share of
    /// a few hundred, in a dark view, moves by whole percents with a line of pixels).
    pub lit_pixels: u64,
}

/// [`IndirectErrors`] of `a` against reference `r`, both less the direct light `direct`.
pub fn indirect_errors(
    a: &HdrImage,
    r: &HdrImage,
    direct: &HdrImage,
) -> Result<IndirectErrors, RenderError> {
    Ok(indirect_map(a, r, direct)?.errors())
}

/// What the reference's indirect light says of a pixel, and the image's there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lit {
    /// The reference's indirect light is under a tenth of its mean (or none): not counted.
    Not,
    /// Lit, and the image's indirect light is at least a tenth of the reference's.
    Lit,
    /// Lit, and the image's is under a tenth of it: black where it is lit.
    Black,
}

/// Per pixel, [`Lit`], with the indirect images' means.
pub struct IndirectMap {
    /// Each pixel's class, rows from the top.
    pub class: Vec<Lit>,
    /// The pixels left out of [`IndirectErrors::black_where_lit`]: those where the reference's
    /// pixel samples saw more than one surface (empty: none).
    pub mixed: Vec<bool>,
    /// Mean indirect light (r + g + b) of the image.
    pub mean_a: f64,
    /// Mean indirect light (r + g + b) of the reference.
    pub mean_r: f64,
}

/// The black map's colour of a pixel black where lit but left out as mixed (dark yellow).
pub const MIXED_BLACK: [u8; 3] = [150, 120, 0];

impl IndirectMap {
    /// Leaves the pixels where `mixed` is true out of the black-where-lit share: a pixel whose
    /// reference samples saw several surfaces (a silhouette, a crease) or albedos tenfold apart
    /// ([`crate::cpu::reference::mixed_pixels`]) averages their light,
    /// where a method that shades one point a pixel sees one of them, and the darker one's
    /// indirect light may be under a tenth of the average with no visibility error at all.
    pub fn leave_out_mixed(mut self, mixed: Vec<bool>) -> Result<IndirectMap, RenderError> {
        if !mixed.is_empty() && mixed.len() != self.class.len() {
            return Err(RenderError::Param(format!(
                "a mask of {} pixels for an image of {}",
                mixed.len(),
                self.class.len()
            )));
        }
        self.mixed = mixed;
        Ok(self)
    }

    /// Whether pixel `i` is left out as mixed.
    fn is_mixed(&self, i: usize) -> bool {
        self.mixed.get(i).copied().unwrap_or(false)
    }

    /// The energy ratio and the black-where-lit shares.
    pub fn errors(&self) -> IndirectErrors {
        // Lit and black pixels: [left in, every one].
        let (mut lit, mut black) = ([0usize; 2], [0usize; 2]);
        for (i, c) in self.class.iter().enumerate() {
            if *c != Lit::Not {
                for (k, counted) in [!self.is_mixed(i), true].into_iter().enumerate() {
                    lit[k] += usize::from(counted);
                    black[k] += usize::from(counted && *c == Lit::Black);
                }
            }
        }
        let share = |k: usize| black[k] as f64 / lit[k].max(1) as f64;
        IndirectErrors {
            energy_ratio: if self.mean_r > 0.0 {
                self.mean_a / self.mean_r
            } else {
                1.0
            },
            black_where_lit: share(0),
            black_where_lit_all: share(1),
            lit_pixels: lit[0] as u64,
        }
    }

    /// The classes as a picture: red where black where lit, dark yellow ([`MIXED_BLACK`])
    /// where so but left out as mixed, grey where lit, dark grey where the reference's
    /// indirect light is not counted.
    pub fn to_image(&self, width: u32, height: u32) -> image::RgbImage {
        image::ImageBuffer::from_fn(width, height, |x, y| {
            let i = (y * width + x) as usize;
            image::Rgb(match self.class[i] {
                Lit::Not => [32, 32, 32],
                Lit::Lit => [150, 150, 150],
                Lit::Black if self.is_mixed(i) => MIXED_BLACK,
                Lit::Black => [255, 0, 0],
            })
        })
    }
}

/// Each pixel of `a` against reference `r`, both less the direct light `direct`.
pub fn indirect_map(
    a: &HdrImage,
    r: &HdrImage,
    direct: &HdrImage,
) -> Result<IndirectMap, RenderError> {
    same_size(a, r)?;
    same_size(direct, r)?;
    let sum = |p: Vec3| (p.x + p.y + p.z) as f64;
    let ind = |img: &HdrImage| -> Vec<f64> {
        img.pixels
            .iter()
            .zip(&direct.pixels)
            .map(|(p, d)| sum(*p - *d).max(0.0))
            .collect()
    };
    let (ia, ir) = (ind(a), ind(r));
    let n = ir.len().max(1) as f64;
    let (mean_a, mean_r) = (ia.iter().sum::<f64>() / n, ir.iter().sum::<f64>() / n);
    let class = ia
        .iter()
        .zip(&ir)
        .map(|(&a, &r)| {
            if !(r > 0.0 && r >= 0.1 * mean_r) {
                Lit::Not
            } else if a < 0.1 * r {
                Lit::Black
            } else {
                Lit::Lit
            }
        })
        .collect();
    Ok(IndirectMap {
        class,
        mixed: Vec::new(),
        mean_a,
        mean_r,
    })
}

/// `image` with its own direct light `own` replaced by `reference_direct`: its indirect light
/// over the reference's direct light, so that [`indirect_errors`] sees the method's indirect
/// light alone (GPU shadow maps and CPU shadow rays differ a little at shadow edges).
pub fn rebase_direct(
    image: &HdrImage,
    own: &HdrImage,
    reference_direct: &HdrImage,
) -> Result<HdrImage, RenderError> {
    same_size(image, own)?;
    same_size(image, reference_direct)?;
    let mut m = image.clone();
    for ((p, o), d) in m
        .pixels
        .iter_mut()
        .zip(&own.pixels)
        .zip(&reference_direct.pixels)
    {
        *p = *p - *o + *d;
    }
    Ok(m)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn image(px: &[f32]) -> HdrImage {
        let mut img = HdrImage::new(px.len() as u32, 1);
        img.pixels = px.iter().map(|&v| Vec3::splat(v)).collect();
        img
    }

    #[test]
    fn the_relative_mse_against_a_black_reference_is_finite() {
        let black = image(&[0.0, 0.0]);
        let dim = image(&[1e-6, 0.0]);
        let e = errors(&dim, &black).expect("size");
        // ε = 1e-2 · (0.5e-6)²: each of the three channels of the lit pixel (1e-6)² / ε = 400,
        // over six values.
        assert!((e.rel_mse - 200.0).abs() < 1e-3, "{e:?}");
        assert_eq!(errors(&black, &black).expect("size").rel_mse, 0.0);
    }

    #[test]
    fn indirect_errors_count_energy_and_black_pixels_above_the_direct_light() {
        let direct = image(&[1.0, 1.0, 0.0, 0.0]);
        let reference = image(&[2.0, 1.5, 1.0, 0.5]); // indirect 1, 0.5, 1, 0.5
        let method = image(&[2.0, 1.02, 0.0, 0.5]); // indirect 1, 0.02, 0, 0.5
        let e = indirect_errors(&method, &reference, &direct).expect("same size");
        assert!((e.energy_ratio - 1.52 / 3.0).abs() < 1e-6, "{e:?}");
        // Two of the four lit pixels are under a tenth of the reference's indirect light.
        assert!((e.black_where_lit - 0.5).abs() < 1e-12, "{e:?}");
        let same = indirect_errors(&reference, &reference, &direct).expect("same size");
        assert_eq!((same.energy_ratio, same.black_where_lit), (1.0, 0.0));
        // Pixel by pixel: the second and third are black, and red in the picture.
        let map = indirect_map(&method, &reference, &direct).expect("same size");
        assert_eq!(map.class, [Lit::Lit, Lit::Black, Lit::Black, Lit::Lit]);
        let red = map
            .to_image(4, 1)
            .pixels()
            .map(|p| p.0 == [255, 0, 0])
            .collect::<Vec<_>>();
        assert_eq!(red, [false, true, true, false]);
        // The third pixel mixed: left out of the share (one black of three lit), counted in
        // the share over every pixel, and dark yellow in the picture.
        let mixed = map
            .leave_out_mixed(vec![false, false, true, false])
            .expect("same size");
        let e = mixed.errors();
        assert!((e.black_where_lit - 1.0 / 3.0).abs() < 1e-12, "{e:?}");
        assert!((e.black_where_lit_all - 0.5).abs() < 1e-12, "{e:?}");
        assert_eq!(mixed.to_image(4, 1).get_pixel(2, 0).0, MIXED_BLACK);
        let wrong = indirect_map(&method, &reference, &direct).expect("same size");
        assert!(wrong.leave_out_mixed(vec![false; 3]).is_err());
    }
}

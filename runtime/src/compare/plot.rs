//! The pictures of a comparison: the Pareto plot (frame time against error, log-log, a curve
//! per method over its VPL counts, the non-dominated points filled, the answers ringed) and
//! the panels (reference | method | false-colour FLIP map | black where lit, JPEG), drawn with
//! plotters into bitmaps, text in egui's own font so nothing is looked up on the system.

use std::sync::Once;

use image::RgbImage;
use plotters::prelude::*;

use super::pareto::{Answer, Point};
use crate::RenderError;
use crate::hdr::{HdrImage, false_colour};

const FONT: &str = "sans-serif";

/// Registers the font once (plotters' ab_glyph backend has none of its own).
fn font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TTF shipped with egui; a failure leaves text undrawn.
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

fn drawing<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> RenderError {
    RenderError::Param(format!("drawing a plot: {e}"))
}

/// A log axis' label: only at 1, 2 and 5 times a power of ten (the others stay unlabelled
/// grid lines), in plain or scientific notation.
fn tick(v: f64, scientific: bool) -> String {
    let e = v.log10().floor();
    let m = v / 10f64.powf(e);
    if ![1.0, 2.0, 5.0, 10.0]
        .iter()
        .any(|k| (m - k).abs() < 1e-6 * k)
    {
        return String::new();
    }
    match (scientific, v) {
        (true, _) => format!("{v:.0e}"),
        (false, v) if v >= 1.0 => format!("{v:.0}"),
        (false, v) => format!("{v}"),
    }
}

/// The Pareto plot of `points` (`metric` names the error axis), `w × h` pixels.
pub fn pareto(
    points: &[Point],
    answers: &[Answer],
    title: &str,
    metric: &str,
    [w, h]: [u32; 2],
) -> Result<RgbImage, RenderError> {
    font();
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let modes: Vec<&str> = points.iter().fold(Vec::new(), |mut v, p| {
        if !v.contains(&p.mode.as_str()) {
            v.push(&p.mode);
        }
        v
    });
    let range = |f: &dyn Fn(&Point) -> f64| {
        let (lo, hi) = points
            .iter()
            .map(|p| f(p).max(1e-12))
            .fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
        match lo.is_finite() {
            true => (lo / 1.6)..(hi * 1.6),
            false => 0.1..10.0,
        }
    };
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(78)
            .build_cartesian_2d(
                range(&|p| p.ms).log_scale(),
                range(&|p| p.error).log_scale(),
            )
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .x_desc("frame time (ms), mean over the cameras")
            .y_desc(format!("{metric}, mean over the cameras"))
            .x_label_formatter(&|v| tick(*v, false))
            .y_label_formatter(&|v| tick(*v, true))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .light_line_style(TRANSPARENT)
            .draw()
            .map_err(drawing)?;
        for (i, mode) in modes.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let mut pts: Vec<&Point> = points.iter().filter(|p| p.mode == *mode).collect();
            pts.sort_by_key(|p| p.vpls);
            let xy = |p: &Point| (p.ms.max(1e-12), p.error.max(1e-12));
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| xy(p)),
                    colour.stroke_width(2),
                ))
                .map_err(drawing)?
                .label(*mode)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], colour.stroke_width(3))
                });
            chart
                .draw_series(pts.iter().map(|p| {
                    let style = match p.pareto {
                        true => colour.filled(),
                        false => WHITE.filled(),
                    };
                    EmptyElement::at(xy(p))
                        + Circle::new((0, 0), 6, style)
                        + Circle::new((0, 0), 6, colour.stroke_width(2))
                        + Text::new(format!("{}", p.vpls), (8, -16), (FONT, 12))
                }))
                .map_err(drawing)?;
        }
        // One ring per answered point, its answers named together.
        let mut answered: Vec<(&Point, Vec<&str>)> = Vec::new();
        for a in answers {
            let Some(p) = &a.point else { continue };
            match answered.iter_mut().find(|(q, _)| *q == p) {
                Some((_, kinds)) => kinds.push(&a.kind),
                None => answered.push((p, vec![&a.kind])),
            }
        }
        for (p, kinds) in answered {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((p.ms.max(1e-12), p.error.max(1e-12)))
                        + Circle::new((0, 0), 12, BLACK.stroke_width(2))
                        + Text::new(kinds.join(" + "), (-14, 16), (FONT, 14)),
                ))
                .map_err(drawing)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(drawing)?;
        root.present().map_err(drawing)?;
    }
    RgbImage::from_raw(w, h, buf).ok_or_else(|| RenderError::Param("plot buffer size".into()))
}

/// Reference | method | FLIP map (black 0 … white 1) | black where lit (red: the method's
/// indirect light under a tenth of the reference's where that counts, dark yellow: so where
/// the reference's samples see several surfaces, left out; grey: lit and counted;
/// [`crate::metrics::IndirectMap::to_image`]) side by side under `title`, both images tone
/// mapped at `exposure` stops.
pub fn panel(
    reference: &HdrImage,
    image: &HdrImage,
    (flip_map, black_map): (&[f32], &RgbImage),
    exposure: f32,
    title: &str,
) -> Result<RgbImage, RenderError> {
    font();
    let (w, h) = (image.width, image.height);
    let (gap, top) = (6u32, 44u32);
    let tiles = [
        reference.to_srgb8(exposure),
        image.to_srgb8(exposure),
        false_colour(flip_map, w, h, 1.0),
        black_map.clone(),
    ];
    let n = tiles.len() as u32;
    let (pw, ph) = (n * w + (n - 1) * gap, h + top);
    let mut out = RgbImage::from_pixel(pw, ph, image::Rgb([255, 255, 255]));
    for (i, t) in tiles.iter().enumerate() {
        image::imageops::replace(&mut out, t, (i as u32 * (w + gap)) as i64, top as i64);
    }
    let mut buf = out.into_raw();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (pw, ph)).into_drawing_area();
        let style = (FONT, 14).into_font().color(&BLACK);
        root.draw_text(title, &style, (2, 2)).map_err(drawing)?;
        // Each tile's label, shortened where a small image's tile is narrower (at 96 × 72
        // the long ones ran into each other).
        for (i, labels) in [
            ["reference", "ref."],
            ["method", "method"],
            ["FLIP (black 0 … white 1)", "FLIP"],
            ["red: black where lit · yellow: mixed", "red: black"],
        ]
        .iter()
        .enumerate()
        {
            let fits = |l: &&str| {
                let size = root.estimate_text_size(l, &style);
                size.is_ok_and(|(lw, _)| lw + 4 <= w)
            };
            let label = labels.iter().copied().find(fits).unwrap_or(labels[1]);
            let x = (i as u32 * (w + gap)) as i32 + 2;
            root.draw_text(label, &style, (x, 22)).map_err(drawing)?;
        }
        root.present().map_err(drawing)?;
    }
    RgbImage::from_raw(pw, ph, buf).ok_or_else(|| RenderError::Param("panel buffer size".into()))
}

/// Writes `picture` as a JPEG of quality 90 (a fifth of the PNG's size for rendered images,
/// so that reports with dozens of panels stay small enough to keep in a repository).
pub fn write_jpeg(picture: &RgbImage, path: &std::path::Path) -> Result<(), RenderError> {
    let file = std::fs::File::create(path).map_err(|e| RenderError::io(path, e))?;
    image::codecs::jpeg::JpegEncoder::new_with_quality(std::io::BufWriter::new(file), 90)
        .encode_image(picture)
        .map_err(|e| RenderError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether any pixel of `picture`'s label row in columns `xs` is not white.
    fn inked(picture: &RgbImage, xs: std::ops::Range<u32>) -> bool {
        xs.flat_map(|x| (20..40).map(move |y| (x, y)))
            .any(|(x, y)| picture.get_pixel(x, y).0 != [255, 255, 255])
    }

    #[test]
    fn a_small_image_s_panel_keeps_each_label_over_its_own_tile() {
        for (w, h) in [(96, 72), (320, 240)] {
            let image = HdrImage::new(w, h);
            let black = RgbImage::new(w, h);
            let flip = vec![0.0; (w * h) as usize];
            let p = panel(&image, &image, (&flip, &black), 0.0, "t").expect("panel");
            // The label row is inked in each tile, and not in the gaps between them.
            for i in 0..4 {
                let x = i * (w + 6);
                assert!(inked(&p, x..x + w), "{w}: tile {i} has no label");
                if i < 3 {
                    assert!(!inked(&p, x + w..x + w + 6), "{w}: label {i} runs on");
                }
            }
        }
    }
}

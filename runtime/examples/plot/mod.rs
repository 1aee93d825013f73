//! A line chart as a PNG, for the examples' figures: no text (the README's caption names the
//! axes and series), light grid lines at each power of ten on a log axis.

use image::{Rgb, RgbImage};

/// One series: its colour and (x, y) points.
pub struct Series {
    pub colour: [u8; 3],
    pub points: Vec<(f64, f64)>,
    /// Dashed (every other 6 px left out).
    pub dashed: bool,
}

/// Axis ranges and scales.
pub struct Axes {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub log_x: bool,
    pub log_y: bool,
}

/// Draws `series` on `axes` into a `w`×`h` PNG at `path`.
pub fn line_chart(
    path: &std::path::Path,
    w: u32,
    h: u32,
    axes: &Axes,
    series: &[Series],
) -> Result<(), Box<dyn std::error::Error>> {
    let mut img = RgbImage::from_pixel(w, h, Rgb([255, 255, 255]));
    let (ml, mr, mt, mb) = (40.0, 16.0, 16.0, 32.0);
    let f = |v: f64, log: bool| if log { v.max(1e-300).log10() } else { v };
    let (x0, x1) = (f(axes.x.0, axes.log_x), f(axes.x.1, axes.log_x));
    let (y0, y1) = (f(axes.y.0, axes.log_y), f(axes.y.1, axes.log_y));
    let to_px = |x: f64, y: f64| -> (f64, f64) {
        let u = (f(x, axes.log_x) - x0) / (x1 - x0);
        let v = (f(y, axes.log_y) - y0) / (y1 - y0);
        (
            ml + u * (w as f64 - ml - mr),
            h as f64 - mb - v * (h as f64 - mt - mb),
        )
    };
    let put = |img: &mut RgbImage, x: f64, y: f64, c: [u8; 3]| {
        let (xi, yi) = (x.round() as i64, y.round() as i64);
        if xi >= 0 && yi >= 0 && (xi as u32) < w && (yi as u32) < h {
            img.put_pixel(xi as u32, yi as u32, Rgb(c));
        }
    };
    // Grid: decades on log axes, tenths otherwise.
    let ticks = |a: f64, b: f64, log: bool| -> Vec<f64> {
        if log {
            (a.floor() as i64..=b.ceil() as i64)
                .map(|e| 10f64.powi(e as i32))
                .collect()
        } else {
            (0..=10).map(|i| a + (b - a) * i as f64 / 10.0).collect()
        }
    };
    for t in ticks(x0, x1, axes.log_x) {
        let (px, _) = to_px(t, axes.y.0);
        for y in mt as u32..(h - mb as u32) {
            put(&mut img, px, y as f64, [225, 225, 225]);
        }
    }
    for t in ticks(y0, y1, axes.log_y) {
        let (_, py) = to_px(axes.x.0, t);
        for x in ml as u32..(w - mr as u32) {
            put(&mut img, x as f64, py, [225, 225, 225]);
        }
    }
    // Frame.
    for x in ml as u32..(w - mr as u32) {
        put(&mut img, x as f64, h as f64 - mb, [0, 0, 0]);
        put(&mut img, x as f64, mt, [0, 0, 0]);
    }
    for y in mt as u32..=(h - mb as u32) {
        put(&mut img, ml, y as f64, [0, 0, 0]);
        put(&mut img, w as f64 - mr, y as f64, [0, 0, 0]);
    }
    for s in series {
        let mut run = 0.0;
        for pair in s.points.windows(2) {
            let (a, b) = (to_px(pair[0].0, pair[0].1), to_px(pair[1].0, pair[1].1));
            let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) * 2.0)
                .ceil()
                .max(1.0) as u32;
            for i in 0..=steps {
                let t = i as f64 / steps as f64;
                run += 0.5;
                if s.dashed && (run as u64 / 6) % 2 == 1 {
                    continue;
                }
                let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
                    put(&mut img, x + dx, y + dy, s.colour);
                }
            }
        }
        for &(x, y) in &s.points {
            let (px, py) = to_px(x, y);
            for dy in -2..=2 {
                for dx in -2..=2 {
                    put(&mut img, px + dx as f64, py + dy as f64, s.colour);
                }
            }
        }
    }
    img.save(path)?;
    Ok(())
}

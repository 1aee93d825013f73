//! How much of a pixel's light a few VPLs carry, against what the near field walks at the
//! pixel: for every pixel centre of a view, its unshadowed light U (every VPL's flux × min(cos
//! cos / d², g_max), summed over the channels, no visibility), the VPLs that each carry at least
//! α of it (1, 2, 5 %: a pixel's dominant VPLs) and their share of U, and the VPLs within the
//! near field's radius at K = 4 and K = 8 blocks of 8 × 8 pixels (`--near-field K`). Where the
//! dominant VPLs carry much of U and lie beyond the near field, the interleaving spreads their
//! shadow edges over its blocks (e2m3's `hall` under its second lamp: README, *The near
//! field*): the case for walking them at the pixel.
//!
//! `cargo run --release --example dominant_vpls -- SCENE LEVEL.vgate CAMERA [WxH] [PATHS] [G_MAX]`
//! (G_MAX in 1/m², default 1 / (0.025 of the scene's diagonal)², as `visgate compare`).

#[path = "common/pairs.rs"]
mod pairs;

use glam::{Vec2, Vec3};

/// The shares of U that make a VPL dominant.
const ALPHAS: [f32; 3] = [0.01, 0.02, 0.05];

/// Sums over the lit pixels.
#[derive(Default)]
struct Sums {
    pixels: u64,
    near: [u64; 2],
    dominant: [u64; 3],
    dominant_share: [f64; 3],
    dominant_near_share: [f64; 3],
}

fn main() -> anyhow::Result<()> {
    let p = pairs::from_args("dominant_vpls")?;
    let g_max = match std::env::args().nth(6) {
        Some(g) => g.parse::<f32>()?,
        None => {
            let (lo, hi) = p
                .scene
                .bounds()
                .ok_or_else(|| anyhow::anyhow!("empty scene"))?;
            (0.025 * (hi - lo).length()).powi(-2)
        }
    };
    let [w, h] = p.size;
    let centre = Vec2::new(w as f32 / 2.0, h as f32 / 2.0);
    let pixel_angle = p
        .view
        .ray_dir(centre)
        .angle_between(p.view.ray_dir(centre + Vec2::X));
    let mut s = Sums::default();
    for y in 0..h {
        for x in 0..w {
            let dir = p.view.ray_dir(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = p.tracer.trace(p.view.eye, dir) else {
                continue;
            };
            // Each VPL's light at the pixel and its distance.
            let lights: Vec<(f32, f32)> = p
                .vpls
                .iter()
                .filter_map(|v| {
                    let to = Vec3::from(v.position) - hit.position;
                    let d = to.length();
                    let cos_x = to.dot(hit.normal) / d;
                    let cos_v = -to.dot(Vec3::from(v.normal)) / d;
                    let flux = Vec3::from(v.flux).element_sum();
                    (cos_x > 0.0 && cos_v > 0.0)
                        .then(|| (flux * (cos_x * cos_v / (d * d)).min(g_max), d))
                })
                .collect();
            let u: f32 = lights.iter().map(|l| l.0).sum();
            if u <= 0.0 {
                continue;
            }
            s.pixels += 1;
            let r4 = 4.0 * 8.0 * pixel_angle * hit.t;
            for (k, r) in [r4, 2.0 * r4].into_iter().enumerate() {
                s.near[k] += lights.iter().filter(|l| l.1 < r).count() as u64;
            }
            for (k, a) in ALPHAS.iter().enumerate() {
                let dominant = lights.iter().filter(|l| l.0 >= a * u);
                s.dominant[k] += dominant.clone().count() as u64;
                s.dominant_share[k] += f64::from(dominant.clone().map(|l| l.0).sum::<f32>() / u);
                let near = dominant.filter(|l| l.1 < r4).map(|l| l.0).sum::<f32>();
                s.dominant_near_share[k] += f64::from(near / u);
            }
        }
    }
    let n = s.pixels.max(1) as f64;
    println!(
        "{} ({}x{}, {} VPLs): {} pixels with light; VPLs a pixel in the near field: K = 4 {:.1}, K = 8 {:.1}",
        p.camera,
        w,
        h,
        p.vpls.len(),
        s.pixels,
        s.near[0] as f64 / n,
        s.near[1] as f64 / n
    );
    for (k, a) in ALPHAS.iter().enumerate() {
        println!(
            "  alpha {:.0} %: {:.2} dominant VPLs a pixel carry {:.3} of U ({:.3} within K = 4)",
            100.0 * a,
            s.dominant[k] as f64 / n,
            s.dominant_share[k] / n,
            s.dominant_near_share[k] / n
        );
    }
    Ok(())
}

//! The imperfect shadow maps of one VPL as the runtime builds them, like Fig. 4 of
//! Weinzierl-Heigl (an ISM with holes, and after pull-push): side by side, the bare points
//! (no splat, no pull-push), the surfel splats alone, and the default (splats + 2 pull-push
//! levels), each map's distances in grey (near bright, far dark, logarithmic) and its holes
//! in red; the holes inside the paraboloid's disk are counted for each.
//!
//! `cargo run --release --example ism_maps -- [SCENE] [POINTS PER MAP] [OUT.png]`
//!
//! Defaults: builtin:cornell-box, 8,192 points, ism-maps.png. The VPL is the brightest of
//! 256 light paths.

use visgate_formats::ImportOptions;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{GpuContext, GpuRenderer, IsmParams};
use visgate_runtime::vpl::{PathParams, path_vpls};

/// One map as RGB, `scale` pixels a texel, and its holes inside the disk.
fn picture(maps: &[f32], s: u32) -> (Vec<[u8; 3]>, usize) {
    let finite = maps.iter().filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f32::MAX, 0.0f32), |(a, b), &d| (a.min(d), b.max(d)));
    let mut holes = 0;
    let texels = (0..s * s)
        .map(|i| {
            let (x, y) = (i % s, i / s);
            let u = (x as f32 + 0.5) / s as f32 * 2.0 - 1.0;
            let v = (y as f32 + 0.5) / s as f32 * 2.0 - 1.0;
            let d = maps[i as usize];
            if u * u + v * v >= 1.0 {
                return [24, 24, 24];
            }
            if !d.is_finite() {
                holes += 1;
                return [220, 30, 30];
            }
            let t = ((d / lo).ln() / (hi / lo).max(1.0 + 1e-6).ln()).clamp(0.0, 1.0);
            let g = (235.0 - 200.0 * t) as u8;
            [g, g, g]
        })
        .collect();
    (texels, holes)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene_arg = args.next().unwrap_or_else(|| "builtin:cornell-box".into());
    let points: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(8192);
    let out = args.next().unwrap_or_else(|| "ism-maps.png".into());
    let scene = visgate_scenes::load(&scene_arg, &ImportOptions::default())?;
    let tracer = Tracer::new(&scene);
    let paths = PathParams {
        paths: 256,
        bounces: 1,
        seed: 1,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths)?;
    let brightest = vpls
        .iter()
        .max_by(|a, b| {
            (a.flux[0] + a.flux[1] + a.flux[2]).total_cmp(&(b.flux[0] + b.flux[1] + b.flux[2]))
        })
        .ok_or("the scene's lights make no VPL")?;
    let ctx = GpuContext::new()?;
    let mut gpu = GpuRenderer::new(&ctx, &scene)?;
    let base = IsmParams {
        map_size: Some(128),
        points_per_map: points,
        ..IsmParams::default()
    };
    let variants = [
        (
            "points",
            IsmParams {
                max_splat: 0.0,
                pull_push: 0,
                coverage: 1.0,
                ..base
            },
        ),
        (
            "surfel splats",
            IsmParams {
                pull_push: 0,
                ..base
            },
        ),
        ("splats + pull-push 2 (default)", base),
    ];
    let (s, scale) = (128u32, 2u32);
    let mut img = image::RgbImage::new(3 * s * scale + 2 * 8, s * scale);
    for (k, (name, p)) in variants.iter().enumerate() {
        let (maps, side) = gpu.ism_maps(&ctx, std::slice::from_ref(brightest), p)?;
        assert_eq!(side, s);
        let (texels, holes) = picture(&maps, s);
        println!("{scene_arg}, {points} points: {name}: {holes} holes in the disk");
        for (i, t) in texels.iter().enumerate() {
            let (x, y) = (i as u32 % s, i as u32 / s);
            for (dx, dy) in (0..scale).flat_map(|a| (0..scale).map(move |b| (a, b))) {
                let px = k as u32 * (s * scale + 8) + x * scale + dx;
                img.put_pixel(px, y * scale + dy, image::Rgb(*t));
            }
        }
    }
    img.save(&out)?;
    println!("wrote {out}");
    Ok(())
}

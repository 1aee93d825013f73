//! Temporal coherence of the VAL clustering, like Fig. 8 of Dong et al.: a spot light in the
//! Cornell box turns from a wall to the ceiling over 120 frames; per frame, the live VALs (with
//! at least one VPL) and the flicker of the indirect image (mean absolute change from the last
//! frame) for the paper's restart (VAL k from VPL ⌊k·N/M⌋ every frame) and for reusing last
//! frame's centres.
//!
//! `cargo run --release -p visgate-runtime --example val_coherence -- [FRAMES] [SIZE] [PNG]`
//!
//! Defaults: 120 frames, 64 × 64, M = 30, 1024 light paths, val-cssm without interleaving; the
//! plot (live VALs per frame: restart red, warm start blue) goes to
//! docs/images/val-coherence.png.

mod plot;

use glam::Vec3;
use visgate_formats::Light;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::cpu::val::centres_of;
use visgate_runtime::cpu::val::{ValParams, cluster};
use visgate_runtime::gpu::{
    CssmParams, GpuContext, GpuMode, GpuParams, GpuRenderer, InterleaveParams, ValModeParams,
};
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::vpl::{PathParams, path_vpls};
use visgate_scenes::Builtin;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let frames: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(120);
    let size: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(64);
    let png = args
        .next()
        .unwrap_or_else(|| "docs/images/val-coherence.png".into());
    let mut scene = Builtin::CornellBox.scene()?;
    let (lo, hi) = scene.bounds().ok_or("empty scene")?;
    let centre = (lo + hi) * 0.5;
    let view = View::new(scene.cameras.first().ok_or("no camera")?, [size, size])?;
    let ctx = GpuContext::new()?;
    let mut restart = GpuRenderer::new(&ctx, &scene)?;
    let mut warm = GpuRenderer::new(&ctx, &scene)?;
    let vals = |warm_start| ValParams {
        warm_start,
        ..ValParams::default()
    };
    let params = |warm_start| {
        GpuParams::with_mode(GpuMode::ValCssm(
            ValModeParams {
                vals: vals(warm_start),
                interleave: InterleaveParams {
                    block: 1,
                    ..InterleaveParams::default()
                },
                ..ValModeParams::new()
            },
            CssmParams::default(),
        ))
    };
    let indirect = |img: &HdrImage, direct: &HdrImage| -> Vec<Vec3> {
        img.pixels
            .iter()
            .zip(&direct.pixels)
            .map(|(a, b)| *a - *b)
            .collect()
    };
    let flicker = |a: &[Vec3], b: &[Vec3]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| ((*x - *y).abs().element_sum() / 3.0) as f64)
            .sum::<f64>()
            / a.len() as f64
    };
    let (mut last_r, mut last_w): (Option<Vec<Vec3>>, Option<Vec<Vec3>>) = (None, None);
    let mut warm_centres = None;
    let (mut live_r, mut live_w, mut fl_r, mut fl_w) = (vec![], vec![], vec![], vec![]);
    println!("frame,live_restart,live_warm,flicker_restart,flicker_warm");
    for f in 0..frames {
        let t = f as f32 / (frames - 1).max(1) as f32 * std::f32::consts::FRAC_PI_2;
        let dir = Vec3::new(-t.cos(), t.sin(), 0.0);
        let light = Light::Spot {
            position: centre,
            direction: dir,
            intensity: Vec3::splat(4.0),
            cutoff_rad: 30f32.to_radians(),
            beam_rad: 20f32.to_radians(),
        };
        scene.lights = vec![light];
        let tracer = Tracer::new(&scene);
        let vpls = path_vpls(
            &tracer,
            &scene.lights,
            &PathParams {
                paths: 1024,
                bounces: 1,
                seed: 1,
            },
        )?;
        restart.set_lights(&scene.lights);
        warm.set_lights(&scene.lights);
        let (direct, _) =
            restart.render(&ctx, &view, &[], &GpuParams::with_mode(GpuMode::DirectOnly))?;
        let (img_r, _) = restart.render(&ctx, &view, &vpls, &params(false))?;
        let (img_w, _) = warm.render(&ctx, &view, &vpls, &params(true))?;
        // The same clusterings on the CPU twin (equal to the GPU's) for the live counts.
        let cr = cluster(&vpls, &vals(false), None)?;
        let cw = cluster(&vpls, &vals(true), warm_centres.as_deref())?;
        warm_centres = Some(centres_of(&cw));
        let (ir, iw) = (indirect(&img_r, &direct), indirect(&img_w, &direct));
        let (a, b) = (
            last_r.as_ref().map_or(0.0, |l| flicker(&ir, l)),
            last_w.as_ref().map_or(0.0, |l| flicker(&iw, l)),
        );
        println!("{f},{},{},{a:.3e},{b:.3e}", cr.live(), cw.live());
        live_r.push((f as f64, cr.live() as f64));
        live_w.push((f as f64, cw.live() as f64));
        if f > 0 {
            fl_r.push(a);
            fl_w.push(b);
        }
        last_r = Some(ir);
        last_w = Some(iw);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let min = |v: &[(f64, f64)]| v.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    println!(
        "restart: live VALs min {} mean {:.1}, flicker {:.3e}; warm start: live VALs min {} \
         mean {:.1} (last frame {}), flicker {:.3e}",
        min(&live_r),
        mean(&live_r.iter().map(|p| p.1).collect::<Vec<_>>()),
        mean(&fl_r),
        min(&live_w),
        mean(&live_w.iter().map(|p| p.1).collect::<Vec<_>>()),
        live_w.last().map_or(0.0, |p| p.1),
        mean(&fl_w)
    );
    plot::line_chart(
        std::path::Path::new(&png),
        480,
        240,
        &plot::Axes {
            x: (0.0, (frames - 1) as f64),
            y: (0.0, 32.0),
            log_x: false,
            log_y: false,
        },
        &[
            plot::Series {
                colour: [200, 30, 30],
                points: live_r,
                dashed: false,
            },
            plot::Series {
                colour: [30, 60, 200],
                points: live_w,
                dashed: false,
            },
        ],
    )?;
    println!("plot: {png}");
    Ok(())
}

//! Convergence of the VAL modes with the number of VALs, like Fig. 10 of Dong et al.: MSE
//! against the exact CPU reference with the same VPLs, for M = 2, 4, 8, 16, 30, 64, beside no
//! visibility and per-VPL shadow maps, on the Cornell box and the four rooms.
//!
//! `cargo run --release -p visgate-runtime --example val_convergence -- [WxH] [VPL paths] [PNG]`
//!
//! Defaults: 128×96, 1024 paths; the plot goes to docs/images/val-convergence.png (x: M, log;
//! y: MSE, log; Cornell box red, four rooms blue, val-cssm solid, val-hard dashed and paler;
//! no visibility grey and per-VPL shadow maps black as flat lines, solid for the Cornell box,
//! dashed for the four rooms).

mod fixture;
mod plot;

use visgate_runtime::cpu::val::ValParams;
use visgate_runtime::gpu::{
    CssmParams, GpuContext, GpuMode, GpuParams, GpuRenderer, InterleaveParams, MethodSettings,
    ValModeParams,
};
use visgate_runtime::metrics::errors;
use visgate_scenes::Builtin;

const COUNTS: [u32; 6] = [2, 4, 8, 16, 30, 64];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size = args.next().unwrap_or_else(|| "128x96".into());
    let (w, h) = size.split_once('x').ok_or("size WxH")?;
    let size = [w.parse()?, h.parse()?];
    let paths: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(1024);
    let png = args
        .next()
        .unwrap_or_else(|| "docs/images/val-convergence.png".into());
    let ctx = GpuContext::new()?;
    println!(
        "MSE against the reference with the same VPLs ({paths} light paths, {}×{}, on {})",
        size[0], size[1], ctx.adapter_info.name
    );
    println!("| scene | VPLs | none | per-VPL maps | mode | M = 2 | 4 | 8 | 16 | 30 | 64 |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut series = Vec::new();
    let mut lo = f64::INFINITY;
    let mut hi = 0f64;
    for (b, colour) in [
        (Builtin::CornellBox, [200, 30, 30]),
        (Builtin::FourRooms, [30, 60, 200]),
    ] {
        let fixture::Fixture {
            scene,
            view,
            vpls,
            reference,
        } = fixture::fixture(b, size, paths)?;
        let mut gpu = GpuRenderer::new(&ctx, &scene)?;
        let mut mse = |mode: fn(ValModeParams) -> GpuMode,
                       m: u32|
         -> Result<f64, Box<dyn std::error::Error>> {
            let (img, _) = gpu.render(
                &ctx,
                &view,
                &vpls,
                &GpuParams::with_mode(mode(ValModeParams {
                    vals: ValParams {
                        count: m,
                        ..ValParams::default()
                    },
                    // Every VPL at every pixel: the error of the visibility alone.
                    interleave: InterleaveParams {
                        block: 1,
                        ..InterleaveParams::default()
                    },
                    ..ValModeParams::new()
                })),
            )?;
            Ok(errors(&img, &reference)?.mse)
        };
        let none = mse(|_| GpuMode::None, 1)?;
        let per_vpl = mse(
            |_| GpuMode::PerVplShadowMaps(MethodSettings::default().per_vpl),
            1,
        )?;
        for (x, c) in [(none, [150, 150, 150]), (per_vpl, [0, 0, 0])] {
            series.push(plot::Series {
                colour: c,
                points: vec![(2.0, x), (64.0, x)],
                dashed: b == Builtin::FourRooms,
            });
        }
        lo = lo.min(none).min(per_vpl);
        hi = hi.max(none).max(per_vpl);
        for (name, mode, dashed) in [
            (
                "val-cssm",
                (|v| GpuMode::ValCssm(v, CssmParams::default())) as fn(ValModeParams) -> GpuMode,
                false,
            ),
            ("val-hard", GpuMode::ValHard, true),
        ] {
            let e: Vec<f64> = COUNTS
                .iter()
                .map(|&m| mse(mode, m))
                .collect::<Result<_, _>>()?;
            println!(
                "| {} | {} | {none:.3e} | {per_vpl:.3e} | {name} | {} |",
                b.name(),
                vpls.len(),
                e.iter()
                    .map(|x| format!("{x:.3e}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
            for &x in &e {
                lo = lo.min(x);
                hi = hi.max(x);
            }
            series.push(plot::Series {
                colour: colour.map(|c: u8| if dashed { c / 2 + 100 } else { c }),
                points: COUNTS.iter().map(|&m| m as f64).zip(e).collect(),
                dashed,
            });
        }
    }
    plot::line_chart(
        std::path::Path::new(&png),
        480,
        320,
        &plot::Axes {
            x: (2.0, 64.0),
            y: (lo * 0.8, hi * 1.25),
            log_x: true,
            log_y: true,
        },
        &series,
    )?;
    println!("plot: {png}");
    Ok(())
}

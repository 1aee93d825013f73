//! The effect of the VAL clustering's weights, like Fig. 6 of Dong et al. (which shows the
//! clusterings): MSE against the exact CPU reference with the same VPLs for w_x = 1 − w_α from
//! 0 (normals only) to 1 (positions only), M = 30 VALs, val-cssm and val-hard, every VPL at
//! every pixel, on the Cornell box and the four rooms; and each clustering's mean VAL area.
//! The last column is the paper's own metric, `0.7·Δx + 0.3·Δα` in metres and radians: the
//! normalised one with `w_x = 0.7·D / (0.7·D + 0.3·π)` (D the VPLs' diagonal), so it changes
//! with the scene's scale.
//!
//! `cargo run --release -p visgate-runtime --example val_weights -- [WxH] [VPL paths]`

mod fixture;

use visgate_runtime::cpu::val::{ValParams, cluster, scale_of};
use visgate_runtime::gpu::{
    CssmParams, GpuContext, GpuMode, GpuParams, GpuRenderer, InterleaveParams, ValModeParams,
};
use visgate_runtime::metrics::errors;
use visgate_scenes::Builtin;

const W_X: [f32; 5] = [0.0, 0.3, 0.5, 0.7, 1.0];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size = args.next().unwrap_or_else(|| "128x96".into());
    let (w, h) = size.split_once('x').ok_or("size WxH")?;
    let size = [w.parse()?, h.parse()?];
    let paths: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(1024);
    let ctx = GpuContext::new()?;
    println!(
        "M = 30, {paths} light paths, {}×{}; MSE (mean VAL area, m²)",
        size[0], size[1]
    );
    println!("| scene | mode | w_x = 0 | 0.3 | 0.5 | 0.7 (paper) | 1 | paper, unnormalised |");
    println!("|---|---|---|---|---|---|---|---|");
    for b in [Builtin::CornellBox, Builtin::FourRooms] {
        let fixture::Fixture {
            scene,
            view,
            vpls,
            reference,
        } = fixture::fixture(b, size, paths)?;
        let mut gpu = GpuRenderer::new(&ctx, &scene)?;
        for soft in [true, false] {
            let mut row = format!(
                "| {} | {} |",
                b.name(),
                if soft { "val-cssm" } else { "val-hard" }
            );
            // The paper's unnormalised 0.7 / 0.3 as normalised weights (scaled to sum 1).
            let d = scale_of(&vpls);
            let unnormalised = 0.7 * d / (0.7 * d + 0.3 * std::f32::consts::PI);
            for w_x in W_X.into_iter().chain([unnormalised]) {
                let vals = ValParams {
                    count: 30,
                    w_x,
                    w_alpha: 1.0 - w_x,
                    ..ValParams::default()
                };
                let v = ValModeParams {
                    vals,
                    interleave: InterleaveParams {
                        block: 1,
                        ..InterleaveParams::default()
                    },
                    ..ValModeParams::new()
                };
                let mode = match soft {
                    true => GpuMode::ValCssm(v, CssmParams::default()),
                    false => GpuMode::ValHard(v),
                };
                let (img, _) = gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))?;
                let c = cluster(&vpls, &vals, None)?;
                let live = c.vals.iter().filter(|v| v.vpl_count() > 0);
                let area: f32 =
                    live.clone().map(|v| v.normal[3]).sum::<f32>() / live.count().max(1) as f32;
                let mse = errors(&img, &reference)?.mse;
                row += &match w_x == unnormalised {
                    true => format!(" {mse:.3e} ({area:.2}; w_x {w_x:.3}, D {d:.2} m) |"),
                    false => format!(" {mse:.3e} ({area:.2}) |"),
                };
            }
            println!("{row}");
        }
    }
    Ok(())
}

//! A timing breakdown like Table 2 of Dong et al.: VPL generation (RSM, GPU), VAL clustering,
//! CSSM (a paraboloid map per VAL, the Fourier basis and its mips), indirect lighting, beside
//! per-VPL shadow maps with the same VPLs. GPU ms from timestamp queries, each mode on a fresh
//! device after a warm-up frame; the VAL modes with the default interleaving (8 × 8 blocks)
//! and blur.
//!
//! `cargo run --release -p visgate-runtime --example val_timings -- [SCENE] [SIZE] [N] [M]`
//!
//! Defaults: cornell-box, 800 (square), N = 1024 RSM VPLs, M = 30.

use std::time::Instant;

use visgate_runtime::camera::View;
use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer, PassTimes};
use visgate_runtime::val::ValParams;
use visgate_scenes::Builtin;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "cornell-box".into());
    let size: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(800);
    let n: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(1024);
    let m: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(30);
    let b = Builtin::from_name(&name).ok_or(format!("no built-in scene '{name}'"))?;
    let scene = b.scene()?;
    let view = View::new(scene.cameras.first().ok_or("no camera")?, [size, size])?;
    let run = |mode: GpuMode| -> Result<(f64, PassTimes, String), Box<dyn std::error::Error>> {
        let ctx = GpuContext::new()?;
        let gpu = GpuRenderer::new(&ctx, &scene)?;
        let params = GpuParams {
            mode,
            vals: ValParams {
                count: m,
                ..ValParams::default()
            },
            ..GpuParams::default()
        };
        let warm = gpu.rsm_vpls(&ctx, 64, 256, 1)?;
        gpu.render(&ctx, &view, &warm, &params)?;
        let t0 = Instant::now();
        let vpls = gpu.rsm_vpls(&ctx, n, 256, 1)?;
        let gen_s = t0.elapsed().as_secs_f64();
        let (_, t) = gpu.render(&ctx, &view, &vpls, &params)?;
        Ok((gen_s, t, ctx.adapter_info.name.clone()))
    };
    let (gen_c, c, adapter) = run(GpuMode::ValCssm)?;
    let (gen_h, hd, _) = run(GpuMode::ValHard)?;
    let (gen_p, p, _) = run(GpuMode::PerVplShadowMaps)?;
    let ms = |x: f64| format!("{:.1}", x * 1e3);
    let g = |t: &PassTimes| t.gpu.unwrap_or_default();
    println!(
        "{name}, {size}×{size}, N = {n} RSM VPLs, M = {m}, on {adapter}: GPU ms per stage \
         (VPL generation: CPU wall time of the RSM pass and read-back)"
    );
    println!(
        "| mode | VPL generation | G-buffer + direct | clustering | shadow maps (per VAL / per VPL) | \
         CSSM basis + mips | indirect lighting | blur | total | speedup |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let total = |vpl_s: f64, t: &PassTimes| {
        let s = g(t);
        vpl_s
            + s.shadows
            + s.gbuffer
            + s.shade
            + s.val_clustering
            + s.vpl_maps
            + s.cssm
            + s.vpl_gather
            + s.blur
    };
    let base = total(gen_p, &p);
    for (label, vpl_s, t) in [
        ("val-cssm", gen_c, &c),
        ("val-hard", gen_h, &hd),
        ("per-vpl-shadow-maps", gen_p, &p),
    ] {
        let s = g(t);
        println!(
            "| {label} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2}× |",
            ms(vpl_s),
            ms(s.shadows + s.gbuffer + s.shade),
            ms(s.val_clustering),
            ms(s.vpl_maps),
            ms(s.cssm),
            ms(s.vpl_gather),
            ms(s.blur),
            ms(total(vpl_s, t)),
            base / total(vpl_s, t)
        );
    }
    Ok(())
}

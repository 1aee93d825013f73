//! A timing breakdown like Table 2 of Dong et al.: VPL generation (RSM, GPU), VAL clustering,
//! CSSM (a paraboloid map per VAL, the Fourier basis and its mips), indirect lighting, beside
//! per-VPL shadow maps with the same VPLs. GPU ms from timestamp queries, each mode on a fresh
//! device after a warm-up frame; the VAL modes with the default interleaving (8 × 8 blocks)
//! and blur.
//!
//! `cargo run --release -p visgate-runtime --example val_timings -- [SCENE] [SIZE] [N] [M]`
//!
//! Defaults: cornell-box, 800 (square), N = 1024 RSM VPLs, M = 30.

use visgate_runtime::camera::View;
use visgate_runtime::gpu::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, MethodSettings, PassTimes, RsmParams, VplInput,
};
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
    let run = |mode: GpuMode| -> Result<(PassTimes, String), Box<dyn std::error::Error>> {
        let ctx = GpuContext::new()?;
        let mut gpu = GpuRenderer::new(&ctx, &scene)?;
        let params = GpuParams::with_mode(mode);
        let rsm = |count| {
            VplInput::Rsm(RsmParams {
                count,
                rsm_size: 256,
                seed: 1,
            })
        };
        gpu.render_frame(&ctx, &view, rsm(64), &params)?;
        let (_, t) = gpu.render_frame(&ctx, &view, rsm(n), &params)?;
        Ok((t, ctx.adapter_info.name.clone()))
    };
    let mut s = MethodSettings::default();
    s.vals.vals.count = m;
    let (c, adapter) = run(GpuMode::ValCssm(s.vals, s.cssm))?;
    let (hd, _) = run(GpuMode::ValHard(s.vals))?;
    let (p, _) = run(GpuMode::PerVplShadowMaps(s.per_vpl))?;
    let ms = |x: f64| format!("{:.1}", x * 1e3);
    let g = |t: &PassTimes| Stages::of(t);
    println!(
        "{name}, {size}×{size}, N = {n} RSM VPLs, M = {m}, on {adapter}: GPU ms per stage \
         (VPL generation: the RSM pass, the VPLs staying on the GPU)"
    );
    println!(
        "| mode | VPL generation | G-buffer + direct | clustering | shadow maps (per VAL / per VPL) | \
         CSSM basis + mips | indirect lighting | blur | total | speedup |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let total = |t: &PassTimes| {
        let s = g(t);
        s.rsm
            + s.shadows
            + s.gbuffer
            + s.shade
            + s.val_clustering
            + s.vpl_maps
            + s.cssm
            + s.vpl_gather
            + s.blur
    };
    let base = total(&p);
    for (label, t) in [
        ("val-cssm", &c),
        ("val-hard", &hd),
        ("per-vpl-shadow-maps", &p),
    ] {
        let s = g(t);
        println!(
            "| {label} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2}× |",
            ms(s.rsm),
            ms(s.shadows + s.gbuffer + s.shade),
            ms(s.val_clustering),
            ms(s.vpl_maps),
            ms(s.cssm),
            ms(s.vpl_gather),
            ms(s.blur),
            ms(total(t)),
            base / total(t)
        );
    }
    Ok(())
}

/// GPU seconds of the stages this table shows.
struct Stages {
    rsm: f64,
    shadows: f64,
    gbuffer: f64,
    shade: f64,
    val_clustering: f64,
    vpl_maps: f64,
    cssm: f64,
    vpl_gather: f64,
    blur: f64,
}

impl Stages {
    fn of(t: &PassTimes) -> Stages {
        let g = |name: &str| t.gpu(name).unwrap_or(0.0);
        Stages {
            rsm: g("RSM VPLs"),
            shadows: g("shadow maps"),
            gbuffer: g("geometry pass (G-buffer)"),
            shade: g("shading: direct lighting"),
            val_clustering: g("VAL clustering"),
            vpl_maps: g("VAL paraboloid maps") + g("VPL paraboloid maps"),
            cssm: g("CSSM basis + mips"),
            vpl_gather: g("indirect lighting") + g("VPL gather"),
            blur: g("blur + compose"),
        }
    }
}

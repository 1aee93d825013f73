//! Frame times of every GPU mode, and the images they make, from one renderer per mode: the
//! first frame (resources created) and the second with the same settings (resources kept).
//!
//! `cargo run --release --example frame_times -- [SCENE] [SIZE] [VPLS] [OUT_DIR]`
//!
//! Defaults: builtin:four-rooms (baked here at 128 for the gate modes), 512 (square), 1024
//! light-path VPLs, no images written. With OUT_DIR, each mode's second frame is written as
//! OUT_DIR/MODE.exr (the before/after comparison of a restructuring reads these).

use std::time::Instant;

use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{GpuContext, GpuParams, GpuRenderer, METHODS, MethodSettings};
use visgate_runtime::vpl::{PathParams, path_vpls};

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene_arg = args.next();
    let mut it = scene_arg.clone().into_iter();
    let (name, scene, level) = common::scene_and_level(&mut it)?;
    let size: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(512);
    let n: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(1024);
    let out = args.next().map(std::path::PathBuf::from);
    let view = View::new(scene.cameras.first().ok_or("no camera")?, [size, size])?;
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths: n,
            bounces: 1,
            seed: 1,
        },
    )?;
    let gates = GateLevel::new(level, &scene)?;
    let ctx = GpuContext::new()?;
    println!(
        "{name}, {size}×{size}, {} VPLs, on {}: wall ms per frame",
        vpls.len(),
        ctx.adapter_info.name
    );
    println!(
        "| mode | first frame | second frame | its GPU time | its recording | resources made \
         (first / second) |"
    );
    println!("|---|---|---|---|---|---|");
    let settings = MethodSettings::default();
    for m in METHODS {
        let mut gpu = GpuRenderer::new(&ctx, &scene)?;
        gpu.set_level(&ctx, &gates)?;
        let params = GpuParams::with_mode((m.make)(&settings));
        let t0 = Instant::now();
        gpu.render(&ctx, &view, &vpls, &params)?;
        let first = t0.elapsed().as_secs_f64();
        let made = gpu.resources_created();
        let t0 = Instant::now();
        let (img, t) = gpu.render(&ctx, &view, &vpls, &params)?;
        let second = t0.elapsed().as_secs_f64();
        let ms = |x: Option<f64>| x.map_or("–".into(), |v| format!("{:.1}", v * 1e3));
        println!(
            "| {} | {:.1} | {:.1} | {} | {:.1} | {} / {} |",
            m.name,
            first * 1e3,
            second * 1e3,
            ms(t.gpu_total()),
            (t.frame_s - t.readback_s) * 1e3,
            made,
            gpu.resources_created() - made
        );
        if let Some(dir) = &out {
            std::fs::create_dir_all(dir)?;
            img.write(&dir.join(format!("{}.exr", m.name)), 0.0)?;
        }
    }
    Ok(())
}

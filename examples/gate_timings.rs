//! A timing table like Table I of the visibility-gates paper: GPU time per pass (timestamp
//! queries) of mode gates — geometry pass, unique clusters, light assignment, indirect
//! lighting — with portals and with the paper's disks, beside val-hard, val-cssm, per-VPL
//! shadow maps and no visibility, at 512 / 1024 / 2048 VPLs (`GATE_TIMINGS_VPLS=1024,4096`
//! sets them; `GATE_TIMINGS_ONLY=gates,none` the modes).
//!
//! `cargo run --release --example gate_timings -- [SCENE] [LEVEL.vgate|-] [WxH] [CAMERA]`
//!
//! Without arguments: the built-in four rooms, baked here at 128, at 1024×512. The total is
//! the frame's GPU time (direct shadow maps included); the speedup is per-VPL shadow maps'
//! total over the row's at the same VPLs, measured in one run.

use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::{GateLevel, GateShape};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    GpuContext, GpuMode, GpuParams, GpuRenderer, MethodSettings, PassTimes,
};
use visgate_runtime::vpl::{PathParams, path_vpls};

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (_, scene, level) = common::scene_and_level(&mut args)?;
    let size = args.next().unwrap_or_else(|| "1024x512".into());
    let (w, h) = size.split_once('x').ok_or("size WxH")?;
    let size = [w.parse()?, h.parse()?];
    let camera = match args.next() {
        Some(name) => scene.camera(&name).ok_or("no such camera")?.clone(),
        None => scene
            .cameras
            .first()
            .ok_or("the scene has no camera")?
            .clone(),
    };
    let view = View::new(&camera, size)?;
    let only = std::env::var("GATE_TIMINGS_ONLY").ok();
    let gates = GateLevel::new(level, &scene)?;
    let tracer = Tracer::new(&scene);
    // Each measurement on a fresh device (lavapipe slows a pass that follows others on the
    // same device by up to 3×), after one warm-up frame.
    let render = |mode: GpuMode, vpls: &[visgate_runtime::vpl::Vpl]| {
        let ctx = GpuContext::new()?;
        let mut gpu = GpuRenderer::new(&ctx, &scene)?;
        gpu.set_level(&ctx, &gates)?;
        let params = GpuParams::with_mode(mode);
        gpu.render(&ctx, &view, &vpls[..vpls.len().min(16)], &params)?;
        gpu.render(&ctx, &view, vpls, &params)
            .map(|(_, t)| (t, ctx.adapter_info.name.clone()))
    };
    let (_, adapter) = render(GpuMode::DirectOnly, &[])?;
    println!(
        "{} camera {} at {}x{} on {adapter}; GPU ms per pass from timestamp queries",
        scene.name, camera.name, size[0], size[1]
    );
    println!(
        "| VPLs | mode | geometry pass | unique clusters | light assignment | shading (direct + \
         indirect) | VPL maps | indirect gather (+ blur) | total | per-VPL maps / this |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let counts: Vec<u32> = match std::env::var("GATE_TIMINGS_VPLS") {
        Ok(list) => list
            .split(',')
            .filter_map(|n| n.trim().parse().ok())
            .collect(),
        Err(_) => vec![512, 1024, 2048],
    };
    for n in counts {
        let vpls = path_vpls(
            &tracer,
            &scene.lights,
            &PathParams {
                paths: n,
                bounces: 1,
                seed: 1,
            },
        )?;
        let mut rows: Vec<(&str, Stages, Option<u64>)> = Vec::new();
        let s = MethodSettings::default();
        let mut disks = s.gates;
        disks.gates.shape = GateShape::Disk;
        let modes = [
            ("none", GpuMode::None),
            ("gates", GpuMode::Gates(s.gates)),
            ("gates-disk", GpuMode::Gates(disks)),
            ("gates per pixel", GpuMode::GatesPerPixel(s.gates.gates)),
            ("val-hard", GpuMode::ValHard(s.vals)),
            ("val-cssm", GpuMode::ValCssm(s.vals, s.cssm)),
            ("per-VPL shadow maps", GpuMode::PerVplShadowMaps(s.per_vpl)),
        ];
        let order: Vec<(&str, GpuMode)> = match &only {
            Some(list) => list
                .split(',')
                .filter_map(|o| modes.iter().find(|m| m.0 == o).copied())
                .collect(),
            None => modes.to_vec(),
        };
        for (name, mode) in order {
            // A mode that cannot run at this size (its lists outgrow the adapter) says why.
            let (t, _) = match render(mode, &vpls) {
                Ok(r) => r,
                Err(e) => {
                    println!("| {} | {name} | failed: {e} |", vpls.len());
                    continue;
                }
            };
            let g = Stages::of(&t).ok_or("the adapter has no timestamp queries")?;
            rows.push((name, g, t.lists.map(|l| l.entries)));
        }
        let total = |g: &Stages| g.total;
        let base = rows
            .iter()
            .find(|r| r.0 == "per-VPL shadow maps")
            .map_or(f64::NAN, |r| total(&r.1));
        for (name, g, entries) in &rows {
            let ms = |x: f64| format!("{:.1}", x * 1e3);
            let dash = |x: f64| if x > 0.0 { ms(x) } else { "–".into() };
            println!(
                "| {} | {name}{} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
                vpls.len(),
                entries.map_or(String::new(), |e| format!(" ({e} entries)")),
                ms(g.gbuffer),
                dash(g.unique_clusters),
                dash(g.light_assignment),
                ms(g.shade),
                dash(g.vpl_maps),
                dash(g.vpl_gather),
                ms(total(g)),
                base / total(g)
            );
        }
    }
    Ok(())
}

/// GPU seconds of the passes this table shows.
struct Stages {
    gbuffer: f64,
    unique_clusters: f64,
    light_assignment: f64,
    shade: f64,
    vpl_maps: f64,
    vpl_gather: f64,
    total: f64,
}

impl Stages {
    fn of(t: &PassTimes) -> Option<Stages> {
        let total = t.gpu_total()?;
        let g = |name: &str| t.gpu(name).unwrap_or(0.0);
        Some(Stages {
            gbuffer: g("geometry pass (G-buffer)"),
            unique_clusters: g("unique clusters"),
            light_assignment: g("light assignment"),
            shade: g("shading: direct + indirect lighting") + g("shading: direct lighting"),
            vpl_maps: g("VPL paraboloid maps"),
            vpl_gather: g("VPL gather") + g("indirect lighting") + g("blur + compose"),
            total,
        })
    }
}

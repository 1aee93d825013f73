//! An error table like Table II of the visibility-gates paper, from the CPU renderers: MSE
//! (and relative MSE, FLIP, the indirect energy ratio and the share of pixels black where the
//! reference's indirect light is) against the exact reference with the same VPLs, for direct light
//! only, no visibility on indirect light, and gate visibility (the paper's 1 hop, 2 hops,
//! oversized disks). The CPU twin of the gates mode gives the same image as the GPU's
//! clustered gates (the tests hold them equal).
//!
//! `cargo run --release --example gate_errors -- [SCENE] [LEVEL.vgate] [CAMERA|x,y,z:tx,ty,tz]`
//!
//! With a GPU adapter, the GPU methods follow on the same VPLs and view: none, gates with disks
//! and with portals, val-hard, val-cssm, per-VPL shadow maps.
//!
//! Light configurations: each of the scene's lights alone (all of them when there is one).
//! Without arguments: the built-in four rooms (a point light in one room, a spot in the room
//! diagonal to it), baked here at 128, seen by its camera and by a camera in the diagonal room.

use glam::Vec3;
use visgate_formats::Camera;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::{GateLevel, GateParams, GateShape};
use visgate_runtime::cpu::reference::{IndirectVisibility, ReferenceParams, render_with};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    CssmParams, GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer, PerVplParams,
    ValModeParams,
};
use visgate_runtime::hdr::HdrImage;
use visgate_runtime::metrics::{errors, flip, indirect_errors};
use visgate_runtime::vpl::{PathParams, path_vpls};

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (scene_arg, scene, level) = common::scene_and_level(&mut args)?;
    let mut cameras: Vec<Camera> = scene.cameras.clone();
    if let Some(c) = args.next() {
        let parse = |s: &str| -> Option<Vec3> {
            let v: Vec<f32> = s.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
        };
        cameras = match c.split_once(':') {
            Some((e, t)) => vec![Camera {
                name: "given".into(),
                eye: parse(e).ok_or("eye x,y,z")?,
                target: parse(t).ok_or("target x,y,z")?,
                up: Vec3::Y,
                fov_x_rad: 70f32.to_radians(),
            }],
            None => cameras.into_iter().filter(|k| k.name == c).collect(),
        };
    } else if scene_arg == "builtin:four-rooms" {
        cameras.push(Camera {
            name: "far room (indirect only)".into(),
            eye: Vec3::new(7.6, 1.6, 7.6),
            target: Vec3::new(4.6, 0.8, 4.6),
            up: Vec3::Y,
            fov_x_rad: 75f32.to_radians(),
        });
    }
    let gates = GateLevel::new(level, &scene)?;
    let tracer = Tracer::new(&scene);
    // The GPU methods beside the CPU twins, on the same VPLs and view (none without an adapter).
    let ctx = GpuContext::new().ok();
    println!(
        "{}: {} clusters, {} gates, 1024 light paths per configuration, 128×96, 1 spp",
        scene.name,
        gates.cluster_count(),
        gates.gate_count(),
    );
    let configs: Vec<Vec<visgate_formats::Light>> = if scene.lights.len() > 1 {
        scene.lights.iter().map(|l| vec![*l]).collect()
    } else {
        vec![scene.lights.clone()]
    };
    for (lights, cam) in configs
        .iter()
        .flat_map(|l| cameras.iter().map(move |c| (l, c)))
    {
        let vpls = path_vpls(
            &tracer,
            lights,
            &PathParams {
                paths: 1024,
                bounces: 1,
                seed: 1,
            },
        )?;
        let view = View::new(cam, [128, 96])?;
        let p = ReferenceParams {
            samples_per_pixel: 1,
            ..ReferenceParams::default()
        };
        let run = |vis: IndirectVisibility, indirect: bool| {
            let params = ReferenceParams { indirect, ..p };
            render_with(&tracer, lights, &vpls, &view, &params, vis, &|_, _| {}).map(|r| r.0)
        };
        let reference = run(IndirectVisibility::Exact, true)?;
        let direct = run(IndirectVisibility::Unoccluded, false)?;
        let light = match &lights[..] {
            [visgate_formats::Light::Point { position, .. }] => {
                format!("point light at {position}")
            }
            [visgate_formats::Light::Spot { position, .. }] => format!("spot light at {position}"),
            _ => format!("{} lights", lights.len()),
        };
        println!("\n{light} ({} VPLs), camera {}", vpls.len(), cam.name);
        println!("| method | MSE | rel. MSE | FLIP | indirect energy | black where lit |");
        println!("|---|---|---|---|---|---|");
        let gp = |oversize: f32, max_hops: u32| {
            IndirectVisibility::Gates(
                &gates,
                GateParams {
                    oversize,
                    max_hops,
                    shape: GateShape::Disk,
                    ..GateParams::default()
                },
            )
        };
        let portals = IndirectVisibility::Gates(
            &gates,
            GateParams {
                shape: GateShape::Portal,
                ..GateParams::default()
            },
        );
        for (name, vis, indirect) in [
            ("direct only", IndirectVisibility::Unoccluded, false),
            ("no visibility", IndirectVisibility::Unoccluded, true),
            ("gates (paper: 1 hop)", gp(1.0, 1), true),
            ("gates, 2 hops", gp(1.0, 2), true),
            ("gates × 1.5, 2 hops", gp(1.5, 2), true),
            ("gates × 2, 2 hops", gp(2.0, 2), true),
            ("portals (walk)", portals, true),
        ] {
            let img = run(vis, indirect)?;
            row(name, &img, &reference, &direct, None)?;
            let over = gates.take_walks_over_limit();
            if over > 0 {
                let limit = GateParams::default().max_walk;
                println!("|   ({over} portal walks reached the limit of {limit}: occluded) |");
            }
        }
        if let Some(ctx) = &ctx {
            // The configuration's lights alone, as the CPU rows.
            let mut alone = scene.clone();
            alone.lights = lights.clone();
            let mut gpu = GpuRenderer::new(ctx, &alone)?;
            gpu.set_level(ctx, &gates)?;
            let mut render = |mode: GpuMode| {
                gpu.render(ctx, &view, &vpls, &GpuParams::with_mode(mode))
                    .map(|r| r.0)
            };
            // GPU direct light (shadow maps, PCF) differs a little from the CPU's rays: the
            // indirect figures of GPU rows take the GPU's own direct light out (MSE, relative
            // MSE and FLIP are of the whole image, as a user sees it).
            let gpu_direct = render(GpuMode::DirectOnly)?;
            let disk = GateParams {
                shape: GateShape::Disk,
                ..GateParams::default()
            };
            for (name, mode) in [
                ("GPU none", GpuMode::None),
                (
                    "GPU gates, disks (2 hops)",
                    GpuMode::Gates(GatesParams {
                        gates: disk,
                        ..GatesParams::default()
                    }),
                ),
                ("GPU gates, portals", GpuMode::Gates(GatesParams::default())),
                ("GPU val-hard", GpuMode::ValHard(ValModeParams::new())),
                (
                    "GPU val-cssm",
                    GpuMode::ValCssm(ValModeParams::new(), CssmParams::default()),
                ),
                (
                    "GPU per-VPL shadow maps",
                    GpuMode::PerVplShadowMaps(PerVplParams::default()),
                ),
            ] {
                let img = render(mode)?;
                row(name, &img, &reference, &direct, Some(&gpu_direct))?;
            }
        }
    }
    Ok(())
}

/// One table row: MSE, relative MSE, FLIP, indirect energy ratio, black where lit; the
/// indirect light is the image less `own_direct` (its method's direct light) where given, less
/// the reference's `direct` otherwise.
fn row(
    name: &str,
    img: &HdrImage,
    reference: &HdrImage,
    direct: &HdrImage,
    own_direct: Option<&HdrImage>,
) -> Result<(), Box<dyn std::error::Error>> {
    let e = errors(img, reference)?;
    let (f, _) = flip(img, reference, 0.0)?;
    // The image's indirect light over the reference's direct light (a clone only then).
    let net;
    let with_reference_direct = match own_direct {
        Some(own) => {
            let mut m = img.clone();
            for ((p, o), d) in m.pixels.iter_mut().zip(&own.pixels).zip(&direct.pixels) {
                *p = *p - *o + *d;
            }
            net = m;
            &net
        }
        None => img,
    };
    let i = indirect_errors(with_reference_direct, reference, direct)?;
    println!(
        "| {name} | {:.3e} | {:.3e} | {f:.4} | {:.3} | {:.1} % |",
        e.mse,
        e.rel_mse,
        i.energy_ratio,
        i.black_where_lit * 100.0
    );
    Ok(())
}

//! An error table like Table II of the visibility-gates paper, from the CPU renderers: MSE
//! (and relative MSE, FLIP, the indirect energy ratio and the share of pixels black where the
//! reference's indirect light is) against the exact reference with the same VPLs, for direct light
//! only, no visibility on indirect light, and gate visibility (the paper's 1 hop, 2 hops,
//! oversized disks). The CPU twin of the gates mode gives the same image as the GPU's
//! clustered gates (the tests hold them equal).
//!
//! `cargo run --release --example gate_errors -- [SCENE] [LEVEL.vgate] [CAMERA|x,y,z:tx,ty,tz]`
//!
//! The GPU methods on the same VPLs and views are `visgate compare`'s (its report has every
//! mode's MSE, FLIP, indirect energy and black-where-lit share beside its pass times).
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
            row(name, &img, &reference, &direct)?;
            let over = gates.take_walks_over_limit();
            if over > 0 {
                let limit = GateParams::default().max_walk;
                println!("|   ({over} portal walks reached the limit of {limit}: occluded) |");
            }
        }
    }
    Ok(())
}

/// One table row: MSE, relative MSE, FLIP, indirect energy ratio, black where lit (the
/// indirect light is the image less the reference's `direct`: the CPU twins share its rays).
fn row(
    name: &str,
    img: &HdrImage,
    reference: &HdrImage,
    direct: &HdrImage,
) -> Result<(), Box<dyn std::error::Error>> {
    let e = errors(img, reference)?;
    let (f, _) = flip(img, reference, 0.0)?;
    let i = indirect_errors(img, reference, direct)?;
    println!(
        "| {name} | {:.3e} | {:.3e} | {f:.4} | {:.3} | {:.1} % |",
        e.mse,
        e.rel_mse,
        i.energy_ratio,
        i.black_where_lit * 100.0
    );
    Ok(())
}

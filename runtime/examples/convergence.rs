//! Convergence of the CPU reference with light-path VPLs: relative MSE (and MSE, FLIP) of the
//! image with N VPL paths against the image with `N_ref` paths, same camera, same pixel
//! samples, exact visibility.
//!
//! `cargo run --release -p visgate-runtime --example convergence -- [SCENE] [SIZE] [N_REF]`
//!
//! SCENE is a built-in name (cornell-box by default); SIZE the square image's side (96);
//! N_REF the reference's paths (65536). Prints a Markdown table for N = 256 … 16384.

use visgate_runtime::camera::View;
use visgate_runtime::cpu::reference::{ReferenceParams, render_reference};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::metrics::{errors, flip};
use visgate_runtime::vpl::{PathParams, path_vpls};
use visgate_scenes::Builtin;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "cornell-box".into());
    let size: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(96);
    let n_ref: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(65536);
    let b = Builtin::from_name(&name).ok_or(format!("no built-in scene '{name}'"))?;
    let scene = b.scene()?;
    let cam = scene.cameras.first().ok_or("scene has no camera")?;
    let view = View::new(cam, [size, size])?;
    let tracer = Tracer::new(&scene);
    let params = ReferenceParams {
        samples_per_pixel: 1,
        ..ReferenceParams::default()
    };
    let render = |n: u32| -> Result<_, Box<dyn std::error::Error>> {
        let vpls = path_vpls(
            &tracer,
            &scene.lights,
            &PathParams {
                paths: n,
                bounces: 1,
                seed: 1,
            },
        )?;
        let (img, stats) =
            render_reference(&tracer, &scene.lights, &vpls, &view, &params, &|_, _| {})?;
        Ok((img, stats, vpls.len()))
    };
    let (reference, rs, rn) = render(n_ref)?;
    println!(
        "{name} {size}x{size}, 1 spp, reference {n_ref} paths ({rn} VPLs): {:.1} s, {:.2} M shadow rays/s",
        rs.seconds,
        rs.shadow_rays as f64 / rs.seconds / 1e6
    );
    println!("| N paths | VPLs | rel. MSE | MSE | FLIP | render s |");
    println!("|---|---|---|---|---|---|");
    let mut n = 256;
    while n <= 16384 && n < n_ref {
        let (img, st, count) = render(n)?;
        let e = errors(&img, &reference)?;
        let (f, _) = flip(&img, &reference, 0.0)?;
        println!(
            "| {n} | {count} | {:.3e} | {:.3e} | {f:.4} | {:.2} |",
            e.rel_mse, e.mse, st.seconds
        );
        n *= 2;
    }
    Ok(())
}

//! Benchmark of the whole bake: bakes one scene several times in this process and prints each
//! stage's median and fastest time, the total, peak memory and the headline counts.
//!
//! `cargo run --release -p visgate-preprocess --example bake_bench -- SCENE [RESOLUTION] [RUNS]`
//!
//! SCENE is a scene `.toml` or a mesh file (`.obj`, `.gltf`, `.glb`); RESOLUTION is voxels on
//! the longest axis (256 by default); RUNS defaults to 5. The first run is a warm-up and is not
//! counted. The target: Crytek Sponza at 256 in under 3 s on 2 cores.

use std::path::Path;

use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_formats::{ImportOptions, Scene};
use visgate_preprocess::bake::{BakeOptions, bake};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: bake_bench SCENE [RESOLUTION] [RUNS]";
    let path = args.next().ok_or(usage)?;
    let res: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(256);
    let runs: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(5);
    if runs == 0 {
        return Err(format!("RUNS must be at least 1\n{usage}").into());
    }
    let scene = Scene::load(
        Path::new(&path),
        &ImportOptions {
            load_textures: false,
            ..ImportOptions::default()
        },
    )?;
    let params = BakeParams {
        resolution: Resolution::LongestAxisVoxels(res),
        ..BakeParams::default()
    };
    let options = BakeOptions::default();
    // Warm-up: page in the allocator and the scene.
    let first = bake(&scene, &params, &options, &|_| {})?;
    let mut reports = Vec::new();
    for _ in 0..runs {
        reports.push(bake(&scene, &params, &options, &|_| {})?.report);
    }
    let median = |mut v: Vec<f64>| -> (f64, f64) {
        v.sort_by(f64::total_cmp);
        (v[v.len() / 2], v[0])
    };
    println!(
        "{path} at {res}: grid {:?}, {} runs on {} thread(s)",
        first.report.grid.dims, runs, first.report.threads
    );
    println!("{:<22} {:>9} {:>9}", "stage", "median s", "min s");
    for (i, stage) in first.report.stages.iter().enumerate() {
        let (med, min) = median(reports.iter().map(|r| r.stages[i].seconds).collect());
        println!("{:<22} {med:>9.3} {min:>9.3}", stage.name);
    }
    let (med, min) = median(reports.iter().map(|r| r.total_seconds).collect());
    println!("{:<22} {med:>9.3} {min:>9.3}", "total");
    let s = &first.report.summary;
    println!(
        "peak memory {:.0} MiB; skeleton nodes {}, segmented nodes {}, clusters {}, gates {}, cycles {}",
        first.report.peak_memory_bytes.unwrap_or(0) as f64 / (1u64 << 20) as f64,
        s.skeleton_nodes,
        s.segmented_nodes[0],
        s.clusters,
        s.gates,
        s.cycles
    );
    Ok(())
}

//! Times the bake stages that exist so far on a scene file.
//!
//! `cargo run --release -p visgate-preprocess --example stages -- SCENE [RESOLUTION]`

use std::path::Path;
use std::time::Instant;

use visgate_formats::vgate::Resolution;
use visgate_formats::{ImportOptions, Scene};
use visgate_preprocess::{distance, voxelize};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: stages SCENE [RESOLUTION]")?;
    let res: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(256);
    let t = Instant::now();
    let scene = Scene::load(
        Path::new(&path),
        &ImportOptions {
            load_textures: false,
        },
    )?;
    let load_s = t.elapsed().as_secs_f64();
    let tris: Vec<_> = scene.static_triangles().collect();
    let bounds = scene.static_bounds().ok_or("no static geometry")?;
    let t = Instant::now();
    let meta = voxelize::grid_for(bounds, Resolution::LongestAxisVoxels(res), 16 << 30)?;
    let grid = voxelize::voxelize(meta, &tris);
    let vox_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let d2 = distance::squared_distance(meta.dims, &grid.solid);
    let edt_s = t.elapsed().as_secs_f64();
    let max_r = d2
        .iter()
        .copied()
        .filter(|&d| d < 1 << 40)
        .max()
        .unwrap_or(0);
    println!(
        "{path}: {} triangles, grid {:?} ({} voxels of {:.4} m), {} solid",
        tris.len(),
        meta.dims,
        grid.solid.len(),
        meta.voxel_size_m,
        grid.solid_count()
    );
    println!(
        "load {load_s:.3} s, voxelize {vox_s:.3} s, distance {edt_s:.3} s (largest max-ball radius {:.1} vx), {} threads",
        (max_r as f64).sqrt(),
        rayon::current_num_threads()
    );
    Ok(())
}

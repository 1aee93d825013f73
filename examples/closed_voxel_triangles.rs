//! What the voxel walk gains by testing the triangles in the closed voxels it crosses
//! (`runtime::cpu::sight_triangles`): every pixel–VPL pair of a view that could exchange light
//! (as `portal_agreement`), walked four ways and measured against the shadow ray — between
//! ends set off the surfaces with closed voxels blocking (`--no-closed-voxel-planes`), the
//! default walk with a closed voxel passed where the segment meets neither of its planes
//! (`runtime::cpu::sight_planes`, its ends 0.3 voxels off the surfaces where the planes allow),
//! the blocking walk's ends with a closed voxel passed where the segment misses the triangles
//! listed in it, and the walk of `--closed-voxel-triangles`, along the true segment between the
//! surface points, with the lists. Then, per pixel, the light of every VPL (cos · cos / d², pixel centres) each way
//! lets through against the shadow rays': the share of the lit pixels that a way leaves black
//! (under a tenth of the rays' light, where that is at least a tenth of its mean), `visgate
//! compare`'s *black where lit* without the interleaving.
//!
//! `cargo run --release --example closed_voxel_triangles -- SCENE LEVEL.vgate CAMERA [WxH] [PATHS]`

#[path = "common/pairs.rs"]
mod pairs;

use visgate_runtime::cpu::portal_walk::facing_pairs;
use visgate_runtime::cpu::sight::Closed;

fn main() -> anyhow::Result<()> {
    let pairs::Pairs {
        gates,
        tracer,
        vpls,
        view,
        camera,
        size: [w, h],
        ..
    } = pairs::from_args("closed_voxel_triangles")?;
    let sight = gates.sight();
    let lists = sight.triangles();
    println!(
        "closed voxels with triangles {}, {} lists (shared), triangle references {}",
        lists.voxels(),
        lists.lists(),
        lists.references()
    );
    let planes = sight.planes();
    let [one, two] = planes.counts();
    println!(
        "closed voxels {}: one plane {one}, two {two}",
        planes.voxels()
    );
    const WAYS: [&str; 4] = [
        "closed voxels block (ends off the surfaces)",
        "closed voxels' planes (the default)",
        "+ triangles in closed voxels (ends off the surfaces)",
        "the true segment walked with the triangles (--closed-voxel-triangles)",
    ];
    // Per way: [exact][walk] pair counts.
    let mut n = [[[0u64; 2]; 2]; 4];
    // Per pixel with pairs: the light the rays let through, then each way's.
    let mut light: Vec<[f64; 5]> = Vec::new();
    let mut last_point = None;
    facing_pairs(&tracer, &gates, &view, &vpls, |pair| {
        // The pairs come a pixel at a time.
        if last_point != Some(pair.point) {
            last_point = Some(pair.point);
            light.push([0.0; 5]);
        }
        let ends = (
            sight.end(pair.vpl, pair.vpl_normal),
            sight.end(pair.point, pair.point_normal),
        );
        let ways = match ends {
            (Some(x), Some(y)) => [
                sight.clear(x, y, Closed::Blocks),
                sight.visible_off_surfaces(
                    pair.vpl,
                    pair.vpl_normal,
                    pair.point,
                    pair.point_normal,
                    true,
                ),
                sight.clear(x, y, Closed::Triangles),
                sight.visible(pair.vpl, pair.vpl_normal, pair.point, pair.point_normal),
            ],
            _ => [true; 4],
        };
        let d = pair.vpl - pair.point;
        let dir = d.normalize_or_zero();
        let g = f64::from(
            dir.dot(pair.point_normal).max(0.0) * (-dir).dot(pair.vpl_normal).max(0.0)
                / d.length_squared().max(0.01),
        );
        let pixel = light.last_mut().expect("a pixel");
        pixel[0] += if pair.exact { g } else { 0.0 };
        for (k, clear) in ways.into_iter().enumerate() {
            n[k][pair.exact as usize][clear as usize] += 1;
            pixel[k + 1] += if clear { g } else { 0.0 };
        }
    });
    let pairs: u64 = n[0].iter().flatten().sum();
    let visible: u64 = n[0][1].iter().sum();
    println!(
        "{camera}: {pairs} pairs ({visible} visible), {} VPLs, {w}x{h}",
        vpls.len()
    );
    let pct = |k: u64| 100.0 * k as f64 / pairs.max(1) as f64;
    for (name, m) in WAYS.iter().zip(n) {
        let (blocked, through) = (m[1][0], m[0][1]);
        println!(
            "{name}: agree {:.2} %, false occluded {blocked} ({:.1} % of the visible pairs), \
             false visible {through} ({:.2} %)",
            100.0 - pct(blocked + through),
            100.0 * blocked as f64 / visible.max(1) as f64,
            pct(through)
        );
    }
    // Pixels without pairs get no light: the mean is over the whole view.
    let mean = light.iter().map(|p| p[0]).sum::<f64>() / f64::from(w * h);
    let lit: Vec<&[f64; 5]> = light.iter().filter(|p| p[0] >= 0.1 * mean).collect();
    for (k, name) in WAYS.iter().enumerate() {
        let black = lit.iter().filter(|p| p[k + 1] < 0.1 * p[0]).count();
        println!(
            "{name}: black where lit (every VPL at every pixel) {black} of {} ({:.1} %)",
            lit.len(),
            100.0 * black as f64 / lit.len().max(1) as f64
        );
    }
    Ok(())
}

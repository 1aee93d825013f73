//! What the voxel walk would gain if the closed voxels it crosses were tested against the
//! triangles in them: every pixel–VPL pair of a view that could exchange light (as
//! `portal_agreement`), the voxel walk's answer beside a hybrid that walks the same ends but,
//! in each closed voxel, lets the segment pass unless it hits one of the triangles that touch
//! that voxel (the sight grid as a ray tracer's acceleration grid). Both are measured against
//! the shadow ray; then the hybrid that also tests the true segment (between the surface points
//! themselves) against the same triangles. A measurement, not a mode: it says how much of the
//! walk's false occlusion is a segment grazing geometry within a voxel, and what the hybrid
//! costs in false visible pairs (the walk's ends sit off their surfaces, the shadow ray's do
//! not, so the ends' segment alone passes thin geometry the true one meets).
//!
//! `cargo run --release --example closed_voxel_triangles -- SCENE LEVEL.vgate CAMERA [WxH] [PATHS]`

#[path = "common/pairs.rs"]
mod pairs;

use std::collections::HashMap;

use glam::{IVec3, Vec3};
use visgate_formats::vgate::GridMeta;
use visgate_preprocess::voxelize::tri_box_overlap;
use visgate_runtime::cpu::portal_walk::facing_pairs;
use visgate_runtime::cpu::sight::VoxelSight;

/// The triangles touching each closed voxel of the sight grid.
struct ClosedTriangles {
    grid: GridMeta,
    by_voxel: HashMap<IVec3, Vec<u32>>,
    triangles: Vec<[Vec3; 3]>,
}

impl ClosedTriangles {
    fn new(grid: GridMeta, sight: &VoxelSight, triangles: Vec<[Vec3; 3]>) -> ClosedTriangles {
        let (o, vs) = (Vec3::from(grid.origin_m), grid.voxel_size_m);
        let dims = IVec3::from(grid.dims.map(|d| d as i32));
        let mut by_voxel: HashMap<IVec3, Vec<u32>> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            let lo = tri[0].min(tri[1]).min(tri[2]);
            let hi = tri[0].max(tri[1]).max(tri[2]);
            let a = ((lo - o) / vs).floor().as_ivec3().max(IVec3::ZERO);
            let b = ((hi - o) / vs).floor().as_ivec3().min(dims - 1);
            let corners = tri.map(|p| p.as_dvec3());
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        let v = IVec3::new(x, y, z);
                        let c = (o + (v.as_vec3() + 0.5) * vs).as_dvec3();
                        if !sight.open(v) && tri_box_overlap(c, 0.5 * f64::from(vs), corners) {
                            by_voxel.entry(v).or_default().push(t as u32);
                        }
                    }
                }
            }
        }
        ClosedTriangles {
            grid,
            by_voxel,
            triangles,
        }
    }

    /// Whether the segment between voxel coordinates `x` and `y` passes every closed voxel it
    /// crosses without hitting a triangle there (a plain 3D DDA, voxel by voxel).
    fn clear(&self, sight: &VoxelSight, x: Vec3, y: Vec3, also: Option<(Vec3, Vec3)>) -> bool {
        let (o, vs) = (Vec3::from(self.grid.origin_m), self.grid.voxel_size_m);
        let (a, b) = (o + x * vs, o + y * vs);
        let d = y - x;
        let step = d.signum().as_ivec3();
        let mut v = x.floor().as_ivec3();
        let end = y.floor().as_ivec3();
        let next = |k: usize, v: IVec3| {
            if d[k] == 0.0 {
                f32::INFINITY
            } else {
                let face = if d[k] > 0.0 { v[k] + 1 } else { v[k] } as f32;
                (face - x[k]) / d[k]
            }
        };
        let mut t = Vec3::new(next(0, v), next(1, v), next(2, v));
        loop {
            if !sight.open(v) && (self.hit(v, a, b) || also.is_some_and(|(p, q)| self.hit(v, p, q)))
            {
                return false;
            }
            if v == end {
                return true;
            }
            let k = if t.x <= t.y && t.x <= t.z {
                0
            } else if t.y <= t.z {
                1
            } else {
                2
            };
            if t[k] > 1.0 {
                return true;
            }
            v[k] += step[k];
            t[k] = next(k, v);
        }
    }

    /// Whether segment `a`–`b` (m) hits a triangle touching voxel `v` strictly between its ends
    /// (Möller–Trumbore).
    fn hit(&self, v: IVec3, a: Vec3, b: Vec3) -> bool {
        let Some(list) = self.by_voxel.get(&v) else {
            return false;
        };
        let d = b - a;
        list.iter().any(|&t| {
            let [p0, p1, p2] = self.triangles[t as usize];
            let (e1, e2) = (p1 - p0, p2 - p0);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                return false;
            }
            let s = a - p0;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let w = d.dot(q) / det;
            let h = e2.dot(q) / det;
            u >= 0.0 && w >= 0.0 && u + w <= 1.0 && h > 1e-4 && h < 1.0 - 1e-4
        })
    }
}

fn main() -> anyhow::Result<()> {
    let pairs::Pairs {
        gates,
        tracer,
        vpls,
        view,
        camera,
        size: [w, h],
        scene,
    } = pairs::from_args("closed_voxel_triangles")?;
    let grid = gates.baked().info.sight_grid;
    let sight = gates.sight();
    let t0 = std::time::Instant::now();
    let closed = ClosedTriangles::new(grid, sight, scene.static_triangles().collect());
    let refs: usize = closed.by_voxel.values().map(Vec::len).sum();
    println!(
        "closed voxels with triangles {}, triangle references {refs}, built in {:.2} s",
        closed.by_voxel.len(),
        t0.elapsed().as_secs_f64()
    );
    // [exact][walk][hybrid] pair counts; the same with the true segment tested too.
    let mut n = [[[0u64; 2]; 2]; 2];
    let mut n2 = [[[0u64; 2]; 2]; 2];
    let eps = 1e-3 * grid.voxel_size_m;
    facing_pairs(&tracer, &gates, &view, &vpls, |pair| {
        let ends = (
            sight.end(pair.vpl, pair.vpl_normal),
            sight.end(pair.point, pair.point_normal),
        );
        let truth = (
            pair.vpl + pair.vpl_normal * eps,
            pair.point + pair.point_normal * eps,
        );
        let (walk, hybrid, both) = match ends {
            (Some(x), Some(y)) => {
                let walk = sight.clear(x, y);
                (
                    walk,
                    walk || closed.clear(sight, x, y, None),
                    walk || closed.clear(sight, x, y, Some(truth)),
                )
            }
            _ => (true, true, true),
        };
        n[pair.exact as usize][walk as usize][hybrid as usize] += 1;
        n2[pair.exact as usize][walk as usize][both as usize] += 1;
    });
    let pairs: u64 = n.iter().flatten().flatten().sum();
    let pct = |k: u64| 100.0 * k as f64 / pairs.max(1) as f64;
    let visible: u64 = n[1].iter().flatten().sum();
    let (walk_blocked, hybrid_blocked) = (n[1][0][0] + n[1][0][1], n[1][0][0] + n[1][1][0]);
    let (walk_through, hybrid_through) = (n[0][1][0] + n[0][1][1], n[0][0][1] + n[0][1][1]);
    println!(
        "{camera}: {pairs} pairs ({visible} visible), {} VPLs, {w}x{h}",
        vpls.len()
    );
    let (both_blocked, both_through) = (n2[1][0][0] + n2[1][1][0], n2[0][0][1] + n2[0][1][1]);
    for (name, blocked, through) in [
        ("voxel walk", walk_blocked, walk_through),
        (
            "walk + triangles in closed voxels",
            hybrid_blocked,
            hybrid_through,
        ),
        (
            "... tested on the true segment too",
            both_blocked,
            both_through,
        ),
    ] {
        println!(
            "{name}: agree {:.2} %, false occluded {blocked} ({:.1} % of the visible pairs), \
             false visible {through} ({:.2} %)",
            100.0 - pct(blocked + through),
            100.0 * blocked as f64 / visible.max(1) as f64,
            pct(through)
        );
    }
    Ok(())
}

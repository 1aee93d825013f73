//! The portal walk against shadow rays on any scene and level, every pixel–VPL pair of a view
//! that could exchange light (the two surfaces face each other): the pairs an exact ray sees
//! that the walk finds or blocks, the pairs it occludes that the walk lets through or blocks,
//! and the blocked ones by how many cluster changes the segment passes (sampled at 101
//! points); then the voxel walk's agreement on the same pairs (every closed voxel blocking:
//! `--no-closed-voxel-planes`; `closed_voxel_triangles` measures the default), where along the segment it
//! blocks the visible ones (voxels from the nearer end), and both walks' CPU time.
//! `tests/portals.rs` holds `ajar-door` to this on built-ins; this measures real levels.
//!
//! `cargo run --release --example portal_agreement -- SCENE LEVEL.vgate CAMERA [WxH] [PATHS]`
//!
//! Defaults: 160x90, 1,024 one-bounce light paths (seed 1, as `visgate compare`).

#[path = "common/pairs.rs"]
mod pairs;

use glam::Vec3;
use visgate_runtime::cpu::gates::{GateLevel, GateParams, Walk};
use visgate_runtime::cpu::portal_walk::facing_pairs;
use visgate_runtime::cpu::sight::{Closed, VoxelSight};

/// Pair counts of one view.
#[derive(Debug, Default)]
struct Counts {
    visible_found: u64,
    visible_blocked: u64,
    occluded_let_through: u64,
    occluded_blocked: u64,
    /// Blocked visible pairs by the cluster changes along the segment: 0, 1, 2–3, 4 or more.
    blocked_by_changes: [u64; 4],
    over_the_limit: u64,
    /// The voxel walk: visible and found, visible and blocked, occluded and let through.
    voxels: [u64; 3],
    /// The voxel walk's blocked visible pairs by how far the first closed voxel lies from the
    /// nearer end, in voxels: under 1, 1–2, 2–4, 4–8, 8 or more.
    voxels_blocked_from_end: [u64; 5],
    /// CPU time of the portal walks and of the voxel walks.
    seconds: [f64; 2],
}

/// Cluster changes along `a`–`b`, sampled at 101 points (looked up facing along the segment).
fn changes(gates: &GateLevel, a: Vec3, b: Vec3) -> usize {
    let dir = (b - a).normalize_or_zero();
    let mut last = None;
    let mut n = 0;
    for k in 0..=100 {
        let c = gates.cluster_at(a + (b - a) * (k as f32 / 100.0), dir);
        if last.is_some() && c != last.flatten() {
            n += 1;
        }
        last = Some(c);
    }
    n
}

/// How far along the walk from `x` to `y` (voxel coordinates) the voxel that blocks it lies
/// from the nearer end, in voxels (bisection on where the walk stops being clear).
fn block_from_end(sight: &VoxelSight, x: Vec3, y: Vec3) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..24 {
        let m = 0.5 * (lo + hi);
        if sight.clear(x, x + (y - x) * m, Closed::Blocks) {
            lo = m;
        } else {
            hi = m;
        }
    }
    let len = (y - x).length();
    (lo * len).min((1.0 - lo) * len)
}

fn main() -> anyhow::Result<()> {
    let pairs::Pairs {
        gates,
        tracer,
        vpls,
        view,
        camera,
        size: [w, h],
        ..
    } = pairs::from_args("portal_agreement")?;
    let walk = GateParams::default();
    let mut n = Counts::default();
    facing_pairs(&tracer, &gates, &view, &vpls, |pair| {
        let t = std::time::Instant::now();
        let found = match gates.walk(pair.vpl, pair.there, pair.point, pair.here, walk.max_walk) {
            Walk::Visible(_) => true,
            Walk::Blocked => false,
            Walk::Limit => {
                n.over_the_limit += 1;
                false
            }
        };
        n.seconds[0] += t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let sight = gates.sight();
        let through = sight.visible_off_surfaces(
            pair.vpl,
            pair.vpl_normal,
            pair.point,
            pair.point_normal,
            false,
        );
        n.seconds[1] += t.elapsed().as_secs_f64();
        match (pair.exact, through) {
            (true, true) => n.voxels[0] += 1,
            (true, false) => {
                n.voxels[1] += 1;
                let ends = (
                    sight.end(pair.vpl, pair.vpl_normal),
                    sight.end(pair.point, pair.point_normal),
                );
                if let (Some(x), Some(y)) = ends {
                    let d = block_from_end(sight, x, y);
                    n.voxels_blocked_from_end[[1.0, 2.0, 4.0, 8.0].partition_point(|&b| b <= d)] +=
                        1;
                }
            }
            (false, true) => n.voxels[2] += 1,
            (false, false) => {}
        }
        match (pair.exact, found) {
            (true, true) => n.visible_found += 1,
            (true, false) => {
                n.visible_blocked += 1;
                let k = match changes(&gates, pair.vpl, pair.point) {
                    0 => 0,
                    1 => 1,
                    2 | 3 => 2,
                    _ => 3,
                };
                n.blocked_by_changes[k] += 1;
            }
            (false, true) => n.occluded_let_through += 1,
            (false, false) => n.occluded_blocked += 1,
        }
    });
    let pairs = n.visible_found + n.visible_blocked + n.occluded_let_through + n.occluded_blocked;
    let pct = |k: u64| 100.0 * k as f64 / pairs.max(1) as f64;
    println!("{camera}: {pairs} pairs, {} VPLs, {w}x{h}", vpls.len());
    println!(
        "agree {:.2} %: visible and found {}, occluded and blocked {}",
        pct(n.visible_found + n.occluded_blocked),
        n.visible_found,
        n.occluded_blocked
    );
    println!(
        "false occluded {} ({:.2} %; {:.1} % of the visible pairs), false visible {} ({:.2} %)",
        n.visible_blocked,
        pct(n.visible_blocked),
        100.0 * n.visible_blocked as f64 / (n.visible_found + n.visible_blocked).max(1) as f64,
        n.occluded_let_through,
        pct(n.occluded_let_through)
    );
    let [c0, c1, c2, c4] = n.blocked_by_changes;
    println!(
        "blocked visible pairs by cluster changes along the segment: 0: {c0}, 1: {c1}, \
         2-3: {c2}, 4+: {c4}; walks over the limit {}",
        n.over_the_limit
    );
    let [found, blocked, let_through] = n.voxels;
    println!(
        "voxel walk: agree {:.2} %, false occluded {blocked} ({:.2} %; {:.1} % of the visible \
         pairs), false visible {let_through} ({:.2} %)",
        100.0 - pct(blocked + let_through),
        pct(blocked),
        100.0 * blocked as f64 / (found + blocked).max(1) as f64,
        pct(let_through)
    );
    let [b1, b2, b4, b8, b_far] = n.voxels_blocked_from_end;
    println!(
        "voxel walk's blocked visible pairs by the first closed voxel's distance from the nearer \
         end: < 1 voxel {b1}, 1-2 {b2}, 2-4 {b4}, 4-8 {b8}, 8 or more {b_far}"
    );
    println!(
        "CPU time: portal walks {:.0} ms, voxel walks {:.0} ms",
        n.seconds[0] * 1e3,
        n.seconds[1] * 1e3
    );
    Ok(())
}

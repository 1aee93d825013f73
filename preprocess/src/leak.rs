//! Where a closed level leaks: the openings through which its kept empty space reaches the
//! outside, found as Quake's map compiler finds them for its point file — a path through the
//! empty voxels from a camera or light that keeps the space (or a bare mesh's inside,
//! inside.rs) to the grid's bounds.
//!
//! The path is the **widest** one out (the one whose narrowest point is widest: a bottleneck
//! search over the clearance of each voxel, its distance to the nearest voxel that is not
//! empty; the outside beyond the bounds counts as empty), so it runs through the middle of the
//! largest opening. Its narrowest voxel, the one nearest the outside among equals, is the
//! **opening** — a window, a gap under a door, a missing wall — about twice its clearance less
//! a voxel wide. Separate openings are found one after another: each found opening is closed
//! (a ball of √2 its clearance and two voxels more: a square window's corners too) and the
//! search runs again, up to [`MAX_OPENINGS`]; a path out within twice an opening's ball (what
//! it left open of a long window, the rest of a roof open to the sky) is that opening again,
//! closed with a ball twice as wide and not listed.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::io::{self, Write};

use serde::Serialize;
use visgate_formats::vgate::GridMeta;

/// Openings listed at most.
pub const MAX_OPENINGS: usize = 8;

/// Searches at most (an opening's leftovers found again are not listed twice).
const MAX_SEARCHES: usize = 2 * MAX_OPENINGS;

/// A path from a camera or light to the outside and the opening it passes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeakPath {
    /// The camera or light it starts from, e.g. `light 1`.
    pub from: String,
    /// Where that is, metres.
    pub from_m: [f32; 3],
    /// The opening: the path's narrowest voxel's centre, metres.
    pub opening_m: [f32; 3],
    /// About how wide the opening is, metres.
    pub width_m: f32,
    /// The path's voxel centres from the seed to the bounds, metres.
    pub path_m: Vec<[f32; 3]>,
}

impl LeakPath {
    /// One line for the terminal.
    pub fn describe(&self) -> String {
        // To the centimetre, or finer where the opening is under 10 cm wide (a level modelled
        // small: 8 mm read "0.01 m wide" at a place given to the centimetre).
        let d = decimals_for(self.width_m);
        let p = |v: [f32; 3]| format!("({:.d$}, {:.d$}, {:.d$})", v[0], v[1], v[2]);
        format!(
            "{} at {} m reaches the outside through an opening near {} m, about {:.d$} m wide",
            self.from,
            p(self.from_m),
            p(self.opening_m),
            self.width_m
        )
    }
}

/// Decimals that show two significant digits of `width` (metres), at least 2, at most 6.
fn decimals_for(width: f32) -> usize {
    if width.is_nan() || width <= 0.0 {
        return 2;
    }
    ((-width.log10()).ceil() as i32 + 1).clamp(2, 6) as usize
}

/// The openings as a clause for a message: `: leak: …; leak: …` (nothing when there are none).
pub fn describe_all(openings: &[LeakPath]) -> String {
    openings
        .iter()
        .map(|o| format!("; leak: {}", o.describe()))
        .collect::<String>()
        .replacen(';', ":", 1)
}

/// Whether voxel `v` lies next to the grid's solid border ring (the bounds): where kept empty
/// space of a closed scene leaks.
pub fn next_to_ring(v: [u32; 3], dims: [u32; 3]) -> bool {
    (0..3).any(|a| v[a] == 1 || v[a] + 2 == dims[a])
}

/// The openings through which the `empty` voxels (`true`: kept empty space) reach the bounds
/// from the `seeds` (a name, its position and its voxel index).
pub fn find_openings(
    meta: &GridMeta,
    empty: &[bool],
    seeds: &[(String, [f32; 3], usize)],
) -> Vec<LeakPath> {
    find_openings_with(meta, empty, &clearance_to_walls(meta, empty), seeds)
}

/// Each voxel's squared distance to the nearest voxel that is neither `empty` nor on the
/// border ring, which stands for the outside beyond the bounds: open, not an obstacle.
/// [Units: voxels²]
pub fn clearance_to_walls(meta: &GridMeta, empty: &[bool]) -> Vec<u64> {
    let dims = meta.dims;
    let ring = |i: usize| {
        let v = meta.coords(i as u32);
        (0..3).any(|a| v[a] == 0 || v[a] + 1 == dims[a])
    };
    let not_empty: Vec<bool> = (0..empty.len()).map(|i| !empty[i] && !ring(i)).collect();
    crate::distance::squared_distance(meta.dims, &not_empty)
}

/// [`find_openings`] with each voxel's [`clearance_to_walls`] given.
pub fn find_openings_with(
    meta: &GridMeta,
    empty: &[bool],
    d2: &[u64],
    seeds: &[(String, [f32; 3], usize)],
) -> Vec<LeakPath> {
    let mut open = empty.to_vec();
    let mut out = Vec::new();
    // Openings found so far: voxel and the radius closed about it. [Units: voxels]
    let mut closed: Vec<([u32; 3], f32)> = Vec::new();
    for search in 0..MAX_SEARCHES {
        if out.len() >= MAX_OPENINGS {
            break;
        }
        // Once an opening is closed, a plain flood first: the widest-path search's heap costs
        // several times as much to learn that the last one is closed (0.63–0.73 s on a level
        // of 3 M empty voxels, the flood about 0.1 s). The first search has a way out: the
        // caller saw it.
        if search > 0 && !reaches_bounds(meta, &open, seeds) {
            break;
        }
        let Some((path, seed)) = widest_path_out(meta, &open, d2, seeds) else {
            break;
        };
        // The narrowest voxel, the one nearest the outside among equals.
        let k = (0..path.len())
            .rev()
            .min_by_key(|&k| d2[path[k]])
            .expect("a path has a voxel");
        let clearance = (d2[path[k]] as f32).sqrt();
        let centre = |i: usize| meta.voxel_to_world(meta.coords(i as u32));
        let at = meta.coords(path[k] as u32);
        // What the ball about an opening left open of it — the corners of a square window, the
        // rest of a roof open to the sky — is the same opening, not another: its ball grows
        // twice as wide, so that a wide opening takes a few searches, not one a ball.
        let same = closed.iter_mut().find(|(c, r)| {
            let d2: f32 = (0..3).map(|a| (at[a] as f32 - c[a] as f32).powi(2)).sum();
            d2 <= (2.0 * *r) * (2.0 * *r)
        });
        // A ball that holds a square window's corners.
        let ball = std::f32::consts::SQRT_2 * clearance + 2.0;
        if let Some((c, r)) = same {
            *r *= 2.0;
            close_ball(meta, &mut open, meta.index(*c), *r);
            close_ball(meta, &mut open, path[k], ball);
            continue;
        }
        close_ball(meta, &mut open, path[k], ball);
        closed.push((at, ball));
        out.push(LeakPath {
            from: seeds[seed].0.clone(),
            from_m: seeds[seed].1,
            opening_m: centre(path[k]),
            width_m: (2.0 * clearance - 1.0).max(1.0) * meta.voxel_size_m,
            path_m: path.iter().map(|&i| centre(i)).collect(),
        });
    }
    out
}

/// The widest 26-connected path through `open` voxels from a seed to a voxel next to the
/// bounds — the one whose smallest squared clearance `d2` is largest (a bottleneck search:
/// voxels taken widest reach first) — seed first, and which seed it starts from.
fn widest_path_out(
    meta: &GridMeta,
    open: &[bool],
    d2: &[u64],
    seeds: &[(String, [f32; 3], usize)],
) -> Option<(Vec<usize>, usize)> {
    const NONE: u32 = u32::MAX;
    let mut parent = vec![NONE; open.len()];
    // (the path's smallest clearance so far, nearer first among equals, voxel)
    let mut heap = BinaryHeap::new();
    for &(_, _, i) in seeds {
        if open.get(i) == Some(&true) && parent[i] == NONE {
            parent[i] = i as u32;
            heap.push((d2[i], Reverse(0u32), i));
        }
    }
    while let Some((reach, Reverse(steps), i)) = heap.pop() {
        let v = meta.coords(i as u32);
        if next_to_ring(v, meta.dims) {
            let (mut path, mut c) = (vec![i], i);
            while parent[c] as usize != c {
                c = parent[c] as usize;
                path.push(c);
            }
            path.reverse();
            let seed = seeds.iter().position(|s| s.2 == path[0]).unwrap_or(0);
            return Some((path, seed));
        }
        for k in 0..27 {
            if k == 13 {
                continue;
            }
            let o = [k % 3, (k / 3) % 3, k / 9];
            // The border ring is solid, so a voxel inside it has every neighbour in the grid.
            let j = meta.index(std::array::from_fn(|a| v[a] + o[a] - 1));
            if open[j] && parent[j] == NONE {
                parent[j] = i as u32;
                heap.push((reach.min(d2[j]), Reverse(steps + 1), j));
            }
        }
    }
    None
}

/// Whether a 26-connected path through `open` voxels leads from a seed to a voxel next to
/// the bounds (breadth-first, a bit a voxel).
fn reaches_bounds(meta: &GridMeta, open: &[bool], seeds: &[(String, [f32; 3], usize)]) -> bool {
    let mut seen = vec![0u64; open.len().div_ceil(64)];
    let mut queue: Vec<usize> = Vec::new();
    for &(_, _, i) in seeds {
        if open.get(i) == Some(&true) && seen[i / 64] & (1 << (i % 64)) == 0 {
            seen[i / 64] |= 1 << (i % 64);
            queue.push(i);
        }
    }
    let [nx, ny, _] = meta.dims.map(|d| d as isize);
    let offsets: [isize; 27] = std::array::from_fn(|k| {
        let k = k as isize;
        (k % 3 - 1) + nx * ((k / 3) % 3 - 1) + nx * ny * (k / 9 - 1)
    });
    while let Some(i) = queue.pop() {
        if next_to_ring(meta.coords(i as u32), meta.dims) {
            return true;
        }
        for o in offsets {
            // The border ring is solid, so a voxel inside it has every neighbour in the grid.
            let j = (i as isize + o) as usize;
            if open[j] && seen[j / 64] & (1 << (j % 64)) == 0 {
                seen[j / 64] |= 1 << (j % 64);
                queue.push(j);
            }
        }
    }
    false
}

/// Makes the ball of `radius` voxels about voxel `i` not open.
fn close_ball(meta: &GridMeta, open: &mut [bool], i: usize, radius: f32) {
    let v = meta.coords(i as u32).map(i64::from);
    let r = radius.ceil() as i64;
    for dz in -r..=r {
        for dy in -r..=r {
            for dx in -r..=r {
                let w = [v[0] + dx, v[1] + dy, v[2] + dz];
                if (0..3).any(|a| w[a] < 0 || w[a] >= i64::from(meta.dims[a]))
                    || ((dx * dx + dy * dy + dz * dz) as f32) > radius * radius
                {
                    continue;
                }
                open[meta.index(w.map(|c| c as u32))] = false;
            }
        }
    }
}

/// Writes `paths` as a PLY of polylines (vertices and edges), each opening a vertex of its own
/// (property `opening` 1), to open beside the level in Blender or MeshLab.
pub fn write_ply(w: &mut dyn Write, paths: &[LeakPath]) -> io::Result<()> {
    let vertices: usize = paths.iter().map(|p| p.path_m.len() + 1).sum();
    let edges: usize = paths.iter().map(|p| p.path_m.len().saturating_sub(1)).sum();
    writeln!(
        w,
        "ply\nformat ascii 1.0\ncomment visgate leaks: the path from a camera or light to the \
         outside, and its opening\nelement vertex {vertices}\nproperty float x\nproperty float \
         y\nproperty float z\nproperty uchar opening\nelement edge {edges}\nproperty int \
         vertex1\nproperty int vertex2\nend_header"
    )?;
    for p in paths {
        for v in &p.path_m {
            writeln!(w, "{} {} {} 0", v[0], v[1], v[2])?;
        }
        let o = p.opening_m;
        writeln!(w, "{} {} {} 1", o[0], o[1], o[2])?;
    }
    let mut base = 0;
    for p in paths {
        for k in 1..p.path_m.len() {
            writeln!(w, "{} {}", base + k - 1, base + k)?;
        }
        base += p.path_m.len() + 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leak_is_told_to_two_digits_of_its_width_at_every_scale() {
        let leak = |scale: f32| LeakPath {
            from: "light 0".to_string(),
            from_m: [5.84 * scale, 1.47 * scale, -2.53 * scale],
            opening_m: [7.97 * scale, 1.53 * scale, -1.97 * scale],
            width_m: 0.81 * scale,
            path_m: Vec::new(),
        };
        assert_eq!(
            leak(1.0).describe(),
            "light 0 at (5.84, 1.47, -2.53) m reaches the outside through an opening near \
             (7.97, 1.53, -1.97) m, about 0.81 m wide"
        );
        // The same level modelled 1/100 the size: 8.1 mm, not "0.01 m".
        let small = leak(0.01).describe();
        assert!(
            small.contains("(0.0797, 0.0153, -0.0197) m") && small.ends_with("about 0.0081 m wide"),
            "{small}"
        );
        // 100 times the size: to the centimetre still.
        assert!(leak(100.0).describe().ends_with("about 81.00 m wide"));
    }
}

//! The sight grid's voxelization: the thinnest that still stops a voxel walk.
//!
//! A voxel is closed when a triangle crosses one of its three *centre segments* — the segments
//! through its centre along x, y and z, each as long as the voxel (Schwarz & Seidel 2010's
//! 6-separating surface voxelization tests the same thing in projection). A path of voxels
//! joined by faces (what the voxel walk steps through) joins their centres by such segments,
//! half in each voxel: if the path crosses a surface, the crossing lies on a centre segment of
//! one of its voxels, and that voxel is closed. So no walk passes through a watertight surface,
//! and a plane closes one voxel per column (the conservative voxelization closes every voxel it
//! touches: two or three per column, which narrows every opening by up to a voxel at each edge,
//! and thickens a thin arch, trim or railing into a wall).
//!
//! Each triangle is rasterized three times, once along each axis: the grid lines along axis `a`
//! through voxel centres that its projection covers (edge tests with 1e-10 of a voxel's
//! slack, so a line through an edge shared by two triangles hits one of them) meet its plane at
//! one point, whose voxel is closed (both voxels when the point lies on their common face).

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use visgate_formats::vgate::{GridMeta, VoxelBits};

use crate::voxelize::SharedBits;

/// The open voxels of `meta`'s grid: not crossed by a triangle on a centre segment, and not in
/// the one-voxel border ring (closed, as the level grid's is).
pub fn open_voxels(meta: GridMeta, triangles: &[[Vec3; 3]]) -> VoxelBits {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let n = nx * ny * nz;
    let grid = Lines {
        origin: Vec3::from(meta.origin_m).as_dvec3(),
        size: f64::from(meta.voxel_size_m),
        dims: [nx, ny, nz],
    };
    let closed = SharedBits::new(n);
    triangles.par_iter().for_each(|tri| {
        grid.mark(tri.map(|p| p.as_dvec3()), &mut |[x, y, z]| {
            closed.set(x + nx * (y + ny * z));
        });
    });
    let mut open = closed.into_words();
    open.par_iter_mut().for_each(|w| *w = !*w);
    // The border ring: two voxels a row, and the rows of the four sides.
    let mut close = |x: usize, y: usize, z: usize| {
        let i = x + nx * (y + ny * z);
        open[i / 64] &= !(1 << (i % 64));
    };
    for (y, z) in (0..nz).flat_map(|z| (0..ny).map(move |y| (y, z))) {
        let side = y == 0 || z == 0 || y == ny - 1 || z == nz - 1;
        for x in if side { 0..nx } else { 0..0 } {
            close(x, y, z);
        }
        close(0, y, z);
        close(nx - 1, y, z);
    }
    VoxelBits::from_words(n, open)
}

/// `x` rounded down, as a whole number: `f64::floor` is a call into the C library on the
/// x86-64 baseline (no SSE4.1), and the sight grid reads one a line it meets. Exact for
/// `|x| < 2^63`.
fn floor(x: f64) -> i64 {
    let i = x as i64;
    i.saturating_sub(i64::from((i as f64) > x))
}

/// The grid's voxel-centre lines.
struct Lines {
    origin: DVec3,
    size: f64,
    dims: [usize; 3],
}

impl Lines {
    /// Calls `hit` with every voxel one of whose centre segments triangle `v` crosses (a voxel
    /// of the border ring marks its neighbour inside instead, as the level's voxelizer does).
    fn mark(&self, v: [DVec3; 3], hit: &mut impl FnMut([usize; 3])) {
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let q = v.map(|p| (p - self.origin) / self.size);
        for a in 0..3 {
            if n[a] == 0.0 {
                continue;
            }
            let (u, w) = ((a + 1) % 3, (a + 2) % 3);
            let p = q.map(|p| DVec2::new(p[u], p[w]));
            // Twice the projected area's sign: edge tests read the same way for either
            // winding.
            let s = (p[1] - p[0]).perp_dot(p[2] - p[0]).signum();
            let lo = p[0].min(p[1]).min(p[2]);
            let hi = p[0].max(p[1]).max(p[2]);
            // The voxels on axis k whose centre (i + 0.5) lies in lo..=hi.
            let cells = |k: usize, lo: f64, hi: f64| {
                let first = (lo - 0.5).ceil().max(0.0) as usize;
                let last = (hi - 0.5).floor().min(self.dims[k] as f64 - 1.0);
                first..(last + 1.0).max(0.0) as usize
            };
            // Each edge's start, direction and tolerance, read the same way for every centre.
            let edges: [(DVec2, DVec2, f64); 3] = std::array::from_fn(|k| {
                let (e0, e1) = (p[k], p[(k + 1) % 3]);
                (e0, e1 - e0, -1e-10 * (e1 - e0).length())
            });
            for iw in cells(w, lo.y, hi.y) {
                for iu in cells(u, lo.x, hi.x) {
                    let c = DVec2::new(iu as f64 + 0.5, iw as f64 + 0.5);
                    let inside = edges
                        .iter()
                        .all(|&(e0, e, tol)| s * e.perp_dot(c - e0) >= tol);
                    if !inside {
                        continue;
                    }
                    // Where the line meets the plane: n · (x − q0) = 0, solved for x[a].
                    let t = q[0][a] - (n[u] * (c.x - q[0][u]) + n[w] * (c.y - q[0][w])) / n[a];
                    let mut at = [0usize; 3];
                    (at[u], at[w]) = (iu, iw);
                    // The voxels either side of a boundary the line meets the plane on, else
                    // the one it meets it in (once).
                    for ia in floor(t - 1e-10)..=floor(t + 1e-10) {
                        if ia < 0 || ia >= self.dims[a] as i64 {
                            continue;
                        }
                        at[a] = ia as usize;
                        hit(std::array::from_fn(|k| at[k].clamp(1, self.dims[k] - 2)));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};
    use visgate_formats::vgate::{GridMeta, Resolution, VoxelBits};

    use super::{floor, open_voxels};
    use crate::voxelize::{grid_for, voxelize};

    /// The 12 triangles of the cube of half-size `h` about `c`, turned by `q`.
    fn cube(c: Vec3, h: f32, q: Quat) -> Vec<[Vec3; 3]> {
        let corner = |i: usize| {
            let s = Vec3::new(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            );
            c + q * s
        };
        let faces = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        faces
            .iter()
            .flat_map(|f| {
                let p = f.map(corner);
                [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
            })
            .collect()
    }

    /// The open voxels reached from voxel `from` across faces.
    fn flood(meta: &GridMeta, open: &VoxelBits, from: [usize; 3]) -> Vec<bool> {
        let [nx, ny, nz] = meta.dims.map(|d| d as usize);
        let mut seen = vec![false; nx * ny * nz];
        let index = |[x, y, z]: [usize; 3]| x + nx * (y + ny * z);
        let mut stack = vec![from];
        seen[index(from)] = true;
        while let Some(v) = stack.pop() {
            for (a, d) in [(0, -1), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1)] {
                let mut w = v;
                w[a] = (v[a] as isize + d) as usize;
                let i = index(w);
                if open.get(i) && !seen[i] {
                    seen[i] = true;
                    stack.push(w);
                }
            }
        }
        seen
    }

    #[test]
    fn floor_rounds_down_as_the_library_does() {
        for x in [
            0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.999_999, -2.000_001, 1e-10, -1e-10, 511.5, 1e15,
            -1e15,
        ] {
            assert_eq!(floor(x), x.floor() as i64, "{x}");
        }
        assert_eq!(floor(f64::NEG_INFINITY), i64::MIN);
    }

    #[test]
    fn no_path_across_faces_leaves_a_closed_box_turned_and_scaled_anyhow() {
        let mut next = crate::xorshift32(0x51ab_c0de);
        let mut unit = || (next() as f32 / u32::MAX as f32) * 2.0 - 1.0;
        for case in 0..40 {
            let scale = [1e-3f32, 1.0, 37.0, 1e4][case % 4];
            let q = Quat::from_axis_angle(
                Vec3::new(unit(), unit(), unit()).normalize_or(Vec3::Y),
                3.2 * unit(),
            );
            let c = Vec3::new(unit(), unit(), unit()) * 0.1 * scale;
            let tris = cube(c, 0.5 * scale, q);
            let bounds = (c - Vec3::splat(scale), c + Vec3::splat(scale));
            let res = [12, 17, 32, 61][case / 10];
            let meta =
                grid_for(bounds, Resolution::LongestAxisVoxels(res), u64::MAX).expect("grid");
            let open = open_voxels(meta, &tris);
            let inside = meta.dims.map(|d| d as usize / 2);
            assert!(
                open.get(
                    inside[0]
                        + meta.dims[0] as usize * (inside[1] + meta.dims[1] as usize * inside[2])
                ),
                "case {case}: the box's centre is closed"
            );
            let seen = flood(&meta, &open, inside);
            // Every voxel reached lies within a voxel's diagonal of the box (its centre is
            // inside the box or its surface passes through the voxel).
            let reach = 0.5 * scale + f32::sqrt(3.0) * meta.voxel_size_m;
            let [nx, ny, _] = meta.dims.map(|d| d as usize);
            for (i, _) in seen.iter().enumerate().filter(|(_, s)| **s) {
                let v = Vec3::new(
                    (i % nx) as f32,
                    (i / nx % ny) as f32,
                    (i / (nx * ny)) as f32,
                );
                let p = Vec3::from(meta.origin_m) + (v + 0.5) * meta.voxel_size_m;
                let local = q.inverse() * (p - c);
                assert!(
                    local.abs().max_element() <= reach,
                    "case {case} (scale {scale}, {res} voxels): voxel {v} reached, {local} from the box's centre"
                );
            }
        }
    }

    #[test]
    fn thin_closes_a_subset_of_what_the_conservative_voxelization_closes() {
        let mut next = crate::xorshift32(0x0dd_ba11);
        let mut unit = || next() as f32 / u32::MAX as f32;
        let bounds = (Vec3::ZERO, Vec3::splat(1.0));
        for res in [9, 24, 50] {
            let meta =
                grid_for(bounds, Resolution::LongestAxisVoxels(res), u64::MAX).expect("grid");
            let tris: Vec<[Vec3; 3]> = (0..60)
                .map(|k| {
                    let a = Vec3::new(unit(), unit(), unit());
                    let size = [0.01, 0.1, 0.6][k % 3];
                    let mut p = || a + (Vec3::new(unit(), unit(), unit()) - 0.5) * size;
                    [p(), p(), p()].map(|p| p.clamp(Vec3::ZERO, Vec3::ONE))
                })
                .collect();
            let thin = open_voxels(meta, &tris);
            let solid = voxelize(meta, &tris).solid;
            let extra = (0..solid.len())
                .filter(|&i| thin.get(i) && solid[i])
                .count();
            assert!((0..solid.len()).all(|i| thin.get(i) || solid[i]), "{res}");
            assert!(
                extra > 0,
                "{res}: the thin voxelization closed all the conservative one did"
            );
        }
    }

    #[test]
    fn a_plane_closes_a_voxel_a_column_where_the_conservative_voxels_close_two_or_three() {
        let bounds = (Vec3::ZERO, Vec3::splat(1.0));
        let meta = grid_for(bounds, Resolution::LongestAxisVoxels(10), u64::MAX).expect("grid");
        let quad = |z: f32| {
            let p =
                [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| Vec3::new(x, y, z));
            vec![[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
        };
        let closed = |tris: &[[Vec3; 3]]| {
            let open = open_voxels(meta, tris);
            let conservative = voxelize(meta, tris).solid.iter().filter(|s| !**s).count();
            // (how many fewer voxels it closes than the conservative voxelization, how many
            // it closes)
            (
                open.count_ones() - conservative as u64,
                open.len() - open.count_ones(),
            )
        };
        // A plane through the middle of a layer of voxels closes that layer, as the
        // conservative voxelization does: 10 × 10 columns inside the border ring.
        let (fewer, all) = closed(&quad(0.45));
        assert_eq!(fewer, 0, "one layer either way in the middle of a layer");
        let ring = 12 * 12 * 12 - 10 * 10 * 10;
        assert_eq!(all, ring + 10 * 10);
        // Tilted across three layers: every column closed, by fewer voxels than the
        // conservative voxelization closes (it takes each voxel the plane touches).
        let p = [
            (0.0, 0.0, 0.41),
            (1.0, 0.0, 0.41),
            (1.0, 1.0, 0.69),
            (0.0, 1.0, 0.69),
        ]
        .map(|(x, y, z)| Vec3::new(x, y, z));
        let tilted = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
        let open = open_voxels(meta, &tilted);
        for (x, y) in (1..11).flat_map(|x| (1..11).map(move |y| (x, y))) {
            assert!(
                (1..11).any(|z| !open.get(x + 12 * (y + 12 * z))),
                "column ({x}, {y}) open"
            );
        }
        // Exactly one a column (the lines along x and y meet the plane only where the
        // column's own voxel is), 20 fewer than the conservative voxelization's.
        let (fewer, all) = closed(&tilted);
        assert_eq!((fewer, all), (20, ring + 10 * 10));
    }

    #[test]
    fn a_crack_narrower_than_a_voxel_is_open_only_where_a_row_of_centres_falls_in_it() {
        let bounds = (Vec3::ZERO, Vec3::splat(1.0));
        let meta = grid_for(bounds, Resolution::LongestAxisVoxels(10), u64::MAX).expect("grid");
        // A wall at x = 0.52 across the whole level, in two pieces that leave a crack between
        // heights lo and hi (the voxel centres lie at heights 0.05, 0.15, …).
        let wall = |lo: f32, hi: f32| {
            let quad = |y0: f32, y1: f32| {
                let p = [(y0, 0.0), (y0, 1.0), (y1, 1.0), (y1, 0.0)]
                    .map(|(y, z)| Vec3::new(0.52, y, z));
                [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
            };
            [quad(0.0, lo), quad(hi, 1.0)].concat()
        };
        // Voxel (x, y, z) of the grid's inside (1..=10 each; centres at (i - 0.5) / 10).
        let across = |tris: &[[Vec3; 3]]| {
            let open = open_voxels(meta, tris);
            let seen = flood(&meta, &open, [3, 5, 5]);
            seen[8 + 12 * (5 + 12 * 5)]
        };
        assert!(
            across(&wall(0.44, 0.46)),
            "a row of centres (0.45) in the crack: open"
        );
        assert!(!across(&wall(0.49, 0.51)), "no centre in the crack: sealed");
        assert!(!across(&wall(0.5, 0.5)), "no crack");
        // The conservative voxels seal it: every voxel beside the crack touches a piece.
        let solid = voxelize(meta, &wall(0.44, 0.46)).solid;
        let open = VoxelBits::from_fn(solid.len(), |i| !solid[i]);
        assert!(!flood(&meta, &open, [3, 5, 5])[8 + 12 * (5 + 12 * 5)]);
    }
}

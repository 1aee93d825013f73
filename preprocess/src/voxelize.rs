//! Stage 2, voxelize: conservative triangle/box overlap → binary solid grid.
//!
//! Every voxel that a static triangle touches (closed box, separating-axis test of
//! Akenine-Möller) is solid, so a wall thinner than a voxel still closes the space behind it.
//! The grid covers the static bounds plus one voxel on every side; that border ring is solid
//! by convention (it closes open roofs), so the empty space never touches the grid's edge. No
//! triangle marks the ring itself: a voxel of the ring that a triangle touches marks its
//! neighbour inside instead, so that a wall lying exactly on the bounds closes the level at
//! every resolution and scale whatever the rounding puts where (and empty space next to the
//! ring is truly beyond the geometry: a leak).

use std::ops::RangeInclusive;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
pub use visgate_formats::geom::tri_box_overlap;
use visgate_formats::vgate::{GridMeta, Resolution};

use crate::BakeError;

/// Bytes per voxel that a whole bake holds at its peak (solid flags, squared distance,
/// labels, nearest-node and cluster grids, thinning state), used to refuse a resolution that
/// would not fit before anything is allocated.
pub const BAKE_BYTES_PER_VOXEL: u64 = 24;

/// A binary voxel grid: `true` = solid.
#[derive(Debug, Clone, PartialEq)]
pub struct SolidGrid {
    /// Grid placement and size.
    pub meta: GridMeta,
    /// One flag per voxel, x fastest.
    pub solid: Vec<bool>,
}

impl SolidGrid {
    /// Number of solid voxels.
    pub fn solid_count(&self) -> u64 {
        self.solid.iter().filter(|&&s| s).count() as u64
    }
}

/// The grid that covers `bounds` at `resolution`, with a one-voxel border on every side.
pub fn grid_for(
    bounds: (Vec3, Vec3),
    resolution: Resolution,
    memory_limit_bytes: u64,
) -> Result<GridMeta, BakeError> {
    let (lo, hi) = (bounds.0.as_dvec3(), bounds.1.as_dvec3());
    let extent = hi - lo;
    if let Some(axis) = flat_axis(extent) {
        return Err(BakeError::Flat {
            extent: extent.to_array(),
            axis,
        });
    }
    let size = match resolution {
        Resolution::LongestAxisVoxels(n) => {
            if !(8..=2048).contains(&n) {
                return Err(BakeError::Param(format!(
                    "resolution {n} voxels on the longest axis must be in 8..=2048"
                )));
            }
            extent.max_element() / f64::from(n)
        }
        Resolution::VoxelSizeM(s) => {
            if !(s.is_finite() && s > 0.0) {
                return Err(BakeError::Param(format!(
                    "voxel size {s} m must be a finite number > 0"
                )));
            }
            f64::from(s)
        }
    };
    if !(size.is_finite() && size > 0.0) {
        return Err(BakeError::Param(format!(
            "the static geometry is a point (extent {extent} m): nothing to voxelize"
        )));
    }
    let inner = (extent / size).ceil().max(DVec3::ONE);
    let dims_f = inner + 2.0;
    if dims_f.max_element() > f64::from(u32::MAX / 4) {
        return Err(BakeError::TooLarge {
            dims: dims_f.to_array(),
            bytes: f64::INFINITY,
            limit: memory_limit_bytes,
        });
    }
    let bytes = dims_f.x * dims_f.y * dims_f.z * BAKE_BYTES_PER_VOXEL as f64;
    if bytes > memory_limit_bytes as f64 {
        return Err(BakeError::TooLarge {
            dims: dims_f.to_array(),
            bytes,
            limit: memory_limit_bytes,
        });
    }
    // Centre the voxels on the bounds so the border is symmetric.
    let slack = (inner * size - extent) * 0.5;
    let origin = lo - slack - DVec3::splat(size);
    Ok(GridMeta {
        origin_m: origin.as_vec3().to_array(),
        voxel_size_m: size as f32,
        dims: dims_f.to_array().map(|d| d as u32),
    })
}

/// The axis along which bounds of this extent are flat (`visgate_formats::geom::flat_axis`),
/// named.
fn flat_axis(extent: DVec3) -> Option<char> {
    visgate_formats::geom::flat_axis(extent).map(|a| ['x', 'y', 'z'][a])
}

/// Voxels across the level's shortest side that [`all_solid`] suggests. [Units: voxels]
const SUGGESTED_ACROSS: f64 = 24.0;

/// Why a grid with no empty voxel (the empty-space stage finds none) is useless and what voxel
/// size would do, with the grid and the memory that takes: a ground or a sky far wider than
/// the rooms sets the voxel (the ajar door on a 400 m ground: 3.1 m voxels at 128, its 3 m
/// rooms one voxel high).
pub fn all_solid(meta: &GridMeta) -> String {
    let [nx, ny, nz] = meta.dims;
    let vs = f64::from(meta.voxel_size_m);
    // The inner extent (the grid less its border ring).
    let extent = meta
        .dims
        .map(|d| f64::from(d.saturating_sub(2).max(1)) * vs);
    let shortest = extent.iter().copied().fold(f64::INFINITY, f64::min);
    let size = shortest / SUGGESTED_ACROSS;
    let dims = extent.map(|e| (e / size).ceil() + 2.0);
    let bytes = dims.iter().product::<f64>() * BAKE_BYTES_PER_VOXEL as f64;
    format!(
        "every voxel of the {nx} x {ny} x {nz} grid is solid: the level is {:.1} x {:.1} x {:.1} m \
         and its voxels {vs:.3} m, so its shortest side is {:.0} voxel(s) across. Raise \
         --resolution so the geometry's gaps are wider than a voxel; where a ground or a sky far \
         wider than the rooms sets the grid, crop it in the modelling tool, or give a voxel size: \
         --voxel-size {size:.3} puts {SUGGESTED_ACROSS:.0} voxels across the shortest side \
         ({:.0} x {:.0} x {:.0} voxels, {:.1} GiB to bake)",
        extent[0],
        extent[1],
        extent[2],
        shortest / vs,
        dims[0],
        dims[1],
        dims[2],
        bytes / f64::from(1u32 << 30)
    )
}

/// Marks every voxel a triangle touches, plus the border ring, as solid.
pub fn voxelize(meta: GridMeta, triangles: &[[Vec3; 3]]) -> SolidGrid {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let n = nx * ny * nz;
    let origin = Vec3::from(meta.origin_m).as_dvec3();
    let size = f64::from(meta.voxel_size_m);
    // A hair over half a voxel, so that a triangle lying exactly on a voxel face marks both
    // sides (conservative) whatever the rounding.
    let half = 0.5 * size * (1.0 + 1e-9);
    let grid = TriGrid {
        origin,
        size,
        half,
        dims: [nx, ny, nz],
    };
    // One grid of bits marked from every thread: a grid a rayon split (4.4 MB each at 512) was
    // allocated, filled and merged.
    let bits = SharedBits::new(n);
    triangles.par_iter().for_each(|tri| {
        grid.mark(tri.map(|p| p.as_dvec3()), &mut |[x, y, z]| {
            // Geometry never falls into the border ring: a wall on the bounds (rounding may put
            // it in the ring alone) marks the first voxel inside instead.
            let (x, y, z) = (x.clamp(1, nx - 2), y.clamp(1, ny - 2), z.clamp(1, nz - 2));
            bits.set(x + nx * (y + ny * z));
        });
    });
    // Unpacked a row at a time in parallel, with the border ring.
    let mut solid = vec![false; n];
    solid.par_chunks_mut(nx).enumerate().for_each(|(row, out)| {
        let (y, z) = (row % ny, row / ny);
        if y == 0 || z == 0 || y == ny - 1 || z == nz - 1 {
            out.fill(true);
            return;
        }
        let first = row * nx;
        for (x, s) in out.iter_mut().enumerate() {
            *s = bits.get(first + x);
        }
        out[0] = true;
        out[nx - 1] = true;
    });
    SolidGrid { meta, solid }
}

/// A grid of bits that every thread sets (an OR in any order gives the same bits), for the
/// voxelizers: one grid, where a grid a thread costs as many copies as rayon splits the work.
pub(crate) struct SharedBits(Vec<AtomicU64>);

impl SharedBits {
    /// `n` bits, all clear.
    pub(crate) fn new(n: usize) -> SharedBits {
        SharedBits(
            (0..n.div_ceil(64))
                .into_par_iter()
                .map(|_| AtomicU64::new(0))
                .collect(),
        )
    }

    /// Sets bit `i`. A voxel is marked by every triangle around it: a read first spares the
    /// atomic write where its bit is set.
    pub(crate) fn set(&self, i: usize) {
        let (word, bit) = (&self.0[i / 64], 1u64 << (i % 64));
        if word.load(Ordering::Relaxed) & bit == 0 {
            word.fetch_or(bit, Ordering::Relaxed);
        }
    }

    /// Bit `i`.
    pub(crate) fn get(&self, i: usize) -> bool {
        self.0[i / 64].load(Ordering::Relaxed) >> (i % 64) & 1 == 1
    }

    /// The bits as words (bit `i` in word `i / 64`).
    pub(crate) fn into_words(self) -> Vec<u64> {
        self.0.into_par_iter().map(AtomicU64::into_inner).collect()
    }
}

/// The grid as the voxelizer sees it: voxel `i` on axis `a` spans `origin[a] + [i, i + 1) ·
/// size`, tested as a closed box of half-size `half`.
struct TriGrid {
    origin: DVec3,
    size: f64,
    half: f64,
    dims: [usize; 3],
}

impl TriGrid {
    /// The voxel of coordinate `t` on axis `a`, clamped to the grid.
    fn cell(&self, t: f64, a: usize) -> usize {
        (((t - self.origin[a]) / self.size).floor().max(0.0) as usize).min(self.dims[a] - 1)
    }

    /// The centre of voxel `i` on axis `a`.
    fn centre(&self, a: usize, i: usize) -> f64 {
        self.origin[a] + (i as f64 + 0.5) * self.size
    }

    /// The voxels on axis `a` whose centre lies in `lo..=hi` widened by a millionth of a voxel
    /// (far more than rounding moves it), within `span`.
    fn centres_in(
        &self,
        a: usize,
        (lo, hi): (f64, f64),
        span: (usize, usize),
    ) -> RangeInclusive<usize> {
        let slack = 1e-6 * self.size + 1e-12 * (lo.abs() + hi.abs());
        let (lo, hi) = (lo - slack, hi + slack);
        let low = self.cell(lo - 0.5 * self.size, a);
        let low = low + usize::from(self.centre(a, low) < lo);
        low.max(span.0)..=self.cell(hi - 0.5 * self.size, a).min(span.1)
    }

    /// Calls `hit` with every voxel that triangle `v` touches ([`tri_box_overlap`]). The box
    /// around the triangle is walked as columns along the axis its normal is nearest, each row
    /// of columns only where the triangle's part in the row's slab reaches (within the box's
    /// half-size); in each column only the voxels whose centre lies within the box's reach of
    /// the triangle's plane are tested — a voxel or two a column instead of the box's whole
    /// depth; the exact test decides as before.
    fn mark(&self, v: [DVec3; 3], hit: &mut impl FnMut([usize; 3])) {
        let h = self.half;
        let lo = v[0].min(v[1]).min(v[2]) - h;
        let hi = v[0].max(v[1]).max(v[2]) + h;
        let span = |k: usize| (self.cell(lo[k], k), self.cell(hi[k], k));
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let a = n.abs().max_position();
        let (u, w) = ((a + 1) % 3, (a + 2) % 3);
        let reach = h * (n.x.abs() + n.y.abs() + n.z.abs());
        let (w0, w1) = span(w);
        let inside = Inside::new(v, u, w, h);
        for iw in w0..=w1 {
            let cw = self.centre(w, iw);
            let Some((u_lo, u_hi)) = slab_extent(v, u, w, cw, h) else {
                continue;
            };
            for iu in self.centres_in(u, (u_lo - h, u_hi + h), span(u)) {
                let cu = self.centre(u, iu);
                let within = inside.column(cu, cw);
                let column = if n[a] == 0.0 {
                    span(a).0..=span(a).1
                } else {
                    // |n · (c − v0)| ≤ reach, solved for the centre's coordinate on axis a.
                    let s = n[u] * (cu - v[0][u]) + n[w] * (cw - v[0][w]);
                    let (t0, t1) = ((-reach - s) / n[a], (reach - s) / n[a]);
                    let along = (t0.min(t1) + v[0][a], t0.max(t1) + v[0][a]);
                    self.centres_in(a, along, span(a))
                };
                for ia in column {
                    let mut at = [0usize; 3];
                    (at[a], at[u], at[w]) = (ia, iu, iw);
                    let c = DVec3::from_array(std::array::from_fn(|k| self.centre(k, at[k])));
                    // A column inside the triangle's outline: the box touches the triangle
                    // where it touches its plane, so the nine edge axes need no testing.
                    let plane = within.then(|| plane_verdict(n, v[0], c, reach)).flatten();
                    if plane.unwrap_or_else(|| tri_box_overlap(c, h, v)) {
                        hit(at);
                    }
                }
            }
        }
    }
}

/// How far clear of a boundary a fast answer must be, relative to the quantities compared: far
/// more than rounding moves them, so the fast answers are the separating-axis test's.
const MARGIN: f64 = 1e-9;

/// Whether the plane of triangle `v` (normal `n`, not normalized) passes through the box about
/// `c` whose reach along `n` is `reach`, where the answer is clear of rounding (`None`: too
/// near to tell; the full test decides).
fn plane_verdict(n: DVec3, v0: DVec3, c: DVec3, reach: f64) -> Option<bool> {
    let d = n.dot(v0 - c).abs();
    if d < reach * (1.0 - MARGIN) {
        Some(true)
    } else if d > reach * (1.0 + MARGIN) {
        Some(false)
    } else {
        None
    }
}

/// A triangle's outline projected along its dominant axis, for telling which columns of voxels
/// lie wholly inside it.
struct Inside {
    /// Each edge's start and direction, projected, and the square's reach across the edge (in
    /// the edge test's units: the direction is not normalized): a column's centre must lie
    /// that far inside, and a margin more.
    edges: [(DVec2, DVec2, f64); 3],
    /// The projection's winding (0: degenerate, no column is inside).
    sign: f64,
}

impl Inside {
    /// Triangle `v` projected onto axes `u` and `w`, for squares of half-width `h`.
    fn new(v: [DVec3; 3], u: usize, w: usize, h: f64) -> Inside {
        let p = v.map(|q| DVec2::new(q[u], q[w]));
        let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        // signum() of ±0 is ±1: a degenerate outline keeps 0.
        let sign = if area == 0.0 { 0.0 } else { area.signum() };
        let edges = std::array::from_fn(|k| {
            let (e0, e) = (p[k], p[(k + 1) % 3] - p[k]);
            (e0, e, h * (e.x.abs() + e.y.abs()))
        });
        Inside { edges, sign }
    }

    /// Whether the square of half-width `h` about column centre (`cu`, `cw`) lies inside the
    /// outline, clear of rounding.
    fn column(&self, cu: f64, cw: f64) -> bool {
        let c = DVec2::new(cu, cw);
        self.sign != 0.0
            && self.edges.iter().all(|&(e0, e, half)| {
                let d = c - e0;
                let slack = MARGIN * (e.x.abs() + e.y.abs()) * (d.x.abs() + d.y.abs() + half);
                self.sign * e.perp_dot(d) - half > slack
            })
    }
}

/// The extent on axis `u` of the part of triangle `v` whose coordinate on axis `w` lies within
/// `h` of `c`: its vertices in that slab and its edges' crossings of the slab's two faces
/// (`None`: the triangle misses the slab).
fn slab_extent(v: [DVec3; 3], u: usize, w: usize, c: f64, h: f64) -> Option<(f64, f64)> {
    let (lo, hi) = (c - h, c + h);
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |x: f64| {
        min = min.min(x);
        max = max.max(x);
    };
    for k in 0..3 {
        let (p, q) = (v[k], v[(k + 1) % 3]);
        if (lo..=hi).contains(&p[w]) {
            take(p[u]);
        }
        for face in [lo, hi] {
            if (p[w] - face) * (q[w] - face) < 0.0 {
                let t = (face - p[w]) / (q[w] - p[w]);
                take(p[u] + t * (q[u] - p[u]));
            }
        }
    }
    (min <= max).then_some((min, max))
}

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

use glam::{DVec3, Vec3};
use rayon::prelude::*;
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
            "the static geometry is flat or a point (extent {extent} m): nothing to voxelize"
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

/// Marks every voxel a triangle touches, plus the border ring, as solid.
pub fn voxelize(meta: GridMeta, triangles: &[[Vec3; 3]]) -> SolidGrid {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let n = nx * ny * nz;
    let words = n.div_ceil(64);
    let origin = Vec3::from(meta.origin_m).as_dvec3();
    let size = f64::from(meta.voxel_size_m);
    // A hair over half a voxel, so that a triangle lying exactly on a voxel face marks both
    // sides (conservative) whatever the rounding.
    let half = 0.5 * size * (1.0 + 1e-9);
    let bits = triangles
        .par_chunks(4096)
        .fold(
            || vec![0u64; words],
            |mut bits, chunk| {
                for tri in chunk {
                    let v = tri.map(|p| p.as_dvec3());
                    let lo = v[0].min(v[1]).min(v[2]);
                    let hi = v[0].max(v[1]).max(v[2]);
                    let cell = |p: DVec3, a: usize, n: usize| {
                        (((p[a] - origin[a]) / size).floor().max(0.0) as usize).min(n - 1)
                    };
                    let (x0, x1) = (cell(lo - half, 0, nx), cell(hi + half, 0, nx));
                    let (y0, y1) = (cell(lo - half, 1, ny), cell(hi + half, 1, ny));
                    let (z0, z1) = (cell(lo - half, 2, nz), cell(hi + half, 2, nz));
                    for z in z0..=z1 {
                        for y in y0..=y1 {
                            for x in x0..=x1 {
                                let c = origin
                                    + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * size;
                                if tri_box_overlap(c, half, v) {
                                    // Geometry never falls into the border ring: a wall on
                                    // the bounds (rounding may put it in the ring alone)
                                    // marks the first voxel inside instead.
                                    let (x, y, z) = (
                                        x.clamp(1, nx - 2),
                                        y.clamp(1, ny - 2),
                                        z.clamp(1, nz - 2),
                                    );
                                    let i = x + nx * (y + ny * z);
                                    bits[i / 64] |= 1 << (i % 64);
                                }
                            }
                        }
                    }
                }
                bits
            },
        )
        .reduce(
            || vec![0u64; words],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x |= y);
                a
            },
        );
    let mut solid: Vec<bool> = (0..n).map(|i| bits[i / 64] >> (i % 64) & 1 == 1).collect();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if x == 0 || y == 0 || z == 0 || x == nx - 1 || y == ny - 1 || z == nz - 1 {
                    solid[x + nx * (y + ny * z)] = true;
                }
            }
        }
    }
    SolidGrid { meta, solid }
}

/// Whether triangle `v` touches the closed axis-aligned box of centre `c` and half-size `h`
/// (separating axis theorem, Akenine-Möller 2001: 3 box normals, the triangle normal, and the
/// 9 cross products of box axes and triangle edges).
pub fn tri_box_overlap(c: DVec3, h: f64, v: [DVec3; 3]) -> bool {
    let v = v.map(|p| p - c);
    // Box normals: the triangle's bounds against the box.
    let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
    if lo.max_element() > h || hi.min_element() < -h {
        return false;
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    for edge in e {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            let a = axis.cross(edge);
            let p = v.map(|q| a.dot(q));
            let r = h * (a.x.abs() + a.y.abs() + a.z.abs());
            if p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r {
                return false;
            }
        }
    }
    let n = e[0].cross(e[1]);
    let r = h * (n.x.abs() + n.y.abs() + n.z.abs());
    n.dot(v[0]).abs() <= r
}

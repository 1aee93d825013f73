//! The sight grid's stage: a bit a voxel, open where no triangle crosses the voxel's centre
//! segments ([`crate::separating`]), on a grid finer than the level's, which the runtime's
//! voxel walk (`--gate-shape voxels`) marches between a VPL and a surface point.
//!
//! **Its default voxel.** An opening narrows by up to half a sight voxel at each edge, and a
//! segment that passes within a voxel of a surface is blocked, so the voxel sets how close to
//! a column, a curtain or a leaf light passes. At most 1/[`SIGHT_PARTS`] of the level (the
//! built-ins: 8–16 m on 512 voxels, 1.6–3.2 cm), and on a larger level finer, down to
//! [`SIGHT_DETAIL_M`] while the grid holds at most [`SIGHT_DEFAULT_MAX_VOXELS`]: real levels'
//! detail is sized in centimetres whatever the level's size. Crytek Sponza (37 m), whose
//! fluted columns, curtains and plants the 7.3 cm voxels of 1/512 blocked, took 4.5 % of the
//! gallery's lit pixels black (every VPL at every pixel, 160 × 120, the 256 level); on 4.69 cm
//! voxels 2.3 % (1.4–2.4 % from 4 to 4.7 cm, as the grid's planes fall against the columns),
//! and it now gets 4 cm.

use visgate_formats::vgate::{BakeParams, GridMeta, Resolution, VoxelBits};

use crate::BakeError;
use crate::bake::BakeOptions;
use crate::counters::SightCounts;
use crate::stages;
use crate::voxelize::grid_for;

/// The default sight voxel is at most 1/this of the level's longest extent: a level baked
/// coarser still walks its openings on this many voxels.
pub const SIGHT_PARTS: u32 = 512;

/// On a level longer than [`SIGHT_PARTS`] of these, the default sight voxel is finer than
/// 1/[`SIGHT_PARTS`] of it, down to this (Crytek Sponza's gallery, the 256 level, every VPL at
/// every pixel: black where lit 4.5 % on its 7.3 cm voxels of 1/512, 3.2 % on 5.5 cm, 2.0 %
/// on 5.15 cm, 1.4 % on 4.65 cm and on 3.6 cm). [Units: m]
pub const SIGHT_DETAIL_M: f32 = 0.04;

/// The most voxels a default sight grid finer than 1/[`SIGHT_PARTS`] holds: 2^28, 32 MiB of
/// bits (fewer bytes in the file, as runs) and 64 MiB on the GPU with the walk's bricks, half
/// the 128 MiB binding that wgpu allows by default. Crytek Sponza's 4 cm is 210 M voxels: on
/// the 4.69 cm that 2^27 gave it, its gallery had 0.887 of the indirect light and 3.0 % of
/// its lit pixels black (the default gates, 1,024 VPLs, 320 × 240, the 256 level), on 4 cm
/// 0.904 and 2.8 %.
pub const SIGHT_DEFAULT_MAX_VOXELS: u64 = 1 << 28;

/// Bytes a sight grid's voxel costs at its peak: its closed bits and its open bits as it is
/// voxelized, the file's copy and the runtime's bricks (an eighth of a byte each, and less).
const SIGHT_BYTES_PER_VOXEL: f64 = 0.5;

/// The default sight voxel of a level of `bounds` baked on voxels of `voxel_m` (see the module
/// notes): never coarser than the level's voxel.
pub fn default_sight_voxel(bounds: (glam::Vec3, glam::Vec3), voxel_m: f32) -> f32 {
    let longest = (bounds.1 - bounds.0).max_element();
    let coarse = longest / SIGHT_PARTS as f32;
    if SIGHT_DETAIL_M >= coarse {
        return voxel_m.min(coarse);
    }
    let voxels = |s: f32| {
        grid_for(bounds, Resolution::VoxelSizeM(s), u64::MAX)
            .ok()
            .and_then(|g| g.voxel_count())
            .unwrap_or(u64::MAX)
    };
    // Coarser by 1 % steps from 4 cm until the grid fits (tens of steps on a level a few times
    // 20 m long, a few hundred on a kilometre cube, each a grid's size: microseconds).
    let mut s = SIGHT_DETAIL_M;
    while s < coarse && voxels(s) > SIGHT_DEFAULT_MAX_VOXELS {
        s *= 1.01;
    }
    voxel_m.min(s.min(coarse))
}

/// The sight grid ([`BakeParams::sight_voxel_m`], filled in: the level's grid, or its bounds at
/// the finer sight voxel) and its open voxels, voxelized thin ([`crate::separating`]).
pub fn sight_grid(
    input: &stages::Loaded,
    meta: &GridMeta,
    params: &BakeParams,
    options: &BakeOptions,
) -> Result<((GridMeta, VoxelBits), SightCounts), BakeError> {
    let size = params.sight_voxel_m.unwrap_or(meta.voxel_size_m);
    let grid = if size < 0.99 * meta.voxel_size_m {
        // A bit a voxel, not the whole bake's bytes: checked against its own cost.
        let grid = grid_for(input.bounds, Resolution::VoxelSizeM(size), u64::MAX)?;
        let bytes = grid.voxel_count().map_or(f64::INFINITY, |n| n as f64) * SIGHT_BYTES_PER_VOXEL;
        if bytes > options.memory_limit_bytes as f64 {
            return Err(BakeError::SightTooLarge {
                dims: grid.dims.map(f64::from),
                voxel_m: size,
                bytes,
                limit: options.memory_limit_bytes,
            });
        }
        grid
    } else {
        *meta
    };
    let bits = crate::separating::open_voxels(grid, &input.triangles);
    let counts = SightCounts {
        dims: grid.dims,
        voxel_size_m: grid.voxel_size_m,
        open_voxels: bits.count_ones(),
        bytes: grid.voxel_count().unwrap_or(0).div_ceil(8),
    };
    Ok(((grid, bits), counts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn level(size: [f32; 3]) -> (Vec3, Vec3) {
        (Vec3::ZERO, Vec3::from(size))
    }

    #[test]
    fn the_default_sight_voxel_is_centimetres_on_large_levels_within_its_budget() {
        let voxels = |b, s| {
            grid_for(b, Resolution::VoxelSizeM(s), u64::MAX)
                .expect("a grid")
                .voxel_count()
                .expect("voxels")
        };
        // A built-in's size: 1/512, or the level's voxel where finer.
        assert_eq!(
            default_sight_voxel(level([8.0, 3.0, 4.0]), 0.0625),
            8.0 / 512.0
        );
        assert_eq!(default_sight_voxel(level([8.0, 3.0, 4.0]), 0.01), 0.01);
        // Up to 20.48 m, 1/512 is 4 cm or finer.
        assert_eq!(
            default_sight_voxel(level([20.0, 5.0, 10.0]), 0.1),
            20.0 / 512.0
        );
        // Long and flat: 4 cm.
        let street = level([60.0, 2.0, 10.0]);
        assert_eq!(default_sight_voxel(street, 0.3), SIGHT_DETAIL_M);
        // Crytek Sponza's bounds, a hall 50 m long and a 25 m cube: 4 cm fits (212, 158 and
        // 246 M voxels).
        for b in [[37.2, 15.8, 22.8], [50.0, 10.0, 20.0], [25.0; 3]] {
            assert_eq!(default_sight_voxel(level(b), 1.0), SIGHT_DETAIL_M, "{b:?}");
        }
        // An 80 m hall and a kilometre cube: coarser than 4 cm, within 1 % of the budget,
        // finer than 1/512 (a cube's 1/512 holds half the budget).
        for (b, coarse) in [
            ([80.0, 15.0, 40.0], 80.0 / 512.0),
            ([1000.0; 3], 1000.0 / 512.0),
        ] {
            let s = default_sight_voxel(level(b), 5.0);
            let n = voxels(level(b), s);
            assert!(n <= SIGHT_DEFAULT_MAX_VOXELS, "{b:?}: {s} m, {n}");
            assert!(
                voxels(level(b), s / 1.011) > SIGHT_DEFAULT_MAX_VOXELS,
                "{b:?}: {s} m"
            );
            assert!(s > SIGHT_DETAIL_M && s < coarse, "{b:?}: {s} m");
        }
    }
}

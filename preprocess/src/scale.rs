//! The bake's defaults scaled to the level: the minimum gap, the partition voxel and the
//! sight voxel a bake leaves to the level's size and voxel, filled in before its stages run
//! (the values used, which the file records).

use visgate_formats::vgate::BakeParams;

use crate::sight_grid::default_sight_voxel;

/// The default minimum gap ([`BakeParams::min_gap_m`]: half the width of a gap, 20 cm wide),
/// unless the level is small.
/// [Units: m]
pub const MIN_GAP_M: f32 = 0.1;
/// The default partition voxel ([`BakeParams::partition_voxel_m`]), unless the level is small.
/// [Units: m]
pub const PARTITION_VOXEL_M: f32 = 0.125;
/// The default minimum gap is at most 1/this of the level's longest extent: a small level (a
/// few rooms) keeps the detail of its doors and furniture, and a level whose units were
/// declared wrong (a model in millimetres read as metres) is partitioned as at its true scale.
pub const MIN_GAP_PARTS: u32 = 256;
/// The default partition voxel is at most 1/this of the level's longest extent (so a small
/// level is partitioned on at least this many voxels, and refined from there: `ajar-door` at
/// 256 agrees with shadow rays on 95.4 / 92.1 / 98.3 % of pairs so, on 89.5 / 78.9 / 98.0 %
/// partitioned on its own 256 grid).
pub const PARTITION_PARTS: u32 = 128;
/// A coarse bake is partitioned on a finer grid only where that grid's voxels are at most
/// this ([`default_partition_voxel`]): finer voxels open the doorways and arcades its own
/// close; coarser ones close them too, and the portal walk on a level of 84 cm voxels whose
/// clusters come from 42 cm ones lost half its light (LibreQuake e2m3 at 128: indirect energy
/// 1.08 / 1.13 → 0.62 / 0.49 of the reference's, `--gate-shape portal`). [Units: m]
pub const COARSE_MAX_M: f32 = 0.25;
/// A large level's partition grid has at most this many voxels on its longest axis when the
/// level's grid is coarser ([`default_partition_voxel`]): a 60 m level baked at 128 is
/// partitioned on its 256 grid, 23 cm, not on 12.5 cm voxels (480 of them).
pub const COARSE_PARTS: u32 = 256;

/// `params` with the minimum gap, the partition voxel and the sight voxel it leaves to the
/// bake filled in (see [`MIN_GAP_PARTS`], [`PARTITION_PARTS`], [`default_sight_voxel`]) for a level of
/// `bounds` on voxels of `voxel_m`: the values used, which the file records.
pub(crate) fn level_scaled(
    params: &BakeParams,
    bounds: (glam::Vec3, glam::Vec3),
    voxel_m: f32,
) -> BakeParams {
    let longest = (bounds.1 - bounds.0).max_element();
    let scale = longest / MIN_GAP_PARTS as f32;
    let sight = match params.sight_voxel_m {
        None => default_sight_voxel(bounds, voxel_m),
        Some(v) if v == 0.0 || v > voxel_m => voxel_m,
        Some(v) => v,
    };
    BakeParams {
        sight_voxel_m: Some(sight),
        min_cluster_ball_m: Some(params.min_cluster_ball_m.unwrap_or(0.0)),
        min_gap_m: Some(params.min_gap_m.unwrap_or(MIN_GAP_M.min(scale))),
        partition_voxel_m: Some(
            params
                .partition_voxel_m
                .unwrap_or_else(|| default_partition_voxel(longest, voxel_m)),
        ),
        ..params.clone()
    }
}

/// The default partition voxel of a level `longest` metres long on voxels of `voxel_m`: 1/128
/// of its length where that is under [`PARTITION_VOXEL_M`] (a small level; its voxel where
/// that is coarser), else the finest of 1/128, 1/256, 1/512, … of its length that reaches
/// [`PARTITION_VOXEL_M`] (to 1 %), where that is a whole multiple of its voxel (as at 128,
/// 256, 512, … voxels), else the least whole multiple of its voxel that reaches it: its voxel
/// itself where that reaches it (then the partition is made on the level's own grid). So the
/// partition's voxels are one size at every such resolution: Crytek Sponza is partitioned on
/// 14.6 cm voxels at 256, 512 and 1024 (1, 2 and 4 of its voxels; 73, 84 and 84 clusters),
/// where on 12.5 cm voxels at 512 it made 89 and baked in 3.8–4.5 s instead of 2.9; a 24 m
/// warehouse of shelving on 18.75 cm voxels at 128, 256 and 512 (201 clusters each), where
/// the least whole multiple at 512, three of its 4.7 cm voxels, made 58.
///
/// A coarse bake, whose voxels are at least twice that voxel and 1/[`COARSE_PARTS`] of the
/// level (to 1 %), where the greater of these is at most [`COARSE_MAX_M`], is partitioned on
/// the finest whole fraction of its voxel that is not finer than both, and each of its voxels
/// takes the cluster most of its share of that grid has ([`crate::refine`]): Dabrovic Sponza at 128, whose 27 cm voxels close its upper arcades,
/// is partitioned on its 256 grid (160 clusters, as at 256 and 512, instead of 17); the
/// pillared hall (16.4 m) at 64 on its 128 grid, at 128 on its own.
pub fn default_partition_voxel(longest: f32, voxel_m: f32) -> f32 {
    let small = longest / PARTITION_PARTS as f32;
    let coarsest = small
        .min(PARTITION_VOXEL_M)
        .max(longest / COARSE_PARTS as f32);
    let k = (voxel_m / coarsest * 1.01).floor();
    if k >= 2.0 && coarsest <= COARSE_MAX_M {
        return voxel_m / k;
    }
    if small < PARTITION_VOXEL_M {
        // Under twice the level's voxel: its own grid.
        return small.max(voxel_m);
    }
    // The level's ladder of halvings from 1/128 of it, down to the last that reaches
    // 12.5 cm (to 1 %): a whole multiple of the voxel at 128, 256, 512, … voxels alike.
    let mut ladder = small;
    while ladder / 2.0 * 1.01 >= PARTITION_VOXEL_M {
        ladder /= 2.0;
    }
    let on_ladder = (ladder / voxel_m).round();
    if on_ladder >= 1.0 && (ladder / voxel_m - on_ladder).abs() <= 0.01 * on_ladder {
        return on_ladder * voxel_m;
    }
    let k = (PARTITION_VOXEL_M / voxel_m / 1.01).ceil();
    k.max(1.0) * voxel_m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::{BakeOptions, partition_grid};
    use visgate_formats::vgate::GridMeta;

    #[test]
    fn the_default_partition_voxel_is_a_whole_multiple_of_a_large_levels_voxel() {
        // Crytek Sponza's 37.3 m: 14.6 cm voxels at 256, two of 7.3 cm at 512, four at 1024.
        let v256 = 37.3 / 256.0;
        assert_eq!(default_partition_voxel(37.3, v256 / 2.0), v256);
        assert_eq!(default_partition_voxel(37.3, v256 / 4.0), v256);
        // 10.5 cm voxels: two of them, not the level's own grid (1.2 of them would be 12.5 cm).
        assert_eq!(default_partition_voxel(107.5, 0.105), 0.21);
        // A 24 m level: its 128 voxel (18.75 cm) at 256 and 512 too, four of its 512 voxels
        // where three would reach 12.5 cm; off the ladder (600 voxels, 4 cm), the least whole
        // multiple that reaches 12.5 cm.
        assert_eq!(default_partition_voxel(24.0, 24.0 / 256.0), 0.1875);
        assert_eq!(default_partition_voxel(24.0, 24.0 / 512.0), 0.1875);
        assert_eq!(default_partition_voxel(24.0, 24.0 / 1024.0), 0.1875);
        assert_eq!(default_partition_voxel(24.0, 0.04), 0.16);
        // Voxels that reach 12.5 cm (to 1 %) and 1/256 of the level are the partition's own.
        for v in [v256, 0.124, 0.39] {
            assert_eq!(default_partition_voxel(100.0, v), v);
            let meta = GridMeta {
                origin_m: [0.0; 3],
                voxel_size_m: v,
                dims: [64; 3],
            };
            let params = BakeParams {
                partition_voxel_m: Some(v),
                ..BakeParams::default()
            };
            let bounds = (glam::Vec3::ZERO, glam::Vec3::splat(60.0 * v));
            let grid = partition_grid(bounds, &meta, &params, &BakeOptions::default());
            assert!(grid.expect("sized").is_none(), "{v}");
        }
        // A small level: 1/128 of its length at 128 and finer.
        assert_eq!(default_partition_voxel(10.0, 10.0 / 256.0), 10.0 / 128.0);
        assert_eq!(default_partition_voxel(10.0, 10.0 / 128.0), 10.0 / 128.0);
        // Its own grid at 96 (under twice 1/128 of it).
        assert_eq!(default_partition_voxel(10.0, 10.0 / 96.0), 10.0 / 96.0);
    }

    #[test]
    fn a_coarse_bake_is_partitioned_on_a_whole_fraction_of_its_voxel() {
        // Dabrovic Sponza's 34.8 m at 128 and 64: its 256 grid; a 60 m level at 128: its 256
        // grid (23 cm); a small level at 64: its 128 grid.
        for (longest, res, k) in [(34.8, 128.0, 2.0), (34.8, 64.0, 4.0), (60.0, 128.0, 2.0)] {
            let v = longest / res;
            assert_eq!(
                default_partition_voxel(longest, v),
                v / k,
                "{longest} {res}"
            );
        }
        // LibreQuake e2m3's 107.5 m at 128: its own (its 256 grid's 42 cm voxels are over
        // COARSE_MAX_M).
        assert_eq!(default_partition_voxel(107.5, 107.5 / 128.0), 107.5 / 128.0);
        assert_eq!(default_partition_voxel(10.0, 10.0 / 64.0), 10.0 / 128.0);
        // The pillared hall's 16.4 m at 64: its 128 grid; at 128 (12.8 cm, under twice
        // 12.5 cm) its own, and a 30 m level's 23 cm voxels too.
        let v = 16.4 / 64.0;
        assert_eq!(default_partition_voxel(16.4, v), v / 2.0);
        for (longest, v) in [(16.4, 16.4 / 128.0), (30.0, 30.0 / 128.0)] {
            assert_eq!(default_partition_voxel(longest, v), v);
        }
        // e2m3 at 512 (21 cm, coarser than 12.5 cm but finer than its 256 grid): its own.
        let v512 = 107.5 / 512.0;
        assert_eq!(default_partition_voxel(107.5, v512), v512);
        // A finer partition grid is made; one within 1 % of the level's voxel is not.
        let meta = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 0.4,
            dims: [64; 3],
        };
        let bounds = (glam::Vec3::ZERO, glam::Vec3::splat(24.0));
        for (size, made) in [(0.2, true), (0.399, false), (0.0, false), (0.8, true)] {
            let params = BakeParams {
                partition_voxel_m: Some(size),
                ..BakeParams::default()
            };
            let grid = partition_grid(bounds, &meta, &params, &BakeOptions::default());
            assert_eq!(grid.expect("sized").is_some(), made, "{size}");
        }
    }
}

//! The parameters of mode `gates` (clustered shading with gates, [`super::clustered_gates`]):
//! how light passes the gates, the geometry clusters, the light lists' pool, the interleaving
//! and its blur, the walks' roulette; the accurate and balanced settings; their limits.

use super::interleave_blur::InterleaveParams;
use super::roulette::WalkRoulette;
use crate::RenderError;
use crate::camera::View;
use crate::cpu::clustered::ClusterParams;
use crate::cpu::gates::{GateParams, GateShape};
use crate::gpu::shaders::WG_TILE;

/// The light-list pool's first capacity when it grows on its own. [Units: entries]
pub const AUTO_LIGHT_ENTRIES: u32 = 1 << 22;

/// Parameters of mode `gates` (clustered shading). The default is the fast setting
/// ([`GatesParams::fast`]); `visgate`'s commands and viewer default to the balanced one
/// ([`GatesParams::balanced`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GatesParams {
    /// How light passes gates (`max_hops` 1 or 2 on the GPU).
    pub gates: GateParams,
    /// Geometry clusters (`tile_px` 1..=16 on the GPU).
    pub clusters: ClusterParams,
    /// Capacity of the light-list pool, in (VPL, gates) entries of 8 bytes; a frame that needs
    /// more fails with the count it needs. `None`: the pool starts at [`AUTO_LIGHT_ENTRIES`]
    /// and grows to what a frame needs (that frame is rendered again), up to the adapter's
    /// storage binding limit. [Limit: 1..=storage limit / 8]
    pub light_entries: Option<u32>,
    /// Interleaved sampling and the geometry-aware blur, as the VAL modes have them (the same
    /// defaults: 8 × 8 blocks); block 1 gathers every VPL at every pixel.
    pub interleave: InterleaveParams,
    /// Portals and voxels, Russian roulette on the walks ([`WalkRoulette`]; by default
    /// [`WalkRoulette::Auto`]: on where a pixel walks many VPLs).
    pub walk_roulette: WalkRoulette,
    /// The roulette's random numbers: a Weyl sequence over the VPLs shifted by a hash of this
    /// seed and the pixel's tile (shade.wgsl's `roulette_hash`; a frame's noise is the same
    /// each time it is rendered, another seed draws other walks).
    pub walk_seed: u32,
    /// Interleaved walks, the near field: the VPLs nearer a pixel than this many interleaving
    /// blocks' widths (b pixels on a surface at the pixel's distance, facing the camera) are
    /// left out of its subset's gather and walked at the pixel itself, unblurred (shade.wgsl's
    /// `cs_near_field`). A VPL beside a crease lights the other face in a spot about as wide
    /// as its distance, and its light changes across a block as much as the block's width is
    /// of that distance: interleaved, one pixel in b² takes it and the blur smears it over the
    /// block (the light's own room's corners). 0: none. [Limit: 0..=8]
    pub near_field: f32,
    /// Interleaved walks (portals or voxels), the ratio estimator (Heitz et al. 2018,
    /// "Combining analytic direct illumination and stochastic shadows"): each pixel sums the
    /// unshadowed light of every VPL beyond its near field (no visibility: a loop over the VPLs,
    /// unshadowed.wgsl), and the blur scales it by the share of their
    /// unshadowed light that its taps' walks found visible, instead of averaging the taps'
    /// light: where every VPL is visible the pixel gets its exact light whatever VPL subsets its
    /// taps held, so that the interleaving's error is left to the visibility's changes across a
    /// block. Off: Laine et al.'s average.
    pub ratio: bool,
    /// The ratio estimator's grid: the unshadowed far light summed at every n-th pixel across
    /// and down (a 1/n² share of the pixels, each every VPL) and at the pixels between whose
    /// four grid pixels around do not all lie on their surface (creases, edges, steps); the
    /// others take it bilinearly from those four (ratio.wgsl). 0 or 1: summed at every pixel.
    /// [Limit: 0..=8]
    pub ratio_stride: u32,
}

/// The balanced and accurate settings' ratio estimator's grid stride
/// ([`GatesParams::ratio_stride`]): on the error table's 24 views the indirect MSE within
/// 0.9 % of every pixel's own sum on 23 and 3.6 % on one, for an unshadowed pass 3.1–4.8×
/// shorter on lavapipe at 512² (README; 4 px shortened it no more: more pixels sum their
/// own). [Units: px]
pub const RATIO_STRIDE: u32 = 3;

/// The most pixels across between two of the ratio estimator's grid pixels
/// ([`GatesParams::ratio_stride`]).
pub const RATIO_STRIDE_MAX: u32 = 8;

/// The balanced and accurate settings' near field ([`GatesParams::near_field`]), in blocks:
/// on 24 camera and light configurations (README) the indirect MSE ×0.19–1.0 of the setting's
/// without it, for a near pass of 18–340 ms on lavapipe at 320 × 240, 3–32 % of the frame (the
/// light's own room the most).
pub const NEAR_FIELD: f32 = 4.0;

/// The widest near field ([`GatesParams::near_field`]), in blocks.
pub const NEAR_FIELD_MAX: f32 = 8.0;

/// The most VPLs the near field takes (shade.wgsl's NEAR_WORDS × 32: a workgroup marks its
/// tile's near VPLs a bit each); above, it is off.
pub const NEAR_MAX_VPLS: u32 = 32_768;

/// The VPLs a pixel's subset holds from which the walks' roulette, where it is on, turns the
/// near field and the ratio estimator off (8,192 VPLs in 8 × 8 blocks): both cost a pixel every
/// near or every VPL, which at 16,384 VPLs took e2m3's hall from 3.3 to 8.4 s on lavapipe at
/// 512² (the near field), while the subset's many VPLs have made its error small. Below it the
/// roulette thins the walks alone.
pub const THIN_SUBSET_VPLS: u32 = 128;

/// Checks gate parameters against what the GPU's test does (≤ 2 hops).
pub fn check_gates(g: &GateParams) -> Result<(), RenderError> {
    let o = g.oversize;
    if !(o > 0.0 && o.is_finite() && (1..=2).contains(&g.max_hops)) {
        return Err(RenderError::Param(format!(
            "gate oversize {o} must be > 0 and hops {} 1 or 2 on the GPU (the CPU twin, --cpu, \
             takes more)",
            g.max_hops
        )));
    }
    check_walk_limit(g)
}

/// Checks the portal walk's limit (GPU and CPU twin alike).
pub fn check_walk_limit(g: &GateParams) -> Result<(), RenderError> {
    if !(1..=1024).contains(&g.max_walk) {
        return Err(RenderError::Param(format!(
            "portal walk limit {} must be 1..=1024 portals",
            g.max_walk
        )));
    }
    Ok(())
}

impl GatesParams {
    /// The accurate setting (`--accurate`): the voxel walk (the shape as set; the default)
    /// along the true segment with the closed voxels' triangles, the tent blur, and the
    /// starved pixels walking what their block lacks where fewer than three quarters of its
    /// taps agree with them (48 of 8 × 8; a count already set is kept), the near field of
    /// [`NEAR_FIELD`] blocks and the ratio estimator ([`GatesParams::ratio`]). On sixteen camera-seeds (README, before the near field) the indirect energy
    /// within 1.6 % of the reference's and under 1 % of the lit pixels black, at several
    /// times the default's frame: for stills and reference-grade walk-throughs.
    pub fn accurate(mut self) -> GatesParams {
        self.gates.triangles = true;
        self.interleave.tent = true;
        self.near_field = NEAR_FIELD;
        self.ratio = true;
        self.ratio_stride = RATIO_STRIDE;
        if self.interleave.starved_taps == 0 {
            self.interleave.starved_taps = self.interleave.three_quarters();
        }
        self
    }

    /// The balanced setting (`--balanced`): the closed voxels' triangles, the tent blur, the
    /// near field and the ratio estimator as in [`GatesParams::accurate`], and the pixels whose agreeing taps found no light walking
    /// what their block lacks ([`InterleaveParams::starved_dark`]) instead of every pixel with
    /// fewer than three quarters agreeing (a count already set is kept). On the same sixteen
    /// camera-seeds (README) the indirect energy within 3 % of the reference's and under 1 % of
    /// the lit pixels black, at 0.2–0.7× the accurate setting's frame, with a higher MSE: the
    /// default of `visgate`'s commands and viewer.
    ///
    /// [`InterleaveParams::starved_dark`]: InterleaveParams::starved_dark
    pub fn balanced(mut self) -> GatesParams {
        self.gates.triangles = true;
        self.interleave.tent = true;
        self.near_field = NEAR_FIELD;
        self.ratio = true;
        self.ratio_stride = RATIO_STRIDE;
        self.interleave.starved_dark = true;
        self
    }

    /// The fast setting (`--fast`): the balanced setting's five undone — the voxel walk
    /// passing closed voxels on their planes, the box blur, no dark pixels' walks, no near
    /// field, no ratio estimator (its grid back to every pixel; a `--starved-taps` count is
    /// kept). [`GatesParams::default`] is this setting; `visgate`'s
    /// commands and viewer start from [`GatesParams::balanced`].
    pub fn fast(mut self) -> GatesParams {
        self.gates.triangles = false;
        self.interleave.tent = false;
        self.near_field = 0.0;
        self.interleave.starved_dark = false;
        self.ratio = false;
        self.ratio_stride = 0;
        self
    }

    /// The roulette's share S for a frame of `vpls` VPLs (0: every VPL walked).
    pub fn roulette_share(&self, vpls: u32) -> f32 {
        self.walk_roulette
            .share(self.subset_vpls(vpls), self.interleave.block, self.ratio)
    }

    /// The VPLs a pixel's subset holds in a frame of `vpls` VPLs (the last subsets one fewer).
    fn subset_vpls(&self, vpls: u32) -> u32 {
        vpls.div_ceil(self.interleave.subsets())
    }

    /// The near field's radius per metre of a pixel's distance from the eye in `view`, for a
    /// frame of `vpls` VPLs (0: none — off, no interleaving, the paper's disks, the walks
    /// thinned by the roulette ([`Self::thinned`]), or over [`NEAR_MAX_VPLS`]):
    /// [`GatesParams::near_field`] blocks of b pixels. Where the roulette thins the walks (from
    /// 128 VPLs a subset: 8,192 VPLs in 8 × 8 blocks) the near field is off: its walks, every
    /// near VPL at every pixel, took e2m3's hall at 16,384 VPLs from 3.3 to 8.4 s on lavapipe
    /// at 512².
    pub fn near_scale(&self, view: &View, vpls: u32) -> f32 {
        let walks = self.gates.shape != GateShape::Disk;
        let b = self.interleave.block;
        if self.near_field <= 0.0 || b <= 1 || !walks || self.thinned(vpls) || vpls > NEAR_MAX_VPLS
        {
            return 0.0;
        }
        let pixel = 2.0 * (view.fov_x_rad / 2.0).tan() / view.size[0].max(1) as f32;
        self.near_field * b as f32 * pixel
    }

    /// Whether the blur of a frame of `vpls` VPLs takes the ratio estimator
    /// ([`GatesParams::ratio`]): asked for, the walks (portals or voxels) interleaved, and not
    /// thinned by the roulette ([`Self::thinned`]) — where it thins them (from 128 VPLs a
    /// subset) the near field is off too, and the unshadowed light, every VPL at every pixel,
    /// would cost a GPU what the none mode does (15 ms at 512² and 16,384 VPLs on an H200) for
    /// a subset's error that its many VPLs have made small.
    pub fn ratio_for(&self, vpls: u32) -> bool {
        let walks = self.gates.shape != GateShape::Disk;
        self.ratio && self.interleave.block > 1 && walks && !self.thinned(vpls)
    }

    /// Whether the roulette thins a frame of `vpls` VPLs so far that the near field and the
    /// ratio estimator are off: on, with [`THIN_SUBSET_VPLS`] VPLs a pixel's subset or more.
    pub fn thinned(&self, vpls: u32) -> bool {
        self.roulette_share(vpls) > 0.0 && self.subset_vpls(vpls) >= THIN_SUBSET_VPLS
    }

    /// The ratio estimator's grid stride in pixels ([`GatesParams::ratio_stride`]), at least 1.
    pub fn ratio_grid(&self) -> u32 {
        self.ratio_stride.max(1)
    }

    /// Whether the indirect light is gathered in a pass of its own and composed by the blur
    /// (interleaved, or walks — portals or voxels —, which run in batches on a software
    /// rasterizer), not in the shading pass (disks gathering every VPL at every pixel).
    /// shade.wgsl's `fs` says the same.
    pub fn gathers_apart(&self) -> bool {
        self.interleave.block > 1 || self.gates.shape != GateShape::Disk
    }

    /// Checks the limits (the pool's size against the adapter's at render time).
    pub fn check(&self) -> Result<(), RenderError> {
        check_gates(&self.gates)?;
        self.interleave.check()?;
        let cp = self.clusters;
        if !(1..=WG_TILE).contains(&cp.tile_px) || !(1..=256).contains(&cp.depth_slices) {
            return Err(RenderError::Param(format!(
                "tile side {} px must be 1..={WG_TILE} on the GPU (one workgroup per tile) and \
                 depth slices {} 1..=256",
                cp.tile_px, cp.depth_slices
            )));
        }
        self.walk_roulette.check()?;
        if !(0.0..=NEAR_FIELD_MAX).contains(&self.near_field) {
            return Err(RenderError::Param(format!(
                "the near field {} must be 0..={NEAR_FIELD_MAX} interleaving blocks (0: none)",
                self.near_field
            )));
        }
        if self.ratio_stride > RATIO_STRIDE_MAX {
            return Err(RenderError::Param(format!(
                "the ratio estimator's grid stride {} must be 0..={RATIO_STRIDE_MAX} pixels \
                 (0 or 1: every pixel)",
                self.ratio_stride
            )));
        }
        if self.light_entries == Some(0) {
            return Err(RenderError::Param(
                "the light-entry pool (--light-entries) must hold at least 1 entry".into(),
            ));
        }
        Ok(())
    }
}

//! The settings of the imperfect shadow maps and of the two modes that use them.

use super::interleave_blur::InterleaveParams;
use super::lc_params::PcssParams;
use crate::RenderError;
use crate::cpu::val::ValParams;

/// Imperfect shadow maps (Ritschel et al. 2008; Weinzierl-Heigl §5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsmParams {
    /// Side of each emitter's paraboloid map, a power of two; `None`: 128 (the paper's
    /// 4096² atlas of 128² maps), smaller where that many maps would not fit the adapter's
    /// largest storage buffer. [Units: texels] [Limit: 16..=512]
    pub map_size: Option<u32>,
    /// Points splatted into each map (the sampling density: the scene's area over this is what
    /// a point stands for). [Limit: 64..=65,536]
    pub points_per_map: u32,
    /// Pull-push levels that fill holes (the paper: 2; 0: none). [Limit: 0..=6]
    pub pull_push: u32,
    /// Splats covering a point of a surface on average: a point is splatted as a disk of
    /// √coverage times the radius of its share of the scene's area (random points of coverage
    /// 1 leave e⁻¹ of a surface uncovered, where what lies behind shows through; 4: e⁻⁴).
    /// [Limit: 0.25..=64]
    pub coverage: f32,
    /// Largest splat radius. [Units: texels] [Limit: 0..=8]
    pub max_splat: f32,
    /// Depth bias of lookups (ISM depths are noisy). [Units: texels] [Limit: ≥ 0]
    pub bias: f32,
    /// Normal offset of lookups. [Units: texels] [Limit: ≥ 0]
    pub normal_offset: f32,
    /// Seed of the points.
    pub seed: u32,
}

impl Default for IsmParams {
    fn default() -> Self {
        IsmParams {
            map_size: None,
            points_per_map: 8192,
            pull_push: 2,
            coverage: 4.0,
            max_splat: 3.0,
            bias: 3.0,
            normal_offset: 1.5,
            seed: 1,
        }
    }
}

/// The default map side.
pub const ISM_MAP_SIZE: u32 = 128;

impl IsmParams {
    /// Checks the limits (the maps' memory against the adapter when rendered).
    pub fn check(&self) -> Result<(), RenderError> {
        if let Some(s) = self.map_size
            && !(s.is_power_of_two() && (16..=512).contains(&s))
        {
            return Err(RenderError::Param(format!(
                "ISM map size {s} must be a power of two in 16..=512 texels"
            )));
        }
        let ok = |x: f32, hi: f32| x.is_finite() && (0.0..=hi).contains(&x);
        if !(64..=65_536).contains(&self.points_per_map)
            || self.pull_push > 6
            || !ok(self.max_splat, 8.0)
            || !(0.25..=64.0).contains(&self.coverage)
            || !ok(self.bias, f32::MAX)
            || !ok(self.normal_offset, f32::MAX)
        {
            return Err(RenderError::Param(format!(
                "ISM points per map {} must be 64..=65536, pull-push levels {} 0..=6, coverage \
                 {} 0.25..=64, max splat {} 0..=8 texels, bias {} and normal offset {} ≥ 0 \
                 texels",
                self.points_per_map,
                self.pull_push,
                self.coverage,
                self.max_splat,
                self.bias,
                self.normal_offset
            )));
        }
        Ok(())
    }

    /// The map side for `maps` maps when the largest storage buffer is `limit` bytes: the
    /// given one, or the largest power of two up to [`ISM_MAP_SIZE`] that fits (at least 16).
    pub fn side_for(&self, maps: u32, limit: u64) -> Result<u32, RenderError> {
        let fits = |s: u32| maps.max(1) as u64 * (s as u64 * s as u64) * 4 <= limit;
        let side = match self.map_size {
            Some(s) => s,
            None => {
                let mut s = ISM_MAP_SIZE;
                while s > 16 && !fits(s) {
                    s /= 2;
                }
                s
            }
        };
        if !fits(side) {
            return Err(RenderError::Param(format!(
                "{maps} imperfect shadow maps of {side}² need {} MiB, more than the adapter's \
                 largest storage buffer of {} MiB: use smaller maps (--ism-map-size) or fewer \
                 emitters",
                (maps as u64 * side as u64 * side as u64 * 4) >> 20,
                limit >> 20
            )));
        }
        Ok(side)
    }

    /// In a few words, for reports.
    pub fn describe(&self) -> String {
        let side = match self.map_size {
            Some(s) => format!("{s}²"),
            None => format!("≤ {ISM_MAP_SIZE}²"),
        };
        format!(
            "ISMs {side}, {} pts/map, pull-push {}",
            self.points_per_map, self.pull_push
        )
    }
}

/// Mode `per-vpl-ism`: an imperfect shadow map per VPL, one hard lookup each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VplIsmParams {
    /// The maps.
    pub ism: IsmParams,
    /// Interleaved sampling (default 1: every VPL at every pixel, as `per-vpl-shadow-maps`).
    pub interleave: InterleaveParams,
}

impl Default for VplIsmParams {
    fn default() -> Self {
        VplIsmParams {
            ism: IsmParams::default(),
            interleave: InterleaveParams {
                block: 1,
                ..InterleaveParams::default()
            },
        }
    }
}

impl VplIsmParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        self.ism.check().and(self.interleave.check())
    }
}

/// How a VAL's disk lights a point (`val-ism`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DiskLight {
    /// The paper's point-to-disk form factor at the disk's centre: exact on its axis, 28 %
    /// under at two radii 60° off it, 38 % at 80°.
    Centre,
    /// The disk as 5 parts (its centre and 4 at ¾ of its radius), a fifth of its area and flux
    /// each, each by the form factor: within 4 % from two radii at every angle.
    #[default]
    Parts,
}

impl DiskLight {
    /// `IsmFrame::disk_parts`.
    pub fn parts(&self) -> u32 {
        match self {
            DiskLight::Centre => 1,
            DiskLight::Parts => 5,
        }
    }
}

/// Mode `val-ism` (Weinzierl-Heigl): VALs clustered as the paper clusters them, an ISM each,
/// the point-to-disk form factor, PCSS by the VAL's area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValIsmParams {
    /// The clustering ([`ValParams::ism`]).
    pub vals: ValParams,
    /// The maps.
    pub ism: IsmParams,
    /// PCSS sampling of each VAL's map.
    pub pcss: PcssParams,
    /// One hard lookup per VAL instead of PCSS (the paper's "simple-sampled" VALs of Table 1).
    pub hard_lookups: bool,
    /// How a VAL's disk lights a point.
    pub disk: DiskLight,
    /// The split G-buffer: VAL v lights tile v mod b² (default 4 × 4), then the blur.
    pub interleave: InterleaveParams,
}

impl Default for ValIsmParams {
    fn default() -> Self {
        ValIsmParams {
            vals: ValParams::ism(),
            ism: IsmParams::default(),
            pcss: PcssParams::default(),
            hard_lookups: false,
            disk: DiskLight::default(),
            interleave: InterleaveParams {
                block: 4,
                ..InterleaveParams::default()
            },
        }
    }
}

impl ValIsmParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        self.vals.check()?;
        self.ism.check()?;
        self.interleave.check()?;
        self.pcss.check()
    }
}

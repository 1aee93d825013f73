//! Russian roulette on the gates' walks ([`WalkRoulette`]): its shares, its automatic rule
//! and its flag's text.

use crate::RenderError;

/// Russian roulette on the walks of portals and voxels: a VPL that brings a pixel less than a
/// share S of its subset's unshadowed light is walked with probability (its share ÷ S) and,
/// found visible, counts 1 ÷ that probability — the same light on average, in at most 2 ÷ S
/// walks a pixel's subset on average instead of every VPL. The CPU twin always walks every
/// VPL; the starved pixels' second pass takes the same roulette (shade.wgsl's
/// `cs_starved_walks`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum WalkRoulette {
    /// [`AUTO_ROULETTE_SHARE`] where the frame is interleaved in blocks of at least
    /// [`AUTO_ROULETTE_BLOCK`]² (the blur evens out the noise over as many subsets) and a
    /// pixel's VPL subset holds [`AUTO_ROULETTE_VPLS`] or more (8,192 VPLs in 8 × 8 blocks),
    /// or [`AUTO_ROULETTE_RATIO_VPLS`] (2,048) with the ratio estimator, else every VPL walked:
    /// there it halves the frame on a GPU and moves the indirect MSE by a few per cent (at most
    /// +27 % measured); with fewer VPLs, without the ratio, it saves less and costs more, and
    /// in 4 × 4 blocks it leaves blotches (README). The ratio estimator sums each pixel's own
    /// unshadowed light, so that the roulette's noise moves only the visible share: the
    /// indirect MSE −3 … +5 % on 22 of 24 views at 4,096 VPLs, +17 % and +23 % on two near
    /// black (README).
    #[default]
    Auto,
    /// This share S; 0: every VPL walked. [Limit: 0 ≤ S < 1] [Units: share of the light]
    Share(f32),
}

/// The share [`WalkRoulette::Auto`] takes. [Units: share of a pixel's light]
pub const AUTO_ROULETTE_SHARE: f32 = 0.05;
/// The VPLs a pixel's subset must hold for [`WalkRoulette::Auto`] to take its share.
pub const AUTO_ROULETTE_VPLS: u32 = 128;
/// The VPLs a pixel's subset must hold for [`WalkRoulette::Auto`] to take its share where the
/// blur takes the ratio estimator (2,048 VPLs in 8 × 8 blocks). At 16 a subset (1,024 VPLs) it
/// moved the error table's indirect MSE by −0.5 … +2.6 % on 22 views and +8 % and +16 % on two
/// near black, but one of those, the 98 lit pixels of Crytek Sponza's gallery under the spot,
/// went from 0.90 to 1.19 of the reference's indirect energy, outside the ±10 % the error table
/// holds every view to (README).
pub const AUTO_ROULETTE_RATIO_VPLS: u32 = 32;
/// The least interleaving block side at which [`WalkRoulette::Auto`] takes its share.
pub const AUTO_ROULETTE_BLOCK: u32 = 8;

impl WalkRoulette {
    /// The share S for a frame interleaved in blocks of side `block` whose pixels each light
    /// `subset_vpls` VPLs, its blur with the ratio estimator or not (0: off).
    pub fn share(self, subset_vpls: u32, block: u32, ratio: bool) -> f32 {
        let least = if ratio {
            AUTO_ROULETTE_RATIO_VPLS
        } else {
            AUTO_ROULETTE_VPLS
        };
        match self {
            Self::Share(s) => s,
            Self::Auto if block >= AUTO_ROULETTE_BLOCK && subset_vpls >= least => {
                AUTO_ROULETTE_SHARE
            }
            Self::Auto => 0.0,
        }
    }

    /// A share above 0, whatever the VPLs (not auto, not off).
    pub fn is_fixed(self) -> bool {
        matches!(self, Self::Share(s) if s > 0.0)
    }

    /// Checks a share's limits (0 ≤ S < 1); auto is always within them.
    pub fn check(self) -> Result<(), RenderError> {
        match self {
            Self::Share(s) if !(0.0..1.0).contains(&s) => Err(RenderError::Param(format!(
                "walk roulette {s}: give auto or a share of a pixel's light in 0..1 (0: every \
                 VPL walked; 0.05: VPLs under 5 % of it walked by chance)"
            ))),
            _ => Ok(()),
        }
    }
}

impl std::fmt::Display for WalkRoulette {
    /// `auto`, or the share: what [`FromStr`](std::str::FromStr) reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Auto => f.write_str("auto"),
            Self::Share(s) => write!(f, "{s}"),
        }
    }
}

impl std::str::FromStr for WalkRoulette {
    type Err = RenderError;

    /// `auto`, or a share within [`WalkRoulette::check`]'s limits.
    fn from_str(text: &str) -> Result<Self, RenderError> {
        if text == "auto" {
            return Ok(Self::Auto);
        }
        let share = text.parse::<f32>().map_err(|e| {
            RenderError::Param(format!(
                "walk roulette {text:?}: {e}; give auto or a share of a pixel's light in 0..1"
            ))
        })?;
        let r = Self::Share(share);
        r.check().map(|()| r)
    }
}

//! The visibility methods for indirect light: [`GpuMode`] carries each method's own typed
//! parameters (as Bevy's `ClusterConfig` variants do), and [`METHODS`] is the registry that the
//! CLI's `--mode` values, the viewer's mode list and `compare --modes all` are read from.
//!
//! Adding a method: a pass module in `passes/` beside its WGSL, a variant here with its params,
//! its line in [`METHODS`], and its branch in [`super::GpuRenderer`]'s frame.

use crate::RenderError;
use crate::cpu::gates::{GateParams, GateShape};
use crate::cpu::sight_triangles::TRIANGLE_TESTS_PER_WALK;
use crate::cpu::val::ValParams;

pub use super::passes::clustered_gates::{GatesParams, WalkRoulette};
pub use super::passes::cssm::CssmParams;
pub use super::passes::interleave_blur::InterleaveParams;
pub use super::passes::ism_params::{DiskLight, IsmParams, ValIsmParams, VplIsmParams};
pub use super::passes::light_cluster::{DirectLight, LcDisk, LightClusterGpuParams, PcssParams};
pub use super::passes::per_vpl_maps::PerVplParams;
pub use super::passes::val_gather::ValModeParams;

/// Indirect-light visibility on the GPU, with the method's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GpuMode {
    /// Every VPL lights every pixel (no indirect shadows: the baseline).
    None,
    /// Direct light only.
    DirectOnly,
    /// One paraboloid shadow map per VPL, rendered in batches (the brute-force baseline).
    PerVplShadowMaps(PerVplParams),
    /// VPL light through the gates of the level set with
    /// [`super::GpuRenderer::set_level`], the paper's clustered shading: geometry clusters
    /// (tiles × depth slices × visibility cluster), light lists of (VPL, gate chain) assigned
    /// by cones through the gates, the gather over each pixel's list with the chain tested per
    /// pixel (at most 2 hops), or with portals the walk from the VPL's cluster; with
    /// interleaved sampling (`interleave`, as the VAL modes) each pixel gathers one VPL subset
    /// and the geometry-aware blur follows.
    Gates(GatesParams),
    /// The same gate test, brute force: every pixel tests every VPL (for comparison).
    GatesPerPixel(GateParams),
    /// Every VPL lights every pixel with the visibility of its virtual area light: VPLs
    /// clustered into VALs on the GPU, one hard paraboloid shadow map per VAL (the banding
    /// baseline of Dong et al.).
    ValHard(ValModeParams),
    /// As `ValHard`, with convolution soft shadow maps per VAL (Dong et al.): the paper's
    /// method.
    ValCssm(ValModeParams, CssmParams),
    /// Every VPL lights every pixel with the soft shadow of its cluster: VPLs clustered as
    /// LightCluster clusters lights (minimum distance, nearest centre), a cube map per
    /// cluster, PCSS visibility per cluster and pixel (beyond the LightCluster paper); with
    /// interleaved sampling and the geometry-aware blur as the VAL modes.
    VplClusters(LightClusterGpuParams, InterleaveParams),
    /// Every VPL through its own imperfect shadow map (Ritschel et al. 2008): the scene as
    /// points splatted into one atlas of paraboloid maps, holes filled by pull-push, one hard
    /// lookup — the cheap twin of `PerVplShadowMaps`.
    PerVplIsm(VplIsmParams),
    /// Virtual area lights with imperfect shadow maps and PCSS (Weinzierl-Heigl): VPLs
    /// clustered as the paper clusters its RSM, each VAL a disk lighting through the
    /// point-to-disk form factor, its visibility PCSS on its ISM sized by its area, over an
    /// interleaved split G-buffer and the blur.
    ValIsm(ValIsmParams),
}

/// Every method's settings at once — what a command line or a viewer panel holds; each method
/// takes its own part ([`MethodInfo::make`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodSettings {
    /// Per-VPL maps.
    pub per_vpl: PerVplParams,
    /// Clustered gates (`gates.gates` also serves `gates-per-pixel`).
    pub gates: GatesParams,
    /// The VAL modes.
    pub vals: ValModeParams,
    /// The CSSM of `val-cssm`.
    pub cssm: CssmParams,
    /// The VPL clustering of `vpl-clusters`.
    pub vpl_clusters: LightClusterGpuParams,
    /// `per-vpl-ism`.
    pub vpl_ism: VplIsmParams,
    /// `val-ism`.
    pub val_ism: ValIsmParams,
}

impl Default for MethodSettings {
    fn default() -> Self {
        MethodSettings {
            per_vpl: PerVplParams::default(),
            gates: GatesParams::default(),
            vals: ValModeParams::new(),
            cssm: CssmParams::default(),
            vpl_clusters: LightClusterGpuParams::default(),
            vpl_ism: VplIsmParams::default(),
            val_ism: ValIsmParams::default(),
        }
    }
}

impl MethodSettings {
    /// The gates' [`InterleaveParams::min_vpls`] set to `n` (0: their block as given,
    /// whatever the VPL count), and the VAL modes', which a viewer that keeps one interleaving
    /// for both hands on to the gates (the VAL modes do not read it).
    pub fn with_min_vpls(mut self, n: u32) -> MethodSettings {
        self.gates.interleave.min_vpls = n;
        self.vals.interleave.min_vpls = n;
        self
    }
}

/// A registry entry.
#[derive(Debug, Clone, Copy)]
pub struct MethodInfo {
    /// The name on the command line and in reports (`--mode NAME`).
    pub name: &'static str,
    /// One line for `--help` and the viewer.
    pub summary: &'static str,
    /// Whether it needs a baked level.
    pub needs_level: bool,
    /// The mode with its part of `settings`.
    pub make: fn(&MethodSettings) -> GpuMode,
}

/// Every GPU method, in the order lists show them.
pub const METHODS: [MethodInfo; 10] = [
    MethodInfo {
        name: "none",
        summary: "every VPL lights every point (no indirect shadows)",
        needs_level: false,
        make: |_| GpuMode::None,
    },
    MethodInfo {
        name: "per-vpl-shadow-maps",
        summary: "a paraboloid shadow map per VPL, in batches (brute force)",
        needs_level: false,
        make: |s| GpuMode::PerVplShadowMaps(s.per_vpl),
    },
    MethodInfo {
        name: "per-vpl-ism",
        summary: "an imperfect (point-splatted) shadow map per VPL, holes filled by pull-push",
        needs_level: false,
        make: |s| GpuMode::PerVplIsm(s.vpl_ism),
    },
    MethodInfo {
        name: "gates",
        summary: "visibility through the baked level's gates, by clustered shading",
        needs_level: true,
        make: |s| GpuMode::Gates(s.gates),
    },
    MethodInfo {
        name: "gates-per-pixel",
        summary: "the gate test brute force, every pixel against every VPL",
        needs_level: true,
        make: |s| GpuMode::GatesPerPixel(s.gates.gates),
    },
    MethodInfo {
        name: "val-hard",
        summary: "VPLs clustered into virtual area lights, one hard shadow map each",
        needs_level: false,
        make: |s| GpuMode::ValHard(s.vals),
    },
    MethodInfo {
        name: "val-cssm",
        summary: "virtual area lights with convolution soft shadow maps (Dong et al.)",
        needs_level: false,
        make: |s| GpuMode::ValCssm(s.vals, s.cssm),
    },
    MethodInfo {
        name: "val-ism",
        summary: "virtual area lights as disks with imperfect shadow maps and PCSS \
                  (Weinzierl-Heigl)",
        needs_level: false,
        make: |s| GpuMode::ValIsm(s.val_ism),
    },
    MethodInfo {
        name: "vpl-clusters",
        summary: "VPLs clustered as LightCluster clusters lights, a PCSS soft shadow per cluster",
        needs_level: false,
        make: |s| GpuMode::VplClusters(s.vpl_clusters, s.vals.interleave),
    },
    MethodInfo {
        name: "direct-only",
        summary: "direct light alone",
        needs_level: false,
        make: |_| GpuMode::DirectOnly,
    },
];

/// The registry entry named `name`.
pub fn method(name: &str) -> Option<&'static MethodInfo> {
    METHODS.iter().find(|m| m.name == name)
}

impl GpuMode {
    /// The method's registry name.
    pub fn name(&self) -> &'static str {
        match self {
            GpuMode::None => "none",
            GpuMode::DirectOnly => "direct-only",
            GpuMode::PerVplShadowMaps(_) => "per-vpl-shadow-maps",
            GpuMode::Gates(_) => "gates",
            GpuMode::GatesPerPixel(_) => "gates-per-pixel",
            GpuMode::ValHard(_) => "val-hard",
            GpuMode::ValCssm(..) => "val-cssm",
            GpuMode::VplClusters(..) => "vpl-clusters",
            GpuMode::PerVplIsm(_) => "per-vpl-ism",
            GpuMode::ValIsm(_) => "val-ism",
        }
    }

    /// The interleaving of the interleaved modes.
    pub fn interleave(&self) -> Option<InterleaveParams> {
        match self {
            GpuMode::Gates(p) => Some(p.interleave),
            GpuMode::ValHard(v) | GpuMode::ValCssm(v, _) => Some(v.interleave),
            GpuMode::VplClusters(_, i) => Some(*i),
            GpuMode::PerVplIsm(p) => Some(p.interleave),
            GpuMode::ValIsm(p) => Some(p.interleave),
            _ => None,
        }
    }

    /// The mode with the interleaving a frame of `vpls` VPLs runs: the gates' block shrunk
    /// where the VPLs are too few for it ([`InterleaveParams::for_vpls`]). The VAL modes keep
    /// theirs: their error is the VALs' more than the interleaving's, and measured in 3 × 3
    /// and 2 × 2 blocks at 189 and 78 VPLs (val-hard and val-cssm, five views) it was lower on
    /// 4 of 10 and higher on 6 (up to 2.8×, the apartment's window under a lamp outside it).
    pub fn interleave_for(&self, vpls: u32) -> GpuMode {
        match *self {
            GpuMode::Gates(mut p) => {
                // The rule spent (min_vpls 0), so that two modes that run the same frame
                // compare equal (`compare` renders it once).
                p.interleave = InterleaveParams {
                    min_vpls: 0,
                    ..p.interleave.for_vpls(vpls)
                };
                GpuMode::Gates(p)
            }
            m => m,
        }
    }

    /// The mode as it renders a frame of `vpls` VPLs: its interleaving block for that many
    /// ([`Self::interleave_for`]), the gates' automatic roulette resolved
    /// to the share it takes there (0: every VPL walked), and their near field and ratio
    /// estimator off where the roulette thins the walks that far
    /// ([`GatesParams::thinned`](crate::gpu::passes::gates_params::GatesParams::thinned)), so
    /// that two modes that render the same frame compare equal (`gates` and `gates-roulette` at
    /// 8,192 VPLs or more).
    pub fn resolved_for(&self, vpls: u32) -> GpuMode {
        match self.interleave_for(vpls) {
            GpuMode::Gates(mut p) => {
                let thinned = p.thinned(vpls);
                p.walk_roulette = WalkRoulette::Share(p.roulette_share(vpls));
                if thinned {
                    p.near_field = 0.0;
                    p.ratio = false;
                }
                GpuMode::Gates(p)
            }
            m => m,
        }
    }

    /// Checks the method's parameters against their limits (the adapter's limits are checked
    /// when a frame is rendered).
    pub fn check(&self) -> Result<(), RenderError> {
        match self {
            GpuMode::None | GpuMode::DirectOnly => Ok(()),
            GpuMode::PerVplShadowMaps(p) => p.check(),
            GpuMode::Gates(p) => p.check(),
            GpuMode::GatesPerPixel(g) => super::passes::clustered_gates::check_gates(g),
            GpuMode::ValHard(v) => v.check(),
            GpuMode::ValCssm(v, c) => v.check().and(c.check()),
            GpuMode::VplClusters(p, i) => p.check().and(i.check()),
            GpuMode::PerVplIsm(p) => p.check(),
            GpuMode::ValIsm(p) => p.check(),
        }
    }

    /// How many VPLs a pixel walks (through the portals or the voxels) with `vpls` in the
    /// frame (0 for modes that walk none): all of them per pixel, a b²-th interleaved.
    pub fn walks_per_pixel(&self, vpls: u32) -> u32 {
        match self {
            GpuMode::Gates(p) if p.gates.shape != GateShape::Disk => {
                vpls.div_ceil(p.interleave.subsets())
            }
            GpuMode::GatesPerPixel(g) if g.shape != GateShape::Disk => vpls,
            _ => 0,
        }
    }

    /// The mode a frame runs as: `gates-per-pixel` through portals or voxels is mode `gates`
    /// with every VPL at every pixel (1 × 1 blocks: nothing blurred, no dark pixels' walks, no
    /// roulette), whose walks run in batches where a software rasterizer's loop limit needs
    /// them ([`walk_batch`]). Walked in the shading pass, all in one loop, it lost light on
    /// llvmpipe (the ajar door's `main` at 4,096 VPLs: 0.01807 of mean radiance against the
    /// reference's 0.02295) and at 1,024 took twice as long. Disks keep their per-pixel
    /// chains.
    pub fn as_run(&self) -> GpuMode {
        match *self {
            GpuMode::GatesPerPixel(gates) if gates.shape != GateShape::Disk => {
                GpuMode::Gates(GatesParams {
                    gates,
                    interleave: InterleaveParams {
                        block: 1,
                        ..InterleaveParams::default()
                    },
                    walk_roulette: WalkRoulette::Share(0.0),
                    ..GatesParams::default()
                })
            }
            mode => mode,
        }
    }

    /// The VAL clustering of the VAL modes.
    pub fn vals(&self) -> Option<ValParams> {
        match self {
            GpuMode::ValHard(v) | GpuMode::ValCssm(v, _) => Some(v.vals),
            GpuMode::ValIsm(v) => Some(v.vals),
            _ => None,
        }
    }

    /// The gate parameters of the gate modes.
    pub fn gates(&self) -> Option<GateParams> {
        match self {
            GpuMode::Gates(p) => Some(p.gates),
            GpuMode::GatesPerPixel(g) => Some(*g),
            _ => None,
        }
    }

    /// Whether the mode's blur of a frame of `vpls` VPLs takes the ratio estimator
    /// ([`GatesParams::ratio_for`]).
    pub fn ratio_for(&self, vpls: u32) -> bool {
        matches!(self, GpuMode::Gates(p) if p.ratio_for(vpls))
    }

    /// The ratio estimator's grid stride in pixels ([`GatesParams::ratio_grid`]; 1 for the
    /// modes without it).
    pub fn ratio_stride(&self) -> u32 {
        match self {
            GpuMode::Gates(p) => p.ratio_grid(),
            _ => 1,
        }
    }
}

/// The lights' shadow maps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowParams {
    /// Layer side. [Units: texels] [Limit: 16..=4096]
    pub size: u32,
    /// Normal offset of lookups. [Units: texels]
    pub normal_offset: f32,
    /// Depth bias of lookups. [Units: texels]
    pub bias: f32,
}

impl Default for ShadowParams {
    fn default() -> Self {
        ShadowParams {
            size: 1024,
            normal_offset: 1.5,
            bias: 1.0,
        }
    }
}

/// What a frame is rendered with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuParams {
    /// The visibility method and its parameters.
    pub mode: GpuMode,
    /// Geometry-term clamp of every VPL gather. [Units: 1/m²] [Limit: > 0]
    pub g_max: f32,
    /// The lights' shadow maps (their normal offset and bias also serve the per-VPL and VAL
    /// maps' hard lookups).
    pub shadows: ShadowParams,
    /// The direct lights' visibility: their own shadow maps, or LightCluster.
    pub direct: DirectLight,
}

impl Default for GpuParams {
    fn default() -> Self {
        GpuParams {
            mode: GpuMode::None,
            g_max: 10.0,
            shadows: ShadowParams::default(),
            direct: DirectLight::PerLight,
        }
    }
}

impl GpuParams {
    /// Default parameters with `mode`.
    pub fn with_mode(mode: GpuMode) -> GpuParams {
        GpuParams {
            mode,
            ..GpuParams::default()
        }
    }

    /// Checks every parameter's limits.
    pub fn check(&self) -> Result<(), RenderError> {
        if self.g_max.is_nan() || self.g_max <= 0.0 {
            return Err(RenderError::Param(format!(
                "geometry-term clamp {} must be > 0",
                self.g_max
            )));
        }
        if !(16..=4096).contains(&self.shadows.size) {
            return Err(RenderError::Param(format!(
                "shadow map size {} must be 16..=4096",
                self.shadows.size
            )));
        }
        if let DirectLight::LightCluster(p) = &self.direct {
            p.check()?;
        }
        self.mode.check()
    }
}

/// Mesa's software rasterizer (llvmpipe, lavapipe) ends every loop of a shader invocation after
/// 65,535 iterations in all (its `LP_MAX_TGSI_LOOP_ITERATIONS`), without a word: a pixel that
/// walks many VPLs through the portals stops early and loses their light (ajar-door's `door`
/// camera, gates per pixel against the CPU twin: 93 % of the light at 512 VPLs, 55 % at
/// 4,096; Crytek Sponza's gallery, 512 bake, 1,024 VPLs a pixel: 27 %; an H100 matches it to
/// 0.03 % at every count). Mode `gates` there walks a pixel's VPLs through the portals this
/// many a draw, through the voxels as many as the loop limit allows ([`walk_batch`]), and so
/// does `gates-per-pixel` through them ([`GpuMode::as_run`]).
pub const SOFTWARE_WALK_BATCH: u32 = 16;

/// Whether `adapter` is llvmpipe (lavapipe's rasterizer), with its loop limit.
fn software(adapter: &str) -> bool {
    adapter.contains("llvmpipe")
}

/// The loop iterations a software rasterizer allows a shader invocation, less a margin for
/// the loops around the walks (a walk's end: 3 offsets and a 3³ neighbourhood).
const SOFTWARE_LOOP_ITERATIONS: u32 = 65_535 - 256;

/// VPLs of a pixel's subset that mode `gates` with portals or voxels walks in one draw on
/// `adapter`: 0 (all in one) but on a software rasterizer, where portals take
/// [`SOFTWARE_WALK_BATCH`] and voxel walks as many as fit the loop limit when each takes the
/// most steps one can, `sight_steps` (the sight grid's dims summed, plus one; the level's
/// [`LevelBuffers::sight_steps`](super::passes::clustered_gates::LevelBuffers)), and the
/// list entries a walk may read in closed voxels with the triangles: a draw costs a pass over
/// the frame, so fewer draws are faster (e2m3's 21 cm grid: 52 walks a draw, 37 with the
/// triangles; its hall at 512 x 512, 16,384 VPLs: indirect pass 3,466 -> 3,040 ms against 16 a
/// draw). With the walks' roulette a draw first sums its pixel's whole subset of `vpls` (one
/// iteration a VPL), which the voxel walks' share of the limit leaves out. The limit counts a
/// SIMD vector's iterations: since the march runs in a loop of its own (sight.wgsl's
/// `sight_march`), a closed voxel's step takes the inner loop's last iteration and one of the
/// outer's, and lanes that reach a closed voxel wait for the others', so a vector's walk may
/// take more iterations than its longest lane's steps; the bound here assumes every walk
/// crosses the whole grid, where a walk takes a few dozen steps (e2m3's hall: 31 on average,
/// the bound 2,057 on its 13 cm sight grid), and the test against the CPU twin at 4,096 VPLs
/// a pixel checks it.
pub fn walk_batch(adapter: &str, mode: &GpuMode, sight_steps: Option<u32>, vpls: u32) -> u32 {
    match mode {
        GpuMode::Gates(p) if p.gates.shape != GateShape::Disk && software(adapter) => {
            match (p.gates.shape, sight_steps) {
                (GateShape::Voxels, Some(steps)) => {
                    let lists = if p.gates.triangles {
                        TRIANGLE_TESTS_PER_WALK
                    } else {
                        0
                    };
                    let summed = if p.roulette_share(vpls) > 0.0 {
                        vpls.div_ceil(p.interleave.subsets())
                    } else {
                        0
                    };
                    (SOFTWARE_LOOP_ITERATIONS.saturating_sub(summed) / (steps + 1 + lists)).max(1)
                }
                _ => SOFTWARE_WALK_BATCH,
            }
        }
        _ => 0,
    }
}

/// Marked VPLs a tile of the near field (shade.wgsl's `cs_near_field`) walks a round on
/// `adapter` (0: all in one round) — on a software rasterizer as many as fit its loop limit
/// when each is walked: a near walk is at most `radius` long (the frame's largest), so it
/// crosses at most √3 (radius / voxel + 8) + 4 voxels of a sight grid of `voxel_m` (its ends
/// off the surfaces up to 3.25 voxels each, a voxel's corner), twice that in iterations (a
/// closed voxel's step takes two loops' iterations), and reads up to
/// [`TRIANGLE_TESTS_PER_WALK`] list entries with the triangles; the round's own loops (the
/// tile's marks of `vpls` VPLs read twice, a mark a VPL) take their share of the limit. Portal
/// walks take [`SOFTWARE_WALK_BATCH`] a round. A dispatch over every tile costs lavapipe about
/// 15-20 ms at 512² whatever it walks, so only the first round takes every tile: a tile that
/// marks more VPLs than this walks the rest in the next rounds, which take the tiles left.
pub fn near_run(
    adapter: &str,
    mode: &GpuMode,
    voxel_m: Option<f32>,
    radius: f32,
    vpls: u32,
) -> u32 {
    let GpuMode::Gates(p) = mode else {
        return 0;
    };
    if !software(adapter) || radius <= 0.0 {
        return 0;
    }
    match (p.gates.shape, voxel_m) {
        (GateShape::Voxels, Some(edge)) if edge > 0.0 => {
            let crossed = 3f32.sqrt() * (radius / edge + 8.0) + 4.0;
            let steps = (2.0 * crossed).ceil().min(u32::MAX as f32 / 2.0) as u32;
            let lists = if p.gates.triangles {
                TRIANGLE_TESTS_PER_WALK
            } else {
                0
            };
            let spare = SOFTWARE_LOOP_ITERATIONS - 64 - 2 * vpls.div_ceil(32);
            (spare / (steps + 3 + lists)).max(1)
        }
        _ => SOFTWARE_WALK_BATCH,
    }
}

mod describe;
#[cfg(test)]
mod tests;

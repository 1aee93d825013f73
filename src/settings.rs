//! The flags `render`, `compare` and the viewer share: where the VPLs come from and how the
//! image is sampled ([`LightArgs`]), and every method's settings ([`MethodArgs`]).

use clap::{Args, ValueEnum};
use visgate_runtime::cpu::clustered::ClusterParams;
use visgate_runtime::cpu::gates::{GateParams, GateShape};
use visgate_runtime::cpu::lightcluster::LightClusterParams;
use visgate_runtime::cpu::val::ValParams;
use visgate_runtime::gpu::{
    CssmParams, DirectLight, DiskLight, GatesParams, GpuMode, GpuParams, InterleaveParams,
    IsmParams, LcDisk, LightClusterGpuParams, MethodSettings, PcssParams, PerVplParams,
    ShadowParams, ValIsmParams, ValModeParams, VplIsmParams, WalkRoulette,
};
use visgate_runtime::job::{RenderJob, VplSource as JobVpls};
use visgate_runtime::vpl::GeometryClamp;

/// `--gate-shape`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GateShapeArg {
    /// The walk through the level's open voxels (the default): the openings at voxel
    /// resolution, and what stands inside a cluster (a door panel, a table) blocks too; a
    /// finer sight grid (bake --sight-voxel) is closer.
    Voxels,
    /// The baked portals (the true openings between clusters), walked along each segment.
    Portal,
    /// The paper's disks, through chains of at most --gate-hops of them.
    Disk,
}

/// `--direct`: how the direct lights are shadowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DirectArg {
    /// Each light's own cube (or spot) shadow map, 3 × 3 PCF: exact hard shadows, one map
    /// per light.
    PerLight,
    /// LightCluster: lights in view clustered by a minimum distance, one cube map per
    /// cluster, soft shadows by PCSS with the cluster as a disk (see the --lc-* flags).
    Lightcluster,
}

/// `--lc-disk`: the radius of a cluster's disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LcDiskArg {
    /// The farthest light of the cluster from its centre: a light alone keeps its hard
    /// shadow, a disk is no wider than its lights.
    Extent,
    /// The cluster's minimum distance (the paper); also wider than the lights it stands for.
    MinDistance,
}

/// `--ism-val-disk`: how a VAL's disk lights a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DiskArg {
    /// The disk as 5 parts, each by the form factor.
    Parts,
    /// The paper's form factor at the disk's centre.
    Centre,
}

/// `--vpl-source`: where VPLs come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum VplSource {
    /// Light paths traced on the CPU (any number of bounces).
    Paths,
    /// Reflective shadow maps of the lights, sampled at Halton points on the GPU (one bounce).
    Rsm,
}

/// VPLs, pixel samples and the geometry-term clamp.
#[derive(Debug, Clone, Args)]
#[command(next_help_heading = "VPLs and sampling")]
pub struct LightArgs {
    /// Where the VPLs come from.
    #[arg(long, value_enum, default_value_t = VplSource::Paths)]
    pub vpl_source: VplSource,
    /// RSM size per layer (cube face or spot), texels, for --vpl-source rsm.
    #[arg(long, default_value_t = 256)]
    pub rsm_size: u32,
    /// VPL generations per path (1: one-bounce indirect light).
    #[arg(long, default_value_t = 1)]
    pub bounces: u32,
    /// Seed of the VPLs' low-discrepancy sequence.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Pixel samples (jittered).
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// Upper bound of the VPL geometry term cos·cos/d², 1/m² (against spikes near VPLs);
    /// absolute, so the image changes with the scene's scale. Default: from --clamp-distance.
    #[arg(long, conflicts_with = "clamp_distance")]
    pub g_max: Option<f32>,
    /// The geometry-term clamp starts at this fraction of the scene's bounding diagonal
    /// (g_max = 1 / (F·diagonal)²): the same image, up to scale, at any scale of the level.
    #[arg(long, default_value_t = 0.025)]
    pub clamp_distance: f32,
}

impl LightArgs {
    /// A job with these VPLs, samples and clamp, and `method`'s shadow maps (renderer, VPL
    /// count, size and frames at their defaults).
    pub fn job(&self, method: &MethodArgs) -> RenderJob {
        RenderJob {
            params: GpuParams {
                mode: GpuMode::None,
                g_max: GpuParams::default().g_max,
                shadows: ShadowParams {
                    size: method.shadow_size,
                    ..ShadowParams::default()
                },
                direct: method.direct(),
            },
            clamp: match self.g_max {
                Some(g) => GeometryClamp::PerSquareMetre(g),
                None => GeometryClamp::DiagonalFraction(self.clamp_distance),
            },
            vpl_source: match self.vpl_source {
                VplSource::Paths => JobVpls::Paths,
                VplSource::Rsm => JobVpls::Rsm,
            },
            rsm_size: self.rsm_size,
            bounces: self.bounces,
            seed: self.seed,
            spp: self.spp,
            ..RenderJob::default()
        }
    }
}

/// Every method's settings (each method takes its part).
#[derive(Debug, Clone, Args)]
#[command(next_help_heading = "Method settings")]
pub struct MethodArgs {
    /// Shadow map size per layer (GPU), texels.
    #[arg(long, default_value_t = 1024)]
    pub shadow_size: u32,
    /// How the direct lights are shadowed (GPU; every --mode): each light's own maps, or
    /// LightCluster's soft shadow per cluster of lights.
    #[arg(long, value_enum, default_value_t = DirectArg::PerLight)]
    pub direct: DirectArg,
    /// LightCluster: minimum distance between cluster centres at the eye, metres (0: every
    /// light in view is its own cluster, hard shadows); also each cluster's disk radius.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub lc_min_distance: f32,
    /// LightCluster: growth of the minimum distance with a light's distance d from the eye,
    /// per metre (min distance · (1 + S·d): clusters are smaller near the camera).
    #[arg(long, default_value_t = 0.1, allow_hyphen_values = true)]
    pub lc_distance_scale: f32,
    /// LightCluster: most clusters (cube shadow maps) a frame, 1..=256; lights past them join
    /// the nearest cluster.
    #[arg(long, default_value_t = 64)]
    pub lc_max_clusters: u32,
    /// LightCluster: a light's range ends where its irradiance falls below this fraction of
    /// what the brightest light gives at a tenth of the scene's diagonal; lights whose range
    /// misses the view are culled (not shaded), (0, 1].
    #[arg(long, default_value_t = 1e-3)]
    pub lc_cutoff: f32,
    /// LightCluster: each cluster's disk, whose radius scales PCSS's penumbra.
    #[arg(long, value_enum, default_value_t = LcDiskArg::Extent)]
    pub lc_disk: LcDiskArg,
    /// LightCluster: side of each cluster's cube face, texels, 16..=2048 (the atlas holds
    /// 6 × --lc-max-clusters faces).
    #[arg(long, default_value_t = 256)]
    pub lc_map_size: u32,
    /// LightCluster and val-ism: PCSS blocker-search samples per cluster (VAL) and pixel,
    /// 1..=64.
    #[arg(long, default_value_t = 16)]
    pub pcss_blocker_samples: u32,
    /// LightCluster and val-ism: PCSS filter (PCF) samples per cluster (VAL) and pixel in a
    /// penumbra, 1..=128.
    #[arg(long, default_value_t = 32)]
    pub pcss_filter_samples: u32,
    /// What a gate is (--mode gates): the level's open voxels, walked (the default: the
    /// lowest error and mostly the fastest), the baked portals, walked, or the paper's disks.
    #[arg(long, value_enum, default_value_t = GateShapeArg::Voxels)]
    pub gate_shape: GateShapeArg,
    /// --gate-shape voxels: walk the true segment between the surface points and pass a
    /// closed voxel where it hits none of the scene's triangles listed there (listed once, when
    /// a walk first needs them: 0.8 s for Crytek Sponza at 512 on 2 cores): near-exact
    /// visibility (99.3-100 % of pixel-VPL pairs agree with shadow rays on the levels measured,
    /// against 88-99 % without). Part of the balanced setting (the default) and the accurate
    /// one; with --fast, adds it to the fast setting.
    #[arg(long)]
    pub closed_voxel_triangles: bool,
    /// Gates: the accurate setting in one word — the balanced setting (the default) and the
    /// starved taps at three quarters of the block (48 of 8 x 8; a --starved-taps given is
    /// kept) instead of the dark pixels' walks. On eight cameras of four levels, two seeds each,
    /// at 1,024 VPLs: indirect energy within 1.6 % of the reference's, under 1 % of the lit
    /// pixels black and a lower indirect MSE than the fast setting on all sixteen
    /// (x0.10-0.78), at 2-23x the fast setting's frame on lavapipe: for stills and
    /// reference-grade walk-throughs (README, The accurate setting).
    #[arg(long, conflicts_with_all = ["balanced", "fast"])]
    pub accurate: bool,
    /// Gates: the balanced setting, the default, in one word — --closed-voxel-triangles
    /// --blur-tent --starved-dark --near-field 4 --ratio --ratio-stride 3 on the fast setting
    /// (a --starved-taps given is kept). On the same sixteen camera-seeds as --accurate (before the near field
    /// and the ratio): indirect energy within 3 % of the reference's and under 1 % of the lit
    /// pixels black on all sixteen, where the fast setting left Crytek Sponza's gallery 0.89 of
    /// the light and 2.7 % of it black, at 1.2-2.5x the fast setting's frame on lavapipe
    /// (README, The balanced setting); with them, within 1.5x per-VPL shadow maps' indirect
    /// MSE on 23 of 24 views (README, the error table).
    #[arg(long, conflicts_with = "fast")]
    pub balanced: bool,
    /// Gates: the fast setting — the voxel walk passing closed voxels on their planes, the box
    /// blur, no second walks, no near field, no ratio estimator: the default until the
    /// balanced setting, the fastest voxel walk, and the one that loses light where the
    /// geometry grazes a light's paths within a sight voxel (fluted columns, curtains).
    /// --closed-voxel-triangles, --blur-tent, --starved-dark, --starved-taps, --near-field,
    /// --ratio and --ratio-stride add to it one at a time.
    #[arg(long)]
    pub fast: bool,
    /// --gate-shape voxels without the triangles (--fast): block at every closed voxel, with each end
    /// 1.25 voxels or more off its surface, instead of passing a closed voxel where the segment
    /// meets neither of the one or two planes its geometry lies in (fitted once, when a level
    /// is loaded for the walk), with each end 0.3 voxels off its surface where they allow.
    #[arg(long)]
    pub no_closed_voxel_planes: bool,
    /// Portals one walk may pass before it is given up and counted as occluded (--gate-shape
    /// portal), 1..=1024.
    #[arg(long, default_value_t = 64)]
    pub max_walk: u32,
    /// Gate disks are this many times their baked radius (--gate-shape disk).
    #[arg(long, default_value_t = 1.0)]
    pub gate_oversize: f32,
    /// Gates a VPL's light may pass in a chain (--mode gates; the paper: 1).
    #[arg(long, default_value_t = 2)]
    pub gate_hops: u32,
    /// Screen tile side of geometry clusters (--mode gates), pixels, 1..=16 on the GPU.
    #[arg(long, default_value_t = 16)]
    pub tile_px: u32,
    /// Exponential depth slices of geometry clusters (--mode gates), 1..=256.
    #[arg(long, default_value_t = 24)]
    pub depth_slices: u32,
    /// Capacity of the light-list pool (--mode gates with --gate-shape disk; portals keep no
    /// lists: a pixel walks every VPL of its subset), entries of 8 bytes: a frame that needs
    /// more stops with the count it needs. Unset, the pool grows to what a frame needs, up to
    /// the adapter's storage binding limit.
    #[arg(long)]
    pub light_entries: Option<u32>,
    /// Virtual area lights (--mode val-hard): the VPLs are clustered into this many.
    #[arg(long, default_value_t = 30)]
    pub vals: u32,
    /// Most k-means iterations of the VAL clustering (it stops earlier where the assignment
    /// repeats itself; the pass report says whether it converged).
    #[arg(long, default_value_t = 8)]
    pub val_iterations: u32,
    /// Weight of the position term of the VAL clustering distance (the paper: 0.7).
    #[arg(long, default_value_t = 0.7, allow_hyphen_values = true)]
    pub val_w_x: f32,
    /// Weight of the normal-angle term of the VAL clustering distance (the paper: 0.3).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub val_w_alpha: f32,
    /// val-hard / val-cssm: start each frame's clustering from the last frame's centres
    /// instead of the paper's restart from evenly spaced VPLs (steadier, but VALs emptied as
    /// the light moves stay empty; `visgate compare` counts the live ones over a sequence).
    #[arg(long)]
    pub val_warm_start: bool,
    /// Paraboloid shadow map size per VAL, texels.
    #[arg(long, default_value_t = 256)]
    pub val_map_size: u32,
    /// Fourier terms of the convolution soft shadow maps (--mode val-cssm), 1..=16.
    #[arg(long, default_value_t = 4)]
    pub cssm_terms: u32,
    /// Normal offset of CSSM lookups, texels (slope-scaled up to 2×): larger avoids
    /// self-shadowing under wide filter kernels, smaller keeps contact shadows.
    #[arg(long, default_value_t = 3.0)]
    pub cssm_normal_offset: f32,
    /// VAL modes and gates: interleaved sampling in blocks of this side (each pixel lights
    /// itself with one of side² VPL subsets, then a geometry-aware blur over the block); 1:
    /// every VPL at every pixel (the CPU twins, --cpu, always gather every VPL). The most:
    /// a frame of few VPLs runs smaller blocks (--interleave-min-vpls).
    #[arg(long, default_value_t = 8)]
    pub interleave: u32,
    /// Interleaved gates: the fewest VPLs a pixel walks. A frame with fewer VPLs than
    /// --interleave² times this (a lamp outside a window to the void, whose paths mostly leave
    /// the level) runs smaller blocks, the largest power of two that leaves each pixel this
    /// many (189 VPLs: 2 × 2, 47 a pixel, instead of 3 in 8 × 8); `render` names the block it
    /// ran. 0: the block whatever the count. The default keeps 8 × 8 from 768 VPLs, 4 × 4 from
    /// 192. The VAL modes keep their block (their error is the VALs' more than the
    /// interleaving's).
    #[arg(long, value_name = "N", default_value_t = visgate_runtime::gpu::MIN_VPLS_PER_PIXEL)]
    pub interleave_min_vpls: u32,
    /// Blur: leave out neighbours farther than this fraction of the scene's size.
    #[arg(long, default_value_t = 0.1)]
    pub blur_distance: f32,
    /// Blur: leave out neighbours whose normals' cosine is below this.
    #[arg(long, default_value_t = 0.8, allow_hyphen_values = true)]
    pub blur_normal: f32,
    /// Blur: a neighbour that does not agree with the pixel gives way to the nearest copy of
    /// its VPL subset a block away that does (along a wall's edge, a jamb), so that the
    /// average holds more of the VPLs; every interleaved mode.
    #[arg(long)]
    pub blur_fill: bool,
    /// Blur: weight the neighbours by a tent over (2·side − 1)² pixels instead of the box of
    /// side²: every VPL subset still weighs the same, but a bright or dark pixel spreads as a
    /// soft pyramid instead of a square of the block's size; every interleaved mode (gates
    /// have it in their balanced setting, the default, unless --fast). Summed in two passes,
    /// rows then columns (2·(2·side − 1) taps a pixel instead of (2·side − 1)²).
    #[arg(long)]
    pub blur_tent: bool,
    /// Blur: sum the tent in one pass of (2·side − 1)² taps, as before its two passes (for
    /// comparing them: the two passes take a tap that agrees with its row's pixel, not only
    /// with the pixel, and read the rows that do not agree tap by tap).
    #[arg(long)]
    pub blur_tent_one_pass: bool,
    /// Gates, interleaved: a pixel whose blur block holds fewer pixels than this that agree
    /// with it (a door jamb, a strip along a wall) walks, in a second pass, the VPL subsets of
    /// the pixels that do not agree, so that every VPL counts once there (a pair of pixel and
    /// subset a GPU thread), with the walks' roulette of --walk-roulette; 0: off (default), at
    /// most --interleave². Costs 2-7x the frame on lavapipe at 48-64; `render` prints how many
    /// pixels starved. See the README.
    #[arg(long, default_value_t = 0)]
    pub starved_taps: u32,
    /// Gates, interleaved: a pixel whose agreeing neighbours in its blur block found no light
    /// at all, where another pixel of the block found some, walks the VPL subsets of those
    /// that do not agree too, however many agree (a lit strip whose few VPLs fell in the other
    /// pixels' subsets comes out black without it); a block that found no light anywhere is
    /// taken for indirect shadow. Beside --starved-taps or alone; part of the balanced setting
    /// (the default), so it counts with --fast.
    #[arg(long)]
    pub starved_dark: bool,
    /// Gates with portals or voxels: Russian roulette on the walks (the starved pixels' too).
    /// A VPL that brings a pixel less than this share of its VPL subset's unshadowed light is
    /// walked by chance, with probability its share / this, and counts as much more where
    /// visible: the same light on average in at most 2 / this walks a subset on average (0.05:
    /// 40, where 16,384 VPLs in 8 x 8 blocks walk 256), with noise the blur evens out. 0: every VPL walked. auto: 0.05
    /// where the frame is interleaved in blocks of 8 x 8 or more and a pixel's subset holds 128
    /// VPLs or more (8,192 VPLs in 8 x 8 blocks: there it halves the frame on a GPU and moves
    /// the indirect error by a few per cent, at most +27 % measured; in 4 x 4 blocks it leaves
    /// blotches; see the README), or 32 with the ratio estimator (2,048 VPLs in the balanced
    /// and accurate settings, whose estimator keeps each pixel's own unshadowed light: at
    /// 4,096 VPLs the frame 1.1-1.7x faster on lavapipe, the indirect error -3 ... +5 % on 22
    /// of 24 views, +17 % and +23 % on two near black), else 0.
    #[arg(long, value_name = "auto|SHARE", value_parser = walk_roulette, default_value = "auto")]
    pub walk_roulette: WalkRoulette,
    /// Interleaved gates with portals or voxels, the near field: each pixel walks the VPLs
    /// nearer it than K interleaving blocks' width itself (K x 8 pixels' width on a surface at
    /// its distance), every one of them, unblurred, and its VPL subset the rest. A VPL beside
    /// a crease lights the other face in a spot about as wide as its distance, which
    /// interleaved one pixel in 64 takes and the blur smears over its block: most of the
    /// interleaving's error in the light's own room. 0: none. At most 8; off where the walks'
    /// roulette is on and a pixel's subset holds 128 VPLs or more (by default from 8,192 VPLs
    /// in 8 x 8 blocks) and above 32,768 VPLs.
    /// Unset: 4 in the balanced and accurate settings (the indirect MSE x0.19-1.0 on 24 views
    /// at 1,024 VPLs, its pass 3-32 % of the frame on lavapipe), 0 in the fast one
    #[arg(long, value_name = "K")]
    pub near_field: Option<f32>,
    /// Interleaved gates with portals or voxels, the ratio estimator (Heitz et al. 2018): each
    /// pixel sums the unshadowed light of every VPL beyond its near field itself (no
    /// visibility: a loop over the VPLs, the none mode's cost), and the blur scales it by the
    /// share of their unshadowed light its neighbours' walks found visible, weighed against
    /// their average light by that share: where every VPL is visible a pixel gets its exact
    /// light, whichever VPL subsets its block held, and the interleaving's error is left to
    /// where the visibility changes across a block. Part of the balanced and accurate settings
    /// (the indirect MSE x0.18-0.98 on 21 of 24 views at 1,024 VPLs, within 1.5x per-VPL
    /// shadow maps' on 23; the frame 1.6-2.1x on lavapipe at 512², its pass about 0.8 ms at
    /// 1,024 VPLs on an H200 by the none mode's loop: see the README); this turns it on with --fast. Off where the
    /// walks' roulette is on and a pixel's subset holds 128 VPLs or more (by default from 8,192
    /// VPLs in 8 x 8 blocks).
    #[arg(long, conflicts_with = "no_ratio")]
    pub ratio: bool,
    /// Leaves the ratio estimator (--ratio) out of the balanced or accurate setting: the blur
    /// averages its taps' light (Laine et al.), and the pass that sums each pixel's unshadowed
    /// light is not run.
    #[arg(long)]
    pub no_ratio: bool,
    /// The ratio estimator's grid: the unshadowed light summed at every N-th pixel across and
    /// down (a 1/N² share of the pixels, each every VPL) and at the pixels between whose four
    /// grid pixels around do not all lie on their surface (beside creases, edges and steps:
    /// they sum their own); the others take it bilinearly from those four. The render's report
    /// says how many summed their own. 1: at every pixel. At most 8. Unset: 3 (the indirect
    /// MSE within 0.9 % of every pixel's own on 23 of 24 views, 3.6 % on one, the pass
    /// 3.1-4.8x shorter on lavapipe at 512²; every pixel with --fast --ratio)
    #[arg(long, value_name = "N", conflicts_with = "no_ratio")]
    pub ratio_stride: Option<u32>,
    /// Per-VPL paraboloid map size (GPU), texels.
    #[arg(long, default_value_t = 128)]
    pub vpl_map_size: u32,
    /// Per-VPL maps rendered and gathered per batch (bounds their memory).
    #[arg(long, default_value_t = 128)]
    pub vpl_batch: u32,
    /// Imperfect shadow maps (--mode per-vpl-ism, val-ism): side of each emitter's paraboloid
    /// map, a power of two in 16..=512 texels. Unset: 128 (the paper's 4096² atlas of 128²
    /// maps), halved until the maps fit the adapter's largest storage buffer (4,096 VPLs in
    /// 128 MiB: 64²).
    #[arg(long)]
    pub ism_map_size: Option<u32>,
    /// ISMs: points splatted into each map, 64..=65536 — the sampling density: a point stands
    /// for the scene's area over this many.
    #[arg(long, default_value_t = 8192)]
    pub ism_points: u32,
    /// ISMs: pull-push levels that fill the holes between points (the paper: 2; 0: none).
    #[arg(long, default_value_t = 2)]
    pub ism_pull_push: u32,
    /// ISMs: splats covering a point of a surface on average, 0.25..=64 (a point's splat is
    /// √coverage times the radius of its share of the scene's area; at 1, e⁻¹ of a blocker is
    /// left open and what lies behind shows through).
    #[arg(long, default_value_t = 4.0)]
    pub ism_coverage: f32,
    /// ISMs: largest splat radius of a point near its emitter, texels, 0..=8.
    #[arg(long, default_value_t = 3.0)]
    pub ism_max_splat: f32,
    /// ISMs: depth bias of lookups, texels (point depths are noisy: larger than a rasterised
    /// map's).
    #[arg(long, default_value_t = 3.0)]
    pub ism_bias: f32,
    /// ISMs: normal offset of lookups, texels.
    #[arg(long, default_value_t = 1.5)]
    pub ism_normal_offset: f32,
    /// ISM modes: interleaving block side (the split G-buffer's n × m tiles: emitter i lights
    /// tile i mod side²). Unset: 1 for per-vpl-ism (every VPL at every pixel, as
    /// per-vpl-shadow-maps), 4 for val-ism.
    #[arg(long)]
    pub ism_interleave: Option<u32>,
    /// val-ism: virtual area lights, 1..=4096 (the paper's Table 1: 64).
    #[arg(long, default_value_t = 64)]
    pub ism_vals: u32,
    /// val-ism: weights w_p, w_n, w_f of the clustering metric μ = w_p·d_p + w_n·d_n + w_f·d_f
    /// (position over the VPLs' diagonal, normal angle over π, relative flux difference).
    #[arg(long, value_name = "P,N,F", value_parser = three_weights, default_value = "0.6,0.3,0.1")]
    pub ism_val_weights: [f32; 3],
    /// val-ism: how a VAL's disk lights a point — `parts`: as 5 parts (its centre and 4 at ¾
    /// of its radius), each by the form factor, within 4 % of the disk's integral from two
    /// radii at every angle; `centre`: the paper's form factor at its centre, exact on its
    /// axis but 28 % under at two radii 60° off it (dark corners).
    #[arg(long, value_enum, default_value_t = DiskArg::Parts)]
    pub ism_val_disk: DiskArg,
    /// val-ism: one hard lookup per VAL instead of PCSS (the paper's "simple-sampled" VALs).
    #[arg(long)]
    pub ism_hard_lookups: bool,
    /// val-ism: a VPL joins only the VALs whose point splat reaches it, a radius as a fraction
    /// of the VPLs' diagonal (the nearest VAL where none does).
    #[arg(long, default_value_t = 0.25)]
    pub ism_val_splat: f32,
}

impl MethodArgs {
    /// The direct lights' visibility from the flags.
    pub fn direct(&self) -> DirectLight {
        match self.direct {
            DirectArg::PerLight => DirectLight::PerLight,
            DirectArg::Lightcluster => DirectLight::LightCluster(self.light_cluster()),
        }
    }

    /// LightCluster's settings from the --lc-* and --pcss-* flags (direct lights and mode
    /// vpl-clusters alike).
    pub fn light_cluster(&self) -> LightClusterGpuParams {
        LightClusterGpuParams {
            clustering: LightClusterParams {
                min_distance_m: self.lc_min_distance,
                distance_scale: self.lc_distance_scale,
                max_clusters: self.lc_max_clusters,
                cutoff: self.lc_cutoff,
            },
            disk: match self.lc_disk {
                LcDiskArg::Extent => LcDisk::Extent,
                LcDiskArg::MinDistance => LcDisk::MinDistance,
            },
            map_size: self.lc_map_size,
            pcss: PcssParams {
                blocker_samples: self.pcss_blocker_samples,
                filter_samples: self.pcss_filter_samples,
            },
        }
    }

    /// Interleaving and blur from the flags (VAL modes and gates alike).
    fn interleave_params(&self) -> InterleaveParams {
        InterleaveParams {
            block: self.interleave,
            blur_distance: self.blur_distance,
            blur_normal: self.blur_normal,
            fill: self.blur_fill,
            tent: self.blur_tent,
            tent_rows: !self.blur_tent_one_pass,
            starved_taps: self.starved_taps,
            starved_dark: self.starved_dark,
            min_vpls: self.interleave_min_vpls,
        }
    }

    /// The ISMs from the --ism-* flags.
    fn ism(&self) -> IsmParams {
        IsmParams {
            map_size: self.ism_map_size,
            points_per_map: self.ism_points,
            pull_push: self.ism_pull_push,
            coverage: self.ism_coverage,
            max_splat: self.ism_max_splat,
            bias: self.ism_bias,
            normal_offset: self.ism_normal_offset,
            ..IsmParams::default()
        }
    }

    /// An ISM mode's interleaving: --ism-interleave or `default`, the blur's flags.
    fn ism_interleave(&self, default: u32) -> InterleaveParams {
        InterleaveParams {
            block: self.ism_interleave.unwrap_or(default),
            ..self.interleave_params()
        }
    }

    /// Mode val-ism from the flags.
    fn val_ism(&self) -> ValIsmParams {
        let [w_x, w_alpha, w_f] = self.ism_val_weights;
        let base = ValIsmParams::default();
        ValIsmParams {
            vals: ValParams {
                count: self.ism_vals,
                iterations: self.val_iterations,
                w_x,
                w_alpha,
                w_f,
                splat: Some(self.ism_val_splat),
                ..base.vals
            },
            ism: self.ism(),
            pcss: PcssParams {
                blocker_samples: self.pcss_blocker_samples,
                filter_samples: self.pcss_filter_samples,
            },
            hard_lookups: self.ism_hard_lookups,
            disk: match self.ism_val_disk {
                DiskArg::Parts => DiskLight::Parts,
                DiskArg::Centre => DiskLight::Centre,
            },
            interleave: self.ism_interleave(base.interleave.block),
        }
    }

    /// The gates' parameters as the flags spell them, before the setting (--fast, --balanced
    /// or --accurate) is applied: the fast setting with what the flags add.
    pub fn flagged_gates(&self) -> GatesParams {
        GatesParams {
            gates: GateParams {
                oversize: self.gate_oversize,
                max_hops: self.gate_hops,
                shape: match self.gate_shape {
                    GateShapeArg::Portal => GateShape::Portal,
                    GateShapeArg::Disk => GateShape::Disk,
                    GateShapeArg::Voxels => GateShape::Voxels,
                },
                max_walk: self.max_walk,
                triangles: self.closed_voxel_triangles,
                planes: !self.no_closed_voxel_planes,
            },
            clusters: ClusterParams {
                tile_px: self.tile_px,
                depth_slices: self.depth_slices,
            },
            light_entries: self.light_entries,
            interleave: self.interleave_params(),
            walk_roulette: self.walk_roulette,
            walk_seed: 0,
            near_field: self.near_field.unwrap_or(0.0),
            ratio: self.ratio,
            ratio_stride: self.ratio_stride.unwrap_or(0),
        }
    }

    /// `g` (a setting applied to [`MethodArgs::flagged_gates`]) with the flags that a setting
    /// sets but a user may give: --near-field, --ratio, --no-ratio and --ratio-stride.
    pub fn over_setting(&self, mut g: GatesParams) -> GatesParams {
        if let Some(k) = self.near_field {
            g.near_field = k;
        }
        if self.ratio || self.no_ratio {
            g.ratio = self.ratio;
        }
        if let Some(n) = self.ratio_stride {
            g.ratio_stride = n;
        }
        g
    }

    /// Every method's settings from the flags.
    pub fn settings(&self) -> MethodSettings {
        let gates = self.flagged_gates();
        // The gates' setting over what the other flags say: balanced unless told.
        let gates = self.over_setting(match (self.accurate, self.fast) {
            (true, _) => gates.accurate(),
            (_, true) => gates,
            _ => gates.balanced(),
        });
        MethodSettings {
            per_vpl: PerVplParams {
                map_size: self.vpl_map_size,
                batch: self.vpl_batch,
            },
            gates,
            vals: ValModeParams {
                vals: ValParams {
                    count: self.vals,
                    iterations: self.val_iterations,
                    w_x: self.val_w_x,
                    w_alpha: self.val_w_alpha,
                    warm_start: self.val_warm_start,
                    ..ValParams::default()
                },
                map_size: self.val_map_size,
                interleave: self.interleave_params(),
            },
            vpl_clusters: self.light_cluster(),
            vpl_ism: VplIsmParams {
                ism: self.ism(),
                interleave: self.ism_interleave(VplIsmParams::default().interleave.block),
            },
            val_ism: self.val_ism(),
            cssm: CssmParams {
                terms: self.cssm_terms,
                normal_offset: self.cssm_normal_offset,
                ..CssmParams::default()
            },
        }
    }
}

/// `--walk-roulette auto|SHARE` ([`WalkRoulette`]'s own parser and limits).
fn walk_roulette(text: &str) -> Result<WalkRoulette, String> {
    text.parse()
        .map_err(|e: visgate_runtime::RenderError| e.to_string())
}

/// `--ism-val-weights P,N,F`: three numbers, comma-separated.
fn three_weights(text: &str) -> Result<[f32; 3], String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e}; give three numbers P,N,F such as 0.6,0.3,0.1"))?;
    <[f32; 3]>::try_from(values).map_err(|v| {
        format!(
            "{text:?} gives {} weights; give three, P,N,F (position, normal, flux), such as 0.6,0.3,0.1",
            v.len()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walk_roulette_reads_auto_or_a_share_and_refuses_the_rest() {
        assert_eq!(walk_roulette("auto"), Ok(WalkRoulette::Auto));
        assert_eq!(walk_roulette("0.1"), Ok(WalkRoulette::Share(0.1)));
        assert_eq!(walk_roulette("0"), Ok(WalkRoulette::Share(0.0)));
        for bad in ["1", "-0.1", "half", "NaN"] {
            let e = walk_roulette(bad).expect_err(bad);
            assert!(e.contains("give auto"), "{e}");
        }
    }
}

//! Interleaved sampling's other half (blur.wgsl): the indirect irradiance that the gather wrote
//! with each pixel lit by one of b² VPL subsets, blurred over the b × b block where the
//! geometry agrees (Laine et al.'s thresholds), times albedo / π, added onto the image (through
//! a ping-pong target and a copy).

use std::sync::OnceLock;

use super::gbuffer::GBufferOutput;
use super::shade::{HDR, frame_pass, frame_target};
use crate::RenderError;
use crate::gpu::context::{Pool, bind_group, compute_pipeline_with};
use crate::gpu::layout::ValGather;
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, shaders};

/// Interleaved sampling and the geometry-aware blur.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterleaveParams {
    /// Block side b: a pixel lights itself with one of b² VPL subsets (1: every VPL at every
    /// pixel), then the blur over the block. [Units: px] [Limit: 1..=16]
    pub block: u32,
    /// Blur: neighbours farther than this fraction of the scene's size are left out (Laine et
    /// al.: 0.1). [Limit: ≥ 0]
    pub blur_distance: f32,
    /// Blur: neighbours whose normal's cosine to the pixel's is below this are left out (Laine
    /// et al.: 0.8). [Limit: −1..=1]
    pub blur_normal: f32,
    /// Gates: a pixel whose block holds fewer taps than this that agree with it (the blur's
    /// test) walks the VPL subsets of those that do not itself, and the blur adds them to the
    /// agreeing taps' subsets (a door jamb, a strip along a wall: the few subsets the blur
    /// would average may hold none of the VPLs that light it); 0: none. [Limit: 0..=block²]
    pub starved_taps: u32,
    /// Gates: a pixel whose agreeing taps found no light at all, where some other tap of its
    /// block did, walks the VPL subsets of the taps that do not agree too, however many agree
    /// (a lit strip whose few VPLs fell in the other taps' subsets); a pixel whose whole block
    /// agrees, or whose block found no light anywhere (indirect shadow), walks nothing more.
    pub starved_dark: bool,
    /// Blur: a tap that does not agree with the pixel gives way to the nearest copy of its
    /// VPL subset one block away (a block's side along x or y) that does, so that the average
    /// holds more of the b² subsets; off: it is left out (Laine et al.).
    pub fill: bool,
    /// Blur: the taps weighted by a tent over (2b − 1)² pixels, (b − |dx|)(b − |dy|), instead
    /// of the box of b × b: each of the b² subsets still weighs the same (once at weight b² or
    /// twice summing to it along each axis), but one bright tap spreads as a pyramid instead
    /// of a b × b square. Off: Laine et al.'s box. A starved pixel keeps the box.
    pub tent: bool,
    /// Blur: the tent summed in two passes, each pixel's row of 2b − 1 taps and then its
    /// column of rows (blur.wgsl's `cs_tent_rows`): 2 (2b − 1) taps a pixel instead of
    /// (2b − 1)², the same where every tap agrees with its row's pixel as with the pixel. Off:
    /// one pass. The fill keeps the one pass.
    pub tent_rows: bool,
    /// Gates: the fewest VPLs a pixel walks: where a frame holds fewer than `block`² times this,
    /// the block shrinks to the largest power of two that leaves each pixel this many
    /// ([`InterleaveParams::for_vpls`]), so that a level whose light paths mostly leave it (a
    /// lamp outside a window to the void: 189 VPLs of 1,024 paths, 3 a pixel in 8 × 8 blocks)
    /// is not lit by a few VPLs a pixel; 0: the block as given, whatever the count. 12 keeps 8
    /// × 8 blocks from 768 VPLs, 4 × 4 from 192, 2 × 2 from 48. [Units: VPLs] [Limit:
    /// 0..=4,096]
    pub min_vpls: u32,
}

/// [`InterleaveParams::min_vpls`]'s default: 8 × 8 blocks from 768 VPLs, the count a level of
/// 1,024 light paths keeps where a few of them leave it (LibreQuake e2m3: 928).
pub const MIN_VPLS_PER_PIXEL: u32 = 12;

/// [`InterleaveParams::min_vpls`]'s limit.
const MIN_VPLS_MAX: u32 = 4_096;

impl Default for InterleaveParams {
    fn default() -> Self {
        InterleaveParams {
            block: 8,
            blur_distance: 0.1,
            blur_normal: 0.8,
            starved_taps: 0,
            starved_dark: false,
            fill: false,
            tent: false,
            tent_rows: true,
            min_vpls: MIN_VPLS_PER_PIXEL,
        }
    }
}

impl InterleaveParams {
    /// The interleaving a frame of `vpls` VPLs runs: where the block leaves a pixel fewer
    /// than [`Self::min_vpls`], the largest power of two that leaves it as many (⌊√(vpls /
    /// min_vpls)⌋ rounded down to one, at least 1), and the starved taps with it in proportion
    /// (48 of 8 × 8: 12 of 4 × 4); as given where `min_vpls` is 0, the block is 1 or the frame
    /// holds no VPL. A power of two, for the VPL order stratifies each of b² subsets over every
    /// light's directions only then ([`crate::vpl_order`]): at 189 VPLs in 3 × 3 blocks the sun
    /// window's `door` had 2.5-4.6× the error of 4 × 4 on two seeds of three, and on one more
    /// than in 8 × 8.
    pub fn for_vpls(&self, vpls: u32) -> InterleaveParams {
        if self.min_vpls == 0 || self.block <= 1 || vpls == 0 {
            return *self;
        }
        let fit = (vpls / self.min_vpls).isqrt();
        if fit >= self.block {
            return *self;
        }
        let block = if fit == 0 { 1 } else { 1 << fit.ilog2() };
        let subsets = block * block;
        InterleaveParams {
            block,
            starved_taps: (self.starved_taps * subsets)
                .div_ceil(self.subsets())
                .min(subsets),
            ..*self
        }
    }

    /// The VPL subsets B = b².
    pub fn subsets(&self) -> u32 {
        self.block * self.block
    }

    /// Three quarters of the block's taps: the starved pixels' count of `visgate compare`'s
    /// gates-starved and of the accurate setting (48 of 8 × 8; 0 for a block of 1).
    pub fn three_quarters(&self) -> u32 {
        3 * self.subsets() / 4
    }

    /// Whether starved pixels walk what their block lacks: an interleaved block and a
    /// [`InterleaveParams::starved_taps`] or [`InterleaveParams::starved_dark`] set.
    pub fn walks_starved(&self) -> bool {
        self.block > 1 && (self.starved_taps > 0 || self.starved_dark)
    }

    /// The blur's distance threshold in metres for frame `f` (a fraction of the scene's size).
    pub fn blur_distance_m(&self, f: &Frame) -> f32 {
        self.blur_distance * f.scene.far_m / 4.0
    }

    /// Whether the blur sums the tent by rows ([`InterleaveParams::tent_rows`]): a tent of an
    /// interleaved block, without the fill.
    pub fn by_rows(&self) -> bool {
        self.tent && self.tent_rows && !self.fill && self.block > 1
    }

    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        if !(1..=16).contains(&self.block) {
            return Err(RenderError::Param(format!(
                "interleaving block {} must be 1..=16 pixels (1: every VPL at every pixel)",
                self.block
            )));
        }
        if self.starved_taps > self.subsets() {
            return Err(RenderError::Param(format!(
                "starved taps {} must be at most the interleaving block's {} pixels ({}²; 0 \
                 turns the starved pixels' walks off)",
                self.starved_taps,
                self.subsets(),
                self.block
            )));
        }
        if self.min_vpls > MIN_VPLS_MAX {
            return Err(RenderError::Param(format!(
                "interleaving's fewest VPLs a pixel {} must be at most {MIN_VPLS_MAX} (0: the \
                 block whatever the VPL count)",
                self.min_vpls
            )));
        }
        let (d, n) = (self.blur_distance, self.blur_normal);
        if !(d >= 0.0 && d.is_finite() && (-1.0..=1.0).contains(&n)) {
            return Err(RenderError::Param(format!(
                "blur distance {d} must be >= 0 (a fraction of the scene's size) and blur \
                 normal threshold {n} a cosine in -1..=1"
            )));
        }
        Ok(())
    }
}

/// The blur's passes, each a pipeline of blur.wgsl made when a frame first asks for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum BlurPass {
    /// The compose, every tap read by the pixel (the box, the one-pass tent).
    Compose,
    /// The compose with [`InterleaveParams::fill`] (blur.wgsl's `BLUR_FILL`: a pipeline without
    /// the fill's code runs the taps 3.5× as fast on llvmpipe).
    ComposeFilled,
    /// The compose of the tent from its rows (`BLUR_TENT_ROWS`).
    ComposeRows,
    /// The tent's rows (`cs_tent_rows`).
    TentRows,
}

impl BlurPass {
    fn pipeline(self, d: &wgpu::Device, module: &wgpu::ShaderModule) -> wgpu::ComputePipeline {
        let compose = |label, fill: bool, rows: bool| {
            let constants = [
                ("BLUR_FILL", f64::from(u8::from(fill))),
                ("BLUR_TENT_ROWS", f64::from(u8::from(rows))),
            ];
            compute_pipeline_with(d, label, module, "cs_compose", &constants)
        };
        match self {
            BlurPass::Compose => compose("blur", false, false),
            BlurPass::ComposeFilled => compose("blur (filled)", true, false),
            BlurPass::ComposeRows => compose("blur (tent by rows)", false, true),
            BlurPass::TentRows => {
                compute_pipeline_with(d, "tent rows", module, "cs_tent_rows", &[])
            }
        }
    }
}

/// The blur-and-compose pipelines ([`BlurPass`]).
pub struct InterleaveBlur {
    module: wgpu::ShaderModule,
    pipelines: [OnceLock<wgpu::ComputePipeline>; 4],
}

impl InterleaveBlur {
    /// Builds the plain compose's pipeline (the others when first used).
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<InterleaveBlur, RenderError> {
        let blur = InterleaveBlur {
            module: shaders::module(d, s, "blur.wgsl")?,
            pipelines: Default::default(),
        };
        blur.pipeline(d, BlurPass::Compose);
        Ok(blur)
    }

    fn pipeline(&self, d: &wgpu::Device, pass: BlurPass) -> &wgpu::ComputePipeline {
        self.pipelines[pass as usize].get_or_init(|| pass.pipeline(d, &self.module))
    }

    /// The blur's constants (a `ValGather` with only the interleaving's fields) for a mode
    /// without a VAL gather of its own: its indirect target deinterleaved (the gates') or in
    /// pixel order (the ISM modes').
    pub fn uniform(
        f: &Frame,
        p: &InterleaveParams,
        pool: &mut Pool,
        deinterleaved: bool,
    ) -> wgpu::Buffer {
        let constants = ValGather {
            vpl_count: f.vpl_count,
            g_max: f.params.g_max,
            block: p.block,
            subsets: p.subsets(),
            blur_distance: p.blur_distance_m(f),
            blur_normal: p.blur_normal,
            deinterleaved: u32::from(deinterleaved),
            blur_fill: u32::from(p.fill),
            blur_tent: u32::from(p.tent),
            ratio: u32::from(f.ratio),
            ratio_stride: f.ratio_stride,
            ..bytemuck::Zeroable::zeroed()
        };
        pool.upload(
            f.ctx,
            "blur",
            bytemuck::bytes_of(&constants),
            wgpu::BufferUsages::UNIFORM,
        )
    }

    /// Records the blur of `indirect` composed onto `out`, with the gather's constants
    /// `uniform` (a `ValGather` made from `il`), the starved pixels' own sums where gates
    /// have them (`Shade::record_starved`) and each pixel's unshadowed far light where they
    /// take the ratio estimator (`Unshadowed::record`).
    pub fn record(
        &self,
        f: &Frame,
        il: &InterleaveParams,
        pool: &mut Pool,
        rec: &mut Recorder,
        (g, uniform, indirect, out): (
            &GBufferOutput,
            &wgpu::Buffer,
            &wgpu::Texture,
            &wgpu::Texture,
        ),
        (starved, unshadowed): (Option<&wgpu::Texture>, Option<&wgpu::Texture>),
    ) {
        let d = &f.ctx.device;
        let by_rows = il.by_rows();
        let pass = match (il.fill, by_rows) {
            (true, _) => BlurPass::ComposeFilled,
            (false, true) => BlurPass::ComposeRows,
            (false, false) => BlurPass::Compose,
        };
        let pipeline = self.pipeline(d, pass);
        let other = frame_target(f, pool, "hdr (ping-pong)");
        let tex = wgpu::BindingResource::TextureView;
        let rows = by_rows.then(|| self.tent_rows(f, pool, rec, (g, uniform, indirect)));
        // Modes without them read a texel of zeros (starved: w 0, none starved).
        let mut or_texel = |t: Option<&wgpu::Texture>, label: &'static str| match t {
            Some(t) => t.create_view(&Default::default()),
            None => pool
                .texture(
                    d,
                    label,
                    [1, 1, 1],
                    1,
                    HDR,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                )
                .create_view(&Default::default()),
        };
        let starved_view = or_texel(starved, "no starved pixels");
        let unshadowed_view = or_texel(unshadowed, "no unshadowed light");
        let rows_view = or_texel(rows.as_ref().map(|r| &r[0]), "no tent rows");
        let rows_unshadowed_view = or_texel(rows.as_ref().map(|r| &r[1]), "no tent rows");
        let (out_view, indirect_view, other_view) = (
            out.create_view(&Default::default()),
            indirect.create_view(&Default::default()),
            other.create_view(&Default::default()),
        );
        let bg = bind_group(
            d,
            &pipeline.get_bind_group_layout(0),
            "blur",
            vec![
                (0, uniform.as_entire_binding()),
                (3, tex(&g.views[0])),
                (4, tex(&g.views[1])),
                (5, tex(&g.views[2])),
                (6, tex(&out_view)),
                (12, tex(&indirect_view)),
                (13, tex(&other_view)),
                (14, tex(&starved_view)),
                (15, tex(&unshadowed_view)),
                (18, tex(&rows_view)),
                (19, tex(&rows_unshadowed_view)),
            ],
        );
        let span = rec.begin("blur + compose");
        let size = f.view.size;
        frame_pass(
            &mut rec.enc,
            "blur + compose",
            pipeline,
            &[&bg],
            span.compute(),
            size,
        );
        rec.enc
            .copy_texture_to_texture(other.as_image_copy(), out.as_image_copy(), out.size());
        rec.end();
    }

    /// Records the tent's rows (blur.wgsl's `cs_tent_rows`) of `indirect`: their light and
    /// weight (a frame target) and their unshadowed light (R32F), for the compose by rows.
    fn tent_rows(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        (g, uniform, indirect): (&GBufferOutput, &wgpu::Buffer, &wgpu::Texture),
    ) -> [wgpu::Texture; 2] {
        let d = &f.ctx.device;
        let pipeline = self.pipeline(d, BlurPass::TentRows);
        let [w, h] = f.view.size;
        let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
        let rows = [
            frame_target(f, pool, "tent rows"),
            pool.texture(
                d,
                "tent rows (unshadowed)",
                [w, h, 1],
                1,
                wgpu::TextureFormat::R32Float,
                usage,
            ),
        ];
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (indirect_view, rows_view, unshadowed_view) =
            (view(indirect), view(&rows[0]), view(&rows[1]));
        let tex = wgpu::BindingResource::TextureView;
        let bg = bind_group(
            d,
            &pipeline.get_bind_group_layout(0),
            "tent rows",
            vec![
                (0, uniform.as_entire_binding()),
                (3, tex(&g.views[0])),
                (4, tex(&g.views[1])),
                (12, tex(&indirect_view)),
                (16, tex(&rows_view)),
                (17, tex(&unshadowed_view)),
            ],
        );
        let span = rec.begin("tent rows");
        frame_pass(
            &mut rec.enc,
            "tent rows",
            pipeline,
            &[&bg],
            span.compute(),
            f.view.size,
        );
        rec.end();
        rows
    }
}

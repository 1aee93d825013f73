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
}

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
        }
    }
}

impl InterleaveParams {
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

/// The blur-and-compose pipelines: without [`InterleaveParams::fill`] (every mode's default),
/// and with it, made when a frame first asks for it (blur.wgsl's `BLUR_FILL`: a pipeline
/// without the fill's code runs the taps 3.5× as fast on llvmpipe).
pub struct InterleaveBlur {
    module: wgpu::ShaderModule,
    unfilled: wgpu::ComputePipeline,
    filled: OnceLock<wgpu::ComputePipeline>,
}

impl InterleaveBlur {
    /// Builds the pipeline without the fill.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<InterleaveBlur, RenderError> {
        let module = shaders::module(d, s, "blur.wgsl")?;
        let unfilled = Self::pipeline(d, &module, false);
        Ok(InterleaveBlur {
            module,
            unfilled,
            filled: OnceLock::new(),
        })
    }

    fn pipeline(
        d: &wgpu::Device,
        module: &wgpu::ShaderModule,
        fill: bool,
    ) -> wgpu::ComputePipeline {
        let label = if fill { "blur (filled)" } else { "blur" };
        let constants = [("BLUR_FILL", f64::from(u8::from(fill)))];
        compute_pipeline_with(d, label, module, "cs_compose", &constants)
    }

    /// The pipeline for a blur with or without the fill.
    fn pipeline_for(&self, d: &wgpu::Device, fill: bool) -> &wgpu::ComputePipeline {
        if !fill {
            return &self.unfilled;
        }
        self.filled
            .get_or_init(|| Self::pipeline(d, &self.module, true))
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
        let pipeline = self.pipeline_for(d, il.fill);
        let other = frame_target(f, pool, "hdr (ping-pong)");
        let tex = wgpu::BindingResource::TextureView;
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
}

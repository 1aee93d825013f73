//! The frame for a screen (display.wgsl): the last frame's linear HDR image at an exposure,
//! sRGB-encoded into an `Rgba8Unorm` texture that stays on the GPU — what a window shows
//! without reading the frame back (egui's `register_native_texture`). The arithmetic is
//! `HdrImage::to_srgb8`'s, so the texture equals the PNG `visgate render` writes.

use crate::RenderError;
use crate::gpu::GpuContext;
use crate::gpu::context::{Pool, bind_group, compute_pipelines, read_texture_bytes, row_bytes};
use crate::gpu::shaders::{self, ShaderSources};

/// The display texture's format (egui's native textures: sRGB-encoded values in Rgba8Unorm).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The tone-mapping pipeline.
pub struct Display {
    pipeline: wgpu::ComputePipeline,
}

impl Display {
    /// Builds the pipeline.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<Display, RenderError> {
        let module = shaders::module(d, s, "display.wgsl")?;
        let [pipeline] = compute_pipelines(d, &module, ["cs_display"]);
        Ok(Display { pipeline })
    }

    /// Writes `hdr` at `exposure_stops` into the pool's display texture of its size (made
    /// again only when the size changes) and submits; returns the texture.
    pub fn run(
        &self,
        ctx: &GpuContext,
        pool: &mut Pool,
        hdr: &wgpu::Texture,
        exposure_stops: f32,
    ) -> Result<wgpu::Texture, RenderError> {
        if !exposure_stops.is_finite() {
            return Err(RenderError::Param(format!(
                "exposure {exposure_stops} stops must be finite"
            )));
        }
        let d = &ctx.device;
        let size = hdr.size();
        let out = pool.texture(
            d,
            "display",
            [size.width, size.height, 1],
            1,
            DISPLAY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let scale = [2f32.powf(exposure_stops), 0.0, 0.0, 0.0];
        let uniform = pool.upload(
            ctx,
            "display",
            bytemuck::cast_slice(&scale),
            wgpu::BufferUsages::UNIFORM,
        );
        let (hdr_view, out_view) = (
            hdr.create_view(&Default::default()),
            out.create_view(&Default::default()),
        );
        let bg = bind_group(
            d,
            &self.pipeline.get_bind_group_layout(0),
            "display",
            vec![
                (0, uniform.as_entire_binding()),
                (1, wgpu::BindingResource::TextureView(&hdr_view)),
                (2, wgpu::BindingResource::TextureView(&out_view)),
            ],
        );
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("display"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("display"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(size.width.div_ceil(8), size.height.div_ceil(8), 1);
        }
        ctx.queue.submit([enc.finish()]);
        Ok(out)
    }
}

/// The display texture's pixels read back (waiting for the GPU), as 8-bit sRGB: what a window
/// shows, for screenshots and tests.
pub fn read_display(ctx: &GpuContext, tex: &wgpu::Texture) -> Result<image::RgbImage, RenderError> {
    let bytes = read_texture_bytes(ctx, tex)?;
    let row = row_bytes(tex.width(), 4) as usize;
    Ok(image::RgbImage::from_fn(
        tex.width(),
        tex.height(),
        |x, y| {
            let p = &bytes[y as usize * row + x as usize * 4..][..3];
            image::Rgb([p[0], p[1], p[2]])
        },
    ))
}

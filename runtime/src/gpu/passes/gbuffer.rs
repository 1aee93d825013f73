//! The geometry pass (gbuffer.wgsl): world position (w: the visibility cluster the surface
//! faces, from the level's voxel grid), normal turned to the camera, albedo. Also the lights'
//! reflective shadow maps are G-buffers of this pipeline ([`super::rsm_vpls`]).

use crate::RenderError;
use crate::gpu::context::{Pool, bind_group, render_pipeline};
use crate::gpu::geometry::VERTEX_STRIDE;
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, SceneGpu, shaders};

/// The G-buffer's formats: position (+ cluster), normal, albedo.
pub const FORMATS: [wgpu::TextureFormat; 3] = [
    wgpu::TextureFormat::Rgba32Float,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rgba16Float,
];

/// The G-buffer pipelines: the camera's with reversed depth (an infinite far plane, depth
/// `near / distance`, compare greater, cleared to 0: no far clipping, precision where it is
/// needed), the lights' RSM views with their standard depth.
pub struct GBuffer {
    pipeline: wgpu::RenderPipeline,
    light: wgpu::RenderPipeline,
}

/// Which depth convention a G-buffer pass uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Depth {
    /// The camera's: reversed, infinite far plane.
    Reversed,
    /// A light's view: 0 at near, 1 at far.
    Standard,
}

/// A frame's G-buffer.
pub struct GBufferOutput {
    /// Position (w: encoded cluster), normal, albedo.
    pub textures: [wgpu::Texture; 3],
    /// Their views.
    pub views: [wgpu::TextureView; 3],
}

impl GBuffer {
    /// Builds the pipeline.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<GBuffer, RenderError> {
        let module = shaders::module(d, s, "gbuffer.wgsl")?;
        let attrs = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3
        ];
        let layout = wgpu::VertexBufferLayout {
            array_stride: VERTEX_STRIDE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attrs,
        };
        let make = |label, compare| {
            render_pipeline(
                d,
                label,
                &module,
                ("vs", "fs"),
                &[Some(layout.clone())],
                &FORMATS,
                Some(compare),
            )
        };
        Ok(GBuffer {
            pipeline: make("gbuffer", wgpu::CompareFunction::Greater),
            light: make("rsm gbuffer", wgpu::CompareFunction::Less),
        })
    }

    /// A bind group of the G-buffer's inputs: `globals` (whole, or a 112-byte element at
    /// `offset`), the albedo array and sampler, the level's `grid` and voxel words.
    pub fn bind_group(
        &self,
        convention: Depth,
        d: &wgpu::Device,
        scene: &SceneGpu,
        globals: wgpu::BindingResource,
        grid: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let pipeline = match convention {
            Depth::Reversed => &self.pipeline,
            Depth::Standard => &self.light,
        };
        bind_group(
            d,
            &pipeline.get_bind_group_layout(0),
            "gbuffer",
            vec![
                (0, globals),
                (1, wgpu::BindingResource::TextureView(&scene.albedo_maps)),
                (2, wgpu::BindingResource::Sampler(&scene.albedo_sampler)),
                (8, grid.as_entire_binding()),
                (9, scene.voxel_words().as_entire_binding()),
            ],
        )
    }

    /// Records one G-buffer pass into `targets` and `depth` with the `convention`'s pipeline.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        convention: Depth,
        enc: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        targets: &[wgpu::TextureView; 3],
        depth: &wgpu::TextureView,
        bind_group: &wgpu::BindGroup,
        timestamps: Option<wgpu::RenderPassTimestampWrites>,
    ) {
        let clear = |v| {
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[clear(&targets[0]), clear(&targets[1]), clear(&targets[2])],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(match convention {
                        Depth::Reversed => 0.0,
                        Depth::Standard => 1.0,
                    }),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(match convention {
            Depth::Reversed => &self.pipeline,
            Depth::Standard => &self.light,
        });
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, scene.geometry.vertices.slice(..));
        pass.draw(0..scene.geometry.vertex_count, 0..1);
    }

    /// Records the camera's G-buffer ("geometry pass", as the gates paper's Table I names it).
    pub fn record(&self, f: &Frame, pool: &mut Pool, rec: &mut Recorder) -> GBufferOutput {
        let d = &f.ctx.device;
        let [w, h] = f.view.size;
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let labels = ["g position", "g normal", "g albedo"];
        let textures = [0, 1, 2].map(|k| pool.texture(d, labels[k], [w, h, 1], 1, FORMATS[k], rt));
        let depth = pool.texture(
            d,
            "g depth",
            [w, h, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let views = textures
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        let bg = self.bind_group(
            Depth::Reversed,
            d,
            f.scene,
            f.globals.as_entire_binding(),
            &f.grid,
        );
        let span = rec.begin("geometry pass (G-buffer)");
        self.draw(
            Depth::Reversed,
            &mut rec.enc,
            f.scene,
            &views,
            &depth.create_view(&Default::default()),
            &bg,
            span.render(true, true),
        );
        rec.end();
        GBufferOutput { textures, views }
    }
}

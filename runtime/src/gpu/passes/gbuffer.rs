//! The geometry pass (gbuffer.wgsl): world position (w: the visibility cluster the surface
//! faces, from the level's voxel grid), normal turned to the camera, albedo. Also the lights'
//! reflective shadow maps are G-buffers of this pipeline ([`super::rsm_vpls`]).

use crate::RenderError;
use crate::gpu::context::{Pool, Raster, bind_group, render_pipeline_with};
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
/// needed), and the lights' RSM views with their standard depth; each draws its front faces,
/// then its back faces pushed back ([`BACK_FACE_BIAS`]).
pub struct GBuffer {
    layout: wgpu::BindGroupLayout,
    /// The camera's front faces' and back faces' pipelines.
    camera: [wgpu::RenderPipeline; 2],
    /// The lights' front faces' and back faces' pipelines.
    light: [wgpu::RenderPipeline; 2],
}

/// The back faces' depth bias in the camera's reversed depth (negated in the lights' standard
/// depth), in units of the depth's last bit (2⁻²³ of its magnitude): −256, 3e-5 of the
/// distance, so that of two faces of one plane turned apart (a
/// floor's top and the ceiling under it) the one turned to the eye is seen, as the CPU tracer
/// sees it (`cpu::tracer::FRONT_FACE_TIE`); drawn together, rounding picked between them in
/// stripes.
pub const BACK_FACE_BIAS: i32 = -256;

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
        let layout_of_vertices = wgpu::VertexBufferLayout {
            array_stride: VERTEX_STRIDE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attrs,
        };
        let layout = bind_group_layout(d);
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let make = |label, compare, cull, bias| {
            let raster = Raster {
                layout: Some(&pipeline_layout),
                cull,
                bias: wgpu::DepthBiasState {
                    constant: bias,
                    ..Default::default()
                },
            };
            let buffers = [Some(layout_of_vertices.clone())];
            render_pipeline_with(
                d,
                label,
                &module,
                ("vs", "fs"),
                &buffers,
                &FORMATS,
                Some(compare),
                &raster,
            )
        };
        let (front, back) = (Some(wgpu::Face::Back), Some(wgpu::Face::Front));
        let (greater, less) = (wgpu::CompareFunction::Greater, wgpu::CompareFunction::Less);
        Ok(GBuffer {
            camera: [
                make("gbuffer", greater, front, 0),
                make("gbuffer back faces", greater, back, BACK_FACE_BIAS),
            ],
            // Standard depth grows away from the light: its back faces' bias is positive.
            light: [
                make("rsm gbuffer", less, front, 0),
                make("rsm gbuffer back faces", less, back, -BACK_FACE_BIAS),
            ],
            layout,
        })
    }

    /// A bind group of the G-buffer's inputs: `globals` (whole, or a 112-byte element at
    /// `offset`), the albedo array and sampler, the level's `grid` and voxel words.
    pub fn bind_group(
        &self,
        d: &wgpu::Device,
        scene: &SceneGpu,
        globals: wgpu::BindingResource,
        grid: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        bind_group(
            d,
            &self.layout,
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
        let pipelines = match convention {
            Depth::Reversed => &self.camera,
            Depth::Standard => &self.light,
        };
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, scene.geometry.vertices.slice(..));
        for pipeline in pipelines {
            pass.set_pipeline(pipeline);
            pass.draw(0..scene.geometry.vertex_count, 0..1);
        }
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
        let bg = self.bind_group(d, f.scene, f.globals.as_entire_binding(), &f.grid);
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

/// The G-buffer's inputs (gbuffer.wgsl): globals, the albedo array and its sampler, the level's
/// grid and voxel words; one layout for its three pipelines.
fn bind_group_layout(d: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding, visibility, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    };
    let uniform = wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    let fragment = wgpu::ShaderStages::FRAGMENT;
    d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gbuffer"),
        entries: &[
            entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, uniform),
            entry(
                1,
                fragment,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
            ),
            entry(
                2,
                fragment,
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            ),
            entry(8, fragment, uniform),
            entry(
                9,
                fragment,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            ),
        ],
    })
}

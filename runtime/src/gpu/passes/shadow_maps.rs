//! The lights' shadow maps (shadow.wgsl): a 2D array of R32Float distance layers, 6 per point
//! light (cube faces ±X, ±Y, ±Z, 90° each) and 1 per spot (its cutoff cone), `size`² each,
//! one render pass per layer. The shading pass looks them up with a normal offset and a bias in
//! texels of the layer at that distance, filtered 3 × 3 (PCF).

use glam::Vec3;
use visgate_formats::Light as SceneLight;

use crate::RenderError;
use crate::camera::{look_to, perspective};
use crate::gpu::context::{Pool, bind_group, layer_view, render_pipeline, slice};
use crate::gpu::geometry::{VERTEX_STRIDE, positions};
use crate::gpu::layout::{Light, ShadowView, UNIFORM_STRIDE, strided};
use crate::gpu::shaders::ShaderSources;
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, SceneGpu, shaders};

/// The widest spot cutoff one shadow layer's frustum spans; wider spots get a cube of six.
/// [Units: rad]
pub const MAX_SPOT_FRUSTUM_RAD: f32 = 1.5;

/// The shadow-map pipeline.
pub struct ShadowMaps {
    pipeline: wgpu::RenderPipeline,
}

/// The six 90° cube faces (axis, up) of a point light's (or a wide spot's) shadow layers.
const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// The scene's lights as the GPU sees them and each shadow layer's view, from the scene's near
/// plane to [`SceneGpu::light_far_m`]. A spot whose cutoff is wider than one frustum can span
/// ([`MAX_SPOT_FRUSTUM_RAD`]) gets the six cube faces of a point light (its falloff still
/// applies), so no cutoff a scene file accepts is clamped. A light outside the scene's bounds
/// has its near plane moved out to half its distance from them: the depth test's precision
/// falls with distance over the near plane (a sun's spot 90 m away on a near plane of 1 mm told
/// surfaces apart only half a metre apart, and a wall's shadow leaked along its foot).
pub fn light_views(scene: &SceneGpu) -> (Vec<Light>, Vec<ShadowView>) {
    let mut gpu = Vec::new();
    let mut views = Vec::new();
    let far = scene.light_far_m();
    let near_of = |p: Vec3| {
        let outside = visgate_formats::placement::outside_by(p, scene.bounds);
        scene.near_m.max(0.5 * outside)
    };
    let cube = |position: Vec3, views: &mut Vec<ShadowView>| {
        let near = near_of(position);
        for (f, up) in CUBE_FACES {
            let vp = perspective(1.0, 1.0, near, far) * look_to(Vec3::ZERO, f, up);
            views.push(ShadowView {
                view_proj: vp.to_cols_array_2d(),
                light: position.extend(1.0).to_array(),
            });
        }
    };
    for l in &scene.lights {
        let first = views.len() as u32;
        match *l {
            SceneLight::Point {
                position,
                intensity,
            } => {
                cube(position, &mut views);
                gpu.push(Light {
                    position: position.extend(0.0).to_array(),
                    intensity: intensity.extend(0.0).to_array(),
                    direction: [0.0, -1.0, 0.0, 0.0],
                    layers: [first, 6, 0, 0],
                });
            }
            SceneLight::Spot {
                position,
                direction,
                intensity,
                cutoff_rad,
                beam_rad,
            } => {
                if cutoff_rad > MAX_SPOT_FRUSTUM_RAD {
                    cube(position, &mut views);
                } else {
                    let up = if direction.y.abs() > 0.9 {
                        Vec3::Z
                    } else {
                        Vec3::Y
                    };
                    let t = cutoff_rad.tan();
                    let vp = perspective(t, t, near_of(position), far)
                        * look_to(Vec3::ZERO, direction, up);
                    views.push(ShadowView {
                        view_proj: vp.to_cols_array_2d(),
                        light: position.extend(1.0).to_array(),
                    });
                }
                gpu.push(Light {
                    position: position.extend(1.0).to_array(),
                    intensity: intensity.extend(beam_rad).to_array(),
                    direction: direction.extend(cutoff_rad).to_array(),
                    layers: [first, views.len() as u32 - first, 0, 0],
                });
            }
        }
    }
    (gpu, views)
}

/// One layer of a distance map (shadow or paraboloid): clears `color` to "far" and `depth`,
/// then draws `vertices` with `pipeline` and `bind_group`, instances `instances`.
pub struct DistancePass<'a> {
    /// The layer.
    pub color: &'a wgpu::TextureView,
    /// The shared depth buffer.
    pub depth: &'a wgpu::TextureView,
    /// The pipeline.
    pub pipeline: &'a wgpu::RenderPipeline,
    /// Its bind group.
    pub bind_group: &'a wgpu::BindGroup,
    /// Positions (at `VERTEX_STRIDE` or 12 bytes, as the pipeline reads them).
    pub vertices: &'a wgpu::Buffer,
    /// Vertices to draw.
    pub count: u32,
    /// Instances to draw (the VPL or VAL of a paraboloid map).
    pub instances: std::ops::Range<u32>,
}

impl DistancePass<'_> {
    /// Records the pass.
    pub fn record(
        &self,
        enc: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::RenderPassTimestampWrites>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("distance map layer"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: self.color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 1e30,
                        g: 0.0,
                        b: 0.0,
                        a: 0.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: self.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.pipeline);
        pass.set_bind_group(0, self.bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.draw(0..self.count, self.instances.clone());
    }
}

/// What the shadow maps leave for the shading pass.
pub struct ShadowOutput {
    /// Every layer, as one array.
    pub maps: wgpu::Texture,
    /// The lights.
    pub lights: wgpu::Buffer,
    /// Each layer's view-projection.
    pub matrices: wgpu::Buffer,
}

impl ShadowMaps {
    /// Builds the pipeline.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<ShadowMaps, RenderError> {
        let module = shaders::module(d, s, "shadow.wgsl")?;
        let pipeline = render_pipeline(
            d,
            "shadow",
            &module,
            ("vs", "fs"),
            &[Some(positions(VERTEX_STRIDE))],
            &[wgpu::TextureFormat::R32Float],
            Some(wgpu::CompareFunction::Less),
        );
        Ok(ShadowMaps { pipeline })
    }

    /// Records every light's layers; with `draw` false (LightCluster shadows the direct light)
    /// only uploads the lights, beside a 1-texel stand-in for the maps.
    pub fn record(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        draw: bool,
    ) -> Result<ShadowOutput, RenderError> {
        let d = &f.ctx.device;
        let (lights, mut views) = light_views(f.scene);
        if !draw {
            views.clear();
        }
        let layers = views.len().max(1) as u32;
        if layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "{layers} shadow layers ({} lights) exceed the adapter's {}: use fewer lights",
                lights.len(),
                d.limits().max_texture_array_layers
            )));
        }
        let s = if draw { f.params.shadows.size } else { 1 };
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let maps = pool.texture(
            d,
            "shadow maps",
            [s, s, layers],
            1,
            wgpu::TextureFormat::R32Float,
            rt,
        );
        let depth = pool.texture(
            d,
            "shadow depth",
            [s, s, 1],
            1,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let uniform = wgpu::BufferUsages::UNIFORM;
        let storage = wgpu::BufferUsages::STORAGE;
        let view_buf = pool.upload(f.ctx, "shadow views", &strided(&views), uniform);
        let mats: Vec<[[f32; 4]; 4]> = views.iter().map(|v| v.view_proj).collect();
        let out = ShadowOutput {
            maps: maps.clone(),
            lights: pool.upload(f.ctx, "lights", bytemuck::cast_slice(&lights), storage),
            matrices: pool.upload(
                f.ctx,
                "shadow matrices",
                bytemuck::cast_slice(&mats),
                storage,
            ),
        };
        if views.is_empty() {
            return Ok(out);
        }
        let depth_view = depth.create_view(&Default::default());
        let span = rec.begin("shadow maps");
        let layout = self.pipeline.get_bind_group_layout(0);
        for i in 0..views.len() {
            let size = std::mem::size_of::<ShadowView>() as u64;
            let bg = bind_group(
                d,
                &layout,
                "shadow view",
                vec![(0, slice(&view_buf, (i * UNIFORM_STRIDE) as u64, size))],
            );
            let color = layer_view(&maps, i as u32);
            DistancePass {
                color: &color,
                depth: &depth_view,
                pipeline: &self.pipeline,
                bind_group: &bg,
                vertices: &f.scene.geometry.vertices,
                count: f.scene.geometry.vertex_count,
                instances: 0..1,
            }
            .record(&mut rec.enc, span.render(i == 0, i + 1 == views.len()));
        }
        rec.end();
        Ok(out)
    }
}

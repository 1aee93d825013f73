//! The wgpu renderer: G-buffer → shadow maps → deferred direct light with PCF and the VPL
//! gather → a linear HDR texture, read back as an [`HdrImage`]. One [`GpuRenderer::render`] for
//! any offscreen target size.
//!
//! Shadow maps: a 2D array of R32Float distance layers, 6 per point light (cube faces ±X, ±Y,
//! ±Z, 90° each) and 1 per spot (its cutoff cone), `shadow_size`² each; lookups offset the
//! point along its normal and compare with a bias, both in texels of the layer at that
//! distance, and filter 3 × 3 (PCF).
//!
//! Modes ([`GpuMode`]): `None` (every VPL lights every pixel), `PerVplShadowMaps` (a paraboloid
//! distance map per VPL, rendered and gathered in batches of `vpl_batch` so memory stays
//! bounded), `Gates` (clustered shading through a baked level's gates, `gpu_clustered.rs`),
//! `GatesPerPixel` (the same test brute force), `ValHard` / `ValCssm` (virtual area lights with
//! hard or convolution soft shadow maps, `gpu_vals.rs`) and `DirectOnly`. VPLs from reflective
//! shadow maps ([`GpuRenderer::rsm_vpls`]); GPU time per stage from timestamp queries.

use std::time::Instant;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use visgate_formats::{Light, Scene};
use wgpu::util::DeviceExt;

use crate::RenderError;
use crate::camera::{View, look_to, perspective};
use crate::hdr::HdrImage;
use crate::vpl::Vpl;

#[path = "gpu_clustered.rs"]
mod clustered;
#[path = "gpu_vals.rs"]
mod vals;
pub use clustered::{ClusterFrame, GpuGeometryCluster, LightListStats, MAX_CLUSTERS, MAX_GATES};
pub use vals::{CssmFrame, ValFrame, ValGather, ValMaps, centres_of};

// WGSL has no includes: the VPL struct and gather term, the fullscreen triangle, and the grid
// and gate code are put in front of the shaders that use them.
const GBUFFER_WGSL: &str = concat!(
    include_str!("shaders/grid.wgsl"),
    include_str!("shaders/gbuffer.wgsl")
);
const SHADOW_WGSL: &str = include_str!("shaders/shadow.wgsl");
const SHADE_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/grid.wgsl"),
    include_str!("shaders/gates.wgsl"),
    include_str!("shaders/fullscreen.wgsl"),
    include_str!("shaders/shade.wgsl")
);
const CLUSTERS_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/grid.wgsl"),
    include_str!("shaders/gates.wgsl"),
    include_str!("shaders/clusters.wgsl")
);
const VALS_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/val.wgsl"),
    include_str!("shaders/vals.wgsl")
);
const VAL_GATHER_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/val.wgsl"),
    include_str!("shaders/fullscreen.wgsl"),
    include_str!("shaders/val_gather.wgsl")
);
const CSSM_WGSL: &str = include_str!("shaders/cssm.wgsl");
const VPL_SHADOW_WGSL: &str = concat!(
    include_str!("shaders/val.wgsl"),
    include_str!("shaders/vpl_shadow.wgsl")
);
const GATHER_BATCH_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/val.wgsl"),
    include_str!("shaders/fullscreen.wgsl"),
    include_str!("shaders/gather_batch.wgsl")
);
const RSM_VPLS_WGSL: &str = concat!(
    include_str!("shaders/vpl.wgsl"),
    include_str!("shaders/rsm_vpls.wgsl")
);

/// The WGSL sources (with what is put in front of them), for validation without a GPU.
pub const SHADERS: [(&str, &str); 10] = [
    ("gbuffer.wgsl", GBUFFER_WGSL),
    ("shadow.wgsl", SHADOW_WGSL),
    ("shade.wgsl", SHADE_WGSL),
    ("vpl_shadow.wgsl", VPL_SHADOW_WGSL),
    ("gather_batch.wgsl", GATHER_BATCH_WGSL),
    ("rsm_vpls.wgsl", RSM_VPLS_WGSL),
    ("clusters.wgsl", CLUSTERS_WGSL),
    ("vals.wgsl", VALS_WGSL),
    ("val_gather.wgsl", VAL_GATHER_WGSL),
    ("cssm.wgsl", CSSM_WGSL),
];

/// One RSM sample for the VPL compute pass, shared with WGSL (`Sample` in rsm_vpls.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RsmSample {
    /// x layer, y texel x, z texel y.
    pub texel: [u32; 4],
    /// rgb power (W): intensity towards the sample × its solid angle.
    pub power: [f32; 4],
}

/// Triangles drawn into paraboloid maps are split until no edge is longer than this fraction
/// of the scene's diagonal: the projection bends lines, and short edges bend little.
pub const VPL_SHADOW_MAX_EDGE: f32 = 1.0 / 24.0;

/// One VPL's paraboloid view, shared with WGSL (`VplView` in vpl_shadow.wgsl). 64 bytes, at
/// 256-byte strides.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct VplView {
    /// xyz position (m), w far distance (m).
    pub position: [f32; 4],
    /// Tangent of the VPL's frame.
    pub tangent: [f32; 4],
    /// Bitangent of the VPL's frame.
    pub bitangent: [f32; 4],
    /// The VPL's normal.
    pub normal: [f32; 4],
}

/// A batch of VPLs for the gather, shared with WGSL (`Batch` in gather_batch.wgsl). 32 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Batch {
    /// x first VPL, y count, z map size (texels).
    pub range: [u32; 4],
    /// x g_max (1/m²), y normal offset (texels), z bias (texels).
    pub params: [f32; 4],
}

/// Per-frame constants, shared with WGSL (`Globals` in every shader). 112 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Globals {
    /// Camera view-projection, column-major. Written by [`GpuRenderer::render`].
    pub view_proj: [[f32; 4]; 4],
    /// Eye position (xyz, m), w unused.
    pub eye: [f32; 4],
    /// x: geometry-term clamp (1/m²), y: shadow normal offset (texels), z: shadow bias
    /// (texels), w unused.
    pub params: [f32; 4],
    /// x: VPL count, y: light count, z: mode (0 none, 1 direct light only, 2 gates per
    /// pixel, 3 gates by clustered light lists), w: shadow map size.
    pub counts: [u32; 4],
}

/// The level's grid for the gate test, shared with WGSL (`Grid` in shade.wgsl). 48 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GridUniform {
    /// xyz origin (m), w voxel size (m).
    pub origin: [f32; 4],
    /// xyz dims, w bytes per stored value.
    pub dims: [u32; 4],
    /// x disk oversize, y max hops.
    pub params: [f32; 4],
}

/// A light, shared with WGSL (`Light` in shade.wgsl). 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// xyz position (m), w kind (0 point, 1 spot).
    pub position: [f32; 4],
    /// rgb intensity (W/sr), w beam half-angle (rad).
    pub intensity: [f32; 4],
    /// xyz unit axis, w cutoff half-angle (rad).
    pub direction: [f32; 4],
    /// x first shadow layer, y layer count.
    pub layers: [u32; 4],
}

/// One shadow layer's view, shared with WGSL (`ShadowView` in shadow.wgsl). 80 bytes, placed
/// at 256-byte strides.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ShadowView {
    /// The layer's view-projection.
    pub view_proj: [[f32; 4]; 4],
    /// xyz light position (m).
    pub light: [f32; 4],
}

/// Indirect-light visibility on the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GpuMode {
    /// Every VPL lights every pixel.
    None,
    /// One paraboloid shadow map per VPL, rendered in batches (the brute-force baseline).
    PerVplShadowMaps,
    /// Direct light only.
    DirectOnly,
    /// VPL light through the gates of the level set with [`GpuRenderer::set_level`], the
    /// paper's clustered shading: geometry clusters (tiles × depth slices × visibility
    /// cluster), light lists of (VPL, gate chain) assigned by cones through the gates, the
    /// gather over each pixel's list with the chain tested per fragment. At most 2 hops.
    Gates,
    /// The same gate test, brute force: every fragment tests every VPL (for comparison).
    GatesPerPixel,
    /// Every VPL lights every pixel with the visibility of its virtual area light: VPLs
    /// clustered into VALs on the GPU, one hard paraboloid shadow map per VAL (the banding
    /// baseline of Dong et al.).
    ValHard,
    /// As `ValHard`, with convolution soft shadow maps per VAL (Dong et al.): the paper's
    /// method.
    ValCssm,
}

/// Rendering parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuParams {
    /// Visibility mode.
    pub mode: GpuMode,
    /// Geometry-term clamp. [Units: 1/m²] [Limit: > 0]
    pub g_max: f32,
    /// Shadow map layer size. [Units: texels] [Limit: 16..=4096]
    pub shadow_size: u32,
    /// Normal offset of shadow lookups. [Units: texels]
    pub shadow_normal_offset: f32,
    /// Depth bias of shadow lookups. [Units: texels]
    pub shadow_bias: f32,
    /// Per-VPL paraboloid map size. [Units: texels] [Limit: 16..=2048]
    pub vpl_map_size: u32,
    /// VPL maps rendered and gathered per batch (bounds their memory). [Limit: 1..=2048]
    pub vpl_batch: u32,
    /// How light passes gates in modes `Gates` and `GatesPerPixel` (`max_hops` 1 or 2 on the
    /// GPU).
    pub gates: crate::gates::GateParams,
    /// Geometry clusters of mode `Gates` (`tile_px` 1..=16 on the GPU).
    pub clusters: crate::clustered::ClusterParams,
    /// Capacity of the light-list pool of mode `Gates`, in (VPL, gates) entries of 8 bytes; a
    /// frame that needs more fails with the count it needs. [Limit: 1..=storage limit / 8]
    pub light_entries: u32,
    /// Virtual area lights of mode `ValHard`.
    pub vals: crate::val::ValParams,
    /// Paraboloid map size per VAL. [Units: texels] [Limit: 16..=4096]
    pub val_map_size: u32,
    /// Fourier terms K of the CSSM (mode `ValCssm`). [Limit: 1..=16]
    pub cssm_terms: u32,
    /// Sharpening of the CSSM reconstruction ([`crate::cssm::visibility`]). [Limit: 1..=8]
    pub cssm_sharpness: f32,
    /// Normal offset of CSSM lookups (slope-scaled up to 2×): larger avoids self-shadowing
    /// under wide kernels, smaller keeps contact shadows. [Units: texels] [Limit: 0..=64]
    pub cssm_normal_offset: f32,
    /// VAL modes: interleaved sampling in blocks of this side (a pixel lights itself with one
    /// of side² VPL subsets; 1: every VPL at every pixel), then the geometry-aware blur over
    /// the block. [Units: px] [Limit: 1..=16]
    pub interleave: u32,
    /// Blur: neighbours farther than this fraction of the scene's size are left out (Laine et
    /// al.: 0.1). [Limit: ≥ 0]
    pub blur_distance: f32,
    /// Blur: neighbours whose normal's cosine to the pixel's is below this are left out (Laine
    /// et al.: 0.8). [Limit: −1..=1]
    pub blur_normal: f32,
}

impl Default for GpuParams {
    fn default() -> Self {
        GpuParams {
            mode: GpuMode::None,
            g_max: 10.0,
            shadow_size: 1024,
            shadow_normal_offset: 1.5,
            shadow_bias: 1.0,
            vpl_map_size: 128,
            vpl_batch: 128,
            gates: crate::gates::GateParams::default(),
            clusters: crate::clustered::ClusterParams::default(),
            light_entries: 1 << 23,
            vals: crate::val::ValParams::default(),
            val_map_size: 256,
            cssm_terms: crate::cssm::DEFAULT_TERMS,
            cssm_sharpness: crate::cssm::DEFAULT_SHARPNESS,
            cssm_normal_offset: 3.0,
            interleave: 8,
            blur_distance: 0.1,
            blur_normal: 0.8,
        }
    }
}

/// Wall times of the passes (CPU side, each pass submitted and waited for). [Units: s]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PassTimes {
    /// Shadow maps.
    pub shadows: f64,
    /// G-buffer.
    pub gbuffer: f64,
    /// Direct and indirect shading (direct only with per-VPL shadow maps); with gates the
    /// indirect lighting, the gather over the light lists.
    pub shade: f64,
    /// Mode gates: finding the geometry clusters in view and their boxes.
    pub unique_clusters: f64,
    /// Mode gates: VPL clusters and the light lists.
    pub light_assignment: f64,
    /// VAL modes: clustering the VPLs into VALs.
    pub val_clustering: f64,
    /// Mode val-cssm: depth ranges, Fourier basis and mips.
    pub cssm: f64,
    /// VAL modes: the geometry-aware blur and compose.
    pub blur: f64,
    /// Per-VPL paraboloid maps, all batches.
    pub vpl_maps: f64,
    /// Indirect gather with per-VPL maps, all batches.
    pub vpl_gather: f64,
    /// Copy back to the CPU.
    pub readback: f64,
    /// GPU time of each stage from timestamp queries, where the adapter has them.
    pub gpu: Option<GpuStageTimes>,
    /// Mode gates: how full the light lists came out.
    pub lists: Option<LightListStats>,
}

/// GPU time of each stage, from timestamp queries (summed over a stage's passes). [Units: s]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GpuStageTimes {
    /// Shadow maps.
    pub shadows: f64,
    /// G-buffer.
    pub gbuffer: f64,
    /// Shading.
    pub shade: f64,
    /// Per-VPL paraboloid maps.
    pub vpl_maps: f64,
    /// Gather with per-VPL maps.
    pub vpl_gather: f64,
    /// Unique clusters (mode gates).
    pub unique_clusters: f64,
    /// Light assignment (mode gates).
    pub light_assignment: f64,
    /// VAL clustering (VAL modes).
    pub val_clustering: f64,
    /// CSSM basis and mips (mode val-cssm).
    pub cssm: f64,
    /// Blur and compose (VAL modes).
    pub blur: f64,
}

/// Stages a [`Timer`] tells apart, in [`GpuStageTimes`] order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    Shadows,
    GBuffer,
    Shade,
    VplMaps,
    VplGather,
    UniqueClusters,
    LightAssignment,
    ValClustering,
    Cssm,
    Blur,
}

/// Timestamp queries around stages: each span is the beginning of a stage's first pass and
/// the end of its last. Inactive (all `None`) where the adapter has no timestamps.
struct Timer {
    set: Option<wgpu::QuerySet>,
    used: u32,
    spans: Vec<(Stage, u32)>,
}

impl Timer {
    fn new(ctx: &GpuContext, spans: u32) -> Timer {
        let set = ctx.timestamp_period.map(|_| {
            ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: (2 * spans).clamp(2, 4096),
            })
        });
        Timer {
            set,
            used: 0,
            spans: Vec::new(),
        }
    }

    /// Reserves a span for `stage`; `None` when inactive or full.
    fn span(&mut self, stage: Stage) -> Option<u32> {
        let set = self.set.as_ref()?;
        if self.used + 2 > set.count() {
            return None;
        }
        let b = self.used;
        self.used += 2;
        self.spans.push((stage, b));
        Some(b)
    }

    /// The writes of a pass that is the `first` and/or `last` of span `b`.
    fn writes(
        &self,
        b: Option<u32>,
        first: bool,
        last: bool,
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let (set, b) = (self.set.as_ref()?, b?);
        if !first && !last {
            return None;
        }
        Some(wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: first.then_some(b),
            end_of_pass_write_index: last.then_some(b + 1),
        })
    }

    /// The writes of a compute pass that is all of span `b`.
    fn compute_writes(&self, b: Option<u32>) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let (set, b) = (self.set.as_ref()?, b?);
        Some(wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(b),
            end_of_pass_write_index: Some(b + 1),
        })
    }

    /// Resolves, reads back and sums the spans per stage.
    fn read(&self, ctx: &GpuContext) -> Option<GpuStageTimes> {
        let (set, period) = (self.set.as_ref()?, ctx.timestamp_period?);
        if self.used == 0 {
            return Some(GpuStageTimes::default());
        }
        let d = &ctx.device;
        let bytes = self.used as u64 * 8;
        let resolve = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps readback"),
            size: bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("timestamps"),
        });
        enc.resolve_query_set(set, 0..self.used, &resolve, 0);
        enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, bytes);
        ctx.queue.submit([enc.finish()]);
        let slice = read.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        ctx.wait();
        let ticks: Vec<u64> = bytemuck::cast_slice(&slice.get_mapped_range().ok()?).to_vec();
        read.unmap();
        let mut t = [0f64; 10];
        for &(stage, b) in &self.spans {
            let (a, z) = (ticks[b as usize], ticks[b as usize + 1]);
            t[stage as usize] += z.saturating_sub(a) as f64 * period as f64 * 1e-9;
        }
        Some(GpuStageTimes {
            shadows: t[0],
            gbuffer: t[1],
            shade: t[2],
            vpl_maps: t[3],
            vpl_gather: t[4],
            unique_clusters: t[5],
            light_assignment: t[6],
            val_clustering: t[7],
            cssm: t[8],
            blur: t[9],
        })
    }
}

/// A device and queue.
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says it is.
    pub adapter_info: wgpu::AdapterInfo,
    /// Nanoseconds per timestamp tick, where the adapter has timestamp queries.
    pub timestamp_period: Option<f32>,
}

impl GpuContext {
    /// Opens the first adapter wgpu finds (backends from `WGPU_BACKEND`, else all that are
    /// built in); an error that says what to install when there is none.
    pub fn new() -> Result<GpuContext, RenderError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| {
            RenderError::NoAdapter(format!(
                "{e}. Install a Vulkan driver (on Debian/Ubuntu without a GPU: apt-get install \
                 mesa-vulkan-drivers for the software driver, lavapipe), or Metal/DX12 on macOS/Windows"
            ))
        })?;
        let adapter_info = adapter.get_info();
        let limits = wgpu::Limits {
            max_texture_array_layers: adapter.limits().max_texture_array_layers,
            max_storage_buffer_binding_size: adapter.limits().max_storage_buffer_binding_size,
            max_storage_buffers_per_shader_stage: adapter
                .limits()
                .max_storage_buffers_per_shader_stage
                .min(16),
            ..wgpu::Limits::downlevel_defaults()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("visgate device"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoAdapter(format!("cannot open {}: {e}", adapter_info.name)))?;
        let timestamp_period = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| queue.get_timestamp_period());
        Ok(GpuContext {
            device,
            queue,
            adapter_info,
            timestamp_period,
        })
    }

    fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// The compute pipelines of `source`'s entry points `entries`, in order (auto layouts).
fn compute_pipelines<const N: usize>(
    d: &wgpu::Device,
    label: &str,
    source: &str,
    entries: [&str; N],
) -> [wgpu::ComputePipeline; N] {
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    entries.map(|entry| {
        d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    })
}

/// A bind group for `layout` from (binding, resource) pairs.
fn bind_group(
    d: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    resources: Vec<(u32, wgpu::BindingResource)>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
        .collect();
    d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A storage buffer holding `bytes` (64 zero bytes when empty: bindings cannot be empty).
fn storage(d: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let mut v = bytes.to_vec();
    if v.is_empty() {
        v.resize(64, 0);
    }
    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &v,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// Copies `buf` (made with COPY_SRC) back to the CPU.
fn read_buffer(ctx: &GpuContext, buf: &wgpu::Buffer) -> Result<Vec<u8>, RenderError> {
    let d = &ctx.device;
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: buf.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    enc.copy_buffer_to_buffer(buf, 0, &read, 0, buf.size());
    ctx.queue.submit([enc.finish()]);
    let slice = read.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    ctx.wait();
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| RenderError::Gpu(format!("cannot read a buffer back: {e}")))?
        .to_vec();
    read.unmap();
    Ok(bytes)
}

/// Copies a 2D texture of 4 channels (Rgba32Float, or Rgba16Float widened) back to the CPU,
/// row by row.
fn read_texture(ctx: &GpuContext, tex: &wgpu::Texture) -> Result<Vec<[f32; 4]>, RenderError> {
    let d = &ctx.device;
    let (w, h) = (tex.width(), tex.height());
    let half = tex.format() == wgpu::TextureFormat::Rgba16Float;
    let texel = if half { 8u64 } else { 16 };
    let row = (w as u64 * texel).div_ceil(256) * 256;
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture readback"),
        size: row * h as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("texture readback"),
    });
    enc.copy_texture_to_buffer(
        tex.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &read,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row as u32),
                rows_per_image: Some(h),
            },
        },
        tex.size(),
    );
    ctx.queue.submit([enc.finish()]);
    let slice = read.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    ctx.wait();
    let mut out = Vec::with_capacity((w * h) as usize);
    {
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Gpu(format!("cannot read an image back: {e}")))?;
        for y in 0..h as u64 {
            let r = &bytes[(y * row) as usize..][..(w as u64 * texel) as usize];
            if half {
                let v: &[u16] = bytemuck::cast_slice(r);
                out.extend(
                    v.chunks_exact(4)
                        .map(|c| [0, 1, 2, 3].map(|k| half::f16::from_bits(c[k]).to_f32())),
                );
            } else {
                let v: &[f32] = bytemuck::cast_slice(r);
                out.extend(v.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
            }
        }
    }
    read.unmap();
    Ok(out)
}

/// The buffers every pass of a frame reads.
struct FrameInputs {
    globals: wgpu::Buffer,
    grid: wgpu::Buffer,
    vpls: wgpu::Buffer,
}

/// A 2D (array) texture of `size` = [width, height, layers].
fn texture(
    d: &wgpu::Device,
    label: &str,
    size: [u32; 3],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    d.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: size[2],
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// One layer of a distance map (shadow or paraboloid): clears `color` to "far" and the shared
/// `depth`, then draws `vertices` with `pipeline` and its view in `bind_group`.
#[allow(clippy::too_many_arguments)]
fn distance_pass(
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    vertices: &wgpu::Buffer,
    count: u32,
    instances: std::ops::Range<u32>,
    timestamps: Option<wgpu::RenderPassTimestampWrites>,
) {
    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
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
            view: depth,
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
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[]);
    pass.set_vertex_buffer(0, vertices.slice(..));
    pass.draw(0..count, instances);
}

/// A fullscreen triangle into `target` (cleared to black) with `pipeline` and `bind_group`,
/// submitted and waited for.
fn fullscreen_pass(
    ctx: &GpuContext,
    label: &str,
    target: &wgpu::TextureView,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    timestamps: Option<wgpu::RenderPassTimestampWrites>,
) {
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
    ctx.queue.submit([enc.finish()]);
    ctx.wait();
}

/// The scene's textures as layers of one sRGB array (resized, nearest, to the largest size up to
/// [`MAX_TEXTURE_SIZE`]; one white texel when there are none), and a nearest, repeating sampler.
fn albedo_array(ctx: &GpuContext, scene: &Scene) -> (wgpu::TextureView, wgpu::Sampler) {
    let d = &ctx.device;
    let size = scene
        .textures
        .iter()
        .map(|t| t.width.max(t.height))
        .max()
        .unwrap_or(1)
        .clamp(1, MAX_TEXTURE_SIZE.min(d.limits().max_texture_dimension_2d));
    let layers = (scene.textures.len() as u32).clamp(1, d.limits().max_texture_array_layers);
    let mut bytes = vec![255u8; (size * size * 4 * layers) as usize];
    for (k, t) in scene.textures.iter().take(layers as usize).enumerate() {
        let layer = &mut bytes[k * (size * size * 4) as usize..][..(size * size * 4) as usize];
        if t.width == 0 || t.height == 0 || t.rgba8.len() < (t.width * t.height * 4) as usize {
            continue;
        }
        for y in 0..size {
            for x in 0..size {
                let (sx, sy) = (x * t.width / size, y * t.height / size);
                let s = ((sy * t.width + sx) * 4) as usize;
                let o = ((y * size + x) * 4) as usize;
                layer[o..o + 4].copy_from_slice(&t.rgba8[s..s + 4]);
            }
        }
    }
    let tex = d.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("albedo textures"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &bytes,
    );
    let view = tex.create_view(&wgpu::TextureViewDescriptor {
        label: Some("albedo textures"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("albedo (nearest, repeat)"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Nearest,
        min_filter: wgpu::FilterMode::Nearest,
        ..Default::default()
    });
    (view, sampler)
}

/// The scene on the GPU and the pipelines.
pub struct GpuRenderer {
    vertices: wgpu::Buffer,
    vertex_count: u32,
    lights: Vec<Light>,
    near_m: f32,
    far_m: f32,
    gbuffer: wgpu::RenderPipeline,
    shadow: wgpu::RenderPipeline,
    shade: wgpu::RenderPipeline,
    vpl_vertices: wgpu::Buffer,
    vpl_vertex_count: u32,
    vpl_shadow: wgpu::RenderPipeline,
    gather_batch: wgpu::RenderPipeline,
    rsm_vpls: wgpu::ComputePipeline,
    albedo_maps: wgpu::TextureView,
    albedo_sampler: wgpu::Sampler,
    /// The level's gate tables: grid (origin, dims), voxel words, gates, cluster gates.
    level: Option<LevelBuffers>,
    /// Bound where a mode has no level or no light lists.
    no_level: wgpu::Buffer,
    cluster_pipelines: clustered::Pipelines,
    val_pipelines: vals::Pipelines,
    val_shadow: wgpu::RenderPipeline,
    cssm_pipelines: vals::CssmPipelines,
    /// Last frame's VAL centres (count, buffer), for a warm start.
    val_centres: std::sync::Mutex<Option<(u32, wgpu::Buffer)>>,
}

/// A level's gate tables on the GPU.
struct LevelBuffers {
    origin: [f32; 4],
    dims: [u32; 4],
    voxel_words: wgpu::Buffer,
    gates: wgpu::Buffer,
    cluster_gates: wgpu::Buffer,
}

/// Splits triangles until no edge is longer than `max_edge` (longest edge halved first).
fn subdivide(tris: &[[Vec3; 3]], max_edge: f32) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    let mut stack: Vec<([Vec3; 3], u32)> = tris.iter().map(|&t| (t, 0)).collect();
    while let Some((t, depth)) = stack.pop() {
        let l = [0, 1, 2].map(|k| (t[(k + 1) % 3] - t[k]).length());
        let k = (0..3).max_by(|&a, &b| l[a].total_cmp(&l[b])).unwrap_or(0);
        if l[k] <= max_edge || depth >= 24 {
            out.push(t);
            continue;
        }
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let m = (a + b) * 0.5;
        stack.push(([a, m, c], depth + 1));
        stack.push(([m, b, c], depth + 1));
    }
    out
}

/// Vertex layout: position, normal, albedo, (u, v, texture layer or −1) — f32 × 3 each.
const VERTEX_STRIDE: u64 = 48;
/// Floats per vertex.
const VERTEX_FLOATS: usize = 12;
/// Textures are resized (nearest) to one layer size, at most this. [Units: texels]
pub const MAX_TEXTURE_SIZE: u32 = 1024;

/// A scene's triangles on the GPU: for the G-buffer and shadow maps (position, normal,
/// albedo, texture coordinates), and subdivided for paraboloid maps.
struct Geometry {
    vertices: wgpu::Buffer,
    vertex_count: u32,
    vpl_vertices: wgpu::Buffer,
    vpl_vertex_count: u32,
    /// The scene's diagonal. [Units: m]
    size: f32,
}

impl Geometry {
    fn upload(d: &wgpu::Device, scene: &Scene) -> Geometry {
        let mut data: Vec<f32> = Vec::new();
        for m in &scene.meshes {
            for (t, idx) in m.triangles.iter().enumerate() {
                let mat = m
                    .material
                    .get(t)
                    .and_then(|&k| scene.materials.get(k as usize));
                let albedo = mat.map(|mat| mat.albedo).unwrap_or(Vec3::splat(0.5));
                let layer = mat
                    .and_then(|mat| mat.texture)
                    .filter(|&k| (k as usize) < scene.textures.len())
                    .map(|k| k as f32)
                    .unwrap_or(-1.0);
                let p = idx.map(|i| m.positions[i as usize]);
                if (p[1] - p[0]).cross(p[2] - p[0]).length_squared() <= 0.0 {
                    continue;
                }
                for (k, &i) in idx.iter().enumerate() {
                    let n = m.normals.get(i as usize).copied().unwrap_or(Vec3::Y);
                    data.extend_from_slice(&p[k].to_array());
                    data.extend_from_slice(&n.to_array());
                    data.extend_from_slice(&albedo.to_array());
                    let uv = m.uvs.get(i as usize).copied().unwrap_or_default();
                    data.extend_from_slice(&[uv.x, uv.y, layer]);
                }
            }
        }
        let vertex_count = (data.len() / VERTEX_FLOATS) as u32;
        let size = scene
            .bounds()
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(1.0)
            .max(1e-6);
        let tris: Vec<[Vec3; 3]> = data
            .chunks_exact(3 * VERTEX_FLOATS)
            .map(|c| {
                [0, VERTEX_FLOATS, 2 * VERTEX_FLOATS].map(|o| Vec3::new(c[o], c[o + 1], c[o + 2]))
            })
            .collect();
        let mut vpl_data: Vec<f32> = subdivide(&tris, size * VPL_SHADOW_MAX_EDGE)
            .iter()
            .flat_map(|t| t.iter().flat_map(|p| p.to_array()))
            .collect();
        let vpl_vertex_count = (vpl_data.len() / 3) as u32;
        if vpl_data.is_empty() {
            vpl_data.resize(3, 0.0);
        }
        if data.is_empty() {
            data.resize(VERTEX_FLOATS, 0.0);
        }
        let buffer = |label: &str, v: &[f32]| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(v),
                usage: wgpu::BufferUsages::VERTEX,
            })
        };
        Geometry {
            vertices: buffer("scene vertices", &data),
            vertex_count,
            vpl_vertices: buffer("vpl map vertices (subdivided)", &vpl_data),
            vpl_vertex_count,
            size,
        }
    }
}

impl GpuRenderer {
    /// Uploads every mesh of `scene` (albedo per vertex from its material, textures as layers
    /// of one sRGB array, resized to the largest texture's size up to [`MAX_TEXTURE_SIZE`]) and
    /// builds the pipelines.
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<GpuRenderer, RenderError> {
        let Geometry {
            vertices,
            vertex_count,
            vpl_vertices,
            vpl_vertex_count,
            size,
        } = Geometry::upload(&ctx.device, scene);
        let d = &ctx.device;
        let module = |label: &str, src: &str| {
            d.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            })
        };
        let gb = module("gbuffer.wgsl", GBUFFER_WGSL);
        let sh = module("shadow.wgsl", SHADOW_WGSL);
        let sd = module("shade.wgsl", SHADE_WGSL);
        let vs_mod = module("vpl_shadow.wgsl", VPL_SHADOW_WGSL);
        let gb_mod = module("gather_batch.wgsl", GATHER_BATCH_WGSL);
        let attrs = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3
        ];
        let layout = wgpu::VertexBufferLayout {
            array_stride: VERTEX_STRIDE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attrs,
        };
        let pos_only = [wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 0,
            shader_location: 0,
        }];
        let pos_layout = wgpu::VertexBufferLayout {
            array_stride: VERTEX_STRIDE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &pos_only,
        };
        let depth = Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        });
        let target = |f: wgpu::TextureFormat| {
            Some(wgpu::ColorTargetState {
                format: f,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = |label: &str,
                        m: &wgpu::ShaderModule,
                        buffers: &[Option<wgpu::VertexBufferLayout>],
                        targets: &[Option<wgpu::ColorTargetState>],
                        primitive: wgpu::PrimitiveState,
                        depth: Option<wgpu::DepthStencilState>| {
            d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: None,
                vertex: wgpu::VertexState {
                    module: m,
                    entry_point: Some("vs"),
                    buffers,
                    compilation_options: Default::default(),
                },
                primitive,
                depth_stencil: depth,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: m,
                    entry_point: Some("fs"),
                    targets,
                    compilation_options: Default::default(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let gbuffer = pipeline(
            "gbuffer",
            &gb,
            &[Some(layout)],
            &[
                target(wgpu::TextureFormat::Rgba32Float),
                target(wgpu::TextureFormat::Rgba16Float),
                target(wgpu::TextureFormat::Rgba16Float),
            ],
            wgpu::PrimitiveState::default(),
            depth.clone(),
        );
        let shadow = pipeline(
            "shadow",
            &sh,
            &[Some(pos_layout)],
            &[target(wgpu::TextureFormat::R32Float)],
            wgpu::PrimitiveState::default(),
            depth.clone(),
        );
        let shade = pipeline(
            "shade",
            &sd,
            &[],
            &[target(wgpu::TextureFormat::Rgba32Float)],
            wgpu::PrimitiveState::default(),
            None,
        );
        let pos12 = [wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 0,
            shader_location: 0,
        }];
        let vpl_shadow = pipeline(
            "vpl paraboloid maps",
            &vs_mod,
            &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &pos12,
            })],
            &[target(wgpu::TextureFormat::R32Float)],
            wgpu::PrimitiveState::default(),
            depth.clone(),
        );
        let val_shadow = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("val paraboloid maps"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &vs_mod,
                entry_point: Some("vs_val"),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &pos12,
                })],
                compilation_options: Default::default(),
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: depth.clone(),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &vs_mod,
                entry_point: Some("fs"),
                targets: &[target(wgpu::TextureFormat::R32Float)],
                compilation_options: Default::default(),
            }),
            multiview_mask: None,
            cache: None,
        });
        let gather_batch = pipeline(
            "gather batch",
            &gb_mod,
            &[],
            &[target(wgpu::TextureFormat::Rgba32Float)],
            wgpu::PrimitiveState::default(),
            None,
        );
        let (albedo_maps, albedo_sampler) = albedo_array(ctx, scene);
        let rsm_mod = module("rsm_vpls.wgsl", RSM_VPLS_WGSL);
        let rsm_vpls = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("rsm vpls"),
            layout: None,
            module: &rsm_mod,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        Ok(GpuRenderer {
            vertices,
            vertex_count,
            lights: scene.lights.clone(),
            near_m: size * 1e-4,
            far_m: size * 4.0,
            gbuffer,
            shadow,
            shade,
            vpl_vertices,
            vpl_vertex_count,
            vpl_shadow,
            gather_batch,
            rsm_vpls,
            albedo_maps,
            albedo_sampler,
            level: None,
            no_level: storage(d, "no level", &[]),
            cluster_pipelines: clustered::Pipelines::new(d, CLUSTERS_WGSL),
            val_pipelines: vals::Pipelines::new(d, VALS_WGSL),
            val_shadow,
            cssm_pipelines: vals::CssmPipelines::new(d, CSSM_WGSL, VAL_GATHER_WGSL),
            val_centres: std::sync::Mutex::new(None),
        })
    }

    /// Replaces the geometry and the lights with those of `scene` posed at another time (the
    /// same meshes and materials; dynamic meshes moved, see `Scene::at`). Pipelines, textures,
    /// the level and the near/far planes (from the first scene's size) stay.
    pub fn set_scene(&mut self, ctx: &GpuContext, scene: &Scene) {
        let g = Geometry::upload(&ctx.device, scene);
        self.vertices = g.vertices;
        self.vertex_count = g.vertex_count;
        self.vpl_vertices = g.vpl_vertices;
        self.vpl_vertex_count = g.vpl_vertex_count;
        self.lights = scene.lights.clone();
    }

    /// Replaces the lights (they move freely: shadow maps and RSMs are made per frame).
    pub fn set_lights(&mut self, lights: &[Light]) {
        self.lights = lights.to_vec();
    }

    /// The shadow layers' view-projections and the lights as the GPU sees them.
    fn light_views(&self) -> (Vec<GpuLight>, Vec<ShadowView>) {
        let mut lights = Vec::new();
        let mut views = Vec::new();
        let (near, far) = (self.near_m, self.far_m);
        for l in &self.lights {
            match *l {
                Light::Point {
                    position,
                    intensity,
                } => {
                    let first = views.len() as u32;
                    let faces = [
                        (Vec3::X, Vec3::NEG_Y),
                        (Vec3::NEG_X, Vec3::NEG_Y),
                        (Vec3::Y, Vec3::Z),
                        (Vec3::NEG_Y, Vec3::NEG_Z),
                        (Vec3::Z, Vec3::NEG_Y),
                        (Vec3::NEG_Z, Vec3::NEG_Y),
                    ];
                    for (f, up) in faces {
                        let vp = perspective(1.0, 1.0, near, far) * look_to(position, f, up);
                        views.push(ShadowView {
                            view_proj: vp.to_cols_array_2d(),
                            light: position.extend(1.0).to_array(),
                        });
                    }
                    lights.push(GpuLight {
                        position: position.extend(0.0).to_array(),
                        intensity: intensity.extend(0.0).to_array(),
                        direction: [0.0, -1.0, 0.0, 0.0],
                        layers: [first, 6, 0, 0],
                    });
                }
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    cutoff_rad,
                    beam_rad,
                } => {
                    let first = views.len() as u32;
                    let up = if direction.y.abs() > 0.9 {
                        Vec3::Z
                    } else {
                        Vec3::Y
                    };
                    let t = cutoff_rad.min(1.5).tan();
                    let vp = perspective(t, t, near, far) * look_to(position, direction, up);
                    views.push(ShadowView {
                        view_proj: vp.to_cols_array_2d(),
                        light: position.extend(1.0).to_array(),
                    });
                    lights.push(GpuLight {
                        position: position.extend(1.0).to_array(),
                        intensity: intensity.extend(beam_rad).to_array(),
                        direction: direction.extend(cutoff_rad).to_array(),
                        layers: [first, 1, 0, 0],
                    });
                }
            }
        }
        (lights, views)
    }

    /// Uploads a baked level's gate tables for mode [`GpuMode::Gates`]; the voxel→cluster grid
    /// keeps the smallest integer type that holds the scene's clusters.
    pub fn set_level(
        &mut self,
        ctx: &GpuContext,
        level: &crate::gates::GateLevel,
    ) -> Result<(), RenderError> {
        let t = level.tables();
        let d = &ctx.device;
        if t.gates.len() > MAX_GATES || level.cluster_count() > MAX_CLUSTERS {
            return Err(RenderError::Param(format!(
                "the level has {} gates and {} clusters; the GPU's light lists hold at most {} \
                 gates and {} clusters: bake at a lower resolution",
                t.gates.len(),
                level.cluster_count(),
                MAX_GATES,
                MAX_CLUSTERS
            )));
        }
        let bytes = (t.voxel_words.len() * 4) as u64;
        if bytes > d.limits().max_storage_buffer_binding_size {
            return Err(RenderError::Param(format!(
                "the voxel→cluster grid needs {bytes} bytes, more than the adapter's storage \
                 binding limit {}: bake at a lower resolution",
                d.limits().max_storage_buffer_binding_size
            )));
        }
        let buf = |label: &str, words: &[u32]| {
            let mut w = words.to_vec();
            if w.is_empty() {
                w.resize(16, 0);
            }
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&w),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let gates: Vec<u32> = t.gates.iter().flatten().copied().collect();
        self.level = Some(LevelBuffers {
            origin: t.origin,
            dims: t.dims,
            voxel_words: buf("voxel clusters", &t.voxel_words),
            gates: buf("gates", &gates),
            cluster_gates: buf("cluster gates", &t.cluster_gates),
        });
        Ok(())
    }

    /// VPLs from reflective shadow maps (Dong et al. §6): each light's RSM (`rsm_size`² per
    /// layer: 6 cube faces per point light, 1 per spot) fetched at `n` Halton points in all,
    /// shared between the lights by power, rotated by `seed`. The same lights give the same
    /// VPLs (no flicker). Returned to the CPU so that the reference can use the very same.
    pub fn rsm_vpls(
        &self,
        ctx: &GpuContext,
        n: u32,
        rsm_size: u32,
        seed: u64,
    ) -> Result<Vec<Vpl>, RenderError> {
        if !(16..=4096).contains(&rsm_size) {
            return Err(RenderError::Param(format!(
                "RSM size {rsm_size} must be 16..=4096"
            )));
        }
        if n > 1 << 24 {
            return Err(RenderError::Param(format!(
                "{n} RSM VPLs: at most {} are supported",
                1 << 24
            )));
        }
        let (gpu_lights, views) = self.light_views();
        if n == 0 || views.is_empty() {
            return Ok(Vec::new());
        }
        let d = &ctx.device;
        let layers = views.len() as u32;
        if layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "{layers} RSM layers exceed the adapter's {}",
                d.limits().max_texture_array_layers
            )));
        }
        let s = rsm_size;
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let maps = [
            texture(
                d,
                "rsm position",
                [s, s, layers],
                wgpu::TextureFormat::Rgba32Float,
                rt,
            ),
            texture(
                d,
                "rsm normal",
                [s, s, layers],
                wgpu::TextureFormat::Rgba16Float,
                rt,
            ),
            texture(
                d,
                "rsm albedo",
                [s, s, layers],
                wgpu::TextureFormat::Rgba16Float,
                rt,
            ),
        ];
        let depth = texture(
            d,
            "rsm depth",
            [s, s, 1],
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        // The light's view needs no visibility clusters: a grid of no voxels.
        let no_grid = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("no grid"),
            contents: bytemuck::bytes_of(&GridUniform {
                origin: [0.0, 0.0, 0.0, 1.0],
                dims: [0, 0, 0, 4],
                params: [1.0, 1.0, 0.0, 0.0],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut enc =
            d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("rsm") });
        for (i, v) in views.iter().enumerate() {
            let globals = Globals {
                view_proj: v.view_proj,
                eye: v.light,
                params: [0.0; 4],
                counts: [0; 4],
            };
            let buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("rsm globals"),
                contents: bytemuck::bytes_of(&globals),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("rsm globals"),
                layout: &self.gbuffer.get_bind_group_layout(0),
                entries: &self.gbuffer_entries(&buf, &no_grid),
            });
            let layer_views = maps.each_ref().map(|t| {
                t.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("rsm layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: i as u32,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            });
            self.gbuffer_pass(&mut enc, &layer_views, &depth_view, &bg, None);
        }
        ctx.queue.submit([enc.finish()]);

        // Samples: paths shared by power as for light paths, Halton points per light.
        let lights: Vec<Light> = self.lights.clone();
        let share = crate::vpl::share_by_power(&lights, n);
        if share.iter().all(|&k| k == 0) {
            return Ok(Vec::new());
        }
        let mut samples = Vec::with_capacity(n as usize);
        for (li, l) in lights.iter().enumerate() {
            let m = share[li];
            let gl = &gpu_lights[li];
            let first = gl.layers[0];
            let shift = crate::vpl::seed_shift(seed ^ li as u64, 0);
            for k in 0..m as u64 {
                let u = crate::vpl::halton2(k, 2, 3, shift);
                let (layer, x, y, half) = match *l {
                    Light::Point { .. } => {
                        let f = ((u.x * 6.0) as u32).min(5);
                        (
                            first + f,
                            (u.x * 6.0 - f as f32) * 2.0 - 1.0,
                            u.y * 2.0 - 1.0,
                            1.0,
                        )
                    }
                    Light::Spot { cutoff_rad, .. } => {
                        let t = cutoff_rad.min(1.5).tan();
                        (first, (u.x * 2.0 - 1.0) * t, (u.y * 2.0 - 1.0) * t, t)
                    }
                };
                let faces = if matches!(l, Light::Point { .. }) {
                    6.0
                } else {
                    1.0
                };
                // Direction through (x, y) on the layer's image plane at distance 1.
                let view = Mat4::from_cols_array_2d(&views[layer as usize].view_proj);
                let inv = view.inverse();
                let ndc = glam::Vec4::new(x / half, y / half, 0.5, 1.0);
                let w = inv * ndc;
                let dir = (w.truncate() / w.w
                    - Vec3::from_slice(&views[layer as usize].light[..3]))
                .normalize_or_zero();
                let solid = faces * 4.0 * half * half / m as f32 / (1.0 + x * x + y * y).powf(1.5);
                let power = crate::lights::intensity_towards(l, dir) * solid;
                let tx = (((x / half) * 0.5 + 0.5) * s as f32).clamp(0.0, s as f32 - 1.0) as u32;
                let ty = ((0.5 - (y / half) * 0.5) * s as f32).clamp(0.0, s as f32 - 1.0) as u32;
                samples.push(RsmSample {
                    texel: [layer, tx, ty, 0],
                    power: power.extend(0.0).to_array(),
                });
            }
        }
        let sample_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rsm samples"),
            contents: bytemuck::cast_slice(&samples),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let bytes = (samples.len() * std::mem::size_of::<Vpl>()) as u64;
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rsm vpls"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rsm vpls readback"),
            size: bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let array = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                label: Some("rsm"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let arrays = maps.each_ref().map(array);
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("rsm vpls"),
            layout: &self.rsm_vpls.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: sample_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: out.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&arrays[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&arrays[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&arrays[2]),
                },
            ],
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("rsm vpls"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("rsm vpls"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.rsm_vpls);
            pass.set_bind_group(0, &bg, &[]);
            let groups = (samples.len() as u32).div_ceil(64);
            let max = d.limits().max_compute_workgroups_per_dimension;
            if groups > max {
                return Err(RenderError::Param(format!(
                    "{n} RSM VPLs need {groups} workgroups, more than the adapter's {max}"
                )));
            }
            pass.dispatch_workgroups(groups, 1, 1);
        }
        enc.copy_buffer_to_buffer(&out, 0, &read, 0, bytes);
        ctx.queue.submit([enc.finish()]);
        let slice = read.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        ctx.wait();
        let vpls: Vec<Vpl> = {
            let mapped = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Gpu(format!("cannot read the VPLs back: {e}")))?;
            bytemuck::cast_slice(&mapped).to_vec()
        };
        read.unmap();
        Ok(vpls)
    }

    /// The G-buffer's bindings: `globals`, the albedo array and its sampler, the level's
    /// `grid` uniform and voxel→cluster words.
    fn gbuffer_entries<'a>(
        &'a self,
        globals: &'a wgpu::Buffer,
        grid: &'a wgpu::Buffer,
    ) -> [wgpu::BindGroupEntry<'a>; 5] {
        [
            wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&self.albedo_maps),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&self.albedo_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 8,
                resource: grid.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 9,
                resource: self
                    .level
                    .as_ref()
                    .map_or(&self.no_level, |l| &l.voxel_words)
                    .as_entire_binding(),
            },
        ]
    }

    /// The G-buffer pass into `targets` (position, normal, albedo) and `depth`.
    fn gbuffer_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
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
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.gbuffer);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.draw(0..self.vertex_count, 0..1);
    }

    /// Checks `params` and the VPL count against their limits and the adapter's.
    fn validate(
        &self,
        ctx: &GpuContext,
        vpls: &[Vpl],
        params: &GpuParams,
    ) -> Result<(), RenderError> {
        if params.g_max.is_nan() || params.g_max <= 0.0 {
            return Err(RenderError::Param(format!(
                "geometry-term clamp {} must be > 0",
                params.g_max
            )));
        }
        if !(16..=2048).contains(&params.vpl_map_size) || !(1..=2048).contains(&params.vpl_batch) {
            return Err(RenderError::Param(format!(
                "VPL map size {} must be 16..=2048 and VPL batch {} 1..=2048",
                params.vpl_map_size, params.vpl_batch
            )));
        }
        if matches!(params.mode, GpuMode::Gates | GpuMode::GatesPerPixel) {
            if self.level.is_none() {
                return Err(RenderError::Param(
                    "mode gates needs a baked level (GpuRenderer::set_level, --level)".into(),
                ));
            }
            let o = params.gates.oversize;
            if !(o > 0.0 && o.is_finite() && (1..=2).contains(&params.gates.max_hops)) {
                return Err(RenderError::Param(format!(
                    "gate oversize {o} must be > 0 and hops {} 1 or 2 on the GPU",
                    params.gates.max_hops
                )));
            }
        }
        if !(16..=4096).contains(&params.shadow_size) {
            return Err(RenderError::Param(format!(
                "shadow map size {} must be 16..=4096",
                params.shadow_size
            )));
        }
        let d = &ctx.device;
        let vpl_bytes = std::mem::size_of_val(vpls) as u64;
        if vpl_bytes > d.limits().max_storage_buffer_binding_size {
            return Err(RenderError::Param(format!(
                "{} VPLs need {vpl_bytes} bytes, more than the adapter's storage binding limit {}",
                vpls.len(),
                d.limits().max_storage_buffer_binding_size
            )));
        }
        Ok(())
    }

    /// The buffers every pass of a frame reads: globals, the level's grid uniform, the VPLs.
    fn frame_inputs(
        &self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        params: &GpuParams,
    ) -> Result<FrameInputs, RenderError> {
        self.validate(ctx, vpls, params)?;
        let d = &ctx.device;
        let globals = Globals {
            view_proj: view.view_proj(self.near_m, self.far_m).to_cols_array_2d(),
            eye: view.eye.extend(1.0).to_array(),
            params: [
                params.g_max,
                params.shadow_normal_offset,
                params.shadow_bias,
                0.0,
            ],
            counts: [
                vpls.len() as u32,
                self.lights.len() as u32,
                match params.mode {
                    GpuMode::None => 0,
                    GpuMode::DirectOnly
                    | GpuMode::PerVplShadowMaps
                    | GpuMode::ValHard
                    | GpuMode::ValCssm => 1,
                    GpuMode::GatesPerPixel => 2,
                    GpuMode::Gates => 3,
                },
                params.shadow_size,
            ],
        };
        let level = self.level.as_ref();
        let grid = GridUniform {
            origin: level.map_or([0.0, 0.0, 0.0, 1.0], |l| l.origin),
            dims: level.map_or([0, 0, 0, 4], |l| l.dims),
            params: [
                params.gates.oversize,
                params.gates.max_hops as f32,
                0.0,
                0.0,
            ],
        };
        let uniform = |label: &str, bytes: &[u8]| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        Ok(FrameInputs {
            globals: uniform("globals", bytemuck::bytes_of(&globals)),
            grid: uniform("grid", bytemuck::bytes_of(&grid)),
            vpls: storage(d, "vpls", bytemuck::cast_slice(vpls)),
        })
    }

    /// The geometry pass: the G-buffer (position with the visibility cluster in w, normal,
    /// albedo) of `view`.
    fn geometry_pass(
        &self,
        ctx: &GpuContext,
        view: &View,
        frame: &FrameInputs,
        timer: &mut Timer,
        times: &mut PassTimes,
    ) -> ([wgpu::Texture; 3], [wgpu::TextureView; 3]) {
        let t0 = Instant::now();
        let d = &ctx.device;
        let [w, h] = view.size;
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let targets = [
            ("g position", wgpu::TextureFormat::Rgba32Float),
            ("g normal", wgpu::TextureFormat::Rgba16Float),
            ("g albedo", wgpu::TextureFormat::Rgba16Float),
        ]
        .map(|(label, format)| texture(d, label, [w, h, 1], format, rt));
        let g_depth = texture(
            d,
            "g depth",
            [w, h, 1],
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let views = targets
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        let gdepth_view = g_depth.create_view(&Default::default());
        let gbg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer globals"),
            layout: &self.gbuffer.get_bind_group_layout(0),
            entries: &self.gbuffer_entries(&frame.globals, &frame.grid),
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gbuffer"),
        });
        let span = timer.span(Stage::GBuffer);
        self.gbuffer_pass(
            &mut enc,
            &views,
            &gdepth_view,
            &gbg,
            timer.writes(span, true, true),
        );
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.gbuffer = t0.elapsed().as_secs_f64();
        (targets, views)
    }

    /// Renders `view` with `vpls` and returns the linear HDR image and the pass times.
    pub fn render(
        &self,
        ctx: &GpuContext,
        view: &View,
        vpls: &[Vpl],
        params: &GpuParams,
    ) -> Result<(HdrImage, PassTimes), RenderError> {
        let frame = self.frame_inputs(ctx, view, vpls, params)?;
        let d = &ctx.device;
        let [w, h] = view.size;
        let mut times = PassTimes::default();
        let (gpu_lights, shadow_views) = self.light_views();
        let batches = if params.mode == GpuMode::PerVplShadowMaps {
            vpls.len().div_ceil(params.vpl_batch.max(1) as usize) as u32
        } else {
            0
        };
        let mut timer = Timer::new(ctx, 10 + 2 * batches);
        let layers = shadow_views.len().max(1) as u32;
        if layers > d.limits().max_texture_array_layers {
            return Err(RenderError::Param(format!(
                "{} shadow layers exceed the adapter's {}",
                layers,
                d.limits().max_texture_array_layers
            )));
        }
        let tex = |label: &str, size, format, usage| texture(d, label, size, format, usage);
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let s = params.shadow_size;
        let shadow_tex = tex(
            "shadow maps",
            [s, s, layers],
            wgpu::TextureFormat::R32Float,
            rt,
        );
        let shadow_depth = tex(
            "shadow depth",
            [s, s, 1],
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        // 1. Shadow maps, one pass per layer.
        let t0 = Instant::now();
        let stride = 256u64;
        let mut sv_bytes = vec![0u8; (stride as usize) * shadow_views.len().max(1)];
        for (i, v) in shadow_views.iter().enumerate() {
            let b = bytemuck::bytes_of(v);
            sv_bytes[i * stride as usize..i * stride as usize + b.len()].copy_from_slice(b);
        }
        let sv_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow views"),
            contents: &sv_bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("shadow maps"),
        });
        let depth_view = shadow_depth.create_view(&Default::default());
        let span = timer.span(Stage::Shadows);
        let last = shadow_views.len().saturating_sub(1);
        for (i, _) in shadow_views.iter().enumerate() {
            let layer_view = shadow_tex.create_view(&wgpu::TextureViewDescriptor {
                label: Some("shadow layer"),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: i as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadow view"),
                layout: &self.shadow.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &sv_buf,
                        offset: i as u64 * stride,
                        size: std::num::NonZeroU64::new(std::mem::size_of::<ShadowView>() as u64),
                    }),
                }],
            });
            distance_pass(
                &mut enc,
                "shadow layer",
                &layer_view,
                &depth_view,
                &self.shadow,
                &bg,
                &self.vertices,
                self.vertex_count,
                0..1,
                timer.writes(span, i == 0, i == last),
            );
        }
        ctx.queue.submit([enc.finish()]);
        ctx.wait();
        times.shadows = t0.elapsed().as_secs_f64();

        // 2. Geometry pass (G-buffer).
        let (_targets, views) = self.geometry_pass(ctx, view, &frame, &mut timer, &mut times);

        // 2b. Mode gates: unique clusters and light assignment.
        let lists = if params.mode == GpuMode::Gates {
            Some(self.cluster_passes(
                ctx,
                view,
                vpls,
                &frame.vpls,
                &frame.grid,
                &views[0],
                params,
                &mut timer,
                &mut times,
            )?)
        } else {
            None
        };

        // 3. Shade: direct light and the indirect lighting.
        let t0 = Instant::now();
        let lights_buf = storage(d, "lights", bytemuck::cast_slice(&gpu_lights));
        let mats: Vec<[[f32; 4]; 4]> = shadow_views.iter().map(|v| v.view_proj).collect();
        let mats_buf = storage(d, "shadow matrices", bytemuck::cast_slice(&mats));
        let shadow_array_view = shadow_tex.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        // Gate tables and light lists where the mode has them, placeholders otherwise.
        let level = self.level.as_ref();
        let none = &self.no_level;
        let out = tex(
            "hdr",
            [w, h, 1],
            wgpu::TextureFormat::Rgba32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let out_view = out.create_view(&Default::default());
        let buffers: [(u32, &wgpu::Buffer); 11] = [
            (0, &frame.globals),
            (1, &lights_buf),
            (2, &frame.vpls),
            (3, &mats_buf),
            (8, &frame.grid),
            (9, level.map_or(none, |l| &l.voxel_words)),
            (10, level.map_or(none, |l| &l.gates)),
            (11, level.map_or(none, |l| &l.cluster_gates)),
            (12, lists.as_ref().map_or(none, |b| &b.pixel_cluster)),
            (13, lists.as_ref().map_or(none, |b| &b.clusters)),
            (14, lists.as_ref().map_or(none, |b| &b.entries)),
        ];
        let textures = [
            (4, &shadow_array_view),
            (5, &views[0]),
            (6, &views[1]),
            (7, &views[2]),
        ];
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .map(|&(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .chain(textures.iter().map(|&(binding, v)| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(v),
            }))
            .collect();
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shade"),
            layout: &self.shade.get_bind_group_layout(0),
            entries: &entries,
        });
        let span = timer.span(Stage::Shade);
        fullscreen_pass(
            ctx,
            "shade",
            &out_view,
            &self.shade,
            &bg,
            timer.writes(span, true, true),
        );
        times.shade = t0.elapsed().as_secs_f64();

        // 3b. Per-VPL paraboloid maps and their gather, batch by batch, added onto the image.
        if params.mode == GpuMode::PerVplShadowMaps && !vpls.is_empty() {
            self.per_vpl_batches(
                ctx,
                params,
                vpls,
                &frame.vpls,
                &views,
                &out,
                &mut times,
                &mut timer,
            )?;
        }

        // 3c. VAL modes: cluster, a map per VAL, the gather.
        if matches!(params.mode, GpuMode::ValHard | GpuMode::ValCssm) && !vpls.is_empty() {
            self.val_frame(
                ctx,
                params,
                vpls,
                &frame.vpls,
                &views,
                &out,
                &mut times,
                &mut timer,
            )?;
        }

        // 4. Read back.
        let t0 = Instant::now();
        if let Some(b) = &lists {
            times.lists = Some(self.list_stats(ctx, b)?);
        }
        let px = read_texture(ctx, &out)?;
        let mut img = HdrImage::new(w, h);
        for (o, p) in img.pixels.iter_mut().zip(&px) {
            *o = Vec3::new(p[0], p[1], p[2]);
        }
        times.readback = t0.elapsed().as_secs_f64();
        times.gpu = timer.read(ctx);
        Ok((img, times))
    }

    /// Renders the paraboloid maps of `vpls` in batches of `params.vpl_batch` and adds each
    /// batch's gather onto `out`.
    #[allow(clippy::too_many_arguments)]
    fn per_vpl_batches(
        &self,
        ctx: &GpuContext,
        params: &GpuParams,
        vpls: &[Vpl],
        vpl_buf: &wgpu::Buffer,
        gviews: &[wgpu::TextureView; 3],
        out: &wgpu::Texture,
        times: &mut PassTimes,
        timer: &mut Timer,
    ) -> Result<(), RenderError> {
        let d = &ctx.device;
        // Ping-pong: each batch reads the image so far and writes it plus its light.
        let other = texture(
            d,
            "hdr (ping-pong)",
            [out.width(), out.height(), 1],
            wgpu::TextureFormat::Rgba32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let pair = [
            out.create_view(&Default::default()),
            other.create_view(&Default::default()),
        ];
        let mut current = 0usize;
        let m = params.vpl_map_size;
        let batch = params
            .vpl_batch
            .min(d.limits().max_texture_array_layers)
            .max(1) as usize;
        let far = self.far_m;
        let maps = texture(
            d,
            "vpl paraboloid maps",
            [m, m, batch as u32],
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = texture(
            d,
            "vpl map depth",
            [m, m, 1],
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        let layer_views: Vec<wgpu::TextureView> = (0..batch as u32)
            .map(|l| {
                maps.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("vpl map layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: l,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let array_view = maps.create_view(&wgpu::TextureViewDescriptor {
            label: Some("vpl maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let stride = 256usize;
        for (bi, chunk) in vpls.chunks(batch).enumerate() {
            let t0 = Instant::now();
            let mut bytes = vec![0u8; stride * chunk.len()];
            for (k, v) in chunk.iter().enumerate() {
                let n = Vec3::from(v.normal).normalize_or(Vec3::Y);
                let (t, b) = crate::vpl::basis(n);
                let view = VplView {
                    position: Vec3::from(v.position).extend(far).to_array(),
                    tangent: t.extend(0.0).to_array(),
                    bitangent: b.extend(0.0).to_array(),
                    normal: n.extend(0.0).to_array(),
                };
                bytes[k * stride..k * stride + 64].copy_from_slice(bytemuck::bytes_of(&view));
            }
            let ubuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("vpl views"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("vpl maps"),
            });
            let span = timer.span(Stage::VplMaps);
            for (k, layer_view) in layer_views.iter().enumerate().take(chunk.len()) {
                let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("vpl view"),
                    layout: &self.vpl_shadow.get_bind_group_layout(0),
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &ubuf,
                            offset: (k * stride) as u64,
                            size: std::num::NonZeroU64::new(64),
                        }),
                    }],
                });
                distance_pass(
                    &mut enc,
                    "vpl map",
                    layer_view,
                    &depth_view,
                    &self.vpl_shadow,
                    &bg,
                    &self.vpl_vertices,
                    self.vpl_vertex_count,
                    0..1,
                    timer.writes(span, k == 0, k + 1 == chunk.len()),
                );
            }
            ctx.queue.submit([enc.finish()]);
            ctx.wait();
            times.vpl_maps += t0.elapsed().as_secs_f64();

            let t0 = Instant::now();
            let b = Batch {
                range: [(bi * batch) as u32, chunk.len() as u32, m, 0],
                params: [
                    params.g_max,
                    params.shadow_normal_offset,
                    params.shadow_bias,
                    0.0,
                ],
            };
            let bbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("batch"),
                contents: bytemuck::bytes_of(&b),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gather batch"),
                layout: &self.gather_batch.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: bbuf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: vpl_buf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&array_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(&gviews[0]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&gviews[1]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::TextureView(&gviews[2]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&pair[current]),
                    },
                ],
            });
            let span = timer.span(Stage::VplGather);
            fullscreen_pass(
                ctx,
                "gather batch",
                &pair[1 - current],
                &self.gather_batch,
                &bg,
                timer.writes(span, true, true),
            );
            current = 1 - current;
            times.vpl_gather += t0.elapsed().as_secs_f64();
        }
        if current == 1 {
            let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("ping-pong copy"),
            });
            enc.copy_texture_to_texture(other.as_image_copy(), out.as_image_copy(), out.size());
            ctx.queue.submit([enc.finish()]);
            ctx.wait();
        }
        Ok(())
    }
}

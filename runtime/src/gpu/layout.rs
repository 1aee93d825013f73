//! Every struct shared between Rust and WGSL, in one place, with the same name on both sides.
//!
//! Each is `#[repr(C)]` + bytemuck with explicit padding, declared through [`gpu_struct!`],
//! which also records its layout ([`GpuStruct::layout`]: size, and each field's name, offset and
//! WGSL type). A test parses every composed shader with naga and checks every struct of the
//! same name against that record — size, member names, offsets and types — so a field added on
//! one side only fails the build's tests, not an image. Padding fields are `_padN` in Rust and
//! `padN` in WGSL. [`Vpl`] and [`Val`] live with their CPU twins and are recorded here too.

use bytemuck::{Pod, Zeroable};

pub use crate::cpu::val::Val;
pub use crate::vpl::Vpl;

/// A field's WGSL type, for the layout record.
pub trait WgslType {
    /// The type as WGSL writes it.
    const WGSL: &'static str;
}

macro_rules! wgsl_types {
    ($($t:ty => $w:literal),* $(,)?) => {
        $(impl WgslType for $t {
            const WGSL: &'static str = $w;
        })*
    };
}

wgsl_types! {
    f32 => "f32",
    u32 => "u32",
    [u32; 2] => "vec2<u32>",
    [f32; 2] => "vec2<f32>",
    [f32; 3] => "vec3<f32>",
    [u32; 3] => "vec3<u32>",
    [f32; 4] => "vec4<f32>",
    [u32; 4] => "vec4<u32>",
    [[f32; 4]; 4] => "mat4x4<f32>",
}

/// A shared struct's layout as Rust lays it out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructLayout {
    /// The struct's name (the same in WGSL).
    pub name: &'static str,
    /// Size in bytes.
    pub size: usize,
    /// (name without a leading `_`, byte offset, WGSL type) of each field, in order.
    pub fields: Vec<(&'static str, usize, &'static str)>,
}

/// A struct shared with WGSL.
pub trait GpuStruct: Pod {
    /// Its layout, for the naga test.
    fn layout() -> StructLayout;
}

/// Declares a `#[repr(C)]` Pod struct shared with WGSL and records its layout.
macro_rules! gpu_struct {
    ($(#[$m:meta])* pub struct $name:ident {
        $($(#[$fm:meta])* pub $f:ident : $t:ty),* $(,)?
    }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
        pub struct $name {
            $($(#[$fm])* pub $f: $t),*
        }
        record_layout!($name { $($f: $t),* });
    };
}

/// Records the layout of a struct declared elsewhere.
macro_rules! record_layout {
    ($name:ident { $($f:ident : $t:ty),* $(,)? }) => {
        impl GpuStruct for $name {
            fn layout() -> StructLayout {
                StructLayout {
                    name: stringify!($name),
                    size: std::mem::size_of::<$name>(),
                    fields: vec![$((
                        stringify!($f).trim_start_matches('_'),
                        std::mem::offset_of!($name, $f),
                        <$t as WgslType>::WGSL,
                    )),*],
                }
            }
        }
    };
}

record_layout!(Vpl {
    position: [f32; 3],
    _pad0: f32,
    normal: [f32; 3],
    _pad1: f32,
    flux: [f32; 3],
    _pad2: f32,
});

record_layout!(Val {
    position: [f32; 4],
    normal: [f32; 4],
    flux: [f32; 4],
    rect: [f32; 4],
});

gpu_struct! {
    /// Per-frame constants of the G-buffer and shading passes (globals.wgsl). Written by the
    /// renderer once per frame (and per RSM layer, for the lights' views).
    pub struct Globals {
        /// Camera (or light layer) view-projection, column-major.
        pub view_proj: [[f32; 4]; 4],
        /// Eye position (xyz, m), w 1.
        pub eye: [f32; 4],
        /// Geometry-term clamp of the VPL gather. [Units: 1/m²]
        pub g_max: f32,
        /// Normal offset of shadow lookups. [Units: texels]
        pub shadow_normal_offset: f32,
        /// Depth bias of shadow lookups. [Units: texels]
        pub shadow_bias: f32,
        /// Interleaving block b of clustered gates (≤ 1: every VPL at every pixel; else a
        /// pixel takes the VPLs of its subset, VPL mod b² = its place in the b × b block).
        pub interleave_block: u32,
        /// VPLs in the VPL buffer.
        pub vpl_count: u32,
        /// Lights in the light buffer.
        pub light_count: u32,
        /// What the shading pass adds to direct light: one of the `SHADE_*` constants
        /// ([`super::shaders::ShadeIndirect`]).
        pub shade_mode: u32,
        /// Shadow map layer size. [Units: texels]
        pub shadow_size: u32,
        /// Direct lights' visibility: `DIRECT_PER_LIGHT` (each light's shadow maps) or
        /// `DIRECT_LIGHTCLUSTER` (its cluster's PCSS visibility texture).
        pub direct_mode: u32,
        /// Portals and voxels: VPLs of a pixel's interleaving subset walked a draw (0: all in
        /// one draw; on a software rasterizer, what its loop limit allows,
        /// [`crate::gpu::methods::walk_batch`]).
        pub walk_batch: u32,
        /// Portals and voxels: the walks' Russian roulette, a share of a pixel's light (0:
        /// off; [`crate::gpu::passes::clustered_gates::GatesParams::roulette_share`]).
        pub walk_roulette: f32,
        /// The roulette's seed.
        pub walk_seed: u32,
        /// Interleaved walks: the VPLs nearer a pixel than this times its distance from the
        /// eye are left out of its subset's gather and walked at the pixel itself, unblurred
        /// (0: none; [`crate::gpu::passes::gates_params::GatesParams::near_scale`]).
        pub near_scale: f32,
        /// Interleaved walks, the ratio estimator: 1 where the blur scales each pixel's
        /// unshadowed far light by its taps' visible share, 0 where it averages their light
        /// ([`crate::gpu::passes::gates_params::GatesParams::ratio`]).
        pub ratio: u32,
        /// The ratio estimator's grid: the unshadowed far light summed at every this many
        /// pixels across and down (1: every pixel;
        /// [`crate::gpu::passes::gates_params::GatesParams::ratio_stride`]). [Units: px]
        pub ratio_stride: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// The level's voxel→cluster grid and the gate test's settings (grid.wgsl). Written by the
    /// renderer per frame.
    pub struct Grid {
        /// Grid origin. [Units: m]
        pub origin: [f32; 3],
        /// Voxel side. [Units: m]
        pub voxel_size: f32,
        /// Voxels per axis (0: no level).
        pub dims: [u32; 3],
        /// Bytes per stored cluster value (1, 2 or 4).
        pub value_bytes: u32,
        /// Gate disks are this many times their baked radius.
        pub oversize: f32,
        /// Gates a VPL's light may pass (1 or 2 on the GPU).
        pub max_hops: u32,
        /// 0: gate disks, 1: portals (walked), 2: the voxel walk ([`crate::cpu::gates::GateShape::shader_id`]).
        pub shape: u32,
        /// Portals a walk may pass before it is given up.
        pub max_walk: u32,
        /// The voxel walk: 1 along the true segment with the closed voxels' triangles, 0
        /// between ends off the surfaces.
        pub triangles: u32,
        /// The voxel walk between ends off the surfaces: 1 passing a closed voxel where the
        /// segment meets neither of its planes, 0 blocking at every closed voxel.
        pub planes: u32,
        /// Padding.
        pub _pad1: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// A gate disk (gates.wgsl), from the baked level.
    pub struct Gate {
        /// Centre. [Units: m]
        pub centre: [f32; 3],
        /// Radius (before the oversize factor). [Units: m]
        pub radius: f32,
        /// Unit normal.
        pub normal: [f32; 3],
        /// Padding.
        pub _pad0: f32,
        /// The two visibility clusters it joins.
        pub clusters: [u32; 2],
        /// Padding.
        pub _pad1: [u32; 2],
    }
}

gpu_struct! {
    /// A light as the shading pass reads it (shade.wgsl). 64 bytes.
    pub struct Light {
        /// xyz position (m), w kind (`LIGHT_POINT` or `LIGHT_SPOT`).
        pub position: [f32; 4],
        /// rgb intensity (W/sr), w beam half-angle (rad).
        pub intensity: [f32; 4],
        /// xyz unit axis, w cutoff half-angle (rad).
        pub direction: [f32; 4],
        /// x first shadow layer, y layer count.
        pub layers: [u32; 4],
    }
}

gpu_struct! {
    /// One shadow layer's view (shadow.wgsl), at 256-byte strides in one uniform buffer.
    pub struct ShadowView {
        /// The layer's view-projection of points relative to the light (x − light): a
        /// level far from the origin keeps its precision, where a world matrix subtracted
        /// kilometres inside its product (the ajar door 6 km out: direct light through walls).
        pub view_proj: [[f32; 4]; 4],
        /// xyz light position (m).
        pub light: [f32; 4],
    }
}

impl ShadowView {
    /// The layer's view-projection of world points (the RSM's G-buffer pass draws with it).
    pub fn world_view_proj(&self) -> glam::Mat4 {
        let light = glam::Vec3::from_slice(&self.light[..3]);
        glam::Mat4::from_cols_array_2d(&self.view_proj) * glam::Mat4::from_translation(-light)
    }
}

gpu_struct! {
    /// One RSM sample for the VPL compute pass (rsm_vpls.wgsl).
    pub struct RsmSample {
        /// x layer, y texel x, z texel y.
        pub texel: [u32; 4],
        /// rgb power (W): intensity towards the sample × its solid angle.
        pub power: [f32; 4],
    }
}

gpu_struct! {
    /// A batch of per-VPL maps for the gather (gather_batch.wgsl), at 256-byte strides.
    pub struct Batch {
        /// First VPL of the batch.
        pub first: u32,
        /// VPLs in the batch.
        pub count: u32,
        /// Map side. [Units: texels]
        pub map_size: u32,
        /// Padding.
        pub _pad0: u32,
        /// Geometry-term clamp. [Units: 1/m²]
        pub g_max: f32,
        /// Normal offset. [Units: texels]
        pub normal_offset: f32,
        /// Bias. [Units: texels]
        pub bias: f32,
        /// Padding.
        pub _pad1: f32,
    }
}

gpu_struct! {
    /// Constants of the paraboloid map passes (vpl_shadow.wgsl): a per-VPL map draws VPL
    /// `instance`, a VAL map VAL `instance`.
    pub struct MapParams {
        /// Far distance (normalises depth). [Units: m]
        pub far: f32,
        /// A VAL's centre is moved this far off its surface along its normal. [Units: m]
        pub centre_offset: f32,
        /// Padding.
        pub _pad0: [f32; 2],
    }
}

gpu_struct! {
    /// Per-frame constants of the clustered passes (clusters.wgsl).
    pub struct ClusterFrame {
        /// Eye. [Units: m]
        pub eye: [f32; 3],
        /// Interleaving subsets B: a light list is ordered by (VPL mod B, VPL). [Limit: ≥ 1]
        pub subsets: u32,
        /// Unit view axis.
        pub forward: [f32; 3],
        /// Padding.
        pub _pad1: f32,
        /// Image width. [Units: px]
        pub width: u32,
        /// Image height. [Units: px]
        pub height: u32,
        /// Tile side. [Units: px] [Limit: 1..=16]
        pub tile_px: u32,
        /// Exponential depth slices. [Limit: 1..=256]
        pub depth_slices: u32,
        /// Tiles across.
        pub tiles_x: u32,
        /// Tiles down.
        pub tiles_y: u32,
        /// VPLs.
        pub vpl_count: u32,
        /// Light-entry pool capacity.
        pub capacity: u32,
    }
}

gpu_struct! {
    /// A geometry cluster and its light list (clusters.wgsl, shade.wgsl). 64 bytes.
    pub struct GeometryCluster {
        /// x tile x, y tile y, z depth slice, w visibility cluster (`u32::MAX`: none).
        pub key: [u32; 4],
        /// xyz box minimum (m).
        pub lo: [f32; 4],
        /// xyz box maximum (m).
        pub hi: [f32; 4],
        /// x first entry, y entries, z entries needed (> y only when the pool overflowed).
        pub list: [u32; 4],
    }
}

gpu_struct! {
    /// Per-frame constants of LightCluster (light_cluster.wgsl): the view for the culling,
    /// the clustering's parameters, the cluster shadow atlas and the PCSS settings.
    pub struct LcFrame {
        /// Eye position (xyz, m), w unused.
        pub eye: [f32; 4],
        /// Camera right, up and forward (xyz, unit), w unused.
        pub right: [f32; 4],
        /// See `right`.
        pub up: [f32; 4],
        /// See `right`.
        pub forward: [f32; 4],
        /// cos and sin of the horizontal, then the vertical half field of view.
        pub half_fov: [f32; 4],
        /// Lights in the light buffer.
        pub light_count: u32,
        /// Most clusters (at most [`crate::gpu::passes::light_cluster::MAX_LC_CLUSTERS`]).
        pub max_clusters: u32,
        /// Side of one cube face's tile. [Units: texels]
        pub map_size: u32,
        /// Tiles per row of the atlas.
        pub tiles_per_row: u32,
        /// Minimum distance between centres at the eye. [Units: m]
        pub min_distance_m: f32,
        /// Its growth with the distance from the eye. [Units: 1/m]
        pub distance_scale: f32,
        /// A light's range is `range_scale · sqrt(intensity)`. [Units: m / sqrt(W/sr)]
        pub range_scale: f32,
        /// Near distance of the cube faces. [Units: m]
        pub near_m: f32,
        /// Far distance of the cube faces (the atlas holds distance / far). [Units: m]
        pub far_m: f32,
        /// Normal offset of the lookups. [Units: texels]
        pub normal_offset: f32,
        /// Depth bias of the lookups. [Units: texels]
        pub bias: f32,
        /// PCSS blocker-search samples.
        pub blocker_samples: u32,
        /// PCSS filter (PCF) samples.
        pub filter_samples: u32,
        /// Frame width. [Units: px]
        pub width: u32,
        /// Frame height. [Units: px]
        pub height: u32,
        /// Vertices of the scene (the shadow draw's vertex count).
        pub vertex_count: u32,
        /// A cluster's disk: 0 its minimum distance (the paper), 1 its lights' extent.
        pub disk_extent: u32,
        /// 1: the emitters are VPLs, lighting their normal's hemisphere.
        pub hemisphere: u32,
        /// Padding.
        pub _pad1: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// Per-frame constants of the VAL clustering (vals.wgsl).
    pub struct ValFrame {
        /// VPLs.
        pub vpl_count: u32,
        /// VALs.
        pub val_count: u32,
        /// Interleaving subsets (block side²).
        pub subsets: u32,
        /// 0 restart, 1 Halton seeds warped by flux.
        pub seeding: u32,
        /// Weight of the position term.
        pub w_x: f32,
        /// Weight of the normal-angle term.
        pub w_alpha: f32,
        /// Weight of the flux term.
        pub w_f: f32,
        /// Splat radius over D (0: every centre; 1 / D is a storage word: the GPU computes it
        /// for RSM VPLs).
        pub splat: f32,
        /// 1: a warm start that seeds again the VALs that held no VPL last frame.
        pub reseed: u32,
        /// Padding.
        pub _pad0: u32,
        /// Padding.
        pub _pad1: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// Constants of the VAL gather and the compose (val_gather.wgsl, blur.wgsl).
    pub struct ValGather {
        /// VPLs.
        pub vpl_count: u32,
        /// VALs.
        pub val_count: u32,
        /// VAL map side. [Units: texels]
        pub map_size: u32,
        /// Fourier terms K of the CSSM.
        pub terms: u32,
        /// Geometry-term clamp. [Units: 1/m²]
        pub g_max: f32,
        /// Normal offset of hard lookups. [Units: texels]
        pub normal_offset: f32,
        /// Bias of hard lookups. [Units: texels]
        pub bias: f32,
        /// VAL centre offset along its normal. [Units: m]
        pub centre_offset: f32,
        /// CSSM receiver offset. [Units: normalised depth]
        pub receiver_offset: f32,
        /// CSSM sharpening s.
        pub sharpness: f32,
        /// CSSM normal offset. [Units: texels]
        pub cssm_normal_offset: f32,
        /// Blur: 1 where the taps are weighted by a tent over (2b − 1)² pixels (`blur.wgsl`),
        /// 0 the box of b × b.
        pub blur_tent: u32,
        /// Interleaving block side (1: none). [Units: px]
        pub block: u32,
        /// Interleaving subsets (block²).
        pub subsets: u32,
        /// Layout of the interleaved indirect target: 0 pixel order, 1 deinterleaved (each
        /// VPL subset's pixels side by side; `vpl.wgsl`'s `deinterleaved`).
        pub deinterleaved: u32,
        /// Blur: 1 where a tap that does not agree gives way to its subset's nearest copy a
        /// block away that does, 0 where it is left out.
        pub blur_fill: u32,
        /// Blur: neighbours farther than this are left out. [Units: m]
        pub blur_distance: f32,
        /// Blur: neighbours whose normals' cosine is below this are left out.
        pub blur_normal: f32,
        /// Interleaved walks, the ratio estimator: 1 where the blur scales each pixel's
        /// unshadowed far light by its taps' visible share (`blur.wgsl`), 0 where it averages
        /// their light.
        pub ratio: u32,
        /// The ratio estimator's grid stride (`ratio.wgsl`; 1: every pixel).
        /// [Units: px]
        pub ratio_stride: u32,
    }
}

gpu_struct! {
    /// Constants of the CSSM passes (cssm.wgsl), one per mip level at 256-byte strides.
    pub struct CssmFrame {
        /// VALs.
        pub val_count: u32,
        /// Fourier terms K.
        pub terms: u32,
        /// Basis groups ⌈K/2⌉.
        pub groups: u32,
        /// Map side. [Units: texels]
        pub map_size: u32,
        /// Side of the mip level being written. [Units: texels]
        pub level_size: u32,
        /// Padding.
        pub _pad0: u32,
        /// Padding.
        pub _pad1: [u32; 2],
    }
}

gpu_struct! {
    /// Constants of the imperfect shadow maps and their gathers (ism.wgsl).
    pub struct IsmFrame {
        /// Maps, one per emitter.
        pub emitters: u32,
        /// Map side. [Units: texels]
        pub map_size: u32,
        /// Points in all.
        pub points: u32,
        /// Scene triangles.
        pub triangles: u32,
        /// 0 VPLs, 1 VALs.
        pub kind: u32,
        /// Seed of the points.
        pub seed: u32,
        /// Interleaving block side.
        pub block: u32,
        /// Interleaving subsets.
        pub subsets: u32,
        /// Radius a point stands for. [Units: m]
        pub point_radius: f32,
        /// Largest splat radius. [Units: texels]
        pub max_splat: f32,
        /// VAL centre offset. [Units: m]
        pub centre_offset: f32,
        /// Geometry-term clamp of VPLs. [Units: 1/m²]
        pub g_max: f32,
        /// Lookup depth bias. [Units: texels]
        pub bias: f32,
        /// Lookup normal offset. [Units: texels]
        pub normal_offset: f32,
        /// PCSS blocker samples (0: hard lookups).
        pub blocker_samples: u32,
        /// PCSS filter samples.
        pub filter_samples: u32,
        /// Parts a VAL's disk is lit as (1 or 5).
        pub disk_parts: u32,
        /// Padding.
        pub _pad0: u32,
        /// Padding.
        pub _pad1: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// One pull or push dispatch of the ISMs' pyramid (ism_maps.wgsl).
    pub struct IsmLevel {
        /// The level written.
        pub level: u32,
        /// Its side. [Units: texels]
        pub side: u32,
        /// Where it starts in the pyramid. [Units: words]
        pub offset: u32,
        /// Where the level it reads starts. [Units: words]
        pub other: u32,
    }
}

/// Every shared struct's layout, for the naga test.
pub fn all() -> Vec<StructLayout> {
    vec![
        Vpl::layout(),
        Val::layout(),
        Globals::layout(),
        Grid::layout(),
        Gate::layout(),
        Light::layout(),
        ShadowView::layout(),
        RsmSample::layout(),
        Batch::layout(),
        MapParams::layout(),
        ClusterFrame::layout(),
        GeometryCluster::layout(),
        ValFrame::layout(),
        ValGather::layout(),
        CssmFrame::layout(),
        LcFrame::layout(),
        IsmFrame::layout(),
        IsmLevel::layout(),
    ]
}

/// Uniforms bound at dynamic-free offsets are laid out at this stride (the adapter's minimum
/// uniform offset alignment is at most 256).
pub const UNIFORM_STRIDE: usize = 256;

/// `items` at [`UNIFORM_STRIDE`]-byte strides (at least one stride, zeroed).
pub fn strided<T: Pod>(items: &[T]) -> Vec<u8> {
    let mut bytes = vec![0u8; UNIFORM_STRIDE * items.len().max(1)];
    for (k, item) in items.iter().enumerate() {
        let b = bytemuck::bytes_of(item);
        bytes[k * UNIFORM_STRIDE..k * UNIFORM_STRIDE + b.len()].copy_from_slice(b);
    }
    bytes
}

//! A scene's geometry and textures on the GPU: triangles for the G-buffer and the lights'
//! shadow maps (position, normal, albedo, texture coordinates), the same split finely for
//! paraboloid maps, and the albedo textures as one sRGB array.

use glam::Vec3;
use visgate_formats::Scene;
use wgpu::util::DeviceExt;

use super::GpuContext;

/// Triangles drawn into paraboloid maps are split until no edge is longer than this fraction
/// of the scene's diagonal: the projection bends lines, and short edges bend little.
pub const VPL_SHADOW_MAX_EDGE: f32 = 1.0 / 24.0;

/// The scene's textures as layers of one sRGB array (resized, nearest, to the largest size up to
/// [`MAX_TEXTURE_SIZE`]; one white texel when there are none), and a nearest, repeating sampler.
pub fn albedo_array(ctx: &GpuContext, scene: &Scene) -> (wgpu::TextureView, wgpu::Sampler) {
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

/// The first vertex attribute, a position (f32 × 3 at location 0).
pub const POSITION: [wgpu::VertexAttribute; 1] = [wgpu::VertexAttribute {
    format: wgpu::VertexFormat::Float32x3,
    offset: 0,
    shader_location: 0,
}];

/// A vertex buffer of `stride`-byte vertices read for their [`POSITION`] alone (shadow and
/// paraboloid maps).
pub fn positions(stride: u64) -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: stride,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &POSITION,
    }
}

/// Vertex layout: position, normal, albedo, (u, v, texture layer or −1) — f32 × 3 each.
pub const VERTEX_STRIDE: u64 = 48;
/// Floats per vertex.
const VERTEX_FLOATS: usize = 12;
/// Textures are resized (nearest) to one layer size, at most this: the size the import filters
/// larger ones down to. [Units: texels]
pub const MAX_TEXTURE_SIZE: u32 = visgate_formats::scene::MAX_TEXTURE_TEXELS;

/// A scene's triangles on the GPU: for the G-buffer and shadow maps (position, normal,
/// albedo, texture coordinates), and subdivided for paraboloid maps.
pub struct Geometry {
    /// G-buffer and shadow-map vertices ([`VERTEX_STRIDE`]).
    pub vertices: wgpu::Buffer,
    /// Their count.
    pub vertex_count: u32,
    /// Paraboloid-map vertices (positions, split finely).
    pub vpl_vertices: wgpu::Buffer,
    /// Their count.
    pub vpl_vertex_count: u32,
    /// The scene's diagonal. [Units: m]
    pub size: f32,
    /// The triangles as storage for the imperfect shadow maps' points: 3 corners (xyz, w 0)
    /// each.
    pub triangles: wgpu::Buffer,
    /// Their cumulative area over the total (the last 1).
    pub area_cdf: wgpu::Buffer,
    /// Triangles in them (at least 1: a degenerate one for an empty scene).
    pub triangle_count: u32,
    /// The scene's surface area. [Units: m²]
    pub area_m2: f32,
}

/// The triangles as vec4 corners and their cumulative area over the total, and the total.
fn area_table(tris: &[[Vec3; 3]]) -> (Vec<[f32; 4]>, Vec<f32>, f32) {
    let mut corners = Vec::with_capacity(tris.len() * 3);
    let mut cdf = Vec::with_capacity(tris.len());
    let mut total = 0.0f64;
    for t in tris {
        corners.extend(t.iter().map(|p| p.extend(0.0).to_array()));
        total += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length() as f64;
        cdf.push(total);
    }
    if tris.is_empty() {
        return (vec![[0.0; 4]; 3], vec![1.0], 0.0);
    }
    let cdf = cdf.iter().map(|&c| (c / total) as f32).collect();
    (corners, cdf, total as f32)
}

impl Geometry {
    /// Uploads the triangles of every mesh of `scene` (degenerate ones left out).
    pub fn upload(d: &wgpu::Device, scene: &Scene) -> Geometry {
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
        let size = scene.diagonal_m();
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
        let (corners, cdf, area_m2) = area_table(&tris);
        let init = |label: &str, contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let (vertex, storage) = (wgpu::BufferUsages::VERTEX, wgpu::BufferUsages::STORAGE);
        Geometry {
            vertices: init("scene vertices", bytemuck::cast_slice(&data), vertex),
            vertex_count,
            vpl_vertices: init(
                "vpl map vertices (subdivided)",
                bytemuck::cast_slice(&vpl_data),
                vertex,
            ),
            vpl_vertex_count,
            size,
            triangles: init("ism triangles", bytemuck::cast_slice(&corners), storage),
            area_cdf: init("ism triangle areas", bytemuck::cast_slice(&cdf), storage),
            triangle_count: cdf.len() as u32,
            area_m2,
        }
    }
}

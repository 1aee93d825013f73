//! Ray casting against a scene's triangles on the CPU: a compressed wide BVH (obvhs' CWBVH,
//! built with PLOC) over every mesh, static and dynamic, with the per-triangle data the
//! reference renderer and the light-path VPLs need (shading normal, albedo).
//!
//! Surfaces are two-sided: [`Tracer::surface`] turns the normals towards the side the ray
//! came from.

use std::time::Duration;

use glam::{Vec2, Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use visgate_formats::Scene;

/// Offset of secondary rays from their surface, relative to the scene's size, or
/// [`RAY_EPSILON_ULPS`] float steps of its farthest coordinate where more. [Units: ratio]
pub const RAY_EPSILON_REL: f32 = 1e-5;

/// Secondary rays leave their surface by at least this many float steps (ulps) of the scene's
/// farthest coordinate: a hit point is rounded to them, so it may lie that far behind its
/// surface (the ajar door moved 3 km from the origin, where floats are 0.24 mm apart and its
/// 8 m × 1e-5 is 80 µm, shadowed itself in dots; now 1.4 mm). Levels near the origin keep
/// their size's offset. [Units: ulps]
pub const RAY_EPSILON_ULPS: f32 = 4.0;

/// The offset of secondary rays from their surface in a scene of bounds `lo`..`hi` (m).
pub fn ray_epsilon(lo: Vec3, hi: Vec3) -> f32 {
    let size = (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let far = lo.abs().max(hi.abs()).max_element();
    (size * RAY_EPSILON_REL).max(RAY_EPSILON_ULPS * f32::EPSILON * far)
}

/// Barycentric slack of [`intersect`]: a ray through a shared edge hits one of its triangles.
const EDGE_SLACK: f32 = 1e-6;

/// Möller–Trumbore, two-sided, with barycentric slack so that rays through shared edges and
/// vertices do not slip between triangles (obvhs' own test rejects −0.0). `INFINITY` on a miss.
fn intersect(tri: &Triangle, ray: &Ray) -> f32 {
    intersect_facing(tri, ray).0
}

/// [`intersect`]'s distance, and whether the ray meets the triangle's front (its vertices
/// counter-clockwise seen from the ray's origin, as the G-buffer's rasterizer counts them).
fn intersect_facing(tri: &Triangle, ray: &Ray) -> (f32, bool) {
    let e1 = tri.v1 - tri.v0;
    let e2 = tri.v2 - tri.v0;
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return (f32::INFINITY, false);
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri.v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = ray.direction.dot(q) * inv;
    if u < -EDGE_SLACK || v < -EDGE_SLACK || u + v > 1.0 + EDGE_SLACK {
        return (f32::INFINITY, false);
    }
    let t = e2.dot(q) * inv;
    // det = −direction · (e1 × e2): positive where the ray meets the front.
    if t >= ray.tmin && t <= ray.tmax {
        (t, det > 0.0)
    } else {
        (f32::INFINITY, false)
    }
}

/// How much nearer than a back face a front face must lie to be hidden by it, relative to the
/// distance: two faces of one plane turned apart (a floor's top and the ceiling under it,
/// modelled apart) meet a ray at distances that rounding orders either way, and the pixel
/// showed either face's albedo at random. The G-buffer draws back faces pushed as far back
/// (`gbuffer::BACK_FACE_BIAS`). [Units: ratio]
pub const FRONT_FACE_TIE: f32 = 3e-5;

/// A triangle's shading data.
#[derive(Debug, Clone, Copy)]
struct TriData {
    normals: [Vec3; 3],
    uvs: [Vec2; 3],
    material: u32,
}

/// A point on a surface, as seen from a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Position. [Units: m]
    pub position: Vec3,
    /// Unit shading normal (interpolated), on the side the ray came from.
    pub normal: Vec3,
    /// Unit geometric normal, on the side the ray came from.
    pub geometric_normal: Vec3,
    /// Linear diffuse albedo (material × texture).
    pub albedo: Vec3,
    /// Distance along the ray. [Units: m]
    pub t: f32,
}

/// The scene's triangles in a BVH.
pub struct Tracer {
    tris: Vec<Triangle>,
    data: Vec<TriData>,
    bvh: CwBvh,
    albedo: Vec<Vec3>,
    textures: Vec<Option<u32>>,
    scene_textures: Vec<visgate_formats::scene::Texture>,
    /// Offset of secondary rays. [Units: m]
    pub epsilon_m: f32,
}

impl Tracer {
    /// Builds the BVH over every mesh of `scene` (degenerate triangles are skipped).
    pub fn new(scene: &Scene) -> Tracer {
        let mut tris = Vec::new();
        let mut data = Vec::new();
        for m in &scene.meshes {
            for (t, idx) in m.triangles.iter().enumerate() {
                let p = idx.map(|i| m.positions[i as usize]);
                if (p[1] - p[0]).cross(p[2] - p[0]).length_squared() <= 0.0 {
                    continue;
                }
                tris.push(Triangle {
                    v0: p[0].into(),
                    v1: p[1].into(),
                    v2: p[2].into(),
                });
                data.push(TriData {
                    normals: idx.map(|i| m.normals.get(i as usize).copied().unwrap_or(Vec3::ZERO)),
                    uvs: idx.map(|i| m.uvs.get(i as usize).copied().unwrap_or(Vec2::ZERO)),
                    material: m.material.get(t).copied().unwrap_or(0),
                });
            }
        }
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        Tracer {
            tris,
            data,
            bvh,
            albedo: scene.materials.iter().map(|m| m.albedo).collect(),
            textures: scene.materials.iter().map(|m| m.texture).collect(),
            scene_textures: scene.textures.clone(),
            epsilon_m: ray_epsilon(lo, hi),
        }
    }

    /// Number of triangles in the BVH.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// The nearest hit along `origin + t·dir`, `t` in `(t_min, t_max)`; `dir` need not be unit.
    /// With `front_first`, a front face within [`FRONT_FACE_TIE`] behind a back face is the hit
    /// (what the eye sees of two faces of one plane); without, whichever is nearer.
    fn hit(
        &self,
        origin: Vec3,
        dir: Vec3,
        (t_min, t_max): (f32, f32),
        front_first: bool,
    ) -> Option<(usize, f32)> {
        if self.tris.is_empty() {
            return None;
        }
        // The compressed BVH's slab test misses some axis-aligned rays (a zero component
        // meets a flat box as 0 × ∞): nudge zero components off zero, keeping their sign.
        let dir = Vec3::from_array(dir.to_array().map(|c| {
            if c.abs() < 1e-12 {
                1e-12f32.copysign(c)
            } else {
                c
            }
        }));
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), t_min, t_max);
        let mut hit = RayHit::none();
        let tri = |id: u32| &self.tris[self.bvh.primitive_indices[id as usize] as usize];
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, id| {
            let (t, front) = intersect_facing(tri(id as u32), ray);
            if front_first && !front && t.is_finite() {
                t * (1.0 + FRONT_FACE_TIE)
            } else {
                t
            }
        });
        found.then(|| {
            let t = if front_first {
                // The hit's own distance, not the one it was ranked by.
                intersect(tri(hit.primitive_id), &ray)
            } else {
                hit.t
            };
            (
                self.bvh.primitive_indices[hit.primitive_id as usize] as usize,
                t,
            )
        })
    }

    /// The surface first hit by the ray from `origin` along unit `dir`, beyond `epsilon_m`; of
    /// two faces of one plane, the one turned towards `origin` ([`FRONT_FACE_TIE`]).
    pub fn trace(&self, origin: Vec3, dir: Vec3) -> Option<Surface> {
        let (i, t) = self.hit(origin, dir, (self.epsilon_m, f32::INFINITY), true)?;
        Some(self.surface(i, origin + dir * t, dir, t))
    }

    /// Whether anything lies between `a` and `b` (both ends excluded by `epsilon_m`).
    pub fn occluded(&self, a: Vec3, b: Vec3) -> bool {
        let d = b - a;
        let len = d.length();
        if len <= 2.0 * self.epsilon_m {
            return false;
        }
        let dir = d / len;
        self.hit(a, dir, (self.epsilon_m, len - self.epsilon_m), false)
            .is_some()
    }

    fn surface(&self, i: usize, p: Vec3, dir: Vec3, t: f32) -> Surface {
        let tri = &self.tris[i];
        let (a, b, c) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
        let n = (b - a).cross(c - a);
        let area2 = n.length_squared();
        let bary = {
            let w1 = (p - a).cross(c - a).dot(n) / area2;
            let w2 = (b - a).cross(p - a).dot(n) / area2;
            Vec3::new(1.0 - w1 - w2, w1, w2)
        };
        let d = &self.data[i];
        let mut ng = n.normalize();
        let mut ns = (d.normals[0] * bary.x + d.normals[1] * bary.y + d.normals[2] * bary.z)
            .normalize_or_zero();
        if ns == Vec3::ZERO {
            ns = ng;
        }
        if ng.dot(dir) > 0.0 {
            ng = -ng;
        }
        if ns.dot(ng) < 0.0 {
            ns = -ns;
        }
        let uv = d.uvs[0] * bary.x + d.uvs[1] * bary.y + d.uvs[2] * bary.z;
        Surface {
            position: p,
            normal: ns,
            geometric_normal: ng,
            albedo: self.albedo_at(d.material, uv),
            t,
        }
    }

    /// Material albedo times the texture (nearest texel, repeat), linear.
    fn albedo_at(&self, material: u32, uv: Vec2) -> Vec3 {
        let base = self
            .albedo
            .get(material as usize)
            .copied()
            .unwrap_or(Vec3::splat(0.5));
        let Some(Some(ti)) = self.textures.get(material as usize) else {
            return base;
        };
        let Some(tex) = self.scene_textures.get(*ti as usize) else {
            return base;
        };
        if tex.width == 0 || tex.height == 0 {
            return base;
        }
        let x = ((uv.x.rem_euclid(1.0)) * tex.width as f32) as u32 % tex.width;
        let y = ((uv.y.rem_euclid(1.0)) * tex.height as f32) as u32 % tex.height;
        let k = ((y * tex.width + x) * 4) as usize;
        let srgb = |v: u8| {
            let c = v as f32 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        base * Vec3::new(
            srgb(tex.rgba8[k]),
            srgb(tex.rgba8[k + 1]),
            srgb(tex.rgba8[k + 2]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_leave_their_surface_by_the_levels_size_near_the_origin_and_float_steps_far_from_it() {
        // An 8 m level at the origin: 80 µm; Sponza (37 m, 19 m out): 0.37 mm.
        assert_eq!(
            ray_epsilon(Vec3::ZERO, Vec3::splat(8.0)),
            8.0 * RAY_EPSILON_REL
        );
        let sponza = ray_epsilon(Vec3::new(-19.2, -1.3, -11.8), Vec3::new(18.0, 14.3, 11.1));
        assert!((sponza - 37.2 * RAY_EPSILON_REL).abs() < 1e-9, "{sponza}");
        // The same 8 m level 3 km out: 4 ε × 3008 m, 1.4 mm.
        let far = ray_epsilon(Vec3::splat(3000.0), Vec3::splat(3008.0));
        assert!((far - 4.0 * f32::EPSILON * 3008.0).abs() < 1e-9, "{far}");
        assert!(far > 10.0 * 8.0 * RAY_EPSILON_REL);
    }
}

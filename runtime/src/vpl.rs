//! Virtual point lights (Keller's instant radiosity): one struct for both sources, and the CPU
//! source — light paths traced from the primary lights, a VPL at every hit.
//!
//! A VPL is a cosine emitter: at distance `d`, towards a receiver whose direction makes angle
//! `θ_v` with the VPL's normal and `θ_x` with the receiver's, it gives the receiver
//! irradiance `Φ/π · cos θ_v cos θ_x / d²`, so a Lambertian receiver of albedo ρ reflects
//! `L = ρ/π · Φ/π · G`, `G = cos θ_v cos θ_x / d²` (see [`gather_one`]).
//!
//! **Paths.** Each light emits `N_light` paths, its share of `N` by power; path `k` of a light
//! leaves in the direction of Halton point `k` (bases 2, 3, scrambled by the seed: a
//! Cranley–Patterson rotation), mapped uniformly to the sphere (point light) or to the spot's
//! cone, carrying `Φ_path = I(ω) · Ω / N_light` (`Ω` the solid angle sampled). At each hit a VPL
//! takes `Φ_path · ρ` and the normal facing the path; for `bounces > 1` the path goes on in a
//! cosine-distributed direction (Halton bases 5, 7, then 11, 13, …) with `Φ_path ← Φ_path · ρ`.
//! Deterministic for a fixed seed and scene: the VPLs do not flicker. The list is in
//! [`crate::vpl_order`]'s order, so that each interleaving subset holds all directions.

use std::f32::consts::PI;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use visgate_formats::Light;

use crate::RenderError;
use crate::cpu::tracer::Tracer;
use crate::lights::{intensity_towards, light_position, light_power};

/// One virtual point light, laid out for the GPU (48 bytes, 16-byte aligned fields).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Vpl {
    /// Position. [Units: m]
    pub position: [f32; 3],
    /// Padding (0).
    pub _pad0: f32,
    /// Unit normal of the surface it lies on, on the lit side.
    pub normal: [f32; 3],
    /// Padding (0).
    pub _pad1: f32,
    /// Flux leaving it, per RGB channel. [Units: W]
    pub flux: [f32; 3],
    /// Padding (0).
    pub _pad2: f32,
}

impl Vpl {
    /// A VPL at `position` with `normal` and `flux`.
    pub fn new(position: Vec3, normal: Vec3, flux: Vec3) -> Vpl {
        Vpl {
            position: position.to_array(),
            _pad0: 0.0,
            normal: normal.to_array(),
            _pad1: 0.0,
            flux: flux.to_array(),
            _pad2: 0.0,
        }
    }
}

/// How VPL light is gathered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GatherParams {
    /// Upper bound of the geometry term `cos θ_v cos θ_x / d²`, against the singularity near a
    /// VPL. The energy it removes is measured by [`clamp_loss`]. [Units: 1/m²] [Limit: > 0]
    pub g_max: f32,
}

impl Default for GatherParams {
    fn default() -> Self {
        GatherParams { g_max: 10.0 }
    }
}

/// How the geometry-term clamp `g_max` is chosen: an absolute bound, or one that follows the
/// scene's size so that a level modelled at any scale gives the same image up to scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GeometryClamp {
    /// `g_max` itself. [Units: 1/m²] [Limit: > 0]
    PerSquareMetre(f32),
    /// The clamp starts at this fraction `f` of the scene's bounding diagonal `L`:
    /// `g_max = 1 / (f·L)²`. [Limit: > 0, finite]
    DiagonalFraction(f32),
}

impl Default for GeometryClamp {
    /// `DiagonalFraction(0.025)`: 10 m⁻² in the built-in four rooms (L = 12.6 m), 130 m⁻² in
    /// the Cornell box (3.5 m), 1.2 m⁻² in Crytek Sponza (37 m).
    fn default() -> Self {
        GeometryClamp::DiagonalFraction(0.025)
    }
}

impl GeometryClamp {
    /// `g_max` for a scene whose bounding diagonal is `diagonal` metres.
    pub fn g_max(&self, diagonal: f32) -> Result<f32, RenderError> {
        let g = match *self {
            GeometryClamp::PerSquareMetre(g) => g,
            GeometryClamp::DiagonalFraction(f) => {
                if !(f > 0.0 && f.is_finite()) {
                    return Err(RenderError::Param(format!(
                        "geometry-term clamp distance {f} must be a fraction of the diagonal > 0"
                    )));
                }
                if !(diagonal > 0.0 && diagonal.is_finite()) {
                    return Err(RenderError::Param(format!(
                        "the scene's diagonal is {diagonal} m: a clamp relative to it needs \
                         geometry; give an absolute --g-max"
                    )));
                }
                1.0 / (f * diagonal).powi(2)
            }
        };
        if !(g > 0.0 && g.is_finite()) {
            return Err(RenderError::Param(format!(
                "geometry-term clamp {g} 1/m² must be > 0 and finite"
            )));
        }
        Ok(g)
    }
}

/// Radiance reflected at `x` (normal `n`, albedo ρ) from one VPL, visibility not included.
pub fn gather_one(vpl: &Vpl, x: Vec3, n: Vec3, albedo: Vec3, params: &GatherParams) -> Vec3 {
    let d = Vec3::from(vpl.position) - x;
    let d2 = d.length_squared();
    if d2.is_nan() || d2 <= 0.0 {
        return Vec3::ZERO;
    }
    let w = d / d2.sqrt();
    let cos_x = n.dot(w);
    let cos_v = -Vec3::from(vpl.normal).dot(w);
    if cos_x <= 0.0 || cos_v <= 0.0 {
        return Vec3::ZERO;
    }
    let g = (cos_x * cos_v / d2).min(params.g_max);
    albedo / PI * Vec3::from(vpl.flux) / PI * g
}

/// Parameters of the light-path VPLs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathParams {
    /// Paths to emit over all lights. [Limit: 0..=16M]
    pub paths: u32,
    /// VPL generations per path (1: one-bounce indirect). [Limit: 1..=16]
    pub bounces: u32,
    /// Seed of the sequence's rotation.
    pub seed: u64,
}

/// Radical inverse of `i` in base `b`.
pub fn radical_inverse(mut i: u64, b: u64) -> f32 {
    let (mut inv, mut f) = (0f64, 1f64 / b as f64);
    while i > 0 {
        inv += (i % b) as f64 * f;
        i /= b;
        f /= b as f64;
    }
    inv as f32
}

/// Point `i` of the 2D Halton sequence in bases `(b0, b1)`, rotated by `shift` modulo 1.
pub fn halton2(i: u64, b0: u64, b1: u64, shift: Vec2) -> Vec2 {
    let p = Vec2::new(radical_inverse(i, b0), radical_inverse(i, b1)) + shift;
    p - p.floor()
}

const PRIMES: [u64; 34] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131, 137, 139,
];

/// Rotation of dimension pair `k` for `seed` (splitmix64): a Cranley–Patterson shift of the
/// Halton points (zero for seed 0).
pub fn seed_shift(seed: u64, k: u64) -> Vec2 {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    if seed == 0 {
        return Vec2::ZERO;
    }
    let a = mix(seed ^ (k * 2 + 1));
    let b = mix(a);
    Vec2::new(
        (a >> 40) as f32 / (1u64 << 24) as f32,
        (b >> 40) as f32 / (1u64 << 24) as f32,
    )
}

/// An orthonormal basis around unit `n` (Duff et al. 2017).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// Direction in the cone of half-angle `max_rad` around unit `axis`, uniform in solid angle.
fn cone_dir(u: Vec2, axis: Vec3, max_rad: f32) -> Vec3 {
    let cos_max = max_rad.cos();
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = basis(axis);
    (t * phi.cos() * sin_t + b * phi.sin() * sin_t + axis * cos_t).normalize()
}

/// Cosine-distributed direction around unit `n`.
fn cosine_dir(u: Vec2, n: Vec3) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = basis(n);
    (t * r * phi.cos() + b * r * phi.sin() + n * (1.0 - u.x).max(0.0).sqrt()).normalize()
}

/// `n` split between `lights` by power (luminance), the rounding remainder to the strongest;
/// all zeros when no light emits.
pub fn share_by_power(lights: &[Light], n: u32) -> Vec<u32> {
    let power: Vec<f32> = lights
        .iter()
        .map(|l| {
            light_power(l)
                .dot(Vec3::new(0.2126, 0.7152, 0.0722))
                .max(0.0)
        })
        .collect();
    let total: f32 = power.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        return vec![0; lights.len()];
    }
    let mut share: Vec<u32> = power
        .iter()
        .map(|p| (n as f64 * (*p / total) as f64).floor() as u32)
        .collect();
    let given: u32 = share.iter().sum();
    if let Some(best) = (0..power.len()).max_by(|&a, &b| power[a].total_cmp(&power[b])) {
        share[best] += n - given;
    }
    share
}

/// Traces light paths from `lights` and returns a VPL at every hit (see the module notes).
pub fn path_vpls(
    tracer: &Tracer,
    lights: &[Light],
    params: &PathParams,
) -> Result<Vec<Vpl>, RenderError> {
    if params.paths > 1 << 24 {
        return Err(RenderError::Param(format!(
            "{} VPL paths: at most {} are supported",
            params.paths,
            1 << 24
        )));
    }
    if !(1..=16).contains(&params.bounces) {
        return Err(RenderError::Param(format!(
            "{} bounces: give 1 to 16",
            params.bounces
        )));
    }
    let share = share_by_power(lights, params.paths);
    if share.iter().all(|&n| n == 0) {
        return Ok(Vec::new());
    }
    let mut by_light = Vec::with_capacity(lights.len());
    for (li, light) in lights.iter().enumerate() {
        let n = share[li];
        if n == 0 {
            continue;
        }
        let origin = light_position(light);
        let (axis, max_rad) = match *light {
            Light::Point { .. } => (Vec3::Y, PI),
            Light::Spot {
                direction,
                cutoff_rad,
                ..
            } => (direction, cutoff_rad.min(PI)),
        };
        let solid_angle = 2.0 * PI * (1.0 - max_rad.cos());
        let per_light: Vec<Vec<Vpl>> = {
            use rayon::prelude::*;
            (0..n as u64)
                .into_par_iter()
                .map(|k| {
                    let mut out = Vec::new();
                    let u = halton2(k, 2, 3, seed_shift(params.seed ^ li as u64, 0));
                    let mut dir = cone_dir(u, axis, max_rad);
                    let mut flux = intensity_towards(light, dir) * solid_angle / n as f32;
                    let mut from = origin;
                    for bounce in 0..params.bounces as usize {
                        if flux.max_element() <= 0.0 {
                            break;
                        }
                        let Some(s) = tracer.trace(from, dir) else {
                            break;
                        };
                        flux *= s.albedo;
                        out.push(Vpl::new(s.position, s.normal, flux));
                        if bounce + 1 == params.bounces as usize {
                            break;
                        }
                        let pair = 1 + bounce;
                        let (b0, b1) = (PRIMES[2 * pair % 34], PRIMES[(2 * pair + 1) % 34]);
                        let u =
                            halton2(k, b0, b1, seed_shift(params.seed ^ li as u64, pair as u64));
                        dir = cosine_dir(u, s.normal);
                        from = s.position + s.geometric_normal * tracer.epsilon_m;
                    }
                    out
                })
                .collect()
        };
        by_light.push(per_light);
    }
    Ok(crate::vpl_order::interleaving_order(by_light))
}

/// Fraction of the gathered energy the clamp removes at `x`: `1 − clamped / unclamped` over
/// `vpls` (0 when nothing arrives).
pub fn clamp_loss(vpls: &[Vpl], x: Vec3, n: Vec3, params: &GatherParams) -> f32 {
    let unclamped = GatherParams {
        g_max: f32::INFINITY,
    };
    let (mut a, mut b) = (0f64, 0f64);
    for v in vpls {
        a += gather_one(v, x, n, Vec3::ONE, params).x as f64;
        b += gather_one(v, x, n, Vec3::ONE, &unclamped).x as f64;
    }
    if b > 0.0 { (1.0 - a / b) as f32 } else { 0.0 }
}

/// What a user reads when `asked` light paths made no VPL (every light outside the level, or
/// its positions written in the wrong units), `then` saying what follows for them.
pub fn no_light_paths(asked: u32, then: &str) -> String {
    format!(
        "no light path from the scene's lights met the geometry (0 VPLs of {asked} asked): \
         {then}. Is each light inside the level? (A scene file's positions are in its units, \
         `metres_per_unit`.)"
    )
}

//! Direct light from the scene's point and spot lights, with the radiometry of DESIGN.md
//! (Mitsuba 3's): radiant intensity `I` in W/sr; a spot is 1 inside its beam, linear in angle
//! to 0 at its cutoff; Lambertian surfaces reflect `L = ρ/π · I · cos θ / d²`.

use std::f32::consts::PI;

use glam::Vec3;
use visgate_formats::Light;

use crate::cpu::tracer::{Surface, Tracer};

/// Falloff of a spot light at angle `angle_rad` from its axis.
pub fn spot_falloff(angle_rad: f32, beam_rad: f32, cutoff_rad: f32) -> f32 {
    if angle_rad <= beam_rad {
        1.0
    } else if angle_rad >= cutoff_rad || cutoff_rad <= beam_rad {
        0.0
    } else {
        (cutoff_rad - angle_rad) / (cutoff_rad - beam_rad)
    }
}

/// Position of a light.
pub fn light_position(light: &Light) -> Vec3 {
    match *light {
        Light::Point { position, .. } | Light::Spot { position, .. } => position,
    }
}

/// Radiant intensity of `light` towards unit direction `dir` (from the light). [Units: W/sr]
pub fn intensity_towards(light: &Light, dir: Vec3) -> Vec3 {
    match *light {
        Light::Point { intensity, .. } => intensity,
        Light::Spot {
            direction,
            intensity,
            cutoff_rad,
            beam_rad,
            ..
        } => {
            let angle = direction.dot(dir).clamp(-1.0, 1.0).acos();
            intensity * spot_falloff(angle, beam_rad, cutoff_rad)
        }
    }
}

/// Total power a light emits. [Units: W]
pub fn light_power(light: &Light) -> Vec3 {
    match *light {
        Light::Point { intensity, .. } => intensity * 4.0 * PI,
        Light::Spot {
            intensity,
            cutoff_rad,
            beam_rad,
            ..
        } => {
            // ∫ falloff dω over the cone, by the midpoint rule in angle (exact enough: the
            // integrand is smooth in θ).
            let n = 256;
            let h = cutoff_rad / n as f32;
            let s: f32 = (0..n)
                .map(|k| {
                    let th = (k as f32 + 0.5) * h;
                    spot_falloff(th, beam_rad, cutoff_rad) * th.sin()
                })
                .sum();
            intensity * 2.0 * PI * s * h
        }
    }
}

/// Radiance reflected at `s` towards the viewer from all lights, with shadow rays.
pub fn direct_radiance(tracer: &Tracer, lights: &[Light], s: &Surface) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for light in lights {
        let lp = light_position(light);
        let d = lp - s.position;
        let d2 = d.length_squared();
        if d2 <= 0.0 {
            continue;
        }
        let w = d / d2.sqrt();
        let cos = s.normal.dot(w);
        if cos <= 0.0 || s.geometric_normal.dot(w) <= 0.0 {
            continue;
        }
        let i = intensity_towards(light, -w);
        if i == Vec3::ZERO
            || tracer.occluded(s.position + s.geometric_normal * tracer.epsilon_m, lp)
        {
            continue;
        }
        sum += s.albedo / PI * i * cos / d2;
    }
    sum
}

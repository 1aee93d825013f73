//! Suns: a scene TOML's `[[sun]]` and a glTF's directional light. visgate has no light at
//! infinity, so a sun is placed as a spot light far along its direction ([`sun_spot`]): on the
//! line through the static geometry's centre, [`SUN_DISTANCE_DIAGONALS`] of its box's diagonals
//! away (within the distance at which a light is named as misplaced), its full beam just
//! covering the box, its intensity set so that the irradiance at the centre is the sun's. Its
//! rays are then parallel within 3° and its irradiance within about ±11 % across the level
//! (the inverse square from the near side to the far one); the load says where it went.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::scene::Light;

/// A sun as a scene TOML states it (`[[sun]]`), or as a glTF's directional light is read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunDesc {
    /// Display name (a glTF's light's; a TOML's `sun N` where none is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Where its light travels, in the file's axes (need not be unit length).
    pub direction: [f64; 3],
    /// Irradiance on a surface facing it, W/m² per RGB channel (a glTF's colour × lux / 683).
    pub irradiance: [f32; 3],
}

/// How far from the level's centre a sun's spot stands, in diagonals of the static geometry's
/// box: under [`crate::placement::FAR_DIAGONALS`], at which a light is named as misplaced.
pub const SUN_DISTANCE_DIAGONALS: f32 = 9.5;

/// The spot light a sun shining along `direction` (world, non-zero) with `irradiance` (W/m²)
/// becomes over a level whose static geometry spans `bounds` (world, metres).
pub fn sun_spot((lo, hi): (Vec3, Vec3), direction: Vec3, irradiance: Vec3) -> Light {
    let (centre, diagonal) = (0.5 * (lo + hi), (hi - lo).length().max(1e-6));
    let distance = SUN_DISTANCE_DIAGONALS * diagonal;
    let dir = direction.normalize();
    // The box's bounding sphere seen from the spot, and a little more.
    let beam_rad = (0.5 / SUN_DISTANCE_DIAGONALS).asin() * 1.05;
    Light::Spot {
        position: centre - dir * distance,
        direction: dir,
        intensity: irradiance * distance * distance,
        cutoff_rad: beam_rad * 1.1,
        beam_rad,
    }
}

/// What the load says of a sun placed by [`sun_spot`] as `light`.
pub fn placed_note(
    file: &std::path::Path,
    name: &str,
    irradiance: [f32; 3],
    light: &Light,
) -> String {
    let p = light.position();
    format!(
        "{}: sun '{name}' (irradiance {:.3} {:.3} {:.3} W/m²) placed as a spot light at ({:.1}, \
         {:.1}, {:.1}) m, {SUN_DISTANCE_DIAGONALS} of the level's diagonals from its centre, \
         aimed along its direction: visgate has no light at infinity; its rays are parallel \
         within 3° and its irradiance within about ±11 % across the level",
        file.display(),
        irradiance[0],
        irradiance[1],
        irradiance[2],
        p.x,
        p.y,
        p.z
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sun_s_spot_gives_its_irradiance_at_the_centre_and_covers_the_box() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(7.0, 3.0, 6.0));
        let dir = Vec3::new(1.0, -2.0, 0.5);
        let Light::Spot {
            position,
            direction,
            intensity,
            cutoff_rad,
            beam_rad,
        } = sun_spot((lo, hi), dir, Vec3::new(1.0, 2.0, 3.0))
        else {
            panic!("a spot")
        };
        let centre = 0.5 * (lo + hi);
        let to_centre = centre - position;
        assert!((to_centre.normalize() - dir.normalize()).length() < 1e-5);
        assert!((to_centre.length() - 9.5 * (hi - lo).length()).abs() < 1e-3);
        assert!((direction - dir.normalize()).length() < 1e-6);
        // Nearer the box than the distance at which a light is named as misplaced.
        let off = crate::placement::outside_by(position, (lo, hi));
        assert!(
            off < crate::placement::FAR_DIAGONALS * (hi - lo).length(),
            "{off}"
        );
        let e = intensity / to_centre.length_squared();
        assert!(
            (e - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-5,
            "{e}"
        );
        // Every corner of the box within the full beam.
        for k in 0..8 {
            let c = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let angle = (c - position).normalize().dot(direction).acos();
            assert!(
                angle < beam_rad && beam_rad < cutoff_rad,
                "corner {k}: {angle}"
            );
        }
    }
}

//! A scene description's values against their documented limits, a section at a time: no
//! value is clamped silently, and the first that is out names itself.

use std::path::Path;

use crate::desc::{
    CameraDesc, LightDesc, MaterialOverride, MeshDesc, Orbit, SceneDesc, SpotLightDesc,
};
use crate::error::SceneError;
use crate::sun::SunDesc;

impl SceneDesc {
    /// Checks every value against its documented limits; no value is clamped silently.
    pub fn validate(&self, file: &Path) -> Result<(), SceneError> {
        let bad = |what: String| SceneError::Invalid {
            file: file.to_path_buf(),
            what,
        };
        if !(self.metres_per_unit.is_finite() && self.metres_per_unit > 0.0) {
            return Err(bad(format!(
                "metres_per_unit = {} must be a finite number > 0",
                self.metres_per_unit
            )));
        }
        for (i, m) in self.meshes.iter().enumerate() {
            check_mesh(i + 1, m).map_err(bad)?;
        }
        for o in &self.materials {
            check_material(o).map_err(bad)?;
        }
        for (i, l) in self.lights.iter().enumerate() {
            check_light(i + 1, l).map_err(bad)?;
        }
        check_cameras(&self.cameras).map_err(bad)?;
        for (i, sun) in self.suns.iter().enumerate() {
            check_sun(i + 1, sun).map_err(bad)?;
        }
        Ok(())
    }
}

/// Whether every coordinate is finite.
fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Mesh `n`: a finite transform without a zero scale; a moving mesh is dynamic, and moves by
/// keys or an orbit, not both.
fn check_mesh(n: usize, m: &MeshDesc) -> Result<(), String> {
    let s = m.scale.as_vec();
    let what = format!("mesh {n} ({})", m.path.display());
    if !finite3(&m.translate) || !finite3(&m.rotate_deg) || !finite3(&s) {
        return Err(format!("{what} has a non-finite transform"));
    }
    if s.contains(&0.0) {
        return Err(format!("{what} has a zero scale, which flattens it"));
    }
    if (!m.animate.is_empty() || m.orbit.is_some()) && m.is_static {
        return Err(format!(
            "{what} moves (animate/orbit) but is static: set static = false (static meshes are \
             baked and must not move)"
        ));
    }
    if !m.animate.is_empty() && m.orbit.is_some() {
        return Err(format!("{what}: give animate or orbit, not both"));
    }
    check_keys(
        m.animate
            .iter()
            .map(|k| (k.t, finite3(&k.translate) && finite3(&k.rotate_deg))),
        &what,
    )?;
    check_orbit(m.orbit.as_ref(), &what)
}

/// A material override's albedo: every channel in [0, 1].
fn check_material(o: &MaterialOverride) -> Result<(), String> {
    if o.albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
        return Err(format!(
            "material override '{}': albedo {:?} must have every channel in [0, 1]",
            o.name, o.albedo
        ));
    }
    Ok(())
}

/// Light `n`: a finite position, keys or an orbit (not both), a finite intensity ≥ 0, and a
/// spot's aim and angles.
fn check_light(n: usize, l: &LightDesc) -> Result<(), String> {
    let (position, intensity) = match l {
        LightDesc::Point(p) => (&p.position, &p.intensity),
        LightDesc::Spot(s) => (&s.position, &s.intensity),
    };
    if !finite3(position) {
        return Err(format!("light {n}: position must be finite"));
    }
    let (animate, orbit) = match l {
        LightDesc::Point(p) => (&p.animate, &p.orbit),
        LightDesc::Spot(s) => (&s.animate, &s.orbit),
    };
    let what = format!("light {n}");
    if !animate.is_empty() && orbit.is_some() {
        return Err(format!("{what}: give animate or orbit, not both"));
    }
    check_keys(
        animate.iter().map(|k| {
            let target_ok = k.target.is_none_or(|t| finite3(&t) && t != k.position);
            (k.t, finite3(&k.position) && target_ok)
        }),
        &what,
    )?;
    check_orbit(orbit.as_ref(), &what)?;
    if intensity.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(format!(
            "light {n}: intensity {intensity:?} W/sr must be finite and >= 0"
        ));
    }
    match l {
        LightDesc::Spot(s) => check_spot(n, s),
        LightDesc::Point(_) => Ok(()),
    }
}

/// Spot light `n`: a target or a direction (one), finite and not degenerate; a cutoff
/// half-angle in (0, 90] and a beam within it.
fn check_spot(n: usize, s: &SpotLightDesc) -> Result<(), String> {
    match (s.target, s.direction) {
        (Some(_), Some(_)) => {
            return Err(format!(
                "spot light {n}: give either target or direction, not both"
            ));
        }
        (None, None) => return Err(format!("spot light {n}: give a target or a direction")),
        (Some(t), None) => {
            if !finite3(&t) || t == s.position {
                return Err(format!(
                    "spot light {n}: target must be finite and differ from the position"
                ));
            }
        }
        (None, Some(d)) => {
            if !finite3(&d) || d == [0.0; 3] {
                return Err(format!(
                    "spot light {n}: direction must be finite and non-zero"
                ));
            }
        }
    }
    if !(s.cutoff_deg > 0.0 && s.cutoff_deg <= 90.0) {
        return Err(format!(
            "spot light {n}: cutoff_deg = {} must be in (0, 90] (a half-angle)",
            s.cutoff_deg
        ));
    }
    if !(s.beam_deg > 0.0 && s.beam_deg <= s.cutoff_deg) {
        return Err(format!(
            "spot light {n}: beam_deg = {} must be in (0, cutoff_deg = {}]",
            s.beam_deg, s.cutoff_deg
        ));
    }
    Ok(())
}

/// The cameras: each name once, an eye and a target finite and apart, an up finite and
/// non-zero where given, a horizontal field of view in (0, 180).
fn check_cameras(cameras: &[CameraDesc]) -> Result<(), String> {
    let mut names = std::collections::BTreeSet::new();
    for c in cameras {
        if !names.insert(c.name.as_str()) {
            return Err(format!("two cameras are named '{}'", c.name));
        }
        if !finite3(&c.eye) || !finite3(&c.target) || c.eye == c.target {
            return Err(format!(
                "camera '{}': eye and target must be finite and differ",
                c.name
            ));
        }
        if let Some(up) = c.up
            && (!finite3(&up) || up == [0.0; 3])
        {
            return Err(format!(
                "camera '{}': up must be finite and non-zero",
                c.name
            ));
        }
        if !(c.fov_deg > 0.0 && c.fov_deg < 180.0) {
            return Err(format!(
                "camera '{}': fov_deg = {} must be in (0, 180) (full horizontal angle)",
                c.name, c.fov_deg
            ));
        }
    }
    Ok(())
}

/// Sun `n`: a finite non-zero direction and a finite irradiance ≥ 0.
fn check_sun(n: usize, sun: &SunDesc) -> Result<(), String> {
    let ok = finite3(&sun.direction)
        && sun.direction != [0.0; 3]
        && sun.irradiance.iter().all(|x| x.is_finite() && *x >= 0.0);
    if !ok {
        return Err(format!(
            "sun {n}: direction must be finite and non-zero, irradiance (W/m²) finite and not \
             negative"
        ));
    }
    Ok(())
}

/// Keys (time, values finite) must have finite, strictly increasing times and finite values.
fn check_keys(keys: impl Iterator<Item = (f64, bool)>, what: &str) -> Result<(), String> {
    let mut last = f64::NEG_INFINITY;
    for (i, (t, finite)) in keys.enumerate() {
        if !t.is_finite() || t <= last {
            return Err(format!(
                "{what}: key {} at t = {t} s: times must be finite and increase from key to key",
                i + 1
            ));
        }
        if !finite {
            return Err(format!(
                "{what}: key {} has a non-finite value (or a target on the position)",
                i + 1
            ));
        }
        last = t;
    }
    Ok(())
}

/// An orbit needs a finite centre, a finite radius ≥ 0 and a finite period > 0.
fn check_orbit(orbit: Option<&Orbit>, what: &str) -> Result<(), String> {
    let Some(o) = orbit else { return Ok(()) };
    let ok = o.centre.iter().all(|x| x.is_finite())
        && o.radius.is_finite()
        && o.radius >= 0.0
        && o.period_s.is_finite()
        && o.period_s > 0.0
        && o.phase_deg.is_finite();
    if !ok {
        return Err(format!(
            "{what}: orbit needs a finite centre, radius >= 0, period_s > 0 and a finite phase \
             (got radius {}, period_s {})",
            o.radius, o.period_s
        ));
    }
    Ok(())
}

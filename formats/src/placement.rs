//! Lights and cameras far from the level. A scene TOML's positions are in its own units
//! (`metres_per_unit`), so a level modelled in centimetres with its lights written in metres
//! puts every light a hundredth of the way to the origin: the renders are black, no light
//! path meets the geometry, and every method agrees with the black reference to the digit.
//! Nothing fails; the scene says so when it is read instead.

use glam::{DVec3, Vec3};

use crate::desc::{LightDesc, SceneDesc, UpAxis};
use crate::scene::{Scene, SceneSpace};

/// How far outside the static geometry's box a light or a camera may stand before it is
/// named when its numbers, read as metres in a scene of other units, would put it inside: a
/// lamp outside a window stands within one. [Units: ratio, the box's diagonals]
pub const NEAR_DIAGONALS: f32 = 1.0;

/// How far outside it one is named whatever its numbers: a slip of units in a scene of metres
/// (centimetres: 100 times as far from the origin, inches 39) puts a light that far; a camera
/// looking at a building from across the street, an aerial view, stand within. [Units: ratio,
/// the box's diagonals]
pub const FAR_DIAGONALS: f32 = 10.0;

/// How near the origin every light and camera must stand, where each read as metres would
/// stand inside the level, to be named as a slip of units in a level that holds the origin
/// (modelled from a room's corner or its middle): a lamp and a camera written in metres in a
/// level of centimetres that starts at the origin stand a hundredth of the way there, inside
/// the level's box or at its edge, and the far rule says nothing. [Units: ratio, the box's
/// diagonals]
pub const ORIGIN_DIAGONALS: f32 = 0.02;

/// A level whose farthest coordinate is more than this many times its longest side from the
/// origin is named ([`far_from_origin`]): rays and walks leave their surfaces by 4 float
/// steps of that coordinate, and past this the steps near a tenth of a percent of the level
/// (the ajar door, 8 m, renders as at the origin 6 km out, 750×; 30 km out, 3,750×, the
/// reference lights a line along a corner and the GPU's direct light is 0.72 of it on one
/// view). [Units: ratio]
pub const FAR_FROM_ORIGIN_RATIO: f32 = 2048.0;

/// A warning where `scene`'s static geometry lies more than [`FAR_FROM_ORIGIN_RATIO`] times its
/// longest side from the origin: 32-bit positions there are coarse for its walls.
pub fn far_from_origin(scene: &Scene) -> Option<String> {
    let (lo, hi) = scene.static_bounds().or_else(|| scene.bounds())?;
    let size = (hi - lo).max_element();
    let far = lo.abs().max(hi.abs()).max_element();
    // One float step at `far`: 2^(exponent − 23).
    let step_mm = 1e3 * (far.log2().floor() - 23.0).exp2();
    (far > FAR_FROM_ORIGIN_RATIO * size).then(|| {
        format!(
            "the level lies {far:.0} m from the origin, {:.0}× its {size:.1} m length: 32-bit \
             floats there are {step_mm:.2} mm apart, and rays and walks leave surfaces by four \
             of them, so light may pass walls thinner than that and corners (the ajar door, 8 m \
             long, 30 km out: a line of light along a corner in the reference, the door's lit \
             edge dotted on the GPU; 6 km out it renders as at the origin). Move the level near the origin: in a \
             scene TOML, `translate` its meshes and move its lights and cameras with them",
            far / size,
        )
    })
}

/// Distance from `p` to the box `lo..hi` (0 inside).
pub fn outside_by(p: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}

/// A warning for each light and camera of `scene` (as assembled from `desc`) that lies more
/// than [`NEAR_DIAGONALS`] of the static geometry's box outside it where its numbers, read as
/// metres, would put it inside (with the numbers to write), or more than [`FAR_DIAGONALS`]
/// whatever they are; and, where every one stands within [`ORIGIN_DIAGONALS`] of the origin
/// and each read as metres would stand inside the box, for each of those too (a slip of units
/// in a level that holds the origin).
pub fn far_placements(scene: &Scene, desc: &SceneDesc) -> Vec<String> {
    let Some(bounds) = scene.static_bounds().or_else(|| scene.bounds()) else {
        return Vec::new();
    };
    let diagonal = (bounds.1 - bounds.0).length();
    let space = SceneSpace::new(desc.up, desc.metres_per_unit);
    let mpu = desc.metres_per_unit;
    // The unit the numbers were likely written in where the scene states another: metres in
    // a scene of other units, centimetres in one of metres (an engine's numbers in a level
    // that sets no `metres_per_unit`); the file's numbers that stand where they say, where
    // that is inside the level.
    let (slip_unit, slip_m) = if mpu == 1.0 {
        ("centimetres", 0.01)
    } else {
        ("metres", 1.0)
    };
    let slip = |units: [f64; 3]| {
        let fix = (DVec3::from(units) * (slip_m / mpu)).to_array();
        (outside_by(space.point(fix), bounds) == 0.0).then_some((slip_unit, fix))
    };
    let lights = desc.lights.iter().enumerate().map(|(i, l)| {
        let (kind, at) = match l {
            LightDesc::Point(p) => ("point", p.position),
            LightDesc::Spot(s) => ("spot", s.position),
        };
        (format!("{kind} light {i}"), at)
    });
    let cameras = desc
        .cameras
        .iter()
        .map(|c| (format!("camera '{}'", c.name), c.eye));
    // Numbers written as metres with the other axis up (a Y-up engine's positions in a Z-up
    // file): the file's units that stand where they say, where that is inside the level.
    let other = match desc.up {
        UpAxis::Y => UpAxis::Z,
        UpAxis::Z => UpAxis::Y,
    };
    let to_units = space.matrix.inverse();
    let axes_slip = |units: [f64; 3]| {
        let world = SceneSpace::new(other, 1.0).point(units);
        let fix = to_units.transform_point3(world.as_dvec3()).to_array();
        (mpu != 1.0 && outside_by(world, bounds) == 0.0).then_some((other, fix))
    };
    let placed: Vec<Placed> = lights
        .chain(cameras)
        .map(|(what, units)| {
            let p = space.point(units);
            Placed {
                what,
                units,
                p,
                off: outside_by(p, bounds),
                fix: slip(units),
                axes_fix: axes_slip(units),
            }
        })
        .collect();
    let far = |x: &Placed| match x.fix {
        Some(_) => x.off > NEAR_DIAGONALS * diagonal,
        None => x.off > FAR_DIAGONALS * diagonal,
    };
    // Every one a slip near the origin (of units, or of units and axes), numbers in a larger
    // unit than the file's: none stands where the level is.
    let at_origin = mpu < 1.0
        && !placed.is_empty()
        && placed
            .iter()
            .all(|x| x.origin_fix().is_some() && x.p.length() <= ORIGIN_DIAGONALS * diagonal);
    placed
        .iter()
        .filter_map(|x| {
            if far(x) {
                Some(far_warning(x, bounds, mpu))
            } else {
                let fix = x.origin_fix().filter(|_| at_origin)?;
                Some(origin_warning(x, fix, diagonal, mpu))
            }
        })
        .collect()
}

/// A light or a camera as [`far_placements`] found it.
struct Placed {
    /// What it is (`point light 0`, `camera 'door'`).
    what: String,
    /// Its position as written. [Units: the file's]
    units: [f64; 3],
    /// Its position. [Units: m]
    p: Vec3,
    /// How far outside the level's box it stands. [Units: m]
    off: f32,
    /// The unit those written were likely in (metres; centimetres in a scene of metres) and
    /// the numbers to write then.
    fix: Option<(&'static str, [f64; 3])>,
    /// Where those written were metres with the other axis up: that axis and the numbers.
    axes_fix: Option<(UpAxis, [f64; 3])>,
}

impl Placed {
    /// How the numbers were likely written, read for the origin rule, and the numbers to write:
    /// the unit slip's reading, else the axes'.
    fn origin_fix(&self) -> Option<(String, [f64; 3])> {
        let units = self.fix.map(|(unit, f)| (unit.to_string(), f));
        units.or_else(|| {
            self.axes_fix
                .map(|(up, f)| (format!("metres with {} up", axis_name(up)), f))
        })
    }
}

/// The warning for `placed`, outside the box `(lo, hi)` of a level of `mpu` metres per unit.
fn far_warning(placed: &Placed, (lo, hi): (Vec3, Vec3), mpu: f64) -> String {
    let Placed {
        what,
        units,
        p,
        off,
        fix,
        ..
    } = placed;
    let mut out = format!(
        "{what} at ({:.2}, {:.2}, {:.2}) m stands {off:.1} m outside the level (its geometry spans \
         ({:.2}, {:.2}, {:.2}) .. ({:.2}, {:.2}, {:.2}) m)",
        p.x, p.y, p.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
    );
    if mpu != 1.0 {
        out += &format!("; a scene file's positions are in its units (metres_per_unit = {mpu})");
    } else if fix.is_some() {
        out += "; a scene file's positions are in metres where it sets no metres_per_unit";
    }
    match fix {
        Some((unit, f)) => {
            out += &format!(
                ", so if ({}) are {unit}, write ({}) to put it inside",
                fmt3(DVec3::from(*units)),
                fmt3(DVec3::from(*f))
            );
        }
        None => {
            out += ". If it stands there on purpose (a distant sun, an aerial view), ignore this"
        }
    }
    out
}

/// The warning for `placed`, one of a scene's lights and cameras that all stand near the
/// origin of a level `diagonal` m across, of `mpu` metres per unit, where each read as `read`
/// says (`Placed::origin_fix`) would stand inside it, at `fix` in the file's numbers.
fn origin_warning(
    placed: &Placed,
    (read, fix): (String, [f64; 3]),
    diagonal: f32,
    mpu: f64,
) -> String {
    let Placed { what, units, p, .. } = placed;
    format!(
        "{what} at ({:.3}, {:.3}, {:.3}) m stands {:.2} m from the origin, as every light and \
         camera of the scene does, in a level {diagonal:.1} m across; a scene file's positions \
         are in its units (metres_per_unit = {mpu}) and axes, so if ({}) are {read}, write \
         ({}) to put it where they say",
        p.x,
        p.y,
        p.z,
        p.length(),
        fmt3(DVec3::from(*units)),
        fmt3(DVec3::from(fix)),
    )
}

/// An up axis as a scene file names it.
fn axis_name(up: UpAxis) -> &'static str {
    match up {
        UpAxis::Y => "Y",
        UpAxis::Z => "Z",
    }
}

/// A point's coordinates to four decimals and six significant figures (4200, not the
/// 4199.9998 that a scale by 1000 of 4.2 makes in f32).
fn fmt3(p: DVec3) -> String {
    p.to_array().map(fmt_coordinate).join(", ")
}

fn fmt_coordinate(c: f64) -> String {
    let rounded = (c * 1e4).round() / 1e4;
    let six: f64 = format!("{rounded:.5e}").parse().unwrap_or(rounded);
    // + 0.0: no "-0".
    format!("{}", six + 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_print_to_six_figures_without_float_noise() {
        let p = DVec3::new(4199.9998, -0.00001, 0.123_456_789);
        assert_eq!(fmt3(p), "4200, 0, 0.1235");
        assert_eq!(
            fmt3(DVec3::new(-12.5, 1.0e6 + 0.3, 3.0)),
            "-12.5, 1000000, 3"
        );
    }

    use crate::import::{ImportedModel, RawMesh};
    use std::path::Path;

    /// A 8 × 3 × 4 m room 2.5 km from the origin, modelled in centimetres, with a light and a
    /// camera written at `light` and `eye` (file units).
    fn scene(light: [f64; 3], eye: [f64; 3]) -> (Scene, SceneDesc) {
        room_at(DVec3::new(250_000.0, 1_000.0, -80_000.0), light, eye)
    }

    /// The room in centimetres with its first corner at `o` (file units).
    fn room_at(o: DVec3, light: [f64; 3], eye: [f64; 3]) -> (Scene, SceneDesc) {
        room_in(0.01, o, light, eye)
    }

    /// The room in a file of `mpu` metres per unit with its first corner at `o` (file units).
    fn room_in(mpu: f64, o: DVec3, light: [f64; 3], eye: [f64; 3]) -> (Scene, SceneDesc) {
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                let c = DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64);
                (o + c * DVec3::new(8.0, 3.0, 4.0) / mpu).as_vec3()
            })
            .collect();
        let model = ImportedModel {
            meshes: vec![RawMesh {
                name: "room".into(),
                positions: corners,
                normals: vec![],
                uvs: vec![],
                triangles: vec![[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5]],
                material: 0,
            }],
            materials: vec![crate::Material {
                name: "wall".into(),
                albedo: Vec3::splat(0.5),
                texture: None,
            }],
            ..ImportedModel::default()
        };
        let text = format!(
            "metres_per_unit = {mpu:?}\n[[mesh]]\npath = \"room.obj\"\n\
             [[light]]\ntype = \"point\"\nposition = {light:?}\nintensity = [1, 1, 1]\n\
             [[camera]]\nname = \"door\"\neye = {eye:?}\ntarget = [250400.0, 1100.0, -79800.0]\nfov_deg = 75\n"
        );
        let desc = SceneDesc::from_toml(&text, Path::new("room.toml")).expect("desc");
        let scene = Scene::assemble(&desc, vec![model], Path::new("room.toml")).expect("scene");
        (scene, desc)
    }

    #[test]
    fn a_level_hundreds_of_its_lengths_from_the_origin_is_named() {
        // The 8 m room 2.5 km out (312×) says nothing; 30 km out (3,750×) it is named.
        let (near, _) = scene(
            [250_400.0, 1_150.0, -79_800.0],
            [250_100.0, 1_160.0, -79_900.0],
        );
        assert_eq!(far_from_origin(&near), None);
        let o = DVec3::new(3_000_000.0, 0.0, 3_000_000.0);
        let (far, _) = room_at(
            o,
            [3_000_400.0, 150.0, 3_000_200.0],
            [3_000_100.0, 160.0, 3_000_100.0],
        );
        let w = far_from_origin(&far).expect("named");
        assert!(
            w.starts_with("the level lies 30008 m from the origin, 3751× its 8.0 m length")
                && w.contains("1.95 mm apart")
                && w.contains("`translate`"),
            "{w}"
        );
    }

    #[test]
    fn positions_written_in_metres_in_a_centimetre_scene_are_named_with_the_fix() {
        // Written in metres: both a hundredth of the way to the origin.
        let (s, d) = scene([2506.5, 12.2, -798.8], [2500.6, 11.6, -799.6]);
        let w = far_placements(&s, &d);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].starts_with("point light 0 at (25.07, 0.12, -7.99) m"),
            "{}",
            w[0]
        );
        assert!(
            w[0].contains("if (2506.5, 12.2, -798.8) are metres, write (250650, 1220, -79880)"),
            "{}",
            w[0]
        );
        assert!(w[1].starts_with("camera 'door'"), "{}", w[1]);
        // Written in centimetres: nothing to say.
        let (s, d) = scene(
            [250_650.0, 1_220.0, -79_880.0],
            [250_060.0, 1_160.0, -79_960.0],
        );
        assert!(far_placements(&s, &d).is_empty());
        // A lamp outside a window, within a diagonal of the room: nothing to say either.
        let (s, d) = scene(
            [250_650.0, 1_220.0, -79_000.0],
            [250_060.0, 1_160.0, -79_960.0],
        );
        assert!(far_placements(&s, &d).is_empty());
        // Three diagonals away, not a slip (an aerial view): nothing to say.
        let (s, d) = scene(
            [250_650.0, 1_220.0, -79_880.0],
            [250_400.0, 4_000.0, -79_800.0],
        );
        assert!(
            far_placements(&s, &d).is_empty(),
            "{:?}",
            far_placements(&s, &d)
        );
        // Far, but not a units slip: named without the fix.
        let (s, d) = scene([0.0, 0.0, 0.0], [250_060.0, 1_160.0, -79_960.0]);
        let w = far_placements(&s, &d);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("(metres_per_unit = 0.01)") && !w[0].contains("write"),
            "{}",
            w[0]
        );
    }

    #[test]
    fn positions_written_in_metres_in_a_centimetre_level_at_the_origin_are_named_with_the_fix() {
        // The room from the origin: written in metres, the lamp and the camera stand inside
        // its box or at its edge, within a few centimetres of its corner.
        let o = DVec3::ZERO;
        let (s, d) = room_at(o, [2.5, 2.0, 1.5], [0.5, 1.6, 0.5]);
        let w = far_placements(&s, &d);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].starts_with(
                "point light 0 at (0.025, 0.020, 0.015) m stands 0.04 m from the origin"
            ) && w[0].contains("if (2.5, 2, 1.5) are metres, write (250, 200, 150)"),
            "{}",
            w[0]
        );
        assert!(w[1].starts_with("camera 'door'"), "{}", w[1]);
        // Written in centimetres: nothing to say.
        let (s, d) = room_at(o, [250.0, 200.0, 150.0], [50.0, 160.0, 50.0]);
        assert!(far_placements(&s, &d).is_empty());
        // A lamp in the corner on purpose, the camera across the room: not every one is near
        // the origin, nothing to say.
        let (s, d) = room_at(o, [2.5, 2.0, 1.5], [700.0, 160.0, 300.0]);
        assert!(far_placements(&s, &d).is_empty());
        // Near the origin but, read as metres either way up, outside the room (3.5 m up in a
        // 3 m room; 3.5 m along −z): not a slip that puts them inside, nothing to say.
        let (s, d) = room_at(o, [2.5, 3.5, 1.5], [0.5, 3.5, 0.5]);
        assert!(far_placements(&s, &d).is_empty());
        // Written in metres with Z up (a Z-up tool's numbers in this Y-up file): read Y up
        // they stand under the floor, read Z up inside; named with the numbers for Y up.
        let (s, d) = room_at(o, [2.5, -3.5, 2.0], [0.5, -0.5, 1.6]);
        let w = far_placements(&s, &d);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].contains("if (2.5, -3.5, 2) are metres with Z up, write (250, 200, 350)"),
            "{}",
            w[0]
        );
    }

    #[test]
    fn positions_written_in_centimetres_in_a_scene_of_metres_are_named_with_the_fix() {
        // A room in metres from the origin, its lamp and camera written in centimetres: 100
        // times as far, named with the numbers in metres.
        let (s, d) = room_in(1.0, DVec3::ZERO, [250.0, 200.0, 150.0], [50.0, 160.0, 50.0]);
        let w = far_placements(&s, &d);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].contains("if (250, 200, 150) are centimetres, write (2.5, 2, 1.5)"),
            "{}",
            w[0]
        );
        // Written in metres: nothing to say; near the origin on purpose: nothing either (the
        // origin rule reads numbers as a larger unit than the file's only).
        let (s, d) = room_in(1.0, DVec3::ZERO, [2.5, 2.0, 1.5], [0.5, 1.6, 0.5]);
        assert!(far_placements(&s, &d).is_empty());
        let (s, d) = room_in(1.0, DVec3::ZERO, [0.05, 0.05, 0.05], [0.1, 0.1, 0.1]);
        assert!(
            far_placements(&s, &d).is_empty(),
            "{:?}",
            far_placements(&s, &d)
        );
    }
}

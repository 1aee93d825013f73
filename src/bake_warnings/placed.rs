//! Where the cameras and lights stand, as the bake's empty-space report tells it: inside
//! closed geometry (a lamp's shade, a hollow wall), outside the level (in the void behind its
//! walls, or beyond the grid of a sealed level), or in a part no light is in (a doorway the
//! voxels close); and the report's readings these warnings share.

use serde_json::Value;
use visgate_formats::vgate::GridMeta;
use visgate_preprocess::bake::is_camera_seed;

use super::{MIXED_RATIO, resolution_for};

/// The cameras and lights a part of the report holds.
pub(super) fn seeds_of(c: &Value) -> Vec<String> {
    let list = c["seeds"].as_array().into_iter().flatten();
    list.filter_map(|s| s.as_str().map(str::to_string))
        .collect()
}

/// Whether part `c` of the report reaches the grid's bounds: its box within a voxel and a half
/// of the grid's faces, next to its solid border (the outside).
pub(super) fn reaches_bounds(c: &Value, grid: &GridMeta) -> bool {
    let at = |key: &str, a: usize| c[key][a].as_f64().unwrap_or(0.0);
    let (o, vs) = (grid.origin_m, grid.voxel_size_m as f64);
    (0..3).any(|a| {
        at("bounds_min_m", a) <= o[a] as f64 + 1.5 * vs
            || at("bounds_max_m", a) >= o[a] as f64 + (grid.dims[a] as f64 - 1.5) * vs
    })
}

/// Whether a kept part of the empty space holds cameras or lights, does not reach the bounds,
/// and the triangles around it turn their backs to it: the inside of a closed mesh — a lamp's
/// bulb or shade, a hollow wall or column a camera was put in. (A room joined to the void by a
/// window may see its walls' backs too, but it reaches the bounds.) Their backs must outvote
/// their fronts by [`MIXED_RATIO`]: under it the faces are wound both ways ([`mixed_winding`]
/// says so), and a sealed level whose walls were wound at random, 146 backs to 142 fronts
/// around its rooms, was told that its lamp lit the inside of a bulb.
pub(super) fn enclosed_seed_part(c: &Value, grid: &GridMeta) -> bool {
    seeded_part(c) && outvoted(c, 1) && !reaches_bounds(c, grid)
}

/// Whether part `c` of the report is kept and holds cameras or lights.
pub(super) fn seeded_part(c: &Value) -> bool {
    c["kept"] == true && !seeds_of(c).is_empty()
}

/// Whether the triangles around part `c` of the report turn their backs to it (`side` 1) or
/// face it (`side` 0) [`MIXED_RATIO`] times as often as the other way.
pub(super) fn outvoted(c: &Value, side: usize) -> bool {
    let v = |k: usize| c["faced_by"][k].as_u64().unwrap_or(0);
    let (by, against) = (v(side), v(1 - side));
    by > against && by as f64 >= MIXED_RATIO * against as f64
}

/// Whether part `c` holds cameras or lights and is a room: its triangles face it.
pub(super) fn seeded_room(c: &Value) -> bool {
    seeded_part(c) && outvoted(c, 0)
}

/// Whether a kept part holds cameras or lights, reaches the bounds and sees the backs of the
/// triangles around it while another part with cameras or lights sees their fronts: the void
/// around the level, behind its walls. A camera written a few centimetres outside a wall of a
/// cave whose faces look in was there: the bake kept the void for it, its backs made the
/// level's faces read "wound both ways", and the camera was told to bake at a finer
/// resolution to reach the light.
pub(super) fn outside_seed_part(c: &Value, comps: &[Value], grid: &GridMeta) -> bool {
    seeded_part(c) && outvoted(c, 1) && reaches_bounds(c, grid) && comps.iter().any(seeded_room)
}

/// `one` for a single thing, `many` for several.
pub(super) fn by_count<'a>(n: usize, one: &'a str, many: &'a str) -> &'a str {
    if n == 1 { one } else { many }
}

/// A warning for each part that holds cameras or lights outside the level
/// ([`outside_seed_part`]), and [`beyond_the_grid`]'s. Each names the rooms' span, so that
/// they can be moved in.
pub(super) fn outside_seeds(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
    let comps = empty_space["components"].as_array().map_or(&[][..], |c| c);
    let rooms: Vec<&Value> = comps.iter().filter(|c| seeded_room(c)).collect();
    let in_rooms: Vec<String> = rooms.iter().flat_map(|c| seeds_of(c)).collect();
    let faced: u64 = rooms
        .iter()
        .map(|r| r["faced_by"][0].as_u64().unwrap_or(0))
        .sum();
    let mut out: Vec<String> = comps
        .iter()
        .filter(|c| outside_seed_part(c, comps, grid))
        .map(|c| {
            let seeds = seeds_of(c);
            format!(
                "{} outside the level: in the void around the level, which reaches the scene's \
                 bounds and sees the backs of the {} triangles beside it, while the {faced} \
                 triangles beside {} face them. {} Move {}{}, or if the level is meant to be \
                 seen from outside, ignore this",
                join_and(&seeds),
                c["faced_by"][1].as_u64().unwrap_or(0),
                join_words(&in_rooms),
                if seeds.iter().all(|s| is_camera_seed(s)) {
                    "A camera there sees the level from behind its walls."
                } else {
                    "A light there lights the backs of the walls, not the rooms."
                },
                by_count(seeds.len(), "it", "them"),
                rooms_span(&rooms)
            )
        })
        .collect();
    out.extend(beyond_the_grid(empty_space, comps, grid));
    out
}

/// A warning for the cameras and lights beyond the grid where the level is sealed (no room
/// reaches the grid's bounds): the bake keeps no space for them, and a camera 30 cm behind
/// the ajar door's wall was dropped with nothing said. A level open to the outside is seen
/// and lit from there (the Cornell box's camera, `sun-window`'s lamp beyond its window), and
/// nothing is said.
pub(super) fn beyond_the_grid(
    empty_space: &Value,
    comps: &[Value],
    grid: &GridMeta,
) -> Option<String> {
    let beyond: Vec<String> = empty_space["seeds_outside_grid"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s.as_str().map(str::to_string))
        .collect();
    let kept: Vec<&Value> = comps.iter().filter(|c| seeded_part(c)).collect();
    let sealed = !kept.is_empty() && !kept.iter().any(|c| reaches_bounds(c, grid));
    if beyond.is_empty() || !sealed {
        return None;
    }
    let lo = grid.origin_m.map(f64::from);
    let hi = std::array::from_fn(|a| lo[a] + grid.dims[a] as f64 * grid.voxel_size_m as f64);
    let n = beyond.len();
    let does = if beyond.iter().all(|s| is_camera_seed(s)) {
        by_count(n, "it sees", "they see")
    } else {
        by_count(n, "it lights", "they light")
    };
    Some(format!(
        "{} outside the level: beyond the grid the bake spans around its geometry ({} .. {} m), \
         and none of the level's rooms reaches that grid's bounds, so the bake kept no space for \
         {} and {does} the backs of its walls alone. Move {}{}, or if {} meant to be outside, \
         ignore this",
        join_and(&beyond),
        metres(&json_point(lo)),
        metres(&json_point(hi)),
        by_count(n, "it", "them"),
        by_count(n, "it", "them"),
        rooms_span(&kept),
        by_count(n, "it is", "they are"),
    ))
}

/// ` inside (the rooms span A .. B m)`: the box of `rooms`' bounds, or ` inside` where there
/// are none.
pub(super) fn rooms_span(rooms: &[&Value]) -> String {
    let span = |k: &str, pick: fn(f64, f64) -> f64| {
        let at = |a: usize| rooms.iter().filter_map(|c| c[k][a].as_f64()).reduce(pick);
        Some([at(0)?, at(1)?, at(2)?])
    };
    match (
        span("bounds_min_m", f64::min),
        span("bounds_max_m", f64::max),
    ) {
        (Some(lo), Some(hi)) => format!(
            " inside (the rooms span {} .. {} m)",
            metres(&json_point(lo)),
            metres(&json_point(hi))
        ),
        _ => " inside".to_string(),
    }
}

/// A point `[x, y, z]` as the report writes one.
pub(super) fn json_point(p: [f64; 3]) -> Value {
    Value::from(p.to_vec())
}

/// A warning for each part that holds cameras or lights inside closed geometry
/// ([`enclosed_seed_part`]): a light lights that mesh's inside alone (the built-in ajar door
/// with a 20 cm box around its lamp: 8 voxels, every render black), a camera sees its inside.
pub(super) fn enclosed_seeds(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
    let comps = empty_space["components"].as_array().into_iter().flatten();
    comps
        .filter(|c| enclosed_seed_part(c, grid))
        .map(|c| {
            let seeds = seeds_of(c);
            let what = if seeds.iter().all(|s| is_camera_seed(s)) {
                "it sees that mesh's inside alone (a hollow wall, column or object?). Move the \
                 camera out of the mesh"
            } else {
                "it lights that mesh's inside alone (a lamp's bulb or shade?) and no light \
                 leaves it. Move the light out of the mesh, or leave the mesh out of the \
                 scene's static geometry"
            };
            format!(
                "{} inside closed geometry: the {} triangles around its pocket of {} empty \
                 voxels ({} .. {} m) turn their backs to it, so {what}",
                join_and(&seeds),
                c["faced_by"][1].as_u64().unwrap_or(0),
                c["voxels"].as_u64().unwrap_or(0),
                metres(&c["bounds_min_m"]),
                metres(&c["bounds_max_m"])
            )
        })
        .collect()
}

/// A warning for each kept part of the empty space that holds a camera and no light while
/// another kept part holds one: sealed off from the lights at this resolution (a doorway
/// closed by the voxels), it gets no indirect light from them under gates or the VPL modes,
/// though the level lets light through.
pub(super) fn cut_off_cameras(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
    let Some(comps) = empty_space["components"].as_array() else {
        return Vec::new();
    };
    let is_camera = |s: &String| is_camera_seed(s);
    // Parts inside closed geometry are said by enclosed_seeds: no resolution opens them.
    // Parts outside the level are said by outside_seeds: no resolution joins them either.
    let open = |c: &&Value| {
        c["kept"] == true && !enclosed_seed_part(c, grid) && !outside_seed_part(c, comps, grid)
    };
    let kept: Vec<Vec<String>> = comps.iter().filter(open).map(seeds_of).collect();
    if !kept.iter().any(|s| s.iter().any(|x| !is_camera(x))) {
        return Vec::new(); // no light in any open kept part: nothing is cut off from one
    }
    // Twice this resolution: a doorway a voxel wide is then two.
    let res = resolution_for(grid, 1.0, 2.0);
    kept.iter()
        .filter(|s| !s.is_empty() && s.iter().all(is_camera))
        .map(|cams| {
            format!(
                "{} in a part of the empty space that no light is in: at this resolution \
                 (voxels of {:.3} m) it is sealed off from the lights, so gates and the VPL \
                 modes give it no indirect light from them. A doorway or window narrower than \
                 about two voxels closes: bake at --resolution {res} or more, or if the part \
                 is meant to be sealed, ignore this",
                join_and(cams),
                grid.voxel_size_m
            )
        })
        .collect()
}

/// A point of the JSON report, `(x, y, z)` to the centimetre.
pub(super) fn metres(p: &Value) -> String {
    let c = |a: usize| p[a].as_f64().unwrap_or(f64::NAN);
    format!("({:.2}, {:.2}, {:.2})", c(0), c(1), c(2))
}

/// `a`, `a and b`, `a, b and c`, with "is"/"are" after.
pub(super) fn join_and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [_] => format!("{} is", join_words(items)),
        _ => format!("{} are", join_words(items)),
    }
}

/// `a`, `a and b`, `a, b and c`.
pub(super) fn join_words(items: &[String]) -> String {
    match items {
        [rest @ .., last] if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.concat(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::mixed_winding;
    use super::super::tests::grid;
    use super::*;
    use serde_json::json;

    #[test]
    fn a_camera_sealed_off_from_every_light_is_named_and_one_with_a_light_is_not() {
        let g = grid(24, 4.5);
        let comp = |seeds: &[&str], kept: bool| json!({ "seeds": seeds, "kept": kept });
        let cut = json!({ "components": [
            comp(&["camera 'lit'", "point light 0"], true),
            comp(&["camera 'hall'"], true),
            comp(&[], false),
        ]});
        let w = cut_off_cameras(&cut, &g);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].starts_with("camera 'hall' is in a part") && w[0].contains("--resolution 48"));
        // Both cameras with the light: nothing. No light in any kept part: nothing cut off.
        let together = json!({ "components": [
            comp(&["camera 'lit'", "camera 'hall'", "spot light 1"], true),
        ]});
        assert!(cut_off_cameras(&together, &g).is_empty());
        let unlit =
            json!({ "components": [comp(&["camera 'a'"], true), comp(&["camera 'b'"], true)]});
        assert!(cut_off_cameras(&unlit, &g).is_empty());
        let two = json!({ "components": [
            comp(&["point light 0"], true),
            comp(&["camera 'a'", "camera 'b'", "camera 'c'"], true),
        ]});
        let w = cut_off_cameras(&two, &g);
        assert!(
            w[0].starts_with("camera 'a', camera 'b' and camera 'c' are in"),
            "{w:?}"
        );
    }

    #[test]
    fn a_light_inside_closed_geometry_is_said_and_not_taken_for_a_closed_doorway() {
        let g = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 0.0625,
            dims: [130, 50, 66],
        };
        let part = |seeds: &[&str], faced: [u64; 2], voxels: u64| {
            json!({ "seeds": seeds, "faced_by": faced, "kept": true, "voxels": voxels,
                    "bounds_min_m": [6.5, 2.4, 3.2], "bounds_max_m": [6.7, 2.6, 3.4] })
        };
        // The ajar door with a closed box around its lamp.
        let es = json!({ "components": [
            part(&["camera 'main'", "camera 'door'"], [49, 0], 352_888),
            part(&["point light 0"], [0, 8], 8),
        ]});
        let w = enclosed_seeds(&es, &g);
        assert!(
            w.len() == 1 && w[0].starts_with("point light 0 is inside closed geometry: the 8"),
            "{w:?}"
        );
        assert!(cut_off_cameras(&es, &g).is_empty());
        // A light in a room the doorway closes at this resolution: that warning, not this one.
        let sealed = json!({ "components": [
            part(&["camera 'main'"], [49, 0], 352_888),
            part(&["point light 0"], [30, 0], 40_000),
        ]});
        assert!(enclosed_seeds(&sealed, &g).is_empty());
        assert_eq!(cut_off_cameras(&sealed, &g).len(), 1);
        // The four rooms with a camera put inside a hollow wall: said as such, not taken for
        // a room behind a closed doorway, nor its backs for faces wound both ways.
        let in_wall = json!({ "components": [
            part(&["camera 'main'", "point light 0"], [88, 0], 605_452),
            part(&["camera 'inwall'"], [0, 92], 104_048),
        ]});
        let w = enclosed_seeds(&in_wall, &g);
        assert!(
            w.len() == 1 && w[0].starts_with("camera 'inwall' is inside closed geometry"),
            "{w:?}"
        );
        assert!(w[0].contains("Move the camera out"), "{w:?}");
        assert!(cut_off_cameras(&in_wall, &g).is_empty());
        assert!(mixed_winding(&in_wall, &g).is_none());
        // A sealed level whose walls face their rooms and turn their backs about as often:
        // wound both ways, not the inside of a closed mesh.
        let office = json!({ "components": [
            part(&["camera 'lit'", "camera 'away'", "point light 0"], [142, 146], 294_216),
        ]});
        assert!(enclosed_seeds(&office, &g).is_empty());
        let w = mixed_winding(&office, &g).expect("wound both ways");
        assert!(w.contains("146 turn their backs"), "{w}");
        // Two-sided walls modelled as two faces back to back vote both ways too.
        assert!(w.contains("doubled back to back"), "{w}");
        // A room joined to the void by a window reaches the bounds: its backs say nothing.
        let mut window = part(&["point light 0"], [0, 288], 40_000);
        window["bounds_min_m"] = json!([0.0, 0.0, 0.0]);
        assert!(enclosed_seeds(&json!({ "components": [window] }), &g).is_empty());
    }

    #[test]
    fn a_camera_or_light_in_the_void_around_the_level_is_said_and_nothing_else() {
        let g = GridMeta {
            origin_m: [-4.25, -0.8, -3.94],
            voxel_size_m: 0.158,
            dims: [130, 38, 61],
        };
        let part = |seeds: &[&str], faced: [u64; 2], min: [f64; 3], max: [f64; 3]| {
            json!({ "seeds": seeds, "faced_by": faced, "kept": true, "voxels": 1000,
                    "bounds_min_m": min, "bounds_max_m": max })
        };
        let (in_lo, in_hi) = ([-3.94, -0.49, -3.62], [16.02, 4.89, 5.41]);
        let rooms = part(
            &["camera 'beyond'", "point light 0"],
            [37012, 0],
            in_lo,
            in_hi,
        );
        // The cave with camera 'lit' written a few centimetres outside its wall.
        let void = part(
            &["camera 'lit'"],
            [0, 36855],
            [-4.09, -0.65, -3.78],
            [16.2, 5.1, 5.6],
        );
        let cave = json!({ "components": [rooms.clone(), void.clone()] });
        let w = outside_seeds(&cave, &g);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with("camera 'lit' is outside the level")
                && w[0].contains("backs of the 36855 triangles")
                && w[0].contains("beside camera 'beyond' and point light 0 face them")
                && w[0].contains("from behind its walls")
                && w[0].contains("span (-3.94, -0.49, -3.62) .. (16.02, 4.89, 5.41) m"),
            "{w:?}"
        );
        // Its backs are not taken for faces wound both ways, nor its part for a room behind
        // a doorway closed at this resolution.
        assert!(mixed_winding(&cave, &g).is_none());
        assert!(cut_off_cameras(&cave, &g).is_empty());
        // A lamp under the floor: said as a light.
        let lamp = part(
            &["point light 1"],
            [0, 36855],
            [-4.09, -0.65, -3.78],
            [16.2, 5.1, 5.6],
        );
        let w = outside_seeds(&json!({ "components": [rooms.clone(), lamp] }), &g);
        assert!(
            w.len() == 1 && w[0].contains("lights the backs of the walls"),
            "{w:?}"
        );
        // Alone in the void (a level seen from outside, or lit through a window in one part):
        // nothing, for there is no room to compare it with.
        assert!(outside_seeds(&json!({ "components": [void.clone()] }), &g).is_empty());
        // A pocket that does not reach the bounds is inside closed geometry, not outside.
        let pocket = part(
            &["camera 'lit'"],
            [0, 500],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
        );
        let es = json!({ "components": [rooms.clone(), pocket] });
        assert!(outside_seeds(&es, &g).is_empty());
        assert_eq!(enclosed_seeds(&es, &g).len(), 1);
        // Beyond the grid, behind a sealed level's wall: said, with the grid and the rooms.
        let behind = json!({ "components": [rooms], "seeds_outside_grid": ["camera 'behind'"] });
        let w = outside_seeds(&behind, &g);
        assert!(
            w.len() == 1
                && w[0].starts_with("camera 'behind' is outside the level: beyond the grid")
                && w[0].contains("(-4.25, -0.80, -3.94) .. (16.29, 5.20, 5.70) m")
                && w[0].contains("it sees the backs of its walls alone")
                && w[0].contains("span (-3.94, -0.49, -3.62)"),
            "{w:?}"
        );
        // Where a room reaches the bounds, the level is seen and lit through its openings
        // from there (the Cornell box's camera, sun-window's lamp): nothing.
        let open = part(
            &["point light 0"],
            [900, 0],
            [-4.25, 0.0, 0.0],
            [1.0, 1.0, 1.0],
        );
        let lamp = json!({ "components": [open], "seeds_outside_grid": ["point light 1"] });
        assert!(outside_seeds(&lamp, &g).is_empty());
    }
}

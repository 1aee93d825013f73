//! What `visgate bake` warns of after a bake that succeeded but that a user would not want:
//! a bare mesh's inside that reaches the bounds, most of the level's space dropped, a camera
//! sealed off from every light, a camera or light inside closed geometry or outside the
//! level, a grid too coarse for the level's rooms and doorways. Each warning says why and what to do; the figures also
//! sit in the JSON report.

use serde_json::Value;
use visgate_formats::Scene;
use visgate_formats::stray::{Stray, stray_geometry};
use visgate_formats::vgate::GridMeta;
use visgate_preprocess::bake::is_camera_seed;
use visgate_preprocess::empty::{INSIDE, INSIDE_LEAK_MAX_VOXELS, UNSEEN};
use visgate_preprocess::report::BakeReport;

/// Under this largest-ball radius the kept space is a few voxels across: its clusters follow
/// the voxels rather than the rooms (LibreQuake e2m3 baked at 24 and 32: 2.0 and 2.2 voxels,
/// 2 and 6 clusters, 104 at 128; `ajar-door` at 16: 2.0, its door closed; `four-rooms` at 16,
/// 3.0, still has its 4 rooms). [Units: voxels]
pub const COARSE_RADIUS_VX: f64 = 3.0;

/// The largest-ball radius a suggested resolution aims at. [Units: voxels]
const SUGGESTED_RADIUS_VX: f64 = 6.0;

/// Every warning for `report`, in the order they are printed.
pub fn warnings(report: &BakeReport) -> Vec<String> {
    let es = &report.empty_space;
    let mut out = inside_warnings(es);
    out.extend(turned_faces(es));
    out.extend(mixed_winding(es, &report.grid));
    out.extend(most_dropped(es, &report.grid));
    out.extend(enclosed_seeds(es, &report.grid));
    out.extend(outside_seeds(es, &report.grid));
    out.extend(cut_off_cameras(es, &report.grid));
    let radius = report
        .stages
        .iter()
        .find(|s| s.name == "distance")
        .and_then(|s| s.counts["largest_radius_vx"].as_f64());
    if let Some(r) = radius {
        out.extend(too_coarse(r, report.summary.clusters, &report.grid));
    }
    let sight_bytes = report
        .stages
        .iter()
        .find(|s| s.name == "sight grid")
        .and_then(|s| s.counts["bytes"].as_u64());
    out.extend(sight_bytes.and_then(sight_grid_too_large));
    out
}

/// Prints the warning for `scene`'s stray triangles, where it has any
/// ([`visgate_formats::stray::stray_geometry`]): before a bake, whose grid they size.
pub fn warn_of_strays(scene: &Scene) {
    if let Some(s) = stray_geometry(scene) {
        eprintln!("warning: {}", stray_warning(&s));
    }
}

/// The warning for a level's stray triangles `s`.
fn stray_warning(s: &Stray) -> String {
    let p = s.farthest;
    format!(
        "{} of the level's {} static triangles {} far from the rest: the farthest corner at \
         ({:.2}, {:.2}, {:.2}) m, {:.0} m from the rest's bounds. The grid spans them, a {:.1} m \
         level where the rest is {:.2} m long, so its voxels are {:.0}× as large as the rest \
         alone needs and its rooms and doorways fall to a few voxels. A helper object left in \
         the export, a sky box or a vertex in the wrong place? Delete them in the modelling \
         tool, or give them a mesh of their own and mark it `static = false` in a scene TOML \
         (lit, not baked)",
        s.triangles,
        s.total,
        if s.triangles == 1 { "lies" } else { "lie" },
        p.x,
        p.y,
        p.z,
        s.distance_m,
        s.longest_m(),
        s.rest_longest_m(),
        s.longest_m() / s.rest_longest_m().max(1e-9),
    )
}

/// The storage binding limit over which [`sight_grid_too_large`] warns: wgpu's default and
/// lavapipe's (discrete GPUs allow 1–4 GiB). [Units: bytes]
const GPU_BINDING_DEFAULT: u64 = 128 << 20;

/// A warning where the sight grid, on the GPU (its bits and as many bytes again of bricks), is
/// larger than [`GPU_BINDING_DEFAULT`]: an adapter that allows no more refuses to walk it (the
/// ajar door with `--sight-voxel 0.005`: 194 MB, refused on lavapipe).
fn sight_grid_too_large(bits_bytes: u64) -> Option<String> {
    let gpu = 2 * bits_bytes;
    (gpu > GPU_BINDING_DEFAULT).then(|| {
        format!(
            "the sight grid takes about {} MiB on the GPU (its bits and bricks), over the {} MiB \
             that wgpu allows by default and lavapipe at most: adapters that allow no more \
             refuse the voxel walk (--gate-shape voxels) on this level; most discrete GPUs \
             allow 1-4 GiB. A coarser --sight-voxel fits it (the grid shrinks with the cube of \
             the voxel)",
            gpu >> 20,
            GPU_BINDING_DEFAULT >> 20
        )
    })
}

/// A warning where the bake read the level's faces turned, wound inside out
/// (`visgate_preprocess::winding`).
fn turned_faces(empty_space: &Value) -> Option<String> {
    (empty_space["faces_turned"] == true).then(|| {
        "the level's faces are wound inside out: its rooms see the backs of their walls (the \
         cameras' and lights' space, or a bare mesh's enclosed inside), so the bake read every \
         face turned to keep and drop empty space; the renders light both sides and read no \
         winding. To have the file say what it means, reverse the faces' winding (flip the \
         normals) in the modelling tool or the exporter"
            .to_string()
    })
}

/// Votes under which [`mixed_winding`] says nothing. [Units: triangles]
const MIXED_MIN_VOTES: u64 = 100;

/// Fronts over backs (or backs over fronts) seen from the rooms under which [`mixed_winding`]
/// calls the winding mixed: LibreQuake e2m3's bare OBJ with every other material's faces
/// reversed, 1.06 (4,648 fronts, 4,908 backs); as written 18.5, Crytek Sponza's 2.4. [Units:
/// ratio]
const MIXED_RATIO: f64 = 1.5;

/// A warning where the faces around the level's rooms (the components that hold a camera or a
/// light, or a bare mesh's inside) face them about as often as they turn their backs: some
/// objects wound one way, some the other, so the votes that keep and drop the empty space
/// say little (e2m3 so mixed kept the void around its rooms too: 159 clusters instead of 104).
fn mixed_winding(empty_space: &Value, grid: &GridMeta) -> Option<String> {
    let comps = empty_space["components"].as_array()?;
    let seeded = |c: &Value| !seeds_of(c).is_empty();
    let inside = |c: &Value| c["reason"].as_str().is_some_and(|r| r.starts_with(INSIDE));
    // A camera or light inside closed geometry is no room (enclosed_seeds says so).
    // Nor is the void around the level that one holds (outside_seeds says so).
    let room = |c: &&Value| {
        (seeded(c) || inside(c))
            && !enclosed_seed_part(c, grid)
            && !outside_seed_part(c, comps, grid)
    };
    let (f, b) = comps.iter().filter(room).fold((0, 0), |(f, b), c| {
        let v = |k: usize| c["faced_by"][k].as_u64().unwrap_or(0);
        (f + v(0), b + v(1))
    });
    let (lo, hi) = (f.min(b) as f64, f.max(b) as f64);
    (f + b >= MIXED_MIN_VOTES && hi < MIXED_RATIO * lo).then(|| {
        // Kept by the votes: no camera or light holds them, and they are not the inside.
        let by_votes = |c: &&Value| c["kept"] == true && !seeded(c) && !inside(c);
        let kept = comps.iter().filter(by_votes).count();
        format!(
            "the level's faces are wound both ways: of the triangles beside its rooms {f} face \
             them and {b} turn their backs (objects mirrored or exported inside out, or faces \
             doubled back to back?). The bake keeps and drops empty space by these votes, and \
             kept {kept} part(s) beside the rooms by them, which may be the void around the \
             level or the insides of walls. Make the winding consistent (one face a surface, \
             facing the rooms), or name the level in a scene file with a camera or a light \
             inside and `closed = true`, which drops what reaches the bounds"
        )
    })
}

/// What to say of a bare mesh's inside (kept as the level's, no camera or light named) that
/// reaches the scene's bounds: that its openings were not looked for on so large a grid, or,
/// where they were (the `leak:` lines before), what to do about them.
fn inside_warnings(empty_space: &Value) -> Vec<String> {
    let mut out = Vec::new();
    if empty_space["inside_leaks_not_looked_for"] == true {
        out.push(format!(
            "the scene names no camera or light, and the empty space kept as the level's \
             inside (the one the most triangles face) reaches the scene's bounds; its openings \
             are looked for on grids of up to {} M voxels: bake at a lower --resolution to have \
             them named",
            INSIDE_LEAK_MAX_VOXELS >> 20
        ));
    }
    let openings = empty_space["openings"].as_array().into_iter().flatten();
    if openings.into_iter().any(|o| o["from"] == INSIDE) {
        out.push(
            "the scene names no camera or light, so the bake kept as the level's inside the \
             empty space that the most triangles face, and that space reaches the scene's \
             bounds as above. If the level is meant to be sealed, close it there; in a scene \
             file (`visgate scenes export`), `closed = true` with a camera or light inside \
             makes the bake stop on a leak"
                .to_string(),
        );
    }
    out
}

/// The resolution (voxels on the longest axis) at which space `radius_vx` voxels wide now
/// would be `aim` voxels wide, rounded up to a multiple of 8.
fn resolution_for(grid: &GridMeta, radius_vx: f64, aim: f64) -> u32 {
    // The grid holds a voxel of border on each side.
    let longest = grid
        .dims
        .iter()
        .max()
        .copied()
        .unwrap_or(2)
        .saturating_sub(2) as f64;
    let r = (longest * aim / radius_vx.max(0.5)).ceil() as u32;
    r.div_ceil(8) * 8
}

/// A warning when the kept space's widest ball is under [`COARSE_RADIUS_VX`] voxels: the bake
/// found fewer clusters than the level has rooms, or clusters that follow the voxels.
fn too_coarse(radius_vx: f64, clusters: u64, grid: &GridMeta) -> Option<String> {
    (radius_vx < COARSE_RADIUS_VX).then(|| {
        let r = resolution_for(grid, radius_vx, SUGGESTED_RADIUS_VX);
        format!(
            "the grid is too coarse for this level: its widest empty space is {:.1} voxels \
             across (voxels of {:.3} m), so doorways narrower than a voxel or two are closed \
             and the {clusters} cluster(s) follow the voxels, not the rooms. Bake at \
             --resolution {r} or more (voxels of about {:.3} m)",
            2.0 * radius_vx,
            grid.voxel_size_m,
            grid.voxel_size_m as f64 * radius_vx / SUGGESTED_RADIUS_VX
        )
    })
}

/// The cameras and lights a part of the report holds.
fn seeds_of(c: &Value) -> Vec<String> {
    let list = c["seeds"].as_array().into_iter().flatten();
    list.filter_map(|s| s.as_str().map(str::to_string))
        .collect()
}

/// Whether part `c` of the report reaches the grid's bounds: its box within a voxel and a half
/// of the grid's faces, next to its solid border (the outside).
fn reaches_bounds(c: &Value, grid: &GridMeta) -> bool {
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
fn enclosed_seed_part(c: &Value, grid: &GridMeta) -> bool {
    seeded_part(c) && outvoted(c, 1) && !reaches_bounds(c, grid)
}

/// Whether part `c` of the report is kept and holds cameras or lights.
fn seeded_part(c: &Value) -> bool {
    c["kept"] == true && !seeds_of(c).is_empty()
}

/// Whether the triangles around part `c` of the report turn their backs to it (`side` 1) or
/// face it (`side` 0) [`MIXED_RATIO`] times as often as the other way.
fn outvoted(c: &Value, side: usize) -> bool {
    let v = |k: usize| c["faced_by"][k].as_u64().unwrap_or(0);
    let (by, against) = (v(side), v(1 - side));
    by > against && by as f64 >= MIXED_RATIO * against as f64
}

/// Whether part `c` holds cameras or lights and is a room: its triangles face it.
fn seeded_room(c: &Value) -> bool {
    seeded_part(c) && outvoted(c, 0)
}

/// Whether a kept part holds cameras or lights, reaches the bounds and sees the backs of the
/// triangles around it while another part with cameras or lights sees their fronts: the void
/// around the level, behind its walls. A camera written a few centimetres outside a wall of a
/// cave whose faces look in was there: the bake kept the void for it, its backs made the
/// level's faces read "wound both ways", and the camera was told to bake at a finer
/// resolution to reach the light.
fn outside_seed_part(c: &Value, comps: &[Value], grid: &GridMeta) -> bool {
    seeded_part(c) && outvoted(c, 1) && reaches_bounds(c, grid) && comps.iter().any(seeded_room)
}

/// `one` for a single thing, `many` for several.
fn by_count<'a>(n: usize, one: &'a str, many: &'a str) -> &'a str {
    if n == 1 { one } else { many }
}

/// A warning for each part that holds cameras or lights outside the level
/// ([`outside_seed_part`]), and [`beyond_the_grid`]'s. Each names the rooms' span, so that
/// they can be moved in.
fn outside_seeds(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
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
fn beyond_the_grid(empty_space: &Value, comps: &[Value], grid: &GridMeta) -> Option<String> {
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
fn rooms_span(rooms: &[&Value]) -> String {
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
fn json_point(p: [f64; 3]) -> Value {
    Value::from(p.to_vec())
}

/// A warning for each part that holds cameras or lights inside closed geometry
/// ([`enclosed_seed_part`]): a light lights that mesh's inside alone (the built-in ajar door
/// with a 20 cm box around its lamp: 8 voxels, every render black), a camera sees its inside.
fn enclosed_seeds(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
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
fn cut_off_cameras(empty_space: &Value, grid: &GridMeta) -> Vec<String> {
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
fn metres(p: &Value) -> String {
    let c = |a: usize| p[a].as_f64().unwrap_or(f64::NAN);
    format!("({:.2}, {:.2}, {:.2})", c(0), c(1), c(2))
}

/// `a`, `a and b`, `a, b and c`, with "is"/"are" after.
fn join_and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [_] => format!("{} is", join_words(items)),
        _ => format!("{} are", join_words(items)),
    }
}

/// `a`, `a and b`, `a, b and c`.
fn join_words(items: &[String]) -> String {
    match items {
        [rest @ .., last] if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.concat(),
    }
}

/// A warning when the bake dropped an enclosed part of the empty space larger than all it
/// kept (the outside, which reaches the grid's bounds, is meant to go): that part, why, and
/// what to do (the reason also sits in the JSON report). None where a bare mesh's inside was
/// kept: that is the space the most triangles face, and a larger part dropped faces fewer (the
/// space around and over Crytek Sponza's rooms, from its bare GLB at 128).
fn most_dropped(empty_space: &Value, grid: &GridMeta) -> Option<String> {
    let comps = empty_space["components"].as_array()?;
    let voxels = |c: &Value| c["voxels"].as_u64().unwrap_or(0);
    let inside = |c: &Value| c["reason"].as_str().is_some_and(|r| r.starts_with(INSIDE));
    if comps.iter().any(inside) {
        return None;
    }
    let fronts = |c: &Value| c["faced_by"][0].as_u64().unwrap_or(0);
    let unseen = |c: &Value| c["reason"].as_str().is_some_and(|r| r.starts_with(UNSEEN));
    let kept_comps = || comps.iter().filter(|c| c["kept"] == true);
    let kept: u64 = kept_comps().map(voxels).sum();
    let kept_fronts: u64 = kept_comps().map(fronts).sum();
    // Space that no camera or light is in and that turns its back to the geometry is dropped
    // by design; it may be the level's inside only where more triangles face it than the kept
    // space (the cameras and lights outside the rooms): Crytek Sponza's 2.4 M voxels around
    // its rooms, 2,791 fronts (0.75 voxel off) against the rooms' 90,668, are not.
    let suspect = |c: &&Value| {
        c["kept"] != true && !reaches_bounds(c, grid) && (!unseen(c) || fronts(c) > kept_fronts)
    };
    let largest = comps.iter().filter(suspect).max_by_key(|c| voxels(c))?;
    (voxels(largest) > kept).then(|| {
        format!(
            "kept {kept} empty voxels, and dropped an enclosed part larger than that ({} voxels, \
             {} .. {} m) as {}. If that is the level's inside, put a camera or a light in it (a \
             scene file: see `visgate scenes export`), or check that the mesh's normals face \
             into the rooms",
            voxels(largest),
            metres(&largest["bounds_min_m"]),
            metres(&largest["bounds_max_m"]),
            largest["reason"].as_str().unwrap_or("?")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_sight_grid_over_wgpus_default_binding_is_told_with_its_size() {
        // The sun window's at 5 mm: 97 MB of bits, 185 MiB with its bricks.
        let said = sight_grid_too_large(97_127_222).expect("over 128 MiB");
        assert!(
            said.contains("185 MiB") && said.contains("--sight-voxel"),
            "{said}"
        );
        // Crytek Sponza's at 1/1024 of the level: 35 MB of bits, 67 MiB.
        assert_eq!(sight_grid_too_large(35 << 20), None);
    }

    #[test]
    fn an_enclosed_part_dropped_and_larger_than_all_kept_is_named_and_the_outside_is_not() {
        let grid = visgate_formats::vgate::GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims: [100, 40, 100],
        };
        let comp = |voxels: u64, lo: f32, hi: f32, kept: bool, reason: &str| {
            json!({ "voxels": voxels, "bounds_min_m": [lo, lo, lo],
                    "bounds_max_m": [hi, hi.min(38.0), hi], "kept": kept, "reason": reason })
        };
        // The outside (next to the grid's faces) dropped, rooms kept: nothing to say.
        let fine = json!({ "components": [
            comp(300_000, 1.0, 99.0, false, "outside the closed level"),
            comp(5_000, 10.0, 30.0, true, "holds light 0"),
        ]});
        assert_eq!(most_dropped(&fine, &grid), None);
        // The level's inside dropped as a wall's, four pockets kept: the warning names it.
        let lost = json!({ "components": [
            comp(60_000, 5.0, 90.0, false, "inside closed geometry: 12191 triangles turn their back to it, 10929 face it"),
            comp(300, 40.0, 45.0, true, "large and faced by the geometry"),
        ]});
        let w = most_dropped(&lost, &grid).expect("a warning");
        assert!(
            w.contains("kept 300 empty voxels") && w.contains("60000 voxels"),
            "{w}"
        );
        assert!(w.contains("12191 triangles turn their back"), "{w}");
        // A bare mesh's inside kept: the larger part dropped is not it.
        let bare = json!({ "components": [
            comp(60_000, 5.0, 90.0, false, "inside closed geometry: 9925 triangles turn their back to it, 6984 face it"),
            comp(3_000, 40.0, 45.0, true, "the level's inside: the most triangles face it (90668 of them; no camera or light named)"),
        ]});
        assert_eq!(most_dropped(&bare, &grid), None);
        // Space no camera or light is in, dropped by design: said only where more triangles
        // face it than the kept space (the camera and light outside the rooms).
        let unseen = |fronts: u64| {
            let mut around = comp(60_000, 5.0, 90.0, false, UNSEEN);
            around["faced_by"] = json!([fronts, 10]);
            let mut rooms = comp(3_000, 40.0, 45.0, true, "holds camera 'main'");
            rooms["faced_by"] = json!([500, 20]);
            json!({ "components": [around, rooms] })
        };
        assert_eq!(most_dropped(&unseen(400), &grid), None);
        let w = most_dropped(&unseen(600), &grid).expect("the rooms dropped");
        assert!(w.contains("60000 voxels") && w.contains(UNSEEN), "{w}");
    }

    fn grid(longest: u32, voxel_size_m: f32) -> GridMeta {
        GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m,
            dims: [longest + 2, longest / 2 + 2, longest + 2],
        }
    }

    #[test]
    fn a_grid_whose_widest_space_is_under_three_voxels_is_too_coarse() {
        let g = grid(24, 4.5);
        let w = too_coarse(2.0, 2, &g).expect("a warning at 2 voxels");
        // 24 voxels × 6 / 2 = 72, a multiple of 8; voxels of 4.5 × 2 / 6 m.
        assert!(
            w.contains("4.0 voxels across") && w.contains("the 2 cluster(s)"),
            "{w}"
        );
        assert!(
            w.contains("--resolution 72 or more (voxels of about 1.500 m)"),
            "{w}"
        );
        assert_eq!(
            too_coarse(3.0, 4, &g),
            None,
            "four-rooms at 16: 3 voxels is enough"
        );
        assert_eq!(
            resolution_for(&grid(32, 1.0), 2.236, 6.0),
            88,
            "86 rounded up to 8s"
        );
    }

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
    fn a_bare_mesh_s_inside_at_the_bounds_is_said_searched_or_not() {
        let none = json!({ "openings": [], "inside_leaks_not_looked_for": false });
        assert!(inside_warnings(&none).is_empty());
        // A closed scene's leak from a light: its own error or warning, not this one.
        let light = json!({ "openings": [{ "from": "point light 0" }] });
        assert!(inside_warnings(&light).is_empty());
        let found = json!({ "openings": [{ "from": INSIDE }] });
        let w = inside_warnings(&found);
        assert!(w.len() == 1 && w[0].contains("`closed = true`"), "{w:?}");
        let unsearched = json!({ "openings": [], "inside_leaks_not_looked_for": true });
        let w = inside_warnings(&unsearched);
        assert!(w.len() == 1 && w[0].contains("up to 32 M voxels"), "{w:?}");
    }

    #[test]
    fn faces_read_turned_are_said_with_what_to_do() {
        assert!(turned_faces(&json!({ "faces_turned": false })).is_none());
        assert!(turned_faces(&json!({})).is_none());
        let w = turned_faces(&json!({ "faces_turned": true })).expect("a warning");
        assert!(w.contains("wound inside out") && w.contains("reverse the faces' winding"));
    }

    #[test]
    fn faces_wound_both_ways_are_said() {
        let g = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 0.1,
            dims: [100, 40, 100],
        };
        let comp = |seeds: &[&str], reason: &str, faced: [u64; 2], kept: bool| json!({ "seeds": seeds, "reason": reason, "faced_by": faced, "kept": kept });
        let inside = format!("{INSIDE}: the most triangles face it");
        // e2m3 with every other material reversed: its inside and the void both kept.
        let mixed = json!({ "components": [
            comp(&[], "large and faced by the geometry", [4145, 4092], true),
            comp(&[], &inside, [4648, 4908], true),
        ]});
        let w = mixed_winding(&mixed, &g).expect("a warning");
        assert!(
            w.contains("4648 face them and 4908 turn") && w.contains("kept 1 part"),
            "{w}"
        );
        // As written, and Crytek Sponza's rooms: nothing.
        let e2m3 = json!({ "components": [comp(&[], &inside, [8924, 482], true)] });
        assert!(mixed_winding(&e2m3, &g).is_none());
        let sponza =
            json!({ "components": [comp(&["camera 'a'"], "holds", [85417, 35427], true)] });
        assert!(mixed_winding(&sponza, &g).is_none());
        // Too few votes: nothing.
        let few = json!({ "components": [comp(&["camera 'a'"], "holds", [40, 45], true)] });
        assert!(mixed_winding(&few, &g).is_none());
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

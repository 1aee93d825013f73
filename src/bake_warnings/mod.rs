//! What `visgate bake` warns of after a bake that succeeded but that a user would not want:
//! a bare mesh's inside that reaches the bounds, most of the level's space dropped, a camera
//! sealed off from every light, a camera or light inside closed geometry or outside the
//! level, a grid too coarse for the level's rooms and doorways. Each warning says why and what to do; the figures also
//! sit in the JSON report.

use serde_json::Value;
use visgate_formats::Scene;
use visgate_formats::stray::{Stray, stray_geometry};
use visgate_formats::vgate::GridMeta;
use visgate_preprocess::empty::{INSIDE, INSIDE_LEAK_MAX_VOXELS, UNSEEN};
use visgate_preprocess::report::BakeReport;

mod placed;

use placed::{
    cut_off_cameras, enclosed_seed_part, enclosed_seeds, metres, outside_seed_part, outside_seeds,
    reaches_bounds, seeds_of,
};

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
    let fix = if s.objects.is_empty() {
        "A helper object left in the export, a sky box or a vertex in the wrong place? Delete \
         them in the modelling tool, or give them a mesh of their own and mark it `static = \
         false` in a scene TOML (lit, not baked)"
            .to_string()
    } else {
        let names: Vec<String> = s.objects.iter().map(|o| format!("\"{o}\"")).collect();
        format!(
            "A sky dome or a sky box? Leave them out in a scene TOML, `leave_out = [{}]` in \
             their file's [[mesh]], or delete them in the modelling tool",
            names.join(", ")
        )
    };
    format!(
        "{} m, {:.0} m from the rest's bounds. The grid spans them, a {:.1} m level where the \
         rest is {:.2} m long, so its voxels are {:.0}× as large as the rest alone needs and its \
         rooms and doorways fall to a few voxels. {fix}",
        s.said("the level's", "static triangles"),
        s.distance_m,
        s.longest_m(),
        s.rest_longest_m(),
        s.growth(),
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
    use glam::Vec3;
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

    pub(super) fn grid(longest: u32, voxel_size_m: f32) -> GridMeta {
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
    fn a_surrounding_object_is_told_the_toml_line_that_leaves_it_out() {
        let (lo, hi) = (Vec3::splat(-2000.0), Vec3::splat(2000.0));
        let mut s = Stray {
            triangles: 2208,
            total: 24070,
            farthest: Vec3::new(30.0, 2000.0, 40.0),
            distance_m: 1981.3,
            bounds: (lo, hi),
            rest: (Vec3::ZERO, Vec3::new(108.1, 48.8, 105.7)),
            objects: vec!["SkyDome".into()],
        };
        let w = stray_warning(&s);
        assert!(
            w.contains("(the whole of 'SkyDome', round it)")
                && w.contains("`leave_out = [\"SkyDome\"]` in their file's [[mesh]]")
                && !w.contains("static = false"),
            "{w}"
        );
        // A few far triangles of any object: their own mesh, marked dynamic.
        s.objects.clear();
        let w = stray_warning(&s);
        assert!(
            w.contains("static = false") && !w.contains("leave_out"),
            "{w}"
        );
    }
}

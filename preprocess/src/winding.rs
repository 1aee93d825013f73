//! Faces wound inside out. The empty-space stage keeps and drops components by which side of
//! the triangles faces them (a room sees the fronts of its walls, the inside of a thick wall
//! and the void around a level their backs), and picks a bare mesh's inside as the component
//! the most fronts face. A level whose faces are all wound the other way (exporters that
//! mirror an axis, tools of the other handedness, Quake's clockwise faces) turns that round:
//! LibreQuake e2m3's OBJ with every face reversed kept the 735 k-voxel void around the level
//! as its inside and dropped the 125 k voxels of its rooms, with nothing said. The renders are
//! two-sided, so only the bake reads the winding; here it is judged from what it must mean:
//!
//! - with cameras or lights, their components are the level's rooms: if they see the backs of
//!   more than [`TURNED_RATIO`] times as many triangles as fronts — and, where one of them
//!   reaches the bounds (a room joined to the void by a window sees the backs of its walls from
//!   outside too), more than [`OPEN_RATIO`] times as many from each face's first open voxel —
//!   the faces are turned ([`rooms_turned`]), unless the turn would drop a sealed part larger
//!   and more faced than the rooms (a lamp inside its shade: [`turning_drops_more`]);
//! - a bare mesh's inside as written (the most fronts) and as turned (the most backs), where
//!   they differ and about as many triangles face each ([`FACED_RATIO`]), is the turned one
//!   where the written one reaches all six sides of the grid (the void around a level) and the
//!   turned one's voxels are more often **enclosed** (at most [`crate::inside::MAX_ESCAPES`] of
//!   the 26 rays from a voxel reach the grid's border) by [`ENCLOSED_MARGIN`], or where both
//!   are enclosed alike and the turned one is [`LARGER_RATIO`] times as large (not the inside
//!   of a hollow wall); the inside so found is then judged as a camera's room. A level's rooms
//!   open to the sky or a Cornell box's open front reach one side, not six; hollow brushes
//!   (closed boxes, their backs inward) are enclosed but small. Not caught: the Cornell box
//!   turned (its open room is not enclosed; the bake keeps its blocks' insides, which its
//!   turned faces face).
//!
//! Turned faces are then read as turned (each component's votes swapped) and the bake says so.

use visgate_formats::vgate::GridMeta;

use crate::neighbourhood::Components;

/// Backs over fronts seen from the cameras' and lights' components above which the faces are
/// turned (a level's rooms see at least as many fronts: Crytek Sponza's 3.4× as many,
/// LibreQuake e2m3's 18×). [Units: ratio]
pub const TURNED_RATIO: u64 = 2;

/// Triangles below which the votes say nothing: low-poly levels give few (a triangle votes
/// from its centroid, 0.75 voxel off it, and the built-in L corridor's thick walls leave its
/// corridor 2). [Units: count]
pub const MIN_VOTES: u64 = 2;

/// Where the rooms reach the bounds, backs over fronts from their first open voxel above which
/// their votes are believed: Crytek Sponza's OBJ turned, its rooms open to the sky, 1.65
/// (182,704 backs, 110,738 fronts; its votes 0.75 voxel off 85,417 and 35,427); a room of
/// single-sided walls with a window and a slab outside turning 576 faces' backs to the void,
/// as written, 0.98 (584 and 596; its votes 288 backs and no front). [Units: ratio]
pub const OPEN_RATIO: f64 = 1.25;

/// How much more often the turned inside's voxels must be enclosed than the written one's.
/// [Units: share]
pub const ENCLOSED_MARGIN: f64 = 0.25;

/// The turned inside is weighed against the written one only where at least 1 / this as many
/// triangles face it (the Cornell box: its blocks are closed boxes whose enclosed insides 10
/// backs face, against the 30 fronts that face its open room). [Units: ratio]
pub const FACED_RATIO: u64 = 2;

/// How many times as large the turned inside must be, where both are enclosed alike, to be
/// taken for the rooms: hollow thick walls and pillars (brushes) are enclosed too, and turned
/// faces make their insides look like rooms (the built-in L corridor's: 8,208 voxels against
/// its corridor's 31,832). [Units: ratio]
pub const LARGER_RATIO: u64 = 2;

/// Voxels of a component tested for being enclosed, spread evenly over it. [Units: count]
const SAMPLES: u64 = 256;

/// What the faces say of each component.
pub struct Votes<'a> {
    /// The triangles whose front and whose back lie on its side, 0.75 voxel off them.
    pub faced: &'a [[u64; 2]],
    /// The triangles whose front it is the first open voxel off (0.75, 1.5, 2.25 voxels).
    pub fronts: &'a [u64],
    /// The triangles whose back it is the first open voxel off.
    pub backs: &'a [u64],
    /// Whether it reaches the grid's bounds.
    pub at_bounds: &'a [bool],
}

/// Whether the faces are turned, judged from `rooms` (the components that hold a camera or a
/// light, or a bare mesh's inside): they see the backs of more than [`TURNED_RATIO`] times as
/// many triangles as fronts (at least [`MIN_VOTES`]), and, where one of them reaches the
/// bounds (a room joined to the void by a window sees the backs of its walls from outside
/// too), more than [`OPEN_RATIO`] times as many backs as fronts from their first open voxel.
pub fn rooms_turned(v: &Votes, rooms: &[bool]) -> bool {
    let (mut faced, mut first, mut sealed) = ([0u64; 2], [0u64; 2], true);
    for c in (0..rooms.len()).filter(|&c| rooms[c]) {
        faced = [faced[0] + v.faced[c][0], faced[1] + v.faced[c][1]];
        first = [first[0] + v.fronts[c], first[1] + v.backs[c]];
        sealed &= !v.at_bounds[c];
    }
    let [f, b] = faced;
    let by_votes = b >= MIN_VOTES && b > TURNED_RATIO * f;
    by_votes && (sealed || first[1] as f64 > OPEN_RATIO * first[0] as f64)
}

/// Whether reading the faces turned would drop a sealed part (not reaching the bounds) that the
/// faces as written keep (more fronts than backs face it) and that is both larger than all the
/// `rooms` together and faced by more triangles than turn their backs to them: then the rooms'
/// backs are not turned faces but a closed mesh around them — a lamp inside its bulb or shade,
/// whose 8 voxels see the backs of 8 of the shade's faces while the room around, 352,888
/// voxels, sees 49 fronts. (Crytek Sponza turned, with its scene file: the space around its
/// rooms is larger, 275,913 voxels against 121,436 at 128, but 2,495 fronts face it and
/// 85,417 backs its rooms.)
pub fn turning_drops_more(v: &Votes, rooms: &[bool], voxels: &[u64]) -> bool {
    let in_rooms = || (0..rooms.len()).filter(|&c| rooms[c]);
    let rooms_voxels: u64 = in_rooms().map(|c| voxels[c]).sum();
    let rooms_backs: u64 = in_rooms().map(|c| v.faced[c][1]).sum();
    (0..rooms.len()).any(|c| {
        let [f, b] = v.faced[c];
        let kept_as_written = !rooms[c] && !v.at_bounds[c] && f > b;
        kept_as_written && voxels[c] > rooms_voxels && f > rooms_backs
    })
}

/// The share of component `c`'s voxels (up to 256 of its `voxels`, `SAMPLES`, evenly spread in
/// voxel order) that are enclosed.
pub fn enclosed_share(
    meta: &GridMeta,
    comps: &Components,
    c: u32,
    voxels: u64,
    empty: &dyn Fn(usize) -> bool,
) -> f64 {
    let step = (voxels / SAMPLES).max(1);
    let nx = meta.dims[0] as usize;
    let rows = meta.voxel_count().unwrap_or(0) as usize / nx.max(1);
    let (mut seen, mut tested, mut enclosed) = (0u64, 0u64, 0u64);
    for r in 0..rows {
        for (a, b, _) in comps.row(r).filter(|&(_, _, l)| l == c) {
            for x in a..=b {
                seen += 1;
                if seen % step != 0 {
                    continue;
                }
                let v = meta.coords((r * nx + x as usize) as u32);
                let limit = crate::inside::MAX_ESCAPES + 1;
                tested += 1;
                enclosed += u64::from(crate::inside::escapes(meta, empty, v, limit) < limit);
            }
        }
    }
    enclosed as f64 / tested.max(1) as f64
}

/// Whether component `c` reaches all six sides of the grid (next to its border ring): the
/// void around a level does; a room open to the sky or by a window reaches one or two, the air
/// of an outdoor level five (not the ground's).
pub fn all_round(meta: &GridMeta, comps: &Components, c: u32) -> bool {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let mut sides = [false; 6];
    for r in 0..ny * nz {
        let (y, z) = (r % ny, r / ny);
        for (a, b, _) in comps.row(r).filter(|&(_, _, l)| l == c) {
            sides[0] |= a == 1;
            sides[1] |= b as usize + 2 == nx;
            sides[2] |= y == 1;
            sides[3] |= y + 2 == ny;
            sides[4] |= z == 1;
            sides[5] |= z + 2 == nz;
        }
    }
    sides.iter().all(|&s| s)
}

/// A bare mesh's inside and whether its faces are turned: the component that the most fronts
/// face (ties to the larger, as [`crate::inside::inside_component`]), or, where the component
/// that the most backs face differs, at least 1 / [`FACED_RATIO`] as many triangles face it,
/// and either the written one reaches all six sides of the grid ([`all_round`]: the void)
/// while the turned one is enclosed more often by [`ENCLOSED_MARGIN`], or both are enclosed
/// alike and the turned one is [`LARGER_RATIO`] times as large, that one, turned; and turned
/// too where the inside so found reads turned as a camera's room would ([`rooms_turned`]: a
/// level that its void does not wrap, its inside the first open voxel off both sides of its
/// walls — the pillared hall — or Crytek Sponza, its rooms open to the sky).
pub fn bare_inside(
    meta: &GridMeta,
    comps: &Components,
    first: &Votes,
    voxels: &[u64],
    empty: &dyn Fn(usize) -> bool,
) -> (Option<u32>, bool) {
    let written = crate::inside::inside_component(first.fronts, voxels);
    let turned = crate::inside::inside_component(first.backs, voxels);
    if let (Some(w), Some(t)) = (written, turned) {
        let (bt, fw) = (first.backs[t as usize], first.fronts[w as usize]);
        if w != t && bt * FACED_RATIO >= fw {
            let share = |c: u32| enclosed_share(meta, comps, c, voxels[c as usize], empty);
            let (sw, st) = (share(w), share(t));
            let void = all_round(meta, comps, w) && st > sw + ENCLOSED_MARGIN;
            let larger = voxels[t as usize] >= LARGER_RATIO * voxels[w as usize];
            if void || ((st - sw).abs() <= ENCLOSED_MARGIN && larger) {
                return (Some(t), true);
            }
        }
    }
    match written.or(turned) {
        Some(c) => {
            let only: Vec<bool> = (0..voxels.len()).map(|k| k == c as usize).collect();
            (Some(c), written.is_none() || rooms_turned(first, &only))
        }
        None => (None, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cameras_and_lights_rooms_seeing_backs_turn_the_faces() {
        // Crytek Sponza's bare OBJ: its rooms (open to the sky) and its space around.
        let faced = [[85_417, 35_427], [1_206, 2_495]];
        let (fronts, backs) = ([182_704, 7_280], [110_738, 15_828]);
        let at_bounds = [true, true];
        let v = Votes {
            faced: &faced,
            fronts: &fronts,
            backs: &backs,
            at_bounds: &at_bounds,
        };
        assert!(!rooms_turned(&v, &[true, false]));
        // The same turned.
        let faced_t: Vec<[u64; 2]> = faced.iter().map(|&[f, b]| [b, f]).collect();
        let t = Votes {
            faced: &faced_t,
            fronts: &backs,
            backs: &fronts,
            at_bounds: &at_bounds,
        };
        assert!(rooms_turned(&t, &[true, false]));
        // A room joined to the void by a window, as written: the void sees its walls' backs,
        // but from their first open voxel as many fronts as backs face it.
        let w = Votes {
            faced: &[[0, 288]],
            fronts: &[596],
            backs: &[584],
            at_bounds: &[true],
        };
        assert!(!rooms_turned(&w, &[true]));
        // Sealed, the votes alone decide; too few say nothing.
        let sealed = |f: u64, b: u64, room: bool| {
            let v = Votes {
                faced: &[[f, b]],
                fronts: &[0],
                backs: &[0],
                at_bounds: &[false],
            };
            rooms_turned(&v, &[room])
        };
        assert!(sealed(0, 2, true));
        assert!(!sealed(0, 1, true));
        assert!(!sealed(10, 20, true));
        assert!(!sealed(0, 400, false));
    }

    #[test]
    fn a_turn_that_would_drop_a_larger_and_more_faced_part_is_refused() {
        // The ajar door with a shade around its lamp: the lamp's pocket (a room) sees 8 backs,
        // the room around it 49 fronts and 352,888 voxels.
        let v = Votes {
            faced: &[[49, 0], [0, 8]],
            fronts: &[0, 0],
            backs: &[0, 0],
            at_bounds: &[false, false],
        };
        assert!(turning_drops_more(&v, &[false, true], &[352_888, 8]));
        // Crytek Sponza turned, at 128: the space around its rooms is larger but faced by
        // fewer triangles than turn their backs to the rooms.
        let v = Votes {
            faced: &[[2_495, 1_206], [35_427, 85_417]],
            fronts: &[0, 0],
            backs: &[0, 0],
            at_bounds: &[false, true],
        };
        assert!(!turning_drops_more(&v, &[false, true], &[275_913, 121_436]));
    }
}

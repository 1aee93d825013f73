//! The level's inside, for a scene that names no camera and no light (a bare mesh file): the
//! component a bake keeps as it would keep a camera's, and a point in it.
//!
//! Rule: the inside is the empty component that **the most triangles face** (the fronts of the
//! level's walls look into its rooms; the void around a level sees their backs, the inside of a
//! thick wall backs only; by count, not area: the space around and over Crytek Sponza's rooms
//! is faced by more area, its large outer walls and roofs, and its rooms by 32× the triangles)
//! — kept whatever the facing vote says, since a level's rooms joined to the void through a
//! window are one component that may see more backs than fronts. Its point is the voxel of it
//! farthest from the solid among those that are **enclosed** — of the 26 rays from its centre
//! along a voxel's neighbour directions, at most [`MAX_ESCAPES`] reach the grid's border
//! without meeting solid (a window or a doorway to the void lets a few out; a courtyard or a
//! roof open to the sky lets many) — so the middle of the level's largest room, or its widest
//! voxel where none is enclosed. Where the inside reaches the bounds and its point is enclosed,
//! the bake says where it leaks, from that point (a space open all round — the air around a
//! building — has openings, not leaks).

use visgate_formats::vgate::GridMeta;

/// Rays of the 26 that may escape from an enclosed voxel.
pub const MAX_ESCAPES: u32 = 3;

/// Candidates tested at most (widest first): where none of them is enclosed, the widest is
/// taken, not enclosed.
const MAX_TESTS: usize = 50_000;

/// The level's inside: its voxel (index) and centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inside {
    /// Voxel index.
    pub voxel: usize,
    /// The voxel's centre. [Units: m]
    pub position_m: [f32; 3],
    /// Whether it is enclosed; else the widest voxel of a space open all round (the air
    /// around a building, whose openings are no leak).
    pub enclosed: bool,
}

/// Of the rays from voxel `v` along the 26 neighbour directions through the voxels that are
/// `empty`, how many reach the border ring (stopping at `limit`).
pub fn escapes(meta: &GridMeta, empty: &dyn Fn(usize) -> bool, v: [u32; 3], limit: u32) -> u32 {
    let dims = meta.dims.map(i64::from);
    let mut out = 0;
    for k in 0..27i64 {
        if k == 13 {
            continue;
        }
        let o = [k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1];
        let mut c = v.map(i64::from);
        loop {
            c = std::array::from_fn(|a| c[a] + o[a]);
            if (0..3).any(|a| c[a] <= 0 || c[a] + 1 >= dims[a]) {
                out += 1;
                break;
            }
            if !empty(meta.index(c.map(|x| x as u32))) {
                break;
            }
        }
        if out >= limit {
            return out;
        }
    }
    out
}

/// Calls its argument on each voxel (index) of a set.
pub type Visit<'a> = dyn Fn(&mut dyn FnMut(usize)) + 'a;

/// The point of the level's inside (see the module notes): `d2` is each voxel's squared
/// distance to the nearest voxel that is not empty, `visit(f)` calls `f` on each voxel of the
/// inside's component (twice: a histogram of `d2` finds the widest [`MAX_TESTS`], then they
/// are tested). The widest of its voxels where none of those is enclosed; `None` where it has
/// no voxel.
pub fn find_inside(meta: &GridMeta, d2: &[u64], visit: &Visit) -> Option<Inside> {
    use rayon::prelude::*;
    // The least squared clearance that keeps at most MAX_TESTS voxels (all of the widest): a
    // count per value (squared distances in voxels, under 3 × 2048² on any grid).
    let mut counts: Vec<usize> = Vec::new();
    visit(&mut |i| {
        let d = d2[i] as usize;
        if d >= counts.len() {
            counts.resize(d + 1, 0);
        }
        counts[d] += 1;
    });
    let mut kept = 0;
    let mut floor = 0;
    for (d, &n) in counts.iter().enumerate().rev().filter(|&(_, &n)| n > 0) {
        if kept > 0 && kept + n > MAX_TESTS {
            break;
        }
        kept += n;
        floor = d as u64;
    }
    let mut candidates: Vec<(u64, u32)> = Vec::with_capacity(kept);
    visit(&mut |i| {
        if d2[i] >= floor {
            candidates.push((d2[i], i as u32));
        }
    });
    // Widest first, then the lowest index: the same answer whatever the thread count.
    candidates.par_sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let widest = *candidates.first()?;
    // A voxel that is not empty has no clearance (the border ring has some, but the rays stop
    // at it by their coordinates first).
    let empty_at = |i: usize| d2[i] > 0;
    let inside = |i: u32, enclosed: bool| Inside {
        voxel: i as usize,
        position_m: meta.voxel_to_world(meta.coords(i)),
        enclosed,
    };
    // In parallel chunks, in order: the first enclosed candidate of the first chunk holding one.
    let enclosed = candidates.par_chunks(256).find_map_first(|chunk| {
        chunk.iter().find(|&&(_, i)| {
            escapes(meta, &empty_at, meta.coords(i), MAX_ESCAPES + 1) <= MAX_ESCAPES
        })
    });
    Some(match enclosed {
        Some(&(_, i)) => inside(i, true),
        None => inside(widest.1, false),
    })
}

/// The component of the level's inside: the one that the most triangles face (`fronts`),
/// the larger (`voxels`) among equals, the first among those; `None` where no triangle faces
/// any.
pub fn inside_component(fronts: &[u64], voxels: &[u64]) -> Option<u32> {
    (0..fronts.len())
        .filter(|&c| fronts[c] > 0)
        .max_by(|&a, &b| {
            (fronts[a], voxels[a])
                .cmp(&(fronts[b], voxels[b]))
                .then(b.cmp(&a))
        })
        .map(|c| c as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta(dims: [u32; 3]) -> GridMeta {
        GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims,
        }
    }

    /// A grid of `dims` with its border ring solid and the boxes `rooms` (inclusive voxel
    /// corners) empty.
    fn grid(dims: [u32; 3], rooms: &[([u32; 3], [u32; 3])]) -> Vec<bool> {
        let m = meta(dims);
        let mut empty = vec![false; (dims[0] * dims[1] * dims[2]) as usize];
        for &(lo, hi) in rooms {
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        empty[m.index([x, y, z])] = true;
                    }
                }
            }
        }
        empty
    }

    #[test]
    fn the_inside_point_is_the_widest_enclosed_voxel_not_the_void_beside_it() {
        let dims = [40, 20, 20];
        let m = meta(dims);
        // A closed 9³ room, a one-voxel window in its +x wall onto open space from x = 12 to
        // the border: the void is wider than the room, but its rays escape.
        let empty = grid(
            dims,
            &[
                ([2, 5, 5], [10, 13, 13]),
                ([11, 9, 9], [11, 9, 9]),
                ([12, 1, 1], [38, 18, 18]),
            ],
        );
        let solid: Vec<bool> = empty.iter().map(|&e| !e).collect();
        let d2 = crate::distance::squared_distance(dims, &solid);
        let all = |f: &mut dyn FnMut(usize)| (0..empty.len()).filter(|&i| empty[i]).for_each(f);
        let inside = find_inside(&m, &d2, &all).expect("an inside");
        let empty_at = |i: usize| empty[i];
        let v = m.coords(inside.voxel as u32);
        assert!(v[0] <= 10, "{v:?} lies in the void");
        assert!(escapes(&m, &empty_at, v, 27) <= MAX_ESCAPES);
        // The room's centre sees the window straight ahead along +x: one ray out of 26.
        assert_eq!(escapes(&m, &empty_at, [6, 9, 9], 27), 1);
        // A voxel of the void: many rays out.
        assert!(escapes(&m, &empty_at, [25, 9, 9], 27) > MAX_ESCAPES);
        // Only the void to choose from: its widest voxel.
        let void = |f: &mut dyn FnMut(usize)| {
            (0..empty.len())
                .filter(|&i| empty[i] && m.coords(i as u32)[0] >= 12)
                .for_each(f)
        };
        let widest = find_inside(&m, &d2, &void).expect("the void's widest");
        let v = m.coords(widest.voxel as u32);
        assert!(
            v[0] >= 12 && d2[widest.voxel] == 81,
            "{v:?} {}",
            d2[widest.voxel]
        );
        assert!(inside.enclosed && !widest.enclosed);
    }

    #[test]
    fn the_inside_is_the_component_the_most_triangles_face() {
        // Crytek Sponza's bare OBJ at 256: the space around and over the rooms, faced by large
        // outer walls and roofs (3,443 m² of 2,791 triangles), and its rooms and galleries,
        // by 90,668 smaller ones (the area alone would choose that space).
        let fronts = [2_791, 90_668, 13];
        let voxels = [2_392_584, 1_045_046, 270_354];
        assert_eq!(inside_component(&fronts, &voxels), Some(1));
        // A tie goes to the larger; nothing faced, no inside.
        assert_eq!(inside_component(&[5, 5], &[10, 20]), Some(1));
        assert_eq!(inside_component(&[0], &[10]), None);
    }
}

//! Stage 3, empty space: which empty voxels the skeleton must describe.
//!
//! The empty voxels (not solid, 26-connected) fall into components. A component that holds a
//! camera or a light of the scene is always kept; a bare mesh's inside too (winding.rs). Any
//! other component is dropped (made solid) when it is smaller than `min_component_voxels`, or
//! when it lies inside closed geometry — the triangles around it turn their backs to it (the
//! inside of a thick wall or a pillar at a fine resolution). Where the scene's cameras or
//! lights are in its empty space, that vote counts each triangle's sides from their first
//! open voxel, as the inside's does: a room the voxels cut off from theirs is faced by its
//! walls and kept, the space around and over the rooms sees their walls' backs and is dropped
//! (no camera sees into it and no light, so no VPL, lights it; Crytek Sponza at 256: 2.4 M of
//! its 3.8 M empty voxels). Every component and the reason it was kept or dropped is listed.
//!
//! A scene declared `closed` whose kept empty space reaches the grid's border (the static
//! bounds) leaks: the bake stops and names the sides and boxes where it leaks, unless leaks
//! are allowed.
//!
//! **Cavities.** A solid object floating in empty space (a lamp whose chain is thinner than a
//! voxel, a ball) is a cavity of the empty space: a 2D hole that no curve can keep, so
//! thinning would leave a closed surface around it. Such an object is *hung*: the shortest
//! axis-aligned run of empty voxels from it to other solid is made solid (one voxel wide), which
//! removes the cavity and changes neither the components nor the cycles of the empty space. The
//! skeleton then bends around the object. Each thread is listed (object size, length).

use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use visgate_formats::vgate::GridMeta;

use crate::BakeError;
pub use crate::hang::Thread;
use crate::hang::hang_floating_objects;
use crate::neighbourhood::{Components, Conn, grid_components};
use crate::verdict::Why;

/// What a leak found from the level's inside (a scene without camera or light) starts from.
pub const INSIDE: &str = "the level's inside";

/// How the reason begins where a component is dropped that none of the scene's cameras and
/// lights is in and that turns its back to the geometry.
pub const UNSEEN: &str = "no camera or light in it";

/// Parameters of [`empty_space`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmptySpaceParams {
    /// Components smaller than this that hold no camera or light are dropped. [Units: voxels]
    pub min_component_voxels: u64,
    /// The scene says it is sealed: empty space reaching the bounds is a leak.
    pub closed: bool,
    /// Bake a leaking closed scene anyway (the leaks are still reported).
    pub allow_leaks: bool,
    /// Look for the openings of a bare mesh's inside that reaches the bounds (off where a
    /// coarser partition grid looks for them, and on grids over [`INSIDE_LEAK_MAX_VOXELS`]).
    pub locate_inside_leaks: bool,
}

/// A bare mesh's inside is not searched for openings on grids of more voxels: the search's
/// distance field, paths and heap take about 20 bytes a voxel and seconds at 512³ (Crytek
/// Sponza's bare OBJ at 512, the machine busy: 0.18 → 5.4 s and 320 → 970 MiB; its
/// partition grid looks for them instead). [Units: voxels]
pub const INSIDE_LEAK_MAX_VOXELS: u64 = 1 << 25;

/// A named point that must be in kept empty space (a camera's eye, a light).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Seed {
    /// What it is, e.g. `camera 'main'`.
    pub what: String,
    /// Where, metres.
    pub position_m: [f32; 3],
}

/// One empty component and what became of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentReport {
    /// Empty voxels in it.
    pub voxels: u64,
    /// Bounds of its voxels, metres.
    pub bounds_min_m: [f32; 3],
    /// Maximum corner, metres.
    pub bounds_max_m: [f32; 3],
    /// Cameras and lights inside.
    pub seeds: Vec<String>,
    /// Triangles that face it / turn their back to it.
    pub faced_by: [u64; 2],
    /// Kept for the skeleton.
    pub kept: bool,
    /// Why.
    pub reason: String,
}

/// Where kept empty space of a closed scene reaches the bounds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Leak {
    /// The side of the bounds: `-x`, `+x`, `-y`, `+y`, `-z`, `+z`.
    pub side: &'static str,
    /// Empty voxels touching that side.
    pub voxels: u64,
    /// Box of those voxels, metres.
    pub bounds_min_m: [f32; 3],
    /// Maximum corner, metres.
    pub bounds_max_m: [f32; 3],
}

/// The result of [`empty_space`].
#[derive(Debug, Clone, PartialEq)]
pub struct EmptySpace {
    /// `true` for the empty voxels the skeleton describes.
    pub empty: Vec<bool>,
    /// Kept empty voxels.
    pub empty_voxels: u64,
    /// Every component, largest first.
    pub components: Vec<ComponentReport>,
    /// Leaks of a closed scene (empty when not closed or sealed).
    pub leaks: Vec<Leak>,
    /// Where they leak: the widest paths from the cameras and lights to the outside, and the
    /// openings they pass; for a scene that names none, from the level's inside where its
    /// space reaches the bounds.
    pub openings: Vec<crate::leak::LeakPath>,
    /// The point of the level's inside, for a scene that names no camera and no light, where
    /// its space reaches the bounds and its openings are looked for (inside.rs).
    pub inside: Option<crate::inside::Inside>,
    /// Whether a bare mesh's inside reaches the bounds (its openings looked for or not).
    pub inside_at_bounds: bool,
    /// Floating objects that were hung.
    pub threads: Vec<Thread>,
    /// Seeds that fell outside the grid or in solid with no empty voxel next to them.
    pub seeds_outside: Vec<String>,
    /// Whether the faces were read turned, wound inside out (winding.rs); the components'
    /// `faced_by` are then the turned faces'.
    pub faces_turned: bool,
}

/// Finds the kept empty space of a solid grid (see the module notes).
pub fn empty_space(
    meta: &GridMeta,
    solid: &[bool],
    triangles: &[[Vec3; 3]],
    seeds: &[Seed],
    params: &EmptySpaceParams,
) -> Result<EmptySpace, BakeError> {
    let dims = meta.dims;
    let nx = dims[0] as usize;
    let mut empty: Vec<bool> = solid.iter().map(|&s| !s).collect();
    // Labelled runs along x, not a label a voxel: 4 bytes a voxel would set the bake's peak.
    let comps = grid_components(dims, |i| empty[i], Conn::C26);
    let count = comps.count;
    if count == 0 {
        return Err(BakeError::NoEmptySpace(crate::voxelize::all_solid(meta)));
    }
    let n = count as usize;
    let tally = tally(&comps, dims);
    let Placed {
        seeds_in,
        seeds_outside,
        seed_voxels,
    } = place_seeds(meta, &comps, seeds);
    let bare = seeds.is_empty() && !params.closed;
    let facing = facing(meta, solid, &comps, triangles);
    let read = read_faces(meta, &comps, facing, &tally, &seeds_in, bare, &empty);
    let (inside_component, faces_turned) = (read.inside_component, read.faces_turned);
    let (faced, first_open) = (read.faced, read.first_open);
    let located = locate_inside(meta, &comps, &empty, inside_component, &tally, params);
    let Located {
        inside_at_bounds,
        walls,
        inside,
    } = located;
    let why = Why {
        seeds_in: &seeds_in,
        seeded_any: seeds_in.iter().any(|s| !s.is_empty()),
        inside_component,
        inside_point: inside.map(|s| s.position_m),
        faces_turned,
        first_open: &first_open,
        faced: &faced,
        voxels: &tally.voxels,
        at_bounds: &tally.at_bounds,
        params,
    };
    let mut components: Vec<ComponentReport> = (0..n)
        .map(|c| {
            let (kept, reason) = why.verdict(c);
            ComponentReport {
                voxels: tally.voxels[c],
                bounds_min_m: box_m(meta, tally.lo[c], 0.0),
                bounds_max_m: box_m(meta, tally.hi[c], 1.0),
                seeds: seeds_in[c].clone(),
                faced_by: faced[c],
                kept,
                reason,
            }
        })
        .collect();
    let kept: Vec<bool> = components.iter().map(|c| c.kept).collect();
    for (r, row) in empty.chunks_mut(nx).enumerate() {
        for (a, b, l) in comps.row(r) {
            if !kept[l as usize] {
                row[a as usize..=b as usize].fill(false);
            }
        }
    }
    drop(comps);
    // Leaks: kept empty voxels next to the border ring, and the openings they pass.
    let (leaks, mut openings) = closed_leaks(meta, &empty, &seed_voxels, params)?;
    // The inside's space reaching the bounds: where, from the inside, as for a camera.
    if let (Some(s), Some(d2)) = (inside, &walls)
        && s.enclosed
    {
        let from = (INSIDE.to_string(), s.position_m, s.voxel);
        openings = crate::leak::find_openings_with(meta, &empty, d2, &[from]);
    }
    components.sort_by_key(|c| std::cmp::Reverse(c.voxels));
    let threads = hang_floating_objects(meta, &mut empty);
    let empty_voxels = empty.iter().filter(|&&e| e).count() as u64;
    if empty_voxels == 0 {
        return Err(BakeError::NoEmptySpace(
            "no empty component was kept: add a camera or a light inside the level, or lower the minimum component size".into(),
        ));
    }
    Ok(EmptySpace {
        empty,
        empty_voxels,
        components,
        leaks,
        openings,
        inside,
        inside_at_bounds,
        threads,
        seeds_outside,
        faces_turned,
    })
}

/// Each empty component's voxels, box (lowest and highest voxel) and whether it is next to
/// the border ring.
struct Tally {
    voxels: Vec<u64>,
    lo: Vec<[u32; 3]>,
    hi: Vec<[u32; 3]>,
    at_bounds: Vec<bool>,
}

/// [`Tally`] of `comps`, run by run.
fn tally(comps: &Components, dims: [u32; 3]) -> Tally {
    let [_, ny, nz] = dims.map(|d| d as usize);
    let n = comps.count as usize;
    let mut t = Tally {
        voxels: vec![0u64; n],
        lo: vec![[u32::MAX; 3]; n],
        hi: vec![[0u32; 3]; n],
        at_bounds: vec![false; n],
    };
    for r in 0..ny * nz {
        let (y, z) = ((r % ny) as u32, (r / ny) as u32);
        for (a, b, l) in comps.row(r) {
            let c = l as usize;
            t.voxels[c] += u64::from(b - a + 1);
            for v in [[a, y, z], [b, y, z]] {
                for (ax, &w) in v.iter().enumerate() {
                    t.lo[c][ax] = t.lo[c][ax].min(w);
                    t.hi[c][ax] = t.hi[c][ax].max(w);
                }
                // A run's ends are its only voxels that can be next to the ring in x; in y
                // and z all of its voxels are alike.
                t.at_bounds[c] |= crate::leak::next_to_ring(v, dims);
            }
        }
    }
    t
}

/// The scene's cameras and lights placed in the empty components.
struct Placed {
    /// Per component, what is in it.
    seeds_in: Vec<Vec<String>>,
    /// What fell outside the grid, or in solid with no empty voxel next to it.
    seeds_outside: Vec<String>,
    /// What was placed, where, and its voxel.
    seed_voxels: Vec<(String, [f32; 3], usize)>,
}

/// Places each seed in the component of its voxel, or of an empty voxel next to it.
fn place_seeds(meta: &GridMeta, comps: &Components, seeds: &[Seed]) -> Placed {
    let dims = meta.dims;
    let [nx, ny, _] = dims.map(|d| d as usize);
    let mut placed = Placed {
        seeds_in: vec![Vec::new(); comps.count as usize],
        seeds_outside: Vec::new(),
        seed_voxels: Vec::new(),
    };
    for s in seeds {
        let found = meta.world_to_voxel(s.position_m).and_then(|v| {
            // The voxel itself first, then its 26 neighbours in a fixed order.
            std::iter::once(13u32)
                .chain((0..27).filter(|&k| k != 13))
                .find_map(|k| {
                    let o = [k % 3, (k / 3) % 3, k / 9].map(|c| c as i64 - 1);
                    let w: [i64; 3] = std::array::from_fn(|a| v[a] as i64 + o[a]);
                    if (0..3).any(|a| w[a] < 0 || w[a] >= dims[a] as i64) {
                        return None;
                    }
                    let i = w[0] as usize + nx * (w[1] as usize + ny * w[2] as usize);
                    comps.label(i).map(|l| (l, i))
                })
        });
        match found {
            Some((l, i)) => {
                placed.seeds_in[l as usize].push(s.what.clone());
                placed.seed_voxels.push((s.what.clone(), s.position_m, i));
            }
            None => placed.seeds_outside.push(s.what.clone()),
        }
    }
    placed
}

/// A closed scene's leaks (its kept `empty` voxels next to the border ring, by side) and the
/// openings they pass from `seed_voxels`; an error naming them unless leaks are allowed.
/// Nothing for a scene not declared closed.
fn closed_leaks(
    meta: &GridMeta,
    empty: &[bool],
    seed_voxels: &[(String, [f32; 3], usize)],
    params: &EmptySpaceParams,
) -> Result<(Vec<Leak>, Vec<crate::leak::LeakPath>), BakeError> {
    if !params.closed {
        return Ok((Vec::new(), Vec::new()));
    }
    let leaks = leaks_by_side(meta, empty);
    if leaks.is_empty() {
        return Ok((leaks, Vec::new()));
    }
    let openings = crate::leak::find_openings(meta, empty, seed_voxels);
    if params.allow_leaks {
        return Ok((leaks, openings));
    }
    let list: Vec<String> = leaks
        .iter()
        .map(|l| {
            let (a, b) = (l.bounds_min_m, l.bounds_max_m);
            format!(
                "{} side: {} voxels in [{:.2}, {:.2}, {:.2}]..[{:.2}, {:.2}, {:.2}] m",
                l.side, l.voxels, a[0], a[1], a[2], b[0], b[1], b[2]
            )
        })
        .collect();
    Err(BakeError::Leak {
        openings,
        sides: list.join("; "),
    })
}

/// The faces as the rooms see them, and a bare mesh's inside (winding.rs).
struct Read {
    /// A bare mesh's inside: the component the most triangles face.
    inside_component: Option<u32>,
    /// Whether the faces were read turned, wound inside out.
    faces_turned: bool,
    /// Per component, the triangles whose front and whose back lie 0.75 voxel off on its side.
    faced: Vec<[u64; 2]>,
    /// Per component, the triangles whose front and whose back face it from their first open
    /// voxel.
    first_open: Vec<[u64; 2]>,
}

/// Reads the faces' votes: a scene that names no camera and no light (`bare`, a bare mesh)
/// gets its inside, as a camera would keep its component (inside.rs), and faces wound inside
/// out are read turned (winding.rs).
fn read_faces(
    meta: &GridMeta,
    comps: &Components,
    facing: Facing,
    tally: &Tally,
    seeds_in: &[Vec<String>],
    bare: bool,
    empty: &[bool],
) -> Read {
    let Facing {
        mut faced,
        fronts,
        backs,
    } = facing;
    let (at_bounds, voxels) = (&tally.at_bounds, &tally.voxels);
    let votes = crate::winding::Votes {
        faced: &faced,
        fronts: &fronts,
        backs: &backs,
        at_bounds,
    };
    let (inside_component, faces_turned) = if bare {
        let is_empty = |i: usize| empty[i];
        crate::winding::bare_inside(meta, comps, &votes, voxels, &is_empty)
    } else {
        let seeded: Vec<bool> = seeds_in.iter().map(|s| !s.is_empty()).collect();
        let turned = crate::winding::rooms_turned(&votes, &seeded)
            && !crate::winding::turning_drops_more(&votes, &seeded, voxels);
        (None, turned)
    };
    // Each component's first-open votes, [fronts, backs], the faces read as the rooms see them.
    let first_open: Vec<[u64; 2]> = fronts
        .iter()
        .zip(&backs)
        .map(|(&f, &b)| if faces_turned { [b, f] } else { [f, b] })
        .collect();
    if faces_turned {
        faced.iter_mut().for_each(|f| f.swap(0, 1));
    }
    Read {
        inside_component,
        faces_turned,
        faced,
        first_open,
    }
}

/// A bare mesh's inside where it reaches the bounds: its point and the distance field its
/// openings are looked for on.
struct Located {
    /// Whether the inside reaches the bounds (its openings looked for or not).
    inside_at_bounds: bool,
    /// The squared clearance to the walls, where the openings are looked for.
    walls: Option<Vec<u64>>,
    /// The inside's point.
    inside: Option<crate::inside::Inside>,
}

/// Only where the inside reaches the bounds (a sealed level's inside needs no point), one
/// distance field for its point and its leaks (the border ring open: a voxel by a window to
/// the void is wide, but its rays escape).
fn locate_inside(
    meta: &GridMeta,
    comps: &Components,
    empty: &[bool],
    inside_component: Option<u32>,
    tally: &Tally,
    params: &EmptySpaceParams,
) -> Located {
    let at_bounds = &tally.at_bounds;
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let inside_at_bounds = inside_component.is_some_and(|c| at_bounds[c as usize]);
    let locate = params.locate_inside_leaks
        && meta
            .voxel_count()
            .is_some_and(|v| v <= INSIDE_LEAK_MAX_VOXELS);
    let walls = (inside_at_bounds && locate).then(|| crate::leak::clearance_to_walls(meta, empty));
    let inside = inside_component.zip(walls.as_ref()).and_then(|(c, d2)| {
        // The inside's voxels, run by run: a label looked up a voxel cost seconds at 512³.
        let visit = |f: &mut dyn FnMut(usize)| {
            for r in 0..ny * nz {
                for (a, b, l) in comps.row(r) {
                    if l == c {
                        (a..=b).for_each(|x| f(r * nx + x as usize));
                    }
                }
            }
        };
        crate::inside::find_inside(meta, d2, &visit)
    });
    Located {
        inside_at_bounds,
        walls,
        inside,
    }
}

/// A corner of voxel `v`'s cube in metres: its low corner at `corner` 0, its high one at 1 (a
/// box of voxels from its lowest and highest).
fn box_m(meta: &GridMeta, v: [u32; 3], corner: f32) -> [f32; 3] {
    std::array::from_fn(|a| meta.origin_m[a] + (v[a] as f32 + corner) * meta.voxel_size_m)
}

/// Where the kept `empty` voxels of a closed scene touch each side of the bounds (the voxels
/// next to the border ring): a leak per side touched, with its count and box.
fn leaks_by_side(meta: &GridMeta, empty: &[bool]) -> Vec<Leak> {
    const SIDES: [&str; 6] = ["-x", "+x", "-y", "+y", "-z", "+z"];
    let dims = meta.dims;
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut acc: Vec<(u64, [u32; 3], [u32; 3])> = vec![(0, [u32::MAX; 3], [0; 3]); 6];
    for z in 1..nz - 1 {
        for y in 1..ny - 1 {
            for x in 1..nx - 1 {
                if !empty[x + nx * (y + ny * z)] {
                    continue;
                }
                let v = [x, y, z];
                for a in 0..3 {
                    for (s, edge) in [(2 * a, 1), (2 * a + 1, dims[a] as usize - 2)] {
                        if v[a] == edge {
                            let e = &mut acc[s];
                            e.0 += 1;
                            for (b, &c) in v.iter().enumerate() {
                                e.1[b] = e.1[b].min(c as u32);
                                e.2[b] = e.2[b].max(c as u32);
                            }
                        }
                    }
                }
            }
        }
    }
    acc.into_iter()
        .enumerate()
        .filter(|(_, (count, ..))| *count > 0)
        .map(|(s, (count, l, h))| Leak {
            side: SIDES[s],
            voxels: count,
            bounds_min_m: box_m(meta, l, 0.0),
            bounds_max_m: box_m(meta, h, 1.0),
        })
        .collect()
}

/// Which side of each triangle each of `comps`' components lies on (`[front, back]`
/// counts), sampled 0.75 voxel off the triangle's centroid along its normal and against it;
/// and the triangles whose front and whose back face each component
/// seen from the first voxel off the centroid that is not solid (0.75, 1.5 or 2.25 voxels along
/// the normal or against it): a wall that lies on a voxel boundary is voxelized into the layers
/// on both sides of it, so 0.75 voxel off it is its own solid and the first count gives it to
/// no side.
fn facing(
    meta: &GridMeta,
    solid: &[bool],
    comps: &crate::neighbourhood::Components,
    triangles: &[[Vec3; 3]],
) -> Facing {
    let n = comps.count as usize;
    let vs = meta.voxel_size_m;
    let label_at = |p: Vec3| {
        let i = meta.index(meta.world_to_voxel(p.to_array())?);
        Some((solid[i], comps.label(i)))
    };
    // Per component: [faced front, faced back, first open front, first open back], summed
    // over chunks of triangles in parallel (integer sums: the same in any order).
    let count = |mut acc: Vec<[u64; 4]>, t: &[Vec3; 3]| {
        let nrm = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        if nrm == Vec3::ZERO {
            return acc;
        }
        let c = (t[0] + t[1] + t[2]) / 3.0;
        for (side, dir) in [(0, nrm), (1, -nrm)] {
            let near = label_at(c + dir * (0.75 * vs));
            if let Some((_, Some(l))) = near {
                acc[l as usize][side] += 1;
            }
            let first_open = std::iter::once(near)
                .chain([1.5, 2.25].map(|k| label_at(c + dir * (k * vs))))
                .find_map(|x| x.filter(|&(s, _)| !s));
            if let Some((_, Some(l))) = first_open {
                acc[l as usize][2 + side] += 1;
            }
        }
        acc
    };
    let sums = triangles
        .par_chunks(8192)
        .map(|chunk| chunk.iter().fold(vec![[0u64; 4]; n], count))
        .reduce(
            || vec![[0u64; 4]; n],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    *x = std::array::from_fn(|k| x[k] + y[k]);
                }
                a
            },
        );
    Facing {
        faced: sums.iter().map(|s| [s[0], s[1]]).collect(),
        fronts: sums.iter().map(|s| s[2]).collect(),
        backs: sums.iter().map(|s| s[3]).collect(),
    }
}

/// What [`facing`] counts.
struct Facing {
    /// Per component, the triangles whose front and whose back lie on its side.
    faced: Vec<[u64; 2]>,
    /// Per component, the triangles whose front faces it from their first open voxel.
    fronts: Vec<u64>,
    /// Per component, the triangles whose back faces it from their first open voxel.
    backs: Vec<u64>,
}

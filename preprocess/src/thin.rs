//! Stage 5, thin: the empty space → a curvilinear skeleton with the same topology.
//!
//! Asymmetric parallel thinning by critical kernels with 1D isthmuses and persistence
//! (Couprie & Bertrand, Pattern Recognition Letters 76, 2016; the critical-kernel theorem of
//! Bertrand & Couprie). Each step works on the current border only:
//!
//! 1. every border voxel that is a 1D isthmus (`T26 >= 2`: it lies inside a curve) gets a birth
//!    step; once it has been an isthmus for `persistence` steps it joins the constraint set
//!    `K` and is never deleted — so curves shorter than the persistence (the branches that
//!    noise on a wall sprouts) are eaten from their ends before they are kept;
//! 2. the candidates are the simple voxels not in `K`;
//! 3. critical cliques made only of candidates get one voxel kept: first the 2-cliques (two
//!    face neighbours whose 3 × 3 × 2 slab projects onto a non-simple 2D configuration), then
//!    the 1-cliques (four voxels around an edge holding a diagonal pair, whose layers above
//!    and below are both empty or both not), then the 0-cliques (a 2 × 2 × 2 cube holding
//!    an antipodal pair). A clique that already holds a kept voxel needs none. The kept voxel
//!    is the one farthest from the solid (largest distance value, then lowest index), so the
//!    skeleton is centred;
//! 4. every candidate not kept is deleted, all at once. By the critical-kernel theorem this
//!    preserves topology.
//!
//! The cliques are found in parallel and resolved in voxel order, so the result does not depend
//! on the number of threads. Thinning stops when a step deletes nothing.

use rayon::prelude::*;

use crate::neighbourhood::{RING, bit, is_simple_2d, isthmus_and_simple};
use crate::thin_next::{Marks, next_by_lists, next_by_words};

/// Parameters of [`thin`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThinParams {
    /// Steps a voxel must stay a 1D isthmus before it is kept. 0 keeps every curve at once
    /// (noisy walls then sprout branches); it should grow with the resolution.
    /// [Units: thinning steps, one voxel layer each]
    pub persistence: u32,
}

/// The result of [`thin`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Thinned {
    /// Skeleton voxels, ascending voxel index.
    pub skeleton: Vec<u32>,
    /// Thinning steps until stable.
    pub steps: u32,
    /// Voxels of the constraint set (kept 1D isthmuses).
    pub constrained: u64,
    /// Voxels examined, summed over all steps (the work done).
    pub border_visits: u64,
}

pub(crate) const X: u8 = 1;
pub(crate) const K: u8 = 2;
const CAND: u8 = 4;
const SEL: u8 = 8;

/// Thins `object` (true = empty voxel, none on the grid's edge) to a curvilinear skeleton.
/// `dist2` orders the voxels of a critical clique (the farthest from the solid is kept).
/// `progress(deleted, total)` is called after each step.
pub fn thin(
    dims: [u32; 3],
    object: &[bool],
    dist2: &[u64],
    params: &ThinParams,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Thinned {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let sx = 1isize;
    let sy = nx as isize;
    let sz = (nx * ny) as isize;
    let off: [isize; 27] = std::array::from_fn(|k| {
        let k = k as isize;
        (k % 3 - 1) * sx + ((k / 3) % 3 - 1) * sy + (k / 9 - 1) * sz
    });
    let mut flags: Vec<u8> = object.iter().map(|&o| if o { X } else { 0 }).collect();
    let total = object.iter().filter(|&&o| o).count() as u64;
    // Voxels to examine: at first the whole border, then those whose neighbourhood changed.
    let mut border = initial_border(&flags, [nx, ny, nz]);
    let mut birth: Vec<u16> = vec![u16::MAX; flags.len()];
    let mut marks = Marks::new(flags.len());
    let mut deleted_total = 0u64;
    let mut border_visits = 0u64;
    let mut step: u32 = 0;
    // Object bits of the neighbourhood of `i`.
    let object_mask = |flags: &[u8], i: usize| -> u32 {
        let mut xm = 0u32;
        for (k, &o) in off.iter().enumerate() {
            xm |= u32::from(flags[(i as isize + o) as usize] & X) << k;
        }
        xm
    };
    loop {
        step += 1;
        border_visits += border.len() as u64;
        // 1–2: isthmuses and simple voxels.
        let status: Vec<(bool, bool, u32)> = border
            .par_iter()
            .map(|&i| {
                let i = i as usize;
                if flags[i] & K != 0 {
                    return (false, false, 0);
                }
                let m = object_mask(&flags, i);
                let (isthmus, simple) = isthmus_and_simple(m);
                (isthmus, simple, m)
            })
            .collect();
        let s16 = step.min(u16::MAX as u32 - 1) as u16;
        // The candidates and their object masks (their neighbours' objects stay until step 4).
        let mut candidates = Vec::new();
        let mut candidate_xm = Vec::new();
        for (&i, &(isthmus, simple, xm)) in border.iter().zip(&status) {
            let i = i as usize;
            if isthmus {
                if birth[i] == u16::MAX {
                    birth[i] = s16;
                }
                if u32::from(s16 - birth[i]) >= params.persistence {
                    flags[i] |= K;
                }
            }
            if simple && flags[i] & K == 0 {
                flags[i] |= CAND;
                candidates.push(i as u32);
                candidate_xm.push(xm);
            }
        }
        if candidates.is_empty() {
            break;
        }
        // 3: critical cliques of candidates, found in parallel, resolved in order.
        let by_phase = find_cliques(&flags, &off, &candidates, &candidate_xm);
        keep_one_of_each(&mut flags, dist2, &by_phase);
        // 4: delete the candidates not kept.
        let deleted = delete_unkept(&mut flags, &candidates);
        if deleted.is_empty() {
            break;
        }
        deleted_total += deleted.len() as u64;
        progress(deleted_total, total);
        // Next step's voxels to examine: only those whose neighbourhood changed (a voxel's
        // status depends on nothing else), and the isthmuses still waiting for persistence.
        // Voxels not examined are kept this step, which is always safe.
        let waiting: Vec<u32> = border
            .iter()
            .copied()
            .filter(|&i| flags[i as usize] & (X | K) == X && birth[i as usize] != u16::MAX)
            .collect();
        let next = match deleted.len() >= 2 * marks.words() {
            true => next_by_words(&flags, [nx, ny], &deleted, &waiting),
            false => next_by_lists(&flags, &mut marks, &deleted, &waiting, &off),
        };
        border = next;
    }
    let skeleton: Vec<u32> = (0..flags.len())
        .into_par_iter()
        .filter(|&i| flags[i] & X != 0)
        .map(|i| i as u32)
        .collect();
    let constrained = flags.par_iter().filter(|&&f| f & K != 0).count() as u64;
    Thinned {
        skeleton,
        steps: step,
        constrained,
        border_visits,
    }
}

/// The object's voxels with a face neighbour outside it (`flags`' X bit), in order. The
/// object never touches the grid's edge (its border ring is solid).
fn initial_border(flags: &[u8], [nx, ny, nz]: [usize; 3]) -> Vec<u32> {
    let face = [
        1,
        -1,
        nx as isize,
        -(nx as isize),
        (nx * ny) as isize,
        -((nx * ny) as isize),
    ];
    (0..flags.len())
        .into_par_iter()
        .filter(|&i| {
            flags[i] & X != 0 && {
                let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
                debug_assert!(x > 0 && y > 0 && z > 0 && x < nx - 1 && y < ny - 1 && z < nz - 1);
                face.iter()
                    .any(|&f| flags[(i as isize + f) as usize] & X == 0)
            }
        })
        .map(|i| i as u32)
        .collect()
}

/// Deletes the `candidates` no clique kept (SEL clear) from the object, clears every
/// candidate's marks, and returns the deleted, in order.
fn delete_unkept(flags: &mut [u8], candidates: &[u32]) -> Vec<u32> {
    let mut deleted = Vec::new();
    for &i in candidates {
        let f = &mut flags[i as usize];
        if *f & SEL == 0 {
            *f &= !X;
            deleted.push(i);
        }
        *f &= !(CAND | SEL);
    }
    deleted
}

/// The critical cliques through `candidates` (with their object masks `xm`) whose members are
/// all candidates: by phase, then by candidate, then by template — the order they are
/// resolved in.
fn find_cliques(
    flags: &[u8],
    off: &[isize; 27],
    candidates: &[u32],
    xm: &[u32],
) -> [Vec<Clique>; 3] {
    // Candidate bits of the object voxels above `i` and of `i` itself (a candidate): all a
    // clique through `i` may hold (critical_cliques).
    let candidate_mask = |i: usize, xm: u32| -> u32 {
        let mut cm = CENTRE_BIT;
        let mut above = xm & ABOVE_CENTRE;
        while above != 0 {
            let k = above.trailing_zeros();
            above &= above - 1;
            if flags[(i as isize + off[k as usize]) as usize] & CAND != 0 {
                cm |= 1 << k;
            }
        }
        cm
    };
    candidates
        .par_iter()
        .zip(xm)
        .fold(Default::default, |mut out: [Vec<Clique>; 3], (&i, &xm)| {
            let cm = candidate_mask(i as usize, xm);
            critical_cliques(xm, cm, |phase, mut bits| {
                let mut c = Clique {
                    members: [0; 8],
                    len: 0,
                };
                while bits != 0 {
                    let k = bits.trailing_zeros();
                    bits &= bits - 1;
                    c.members[c.len as usize] = (i as isize + off[k as usize]) as u32;
                    c.len += 1;
                }
                out[phase as usize].push(c);
            });
            out
        })
        .reduce(Default::default, |mut a, b| {
            for (a, mut b) in a.iter_mut().zip(b) {
                a.append(&mut b);
            }
            a
        })
}

/// Marks SEL one voxel of each clique of `by_phase` that holds none yet: the farthest from the
/// solid (`dist2`), then the lowest index.
fn keep_one_of_each(flags: &mut [u8], dist2: &[u64], by_phase: &[Vec<Clique>; 3]) {
    for c in by_phase.iter().flatten() {
        let members = &c.members[..c.len as usize];
        if members.iter().any(|&m| flags[m as usize] & SEL != 0) {
            continue;
        }
        let best = members
            .iter()
            .copied()
            .max_by(|&a, &b| dist2[a as usize].cmp(&dist2[b as usize]).then(b.cmp(&a)))
            .unwrap_or(members[0]);
        flags[best as usize] |= SEL;
    }
}

/// A clique's object members: the bits of the finder's neighbourhood, then voxel indices.
#[derive(Debug, Clone, Copy)]
struct Clique {
    members: [u32; 8],
    len: u8,
}

/// The ways a critical clique can pass through the centre of a neighbourhood, as bit masks, in
/// the order the cliques are resolved within a phase.
struct Templates {
    /// 2-cliques {centre, other} (one per axis, `other` the face neighbour above): `other`'s
    /// bit and the 8 pairs of bits whose union is the projected ring.
    two: [(u32, [(u32, u32); 8]); 3],
    /// 1-cliques: the square's bits, its two diagonals, and the layers below and above.
    one: [OneClique; 12],
    /// 0-cliques: the cube's bits and its four antipodal pairs.
    zero: [(u32, [u32; 4]); 8],
}

/// A 1-clique's masks ([`Templates::one`]).
#[derive(Debug, Clone, Copy, Default)]
struct OneClique {
    square: u32,
    diagonals: [u32; 2],
    below: u32,
    above: u32,
}

fn templates() -> &'static Templates {
    static T: std::sync::LazyLock<Templates> = std::sync::LazyLock::new(|| {
        let b = |p: [i32; 3]| 1u32 << bit(p[0], p[1], p[2]);
        let place = |axis: usize, a: i32, u: i32, v: i32| -> [i32; 3] {
            match axis {
                0 => [a, u, v],
                1 => [u, a, v],
                _ => [u, v, a],
            }
        };
        let two = [0, 1, 2].map(|axis| {
            let ring = RING.map(|(u, v)| {
                (
                    bit_index(place(axis, 0, u, v)),
                    bit_index(place(axis, 1, u, v)),
                )
            });
            (bit_index(place(axis, 1, 0, 0)), ring)
        });
        // A corner's offset from its place in the order: -1 first, then 0.
        let low = |place: usize| place as i32 - 1;
        let mut one = [OneClique::default(); 12];
        for (k, t) in one.iter_mut().enumerate() {
            // Axis by axis, the square's low corner at u then v = -1, 0 (the cliques' order).
            let (axis, su, sv) = (k / 4, low(k / 2 % 2), low(k % 2));
            let sq = [(su, sv), (su + 1, sv), (su, sv + 1), (su + 1, sv + 1)];
            let layer = |a: i32| sq.iter().fold(0, |m, &(u, v)| m | b(place(axis, a, u, v)));
            let p = sq.map(|(u, v)| b(place(axis, 0, u, v)));
            *t = OneClique {
                square: layer(0),
                diagonals: [p[0] | p[3], p[1] | p[2]],
                below: layer(-1),
                above: layer(1),
            };
        }
        let zero = std::array::from_fn(|k| {
            let (cx, cy, cz) = (low(k / 4), low(k / 2 % 2), low(k % 2));
            let corner = |c: i32| b([cx + (c & 1), cy + ((c >> 1) & 1), cz + ((c >> 2) & 1)]);
            (
                (0..8).fold(0, |m, c| m | corner(c)),
                [0, 1, 2, 3].map(|c| corner(c) | corner(7 - c)),
            )
        });
        Templates { two, one, zero }
    });
    &T
}

fn bit_index(p: [i32; 3]) -> u32 {
    bit(p[0], p[1], p[2])
}

/// Bits whose voxel index is above the centre's (the offsets grow with the bit index).
const ABOVE_CENTRE: u32 = !((1 << 14) - 1) & ((1 << 27) - 1);
const CENTRE_BIT: u32 = 1 << 13;

/// Critical cliques through the centre of neighbourhood `xm` (object bits) whose object
/// members are all candidates (`cm`, read only above the centre and at it) and whose
/// lowest-index member is the centre. Phases:
/// 0 = 2-cliques, 1 = 1-cliques, 2 = 0-cliques. Members are returned as bit masks.
fn critical_cliques(xm: u32, cm: u32, mut emit: impl FnMut(u8, u32)) {
    // Every clique has a member besides the centre (a face neighbour, or the other end of a
    // diagonal or antipodal pair), which must be a candidate above it.
    let eligible_bits = cm & (ABOVE_CENTRE | CENTRE_BIT);
    if eligible_bits & ABOVE_CENTRE == 0 {
        return;
    }
    let eligible = |members: u32| members & !eligible_bits == 0;
    let t = templates();
    for &(other, ring) in &t.two {
        if eligible_bits >> other & 1 == 0 {
            continue;
        }
        let mut r = 0u8;
        for (k, (p, q)) in ring.iter().enumerate() {
            if (xm >> p | xm >> q) & 1 == 1 {
                r |= 1 << k;
            }
        }
        if !is_simple_2d(r) {
            emit(0, CENTRE_BIT | 1 << other);
        }
    }
    for o in &t.one {
        let members = xm & o.square;
        if !eligible(members) || o.diagonals.iter().all(|&d| xm & d != d) {
            continue;
        }
        if (xm & o.below != 0) == (xm & o.above != 0) {
            emit(1, members);
        }
    }
    for &(cube, antipodes) in &t.zero {
        let members = xm & cube;
        if eligible(members) && antipodes.iter().any(|&d| d & !xm == 0) {
            emit(2, members);
        }
    }
}

/// Re-extends the ends of the skeleton that persistence shortened: from every end voxel (one
/// skeleton neighbour) it climbs the distance map by steepest ascent — to the empty
/// 26-neighbour of largest distance, while that is strictly larger — and adds the voxels
/// climbed. A climb stops before touching any other part of the skeleton, so topology is
/// unchanged. Returns the voxels added. `skeleton` stays sorted.
pub fn extend_ends(dims: [u32; 3], object: &[bool], dist2: &[u64], skeleton: &mut Vec<u32>) -> u64 {
    let [nx, ny, _] = dims.map(|d| d as isize);
    let off: Vec<isize> = (0..27isize)
        .filter(|&k| k != 13)
        .map(|k| (k % 3 - 1) + nx * ((k / 3) % 3 - 1) + nx * ny * (k / 9 - 1))
        .collect();
    let mut in_skel = vec![false; object.len()];
    skeleton.iter().for_each(|&i| in_skel[i as usize] = true);
    let neighbours = |in_skel: &[bool], i: usize| -> Vec<usize> {
        off.iter()
            .map(|&o| (i as isize + o) as usize)
            .filter(|&j| in_skel[j])
            .collect()
    };
    let ends: Vec<u32> = skeleton
        .iter()
        .copied()
        .filter(|&i| neighbours(&in_skel, i as usize).len() == 1)
        .collect();
    let mut added = Vec::new();
    for end in ends {
        let (mut tip, mut prev) = (end as usize, neighbours(&in_skel, end as usize)[0]);
        loop {
            let next = off
                .iter()
                .map(|&o| (tip as isize + o) as usize)
                .filter(|&j| object[j] && !in_skel[j] && dist2[j] > dist2[tip])
                .max_by(|&a, &b| dist2[a].cmp(&dist2[b]).then(b.cmp(&a)));
            let Some(next) = next else { break };
            if neighbours(&in_skel, next)
                .iter()
                .any(|&j| j != tip && j != prev)
            {
                break;
            }
            in_skel[next] = true;
            added.push(next as u32);
            prev = tip;
            tip = next;
        }
    }
    let n = added.len() as u64;
    skeleton.extend(added);
    skeleton.sort_unstable();
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(dims: [u32; 3], f: impl Fn(u32, u32, u32) -> bool) -> Vec<bool> {
        let mut v = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let inner = x > 0
                        && y > 0
                        && z > 0
                        && x + 1 < dims[0]
                        && y + 1 < dims[1]
                        && z + 1 < dims[2];
                    v.push(inner && f(x, y, z));
                }
            }
        }
        v
    }

    #[test]
    fn the_next_step_s_voxels_by_words_are_those_by_lists() {
        // Random object, constraint and deleted voxels inside grids whose rows are and are not
        // whole words: both ways list the same voxels, in order.
        let mut next = crate::xorshift32(0x51ed_270b);
        for dims in [[64u32, 5, 6], [23, 9, 7], [70, 4, 5]] {
            let [nx, ny, _] = dims.map(|d| d as usize);
            let off: [isize; 27] = std::array::from_fn(|k| {
                let k = k as isize;
                (k % 3 - 1) + (k / 3 % 3 - 1) * nx as isize + (k / 9 - 1) * (nx * ny) as isize
            });
            for density in [5, 40, 90] {
                let inner = grid(dims, |_, _, _| true);
                let flags: Vec<u8> = inner
                    .iter()
                    .map(|&o| match o && next() % 100 < density {
                        true if next().is_multiple_of(10) => X | K,
                        true => X,
                        false => 0,
                    })
                    .collect();
                let deleted: Vec<u32> = (0..flags.len() as u32)
                    .filter(|&i| {
                        inner[i as usize] && flags[i as usize] == 0 && next().is_multiple_of(3)
                    })
                    .collect();
                let waiting: Vec<u32> = (0..flags.len() as u32)
                    .filter(|&i| flags[i as usize] == X && next().is_multiple_of(7))
                    .collect();
                let mut marks = Marks::new(flags.len());
                let by_lists = next_by_lists(&flags, &mut marks, &deleted, &waiting, &off);
                let by_words = next_by_words(&flags, [nx, ny], &deleted, &waiting);
                assert!(!by_lists.is_empty(), "{dims:?} at {density} %");
                assert_eq!(by_words, by_lists, "{dims:?} at {density} %");
                // The marks are cleared for the next step: the same lists again.
                assert_eq!(
                    next_by_lists(&flags, &mut marks, &deleted, &waiting, &off),
                    by_lists
                );
            }
        }
    }

    fn thinned(dims: [u32; 3], obj: &[bool]) -> (Thinned, crate::betti::Betti) {
        let solid: Vec<bool> = obj.iter().map(|&o| !o).collect();
        let d = crate::distance::squared_distance(dims, &solid);
        let t = thin(dims, obj, &d, &ThinParams { persistence: 0 }, &|_, _| {});
        let mut s = vec![false; obj.len()];
        t.skeleton.iter().for_each(|&i| s[i as usize] = true);
        let b = crate::betti::betti(dims, &s);
        (t, b)
    }

    #[test]
    fn a_box_thins_to_a_point_and_a_bar_to_a_line() {
        let dims = [12, 12, 12];
        let (t, b) = thinned(dims, &grid(dims, |_, _, _| true));
        assert_eq!((b.components, b.cycles, b.cavities), (1, 0, 0));
        assert!(
            t.skeleton.len() <= 2,
            "a cube keeps {} voxels",
            t.skeleton.len()
        );
        // A 30 × 4 × 4 bar keeps a line along x, most of its length.
        let dims = [32, 6, 6];
        let (t, b) = thinned(dims, &grid(dims, |_, _, _| true));
        assert_eq!((b.components, b.cycles), (1, 0));
        let xs: Vec<u32> = t.skeleton.iter().map(|&i| i % 32).collect();
        let span = xs.iter().max().unwrap_or(&0) - xs.iter().min().unwrap_or(&0);
        assert!(span >= 20, "the line spans {span} voxels of 30");
        assert_eq!(t.skeleton.len() as u32, span + 1, "one voxel thin");
    }
}

//! Clusters that do not reach around walls. The nearest-node rule gives a doorway node's
//! cluster the voxels on both sides of a thin wall beside the doorway, so a cluster wraps
//! around the wall's edge and stops being quasi-convex: light then "passes" the wall inside
//! one cluster. Here an empty voxel keeps its cluster only if it sees, along a line of empty
//! voxels, the cluster's seed (the centre of its largest ball) or its own segmented node when
//! that node is of its cluster; the others take the cluster of the nearest voxel that keeps
//! one (breadth-first through empty space). Voxels that are not
//! empty get no cluster: a surface point takes the cluster of the empty voxel its side faces.
//!
//! **Speed.** A sight line is a 3D DDA over every voxel it crosses, and a 512³ level asks for
//! tens of millions of lines of a few hundred voxels. Most of their length runs through open
//! space, where the distance field already says that no obstacle is near: [`Sight::sees`]
//! walks the DDA only where the space is narrow and, where it is wide, proves whole stretches
//! clear with the voxels' clearance (a sphere march, as in sphere tracing). A stretch is
//! skipped only when every voxel the DDA could cross in it is empty, so the answer is the
//! DDA's, bit for bit (tested against the plain DDA over random grids).

use std::collections::VecDeque;

use glam::Vec3;
use rayon::prelude::*;

use visgate_formats::vgate::{GridMeta, NONE};

/// The empty voxels, and optionally each voxel's clearance: a lower bound, in whole voxels, of
/// the distance from its centre to the centre of the nearest voxel that is not empty (the
/// max-ball radii of the distance stage are one).
#[derive(Debug, Clone, Copy)]
pub struct Sight<'a> {
    /// The grid.
    pub meta: &'a GridMeta,
    /// Empty voxels.
    pub empty: &'a [bool],
    /// Each voxel's clearance in whole voxels, if known (0 for voxels that are not empty).
    pub clearance_vx: Option<&'a [u16]>,
}

/// Clearance below which a stretch is walked voxel by voxel: a proof's steps read voxels far
/// along the line, and below 5 voxels they are too short to pay for it (Crytek Sponza 256's
/// sight lines 0.54 → 0.50 s with 5 instead of 3; 8 was slower again). [Units: voxels]
const MIN_PROOF_CLEARANCE: u16 = 5;
/// What a voxel crossed by the line lies from the line (half a diagonal), twice — at the
/// proof's point and at the crossed voxel — plus a margin for rounding. [Units: voxels]
const PROOF_SLACK: f32 = 1.75;

impl<'a> Sight<'a> {
    /// Whether the voxels strictly between voxels `from` and `to` are all empty: a 3D DDA
    /// (Amanatides & Woo) between their centres, in voxel units and exact integer arithmetic,
    /// so that a line through voxel edges and corners takes the same voxels at every scale of
    /// the level (on a tie the lowest axis steps first).
    ///
    /// The line's `n`-th crossing of a voxel boundary on axis `k` comes at `t = (2n + 1) /
    /// (2 |d_k|)`; in units of `1 / (2 P)`, `P` the product of the non-zero `|d_k|`, that is
    /// the integer `(2n + 1) · P / |d_k|`, so crossings compare exactly and the walk can jump
    /// to any time: after a stretch proved clear it resumes where the proof stopped.
    pub fn sees(&self, from: [u32; 3], to: [u32; 3]) -> bool {
        let dims = self.meta.dims;
        match self.clearance_vx {
            None => walk(dims, &Plain(self.empty), from, to),
            Some(clear) => walk(
                dims,
                &Split {
                    empty: self.empty,
                    clear,
                },
                from,
                to,
            ),
        }
    }

    /// The same sight lines over one byte a voxel: 0 where not empty, else 1 + the clearance
    /// (saturated at 254, which only shortens a proof's steps): a third of the memory of the
    /// flags and the clearance together and one load a step (measured with the stepping by
    /// stride: Crytek Sponza's 512 flatten 1.40 → 1.25 s).
    pub fn packed(&self) -> PackedSight<'a> {
        let cells = self
            .empty
            .par_iter()
            .enumerate()
            .map(|(i, &e)| {
                let r = self.clearance_vx.map_or(0, |c| c[i]);
                if e { r.min(254) as u8 + 1 } else { 0 }
            })
            .collect();
        PackedSight {
            meta: self.meta,
            cells,
        }
    }
}

/// Sight lines over one byte a voxel ([`Sight::packed`]).
pub struct PackedSight<'a> {
    /// The grid.
    pub meta: &'a GridMeta,
    cells: Vec<u8>,
}

impl PackedSight<'_> {
    /// [`Sight::sees`], with the same answer.
    pub fn sees(&self, from: [u32; 3], to: [u32; 3]) -> bool {
        walk(self.meta.dims, &self.cells[..], from, to)
    }

    /// Whether voxel `i` is empty.
    pub fn empty(&self, i: usize) -> bool {
        self.cells[i] != 0
    }

    /// A byte a voxel: 0 where not empty, else 1 + its clearance saturated at 254.
    pub fn cells(&self) -> &[u8] {
        &self.cells
    }
}

/// What a sight line reads of a voxel: whether it is empty, and its clearance (0 when not
/// known, so that no proof starts there).
trait Cells {
    fn empty(&self, i: usize) -> bool;
    fn clearance(&self, i: usize) -> u16;
}

/// Empty flags alone.
struct Plain<'a>(&'a [bool]);

impl Cells for Plain<'_> {
    fn empty(&self, i: usize) -> bool {
        self.0[i]
    }
    fn clearance(&self, _: usize) -> u16 {
        0
    }
}

/// Empty flags and the clearance, apart.
struct Split<'a> {
    empty: &'a [bool],
    clear: &'a [u16],
}

impl Cells for Split<'_> {
    fn empty(&self, i: usize) -> bool {
        self.empty[i]
    }
    fn clearance(&self, i: usize) -> u16 {
        self.clear[i]
    }
}

impl Cells for [u8] {
    fn empty(&self, i: usize) -> bool {
        self[i] != 0
    }
    fn clearance(&self, i: usize) -> u16 {
        u16::from(self[i].saturating_sub(1))
    }
}

/// [`Sight::sees`] over any cells.
fn walk<C: Cells + ?Sized>(dims: [u32; 3], cells: &C, from: [u32; 3], to: [u32; 3]) -> bool {
    let (from, to) = (from.map(i64::from), to.map(i64::from));
    let d: [i64; 3] = std::array::from_fn(|k| to[k] - from[k]);
    // |d_k|, with 1 for an axis not crossed, so that products skip it.
    let m = d.map(|x| x.abs().max(1));
    let p: i64 = m[0] * m[1] * m[2];
    // Boundary-crossing period per axis, in units of 1 / (2P): P / |d_k|, the product of
    // the other two; 0 for an axis not crossed.
    let q: [i64; 3] = std::array::from_fn(|k| {
        if d[k] == 0 {
            0
        } else {
            m[(k + 1) % 3] * m[(k + 2) % 3]
        }
    });
    let step = d.map(i64::signum);
    let dims = dims.map(i64::from);
    let index = |c: [i64; 3]| (c[0] + dims[0] * (c[1] + dims[1] * c[2])) as usize;
    // Within an end's clearance (less the slack) the whole segment is: every voxel it
    // crosses has its centre nearer that end's than any voxel that is not empty.
    let len2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f32;
    let within = |c: [i64; 3]| {
        let r = f32::from(cells.clearance(index(c))) - PROOF_SLACK;
        r > 0.0 && len2 <= r * r
    };
    if within(to) || within(from) {
        return true;
    }
    let two_p = 2 * p;
    // The walk stays in the box of the two voxels (both in the grid): a voxel's index
    // moves by a stride a step.
    let stride = [1, dims[0], dims[0] * dims[1]];
    let crossing = |k: usize, n: i64| {
        if q[k] == 0 {
            i64::MAX
        } else {
            (2 * n + 1) * q[k]
        }
    };
    // Each axis's next crossing, its period and the index's move at it, as scalars: the
    // step picks one by comparisons, not by an index into arrays (kept in memory, that cost
    // the bake's sight lines a fifth of their time).
    let [mut t0, mut t1, mut t2] = [0, 1, 2].map(|k| crossing(k, 0));
    let [p0, p1, p2] = q.map(|x| 2 * x);
    let [m0, m1, m2] = [0, 1, 2].map(|k| step[k] * stride[k]);
    let (mut i, end) = (index(from) as i64, index(to) as i64);
    let line = Line::between(from, d);
    // A proof is tried again only past the narrow place where the last one stopped.
    let mut retry_from = 0i64;
    loop {
        // The axis whose boundary comes first, the lowest on a tie.
        let entered;
        if t0 <= t1 && t0 <= t2 {
            entered = t0;
            t0 += p0;
            i += m0;
        } else if t1 <= t2 {
            entered = t1;
            t1 += p1;
            i += m1;
        } else {
            entered = t2;
            t2 += p2;
            i += m2;
        }
        if entered > two_p {
            return true;
        }
        if i == end {
            return true;
        }
        if !cells.empty(i as usize) {
            return false;
        }
        let here = cells.clearance(i as usize);
        if entered < retry_from || here < MIN_PROOF_CLEARANCE {
            continue;
        }
        let t_start = entered as f64 / two_p as f64;
        match prove_clear(&|i| cells.clearance(i), dims, &line, t_start as f32, here) {
            Ok(()) => return true,
            Err(stopped) => {
                // Every crossing up to `stopped` is proved clear: jump past them.
                let tau = ((f64::from(stopped) * two_p as f64).floor() as i64).min(two_p);
                if tau > entered {
                    // Crossings made along each axis by then, and the voxel reached.
                    let n = q.map(|qk| if qk == 0 { 0 } else { (tau / qk + 1) / 2 });
                    [t0, t1, t2] = [0, 1, 2].map(|k| crossing(k, n[k]));
                    let cell: [i64; 3] = std::array::from_fn(|k| from[k] + step[k] * n[k]);
                    i = index(cell) as i64;
                    if i == end {
                        return true;
                    }
                }
                retry_from = tau.max(entered) + 1;
            }
        }
    }
}

/// A segment `a + t·d`, `t` in 0..=1. [Units: voxels]
struct Line {
    a: Vec3,
    d: Vec3,
}

impl Line {
    /// From the centre of voxel `from` along `d` (to the centre of voxel `from + d`).
    fn between(from: [i64; 3], d: [i64; 3]) -> Line {
        Line {
            a: Vec3::from(from.map(|c| c as f32 + 0.5)),
            d: Vec3::from(d.map(|c| c as f32)),
        }
    }
}

/// Proves that every voxel the segment crosses for `t` from `t0` to 1 is empty, by steps of
/// the clearance at each point less the slack; `r0` is the clearance of a voxel whose cube
/// holds the point at `t0`. `Err(t)`: proved up to `t`, where a voxel's clearance is too
/// small to go on.
fn prove_clear(
    clear: &impl Fn(usize) -> u16,
    dims: [i64; 3],
    line: &Line,
    t0: f32,
    r0: u16,
) -> Result<(), f32> {
    let len = line.d.length();
    let (mut t, mut r) = (t0, r0);
    loop {
        if r < MIN_PROOF_CLEARANCE {
            return Err(t);
        }
        t += (f32::from(r) - PROOF_SLACK) / len;
        if t >= 1.0 {
            return Ok(());
        }
        // Points of the segment lie in the grid's box (coordinates ≥ 0.5): truncation floors.
        let c = (line.a + line.d * t).as_i64vec3().to_array();
        if (0..3).any(|k| c[k] < 0 || c[k] >= dims[k]) {
            return Err(t);
        }
        r = clear((c[0] + dims[0] * (c[1] + dims[1] * c[2])) as usize);
    }
}

/// Reassigns the clusters of empty voxels that see neither their cluster's seed (its voxel in
/// `seeds`, by cluster) nor their `anchor` (a cluster and a voxel: the voxel's own segmented
/// node, which counts only when of the voxel's cluster), and clears the cluster of voxels that
/// are not empty. Returns how many empty voxels changed cluster.
pub fn clusters_by_sight(
    sight: &PackedSight,
    cluster: &mut [u32],
    seeds: &[[u32; 3]],
    anchor: &(dyn Fn(usize) -> Option<(u32, [u32; 3])> + Sync),
) -> u64 {
    let meta = sight.meta;
    let empty = |i: usize| sight.empty(i);
    // A voxel that had a cluster and sees neither its node nor its seed waits for a new one.
    let mut pending: Vec<bool> = cluster
        .par_iter()
        .enumerate()
        .map(|(i, &c)| {
            if !empty(i) || c == NONE {
                return false;
            }
            let at = meta.coords(i as u32);
            // The voxel's own node first: it is usually nearer than the seed, so its line is
            // shorter.
            let sees_own = anchor(i).is_some_and(|(ac, v)| ac == c && sight.sees(at, v));
            !(sees_own || seeds.get(c as usize).is_some_and(|&s| sight.sees(at, s)))
        })
        .collect();
    cluster.par_iter_mut().enumerate().for_each(|(i, c)| {
        if !empty(i) {
            *c = NONE;
        }
    });
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let neighbours = move |i: usize| {
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        [
            (x > 0).then(|| i - 1),
            (x + 1 < nx).then(|| i + 1),
            (y > 0).then(|| i - nx),
            (y + 1 < ny).then(|| i + nx),
            (z > 0).then(|| i - nx * ny),
            (z + 1 < nz).then(|| i + nx * ny),
        ]
        .into_iter()
        .flatten()
    };
    // Breadth-first from the kept voxels, in voxel order; only those beside a waiting voxel
    // can give a cluster, so only they start in the queue.
    let kept = |i: usize| empty(i) && cluster[i] != NONE && !pending[i];
    let starts: Vec<u32> = (0..cluster.len())
        .into_par_iter()
        .filter(|&i| kept(i) && neighbours(i).any(|j| pending[j]))
        .map(|i| i as u32)
        .collect();
    let mut queue: VecDeque<u32> = starts.into();
    let mut moved = 0u64;
    while let Some(i) = queue.pop_front() {
        let c = cluster[i as usize];
        for j in neighbours(i as usize) {
            if pending[j] {
                pending[j] = false;
                moved += u64::from(cluster[j] != c);
                cluster[j] = c;
                queue.push_back(j as u32);
            }
        }
    }
    // What no kept voxel reaches keeps no cluster.
    for (c, p) in cluster.iter_mut().zip(&pending) {
        if *p {
            *c = NONE;
            moved += 1;
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::distance;
    use visgate_formats::vgate::MaxBall;

    /// Sight lines walked voxel by voxel, without clearance.
    fn plain<'a>(meta: &'a GridMeta, empty: &'a [bool]) -> Sight<'a> {
        Sight {
            meta,
            empty,
            clearance_vx: None,
        }
    }

    /// Each voxel's max-ball radius in whole voxels, as the bake's distance stage gives it.
    fn clearance(meta: &GridMeta, empty: &[bool], rule: MaxBall) -> Vec<u16> {
        let not_empty: Vec<bool> = empty.iter().map(|&e| !e).collect();
        distance::transform(meta.dims, &not_empty, rule)
            .into_iter()
            .map(|d| distance::radius_vx(d, rule) as u16)
            .collect()
    }

    /// A `dims` grid with a solid border and `blocks` random solid boxes (1–6 voxels a side)
    /// from the generator `next`.
    fn random_level(dims: [u32; 3], blocks: usize, next: &mut impl FnMut() -> u32) -> Vec<bool> {
        let meta = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims,
        };
        let mut empty: Vec<bool> = (0..dims.iter().product::<u32>())
            .map(|i| {
                let v = meta.coords(i);
                (0..3).all(|a| v[a] > 0 && v[a] + 1 < dims[a])
            })
            .collect();
        for _ in 0..blocks {
            let lo: [u32; 3] = std::array::from_fn(|a| next() % dims[a]);
            let size: [u32; 3] = std::array::from_fn(|_| 1 + next() % 6);
            for z in lo[2]..(lo[2] + size[2]).min(dims[2]) {
                for y in lo[1]..(lo[1] + size[1]).min(dims[1]) {
                    for x in lo[0]..(lo[0] + size[0]).min(dims[0]) {
                        empty[meta.index([x, y, z])] = false;
                    }
                }
            }
        }
        empty
    }

    #[test]
    fn sight_lines_with_clearance_answer_as_the_plain_dda_on_random_levels() {
        // The same levels and pairs every run.
        let mut next = crate::xorshift32(0x9e37_79b9);
        let (mut pairs, mut seen, mut proved) = (0u64, 0u64, 0u64);
        for (level, blocks) in [0usize, 4, 12, 30, 60, 120].into_iter().enumerate() {
            let dims = [40 + 7 * level as u32, 31, 36 - 2 * level as u32];
            let meta = GridMeta {
                origin_m: [0.0; 3],
                voxel_size_m: 1.0,
                dims,
            };
            let empty = random_level(dims, blocks, &mut next);
            for rule in [MaxBall::SolidCentre, MaxBall::Contained] {
                let clear = clearance(&meta, &empty, rule);
                let fast = Sight {
                    meta: &meta,
                    empty: &empty,
                    clearance_vx: Some(&clear),
                };
                let slow = plain(&meta, &empty);
                let packed = fast.packed();
                let n = dims.iter().product::<u32>();
                for p in 0..3000u32 {
                    let from = meta.coords(next() % n);
                    // Every third pair along an exact diagonal: lines through voxel edges and
                    // corners, where the DDA breaks ties.
                    let to = if p % 3 == 0 {
                        let k = next() % 30;
                        let s = [next() % 3, next() % 3, next() % 3].map(|d| d as i64 - 1);
                        std::array::from_fn(|a| {
                            (i64::from(from[a]) + s[a] * i64::from(k))
                                .clamp(0, i64::from(dims[a]) - 1) as u32
                        })
                    } else {
                        meta.coords(next() % n)
                    };
                    let answer = slow.sees(from, to);
                    assert_eq!(fast.sees(from, to), answer, "{from:?} -> {to:?}, {rule:?}");
                    assert_eq!(packed.sees(from, to), answer, "packed {from:?} -> {to:?}");
                    pairs += 1;
                    seen += u64::from(answer);
                    let (f, t) = (from.map(i64::from), to.map(i64::from));
                    let line = Line::between(f, std::array::from_fn(|k| t[k] - f[k]));
                    let r0 = clear[meta.index(from)];
                    let long = line.d.length() > 8.0;
                    proved += u64::from(
                        long && prove_clear(&|i| clear[i], dims.map(i64::from), &line, 0.0, r0)
                            .is_ok(),
                    );
                }
            }
        }
        // The levels hold both answers, and many long lines are proved clear at once.
        assert!(
            seen > pairs / 10 && seen < pairs * 9 / 10,
            "{seen} of {pairs}"
        );
        assert!(proved > pairs / 50, "{proved} of {pairs}");
    }

    #[test]
    fn a_cluster_reaching_around_a_thin_wall_gives_the_far_side_back() {
        // 12 × 1 × 12 voxels; a wall at x = 6 for z < 9 (a gap at z >= 9). Cluster 0's seed at
        // (2, 0, 2), cluster 1's at (9, 0, 2); cluster 1 was given the voxels x 4..6 too.
        let meta = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims: [12, 1, 12],
        };
        let n = 144;
        let empty: Vec<bool> = (0..n as u32)
            .map(|i| {
                let [x, _, z] = meta.coords(i);
                !(x == 6 && z < 9)
            })
            .collect();
        let mut cluster: Vec<u32> = (0..n as u32)
            .map(|i| {
                let [x, _, _] = meta.coords(i);
                u32::from(x >= 4)
            })
            .collect();
        let seeds = [[2, 0, 2], [9, 0, 2]];
        let moved = clusters_by_sight(
            &plain(&meta, &empty).packed(),
            &mut cluster,
            &seeds,
            &|_| None,
        );
        let at = |x: u32, z: u32| cluster[meta.index([x, 0, z])];
        // Behind the wall from cluster 1's seed, beside cluster 0: back to 0.
        assert_eq!(at(5, 2), 0);
        assert_eq!(at(4, 0), 0);
        // Cluster 1's own side and the wall.
        assert_eq!(at(8, 5), 1);
        assert_eq!(at(6, 3), NONE);
        assert!(moved >= 2 * 9, "{moved}");
    }

    #[test]
    fn a_voxel_hidden_from_its_seed_stays_where_it_sees_its_own_node() {
        // 12 × 1 × 12 voxels, a column at x 5..7, z 5..7. Cluster 1 is the strip x = 11 (seed
        // at its end), cluster 0 the rest (seed at (1, 0, 1)). The voxels the column hides from
        // cluster 0's seed see cluster 0's node at (10, 0, 10): with that node as their own
        // they stay; without it the strip's cluster floods in.
        let meta = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims: [12, 1, 12],
        };
        let empty: Vec<bool> = (0..144u32)
            .map(|i| {
                let [x, _, z] = meta.coords(i);
                !((5..7).contains(&x) && (5..7).contains(&z))
            })
            .collect();
        let start: Vec<u32> = (0..144u32)
            .map(|i| u32::from(meta.coords(i)[0] == 11))
            .collect();
        let seeds = [[1, 0, 1], [11, 0, 0]];
        let corner = meta.index([10, 0, 10]);
        let mut cluster = start.clone();
        let own = |i: usize| Some((start[i], [10, 0, 10])).filter(|c| c.0 == 0);
        assert_eq!(
            clusters_by_sight(&plain(&meta, &empty).packed(), &mut cluster, &seeds, &own),
            0
        );
        let mut cluster = start.clone();
        let moved = clusters_by_sight(
            &plain(&meta, &empty).packed(),
            &mut cluster,
            &seeds,
            &|_| None,
        );
        assert!(moved > 0 && cluster[corner] == 1, "{moved}");
    }
}

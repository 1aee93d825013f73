//! Local digital topology on the 3 × 3 × 3 neighbourhood: topological numbers, simple points,
//! 1D isthmuses (object 26-connected, background 6-connected), the 2D simple-point test the
//! critical 2-cliques need, and global counts (components, Euler characteristic, independent
//! cycles) used to check that the skeleton keeps the empty space's topology.
//!
//! A neighbourhood is a 27-bit mask: bit `k = (dx+1) + 3(dy+1) + 9(dz+1)` is set when the voxel
//! at offset `(dx, dy, dz)` belongs to the object; bit 13 is the centre and is ignored.
//! The topological numbers are those of Bertrand & Malandain (1994): `T26` counts the
//! 26-components of the object in the 26-neighbourhood, `T6bar` the 6-components of the
//! background in the 18-neighbourhood that touch the centre's faces. A voxel is simple iff
//! both are 1; it is a 1D isthmus (a curve voxel) iff `T26 >= 2`.

use rayon::prelude::*;

/// Bit of the centre voxel.
pub const CENTRE: u32 = 13;

/// Bit index of offset `(dx, dy, dz)`, each in -1..=1.
pub const fn bit(dx: i32, dy: i32, dz: i32) -> u32 {
    ((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)) as u32
}

const fn offset(k: u32) -> [i32; 3] {
    let k = k as i32;
    [k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1]
}

const fn build_adj(kind: u32) -> [u32; 27] {
    // kind 26: 26-adjacency among the 26 neighbours; kind 6: 6-adjacency among the 18.
    let mut t = [0u32; 27];
    let mut a = 0;
    while a < 27 {
        let pa = offset(a);
        let la = pa[0].abs() + pa[1].abs() + pa[2].abs();
        let mut b = 0;
        while b < 27 {
            let pb = offset(b);
            let lb = pb[0].abs() + pb[1].abs() + pb[2].abs();
            let d = [
                (pa[0] - pb[0]).abs(),
                (pa[1] - pb[1]).abs(),
                (pa[2] - pb[2]).abs(),
            ];
            let ok = a != b
                && a != CENTRE
                && b != CENTRE
                && if kind == 26 {
                    d[0] <= 1 && d[1] <= 1 && d[2] <= 1
                } else {
                    la <= 2 && lb <= 2 && d[0] + d[1] + d[2] == 1
                };
            if ok {
                t[a as usize] |= 1 << b;
            }
            b += 1;
        }
        a += 1;
    }
    t
}

const ADJ26: [u32; 27] = build_adj(26);
const ADJ6_IN_N18: [u32; 27] = build_adj(6);

const fn mask_where(max_l1: i32, min_l1: i32) -> u32 {
    let mut m = 0;
    let mut k = 0;
    while k < 27 {
        let p = offset(k);
        let l = p[0].abs() + p[1].abs() + p[2].abs();
        if l <= max_l1 && l >= min_l1 {
            m |= 1 << k;
        }
        k += 1;
    }
    m
}

/// The 26 neighbours (centre excluded).
pub const N26: u32 = mask_where(3, 1);
/// The 18 neighbours sharing a face or an edge with the centre.
pub const N18: u32 = mask_where(2, 1);
/// The 6 face neighbours.
pub const N6: u32 = mask_where(1, 1);

/// Number of components of `set` under adjacency `adj`, counting only those that meet
/// `seeds`; stops early once `limit` is reached.
#[inline]
fn components(mut set: u32, adj: &[u32; 27], seeds: u32, limit: u32) -> u32 {
    let mut count = 0;
    while set != 0 {
        let start = set.trailing_zeros();
        let mut comp = 1u32 << start;
        let mut frontier = comp;
        while frontier != 0 {
            let k = frontier.trailing_zeros();
            frontier &= frontier - 1;
            let new = adj[k as usize] & set & !comp;
            comp |= new;
            frontier |= new;
        }
        set &= !comp;
        if comp & seeds != 0 {
            count += 1;
            if count >= limit {
                return count;
            }
        }
    }
    count
}

/// `T26`: 26-components of the object among the 26 neighbours.
#[inline]
pub fn t26(mask: u32) -> u32 {
    components(mask & N26, &ADJ26, N26, u32::MAX)
}

/// `T6bar`: 6-components of the background among the 18 neighbours that are 6-adjacent to
/// the centre.
#[inline]
pub fn t6bar(mask: u32) -> u32 {
    components(!mask & N18, &ADJ6_IN_N18, N6, u32::MAX)
}

/// Whether the centre is a simple voxel: deleting it changes no topology.
#[inline]
pub fn is_simple(mask: u32) -> bool {
    components(mask & N26, &ADJ26, N26, 2) == 1 && components(!mask & N18, &ADJ6_IN_N18, N6, 2) == 1
}

/// Whether the centre is a 1D isthmus: its object neighbours fall apart into two or more
/// pieces, so it lies inside a curve (or at a junction).
#[inline]
pub fn is_isthmus_1d(mask: u32) -> bool {
    components(mask & N26, &ADJ26, N26, 2) >= 2
}

/// [`is_isthmus_1d`] and [`is_simple`] together (the thinning asks both of every border
/// voxel), by growing one component a layer at a time with shifts of the whole mask: the
/// object's component of its first neighbour is all of it or not (`T26` is 1 or at least 2),
/// and the background's component of its first face neighbour holds every face neighbour of
/// the background or not (`T6bar` is 1 or at least 2). The same answers as counting the
/// components a voxel at a time ([`components`]; tested on random masks) in fewer steps.
#[inline]
pub fn isthmus_and_simple(mask: u32) -> (bool, bool) {
    let object = mask & N26;
    if object == 0 {
        return (false, false);
    }
    let first = grow(object, object & object.wrapping_neg(), dilate26);
    if first != object {
        return (true, false);
    }
    let background = !mask & N18;
    let faces = background & N6;
    let simple = faces != 0 && {
        let reached = grow(background, faces & faces.wrapping_neg(), dilate6);
        faces & !reached == 0
    };
    (false, simple)
}

/// Bits of the 3 × 3 × 3 block at x = 0, at x = 2, at y = 0, at y = 2.
const X_LOW: u32 = 0b001_001_001 * (1 | 1 << 9 | 1 << 18);
const X_HIGH: u32 = X_LOW << 2;
const Y_LOW: u32 = 0b111 * (1 | 1 << 9 | 1 << 18);
const Y_HIGH: u32 = Y_LOW << 6;
const BLOCK: u32 = (1 << 27) - 1;

/// `seed`'s component in `set` under the adjacency whose one step is `dilate`.
#[inline]
fn grow(set: u32, seed: u32, dilate: fn(u32) -> u32) -> u32 {
    let mut c = seed;
    loop {
        let next = dilate(c) & set;
        if next == c {
            return c;
        }
        c = next;
    }
}

/// The bits of `m` and their 26 neighbours in the block.
#[inline]
fn dilate26(m: u32) -> u32 {
    // Each axis's shifts kept in the block before the next axis's, which would bring bits
    // shifted out of it back in.
    let m = (m | (m << 1 & !X_LOW) | (m >> 1 & !X_HIGH)) & BLOCK;
    let m = (m | (m << 3 & !Y_LOW) | (m >> 3 & !Y_HIGH)) & BLOCK;
    (m | m << 9 | m >> 9) & BLOCK
}

/// The bits of `m` and their 6 face neighbours in the block.
#[inline]
fn dilate6(m: u32) -> u32 {
    let x = m << 1 & !X_LOW | m >> 1 & !X_HIGH;
    let y = m << 3 & !Y_LOW | m >> 3 & !Y_HIGH;
    (m | x | y | m << 9 | m >> 9) & BLOCK
}

/// 2D simplicity of the centre of a 3 × 3 square, (8, 4) connectivity, given the 8-bit ring
/// `ring` in the order of [`RING`]. A 256-entry table.
#[inline]
pub fn is_simple_2d(ring: u8) -> bool {
    static TABLE: std::sync::LazyLock<[bool; 256]> =
        std::sync::LazyLock::new(|| std::array::from_fn(|r| simple_2d_by_flood(r as u8)));
    TABLE[ring as usize]
}

/// Adjacency within the 8-position ring of [`RING`]: consecutive positions (a corner and a
/// side) are 4-adjacent; with `eight`, two sides two apart are adjacent too.
const fn ring_adj(eight: bool) -> [u32; 27] {
    let mut t = [0u32; 27];
    let mut i = 0;
    while i < 8 {
        t[i] = 1 << ((i + 1) % 8) | 1 << ((i + 7) % 8);
        if eight && i % 2 == 1 {
            t[i] |= 1 << ((i + 2) % 8) | 1 << ((i + 6) % 8);
        }
        i += 1;
    }
    t
}

const RING_ADJ8: [u32; 27] = ring_adj(true);
const RING_ADJ4: [u32; 27] = ring_adj(false);
/// Ring positions 4-adjacent to the centre (the sides).
const RING_SIDES: u32 = 0b1010_1010;

/// (8, 4) simplicity: one 8-component of object in the ring, one 4-component of background
/// touching the centre's sides.
fn simple_2d_by_flood(ring: u8) -> bool {
    components(u32::from(ring), &RING_ADJ8, 0xff, 2) == 1
        && components(u32::from(!ring), &RING_ADJ4, RING_SIDES, 2) == 1
}

/// The 8 ring offsets of [`is_simple_2d`], as (u, v) in the square's two axes.
pub const RING: [(i32, i32); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
];

/// Voxel adjacency for component labelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Conn {
    /// Faces only.
    C6,
    /// Faces, edges and corners.
    C26,
}

/// Labels the components of `set`: returns per-voxel labels (`u32::MAX` outside the set) and
/// the number of components. Labels are numbered in the order of each component's first voxel
/// (lowest grid index), so they are deterministic. Voxels on the grid's edge take part;
/// neighbours outside the grid are ignored.
///
/// Works on runs along x: each row's runs are joined (union-find) with the overlapping runs of
/// the rows before it that touch it (2 rows for 6-adjacency, 4 for 26-adjacency, where runs
/// that meet at a corner or edge overlap once widened by one voxel).
pub fn label_components(dims: [u32; 3], set: &[bool], conn: Conn) -> (Vec<u32>, u32) {
    let c = grid_components(dims, |i| set[i], conn);
    let mut label = vec![u32::MAX; set.len()];
    label
        .par_chunks_mut(dims[0] as usize)
        .enumerate()
        .for_each(|(r, row)| {
            for (a, b, l) in c.row(r) {
                row[a as usize..=b as usize].fill(l);
            }
        });
    (label, c.count)
}

/// The number of components of the voxels where `member` holds (as [`label_components`]
/// counts them), without a label per voxel: the topology check counts four sets of a 512³
/// grid, and their labels would take 4 bytes a voxel each.
pub fn count_components(dims: [u32; 3], member: impl Fn(usize) -> bool + Sync, conn: Conn) -> u32 {
    grid_components(dims, member, conn).count
}

/// The components of a set as labelled runs along x, row by row: what [`label_components`]
/// writes out per voxel, in a few bytes a run ([`grid_components`]).
pub struct Components {
    /// Voxels a row.
    nx: usize,
    /// Each run's first and last x, rows in voxel order.
    runs: Vec<(u32, u32)>,
    /// Where each row's runs start in `runs` (one more entry than rows).
    row_start: Vec<usize>,
    /// Each run's component.
    run_label: Vec<u32>,
    /// Number of components.
    pub count: u32,
}

impl Components {
    /// Row `r`'s runs: first x, last x, component.
    pub fn row(&self, r: usize) -> impl Iterator<Item = (u32, u32, u32)> + '_ {
        let mine = self.row_start[r]..self.row_start[r + 1];
        self.runs[mine.clone()]
            .iter()
            .zip(&self.run_label[mine])
            .map(|(&(a, b), &l)| (a, b, l))
    }

    /// The component of voxel `i`, if it is in the set.
    pub fn label(&self, i: usize) -> Option<u32> {
        let (r, x) = (i / self.nx, (i % self.nx) as u32);
        let runs = &self.runs[self.row_start[r]..self.row_start[r + 1]];
        let k = runs.partition_point(|&(_, b)| b < x);
        runs.get(k)
            .filter(|&&(a, _)| a <= x)
            .map(|_| self.run_label[self.row_start[r] + k])
    }
}

/// The components of the voxels where `member` holds, labels numbered by each component's
/// first voxel.
pub fn grid_components(
    dims: [u32; 3],
    member: impl Fn(usize) -> bool + Sync,
    conn: Conn,
) -> Components {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let rows = ny * nz;
    // Runs of each row, in voxel order: (first x, last x).
    let per_row: Vec<Vec<(u32, u32)>> = (0..rows)
        .into_par_iter()
        .map(|r| {
            let row = |x: usize| member(r * nx + x);
            let mut runs = Vec::new();
            let mut x = 0;
            while x < nx {
                if row(x) {
                    let start = x;
                    while x < nx && row(x) {
                        x += 1;
                    }
                    runs.push((start as u32, x as u32 - 1));
                } else {
                    x += 1;
                }
            }
            runs
        })
        .collect();
    let mut row_start = Vec::with_capacity(rows + 1);
    row_start.push(0usize);
    for r in &per_row {
        row_start.push(row_start.last().copied().unwrap_or(0) + r.len());
    }
    let runs: Vec<(u32, u32)> = per_row.into_iter().flatten().collect();
    let mut parent: Vec<u32> = (0..runs.len() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    // Earlier rows that touch row (y, z), and how far runs are widened to count as touching.
    let (earlier, widen): (&[(isize, isize)], u32) = match conn {
        Conn::C6 => (&[(-1, 0), (0, -1)], 0),
        Conn::C26 => (&[(-1, 0), (-1, -1), (0, -1), (1, -1)], 1),
    };
    for z in 0..nz {
        for y in 0..ny {
            let r = y + ny * z;
            let mine = row_start[r]..row_start[r + 1];
            if mine.is_empty() {
                continue;
            }
            for &(dy, dz) in earlier {
                let (oy, oz) = (y as isize + dy, z as isize + dz);
                if oy < 0 || oz < 0 || oy >= ny as isize {
                    continue;
                }
                let o = oy as usize + ny * oz as usize;
                let (mut i, mut j) = (mine.start, row_start[o]);
                let (i_end, j_end) = (mine.end, row_start[o + 1]);
                while i < i_end && j < j_end {
                    let (a0, a1) = runs[i];
                    let (b0, b1) = runs[j];
                    if b0 <= a1 + widen && a0 <= b1 + widen {
                        let (ra, rb) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                        if ra != rb {
                            let (lo, hi) = (ra.min(rb), ra.max(rb));
                            parent[hi as usize] = lo;
                        }
                    }
                    // Advance whichever run ends first.
                    if a1 < b1 {
                        i += 1;
                    } else {
                        j += 1;
                    }
                }
            }
        }
    }
    // Roots are each component's lowest run, so numbering roots in run order numbers the
    // components by their first voxel.
    let mut run_label = vec![0u32; runs.len()];
    let mut count = 0u32;
    for i in 0..runs.len() {
        let root = find(&mut parent, i as u32) as usize;
        run_label[i] = if root == i {
            count += 1;
            count - 1
        } else {
            run_label[root]
        };
    }
    Components {
        nx,
        runs,
        row_start,
        run_label,
        count,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask_of(points: &[[i32; 3]]) -> u32 {
        points.iter().fold(0, |m, p| m | 1 << bit(p[0], p[1], p[2]))
    }

    #[test]
    fn topological_numbers_of_known_configurations() {
        // Isolated voxel: T26 = 0, not simple. End of a line: simple. Middle of a line: isthmus.
        assert_eq!(t26(0), 0);
        assert!(!is_simple(0));
        assert!(is_simple(mask_of(&[[1, 0, 0]])));
        let line = mask_of(&[[-1, 0, 0], [1, 0, 0]]);
        assert_eq!(t26(line), 2);
        assert!(is_isthmus_1d(line) && !is_simple(line));
        // Interior voxel: T6bar = 0, not simple.
        assert_eq!(t6bar(N26), 0);
        assert!(!is_simple(N26));
        // Plane: T26 = 1, T6bar = 2, not simple.
        let plane: Vec<[i32; 3]> = (-1..=1)
            .flat_map(|x| (-1..=1).map(move |z| [x, 0, z]))
            .filter(|p| *p != [0, 0, 0])
            .collect();
        let m = mask_of(&plane);
        assert_eq!((t26(m), t6bar(m)), (1, 2));
        // Half space below: simple.
        let half: Vec<[i32; 3]> = (-1..=1)
            .flat_map(|x| (-1..=1).flat_map(move |z| (-1..=0).map(move |y| [x, y, z])))
            .filter(|p| *p != [0, 0, 0])
            .collect();
        assert!(is_simple(mask_of(&half)));
    }

    #[test]
    fn isthmus_and_simple_together_answer_as_each_alone() {
        // Random neighbourhoods of every density, and the known ones above.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for k in 0..200_000u64 {
            // A density from 1/8 to 7/8: AND or OR of two or three random words.
            let (a, b, c) = (next() as u32, next() as u32, next() as u32);
            let m = [a & b & c, a & b, a, a | b, a | b | c][(k % 5) as usize] & ((1 << 27) - 1);
            assert_eq!(
                isthmus_and_simple(m),
                (is_isthmus_1d(m), is_simple(m)),
                "{m:#x}"
            );
        }
        for m in [
            0,
            N26,
            mask_of(&[[1, 0, 0]]),
            mask_of(&[[-1, 0, 0], [1, 0, 0]]),
        ] {
            assert_eq!(isthmus_and_simple(m), (is_isthmus_1d(m), is_simple(m)));
        }
    }

    #[test]
    fn simple_2d() {
        assert!(!is_simple_2d(0)); // isolated
        assert!(is_simple_2d(0b0000_0001)); // one corner
        assert!(!is_simple_2d(0b0010_0010)); // two opposite sides: a 2D isthmus
        assert!(!is_simple_2d(0xff)); // interior
        assert!(is_simple_2d(0b0000_0111)); // a row
    }

    #[test]
    fn labelled_runs_give_every_voxel_the_label_of_the_per_voxel_labelling() {
        // Random sets of several densities, both adjacencies: the runs' labels, looked up
        // voxel by voxel, are the per-voxel labels, and the counts agree.
        let mut next = crate::xorshift32(0x2545_f491);
        let dims = [23, 9, 7];
        let n = 23 * 9 * 7;
        for density in [10, 35, 50, 65, 90] {
            let set: Vec<bool> = (0..n).map(|_| next() % 100 < density).collect();
            for conn in [Conn::C6, Conn::C26] {
                let (label, count) = label_components(dims, &set, conn);
                let runs = grid_components(dims, |i| set[i], conn);
                assert_eq!(runs.count, count);
                assert_eq!(count_components(dims, |i| set[i], conn), count);
                for (i, &l) in label.iter().enumerate() {
                    assert_eq!(runs.label(i), (l != u32::MAX).then_some(l), "voxel {i}");
                }
            }
        }
    }
}

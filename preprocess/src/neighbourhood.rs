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

/// Topological counts of a voxel set taken as a union of closed unit cubes (so 26-connected).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Betti {
    /// Connected components (β0).
    pub components: u64,
    /// Independent cycles, tunnels (β1).
    pub cycles: u64,
    /// Cavities: bounded components of the complement (β2).
    pub cavities: u64,
    /// Euler characteristic χ = β0 − β1 + β2.
    pub euler: i64,
}

/// Counts components, cavities and (through the Euler characteristic) independent cycles of
/// the voxels where `set` is true. The set must not touch the grid's edge.
pub fn betti(dims: [u32; 3], set: &[bool]) -> Betti {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let at = |x: usize, y: usize, z: usize| -> bool {
        x < nx && y < ny && z < nz && set[x + nx * (y + ny * z)]
    };
    // χ of the cubical complex: vertices − edges + faces − cubes. A lattice cell of dimension
    // d is in the complex if any of the 2^(3−d) voxels around it is in the set. Lattice point
    // (x, y, z) is the corner shared by voxels (x−1..x, y−1..y, z−1..z).
    let get = |x: isize, y: isize, z: isize| -> bool {
        x >= 0 && y >= 0 && z >= 0 && at(x as usize, y as usize, z as usize)
    };
    let mut chi: i64 = 0;
    for z in 0..=nz as isize {
        for y in 0..=ny as isize {
            for x in 0..=nx as isize {
                // Vertex at lattice point (x, y, z).
                let mut c = [[[false; 2]; 2]; 2];
                for (dz, cz) in c.iter_mut().enumerate() {
                    for (dy, cy) in cz.iter_mut().enumerate() {
                        for (dx, v) in cy.iter_mut().enumerate() {
                            *v = get(
                                x - 1 + dx as isize,
                                y - 1 + dy as isize,
                                z - 1 + dz as isize,
                            );
                        }
                    }
                }
                let any = c.iter().flatten().flatten().any(|&v| v);
                if !any {
                    continue;
                }
                chi += 1;
                // Edges leaving this point in +x, +y, +z: the 4 voxels around each.
                let ex = c[0][0][1] || c[0][1][1] || c[1][0][1] || c[1][1][1];
                let ey = c[0][1][0] || c[0][1][1] || c[1][1][0] || c[1][1][1];
                let ez = c[1][0][0] || c[1][0][1] || c[1][1][0] || c[1][1][1];
                chi -= ex as i64 + ey as i64 + ez as i64;
                // Faces with this corner as minimum: xy (voxels z−1, z at x, y), xz, yz.
                let fxy = c[0][1][1] || c[1][1][1];
                let fxz = c[1][0][1] || c[1][1][1];
                let fyz = c[1][1][0] || c[1][1][1];
                chi += fxy as i64 + fxz as i64 + fyz as i64;
                // The cube with this corner as minimum.
                chi -= c[1][1][1] as i64;
            }
        }
    }
    let components = label_components(dims, set, Conn::C26).1 as u64;
    let complement: Vec<bool> = set.iter().map(|&s| !s).collect();
    let background = label_components(dims, &complement, Conn::C6).1 as u64;
    let cavities = background.saturating_sub(1);
    let cycles = (components as i64 + cavities as i64 - chi).max(0) as u64;
    Betti {
        components,
        cycles,
        cavities,
        euler: chi,
    }
}

/// Voxel adjacency for component labelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Conn {
    /// Faces only.
    C6,
    /// Faces, edges and corners.
    C26,
}

/// Labels the components of `set` (flood fill from the lowest voxel index, so deterministic):
/// returns per-voxel labels (`u32::MAX` outside the set) and the number of components.
/// Voxels on the grid's edge take part; neighbours outside the grid are ignored.
pub fn label_components(dims: [u32; 3], set: &[bool], conn: Conn) -> (Vec<u32>, u32) {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut label = vec![u32::MAX; set.len()];
    let offsets: Vec<[i32; 3]> = (0..27)
        .map(offset)
        .filter(|o| {
            let l = o[0].abs() + o[1].abs() + o[2].abs();
            l > 0 && (conn == Conn::C26 || l == 1)
        })
        .collect();
    let fast: Vec<isize> = offsets
        .iter()
        .map(|o| o[0] as isize + nx as isize * (o[1] as isize + ny as isize * o[2] as isize))
        .collect();
    let mut count = 0u32;
    let mut stack = Vec::new();
    for start in 0..set.len() {
        if !set[start] || label[start] != u32::MAX {
            continue;
        }
        label[start] = count;
        stack.push(start);
        while let Some(i) = stack.pop() {
            let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
            if x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz {
                for &o in &fast {
                    let j = (i as isize + o) as usize;
                    if set[j] && label[j] == u32::MAX {
                        label[j] = count;
                        stack.push(j);
                    }
                }
                continue;
            }
            for o in &offsets {
                let (a, b, c) = (
                    x as i64 + o[0] as i64,
                    y as i64 + o[1] as i64,
                    z as i64 + o[2] as i64,
                );
                if a < 0 || b < 0 || c < 0 || a >= nx as i64 || b >= ny as i64 || c >= nz as i64 {
                    continue;
                }
                let j = a as usize + nx * (b as usize + ny * c as usize);
                if set[j] && label[j] == u32::MAX {
                    label[j] = count;
                    stack.push(j);
                }
            }
        }
        count += 1;
    }
    (label, count)
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
    fn simple_2d() {
        assert!(!is_simple_2d(0)); // isolated
        assert!(is_simple_2d(0b0000_0001)); // one corner
        assert!(!is_simple_2d(0b0010_0010)); // two opposite sides: a 2D isthmus
        assert!(!is_simple_2d(0xff)); // interior
        assert!(is_simple_2d(0b0000_0111)); // a row
    }

    #[test]
    fn betti_of_a_torus_and_a_shell() {
        let dims = [7, 7, 5];
        let idx = |x: usize, y: usize, z: usize| x + 7 * (y + 7 * z);
        let mut ring = vec![false; 7 * 7 * 5];
        for x in 1..6 {
            for y in 1..6 {
                if x == 1 || x == 5 || y == 1 || y == 5 {
                    ring[idx(x, y, 2)] = true;
                }
            }
        }
        let b = betti(dims, &ring);
        assert_eq!((b.components, b.cycles, b.cavities), (1, 1, 0));
        let mut shell = vec![false; 7 * 7 * 5];
        for x in 1..6 {
            for y in 1..6 {
                for z in 1..4 {
                    if x == 1 || x == 5 || y == 1 || y == 5 || z == 1 || z == 3 {
                        shell[idx(x, y, z)] = true;
                    }
                }
            }
        }
        let b = betti(dims, &shell);
        assert_eq!((b.components, b.cycles, b.cavities), (1, 0, 1));
    }
}

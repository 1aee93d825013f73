//! The topology of a voxel set counted directly: components, cycles and cavities (the Betti
//! numbers) from its Euler characteristic and two component counts — the bake's topology check
//! (stage 12) and the thinning's tests.

use rayon::prelude::*;

use crate::neighbourhood::{Conn, count_components};

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

/// χ of the cubical complex of `set` (each voxel a closed unit cube): vertices − edges +
/// faces − cubes. A lattice cell is in the complex if any voxel around it is in the set; each
/// lattice point counts itself, the edges, faces and cube that leave it towards +x, +y, +z,
/// which depend on the 2 × 2 × 2 voxels around it alone ([`CHI_OF_CORNER`]). Lattice point
/// (x, y, z) is the corner shared by voxels (x−1..x, y−1..y, z−1..z); along a row the four
/// voxels at x become the four at x − 1 of the next point.
fn euler_characteristic(dims: [u32; 3], set: &[bool]) -> i64 {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    // Bits 2k of a column's four voxels, k = dy + 2 dz: their place at dx = 0.
    const SPREAD: [u8; 16] = {
        let mut t = [0u8; 16];
        let mut k = 0;
        while k < 16 {
            t[k] = ((k & 1) | (k & 2) << 1 | (k & 4) << 2 | (k & 8) << 3) as u8;
            k += 1;
        }
        t
    };
    (0..=nz)
        .into_par_iter()
        .map(|z| {
            let mut chi: i64 = 0;
            for y in 0..=ny {
                // The voxel rows (y − 1 + dy, z − 1 + dz) that exist, bit k = dy + 2 dz.
                let rows: [Option<&[bool]>; 4] = std::array::from_fn(|k| {
                    let (yy, zz) = (
                        (y + (k & 1)).checked_sub(1)?,
                        (z + (k >> 1)).checked_sub(1)?,
                    );
                    (yy < ny && zz < nz).then(|| &set[nx * (yy + ny * zz)..][..nx])
                });
                if rows.iter().all(Option::is_none) {
                    continue;
                }
                let mut before = 0u8;
                for x in 0..=nx {
                    let mut here = 0u8;
                    if x < nx {
                        for (k, row) in rows.iter().enumerate() {
                            if row.is_some_and(|r| r[x]) {
                                here |= 1 << k;
                            }
                        }
                    }
                    let corner = SPREAD[before as usize] | SPREAD[here as usize] << 1;
                    chi += i64::from(CHI_OF_CORNER[corner as usize]);
                    before = here;
                }
            }
            chi
        })
        .sum()
}

/// What a lattice point adds to χ, by the 2 × 2 × 2 voxels around it (bit dx + 2 dy + 4 dz
/// for the voxel at (x − 1 + dx, y − 1 + dy, z − 1 + dz)): the point itself if any is in the
/// set, less the edges leaving it along +x, +y, +z (the 4 voxels around each), plus the faces
/// with it as their lowest corner (the 2 voxels beside each), less the cube (the voxel at +1,
/// +1, +1).
const CHI_OF_CORNER: [i8; 256] = {
    let mut t = [0i8; 256];
    let mut c = 1;
    const fn any(c: usize, m: usize) -> i8 {
        (c & m != 0) as i8
    }
    while c < 256 {
        // Voxels with dx = 1: bits 1, 3, 5, 7; dy = 1: 2, 3, 6, 7; dz = 1: 4, 5, 6, 7.
        let edges = any(c, 0b1010_1010) + any(c, 0b1100_1100) + any(c, 0b1111_0000);
        let faces = any(c, 0b1000_1000) + any(c, 0b1010_0000) + any(c, 0b1100_0000);
        t[c] = 1 - edges + faces - any(c, 0b1000_0000);
        c += 1;
    }
    t
};

/// Counts components, cavities and (through the Euler characteristic) independent cycles of
/// the voxels where `set` is true. The set must not touch the grid's edge.
pub fn betti(dims: [u32; 3], set: &[bool]) -> Betti {
    let chi = euler_characteristic(dims, set);
    let (components, background) = rayon::join(
        || count_components(dims, |i| set[i], Conn::C26) as u64,
        || count_components(dims, |i| !set[i], Conn::C6) as u64,
    );
    let cavities = background.saturating_sub(1);
    let cycles = (components as i64 + cavities as i64 - chi).max(0) as u64;
    Betti {
        components,
        cycles,
        cavities,
        euler: chi,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// χ cell by cell: each lattice point's 8 voxels looked up alone (the stage's first
    /// version, kept as the oracle of the sliding one).
    fn chi_cell_by_cell(dims: [u32; 3], set: &[bool]) -> i64 {
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
        // Slabs of constant z are independent: sum them in parallel.
        (0..=nz as isize)
            .map(|z| {
                let mut chi: i64 = 0;
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
                chi
            })
            .sum()
    }

    #[test]
    fn the_euler_characteristic_slid_along_rows_is_counted_cell_by_cell() {
        let mut next = crate::xorshift32(0x9e37_79b9);
        for dims in [[1, 1, 1], [5, 1, 3], [23, 9, 7], [8, 13, 11]] {
            let n = dims.iter().product::<u32>() as usize;
            for density in [0, 5, 30, 50, 70, 95, 100] {
                let set: Vec<bool> = (0..n).map(|_| next() % 100 < density).collect();
                assert_eq!(
                    euler_characteristic(dims, &set),
                    chi_cell_by_cell(dims, &set),
                    "{dims:?} at {density} %"
                );
            }
        }
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

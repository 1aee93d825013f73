//! The partition carried from the partition grid to the level's grid.
//!
//! When the level's voxels are finer than the partition's size (`--partition-voxel`), the
//! skeleton, the clusters and the gates are made on a coarser grid of the same bounds, and
//! this stage gives every voxel of the fine grid its cluster:
//!
//! 1. a fine empty voxel whose centre lies in an empty coarse voxel takes that voxel's
//!    cluster (a coarse empty voxel holds no geometry, so no wall separates the two);
//! 2. the fine empty voxels left — in coarse voxels that the conservative voxelization made
//!    solid: beside walls, in gaps and openings only the fine grid resolves — are flooded
//!    breadth-first through the fine empty space, so a voxel beside a thin wall takes the
//!    cluster of its own side: across faces first, then across edges and corners for what only
//!    they join (a flood across edges slips past a door's edge sooner: `ajar-door` at 256
//!    refined from 128 agreed with shadow rays on 95.24 / 91.45 / 98.28 % of pairs so, 95.43 /
//!    92.05 / 98.31 % face first);
//! 3. the solid voxels near the empty space take a cluster the same way ([`SOLID_SHELL_VOXELS`]
//!    steps across faces, then as many across edges and corners), as the nearest-node grid
//!    gives them on a single grid (a surface point is looked up half a voxel towards its normal
//!    or in its solid voxel).
//!
//! A coarse bake, partitioned on a finer grid ([`crate::bake::default_partition_voxel`]), takes
//! the same steps but for the first: a voxel of the level holds `k³` partition voxels, and it
//! takes the cluster most of the empty ones at its `k³` evenly spaced samples have (the lowest
//! on a tie; `Coarse` is then the finer grid).
//!
//! The floods of the empty voxels go at most [`FLOOD_COARSE_VOXELS`] coarse voxels deep. Fine
//! empty voxels they do not reach are dropped from the kept space, as the partition grid
//! dropped them: a component of the fine empty space with no voxel in the partition grid's (a
//! pocket the coarse voxels closed off), or space the partition grid dropped that cracks only
//! the fine voxels resolve join to the kept rooms (Crytek Sponza at 512: 20.7 M fine voxels
//! around and over its rooms, which no camera or light is in; flooded whole, 3.7 s).

use rayon::prelude::*;
use serde::Serialize;
use visgate_formats::vgate::{BakedLevel, GridMeta};

use crate::graph::SOLID_SHELL_VOXELS;
use crate::neighbourhood::Conn;

/// How deep the floods of the empty voxels go, in voxels of the partition grid: past the
/// coarse voxels beside the walls and through the gaps only the fine grid resolves.
pub const FLOOD_COARSE_VOXELS: u32 = 4;

/// The partition grid's result to carry (coarser than the level's grid, or finer for a coarse
/// bake).
pub struct Coarse<'a> {
    /// Its grid.
    pub meta: &'a GridMeta,
    /// Its kept empty voxels.
    pub empty: &'a [bool],
    /// Each of its voxels' cluster (`u32::MAX`: none).
    pub voxel_cluster: &'a [u32],
}

impl Coarse<'_> {
    /// The cluster of the partition voxel `c` if it is a kept empty voxel (`u32::MAX`: none,
    /// or off the grid).
    fn cluster_at(&self, c: [u32; 3]) -> u32 {
        if c.contains(&u32::MAX) {
            return u32::MAX;
        }
        let i = self.meta.index(c);
        if self.empty[i] {
            self.voxel_cluster[i]
        } else {
            u32::MAX
        }
    }

    /// The cluster most of the partition voxels at the samples `xs × ys × zs` have (the
    /// lowest on a tie; `u32::MAX` if none has one); `votes` is scratch.
    fn vote(&self, [xs, ys, zs]: [&[u32]; 3], votes: &mut Vec<u32>) -> u32 {
        votes.clear();
        for &z in zs {
            for &y in ys {
                for &x in xs {
                    let c = self.cluster_at([x, y, z]);
                    if c != u32::MAX {
                        votes.push(c);
                    }
                }
            }
        }
        votes.sort_unstable();
        let mut best = (0, u32::MAX);
        for run in votes.chunk_by(|a, b| a == b) {
            if run.len() > best.0 {
                best = (run.len(), run[0]);
            }
        }
        best.1
    }
}

/// Samples a fine voxel takes along each axis: 1 (its centre) when the partition grid is
/// coarser than the level's, else as many as the partition's voxels fit across one of the
/// level's (to 1 %; a coarse bake partitioned on a finer grid, at most 8).
fn samples_per_axis(meta: &GridMeta, partition: &GridMeta) -> usize {
    let k = (meta.voxel_size_m / partition.voxel_size_m / 1.01).ceil();
    k.clamp(1.0, 8.0) as usize
}

/// The [`samples_per_axis`] `s`, and for each axis the partition voxel of each of the `s`
/// evenly spaced samples of each of the level's voxels along it (`u32::MAX`: off the partition
/// grid), the samples of a voxel adjacent. The mapping is separable: `world_to_voxel` of the
/// sample's point, one axis at a time.
fn samples_along(meta: &GridMeta, partition: &GridMeta) -> (usize, [Vec<u32>; 3]) {
    let s = samples_per_axis(meta, partition);
    let step = meta.voxel_size_m / s as f32;
    // A point at the partition grid's first voxel centre, moved along one axis at a time.
    let base = partition.origin_m.map(|o| o + 0.5 * partition.voxel_size_m);
    let along = std::array::from_fn(|a| {
        (0..meta.dims[a] as usize * s)
            .map(|i| {
                let (v, k) = (i / s, i % s);
                let mut p = [0u32; 3];
                p[a] = v as u32;
                let mut w = base;
                w[a] = meta.voxel_to_world(p)[a] + (k as f32 + 0.5 - 0.5 * s as f32) * step;
                partition.world_to_voxel(w).map_or(u32::MAX, |c| c[a])
            })
            .collect()
    });
    (s, along)
}

/// What [`refine`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RefineCounts {
    /// Fine empty voxels that took their coarse voxel's cluster.
    pub from_coarse: u64,
    /// Fine empty voxels flooded from their neighbours.
    pub flooded: u64,
    /// Fine empty voxels no flood reached: dropped from the kept space.
    pub unreached: u64,
    /// Solid voxels of the shell given a cluster.
    pub shell: u64,
    /// Voxel edge of the partition grid. [Units: m]
    pub partition_voxel_m: f32,
}

/// Each fine voxel's cluster (see the module notes); the fine empty voxels no flood reaches
/// are dropped from `empty`.
pub fn refine(meta: &GridMeta, empty: &mut [bool], coarse: &Coarse) -> (Vec<u32>, RefineCounts) {
    let [nx, ny, _] = meta.dims.map(|d| d as usize);
    let (s, along) = samples_along(meta, coarse.meta);
    // Every voxel written, and those given a cluster counted, a row at a time on every thread
    // (filled on one thread first, this step took 0.20 s at 512, now 0.11 s).
    let mut cluster: Vec<u32> = vec![0; empty.len()];
    let from_coarse = cluster
        .par_chunks_mut(nx)
        .zip(empty.par_chunks(nx))
        .enumerate()
        .map(|(row, (cs, es))| {
            let (ys, zs) = (
                &along[1][row % ny * s..][..s],
                &along[2][row / ny * s..][..s],
            );
            let mut votes = Vec::new();
            let mut given = 0u64;
            for (x, (c, &e)) in cs.iter_mut().zip(es).enumerate() {
                let xs = &along[0][x * s..][..s];
                *c = match e {
                    true if s == 1 => coarse.cluster_at([xs[0], ys[0], zs[0]]),
                    true => coarse.vote([xs, ys, zs], &mut votes),
                    false => u32::MAX,
                };
                given += u64::from(*c != u32::MAX);
            }
            given
        })
        .sum::<u64>();
    // Across faces first: a flood across edges and corners slips past a wall's end (a door's
    // edge) sooner; then across edges and corners, for what only they join.
    let ratio = (coarse.meta.voxel_size_m / meta.voxel_size_m).ceil() as usize;
    let rounds = FLOOD_COARSE_VOXELS as usize * ratio.max(1);
    // The floods read and keep up to date which voxels have a cluster, on bits.
    let mut has = row_bits(nx, &cluster, |&c| c != u32::MAX);
    let open = row_bits(nx, empty, |&e| e);
    let flooded = flood(meta, &mut cluster, (&mut has, &open), rounds, Conn::C6)
        + flood(meta, &mut cluster, (&mut has, &open), rounds, Conn::C26);
    let unreached = empty
        .par_iter_mut()
        .zip(&cluster)
        .filter(|(e, c)| **e && **c == u32::MAX)
        .map(|(e, _)| *e = false)
        .count() as u64;
    // The shell likewise: across faces, then what only edges and corners reach.
    let depth = SOLID_SHELL_VOXELS as usize;
    let solid = row_bits(nx, empty, |&e| !e);
    let shell = flood(meta, &mut cluster, (&mut has, &solid), depth, Conn::C6)
        + flood(meta, &mut cluster, (&mut has, &solid), depth, Conn::C26);
    let counts = RefineCounts {
        from_coarse,
        flooded,
        unreached,
        shell,
        partition_voxel_m: coarse.meta.voxel_size_m,
    };
    (cluster, counts)
}

/// Sets each cluster's bounds to those of its voxels on the fine grid (a cluster without any
/// keeps the bounds it had), and every skeleton node's voxel to the fine voxel holding it.
pub fn carry_level(meta: &GridMeta, empty: &[bool], voxel_cluster: &[u32], level: &mut BakedLevel) {
    let t = &mut level.topology;
    let boxes = crate::flatten::cluster_bounds_m(meta, empty, voxel_cluster, t.clusters.len());
    for (cl, found) in t.clusters.iter_mut().zip(boxes) {
        if let Some((lo, hi)) = found {
            (cl.bounds_min_m, cl.bounds_max_m) = (lo, hi);
        }
    }
    for n in &mut t.skeleton.nodes {
        let v: [f32; 3] = std::array::from_fn(|a| {
            ((n.position_m[a] - meta.origin_m[a]) / meta.voxel_size_m)
                .clamp(0.0, (meta.dims[a] - 1) as f32)
        });
        n.voxel = v.map(|c| c as u32);
    }
    level.info.grid = *meta;
}

/// Breadth-first flood of the clusters into the voxels without one that `open` holds, at
/// most `rounds` steps from the voxels that have one; returns the voxels given a cluster.
/// `has` (which voxels have a cluster) and `open` are bits ([`row_bits`]); `has` is kept up to
/// date. A voxel reached in a round takes the cluster of its lowest-index neighbour that had
/// one before the round (the result does not depend on the threads). Each round is found on
/// the bits, 64 voxels a word ([`beside`]): the first on every row, the later ones only on the
/// rows beside a row the round before reached (the same voxels as a list of the neighbours of
/// each round's voxels, marked and sorted, which took Crytek Sponza's refinement at 512 0.61 s,
/// now 0.42–0.47 s, same bytes). The grid's outer layer is never entered.
fn flood(
    meta: &GridMeta,
    cluster: &mut [u32],
    (has, open): (&mut [u64], &[u64]),
    rounds: usize,
    conn: Conn,
) -> u64 {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    if rounds == 0 {
        return 0;
    }
    // Ascending, so the first neighbour found is the lowest index.
    let faces = [4, 10, 12, 14, 16, 22];
    let off: Vec<isize> = (0..27)
        .filter(|&k| k != 13 && (conn == Conn::C26 || faces.contains(&k)))
        .map(|k: isize| {
            (k % 3 - 1) + ((k / 3) % 3 - 1) * nx as isize + (k / 9 - 1) * (nx * ny) as isize
        })
        .collect();
    let words = nx.div_ceil(64);
    // The rows a round looks at: every row first, then those beside a row the round before
    // reached.
    let mut look = vec![true; ny * nz];
    let mut given = 0u64;
    for _ in 0..rounds {
        let shared: &[u32] = cluster;
        let reached: Vec<(u32, u32)> = beside(meta.dims, has, open, &look, conn)
            .into_par_iter()
            .filter_map(|j| {
                off.iter()
                    .map(|&o| shared[(j as isize + o) as usize])
                    .find(|&c| c != u32::MAX)
                    .map(|c| (j, c))
            })
            .collect();
        if reached.is_empty() {
            break;
        }
        let mut touched = vec![false; ny * nz];
        for &(j, c) in &reached {
            let (row, x) = (j as usize / nx, j as usize % nx);
            cluster[j as usize] = c;
            has[row * words + x / 64] |= 1 << (x % 64);
            touched[row] = true;
        }
        given += reached.len() as u64;
        look.iter_mut().enumerate().for_each(|(r, l)| {
            let (y, z) = (r % ny, r / ny);
            *l = (0..9).any(|k| {
                let (y, z) = ((y + k % 3).wrapping_sub(1), (z + k / 3).wrapping_sub(1));
                y < ny && z < nz && touched[y + ny * z]
            });
        });
    }
    given
}

/// Each row's voxels of `v` that `set` holds, a bit each (`nx.div_ceil(64)` words a row, bit
/// `x % 64` of word `x / 64`).
fn row_bits<T: Sync>(nx: usize, v: &[T], set: impl Fn(&T) -> bool + Sync) -> Vec<u64> {
    v.par_chunks(nx)
        .flat_map_iter(|row| {
            row.chunks(64).map(|c| {
                c.iter()
                    .enumerate()
                    .fold(0u64, |b, (i, v)| b | u64::from(set(v)) << i)
            })
        })
        .collect()
}

/// The voxels off the grid's outer layer, on the rows `look` marks, that `open` holds and
/// `has` does not and that have a neighbour `has` holds (across faces, or across faces, edges
/// and corners), ascending. Found a row of 64 voxels at a time, on bits ([`row_bits`]): a scan
/// that looked at every voxel's neighbours took most of the stage (LibreQuake e2m3 at 512,
/// 60 M voxels, four floods).
fn beside(dims: [u32; 3], has: &[u64], open: &[u64], look: &[bool], conn: Conn) -> Vec<u32> {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let words = nx.div_ceil(64);
    let has_row = |y: usize, z: usize| &has[(y + ny * z) * words..][..words];
    // Bits shifted one voxel either way along the row, or'd in.
    let widen = |v: &[u64], out: &mut [u64]| {
        for w in 0..words {
            let before = if w > 0 { v[w - 1] >> 63 } else { 0 };
            let after = if w + 1 < words { v[w + 1] << 63 } else { 0 };
            out[w] |= v[w] | v[w] << 1 | before | v[w] >> 1 | after;
        }
    };
    (0..ny * nz)
        .into_par_iter()
        .filter(|&r| look[r])
        .flat_map_iter(|r| {
            let (y, z) = (r % ny, r / ny);
            let mut near = vec![0u64; words];
            if y > 0 && z > 0 && y + 1 < ny && z + 1 < nz {
                for (dy, dz) in (0..9).map(|k| (k % 3, k / 3)) {
                    let bits = has_row(y + dy - 1, z + dz - 1);
                    match conn {
                        Conn::C26 => widen(bits, &mut near),
                        _ if dy == 1 && dz == 1 => widen(bits, &mut near),
                        _ if dy == 1 || dz == 1 => {
                            near.iter_mut().zip(bits).for_each(|(n, b)| *n |= b)
                        }
                        _ => {}
                    }
                }
                let own = has_row(y, z);
                let open = &open[r * words..][..words];
                near.iter_mut()
                    .zip(own.iter().zip(open))
                    .for_each(|(n, (h, o))| *n &= !h & o);
                // Off the row's ends, and past them.
                near[0] &= !1;
                near[(nx - 1) / 64] &= !(1u64 << ((nx - 1) % 64));
                if nx % 64 != 0 {
                    near[words - 1] &= (1u64 << (nx % 64)) - 1;
                }
            }
            let base = (r * nx) as u32;
            near.into_iter().enumerate().flat_map(move |(w, mut bits)| {
                std::iter::from_fn(move || {
                    (bits != 0).then(|| {
                        let b = bits.trailing_zeros();
                        bits &= bits - 1;
                        base + (w * 64) as u32 + b
                    })
                })
            })
        })
        .collect()
}

/// The voxels off the grid's outer layer without a cluster that have a neighbour with one: a
/// flood's first round, every voxel open.
#[cfg(test)]
fn beside_a_cluster(dims: [u32; 3], cluster: &[u32], conn: Conn) -> Vec<u32> {
    let nx = dims[0] as usize;
    let has = row_bits(nx, cluster, |&c| c != u32::MAX);
    let open = row_bits(nx, cluster, |_| true);
    let rows = (dims[1] * dims[2]) as usize;
    beside(dims, &has, &open, &vec![true; rows], conn)
}

#[cfg(test)]
mod tests;

//! Clusters that do not reach around walls. The nearest-node rule gives a doorway node's
//! cluster the voxels on both sides of a thin wall beside the doorway, so a cluster wraps
//! around the wall's edge and stops being quasi-convex: light then "passes" the wall inside
//! one cluster. Here an empty voxel keeps its cluster only if it sees, along a line of empty
//! voxels, the cluster's seed (the centre of its largest ball) or its own segmented node when
//! that node is of its cluster; the others take the cluster of the nearest voxel that keeps
//! one (breadth-first through empty space). Voxels that are not
//! empty get no cluster: a surface point takes the cluster of the empty voxel its side faces.

use std::collections::VecDeque;

use glam::Vec3;
use rayon::prelude::*;

use visgate_formats::vgate::{GridMeta, NONE};

/// Whether the voxels strictly between voxels `from` and `to` are all empty: a 3D DDA
/// (Amanatides & Woo) between their centres, in voxel units, so that a line through voxel
/// edges and corners takes the same voxels at every scale of the level.
pub(crate) fn sees(meta: &GridMeta, empty: &[bool], from: [u32; 3], to: [u32; 3]) -> bool {
    let a = Vec3::from(from.map(|c| c as f32 + 0.5));
    let b = Vec3::from(to.map(|c| c as f32 + 0.5));
    let d = b - a;
    let mut cell = from.map(|c| c as i64);
    let end = b.floor().as_i64vec3().to_array();
    let mut t_max = [f32::INFINITY; 3];
    let mut t_delta = [f32::INFINITY; 3];
    let mut step = [0i64; 3];
    for k in 0..3 {
        if d[k] != 0.0 {
            step[k] = if d[k] > 0.0 { 1 } else { -1 };
            let next = if d[k] > 0.0 {
                (a[k]).floor() + 1.0
            } else {
                (a[k]).floor()
            };
            t_max[k] = (next - a[k]) / d[k];
            t_delta[k] = 1.0 / d[k].abs();
        }
    }
    let dims = meta.dims.map(i64::from);
    loop {
        // The axis whose boundary comes first, the lowest on a tie (as `min_by` would).
        let k = if t_max[0] <= t_max[1] {
            if t_max[0] <= t_max[2] { 0 } else { 2 }
        } else if t_max[1] <= t_max[2] {
            1
        } else {
            2
        };
        if t_max[k] > 1.0 {
            return true;
        }
        cell[k] += step[k];
        t_max[k] += t_delta[k];
        if cell == end {
            return true;
        }
        if (0..3).any(|i| cell[i] < 0 || cell[i] >= dims[i]) {
            return false;
        }
        let i = (cell[0] + dims[0] * (cell[1] + dims[1] * cell[2])) as usize;
        if !empty[i] {
            return false;
        }
    }
}

/// Reassigns the clusters of empty voxels that see neither their cluster's seed (its voxel in
/// `seeds`, by cluster) nor their `anchor` (a cluster and a voxel: the voxel's own segmented
/// node, which counts only when of the voxel's cluster), and clears the cluster of voxels that
/// are not empty. Returns how many empty voxels changed cluster.
pub fn clusters_by_sight(
    meta: &GridMeta,
    empty: &[bool],
    cluster: &mut [u32],
    seeds: &[[u32; 3]],
    anchor: &(dyn Fn(usize) -> Option<(u32, [u32; 3])> + Sync),
) -> u64 {
    let keep: Vec<bool> = cluster
        .par_iter()
        .enumerate()
        .map(|(i, &c)| {
            let at = meta.coords(i as u32);
            empty[i]
                && c != NONE
                && (seeds
                    .get(c as usize)
                    .is_some_and(|&s| sees(meta, empty, at, s))
                    || anchor(i).is_some_and(|(ac, v)| ac == c && sees(meta, empty, at, v)))
        })
        .collect();
    let old: Vec<u32> = cluster.to_vec();
    let mut queue: VecDeque<usize> = VecDeque::new();
    for (i, c) in cluster.iter_mut().enumerate() {
        if keep[i] {
            queue.push_back(i);
        } else {
            *c = NONE;
        }
    }
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    while let Some(i) = queue.pop_front() {
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        let c = cluster[i];
        let mut visit = |j: usize| {
            if empty[j] && cluster[j] == NONE && old[j] != NONE {
                cluster[j] = c;
                queue.push_back(j);
            }
        };
        if x > 0 {
            visit(i - 1);
        }
        if x + 1 < nx {
            visit(i + 1);
        }
        if y > 0 {
            visit(i - nx);
        }
        if y + 1 < ny {
            visit(i + nx);
        }
        if z > 0 {
            visit(i - nx * ny);
        }
        if z + 1 < nz {
            visit(i + nx * ny);
        }
    }
    cluster
        .iter()
        .zip(&old)
        .zip(empty)
        .filter(|((c, o), e)| **e && c != o)
        .count() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let moved = clusters_by_sight(&meta, &empty, &mut cluster, &seeds, &|_| None);
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
            clusters_by_sight(&meta, &empty, &mut cluster, &seeds, &own),
            0
        );
        let mut cluster = start.clone();
        let moved = clusters_by_sight(&meta, &empty, &mut cluster, &seeds, &|_| None);
        assert!(moved > 0 && cluster[corner] == 1, "{moved}");
    }
}

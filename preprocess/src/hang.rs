//! Floating objects hung to other solid (the cavities of the empty space; see empty.rs's
//! module notes).

use serde::Serialize;
use visgate_formats::vgate::GridMeta;

use crate::neighbourhood::{Conn, grid_components};

/// A floating solid object hung to other solid (see the module notes).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Thread {
    /// Solid voxels of the object.
    pub object_voxels: u64,
    /// Where the thread starts (on the object), metres.
    pub from_m: [f32; 3],
    /// Empty voxels made solid.
    pub length_voxels: u64,
}

/// Hangs every solid 6-component that does not reach the grid border (see module notes).
pub(crate) fn hang_floating_objects(meta: &GridMeta, empty: &mut [bool]) -> Vec<Thread> {
    let dims = meta.dims;
    let [nx, ny, _] = dims.map(|d| d as usize);
    let strides = [1isize, nx as isize, (nx * ny) as isize];
    let mut threads = Vec::new();
    loop {
        let solid = grid_components(dims, |i| !empty[i], Conn::C6);
        let count = solid.count;
        if count <= 1 {
            return threads;
        }
        // Voxel 0 is on the border ring, which is solid: its label is the grounded one.
        let ground = solid.label(0).unwrap_or(u32::MAX);
        let mut sizes = vec![0u64; count as usize];
        let rows = empty.len() / nx;
        for r in 0..rows {
            for (a, b, l) in solid.row(r) {
                sizes[l as usize] += u64::from(b - a + 1);
            }
        }
        // Shortest march per floating component: (length, start, dir).
        let mut best: Vec<Option<(usize, usize, usize)>> = vec![None; count as usize];
        let floating = (0..rows).flat_map(|r| {
            solid
                .row(r)
                .filter(|&(_, _, l)| l != ground)
                .flat_map(move |(a, b, l)| (a..=b).map(move |x| (r * nx + x as usize, l)))
        });
        for (i, l) in floating {
            for dir in 0..6 {
                let step = if dir % 2 == 0 {
                    -strides[dir / 2]
                } else {
                    strides[dir / 2]
                };
                let mut j = i as isize + step;
                let mut len = 0usize;
                // Never out of the grid: the ring is solid and stops every march.
                while empty[j as usize] {
                    len += 1;
                    j += step;
                }
                if len == 0 || solid.label(j as usize) == Some(l) {
                    continue;
                }
                let cand = (len, i, dir);
                let b = &mut best[l as usize];
                if b.is_none_or(|b| cand < b) {
                    *b = Some(cand);
                }
            }
        }
        let mut hung = 0;
        for (l, b) in best.iter().enumerate() {
            let Some((len, start, dir)) = *b else {
                continue;
            };
            let step = if dir % 2 == 0 {
                -strides[dir / 2]
            } else {
                strides[dir / 2]
            };
            let mut j = start as isize;
            for _ in 0..len {
                j += step;
                empty[j as usize] = false;
            }
            let v = [
                (start % nx) as u32,
                ((start / nx) % ny) as u32,
                (start / (nx * ny)) as u32,
            ];
            threads.push(Thread {
                object_voxels: sizes[l],
                from_m: meta.voxel_to_world(v),
                length_voxels: len as u64,
            });
            hung += 1;
        }
        // Relabel: a thread may have reached another floating object, which then still floats.
        if hung == 0 {
            return threads;
        }
    }
}

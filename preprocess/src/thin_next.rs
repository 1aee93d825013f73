//! The thinning's next step's voxels ([`crate::thin`]): the voxels whose neighbourhood a step
//! changed, found voxel by voxel or, where the step deleted many, a bitset word at a time.

use rayon::prelude::*;

use crate::thin::{K, X};

/// One bit a voxel, set at most once between clears from any thread: the voxels listed for the
/// next step.
pub(crate) struct Marks(Vec<std::sync::atomic::AtomicU64>);

impl Marks {
    pub(crate) fn new(voxels: usize) -> Marks {
        Marks(
            (0..voxels.div_ceil(64))
                .map(|_| Default::default())
                .collect(),
        )
    }

    /// Its words of 64 voxels.
    pub(crate) fn words(&self) -> usize {
        self.0.len()
    }

    /// Marks voxel `i`; whether it was not marked before.
    fn mark(&self, i: usize) -> bool {
        let bit = 1 << (i % 64);
        self.0[i / 64].fetch_or(bit, std::sync::atomic::Ordering::Relaxed) & bit == 0
    }

    /// Clears the marks of `voxels`.
    fn clear(&mut self, voxels: &[u32]) {
        for &i in voxels {
            *self.0[i as usize / 64].get_mut() = 0;
        }
    }
}

/// The next step's voxels (ascending): `waiting` and the voxels around `deleted` (at offsets
/// `off`) still in the object and not constrained, each once — found voxel by voxel, marked
/// in `marks` (cleared again), in parallel, then sorted.
pub(crate) fn next_by_lists(
    flags: &[u8],
    marks: &mut Marks,
    deleted: &[u32],
    waiting: &[u32],
    off: &[isize; 27],
) -> Vec<u32> {
    let mut next: Vec<u32> = waiting
        .iter()
        .copied()
        .filter(|&i| marks.mark(i as usize))
        .collect();
    let around: Vec<u32> = deleted
        .par_chunks(4096)
        .flat_map_iter(|chunk| {
            let mut found = Vec::new();
            for &i in chunk {
                for o in off {
                    let j = (i as isize + o) as usize;
                    if flags[j] & (X | K) == X && marks.mark(j) {
                        found.push(j as u32);
                    }
                }
            }
            found
        })
        .collect();
    next.extend(around);
    next.par_sort_unstable();
    marks.clear(&next);
    next
}

/// [`next_by_lists`] a word of 64 voxels along x at a time, for steps that delete many voxels
/// (the first steps delete most of the empty space, and looking at each deleted voxel's 26
/// neighbours and sorting them took a third of the thinning): the deleted voxels as a bitset,
/// dilated along x by shifts and along y and z by the words of the 9 rows around, the
/// voxels in the object and not constrained kept. Comes out in order.
pub(crate) fn next_by_words(
    flags: &[u8],
    [nx, ny]: [usize; 2],
    deleted: &[u32],
    waiting: &[u32],
) -> Vec<u32> {
    let words = flags.len().div_ceil(64);
    let mut del = vec![0u64; words];
    for &i in deleted {
        del[i as usize / 64] |= 1 << (i % 64);
    }
    let word = |b: &[u64], w: isize| -> u64 {
        if w < 0 {
            0
        } else {
            b.get(w as usize).copied().unwrap_or(0)
        }
    };
    let along_x: Vec<u64> = (0..words as isize)
        .into_par_iter()
        .map(|w| {
            let d = del[w as usize];
            d | d << 1 | word(&del, w - 1) >> 63 | d >> 1 | word(&del, w + 1) << 63
        })
        .collect();
    // The 64 bits of `along_x` from bit `p` on (0 outside the grid).
    let bits_from = |p: isize| -> u64 {
        let (q, s) = (p.div_euclid(64), p.rem_euclid(64) as u32);
        match s {
            0 => word(&along_x, q),
            _ => word(&along_x, q) >> s | word(&along_x, q + 1) << (64 - s),
        }
    };
    let (nx, plane) = (nx as isize, (nx * ny) as isize);
    let rows: [isize; 9] =
        std::array::from_fn(|k| (k as isize % 3 - 1) * nx + (k as isize / 3 - 1) * plane);
    let mut next: Vec<u64> = (0..words)
        .into_par_iter()
        .map(|w| {
            let mut near = rows
                .iter()
                .fold(0, |a, &o| a | bits_from(w as isize * 64 + o));
            let mut kept = 0u64;
            while near != 0 {
                let b = near.trailing_zeros();
                near &= near - 1;
                if flags
                    .get(w * 64 + b as usize)
                    .is_some_and(|&f| f & (X | K) == X)
                {
                    kept |= 1 << b;
                }
            }
            kept
        })
        .collect();
    for &i in waiting {
        next[i as usize / 64] |= 1 << (i % 64);
    }
    next.par_iter()
        .enumerate()
        .flat_map_iter(|(w, &m)| {
            let mut m = m;
            std::iter::from_fn(move || {
                (m != 0).then(|| {
                    let b = m.trailing_zeros();
                    m &= m - 1;
                    (w * 64) as u32 + b
                })
            })
        })
        .collect()
}

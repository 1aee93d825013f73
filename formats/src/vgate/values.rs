//! Per-voxel grids packed into the smallest unsigned type, and the blob element types.

use serde::{Deserialize, Serialize};

use super::NONE;

/// One value per voxel, `None` stored as the element type's maximum.
#[derive(Debug, Clone, PartialEq)]
pub enum VoxelValues {
    /// 8-bit values.
    U8(Vec<u8>),
    /// 16-bit values.
    U16(Vec<u16>),
    /// 32-bit values.
    U32(Vec<u32>),
}

impl VoxelValues {
    /// Packs u32 values (with [`NONE`]) into the smallest type that holds them.
    pub fn pack(values: &[u32]) -> Self {
        let max = values.iter().copied().filter(|&v| v != NONE).max();
        match max {
            Some(m) if m >= u32::from(u16::MAX) => VoxelValues::U32(values.to_vec()),
            Some(m) if m >= u32::from(u8::MAX) => VoxelValues::U16(
                values
                    .iter()
                    .map(|&v| if v == NONE { u16::MAX } else { v as u16 })
                    .collect(),
            ),
            _ => VoxelValues::U8(
                values
                    .iter()
                    .map(|&v| if v == NONE { u8::MAX } else { v as u8 })
                    .collect(),
            ),
        }
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            VoxelValues::U8(v) => v.len(),
            VoxelValues::U16(v) => v.len(),
            VoxelValues::U32(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The value at `i` widened to u32 ([`NONE`] for none); `None` past the end.
    pub fn get(&self, i: usize) -> Option<u32> {
        Some(match self {
            VoxelValues::U8(v) => widen(u32::from(*v.get(i)?), u8::MAX.into()),
            VoxelValues::U16(v) => widen(u32::from(*v.get(i)?), u16::MAX.into()),
            VoxelValues::U32(v) => *v.get(i)?,
        })
    }

    /// Element type.
    pub fn elem(&self) -> Elem {
        match self {
            VoxelValues::U8(_) => Elem::U8,
            VoxelValues::U16(_) => Elem::U16,
            VoxelValues::U32(_) => Elem::U32,
        }
    }

    pub(super) fn max_value(&self) -> Option<u32> {
        // Plain folds per type: this runs over every voxel on each load.
        // Shift values up by one so that "none" becomes 0: a branch-free max that vectorises.
        fn max_of<T: Copy + Into<u32>>(v: &[T], none: u32) -> Option<u32> {
            let m = v
                .iter()
                .map(|&x| {
                    let x: u32 = x.into();
                    if x == none { 0 } else { u64::from(x) + 1 }
                })
                .max()
                .unwrap_or(0);
            (m > 0).then(|| (m - 1) as u32)
        }
        match self {
            VoxelValues::U8(v) => max_of(v, u8::MAX.into()),
            VoxelValues::U16(v) => max_of(v, u16::MAX.into()),
            VoxelValues::U32(v) => max_of(v, NONE),
        }
    }

    pub(super) fn to_le_bytes(&self) -> Vec<u8> {
        match self {
            VoxelValues::U8(v) => v.clone(),
            VoxelValues::U16(v) => {
                let mut out = Vec::with_capacity(v.len() * 2);
                for x in v {
                    out.extend_from_slice(&x.to_le_bytes());
                }
                out
            }
            VoxelValues::U32(v) => {
                let mut out = Vec::with_capacity(v.len() * 4);
                for x in v {
                    out.extend_from_slice(&x.to_le_bytes());
                }
                out
            }
        }
    }

    /// Bytes of [`VoxelValues::to_le_bytes`], without encoding them.
    pub(super) fn dense_len(&self) -> u64 {
        self.len() as u64 * self.elem().size()
    }

    /// The values as runs of equal values in index order, each a u32 LE length and a value LE
    /// of the element type: a level's clusters are large, so a 512³ grid is a few hundred
    /// thousand runs instead of 35 million values.
    pub(super) fn to_runs_le_bytes(&self) -> Vec<u8> {
        fn runs<T: Copy + PartialEq>(v: &[T], put: impl Fn(&mut Vec<u8>, T)) -> Vec<u8> {
            let mut out = Vec::new();
            let mut i = 0;
            while i < v.len() {
                let start = i;
                // A run's length is a u32: a longer one is cut in two.
                while i < v.len() && v[i] == v[start] && i - start < u32::MAX as usize {
                    i += 1;
                }
                out.extend_from_slice(&((i - start) as u32).to_le_bytes());
                put(&mut out, v[start]);
            }
            out
        }
        match self {
            VoxelValues::U8(v) => runs(v, |o, x| o.push(x)),
            VoxelValues::U16(v) => runs(v, |o, x| o.extend_from_slice(&x.to_le_bytes())),
            VoxelValues::U32(v) => runs(v, |o, x| o.extend_from_slice(&x.to_le_bytes())),
        }
    }

    /// Decodes [`VoxelValues::to_runs_le_bytes`]: `Err` says what is wrong when the runs are
    /// not whole, one is empty, or they do not add up to `voxels`.
    pub(super) fn from_runs_le_bytes(
        elem: Elem,
        bytes: &[u8],
        voxels: u64,
    ) -> Result<Self, String> {
        let es = elem.size() as usize;
        if elem == Elem::Structure || !bytes.len().is_multiple_of(4 + es) {
            return Err(format!(
                "{} bytes are not whole runs of a u32 length and a {elem:?} value",
                bytes.len()
            ));
        }
        let total: u64 = bytes
            .chunks_exact(4 + es)
            .map(|r| u64::from(u32::from_le_bytes([r[0], r[1], r[2], r[3]])))
            .sum();
        if total != voxels {
            return Err(format!("runs cover {total} voxels, the grid has {voxels}"));
        }
        if total > u64::from(u32::MAX) {
            return Err(format!("{total} voxels: grids are indexed by u32"));
        }
        fn decode<T: Copy>(
            bytes: &[u8],
            es: usize,
            total: u64,
            value: impl Fn(&[u8]) -> T,
        ) -> Result<Vec<T>, String> {
            // A few runs can declare a huge grid: refuse one that does not fit rather than abort.
            let mut out = Vec::new();
            out.try_reserve_exact(total as usize).map_err(|_| {
                format!("the runs describe {total} voxels, more than this machine can hold")
            })?;
            for r in bytes.chunks_exact(4 + es) {
                let n = u32::from_le_bytes([r[0], r[1], r[2], r[3]]) as usize;
                if n == 0 {
                    return Err(format!("an empty run at value {} of the grid", out.len()));
                }
                out.resize(out.len() + n, value(&r[4..]));
            }
            Ok(out)
        }
        Ok(match elem {
            Elem::U8 | Elem::Structure => VoxelValues::U8(decode(bytes, es, total, |b| b[0])?),
            Elem::U16 => VoxelValues::U16(decode(bytes, es, total, |b| {
                u16::from_le_bytes([b[0], b[1]])
            })?),
            Elem::U32 => VoxelValues::U32(decode(bytes, es, total, |b| {
                u32::from_le_bytes([b[0], b[1], b[2], b[3]])
            })?),
        })
    }

    pub(super) fn from_le_bytes(elem: Elem, bytes: &[u8]) -> Self {
        match elem {
            Elem::U8 | Elem::Structure => VoxelValues::U8(bytes.to_vec()),
            Elem::U16 => VoxelValues::U16(
                bytes
                    .chunks_exact(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]))
                    .collect(),
            ),
            Elem::U32 => VoxelValues::U32(
                bytes
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect(),
            ),
        }
    }
}

fn widen(v: u32, none: u32) -> u32 {
    if v == none { NONE } else { v }
}

/// Element type of a blob section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Elem {
    /// No elements: a postcard structure.
    Structure,
    /// u8.
    U8,
    /// u16 LE.
    U16,
    /// u32 LE.
    U32,
}

impl Elem {
    /// Bytes per element (1 for a structure, whose length is in bytes).
    pub fn size(self) -> u64 {
        match self {
            Elem::Structure | Elem::U8 => 1,
            Elem::U16 => 2,
            Elem::U32 => 4,
        }
    }
}

//! One bit per voxel: the level's open voxels (those the voxelization left empty), which the
//! runtime's voxel walk reads to tell a clear segment from one that meets a wall.

/// A bit per voxel in voxel order (x fastest), 64 to a word, bit `i % 64` of word `i / 64`;
/// the bits past the last voxel are 0.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VoxelBits {
    len: u64,
    words: Vec<u64>,
}

impl VoxelBits {
    /// `len` bits, bit `i` = `f(i)`.
    pub fn from_fn(len: usize, f: impl Fn(usize) -> bool) -> VoxelBits {
        let words = (0..len.div_ceil(64))
            .map(|w| {
                let base = w * 64;
                (0..64.min(len - base)).fold(0u64, |acc, b| acc | (u64::from(f(base + b)) << b))
            })
            .collect();
        VoxelBits {
            len: len as u64,
            words,
        }
    }

    /// `len` bits from whole words (bit `i % 64` of word `i / 64`), the bits past the last
    /// cleared. Panics unless there are `len.div_ceil(64)` words.
    pub fn from_words(len: usize, mut words: Vec<u64>) -> VoxelBits {
        assert_eq!(words.len(), len.div_ceil(64), "words for {len} bits");
        if let (Some(last), tail @ 1..) = (words.last_mut(), len % 64) {
            *last &= (1u64 << tail) - 1;
        }
        VoxelBits {
            len: len as u64,
            words,
        }
    }

    /// Number of bits (voxels).
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Whether there are no bits.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bit `i` (false past the end).
    #[inline]
    pub fn get(&self, i: usize) -> bool {
        (i as u64) < self.len && (self.words[i / 64] >> (i % 64)) & 1 == 1
    }

    /// Bits set.
    pub fn count_ones(&self) -> u64 {
        self.words.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// The words, 64 bits each.
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// The words as little-endian bytes (the file's blob).
    pub(super) fn to_le_bytes(&self) -> Vec<u8> {
        self.words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    /// Decodes `len` bits from `data` (whole little-endian words, nothing after the last bit).
    pub(super) fn from_le_bytes(data: &[u8], len: u64) -> Result<VoxelBits, String> {
        let words = len.div_ceil(64);
        if data.len() as u64 != words * 8 {
            return Err(format!(
                "{} bytes for {len} voxels, expected {} (a 64-bit word per 64 voxels)",
                data.len(),
                words * 8
            ));
        }
        let words: Vec<u64> = data
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect();
        let tail = len % 64;
        if tail != 0 && words.last().is_some_and(|w| w >> tail != 0) {
            return Err(format!("bits set past the last of {len} voxels"));
        }
        Ok(VoxelBits { len, words })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_through_bytes_and_refuse_a_wrong_length_or_a_stray_bit() {
        for len in [0usize, 1, 63, 64, 65, 200] {
            let b = VoxelBits::from_fn(len, |i| i % 3 == 0 || i % 7 == 1);
            assert_eq!(b.len(), len as u64);
            for i in 0..len + 3 {
                assert_eq!(b.get(i), i < len && (i % 3 == 0 || i % 7 == 1), "{len} {i}");
            }
            let bytes = b.to_le_bytes();
            assert_eq!(VoxelBits::from_le_bytes(&bytes, len as u64), Ok(b.clone()));
            assert!(VoxelBits::from_le_bytes(&bytes, len as u64 + 64).is_err());
            if len % 64 != 0 {
                let mut stray = bytes.clone();
                let last = stray.len() - 1;
                stray[last] |= 0x80;
                assert!(VoxelBits::from_le_bytes(&stray, len as u64).is_err());
            }
        }
        let b = VoxelBits::from_fn(130, |i| i < 100);
        assert_eq!(b.count_ones(), 100);
    }

    #[test]
    fn bits_from_whole_words_clear_what_lies_past_the_last() {
        for len in [1usize, 63, 64, 65, 130] {
            let b = VoxelBits::from_words(len, vec![u64::MAX; len.div_ceil(64)]);
            assert_eq!(b, VoxelBits::from_fn(len, |_| true), "{len}");
            assert_eq!(b.count_ones(), len as u64);
        }
    }
}

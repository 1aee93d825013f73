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

    /// The words as runs (format 7): a u32 LE count `n`, then, where its top bit is clear, one
    /// u64 LE word repeated `n` times, or, where it is set, `n & 0x7fff_ffff` words as they are.
    /// A sight grid is open space and solid walls, whole words of ones or zeros, save where a
    /// surface crosses a word: Crytek Sponza's 210 M voxels of 4 cm fill 26 MB of words and
    /// far fewer bytes of runs.
    pub(super) fn to_runs_le_bytes(&self) -> Vec<u8> {
        const MOST: usize = 0x7fff_ffff;
        let w = &self.words;
        let mut out = Vec::new();
        // Where the literal words since the last repeat begin.
        let mut literal = 0;
        let mut i = 0;
        let flush = |out: &mut Vec<u8>, from: usize, to: usize| {
            for chunk in w[from..to].chunks(MOST) {
                out.extend_from_slice(&(chunk.len() as u32 | 1 << 31).to_le_bytes());
                out.extend(chunk.iter().flat_map(|x| x.to_le_bytes()));
            }
        };
        while i < w.len() {
            let mut j = i + 1;
            while j < w.len() && w[j] == w[i] && j - i < MOST {
                j += 1;
            }
            // Two equal words or more make a repeat (12 bytes, not 16).
            if j - i >= 2 {
                flush(&mut out, literal, i);
                out.extend_from_slice(&((j - i) as u32).to_le_bytes());
                out.extend_from_slice(&w[i].to_le_bytes());
                literal = j;
            }
            i = j;
        }
        flush(&mut out, literal, w.len());
        out
    }

    /// Decodes `len` bits from [`VoxelBits::to_runs_le_bytes`]'s runs: `Err` says what is
    /// wrong where a run is cut short or empty, or the runs do not make the grid's words. The
    /// runs are read through once before anything is allocated, so a file whose runs do not
    /// add up to its grid is refused without holding the grid.
    pub(super) fn from_runs_le_bytes(data: &[u8], len: u64) -> Result<VoxelBits, String> {
        let words = len.div_ceil(64);
        // Each run: (words it makes, whether they follow as they are, where its body starts).
        let mut runs: Vec<(u64, bool, usize)> = Vec::new();
        let (mut at, mut total) = (0usize, 0u64);
        while at < data.len() {
            let head = data
                .get(at..at + 4)
                .ok_or_else(|| format!("a run's count cut short at byte {at}"))?;
            let head = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
            let (n, literal) = (u64::from(head & 0x7fff_ffff), head >> 31 == 1);
            if n == 0 || total + n > words {
                return Err(format!(
                    "a run of {n} words at byte {at}, after {total} of the grid's {words}"
                ));
            }
            let bytes = if literal { 8 * n as usize } else { 8 };
            if data.len() < at + 4 + bytes {
                return Err(format!("a run of {n} words cut short at byte {at}"));
            }
            runs.push((n, literal, at + 4));
            total += n;
            at += 4 + bytes;
        }
        if total != words {
            return Err(format!("runs make {total} words, the grid has {words}"));
        }
        let mut out: Vec<u64> = Vec::new();
        out.try_reserve_exact(words as usize)
            .map_err(|_| format!("{len} voxels: more than this machine can hold"))?;
        let word = |at: usize| {
            let b = &data[at..at + 8];
            u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
        };
        for (n, literal, body) in runs {
            if literal {
                out.extend((0..n as usize).map(|k| word(body + 8 * k)));
            } else {
                out.resize(out.len() + n as usize, word(body));
            }
        }
        Self::checked(out, len)
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
        Self::checked(words, len)
    }

    /// `len` bits from their words, refused where a bit past the last is set.
    fn checked(words: Vec<u64>, len: u64) -> Result<VoxelBits, String> {
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
    fn bits_round_trip_through_runs_and_refuse_runs_that_do_not_make_the_grid() {
        // Open space, a wall, and surfaces crossing words, at lengths around whole words.
        for len in [0usize, 1, 64, 65, 640, 6400 + 17] {
            let b = VoxelBits::from_fn(len, |i| match i / 64 % 10 {
                0..=4 => true,
                5 | 6 => false,
                _ => i % 5 != 0,
            });
            let runs = b.to_runs_le_bytes();
            assert_eq!(
                VoxelBits::from_runs_le_bytes(&runs, len as u64),
                Ok(b.clone())
            );
            if len >= 640 {
                assert!(
                    runs.len() < b.to_le_bytes().len(),
                    "{len}: {} bytes",
                    runs.len()
                );
            }
            if len > 0 {
                assert!(VoxelBits::from_runs_le_bytes(&runs, len as u64 + 64).is_err());
                assert!(
                    VoxelBits::from_runs_le_bytes(&runs[..runs.len() - 1], len as u64).is_err()
                );
            }
        }
        // One word repeated, 12 bytes; an empty run, and runs past the grid, refused.
        let open = VoxelBits::from_fn(64 * 1000, |_| true);
        assert_eq!(open.to_runs_le_bytes().len(), 12);
        let empty_run = [0u8; 12];
        assert!(VoxelBits::from_runs_le_bytes(&empty_run, 64).is_err());
        let mut two = 2u32.to_le_bytes().to_vec();
        two.extend(u64::MAX.to_le_bytes());
        assert!(VoxelBits::from_runs_le_bytes(&two, 64).is_err());
        // A stray bit past the last voxel, as in the words.
        assert!(VoxelBits::from_runs_le_bytes(&two, 127).is_err());
        assert!(VoxelBits::from_runs_le_bytes(&two, 128).is_ok());
        // A grid of 2^40 voxels (128 GiB of words) and runs that make two words: refused for
        // that, before anything is allocated.
        let e = VoxelBits::from_runs_le_bytes(&two, 1 << 40).expect_err("short");
        assert!(e.contains("runs make 2 words"), "{e}");
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

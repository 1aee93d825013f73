//! The VPL list's order, made for interleaved sampling.
//!
//! A pixel of a b × b block gathers the VPLs at j, j + b², j + 2b², … of the list. Light path
//! k leaves in the direction of Halton point k, whose base-2 coordinate is the cone's cos θ:
//! in the paths' order every 64th path keeps its first six binary digits, so that each of the
//! 64 subsets at 8 × 8 would hold one band of 1/64 of a light's directions. Here the lights'
//! paths are first merged evenly by their place in their own light's sequence (path i of a
//! light of n paths at (i + ½)/n, ties to the lower light) into one *sequence*, and that
//! sequence is dealt out bit-reversed: the entry at place c of the first 2^⌊log₂ n⌋ goes to
//! position rev(c), and where rev(c) + 2^⌊log₂ n⌋ is still a position, the next entry goes
//! there. For every power-of-two b² each subset then holds a run of consecutive Halton points
//! of every light — each stratified over all of its directions.
//!
//! [`dealt_position`] inverts the deal, so that what reads the sequence's places (the VALs'
//! restart VPLs, `vals.wgsl`) picks the same VPLs in either order; `vpl.wgsl`'s
//! `dealt_position` is its GPU twin.

/// The low `bits` bits of `c` reversed.
fn rev(c: u32, bits: u32) -> u32 {
    if bits == 0 {
        0
    } else {
        c.reverse_bits() >> (32 - bits)
    }
}

/// `⌊log₂ n⌋` and `n − 2^⌊log₂ n⌋` (n ≥ 1): the deal's places and its doubled ones.
fn split(n: u32) -> (u32, u32) {
    let bits = n.ilog2();
    (bits, n - (1 << bits))
}

/// The entries the deal has given out before place `c`: `c` plus the places before it that
/// give two, `#{x < c : rev(x) < r}` (counted per set bit of `c`: the x that share c's bits
/// above it, hold 0 there and anything below).
fn start(c: u32, bits: u32, r: u32) -> u32 {
    let mut doubled = 0;
    for i in 0..bits {
        if c >> i & 1 == 0 {
            continue;
        }
        // rev(x) = T · 2^(bits − i) + f, T the reversed free bits, f the fixed bits' part.
        let f = rev(c >> (i + 1) << (i + 1), bits);
        let p = 1u32 << (bits - i);
        if r > f {
            doubled += (r - f).div_ceil(p).min(1 << i);
        }
    }
    c + doubled
}

/// Where the deal puts the entry at place `s` of the merged sequence of `n` (`s < n`).
pub fn dealt_position(s: u32, n: u32) -> u32 {
    debug_assert!(s < n);
    let (bits, r) = split(n);
    // The last place c whose first entry is at or before s.
    let (mut lo, mut hi) = (0u32, (1u32 << bits) - 1);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if start(mid, bits, r) <= s {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let q = rev(lo, bits);
    if start(lo, bits, r) == s {
        q
    } else {
        q + (1 << bits)
    }
}

/// The deal of `sequence` (see the module notes).
pub fn deal<T>(sequence: Vec<T>) -> Vec<T> {
    let n = sequence.len();
    if n <= 1 {
        return sequence;
    }
    let (bits, r) = split(n as u32);
    let mut out: Vec<Option<T>> = (0..n).map(|_| None).collect();
    let mut next = sequence.into_iter();
    for c in 0..1u32 << bits {
        let q = rev(c, bits);
        out[q as usize] = next.next();
        if q < r {
            out[(q + (1 << bits)) as usize] = next.next();
        }
    }
    out.into_iter()
        .map(|v| v.expect("the deal fills every position"))
        .collect()
}

/// The lights' paths (`by_light[l][i]`: the entries of light l's path i, possibly none)
/// merged evenly by their place in their own light's sequence, then dealt (module notes).
pub fn interleaving_order<T: Send>(by_light: Vec<Vec<Vec<T>>>) -> Vec<T> {
    let mut keys: Vec<(u64, u64, usize)> = by_light
        .iter()
        .enumerate()
        .flat_map(|(l, paths)| {
            (0..paths.len()).map(move |i| ((2 * i + 1) as u64, paths.len() as u64, l))
        })
        .collect();
    // (2i + 1) / 2n compared exactly by cross-multiplying (i < 2^24, n ≤ 2^24).
    keys.sort_unstable_by(|a, b| (a.0 * b.1).cmp(&(b.0 * a.1)).then(a.2.cmp(&b.2)));
    let mut lights: Vec<_> = by_light.into_iter().map(|p| p.into_iter()).collect();
    let mut sequence = Vec::new();
    for (_, _, l) in keys {
        sequence.extend(lights[l].next().into_iter().flatten());
    }
    deal(sequence)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vpl::radical_inverse;

    #[test]
    fn the_deal_is_inverted_by_dealt_position_at_every_size() {
        for n in 1..=300u32 {
            let dealt = deal((0..n).collect::<Vec<_>>());
            let mut seen = vec![false; n as usize];
            for (p, &s) in dealt.iter().enumerate() {
                assert_eq!(dealt_position(s, n), p as u32, "n {n}, place {s}");
                seen[s as usize] = true;
            }
            assert!(seen.iter().all(|&x| x), "n {n}: a permutation");
        }
        let n = 1_000_003;
        let dealt = deal((0..n).collect::<Vec<_>>());
        for s in (0..n).step_by(997) {
            assert_eq!(dealt[dealt_position(s, n) as usize], s);
        }
    }

    #[test]
    fn each_subset_of_one_light_is_a_run_of_its_sequence() {
        let order = interleaving_order(vec![(0..1024u32).map(|k| vec![k]).collect()]);
        for b2 in [4usize, 16, 64, 256] {
            for j in 0..b2 {
                let mut subset: Vec<u32> = order.iter().skip(j).step_by(b2).copied().collect();
                subset.sort_unstable();
                let first = subset[0];
                assert_eq!(first % (1024 / b2) as u32, 0, "an aligned run");
                assert!(
                    subset
                        .iter()
                        .enumerate()
                        .all(|(i, &k)| k == first + i as u32)
                );
            }
        }
    }

    #[test]
    fn lights_share_every_subset_by_their_paths_and_cover_their_directions() {
        // Light 0: 750 paths, every 5th a miss, every 7th two VPLs; light 1: 250 paths.
        let l0 = (0..750u32)
            .map(|k| match (k % 5, k % 7) {
                (0, _) => vec![],
                (_, 0) => vec![(0, k), (0, k)],
                _ => vec![(0, k)],
            })
            .collect();
        let l1 = (0..250u32).map(|k| vec![(1, k)]).collect();
        let order = interleaving_order(vec![l0, l1]);
        let share1 = order.iter().filter(|v| v.0 == 1).count() as f64 / order.len() as f64;
        for j in 0..64 {
            let subset: Vec<(u32, u32)> = order.iter().skip(j).step_by(64).copied().collect();
            let ones = subset.iter().filter(|v| v.0 == 1).count() as f64;
            assert!(
                (ones / subset.len() as f64 - share1).abs() < 0.07,
                "subset {j}"
            );
            for (light, at_least) in [(0, 7), (1, 3)] {
                let mut eighths = [false; 8];
                for v in subset.iter().filter(|v| v.0 == light) {
                    eighths[(radical_inverse(v.1 as u64, 2) * 8.0) as usize] = true;
                }
                let n = eighths.iter().filter(|&&e| e).count();
                assert!(n >= at_least, "subset {j}, light {light}: {n} eighths");
            }
        }
        let even = interleaving_order(vec![
            (0..512u32).map(|k| vec![(0, k)]).collect(),
            (0..512u32).map(|k| vec![(1, k)]).collect(),
        ]);
        for j in 0..64 {
            let subset: Vec<(u32, u32)> = even.iter().skip(j).step_by(64).copied().collect();
            assert_eq!(subset.iter().filter(|v| v.0 == 1).count(), 8, "subset {j}");
            let mut eighths = [0; 8];
            for v in &subset {
                eighths[(radical_inverse(v.1 as u64, 2) * 8.0) as usize] += 1;
            }
            assert_eq!(eighths, [2; 8], "subset {j}");
        }
    }
}

// The near field's rounds (shade.wgsl's cs_near_field says what they are): the run of a
// tile's marked VPLs that a round walks, and the rounds' lists of tiles. It reads and writes
// the including pass's near_tiles, near_out and near_spare; no bindings of its own.

// Of the VPLs that tile words `at` marks from VPL `first` on, the run a round walks: at most
// `budget` marked ones (its end, the next marked VPL or the VPL count; and how many it holds).
fn near_run(at: u32, first: u32, words: u32, budget: u32) -> vec2<u32> {
    var left = budget;
    for (var w = first / 32u; w < words; w++) {
        var bits = near_word(at, w, first);
        let c = countOneBits(bits);
        if c > left {
            for (var i = 0u; i < left; i++) {
                bits &= bits - 1u;
            }
            return vec2<u32>(w * 32u + firstTrailingBit(bits), budget);
        }
        left -= c;
    }
    return vec2<u32>(globals.vpl_count, budget - left);
}

// Word w of the tile marks at `at`, without the VPLs before `first`.
fn near_word(at: u32, w: u32, first: u32) -> u32 {
    let bits = near_tiles[at + w];
    return select(bits, bits & (~0u << (first % 32u)), w == first / 32u);
}

// The next round's list (near_out): tile `tile` from VPL `start` on, in the next slot, the
// indirect dispatch's workgroups grown to hold it (rows of NEAR_ROUND_ROW).
fn near_round_append(tile: u32, start: u32) {
    let slot = atomicAdd(&near_out[3], 1u);
    atomicStore(&near_out[NEAR_LIST_HEAD + 2u * slot], tile);
    atomicStore(&near_out[NEAR_LIST_HEAD + 2u * slot + 1u], start);
    atomicMax(&near_out[0], min(slot + 1u, NEAR_ROUND_ROW));
    atomicMax(&near_out[1], slot / NEAR_ROUND_ROW + 1u);
}

// The list after the next one emptied: its control slot alone, a workgroup (x 1, y 1, z 1).
fn near_round_reset() {
    near_spare[0] = 1u;
    near_spare[1] = 1u;
    near_spare[3] = 1u;
}

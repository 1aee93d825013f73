//! Stage 4, distance: the exact Euclidean distance transform of the empty space.
//!
//! Convention: for every empty voxel, `dist2_vx` is the squared distance, in voxel units, from
//! its centre to the centre of the nearest solid voxel (0 for solid voxels). The maximal ball
//! centred on an empty voxel has radius `sqrt(dist2_vx) · voxel_size_m`: it reaches the
//! nearest solid voxel's centre. Computed exactly by three separable passes of the
//! lower-envelope algorithm of Felzenszwalb & Huttenlocher (2012), each parallel over lines.

use rayon::prelude::*;

/// "Infinitely far": larger than any squared distance in a grid of up to 2^20 voxels a side.
const INF: i64 = 1 << 42;

/// Squared Euclidean distance (voxel units) to the nearest solid voxel, per voxel.
pub fn squared_distance(dims: [u32; 3], solid: &[bool]) -> Vec<u64> {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut d: Vec<i64> = solid.iter().map(|&s| if s { 0 } else { INF }).collect();
    // Along x: contiguous rows.
    d.par_chunks_mut(nx).for_each(|row| {
        let out = envelope(row);
        row.copy_from_slice(&out);
    });
    // Along y and z: gather each line, transform, scatter.
    for (len, stride, lines) in [
        (
            ny,
            nx,
            (0..nz)
                .flat_map(|z| (0..nx).map(move |x| x + nx * ny * z))
                .collect::<Vec<_>>(),
        ),
        (nz, nx * ny, (0..nx * ny).collect::<Vec<_>>()),
    ] {
        let results: Vec<Vec<i64>> = lines
            .par_iter()
            .map(|&start| {
                let line: Vec<i64> = (0..len).map(|k| d[start + k * stride]).collect();
                envelope(&line)
            })
            .collect();
        for (&start, r) in lines.iter().zip(&results) {
            for (k, v) in r.iter().enumerate() {
                d[start + k * stride] = *v;
            }
        }
    }
    d.into_iter().map(|v| v.min(INF) as u64).collect()
}

/// 1D squared distance transform of sampled function `f` (lower envelope of parabolas).
fn envelope(f: &[i64]) -> Vec<i64> {
    let n = f.len();
    let mut out = vec![INF; n];
    let mut v = vec![0usize; n];
    let mut z = vec![0f64; n + 1];
    let mut k = 0usize;
    let mut first = None;
    for q in 0..n {
        if f[q] >= INF {
            continue;
        }
        match first {
            None => {
                first = Some(q);
                v[0] = q;
                z[0] = f64::NEG_INFINITY;
                z[1] = f64::INFINITY;
                k = 0;
            }
            Some(_) => loop {
                let p = v[k];
                let s = ((f[q] + (q * q) as i64) - (f[p] + (p * p) as i64)) as f64
                    / (2.0 * (q as f64 - p as f64));
                // z[0] = −∞, so k never goes below 0.
                if s <= z[k] {
                    k -= 1;
                    continue;
                }
                k += 1;
                v[k] = q;
                z[k] = s;
                z[k + 1] = f64::INFINITY;
                break;
            },
        }
    }
    if first.is_none() {
        return out;
    }
    let mut k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let dq = q as i64 - p as i64;
        *o = dq * dq + f[p];
    }
    out
}

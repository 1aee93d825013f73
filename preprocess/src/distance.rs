//! Stage 4, distance: the exact Euclidean distance transform of the empty space.
//!
//! Two conventions ([`MaxBall`]), each exact, by three separable passes of the lower-envelope
//! algorithm of Felzenszwalb & Huttenlocher (2012), each parallel over lines:
//!
//! - `SolidCentre`: the squared distance, in voxels, from a voxel's centre to the centre of
//!   the nearest solid voxel (0 for solid voxels); radius `sqrt(d) · voxel_size`.
//! - `Contained` (the paper's maximal ball contained in the empty space): four times the
//!   squared distance from the centre to the nearest solid voxel's *cube*; radius
//!   `sqrt(d) / 2 · voxel_size`. Per axis the cube is `max(|k| − ½, 0)` away, and
//!   `(2|k| − 1)²` is the parabola `(2q ∓ 1 − 2p)²` on the side of `p` it lies: the envelope
//!   of parabolas centred at `2p`, read at `2q − 1` and `2q + 1`, and the line's own value at
//!   `q`, give the exact minimum.

use rayon::prelude::*;
use visgate_formats::vgate::MaxBall;

/// "Infinitely far": larger than any squared distance in a grid of up to 2^20 voxels a side.
const INF: i64 = 1 << 42;

/// Squared Euclidean distance (voxel units) to the nearest solid voxel's centre, per voxel.
pub fn squared_distance(dims: [u32; 3], solid: &[bool]) -> Vec<u64> {
    transform(dims, solid, MaxBall::SolidCentre)
}

/// The max-ball radius, in voxels, of a value of [`transform`] with `rule`.
pub fn radius_vx(d: u64, rule: MaxBall) -> f64 {
    match rule {
        MaxBall::SolidCentre => (d as f64).sqrt(),
        MaxBall::Contained => (d as f64).sqrt() * 0.5,
    }
}

/// Per voxel, the squared distance to the nearest solid voxel under `rule` (see the module
/// notes for the units); 0 for solid voxels, ordered as the radii.
pub fn transform(dims: [u32; 3], solid: &[bool], rule: MaxBall) -> Vec<u64> {
    let [nx, ny, _] = dims.map(|d| d as usize);
    if nx == 0 || ny == 0 {
        return Vec::new();
    }
    let mut d: Vec<i64> = solid.par_iter().map(|&s| if s { 0 } else { INF }).collect();
    // Along x: each row alone.
    d.par_chunks_mut(nx)
        .for_each_init(Lines::default, |lines, row| {
            lines.along(row, rule);
        });
    // Along y: each z-slice's rows, a line through element x of every row.
    d.par_chunks_mut(nx * ny)
        .for_each_init(Lines::default, |lines, slice| {
            let mut rows: Vec<&mut [i64]> = slice.chunks_mut(nx).collect();
            lines.across(&mut rows, rule);
        });
    // Along z: the rows of one y from every slice (about nz × nx values: they stay in cache
    // while the lines are read and written back, where a line at a time read the grid with a
    // stride of a slice).
    let mut by_y: Vec<Vec<&mut [i64]>> = (0..ny).map(|_| Vec::new()).collect();
    for (r, row) in d.chunks_mut(nx).enumerate() {
        by_y[r % ny].push(row);
    }
    by_y.par_iter_mut()
        .for_each_init(Lines::default, |lines, rows| lines.across(rows, rule));
    // Every value is at most INF already; collected in place (no second grid).
    d.into_iter().map(|v| v as u64).collect()
}

/// One thread's buffers for the 1D transforms.
#[derive(Default)]
struct Lines {
    f: Vec<i64>,
    out: Vec<i64>,
    v: Vec<usize>,
    z: Vec<f64>,
}

impl Lines {
    /// Transforms `row` in place, a line of its own.
    fn along(&mut self, row: &mut [i64], rule: MaxBall) {
        self.f.clear();
        self.f.extend_from_slice(row);
        self.transform(rule);
        row.copy_from_slice(&self.out);
    }

    /// Transforms, for each `x`, the line through element `x` of every row, in place.
    fn across(&mut self, rows: &mut [&mut [i64]], rule: MaxBall) {
        for x in 0..rows.first().map_or(0, |r| r.len()) {
            self.f.clear();
            self.f.extend(rows.iter().map(|r| r[x]));
            self.transform(rule);
            for (r, &o) in rows.iter_mut().zip(&self.out) {
                r[x] = o;
            }
        }
    }

    /// `f`'s transform into `out`.
    fn transform(&mut self, rule: MaxBall) {
        let len = self.f.len();
        self.out.resize(len, 0);
        self.v.resize(len, 0);
        self.z.resize(len + 1, 0.0);
        let (f, out, v, z) = (&self.f, &mut self.out, &mut self.v, &mut self.z);
        match rule {
            MaxBall::SolidCentre => envelope(f, out, v, z),
            MaxBall::Contained => envelope_to_cubes(f, out, v, z),
        }
    }
}

/// 1D squared distance transform of sampled function `f` (lower envelope of parabolas) into
/// `out`; `v` and `z` are scratch of `f`'s length and one more.
fn envelope(f: &[i64], out: &mut [i64], v: &mut [usize], z: &mut [f64]) {
    lower_envelope(f, 1, &|q, eval| eval(q as i64), out, v, z)
}

/// 1D transform to the nearest cube, ×4: `min_p f[p] + g(q − p)` with `g(0) = 0` and
/// `g(k) = (2|k| − 1)²` (buffers as [`envelope`]'s).
fn envelope_to_cubes(f: &[i64], out: &mut [i64], v: &mut [usize], z: &mut [f64]) {
    lower_envelope(
        f,
        2,
        &|q, eval| {
            let q2 = 2 * q as i64;
            f[q].min(eval(q2 - 1)).min(eval(q2 + 1))
        },
        out,
        v,
        z,
    )
}

/// How [`lower_envelope`] reads line position `q` from the envelope's value at any `x`.
type Read<'a> = dyn Fn(usize, &mut dyn FnMut(i64) -> i64) -> i64 + 'a;

/// The lower envelope of the parabolas `f[p] + (x − c·p)²` (`f[p] ≥ INF`: none), and for each
/// `q`, `out[q] = read(q, eval)` with `eval(x)` its value at `x`. The `x` read must not
/// decrease with `q`. `v` (the envelope's parabolas) and `z` (their bounds) are scratch.
fn lower_envelope(
    f: &[i64],
    c: i64,
    read: &Read<'_>,
    out: &mut [i64],
    v: &mut [usize],
    z: &mut [f64],
) {
    let n = f.len();
    out.fill(INF);
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
                let (cq, cp) = (c * q as i64, c * p as i64);
                let s =
                    ((f[q] + cq * cq) - (f[p] + cp * cp)) as f64 / (2.0 * (cq as f64 - cp as f64));
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
        return;
    }
    let mut k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        let mut eval = |x: i64| {
            while z[k + 1] < x as f64 {
                k += 1;
            }
            let d = x - c * v[k] as i64;
            d * d + f[v[k]]
        };
        *o = read(q, &mut eval).min(INF);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the minimum over solid voxels of the per-axis distances under `rule`.
    fn brute(dims: [u32; 3], solid: &[bool], rule: MaxBall) -> Vec<u64> {
        let [nx, ny, nz] = dims.map(|d| d as i64);
        let idx = |x: i64, y: i64, z: i64| (x + nx * (y + ny * z)) as usize;
        let axis = |k: i64| -> u64 {
            match (rule, k) {
                (MaxBall::SolidCentre, _) => (k * k) as u64,
                (MaxBall::Contained, 0) => 0,
                (MaxBall::Contained, _) => ((2 * k.abs() - 1) * (2 * k.abs() - 1)) as u64,
            }
        };
        let mut out = vec![INF as u64; solid.len()];
        for (z, y, x) in
            (0..nz).flat_map(|z| (0..ny).flat_map(move |y| (0..nx).map(move |x| (z, y, x))))
        {
            for (c, d, e) in
                (0..nz).flat_map(|c| (0..ny).flat_map(move |d| (0..nx).map(move |e| (c, d, e))))
            {
                if solid[idx(e, d, c)] {
                    let v = axis(x - e) + axis(y - d) + axis(z - c);
                    out[idx(x, y, z)] = out[idx(x, y, z)].min(v);
                }
            }
        }
        out
    }

    #[test]
    fn grids_one_voxel_thin_along_any_axis_transform_as_brute_force() {
        for dims in [
            [5, 1, 4],
            [1, 6, 1],
            [4, 3, 1],
            [1, 1, 7],
            [1, 1, 1],
            [6, 5, 2],
        ] {
            let n = dims.iter().product::<u32>() as u64;
            let solid: Vec<bool> = (0..n)
                .map(|i| (i.wrapping_mul(2_654_435_761) >> 5) % 5 == 0)
                .collect();
            for rule in [MaxBall::SolidCentre, MaxBall::Contained] {
                assert_eq!(
                    transform(dims, &solid, rule),
                    brute(dims, &solid, rule),
                    "{dims:?} {rule:?}"
                );
            }
        }
    }

    #[test]
    fn both_transforms_equal_brute_force_and_the_contained_ball_is_the_smaller() {
        let dims = [9, 7, 6];
        let n = 9 * 7 * 6;
        // A pseudo-random sprinkle of solid voxels (about one in eight).
        let solid: Vec<bool> = (0..n as u64)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 7) % 8 == 0)
            .collect();
        assert!(solid.iter().any(|&s| s) && !solid.iter().all(|&s| s));
        for rule in [MaxBall::SolidCentre, MaxBall::Contained] {
            assert_eq!(
                transform(dims, &solid, rule),
                brute(dims, &solid, rule),
                "{rule:?}"
            );
        }
        let centre = transform(dims, &solid, MaxBall::SolidCentre);
        let cube = transform(dims, &solid, MaxBall::Contained);
        for (&a, &b) in centre.iter().zip(&cube) {
            let (ra, rb) = (
                radius_vx(a, MaxBall::SolidCentre),
                radius_vx(b, MaxBall::Contained),
            );
            // Half a voxel smaller along an axis, at most √3/2 smaller along a diagonal.
            assert!(rb <= ra - 0.5 + 1e-9 || a == 0, "{ra} {rb}");
            assert!(rb >= ra - 3f64.sqrt() / 2.0 - 1e-9, "{ra} {rb}");
        }
        // One voxel from a wall: the ball reaches the wall's face, half a voxel away.
        let mut wall = vec![false; n];
        (0..9 * 7).for_each(|i| wall[i] = true);
        let d = transform(dims, &wall, MaxBall::Contained);
        assert_eq!(radius_vx(d[9 * 7], MaxBall::Contained), 0.5);
        assert_eq!(radius_vx(d[3 * 9 * 7 + 4], MaxBall::Contained), 2.5);
    }
}

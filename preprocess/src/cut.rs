//! Gates cut the empty space along their planes, so that each side of an opening becomes a
//! piece of its own. A gate's disk has the radius of the largest ball at the opening's
//! narrowest place: for a round doorway it spans the opening, but a tall slot (a door standing
//! ajar, a gap between a column and a wall) is much longer than its width, and the disk closes
//! only a part of it. So the cut is the disk (three radii, as before) and, beyond it, the
//! plane's voxels reached from the centre through voxels as narrow as the opening (largest
//! ball at most 1.5 gate radii + 1 voxel): the whole slot, stopping where the space widens
//! into the rooms. The plane is the gate's, turned to contain the slot's long axis when the
//! opening is much longer than wide (a door ajar leaves a slot whose skeleton runs slanted
//! through it; a plane along that slant would leave the slot's top and bottom uncut).

use std::collections::VecDeque;

use glam::Vec3;
use visgate_formats::vgate::GridMeta;

use crate::clusters::GateDisk;

/// Voxels one gate's flood may visit.
const MAX_FLOOD: usize = 1 << 20;
/// How far from the gate's centre the voxels that tell a slot's direction are sought, in
/// reaches of its cut's disk (three radii and a voxel). [Units: ratio]
const SLOT_SEARCH_REACHES: f32 = 4.0;

/// The largest eigenvector of a symmetric 3×3 matrix (columns), by power iteration, and its
/// eigenvalue.
fn dominant(m: glam::Mat3) -> (Vec3, f32) {
    let mut v = Vec3::new(0.577, 0.577, 0.577);
    for _ in 0..64 {
        let w = m * v;
        let l = w.length();
        if l <= f32::MIN_POSITIVE {
            return (v, 0.0);
        }
        v = w / l;
    }
    (v, v.dot(m * v))
}

/// The cut plane's normal: the gate's, or, in a slot (the narrow voxels near the plane spread
/// at least twice as far along one axis as along any other, that axis across the gate's
/// normal), the gate's normal with its component along the slot removed.
fn cut_normal(
    scratch: &mut Flood,
    meta: &GridMeta,
    space: Space,
    g: &GateDisk,
    narrow: f32,
) -> Vec3 {
    let vs = meta.voxel_size_m;
    let band = 2.0 * g.radius + vs;
    // Only the narrow voxels near the gate say which way a slot runs; unbounded, the flood
    // followed the narrow strip along every wall of the level within the band.
    let near = SLOT_SEARCH_REACHES * (3.0 * g.radius + vs);
    let found = scratch.spans_within_cap(meta, g.centre, |i, p| {
        // The arithmetic first: most voxels tried lie off the band, and their grid reads wait
        // on memory.
        let d = p - g.centre;
        d.dot(g.normal).abs() <= band
            && d.length_squared() <= near * near
            && space.narrow(i, narrow)
    });
    // More than a million narrow voxels near the gate: open space along walls, no slot (each
    // such gate of the shared levels, 8 of Dabrovic Sponza's at 256 and 512, 10 of LibreQuake
    // e2m3's at 512, has its first million spread less than 3.5× as far along one axis as
    // along another; the breadth-first flood that found that million took Dabrovic Sponza 256's
    // cuts 0.5 s).
    let Ok(found) = found else {
        return g.normal;
    };
    let Some(cov) = covariance(&found) else {
        return g.normal;
    };
    let (a, l1) = dominant(cov);
    let deflated = cov - glam::Mat3::from_cols(a * a.x, a * a.y, a * a.z) * l1;
    let (_, l2) = dominant(deflated);
    if l1 < 4.0 * l2.max(0.0) || a.dot(g.normal).abs() > 0.6 {
        return g.normal;
    }
    (g.normal - a * a.dot(g.normal)).normalize_or(g.normal)
}

/// The covariance (in voxels²) of the voxels of `runs` (y, z, first and last x), from their
/// moments summed exactly in whole numbers a run at a time (a run's sums in closed form: the
/// order the fill finds them in does not show, and a million voxels cost their runs, not a
/// point each: Crytek Sponza 256's slot searches spent over a quarter of their time on the points);
/// `None` under 8 voxels.
fn covariance(runs: &[(i64, i64, i64, i64)]) -> Option<glam::Mat3> {
    let &(y0, z0, x0, _) = runs.first()?;
    // Sums of 1, x, y, z and their products, about the first run's start (small numbers).
    let (mut n, mut s, mut ss) = (0i64, [0i64; 3], [[0i64; 3]; 3]);
    for &(y, z, a, b) in runs {
        let (y, z, a, b) = (y - y0, z - z0, a - x0, b - x0);
        let m = b - a + 1;
        // Σx and Σx² over a..=b.
        let sx = (a + b) * m / 2;
        // F(k) = k(k + 1)(2k + 1)/6 has F(k) − F(k − 1) = k² at every whole k, negative too.
        let f = |k: i64| k * (k + 1) * (2 * k + 1) / 6;
        let sxx = f(b) - f(a - 1);
        n += m;
        s[0] += sx;
        s[1] += y * m;
        s[2] += z * m;
        ss[0][0] += sxx;
        ss[0][1] += y * sx;
        ss[0][2] += z * sx;
        ss[1][1] += y * y * m;
        ss[1][2] += y * z * m;
        ss[2][2] += z * z * m;
    }
    if n < 8 {
        return None;
    }
    let nf = n as f64;
    let mean = s.map(|v| v as f64 / nf);
    let c = |i: usize, j: usize| {
        let (i, j) = (i.min(j), i.max(j));
        (ss[i][j] as f64 / nf - mean[i] * mean[j]) as f32
    };
    Some(glam::Mat3::from_cols_array(&[
        c(0, 0),
        c(1, 0),
        c(2, 0),
        c(0, 1),
        c(1, 1),
        c(2, 1),
        c(0, 2),
        c(1, 2),
        c(2, 2),
    ]))
}

/// The empty space as the cuts read it: a byte a voxel, 0 where not empty, else 1 + its
/// largest-ball radius in whole voxels saturated at 254 ([`crate::sightline::PackedSight`]'s
/// cells: one read a voxel where the flags and the radii took two, a third of the memory), and
/// the radii themselves (saturated at `u16::MAX`) for the voxels whose byte saturated.
#[derive(Debug, Clone, Copy)]
pub struct Space<'a> {
    /// A byte a voxel (see above).
    pub cells: &'a [u8],
    /// Each voxel's largest-ball radius in whole voxels (saturated).
    pub radius_vx: &'a [u16],
}

impl Space<'_> {
    /// Whether voxel `i` is empty with a largest ball of at most `narrow` voxels.
    fn narrow(&self, i: usize, narrow: f32) -> bool {
        match self.cells[i] {
            0 => false,
            u8::MAX => f32::from(self.radius_vx[i]) <= narrow,
            c => f32::from(c - 1) <= narrow,
        }
    }
}

/// A flood's scratch, kept from one flood to the next by the thread that runs them: a bit a
/// voxel of the grid, of which only the words a flood set are cleared after it. A fresh
/// bitset a flood (4.4 MB at 512³, thousands of floods) cost a page fault every few voxels; a
/// hash set of coordinates, 26 hashes a voxel; bricks allocated on demand, a table lookup a
/// neighbour.
pub struct Flood {
    /// Grid dimensions.
    dims: [i64; 3],
    /// One bit a voxel: seen by the current flood.
    seen: Vec<u64>,
    /// The words of `seen` the current flood set.
    touched: Vec<usize>,
    /// The breadth-first queue.
    queue: VecDeque<[i64; 3]>,
}

impl Flood {
    /// Scratch for floods of `meta`'s grid.
    pub fn new(meta: &GridMeta) -> Flood {
        let dims = meta.dims.map(i64::from);
        Flood {
            dims,
            seen: vec![0; (dims.iter().product::<i64>() as usize).div_ceil(64)],
            touched: Vec::new(),
            queue: VecDeque::new(),
        }
    }

    /// Marks voxel `i` seen; whether it was new.
    fn insert(&mut self, i: usize) -> bool {
        let (w, bit) = (i / 64, 1u64 << (i % 64));
        let word = self.seen[w];
        if word & bit != 0 {
            return false;
        }
        if word == 0 {
            self.touched.push(w);
        }
        self.seen[w] = word | bit;
        true
    }

    /// The voxels reached from `from`'s voxel (26-connected) through voxels that `keep`
    /// (linear index, centre) accepts, as linear indices in breadth-first order; at most
    /// [`MAX_FLOOD`].
    fn run(
        &mut self,
        meta: &GridMeta,
        from: Vec3,
        keep: impl Fn(usize, Vec3) -> bool,
    ) -> Vec<usize> {
        let dims = self.dims;
        let mut out = Vec::new();
        let Some(start) = self.start(meta, from) else {
            return out;
        };
        self.insert(self.index(start));
        self.queue.push_back(start);
        while let Some(v) = self.queue.pop_front() {
            let i = self.index(v);
            let p = Vec3::from(meta.voxel_to_world(v.map(|c| c as u32)));
            if !keep(i, p) || out.len() >= MAX_FLOOD {
                continue;
            }
            out.push(i);
            // Away from the grid's faces every neighbour is inside it.
            let interior = (0..3).all(|a| v[a] > 0 && v[a] + 1 < dims[a]);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let w = [v[0] + dx, v[1] + dy, v[2] + dz];
                        if (interior || (0..3).all(|a| w[a] >= 0 && w[a] < dims[a]))
                            && self.insert(self.index(w))
                        {
                            self.queue.push_back(w);
                        }
                    }
                }
            }
        }
        self.forget();
        out
    }

    /// The first voxel from `i` to `last` (linear indices) not yet seen, or `last + 1`.
    fn next_unseen(&self, i: usize, last: usize) -> usize {
        let mut w = i / 64;
        let mut free = !self.seen[w] >> (i % 64) << (i % 64);
        loop {
            if free != 0 {
                return (w * 64 + free.trailing_zeros() as usize).min(last + 1);
            }
            w += 1;
            if w * 64 > last {
                return last + 1;
            }
            free = !self.seen[w];
        }
    }

    /// Voxel `v`'s linear index (x fastest).
    fn index(&self, v: [i64; 3]) -> usize {
        let d = self.dims;
        (v[0] + d[0] * (v[1] + d[1] * v[2])) as usize
    }

    /// The voxel of point `from` (m), if it lies in the grid: where a flood starts.
    fn start(&self, meta: &GridMeta, from: Vec3) -> Option<[i64; 3]> {
        let o = Vec3::from(meta.origin_m);
        let start = ((from - o) / meta.voxel_size_m)
            .floor()
            .as_i64vec3()
            .to_array();
        (0..3)
            .all(|a| (0..self.dims[a]).contains(&start[a]))
            .then_some(start)
    }

    /// Clears the bits the current flood set.
    fn forget(&mut self) {
        for &w in &self.touched {
            self.seen[w] = 0;
        }
        self.touched.clear();
    }

    /// The same voxels as [`Flood::run`], in another order: a scanline fill, a row's run of
    /// accepted voxels at a time, that looks at the 8 rows beside a run once for all its voxels
    /// (26 neighbour tests a voxel in the breadth-first flood: Crytek Sponza 256's gate cuts
    /// 0.36 → 0.29 s). Past [`MAX_FLOOD`] voxels it gives the breadth-first flood's, whose cap
    /// keeps those nearest the start.
    fn spans(
        &mut self,
        meta: &GridMeta,
        from: Vec3,
        keep: impl Fn(usize, Vec3) -> bool,
    ) -> Vec<usize> {
        match self.spans_within_cap(meta, from, keep) {
            Ok(runs) => runs
                .iter()
                .flat_map(|&(y, z, a, b)| {
                    let first = self.index([a, y, z]);
                    first..=first + (b - a) as usize
                })
                .collect(),
            Err(keep) => self.run(meta, from, keep),
        }
    }

    /// [`Flood::spans`]'s scanline fill as the runs it found (y, z, first and last x), or,
    /// where it finds more than [`MAX_FLOOD`] voxels, its `keep` back.
    fn spans_within_cap<K: Fn(usize, Vec3) -> bool>(
        &mut self,
        meta: &GridMeta,
        from: Vec3,
        keep: K,
    ) -> Result<Vec<(i64, i64, i64, i64)>, K> {
        let Some(start) = self.start(meta, from) else {
            return Ok(Vec::new());
        };
        let mut fill = Fill {
            flood: self,
            meta,
            keep,
            found: Vec::new(),
            voxels: 0,
            runs: Vec::new(),
        };
        if fill.claim(start) {
            fill.run_from(start);
        }
        while let Some((y, z, a, b)) = fill.runs.pop() {
            if fill.voxels > MAX_FLOOD {
                break;
            }
            fill.beside(y, z, a, b);
        }
        let Fill {
            found,
            voxels,
            keep,
            ..
        } = fill;
        self.forget();
        if voxels > MAX_FLOOD {
            return Err(keep);
        }
        Ok(found)
    }
}

/// A scanline fill in progress ([`Flood::spans`]).
struct Fill<'a, K> {
    flood: &'a mut Flood,
    meta: &'a GridMeta,
    keep: K,
    /// The runs of accepted voxels so far: y, z, first and last x.
    found: Vec<(i64, i64, i64, i64)>,
    /// How many voxels they hold.
    voxels: usize,
    /// Runs whose neighbouring rows are still to look at: y, z, first and last x.
    runs: Vec<(i64, i64, i64, i64)>,
}

impl<K: Fn(usize, Vec3) -> bool> Fill<'_, K> {
    /// Marks voxel `v` seen; whether it was not seen before and is accepted.
    fn claim(&mut self, v: [i64; 3]) -> bool {
        let i = self.flood.index(v);
        self.flood.insert(i)
            && (self.keep)(i, Vec3::from(self.meta.voxel_to_world(v.map(|c| c as u32))))
    }

    /// Grows the run of accepted voxels through claimed voxel `v` along x, records it and
    /// returns its last x.
    fn run_from(&mut self, v: [i64; 3]) -> i64 {
        let [x, y, z] = v;
        let (mut a, mut b) = (x, x);
        while a > 0 && self.claim([a - 1, y, z]) {
            a -= 1;
        }
        while b + 1 < self.flood.dims[0] && self.claim([b + 1, y, z]) {
            b += 1;
        }
        self.found.push((y, z, a, b));
        self.voxels += (b - a + 1) as usize;
        self.runs.push((y, z, a, b));
        b
    }

    /// Claims the voxels of the 8 rows beside run `a..=b` of row (y, z) that touch it.
    fn beside(&mut self, y: i64, z: i64, a: i64, b: i64) {
        let dims = self.flood.dims;
        for dz in -1..=1 {
            for dy in -1..=1 {
                let (ry, rz) = (y + dy, z + dz);
                if (dy, dz) == (0, 0) || ry < 0 || rz < 0 || ry >= dims[1] || rz >= dims[2] {
                    continue;
                }
                let row = self.flood.index([0, ry, rz]);
                let last = (b + 1).min(dims[0] - 1);
                let mut x = (a - 1).max(0);
                // A run claimed here may end past `last` (at the row's end).
                while x <= last {
                    // Voxels already seen are skipped a word of the bitset at a time: most of a
                    // neighbouring row was claimed by the runs beside it.
                    x = self
                        .flood
                        .next_unseen(row + x as usize, row + last as usize)
                        as i64
                        - row as i64;
                    if x > last {
                        break;
                    }
                    if self.claim([x, ry, rz]) {
                        x = self.run_from([x, ry, rz]);
                    }
                    x += 1;
                }
            }
        }
    }
}

/// The voxels of gate `g`'s cut (linear indices; the caller clears them from the empty
/// space): the plane's voxels reached from the gate's centre through the disk (solid or not)
/// or through empty voxels as narrow as the opening; `radius_vx` is each voxel's largest-ball
/// radius in whole voxels (saturated).
pub fn gate_cut(meta: &GridMeta, space: Space, g: &GateDisk) -> Vec<usize> {
    gate_cut_with(&mut Flood::new(meta), meta, space, g)
}

/// [`gate_cut`] with a flood's scratch of the caller's (one a thread, for many gates).
pub fn gate_cut_with(
    scratch: &mut Flood,
    meta: &GridMeta,
    space: Space,
    g: &GateDisk,
) -> Vec<usize> {
    let vs = meta.voxel_size_m;
    // Thresholds a hair over their values, so that a distance equal to one in exact arithmetic
    // counts the same at every scale of the level (voxel units round differently).
    let reach = (3.0 * g.radius + vs) * (1.0 + 1e-4);
    let narrow = (1.5 * g.radius / vs + 1.0 + 1e-3).floor();
    let normal = cut_normal(scratch, meta, space, g, narrow);
    // A voxel lies on the plane when the plane passes through its cube.
    let half = 0.5 * vs * normal.abs().element_sum();
    let on_cut = |i: usize, p: Vec3| {
        let d = p - g.centre;
        let along = d.dot(normal);
        along.abs() <= half && ((d - along * normal).length() <= reach || space.narrow(i, narrow))
    };
    scratch.spans(meta, g.centre, on_cut)
}

#[cfg(test)]
mod tests;

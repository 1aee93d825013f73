//! The voxel walk: whether the segment between a VPL and a surface point meets a wall, read
//! from the level's open voxels (the sight grid, voxelized thin by the bake:
//! `visgate_preprocess::separating`; `sight.wgsl` is the GPU twin).
//!
//! A voxel is closed when a triangle crosses one of its three centre segments, so no path of
//! voxels joined by faces — which is what the walk steps through — passes through a watertight
//! surface, and a plane closes one voxel a column (it may graze a triangle's edge by less than
//! a voxel). So the walk is the portal walk with the portals at voxel resolution: it passes
//! from cluster to cluster through the interface faces themselves, not through planes fitted
//! to them, and it also meets what stands inside a cluster (a door panel, a table). It steps
//! through the grid like a DDA, but jumps: the grid is cut into bricks of [`BRICK`]³ voxels,
//! and each brick knows its chessboard distance, in bricks, to the nearest brick that holds a
//! closed voxel; a brick `c` bricks clear sits in a cube of `2c − 1` bricks that holds none,
//! so the walk crosses that cube in one step. Near walls it steps voxel by voxel. On the
//! shared levels at 512 voxels a walk took about 20 steps with 4³ bricks where the plain DDA
//! takes 120–160.
//!
//! A closed voxel is where geometry may be, not where it is: with the scene's triangles listed
//! in the closed voxels ([`super::sight_triangles`], when a walk first needs them), the walk of
//! [`VoxelSight::visible`] runs along the true segment, between the two surface points, and
//! passes a closed voxel where the segment hits none of them, so a segment that grazes a wall, a
//! column or a door's edge within a voxel is not blocked; [`VoxelSight::visible_off_surfaces`]
//! is the walk without them, between the ends described next (the default: several times
//! faster), where a closed voxel blocks or, with its planes ([`super::sight_planes`], the
//! default), passes a segment that meets neither of the one or two planes its geometry lies in.
//!
//! Each end starts off its own surface, whose closed voxels it may lie in: at the first of
//! [`END_OFFSETS_VOXELS`] along its normal that lands in an open voxel (a segment from a plane
//! that starts √3 voxels off it never enters that plane's voxels again), else at the centre of
//! the open voxel in front of the surface nearest to one voxel out (a point in a corner). An
//! end with no open voxel near it is where the bake knows nothing: it is unoccluded, as a
//! point outside every cluster is.

use glam::{BVec3, IVec3, Vec3};
use visgate_formats::vgate::{GridMeta, VoxelBits};

use super::sight_clearance::{chessboard, closed_bricks};
use super::sight_planes::{self, ClosedPlanes, END_PLANES_OFFSET_VOXELS};
use super::sight_triangles::{
    ClosedTriangles, TRIANGLE_TESTS_PER_WALK, WalkTests, true_end_offset,
};

/// What a walk does at a closed voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Closed {
    /// It blocks.
    Blocks,
    /// It passes where the segment meets neither of its planes ([`super::sight_planes`]).
    Planes,
    /// It passes where the segment hits none of its listed triangles
    /// ([`super::sight_triangles`]).
    Triangles,
}

/// Voxels along a brick's side (sight.wgsl's `SIGHT_BRICK`). 2³ bricks step near walls in
/// fewer, shorter steps than 4³ ones and cost as many bytes as the open bits (a byte a
/// brick): on lavapipe, four rooms and e2m3's hall at 320 × 240, 1,024 VPLs, the indirect pass
/// took 227–252 and 155–169 ms against 313–320 and 179–206 ms with 4³ bricks.
pub const BRICK: i32 = 2;

/// Offsets of a segment's end along its surface normal, tried in order: the first that lands
/// in an open voxel is the end. [Units: voxels]
pub const END_OFFSETS_VOXELS: [f32; 3] = [1.25, 2.25, 3.25];

/// A level's open voxels and their bricks' clearance, ready for walks.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelSight {
    origin_m: Vec3,
    voxel_m: f32,
    dims: IVec3,
    /// A true end's offset off its surface ([`true_end_offset`]). [Units: voxels]
    hair: f32,
    /// The open bits, 32 to a word (bit `i % 32` of word `i / 32`).
    words: Vec<u32>,
    /// Bricks per axis.
    bricks: IVec3,
    /// Per brick, the chessboard distance in bricks to the nearest brick that holds a closed
    /// voxel (0: it holds one), at most 255; the grid's outside counts as closed.
    clear: Vec<u8>,
    /// The static triangles (m) to list in the closed voxels (none: every closed voxel blocks).
    source: std::sync::Arc<[[Vec3; 3]]>,
    /// Their lists, made on the first walk that reads them or by [`VoxelSight::list_triangles`]
    /// (0.8 s and 35 MB for Crytek Sponza at 512: a level that never walks with them pays
    /// neither).
    triangles: std::sync::OnceLock<ClosedTriangles>,
    /// The closed voxels' planes, fitted to the lists when first needed.
    planes: std::sync::OnceLock<ClosedPlanes>,
}

/// `a` divided by `b`, rounded up.
fn div_up(a: i32, b: i32) -> i32 {
    (a + b - 1) / b
}

impl VoxelSight {
    /// The walk over `open` (one bit per voxel of `grid`).
    pub fn new(grid: &GridMeta, open: &VoxelBits) -> VoxelSight {
        let dims = IVec3::from_array(grid.dims.map(|d| d as i32));
        let words: Vec<u32> = open
            .words()
            .iter()
            .flat_map(|&w| [w as u32, (w >> 32) as u32])
            .take((open.len() as usize).div_ceil(32))
            .collect();
        let bricks = IVec3::new(
            div_up(dims.x, BRICK),
            div_up(dims.y, BRICK),
            div_up(dims.z, BRICK),
        );
        let closed = closed_bricks(dims, bricks, &words);
        let origin_m = Vec3::from(grid.origin_m);
        let far_corner = origin_m + dims.as_vec3() * grid.voxel_size_m;
        VoxelSight {
            origin_m,
            voxel_m: grid.voxel_size_m,
            dims,
            hair: true_end_offset(origin_m, far_corner, grid.voxel_size_m),
            words,
            bricks,
            clear: chessboard(bricks, &closed),
            source: std::sync::Arc::new([]),
            triangles: std::sync::OnceLock::new(),
            planes: std::sync::OnceLock::new(),
        }
    }

    /// The same walk, passing a closed voxel where the segment hits none of the `triangles`
    /// (m, the level's static geometry) that touch it ([`super::sight_triangles`]); they are
    /// listed by voxel when first needed.
    pub fn with_triangles(self, triangles: &[[Vec3; 3]]) -> VoxelSight {
        VoxelSight {
            source: triangles.into(),
            triangles: std::sync::OnceLock::new(),
            planes: std::sync::OnceLock::new(),
            ..self
        }
    }

    /// The triangles in the closed voxels, listed now if they were not yet.
    pub fn triangles(&self) -> &ClosedTriangles {
        self.triangles.get_or_init(|| self.list())
    }

    /// The triangles listed in the closed voxels (timed in the log).
    fn list(&self) -> ClosedTriangles {
        let t0 = std::time::Instant::now();
        let grid = GridMeta {
            origin_m: self.origin_m.to_array(),
            voxel_size_m: self.voxel_m,
            dims: self.dims.to_array().map(|d| d as u32),
        };
        let lists = ClosedTriangles::new(&grid, |v| self.open(v), &self.source);
        tracing::info!(
            "voxel walk: {} closed voxels list {} triangle references ({:.2} s)",
            lists.voxels(),
            lists.references(),
            t0.elapsed().as_secs_f64()
        );
        lists
    }

    /// The closed voxels' planes, fitted now if they were not yet (to the triangle lists: those
    /// of [`VoxelSight::triangles`] where they are listed, else lists made for the fit and
    /// dropped, so that the planes alone do not make the lists count as listed); none without
    /// triangles.
    pub fn planes(&self) -> &ClosedPlanes {
        self.planes.get_or_init(|| {
            if self.source.is_empty() {
                return ClosedPlanes::default();
            }
            let made;
            let lists = match self.triangles.get() {
                Some(l) => l,
                None => {
                    made = self.list();
                    &made
                }
            };
            let t0 = std::time::Instant::now();
            let planes = ClosedPlanes::new(self.dims, &self.words, lists);
            let [one, two] = planes.counts();
            tracing::info!(
                "voxel walk: of {} closed voxels {one} hold one plane, {two} two ({:.2} s)",
                planes.voxels(),
                t0.elapsed().as_secs_f64()
            );
            planes
        })
    }

    /// Whether the closed voxels' planes are fitted (and [`VoxelSight::words`] carries them).
    pub fn planes_fitted(&self) -> bool {
        self.planes.get().is_some()
    }

    /// The planes of closed voxel `v`, none where it blocks (or is open, or outside the grid).
    fn planes_of(&self, v: IVec3) -> Option<[Option<sight_planes::Plane>; 2]> {
        let i = self.index(v)?;
        self.planes().of(i, &self.words)
    }

    /// Lists the triangles in the closed voxels now, so that [`VoxelSight::words`] carries
    /// them to the GPU.
    pub fn list_triangles(&self) {
        self.triangles();
    }

    /// Whether the triangles are listed (and [`VoxelSight::words`] carries them).
    pub fn triangles_listed(&self) -> bool {
        self.triangles.get().is_some()
    }

    /// The grid's voxel edge. [Units: m]
    pub fn voxel_m(&self) -> f32 {
        self.voxel_m
    }

    /// Point `p` (m) in voxel coordinates.
    pub fn to_voxels(&self, p: Vec3) -> Vec3 {
        (p - self.origin_m) / self.voxel_m
    }

    /// Whether voxel `v` is open (false outside the grid).
    #[inline]
    pub fn open(&self, v: IVec3) -> bool {
        self.index(v)
            .is_some_and(|i| (self.words[i / 32] >> (i % 32)) & 1 == 1)
    }

    /// Voxel `v`'s index in the grid (x fastest), `None` outside it.
    #[inline]
    fn index(&self, v: IVec3) -> Option<usize> {
        if v.cmplt(IVec3::ZERO).any() || v.cmpge(self.dims).any() {
            return None;
        }
        Some((v.x + self.dims.x * (v.y + self.dims.y * v.z)) as usize)
    }

    /// A brick's clearance ([`VoxelSight::clear`]'s field), 0 outside the brick grid.
    fn brick_clear(&self, b: IVec3) -> i32 {
        if b.cmplt(IVec3::ZERO).any() || b.cmpge(self.bricks).any() {
            return 0;
        }
        i32::from(self.clear[(b.x + self.bricks.x * (b.y + self.bricks.y * b.z)) as usize])
    }

    /// Where the walk from or to surface point `p` (normal `n`) starts, in voxel coordinates
    /// (the grid's minimum corner at 0, a voxel 1 wide); `None` with no open voxel near.
    pub fn end(&self, p: Vec3, n: Vec3) -> Option<Vec3> {
        self.end_with(p, n, false)
    }

    /// [`VoxelSight::end`]; with `planes`, first [`END_PLANES_OFFSET_VOXELS`] off the surface
    /// where that point lies in an open voxel or in a closed one whose planes are farther than
    /// their fit from it.
    pub fn end_with(&self, p: Vec3, n: Vec3, planes: bool) -> Option<Vec3> {
        let q = self.to_voxels(p);
        if planes {
            let s = q + n * END_PLANES_OFFSET_VOXELS;
            let v = s.floor().as_ivec3();
            let clear = || {
                self.planes_of(v)
                    .is_some_and(|c| sight_planes::clear_of(c, v, s))
            };
            if self.open(v) || clear() {
                return Some(s);
            }
        }
        for k in END_OFFSETS_VOXELS {
            let s = q + n * k;
            if self.open(s.floor().as_ivec3()) {
                return Some(s);
            }
        }
        let out = q + n;
        let base = out.floor().as_ivec3();
        let mut best: Option<(f32, Vec3)> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let v = base + IVec3::new(dx, dy, dz);
                    let centre = v.as_vec3() + 0.5;
                    let d2 = (centre - out).length_squared();
                    if self.open(v)
                        && (centre - q).dot(n) > 0.0
                        && best.is_none_or(|(bd, _)| d2 < bd)
                    {
                        best = Some((d2, centre));
                    }
                }
            }
        }
        best.map(|(_, c)| c)
    }

    /// The most steps a walk takes (sight.wgsl's loop bound too): each step crosses a face
    /// along the segment, so at most as many as the segment crosses voxel faces — the grid's
    /// dims summed — plus one.
    pub fn most_steps(&self) -> u32 {
        (self.dims.x + self.dims.y + self.dims.z + 1) as u32
    }

    /// Whether the segment from `a` to `b` (voxel coordinates) crosses open voxels alone — the
    /// brick march described in the module docs — or also closed voxels where it meets
    /// neither of their planes ([`Closed::Planes`]), or hits none of the triangles listed
    /// there within [`TRIANGLE_TESTS_PER_WALK`] list entries ([`Closed::Triangles`]).
    pub fn clear(&self, a: Vec3, b: Vec3, closed: Closed) -> bool {
        let mut tests = WalkTests::new(TRIANGLE_TESTS_PER_WALK);
        let d = b - a;
        let (moves, up) = (d.cmpne(Vec3::ZERO), d.cmpgt(Vec3::ZERO));
        // An axis the segment does not move along is never the one it leaves a cube across.
        let inv = Vec3::select(moves, d.recip(), Vec3::ZERO);
        let end = b.floor().as_ivec3();
        let mut v = a.floor().as_ivec3();
        for _ in 0..self.most_steps() {
            let brick = v.div_euclid(IVec3::splat(BRICK));
            let c = self.brick_clear(brick);
            let (lo, hi) = if c > 0 {
                ((brick - (c - 1)) * BRICK, (brick + c) * BRICK - 1)
            } else if self.open(v) || self.passes(v, (a, b), closed, &mut tests) {
                (v, v)
            } else {
                return false;
            };
            // The cube is open and convex: from where the segment entered it, a cube that
            // holds the end holds the rest of the segment (said before any time is computed,
            // whose rounding could take the walk past an end on the cube's face).
            if end.cmpge(lo).all() && end.cmple(hi).all() {
                return true;
            }
            // The time the segment leaves the open cube [lo, hi] along each axis.
            let face = Vec3::select(up, (hi + 1).as_vec3(), lo.as_vec3());
            let t = Vec3::select(moves, (face - a) * inv, Vec3::INFINITY);
            let te = t.min_element();
            if te >= 1.0 {
                return true;
            }
            // It leaves across the first axis to reach that time (the lowest, on a tie), into
            // the voxel beyond the face; on the other axes it stays within the cube.
            let across = if t.x <= t.y && t.x <= t.z {
                BVec3::new(true, false, false)
            } else if t.y <= t.z {
                BVec3::new(false, true, false)
            } else {
                BVec3::new(false, false, true)
            };
            let inside = (a + d * te).floor().as_ivec3().clamp(lo, hi);
            v = IVec3::select(across, IVec3::select(up, hi + 1, lo - 1), inside);
        }
        false
    }

    /// Whether a walk passes closed voxel `v` on its planes or its triangles (never outside the
    /// grid; a voxel with the list the walk last read whole passes unread, out of tests or
    /// not, as on the GPU).
    fn passes(
        &self,
        v: IVec3,
        (a, b): (Vec3, Vec3),
        closed: Closed,
        tests: &mut WalkTests,
    ) -> bool {
        match closed {
            Closed::Blocks => false,
            Closed::Planes => self
                .planes_of(v)
                .is_some_and(|p| sight_planes::passes(p, v, a, b - a)),
            Closed::Triangles => self
                .index(v)
                .is_some_and(|i| self.triangles().pass(i, (a, b), tests)),
        }
    }

    /// The true segment's end at surface point `p` (normal `n`), in voxel coordinates.
    pub fn true_end(&self, p: Vec3, n: Vec3) -> Vec3 {
        self.to_voxels(p) + n * self.hair
    }

    /// Whether light passes between surface points `a` (normal `na`) and `b` (normal `nb`):
    /// the walk along the segment between them (each end a hair off its surface), through the
    /// closed voxels whose listed triangles it misses; unoccluded when either has no open
    /// voxel near.
    pub fn visible(&self, a: Vec3, na: Vec3, b: Vec3, nb: Vec3) -> bool {
        if self.end(a, na).is_none() || self.end(b, nb).is_none() {
            return true;
        }
        self.clear(
            self.true_end(a, na),
            self.true_end(b, nb),
            Closed::Triangles,
        )
    }

    /// Whether light passes between surface points `a` (normal `na`) and `b` (normal `nb`):
    /// the walk between their ends off the surfaces ([`VoxelSight::end_with`]), each closed
    /// voxel blocking or, with `planes`, passed where the segment meets neither of its planes;
    /// unoccluded when either has no open voxel near.
    pub fn visible_off_surfaces(&self, a: Vec3, na: Vec3, b: Vec3, nb: Vec3, planes: bool) -> bool {
        match (self.end_with(a, na, planes), self.end_with(b, nb, planes)) {
            (Some(x), Some(y)) => self.clear(
                x,
                y,
                if planes {
                    Closed::Planes
                } else {
                    Closed::Blocks
                },
            ),
            _ => true,
        }
    }

    /// The walk's tables packed into words for sight.wgsl, in two arrays (each a binding of
    /// its own, so that each fits an adapter's storage binding limit: Crytek Sponza's 4 cm
    /// grid with its triangle lists is 153 MB, over the 128 MiB of lavapipe and of wgpu's
    /// default). [`SightWords::base`]: `[nx, ny, nz, bricks x, y, z, word offset of the
    /// clearances, triangle tests a walk, origin x, y, z (m, f32 bits), voxel edge (m, f32
    /// bits), word offsets in [`SightWords::extra`] of the closed voxels' marks, lists,
    /// triangle indices and triangles (0: no lists), of the planes' counts and planes (0:
    /// none), a true end's offset (voxels, f32 bits: [`true_end_offset`])]`, the open bits (32 a word), the bricks' clearances, four bytes a word
    /// (little-endian). [`SightWords::extra`]: a word 0 (so that no table starts at 0), then
    /// the triangle lists ([`ClosedTriangles::words`]) if they are listed
    /// ([`VoxelSight::list_triangles`]) and the planes ([`ClosedPlanes::words`]) if they are
    /// fitted ([`VoxelSight::planes`]).
    pub fn words(&self) -> SightWords {
        self.words_with(true, true)
    }

    /// [`VoxelSight::words`], with the triangle lists only where `lists` asks for them and
    /// the planes where `planes` does (each where it is made): a walk without them need not
    /// carry them.
    pub fn words_with(&self, lists: bool, planes: bool) -> SightWords {
        let clear_at = SIGHT_HEADER_WORDS + self.words.len();
        let none = ClosedTriangles::default();
        let listed = self.triangles.get().filter(|_| lists);
        let (lists, at) = listed.unwrap_or(&none).words(1);
        let no_planes = ClosedPlanes::default();
        let fitted = self.planes.get().filter(|_| planes);
        let (planes, planes_at) = fitted.unwrap_or(&no_planes).words(1 + lists.len());
        let mut w = Vec::with_capacity(clear_at + self.clear.len().div_ceil(4));
        w.extend(self.dims.to_array().map(|x| x as u32));
        w.extend(self.bricks.to_array().map(|x| x as u32));
        w.extend([clear_at as u32, TRIANGLE_TESTS_PER_WALK]);
        w.extend(self.origin_m.to_array().map(f32::to_bits));
        w.push(self.voxel_m.to_bits());
        w.extend(at);
        w.extend(planes_at);
        w.push(self.hair.to_bits());
        w.extend(&self.words);
        w.extend(self.clear.chunks(4).map(|c| {
            let mut b = [0u8; 4];
            b[..c.len()].copy_from_slice(c);
            u32::from_le_bytes(b)
        }));
        let mut extra = Vec::with_capacity(1 + lists.len() + planes.len());
        extra.push(0);
        extra.extend(lists);
        extra.extend(planes);
        SightWords { base: w, extra }
    }
}

/// The voxel walk's tables as sight.wgsl reads them ([`VoxelSight::words`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SightWords {
    /// The header, the open bits and the bricks' clearances (`sight_words`).
    pub base: Vec<u32>,
    /// A word 0, then the closed voxels' triangle lists and planes (`sight_extra`).
    pub extra: Vec<u32>,
}

/// Words before the open bits in [`VoxelSight::words`].
pub const SIGHT_HEADER_WORDS: usize = 19;

/// Voxel `i` of a grid of `dims` (x fastest).
pub(super) fn voxel_of(i: usize, dims: IVec3) -> IVec3 {
    let (nx, ny) = (dims.x as usize, dims.y as usize);
    IVec3::new(
        (i % nx) as i32,
        ((i / nx) % ny) as i32,
        (i / (nx * ny)) as i32,
    )
}

#[cfg(test)]
mod tests;

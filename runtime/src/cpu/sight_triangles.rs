//! The triangles in the sight grid's closed voxels, so that the voxel walk can pass a closed
//! voxel where the segment misses them ([`super::sight`]).
//!
//! A voxel is closed when a triangle crosses one of its centre segments, so a walk that blocks
//! at every closed voxel blocks a segment that grazes a wall, a column or a door's edge within
//! a voxel, though the shadow ray passes (on the shared levels most of that walk's false
//! occlusion lay there, far from both ends: Crytek Sponza's gallery at 512, 66 % of the
//! blocked visible pairs 8 voxels or more from both ends), and it had to start each end a
//! voxel or more off its surface, past geometry in contact with it. With the triangles that
//! touch each closed voxel listed, the walk runs along the true segment, from surface point to
//! surface point (each a hair off its surface, [`TRUE_END_OFFSET_VOXELS`]), and in a closed
//! voxel tests the segment against that voxel's triangles: the voxels find where geometry may
//! be, the triangles say whether the light meets it. A voxel lists the triangles that touch it
//! grown by a thousandth of a voxel ([`LIST_HALF`]), so that a triangle on a face two voxels
//! share is in both whatever the rounding of its corners. A closed voxel with no list (the
//! grid's border) blocks. A walk reads at most [`TRIANGLE_TESTS_PER_WALK`] list entries and is
//! blocked past that, which bounds its cost; a triangle met again in the next voxels (a wall
//! the walk grazes, the walk's own surface) is read but not tested again, and a voxel with the
//! same triangles as the last list read whole, which shares its list, is passed unread
//! ([`WalkTests`]).

use rustc_hash::FxHashMap;

use glam::{DVec3, IVec3, Vec3};
use rayon::prelude::*;
use visgate_formats::geom::tri_box_overlap;
use visgate_formats::vgate::GridMeta;

/// The most list entries one walk reads before it counts as blocked (sight.wgsl reads it from
/// the packed words): a walk that grazes finely cut geometry along many voxels stops there. On
/// Crytek Sponza's atrium at 512 (928 VPLs, 160 × 90), with lists of voxels grown by half a
/// voxel, 256 left 3.3 % of the visible pairs blocked, 512 1.4 %, 1,024 1.0 %; with
/// [`LIST_HALF`]'s lists, 512 leaves 0.9 %.
pub const TRIANGLE_TESTS_PER_WALK: u32 = 512;

/// Half the side of the box a triangle must touch to be listed in a voxel (see the module
/// docs; lists of voxels grown by half a voxel held twice the references and left more walks
/// out of tests: Crytek Sponza's atrium agreed on 99.20 % of its pairs, 99.36 % with these).
/// [Units: voxels]
pub const LIST_HALF: f64 = 0.5 + 1e-3;

/// What a walk may still read of the lists, and what it has tested (and found missed): the last
/// list whole, and the last two triangles (a wall's triangles span many voxels of a walk that
/// grazes it; voxels with the same triangles share one list, passed without a read).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WalkTests {
    /// List entries left to read (a triangle tested, or passed over as tested lately).
    pub left: u32,
    /// The last list read whole, `u32::MAX` for none yet.
    list: u32,
    /// The last two triangles tested, the latest first; `u32::MAX` for none yet.
    last: [u32; 2],
}

impl WalkTests {
    /// A walk that may read `left` list entries.
    pub fn new(left: u32) -> WalkTests {
        WalkTests {
            left,
            list: u32::MAX,
            last: [u32::MAX; 2],
        }
    }
}

/// Bits of a packed list's start in the triangle indices: 2²⁴ references at most (Crytek Sponza
/// at 512 has 3.6 M before lists are shared).
pub const LIST_START_BITS: u32 = 24;

/// The longest list a voxel keeps; a voxel touched by more triangles blocks, as a closed voxel
/// did before the lists.
pub const LIST_MAX: usize = (1 << (32 - LIST_START_BITS)) - 1;

const LIST_LENGTH_MASK: u32 = (1 << (32 - LIST_START_BITS)) - 1;

/// The true segment's end is this far along its surface normal, so that its own triangle does
/// not hit it, or farther where the level lies far from the origin ([`true_end_offset`]).
/// [Units: voxels]
pub const TRUE_END_OFFSET_VOXELS: f32 = 1e-3;

/// A true end's offset is at least this many float steps (ulps) of the level's farthest
/// coordinate: positions are rounded to those steps, so a point on a surface may lie that far
/// behind it. [Units: ulps]
pub const TRUE_END_OFFSET_ULPS: f32 = 4.0;

/// The true end's offset along the normal in a grid whose corners lie at `origin_m` and
/// `far_corner_m`, of voxels `voxel_m` across: [`TRUE_END_OFFSET_VOXELS`], or
/// [`TRUE_END_OFFSET_ULPS`] float steps of the farthest corner's largest coordinate where that
/// is more. Every level near the origin keeps 1e-3 (LibreQuake e2m3, 88 m from it, needs 3.3e-4
/// of its 12.8 cm voxels); the ajar door moved 3 km away needs 0.092 of its 1.56 cm voxels
/// (1.4 mm), where 1e-3 of one (16 µm) is a fifteenth of the 0.24 mm between floats there, so
/// that walks began behind their own walls (`tests/far_from_origin.rs`). [Units: voxels]
pub fn true_end_offset(origin_m: Vec3, far_corner_m: Vec3, voxel_m: f32) -> f32 {
    let far = origin_m.abs().max(far_corner_m.abs()).max_element();
    TRUE_END_OFFSET_VOXELS.max(TRUE_END_OFFSET_ULPS * f32::EPSILON * far / voxel_m)
}

/// The triangles touching each closed voxel that any triangle touches, in the layout the GPU
/// reads (a rank over the grid, list ids, list offsets, indices, corners).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClosedTriangles {
    /// Per word of 32 voxels (the open bits' words): the voxels of the word that hold a list
    /// (bit `i % 32`), and how many voxels before the word hold one. Empty: no lists.
    marks: Vec<[u32; 2]>,
    /// Per voxel that holds a list, in voxel order, its list: where it starts in `refs` (the
    /// high [`LIST_START_BITS`] bits) and its length (the low bits, at most [`LIST_MAX`]);
    /// voxels touched by the same triangles share one.
    ids: Vec<u32>,
    /// Lists (each shared one once).
    lists: usize,
    /// Triangle indices into `corners`.
    refs: Vec<u32>,
    /// Each triangle's corners in voxel coordinates (the grid's minimum corner at 0, a voxel
    /// 1 wide).
    corners: Vec<[Vec3; 3]>,
}

impl ClosedTriangles {
    /// Lists `triangles` (m) by the voxels of `grid` they touch where `open(voxel)` is false;
    /// in parallel over triangles.
    pub fn new(
        grid: &GridMeta,
        open: impl Fn(IVec3) -> bool + Sync,
        triangles: &[[Vec3; 3]],
    ) -> ClosedTriangles {
        let dims = IVec3::from_array(grid.dims.map(|d| d as i32));
        let origin = Vec3::from(grid.origin_m).as_dvec3();
        let size = f64::from(grid.voxel_size_m);
        let corners: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|p| (p.as_dvec3() - origin) / size))
            .collect();
        let index = |v: IVec3| (v.x + dims.x * (v.y + dims.y * v.z)) as u64;
        let mut pairs: Vec<u64> = corners
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, &c)| {
                // The voxels whose listing box meets the triangle's bounds.
                let margin = DVec3::splat(LIST_HALF - 0.5);
                let lo = (c[0].min(c[1]).min(c[2]) - margin).floor().as_ivec3();
                let hi = (c[0].max(c[1]).max(c[2]) + margin).floor().as_ivec3();
                let (lo, hi) = (lo.max(IVec3::ZERO), hi.min(dims - 1));
                let open = &open;
                (lo.z..=hi.z).flat_map(move |z| {
                    (lo.y..=hi.y).flat_map(move |y| {
                        (lo.x..=hi.x).filter_map(move |x| {
                            let v = IVec3::new(x, y, z);
                            let touches = || tri_box_overlap(v.as_dvec3() + 0.5, LIST_HALF, c);
                            (!open(v) && touches()).then(|| index(v) << 32 | t as u64)
                        })
                    })
                })
            })
            .collect();
        pairs.par_sort_unstable();
        let voxels = (dims.x as usize) * (dims.y as usize) * (dims.z as usize);
        let mut marks = vec![[0u32; 2]; voxels.div_ceil(32)];
        let mut ids = Vec::new();
        let mut refs = Vec::new();
        // Voxels with the same triangles share a list: keyed by the triangles' run in the
        // sorted pairs' low words (no list made per voxel; Crytek Sponza's 9.7 M pairs and
        // 7.2 M voxels took 0.70 s with a list each and the standard hasher).
        let triangles: Vec<u32> = pairs.par_iter().map(|&p| p as u32).collect();
        let mut lists: FxHashMap<&[u32], u32> = FxHashMap::default();
        let mut start = 0;
        for run in pairs.chunk_by(|p, q| p >> 32 == q >> 32) {
            let v = run[0] >> 32;
            marks[(v / 32) as usize][0] |= 1 << (v % 32);
            // A list too long to pack is cut to its first LIST_MAX + 1 (which the walk reads
            // as blocking).
            let t = &triangles[start..start + run.len().min(LIST_MAX + 1)];
            start += run.len();
            let id = *lists.entry(t).or_insert_with(|| {
                let first = refs.len() as u32;
                refs.extend_from_slice(t);
                (first << (32 - LIST_START_BITS)) | (t.len() as u32 - 1)
            });
            ids.push(id);
        }
        let lists = lists.len();
        let mut before = 0;
        for m in &mut marks {
            m[1] = before;
            before += m[0].count_ones();
        }
        assert!(
            refs.len() < 1 << LIST_START_BITS,
            "triangle lists past their packing"
        );
        ClosedTriangles {
            marks,
            ids,
            lists,
            refs,
            corners: corners.iter().map(|c| c.map(|p| p.as_vec3())).collect(),
        }
    }

    /// Voxels that hold a list.
    pub fn voxels(&self) -> usize {
        self.ids.len()
    }

    /// Lists, voxels with the same triangles sharing one.
    pub fn lists(&self) -> usize {
        self.lists
    }

    /// Triangle references over all lists (each shared list once).
    pub fn references(&self) -> usize {
        self.refs.len()
    }

    /// The list of voxel `i` (its index in the grid), if it has one: its id and triangles.
    fn list(&self, i: usize) -> Option<(u32, &[u32])> {
        let &[mask, before] = self.marks.get(i / 32)?;
        let bit = 1u32 << (i % 32);
        if mask & bit == 0 {
            return None;
        }
        let id = self.ids[(before + (mask & (bit - 1)).count_ones()) as usize];
        let first = (id >> (32 - LIST_START_BITS)) as usize;
        let len = (id & LIST_LENGTH_MASK) as usize + 1;
        Some((id, &self.refs[first..first + len]))
    }

    /// The id of voxel `i`'s list (voxels with the same triangles share it); none without a
    /// list or with one too long to pack.
    pub fn list_id(&self, i: usize) -> Option<u32> {
        let (id, list) = self.list(i)?;
        (list.len() <= LIST_MAX).then_some(id)
    }

    /// The lists' ids, once each.
    pub fn list_ids(&self) -> Vec<u32> {
        let mut ids = self.ids.clone();
        ids.par_sort_unstable();
        ids.dedup();
        ids
    }

    /// The corners (voxel coordinates) of the triangles of list `id`
    /// ([`ClosedTriangles::list_id`]).
    pub fn corners_in(&self, id: u32) -> Vec<[Vec3; 3]> {
        let first = (id >> (32 - LIST_START_BITS)) as usize;
        let len = (id & LIST_LENGTH_MASK) as usize + 1;
        self.refs[first..first + len]
            .iter()
            .map(|&t| self.corners[t as usize])
            .collect()
    }

    /// Whether a walk passes closed voxel `i`: it holds triangles, and segment `a`–`b` (voxel
    /// coordinates) hits none of them, within the walk's `tests` (spent here; a walk out of
    /// tests is blocked).
    pub fn pass(&self, i: usize, (a, b): (Vec3, Vec3), tests: &mut WalkTests) -> bool {
        let Some((id, list)) = self.list(i) else {
            return false;
        };
        if id == tests.list {
            return true;
        }
        if list.len() > LIST_MAX {
            return false;
        }
        for &t in list {
            if tests.left == 0 {
                return false;
            }
            tests.left -= 1;
            if tests.last.contains(&t) {
                continue;
            }
            tests.last = [t, tests.last[0]];
            if hits(self.corners[t as usize], a, b) {
                return false;
            }
        }
        tests.list = id;
        true
    }

    /// Packs the tables after `at` words (sight.wgsl's layout): returns the words and the word
    /// offsets of the marks, the lists, the indices and the triangles ([`TRIANGLE_WORDS`]
    /// each); all 0 with no lists.
    pub fn words(&self, at: usize) -> (Vec<u32>, [u32; 4]) {
        if self.ids.is_empty() {
            return (Vec::new(), [0; 4]);
        }
        let marks_at = at;
        let ids_at = marks_at + 2 * self.marks.len();
        let refs_at = ids_at + self.ids.len();
        let corners_at = refs_at + self.refs.len();
        let mut w = Vec::with_capacity(corners_at - at + TRIANGLE_WORDS * self.corners.len());
        w.extend(self.marks.iter().flatten());
        w.extend(&self.ids);
        w.extend(&self.refs);
        for &c in &self.corners {
            let t = Prepared::of(c);
            let [n, c0, e1, e2] = [t.normal, c[0], t.e1, t.e2].map(|v| v.to_array());
            let floats = [&n[..], &[t.plane], &c0, &e1, &e2].concat();
            w.extend(floats.iter().map(|x| x.to_bits()));
        }
        let at = [marks_at, ids_at, refs_at, corners_at].map(|x| x as u32);
        (w, at)
    }
}

/// Words a triangle takes in [`ClosedTriangles::words`]: its plane's normal (the edges'
/// cross product) and offset, its first corner, its two edges from it.
pub const TRIANGLE_WORDS: usize = 13;

/// A triangle as the walk tests it (what sight.wgsl reads).
struct Prepared {
    normal: Vec3,
    plane: f32,
    e1: Vec3,
    e2: Vec3,
}

impl Prepared {
    fn of(c: [Vec3; 3]) -> Prepared {
        let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
        let normal = e1.cross(e2);
        Prepared {
            normal,
            plane: normal.dot(c[0]),
            e1,
            e2,
        }
    }
}

/// Whether segment `a`–`b` hits triangle `c` strictly between its ends: the ends on either
/// side of its plane (most segments a walk tests are not: the end's own surface, a wall it
/// grazes), then Möller–Trumbore (sight.wgsl's `sight_hits`).
pub fn hits(c: [Vec3; 3], a: Vec3, b: Vec3) -> bool {
    let t = Prepared::of(c);
    if (t.normal.dot(a) - t.plane) * (t.normal.dot(b) - t.plane) >= 0.0 {
        return false;
    }
    let d = b - a;
    let p = d.cross(t.e2);
    let det = t.e1.dot(p);
    if det.abs() < 1e-12 {
        return false;
    }
    let s = a - c[0];
    let u = s.dot(p) / det;
    let q = s.cross(t.e1);
    let w = d.dot(q) / det;
    let h = t.e2.dot(q) / det;
    u >= 0.0 && w >= 0.0 && u + w <= 1.0 && h > 1e-4 && h < 1.0 - 1e-4
}

/// What the open voxels' grid carries beyond its bits, for [`sight_too_large`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SightExtra {
    /// The closed voxels' triangle lists (`--closed-voxel-triangles`).
    Lists,
    /// The closed voxels' planes (the default walk; `--no-closed-voxel-planes` walks without).
    Planes,
}

/// Why the voxel walk's tables do not fit storage bindings of `limit` bytes, and what fits
/// them: the open voxels' grid of `base` bytes, or the closed voxels' triangle lists or planes
/// (`extra`: which, and their bytes), each a binding of its own. The sight grid's voxel
/// (`voxel_m`) is the level's own, not its resolution's (Crytek Sponza's is 4 cm baked at 128
/// or at 512), and the lists and planes are the walk's. `None` where both fit.
pub fn sight_too_large(
    base: u64,
    extra: Option<(SightExtra, u64)>,
    voxel_m: f32,
    limit: u64,
) -> Option<String> {
    // The bits shrink with the cube of the voxel and the lists and planes (one a closed voxel,
    // which lie on the surfaces) with its square at least; a hair coarser than that, as a hint.
    let (what, bytes, power, without) = match extra {
        _ if base > limit => ("the open voxels' grid needs", base, 1.0 / 3.0, ""),
        Some((SightExtra::Lists, bytes)) if bytes > limit => (
            "the closed voxels' triangle lists (the balanced and accurate settings, \
             --closed-voxel-triangles) need",
            bytes,
            0.5,
            "walk on the closed voxels' planes (--fast, without --closed-voxel-triangles), or ",
        ),
        Some((SightExtra::Planes, bytes)) if bytes > limit => (
            "the closed voxels' planes need",
            bytes,
            0.5,
            "walk with --no-closed-voxel-planes, or ",
        ),
        _ => return None,
    };
    let fits = voxel_m * (bytes as f32 / limit as f32).powf(power) * 1.05;
    Some(format!(
        "{what} {bytes} bytes, more than the adapter's storage binding limit {limit}: \
         {without}bake with a coarser --sight-voxel (this level's is {voxel_m:.4} m; about \
         {fits:.4} m fits)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_true_end_leaves_its_surface_by_float_steps_far_from_the_origin() {
        // Near the origin 1e-3 of a voxel (e2m3: 88 m out, 12.8 cm voxels, would need 3.3e-4).
        let e2m3 = true_end_offset(
            Vec3::new(-25.2, -30.1, -17.1),
            Vec3::new(82.9, 18.7, 88.6),
            0.128,
        );
        assert_eq!(e2m3, TRUE_END_OFFSET_VOXELS);
        // The ajar door 3 km out on 1.56 cm voxels: 4 ε × 3008 m, 1.4 mm, 0.092 voxels.
        let far = true_end_offset(Vec3::new(3000.0, 0.0, 3000.0), Vec3::splat(3008.0), 0.0156);
        let want = 4.0 * f32::EPSILON * 3008.0 / 0.0156;
        assert!(
            (far - want).abs() < 1e-6 && far > 30.0 * TRUE_END_OFFSET_VOXELS,
            "{far}"
        );
        // Either side of the origin alike.
        assert_eq!(
            true_end_offset(Vec3::splat(-3008.0), Vec3::splat(-3000.0), 0.0156),
            far
        );
    }

    #[test]
    fn lists_hold_the_triangles_touching_each_closed_voxel_and_nothing_else() {
        // A 6 × 5 × 4 grid of 0.5 m voxels; two triangles; voxels with x = 2 closed.
        let grid = GridMeta {
            origin_m: [1.0, 0.0, -1.0],
            voxel_size_m: 0.5,
            dims: [6, 5, 4],
        };
        let tris = [
            [
                Vec3::new(2.2, 0.1, -0.9),
                Vec3::new(2.3, 2.4, -0.9),
                Vec3::new(2.2, 0.1, 0.9),
            ],
            [
                Vec3::new(3.9, 0.1, -0.9),
                Vec3::new(3.9, 2.4, -0.9),
                Vec3::new(3.9, 0.1, 0.9),
            ],
        ];
        let closed = |v: IVec3| v.x == 2;
        let t = ClosedTriangles::new(&grid, |v| !closed(v), &tris);
        let c = tris.map(|t| t.map(|p| ((p - Vec3::from(grid.origin_m)) / 0.5).as_dvec3()));
        let mut voxels = 0;
        for i in 0..120usize {
            let v = IVec3::new((i % 6) as i32, ((i / 6) % 5) as i32, (i / 30) as i32);
            let want: Vec<u32> = (0..2u32)
                .filter(|&k| {
                    closed(v) && tri_box_overlap(v.as_dvec3() + 0.5, LIST_HALF, c[k as usize])
                })
                .collect();
            assert_eq!(
                t.list(i).map_or(&[][..], |l| l.1),
                want.as_slice(),
                "voxel {v}"
            );
            voxels += usize::from(!want.is_empty());
        }
        assert!(voxels > 4);
        assert_eq!(t.voxels(), voxels);
    }

    #[test]
    fn a_closed_voxel_passes_a_segment_that_misses_its_triangles_within_its_tests() {
        // One voxel (0, 0, 0) closed by a triangle in the plane x = 0.5: y, z ≥ 0, y + z ≤ 0.6.
        let grid = GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 1.0,
            dims: [2, 2, 2],
        };
        let tri = [
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.5, 0.6, 0.0),
            Vec3::new(0.5, 0.0, 0.6),
        ];
        let t = ClosedTriangles::new(&grid, |v| v != IVec3::ZERO, &[tri]);
        let along = |y: f32| (Vec3::new(0.0, y, 0.1), Vec3::new(1.0, y, 0.1));
        let mut tests = WalkTests::new(4);
        assert!(!t.pass(0, along(0.2), &mut tests));
        assert_eq!(tests.left, 3);
        // Tested lately: read but not tested again, its answer taken as a miss (a walk that
        // hit it stopped there).
        assert!(t.pass(0, along(0.8), &mut tests));
        assert_eq!(tests.left, 2);
        let mut tests = WalkTests::new(4);
        assert!(t.pass(0, along(0.8), &mut tests));
        assert_eq!(tests.left, 3);
        assert!(!t.pass(0, along(0.8), &mut WalkTests::new(0)));
        // A voxel without a list blocks.
        assert!(!t.pass(1, along(0.8), &mut WalkTests::new(4)));
    }

    #[test]
    fn a_sight_grid_too_large_for_the_binding_says_what_fits_it() {
        let limit = 128 << 20;
        let lists = |bytes| Some((SightExtra::Lists, bytes));
        let refused = |base, extra, voxel_m| {
            super::sight_too_large(base, extra, voxel_m, limit).expect("refused")
        };
        // Crytek Sponza's on lavapipe: 52 MB of grid and 101 MB of lists fit, each a binding.
        assert_eq!(
            super::sight_too_large(52_000_000, lists(101_000_000), 0.04, limit),
            None
        );
        // Lists past the limit: walk without them, or a coarser voxel.
        let m = refused(52_000_000, lists(200_000_000), 0.04);
        assert!(
            m.starts_with("the closed voxels' triangle lists (the balanced and accurate settings"),
            "{m}"
        );
        assert!(
            m.contains("(--fast, without --closed-voxel-triangles), or "),
            "{m}"
        );
        assert!(
            m.contains("this level's is 0.0400 m; about 0.0513 m fits"),
            "{m}"
        );
        assert!(!m.contains("resolution"), "{m}");
        // The grid itself too large: only the coarser voxel is offered, for the grid.
        let m = refused(300 << 20, lists(10), 0.01);
        assert!(m.starts_with("the open voxels' grid needs"), "{m}");
        assert!(!m.contains("walk without"), "{m}");
        assert!(m.contains("about 0.0139 m fits"), "{m}");
        // The planes: walk without them.
        let planes = Some((SightExtra::Planes, 140_000_000));
        let m = refused(60_000_000, planes, 0.04);
        assert!(m.starts_with("the closed voxels' planes need"), "{m}");
        assert!(m.contains("walk with --no-closed-voxel-planes, or "), "{m}");
        let m = refused(256 << 20, None, 0.02);
        assert!(m.contains("about 0.0265 m fits"), "{m}");
    }
}

//! The closed voxels' planes: where a closed voxel's geometry is one or two planes, the voxel
//! walk passes it when the segment crosses neither inside it ([`super::sight`]).
//!
//! A closed voxel is where geometry may be, not where it is, so the walk that blocks at every
//! closed voxel blocks a segment that passes a door's jamb, a column's corner or a wall's face
//! within a voxel though a shadow ray passes (the pillared hall's side room, seen through its
//! doorway: black strips on the walls where the light through the doorway grazes the jamb).
//! Most closed voxels hold one plane (a wall, a floor) or two (a corner, an edge), so each is
//! stored as at most two planes, 32 bits each, fitted to the triangles that touch the voxel
//! (its triangle list, [`super::sight_triangles`]) so that every part of them inside the voxel
//! lies within [`PLANE_FIT`] of a plane. The walk blocks at the voxel when the segment, inside
//! the voxel, comes within the fit of a plane's patch: of the whole plane, or, where the two
//! planes meet at an edge inside the voxel, of the side of the other plane that the patch lies
//! on (a jamb's face ends at the wall's face, a column's face at its neighbour). So it never
//! passes a segment that hits a triangle inside the voxel (tested on random triangles and
//! segments), and passes what the planes prove clear. A voxel with three planes or more (an
//! ornament, a plant) still blocks.
//!
//! Each end of the walk may then start 0.3 voxels off its surface, inside its own closed voxel
//! where that voxel's planes are farther than the fit from it ([`END_PLANES_OFFSET_VOXELS`]),
//! rather than 1.25 voxels or more out, past the geometry within a voxel of it.
//!
//! On the GPU (`sight.wgsl`) the planes follow the triangle lists' place in the walk's words: a
//! count of the closed voxels before each block of 256 voxels, then a word per closed voxel in
//! voxel order — a plane, or where it has two the place of the pair after them — then the
//! pairs. Crytek Sponza's 9.4 M closed voxels of 4 cm (about 2.2 M of them the grid's border,
//! which blocks) hold 6.3 M single planes and 0.74 M pairs: about 47 MB with the counts, beside
//! its open voxels' 53 MB.

use glam::{IVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::sight::voxel_of;
use super::sight_triangles::ClosedTriangles;

/// How far a closed voxel's triangles may lie from the plane that stands for them, and how near
/// a segment may come to a plane before it counts as meeting it. [Units: voxels]
pub const PLANE_FIT: f32 = 0.05;

/// Where a walk's end starts off its surface when its voxel's planes allow it (then at
/// [`super::sight::END_OFFSETS_VOXELS`]): points of the view with nine tenths of their visible
/// VPLs blocked (160 × 90, 1,024 paths), 0.1 / 0.3 / 1.25 voxels: the pillared hall's side room
/// 12 / 8 / 14, Crytek Sponza's gallery 89 / 40 / 87 (the walk without planes 57 and 108).
/// [Units: voxels]
pub const END_PLANES_OFFSET_VOXELS: f32 = 0.3;

/// Voxels a block of the closed-voxel count covers (eight words of the open bits).
pub const PLANES_BLOCK: usize = 256;

/// A plane word's kind (its low two bits): none (the voxel blocks, or has one plane), a whole
/// plane, or a patch on the positive or the negative side of the voxel's other plane. A closed
/// voxel's own word is none, whole, or `PAIR`: the place of its two plane words.
const NONE: u32 = 0;
const WHOLE: u32 = 1;
const ABOVE: u32 = 2;
const BELOW: u32 = 3;
const PAIR: u32 = 2;

/// Offsets a plane word holds, from the voxel's centre, within ±this. [Units: voxels]
const OFFSET_RANGE: f32 = 1.0;

/// The closed voxels' planes in the layout the GPU reads.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClosedPlanes {
    /// Per block of [`PLANES_BLOCK`] voxels, the closed voxels before it.
    before: Vec<u32>,
    /// Per closed voxel, in voxel order, its word (`NONE`: it blocks; a plane; or `PAIR` and
    /// the place in this table of its two plane words), then the pairs.
    words: Vec<u32>,
    /// Closed voxels.
    closed: usize,
}

/// A plane decoded: unit normal, offset from the voxel's centre, kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    /// Offset along it from the voxel's centre. [Units: voxels]
    pub offset: f32,
    kind: u32,
}

impl Plane {
    /// Signed distance of `x` (relative to the voxel's centre).
    fn at(&self, x: Vec3) -> f32 {
        self.normal.dot(x) - self.offset
    }
}

impl ClosedPlanes {
    /// Fits the planes of every closed voxel of a grid of `dims` whose open bits are `words`
    /// (32 voxels a word) to its listed triangles; in parallel over blocks.
    pub fn new(dims: IVec3, words: &[u32], lists: &ClosedTriangles) -> ClosedPlanes {
        let voxels = (dims.x as usize) * (dims.y as usize) * (dims.z as usize);
        let closed_in = |w: usize| {
            let valid = voxels.saturating_sub(w * 32).min(32);
            let mask = if valid == 32 {
                u32::MAX
            } else {
                (1u32 << valid) - 1
            };
            (!words[w] & mask).count_ones()
        };
        let blocks = voxels.div_ceil(PLANES_BLOCK);
        let words_per_block = PLANES_BLOCK / 32;
        let mut before = Vec::with_capacity(blocks);
        let mut n = 0u32;
        for b in 0..blocks {
            before.push(n);
            let w = b * words_per_block;
            n += (w..(w + words_per_block).min(words.len()))
                .map(closed_in)
                .sum::<u32>();
        }
        // Lists whose triangles lie in one plane (a wall's, a floor's: most), whose voxels then
        // take that plane without a fit.
        let flat: rustc_hash::FxHashMap<u32, (Vec3, f32)> = lists
            .list_ids()
            .into_par_iter()
            .filter_map(|id| one_plane(&lists.corners_in(id)).map(|p| (id, p)))
            .collect();
        let fitted: Vec<[u32; 2]> = (0..blocks)
            .into_par_iter()
            .flat_map_iter(|b| {
                let end = ((b + 1) * PLANES_BLOCK).min(voxels);
                (b * PLANES_BLOCK..end)
                    .filter(|&i| (words[i / 32] >> (i % 32)) & 1 == 0)
                    .map(|i| {
                        let v = voxel_of(i, dims);
                        let Some(id) = lists.list_id(i) else {
                            return [NONE; 2];
                        };
                        match flat.get(&id) {
                            Some(&(n, d)) => [encode(n, d - n.dot(v.as_vec3() + 0.5), WHOLE), NONE],
                            None => fit(v, &lists.corners_in(id)),
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        debug_assert_eq!(fitted.len(), n as usize);
        let closed = fitted.len();
        let mut words: Vec<u32> = Vec::with_capacity(closed);
        let mut pairs = Vec::new();
        for [p, q] in fitted {
            if q == NONE {
                words.push(p);
            } else {
                words.push(PAIR | ((closed + pairs.len()) as u32) << 2);
                pairs.extend([p, q]);
            }
        }
        words.extend(pairs);
        ClosedPlanes {
            before,
            words,
            closed,
        }
    }

    /// Closed voxels.
    pub fn voxels(&self) -> usize {
        self.closed
    }

    /// Closed voxels that hold one plane, and two (the rest block).
    pub fn counts(&self) -> [usize; 2] {
        let own = &self.words[..self.closed];
        let one = own.iter().filter(|&&w| w & 3 == WHOLE).count();
        [one, own.iter().filter(|&&w| w & 3 == PAIR).count()]
    }

    /// The planes of closed voxel `i` (its index in the grid) of open bits `words`; none: it
    /// blocks (or none are fitted).
    pub fn of(&self, i: usize, words: &[u32]) -> Option<[Option<Plane>; 2]> {
        let block = i / PLANES_BLOCK;
        let first = block * PLANES_BLOCK / 32;
        let rank = self.before.get(block)?
            + (first..i / 32)
                .map(|w| (!words[w]).count_ones())
                .sum::<u32>()
            + (!words[i / 32] & ((1u32 << (i % 32)) - 1)).count_ones();
        let w = self.words[rank as usize];
        match w & 3 {
            WHOLE => Some([decode(w), None]),
            PAIR => {
                let at = (w >> 2) as usize;
                Some([decode(self.words[at]), decode(self.words[at + 1])])
            }
            _ => None,
        }
    }

    /// Packs the tables after `at` words: returns the words and the word offsets of the counts
    /// and of the planes; both 0 with none.
    pub fn words(&self, at: usize) -> (Vec<u32>, [u32; 2]) {
        if self.before.is_empty() {
            return (Vec::new(), [0; 2]);
        }
        let mut w = Vec::with_capacity(self.before.len() + self.words.len());
        w.extend(&self.before);
        w.extend(&self.words);
        (w, [at as u32, (at + self.before.len()) as u32])
    }
}

/// Whether segment `a` + t·`d`, t in [0, 1] (voxel coordinates), passes closed voxel `v` whose
/// planes are `planes`: inside the voxel it comes within [`PLANE_FIT`] of neither plane's
/// patch (`sight.wgsl`'s `sight_planes_pass`).
pub fn passes(planes: [Option<Plane>; 2], v: IVec3, a: Vec3, d: Vec3) -> bool {
    let c = v.as_vec3() + 0.5;
    // The segment inside the voxel, relative to its centre.
    let moves = d.cmpne(Vec3::ZERO);
    let inv = Vec3::select(moves, d.recip(), Vec3::ZERO);
    let (t0, t1) = ((c - 0.5 - a) * inv, (c + 0.5 - a) * inv);
    let lo = Vec3::select(moves, t0.min(t1), Vec3::NEG_INFINITY)
        .max_element()
        .max(0.0);
    let hi = Vec3::select(moves, t0.max(t1), Vec3::INFINITY)
        .min_element()
        .min(1.0);
    let (p0, p1) = (a + d * lo - c, a + d * hi.max(lo) - c);
    let tol = PLANE_FIT + 1e-3;
    (0..2).all(|k| {
        let Some(p) = planes[k] else { return true };
        let (s0, s1) = (p.at(p0), p.at(p1));
        if (s0 > tol && s1 > tol) || (s0 < -tol && s1 < -tol) {
            return true;
        }
        let (Some(o), ABOVE | BELOW) = (planes[1 - k], p.kind) else {
            return false;
        };
        // The part of the segment within the fit of the plane, and whether it reaches the
        // patch's side of the other plane there.
        let (ta, tb) = if (s0 - s1).abs() < 1e-6 {
            (0.0, 1.0)
        } else {
            let (x, y) = ((s0 - tol) / (s0 - s1), (s0 + tol) / (s0 - s1));
            (x.min(y).clamp(0.0, 1.0), x.max(y).clamp(0.0, 1.0))
        };
        let side = if p.kind == ABOVE { 1.0 } else { -1.0 };
        let (x, y) = (p0 + (p1 - p0) * ta, p0 + (p1 - p0) * tb);
        (side * o.at(x)).max(side * o.at(y)) < -tol
    })
}

/// Whether point `x` (voxel coordinates) in closed voxel `v` lies farther than the fit from
/// both its planes (an end may start there).
pub fn clear_of(planes: [Option<Plane>; 2], v: IVec3, x: Vec3) -> bool {
    let c = v.as_vec3() + 0.5;
    planes
        .iter()
        .flatten()
        .all(|p| p.at(x - c).abs() > PLANE_FIT + 1e-3)
}

/// The plane (unit normal, offset from the grid's origin; voxel coordinates) of triangles `tris`
/// where every corner lies within a thousandth of a voxel of the first whole triangle's plane:
/// then every voxel they touch holds that plane alone, within the fit whatever the word's
/// rounding (half a degree of normal over the voxel's half diagonal: under 0.01 voxels).
fn one_plane(tris: &[[Vec3; 3]]) -> Option<(Vec3, f32)> {
    let t = tris
        .iter()
        .find(|t| (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0)?;
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    let d = n.dot(t[0]);
    let on = |p: &Vec3| (n.dot(*p) - d).abs() < 1e-3;
    tris.iter().all(|t| t.iter().all(on)).then_some((n, d))
}

/// The plane words of closed voxel `v` for the triangles `tris` (voxel coordinates) that touch
/// it: `[NONE, NONE]` where they do not lie within [`PLANE_FIT`] of two planes.
fn fit(v: IVec3, tris: &[[Vec3; 3]]) -> [u32; 2] {
    let c = v.as_vec3() + 0.5;
    // Per plane: the representative (normal, offset from the centre) and its patch's corners.
    let mut found: Vec<(Vec3, f32, Vec<Vec3>)> = Vec::new();
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.length_squared() == 0.0 {
            continue;
        }
        let Some(patch) = clip_to_box(&t.map(|p| p - c)) else {
            return [NONE; 2];
        };
        let patch = patch.corners();
        if patch.is_empty() {
            continue;
        }
        let near = |(m, off, _): &&mut (Vec3, f32, Vec<Vec3>)| {
            patch
                .iter()
                .all(|&x| (m.dot(x) - *off).abs() < 0.8 * PLANE_FIT)
        };
        match found.iter_mut().find(near) {
            Some(f) => f.2.extend(patch),
            None => {
                let n = n.normalize();
                let off = n.dot(t[0] - c);
                found.push((n, off, patch.to_vec()));
                if found.len() > 2 {
                    return [NONE; 2];
                }
            }
        }
    }
    if found.is_empty() {
        return [NONE; 2];
    }
    let words: Vec<u32> = found.iter().map(|f| encode(f.0, f.1, WHOLE)).collect();
    let planes: Vec<Plane> = words.iter().map(|&w| decode(w).expect("a plane")).collect();
    // Every patch within the fit of its decoded plane, else the voxel blocks.
    for (p, f) in planes.iter().zip(&found) {
        if f.2.iter().any(|&x| p.at(x).abs() >= PLANE_FIT) {
            return [NONE; 2];
        }
    }
    if found.len() == 1 {
        return [words[0], NONE];
    }
    let mut out = [NONE; 2];
    for k in 0..2 {
        let o = planes[1 - k];
        let s: Vec<f32> = found[k].2.iter().map(|&x| o.at(x)).collect();
        let kind = if s.iter().all(|&x| x >= -PLANE_FIT) {
            ABOVE
        } else if s.iter().all(|&x| x <= PLANE_FIT) {
            BELOW
        } else {
            WHOLE
        };
        out[k] = (words[k] & !3) | kind;
    }
    out
}

/// A plane word: kind (2 bits), the normal octahedral (8 + 8 bits), the offset from the voxel's
/// centre in ±[`OFFSET_RANGE`] (14 bits).
fn encode(n: Vec3, offset: f32, kind: u32) -> u32 {
    let o = octahedral(n);
    let q = |x: f32, bits: u32| {
        let m = ((1u32 << bits) - 1) as f32;
        ((x * 0.5 + 0.5).clamp(0.0, 1.0) * m).round() as u32
    };
    let off = q(offset.clamp(-OFFSET_RANGE, OFFSET_RANGE) / OFFSET_RANGE, 14);
    kind | q(o.x, 8) << 2 | q(o.y, 8) << 10 | off << 18
}

/// The plane of word `w` (`sight.wgsl`'s `sight_plane`); none for kind `NONE`.
fn decode(w: u32) -> Option<Plane> {
    let kind = w & 3;
    if kind == NONE {
        return None;
    }
    let f = |x: u32, bits: u32| x as f32 / ((1u32 << bits) - 1) as f32 * 2.0 - 1.0;
    let o = Vec2::new(f((w >> 2) & 0xff, 8), f((w >> 10) & 0xff, 8));
    Some(Plane {
        normal: from_octahedral(o),
        offset: f(w >> 18, 14) * OFFSET_RANGE,
        kind,
    })
}

/// Unit vector `n` on the octahedron, in [-1, 1]².
fn octahedral(n: Vec3) -> Vec2 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 {
        p
    } else {
        (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * Vec2::new(p.x.signum(), p.y.signum())
    }
}

/// The unit vector of octahedral `o`.
fn from_octahedral(o: Vec2) -> Vec3 {
    let z = 1.0 - o.x.abs() - o.y.abs();
    let t = (-z).max(0.0);
    let x = o.x - t * o.x.signum();
    let y = o.y - t * o.y.signum();
    Vec3::new(x, y, z).normalize()
}

/// Triangle `t` (relative to a voxel's centre) clipped to the voxel grown by a hair
/// (Sutherland–Hodgman) in fixed arrays, not a list made per plane (six a triangle): each of the
/// six planes adds at most one corner to a convex polygon's, so the three take at most nine;
/// none where rounding would take it past [`PATCH_MAX`] (the voxel then blocks).
fn clip_to_box(t: &[Vec3; 3]) -> Option<Patch> {
    let mut poly = Patch::empty();
    poly.corners[..3].copy_from_slice(t);
    poly.len = 3;
    let h = 0.5 + 1e-4;
    for axis in 0..3 {
        for side in [1.0f32, -1.0] {
            let inside = |p: Vec3| side * p[axis] <= h;
            let mut out = Patch::empty();
            let corners = poly.corners();
            for (k, &a) in corners.iter().enumerate() {
                let b = corners[(k + 1) % corners.len()];
                if inside(a) {
                    out.push(a)?;
                }
                if inside(a) != inside(b) {
                    let s = (side * h - a[axis]) / (b[axis] - a[axis]);
                    out.push(a + (b - a) * s)?;
                }
            }
            poly = out;
            if poly.len == 0 {
                return Some(poly);
            }
        }
    }
    Some(poly)
}

/// Corners a triangle clipped to a box has at most: its three, one more per plane of the box
/// (and room for rounding).
const PATCH_MAX: usize = 12;

/// A convex polygon of at most [`PATCH_MAX`] corners.
struct Patch {
    corners: [Vec3; PATCH_MAX],
    len: usize,
}

impl Patch {
    fn empty() -> Patch {
        Patch {
            corners: [Vec3::ZERO; PATCH_MAX],
            len: 0,
        }
    }

    fn corners(&self) -> &[Vec3] {
        &self.corners[..self.len]
    }

    /// Adds corner `p`; none where the polygon is full.
    fn push(&mut self, p: Vec3) -> Option<()> {
        *self.corners.get_mut(self.len)? = p;
        self.len += 1;
        Some(())
    }
}

#[cfg(test)]
mod tests;

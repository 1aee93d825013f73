//! Stray geometry: a few static triangles far from the rest of the level — a helper object
//! left in the export, a sky box, a vertex typed in the wrong place — make the bake's grid span
//! them, so its voxels are sized for the level and its strays together and the rooms fall to a
//! few voxels (the ajar door with one triangle 500 m away baked to 1 cluster on 3.9 m voxels
//! where it has 6 on 6 cm). [`stray_geometry`] finds them so that the bake can say where.

use glam::Vec3;

use crate::scene::{Scene, points_bounds};

/// At most this share of the static triangles (and at least one) may be left out of the bulk
/// of the level along each axis. [Units: ratio]
pub const STRAY_SHARE: f64 = 0.01;

/// Triangles count as stray where, without them, the level's longest side would be more than
/// this many times shorter. [Units: ratio]
pub const STRAY_SPAN_RATIO: f32 = 4.0;

/// The static triangles far from the rest of a level ([`stray_geometry`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Stray {
    /// How many static triangles lie far from the rest.
    pub triangles: usize,
    /// How many static triangles the level has.
    pub total: usize,
    /// The stray vertex farthest from the rest's bounds. [Units: m]
    pub farthest: Vec3,
    /// Its distance from the rest's bounds. [Units: m]
    pub distance_m: f32,
    /// The bounds of every static vertex (what the bake's grid spans). [Units: m]
    pub bounds: (Vec3, Vec3),
    /// The bounds of the rest. [Units: m]
    pub rest: (Vec3, Vec3),
}

impl Stray {
    /// The longest side of every static vertex's bounds. [Units: m]
    pub fn longest_m(&self) -> f32 {
        (self.bounds.1 - self.bounds.0).max_element()
    }

    /// The longest side of the rest's bounds. [Units: m]
    pub fn rest_longest_m(&self) -> f32 {
        (self.rest.1 - self.rest.0).max_element()
    }
}

/// The static triangles of `scene` that lie far from the rest, where leaving them out would
/// shorten the level's longest side more than [`STRAY_SPAN_RATIO`] times; `None` where there
/// are none (or under 8 triangles). The rest is the box of the triangles' centres with the
/// [`STRAY_SHARE`] (at least one) lowest and highest left out along each axis; a triangle is
/// far where a corner lies farther from that box than the box's longest side.
pub fn stray_geometry(scene: &Scene) -> Option<Stray> {
    stray_triangles(&scene.static_triangles().collect::<Vec<_>>())
}

/// [`stray_geometry`] of a level's static triangles `tris`.
pub fn stray_triangles(tris: &[[Vec3; 3]]) -> Option<Stray> {
    let n = tris.len();
    if n < 8 {
        return None;
    }
    let k = ((STRAY_SHARE * n as f64) as usize).max(1);
    let (mut lo, mut hi) = (Vec3::ZERO, Vec3::ZERO);
    for axis in 0..3 {
        let mut c: Vec<f32> = tris
            .iter()
            .map(|t| (t[0] + t[1] + t[2])[axis] / 3.0)
            .collect();
        // The k-th lowest, then the k-th highest among those above it.
        let (_, &mut low, above) = c.select_nth_unstable_by(k, f32::total_cmp);
        let (_, &mut high, _) = above.select_nth_unstable_by(n - 2 - 2 * k, f32::total_cmp);
        (lo[axis], hi[axis]) = (low, high);
    }
    let reach = (hi - lo).max_element();
    let (strays, rest): (Vec<&[Vec3; 3]>, Vec<&[Vec3; 3]>) = tris
        .iter()
        .partition(|t| t.iter().any(|&p| off_box(p, (lo, hi)) > reach));
    let corners = |tris: &[&[Vec3; 3]]| points_bounds(tris.iter().flat_map(|t| t.iter().copied()));
    let (Some(rest), Some(bounds)) = (
        corners(&rest),
        points_bounds(tris.iter().flatten().copied()),
    ) else {
        return None;
    };
    let longest = |b: (Vec3, Vec3)| (b.1 - b.0).max_element();
    if strays.is_empty() || strays.len() > k || longest(bounds) <= STRAY_SPAN_RATIO * longest(rest)
    {
        return None;
    }
    let farthest = strays
        .iter()
        .flat_map(|t| t.iter().copied())
        .max_by(|a, b| off_box(*a, rest).total_cmp(&off_box(*b, rest)))?;
    Some(Stray {
        triangles: strays.len(),
        total: n,
        farthest,
        distance_m: off_box(farthest, rest),
        bounds,
        rest,
    })
}

/// How far point `p` lies outside box `b` (0 inside).
fn off_box(p: Vec3, b: (Vec3, Vec3)) -> f32 {
    (b.0 - p).max(p - b.1).max(Vec3::ZERO).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 3 × 4 m room's floor as a grid of triangles, 2 per square metre.
    fn room() -> Vec<[Vec3; 3]> {
        let mut tris = Vec::new();
        for x in 0..4 {
            for z in 0..4 {
                let p = |dx: i32, dz: i32| Vec3::new((x + dx) as f32, 0.0, (z + dz) as f32);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
        tris.push([
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ]);
        tris
    }

    #[test]
    fn a_triangle_far_from_the_room_is_found_and_the_room_alone_is_not() {
        assert_eq!(stray_triangles(&room()), None);
        let mut tris = room();
        let far = Vec3::new(500.0, 0.0, 0.0);
        tris.push([far, far + Vec3::X, far + Vec3::Y]);
        let s = stray_triangles(&tris).expect("the far triangle");
        assert_eq!((s.triangles, s.total), (1, 34));
        assert_eq!(s.farthest, far + Vec3::X);
        assert!((s.distance_m - 497.0).abs() < 1e-3, "{s:?}");
        assert_eq!(s.rest, (Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)));
        assert!((s.longest_m() - 501.0).abs() < 1e-3 && s.rest_longest_m() == 4.0);
    }

    #[test]
    fn a_level_that_is_long_everywhere_has_no_strays() {
        // A corridor 100 m long: its far end is as much the level as its near one.
        let mut tris = Vec::new();
        for x in 0..100 {
            let p = |dx: i32, z: f32| Vec3::new((x + dx) as f32, 0.0, z);
            tris.push([p(0, 0.0), p(1, 0.0), p(1, 2.0)]);
        }
        assert_eq!(stray_triangles(&tris), None);
        // A near triangle, only 3 room-lengths away, is not stray either.
        let mut tris = room();
        let near = Vec3::new(14.0, 0.0, 0.0);
        tris.push([near, near + Vec3::X, near + Vec3::Y]);
        assert_eq!(stray_triangles(&tris), None);
    }
}

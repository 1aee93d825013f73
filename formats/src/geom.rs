//! Geometric predicates that the bake and the runtime (and the scenes) decide with, so that
//! they agree: whether a level is flat (the bake refuses it, a bare one is seen from off it);
//! which voxels a triangle touches (the bake closes them; the runtime lists the triangles in
//! them for the voxel walk).

use glam::DVec3;

/// How thin bounds may be along one axis, as a share of their longest side, before they are
/// flat: a float's rounding of a plane (one ground, one wall), not a thin level (a 1 km ground
/// with a metre of relief is 1e-3). [Units: ratio]
pub const FLAT_SHARE: f64 = 1e-6;

/// The axis (0 x, 1 y, 2 z) along which bounds of size `extent` are flat ([`FLAT_SHARE`]),
/// where one is; none for a point (no longest side).
pub fn flat_axis(extent: DVec3) -> Option<usize> {
    let longest = extent.max_element();
    (longest > 0.0 && extent.min_element() <= longest * FLAT_SHARE).then(|| extent.min_position())
}

/// Whether triangle `v` touches the closed axis-aligned box of centre `c` and half-size `h`
/// (separating axis theorem, Akenine-Möller 2001: 3 box normals, the triangle normal, and the
/// 9 cross products of box axes and triangle edges).
pub fn tri_box_overlap(c: DVec3, h: f64, v: [DVec3; 3]) -> bool {
    let v = v.map(|p| p - c);
    // Box normals: the triangle's bounds against the box.
    let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
    if lo.max_element() > h || hi.min_element() < -h {
        return false;
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    // The triangle's plane before the edge axes: it rejects most of a large triangle's box
    // (the test is the conjunction of all 13, so their order does not change the answer).
    let n = e[0].cross(e[1]);
    let r = h * (n.x.abs() + n.y.abs() + n.z.abs());
    if n.dot(v[0]).abs() > r {
        return false;
    }
    for edge in e {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            let a = axis.cross(edge);
            let p = v.map(|q| a.dot(q));
            let r = h * (a.x.abs() + a.y.abs() + a.z.abs());
            if p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r {
                return false;
            }
        }
    }
    true
}

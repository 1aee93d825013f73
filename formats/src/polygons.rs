//! An OBJ's polygons as triangles. tobj fans every polygon from its first corner, which is
//! right only where the polygon is convex; Blender's OBJ export keeps n-gons, and an L-shaped
//! floor, a U-shaped ceiling round a courtyard or a wall round a doorway's notch written as one
//! concave n-gon, fanned, covers its notch — the fan's triangles reach across it (and fold
//! back over the polygon), so a doorway or a courtyard is closed. Convex polygons are fanned
//! as tobj did (the same triangles, in the same order); concave ones are ear-clipped in their
//! plane (the `earcut` crate), each triangle wound as the polygon is.

use glam::{DVec3, Vec3};

/// How far a corner may turn against the polygon's winding and still count as straight: the
/// sine of the angle (0.06°). The rounding of a straight run's corners turns them by less:
/// LibreQuake e2m3's OBJ, convex brush faces written to five decimals, has 167 polygons whose
/// corners turn back by up to 1.7e-4, fanned as before; a fan over so slight a turn covers a
/// sliver. [Units: ratio]
const REFLEX_SINE: f64 = 1e-3;

/// The triangles (three corners each, indices into `positions`) of the polygons whose corners
/// `indices` lists, `arities` corners each in order (none: every polygon a triangle, as tobj
/// gives them), and how many polygons were concave.
pub fn triangulate(positions: &[Vec3], indices: &[u32], arities: &[u32]) -> (Vec<u32>, usize) {
    if arities.is_empty() {
        return (indices.to_vec(), 0);
    }
    let mut out = Vec::with_capacity(indices.len() * 2);
    let mut earcut = earcut::Earcut::new();
    let (mut start, mut concave) = (0, 0);
    for &n in arities {
        let end = (start + n as usize).min(indices.len());
        let corners = &indices[start..end];
        start = end;
        let at = |i: u32| {
            positions
                .get(i as usize)
                .map_or(DVec3::ZERO, |p| p.as_dvec3())
        };
        let points: Vec<DVec3> = corners.iter().map(|&i| at(i)).collect();
        if corners.len() > 3
            && !is_convex(&points)
            && let Some(tris) = ear_clip(&mut earcut, &points)
        {
            concave += 1;
            out.extend(tris.iter().map(|&k| corners[k as usize]));
            continue;
        }
        fan(corners, &mut out);
    }
    (out, concave)
}

/// Fans the polygon `corners` from its first, as tobj does.
fn fan(corners: &[u32], out: &mut Vec<u32>) {
    for k in 2..corners.len() {
        out.extend([corners[0], corners[k - 1], corners[k]]);
    }
}

/// The polygon's normal by Newell's method: its vector area, twice over.
fn newell(points: &[DVec3]) -> DVec3 {
    let n = points.len();
    (0..n).fold(DVec3::ZERO, |acc, i| {
        acc + points[i].cross(points[(i + 1) % n])
    })
}

/// Whether no corner of the polygon turns against its winding (about its Newell normal) by
/// more than [`REFLEX_SINE`]; a degenerate polygon (no area) counts as convex: it is fanned.
fn is_convex(points: &[DVec3]) -> bool {
    let normal = newell(points).normalize_or_zero();
    if normal == DVec3::ZERO {
        return true;
    }
    let n = points.len();
    (0..n).all(|i| {
        let (a, b, c) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
        let (e0, e1) = (b - a, c - b);
        e0.cross(e1).dot(normal) >= -REFLEX_SINE * e0.length() * e1.length()
    })
}

/// The concave polygon's triangles by ear clipping in its plane, as indices into `points`,
/// each wound as the polygon (its normal along the polygon's); `None` where the clipping gives
/// none (a polygon with no area).
fn ear_clip(earcut: &mut earcut::Earcut<f64>, points: &[DVec3]) -> Option<Vec<u32>> {
    let normal = newell(points);
    let corners: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    let mut flat = Vec::new();
    if !earcut::utils3d::project3d_to_2d(&corners, corners.len(), &mut flat) {
        return None;
    }
    let mut tris: Vec<u32> = Vec::new();
    earcut.earcut(flat, &[] as &[u32], &mut tris);
    if tris.is_empty() {
        return None;
    }
    for t in tris.chunks_exact_mut(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|k| points[k as usize]);
        if (b - a).cross(c - a).dot(normal) < 0.0 {
            t.swap(1, 2);
        }
    }
    Some(tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sum of the triangles' areas.
    fn area(positions: &[Vec3], tris: &[u32]) -> f32 {
        (tris.chunks_exact(3))
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn an_l_shaped_floor_covers_its_own_area_wound_as_written_and_a_square_is_fanned_as_tobj_did() {
        // An L, 3 × 3 m less the 2 × 2 m notch at +x +z, written from a corner beside the
        // notch: a fan from it crosses the notch.
        let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
        let l = [
            p(1., 3.),
            p(1., 1.),
            p(3., 1.),
            p(3., 0.),
            p(0., 0.),
            p(0., 3.),
        ];
        let corners: Vec<u32> = (0..6).collect();
        let (tris, concave) = triangulate(&l, &corners, &[6]);
        assert_eq!((tris.len(), concave), (12, 1));
        assert!((area(&l, &tris) - 5.0).abs() < 1e-5, "{}", area(&l, &tris));
        let normal = newell(&l.map(|v| v.as_dvec3())).as_vec3();
        for t in tris.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| l[t[k] as usize]);
            assert!(
                (b - a).cross(c - a).dot(normal) > 0.0,
                "wound as written: {t:?}"
            );
        }
        // tobj's fan: more area, over the notch.
        let mut fanned = Vec::new();
        fan(&corners, &mut fanned);
        assert!(area(&l, &fanned) > 5.5, "{}", area(&l, &fanned));
        // A square (and a triangle after it) as tobj gave them: the fan from the first corner.
        let sq = [
            p(0., 0.),
            p(1., 0.),
            p(1., 1.),
            p(0., 1.),
            p(2., 0.),
            p(3., 0.),
            p(2., 1.),
        ];
        let (tris, concave) = triangulate(&sq, &[0, 1, 2, 3, 4, 5, 6], &[4, 3]);
        assert_eq!((tris, concave), (vec![0, 1, 2, 0, 2, 3, 4, 5, 6], 0));
        // Triangles alone come through as they are.
        assert_eq!(triangulate(&sq, &[4, 5, 6], &[]), (vec![4, 5, 6], 0));
    }

    #[test]
    fn a_polygon_with_a_straight_run_or_no_area_is_fanned() {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        // A rectangle with a corner in the middle of one side: convex, fanned.
        let run = [p(0., 0.), p(1., 0.), p(2., 0.), p(2., 1.), p(0., 1.)];
        assert_eq!(triangulate(&run, &[0, 1, 2, 3, 4], &[5]).1, 0);
        // All on one line: no area, fanned (and dropped later as degenerate).
        let line = [p(0., 0.), p(1., 0.), p(2., 0.), p(3., 0.)];
        let (tris, concave) = triangulate(&line, &[0, 1, 2, 3], &[4]);
        assert_eq!((tris.len(), concave), (6, 0));
    }
}

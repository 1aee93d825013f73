//! How high a bare mesh's rooms are, in its own units: the statistic that tells a level
//! modelled in millimetres from one in centimetres (or a small level in centimetres from one
//! in metres), which its extent alone cannot (a 9 m apartment in millimetres and a 90 m level
//! in centimetres are both 9,000 units long; `load::bare_mesh_units_with_rooms`).
//!
//! The footprint is cut into columns (at most [`COLUMNS`] along its longer side); every
//! triangle that faces up or down (floors, ceilings, table tops, stair treads: its normal within
//! 45° of the up axis, whichever way it is wound, as single-sided walls and floors come wound
//! either way) gives each column whose centre it covers the surface's height there. A column's
//! tallest free span between two heights is the room it stands in, floor to ceiling (a slab
//! or a table top splits the column into shorter spans); the level's room height is the
//! median of its columns' spans. Columns with one height (under the open sky) hold no room.

use glam::DVec3;

use crate::desc::UpAxis;
use crate::import::ImportedModel;

/// Columns along the footprint's longer side. [Units: count]
pub const COLUMNS: usize = 128;

/// The least cosine between a triangle's normal and the up axis for it to count as a floor or
/// a ceiling (45°). [Units: ratio]
const FACING_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Two heights of a column closer than this share of the level's height are one surface
/// (a floor modelled twice, a slab's two faces a hair apart). [Units: ratio]
const SAME_SURFACE: f64 = 1e-3;

/// The least share of the columns that hold a surface which must hold a room as well before
/// the median is trusted (a terrain under the open sky holds none). [Units: ratio]
const LEAST_ROOM_SHARE: f64 = 0.1;

/// A level's rooms, measured in its file's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoomHeight {
    /// The median over the columns of a column's tallest free span. [Units: the file's]
    pub median: f64,
    /// Columns that hold a room (two surfaces or more). [Units: count]
    pub columns: usize,
}

/// The rooms' height of `models` read with `up` as the up axis (`None`: fewer than
/// [`LEAST_ROOM_SHARE`] of the covered columns hold a room, or no floor or ceiling at all).
pub fn room_height(models: &[ImportedModel], up: UpAxis) -> Option<RoomHeight> {
    room_height_of(
        || {
            models.iter().flat_map(|m| &m.meshes).flat_map(|mesh| {
                mesh.triangles
                    .iter()
                    .map(move |t| t.map(|i| mesh.positions[i as usize].as_dvec3()))
            })
        },
        up,
    )
}

/// [`room_height`] of the triangles that `triangles` yields (each call from the first), read
/// with `up` as the up axis: a loaded scene's in metres, +Y up (`visgate inspect`).
pub fn room_height_of<I>(triangles: impl Fn() -> I, up: UpAxis) -> Option<RoomHeight>
where
    I: Iterator<Item = [DVec3; 3]>,
{
    let (u, v, w) = match up {
        UpAxis::Y => (0, 2, 1),
        UpAxis::Z => (0, 1, 2),
    };
    let (lo, hi) = triangles()
        .flatten()
        .filter(|p| p.is_finite())
        .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let extent = hi - lo;
    let cell = extent[u].max(extent[v]) / COLUMNS as f64;
    if !(cell > 0.0 && extent[w] > 0.0) {
        return None;
    }
    let (nu, nv) = (
        ((extent[u] / cell).ceil() as usize).clamp(1, COLUMNS),
        ((extent[v] / cell).ceil() as usize).clamp(1, COLUMNS),
    );
    let mut columns = vec![Vec::new(); nu * nv];
    for t in triangles().filter(|t| t.iter().all(|p| p.is_finite())) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n[w].abs() < FACING_COS * n.length() || n[w] == 0.0 {
            continue;
        }
        let flat = t.map(|p| ((p[u] - lo[u]) / cell, (p[v] - lo[v]) / cell));
        cover(flat, nu, nv, |i, j, (a, b, c)| {
            let height = a * t[0][w] + b * t[1][w] + c * t[2][w];
            columns[i + nu * j].push(height);
        });
    }
    let same = SAME_SURFACE * extent[w];
    let covered = columns.iter().filter(|c| !c.is_empty()).count();
    let mut spans: Vec<f64> = columns
        .iter_mut()
        .filter_map(|c| tallest_span(c, same))
        .collect();
    if spans.is_empty() || (spans.len() as f64) < LEAST_ROOM_SHARE * covered as f64 {
        return None;
    }
    spans.sort_by(f64::total_cmp);
    Some(RoomHeight {
        median: spans[spans.len() / 2],
        columns: spans.len(),
    })
}

/// Calls `each(i, j, barycentrics)` for every column (i < nu, j < nv) whose centre lies in the
/// triangle `t` (in column units, from the footprint's corner).
fn cover(
    t: [(f64, f64); 3],
    nu: usize,
    nv: usize,
    mut each: impl FnMut(usize, usize, (f64, f64, f64)),
) {
    let [(x0, y0), (x1, y1), (x2, y2)] = t;
    let area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if area == 0.0 {
        return;
    }
    let first = |a: f64| (a - 0.5).ceil().max(0.0) as usize;
    let last = |a: f64, n: usize| ((a - 0.5).floor().max(-1.0) as isize).min(n as isize - 1);
    let (i0, i1) = (first(x0.min(x1).min(x2)), last(x0.max(x1).max(x2), nu));
    let (j0, j1) = (first(y0.min(y1).min(y2)), last(y0.max(y1).max(y2), nv));
    for j in j0 as isize..=j1 {
        for i in i0 as isize..=i1 {
            let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
            let b = ((x2 - x) * (y0 - y) - (x0 - x) * (y2 - y)) / area;
            let c = ((x0 - x) * (y1 - y) - (x1 - x) * (y0 - y)) / area;
            let a = 1.0 - b - c;
            if a >= 0.0 && b >= 0.0 && c >= 0.0 {
                each(i as usize, j as usize, (a, b, c));
            }
        }
    }
}

/// A column's tallest span between two of its heights `same` or more apart (`None`: fewer
/// than two distinct heights).
fn tallest_span(heights: &mut [f64], same: f64) -> Option<f64> {
    heights.sort_by(f64::total_cmp);
    let tallest = heights
        .windows(2)
        .map(|p| p[1] - p[0])
        .filter(|&d| d >= same)
        .fold(0.0, f64::max);
    (tallest > 0.0).then_some(tallest)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::import::RawMesh;

    /// A model of quads, each given by its four corners.
    fn model(quads: &[[[f32; 3]; 4]]) -> ImportedModel {
        let mut mesh = RawMesh {
            name: "m".into(),
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles: Vec::new(),
            material: 0,
        };
        for q in quads {
            let at = mesh.positions.len() as u32;
            mesh.positions.extend(q.iter().map(|&p| Vec3::from(p)));
            mesh.triangles.push([at, at + 1, at + 2]);
            mesh.triangles.push([at, at + 2, at + 3]);
        }
        mesh.normals = vec![Vec3::Y; mesh.positions.len()];
        mesh.uvs = vec![Default::default(); mesh.positions.len()];
        ImportedModel {
            meshes: vec![mesh],
            ..Default::default()
        }
    }

    /// A horizontal quad at height h (y up) over x, z in [0, a] × [0, b].
    fn flat(h: f32, a: f32, b: f32) -> [[f32; 3]; 4] {
        [[0.0, h, 0.0], [a, h, 0.0], [a, h, b], [0.0, h, b]]
    }

    #[test]
    fn a_room_is_as_high_as_its_floor_to_its_ceiling_whichever_way_they_are_wound() {
        // 9,000 × 6,000 units, 2,700 high (an apartment in millimetres); the ceiling wound up.
        let mut ceiling = flat(2700.0, 9000.0, 6000.0);
        ceiling.reverse();
        let m = model(&[flat(0.0, 9000.0, 6000.0), ceiling]);
        let h = room_height(std::slice::from_ref(&m), UpAxis::Y).expect("a room");
        assert!((h.median - 2700.0).abs() < 1e-6, "{h:?}");
        assert!(h.columns > 100 * 80, "{h:?}");
        // Read Z up, the floor and the ceiling are walls: no room.
        assert_eq!(room_height(&[m], UpAxis::Z), None);
    }

    #[test]
    fn a_table_or_a_slab_splits_a_column_but_the_room_above_stays_the_tallest_span() {
        // Two storeys of 3 m on 0.2 m slabs, a table top 0.75 m high over a quarter of the floor.
        let m = model(&[
            flat(0.0, 20.0, 10.0),
            flat(3.0, 20.0, 10.0),
            flat(3.2, 20.0, 10.0),
            flat(6.2, 20.0, 10.0),
            flat(0.75, 10.0, 5.0),
        ]);
        let h = room_height(&[m], UpAxis::Y).expect("rooms");
        assert!((h.median - 3.0).abs() < 1e-9, "{h:?}");
    }

    #[test]
    fn a_floor_under_the_open_sky_holds_no_room() {
        let ground = model(&[flat(0.0, 50.0, 50.0)]);
        assert_eq!(room_height(&[ground], UpAxis::Y), None);
        // A canopy over less than a tenth of it: still none.
        let canopy = model(&[flat(0.0, 50.0, 50.0), flat(4.0, 10.0, 10.0)]);
        assert_eq!(room_height(&[canopy], UpAxis::Y), None);
        assert_eq!(room_height(&[], UpAxis::Y), None);
    }
}

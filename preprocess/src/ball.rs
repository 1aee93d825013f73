//! Where a bare mesh's light and camera go without a bake: the centre of the largest empty
//! ball in the level's inside, found as the bake finds it — the static triangles voxelized at
//! [`BALL_RESOLUTION`] voxels on the longest axis, the empty space the bake keeps (a bare
//! mesh's: the component most triangles face), its exact distance transform — but without
//! the skeleton. It depends on the scene alone, so that a reference rendered without a baked
//! level and a gate render with one look from the same place.

use glam::Vec3;
use visgate_formats::Scene;
use visgate_formats::vgate::{BakeParams, GridMeta, Resolution};

use crate::neighbourhood::{Components, Conn, grid_components};
use crate::stages;
use crate::voxelize::grid_for;

/// Voxels on the longest axis of the grid the ball is found on (the bake's default).
/// [Units: voxels]
pub const BALL_RESOLUTION: u32 = 128;

/// The most memory the search may take (a level 10⁴ times longer than wide would not fit).
/// [Units: bytes]
const BALL_MEMORY_BYTES: u64 = 1 << 30;

/// The centre and radius of the largest ball in `scene`'s kept empty space (metres), or
/// `None` where there is none (no geometry, no empty space, a grid too large); of the voxels
/// whose ball is as large, the one nearest the centroid of the largest piece they make.
pub fn largest_empty_ball(scene: &Scene) -> Option<(Vec3, f32)> {
    // The static triangles and their bounds (stages::load would hash them too, for nothing).
    let triangles: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    let bounds = scene.static_bounds()?;
    let resolution = Resolution::LongestAxisVoxels(BALL_RESOLUTION);
    let meta = grid_for(bounds, resolution, BALL_MEMORY_BYTES).ok()?;
    let ((solid, _), _) = stages::voxelize(meta, &triangles).ok()?;
    let params = BakeParams::default();
    let empty = stages::empty(scene, &meta, &solid.solid, &triangles, &params, false);
    let (es, _) = empty.ok()?;
    let (field, _) = stages::distance(&meta, &es, params.max_ball);
    // Of the kept space, the inside's: a bare mesh keeps other large spaces its faces look
    // into too (the outside between the pillared hall's side rooms, within its bounds), and
    // their balls may be larger.
    let comps = grid_components(meta.dims, |i| es.empty[i], Conn::C26);
    let inside = most_faced(&meta, &comps, &triangles)?;
    let ours = |i: usize| es.empty[i] && comps.label(i) == Some(inside);
    let max = (0..es.empty.len())
        .filter(|&i| ours(i))
        .map(|i| field.dist2[i])
        .max()?;
    // Every voxel of that largest radius: a plateau (a room's middle, where its height caps
    // the ball), or several rooms' alike. Of the largest piece of it (the first in grid order
    // of those as large), the voxel nearest its centroid, so that the ball sits in a room's
    // middle, not on its first voxel in grid order nor between two rooms.
    let top: Vec<usize> = (0..es.empty.len())
        .filter(|&i| field.dist2[i] == max && ours(i))
        .collect();
    let piece = largest_piece(&meta, &top);
    let at = |i: usize| Vec3::from(meta.voxel_to_world(meta.coords(i as u32)));
    let centroid = piece.iter().map(|&i| at(i)).sum::<Vec3>() / piece.len() as f32;
    let i = piece.iter().copied().min_by(|&a, &b| {
        let (da, db) = (
            at(a).distance_squared(centroid),
            at(b).distance_squared(centroid),
        );
        da.total_cmp(&db).then(a.cmp(&b))
    })?;
    let centre = at(i);
    Some((centre, field.radius_vx(i) as f32 * meta.voxel_size_m))
}

/// The component of `comps` that the most `triangles` face: the first that is not solid
/// 0.75, 1.5 or 2.25 voxels off a triangle's centroid along its normal (as the bake's empty
/// stage reads a bare mesh's inside).
fn most_faced(meta: &GridMeta, comps: &Components, triangles: &[[Vec3; 3]]) -> Option<u32> {
    let mut faced = vec![0u64; comps.count as usize];
    let vs = meta.voxel_size_m;
    for t in triangles {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        if n == Vec3::ZERO {
            continue;
        }
        let c = (t[0] + t[1] + t[2]) / 3.0;
        let label = [0.75, 1.5, 2.25].into_iter().find_map(|k| {
            let v = meta.world_to_voxel((c + n * (k * vs)).to_array())?;
            comps.label(meta.index(v))
        });
        if let Some(l) = label {
            faced[l as usize] += 1;
        }
    }
    (0..comps.count).max_by_key(|&l| (faced[l as usize], std::cmp::Reverse(l)))
}

/// The largest 6-connected piece of `voxels` (grid indices, sorted), the first in grid order
/// of those as large.
fn largest_piece(meta: &GridMeta, voxels: &[usize]) -> Vec<usize> {
    let mut seen = vec![false; voxels.len()];
    let slot = |i: usize| voxels.binary_search(&i).ok();
    let mut best: Vec<usize> = Vec::new();
    for start in 0..voxels.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let (mut piece, mut stack) = (Vec::new(), vec![start]);
        while let Some(k) = stack.pop() {
            piece.push(voxels[k]);
            let v = meta.coords(voxels[k] as u32).map(i64::from);
            for (axis, step) in [(0, -1), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1)] {
                let mut w = v;
                w[axis] += step;
                if (0..3).any(|a| w[a] < 0 || w[a] >= i64::from(meta.dims[a])) {
                    continue;
                }
                let n = meta.index(w.map(|c| c as u32));
                if let Some(j) = slot(n).filter(|&j| !seen[j]) {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        if piece.len() > best.len() {
            best = piece;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use visgate_scenes::Builtin;

    /// The ball of `b`: its centre in one of the scene's rooms (not in a wall or a doorway),
    /// its radius; and the same again.
    fn ball_in_a_room(b: Builtin) -> f32 {
        let scene = b.scene().expect("scene");
        let (c, r) = largest_empty_ball(&scene).expect("a ball");
        let rooms = b.empty_boxes_m();
        let inside = |o: &visgate_scenes::Opening| {
            (0..3).all(|a| c[a] > o.min_m[a] && c[a] < o.max_m[a]) && o.width_m() >= 4.0
        };
        assert!(
            rooms.iter().any(inside),
            "{b:?}: the ball at {c} is in no room"
        );
        assert_eq!(largest_empty_ball(&scene), Some((c, r)));
        r
    }

    #[test]
    fn the_largest_ball_sits_in_a_room_as_high_as_it() {
        // Rooms 3 m high: a ball of about 1.5 m, less a voxel's staircase.
        for b in [Builtin::TwoRooms, Builtin::FourRooms] {
            let r = ball_in_a_room(b);
            assert!((1.3..=1.6).contains(&r), "{b:?}: radius {r} m");
        }
        // Zero-thickness walls, a door panel and a table: in one of the two rooms.
        ball_in_a_room(Builtin::AjarDoor);
        // The pillared hall bare (no light, no camera, not closed), as its exported OBJ: the
        // bake keeps the outside between its side rooms too, whose ball is larger; the ball
        // stays in the hall or a side room.
        let mut bare = Builtin::PillaredHall.scene().expect("scene");
        (bare.lights, bare.cameras, bare.closed) = (Vec::new(), Vec::new(), false);
        let (c, _) = largest_empty_ball(&bare).expect("a ball");
        let inside =
            |o: &visgate_scenes::Opening| (0..3).all(|a| c[a] > o.min_m[a] && c[a] < o.max_m[a]);
        assert!(
            Builtin::PillaredHall.empty_boxes_m().iter().any(inside),
            "bare pillared hall: {c}"
        );
        // Rooms whose height caps the ball over a plateau of their floor plans: a room's
        // middle (it stood at a plateau's first voxel, or between two rooms).
        for b in [Builtin::EmptyBox, Builtin::TwoRooms, Builtin::FourRooms] {
            let (c, _) = largest_empty_ball(&b.scene().expect("scene")).expect("a ball");
            let middle = |o: &visgate_scenes::Opening| {
                let m = o.centre_m();
                o.width_m() >= 4.0 && (c.x - m[0]).abs() < 0.1 && (c.z - m[2]).abs() < 0.1
            };
            assert!(b.empty_boxes_m().iter().any(middle), "{b:?}: {c}");
        }
    }
}

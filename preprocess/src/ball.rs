//! Where a bare mesh's light and camera go without a bake: the centre of the largest empty
//! ball in the level's inside, found as the bake finds it — the static triangles voxelized at
//! [`BALL_RESOLUTION`] voxels on the longest axis, the empty space the bake keeps (a bare
//! mesh's: the component most triangles face), its exact distance transform — but without
//! the skeleton. It depends on the scene alone, so that a reference rendered without a baked
//! level and a gate render with one look from the same place.

use glam::Vec3;
use visgate_formats::Scene;
use visgate_formats::vgate::{BakeParams, Resolution};

use crate::stages;
use crate::voxelize::grid_for;

/// Voxels on the longest axis of the grid the ball is found on (the bake's default).
/// [Units: voxels]
pub const BALL_RESOLUTION: u32 = 128;

/// The most memory the search may take (a level 10⁴ times longer than wide would not fit).
/// [Units: bytes]
const BALL_MEMORY_BYTES: u64 = 1 << 30;

/// The centre and radius of the largest ball in `scene`'s kept empty space (metres), or
/// `None` where there is none (no geometry, no empty space, a grid too large); ties go to the
/// first voxel in grid order.
pub fn largest_empty_ball(scene: &Scene) -> Option<(Vec3, f32)> {
    let (input, _) = stages::load(scene).ok()?;
    let resolution = Resolution::LongestAxisVoxels(BALL_RESOLUTION);
    let meta = grid_for(input.bounds, resolution, BALL_MEMORY_BYTES).ok()?;
    let ((solid, _), _) = stages::voxelize(meta, &input.triangles).ok()?;
    let params = BakeParams::default();
    let empty = stages::empty(scene, &meta, &solid.solid, &input.triangles, &params, false);
    let (es, _) = empty.ok()?;
    drop(solid);
    let (field, _) = stages::distance(&meta, &es, params.max_ball);
    let (i, _) = es
        .empty
        .iter()
        .zip(&field.dist2)
        .enumerate()
        .filter(|(_, (e, _))| **e)
        .fold(
            None,
            |best: Option<(usize, u64)>, (i, (_, &d))| match best {
                Some((_, b)) if b >= d => best,
                _ => Some((i, d)),
            },
        )?;
    let centre = Vec3::from(meta.voxel_to_world(meta.coords(i as u32)));
    Some((centre, field.radius_vx(i) as f32 * meta.voxel_size_m))
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
    }
}

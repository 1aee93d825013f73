//! Levels built from single-sided quads and thin boxes, as many real levels are: walls of zero
//! thickness, door panels and table tops thinner than a voxel, legs a few centimetres wide.
//! The box-room generator ([`crate::level`]) gives every wall a real thickness; these levels
//! are the ones that show where a bake or a runtime assumes it.

use glam::{Vec2, Vec3};
use visgate_formats::import::RawMesh;

/// Materials of the quad levels: name and linear albedo.
pub const QUAD_MATERIALS: [(&str, [f32; 3]); 5] = [
    ("floor", [0.70, 0.68, 0.62]),
    ("ceiling", [0.80, 0.80, 0.80]),
    ("wall", [0.75, 0.72, 0.65]),
    ("wood", [0.55, 0.38, 0.22]),
    ("red", [0.70, 0.12, 0.10]),
];

/// Material indices into [`QUAD_MATERIALS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mat {
    /// Floors.
    Floor = 0,
    /// Ceilings.
    Ceiling = 1,
    /// Walls.
    Wall = 2,
    /// Doors and furniture.
    Wood = 3,
    /// A coloured wall, so that colour bleeding shows.
    Red = 4,
}

/// Collects quads into one mesh per material.
pub struct QuadBuilder {
    meshes: Vec<RawMesh>,
}

impl Default for QuadBuilder {
    fn default() -> Self {
        QuadBuilder {
            meshes: crate::level::empty_meshes(&QUAD_MATERIALS),
        }
    }
}

impl QuadBuilder {
    /// A quad `p0 p1 p2 p3`, counter-clockwise seen from the side its normal faces.
    pub fn quad(&mut self, mat: Mat, p: [Vec3; 4]) {
        let mesh = &mut self.meshes[mat as usize];
        let n = (p[1] - p[0]).cross(p[3] - p[0]).normalize();
        let base = mesh.positions.len() as u32;
        let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        for (q, t) in p.iter().zip(uv) {
            mesh.positions.push(*q);
            mesh.normals.push(n);
            mesh.uvs.push(t);
        }
        mesh.triangles
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }

    /// An axis-aligned rectangle on the plane `axis = at`, spanning `lo..hi` on the other two
    /// axes (in the order (axis+1)%3, (axis+2)%3), its normal along +axis or −axis.
    pub fn rect(&mut self, mat: Mat, axis: usize, at: f32, lo: [f32; 2], hi: [f32; 2], plus: bool) {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let point = |a: f32, b: f32| {
            let mut p = Vec3::ZERO;
            p[axis] = at;
            p[u] = a;
            p[v] = b;
            p
        };
        // u × v = +axis, so (lo,lo) (hi,lo) (hi,hi) (lo,hi) faces +axis.
        let ps = [
            point(lo[0], lo[1]),
            point(hi[0], lo[1]),
            point(hi[0], hi[1]),
            point(lo[0], hi[1]),
        ];
        self.quad(
            mat,
            if plus {
                ps
            } else {
                [ps[0], ps[3], ps[2], ps[1]]
            },
        );
    }

    /// A closed box of half extents `half` centred at `centre`, turned by `yaw_deg` about +Y,
    /// faces outward.
    pub fn cuboid(&mut self, mat: Mat, centre: Vec3, half: Vec3, yaw_deg: f32) {
        let (s, c) = yaw_deg.to_radians().sin_cos();
        let at = |x: f32, y: f32, z: f32| {
            let l = Vec3::new(x * half.x, y * half.y, z * half.z);
            centre + Vec3::new(c * l.x + s * l.z, l.y, -s * l.x + c * l.z)
        };
        let corners = |axis: usize, sign: f32| {
            // The face at local axis = sign, counter-clockwise seen from outside.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let pt = |a: f32, b: f32| {
                let mut l = [0.0f32; 3];
                l[axis] = sign;
                l[u] = a;
                l[v] = b;
                at(l[0], l[1], l[2])
            };
            let ps = [pt(-1.0, -1.0), pt(1.0, -1.0), pt(1.0, 1.0), pt(-1.0, 1.0)];
            if sign > 0.0 {
                ps
            } else {
                [ps[0], ps[3], ps[2], ps[1]]
            }
        };
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                self.quad(mat, corners(axis, sign));
            }
        }
    }

    /// A wooden table centred at (`x`, `z`) on the floor: a 1.2 × 0.8 m top 4 cm thick at
    /// 0.76 m, on four 5 cm legs.
    pub fn table(&mut self, x: f32, z: f32) {
        let top_y = 0.76f32;
        self.cuboid(
            Mat::Wood,
            Vec3::new(x, top_y - 0.02, z),
            Vec3::new(0.6, 0.02, 0.4),
            0.0,
        );
        for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            self.cuboid(
                Mat::Wood,
                Vec3::new(x + sx * 0.55, 0.5 * (top_y - 0.04), z + sz * 0.35),
                Vec3::new(0.025, 0.5 * (top_y - 0.04), 0.025),
                0.0,
            );
        }
    }

    /// The meshes that have triangles.
    pub fn finish(self) -> Vec<RawMesh> {
        self.meshes
            .into_iter()
            .filter(|m| !m.triangles.is_empty())
            .collect()
    }
}

/// The ajar-door level: two 4 × 3 × 4 m rooms side by side along x, every wall, the floor
/// and the ceiling a single-sided quad facing the inside (zero thickness); the wall between
/// them at x = 4 m has a 1 × 2.1 m doorway (z 1.5–2.5 m) whose 4 cm door panel, hinged at
/// z = 1.5 m, stands open 20° into room B, leaving a gap of about 0.33 m at its free edge. Room
/// A has a table (1.2 × 0.8 m top, 4 cm thick, at 0.76 m, on four 5 cm legs) and a red wall at
/// z = 4 m.
pub fn ajar_door() -> Vec<RawMesh> {
    two_rooms(false)
}

/// The window of [`sun_window`] in room B's z = 4 m wall: x from / to, y from / to. [Units: m]
pub const SUN_WINDOW: [f32; 4] = [5.5, 6.5, 1.0, 2.2];

/// The sun-window level: [`ajar_door`]'s two rooms with a 1 × 1.2 m window to the void in room
/// B's z = 4 m wall ([`SUN_WINDOW`]), for a light standing outside it.
pub fn sun_window() -> Vec<RawMesh> {
    two_rooms(true)
}

/// The ajar door's two rooms, with the sun window or without.
fn two_rooms(window: bool) -> Vec<RawMesh> {
    let mut b = QuadBuilder::default();
    let (w, h, d) = (8.0f32, 3.0f32, 4.0f32);
    b.rect(Mat::Floor, 1, 0.0, [0.0, 0.0], [d, w], true);
    b.rect(Mat::Ceiling, 1, h, [0.0, 0.0], [d, w], false);
    // Outer walls (axis x: lo/hi over (y, z); axis z: over (x, y)).
    b.rect(Mat::Wall, 0, 0.0, [0.0, 0.0], [h, d], true);
    b.rect(Mat::Wall, 0, w, [0.0, 0.0], [h, d], false);
    b.rect(Mat::Wall, 2, 0.0, [0.0, 0.0], [w, h], true);
    b.rect(Mat::Red, 2, d, [0.0, 0.0], [4.0, h], false);
    if window {
        let [x0, x1, y0, y1] = SUN_WINDOW;
        b.rect(Mat::Wall, 2, d, [4.0, 0.0], [x0, h], false);
        b.rect(Mat::Wall, 2, d, [x1, 0.0], [w, h], false);
        b.rect(Mat::Wall, 2, d, [x0, 0.0], [x1, y0], false);
        b.rect(Mat::Wall, 2, d, [x0, y1], [x1, h], false);
    } else {
        b.rect(Mat::Wall, 2, d, [4.0, 0.0], [w, h], false);
    }
    // The dividing wall at x = 4, facing room A (−x): beside and above the doorway.
    let (z0, z1, top) = (1.5f32, 2.5f32, 2.1f32);
    b.rect(Mat::Wall, 0, 4.0, [0.0, 0.0], [h, z0], false);
    b.rect(Mat::Wall, 0, 4.0, [0.0, z1], [h, d], false);
    b.rect(Mat::Wall, 0, 4.0, [top, z0], [h, z1], false);
    // The door: 0.95 × 2.05 × 0.04 m, hinged at (4, z0), open 20° into room B (+x).
    let open = 20.0f32;
    let (len, th) = (0.95f32, 0.04f32);
    let dir = Vec3::new(open.to_radians().sin(), 0.0, open.to_radians().cos());
    let across = Vec3::new(dir.z, 0.0, -dir.x);
    let centre = Vec3::new(4.0, 1.025, z0) + dir * (0.5 * len + 0.01) + across * (0.5 * th);
    // Local x is across the panel, local z along it: yaw turns local +z onto `dir`.
    b.cuboid(
        Mat::Wood,
        centre,
        Vec3::new(0.5 * th, 1.025, 0.5 * len),
        open,
    );
    // The table in room A.
    b.table(2.2, 1.6);
    b.finish()
}

/// The hole of [`stairwell`]'s floor between its storeys: x from / to, z from / to, at y = 3 m.
/// [Units: m]
pub const STAIR_HOLE: [f32; 4] = [4.8, 7.2, 1.0, 2.2];

/// The stairwell level: two 8 × 3 × 6 m storeys, one over the other, of zero-thickness walls;
/// the floor between them a single plane seen from both sides, open over a flight of ten
/// 0.3 m steps ([`STAIR_HOLE`]) whose top step meets that floor beyond the hole's edge, so that
/// the ground floor sees the upper one only through a horizontal opening; a table with four
/// legs on the ground floor.
pub fn stairwell() -> Vec<RawMesh> {
    let mut b = QuadBuilder::default();
    let (w, h, d) = (8.0f32, 3.0f32, 6.0f32);
    b.rect(Mat::Floor, 1, 0.0, [0.0, 0.0], [d, w], true);
    b.rect(Mat::Ceiling, 1, 2.0 * h, [0.0, 0.0], [d, w], false);
    // The floor between the storeys, around the hole (axis y: lo/hi over (z, x)): a plane of
    // each side's quads, the floor's on top and the ceiling's under it, as a level modelled
    // with zero-thickness floors has them (which one a pixel shows is the face turned to it).
    let [x0, x1, z0, z1] = STAIR_HOLE;
    for (lo, hi) in [
        ([0.0, 0.0], [d, x0]),
        ([0.0, x1], [d, w]),
        ([0.0, x0], [z0, x1]),
        ([z1, x0], [d, x1]),
    ] {
        b.rect(Mat::Floor, 1, h, lo, hi, true);
        b.rect(Mat::Ceiling, 1, h, lo, hi, false);
    }
    // The outer walls, both storeys' height (axis x: over (y, z); axis z: over (x, y)).
    b.rect(Mat::Wall, 0, 0.0, [0.0, 0.0], [2.0 * h, d], true);
    b.rect(Mat::Wall, 0, w, [0.0, 0.0], [2.0 * h, d], false);
    b.rect(Mat::Wall, 2, 0.0, [0.0, 0.0], [w, 2.0 * h], true);
    b.rect(Mat::Red, 2, d, [0.0, 0.0], [w, 2.0 * h], false);
    // The flight: step k rises to 0.3 (k + 1) m, 0.3 m deep, from x1 towards −x.
    for k in 0..10 {
        let top = 0.3 * (k + 1) as f32;
        let x = x1 - 0.3 * (k as f32 + 0.5);
        b.cuboid(
            Mat::Wood,
            Vec3::new(x, 0.5 * top, 0.5 * (z0 + z1)),
            Vec3::new(0.15, 0.5 * top, 0.5 * (z1 - z0)),
            0.0,
        );
    }
    // The table on the ground floor.
    b.table(2.0, 4.0);
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_and_cuboid_normals_face_the_stated_side() {
        let mut b = QuadBuilder::default();
        b.rect(Mat::Wall, 0, 4.0, [0.0, 0.0], [1.0, 1.0], false);
        b.cuboid(Mat::Wood, Vec3::ZERO, Vec3::ONE, 30.0);
        let m = b.finish();
        assert_eq!(m[0].normals[0], Vec3::NEG_X);
        // Each outward face's normal points away from the box's centre.
        for (t, tri) in m[1].triangles.iter().enumerate() {
            let [a, b2, c] = tri.map(|i| m[1].positions[i as usize]);
            let n = (b2 - a).cross(c - a);
            assert!(n.dot((a + b2 + c) / 3.0) > 0.0, "triangle {t} faces inward");
        }
    }
}

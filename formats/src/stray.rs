//! Stray geometry: a few static triangles far from the rest of the level — a helper object
//! left in the export, a sky box, a vertex typed in the wrong place — make the bake's grid span
//! them, so its voxels are sized for the level and its strays together and the rooms fall to a
//! few voxels (the ajar door with one triangle 500 m away baked to 1 cluster on 3.9 m voxels
//! where it has 6 on 6 cm). [`stray_geometry`] finds them so that the bake can say where.

use std::ops::Range;

use glam::Vec3;

use crate::import::{ImportedModel, RawMesh};
use crate::scene::{Scene, points_bounds};

/// At most this share of the static triangles (and at least one) may be left out of the bulk
/// of the level along each axis. [Units: ratio]
pub const STRAY_SHARE: f64 = 0.01;

/// Triangles count as stray where, without them, the level's longest side would be more than
/// this many times shorter. [Units: ratio]
pub const STRAY_SPAN_RATIO: f32 = 4.0;

/// A bare mesh's stray triangles are left out of it ([`leave_out_strays`]) only where leaving
/// them out shortens the level more than this many times: a sky box 2 km round a 10 m house
/// (200×), e2m3's 4,000-unit sky box (37×) and a helper left 500 m from an 8 m level (63×)
/// are; a room of a few dozen triangles round a statue of thousands, which the
/// [`STRAY_SPAN_RATIO`] rule takes the room for stray around (an 8 m room round a 1 m statue:
/// 8×), is not, and the bake warns of it instead. [Units: ratio]
pub const STRAY_LEAVE_OUT_RATIO: f32 = 16.0;

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
    /// The names of the objects the far triangles make up whole, where they surround the rest
    /// (a sky dome); empty where they are a few triangles of any object.
    pub objects: Vec<String>,
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

    /// How many times as large the bake's voxels are with the strays as the rest alone needs.
    /// [Units: ratio]
    pub fn growth(&self) -> f32 {
        self.longest_m() / self.rest_longest_m().max(f32::MIN_POSITIVE)
    }

    /// "N of `whose` M `what` lie far from the rest, the farthest corner at (x, y, z)", as the
    /// warnings begin; where they are whole objects round the rest, "… lie far from the rest
    /// (the whole of 'Sky', round it), …".
    pub fn said(&self, whose: &str, what: &str) -> String {
        let p = self.farthest;
        let objects = match self.objects.len() {
            0 => String::new(),
            n => format!(
                " (the whole of {}, round it)",
                (self.objects.iter().take(4))
                    .map(|o| format!("'{o}'"))
                    .chain((n > 4).then(|| format!("{} more", n - 4)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        format!(
            "{} of {whose} {} {what} {} far from the rest{objects}, the farthest corner at ({:.2}, \
             {:.2}, {:.2})",
            self.triangles,
            self.total,
            if self.triangles == 1 { "lies" } else { "lie" },
            p.x,
            p.y,
            p.z
        )
    }
}

/// The static triangles of `scene` that lie far from the rest, where leaving them out would
/// shorten the level's longest side more than [`STRAY_SPAN_RATIO`] times; `None` where there
/// are none: a few triangles ([`far_triangles`]), or whole meshes round the rest
/// ([`far_parts`]).
pub fn stray_geometry(scene: &Scene) -> Option<Stray> {
    let parts: Vec<Part> = (scene.meshes.iter())
        .filter(|m| m.is_static)
        .map(|m| Part {
            name: &m.name,
            triangles: m.triangles.len(),
        })
        .collect();
    let tris: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    stray_split(&tris, &parts).map(|(s, _)| s)
}

/// [`stray_geometry`] of a level's static triangles `tris`.
pub fn stray_triangles(tris: &[[Vec3; 3]]) -> Option<Stray> {
    stray_split(tris, &[]).map(|(s, _)| s)
}

/// One object of a level for [`stray_split`]: its name, and how many of the level's
/// triangles, in order, are its.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Part<'a> {
    /// The object's name (an OBJ's object or group, a glTF mesh).
    pub name: &'a str,
    /// How many triangles it has.
    pub triangles: usize,
}

/// [`stray_triangles`] of a level made of `parts` (in the order of `tris`; none: one object),
/// and which of `tris` are the stray ones (true: far from the rest). The
/// few far triangles first; where there are none, whole objects that surround the rest from
/// far away ([`far_parts`]): a sky dome of thousands of triangles round a level of a few
/// thousand more is more than the [`STRAY_SHARE`] the first rule may leave out.
pub fn stray_split(tris: &[[Vec3; 3]], parts: &[Part]) -> Option<(Stray, Vec<bool>)> {
    far_triangles(tris).or_else(|| far_parts(tris, parts))
}

/// The few far triangles: the rest is the box of the triangles' centres with the
/// [`STRAY_SHARE`] (at least one) lowest and highest left out along each axis; a triangle is
/// far where a corner lies farther from that box than the box's longest side.
fn far_triangles(tris: &[[Vec3; 3]]) -> Option<(Stray, Vec<bool>)> {
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
    let reach = longest((lo, hi));
    let far: Vec<bool> = (tris.iter())
        .map(|t| t.iter().any(|&p| off_box(p, (lo, hi)) > reach))
        .collect();
    let strays = far.iter().filter(|&&f| f).count();
    if strays == 0 || strays > k {
        return None;
    }
    Some((stray_of(tris, &far, Vec::new())?, far))
}

/// At most this many objects, the largest first, are tried as surrounding the rest of a level
/// from far away ([`far_parts`]): a sky dome, a sky box, a ground plane to the horizon.
const MOST_SURROUNDING_PARTS: usize = 4;

/// Whole objects that surround the rest of the level from far away: the fewest of the largest
/// (at most [`MOST_SURROUNDING_PARTS`]) such that every triangle of each lies, box and all,
/// farther from the rest's bounds than the rest's longest side, each spans the rest's centre
/// along its own two longest axes, and together they hold no more triangles than the rest. A
/// room's floor touches what stands on it, and two buildings far apart do not surround each
/// other, so neither is taken.
fn far_parts(tris: &[[Vec3; 3]], parts: &[Part]) -> Option<(Stray, Vec<bool>)> {
    let mut start = 0;
    // Each object's triangles, their bounds and its name.
    let mut spans: Vec<(Range<usize>, (Vec3, Vec3), &str)> = (parts.iter())
        .filter_map(|p| {
            let range = start..(start + p.triangles).min(tris.len());
            start = range.end;
            let b = points_bounds(tris[range.clone()].iter().flatten().copied())?;
            Some((range, b, p.name))
        })
        .collect();
    spans.sort_by(|a, b| longest(b.1).total_cmp(&longest(a.1)));
    for j in 1..spans.len().min(MOST_SURROUNDING_PARTS + 1) {
        let (out, kept) = spans.split_at(j);
        let count = |s: &[(Range<usize>, _, _)]| s.iter().map(|s| s.0.len()).sum::<usize>();
        if count(out) > count(kept) {
            break;
        }
        let rest = (kept.iter().map(|s| s.1)).reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))?;
        let (reach, centre) = (longest(rest), 0.5 * (rest.0 + rest.1));
        let surrounds = |b: (Vec3, Vec3)| {
            let thinnest = (b.1 - b.0).min_position();
            (0..3).all(|a| a == thinnest || (b.0[a] <= centre[a] && centre[a] <= b.1[a]))
        };
        let far_off = |t: &[Vec3; 3]| {
            let b = points_bounds(t.iter().copied()).unwrap_or((t[0], t[0]));
            box_gap(b, rest) > reach
        };
        if !out
            .iter()
            .all(|s| surrounds(s.1) && tris[s.0.clone()].iter().all(far_off))
        {
            continue;
        }
        let mut far = vec![false; tris.len()];
        let mut names: Vec<String> = Vec::new();
        for (range, _, name) in out {
            far[range.clone()].fill(true);
            if !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
        }
        if let Some(stray) = stray_of(tris, &far, names) {
            return Some((stray, far));
        }
    }
    None
}

/// The [`Stray`] of `tris` whose `far` ones are left out, `objects` the names of those that
/// are whole objects; `None` where leaving them out shortens the level no more than
/// [`STRAY_SPAN_RATIO`] times.
fn stray_of(tris: &[[Vec3; 3]], far: &[bool], objects: Vec<String>) -> Option<Stray> {
    let corners = |stray: bool| {
        (tris.iter().zip(far))
            .filter(move |&(_, &f)| f == stray)
            .flat_map(|(t, _)| t.iter().copied())
    };
    let rest = points_bounds(corners(false))?;
    let bounds = points_bounds(tris.iter().flatten().copied())?;
    if longest(bounds) <= STRAY_SPAN_RATIO * longest(rest) {
        return None;
    }
    let farthest = corners(true).max_by(|a, b| off_box(*a, rest).total_cmp(&off_box(*b, rest)))?;
    Some(Stray {
        triangles: far.iter().filter(|&&f| f).count(),
        total: tris.len(),
        farthest,
        distance_m: off_box(farthest, rest),
        bounds,
        rest,
        objects,
    })
}

/// The longest side of box `b`.
fn longest(b: (Vec3, Vec3)) -> f32 {
    (b.1 - b.0).max_element()
}

/// Leaves the stray triangles ([`stray_triangles`]) of a bare mesh's `models` out of them, in
/// the file's own units and axes, with the vertices only they used, where that shortens the
/// level more than [`STRAY_LEAVE_OUT_RATIO`] times; what was left out, `None` where nothing
/// was. A bare mesh has no scene TOML to mark them `static = false` in, and they
/// would choose its units (a house in a sky box 2 km wide reads as centimetres) and size the
/// bake's grid.
pub fn leave_out_strays(models: &mut [ImportedModel]) -> Option<Stray> {
    let tris: Vec<[Vec3; 3]> = (models.iter().flat_map(|m| &m.meshes))
        .flat_map(|m| {
            m.triangles
                .iter()
                .map(|t| t.map(|i| m.positions[i as usize]))
        })
        .collect();
    let parts: Vec<Part> = (models.iter().flat_map(|m| &m.meshes))
        .map(|m| Part {
            name: &m.name,
            triangles: m.triangles.len(),
        })
        .collect();
    let (stray, far) = stray_split(&tris, &parts)?;
    if stray.growth() <= STRAY_LEAVE_OUT_RATIO {
        return None;
    }
    let mut far = far.into_iter();
    for mesh in models.iter_mut().flat_map(|m| &mut m.meshes) {
        mesh.triangles.retain(|_| !far.next().unwrap_or(false));
        keep_used_vertices(mesh);
    }
    Some(stray)
}

/// Drops the vertices of `mesh` that no triangle uses (their normals and texture coordinates
/// with them), renumbering the triangles' corners.
fn keep_used_vertices(mesh: &mut RawMesh) {
    let mut used = vec![false; mesh.positions.len()];
    for &i in mesh.triangles.iter().flatten() {
        used[i as usize] = true;
    }
    // Each kept vertex's new index: how many kept vertices come before it.
    let new_index: Vec<u32> = (used.iter())
        .scan(0u32, |kept, &u| {
            let before = *kept;
            *kept += u as u32;
            Some(before)
        })
        .collect();
    fn keep<T>(v: &mut Vec<T>, used: &[bool]) {
        if v.len() == used.len() {
            let mut flags = used.iter();
            v.retain(|_| *flags.next().unwrap_or(&false));
        }
    }
    keep(&mut mesh.positions, &used);
    keep(&mut mesh.normals, &used);
    keep(&mut mesh.uvs, &used);
    for t in &mut mesh.triangles {
        *t = t.map(|i| new_index[i as usize]);
    }
}

/// How far apart boxes `a` and `b` are (0 where they touch or overlap).
fn box_gap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> f32 {
    (b.0 - a.1).max(a.0 - b.1).max(Vec3::ZERO).length()
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
    fn a_bare_meshs_far_triangle_is_left_out_with_the_vertices_only_it_used() {
        // The room as one mesh of three corners a triangle, the far triangle first, in its
        // middle or last.
        for at in [0, 10, 33] {
            let mut tris = room();
            let far = Vec3::new(500.0, 0.0, 0.0);
            tris.insert(at, [far, far + Vec3::X, far + Vec3::Y]);
            let mesh = RawMesh {
                name: "level".into(),
                positions: tris.iter().flatten().copied().collect(),
                normals: vec![Vec3::Y; 3 * tris.len()],
                uvs: (0..3 * tris.len())
                    .map(|i| glam::Vec2::splat(i as f32))
                    .collect(),
                triangles: (0..tris.len() as u32)
                    .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                    .collect(),
                material: 0,
            };
            let mut models = vec![ImportedModel {
                meshes: vec![mesh],
                ..ImportedModel::default()
            }];
            let s = leave_out_strays(&mut models).expect("the far triangle");
            assert_eq!((s.triangles, s.total), (1, 34));
            let m = &models[0].meshes[0];
            tris.remove(at);
            let kept: Vec<[Vec3; 3]> = (m.triangles.iter())
                .map(|t| t.map(|i| m.positions[i as usize]))
                .collect();
            assert_eq!(kept, tris, "far triangle at {at}");
            assert_eq!((m.positions.len(), m.normals.len()), (99, 99));
            // The texture coordinates follow their vertices: those after the far triangle's
            // moved down by its three.
            let uv = |i: usize| glam::Vec2::splat(if i < 3 * at { i } else { i + 3 } as f32);
            assert!((0..99).all(|i| m.uvs[i] == uv(i)), "far triangle at {at}");
            // Nothing far: nothing left out.
            assert_eq!(leave_out_strays(&mut models), None);
            assert_eq!(models[0].meshes[0].triangles.len(), 33);
        }
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

    /// A UV sphere of `n` × `n / 2` segments (triangles facing in) round `centre`.
    fn dome(centre: Vec3, radius: f32, n: usize) -> Vec<[Vec3; 3]> {
        let at = |j: usize, i: usize| {
            let (th, ph) = (
                std::f32::consts::PI * j as f32 / (n / 2) as f32,
                std::f32::consts::TAU * i as f32 / n as f32,
            );
            centre + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
        };
        let mut tris = Vec::new();
        for j in 0..n / 2 {
            for i in 0..n {
                let (a, b, c, d) = (at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i));
                if j > 0 {
                    tris.push([a, c, b]);
                }
                if j + 1 < n / 2 {
                    tris.push([a, d, c]);
                }
            }
        }
        tris
    }

    /// `tris` of the parts `a` then `b`, and the parts.
    fn two_parts<'a>(
        a: (&'a str, Vec<[Vec3; 3]>),
        b: (&'a str, Vec<[Vec3; 3]>),
    ) -> (Vec<[Vec3; 3]>, Vec<Part<'a>>) {
        let parts = vec![
            Part {
                name: a.0,
                triangles: a.1.len(),
            },
            Part {
                name: b.0,
                triangles: b.1.len(),
            },
        ];
        ([a.1, b.1].concat(), parts)
    }

    #[test]
    fn a_sky_dome_of_many_triangles_round_the_room_is_found_whole() {
        // The room's floor in 10 cm squares (3,200 triangles and the tall one) in a dome of 48 ×
        // 24 segments, 2,208 triangles: far more than the 1 % the few-far-triangles rule takes.
        let mut dense = Vec::new();
        for (x, z) in (0..40).flat_map(|x| (0..40).map(move |z| (x, z))) {
            let p = |dx: i32, dz: i32| Vec3::new((x + dx) as f32, 0.0, (z + dz) as f32) / 10.0;
            dense.extend([[p(0, 0), p(1, 0), p(1, 1)], [p(0, 0), p(1, 1), p(0, 1)]]);
        }
        dense.push(room()[32]);
        let sky = dome(Vec3::new(2.0, 0.0, 2.0), 500.0, 48);
        let (tris, parts) = two_parts(("room", dense.clone()), ("sky", sky.clone()));
        assert_eq!(stray_triangles(&tris), None, "one object: not found");
        let (s, far) = stray_split(&tris, &parts).expect("the dome");
        assert_eq!((s.triangles, s.total), (2208, 3201 + 2208));
        assert_eq!(s.objects, ["sky"]);
        assert_eq!(s.rest, (Vec3::ZERO, Vec3::new(4.0, 3.0, 4.0)));
        assert!(far[3201..].iter().all(|&f| f) && !far[..3201].iter().any(|&f| f));
        assert!(
            s.said("its", "triangles")
                .contains("(the whole of 'sky', round it)")
        );
        // A hemisphere, its rim level with the floor, as sky domes often are.
        let upper: Vec<[Vec3; 3]> = (sky.iter())
            .filter(|t| t.iter().all(|p| p.y >= -1e-3))
            .copied()
            .collect();
        let (tris, parts) = two_parts(("room", dense.clone()), ("sky", upper.clone()));
        let (s, _) = stray_split(&tris, &parts).expect("the hemisphere");
        assert_eq!(
            (s.triangles, &s.objects[..]),
            (upper.len(), &["sky".to_string()][..])
        );
        // More triangles than the rest (9,024): not taken for its surroundings.
        let finer = dome(Vec3::new(2.0, 0.0, 2.0), 500.0, 96);
        let (tris, parts) = two_parts(("room", dense), ("sky", finer));
        assert_eq!(stray_split(&tris, &parts), None);
    }

    #[test]
    fn a_hall_round_its_furniture_and_two_far_buildings_are_not_strays() {
        // A 40 m hall of 12 triangles round a 2 m table of 160 in its middle: its walls are
        // far from the table, its floor is not (the table stands on it).
        let (l, h) = (40.0, 5.0);
        let mut hall = Vec::new();
        let mut quad = |q: [Vec3; 4]| hall.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
        let p = Vec3::new;
        quad([p(0., 0., 0.), p(0., 0., l), p(l, 0., l), p(l, 0., 0.)]);
        quad([p(0., h, 0.), p(l, h, 0.), p(l, h, l), p(0., h, l)]);
        quad([p(0., 0., 0.), p(l, 0., 0.), p(l, h, 0.), p(0., h, 0.)]);
        quad([p(0., 0., l), p(0., h, l), p(l, h, l), p(l, 0., l)]);
        quad([p(0., 0., 0.), p(0., h, 0.), p(0., h, l), p(0., 0., l)]);
        quad([p(l, 0., 0.), p(l, 0., l), p(l, h, l), p(l, h, 0.)]);
        let table: Vec<[Vec3; 3]> = (0..80)
            .flat_map(|i| {
                let y = i as f32 / 80.0;
                let c = |x: f32, z: f32| p(19.0 + 2.0 * x, y, 19.0 + 2.0 * z);
                [
                    [c(0., 0.), c(0., 1.), c(1., 1.)],
                    [c(0., 0.), c(1., 1.), c(1., 0.)],
                ]
            })
            .collect();
        let (tris, parts) = two_parts(("table", table), ("hall", hall));
        assert_eq!(stray_split(&tris, &parts), None);
        // Two rooms 1 km apart: neither surrounds the other.
        let far_room = room()
            .iter()
            .map(|t| t.map(|v| v + p(1000., 0., 0.)))
            .collect();
        let (tris, parts) = two_parts(("near", room()), ("far", far_room));
        assert_eq!(stray_split(&tris, &parts), None);
    }
}

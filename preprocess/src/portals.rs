//! Portals: the interfaces between adjacent visibility clusters, made planar.
//!
//! Every voxel face between two empty voxels of different clusters is an interface face. The
//! faces of one cluster pair are fitted with a plane whose normal is their summed signed normal
//! (for a staircase of faces that approximates a slanted plane, the sum is that plane's normal
//! times its area); a set that is not planar — its faces spread more than 1.5 voxels from the
//! plane, or their normals cancel (a folded interface) — is split at the median of its longest
//! extent, up to 64 pieces (a piece still not planar then is kept, and counted). Each piece stores the faces' orthographic projection onto its plane
//! as a coverage mask. So every interface face belongs to a portal whose mask covers its
//! projected centre ([`Portals::uncovered`] counts the faces that break it), and a cluster's boundary is its walls plus
//! its portals.

use std::collections::BTreeMap;

use glam::Vec3;
use rayon::prelude::*;
use visgate_formats::vgate::{GridMeta, MAX_MASK_CELLS, NONE, Portal};

/// One interface face: the centre, its axis and the sign of the normal from the pair's lower
/// cluster to the higher.
#[derive(Debug, Clone, Copy)]
struct Face {
    centre: Vec3,
    axis: usize,
    sign: f32,
}

/// Spread of a planar piece's faces about its plane, in voxels of the grid the clusters were
/// made on (the partition grid when the level's grid is finer: the refined interfaces are
/// staircases of its voxels).
pub const PLANAR_SPREAD_VOXELS: f32 = 1.5;
/// Pieces of one pair, at most 2^MAX_DEPTH.
const MAX_DEPTH: u32 = 6;

/// The interface faces of every cluster pair (lower cluster first), in a deterministic order.
fn interface_faces(
    meta: &GridMeta,
    empty: &[bool],
    cluster: &[u32],
) -> BTreeMap<(u32, u32), Vec<Face>> {
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let stride = [1, nx, nx * ny];
    // Each z slab's faces in voxel order, in parallel; then grouped by pair in slab order, so
    // every pair's faces stay in voxel order.
    let slabs: Vec<Vec<((u32, u32), Face)>> = (0..nz)
        .into_par_iter()
        .map(|z| {
            let mut found = Vec::new();
            for y in 0..ny {
                for x in 0..nx {
                    let i = x + nx * (y + ny * z);
                    let c = cluster[i];
                    if !empty[i] || c == NONE {
                        continue;
                    }
                    let at = [x, y, z];
                    for axis in 0..3 {
                        if at[axis] + 1 >= meta.dims[axis] as usize {
                            continue;
                        }
                        let j = i + stride[axis];
                        let d = cluster[j];
                        if !empty[j] || d == NONE || d == c {
                            continue;
                        }
                        let mut centre = Vec3::from(meta.voxel_to_world(at.map(|k| k as u32)));
                        centre[axis] += 0.5 * meta.voxel_size_m;
                        let sign = if c < d { 1.0 } else { -1.0 };
                        found.push(((c.min(d), c.max(d)), Face { centre, axis, sign }));
                    }
                }
            }
            found
        })
        .collect();
    let mut out: BTreeMap<(u32, u32), Vec<Face>> = BTreeMap::new();
    for (key, face) in slabs.into_iter().flatten() {
        out.entry(key).or_default().push(face);
    }
    out
}

fn axis_vec(axis: usize) -> Vec3 {
    let mut v = Vec3::ZERO;
    v[axis] = 1.0;
    v
}

/// The unit normal of a set of faces and whether they form one planar piece.
fn plane_of(faces: &[Face], spread_m: f32) -> (Vec3, Vec3, bool) {
    let sum: Vec3 = faces.iter().map(|f| axis_vec(f.axis) * f.sign).sum();
    let centroid = faces.iter().map(|f| f.centre).sum::<Vec3>() / faces.len() as f32;
    let len = sum.length();
    if len < 0.5 * faces.len() as f32 || len == 0.0 {
        let n = if len > 0.0 { sum / len } else { Vec3::X };
        return (centroid, n, false);
    }
    let n = sum / len;
    let (lo, hi) = faces.iter().fold((f32::MAX, f32::MIN), |(lo, hi), f| {
        let d = (f.centre - centroid).dot(n);
        (lo.min(d), hi.max(d))
    });
    (centroid, n, hi - lo <= spread_m)
}

/// Splits `faces` into planar pieces.
fn pieces(mut faces: Vec<Face>, spread_m: f32, depth: u32, out: &mut Vec<Vec<Face>>) {
    let (_, _, planar) = plane_of(&faces, spread_m);
    if planar || depth >= MAX_DEPTH || faces.len() < 8 {
        out.push(faces);
        return;
    }
    let (lo, hi) = faces.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), f| {
        (lo.min(f.centre), hi.max(f.centre))
    });
    let ext = hi - lo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    faces.sort_by(|a, b| a.centre[axis].total_cmp(&b.centre[axis]));
    let rest = faces.split_off(faces.len() / 2);
    pieces(faces, spread_m, depth + 1, out);
    pieces(rest, spread_m, depth + 1, out);
}

/// A frame (u, v) perpendicular to `n`.
fn frame(n: Vec3) -> (Vec3, Vec3) {
    let a = n.abs();
    let helper = if a.x <= a.y && a.x <= a.z {
        Vec3::X
    } else if a.y <= a.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    let u = n.cross(helper).normalize();
    (u, n.cross(u))
}

/// The corners of a face, metres.
fn corners(f: &Face, vs: f32) -> [Vec3; 4] {
    let (a, b) = ((f.axis + 1) % 3, (f.axis + 2) % 3);
    let h = 0.5 * vs;
    [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(s, t)| f.centre + axis_vec(a) * s + axis_vec(b) * t)
}

/// One portal from a planar piece: the faces' projections rasterised, each face marking every
/// cell its projected square's bounds touch.
fn portal_of(pair: (u32, u32), faces: &[Face], vs: f32, cell_voxels: f32) -> Portal {
    let (centroid, n, _) = plane_of(faces, f32::MAX);
    let (u, v) = frame(n);
    let uv = |p: Vec3| ((p - centroid).dot(u), (p - centroid).dot(v));
    let bounds = |f: &Face| {
        corners(f, vs).iter().fold(
            (f32::MAX, f32::MAX, f32::MIN, f32::MIN),
            |(a, b, c, d), &p| {
                let (x, y) = uv(p);
                (a.min(x), b.min(y), c.max(x), d.max(y))
            },
        )
    };
    let all = faces.iter().map(bounds).fold(
        (f32::MAX, f32::MAX, f32::MIN, f32::MIN),
        |(a, b, c, d), (e, f, g, h)| (a.min(e), b.min(f), c.max(g), d.max(h)),
    );
    let mut cell = cell_voxels * vs;
    // Cell counts and ranges a hair inside their bounds, so that a face edge lying on a cell
    // boundary marks the same cells at every scale of the level (rounding goes either way).
    let cells = |cell: f32| {
        [
            (((all.2 - all.0) / cell - 1e-3).ceil() as u32).max(1),
            (((all.3 - all.1) / cell - 1e-3).ceil() as u32).max(1),
        ]
    };
    while u64::from(cells(cell)[0]) * u64::from(cells(cell)[1]) > MAX_MASK_CELLS {
        cell *= 2.0;
    }
    let size = cells(cell);
    let mut mask = vec![0u32; Portal::words_for(size)];
    let mut mark = |i: i64, j: i64| {
        let i = i.clamp(0, i64::from(size[0]) - 1);
        let j = j.clamp(0, i64::from(size[1]) - 1);
        let k = (j * i64::from(size[0]) + i) as usize;
        mask[k / 32] |= 1 << (k % 32);
    };
    for f in faces {
        let (x0, y0, x1, y1) = bounds(f);
        let (cx, cy) = (((x0 - all.0) / cell), ((y0 - all.1) / cell));
        let (ex, ey) = (((x1 - all.0) / cell), ((y1 - all.1) / cell));
        let (i0, i1) = ((cx + 1e-3).floor() as i64, (ex - 1e-3).ceil() as i64 - 1);
        let (j0, j1) = ((cy + 1e-3).floor() as i64, (ey - 1e-3).ceil() as i64 - 1);
        for j in j0..=j1 {
            for i in i0..=i1 {
                mark(i, j);
            }
        }
        // A face seen edge-on projects to a line, no cell wide: its centre's cell.
        let (mx, my) = uv(f.centre);
        mark(
            ((mx - all.0) / cell).floor() as i64,
            ((my - all.1) / cell).floor() as i64,
        );
    }
    Portal {
        clusters: [pair.0, pair.1],
        origin_m: (centroid + u * all.0 + v * all.1).to_array(),
        normal: n.to_array(),
        u: u.to_array(),
        v: v.to_array(),
        cell_m: cell,
        size,
        mask,
        faces: faces.len() as u32,
    }
}

/// A level's portals and the check of its interfaces against them.
#[derive(Debug, Clone, Default)]
pub struct Portals {
    /// The portals, by cluster pair.
    pub portals: Vec<Portal>,
    /// Interface voxel faces.
    pub interface_faces: u64,
    /// Interface faces whose projected centre no portal of their pair covers: a level whose
    /// clusters are bounded by walls and portals alone has none.
    pub uncovered: u64,
    /// Interface faces farther than 1.5 voxels from every plane of their pair (the pieces a
    /// folded interface keeps after the last split).
    pub off_plane: u64,
}

/// The portals of a level: `empty` marks its empty voxels, `cluster` holds each voxel's
/// cluster ([`NONE`] for none); each interface face is checked against its pair's portals.
/// A piece is planar when its faces spread at most `spread_m` about its plane (at least
/// [`PLANAR_SPREAD_VOXELS`] of this grid's voxels is used).
pub fn portals(
    meta: &GridMeta,
    empty: &[bool],
    cluster: &[u32],
    cell_voxels: f32,
    spread_m: f32,
) -> Portals {
    let vs = meta.voxel_size_m;
    let spread_m = spread_m.max(PLANAR_SPREAD_VOXELS * vs);
    let pairs: Vec<((u32, u32), Vec<Face>)> =
        interface_faces(meta, empty, cluster).into_iter().collect();
    // Each pair on its own (in parallel), joined in pair order.
    let each: Vec<Portals> = pairs
        .into_par_iter()
        .map(|(pair, faces)| {
            let mut parts = Vec::new();
            let count = faces.len() as u64;
            pieces(faces, spread_m, 0, &mut parts);
            let mine: Vec<Portal> = parts
                .iter()
                .map(|p| portal_of(pair, p, vs, cell_voxels))
                .collect();
            let mut out = Portals::default();
            // Each face against its own piece's portal first, which nearly always covers it
            // and lies within the spread: the counts of testing every portal, at a fraction of
            // the tests (Crytek Sponza 512: 64 pieces a pair at most).
            for (k, part) in parts.iter().enumerate() {
                let order = || std::iter::once(&mine[k]).chain(mine.iter());
                for f in part {
                    let c = f.centre.to_array();
                    let covered = order().any(|p| {
                        let q = f.centre - Vec3::from(p.normal) * p.distance(c);
                        p.covers(q.to_array())
                    });
                    let near = order().any(|p| p.distance(c).abs() <= spread_m);
                    out.uncovered += u64::from(!covered);
                    out.off_plane += u64::from(!near);
                }
            }
            out.interface_faces = count;
            out.portals = mine;
            out
        })
        .collect();
    let mut out = Portals::default();
    for p in each {
        out.portals.extend(p.portals);
        out.interface_faces += p.interface_faces;
        out.uncovered += p.uncovered;
        out.off_plane += p.off_plane;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(dims: [u32; 3]) -> GridMeta {
        GridMeta {
            origin_m: [0.0; 3],
            voxel_size_m: 0.1,
            dims,
        }
    }

    #[test]
    fn a_slanted_interface_is_one_portal_with_the_slant_normal_covering_every_face() {
        // 20 × 4 × 20 voxels, all empty; cluster 0 where x + z < 20, else 1.
        let meta = grid([20, 4, 20]);
        let n = 20 * 4 * 20;
        let empty = vec![true; n];
        let cluster: Vec<u32> = (0..n as u32)
            .map(|i| {
                let [x, _, z] = meta.coords(i);
                u32::from(x + z >= 20)
            })
            .collect();
        let out = portals(&meta, &empty, &cluster, 1.0, 0.0);
        let ps = &out.portals;
        assert_eq!(ps.len(), 1, "{ps:?}");
        let nrm = Vec3::from(ps[0].normal);
        assert!(
            (nrm - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-4,
            "{nrm}"
        );
        assert_eq!(
            (out.uncovered, out.interface_faces),
            (0, u64::from(ps[0].faces))
        );
        // A point well inside cluster 0's half projects outside the opening's plane band.
        assert!(ps[0].distance([0.3, 0.2, 0.3]) < 0.0);
    }

    #[test]
    fn an_l_shaped_interface_splits_into_planar_pieces_and_solid_faces_are_not_interface() {
        // Cluster 1 is the corner x >= 10 && z >= 10; a solid column splits nothing else.
        let meta = grid([20, 3, 20]);
        let n = 20 * 3 * 20;
        let mut empty = vec![true; n];
        let cluster: Vec<u32> = (0..n as u32)
            .map(|i| {
                let [x, _, z] = meta.coords(i);
                u32::from(x >= 10 && z >= 10)
            })
            .collect();
        // Solid voxels at x = 9, z >= 15: the faces beside them are walls, not portal.
        for i in 0..n as u32 {
            let [x, _, z] = meta.coords(i);
            if x == 9 && z >= 15 {
                empty[i as usize] = false;
            }
        }
        let out = portals(&meta, &empty, &cluster, 1.0, 0.0);
        let ps = &out.portals;
        assert!(ps.len() >= 2, "{}", ps.len());
        let (uncovered, total) = (out.uncovered, out.interface_faces);
        assert_eq!(uncovered, 0);
        // 10 × 3 faces across z = 10 and 5 × 3 across x = 10 (z 10..15; 15..20 is solid).
        assert_eq!(total, 45);
        assert_eq!(ps.iter().map(|p| u64::from(p.faces)).sum::<u64>(), total);
    }
}

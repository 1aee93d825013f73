//! Clustered shading with gates (section V of the visibility-gates paper, after Olsson et al.),
//! the CPU twin that the GPU passes follow:
//!
//! 1. **Geometry clusters**: every pixel falls in a screen tile (`tile_px`²) and an
//!    exponential view-depth slice; a tile-slice is split further so that all pixels of a
//!    geometry cluster share one visibility cluster.
//! 2. **Unique clusters and bounds**: the clusters in view, each with the box of its pixels'
//!    points and the sphere around the box.
//! 3. **Light assignment**: for each geometry cluster and VPL — same visibility cluster: the VPL
//!    goes on the list; otherwise, for each chain of at most `max_hops` gates leading from the
//!    VPL's cluster to the geometry cluster's, if the cone from the VPL through the chain's
//!    first disk meets the cluster's sphere, the (VPL, chain) pair goes on the list.
//! 4. **Gather**: each pixel walks its geometry cluster's list; an entry with gates is tested
//!    exactly (the segment to the pixel's point crosses every disk of the chain). A VPL with
//!    several passing chains counts once.
//!
//! With portals or voxels the GPU keeps no lists: each pixel walks every VPL of its
//! interleaving subset. This twin still lists them (less the clusters wholly behind a VPL's
//! surface, which light nothing there), so the image is the same and the viewer can draw them.
//!
//! The assignment is conservative (the cone through a disk lies inside the cone through the
//! disk's bounding sphere), so the gather gives exactly the per-point gate test
//! ([`GateLevel::visible`]) — the tests check that — while the lists hold far fewer entries
//! than pixels × VPLs.

use std::collections::BTreeMap;

use glam::Vec3;

use crate::cpu::gates::{End, GateLevel, GateParams, GateShape, Walk, segment_crosses_disk};
use crate::vpl::Vpl;

/// Parameters of geometry clusters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterParams {
    /// Screen tile side. [Units: px] [Limit: 1..=256]
    pub tile_px: u32,
    /// Exponential depth slices between the nearest and farthest visible depth. [Limit: 1..=256]
    pub depth_slices: u32,
}

impl Default for ClusterParams {
    fn default() -> Self {
        ClusterParams {
            tile_px: 16,
            depth_slices: 24,
        }
    }
}

/// A pixel's surface as the G-buffer holds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelSurface {
    /// Position. [Units: m]
    pub position: Vec3,
    /// Unit normal, facing the camera.
    pub normal: Vec3,
    /// View depth (distance along the view axis). [Units: m]
    pub depth: f32,
    /// Visibility cluster (`None`: outside every cluster).
    pub cluster: Option<u32>,
}

/// One geometry cluster in view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometryCluster {
    /// Tile x, tile y, depth slice.
    pub tile: [u32; 3],
    /// Its visibility cluster.
    pub cluster: Option<u32>,
    /// Box of its pixels' points. [Units: m]
    pub bounds: [Vec3; 2],
}

impl GeometryCluster {
    /// The sphere around the box: centre and radius.
    pub fn sphere(&self) -> (Vec3, f32) {
        let c = (self.bounds[0] + self.bounds[1]) * 0.5;
        (c, (self.bounds[1] - c).length())
    }
}

/// An entry of a light list: a VPL and the gates its light passes (none: same cluster).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct LightEntry {
    /// The VPL.
    pub vpl: u32,
    /// Gate indices in order from the VPL, at most `max_hops` (disks).
    pub gates: Vec<u32>,
    /// Portals: the VPL's cluster, where the walk to each point of the list starts (`None`:
    /// the same cluster, or outside every cluster, so nothing to walk).
    pub walk_from: Option<u32>,
}

/// Geometry clusters of an image and their light lists.
#[derive(Debug, Clone, PartialEq)]
pub struct Clustered {
    /// Geometry cluster of each pixel (`u32::MAX`: no surface).
    pub pixel_cluster: Vec<u32>,
    /// The unique geometry clusters, in key order (tile y, tile x, slice, visibility cluster).
    pub clusters: Vec<GeometryCluster>,
    /// Each geometry cluster's light list, ordered by (VPL mod subsets, VPL).
    pub lists: Vec<Vec<LightEntry>>,
}

impl Clustered {
    /// Entries over all lists.
    pub fn entries(&self) -> usize {
        self.lists.iter().map(Vec::len).sum()
    }
}

/// Steps 1–3: geometry clusters of `pixels` (`width` per row), bounds, and light lists, each
/// ordered by (VPL mod `subsets`, VPL) — with interleaved sampling a pixel reads the run of
/// its subset (1: VPL order).
pub fn assign(
    pixels: &[Option<PixelSurface>],
    width: u32,
    vpls: &[Vpl],
    level: &GateLevel,
    gates: &GateParams,
    (params, subsets): (&ClusterParams, u32),
) -> Clustered {
    let subsets = subsets.max(1);
    let tile = params.tile_px.max(1);
    let slices = params.depth_slices.max(1);
    let (mut near, mut far) = (f32::INFINITY, 0f32);
    for p in pixels.iter().flatten() {
        near = near.min(p.depth.max(1e-6));
        far = far.max(p.depth);
    }
    let ratio = if far > near { (far / near).ln() } else { 1.0 };
    let slice_of = |d: f32| -> u32 {
        let t = ((d.max(near) / near).ln() / ratio).clamp(0.0, 1.0);
        ((t * slices as f32) as u32).min(slices - 1)
    };
    // Step 1–2: keys in a sorted map (deterministic order), bounds on the way.
    let mut index: BTreeMap<(u32, u32, u32, u32), usize> = BTreeMap::new();
    let keys: Vec<Option<(u32, u32, u32, u32)>> = pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p.map(|p| {
                let (x, y) = (i as u32 % width, i as u32 / width);
                (
                    y / tile,
                    x / tile,
                    slice_of(p.depth),
                    p.cluster.unwrap_or(u32::MAX),
                )
            })
        })
        .collect();
    for k in keys.iter().flatten() {
        let n = index.len();
        index.entry(*k).or_insert(n);
    }
    // Renumber in key order.
    let order: Vec<(u32, u32, u32, u32)> = index.keys().copied().collect();
    for (i, k) in order.iter().enumerate() {
        index.insert(*k, i);
    }
    let mut clusters: Vec<GeometryCluster> = order
        .iter()
        .map(|&(ty, tx, s, c)| GeometryCluster {
            tile: [tx, ty, s],
            cluster: (c != u32::MAX).then_some(c),
            bounds: [Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)],
        })
        .collect();
    let pixel_cluster: Vec<u32> = keys
        .iter()
        .zip(pixels)
        .map(|(k, p)| match (k, p) {
            (Some(k), Some(p)) => {
                let gc = index[k];
                let b = &mut clusters[gc].bounds;
                b[0] = b[0].min(p.position);
                b[1] = b[1].max(p.position);
                gc as u32
            }
            _ => u32::MAX,
        })
        .collect();
    // Step 3: light lists.
    let vpl_cluster: Vec<Option<u32>> = vpls
        .iter()
        .map(|v| level.cluster_at(Vec3::from(v.position), Vec3::from(v.normal)))
        .collect();
    let lists = clusters
        .iter()
        .map(|gc| {
            let mut list = light_list(gc, (vpls, &vpl_cluster), level, gates);
            list.sort_by_key(|e| (e.vpl % subsets, e.vpl));
            list
        })
        .collect();
    Clustered {
        pixel_cluster,
        clusters,
        lists,
    }
}

/// Step 3 for one geometry cluster: the VPLs (with their visibility clusters) that may light
/// it, each with its chains of gates (disks) or where its walk starts (portals), in VPL order.
fn light_list(
    gc: &GeometryCluster,
    (vpls, vpl_cluster): (&[Vpl], &[Option<u32>]),
    level: &GateLevel,
    gates: &GateParams,
) -> Vec<LightEntry> {
    let (s, r) = gc.sphere();
    let mut list = Vec::new();
    for (j, v) in vpls.iter().enumerate() {
        let a = Vec3::from(v.position);
        let in_front = (s - a).dot(Vec3::from(v.normal)) >= -r;
        // An entry with no gates: the walk (if any) runs per point.
        let walk = |walk_from| LightEntry {
            vpl: j as u32,
            gates: Vec::new(),
            walk_from,
        };
        match (vpl_cluster[j], gc.cluster) {
            // Voxels: culled only when the cluster lies wholly behind the VPL's surface; the
            // voxel walk runs per point, whatever the clusters.
            _ if gates.shape == GateShape::Voxels => {
                if in_front {
                    list.push(walk(None));
                }
            }
            // Portals: likewise; the walk runs per point from the VPL's cluster.
            (Some(ca), Some(cb)) if ca != cb && gates.shape == GateShape::Portal => {
                if in_front {
                    list.push(walk(Some(ca)));
                }
            }
            (Some(ca), Some(cb)) if ca != cb => {
                for chain in level.chains(ca, cb, gates.max_hops) {
                    let g = level.gate(chain[0]);
                    if cone_meets_sphere(a, g.0, g.2 * gates.oversize, s, r) {
                        list.push(LightEntry {
                            vpl: j as u32,
                            gates: chain,
                            walk_from: None,
                        });
                    }
                }
            }
            // Same cluster, or outside every cluster: no gate stands between.
            _ => list.push(walk(None)),
        }
    }
    list
}

/// Angular slack of the cone test: GPU and CPU compute asin / acos to different last bits
/// (acos is ill-conditioned near 1), so both widen the cone by this much to stay conservative.
/// [Units: rad]
pub const CONE_SLACK: f32 = 1e-4;

/// Whether the cone from `apex` through the sphere (`disk_centre`, `disk_radius`) — which
/// holds the cone through the disk — meets the sphere (`centre`, `radius`), within
/// [`CONE_SLACK`].
pub fn cone_meets_sphere(
    apex: Vec3,
    disk_centre: Vec3,
    disk_radius: f32,
    centre: Vec3,
    radius: f32,
) -> bool {
    cone_margin(apex, disk_centre, disk_radius, centre, radius) <= CONE_SLACK
}

/// The angle between the cone's axis and the sphere's centre, less the cone's half-angle and
/// the sphere's angular radius (seen from `apex`): ≤ 0 where they meet, −∞ where `apex` lies
/// inside a sphere. [Units: rad]
pub fn cone_margin(
    apex: Vec3,
    disk_centre: Vec3,
    disk_radius: f32,
    centre: Vec3,
    radius: f32,
) -> f32 {
    let axis = disk_centre - apex;
    let (la, ls) = (axis.length(), (centre - apex).length());
    if la <= disk_radius || ls <= radius || la <= 0.0 {
        return f32::NEG_INFINITY; // the apex is inside one of the spheres: no cone to speak of
    }
    let half = (disk_radius / la).clamp(0.0, 1.0).asin();
    let spread = (radius / ls).clamp(0.0, 1.0).asin();
    let angle = (axis / la)
        .dot((centre - apex) / ls)
        .clamp(-1.0, 1.0)
        .acos();
    angle - (half + spread)
}

/// Step 4 for one pixel: whether entry `e`'s light reaches `point` (its cluster `None`:
/// outside every cluster).
pub fn entry_reaches(
    e: &LightEntry,
    vpl: &Vpl,
    point: &End,
    level: &GateLevel,
    gates: &GateParams,
) -> bool {
    if gates.shape == GateShape::Voxels {
        return level.visible(&End::of_vpl(vpl, None), point, gates);
    }
    let (a, p) = (Vec3::from(vpl.position), point.position);
    if let (Some(ca), Some(here)) = (e.walk_from, point.cluster) {
        return matches!(level.walk(a, ca, p, here, gates.max_walk), Walk::Visible(_));
    }
    e.gates.iter().all(|&g| {
        let (c, n, r) = level.gate(g);
        segment_crosses_disk(a, p, c, n, r * gates.oversize)
    })
}

//! Gate visibility (section V of the visibility-gates paper), the CPU side: a baked level's
//! voxel→cluster grid and gates, the visibility cluster of a surface point (the cluster of the
//! empty space it faces), and the gate test — a VPL lights a point of another cluster only if
//! the segment between them passes through the disk of a gate between the two clusters (the
//! point lies in the cone from the VPL through the disk).
//!
//! Beyond the paper, each a parameter: disks oversized by a factor (the paper's suggested fix
//! for darkening), and light through a chain of up to K gates (the paper stops at neighbouring
//! clusters, K = 1); portals, the planar pieces of the interfaces between clusters, walked
//! cluster by cluster ([`super::portal_walk`]); and the walk through the level's open voxels
//! ([`super::sight`]), the openings at voxel resolution.

use glam::Vec3;
use visgate_formats::vgate::GridMeta;
use visgate_formats::{BakedLevel, Scene};

use super::portal_walk::PortalBvh;
use super::sight::VoxelSight;
use crate::RenderError;

/// What a gate is at runtime.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GateShape {
    /// The paper's disks, through chains of at most `max_hops` of them.
    Disk,
    /// The baked portals (the true openings), walked cluster by cluster along the segment.
    Portal,
    /// The walk through the level's open voxels: the segment is blocked by the first voxel
    /// the voxelization closed, or with [`GateParams::triangles`] where it hits a triangle
    /// listed in one ([`super::sight`]). The default: the lowest indirect error of the three
    /// on every camera measured, and faster than the portals on nearly all.
    #[default]
    Voxels,
}

impl GateShape {
    /// Its value in grid.wgsl's `Grid.shape` (`GATE_DISKS`, `GATE_PORTALS`, `GATE_VOXELS`).
    pub fn shader_id(self) -> u32 {
        match self {
            GateShape::Disk => 0,
            GateShape::Portal => 1,
            GateShape::Voxels => 2,
        }
    }
}

/// The end of a portal walk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walk {
    /// The segment reaches the point's cluster after this many portals.
    Visible(u32),
    /// The segment leaves a cluster through no portal of it: a wall is in the way.
    Blocked,
    /// The walk passed the step limit first (counted, treated as occluded).
    Limit,
}

/// How light passes gates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateParams {
    /// Disks or portals.
    pub shape: GateShape,
    /// Portals a walk may pass before it is given up (and counted). [Limit: 1..=1024]
    pub max_walk: u32,
    /// Gate disks are this many times their baked radius. [Limit: > 0] [Units: ratio]
    pub oversize: f32,
    /// Gates a VPL's light may pass on its way, in a chain through intermediate clusters.
    /// [Limit: 1..=16]
    pub max_hops: u32,
    /// Voxels: walk the true segment and pass a closed voxel where it hits none of the
    /// triangles listed there ([`super::sight_triangles`]: near-exact, several times the walk's
    /// cost on lavapipe), instead of blocking at every closed voxel, with the ends set off
    /// their surfaces (the default).
    pub triangles: bool,
    /// Voxels, without the triangles: pass a closed voxel where the segment meets neither of
    /// the one or two planes its geometry lies in ([`super::sight_planes`]), and start each end
    /// 0.3 voxels off its surface where those planes allow; else every closed voxel blocks.
    pub planes: bool,
}

impl Default for GateParams {
    fn default() -> Self {
        GateParams {
            shape: GateShape::Voxels,
            max_walk: 64,
            oversize: 1.0,
            max_hops: 2,
            triangles: false,
            planes: true,
        }
    }
}

/// A baked level checked against its scene, ready for gate tests.
pub struct GateLevel {
    grid: GridMeta,
    level: BakedLevel,
    /// Gates of each cluster, as indices into the level's gates.
    cluster_gates: Vec<Vec<usize>>,
    /// Each cluster's portals in a bounding-volume hierarchy.
    portal_bvh: PortalBvh,
    /// The open voxels, for the voxel walk.
    sight: VoxelSight,
    /// Walks through [`GateLevel::visible`] that reached the limit (counted as occluded).
    walks_over_limit: std::sync::atomic::AtomicU64,
}

impl GateLevel {
    /// Takes `level` for `scene`; refuses a level baked from other static geometry.
    pub fn new(level: BakedLevel, scene: &Scene) -> Result<GateLevel, RenderError> {
        if level.info.geometry_hash != scene.static_geometry_hash() {
            // A bare mesh read in other units or on another axis than at the bake is other
            // geometry too.
            return Err(RenderError::Param(format!(
                "the level was baked from other static geometry than scene '{}' (hash {} vs \
                 {}): re-bake it with `visgate bake`{}",
                scene.name,
                level.info.geometry_hash,
                scene.static_geometry_hash(),
                if scene.is_bare_mesh() {
                    ", or read the mesh as the bake did (the same --up, --metres-per-unit and --keep-far)"
                } else {
                    ""
                }
            )));
        }
        let clusters = level.topology.clusters.len();
        let mut cluster_gates = vec![Vec::new(); clusters];
        for (i, g) in level.topology.gates.iter().enumerate() {
            for c in g.clusters {
                if let Some(list) = cluster_gates.get_mut(c as usize) {
                    list.push(i);
                }
            }
        }
        let portal_bvh = PortalBvh::new(&level.topology.portals, clusters);
        let sight = sight_with_triangles(&level, scene);
        Ok(GateLevel {
            grid: level.info.grid,
            level,
            cluster_gates,
            portal_bvh,
            sight,
            walks_over_limit: std::sync::atomic::AtomicU64::new(0),
        })
    }

    /// The baked level (skeleton, clusters, gates), for drawing.
    pub fn baked(&self) -> &BakedLevel {
        &self.level
    }

    /// Number of visibility clusters.
    pub fn cluster_count(&self) -> usize {
        self.cluster_gates.len()
    }

    /// Every cluster's portal hierarchy.
    pub fn portal_bvh(&self) -> &PortalBvh {
        &self.portal_bvh
    }

    /// The open voxels, for the voxel walk.
    pub fn sight(&self) -> &VoxelSight {
        &self.sight
    }

    /// Lists the scene's triangles in the closed voxels now (once; a walk with the triangles
    /// on the CPU lists them when first needed), so that [`GateLevel::tables`] and
    /// `GpuRenderer::set_level` carry them: the GPU's voxel walk with the triangles needs them.
    pub fn list_triangles(&self) {
        self.sight.list_triangles();
    }

    /// Fits the closed voxels' planes now (once; listing the triangles first; a walk with the
    /// planes on the CPU fits them when first needed), so that [`GateLevel::tables`] and
    /// `GpuRenderer::set_level` carry them.
    pub fn fit_planes(&self) {
        self.sight.planes();
    }

    /// Voxel edge of the level's grid. [Units: m]
    pub fn voxel_size(&self) -> f32 {
        self.grid.voxel_size_m
    }

    /// Number of gates.
    pub fn gate_count(&self) -> usize {
        self.level.topology.gates.len()
    }

    fn cluster_of_voxel(&self, p: Vec3) -> Option<u32> {
        let v = self.grid.world_to_voxel(p.to_array())?;
        self.level
            .voxel_cluster
            .get(self.grid.index(v))
            .filter(|&c| c != u32::MAX)
    }

    /// The visibility cluster of a surface point: that of the empty voxel it faces, looked up
    /// 0.5, 1.5 and 2.5 voxels along its normal (a wall on a voxel face is two voxels thick);
    /// for a point in a corner, whose normal runs along the other wall's solid voxels, the
    /// voxel with a cluster nearest to the point one voxel out among the 27 around it that lie
    /// in front of the surface; then the point's own voxel (a dynamic mesh in empty space).
    /// Only empty voxels have a cluster. grid.wgsl's `cluster_at` is the GPU twin.
    pub fn cluster_at(&self, p: Vec3, n: Vec3) -> Option<u32> {
        let vs = self.grid.voxel_size_m;
        if let Some(c) = [0.5, 1.5, 2.5]
            .iter()
            .find_map(|&k| self.cluster_of_voxel(p + n * (k * vs)))
        {
            return Some(c);
        }
        let o = Vec3::from(self.grid.origin_m);
        let q = p + n * vs;
        let base = ((q - o) / vs).floor();
        let mut best: Option<(f32, u32)> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let centre = o + (base + Vec3::new(dx as f32, dy as f32, dz as f32) + 0.5) * vs;
                    let Some(c) = self.cluster_of_voxel(centre) else {
                        continue;
                    };
                    let d2 = (centre - q).length_squared();
                    if (centre - p).dot(n) > 0.0 && best.is_none_or(|(bd, _)| d2 < bd) {
                        best = Some((d2, c));
                    }
                }
            }
        }
        best.map(|(_, c)| c).or_else(|| self.cluster_of_voxel(p))
    }

    /// Gate `i`: centre, unit normal, radius (m).
    pub fn gate(&self, i: u32) -> (Vec3, Vec3, f32) {
        let g = &self.level.topology.gates[i as usize];
        (Vec3::from(g.centre_m), Vec3::from(g.normal), g.radius_m)
    }

    /// Every chain of at most `max_hops` gates leading from cluster `ca` to `cb` through
    /// distinct clusters, in a deterministic order.
    pub fn chains(&self, ca: u32, cb: u32, max_hops: u32) -> Vec<Vec<u32>> {
        let gates = &self.level.topology.gates;
        let mut out = Vec::new();
        let mut stack: Vec<(u32, Vec<u32>, Vec<u32>)> = vec![(ca, Vec::new(), vec![ca])];
        while let Some((c, chain, visited)) = stack.pop() {
            if chain.len() as u32 >= max_hops {
                continue;
            }
            for &gi in self
                .cluster_gates
                .get(c as usize)
                .into_iter()
                .flatten()
                .rev()
            {
                let g = &gates[gi];
                let other = if g.clusters[0] == c {
                    g.clusters[1]
                } else {
                    g.clusters[0]
                };
                if visited.contains(&other) {
                    continue;
                }
                let mut next = chain.clone();
                next.push(gi as u32);
                if other == cb {
                    out.push(next);
                } else {
                    let mut v = visited.clone();
                    v.push(other);
                    stack.push((other, next, v));
                }
            }
        }
        out.sort();
        out
    }

    /// Walks that [`GateLevel::visible`] gave up at the limit since the level was made or this
    /// was last called (each counted as occluded); resets the count.
    pub fn take_walks_over_limit(&self) -> u64 {
        self.walks_over_limit
            .swap(0, std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether light from a VPL reaches a surface point: with voxels, the voxel walk between
    /// them; otherwise through the gates — same cluster, outside every cluster (the bake knows
    /// nothing there: unoccluded), or (disks) the segment passes through a chain of at most
    /// `max_hops` gate disks that leads from the VPL's cluster to the point's, or (portals)
    /// the walk reaches the point's cluster (a walk over the limit counts as occluded).
    pub fn visible(&self, vpl: &End, point: &End, params: &GateParams) -> bool {
        if params.shape == GateShape::Voxels {
            let (a, b) = (vpl, point);
            return if params.triangles {
                self.sight
                    .visible(a.position, a.normal, b.position, b.normal)
            } else {
                self.sight.visible_off_surfaces(
                    a.position,
                    a.normal,
                    b.position,
                    b.normal,
                    params.planes,
                )
            };
        }
        let (Some(ca), Some(cb)) = (vpl.cluster, point.cluster) else {
            return true;
        };
        let (a, b) = (vpl.position, point.position);
        if ca == cb {
            return true;
        }
        if params.shape == GateShape::Portal {
            return match self.walk(a, ca, b, cb, params.max_walk) {
                Walk::Visible(_) => true,
                Walk::Blocked => false,
                Walk::Limit => {
                    self.walks_over_limit
                        .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    false
                }
            };
        }
        let gates = &self.level.topology.gates;
        let mut frontier = vec![ca];
        let mut seen = vec![ca];
        for _ in 0..params.max_hops {
            let mut next = Vec::new();
            for &c in &frontier {
                for &gi in self.cluster_gates.get(c as usize).into_iter().flatten() {
                    let g = &gates[gi];
                    let other = if g.clusters[0] == c {
                        g.clusters[1]
                    } else {
                        g.clusters[0]
                    };
                    if seen.contains(&other)
                        || !segment_crosses_disk(
                            a,
                            b,
                            Vec3::from(g.centre_m),
                            Vec3::from(g.normal),
                            g.radius_m * params.oversize,
                        )
                    {
                        continue;
                    }
                    if other == cb {
                        return true;
                    }
                    seen.push(other);
                    next.push(other);
                }
            }
            if next.is_empty() {
                break;
            }
            frontier = next;
        }
        false
    }
}

/// The level's voxel walk, with the scene's static triangles to list in its closed voxels when
/// a walk first needs them.
fn sight_with_triangles(level: &BakedLevel, scene: &Scene) -> VoxelSight {
    let triangles: Vec<[Vec3; 3]> = scene.static_triangles().collect();
    VoxelSight::new(&level.info.sight_grid, &level.open).with_triangles(&triangles)
}

/// One end of a segment that light may pass: a VPL or a surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct End {
    /// Position. [Units: m]
    pub position: Vec3,
    /// Unit normal of its surface, on the side it lights or is lit from: a VPL's own, a
    /// surface point's face normal (the voxel walk starts off it; a shading normal can lean
    /// far off its face).
    pub normal: Vec3,
    /// Its visibility cluster ([`GateLevel::cluster_at`]; `None`: outside every cluster).
    pub cluster: Option<u32>,
}

impl End {
    /// VPL `v`'s end, of visibility cluster `cluster`.
    pub fn of_vpl(v: &crate::vpl::Vpl, cluster: Option<u32>) -> End {
        End {
            position: Vec3::from(v.position),
            normal: Vec3::from(v.normal),
            cluster,
        }
    }

    /// The end at `position` with `normal`, its cluster looked up in `level`.
    pub fn at(level: &GateLevel, position: Vec3, normal: Vec3) -> End {
        End {
            position,
            normal,
            cluster: level.cluster_at(position, normal),
        }
    }
}

/// Whether segment `a`–`b` crosses the disk of `centre`, unit `normal` and `radius`.
pub fn segment_crosses_disk(a: Vec3, b: Vec3, centre: Vec3, normal: Vec3, radius: f32) -> bool {
    let d = b - a;
    let den = d.dot(normal);
    if den.abs() <= f32::EPSILON * d.length() || radius.is_nan() || radius < 0.0 {
        return false;
    }
    let t = (centre - a).dot(normal) / den;
    if !(0.0..=1.0).contains(&t) {
        return false;
    }
    (a + d * t - centre).length_squared() <= radius * radius
}

/// The GPU's copy of a level's gate data: the voxel→cluster grid as little-endian words of its
/// stored element size (u8, u16 or u32: only what the scene's cluster count needs), the gates,
/// and each cluster's gates as offsets + indices.
#[derive(Debug, Clone, PartialEq)]
pub struct GateTables {
    /// Grid origin (xyz, m) and voxel size (w, m).
    pub origin: [f32; 4],
    /// Grid dims (xyz) and bytes per value (w: 1, 2 or 4).
    pub dims: [u32; 4],
    /// The grid's values packed into u32 words, little-endian.
    pub voxel_words: Vec<u32>,
    /// The gate disks.
    pub gates: Vec<crate::gpu::layout::Gate>,
    /// `clusters + 1` offsets into the list that follows them, then the gate indices.
    pub cluster_gates: Vec<u32>,
    /// The portals, packed ([`GateLevel::portal_words`]).
    pub portal_words: Vec<u32>,
    /// The open voxels and their bricks' clearance, packed ([`VoxelSight::words`]).
    pub sight_words: crate::cpu::sight::SightWords,
    /// The most steps a voxel walk takes ([`VoxelSight::most_steps`]).
    pub sight_steps: u32,
}

impl GateLevel {
    /// The tables the GPU's gate test reads, the closed voxels' triangle lists among them where
    /// `lists` asks for them and they are listed ([`GateLevel::list_triangles`]), and their
    /// planes where `planes` does and they are fitted ([`GateLevel::fit_planes`]).
    pub fn tables(&self, lists: bool, planes: bool) -> GateTables {
        use visgate_formats::vgate::VoxelValues;
        let (bytes, words): (u32, Vec<u32>) = match &self.level.voxel_cluster {
            VoxelValues::U8(v) => (
                1,
                v.chunks(4)
                    .map(|c| {
                        let mut b = [u8::MAX; 4];
                        b[..c.len()].copy_from_slice(c);
                        u32::from_le_bytes(b)
                    })
                    .collect(),
            ),
            VoxelValues::U16(v) => (
                2,
                v.chunks(2)
                    .map(|c| u32::from(c[0]) | (u32::from(*c.get(1).unwrap_or(&u16::MAX)) << 16))
                    .collect(),
            ),
            VoxelValues::U32(v) => (4, v.clone()),
        };
        let gates = self
            .level
            .topology
            .gates
            .iter()
            .map(|g| crate::gpu::layout::Gate {
                centre: g.centre_m,
                radius: g.radius_m,
                normal: g.normal,
                clusters: g.clusters,
                ..bytemuck::Zeroable::zeroed()
            })
            .collect();
        let mut starts = Vec::with_capacity(self.cluster_gates.len() + 1);
        let mut list = Vec::new();
        let base = self.cluster_gates.len() as u32 + 1;
        for l in &self.cluster_gates {
            starts.push(base + list.len() as u32);
            list.extend(l.iter().map(|&g| g as u32));
        }
        starts.push(base + list.len() as u32);
        starts.extend(list);
        let g = &self.grid;
        GateTables {
            origin: [g.origin_m[0], g.origin_m[1], g.origin_m[2], g.voxel_size_m],
            dims: [g.dims[0], g.dims[1], g.dims[2], bytes],
            voxel_words: words,
            gates,
            cluster_gates: starts,
            portal_words: self.portal_words(),
            sight_words: self.sight.words_with(lists, planes),
            sight_steps: self.sight.most_steps(),
        }
    }
}

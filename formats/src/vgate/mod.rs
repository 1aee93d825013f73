//! The baked `.vgate` file: the runtime layout of a level's topology.
//!
//! ```text
//! offset  size        field
//! 0       8           magic  b"VGATE\r\n\x1a"  (catches text-mode transfers, like PNG's)
//! 8       4           format version, u32 LE
//! 12      4           header length H, u32 LE
//! 16      H           header: postcard(Header) = BakeInfo (params, geometry hash, grid)
//!                     + a table of sections (kind, offset, length, element type, CRC-32)
//! 16+H    4           CRC-32 of bytes [0, 16+H)
//! ...                 sections, contiguous, in table order, up to the end of the file:
//!                       topology      postcard(Topology): skeleton, segmented skeleton,
//!                                     node→cluster, clusters, gates, portals
//!                       voxel_cluster little-endian blob, one element per voxel (x fastest),
//!                                     or, where smaller, its runs: (u32 LE length, element)
//!                       open_voxels   a bit per voxel of the sight grid (x fastest), 1 = open
//!                                     (no triangle crosses its centre segments), u64 LE
//!                                     words (format 6), or, where smaller, their runs
//!                                     (format 7): a u32 LE count, then one word repeated
//!                                     or, with the count's top bit set, as many words
//! ```
//!
//! The grid is stored in the smallest unsigned type (u8, u16, u32) that holds its largest
//! value, with the type's maximum meaning "none"; as runs of equal values when that is
//! smaller (it is on every real level: Crytek Sponza at 512 keeps 35 M voxels in 8 MB of
//! runs, where format 3's whole file was 145 MB), decoded to the
//! dense grid on load. Format 3 also stored each voxel's nearest skeleton node, which no
//! reader used. Reading checks everything — magic, version,
//! every length against the file and each other, every checksum, every index against the
//! array it indexes, every float — and returns a typed [`VgateError`]; it never panics.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::VgateError;
use crate::scene::GeometryHash;

mod bits;
mod params;
mod portal;
mod read;
mod validate;
mod values;

pub use bits::VoxelBits;
pub use params::{
    AlphaRule, BakeInfo, BakeParams, CurvatureTo, GatePlacement, MaxBall, Resolution,
};
pub use portal::{EDGE_SLACK, MAX_MASK_CELLS, Portal};
pub use values::{Elem, VoxelValues};

/// The first eight bytes of every `.vgate` file.
pub const MAGIC: [u8; 8] = *b"VGATE\r\n\x1a";
/// The format version this build writes.
pub const FORMAT_VERSION: u32 = 7;
/// The oldest format version this build reads: format 6 differs from 7 only in that its open
/// voxels are never stored as runs.
pub const OLDEST_READ_VERSION: u32 = 6;
/// The format version a `.vgate` file states (the u32 after its magic); `None` where the bytes
/// do not begin with [`MAGIC`] and a version.
pub fn stated_version(bytes: &[u8]) -> Option<u32> {
    let v = bytes.get(8..12).filter(|_| bytes[..8] == MAGIC)?;
    Some(u32::from_le_bytes([v[0], v[1], v[2], v[3]]))
}

/// "No node / no cluster" in a grid decoded to u32.
pub const NONE: u32 = u32::MAX;

/// The voxel grid every intermediate and the file share. Voxels are cell-centred:
/// `voxel_to_world(i) = origin_m + (i + 0.5) · voxel_size_m`; linear index
/// `x + nx · (y + ny · z)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GridMeta {
    /// World position of the grid's minimum corner, metres.
    pub origin_m: [f32; 3],
    /// Edge length of a voxel, metres. [Limit: > 0]
    pub voxel_size_m: f32,
    /// Voxels along x, y, z. [Limit: each > 0]
    pub dims: [u32; 3],
}

impl GridMeta {
    /// Number of voxels, or `None` if it overflows.
    pub fn voxel_count(&self) -> Option<u64> {
        let [x, y, z] = self.dims.map(u64::from);
        x.checked_mul(y)?.checked_mul(z)
    }

    /// Linear index of voxel (x, y, z).
    #[inline]
    pub fn index(&self, v: [u32; 3]) -> usize {
        let [nx, ny, _] = self.dims.map(|d| d as usize);
        v[0] as usize + nx * (v[1] as usize + ny * v[2] as usize)
    }

    /// The voxel holding world point `p` (metres), if it lies in the grid.
    #[inline]
    pub fn world_to_voxel(&self, p: [f32; 3]) -> Option<[u32; 3]> {
        let v: [f32; 3] = std::array::from_fn(|a| (p[a] - self.origin_m[a]) / self.voxel_size_m);
        (0..3)
            .all(|a| v[a].is_finite() && v[a] >= 0.0 && v[a] < self.dims[a] as f32)
            .then(|| v.map(|c| c as u32))
    }

    /// Voxel coordinates of grid index `i` (the inverse of [`GridMeta::index`]).
    #[inline]
    pub fn coords(&self, i: u32) -> [u32; 3] {
        let (nx, ny) = (self.dims[0], self.dims[1]);
        [i % nx, (i / nx) % ny, i / (nx * ny)]
    }

    /// Centre of voxel `v` in world space, metres.
    #[inline]
    pub fn voxel_to_world(&self, v: [u32; 3]) -> [f32; 3] {
        std::array::from_fn(|a| self.origin_m[a] + (v[a] as f32 + 0.5) * self.voxel_size_m)
    }
}

/// A skeleton voxel: a node of the curvilinear skeleton graph.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SkeletonNode {
    /// Its voxel.
    pub voxel: [u32; 3],
    /// Its centre in world space, metres.
    pub position_m: [f32; 3],
    /// Radius of the maximal empty ball centred there, metres. [Limit: >= 0]
    pub radius_m: f32,
}

/// The curvilinear skeleton: nodes and undirected adjacency edges.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Skeleton {
    /// Nodes.
    pub nodes: Vec<SkeletonNode>,
    /// Undirected edges `[a, b]`, node indices.
    pub edges: Vec<[u32; 2]>,
}

/// Why a skeleton node was kept by the segmentation (IV.B.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SegNodeKind {
    /// Degree ≠ 2: an end or a junction.
    Topology,
    /// Where the line bends (curvature > 1).
    Curvature,
    /// Added by recursive line splitting so the maximal balls cover the line.
    Coverage,
    /// Where the line narrows well below the balls of its ends (a doorway that the two end
    /// balls happen to cover at a coarse resolution); visgate's addition to IV.B.1.
    Narrowing,
}

/// A node of the segmented skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SegNode {
    /// The skeleton node it is.
    pub skeleton_node: u32,
    /// Why it was kept.
    pub kind: SegNodeKind,
}

/// An edge of the segmented skeleton: a line of skeleton nodes between two segmented nodes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegEdge {
    /// The two segmented nodes.
    pub nodes: [u32; 2],
    /// The skeleton nodes along the original line, from `nodes[0]` to `nodes[1]` inclusive.
    pub path: Vec<u32>,
}

/// The segmented skeleton.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SegmentedSkeleton {
    /// Nodes.
    pub nodes: Vec<SegNode>,
    /// Edges.
    pub edges: Vec<SegEdge>,
}

/// A visibility cluster: a quasi-convex region of empty space.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cluster {
    /// The segmented node the greedy construction grew it from.
    pub seed: u32,
    /// Minimum corner of the bounds of its empty voxels, metres.
    pub bounds_min_m: [f32; 3],
    /// Maximum corner, metres.
    pub bounds_max_m: [f32; 3],
}

/// A visibility gate: a disk joining two clusters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gate {
    /// Disk centre, metres.
    pub centre_m: [f32; 3],
    /// Unit normal of the disk (along the skeleton edge).
    pub normal: [f32; 3],
    /// Disk radius, metres. [Limit: >= 0]
    pub radius_m: f32,
    /// The two clusters it joins (distinct).
    pub clusters: [u32; 2],
    /// The segmented edge it sits on.
    pub seg_edge: u32,
}

/// Everything in the topology section.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Topology {
    /// The curvilinear skeleton.
    pub skeleton: Skeleton,
    /// The segmented skeleton.
    pub segmented: SegmentedSkeleton,
    /// Cluster of each segmented node.
    pub node_cluster: Vec<u32>,
    /// Visibility clusters.
    pub clusters: Vec<Cluster>,
    /// Visibility gates (the paper's disks).
    pub gates: Vec<Gate>,
    /// Portals: the planar pieces of every interface between adjacent clusters (format 3).
    pub portals: Vec<Portal>,
}

/// The sections a file holds, in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SectionKind {
    /// postcard(Topology).
    Topology,
    /// Visibility cluster of every voxel a visible surface or a VPL can fall in, one value
    /// per voxel.
    VoxelCluster,
    /// The same grid as runs of equal values in voxel order: (u32 LE length, value).
    VoxelClusterRuns,
    /// A bit per voxel of the sight grid, set where it is open (no triangle crosses its centre
    /// segments): u64 LE words.
    OpenVoxels,
    /// The same words as runs (format 7): a u32 LE count, then one u64 LE word repeated that
    /// many times or, with the count's top bit set, that many words.
    OpenVoxelRuns,
}

/// An entry of the section table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SectionEntry {
    /// Which section.
    pub kind: SectionKind,
    /// Absolute byte offset.
    pub offset: u64,
    /// Length in bytes.
    pub len: u64,
    /// Element type.
    pub elem: Elem,
    /// CRC-32 (IEEE) of its bytes.
    pub crc32: u32,
}

/// The header after the fixed prefix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// What the file was baked from and with.
    pub info: BakeInfo,
    /// The section table.
    pub sections: Vec<SectionEntry>,
}

/// A whole baked level, as the runtime uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct BakedLevel {
    /// Params, geometry hash, grid.
    pub info: BakeInfo,
    /// Skeleton, segmentation, clusters, gates.
    pub topology: Topology,
    /// Visibility cluster of every voxel; [`NONE`] where no surface or VPL can be.
    pub voxel_cluster: VoxelValues,
    /// The open voxels of [`BakeInfo::sight_grid`], for the voxel walk: no triangle crosses
    /// their centre segments (the bake's thin voxelization), so a walk through open voxels
    /// alone passes through no wall (format 6; files baked before the thin voxelization hold
    /// the conservative one's, which the walk reads the same way).
    pub open: VoxelBits,
}

/// The fixed header's bytes: the magic, the version and the header's length.
const PREFIX: usize = 16;

impl BakedLevel {
    /// Encodes the level after checking it, so that an invalid file is never written.
    pub fn to_bytes(&self) -> Result<Vec<u8>, VgateError> {
        self.validate()?;
        Ok(self.encode_unchecked())
    }

    /// Encodes without validation (tests use it to write corrupt files).
    #[doc(hidden)]
    pub fn encode_unchecked(&self) -> Vec<u8> {
        let topo = postcard::to_allocvec(&self.topology).unwrap_or_default();
        let runs = self.voxel_cluster.to_runs_le_bytes();
        let clusters = if (runs.len() as u64) < self.voxel_cluster.dense_len() {
            (SectionKind::VoxelClusterRuns, runs)
        } else {
            (SectionKind::VoxelCluster, self.voxel_cluster.to_le_bytes())
        };
        let open_runs = self.open.to_runs_le_bytes();
        let open = if (open_runs.len() as u64) < self.open.len().div_ceil(64) * 8 {
            (SectionKind::OpenVoxelRuns, open_runs)
        } else {
            (SectionKind::OpenVoxels, self.open.to_le_bytes())
        };
        let blobs = [
            (SectionKind::Topology, Elem::Structure, topo),
            (clusters.0, self.voxel_cluster.elem(), clusters.1),
            (open.0, Elem::U8, open.1),
        ];
        let mut header = Header {
            info: self.info.clone(),
            sections: blobs
                .iter()
                .map(|(kind, elem, bytes)| SectionEntry {
                    kind: *kind,
                    offset: 0,
                    len: bytes.len() as u64,
                    elem: *elem,
                    crc32: crc32fast::hash(bytes),
                })
                .collect(),
        };
        // Offsets depend on the header's length, which depends on the offsets' varint widths:
        // iterate to the fixed point (two or three rounds).
        let mut header_bytes = Vec::new();
        for _ in 0..8 {
            let mut at = (PREFIX + header_bytes.len() + 4) as u64;
            for s in &mut header.sections {
                s.offset = at;
                at += s.len;
            }
            let next = postcard::to_allocvec(&header).unwrap_or_default();
            if next == header_bytes {
                break;
            }
            header_bytes = next;
        }
        let total: usize =
            PREFIX + header_bytes.len() + 4 + blobs.iter().map(|b| b.2.len()).sum::<usize>();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(header_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(&header_bytes);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        for (_, _, b) in &blobs {
            out.extend_from_slice(b);
        }
        out
    }

    /// Writes the file (to a temporary file beside it, then renamed, so a crash never leaves
    /// half a file under the final name).
    pub fn write(&self, path: &Path) -> Result<(), VgateError> {
        let bytes = self.to_bytes()?;
        let io = |error| VgateError::Io {
            file: path.to_path_buf(),
            error,
        };
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".partial");
        let tmp = std::path::PathBuf::from(tmp);
        std::fs::write(&tmp, &bytes).map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }

    /// Refuses a level baked from other static geometry than `scene_hash`.
    pub fn check_geometry(&self, scene_hash: GeometryHash) -> Result<(), VgateError> {
        if self.info.geometry_hash != scene_hash {
            return Err(VgateError::StaleBake {
                baked: self.info.geometry_hash.to_string(),
                scene: scene_hash.to_string(),
            });
        }
        Ok(())
    }

    /// Independent cycles of the skeleton graph: E − V + C (edges, nodes, components).
    pub fn skeleton_cycles(&self) -> u64 {
        let s = &self.topology.skeleton;
        let comps = components(s.nodes.len(), &s.edges);
        (s.edges.len() as u64 + comps as u64).saturating_sub(s.nodes.len() as u64)
    }
}

/// Connected components of an undirected graph given as an edge list.
pub fn components(n: usize, edges: &[[u32; 2]]) -> usize {
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let mut count = n;
    for e in edges {
        let (a, b) = (e[0] as usize, e[1] as usize);
        if a >= n || b >= n {
            continue;
        }
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra] = rb;
            count -= 1;
        }
    }
    count
}

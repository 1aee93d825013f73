//! # visgate-preprocess
//!
//! The bake, on the CPU (rayon, petgraph): static meshes → conservative voxelization → empty
//! space (border solid, enclosed voids and small unlit components dropped, leaks reported) →
//! exact Euclidean distance transform → topology-preserving curvilinear thinning (asymmetric
//! critical kernels with 1D isthmuses and persistence) → skeleton graph and nearest-node grid
//! → the skeleton without gaps narrower than a size in metres → segmentation (topology, curvature and coverage nodes) → visibility clusters (greedy, α)
//! → visibility gates → the runtime layout of `visgate_formats::vgate`.
//!
//! Each stage is a function from plain data to new plain data with its own params struct.
//! This crate never imports `visgate-runtime`; what the two share is a type in
//! `visgate-formats`.
//!
//! Stages: [`voxelize`], [`empty`], [`distance`], [`thin`], [`graph`], [`simplify`], [`segment`],
//! [`clusters`] (clusters and gates); [`bake::bake`] runs them all, timed and counted, and
//! [`debug`] writes what each produced in formats Blender and MeshLab open.

pub mod bake;
pub mod ball;
pub mod betti;
pub mod clusters;
pub mod convex;
pub mod counters;
pub mod cut;
pub mod debug;
pub mod distance;
pub mod empty;
pub mod flatten;
pub mod gate_step;
pub mod graph;
mod hang;
pub mod inside;
pub mod leak;
pub mod memory;
pub mod neighbourhood;
pub mod portals;
pub mod refine;
pub mod report;
mod scale;
pub mod segment;
pub mod separating;
pub mod sight_grid;
pub mod sightline;
pub mod simplify;
pub mod stages;
pub mod thin;
mod thin_next;
mod verdict;
pub mod voxelize;
pub mod winding;

/// Everything that can stop a bake.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// A parameter is outside its documented limits.
    #[error("invalid bake parameter: {0}")]
    Param(String),
    /// The scene has no empty space to bake (or none was kept).
    #[error("no empty space: {0}")]
    NoEmptySpace(String),
    /// The static geometry lies in one plane: it encloses no space to bake.
    #[error(
        "the level is flat: its static geometry spans {:.2} x {:.2} x {:.2} m, nothing along {axis}, so it encloses no space — a ground, a wall or a sheet alone, not a level. The bake partitions the space that floors, walls and ceilings close around; bake the whole level (every static mesh in a scene TOML), or render this one without --level (the reference needs no bake)",
        extent[0], extent[1], extent[2]
    )]
    Flat {
        /// The geometry's bounding box's size. [Units: m]
        extent: [f64; 3],
        /// The axis it has no extent along (x, y or z).
        axis: char,
    },
    /// The static geometry has no triangle.
    #[error("the scene has no static triangles to bake; mark at least one mesh `static = true`")]
    NoGeometry,
    /// A closed scene's empty space reaches its bounds.
    #[error(
        "the scene is declared closed but its empty space reaches the outside{}; close the geometry there, or bake anyway with --allow-leaks (--debug-dir writes the paths as leak.ply) [sides of the bounds reached: {sides}]",
        leak::describe_all(openings)
    )]
    Leak {
        /// The paths to the outside and their openings.
        openings: Vec<leak::LeakPath>,
        /// The sides of the bounds reached, with boxes.
        sides: String,
    },
    /// The grids would not fit in the memory limit; nothing was allocated.
    #[error(
        "a {:.0} x {:.0} x {:.0} voxel grid needs about {:.1} GiB for the bake, over the limit of {:.1} GiB; lower --resolution or raise --voxel-size",
        dims[0], dims[1], dims[2], *bytes / f64::from(1u32 << 30), *limit as f64 / f64::from(1u32 << 30)
    )]
    TooLarge {
        /// The grid's dimensions.
        dims: [f64; 3],
        /// Bytes it would need.
        bytes: f64,
        /// The limit.
        limit: u64,
    },
    /// The sight grid at `--sight-voxel` would not fit in the memory limit; nothing was
    /// allocated.
    #[error(
        "the sight grid at --sight-voxel {voxel_m} m is {:.0} x {:.0} x {:.0} voxels and needs about {:.1} GiB, over the limit of {:.1} GiB; raise --sight-voxel",
        dims[0], dims[1], dims[2], *bytes / f64::from(1u32 << 30), *limit as f64 / f64::from(1u32 << 30)
    )]
    SightTooLarge {
        /// The sight grid's dimensions.
        dims: [f64; 3],
        /// Its voxel. [Units: m]
        voxel_m: f32,
        /// Bytes it would need.
        bytes: f64,
        /// The limit.
        limit: u64,
    },
}

/// xorshift32 from `seed` (not 0): the same pseudo-random sequence every run, for tests that
/// sweep random levels.
#[cfg(test)]
pub(crate) fn xorshift32(seed: u32) -> impl FnMut() -> u32 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    }
}

//! # visgate-formats
//!
//! Plain data and I/O shared by the bake (`visgate-preprocess`) and the runtime
//! (`visgate-runtime`); no algorithms but one shared predicate, and no GPU:
//!
//! - [`desc`]: the scene description, a TOML file a user writes by hand (meshes, material
//!   overrides, lights, cameras, up axis and units, whether the level is closed);
//! - [`geom`]: the triangle–box test that the bake voxelizes with and the runtime lists
//!   triangles by;
//! - [`import`]: mesh import — OBJ (tobj, with MTL colours and diffuse textures) and glTF/GLB
//!   (gltf, with base colour factor/texture and node transforms) — with every bad input turned
//!   into a typed error or a counted warning;
//! - [`scene`]: the in-memory scene in visgate's space (right-handed, +Y up, metres), and the
//!   hash of its static geometry;
//! - [`room_height`]: how high a bare mesh's rooms stand, which its units are read from where
//!   its extent leaves them in doubt;
//! - [`stray`]: the static triangles far from the rest of a level (a helper left in the
//!   export, a sky box), which would size the bake's grid;
//! - [`vgate`]: the baked `.vgate` file — the runtime layout of a level's skeleton, visibility
//!   clusters and gates, and its voxel grids — with a validating reader.

mod assemble;
pub mod desc;
mod desc_checks;
pub mod error;
pub mod export;
pub mod geom;
pub mod gltf_export;
pub mod gltf_nodes;
mod gltf_quantized;
pub mod import;
mod import_gltf;
pub mod load;
pub mod mitsuba;
pub mod mtl_map;
pub mod placement;
pub mod polygons;
pub mod room_height;
pub mod scene;
pub mod stray;
pub mod sun;
pub mod vgate;

pub use desc::SceneDesc;
pub use error::{SceneError, VgateError};
pub use import::{ImportOptions, ImportedModel};
pub use load::{
    BARE_LEVEL_MAX_M, BareMesh, ROOM_PLAUSIBLE_M, ROOM_TYPICAL_M, ROOM_UNITS, bare_mesh_units,
    bare_mesh_units_with_rooms, bare_mesh_up,
};
pub use scene::{Camera, GeometryHash, Light, Material, Mesh, Scene, Texture};
pub use vgate::BakedLevel;

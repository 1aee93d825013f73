//! Typed errors of the scene loader and the baked-file reader.

use std::path::PathBuf;

/// Everything that can go wrong reading a scene description or importing its meshes.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read (the OS's words in the message alone: as the error's source
    /// too, a chain printed them twice).
    #[error("{}: cannot read: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// The scene TOML does not parse, or has an unknown key.
    #[error("{}: {message}", file.display())]
    Parse {
        /// The scene file.
        file: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
    /// A value is outside its documented limits.
    #[error("{}: {what}", file.display())]
    Invalid {
        /// The scene file.
        file: PathBuf,
        /// What is wrong and what is allowed.
        what: String,
    },
    /// The file's extension names no format visgate imports.
    #[error(
        "{}: unknown file type; visgate reads scene descriptions (.toml) and meshes (.obj, .gltf, .glb){}",
        file.display(),
        convert_hint(file)
    )]
    UnknownFileType {
        /// The file.
        file: PathBuf,
    },
    /// tobj rejected an OBJ file.
    #[error("{}: broken OBJ file: {reason}", file.display())]
    Obj {
        /// The OBJ file.
        file: PathBuf,
        /// tobj's reason.
        reason: tobj::LoadError,
    },
    /// The gltf crate rejected a glTF/GLB file.
    #[error("{}: broken glTF file: {message}", file.display())]
    Gltf {
        /// The glTF file.
        file: PathBuf,
        /// The gltf crate's message.
        message: String,
    },
    /// A glTF/GLB file that requires extensions visgate does not read: compressed meshes, as
    /// Blender's exporter and gltfpack write when asked (quantized ones it reads).
    #[error(
        "{}: needs the glTF extension{} {}, which visgate does not read ({what}). Write the \
         file out without {}: re-export it from the modelling tool with mesh compression off, \
         or decode it with a glTF tool first (gltf-transform; gltfpack without -c)",
        file.display(),
        if extensions.len() == 1 { "" } else { "s" },
        extensions.join(", "),
        if extensions.len() == 1 { "it" } else { "them" }
    )]
    GltfExtensions {
        /// The glTF file.
        file: PathBuf,
        /// The extensions it requires that are not read.
        extensions: Vec<String>,
        /// What they are, where known ("Draco-compressed meshes", …).
        what: String,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error(
        "{}: mesh '{mesh}' has a non-finite (NaN or infinite) vertex coordinate at vertex {vertex}",
        file.display()
    )]
    NonFinite {
        /// The mesh file.
        file: PathBuf,
        /// The mesh (object/group or glTF mesh) name.
        mesh: String,
        /// Index of the first bad vertex in that mesh.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "{}: mesh '{mesh}' has a vertex index {index} out of range (it has {vertices} vertices)",
        file.display()
    )]
    IndexOutOfRange {
        /// The mesh file.
        file: PathBuf,
        /// The mesh name.
        mesh: String,
        /// The bad index.
        index: u64,
        /// How many vertices the mesh has.
        vertices: usize,
    },
    /// A material override names a material that no mesh has.
    #[error(
        "{}: material override '{name}' matches no material of the scene's meshes (they are: {known})",
        file.display()
    )]
    UnknownMaterial {
        /// The scene file.
        file: PathBuf,
        /// The name in the override.
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// After import, the scene has no triangle at all.
    #[error("{}: the scene has no triangles (after dropping degenerate ones)", file.display())]
    Empty {
        /// The scene or mesh file.
        file: PathBuf,
    },
}

/// Everything that can go wrong reading or writing a baked `.vgate` file.
#[derive(Debug, thiserror::Error)]
pub enum VgateError {
    /// The file could not be read or written: the OS's words alone, since every caller names
    /// the file and what it was doing (`cannot read the level L: …`); as the error's source
    /// too, a chain printed them twice, the file's name with them.
    #[error("{error}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// The first bytes are not the `.vgate` magic.
    #[error("not a visgate baked file (wrong magic bytes)")]
    BadMagic,
    /// Written by a newer visgate.
    #[error(
        "baked file format version {found} is newer than this visgate reads ({supported}); update visgate or re-bake"
    )]
    NewerVersion {
        /// Version in the file.
        found: u32,
        /// Version this build reads.
        supported: u32,
    },
    /// Written by an older, unsupported visgate.
    #[error(
        "baked file format version {found} is no longer read (this visgate reads {supported} and later); re-bake the level"
    )]
    OldVersion {
        /// Version in the file.
        found: u32,
        /// The oldest version this build reads.
        supported: u32,
    },
    /// The file ends before its declared contents.
    #[error("truncated baked file: {what} needs {needed} bytes, the file has {available}")]
    Truncated {
        /// What was being read.
        what: &'static str,
        /// Bytes needed (end offset).
        needed: u64,
        /// Bytes the file has.
        available: u64,
    },
    /// A checksum does not match: the file is corrupt.
    #[error(
        "corrupt baked file: checksum of {section} is {found:08x}, expected {expected:08x}; re-bake the level"
    )]
    Checksum {
        /// The section (or "header").
        section: String,
        /// CRC-32 computed over the bytes.
        found: u32,
        /// CRC-32 recorded in the file.
        expected: u32,
    },
    /// Declared lengths disagree with each other or with the file.
    #[error("corrupt baked file: {0}")]
    Length(String),
    /// An index points outside the array it indexes.
    #[error("corrupt baked file: {0}")]
    IndexOutOfRange(String),
    /// A value is not what the format allows (NaN, negative radius, …).
    #[error("corrupt baked file: {0}")]
    BadValue(String),
    /// postcard could not decode a structure.
    #[error("corrupt baked file: cannot decode {what}: {message}")]
    Decode {
        /// What was being decoded.
        what: &'static str,
        /// postcard's message.
        message: String,
    },
    /// The file was baked from other static geometry than the scene given.
    #[error(
        "the baked file is stale: it was baked from static geometry with hash {baked}, but the scene's static geometry hashes to {scene}; re-bake it with `visgate bake`"
    )]
    StaleBake {
        /// Hash recorded in the file.
        baked: String,
        /// Hash of the scene given now.
        scene: String,
    },
}

/// How to turn a mesh format visgate does not read into one it does, for the formats levels
/// come in; empty for another extension.
fn convert_hint(file: &std::path::Path) -> &'static str {
    let ext = file
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("fbx") => {
            ". Convert it to glTF: import it into Blender (File > Import > FBX) and export glTF \
             2.0 (.glb), or run FBX2glTF; Unreal and Unity export glTF with their glTF exporters"
        }
        Some("blend") => ". In Blender: File > Export > glTF 2.0 (.glb), or Wavefront (.obj)",
        Some(
            "dae" | "3ds" | "max" | "ply" | "stl" | "usd" | "usda" | "usdc" | "usdz" | "x3d"
            | "abc",
        ) => ". Import it into Blender and export glTF 2.0 (.glb) or Wavefront (.obj)",
        Some("bsp" | "map") => {
            ". A Quake-style map: export its world geometry to OBJ first (TrenchBroom: File > \
             Export > Wavefront OBJ; a compiled .bsp, with a BSP-to-OBJ converter)"
        }
        _ => "",
    }
}

//! The in-memory scene: every mesh of a scene description imported, transformed and converted
//! once to visgate's space (right-handed, +Y up, metres).

use std::path::{Path, PathBuf};

use glam::{DMat4, DQuat, DVec3, EulerRot, Vec2, Vec3};
use serde::Serialize;

use crate::desc::UpAxis;

/// A diffuse material. The effective albedo at a point is `albedo × texture(uv)` (the
/// texture decoded from sRGB to linear), as in both MTL (`Kd` × `map_Kd`) and glTF
/// (`baseColorFactor` × `baseColorTexture`).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name in the source file.
    pub name: String,
    /// Linear diffuse albedo.
    pub albedo: Vec3,
    /// Index into [`Scene::textures`].
    pub texture: Option<u32>,
}

/// A decoded texture, RGBA8 with sRGB-encoded colour, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// The path it was read from (or its name in the glTF file).
    pub name: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 4` bytes.
    pub rgba8: Vec<u8>,
}

/// The longest side a texture keeps at import: larger ones are filtered down to it, as the GPU
/// draws them (runtime::gpu::geometry's texture array), so that the CPU reference samples what
/// the GPU methods do and a level of 4K textures does not hold gigabytes of texels (one 4096²
/// texture: 64 MiB; at 1024², 4 MiB). [Units: texels]
pub const MAX_TEXTURE_TEXELS: u32 = 1024;

impl Texture {
    /// A texture of `rgba8` (`width × height × 4` bytes), filtered (each texel the mean of the
    /// texels it covers, in their sRGB values: `image`'s thumbnail, where its triangle filter
    /// took twenty 4K textures' load from 2.9 to 5.6 s) down to [`MAX_TEXTURE_TEXELS`] on its longest side where it is larger, its
    /// aspect ratio kept; and whether it was.
    pub fn fitted(name: String, width: u32, height: u32, rgba8: Vec<u8>) -> (Texture, bool) {
        let longest = width.max(height);
        let whole = rgba8.len() == width as usize * height as usize * 4;
        if longest <= MAX_TEXTURE_TEXELS || !whole {
            let t = Texture {
                name,
                width,
                height,
                rgba8,
            };
            return (t, false);
        }
        let image = image::RgbaImage::from_raw(width, height, rgba8)
            .expect("a buffer of width × height × 4 bytes is an image");
        let scale = f64::from(MAX_TEXTURE_TEXELS) / f64::from(longest);
        let fit =
            |side: u32| ((f64::from(side) * scale).round() as u32).clamp(1, MAX_TEXTURE_TEXELS);
        let (w, h) = (fit(width), fit(height));
        let small = image::imageops::thumbnail(&image, w, h);
        let t = Texture {
            name,
            width: w,
            height: h,
            rgba8: small.into_raw(),
        };
        (t, true)
    }
}

/// One triangle mesh in world space.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Object/group name (OBJ) or node/mesh name (glTF).
    pub name: String,
    /// Index of the scene description's `[[mesh]]` entry it came from.
    pub entry: usize,
    /// Static meshes are baked and occlude; dynamic meshes are only lit.
    pub is_static: bool,
    /// Vertex positions, metres.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals (face normals where the file has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (zero where the file has none).
    pub uvs: Vec<Vec2>,
    /// Counter-clockwise vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Material of each triangle, an index into [`Scene::materials`].
    pub material: Vec<u32>,
}

/// A primary light, in world space.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// Position, metres.
        position: Vec3,
        /// Radiant intensity, W/sr per RGB channel.
        intensity: Vec3,
    },
    /// Spot light: full intensity within `beam_rad` of the axis, linear in angle to 0 at
    /// `cutoff_rad` (Mitsuba's `spot`).
    Spot {
        /// Position, metres.
        position: Vec3,
        /// Unit axis direction.
        direction: Vec3,
        /// Radiant intensity on the axis, W/sr per RGB channel.
        intensity: Vec3,
        /// Half-angle where the intensity reaches 0, radians.
        cutoff_rad: f32,
        /// Half-angle of full intensity, radians.
        beam_rad: f32,
    },
}

impl Light {
    /// Where the light is. [Units: m]
    pub fn position(&self) -> Vec3 {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => position,
        }
    }
}

/// A look-at camera, in world space.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Camera {
    /// Name used by `--camera`.
    pub name: String,
    /// Eye position, metres.
    pub eye: Vec3,
    /// Point looked at, metres.
    pub target: Vec3,
    /// Unit up vector.
    pub up: Vec3,
    /// Full horizontal field of view, radians.
    pub fov_x_rad: f32,
}

/// What the import saw and did, for reports.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ImportReport {
    /// Triangles in the files after triangulation of polygons (convex ones fanned, concave
    /// ones ear-clipped: `crate::polygons`).
    pub triangles_read: u64,
    /// An OBJ's concave polygons, ear-clipped (a fan from a corner would cover their notches).
    pub concave_polygons: u64,
    /// Zero-area triangles dropped.
    pub degenerate_dropped: u64,
    /// Textures that failed to load (their materials fall back to the albedo).
    pub textures_failed: u64,
    /// Textures larger than [`MAX_TEXTURE_TEXELS`] filtered down to it ([`Texture::fitted`]).
    pub textures_fitted: u64,
    /// Every warning, in order.
    pub warnings: Vec<String>,
    /// Indices of the materials that glow (an OBJ's `Ke`, a glTF's emissive factor): no light
    /// in visgate, but where a bare mesh's lamps are (`visgate_scenes::bare`).
    pub glowing_materials: Vec<u32>,
    /// Wall-clock time of the whole load, seconds.
    pub load_seconds: f64,
}

/// A scene ready for baking and rendering.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Display name.
    pub name: String,
    /// The file it was loaded from (the TOML, or the bare mesh file), if any.
    pub source: Option<PathBuf>,
    /// Whether the level is meant to be sealed.
    pub closed: bool,
    /// Meshes in world space.
    pub meshes: Vec<Mesh>,
    /// Materials of all meshes.
    pub materials: Vec<Material>,
    /// Decoded textures.
    pub textures: Vec<Texture>,
    /// Primary lights.
    pub lights: Vec<Light>,
    /// Named cameras.
    pub cameras: Vec<Camera>,
    /// What the import saw.
    pub report: ImportReport,
    /// How its dynamic meshes and lights move ([`Scene::at`] poses it).
    pub animation: Animation,
}

/// The motion of a scene's dynamic meshes and lights, in world space.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Animation {
    /// Moving `[[mesh]]` entries.
    pub meshes: Vec<MeshTrack>,
    /// Moving lights.
    pub lights: Vec<LightTrack>,
}

/// How one `[[mesh]]` entry moves: its world transform at time t against the one it was
/// imported with.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshTrack {
    /// The `[[mesh]]` entry (every [`Mesh`] with this `entry` moves).
    pub entry: usize,
    /// File space to world.
    pub(crate) space: DMat4,
    /// The entry's scale.
    pub(crate) scale: DVec3,
    /// Its rotation when not keyframed, degrees.
    pub(crate) rotate_deg: DVec3,
    /// World transform at rest (the imported geometry's).
    pub(crate) rest: DMat4,
    /// Keys (t, translation, rotation in degrees), file units.
    pub(crate) keys: Vec<(f64, DVec3, DVec3)>,
    /// Or a circle (file units).
    pub(crate) orbit: Option<crate::desc::Orbit>,
    /// The file's up axis (the orbit's axis).
    pub(crate) up: UpAxis,
}

/// How one light moves.
#[derive(Debug, Clone, PartialEq)]
pub struct LightTrack {
    /// Index into [`Scene::lights`].
    pub light: usize,
    /// File space to world.
    pub(crate) space: SceneSpace,
    /// Keys (t, position, target), file units.
    pub(crate) keys: Vec<(f64, DVec3, Option<DVec3>)>,
    /// Or a circle (file units).
    pub(crate) orbit: Option<crate::desc::Orbit>,
    /// A spot's fixed target (file units): it re-aims as it moves.
    pub(crate) target: Option<DVec3>,
    /// The file's up axis.
    pub(crate) up: UpAxis,
}

/// A point on an orbit at time t, file units.
fn orbit_point(o: &crate::desc::Orbit, up: UpAxis, t: f64) -> DVec3 {
    let phi = std::f64::consts::TAU * t / o.period_s + o.phase_deg.to_radians();
    let (c, s) = (phi.cos() * o.radius, phi.sin() * o.radius);
    DVec3::from(o.centre)
        + match up {
            UpAxis::Y => DVec3::new(c, 0.0, s),
            UpAxis::Z => DVec3::new(c, s, 0.0),
        }
}

/// Linear interpolation of keyed values at t, held before the first and after the last key.
fn sample<T: Copy>(keys: &[(f64, T)], t: f64, lerp: impl Fn(T, T, f64) -> T) -> Option<T> {
    let first = keys.first()?;
    if t <= first.0 {
        return Some(first.1);
    }
    for w in keys.windows(2) {
        if t <= w[1].0 {
            return Some(lerp(w[0].1, w[1].1, (t - w[0].0) / (w[1].0 - w[0].0)));
        }
    }
    keys.last().map(|k| k.1)
}

impl MeshTrack {
    /// World transform of the entry at time t.
    pub fn world(&self, t: f64) -> DMat4 {
        let (translate, rotate) = match &self.orbit {
            Some(o) => (orbit_point(o, self.up, t), self.rotate_deg),
            None => {
                let keys: Vec<(f64, (DVec3, DVec3))> =
                    self.keys.iter().map(|&(k, a, b)| (k, (a, b))).collect();
                sample(&keys, t, |a, b, u| (a.0.lerp(b.0, u), a.1.lerp(b.1, u)))
                    .unwrap_or((DVec3::ZERO, self.rotate_deg))
            }
        };
        self.space * local_matrix(self.scale, rotate, translate)
    }
}

impl LightTrack {
    /// Position (world) and, for a spot, its axis (world) at time t.
    pub fn pose(&self, t: f64) -> (Vec3, Option<Vec3>) {
        let (pos, target) = match &self.orbit {
            Some(o) => (orbit_point(o, self.up, t), self.target),
            None => {
                // A key without a target keeps the spot's own.
                let keys: Vec<(f64, (DVec3, Option<DVec3>))> = self
                    .keys
                    .iter()
                    .map(|&(k, p, q)| (k, (p, q.or(self.target))))
                    .collect();
                sample(&keys, t, |a, b, u| {
                    let q = match (a.1, b.1) {
                        (Some(x), Some(y)) => Some(x.lerp(y, u)),
                        (x, y) => x.or(y),
                    };
                    (a.0.lerp(b.0, u), q)
                })
                .map(|(p, q)| (p, q.or(self.target)))
                .unwrap_or((DVec3::ZERO, self.target))
            }
        };
        let axis = target
            .filter(|q| *q != pos)
            .map(|q| self.space.direction(q - pos));
        (self.space.point(pos.to_array()), axis)
    }
}

/// A `[[mesh]]` entry's local transform: scale, then Euler rotation (X, then Y, then Z), then
/// translation.
pub(crate) fn local_matrix(scale: DVec3, rotate_deg: DVec3, translate: DVec3) -> DMat4 {
    DMat4::from_scale_rotation_translation(
        scale,
        DQuat::from_euler(
            EulerRot::ZYX,
            rotate_deg.z.to_radians(),
            rotate_deg.y.to_radians(),
            rotate_deg.x.to_radians(),
        ),
        translate,
    )
}

/// The kind of file a scene argument names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A scene description (`.toml`).
    SceneToml,
    /// A Wavefront OBJ mesh.
    Obj,
    /// A glTF 2.0 file, text (`.gltf`) or binary (`.glb`).
    Gltf,
    /// A baked visgate level.
    Vgate,
}

impl FileKind {
    /// Guesses the kind from the file extension (case-insensitive).
    pub fn of(path: &Path) -> Option<FileKind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "toml" => Some(FileKind::SceneToml),
            "obj" => Some(FileKind::Obj),
            "gltf" | "glb" => Some(FileKind::Gltf),
            "vgate" => Some(FileKind::Vgate),
            _ => None,
        }
    }
}

impl Scene {
    /// Whether it was loaded from a bare mesh file (OBJ, glTF, GLB), not a scene TOML or a
    /// built-in: its units and up axis were chosen at load (`--metres-per-unit`, `--up`).
    pub fn is_bare_mesh(&self) -> bool {
        self.source
            .as_deref()
            .and_then(FileKind::of)
            .is_some_and(|k| matches!(k, FileKind::Obj | FileKind::Gltf))
    }

    /// Whether anything moves.
    pub fn is_animated(&self) -> bool {
        !self.animation.meshes.is_empty() || !self.animation.lights.is_empty()
    }

    /// The scene at time `t` (seconds): dynamic meshes and lights where their keyframes or
    /// orbits put them. Static meshes never move, so the static-geometry hash stays.
    pub fn at(&self, t: f64) -> Scene {
        let mut out = self.clone();
        for track in &self.animation.meshes {
            let delta = track.world(t) * track.rest.inverse();
            let normal_m = delta.inverse().transpose();
            for m in out.meshes.iter_mut().filter(|m| m.entry == track.entry) {
                for p in &mut m.positions {
                    *p = delta.transform_point3(p.as_dvec3()).as_vec3();
                }
                for n in &mut m.normals {
                    *n = normal_m
                        .transform_vector3(n.as_dvec3())
                        .normalize_or_zero()
                        .as_vec3();
                }
            }
        }
        for track in &self.animation.lights {
            let (pos, axis) = track.pose(t);
            match out.lights.get_mut(track.light) {
                Some(Light::Point { position, .. }) => *position = pos,
                Some(Light::Spot {
                    position,
                    direction,
                    ..
                }) => {
                    *position = pos;
                    if let Some(a) = axis {
                        *direction = a;
                    }
                }
                None => {}
            }
        }
        out
    }

    /// Triangles of all meshes.
    pub fn triangle_count(&self) -> u64 {
        self.meshes.iter().map(|m| m.triangles.len() as u64).sum()
    }

    /// Triangles of the static meshes only.
    pub fn static_triangle_count(&self) -> u64 {
        self.meshes
            .iter()
            .filter(|m| m.is_static)
            .map(|m| m.triangles.len() as u64)
            .sum()
    }

    /// Axis-aligned bounds of all vertices, metres; `None` for a scene with no vertex.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_of(self.meshes.iter())
    }

    /// The diagonal of [`Scene::bounds`] (1 for a scene of no vertices), at least 1e-6: the
    /// length the renderer's near and far planes and LightCluster's light ranges follow.
    /// [Units: m]
    pub fn diagonal_m(&self) -> f32 {
        self.bounds()
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(1.0)
            .max(1e-6)
    }

    /// Axis-aligned bounds of the static meshes' vertices, metres.
    pub fn static_bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_of(self.meshes.iter().filter(|m| m.is_static))
    }

    /// Every static triangle as three world-space corners, in scene order.
    pub fn static_triangles(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.meshes.iter().filter(|m| m.is_static).flat_map(|m| {
            m.triangles.iter().map(move |t| {
                [
                    m.positions[t[0] as usize],
                    m.positions[t[1] as usize],
                    m.positions[t[2] as usize],
                ]
            })
        })
    }

    /// A hash of the static geometry (world-space corners of every static triangle, in
    /// order): a baked file records it, and the runtime refuses a file whose hash differs.
    pub fn static_geometry_hash(&self) -> GeometryHash {
        let mut h = xxhash_rust::xxh3::Xxh3::new();
        let mut buf = Vec::with_capacity(36 * 1024);
        for tri in self.static_triangles() {
            for p in tri {
                for c in p.to_array() {
                    buf.extend_from_slice(&c.to_le_bytes());
                }
            }
            if buf.len() >= 36 * 1024 {
                h.update(&buf);
                buf.clear();
            }
        }
        h.update(&buf);
        GeometryHash(h.digest128().to_le_bytes())
    }

    /// The camera with this name.
    pub fn camera(&self, name: &str) -> Option<&Camera> {
        self.cameras.iter().find(|c| c.name == name)
    }
}

fn bounds_of<'a>(meshes: impl Iterator<Item = &'a Mesh>) -> Option<(Vec3, Vec3)> {
    points_bounds(meshes.flat_map(|m| m.positions.iter().copied()))
}

/// Axis-aligned bounds of `points`; `None` for none.
pub(crate) fn points_bounds(points: impl Iterator<Item = Vec3>) -> Option<(Vec3, Vec3)> {
    let mut it = points.peekable();
    let first = *it.peek()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

pub(crate) fn parent_dir(path: &Path) -> PathBuf {
    path.parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// 128-bit hash of a scene's static geometry (xxh3-128, little-endian bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct GeometryHash(pub [u8; 16]);

impl std::fmt::Display for GeometryHash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for b in self.0.iter().rev() {
            write!(f, "{b:02x}")?;
        }
        Ok(())
    }
}

/// The conversion from a scene file's space (its up axis and unit) to visgate's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSpace {
    /// The affine map from file coordinates to metres, +Y up.
    pub matrix: DMat4,
}

impl SceneSpace {
    /// The conversion for a file with this up axis and metres per unit.
    pub fn new(up: UpAxis, metres_per_unit: f64) -> Self {
        let axes = match up {
            UpAxis::Y => DMat4::IDENTITY,
            // (x, y, z) → (x, z, −y): a rotation by −90° about X, so handedness is kept.
            UpAxis::Z => DMat4::from_cols(
                glam::DVec4::new(1.0, 0.0, 0.0, 0.0),
                glam::DVec4::new(0.0, 0.0, -1.0, 0.0),
                glam::DVec4::new(0.0, 1.0, 0.0, 0.0),
                glam::DVec4::W,
            ),
        };
        SceneSpace {
            matrix: DMat4::from_scale(DVec3::splat(metres_per_unit)) * axes,
        }
    }

    /// A point in file coordinates, in metres, +Y up.
    pub fn point(&self, p: [f64; 3]) -> Vec3 {
        self.matrix.transform_point3(DVec3::from(p)).as_vec3()
    }

    /// A direction in file coordinates, as a unit vector, +Y up.
    pub fn direction(&self, d: DVec3) -> Vec3 {
        self.matrix
            .transform_vector3(d)
            .normalize_or_zero()
            .as_vec3()
    }
}

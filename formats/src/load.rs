//! Loading a scene: a scene TOML (its meshes imported and assembled: transforms, up axis,
//! units, material overrides, animation tracks) or a bare mesh file. The one module that uses
//! both the scene types (`scene`) and the importers (`import`), so neither depends on the
//! other's loading.

use std::path::Path;
use std::time::Instant;

use glam::DVec3;

use crate::desc::{SceneDesc, UpAxis};
use crate::error::SceneError;
use crate::import::{self, ImportOptions, ImportedModel};
use crate::room_height::{RoomHeight, room_height};
use crate::scene::{FileKind, Scene, parent_dir};
use crate::stray::{Stray, leave_out_strays};

/// The longest a bare mesh may be, read in metres, before it is read in smaller units
/// ([`bare_mesh_units`]): longer than any indoor level. [Units: m]
pub const BARE_LEVEL_MAX_M: f64 = 1000.0;

/// A bare mesh read in metres and longer than this gets a note that it may be modelled in
/// centimetres (a two-room level of 800 cm whose rooms' height is not measured — no ceilings
/// — reads as 800 m): most indoor levels are shorter.
/// [Units: m]
pub const BARE_LEVEL_NOTE_M: f64 = 200.0;

/// A bare mesh read in metres and shorter than this gets a note that it may be modelled in
/// larger units or scaled down on export (a two-room level of 8 m written as 0.08): no room is
/// this small. [Units: m]
pub const BARE_LEVEL_SMALL_M: f64 = 1.0;

/// Metres per unit of a bare mesh (no scene file, so no stated units) whose longest extent is
/// `longest` of its units: metres, unless that makes a level longer than [`BARE_LEVEL_MAX_M`];
/// then centimetres (Crytek Sponza's OBJ and GLB, Unreal, Maya and 3ds Max exports), or
/// millimetres where centimetres still do (a level under 100 m modelled in millimetres is
/// read in centimetres, 10× too large, unless its rooms' height says millimetres:
/// [`bare_mesh_units_with_rooms`]; the warning says which units were read). glTF states
/// metres, but exporters write centimetres there too, so a glTF file is read the same way. A
/// scene TOML's `metres_per_unit` chooses.
pub fn bare_mesh_units(longest: f64) -> f64 {
    [1.0, 0.01]
        .into_iter()
        .find(|m| longest * m <= BARE_LEVEL_MAX_M)
        .unwrap_or(0.001)
}

/// Room heights (floor to ceiling, [`crate::room_height`]) a level's units must give before
/// they replace the units its extent chose ([`bare_mesh_units_with_rooms`]): a house's,
/// an office's, a Quake corridor's, the Cornell box's 1.99 m. [Units: m]
pub const ROOM_TYPICAL_M: (f64, f64) = (1.9, 6.0);

/// Room heights that keep the units a level's extent chose: from a low cellar to a hall
/// (Crytek Sponza's arcades stand 7 m, a nave 20 m). [Units: m]
pub const ROOM_PLAUSIBLE_M: (f64, f64) = (1.9, 20.0);

/// The units a bare mesh's rooms may choose over its extent ([`bare_mesh_units_with_rooms`]),
/// in the order tried: centimetres, inches, millimetres. Centimetres before inches: rooms of
/// 190–236 units are 1.9–2.4 m in centimetres and 4.8–6.0 m in inches, and a low room is
/// likelier than a tall one; below 190 units only inches make a room (an 8 ft ceiling, 96
/// units, is 0.96 m in centimetres). [Units: metres per unit]
pub const ROOM_UNITS: [f64; 3] = [0.01, 0.0254, 0.001];

/// Metres per unit of a bare mesh whose longest extent is `longest` of its units and whose
/// rooms stand `rooms` of them floor to ceiling (`None`: not measured, a level under the open
/// sky): [`bare_mesh_units`], unless that makes its rooms implausible
/// ([`ROOM_PLAUSIBLE_M`]) and another of [`ROOM_UNITS`], the first that does and keeps the
/// level under [`BARE_LEVEL_MAX_M`], makes them typical ([`ROOM_TYPICAL_M`]): a 9 m apartment
/// in millimetres, read in centimetres by its extent, has rooms 27 m high, and in millimetres
/// 2.7 m; an 8 m level in centimetres, read in metres, 270 m and 2.7 m; a house in inches
/// (3ds Max, SketchUp), 96 units floor to ceiling, 96 m in metres and 2.44 m in inches. A
/// level whose rooms no unit makes typical keeps its extent's unit (a level in centimetres
/// under a sky box 100 m above its floor: 10 m in millimetres, no room's height either).
pub fn bare_mesh_units_with_rooms(longest: f64, rooms: Option<f64>) -> f64 {
    let by_extent = bare_mesh_units(longest);
    let within = |h: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&h);
    match rooms {
        Some(h) if !within(h * by_extent, ROOM_PLAUSIBLE_M) => ROOM_UNITS
            .into_iter()
            .filter(|&m| m != by_extent && longest * m <= BARE_LEVEL_MAX_M)
            .find(|&m| within(h * m, ROOM_TYPICAL_M))
            .unwrap_or(by_extent),
        _ => by_extent,
    }
}

/// The name of the unit `metres_per_unit` is, where it is one of the three a bare mesh is read
/// in.
fn unit_name(metres_per_unit: f64) -> &'static str {
    match metres_per_unit {
        1.0 => "metres",
        0.01 => "centimetres",
        0.0254 => "inches",
        _ => "millimetres",
    }
}

/// The size of the box around every finite vertex of `models`, in their own units and axes
/// (`None`: no finite vertex).
fn vertex_extent(models: &[ImportedModel]) -> Option<DVec3> {
    let mut points = models
        .iter()
        .flat_map(|m| &m.meshes)
        .flat_map(|m| &m.positions)
        .filter(|p| p.is_finite());
    let first = *points.next()?;
    let (lo, hi) = points.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    Some((hi - lo).as_dvec3())
}

/// The longest side of the box around every vertex of `models`, in their own units (`None`:
/// no finite vertex).
fn longest_extent(models: &[ImportedModel]) -> Option<f64> {
    vertex_extent(models).map(|e| e.max_element())
}

/// How a bare mesh file (no scene TOML) is read where the user says it (`visgate --up z
/// --metres-per-unit 0.001 …`); what is left `None` is chosen from the mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BareMesh {
    /// Metres per unit of the file; `None`: [`bare_mesh_units`].
    pub metres_per_unit: Option<f64>,
    /// The axis that points up; `None`: +Y for glTF (its convention), [`bare_mesh_up`] for OBJ.
    pub up: Option<UpAxis>,
    /// Keep the triangles far from the rest ([`crate::stray::leave_out_strays`] leaves them
    /// out otherwise).
    pub keep_far: bool,
}

impl BareMesh {
    /// Whether the user said anything.
    pub fn is_set(&self) -> bool {
        self.metres_per_unit.is_some() || self.up.is_some() || self.keep_far
    }
}

/// Leaves the objects that mesh entry `m` names in `leave_out` out of its import `model`; an
/// error that lists the file's objects where a name is none of them.
fn leave_out_objects(
    file: &Path,
    m: &crate::desc::MeshDesc,
    model: &mut ImportedModel,
) -> Result<(), SceneError> {
    let named = |n: &String| model.meshes.iter().any(|r| &r.name == n);
    if let Some(missing) = m.leave_out.iter().find(|n| !named(n)) {
        let mut names: Vec<String> = Vec::new();
        for r in &model.meshes {
            if !names.contains(&r.name) {
                names.push(r.name.clone());
            }
        }
        let shown: Vec<String> = names.iter().take(12).map(|n| format!("'{n}'")).collect();
        let more = names.len().saturating_sub(shown.len());
        return Err(SceneError::Invalid {
            file: file.to_path_buf(),
            what: format!(
                "mesh '{}': leave_out names '{missing}', which is no object of the file; its \
                 objects are {}{}",
                m.path.display(),
                shown.join(", "),
                if more > 0 {
                    format!(" and {more} more")
                } else {
                    String::new()
                }
            ),
        });
    }
    model.meshes.retain(|r| !m.leave_out.contains(&r.name));
    Ok(())
}

/// What a user reads when a bare mesh's stray triangles `s` (in the file's units, now read as
/// `metres_per_unit`) were left out of it.
fn strays_note(path: &Path, s: &Stray, metres_per_unit: f64) -> String {
    let m = metres_per_unit as f32;
    format!(
        "{}: {} in the file, {:.1} m from the rest's bounds: left out of the level. With them it \
         would be {:.1} m long where the rest is {:.2} m, and the bake's voxels {:.0}× as large \
         as the rest needs. A sky box, a helper object left in the export, a vertex in the wrong \
         place? To keep them, pass --keep-far (or name the mesh in a scene TOML, which keeps \
         every triangle)",
        path.display(),
        s.said("its", "triangles"),
        s.distance_m * m,
        s.longest_m() * m,
        s.rest_longest_m() * m,
        s.growth(),
    )
}

/// How much more of the triangles' area must face ±Z than ±Y, and how much lower the level
/// must be along Z than along Y, before a bare OBJ is read Z up. [Units: ratio]
const Z_UP_AREA_RATIO: f64 = 1.0;
/// See [`Z_UP_AREA_RATIO`]. [Units: ratio]
const Z_UP_EXTENT_RATIO: f64 = 0.8;

/// Each axis's share of the triangles' area, weighted by how squarely they face it (Σ area ·
/// n_k², normalised), in the file's axes (`None`: no area).
fn facing_shares(models: &[ImportedModel]) -> Option<DVec3> {
    let mut facing = DVec3::ZERO;
    for mesh in models.iter().flat_map(|m| &m.meshes) {
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            // |n| is twice the area; area · n̂² = n² / (2 |n|).
            let len = n.length();
            if len > 0.0 && len.is_finite() {
                facing += n * n / (2.0 * len);
            }
        }
    }
    let total = facing.element_sum();
    (total > 0.0).then(|| facing / total)
}

/// Above this share of ±Y's area facing ±Z a bare OBJ read +Y up gets a note that it may lie
/// on its side (a Cornell box, a cube, has 1.006). [Units: ratio]
const SIDE_NOTE_AREA_RATIO: f64 = 1.05;

/// The up axis of a bare OBJ, which states none: +Z where more of its area faces ±Z than ±Y
/// (floors and ceilings face up and down) and it is lower along Z than along Y (levels are
/// wider than tall), else +Y, visgate's and most exporters' convention. A cube of a room reads
/// +Y. Returns the axis and what a user should read: why Z, or, read Y up where the area
/// alone says Z, that it may lie on its side.
pub fn bare_mesh_up(models: &[ImportedModel]) -> (UpAxis, Option<String>) {
    let (Some(facing), Some(extent)) = (facing_shares(models), vertex_extent(models)) else {
        return (UpAxis::Y, None);
    };
    let areas = format!(
        "{:.0} % of its area faces ±z against {:.0} % ±y",
        100.0 * facing[2],
        100.0 * facing[1]
    );
    let (by_area, lower) = (
        facing[2] > Z_UP_AREA_RATIO * facing[1],
        extent[2] < Z_UP_EXTENT_RATIO * extent[1],
    );
    if by_area && lower {
        let why = format!(
            "read Z up ({areas}, and it is {:.2} of its y extent high along z)",
            extent[2] / extent[1]
        );
        (UpAxis::Z, Some(why))
    } else if facing[2] > SIDE_NOTE_AREA_RATIO * facing[1] {
        let why = format!(
            "read Y up, though {areas}: if it lies on its side (floors as walls), it is Z up"
        );
        (UpAxis::Y, Some(why))
    } else {
        (UpAxis::Y, None)
    }
}

/// What a user reads when a bare mesh is not read in metres.
fn units_warning(path: &Path, longest: f64, metres_per_unit: f64) -> String {
    let (unit, or_mm) = if metres_per_unit == 0.01 {
        // Where its rooms measure none: a 9 m apartment modelled in millimetres then reads as
        // 90 m, as a 90 m Unreal level does.
        let mm = format!(
            " (in millimetres it would be a {:.1} m level)",
            longest * 0.001
        );
        ("centimetres", mm)
    } else {
        ("millimetres", String::new())
    };
    format!(
        "{}: a bare mesh states no units, and in metres its longest side ({longest:.0} units) \
         would make a {:.1} km level: read in {unit} ({:.1} m){or_mm}. To choose the units, \
         pass --metres-per-unit (0.01 centimetres, 0.0254 inches, 0.001 millimetres) or name \
         the mesh in a scene TOML with `metres_per_unit` (README, Scenes)",
        path.display(),
        longest / 1000.0,
        longest * metres_per_unit,
    )
}

/// What a user reads when a bare mesh's rooms chose its units over its extent.
fn rooms_warning(
    path: &Path,
    longest: f64,
    rooms: &RoomHeight,
    by_extent: f64,
    chosen: f64,
) -> String {
    format!(
        "{}: a bare mesh states no units; its rooms stand {:.0} units floor to ceiling (the \
         median over {} columns of its footprint), which in {} would make them {:.*} m high: \
         read in {} (rooms {:.2} m high, the level {:.1} m long). To choose the units, pass \
         --metres-per-unit (0.01 centimetres, 0.0254 inches, 0.001 millimetres) or name the \
         mesh in a scene TOML with `metres_per_unit` (README, Scenes)",
        path.display(),
        rooms.median,
        rooms.columns,
        unit_name(by_extent),
        // Two decimals under 10 m: 0.96 m in centimetres is no room, where "1.0 m" would hide it.
        if rooms.median * by_extent < 10.0 {
            2
        } else {
            1
        },
        rooms.median * by_extent,
        unit_name(chosen),
        rooms.median * chosen,
        longest * chosen,
    )
}

/// What a user reads when a bare mesh read in metres is longer than [`BARE_LEVEL_NOTE_M`].
fn metres_note(path: &Path, longest: f64) -> String {
    format!(
        "{}: a bare mesh states no units; read in metres, its longest side makes a {longest:.0} m \
         level, longer than most indoor levels. If it is modelled in centimetres (a {:.1} m \
         level) or inches ({:.1} m), pass --metres-per-unit 0.01 or 0.0254, or name the mesh in \
         a scene TOML with `metres_per_unit` (README, Scenes)",
        path.display(),
        longest * 0.01,
        longest * 0.0254,
    )
}

/// What a user reads when a bare mesh read in metres is shorter than [`BARE_LEVEL_SMALL_M`].
fn small_note(path: &Path, longest: f64) -> String {
    format!(
        "{}: a bare mesh states no units; read in metres, its longest side makes a {longest:.3} \
         m level, smaller than any room. If it was scaled down on export or is modelled in \
         larger units (× 100: a {:.1} m level; × 10, decimetres: {:.2} m), pass \
         --metres-per-unit 100 or 10, or name the mesh in a scene TOML with `metres_per_unit` \
         (README, Scenes)",
        path.display(),
        longest * 100.0,
        longest * 10.0,
    )
}

/// A bare mesh's units from its extent and its rooms (`desc.up` read already); the note a user
/// should read of them.
fn choose_units(
    desc: &mut SceneDesc,
    models: &[ImportedModel],
    path: &Path,
    longest: f64,
) -> Option<String> {
    let rooms = room_height(models, desc.up);
    let by_extent = bare_mesh_units(longest);
    desc.metres_per_unit = bare_mesh_units_with_rooms(longest, rooms.map(|r| r.median));
    let m = desc.metres_per_unit;
    match rooms {
        Some(r) if m != by_extent => Some(rooms_warning(path, longest, &r, by_extent, m)),
        _ if m != 1.0 => Some(units_warning(path, longest, m)),
        _ if longest > BARE_LEVEL_NOTE_M => Some(metres_note(path, longest)),
        _ if longest < BARE_LEVEL_SMALL_M => Some(small_note(path, longest)),
        _ => None,
    }
}

/// What a user reads when the up axis of a bare OBJ is in doubt or Z.
fn up_warning(path: &Path, why: &str) -> String {
    format!(
        "{}: a bare OBJ states no up axis; {why}. To choose, pass --up y or --up z, or name the \
         mesh in a scene TOML with `up` (README, Scenes)",
        path.display()
    )
}

/// A bare mesh's units and up axis: the user's where given, else chosen from `models`; the
/// warnings for what was chosen that a user may not expect.
fn read_bare(
    desc: &mut SceneDesc,
    models: &[ImportedModel],
    path: &Path,
    kind: FileKind,
    said: BareMesh,
) -> Vec<String> {
    let mut notes = Vec::new();
    // The up axis first: the rooms' height, which the units may come from, is along it.
    desc.up = match (said.up, kind) {
        (Some(up), _) => up,
        (None, FileKind::Obj) => {
            let (up, why) = bare_mesh_up(models);
            notes.extend(why.map(|why| up_warning(path, &why)));
            up
        }
        (None, _) => UpAxis::Y,
    };
    match said.metres_per_unit {
        Some(m) => desc.metres_per_unit = m,
        None => {
            if let Some(longest) = longest_extent(models) {
                notes.extend(choose_units(desc, models, path, longest));
            }
        }
    }
    for note in &notes {
        tracing::warn!("{note}");
    }
    notes
}

/// What a user reads when a scene with no light has materials that glow (logged as well).
fn glowing_warning(path: &Path, glowing: &[String]) -> Option<String> {
    let (first, more) = match glowing {
        [] => return None,
        [a] => (a.clone(), String::new()),
        [a, rest @ ..] => (a.clone(), format!(" and {} more", rest.len())),
    };
    let note = format!(
        "{}: material '{first}'{more} glows, but visgate lights by point and spot lights alone: \
         an emissive surface adds no light. Place a light at each (a [[light]] in a scene TOML, \
         or a KHR_lights_punctual light in the glTF); until then render, view and compare put \
         one in front of each glowing surface that faces one way (a closed bulb gets none)",
        path.display()
    );
    tracing::warn!("{note}");
    Some(note)
}

/// What a scene TOML leaves unread of its mesh files: the lights and cameras a glTF places
/// where the TOML states none of its own (logged as well).
fn unread_lights_and_cameras(
    desc: &SceneDesc,
    models: &[ImportedModel],
    path: &Path,
) -> Vec<String> {
    let mut notes = Vec::new();
    let (lights, cameras) = models.iter().fold((0, 0), |(l, c), m| {
        (l + m.lights.len() + m.suns.len(), c + m.cameras.len())
    });
    if desc.lights.is_empty() && lights > 0 {
        notes.push(format!(
            "{}: its mesh files place {lights} light(s), which a scene TOML does not read: state \
             them as [[light]] (a glTF given bare, without a TOML, brings its own)",
            path.display()
        ));
    }
    if desc.cameras.is_empty() && cameras > 0 {
        notes.push(format!(
            "{}: its mesh files place {cameras} camera(s), which a scene TOML does not read: \
             state them as [[camera]] (a glTF given bare, without a TOML, brings its own)",
            path.display()
        ));
    }
    for note in &notes {
        tracing::warn!("{note}");
    }
    notes
}

impl Scene {
    /// Loads a scene TOML, or a bare OBJ/glTF/GLB file as one static mesh with no lights, in
    /// the units [`bare_mesh_units_with_rooms`] picks from its size and its rooms.
    pub fn load(path: &Path, options: &ImportOptions) -> Result<Scene, SceneError> {
        let start = Instant::now();
        let kind = FileKind::of(path);
        let (mut desc, base, bare) = match kind {
            Some(FileKind::SceneToml) => (SceneDesc::read(path)?, parent_dir(path), false),
            Some(FileKind::Obj | FileKind::Gltf) => {
                (SceneDesc::for_mesh_file(path), parent_dir(path), true)
            }
            _ => {
                return Err(SceneError::UnknownFileType {
                    file: path.to_path_buf(),
                });
            }
        };
        if !bare && options.bare.is_set() {
            return Err(SceneError::Invalid {
                file: path.to_path_buf(),
                what: "--up, --metres-per-unit and --keep-far read a bare mesh file (OBJ, glTF, \
                       GLB); a scene TOML states its own `up` and `metres_per_unit` and keeps \
                       every triangle"
                    .into(),
            });
        }
        let mut models = desc
            .meshes
            .iter()
            .map(|m| import::import_file(&base.join(&m.path), options))
            .collect::<Result<Vec<_>, _>>()?;
        for (m, model) in desc.meshes.iter().zip(&mut models) {
            leave_out_objects(path, m, model)?;
        }
        let strays = (bare && !options.bare.keep_far)
            .then(|| leave_out_strays(&mut models))
            .flatten();
        let mut notes = match kind {
            Some(k) if bare => read_bare(&mut desc, &models, path, k, options.bare),
            _ => Vec::new(),
        };
        if let Some(s) = strays {
            let note = strays_note(path, &s, desc.metres_per_unit);
            tracing::warn!("{note}");
            notes.insert(0, note);
        }
        if bare {
            // A bare glTF file brings the lights and cameras it places (gltf_nodes.rs), its suns
            // placed as far spot lights when the scene is assembled (sun.rs).
            desc.lights = models.iter().flat_map(|m| m.lights.clone()).collect();
            desc.suns = models.iter().flat_map(|m| m.suns.clone()).collect();
            desc.cameras = models.iter().flat_map(|m| m.cameras.clone()).collect();
            desc.validate(path)?;
        } else {
            notes.extend(unread_lights_and_cameras(&desc, &models, path));
        }
        let mut scene = Scene::assemble(&desc, models, path)?;
        if scene.lights.is_empty() {
            let glowing: Vec<String> = (scene.report.glowing_materials.iter())
                .map(|&m| scene.materials[m as usize].name.clone())
                .collect();
            notes.extend(glowing_warning(path, &glowing));
        }
        scene.report.warnings.extend(notes);
        scene.report.load_seconds = start.elapsed().as_secs_f64();
        Ok(scene)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::RawMesh;
    use glam::Vec3;

    /// An open-topped box of size `s` (its floor and four walls; `lid`: its ceiling too), as
    /// one model.
    fn room(s: [f32; 3], lid: bool) -> Vec<ImportedModel> {
        let c =
            |x: u32, y: u32, z: u32| Vec3::new(x as f32 * s[0], y as f32 * s[1], z as f32 * s[2]);
        let positions: Vec<Vec3> = (0..8).map(|i| c(i & 1, (i >> 1) & 1, i >> 2)).collect();
        // Quads by corner index (bit 0 x, bit 1 y, bit 2 z): -y floor, +y lid, ±x, ±z walls.
        let mut quads = vec![
            [0, 1, 5, 4],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        if lid {
            quads.push([2, 6, 7, 3]);
        }
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        vec![ImportedModel {
            meshes: vec![RawMesh {
                name: "room".into(),
                normals: vec![Vec3::Y; 8],
                uvs: vec![glam::Vec2::ZERO; 8],
                positions,
                triangles,
                material: 0,
            }],
            ..ImportedModel::default()
        }]
    }

    #[test]
    fn a_bare_obj_is_read_z_up_only_when_its_floors_and_its_shape_both_say_so() {
        // A hall 20 × 4 × 12 written Y up, then Z up: floor and ceiling face the short axis.
        assert_eq!(
            bare_mesh_up(&room([20.0, 4.0, 12.0], true)),
            (UpAxis::Y, None)
        );
        let (up, why) = bare_mesh_up(&room([20.0, 12.0, 4.0], true));
        assert_eq!(up, UpAxis::Z);
        assert!(why.is_some_and(|w| w.contains("read Z up")));
        // A cube: nothing to tell, Y and no note.
        assert_eq!(
            bare_mesh_up(&room([5.0, 5.0, 5.0], true)),
            (UpAxis::Y, None)
        );
        // As deep along z as high along y, with no ceiling: its ±z walls outweigh its floor
        // (480 against 240 m²) but its shape says nothing: Y, with the note that it may lie on
        // its side.
        let (up, why) = bare_mesh_up(&room([20.0, 12.0, 12.0], false));
        assert_eq!(up, UpAxis::Y);
        assert!(why.is_some_and(|w| w.contains("lies on its side")));
    }
}

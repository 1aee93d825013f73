//! `visgate inspect`: summaries of scenes, meshes and baked levels, as text or JSON.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use visgate_formats::desc::UpAxis;
use visgate_formats::room_height::room_height_of;
use visgate_formats::scene::FileKind;
use visgate_formats::vgate::{BakeParams, BakedLevel, GridMeta, SectionKind};
use visgate_formats::{Light, Scene};

/// The summary of a scene, as printed and as JSON.
#[derive(Serialize)]
struct SceneSummary {
    kind: &'static str,
    name: String,
    source: Option<String>,
    meshes: usize,
    static_meshes: usize,
    dynamic_meshes: usize,
    /// The objects (meshes of one name: an OBJ's object or group, a glTF node) and their
    /// triangles, the most first: the names a scene TOML's `leave_out` takes.
    objects: Vec<(String, usize)>,
    triangles: u64,
    static_triangles: u64,
    triangles_read: u64,
    degenerate_dropped: u64,
    /// An OBJ's concave polygons, ear-clipped (visgate_formats::polygons).
    concave_polygons: u64,
    vertices: u64,
    materials: usize,
    textured_materials: usize,
    textures: usize,
    textures_failed: u64,
    /// Filtered down to `MAX_TEXTURE_TEXELS` on their longest side at load.
    textures_fitted: u64,
    point_lights: usize,
    spot_lights: usize,
    lights: Vec<Light>,
    cameras: Vec<String>,
    bounds_min_m: Option<[f32; 3]>,
    bounds_max_m: Option<[f32; 3]>,
    /// The rooms' height, floor to ceiling (visgate_formats::room_height: the median over
    /// columns of the footprint of each one's tallest free span; `None`: no room measured).
    rooms_m: Option<f64>,
    /// The columns that hold a room.
    room_columns: usize,
    closed: bool,
    static_geometry_hash: String,
    load_seconds: f64,
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct BakedSummary {
    kind: &'static str,
    file: String,
    file_bytes: u64,
    format_version: u32,
    tool_version: String,
    geometry_hash: String,
    grid: GridMeta,
    params: BakeParams,
    skeleton_nodes: usize,
    skeleton_edges: usize,
    skeleton_cycles: u64,
    segmented_nodes: usize,
    segmented_edges: usize,
    clusters: usize,
    gates: usize,
    portals: usize,
    portal_mask_cells: u64,
    voxel_cluster_bytes_per_voxel: u32,
    /// How the file stores the voxel→cluster grid ("dense" or "runs") and its bytes there.
    voxel_cluster_stored_as: &'static str,
    voxel_cluster_stored_bytes: u64,
    /// Voxels the voxelization left open (the voxel walk's grid).
    open_voxels: u64,
    /// How the file stores their bits ("dense" words or "runs") and its bytes there.
    open_voxels_stored_as: &'static str,
    open_voxels_stored_bytes: u64,
    read_seconds: f64,
}

pub fn run(arg: &str, json: bool, no_textures: bool) -> Result<()> {
    let path = Path::new(arg);
    if !arg.starts_with("builtin:") && FileKind::of(path) == Some(FileKind::Vgate) {
        return inspect_baked(path, json);
    }
    let scene = crate::load_scene(arg, !no_textures)?;
    let s = summarise(&scene);
    if json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        print_scene(&s);
    }
    Ok(())
}

fn summarise(scene: &Scene) -> SceneSummary {
    let (lo, hi) = scene.bounds().unzip();
    let rooms = room_height_of(
        || scene.static_triangles().map(|t| t.map(|p| p.as_dvec3())),
        UpAxis::Y,
    );
    SceneSummary {
        kind: "scene",
        name: scene.name.clone(),
        source: scene.source.as_ref().map(|p| p.display().to_string()),
        meshes: scene.meshes.len(),
        static_meshes: scene.meshes.iter().filter(|m| m.is_static).count(),
        dynamic_meshes: scene.meshes.iter().filter(|m| !m.is_static).count(),
        objects: objects(scene),
        triangles: scene.triangle_count(),
        static_triangles: scene.static_triangle_count(),
        triangles_read: scene.report.triangles_read,
        degenerate_dropped: scene.report.degenerate_dropped,
        concave_polygons: scene.report.concave_polygons,
        vertices: scene.meshes.iter().map(|m| m.positions.len() as u64).sum(),
        materials: scene.materials.len(),
        textured_materials: scene
            .materials
            .iter()
            .filter(|m| m.texture.is_some())
            .count(),
        textures: scene.textures.len(),
        textures_failed: scene.report.textures_failed,
        textures_fitted: scene.report.textures_fitted,
        point_lights: scene
            .lights
            .iter()
            .filter(|l| matches!(l, Light::Point { .. }))
            .count(),
        spot_lights: scene
            .lights
            .iter()
            .filter(|l| matches!(l, Light::Spot { .. }))
            .count(),
        lights: scene.lights.clone(),
        cameras: scene.cameras.iter().map(|c| c.name.clone()).collect(),
        bounds_min_m: lo.map(|v| v.to_array()),
        bounds_max_m: hi.map(|v| v.to_array()),
        rooms_m: rooms.map(|r| r.median),
        room_columns: rooms.map_or(0, |r| r.columns),
        closed: scene.closed,
        static_geometry_hash: scene.static_geometry_hash().to_string(),
        load_seconds: scene.report.load_seconds,
        warnings: scene.report.warnings.clone(),
    }
}

/// `scene`'s objects: its meshes' names, each with the triangles of the meshes of that name,
/// the most first.
fn objects(scene: &Scene) -> Vec<(String, usize)> {
    let mut out: Vec<(String, usize)> = Vec::new();
    for m in &scene.meshes {
        match out.iter_mut().find(|(name, _)| *name == m.name) {
            Some((_, n)) => *n += m.triangles.len(),
            None => out.push((m.name.clone(), m.triangles.len())),
        }
    }
    out.sort_by_key(|o| std::cmp::Reverse(o.1));
    out
}

/// Objects the text summary names.
const OBJECTS_LISTED: usize = 6;

/// Lights the text summary lists one a line.
const LIGHTS_LISTED: usize = 8;

/// One light as a line: where it is, how bright, and a spot's aim and cone.
fn light_line(l: &Light) -> String {
    match *l {
        Light::Point {
            position,
            intensity,
        } => format!(
            "point at {} m, {} W/sr",
            v3(position.to_array()),
            v3(intensity.to_array())
        ),
        Light::Spot {
            position,
            direction,
            intensity,
            cutoff_rad,
            beam_rad,
        } => format!(
            "spot  at {} m towards {}, {} W/sr, beam {:.1}°, cutoff {:.1}°",
            v3(position.to_array()),
            v3(direction.to_array()),
            v3(intensity.to_array()),
            beam_rad.to_degrees(),
            cutoff_rad.to_degrees()
        ),
    }
}

fn v3(v: [f32; 3]) -> String {
    format!("({:.3}, {:.3}, {:.3})", v[0], v[1], v[2])
}

fn print_scene(s: &SceneSummary) {
    println!("scene       {}", s.name);
    if let Some(src) = &s.source {
        println!("source      {src}");
    }
    println!(
        "meshes      {} ({} static, {} dynamic)",
        s.meshes, s.static_meshes, s.dynamic_meshes
    );
    let named: Vec<String> = (s.objects.iter().take(OBJECTS_LISTED))
        .map(|(name, n)| format!("'{name}' {n}"))
        .collect();
    let more = s.objects.len().saturating_sub(OBJECTS_LISTED);
    println!(
        "objects     {}: {}{} (triangles; a scene TOML's leave_out takes these names)",
        s.objects.len(),
        named.join(", "),
        if more > 0 {
            format!(", and {more} more")
        } else {
            String::new()
        }
    );
    println!(
        "triangles   {} ({} static); {} read, {} degenerate dropped{}",
        s.triangles,
        s.static_triangles,
        s.triangles_read,
        s.degenerate_dropped,
        match s.concave_polygons {
            0 => String::new(),
            n => format!("; {n} concave polygons ear-clipped"),
        }
    );
    println!("vertices    {}", s.vertices);
    println!(
        "materials   {} ({} textured); textures {} loaded, {} failed{}",
        s.materials,
        s.textured_materials,
        s.textures,
        s.textures_failed,
        match s.textures_fitted {
            0 => String::new(),
            n => format!(
                ", {n} filtered down to {} texels on their longest side",
                visgate_formats::scene::MAX_TEXTURE_TEXELS
            ),
        }
    );
    println!(
        "lights      {} point, {} spot",
        s.point_lights, s.spot_lights
    );
    for l in s.lights.iter().take(LIGHTS_LISTED) {
        println!("  {}", light_line(l));
    }
    if s.lights.len() > LIGHTS_LISTED {
        println!(
            "  … and {} more (--json lists them all)",
            s.lights.len() - LIGHTS_LISTED
        );
    }
    println!(
        "cameras     {}",
        if s.cameras.is_empty() {
            "none".to_string()
        } else {
            s.cameras.join(", ")
        }
    );
    if let (Some(lo), Some(hi)) = (s.bounds_min_m, s.bounds_max_m) {
        let size = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        println!(
            "bounds      {} .. {} m (size {} m)",
            v3(lo),
            v3(hi),
            v3(size)
        );
    }
    match s.rooms_m {
        Some(h) => println!(
            "rooms       {h:.2} m floor to ceiling (the median of {} columns' tallest free span)",
            s.room_columns
        ),
        None => println!("rooms       none measured (too few floors under a ceiling)"),
    }
    println!("closed      {}", if s.closed { "yes" } else { "no" });
    println!("static hash {}", s.static_geometry_hash);
    println!("load time   {:.3} s", s.load_seconds);
    if !s.warnings.is_empty() {
        println!("warnings    {}", s.warnings.len());
        for w in &s.warnings {
            println!("  - {w}");
        }
    }
}

fn inspect_baked(path: &Path, json: bool) -> Result<()> {
    let start = std::time::Instant::now();
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let level = BakedLevel::from_bytes(&bytes)
        .with_context(|| format!("{}: cannot load the baked level", path.display()))?;
    let read_seconds = start.elapsed().as_secs_f64();
    let t = &level.topology;
    let sections = BakedLevel::read_header(&bytes)?.sections;
    let stored = |kinds: [SectionKind; 2]| {
        sections
            .iter()
            .find_map(|s| {
                let how = if s.kind == kinds[0] { "dense" } else { "runs" };
                kinds.contains(&s.kind).then_some((how, s.len))
            })
            .unwrap_or(("absent", 0))
    };
    let (stored_as, stored_bytes) =
        stored([SectionKind::VoxelCluster, SectionKind::VoxelClusterRuns]);
    let (open_stored_as, open_stored_bytes) =
        stored([SectionKind::OpenVoxels, SectionKind::OpenVoxelRuns]);
    let s = BakedSummary {
        kind: "baked level",
        file: path.display().to_string(),
        file_bytes: bytes.len() as u64,
        // The file's own, not the build's (from_bytes read it).
        format_version: visgate_formats::vgate::stated_version(&bytes).unwrap_or(0),
        tool_version: level.info.tool_version.clone(),
        geometry_hash: level.info.geometry_hash.to_string(),
        grid: level.info.grid,
        params: level.info.params.clone(),
        skeleton_nodes: t.skeleton.nodes.len(),
        skeleton_edges: t.skeleton.edges.len(),
        skeleton_cycles: level.skeleton_cycles(),
        segmented_nodes: t.segmented.nodes.len(),
        segmented_edges: t.segmented.edges.len(),
        clusters: t.clusters.len(),
        gates: t.gates.len(),
        portals: t.portals.len(),
        portal_mask_cells: t
            .portals
            .iter()
            .map(|p| u64::from(p.size[0]) * u64::from(p.size[1]))
            .sum(),
        voxel_cluster_bytes_per_voxel: level.voxel_cluster.elem().size() as u32,
        voxel_cluster_stored_as: stored_as,
        voxel_cluster_stored_bytes: stored_bytes,
        open_voxels: level.open.count_ones(),
        open_voxels_stored_as: open_stored_as,
        open_voxels_stored_bytes: open_stored_bytes,
        read_seconds,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&s)?);
        return Ok(());
    }
    let g = &s.grid;
    println!("baked level {}", s.file);
    println!(
        "file        {} bytes, format v{}, baked by visgate {}",
        s.file_bytes, s.format_version, s.tool_version
    );
    println!("static hash {}", s.geometry_hash);
    println!(
        "grid        {} x {} x {} voxels of {} m, origin {} m",
        g.dims[0],
        g.dims[1],
        g.dims[2],
        g.voxel_size_m,
        v3(g.origin_m)
    );
    println!("params      {:?}", s.params);
    let on = match s.params.separate_partition_voxel(g.voxel_size_m) {
        Some(pv) if pv > g.voxel_size_m => format!("on a {pv} m grid, refined onto this one"),
        Some(pv) => format!("on a finer {pv} m grid, each voxel here its share's cluster"),
        None => "on this grid".to_string(),
    };
    println!(
        "partition   skeleton, clusters and gates made {on}; gaps under {} m left out",
        s.params.min_gap_m.unwrap_or(0.0)
    );
    println!(
        "skeleton    {} nodes, {} edges, {} independent cycles",
        s.skeleton_nodes, s.skeleton_edges, s.skeleton_cycles
    );
    println!(
        "segmented   {} nodes, {} edges",
        s.segmented_nodes, s.segmented_edges
    );
    println!("clusters    {}", s.clusters);
    println!("gates       {}", s.gates);
    println!(
        "portals     {} ({} mask cells)",
        s.portals, s.portal_mask_cells
    );
    println!(
        "grid        voxel→cluster {} B/voxel in memory, stored {} in {} bytes",
        s.voxel_cluster_bytes_per_voxel, s.voxel_cluster_stored_as, s.voxel_cluster_stored_bytes
    );
    let sg = &level.info.sight_grid;
    println!(
        "sight grid  {} x {} x {} voxels of {} m: {} left open by its thin voxelization \
         (the voxel walk's grid, a bit each), stored {} in {} bytes",
        sg.dims[0],
        sg.dims[1],
        sg.dims[2],
        sg.voxel_size_m,
        s.open_voxels,
        s.open_voxels_stored_as,
        s.open_voxels_stored_bytes
    );
    println!("read time   {:.3} s", s.read_seconds);
    Ok(())
}

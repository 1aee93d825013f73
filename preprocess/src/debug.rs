//! Debug exports of a bake, each loadable in Blender or MeshLab (PLY), and the voxel grids as
//! NumPy arrays so other tools can check the topology independently.
//!
//! | file | what |
//! |---|---|
//! | `solid_surface.ply` | quads between solid voxels and kept empty voxels (the surface the bake saw) |
//! | `skeleton.ply` | skeleton nodes (property `radius`, metres) and edges |
//! | `segmented.ply` | segmented nodes coloured by class (topology red, curvature green, coverage blue, narrowing yellow), edges straight |
//! | `clusters.ply` | kept empty voxels (every 2nd in each axis) coloured by cluster |
//! | `gates.ply` | gates as 32-sided disks, coloured like their first cluster |
//! | `leak.ply` | a leaking closed scene's paths to the outside (written by the CLI, also when the bake stops; [`crate::leak::write_ply`]) |
//! | `solid.npy`, `skeleton.npy` | uint8 `[nx, ny, nz]`, C order, indexed `[x, y, z]`, 1 = solid / skeleton voxel, border included |

use std::io::{self, BufWriter, Write};
use std::path::Path;

use glam::Vec3;
use visgate_formats::vgate::{BakedLevel, SegNodeKind, Topology};

use crate::bake::BakeGrids;

/// Writes every debug file into `dir` (created if missing); returns the paths written.
pub fn write_all(dir: &Path, level: &BakedLevel, grids: &BakeGrids) -> io::Result<Vec<String>> {
    let solid = grids.solid.as_ref().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the bake did not keep its solid grid: bake with BakeOptions::keep_solid_grid",
        )
    })?;
    std::fs::create_dir_all(dir)?;
    let meta = &level.info.grid;
    let dims = meta.dims;
    let mut written = Vec::new();
    let mut out = |name: &str, f: &dyn Fn(&mut dyn Write) -> io::Result<()>| -> io::Result<()> {
        let path = dir.join(name);
        let mut w = BufWriter::new(std::fs::File::create(&path)?);
        f(&mut w)?;
        w.flush()?;
        written.push(path.display().to_string());
        Ok(())
    };
    let mut skel = vec![false; grids.empty.len()];
    grids.skeleton.iter().for_each(|&i| skel[i as usize] = true);
    out("solid.npy", &|w| write_npy(w, dims, &solid.solid))?;
    out("skeleton.npy", &|w| write_npy(w, dims, &skel))?;
    out("solid_surface.ply", &|w| {
        solid_surface(w, level, &solid.solid, &grids.empty)
    })?;
    let t = &level.topology;
    out("skeleton.ply", &|w| skeleton_ply(w, t))?;
    out("segmented.ply", &|w| segmented_ply(w, t))?;
    out("clusters.ply", &|w| clusters_ply(w, level, &grids.empty))?;
    out("gates.ply", &|w| gates_ply(w, t))?;
    Ok(written)
}

/// The skeleton as a PLY: its nodes with their max-ball radius (m), its edges.
fn skeleton_ply(w: &mut dyn Write, t: &Topology) -> io::Result<()> {
    writeln!(
        w,
        "ply\nformat ascii 1.0\ncomment visgate skeleton: nodes with max-ball radius (m), edges\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float radius\nelement edge {}\nproperty int vertex1\nproperty int vertex2\nend_header",
        t.skeleton.nodes.len(),
        t.skeleton.edges.len()
    )?;
    for n in &t.skeleton.nodes {
        let p = n.position_m;
        writeln!(w, "{} {} {} {}", p[0], p[1], p[2], n.radius_m)?;
    }
    for e in &t.skeleton.edges {
        writeln!(w, "{} {}", e[0], e[1])?;
    }
    Ok(())
}

/// The segmented skeleton as a PLY: its nodes coloured by kind (red topology, green
/// curvature, blue coverage, yellow narrowing) with their radius, its edges.
fn segmented_ply(w: &mut dyn Write, t: &Topology) -> io::Result<()> {
    writeln!(
        w,
        "ply\nformat ascii 1.0\ncomment visgate segmented skeleton: red topology, green curvature, blue coverage, yellow narrowing nodes\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float radius\nelement edge {}\nproperty int vertex1\nproperty int vertex2\nend_header",
        t.segmented.nodes.len(),
        t.segmented.edges.len()
    )?;
    for n in &t.segmented.nodes {
        let s = &t.skeleton.nodes[n.skeleton_node as usize];
        let p = s.position_m;
        let c = match n.kind {
            SegNodeKind::Topology => [230, 40, 40],
            SegNodeKind::Curvature => [40, 200, 40],
            SegNodeKind::Coverage => [40, 90, 230],
            SegNodeKind::Narrowing => [230, 200, 40],
        };
        writeln!(
            w,
            "{} {} {} {} {} {} {}",
            p[0], p[1], p[2], c[0], c[1], c[2], s.radius_m
        )?;
    }
    for e in &t.segmented.edges {
        writeln!(w, "{} {}", e.nodes[0], e.nodes[1])?;
    }
    Ok(())
}

/// The kept empty voxels (every second per axis) as a binary PLY of points coloured by cluster.
fn clusters_ply(w: &mut dyn Write, level: &BakedLevel, empty: &[bool]) -> io::Result<()> {
    let meta = &level.info.grid;
    let mut pts = Vec::new();
    for (i, &e) in empty.iter().enumerate() {
        let v = meta.coords(i as u32);
        if !e || v.iter().any(|c| c % 2 == 1) {
            continue;
        }
        if let Some(c) = level.voxel_cluster.get(i).filter(|&c| c != u32::MAX) {
            pts.push((meta.voxel_to_world(v), colour(c)));
        }
    }
    writeln!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment visgate clusters: kept empty voxels (every 2nd per axis) coloured by cluster\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header",
        pts.len()
    )?;
    for (p, c) in pts {
        for x in p {
            w.write_all(&x.to_le_bytes())?;
        }
        w.write_all(&c)?;
    }
    Ok(())
}

/// The gates as a PLY of disks (32-sided fans) coloured by their first cluster.
fn gates_ply(w: &mut dyn Write, t: &Topology) -> io::Result<()> {
    const SIDES: usize = 32;
    writeln!(
        w,
        "ply\nformat ascii 1.0\ncomment visgate gates: disks\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\nproperty list uchar int vertex_indices\nend_header",
        t.gates.len() * (SIDES + 1),
        t.gates.len() * SIDES
    )?;
    for g in &t.gates {
        let n = Vec3::from(g.normal);
        let (u, v) = n.any_orthonormal_pair();
        let c = Vec3::from(g.centre_m);
        let col = colour(g.clusters[0]);
        writeln!(
            w,
            "{} {} {} {} {} {}",
            c.x, c.y, c.z, col[0], col[1], col[2]
        )?;
        for k in 0..SIDES {
            let a = k as f32 / SIDES as f32 * std::f32::consts::TAU;
            let p = c + (u * a.cos() + v * a.sin()) * g.radius_m;
            writeln!(
                w,
                "{} {} {} {} {} {}",
                p.x, p.y, p.z, col[0], col[1], col[2]
            )?;
        }
    }
    for gi in 0..t.gates.len() {
        let base = gi * (SIDES + 1);
        for k in 0..SIDES {
            let (a, b) = (base + 1 + k, base + 1 + (k + 1) % SIDES);
            writeln!(w, "3 {base} {a} {b}")?;
        }
    }
    Ok(())
}

/// A distinct colour per cluster (golden-angle hues).
pub fn colour(c: u32) -> [u8; 3] {
    let h = (c as f32 * 0.618_034).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    [r, g, b].map(|v: f32| (40.0 + 200.0 * v) as u8)
}

/// Writes a boolean grid (x fastest) as a uint8 `.npy` of shape `[nx, ny, nz]`, C order.
pub fn write_npy(w: &mut dyn Write, dims: [u32; 3], grid: &[bool]) -> io::Result<()> {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut header =
        format!("{{'descr': '|u1', 'fortran_order': False, 'shape': ({nx}, {ny}, {nz}), }}");
    // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    w.write_all(b"\x93NUMPY\x01\x00")?;
    w.write_all(&(header.len() as u16).to_le_bytes())?;
    w.write_all(header.as_bytes())?;
    let mut row = vec![0u8; nz];
    for x in 0..nx {
        for y in 0..ny {
            for (z, r) in row.iter_mut().enumerate() {
                *r = grid[x + nx * (y + ny * z)] as u8;
            }
            w.write_all(&row)?;
        }
    }
    Ok(())
}

fn solid_surface(
    w: &mut dyn Write,
    level: &BakedLevel,
    solid: &[bool],
    empty: &[bool],
) -> io::Result<()> {
    let meta = &level.info.grid;
    let [nx, ny, nz] = meta.dims.map(|d| d as usize);
    let s = meta.voxel_size_m;
    let o = Vec3::from(meta.origin_m);
    let mut quads: Vec<[Vec3; 4]> = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let i = x + nx * (y + ny * z);
                if !solid[i] {
                    continue;
                }
                for axis in 0..3 {
                    for dir in [-1i64, 1] {
                        let mut c = [x as i64, y as i64, z as i64];
                        c[axis] += dir;
                        if c.iter()
                            .zip([nx, ny, nz])
                            .any(|(&v, n)| v < 0 || v >= n as i64)
                        {
                            continue;
                        }
                        let j = c[0] as usize + nx * (c[1] as usize + ny * c[2] as usize);
                        if !empty[j] {
                            continue;
                        }
                        // The face between voxel i and j, wound to face the empty side.
                        let mut base = Vec3::new(x as f32, y as f32, z as f32);
                        if dir > 0 {
                            base[axis] += 1.0;
                        }
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let mut eu = Vec3::ZERO;
                        eu[u] = 1.0;
                        let mut ev = Vec3::ZERO;
                        ev[v] = 1.0;
                        let q = [base, base + eu, base + eu + ev, base + ev];
                        let mut q = q.map(|p| o + p * s);
                        if dir < 0 {
                            q.reverse();
                        }
                        quads.push(q);
                    }
                }
            }
        }
    }
    writeln!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment visgate solid voxels' surface facing the kept empty space\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header",
        quads.len() * 4,
        quads.len()
    )?;
    for q in &quads {
        for p in q {
            for c in p.to_array() {
                w.write_all(&c.to_le_bytes())?;
            }
        }
    }
    for k in 0..quads.len() {
        w.write_all(&[4u8])?;
        for d in 0..4 {
            w.write_all(&((4 * k + d) as i32).to_le_bytes())?;
        }
    }
    Ok(())
}

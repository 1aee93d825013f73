//! Box-room levels generated on a cell grid: rooms, corridors and doorways are boxes of empty
//! cells; every solid cell within `wall_cells` of an empty cell, or enclosed by walls, is wall;
//! the mesh is the boundary of the wall cells, merged into maximal rectangles (greedy meshing).
//! Walls therefore have a real thickness, with faces on both sides, and solid pillars have
//! no faces inside them.

use glam::{Vec2, Vec3};
use visgate_formats::import::RawMesh;

/// A box of cells, `min` inclusive, `max` exclusive, in cell units (x, y, z).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellBox {
    /// Minimum cell.
    pub min: [i32; 3],
    /// One past the maximum cell.
    pub max: [i32; 3],
}

/// Shorthand for a [`CellBox`] spanning x0..x1, y0..y1, z0..z1.
pub const fn cbox(x0: i32, x1: i32, y0: i32, y1: i32, z0: i32, z1: i32) -> CellBox {
    CellBox {
        min: [x0, y0, z0],
        max: [x1, y1, z1],
    }
}

/// A level: empty boxes and the cell size.
#[derive(Debug, Clone)]
pub struct BoxLevel {
    /// Cell edge, metres.
    pub cell_m: f32,
    /// Wall thickness, cells.
    pub wall_cells: i32,
    /// The empty boxes (rooms, corridors, doorways).
    pub empty: Vec<CellBox>,
}

/// Material indices of the generated mesh.
pub const MATERIALS: [(&str, [f32; 3]); 4] = [
    ("floor", [0.70, 0.68, 0.62]),
    ("ceiling", [0.80, 0.80, 0.80]),
    ("wall", [0.75, 0.72, 0.65]),
    ("exterior", [0.40, 0.40, 0.40]),
];

#[derive(Clone, Copy, PartialEq, Eq)]
enum Cell {
    Outside,
    Wall,
    Empty,
}

/// One empty mesh per material, named after it (the generators fill them).
pub fn empty_meshes(materials: &[(&str, [f32; 3])]) -> Vec<RawMesh> {
    materials
        .iter()
        .enumerate()
        .map(|(i, (name, _))| RawMesh {
            name: (*name).to_string(),
            positions: vec![],
            normals: vec![],
            uvs: vec![],
            triangles: vec![],
            material: i as u32,
        })
        .collect()
}

impl BoxLevel {
    /// Generates the triangle meshes, one per material, in metres (+Y up), normals facing
    /// away from the wall.
    pub fn meshes(&self) -> Vec<RawMesh> {
        let t = self.wall_cells;
        let lo: [i32; 3] =
            std::array::from_fn(|a| self.empty.iter().map(|b| b.min[a]).min().unwrap_or(0) - t - 1);
        let hi: [i32; 3] =
            std::array::from_fn(|a| self.empty.iter().map(|b| b.max[a]).max().unwrap_or(0) + t + 1);
        let dims: [usize; 3] = std::array::from_fn(|a| (hi[a] - lo[a]) as usize);
        let idx = |x: usize, y: usize, z: usize| x + dims[0] * (y + dims[1] * z);
        let mut cells = vec![Cell::Outside; dims[0] * dims[1] * dims[2]];
        // Walls: every box dilated by t; then empties carve them.
        for b in &self.empty {
            for z in (b.min[2] - t)..(b.max[2] + t) {
                for y in (b.min[1] - t)..(b.max[1] + t) {
                    for x in (b.min[0] - t)..(b.max[0] + t) {
                        let (i, j, k) = (
                            (x - lo[0]) as usize,
                            (y - lo[1]) as usize,
                            (z - lo[2]) as usize,
                        );
                        cells[idx(i, j, k)] = Cell::Wall;
                    }
                }
            }
        }
        for b in &self.empty {
            for z in b.min[2]..b.max[2] {
                for y in b.min[1]..b.max[1] {
                    for x in b.min[0]..b.max[0] {
                        let (i, j, k) = (
                            (x - lo[0]) as usize,
                            (y - lo[1]) as usize,
                            (z - lo[2]) as usize,
                        );
                        cells[idx(i, j, k)] = Cell::Empty;
                    }
                }
            }
        }
        // Outside cells not reachable from the grid border are enclosed (inside a pillar):
        // make them wall, so the pillar is solid.
        let mut reach = vec![false; cells.len()];
        let mut stack = vec![idx(0, 0, 0)];
        reach[idx(0, 0, 0)] = true;
        while let Some(i) = stack.pop() {
            let (x, y, z) = (
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
            );
            let c = [x, y, z];
            for a in 0..3 {
                for d in [-1i64, 1] {
                    let n = c[a] as i64 + d;
                    if n < 0 || n >= dims[a] as i64 {
                        continue;
                    }
                    let mut m = c;
                    m[a] = n as usize;
                    let j = idx(m[0], m[1], m[2]);
                    if !reach[j] && cells[j] == Cell::Outside {
                        reach[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        for (c, r) in cells.iter_mut().zip(&reach) {
            if *c == Cell::Outside && !r {
                *c = Cell::Wall;
            }
        }
        let get = |c: [i64; 3]| -> Cell {
            if (0..3).any(|a| c[a] < 0 || c[a] >= dims[a] as i64) {
                Cell::Outside
            } else {
                cells[idx(c[0] as usize, c[1] as usize, c[2] as usize)]
            }
        };

        let mut meshes = empty_meshes(&MATERIALS);
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let (nu, nv) = (dims[u], dims[v]);
            for s in 0..=dims[axis] {
                // mask: 0 none, else 1 + dir(0: +axis, 1: −axis) * 4 + material.
                let mut mask = vec![0u8; nu * nv];
                for j in 0..nv {
                    for i in 0..nu {
                        let mut a = [0i64; 3];
                        a[axis] = s as i64 - 1;
                        a[u] = i as i64;
                        a[v] = j as i64;
                        let mut b = a;
                        b[axis] = s as i64;
                        let (ca, cb) = (get(a), get(b));
                        let face = match (ca == Cell::Wall, cb == Cell::Wall) {
                            // Wall below, open above: the face looks towards +axis.
                            (true, false) => Some((0u8, cb)),
                            (false, true) => Some((1u8, ca)),
                            _ => None,
                        };
                        if let Some((dir, open)) = face {
                            let mat = if open == Cell::Outside {
                                3
                            } else if axis == 1 {
                                if dir == 0 { 0 } else { 1 }
                            } else {
                                2
                            };
                            mask[i + nu * j] = 1 + dir * 4 + mat;
                        }
                    }
                }
                // Greedy merge into rectangles.
                for j in 0..nv {
                    let mut i = 0;
                    while i < nu {
                        let code = mask[i + nu * j];
                        if code == 0 {
                            i += 1;
                            continue;
                        }
                        let mut w = 1;
                        while i + w < nu && mask[i + w + nu * j] == code {
                            w += 1;
                        }
                        let mut h = 1;
                        'grow: while j + h < nv {
                            for k in 0..w {
                                if mask[i + k + nu * (j + h)] != code {
                                    break 'grow;
                                }
                            }
                            h += 1;
                        }
                        for jj in 0..h {
                            for k in 0..w {
                                mask[i + k + nu * (j + jj)] = 0;
                            }
                        }
                        let dir = (code - 1) / 4;
                        let mat = ((code - 1) % 4) as usize;
                        let corner = |ci: usize, cj: usize| {
                            let mut p = [0f32; 3];
                            p[axis] = (s as i32 + lo[axis]) as f32 * self.cell_m;
                            p[u] = (ci as i32 + lo[u]) as f32 * self.cell_m;
                            p[v] = (cj as i32 + lo[v]) as f32 * self.cell_m;
                            Vec3::from(p)
                        };
                        let mut normal = [0f32; 3];
                        normal[axis] = if dir == 0 { 1.0 } else { -1.0 };
                        let quad = [
                            corner(i, j),
                            corner(i + w, j),
                            corner(i + w, j + h),
                            corner(i, j + h),
                        ];
                        let m = &mut meshes[mat];
                        let base = m.positions.len() as u32;
                        for p in quad {
                            m.positions.push(p);
                            m.normals.push(Vec3::from(normal));
                            // Planar mapping, one texture repeat per metre.
                            m.uvs.push(Vec2::new(p[u], p[v]));
                        }
                        // (u, v, axis) is right-handed, so CCW in (u, v) faces +axis.
                        if dir == 0 {
                            m.triangles.push([base, base + 1, base + 2]);
                            m.triangles.push([base, base + 2, base + 3]);
                        } else {
                            m.triangles.push([base, base + 2, base + 1]);
                            m.triangles.push([base, base + 3, base + 2]);
                        }
                        i += w;
                    }
                }
            }
        }
        meshes.retain(|m| !m.triangles.is_empty());
        meshes
    }
}

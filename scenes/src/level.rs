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

/// The level's cells: `dims` of them from cell `lo`, x fastest.
struct Cells {
    lo: [i32; 3],
    dims: [usize; 3],
    cells: Vec<Cell>,
}

impl Cells {
    /// Linear index of cell `[x, y, z]` (from `lo`).
    fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Sets every cell of box `b` (level cells) to `c`.
    fn fill(&mut self, b: &CellBox, grow: i32, c: Cell) {
        for z in (b.min[2] - grow)..(b.max[2] + grow) {
            for y in (b.min[1] - grow)..(b.max[1] + grow) {
                for x in (b.min[0] - grow)..(b.max[0] + grow) {
                    let at = [x, y, z];
                    let i = self.index(std::array::from_fn(|a| (at[a] - self.lo[a]) as usize));
                    self.cells[i] = c;
                }
            }
        }
    }

    /// Outside cells not reachable from the grid's corner are enclosed (inside a pillar): they
    /// become wall, so that the pillar is solid.
    fn wall_in_enclosed(&mut self) {
        let dims = self.dims;
        let mut reach = vec![false; self.cells.len()];
        let mut stack = vec![0usize];
        reach[0] = true;
        while let Some(i) = stack.pop() {
            let c = [
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
            ];
            for a in 0..3 {
                for d in [-1i64, 1] {
                    let n = c[a] as i64 + d;
                    if n < 0 || n >= dims[a] as i64 {
                        continue;
                    }
                    let mut m = c;
                    m[a] = n as usize;
                    let j = self.index(m);
                    if !reach[j] && self.cells[j] == Cell::Outside {
                        reach[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        for (c, r) in self.cells.iter_mut().zip(&reach) {
            if *c == Cell::Outside && !r {
                *c = Cell::Wall;
            }
        }
    }

    /// The cell at `c` (from `lo`); outside the grid, outside.
    fn get(&self, c: [i64; 3]) -> Cell {
        if (0..3).any(|a| c[a] < 0 || c[a] >= self.dims[a] as i64) {
            Cell::Outside
        } else {
            self.cells[self.index(c.map(|v| v as usize))]
        }
    }

    /// The faces of plane `s` across `axis` (between cell layers s − 1 and s), over (u, v) =
    /// the next two axes: 0 none, else 1 + dir (0: facing +axis, 1: −axis) · 4 + material.
    fn face_mask(&self, axis: usize, s: usize) -> Vec<u8> {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let (nu, nv) = (self.dims[u], self.dims[v]);
        let mut mask = vec![0u8; nu * nv];
        for j in 0..nv {
            for i in 0..nu {
                let mut a = [0i64; 3];
                a[axis] = s as i64 - 1;
                a[u] = i as i64;
                a[v] = j as i64;
                let mut b = a;
                b[axis] = s as i64;
                let (ca, cb) = (self.get(a), self.get(b));
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
        mask
    }
}

/// Takes the maximal rectangles of equal codes out of `mask` (`nu` wide), greedily, row by row:
/// each as (i, j, w, h, code).
fn merge_rectangles(mask: &mut [u8], nu: usize) -> Vec<(usize, usize, usize, usize, u8)> {
    let nv = mask.len() / nu.max(1);
    let mut out = Vec::new();
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
            out.push((i, j, w, h, code));
            i += w;
        }
    }
    out
}

/// Appends the quad `corners` (counter-clockwise about +axis) to `m`, facing +axis when `dir`
/// is 0 and −axis when 1, with planar texture coordinates on axes `u` and `v`.
fn push_quad(m: &mut RawMesh, corners: [Vec3; 4], (axis, u, v): (usize, usize, usize), dir: u8) {
    let mut normal = [0f32; 3];
    normal[axis] = if dir == 0 { 1.0 } else { -1.0 };
    let base = m.positions.len() as u32;
    for p in corners {
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
}

impl BoxLevel {
    /// The level's cells: every box dilated by the wall thickness is wall, then the boxes are
    /// carved empty, and enclosed outside cells are walled in.
    fn cells(&self) -> Cells {
        let t = self.wall_cells;
        let lo: [i32; 3] =
            std::array::from_fn(|a| self.empty.iter().map(|b| b.min[a]).min().unwrap_or(0) - t - 1);
        let hi: [i32; 3] =
            std::array::from_fn(|a| self.empty.iter().map(|b| b.max[a]).max().unwrap_or(0) + t + 1);
        let dims: [usize; 3] = std::array::from_fn(|a| (hi[a] - lo[a]) as usize);
        let mut cells = Cells {
            lo,
            dims,
            cells: vec![Cell::Outside; dims[0] * dims[1] * dims[2]],
        };
        for b in &self.empty {
            cells.fill(b, t, Cell::Wall);
        }
        for b in &self.empty {
            cells.fill(b, 0, Cell::Empty);
        }
        cells.wall_in_enclosed();
        cells
    }

    /// Generates the triangle meshes, one per material, in metres (+Y up), normals facing
    /// away from the wall.
    pub fn meshes(&self) -> Vec<RawMesh> {
        let cells = self.cells();
        let (lo, dims) = (cells.lo, cells.dims);
        let mut meshes = empty_meshes(&MATERIALS);
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for s in 0..=dims[axis] {
                let mut mask = cells.face_mask(axis, s);
                for (i, j, w, h, code) in merge_rectangles(&mut mask, dims[u]) {
                    let corner = |ci: usize, cj: usize| {
                        let mut p = [0f32; 3];
                        p[axis] = (s as i32 + lo[axis]) as f32 * self.cell_m;
                        p[u] = (ci as i32 + lo[u]) as f32 * self.cell_m;
                        p[v] = (cj as i32 + lo[v]) as f32 * self.cell_m;
                        Vec3::from(p)
                    };
                    let quad = [
                        corner(i, j),
                        corner(i + w, j),
                        corner(i + w, j + h),
                        corner(i, j + h),
                    ];
                    let mesh = &mut meshes[((code - 1) % 4) as usize];
                    push_quad(mesh, quad, (axis, u, v), (code - 1) / 4);
                }
            }
        }
        meshes.retain(|m| !m.triangles.is_empty());
        meshes
    }
}

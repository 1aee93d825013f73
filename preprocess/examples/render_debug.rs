//! Renders the debug exports of a bake (`visgate bake ... --debug-dir DIR`) to PNG pictures:
//! an oblique orthographic view from above of the solid's surface cut at a height, with the
//! whole skeleton (lines coloured by max-ball radius), the visibility clusters below the cut
//! (points coloured by cluster) or all the gates (disks) over it. These are the README's
//! screenshots.
//!
//! `cargo run --release -p visgate-preprocess --example render_debug -- DIR OUT_PREFIX
//! [CUT_FRACTION] [SIZE]`
//!
//! CUT_FRACTION (0.45 by default) keeps the solid below that fraction of its height, so the
//! inside shows; SIZE is the image's width in pixels (1200). Writes OUT_PREFIX-skeleton.png,
//! OUT_PREFIX-clusters.png and OUT_PREFIX-gates.png.

use std::error::Error;
use std::path::Path;

use glam::{Vec2, Vec3};
use image::{Rgb, RgbImage};

/// One element of a PLY file: per-vertex float properties by name, and lists.
struct Element {
    name: String,
    count: usize,
    props: Vec<(String, String)>, // (type, name); a list is ("list:uchar:int", name)
}

/// The vertices (position, colour) and faces/edges of a PLY written by the bake.
#[derive(Default)]
struct Ply {
    pos: Vec<Vec3>,
    colour: Vec<[u8; 3]>,
    radius: Vec<f32>,
    faces: Vec<Vec<u32>>,
    edges: Vec<[u32; 2]>,
}

fn read_ply(path: &Path) -> Result<Ply, Box<dyn Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .ok_or_else(|| format!("{}: no end_header", path.display()))?;
    let header = std::str::from_utf8(&bytes[..end])?;
    let mut body = &bytes[end + 11..];
    let binary = header.contains("binary_little_endian");
    let mut elements: Vec<Element> = Vec::new();
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["element", name, n] => elements.push(Element {
                name: name.to_string(),
                count: n.parse()?,
                props: Vec::new(),
            }),
            ["property", "list", a, b, name] => {
                if let Some(e) = elements.last_mut() {
                    e.props.push((format!("list:{a}:{b}"), name.to_string()))
                }
            }
            ["property", ty, name] => {
                if let Some(e) = elements.last_mut() {
                    e.props.push((ty.to_string(), name.to_string()))
                }
            }
            _ => {}
        }
    }
    let text = if binary {
        String::new()
    } else {
        String::from_utf8_lossy(body).into_owned()
    };
    let mut words = text.split_whitespace();
    let mut scalar = |ty: &str, body: &mut &[u8]| -> Result<f64, Box<dyn Error>> {
        if !binary {
            return Ok(words.next().ok_or("PLY body too short")?.parse()?);
        }
        let size = match ty {
            "uchar" | "uint8" | "char" => 1,
            "float" | "int" | "uint" | "float32" | "int32" => 4,
            other => return Err(format!("PLY type {other} not read").into()),
        };
        if body.len() < size {
            return Err("PLY body too short".into());
        }
        let (b, rest) = body.split_at(size);
        *body = rest;
        Ok(match ty {
            "uchar" | "uint8" => b[0] as f64,
            "char" => b[0] as i8 as f64,
            "float" | "float32" => f32::from_le_bytes(b.try_into()?) as f64,
            "int" | "int32" => i32::from_le_bytes(b.try_into()?) as f64,
            _ => u32::from_le_bytes(b.try_into()?) as f64,
        })
    };
    let mut ply = Ply::default();
    for e in &elements {
        for _ in 0..e.count {
            let mut v = [0f64; 8];
            let mut names: Vec<&str> = Vec::new();
            let mut list = Vec::new();
            for (ty, name) in &e.props {
                if let Some(rest) = ty.strip_prefix("list:") {
                    let (count_ty, item_ty) = rest.split_once(':').ok_or("bad list")?;
                    let n = scalar(count_ty, &mut body)? as usize;
                    for _ in 0..n {
                        list.push(scalar(item_ty, &mut body)? as u32);
                    }
                } else {
                    let x = scalar(ty, &mut body)?;
                    if names.len() < v.len() {
                        v[names.len()] = x;
                        names.push(name);
                    }
                }
            }
            let get = |n: &str| names.iter().position(|&m| m == n).map(|i| v[i]);
            match e.name.as_str() {
                "vertex" => {
                    ply.pos.push(Vec3::new(
                        get("x").unwrap_or(0.0) as f32,
                        get("y").unwrap_or(0.0) as f32,
                        get("z").unwrap_or(0.0) as f32,
                    ));
                    if let (Some(r), Some(g), Some(b)) = (get("red"), get("green"), get("blue")) {
                        ply.colour.push([r as u8, g as u8, b as u8]);
                    }
                    if let Some(r) = get("radius") {
                        ply.radius.push(r as f32);
                    }
                }
                "face" => ply.faces.push(list),
                "edge" => {
                    if let (Some(a), Some(b)) = (get("vertex1"), get("vertex2")) {
                        ply.edges.push([a as u32, b as u32]);
                    }
                }
                _ => {}
            }
        }
    }
    Ok(ply)
}

/// An orthographic camera looking down at `elevation` from `azimuth`, fitted to a box.
struct View {
    right: Vec3,
    up: Vec3,
    fwd: Vec3,
    origin: Vec2,
    scale: f32,
    size: [u32; 2],
}

impl View {
    fn fit(lo: Vec3, hi: Vec3, width: u32) -> View {
        let (az, el) = (35f32.to_radians(), 50f32.to_radians());
        let fwd = -Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        let right = fwd.cross(Vec3::Y).normalize();
        let up = right.cross(fwd);
        let corners = (0..8).map(|k| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let (mut a, mut b) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for c in corners {
            let p = Vec2::new(c.dot(right), c.dot(up));
            a = a.min(p);
            b = b.max(p);
        }
        let ext = (b - a) * 1.04;
        let scale = width as f32 / ext.x;
        let height = (ext.y * scale).ceil().max(1.0) as u32;
        View {
            right,
            up,
            fwd,
            origin: (a + b) * 0.5 - ext * 0.5,
            scale,
            size: [width, height],
        }
    }

    /// Pixel x, y and depth (larger is farther).
    fn project(&self, p: Vec3) -> Vec3 {
        let x = (p.dot(self.right) - self.origin.x) * self.scale;
        let y = self.size[1] as f32 - (p.dot(self.up) - self.origin.y) * self.scale;
        Vec3::new(x, y, p.dot(self.fwd))
    }
}

struct Canvas {
    img: RgbImage,
    depth: Vec<f32>,
}

impl Canvas {
    fn new(size: [u32; 2]) -> Canvas {
        Canvas {
            img: RgbImage::from_pixel(size[0], size[1], Rgb([255, 255, 255])),
            depth: vec![f32::INFINITY; (size[0] * size[1]) as usize],
        }
    }

    fn plot(&mut self, x: i32, y: i32, z: f32, c: [u8; 3]) {
        let (w, h) = self.img.dimensions();
        if x < 0 || y < 0 || x >= w as i32 || y >= h as i32 {
            return;
        }
        let i = (y as u32 * w + x as u32) as usize;
        if z < self.depth[i] {
            self.depth[i] = z;
            self.img.put_pixel(x as u32, y as u32, Rgb(c));
        }
    }

    fn triangle(&mut self, v: [Vec3; 3], c: [u8; 3]) {
        let lo = v[0].min(v[1]).min(v[2]).floor();
        let hi = v[0].max(v[1]).max(v[2]).ceil();
        let area = (v[1] - v[0]).truncate().perp_dot((v[2] - v[0]).truncate());
        if area.abs() < 1e-9 {
            return;
        }
        for y in lo.y as i32..=hi.y as i32 {
            for x in lo.x as i32..=hi.x as i32 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w0 = (v[2] - v[1]).truncate().perp_dot(p - v[1].truncate()) / area;
                let w1 = (v[0] - v[2]).truncate().perp_dot(p - v[2].truncate()) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 >= -1e-4 && w1 >= -1e-4 && w2 >= -1e-4 {
                    self.plot(x, y, w0 * v[0].z + w1 * v[1].z + w2 * v[2].z, c);
                }
            }
        }
    }

    fn line(&mut self, a: Vec3, b: Vec3, c: [u8; 3], width: i32) {
        let n = (b - a).truncate().length().ceil().max(1.0) as i32;
        for i in 0..=n {
            let p = a.lerp(b, i as f32 / n as f32);
            for dy in -width / 2..=width / 2 {
                for dx in -width / 2..=width / 2 {
                    self.plot(p.x as i32 + dx, p.y as i32 + dy, p.z - 1e-3, c);
                }
            }
        }
    }
}

/// Draws the solid surface below `cut_y`, shaded by face orientation.
fn draw_solid(canvas: &mut Canvas, view: &View, solid: &Ply, cut_y: f32) {
    let light = Vec3::new(0.4, 0.8, 0.45).normalize();
    for f in &solid.faces {
        if f.len() < 3 {
            continue;
        }
        let p: Vec<Vec3> = f.iter().map(|&i| solid.pos[i as usize]).collect();
        if p.iter().any(|q| q.y > cut_y) {
            continue;
        }
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        let shade = (0.55 + 0.4 * n.dot(light).abs()) * 235.0;
        let c = [shade as u8; 3];
        let q: Vec<Vec3> = p.iter().map(|&x| view.project(x)).collect();
        for k in 1..q.len() - 1 {
            canvas.triangle([q[0], q[k], q[k + 1]], c);
        }
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: render_debug DIR OUT_PREFIX [CUT_FRACTION] [SIZE]";
    let dir = std::path::PathBuf::from(args.next().ok_or(usage)?);
    let out = args.next().ok_or(usage)?;
    let cut: f32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(0.45);
    let width: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(1200);
    if !(0.0..=1.0).contains(&cut) || !(64..=8192).contains(&width) {
        return Err(format!("CUT_FRACTION in 0..=1 and SIZE in 64..=8192\n{usage}").into());
    }
    let solid = read_ply(&dir.join("solid_surface.ply"))?;
    let skeleton = read_ply(&dir.join("skeleton.ply"))?;
    let clusters = read_ply(&dir.join("clusters.ply"))?;
    let gates = read_ply(&dir.join("gates.ply"))?;
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for &p in &solid.pos {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !lo.is_finite() {
        return Err(format!("{}: no solid surface", dir.display()).into());
    }
    let cut_y = lo.y + (hi.y - lo.y) * cut;
    let view = View::fit(lo, hi, width);

    // Skeleton: lines coloured from blue (narrow) to red (wide).
    let mut canvas = Canvas::new(view.size);
    draw_solid(&mut canvas, &view, &solid, cut_y);
    let r_max = skeleton.radius.iter().copied().fold(1e-6f32, f32::max);
    for &[a, b] in &skeleton.edges {
        let (pa, pb) = (skeleton.pos[a as usize], skeleton.pos[b as usize]);
        let t = skeleton.radius.get(a as usize).copied().unwrap_or(0.0) / r_max;
        let c = [(255.0 * t) as u8, 40, (255.0 * (1.0 - t)) as u8];
        canvas.line(view.project(pa), view.project(pb), c, 3);
    }
    canvas.img.save(format!("{out}-skeleton.png"))?;

    // Clusters: the kept empty voxels' points, coloured by cluster.
    let mut canvas = Canvas::new(view.size);
    draw_solid(&mut canvas, &view, &solid, cut_y);
    let dot = 2;
    for (p, c) in clusters.pos.iter().zip(&clusters.colour) {
        if p.y > cut_y {
            continue;
        }
        let q = view.project(*p);
        for dy in 0..dot {
            for dx in 0..dot {
                canvas.plot(q.x as i32 + dx, q.y as i32 + dy, q.z, *c);
            }
        }
    }
    canvas.img.save(format!("{out}-clusters.png"))?;

    // Gates: disks in their colours over the skeleton in grey.
    let mut canvas = Canvas::new(view.size);
    draw_solid(&mut canvas, &view, &solid, cut_y);
    for &[a, b] in &skeleton.edges {
        let (pa, pb) = (skeleton.pos[a as usize], skeleton.pos[b as usize]);
        canvas.line(view.project(pa), view.project(pb), [90, 90, 90], 1);
    }
    for f in &gates.faces {
        if f.len() < 3 {
            continue;
        }
        let c = gates
            .colour
            .get(f[0] as usize)
            .copied()
            .unwrap_or([255, 0, 0]);
        let q: Vec<Vec3> = f
            .iter()
            .map(|&i| view.project(gates.pos[i as usize]) - Vec3::Z * 1e-2)
            .collect();
        for k in 1..q.len() - 1 {
            canvas.triangle([q[0], q[k], q[k + 1]], c);
        }
    }
    canvas.img.save(format!("{out}-gates.png"))?;
    println!("wrote {out}-skeleton.png, {out}-clusters.png, {out}-gates.png");
    Ok(())
}

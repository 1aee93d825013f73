//! The viewer's debug layers, drawn over the image: the visibility cluster of every pixel
//! (found by a CPU ray per pixel and the level's voxel→cluster grid, as the renderer finds
//! it), the gates as disks, the skeleton coloured by max-ball radius, the VPLs coloured by
//! flux, the VALs of the VAL modes as disks of their area; and what lies under the pointer
//! (cluster, position, normal, VPLs that reach it).

use eframe::egui;
use glam::Vec3;
use rayon::prelude::*;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::{End, GateLevel, GateParams};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::vpl::Vpl;

/// Which layers are on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Layers {
    /// Each pixel's visibility cluster, in distinct colours (grey: none).
    pub clusters: bool,
    /// The gates as disks.
    pub gates: bool,
    /// The skeleton, blue narrow to red wide.
    pub skeleton: bool,
    /// The VPLs as points.
    pub vpls: bool,
    /// The frame less its direct light.
    pub indirect: bool,
    /// Each pixel's geometry cluster (screen tile × depth slice × visibility cluster).
    pub geometry: bool,
    /// Each pixel's light-list length, as a heat map.
    pub lists: bool,
    /// The VALs of a VAL mode as disks of their area.
    pub vals: bool,
}

/// A VAL as the layer draws it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValDisk {
    /// Centre. [Units: m]
    pub centre: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Radius of the disk of its area. [Units: m]
    pub radius: f32,
    /// Its flux over the brightest VAL's (√, per channel).
    pub colour: egui::Color32,
}

/// The VALs that hold VPLs as disks: the area of `val-ism`'s form factor (the disk of their
/// VPLs' second moment), coloured by flux.
pub fn val_disks(vals: &[visgate_runtime::cpu::val::Val]) -> Vec<ValDisk> {
    let live: Vec<_> = vals.iter().filter(|v| v.vpl_count() > 0).collect();
    let flux = |v: &visgate_runtime::cpu::val::Val| Vec3::from_slice(&v.flux[..3]);
    let max = live
        .iter()
        .map(|v| flux(v).max_element())
        .fold(1e-30, f32::max);
    live.iter()
        .map(|v| {
            let f = flux(v) / max;
            ValDisk {
                centre: v.centre(),
                normal: v.unit_normal(),
                radius: (v.disk_area() / std::f32::consts::PI).sqrt(),
                colour: egui::Color32::from_rgb(
                    (255.0 * f.x.sqrt()) as u8,
                    (255.0 * f.y.sqrt()) as u8,
                    (255.0 * f.z.sqrt()) as u8,
                ),
            }
        })
        .collect()
}

impl Layers {
    /// The pixel layer shown (one at a time): list length, else geometry clusters, else
    /// visibility clusters.
    pub fn pixel_layer(&self) -> Option<PixelLayer> {
        match (self.lists, self.geometry, self.clusters) {
            (true, _, _) => Some(PixelLayer::Lists),
            (false, true, _) => Some(PixelLayer::Geometry),
            (false, false, true) => Some(PixelLayer::Clusters),
            _ => None,
        }
    }
}

/// A layer with a colour per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelLayer {
    /// Visibility clusters.
    Clusters,
    /// Geometry clusters.
    Geometry,
    /// Light-list length.
    Lists,
}

/// A distinct colour for id `k`.
pub fn id_colour(k: u32) -> egui::Color32 {
    let h = (k as f32 * 0.618_034) % 1.0;
    egui::Color32::from(egui::ecolor::Hsva::new(h, 0.75, 0.95, 1.0))
}

/// Where world point `p` falls in `rect`, showing `view`; `None` behind the camera.
pub fn project(view: &View, rect: egui::Rect, p: Vec3) -> Option<egui::Pos2> {
    let d = p - view.eye;
    let z = d.dot(view.forward);
    if z <= 1e-6 * d.length().max(1e-30) {
        return None;
    }
    let tx = (0.5 * view.fov_x_rad).tan();
    let ty = tx * view.size[1] as f32 / view.size[0] as f32;
    let x = d.dot(view.right) / (z * tx);
    let y = d.dot(view.up) / (z * ty);
    Some(egui::pos2(
        rect.left() + (x + 1.0) * 0.5 * rect.width(),
        rect.top() + (1.0 - y) * 0.5 * rect.height(),
    ))
}

/// The surface of every pixel of `view` as the G-buffer holds it (normal turned to the camera,
/// view depth, visibility cluster); `None`: no surface.
pub fn pixel_surfaces(
    view: &View,
    tracer: &Tracer,
    level: &GateLevel,
) -> Vec<Option<visgate_runtime::cpu::clustered::PixelSurface>> {
    let [w, h] = view.size;
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let p = glam::Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let dir = view.ray_dir(p);
            let s = tracer.trace(view.eye, dir)?;
            let n = if s.normal.dot(dir) > 0.0 {
                -s.normal
            } else {
                s.normal
            };
            Some(visgate_runtime::cpu::clustered::PixelSurface {
                position: s.position,
                normal: n,
                depth: s.t * dir.dot(view.forward),
                cluster: level.cluster_at(s.position, n),
            })
        })
        .collect()
}

/// The cluster of every pixel of `view` (row-major; `None`: no surface or no cluster).
pub fn pixel_clusters(view: &View, tracer: &Tracer, level: &GateLevel) -> Vec<Option<u32>> {
    pixel_surfaces(view, tracer, level)
        .iter()
        .map(|p| p.and_then(|p| p.cluster))
        .collect()
}

/// The geometry clusters or the light-list lengths of `view` as the clustered-gates twin
/// (`cpu::clustered::assign`, which the GPU passes follow) finds them for `vpls`, with tiles of
/// `tile_px` pixels of this view; lengths in false colour up to the longest list.
pub fn clustered_image(
    view: &View,
    tracer: &Tracer,
    level: &GateLevel,
    vpls: &[Vpl],
    gates: &GateParams,
    tile_px: u32,
    which: PixelLayer,
) -> egui::ColorImage {
    use visgate_runtime::cpu::clustered::{ClusterParams, assign};
    let [w, h] = view.size;
    let pixels = pixel_surfaces(view, tracer, level);
    let params = ClusterParams {
        tile_px,
        ..ClusterParams::default()
    };
    let c = assign(&pixels, w, vpls, level, gates, (&params, 1));
    let longest = c.lists.iter().map(Vec::len).max().unwrap_or(0).max(1);
    let px: Vec<egui::Color32> = c
        .pixel_cluster
        .iter()
        .map(|&g| match (g, which) {
            (u32::MAX, _) => egui::Color32::from_gray(40),
            (g, PixelLayer::Lists) => {
                let t = c.lists[g as usize].len() as f32 / longest as f32;
                egui::Color32::from(egui::ecolor::Hsva::new(0.66 * (1.0 - t), 0.9, 0.95, 1.0))
            }
            (g, _) => id_colour(g),
        })
        .collect();
    egui::ColorImage::new([w as usize, h as usize], px)
}

/// The cluster image as an egui image.
pub fn cluster_image(view: &View, clusters: &[Option<u32>]) -> egui::ColorImage {
    let px: Vec<egui::Color32> = clusters
        .iter()
        .map(|c| match c {
            Some(k) => id_colour(*k),
            None => egui::Color32::from_gray(40),
        })
        .collect();
    egui::ColorImage::new([view.size[0] as usize, view.size[1] as usize], px)
}

/// A segment in metres and its colour.
pub type Line = (Vec3, Vec3, egui::Color32);

/// Every portal's outline ([`portal_outline`]), coloured by the pair of clusters it joins.
pub fn portal_lines(level: &GateLevel) -> Vec<Line> {
    let mut out = Vec::new();
    for p in &level.baked().topology.portals {
        let colour = id_colour(p.clusters[0] * 7919 + p.clusters[1]);
        out.extend(portal_outline(p).into_iter().map(|(a, b)| (a, b, colour)));
    }
    out
}

/// Draws the line layers (gates with the level's `portals` outlines, skeleton, VPLs, VALs)
/// over `rect`.
pub fn draw_lines(
    painter: &egui::Painter,
    rect: egui::Rect,
    view: &View,
    on: Layers,
    (level, vpls, portals, vals): (Option<&GateLevel>, &[Vpl], &[Line], &[ValDisk]),
) {
    let seg = |a: Vec3, b: Vec3, colour: egui::Color32, width: f32| {
        if let (Some(p), Some(q)) = (project(view, rect, a), project(view, rect, b)) {
            painter.line_segment([p, q], egui::Stroke::new(width, colour));
        }
    };
    if let (true, Some(l)) = (on.skeleton, level) {
        let sk = &l.baked().topology.skeleton;
        let r_max = sk.nodes.iter().map(|n| n.radius_m).fold(1e-30, f32::max);
        for [a, b] in &sk.edges {
            let (na, nb) = (&sk.nodes[*a as usize], &sk.nodes[*b as usize]);
            let t = 0.5 * (na.radius_m + nb.radius_m) / r_max;
            let colour = egui::Color32::from_rgb((255.0 * t) as u8, 60, (255.0 * (1.0 - t)) as u8);
            seg(na.position_m.into(), nb.position_m.into(), colour, 2.0);
        }
    }
    // A disk's outline and a tick along its normal.
    let disk = |c: Vec3, n: Vec3, r: f32, colour: egui::Color32, width: f32| {
        let u = n.any_orthonormal_vector();
        let v = n.cross(u);
        let ring = |k: u32| {
            let a = k as f32 / 32.0 * std::f32::consts::TAU;
            c + (u * a.cos() + v * a.sin()) * r
        };
        for k in 0..32 {
            seg(ring(k), ring(k + 1), colour, width);
        }
        seg(c, c + n * r * 0.3, colour, 1.0);
    };
    if let (true, Some(l)) = (on.gates, level) {
        for i in 0..l.gate_count() as u32 {
            let (c, n, r) = l.gate(i);
            disk(c, n, r, id_colour(i), 2.0);
        }
        for &(a, b, colour) in portals {
            seg(a, b, colour, 1.0);
        }
    }
    if on.vals {
        for d in vals {
            disk(d.centre, d.normal, d.radius, d.colour, 2.0);
            if let Some(p) = project(view, rect, d.centre) {
                painter.circle_filled(p, 2.5, d.colour);
            }
        }
    }
    if on.vpls {
        let max = vpls
            .iter()
            .map(|v| Vec3::from(v.flux).max_element())
            .fold(1e-30, f32::max);
        for v in vpls {
            if let Some(p) = project(view, rect, v.position.into()) {
                let f = Vec3::from(v.flux) / max;
                let colour = egui::Color32::from_rgb(
                    (255.0 * f.x.sqrt()) as u8,
                    (255.0 * f.y.sqrt()) as u8,
                    (255.0 * f.z.sqrt()) as u8,
                );
                painter.circle_filled(p, 2.0, colour);
            }
        }
    }
}

/// The edges between a portal's open mask cells and closed ones (or the mask's border), in
/// metres.
pub fn portal_outline(p: &visgate_formats::vgate::Portal) -> Vec<(Vec3, Vec3)> {
    let (o, u, v) = (Vec3::from(p.origin_m), Vec3::from(p.u), Vec3::from(p.v));
    let at = |i: i64, j: i64| o + (u * i as f32 + v * j as f32) * p.cell_m;
    let mut out = Vec::new();
    for j in 0..i64::from(p.size[1]) {
        for i in 0..i64::from(p.size[0]) {
            if !p.cell(i, j) {
                continue;
            }
            if !p.cell(i - 1, j) {
                out.push((at(i, j), at(i, j + 1)));
            }
            if !p.cell(i + 1, j) {
                out.push((at(i + 1, j), at(i + 1, j + 1)));
            }
            if !p.cell(i, j - 1) {
                out.push((at(i, j), at(i + 1, j)));
            }
            if !p.cell(i, j + 1) {
                out.push((at(i, j + 1), at(i + 1, j + 1)));
            }
        }
    }
    out
}

/// What lies under image point `p` (pixels of `view`): a line of text.
pub fn probe(
    view: &View,
    p: glam::Vec2,
    tracer: &Tracer,
    level: Option<&GateLevel>,
    vpls: &[Vpl],
    gates: &GateParams,
) -> String {
    let Some(s) = tracer.trace(view.eye, view.ray_dir(p)) else {
        return "no surface".into();
    };
    let (x, n) = (s.position, s.normal);
    let facing: Vec<&Vpl> = vpls
        .iter()
        .filter(|v| {
            let d = Vec3::from(v.position) - x;
            d.dot(n) > 0.0 && d.dot(Vec3::from(v.normal)) < 0.0
        })
        .collect();
    let exact = facing
        .iter()
        .filter(|v| {
            // Offset both ends as the exact reference does.
            let from = x + s.geometric_normal * tracer.epsilon_m;
            let to = Vec3::from(v.position) + Vec3::from(v.normal) * tracer.epsilon_m;
            !tracer.occluded(from, to)
        })
        .count();
    let mut out = format!(
        "({:.2}, {:.2}, {:.2}) m, normal ({:.2}, {:.2}, {:.2}); VPLs facing {}, unoccluded {}",
        x.x,
        x.y,
        x.z,
        n.x,
        n.y,
        n.z,
        facing.len(),
        exact
    );
    if let Some(l) = level {
        let point = End {
            position: x,
            normal: s.geometric_normal,
            cluster: l.cluster_at(x, n),
        };
        let through = facing
            .iter()
            .filter(|v| {
                let vpl = End::at(l, Vec3::from(v.position), Vec3::from(v.normal));
                l.visible(&vpl, &point, gates)
            })
            .count();
        out += &match point.cluster {
            Some(k) => format!("; cluster {k}, through the gates {through}"),
            None => format!("; no cluster (unoccluded), through the gates {through}"),
        };
    }
    out
}

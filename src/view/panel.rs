//! The viewer's side-panel sections: each method's settings, the camera, the frame's passes.

use std::collections::VecDeque;

use eframe::egui;
use visgate_formats::Scene;
use visgate_runtime::cpu::gates::GateShape;
use visgate_runtime::gpu::{
    AUTO_ROULETTE_BLOCK, AUTO_ROULETTE_RATIO_VPLS, AUTO_ROULETTE_SHARE, AUTO_ROULETTE_VPLS,
    DirectLight, DiskLight, GatesParams, GpuMode, InterleaveParams, IsmParams, LcDisk,
    LightClusterGpuParams, MethodSettings, NEAR_FIELD_MAX, PassTimes, RATIO_STRIDE_MAX,
    WalkRoulette,
};

use super::camera::FlyCamera;

/// The gates' roulette on the walks: auto, or a share of a pixel's light.
fn walk_roulette(ui: &mut egui::Ui, r: &mut WalkRoulette) {
    let mut auto = *r == WalkRoulette::Auto;
    ui.horizontal(|ui| {
        let (b, n, m) = (
            AUTO_ROULETTE_BLOCK,
            AUTO_ROULETTE_VPLS,
            AUTO_ROULETTE_RATIO_VPLS,
        );
        let hint = format!(
            "{AUTO_ROULETTE_SHARE} in blocks of {b} × {b} or more where a pixel's subset holds \
             {n} VPLs or more ({} VPLs in {b} × {b} blocks), {m} with the ratio estimator \
             ({}), else every VPL walked",
            n * b * b,
            m * b * b
        );
        if ui.checkbox(&mut auto, "auto").on_hover_text(hint).changed() {
            *r = if auto {
                WalkRoulette::Auto
            } else {
                WalkRoulette::Share(AUTO_ROULETTE_SHARE)
            };
        }
        if let WalkRoulette::Share(share) = r {
            ui.add(egui::Slider::new(share, 0.0..=0.5).text("walk roulette"))
                .on_hover_text(
                    "a VPL bringing a pixel less than this share of its subset's light is \
                     walked by chance and weighted up: the same light on average in fewer \
                     walks, with noise; 0: every VPL walked",
                );
        } else {
            ui.label("walk roulette");
        }
    });
}

/// The gates' settings (mode gates or gates-per-pixel): the shape and its walk or disks,
/// and for interleaved gates the blur, the starved pixels and the walks' roulette.
fn gates_settings(ui: &mut egui::Ui, mode: &str, s: &mut MethodSettings) {
    let g = &mut s.gates.gates;
    ui.horizontal(|ui| {
        ui.radio_value(&mut g.shape, GateShape::Voxels, "voxels")
            .on_hover_text("the walk through the level's open voxels");
        ui.radio_value(&mut g.shape, GateShape::Portal, "portals");
        ui.radio_value(&mut g.shape, GateShape::Disk, "disks (paper)");
    });
    if g.shape == GateShape::Portal {
        ui.add(egui::Slider::new(&mut g.max_walk, 1..=256).text("portals per walk"));
    } else if g.shape == GateShape::Disk {
        ui.add(egui::Slider::new(&mut g.max_hops, 1..=2).text("gate hops"));
        ui.add(egui::Slider::new(&mut g.oversize, 0.5..=3.0).text("gate oversize"));
    } else {
        ui.checkbox(&mut g.triangles, "triangles in closed voxels")
            .on_hover_text(
                "the walk along the true segment, tested against the scene's triangles \
                 in the closed voxels it crosses: near-exact, several times slower",
            );
        ui.add_enabled(
            !g.triangles,
            egui::Checkbox::new(&mut g.planes, "planes in closed voxels"),
        )
        .on_hover_text(
            "pass a closed voxel where the segment meets neither of the one or two \
                 planes its geometry lies in (fewer black pixels beside jambs, columns \
                 and creases; about twice the walk's time); off: every closed voxel \
                 blocks",
        );
    }
    if mode == "gates" {
        let il = &mut s.vals.interleave;
        interleave(ui, il);
        if il.block > 1 {
            ui.add(egui::Slider::new(&mut il.min_vpls, 0..=64).text("fewest VPLs a pixel"))
                .on_hover_text(
                    "where the frame's VPLs are too few for the block (a lamp outside a \
                     window: most of its paths leave the level), the gates run the largest \
                     block that leaves each pixel this many; 0: the block whatever the count",
                );
            let most = il.block * il.block;
            ui.add(egui::Slider::new(&mut il.starved_taps, 0..=most).text("starved taps"))
                .on_hover_text(
                    "a pixel whose blur block holds fewer pixels than this that agree \
                     with it walks the VPLs of the rest itself (by the walk roulette): \
                     fewer black strips along walls and jambs, 2-7x the frame on \
                     lavapipe; 0: off",
                );
            ui.checkbox(&mut il.starved_dark, "dark pixels walk the rest")
                .on_hover_text(
                    "a pixel whose agreeing neighbours found no light walks the VPLs \
                     of the rest itself: a lit strip whose few VPLs fell in the other \
                     pixels' subsets is no longer black",
                );
        }
        if g.shape != GateShape::Disk {
            walk_roulette(ui, &mut s.gates.walk_roulette);
            if il.block > 1 {
                ui.add(
                    egui::Slider::new(&mut s.gates.near_field, 0.0..=NEAR_FIELD_MAX)
                        .text("near field (blocks)"),
                )
                .on_hover_text(
                    "each pixel walks the VPLs nearer it than this many blur blocks' width \
                     itself, unblurred: the spots that single VPLs light in the creases \
                     beside a light, which interleaving smears; 0: off",
                );
                ui.checkbox(&mut s.gates.ratio, "ratio estimator")
                    .on_hover_text(
                        "each pixel sums every far VPL's unshadowed light itself and the blur \
                         scales it by the share its neighbours' walks found visible: the \
                         interleaving's error left to where the visibility changes (off where \
                         the walk roulette is on)",
                    );
                if s.gates.ratio {
                    ui.add(
                        egui::Slider::new(&mut s.gates.ratio_stride, 1..=RATIO_STRIDE_MAX)
                            .text("ratio grid (px)"),
                    )
                    .on_hover_text(
                        "the unshadowed light is summed at every n-th pixel across and down \
                         and at the pixels beside a crease or an edge; the others take it \
                         between their four grid pixels: n² times fewer sums on flat walls",
                    );
                }
            }
        }
    }
}

/// The settings of method `mode` (by its registry name). Clustered gates and the VAL modes
/// share one interleaving block, so that their speed compares like with like.
pub fn method_settings(ui: &mut egui::Ui, mode: &str, s: &mut MethodSettings) {
    match mode {
        "gates" | "gates-per-pixel" => gates_settings(ui, mode, s),
        "val-hard" | "val-cssm" => {
            let v = &mut s.vals;
            ui.add(egui::Slider::new(&mut v.vals.count, 1..=256).text("VALs"));
            ui.add(egui::Slider::new(&mut v.vals.iterations, 0..=64).text("k-means iterations"))
                .on_hover_text("the clustering's k-means iterations a frame");
            ui.checkbox(&mut v.vals.warm_start, "warm start (last frame's centres)")
                .on_hover_text(
                    "off: the paper's restart from evenly spaced VPLs every frame; on: steadier, \
                     but VALs emptied as the light moves stay empty (the live count is below)",
                );
            interleave(ui, &mut v.interleave);
            ui.add(egui::Slider::new(&mut v.map_size, 32..=512).text("VAL map size"));
        }
        "vpl-clusters" => {
            lc_controls(ui, &mut s.vpl_clusters);
            interleave(ui, &mut s.vals.interleave);
        }
        "per-vpl-ism" => {
            ism_controls(ui, &mut s.vpl_ism.ism);
            interleave(ui, &mut s.vpl_ism.interleave);
        }
        "val-ism" => {
            let v = &mut s.val_ism;
            ui.add(egui::Slider::new(&mut v.vals.count, 1..=1024).text("VALs"));
            ui.add(egui::Slider::new(&mut v.vals.iterations, 0..=64).text("k-means iterations"));
            ui.horizontal(|ui| {
                ui.radio_value(&mut v.disk, DiskLight::Parts, "disk: 5 parts");
                ui.radio_value(&mut v.disk, DiskLight::Centre, "disk: centre (paper)");
            });
            ui.checkbox(&mut v.hard_lookups, "hard lookups (no PCSS)");
            if !v.hard_lookups {
                let p = &mut v.pcss;
                ui.add(
                    egui::Slider::new(&mut p.blocker_samples, 1..=64).text("PCSS blocker samples"),
                );
                ui.add(
                    egui::Slider::new(&mut p.filter_samples, 1..=128).text("PCSS filter samples"),
                );
            }
            ism_controls(ui, &mut v.ism);
            interleave(ui, &mut v.interleave);
        }
        "per-vpl-shadow-maps" => {
            ui.add(egui::Slider::new(&mut s.per_vpl.map_size, 16..=512).text("map size"));
            ui.add(egui::Slider::new(&mut s.per_vpl.batch, 1..=256).text("VPLs per batch"));
        }
        _ => {}
    }
    let voxels = s.gates.gates.shape == GateShape::Voxels;
    if mode == "gates" && voxels && s.vals.interleave.block > 1 {
        ui.horizontal(|ui| {
            for (name, hover, setting) in SETTINGS {
                let button = ui.button(format!("{name} setting"));
                if button.on_hover_text(hover).clicked() {
                    set_gates(s, setting);
                }
            }
        });
        let now = GatesParams {
            interleave: s.vals.interleave,
            ..s.gates
        };
        ui.label(format!("gates setting: {}", setting_name(&now)))
            .on_hover_text("the setting the ticks above make, or your own where they make none");
    }
    let il = &mut s.vals.interleave;
    il.starved_taps = il.starved_taps.min(il.block * il.block);
    s.gates.interleave = *il;
}

/// One of the gates' settings ([`GatesParams::fast`], `balanced`, `accurate`).
type GatesSetting = fn(GatesParams) -> GatesParams;

/// The gates' three settings, as the viewer names them (its buttons: "NAME setting") and
/// describes them.
const SETTINGS: [(&str, &str, GatesSetting); 3] = [
    (
        "fast",
        "the walk passing closed voxels on their planes, the box blur, no second walks and no \
         near field (render --fast): the fastest walk, which loses light where columns, \
         curtains or plants stand within a sight voxel of the light's paths",
        GatesParams::fast,
    ),
    (
        "balanced",
        "the default: the triangles in closed voxels, the tent blur, the dark pixels' walks and \
         the near field of 4 blocks (render --balanced): the reference's light within a few per \
         cent and under 1 % of the lit pixels black where measured, the light's own room's \
         creases as the reference draws them, at 1.2-2.5x the fast setting's frame on a \
         software rasterizer before the near field (which adds 0-45 %)",
        GatesParams::balanced,
    ),
    (
        "accurate",
        "the triangles in closed voxels, the tent blur, the near field and the starved taps at \
         3/4 of the block (render --accurate): the reference's light within a few per cent, \
         under 1 % of the lit pixels black and the lowest error where measured, at several \
         times the frame",
        GatesParams::accurate,
    ),
];

/// What every setting starts from: `g` in the fast setting, without starved taps (each
/// setting has its own); its block, blur thresholds, fill and roulette as they are.
fn setting_base(g: GatesParams) -> GatesParams {
    GatesParams {
        interleave: InterleaveParams {
            starved_taps: 0,
            ..g.interleave
        },
        ..g
    }
    .fast()
}

/// A setting of the gates (`render --fast`: [`GatesParams::fast`]; `--balanced`,
/// `--accurate`), whole, on the viewer's gates, whose interleaving is the VAL modes' (one
/// block for both, to compare like with like).
fn set_gates(s: &mut MethodSettings, setting: GatesSetting) {
    s.gates = setting(setting_base(GatesParams {
        interleave: s.vals.interleave,
        ..s.gates
    }));
    s.vals.interleave = s.gates.interleave;
}

/// Which of the three settings gates `g` are in, or "your own".
fn setting_name(g: &GatesParams) -> &'static str {
    let base = setting_base(*g);
    SETTINGS
        .iter()
        .find(|(_, _, setting)| setting(base) == *g)
        .map_or("your own", |(name, ..)| name)
}

/// The viewer's settings at start: every method's defaults, the gates in the balanced setting
/// (`visgate render`'s default), whose tent blur the VAL modes share.
pub fn start_settings() -> MethodSettings {
    let mut s = MethodSettings::default();
    set_gates(&mut s, GatesParams::balanced);
    s
}

/// The direct lights' shadows: each light's maps, or LightCluster with its clustering, disk
/// and PCSS sampling.
pub fn direct_settings(ui: &mut egui::Ui, direct: &mut DirectLight) {
    let mut lc = matches!(direct, DirectLight::LightCluster(_));
    ui.horizontal(|ui| {
        ui.label("direct shadows");
        ui.radio_value(&mut lc, false, "per light");
        ui.radio_value(&mut lc, true, "LightCluster");
    });
    match (lc, &mut *direct) {
        (false, _) => *direct = DirectLight::PerLight,
        (true, DirectLight::PerLight) => {
            *direct = DirectLight::LightCluster(LightClusterGpuParams::default());
        }
        (true, DirectLight::LightCluster(p)) => lc_controls(ui, p),
    }
}

/// LightCluster's clustering, disk and PCSS sampling (direct lights or VPLs).
fn lc_controls(ui: &mut egui::Ui, p: &mut LightClusterGpuParams) {
    let c = &mut p.clustering;
    ui.add(
        egui::Slider::new(&mut c.min_distance_m, 0.0..=20.0)
            .logarithmic(true)
            .text("min distance (m)"),
    );
    ui.add(egui::Slider::new(&mut c.distance_scale, 0.0..=1.0).text("distance scale (1/m)"));
    ui.add(egui::Slider::new(&mut c.max_clusters, 1..=256).text("max clusters"));
    ui.horizontal(|ui| {
        ui.radio_value(&mut p.disk, LcDisk::Extent, "disk: extent");
        ui.radio_value(
            &mut p.disk,
            LcDisk::MinDistance,
            "disk: min distance (paper)",
        );
    });
    let samples = &mut p.pcss;
    ui.add(egui::Slider::new(&mut samples.blocker_samples, 1..=64).text("PCSS blocker samples"));
    ui.add(egui::Slider::new(&mut samples.filter_samples, 1..=128).text("PCSS filter samples"));
}

/// The imperfect shadow maps: map side (auto or a power of two), points, pull-push, bias.
fn ism_controls(ui: &mut egui::Ui, p: &mut IsmParams) {
    let mut log2 = p.map_size.map_or(0, |s| s.trailing_zeros());
    ui.add(
        egui::Slider::new(&mut log2, 0..=9)
            .custom_formatter(|v, _| match v as u32 {
                0..=3 => "auto".into(),
                k => format!("{}²", 1u32 << k),
            })
            .text("ISM map size"),
    );
    p.map_size = (log2 >= 4).then(|| 1 << log2);
    ui.add(
        egui::Slider::new(&mut p.points_per_map, 64..=65_536)
            .logarithmic(true)
            .text("ISM points per map"),
    );
    ui.add(egui::Slider::new(&mut p.pull_push, 0..=6).text("pull-push levels"));
    ui.add(egui::Slider::new(&mut p.coverage, 0.25..=16.0).text("splat coverage"));
    ui.add(egui::Slider::new(&mut p.bias, 0.0..=16.0).text("ISM bias (texels)"));
}

/// The interleaving block's slider and, while it is over 1, the blur's fill and tent.
fn interleave(ui: &mut egui::Ui, il: &mut InterleaveParams) {
    ui.add(egui::Slider::new(&mut il.block, 1..=8).text("interleave block"));
    if il.block > 1 {
        ui.checkbox(&mut il.fill, "blur filled from the next blocks")
            .on_hover_text(
                "a neighbour whose surface does not agree with the pixel gives way to the \
                 nearest copy of its VPL subset a block away that does: the average holds more \
                 of the VPLs along edges and jambs, at a few % of the frame",
            );
        ui.checkbox(&mut il.tent, "tent blur").on_hover_text(
            "the neighbours weighted by a tent twice the block's side instead of the \
                 block's box: every VPL subset weighs the same, and a bright or dark pixel \
                 spreads as a soft pyramid instead of a square",
        );
    }
}

/// The camera: speed, field of view, the scene's cameras as bookmarks, framing the level.
pub fn camera_controls(ui: &mut egui::Ui, camera: &mut FlyCamera, scene: &Scene) {
    ui.label(
        "WASD + QE fly, right drag looks, middle drag orbits about the surface under the \
         pointer, scroll sets the speed, F frames the level",
    );
    ui.add(
        egui::Slider::new(&mut camera.speed, 1e-3..=1e4)
            .logarithmic(true)
            .text("speed (m/s)"),
    );
    let mut fov = camera.fov_x.to_degrees();
    if ui
        .add(egui::Slider::new(&mut fov, 10.0..=150.0).text("field of view (°)"))
        .changed()
    {
        camera.fov_x = fov.to_radians();
    }
    ui.horizontal_wrapped(|ui| {
        for c in &scene.cameras {
            if ui.button(&c.name).clicked() {
                *camera = FlyCamera::from_camera(c, camera.speed);
            }
        }
    });
    let e = camera.eye;
    ui.label(format!("eye ({:.2}, {:.2}, {:.2}) m", e.x, e.y, e.z));
}

/// The frame's passes as a stacked bar and a table, and the frame times of the last frames.
pub fn pass_times(ui: &mut egui::Ui, size: [u32; 2], t: &PassTimes, history: &VecDeque<f32>) {
    ui.label(format!("{} × {}", size[0], size[1]));
    let passes = t.by_name();
    let total: f64 = passes
        .iter()
        .map(|(_, g, c)| g.or(*c).unwrap_or(0.0))
        .sum::<f64>()
        .max(1e-9);
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 14.0), egui::Sense::hover());
    let mut x = rect.left();
    for (k, (_, g, c)) in passes.iter().enumerate() {
        let w = (g.or(*c).unwrap_or(0.0) / total) as f32 * rect.width();
        let colour = egui::ecolor::Hsva::new(k as f32 * 0.13 % 1.0, 0.6, 0.8, 1.0);
        let r = egui::Rect::from_min_size(egui::pos2(x, rect.top()), egui::vec2(w, 14.0));
        ui.painter().rect_filled(r, 0.0, colour);
        x += w;
    }
    let source = if t.gpu_total().is_some() {
        "GPU"
    } else {
        "CPU wall"
    };
    egui::Grid::new("passes").striped(true).show(ui, |ui| {
        for (name, g, c) in &passes {
            ui.label(*name);
            ui.label(format!("{:.2} ms", g.or(*c).unwrap_or(0.0) * 1e3));
            ui.end_row();
        }
        ui.label(format!("frame ({source})"));
        ui.label(format!(
            "{:.2} ms",
            t.gpu_total().unwrap_or(t.frame_s) * 1e3
        ));
        ui.end_row();
    });
    if let Some(l) = &t.lists {
        ui.label(format!(
            "light lists: {} geometry clusters, {} entries ({:.1} % of the pool); outside every \
             visibility cluster: {} pixels, {} VPLs",
            l.geometry_clusters,
            l.entries,
            100.0 * l.entries as f64 / l.capacity.max(1) as f64,
            l.pixels_outside,
            l.vpls_outside
        ));
    }
    if let Some(r) = &t.ratio {
        ui.label(format!(
            "ratio estimator: unshadowed light at {} grid pixels (every {} px) and {} of their \
             own ({:.1} %)",
            r.grid,
            r.stride,
            r.own,
            100.0 * f64::from(r.own) / f64::from(r.pixels.max(1))
        ));
    }
    if let Some(c) = &t.direct_clusters {
        ui.label(format!(
            "LightCluster: {} lights in {} clusters, {} culled",
            c.lights - c.culled,
            c.clusters,
            c.culled
        ));
    }
    if let Some(v) = &t.vals {
        ui.label(format!(
            "VAL clustering: {} of {} VALs live, {} of at most {} iterations{}",
            v.live,
            v.count,
            v.iterations,
            v.max,
            if v.converged { ", converged" } else { "" }
        ));
    }
    // Frame times, newest right, scaled to the slowest.
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 48.0), egui::Sense::hover());
    let max = history.iter().copied().fold(1e-3f32, f32::max);
    let n = history.len().max(2) - 1;
    let points: Vec<egui::Pos2> = history
        .iter()
        .enumerate()
        .map(|(i, ms)| {
            egui::pos2(
                rect.left() + rect.width() * i as f32 / n as f32,
                rect.bottom() - rect.height() * ms / max,
            )
        })
        .collect();
    ui.painter().rect_stroke(
        rect,
        0.0,
        egui::Stroke::new(1.0, egui::Color32::GRAY),
        egui::StrokeKind::Inside,
    );
    ui.painter().add(egui::Shape::line(
        points,
        egui::Stroke::new(1.5, egui::Color32::LIGHT_GREEN),
    ));
    ui.label(format!(
        "frame time, last {} frames (max {max:.1} ms)",
        history.len()
    ));
}

/// `--shader-dir`: where the shaders come from, or the error that keeps the last good ones.
pub fn shader_status(ui: &mut egui::Ui, w: &super::shader_watch::ShaderWatch) {
    match &w.error {
        Some(e) => {
            ui.colored_label(
                egui::Color32::LIGHT_RED,
                format!("shader error, the last good shaders draw on:\n{e}"),
            );
        }
        None => {
            ui.label(format!(
                "shaders: {} file(s) from {} (compiled {} time(s); saved changes reload)",
                w.files,
                w.dir().display(),
                w.reloads
            ));
        }
    }
}

/// The gates' block as a frame of `vpls` VPLs runs it, where that is smaller than the block
/// set ([`GpuMode::shrunk_block`]): "189 VPLs: 2 × 2 blocks (3.0 a pixel in 8 × 8)".
pub fn block_note(mode: &GpuMode, vpls: u32) -> Option<String> {
    let (b, g, each) = mode.shrunk_block(vpls)?;
    Some(format!(
        "{vpls} VPLs: {b} × {b} blocks ({each:.1} a pixel in {g} × {g})"
    ))
}

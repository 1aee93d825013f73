//! Snapshot tests of the viewer's window, rendered headless by egui_kittest with wgpu
//! (lavapipe in CI): the four rooms with a level baked at 64, one snapshot per debug layer and
//! one of the split comparison with the reference. The goldens are `tests/snapshots/*.png`;
//! they change only when asked (`UPDATE_SNAPSHOTS=1 cargo test --bin visgate snapshots`), and a
//! failure writes the new image and the difference beside them (`*.new.png`, `*.diff.png`).

use egui_kittest::kittest::Queryable;
use egui_kittest::{Harness, SnapshotOptions};
use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_preprocess::bake::{BakeOptions, bake};
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::gpu::GatesParams;
use visgate_runtime::job::RenderJob;
use visgate_scenes::Builtin;

use super::{Start, ViewerApp};
use crate::view::layers::Layers;

/// The viewer of the four rooms (baked at 64), its first camera, 32 light paths, a 240×150
/// frame, with `layers` and, if `compare`, the reference beside the method.
fn viewer(layers: Layers, compare: bool) -> ViewerApp {
    let scene = Builtin::FourRooms.scene().expect("scene");
    let params = BakeParams {
        resolution: Resolution::LongestAxisVoxels(64),
        ..BakeParams::default()
    };
    let baked = bake(&scene, &params, &BakeOptions::default(), &|_| {}).expect("bake");
    let level = GateLevel::new(baked.level, &scene).expect("level");
    let g_max = RenderJob::default()
        .for_scene(&scene)
        .expect("job")
        .params
        .g_max;
    let start = Start {
        time: 0.0,
        level: Some(level),
        mode: "gates",
        vpls: Some(32),
        rsm: false,
        size: Some([240, 150]),
        g_max,
        camera: Some(0),
        screenshot: None,
        window_shot: None,
        layers,
        compare,
        benchmark: None,
        benchmark_path: None,
        record_path: "camera-path.json".into(),
        restore: None,
        persist: false,
        shader_dir: None,
        scene,
    };
    ViewerApp::new(start, window()).expect("viewer")
}

/// A fresh window device as the viewer's window asks for it (`view::wgpu_setup`), preferring
/// a software adapter as kittest does (the goldens come from lavapipe).
fn window() -> eframe::egui_wgpu::RenderState {
    use eframe::egui_wgpu::WgpuSetup;
    let setup = match egui_kittest::wgpu::default_wgpu_setup() {
        WgpuSetup::CreateNew(mut kittest) => {
            let ours = crate::view::wgpu_setup();
            kittest.instance_descriptor.backends = ours.instance_descriptor.backends;
            kittest.device_descriptor = ours.device_descriptor;
            WgpuSetup::CreateNew(kittest)
        }
        existing => existing,
    };
    let options = eframe::egui_wgpu::RendererOptions::PREDICTABLE;
    egui_kittest::wgpu::create_render_state(setup, options)
}

/// The harness that draws `app`'s window with the app's own device.
fn harness(app: ViewerApp) -> Harness<'static, ViewerApp> {
    let renderer = egui_kittest::wgpu::WgpuTestRenderer::from_render_state(app.window.clone());
    Harness::builder()
        .with_size([900.0, 560.0])
        .renderer(renderer)
        .build_ui_state(|ui, app: &mut ViewerApp| app.draw(ui), app)
}

/// Renders the window until the frame (and the reference, if asked) is drawn, then checks it
/// against golden `name`.
fn snapshot(name: &str, layers: Layers, compare: bool) {
    let mut harness = harness(viewer(layers, compare));
    for _ in 0..600 {
        harness.step();
        let app = harness.state();
        if app.frames > 0 && (!compare || app.compare.is_done()) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // Two more steps: the layers and the reference are drawn the frame after they are ready.
    harness.run_steps(2);
    assert!(harness.state().frames > 0, "{name}: no frame");
    harness.snapshot_options(name, &SnapshotOptions::new().threshold(2.0));
}

/// The window of `app` stepped until its first frame is drawn.
fn first_frame(app: ViewerApp) -> Harness<'static, ViewerApp> {
    let mut harness = harness(app);
    for _ in 0..600 {
        harness.step();
        if harness.state().frames > 0 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    harness
}

/// Steps `harness` until it has drawn more than `before` frames (a minute at most).
fn until_a_frame_after(harness: &mut Harness<'static, ViewerApp>, before: u32) {
    for _ in 0..3000 {
        harness.step();
        if harness.state().frames > before {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

// One test per snapshot: kittest keeps one harness's results per test.

#[test]
fn the_viewer_with_clusters_and_gates() {
    let layers = Layers {
        clusters: true,
        gates: true,
        ..Layers::default()
    };
    snapshot("viewer_clusters_gates", layers, false);
}

#[test]
fn the_viewer_with_the_skeleton_and_vpls() {
    let layers = Layers {
        skeleton: true,
        vpls: true,
        ..Layers::default()
    };
    snapshot("viewer_skeleton_vpls", layers, false);
}

#[test]
fn the_viewer_with_geometry_clusters() {
    let layers = Layers {
        geometry: true,
        ..Layers::default()
    };
    snapshot("viewer_geometry_clusters", layers, false);
}

#[test]
fn the_viewer_with_light_list_lengths() {
    let layers = Layers {
        lists: true,
        ..Layers::default()
    };
    snapshot("viewer_light_lists", layers, false);
}

#[test]
fn the_viewer_with_the_indirect_light_alone() {
    let layers = Layers {
        indirect: true,
        ..Layers::default()
    };
    snapshot("viewer_indirect", layers, false);
}

#[test]
fn the_viewer_beside_the_reference() {
    snapshot("viewer_compare", Layers::default(), true);
}

#[test]
fn the_viewer_reads_the_point_under_the_pointer_on_a_dark_band() {
    // The line under the frame (the point, its normal, the VPLs facing it and those the gates
    // pass) is drawn on a dark band: white on a lit wall could not be read.
    let mut harness = first_frame(viewer(Layers::default(), false));
    harness.hover_at(eframe::egui::pos2(600.0, 280.0));
    harness.run_steps(2);
    harness.snapshot_options("viewer_probe", &SnapshotOptions::new().threshold(2.0));
}

#[test]
fn the_viewer_starts_balanced_and_its_fast_setting_walks_the_planes() {
    let mut harness = first_frame(viewer(Layers::default(), false));
    // The balanced setting, `visgate render`'s default: the triangles listed for the first
    // frame (the level loads without them), the dark pixels' pass in it.
    let app = harness.state();
    assert_eq!(
        app.settings.gates,
        on_software(GatesParams::default().balanced())
    );
    let listed = |app: &ViewerApp| {
        let cpu = app
            .start
            .level
            .as_ref()
            .map(|l| l.sight().triangles_listed());
        (cpu, app.gpu.level_has_triangles())
    };
    assert_eq!(listed(app), (Some(true), true));
    assert!(has_pass(app, "indirect lighting: starved pixels"));
    assert!(
        has_pass(app, "indirect lighting: unshadowed"),
        "the ratio's pass"
    );
    harness.get_by_label("gates setting: balanced");
    // Its grid's slider beside the tick, at the setting's 3 px.
    let grid_slider =
        |h: &Harness<'static, ViewerApp>| h.query_all_by_label("ratio grid (px)").next().is_some();
    assert!(grid_slider(&harness));
    assert_eq!(harness.state().settings.gates.ratio_stride, 3);
    // And where it summed, under the passes.
    let said = harness.query_all_by_label_contains("ratio estimator: unshadowed light at");
    assert!(said.count() == 1, "the grid's report");
    // The ratio's tick: its pass off on the next frame, its grid's slider gone, a setting of
    // the user's own; on again.
    let app = clicked(&mut harness, "ratio estimator");
    assert!(!app.settings.gates.ratio);
    assert!(!has_pass(app, "indirect lighting: unshadowed"));
    assert!(!grid_slider(&harness));
    harness.get_by_label("gates setting: your own");
    let app = clicked(&mut harness, "ratio estimator");
    assert!(has_pass(app, "indirect lighting: unshadowed"));
    harness.get_by_label("gates setting: balanced");
    // The fast setting: no triangles, no tent, no second pass, no ratio.
    let app = clicked(&mut harness, "fast setting");
    assert_eq!(app.settings.gates, on_software(GatesParams::default()));
    assert!(!has_pass(app, "indirect lighting: starved pixels"));
    assert!(!has_pass(app, "indirect lighting: unshadowed"));
    assert!(has_pass(app, "indirect lighting"));
    harness.get_by_label("gates setting: fast");
    // The triangles' tick alone on it: a setting of the user's own.
    let app = clicked(&mut harness, "triangles in closed voxels");
    assert!(app.settings.gates.gates.triangles && !app.settings.gates.interleave.tent);
    harness.get_by_label("gates setting: your own");
}

/// Clicks `label` and waits for the next frame, which has no error.
fn clicked<'h>(harness: &'h mut Harness<'static, ViewerApp>, label: &str) -> &'h ViewerApp {
    let before = harness.state().frames;
    harness.get_by_label(label).click();
    until_a_frame_after(harness, before);
    let app = harness.state();
    assert_eq!(app.error, None);
    assert!(app.frames > before, "no frame after {label}");
    app
}

/// Whether `app`'s last frame has the pass `name`.
fn has_pass(app: &ViewerApp, name: &str) -> bool {
    let (_, times) = app.last.as_ref().expect("a frame");
    times.passes.iter().any(|p| p.name == name)
}

#[test]
fn the_viewer_s_accurate_setting_walks_the_triangles_and_the_starved_pixels() {
    let mut harness = first_frame(viewer(Layers::default(), false));
    let g = clicked_walks_starved(&mut harness, "accurate setting");
    assert!(g.gates.triangles && g.interleave.tent);
    assert_eq!(g.interleave.starved_taps, 48, "3/4 of the 8 x 8 block");
    harness.get_by_label("gates setting: accurate");
}

/// `g` as the viewer holds it on a software adapter (these tests' lavapipe): its block kept
/// whatever the VPL count (32 here would run in 1 × 1 blocks).
fn on_software(mut g: GatesParams) -> GatesParams {
    g.interleave.min_vpls = 0;
    g
}

/// Clicks the setting button `label` and waits for the next frame: it has no error and has
/// the starved pixels' pass; returns the gates' settings the button made.
fn clicked_walks_starved(harness: &mut Harness<'static, ViewerApp>, label: &str) -> GatesParams {
    let app = clicked(harness, label);
    assert!(has_pass(app, "indirect lighting: starved pixels"));
    app.settings.gates
}

#[test]
fn the_viewer_s_balanced_setting_walks_the_triangles_and_the_dark_pixels() {
    let mut harness = first_frame(viewer(Layers::default(), false));
    // From the accurate setting back to the balanced one: its own starved taps (none).
    clicked_walks_starved(&mut harness, "accurate setting");
    let g = clicked_walks_starved(&mut harness, "balanced setting");
    assert_eq!(g, on_software(GatesParams::default().balanced()));
    // Its tick turns the dark pixels' walks off again.
    let app = clicked(&mut harness, "dark pixels walk the rest");
    assert!(!app.settings.gates.interleave.starved_dark);
    let (_, times) = app.last.as_ref().expect("a frame");
    assert!(
        !times.passes.iter().any(|p| p.name.contains("starved")),
        "no starved pass without it"
    );
}

#[test]
fn the_viewer_renders_lightcluster_direct_shadows() {
    use visgate_runtime::gpu::{DirectLight, LightClusterGpuParams};
    let mut app = viewer(Layers::default(), false);
    app.direct = DirectLight::LightCluster(LightClusterGpuParams::default());
    let harness = first_frame(app);
    let app = harness.state();
    assert_eq!(app.error, None);
    let (_, times) = app.last.as_ref().expect("a frame");
    let c = times.direct_clusters.expect("LightCluster's counts");
    // The four rooms' point light and spot.
    assert_eq!(c.lights, 2);
    assert!((1..=2).contains(&c.clusters), "{c:?}");
    assert!(times.passes.iter().any(|p| p.name == "PCSS visibility"));
}

#[test]
fn the_viewer_draws_val_isms_vals_as_disks() {
    let mut app = viewer(
        Layers {
            vals: true,
            ..Layers::default()
        },
        false,
    );
    app.start.mode = "val-ism";
    app.settings.val_ism.vals.count = 8;
    let mut harness = first_frame(app);
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(app.error, None);
    let (_, disks) = app.val_disks.as_ref().expect("the VAL layer's disks");
    // The 32 light paths' VPLs in at most 8 VALs, each a disk of positive size.
    assert!((1..=8).contains(&disks.len()), "{}", disks.len());
    assert!(
        disks
            .iter()
            .all(|d| d.radius >= 0.0 && d.radius.is_finite())
    );
    assert!(disks.iter().any(|d| d.radius > 0.0));
    harness.snapshot_options(
        "viewer_val_ism_vals",
        &SnapshotOptions::new().threshold(2.0),
    );
}

#[test]
fn the_viewer_says_when_few_vpls_shrink_the_gates_block() {
    let mut harness = first_frame(viewer(Layers::default(), false));
    // On a software adapter the block stays 8 × 8 at the test's 32 VPLs, and nothing is said.
    assert_eq!(harness.state().settings.vals.interleave.min_vpls, 0);
    let slider = harness.query_all_by_label("fewest VPLs a pixel").next();
    assert!(slider.is_some(), "its slider beside the block's");
    assert!(harness.state().block_note.is_none());
    // Asked for 4 a pixel: 32 VPLs run in 2 × 2 blocks, said under the settings.
    let before = harness.state().frames;
    harness.state_mut().settings.vals.interleave.min_vpls = 4;
    until_a_frame_after(&mut harness, before);
    let note = "32 VPLs: 2 × 2 blocks (0.5 a pixel in 8 × 8)";
    assert_eq!(harness.state().block_note.as_deref(), Some(note));
    harness.step();
    harness.get_by_label(note);
}

//! LightCluster on the GPU (`--direct lightcluster`): the clustering equals its CPU twin, PCSS
//! with radius 0 is the hard shadow, an umbra stays dark and the open stays lit, and 0, 1,
//! 1,024 lights, too many lights and lights inside geometry. A missing adapter fails the test.

use glam::{Vec2, Vec3};
use visgate_formats::{Camera, Light, Scene};
use visgate_runtime::camera::View;
use visgate_runtime::cpu::lightcluster::{LightClusterParams, cluster_lights};
use visgate_runtime::cpu::reference::{ReferenceParams, render_reference};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::gpu::{
    DirectLight, GpuContext, GpuMode, GpuParams, GpuRenderer, InterleaveParams, LcDisk,
    LightClusterGpuParams, MAX_LC_LIGHTS,
};
use visgate_runtime::hdr::HdrImage;
use visgate_scenes::Builtin;

mod common;
use common::{closed_box, floor, quads};

fn context() -> GpuContext {
    match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("GPU tests need an adapter (CI installs lavapipe): {e}"),
    }
}

fn lc(min_distance_m: f32, distance_scale: f32, max_clusters: u32) -> LightClusterGpuParams {
    LightClusterGpuParams {
        clustering: LightClusterParams {
            min_distance_m,
            distance_scale,
            max_clusters,
            ..LightClusterParams::default()
        },
        // The paper's disk: its radius is the minimum distance (PCSS at every radius).
        disk: LcDisk::MinDistance,
        ..LightClusterGpuParams::default()
    }
}

fn point(p: Vec3, i: f32) -> Light {
    Light::Point {
        position: p,
        intensity: Vec3::splat(i),
    }
}

fn camera(eye: Vec3, target: Vec3, fov_deg: f32) -> Camera {
    Camera {
        name: "test".into(),
        eye,
        target,
        up: Vec3::Y,
        fov_x_rad: fov_deg.to_radians(),
    }
}

/// `n` lights scattered (a fixed LCG) in the box [-r, r]³, intensities 1–3 W/sr.
fn scattered(n: usize, r: f32) -> Vec<Light> {
    let mut s = 0x2545_f491_u32;
    let mut next = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    (0..n)
        .map(|_| {
            let p = Vec3::new(next(), next(), next()) * 2.0 * r - Vec3::splat(r);
            point(p, 1.0 + 2.0 * next())
        })
        .collect()
}

/// The GPU's clusters against the CPU twin's for every camera of `scene` and every setting.
fn check_twin(ctx: &GpuContext, scene: &Scene, cameras: &[Camera], settings: &[(f32, f32, u32)]) {
    let mut gpu = GpuRenderer::new(ctx, scene).expect("upload");
    let diagonal = scene.diagonal_m();
    for cam in cameras {
        let view = View::new(cam, [320, 180]).expect("view");
        for &(d, s, m) in settings {
            let p = lc(d, s, m);
            let mut got = gpu.cluster_direct_lights(ctx, &view, &p).expect("GPU");
            let want = cluster_lights(&scene.lights, &view, diagonal, &p.clustering).expect("CPU");
            let what = format!(
                "{} lights, camera {}, min distance {d} m, scale {s}, max {m}",
                scene.lights.len(),
                cam.name
            );
            // Extents are square roots the GPU may round otherwise: within 1e-5 m.
            assert_eq!(got.extent_m.len(), want.extent_m.len(), "{what}");
            for (g, w) in got.extent_m.iter().zip(&want.extent_m) {
                assert!(
                    (g - w).abs() <= 1e-5 * w.max(1.0),
                    "{what}: extent {g} vs {w}"
                );
            }
            got.extent_m.clone_from(&want.extent_m);
            assert_eq!(got, want, "{what}");
        }
    }
}

#[test]
fn gpu_clustering_equals_its_cpu_twin() {
    let ctx = context();
    let settings = [
        (0.0, 0.1, 64),
        (0.5, 0.1, 64),
        (1.0, 0.1, 64),
        (2.0, 0.0, 64),
        (4.0, 0.5, 64),
        (1.0, 0.1, 5),
        (0.0, 0.0, 256),
    ];
    let hall = Builtin::LampHall.scene().expect("scene");
    assert_eq!(hall.lights.len(), 51);
    check_twin(&ctx, &hall, &hall.cameras, &settings);
    // 0, 1 and 1,024 lights in a 20 m box, seen from inside and from a corner.
    let cams = [
        camera(Vec3::ZERO, Vec3::new(1.0, 0.2, 0.3), 75.0),
        camera(Vec3::splat(9.0), Vec3::ZERO, 60.0),
    ];
    for n in [0, 1, 1024] {
        let scene = quads(&closed_box(10.0), 0.5, scattered(n, 9.5));
        check_twin(&ctx, &scene, &cams, &settings);
    }
}

#[test]
fn clusters_shrink_near_the_camera_and_lights_out_of_view_are_culled() {
    let ctx = context();
    let hall = Builtin::LampHall.scene().expect("scene");
    let mut gpu = GpuRenderer::new(&ctx, &hall).expect("upload");
    // Down the south row from its west end: the row's far lamps merge more than its near ones.
    let cam = hall
        .cameras
        .iter()
        .find(|c| c.name == "south-row")
        .expect("camera");
    let view = View::new(cam, [320, 180]).expect("view");
    let c = gpu
        .cluster_direct_lights(&ctx, &view, &lc(0.6, 0.5, 64))
        .expect("GPU");
    let near: Vec<f32> = c
        .centres
        .iter()
        .zip(&c.radius_m)
        .filter(|&(&i, _)| hall.lights[i as usize].position().x < 4.0)
        .map(|(_, &r)| r)
        .collect();
    let far: Vec<f32> = c
        .centres
        .iter()
        .zip(&c.radius_m)
        .filter(|&(&i, _)| hall.lights[i as usize].position().x > 12.0)
        .map(|(_, &r)| r)
        .collect();
    assert!(!near.is_empty() && !far.is_empty(), "{c:?}");
    let max_near = near.iter().copied().fold(0.0, f32::max);
    let min_far = far.iter().copied().fold(f32::MAX, f32::min);
    assert!(max_near < min_far, "near radii {near:?}, far {far:?}");
    // Looking at the west wall from 1 m: the lamps behind the camera and in the side rooms
    // east of it are culled with a tight cutoff.
    let wall = camera(Vec3::new(1.0, 1.5, 2.5), Vec3::new(0.0, 1.5, 2.5), 60.0);
    let view = View::new(&wall, [320, 180]).expect("view");
    let mut p = lc(1.0, 0.1, 64);
    p.clustering.cutoff = 0.5;
    let c = gpu.cluster_direct_lights(&ctx, &view, &p).expect("GPU");
    assert!(c.culled > 20, "{} of 51 culled", c.culled);
}

/// A 40 m floor, a point light 4 m above its centre and a blocker 2 m up, `half` m square.
fn blocker_scene(half: f32) -> Scene {
    let b = [
        Vec3::new(-half, 2.0, -half),
        Vec3::new(half, 2.0, -half),
        Vec3::new(half, 2.0, half),
        Vec3::new(-half, 2.0, half),
    ];
    // Both faces of the blocker (one-sided quads).
    let under = [b[0], b[3], b[2], b[1]];
    quads(
        &[floor(20.0), b, under],
        0.5,
        vec![point(Vec3::new(0.0, 4.0, 0.0), 20.0)],
    )
}

fn render(ctx: &GpuContext, scene: &Scene, view: &View, direct: DirectLight) -> HdrImage {
    let mut gpu = GpuRenderer::new(ctx, scene).expect("upload");
    let params = GpuParams {
        direct,
        ..GpuParams::with_mode(GpuMode::DirectOnly)
    };
    let (img, _) = gpu.render(ctx, view, &[], &params).expect("frame");
    assert!(
        img.pixels.iter().all(|p| p.is_finite()),
        "a pixel is not finite"
    );
    img
}

/// The pixel that world point `p` falls in.
fn pixel(view: &View, p: Vec3) -> (u32, u32) {
    let c = view.view_proj(0.01) * p.extend(1.0);
    let ndc = Vec2::new(c.x, c.y) / c.w;
    (
        ((ndc.x * 0.5 + 0.5) * view.size[0] as f32) as u32,
        ((0.5 - ndc.y * 0.5) * view.size[1] as f32) as u32,
    )
}

#[test]
fn pcss_with_radius_zero_is_the_hard_shadow_map() {
    let ctx = context();
    let scene = blocker_scene(1.0);
    let cam = camera(Vec3::new(9.0, 7.0, 0.0), Vec3::ZERO, 70.0);
    let view = View::new(&cam, [160, 120]).expect("view");
    let hard = render(&ctx, &scene, &view, DirectLight::PerLight);
    let mut p = lc(0.0, 0.0, 1);
    p.map_size = 1024;
    let pcss = render(&ctx, &scene, &view, DirectLight::LightCluster(p));
    // A light alone under visgate's disk (its cluster's extent) is hard at any minimum
    // distance.
    let mut alone = lc(5.0, 0.1, 1);
    alone.disk = LcDisk::Extent;
    alone.map_size = 1024;
    let extent = render(&ctx, &scene, &view, DirectLight::LightCluster(alone));
    assert_eq!(extent.pixels, pcss.pixels);
    let differ = hard
        .pixels
        .iter()
        .zip(&pcss.pixels)
        .filter(|(a, b)| (a.x - b.x).abs() > 0.02 * a.x.max(b.x).max(1e-3))
        .count();
    // The per-light maps filter 3 × 3 (PCF), one lookup here: they differ on the shadow's
    // outline alone.
    let share = differ as f32 / hard.pixels.len() as f32;
    assert!(share < 0.01, "{:.2} % of pixels differ", share * 100.0);
    let (x, y) = pixel(&view, Vec3::ZERO);
    assert!(hard.at(x, y).x < 1e-4 && pcss.at(x, y).x < 1e-4);
}

#[test]
fn an_umbra_stays_dark_and_the_open_stays_lit_at_any_radius() {
    let ctx = context();
    // The blocker spans ±56° below the light, wider than PCSS's widest filter (45°).
    let scene = blocker_scene(3.0);
    let cam = camera(Vec3::new(22.0, 8.0, 6.0), Vec3::new(5.0, 0.0, 0.0), 90.0);
    let view = View::new(&cam, [200, 150]).expect("view");
    let hard = render(&ctx, &scene, &view, DirectLight::PerLight);
    let umbra = pixel(&view, Vec3::new(0.5, 0.0, 0.3));
    // At 14 m the cone from the floor to a disk of radius r passes 1.1 m − 0.75·r from the
    // blocker's edge: nothing hides any of the disk up to r = 1.46 m.
    let open = pixel(&view, Vec3::new(14.0, 0.0, 0.0));
    let lit = hard.at(open.0, open.1).x;
    assert!(lit > 0.0 && hard.at(umbra.0, umbra.1).x < 1e-4);
    for r in [0.0, 0.1, 0.5, 1.0, 2.0, 10.0, 100.0] {
        let img = render(
            &ctx,
            &scene,
            &view,
            DirectLight::LightCluster(lc(r, 0.0, 64)),
        );
        let dark = img.at(umbra.0, umbra.1).x;
        assert!(dark < 1e-3 * lit, "radius {r} m: umbra {dark}, open {lit}");
        if r <= 1.0 {
            let here = img.at(open.0, open.1).x;
            assert!(
                (here - lit).abs() < 0.01 * lit,
                "radius {r} m: open {here}, hard {lit}"
            );
        }
    }
}

#[test]
fn no_lights_many_lights_too_many_lights_and_a_light_inside_geometry() {
    let ctx = context();
    let cam = camera(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, -0.3, 0.2), 80.0);
    let view = View::new(&cam, [96, 64]).expect("view");
    let direct = DirectLight::LightCluster(lc(1.0, 0.1, 64));
    let dark = render(&ctx, &quads(&closed_box(10.0), 0.5, vec![]), &view, direct);
    assert_eq!(dark.mean(), Vec3::ZERO);
    let many = quads(&closed_box(10.0), 0.5, scattered(1024, 9.5));
    let img = render(&ctx, &many, &view, direct);
    // 6,144 cube faces are more layers than an adapter holds: the CPU reference (shadow rays,
    // pixel centres) instead.
    let params = ReferenceParams {
        samples_per_pixel: 1,
        indirect: false,
        ..ReferenceParams::default()
    };
    let (reference, _) = render_reference(
        &Tracer::new(&many),
        &many.lights,
        &[],
        &view,
        &params,
        &|_, _| {},
    )
    .expect("reference");
    let ratio = img.mean().x / reference.mean().x;
    eprintln!("1,024 lights: LightCluster / reference direct energy {ratio:.3}");
    assert!((0.8..=1.05).contains(&ratio), "energy ratio {ratio}");
    let too_many = quads(
        &closed_box(10.0),
        0.5,
        scattered(MAX_LC_LIGHTS as usize + 1, 9.5),
    );
    let mut gpu = GpuRenderer::new(&ctx, &too_many).expect("upload");
    let params = GpuParams {
        direct,
        ..GpuParams::with_mode(GpuMode::DirectOnly)
    };
    let err = gpu
        .render(&ctx, &view, &[], &params)
        .expect_err("too many lights");
    assert!(err.to_string().contains("at most 16384 lights"), "{err}");
    // A light sealed in a 1 m box inside the room lights nothing outside it, clustered
    // alone or with an open light 0.8 m away (then the sealed one is the centre: the cluster's
    // shadow is the box's).
    let mut faces = closed_box(10.0);
    let inner: Vec<[Vec3; 4]> = closed_box(0.5)
        .into_iter()
        .map(|q| q.map(|v| v + Vec3::new(3.0, 0.0, 0.0)))
        .collect();
    // The inner box seen from outside: its faces turned around.
    faces.extend(inner.iter().map(|q| [q[0], q[3], q[2], q[1]]));
    let sealed = point(Vec3::new(3.0, 0.0, 0.0), 5.0);
    let alone = render(&ctx, &quads(&faces, 0.5, vec![sealed]), &view, direct);
    assert!(alone.mean().max_element() < 1e-6, "{:?}", alone.mean());
    let pair = quads(
        &faces,
        0.5,
        vec![sealed, point(Vec3::new(3.8, 0.0, 0.0), 5.0)],
    );
    let shared = render(&ctx, &pair, &view, direct);
    let own = render(&ctx, &pair, &view, DirectLight::PerLight);
    assert!(
        shared.mean().x < 0.05 * own.mean().x,
        "clustered {:?}, own maps {:?}",
        shared.mean(),
        own.mean()
    );
}

#[test]
fn vpl_clusters_shadow_indirect_light_close_to_the_reference() {
    use visgate_runtime::cpu::tracer::Tracer;
    use visgate_runtime::metrics::{errors, indirect_errors};
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let ctx = context();
    let scene = Builtin::FourRooms.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let paths = PathParams {
        paths: 256,
        bounces: 1,
        seed: 3,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let view = View::new(scene.cameras.first().expect("camera"), [96, 72]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let mut frames = Vec::new();
    for block in [1, 8] {
        let il = InterleaveParams {
            block,
            ..InterleaveParams::default()
        };
        let mode = GpuMode::VplClusters(LightClusterGpuParams::default(), il);
        let (img, times) = gpu
            .render(&ctx, &view, &vpls, &GpuParams::with_mode(mode))
            .expect("frame");
        let c = times.vpl_clusters.expect("the VPLs' clusters");
        assert_eq!(c.lights, vpls.len() as u32);
        assert!(c.clusters >= 1 && c.clusters <= 64, "{c:?}");
        frames.push((block, c.clusters, img));
    }
    let (direct, _) = gpu
        .render(&ctx, &view, &[], &GpuParams::with_mode(GpuMode::DirectOnly))
        .expect("direct");
    let params = ReferenceParams {
        samples_per_pixel: 1,
        gather: visgate_runtime::vpl::GatherParams::default(),
        ..ReferenceParams::default()
    };
    let (reference, _) =
        render_reference(&tracer, &scene.lights, &vpls, &view, &params, &|_, _| {})
            .expect("reference");
    for (block, clusters, img) in &frames {
        let i = indirect_errors(img, &reference, &direct).expect("sizes");
        let e = errors(img, &reference).expect("sizes");
        eprintln!(
            "vpl-clusters {block}×{block}, four rooms, {} VPLs in {clusters} clusters: rel. MSE \
             {:.3e}, indirect energy {:.3}, black where lit {:.1} %",
            vpls.len(),
            e.rel_mse,
            i.energy_ratio,
            i.black_where_lit * 100.0
        );
        assert!((0.9..=1.1).contains(&i.energy_ratio), "{}", i.energy_ratio);
        assert!(i.black_where_lit < 0.01, "{}", i.black_where_lit);
        // Interleaved, 256 VPLs leave 4 a pixel: the blur's error on top.
        let bound = if *block == 1 { 5e-3 } else { 3e-2 };
        assert!(e.rel_mse < bound, "{block}: {}", e.rel_mse);
    }
}

#[test]
fn lightcluster_shadows_spots_too_and_combines_with_every_indirect_mode() {
    use visgate_runtime::gpu::{METHODS, MethodSettings};
    use visgate_runtime::vpl::{PathParams, path_vpls};
    let ctx = context();
    // The pillared hall: a point light and a spot. Every light its own cluster (radius 0):
    // the same light as the per-light maps (spots keep their cone in shading).
    let scene = Builtin::PillaredHall.scene().expect("scene");
    let view = View::new(scene.cameras.first().expect("camera"), [96, 64]).expect("view");
    let own = render(&ctx, &scene, &view, DirectLight::PerLight);
    let hard = render(
        &ctx,
        &scene,
        &view,
        DirectLight::LightCluster(lc(0.0, 0.0, 64)),
    );
    let ratio = hard.mean().x / own.mean().x;
    eprintln!("pillared hall, point + spot, radius 0: LightCluster / per light {ratio:.4}");
    assert!((ratio - 1.0).abs() < 0.02, "spot + point: {ratio}");
    // Every registered method without a level, its indirect light beside LightCluster's
    // direct light.
    let tracer = visgate_runtime::cpu::tracer::Tracer::new(&scene);
    let paths = PathParams {
        paths: 64,
        bounces: 1,
        seed: 1,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &paths).expect("vpls");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    for m in METHODS.iter().filter(|m| !m.needs_level) {
        let params = GpuParams {
            direct: DirectLight::LightCluster(LightClusterGpuParams::default()),
            ..GpuParams::with_mode((m.make)(&MethodSettings::default()))
        };
        let (img, times) = gpu
            .render(&ctx, &view, &vpls, &params)
            .unwrap_or_else(|e| panic!("{}: {e}", m.name));
        assert!(img.pixels.iter().all(|p| p.is_finite()), "{}", m.name);
        assert!(img.mean().x > 0.0, "{}", m.name);
        let c = times.direct_clusters.expect("LightCluster's counts");
        assert_eq!(c.lights, 2, "{}", m.name);
        assert!(
            times.passes.iter().all(|p| p.name != "shadow maps"),
            "{}: the per-light maps were drawn",
            m.name
        );
    }
}

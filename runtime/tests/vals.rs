//! Virtual area lights: the GPU k-means against its CPU twin, and the edge cases.

use glam::Vec3;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::cpu::val::centres_of;
use visgate_runtime::cpu::val::{Clustering, NO_VAL, ValParams, cluster};
use visgate_runtime::gpu::{CssmParams, GpuContext, GpuMode, GpuRenderer, ValModeParams};
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

fn hard() -> GpuMode {
    GpuMode::ValHard(ValModeParams::new())
}

fn cssm() -> GpuMode {
    GpuMode::ValCssm(ValModeParams::new(), CssmParams::default())
}

fn context() -> GpuContext {
    GpuContext::new()
        .unwrap_or_else(|e| panic!("GPU tests need an adapter (CI installs lavapipe): {e}"))
}

fn assert_sane(c: &Clustering, n: usize, m: u32) {
    assert_eq!(c.vals.len(), m as usize);
    assert_eq!(c.mapping.len(), n);
    assert!(c.mapping.iter().all(|&k| k < m || k == NO_VAL));
    let counted: u32 = c.vals.iter().map(|v| v.vpl_count()).sum();
    let live = c.mapping.iter().filter(|&&k| k != NO_VAL).count();
    assert_eq!(counted as usize, live);
    for v in &c.vals {
        let all = v
            .position
            .iter()
            .chain(&v.normal)
            .chain(&v.flux)
            .chain(&v.rect);
        assert!(all.clone().all(|x| x.is_finite()), "{v:?}");
        assert!(v.normal[3] >= 0.0, "area {v:?}");
    }
}

#[test]
fn gpu_k_means_equals_the_cpu_twin() {
    let ctx = context();
    for b in [Builtin::CornellBox, Builtin::FourRooms] {
        let (scene, vpls) = common::vpls_of(b, 1024);
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        for (m, iterations) in [(1, 8), (4, 8), (30, 8), (64, 8), (30, 64), (4, 2)] {
            let params = ValParams {
                count: m,
                iterations,
                ..ValParams::default()
            };
            let cpu = cluster(&vpls, &params, None).expect("cpu");
            let got = gpu.cluster_vals(&ctx, &vpls, &params).expect("gpu");
            // Both stop where the assignment repeats itself, after the same updates.
            assert_eq!(
                (cpu.iterations, cpu.converged),
                (got.iterations, got.converged),
                "{} M = {m}, at most {iterations}",
                b.name()
            );
            assert_sane(&cpu, vpls.len(), m);
            assert_sane(&got, vpls.len(), m);
            let differ = cpu
                .mapping
                .iter()
                .zip(&got.mapping)
                .filter(|(a, b)| a != b)
                .count();
            eprintln!(
                "{} M = {m}: {} live VALs, {differ} of {} VPLs mapped differently, {} \
                 iterations (at most {iterations}), converged {}",
                b.name(),
                cpu.live(),
                vpls.len(),
                cpu.iterations,
                cpu.converged
            );
            assert_eq!(differ, 0, "{} M = {m}", b.name());
            for (a, g) in cpu.vals.iter().zip(&got.vals) {
                assert_eq!(a.position[3], g.position[3]);
                for (x, y) in a
                    .position
                    .iter()
                    .chain(&a.normal)
                    .chain(&a.flux)
                    .chain(&a.rect)
                    .zip(
                        g.position
                            .iter()
                            .chain(&g.normal)
                            .chain(&g.flux)
                            .chain(&g.rect),
                    )
                {
                    assert!((x - y).abs() <= 1e-4 * x.abs().max(1.0), "{a:?} vs {g:?}");
                }
            }
        }
    }
}

#[test]
fn vals_stay_sane_at_the_extremes() {
    let ctx = context();
    let (scene, vpls) = common::vpls_of(Builtin::FourRooms, 256);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let p = |count| ValParams {
        count,
        ..ValParams::default()
    };
    // N = 0: empty VALs, no mapping.
    for c in [
        cluster(&[], &p(8), None).expect("cpu"),
        gpu.cluster_vals(&ctx, &[], &p(8)).expect("gpu"),
    ] {
        assert_sane(&c, 0, 8);
        assert_eq!(c.live(), 0);
    }
    // M > N: at most N live VALs, each VPL in one.
    let few = &vpls[..5];
    for c in [
        cluster(few, &p(30), None).expect("cpu"),
        gpu.cluster_vals(&ctx, few, &p(30)).expect("gpu"),
    ] {
        assert_sane(&c, 5, 30);
        assert!(c.live() <= 5);
    }
    // A VAL of one VPL: zero area, centred on its VPL.
    let one = cluster(&vpls[..1], &p(1), None).expect("one");
    assert_eq!(one.vals[0].normal[3], 0.0);
    assert_eq!(one.vals[0].centre(), Vec3::from(vpls[0].position));
    // M = 1: every VPL in it, its rectangle holds them all.
    let all = cluster(&vpls, &p(1), None).expect("M = 1");
    assert_eq!(all.vals[0].vpl_count() as usize, vpls.len());
    assert!(all.vals[0].normal[3] > 0.0);
    // All VPLs coplanar (a floor): zero-area in no direction, normal up, finite.
    let floor: Vec<Vpl> = (0..64)
        .map(|i| {
            Vpl::new(
                Vec3::new((i % 8) as f32, 0.0, (i / 8) as f32),
                Vec3::Y,
                Vec3::ONE,
            )
        })
        .collect();
    for c in [
        cluster(&floor, &p(4), None).expect("cpu"),
        gpu.cluster_vals(&ctx, &floor, &p(4)).expect("gpu"),
    ] {
        assert_sane(&c, 64, 4);
        for v in c.vals.iter().filter(|v| v.vpl_count() > 0) {
            assert!((v.unit_normal() - Vec3::Y).length() < 1e-5, "{v:?}");
        }
    }
    // The same VPLs collapsed onto one point (a VAL of zero extent): finite, area 0.
    let point: Vec<Vpl> = (0..16)
        .map(|_| Vpl::new(Vec3::ONE, Vec3::Y, Vec3::ONE))
        .collect();
    let c = gpu.cluster_vals(&ctx, &point, &p(4)).expect("gpu");
    assert_sane(&c, 16, 4);
    // Bad parameters: clear errors.
    for bad in [
        ValParams { count: 0, ..p(1) },
        ValParams { w_x: -1.0, ..p(4) },
        ValParams {
            w_x: 0.0,
            w_alpha: 0.0,
            ..p(4)
        },
    ] {
        assert!(cluster(&vpls, &bad, None).is_err());
        assert!(gpu.cluster_vals(&ctx, &vpls, &bad).is_err());
    }
}

#[test]
fn a_static_light_gives_the_same_vals_every_frame_at_any_scale() {
    let ctx = context();
    let (scene, vpls) = common::vpls_of(Builtin::FourRooms, 1024);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let params = ValParams::default();
    let a = gpu.cluster_vals(&ctx, &vpls, &params).expect("frame 1");
    let b = gpu.cluster_vals(&ctx, &vpls, &params).expect("frame 2");
    assert_eq!(a, b);
    // Restarting from last frame's centres with the same VPLs changes nothing either.
    let warm = cluster(&vpls, &params, Some(&centres_of(&a))).expect("warm");
    let cold = cluster(&vpls, &params, None).expect("cold");
    let moved = warm
        .mapping
        .iter()
        .zip(&cold.mapping)
        .filter(|(x, y)| x != y)
        .count();
    eprintln!("warm start vs restart: {moved} VPLs change VAL");
    // Position weights are relative to the VPLs' extent: × 1000 in size, the same VALs.
    let big: Vec<Vpl> = vpls
        .iter()
        .map(|v| {
            Vpl::new(
                Vec3::from(v.position) * 1000.0,
                Vec3::from(v.normal),
                Vec3::from(v.flux),
            )
        })
        .collect();
    let scaled = cluster(&big, &params, None).expect("scaled");
    let same = scaled
        .mapping
        .iter()
        .zip(&cold.mapping)
        .filter(|(x, y)| x == y)
        .count();
    assert!(same * 100 >= vpls.len() * 99, "{same} of {}", vpls.len());
}

mod common;

/// GPU image of `scene` from `cam` with `vpls` in `mode`, 64×48, every VPL at every pixel.
fn gpu_image(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    cam: &visgate_formats::Camera,
    vpls: &[Vpl],
    mode: visgate_runtime::gpu::GpuMode,
    vals: u32,
) -> visgate_runtime::hdr::HdrImage {
    gpu_image_with(ctx, scene, cam, vpls, mode, vals, 1, [64, 48])
}

/// As [`gpu_image`] with interleaving blocks of side `interleave` at `size`.
#[allow(clippy::too_many_arguments)]
fn gpu_image_with(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    cam: &visgate_formats::Camera,
    vpls: &[Vpl],
    mode: visgate_runtime::gpu::GpuMode,
    vals: u32,
    interleave: u32,
    size: [u32; 2],
) -> visgate_runtime::hdr::HdrImage {
    use visgate_runtime::gpu::{GpuParams, InterleaveParams};
    let mut gpu = GpuRenderer::new(ctx, scene).expect("upload");
    let v = ValModeParams {
        vals: ValParams {
            count: vals,
            ..ValParams::default()
        },
        interleave: InterleaveParams {
            block: interleave,
            ..InterleaveParams::default()
        },
        ..ValModeParams::new()
    };
    let mode = match mode {
        GpuMode::ValHard(_) => GpuMode::ValHard(v),
        GpuMode::ValCssm(_, c) => GpuMode::ValCssm(v, c),
        other => other,
    };
    let view = visgate_runtime::camera::View::new(cam, size).expect("view");
    gpu.render(ctx, &view, vpls, &GpuParams::with_mode(mode))
        .expect("render")
        .0
}

#[test]
fn vals_a_receiver_under_a_large_blocker_is_dark_and_one_in_the_open_lit() {
    let ctx = context();
    // A floor, a wide blocker 1 m above its middle strip, VPLs above the blocker facing down.
    let (scene, vpls, cam) = common::blocker_scene();
    for (mode, m) in [
        (hard(), 1),
        (hard(), 4),
        (hard(), 30),
        (cssm(), 30),
        (cssm(), 64),
    ] {
        let img = gpu_image(&ctx, &scene, &cam, &vpls, mode, m);
        let none = gpu_image(&ctx, &scene, &cam, &vpls, GpuMode::None, m);
        let [[under, open], [unshadowed, open_none]] =
            common::under_and_open(&scene, &cam, &[&img, &none])
                .try_into()
                .expect("two images");
        let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
        assert!(
            under.len() > 20 && open.len() > 20,
            "{} / {} pixels",
            under.len(),
            open.len()
        );
        let (under, open, unshadowed) = (mean(&under), mean(&open), mean(&unshadowed));
        eprintln!(
            "{mode:?} M = {m}: under the blocker {under}, in the open {open}, unshadowed {unshadowed}"
        );
        // Every VPL sees the open floor over the blocker's edge: lit as without visibility.
        // Hard maps get it exactly; soft ones blur over a penumbra the VAL's size sets.
        let lit = mean(&open_none);
        let (lit_at_least, dark_below) = match mode {
            GpuMode::ValHard(_) => (0.9, 0.02),
            _ => (0.75, 0.1),
        };
        assert!(
            open > lit_at_least * lit && open > 0.0,
            "the open floor is lit: {open} vs {lit}"
        );
        assert!(
            under < dark_below * unshadowed,
            "under the blocker dark: {under} vs {unshadowed}"
        );
    }
}

#[test]
fn vals_are_closer_to_the_reference_than_no_visibility() {
    use visgate_runtime::cpu::reference::{ReferenceParams, render_reference};
    use visgate_runtime::metrics::errors;
    let ctx = context();
    for b in [Builtin::CornellBox, Builtin::FourRooms] {
        let (scene, vpls) = common::vpls_of(b, 1024);
        let cam = scene.cameras[0].clone();
        let tracer = Tracer::new(&scene);
        let view = visgate_runtime::camera::View::new(&cam, [64, 48]).expect("view");
        let (reference, _) = render_reference(
            &tracer,
            &scene.lights,
            &vpls,
            &view,
            &ReferenceParams {
                samples_per_pixel: 1,
                ..ReferenceParams::default()
            },
            &|_, _| {},
        )
        .expect("reference");
        let none = errors(
            &gpu_image(&ctx, &scene, &cam, &vpls, GpuMode::None, 30),
            &reference,
        )
        .expect("size");
        for mode in [hard(), cssm()] {
            let vh =
                errors(&gpu_image(&ctx, &scene, &cam, &vpls, mode, 30), &reference).expect("size");
            eprintln!(
                "{} {mode:?}: MSE none {:.3e}, 30 VALs {:.3e}; rel. MSE {:.3e} vs {:.3e}",
                b.name(),
                none.mse,
                vh.mse,
                none.rel_mse,
                vh.rel_mse
            );
            // Relative MSE everywhere; MSE too in the Cornell box (in the four rooms' lit room
            // the VALs' hard shadows cost about what leaking costs where it is brightest).
            assert!(
                vh.rel_mse < none.rel_mse,
                "{}: {vh:?} vs {none:?}",
                b.name()
            );
            if b == Builtin::CornellBox {
                assert!(vh.mse < none.mse, "{vh:?} vs {none:?}");
            }
            assert!(
                (vh.image_mean / vh.reference_mean - 1.0).abs() < 0.1,
                "{vh:?}"
            );
        }
    }
}

#[test]
fn the_fourier_shadow_test_approaches_the_step_and_rings_within_its_bound() {
    use visgate_runtime::cpu::cssm::{
        DEFAULT_SHARPNESS, receiver_offset, reconstruct, ringing_bound, visibility,
    };
    let mut last = f32::INFINITY;
    for terms in [1, 2, 4, 8, 16] {
        let (mut err, mut lo, mut hi) = (0f32, f32::INFINITY, f32::NEG_INFINITY);
        let n = 200;
        for i in 0..=n {
            for j in 0..=n {
                let (d, z) = (i as f32 / n as f32, j as f32 / n as f32);
                let f = reconstruct(d, z, terms);
                lo = lo.min(f);
                hi = hi.max(f);
                let step = if z >= d { 1.0 } else { 0.0 };
                err += (f - step).abs();
            }
        }
        let err = err / ((n + 1) * (n + 1)) as f32;
        eprintln!("K = {terms}: mean |error| {err:.4}, range [{lo:.4}, {hi:.4}]");
        assert!(err < last, "K = {terms}: {err} not below {last}");
        let b = ringing_bound(terms);
        assert!(lo >= -b && hi <= 1.0 + b, "K = {terms}: [{lo}, {hi}]");
        last = err;
        // Sharpened and clamped, the test is the step but within the receiver offset of it:
        // a surface is not its own blocker, and a blocker farther in front is whole.
        let s = DEFAULT_SHARPNESS;
        let off = receiver_offset(terms, s);
        let mut worst = 0f32;
        for i in 0..=n {
            for j in 0..=n {
                let (d, z) = (i as f32 / n as f32, j as f32 / n as f32);
                if (z - d).abs() > off && (z - d).abs() < 1.0 - off && terms >= 4 {
                    let step = if z >= d { 1.0 } else { 0.0 };
                    worst = worst.max((visibility(d, z, terms, s) - step).abs());
                }
            }
            let z = i as f32 / n as f32;
            assert!(
                visibility(z - off, z, terms, s) > 0.99,
                "K = {terms} z = {z}"
            );
        }
        assert!(worst < 0.02, "K = {terms}: sharpened step off by {worst}");
    }
}

#[test]
fn val_modes_render_0_vpls_m_above_n_one_val_and_coplanar_vpls_without_nan() {
    let ctx = context();
    let (scene, vpls) = common::vpls_of(Builtin::FourRooms, 256);
    let cam = scene.cameras[0].clone();
    let floor = common::coplanar_vpls();
    let direct = gpu_image(&ctx, &scene, &cam, &[], GpuMode::DirectOnly, 1);
    for mode in [hard(), cssm()] {
        // N = 0: direct light alone.
        let img = gpu_image(&ctx, &scene, &cam, &[], mode, 30);
        assert_eq!(img.pixels, direct.pixels, "{mode:?} without VPLs");
        for (what, v, m) in [
            ("M > N", &vpls[..5], 30),
            ("M = 1", &vpls[..], 1),
            ("one VPL per VAL", &vpls[..64], 64),
            ("coplanar VPLs (zero-area VALs in one plane)", &floor[..], 4),
        ] {
            let img = gpu_image(&ctx, &scene, &cam, v, mode, m);
            assert!(img.pixels.iter().all(|p| p.is_finite()), "{mode:?} {what}");
            assert!(
                img.mean().x >= direct.mean().x,
                "{mode:?} {what}: light only adds"
            );
        }
    }
}

#[test]
fn interleaved_sampling_with_the_blur_stays_close_to_every_vpl_at_every_pixel() {
    use visgate_runtime::metrics::errors;
    let ctx = context();
    let (scene, vpls) = common::vpls_of(Builtin::CornellBox, 1024);
    let cam = scene.cameras[0].clone();
    let full = gpu_image_with(&ctx, &scene, &cam, &vpls, cssm(), 30, 1, [128, 128]);
    for block in [2, 4, 8] {
        let img = gpu_image_with(&ctx, &scene, &cam, &vpls, cssm(), 30, block, [128, 128]);
        let e = errors(&img, &full).expect("size");
        eprintln!("interleave {block}: {e:?}");
        assert!(img.pixels.iter().all(|p| p.is_finite()));
        assert!(e.rel_mse < 0.05, "block {block}: {e:?}");
        assert!(
            (e.image_mean / e.reference_mean - 1.0).abs() < 0.02,
            "{e:?}"
        );
    }
}

#[test]
fn set_scene_moves_geometry_and_lights_as_a_fresh_upload_does() {
    use visgate_runtime::gpu::GpuParams;
    let ctx = context();
    let blocker = |x: f32| {
        [
            Vec3::new(x - 1.0, 1.0, -1.0),
            Vec3::new(x + 1.0, 1.0, -1.0),
            Vec3::new(x + 1.0, 1.0, 1.0),
            Vec3::new(x - 1.0, 1.0, 1.0),
        ]
    };
    let light = |x: f32| visgate_formats::Light::Point {
        position: Vec3::new(x, 3.0, 0.0),
        intensity: Vec3::splat(5.0),
    };
    let a = common::quads(&[common::floor(5.0), blocker(-2.0)], 0.5, vec![light(-1.0)]);
    let b = common::quads(&[common::floor(5.0), blocker(2.0)], 0.5, vec![light(1.0)]);
    let cam = visgate_formats::Camera {
        name: "above".into(),
        eye: Vec3::new(0.0, 6.0, 6.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_x_rad: 60f32.to_radians(),
    };
    let view = visgate_runtime::camera::View::new(&cam, [48, 36]).expect("view");
    let tracer = Tracer::new(&b);
    let vpls = path_vpls(
        &tracer,
        &b.lights,
        &PathParams {
            paths: 256,
            bounces: 1,
            seed: 1,
        },
    )
    .expect("vpls");
    let per_vpl = GpuMode::PerVplShadowMaps(Default::default());
    // The ISMs' points are drawn from the triangles of the frame: moved meshes move them.
    let per_vpl_ism = GpuMode::PerVplIsm(Default::default());
    let mut val_ism = visgate_runtime::gpu::ValIsmParams::default();
    val_ism.vals.warm_start = false;
    for mode in [
        GpuMode::None,
        cssm(),
        per_vpl,
        per_vpl_ism,
        GpuMode::ValIsm(val_ism),
    ] {
        let params = GpuParams::with_mode(mode);
        let mut fresh = GpuRenderer::new(&ctx, &b).expect("upload b");
        let (want, _) = fresh.render(&ctx, &view, &vpls, &params).expect("fresh");
        let mut moved = GpuRenderer::new(&ctx, &a).expect("upload a");
        let (before, _) = moved.render(&ctx, &view, &vpls, &params).expect("a");
        moved.set_scene(&ctx, &b);
        let (got, _) = moved.render(&ctx, &view, &vpls, &params).expect("moved");
        assert_ne!(before.pixels, want.pixels, "{mode:?}: the scenes differ");
        assert_eq!(got.pixels, want.pixels, "{mode:?}");
    }
}

/// A horizontal square of half-side `r` at height `y`.
fn square(r: f32, y: f32) -> [Vec3; 4] {
    [
        Vec3::new(-r, y, -r),
        Vec3::new(r, y, -r),
        Vec3::new(r, y, r),
        Vec3::new(-r, y, r),
    ]
}

#[test]
fn cssm_receivers_at_a_val_of_no_area_stay_finite_and_the_open_stays_lit() {
    // Every VPL at one point on the floor (a VAL of no area), a small blocker 5 cm above it and
    // receivers 10 cm above it: within range/32 of the VAL, where its normalised depth is 0
    // (the receiver offset), and one receiver at the VAL's centre itself.
    let ctx = context();
    let scene = common::quads(
        &[
            square(3.0, 0.0),
            square(3.0, 3.0),
            square(0.02, 0.05),
            square(0.3, 0.1),
        ],
        0.5,
        vec![],
    );
    let mut vpls: Vec<Vpl> = (0..16)
        .map(|_| Vpl::new(Vec3::new(0.0, 1e-3, 0.0), Vec3::Y, Vec3::splat(0.05)))
        .collect();
    // A VPL exactly on the blocker's underside's centre line: p = c for a receiver there.
    vpls.push(Vpl::new(
        Vec3::new(0.0, 0.05, 0.0),
        Vec3::NEG_Y,
        Vec3::splat(0.05),
    ));
    let cam = visgate_formats::Camera {
        name: "under".into(),
        eye: Vec3::new(0.6, 0.02, 0.6),
        target: Vec3::new(0.0, 0.1, 0.0),
        up: Vec3::Y,
        fov_x_rad: 90f32.to_radians(),
    };
    for m in [1, 2] {
        let img = gpu_image_with(&ctx, &scene, &cam, &vpls, cssm(), m, 1, [48, 36]);
        let bad = img.pixels.iter().filter(|p| !p.is_finite()).count();
        assert_eq!(bad, 0, "M = {m}: {bad} pixels not finite");
        let none = gpu_image_with(&ctx, &scene, &cam, &vpls, GpuMode::None, m, 1, [48, 36]);
        // Light only darkens under visibility, and the receivers away from the blocker are lit.
        assert!(
            img.mean().x > 0.2 * none.mean().x,
            "{} vs {}",
            img.mean(),
            none.mean()
        );
        assert!(img.mean().x <= none.mean().x * 1.0001);
    }
}

#[test]
fn k_means_stops_where_the_assignment_repeats_and_more_iterations_change_nothing() {
    let (_, vpls) = common::vpls_of(Builtin::CornellBox, 1024);
    let at = |iterations| {
        cluster(
            &vpls,
            &ValParams {
                count: 30,
                iterations,
                ..ValParams::default()
            },
            None,
        )
        .expect("cluster")
    };
    let long = at(256);
    assert!(long.converged, "30 VALs of the Cornell box converge");
    assert!(long.iterations < 256);
    // Allowing exactly the updates it needed, or any more, gives the same clustering.
    for more in [long.iterations + 1, long.iterations + 20] {
        let c = at(more);
        assert!(c.converged);
        assert_eq!(c.mapping, long.mapping);
        assert_eq!(c.vals, long.vals);
    }
    // One update fewer than needed has not converged.
    if long.iterations > 0 {
        assert!(!at(long.iterations - 1).converged || long.iterations == 1);
    }
    eprintln!(
        "Cornell box, 30 VALs: converged after {} updates",
        long.iterations
    );
}

#[test]
fn rsm_samples_that_find_nothing_join_no_val_on_the_gpu_as_on_the_cpu() {
    // The Cornell box is open at the front: a share of its light's RSM sees nothing and gives
    // VPLs of zero flux at the origin. They join no VAL and leave D alone.
    let ctx = context();
    let scene = Builtin::CornellBox.scene().expect("scene");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let vpls = gpu.rsm_vpls(&ctx, 2048, 128, 1).expect("rsm");
    let dead = vpls.iter().filter(|v| v.flux == [0.0; 3]).count();
    assert!(
        dead > 20,
        "{dead} of {} RSM samples find nothing",
        vpls.len()
    );
    let live: Vec<Vpl> = vpls
        .iter()
        .filter(|v| v.flux != [0.0; 3])
        .copied()
        .collect();
    let params = ValParams {
        count: 30,
        ..ValParams::default()
    };
    let cpu = cluster(&vpls, &params, None).expect("cpu");
    let got = gpu.cluster_vals(&ctx, &vpls, &params).expect("gpu");
    assert_sane(&cpu, vpls.len(), 30);
    assert_sane(&got, vpls.len(), 30);
    assert_eq!(cpu.mapping, got.mapping);
    for (v, k) in vpls.iter().zip(&got.mapping) {
        assert_eq!(v.flux == [0.0; 3], *k == NO_VAL, "{v:?} → {k}");
    }
    // D is the live VPLs' diagonal, as if the dead ones were not there.
    let alone = cluster(&live, &params, None).expect("live alone");
    assert_eq!(cpu.scale_m, alone.scale_m);
    eprintln!("{dead} dead of {}; D {} m", vpls.len(), cpu.scale_m);
}

#[test]
fn cssm_receivers_near_a_val_under_an_open_sky_are_lit() {
    // VPLs on a floor facing up, nothing above but a small receiver panel 20 cm up (facing
    // down) and a far wall that sets the VAL's depth range: nothing blocks the panel. Its
    // filter kernel reaches the map's empty texels (the open sky), whose depth must read as
    // "no blocker", not as a half-shadowing wrap-around of the Fourier step.
    let ctx = context();
    let wall = [
        Vec3::new(-20.0, 0.0, -20.0),
        Vec3::new(20.0, 0.0, -20.0),
        Vec3::new(20.0, 20.0, -20.0),
        Vec3::new(-20.0, 20.0, -20.0),
    ];
    let scene = common::quads(&[square(1.0, 0.0), square(0.3, 0.2), wall], 0.5, vec![]);
    let vpls: Vec<Vpl> = (0..64)
        .map(|i| {
            let p = Vec3::new(
                -0.2 + (i % 8) as f32 * 0.05,
                1e-3,
                -0.2 + (i / 8) as f32 * 0.05,
            );
            Vpl::new(p, Vec3::Y, Vec3::splat(0.02))
        })
        .collect();
    let cam = visgate_formats::Camera {
        name: "under the panel".into(),
        eye: Vec3::new(0.0, 0.05, 0.6),
        target: Vec3::new(0.0, 0.2, 0.0),
        up: Vec3::Y,
        fov_x_rad: 60f32.to_radians(),
    };
    let soft = gpu_image_with(&ctx, &scene, &cam, &vpls, cssm(), 1, 1, [32, 24]);
    let open = gpu_image_with(&ctx, &scene, &cam, &vpls, GpuMode::None, 1, 1, [32, 24]);
    let ratio = soft.mean().x / open.mean().x;
    eprintln!(
        "open sky: CSSM {} vs unoccluded {} ({ratio})",
        soft.mean().x,
        open.mean().x
    );
    assert!(
        ratio > 0.9,
        "the unblocked panel is darkened to {ratio} of its light"
    );
}

//! The VALs' shadows: blockers, the reference, the Fourier test, edge cases, interleaving, moved geometry and open skies.

use super::*;

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

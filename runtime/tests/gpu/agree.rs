//! The GPU against the CPU reference: every mode, closed forms, VPL counts, RSM VPLs, scales, a light inside geometry, textures.

use super::*;

#[test]
fn gpu_modes_agree_with_the_cpu_reference_with_the_same_vpls_and_visibility() {
    for (b, mode) in [
        (Builtin::FourRooms, GpuMode::None),
        (Builtin::FourRooms, GpuMode::DirectOnly),
        (Builtin::CornellBox, GpuMode::None),
        (Builtin::FourRooms, per_vpl()),
        (Builtin::CornellBox, per_vpl()),
    ] {
        let (gpu, cpu) = both(b, [64, 48], 256, mode);
        let e = errors(&gpu, &cpu).expect("same size");
        let (f, _) = flip(&gpu, &cpu, 0.0).expect("same size");
        eprintln!("{} {mode:?}: {e:?}, FLIP {f}", b.name());
        assert!(cpu.mean().x > 0.0);
        // Shadow maps (PCF, bias) differ from shadow rays at shadow edges only.
        assert!(e.rel_mse < 0.05, "{} {mode:?}: {e:?}", b.name());
        assert!(f < 0.08, "{} {mode:?}: FLIP {f}", b.name());
        assert!(
            (e.image_mean / e.reference_mean - 1.0).abs() < 0.03,
            "{e:?}"
        );
    }
}

#[test]
fn gpu_white_plane_under_a_point_light_has_the_closed_form_radiance() {
    use visgate_formats::{Camera, Light};
    let (rho, i, h) = (0.8f32, 10.0f32, 2.0f32);
    let scene = floor_scene(
        rho,
        vec![Light::Point {
            position: Vec3::new(0.0, h, 0.0),
            intensity: Vec3::splat(i),
        }],
    );
    let ctx = context();
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    // Looking straight down from beside the light at the point under it.
    let cam = Camera {
        name: "down".into(),
        eye: Vec3::new(0.0, 1.0, 0.0),
        target: Vec3::ZERO,
        up: Vec3::Z,
        fov_x_rad: 0.2,
    };
    let view = View::new(&cam, [9, 9]).expect("view");
    let (img, _) = gpu
        .render(
            &ctx,
            &view,
            &[],
            &GpuParams {
                mode: GpuMode::DirectOnly,
                ..GpuParams::default()
            },
        )
        .expect("render");
    let want = rho / PI * i / (h * h);
    let got = img.at(4, 4).x;
    assert!((got - want).abs() / want < 1e-3, "{got} vs {want}");
}

#[test]
fn gpu_renders_0_1_and_65536_vpls_and_a_vpl_on_the_receiver_without_nan() {
    let ctx = context();
    let scene = Builtin::FourRooms.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths: 65536,
            bounces: 1,
            seed: 5,
        },
    )
    .expect("vpls");
    let view = View::new(scene.cameras.first().expect("camera"), [16, 12]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let mut means = Vec::new();
    for v in [&vpls[..0], &vpls[..1], &vpls[..]] {
        let (img, _) = gpu
            .render(&ctx, &view, v, &GpuParams::default())
            .expect("render");
        assert!(
            img.pixels
                .iter()
                .all(|p| p.is_finite() && p.min_element() >= 0.0)
        );
        means.push(img.mean().x);
    }
    assert!(means[2] > means[0], "{means:?}");
    // Timestamp queries, where the adapter has them and is not a CPU one (lavapipe's close a
    // compute pass before its dispatches end): every stage that ran took GPU time, and the
    // stages that did not run took none; else every stage is waited for.
    if ctx.adapter_info.device_type == wgpu::DeviceType::Cpu {
        assert!(ctx.timestamp_period.is_none(), "{:?}", ctx.adapter_info);
    }
    let (_, times) = gpu
        .render(
            &ctx,
            &view,
            &vpls[..64],
            &GpuParams::with_mode(GpuMode::PerVplShadowMaps(PerVplParams {
                batch: 16,
                ..PerVplParams::default()
            })),
        )
        .expect("render");
    let names: Vec<&str> = times.passes.iter().map(|p| p.name).collect();
    // 64 VPLs in batches of 16: 4 × (maps, gather), after the shadow maps, G-buffer, shading.
    assert_eq!(
        names
            .iter()
            .filter(|n| **n == "VPL paraboloid maps")
            .count(),
        4
    );
    assert_eq!(names.iter().filter(|n| **n == "VPL gather").count(), 4);
    assert_eq!(
        names[..3],
        [
            "shadow maps",
            "geometry pass (G-buffer)",
            "shading: direct lighting"
        ]
    );
    let spans_timed = times
        .passes
        .iter()
        .all(|p| p.gpu_s.is_some_and(|s| s > 0.0));
    let spans_waited = times.passes.iter().all(|p| p.cpu_s.is_some());
    match ctx.timestamp_period {
        Some(_) => assert!(spans_timed, "{times:?}"),
        None => assert!(spans_waited, "{times:?}"),
    }
    let (_, times) = gpu
        .render(&ctx, &view, &vpls[..64], &GpuParams::default())
        .expect("render");
    assert!(times.gpu("VPL paraboloid maps").is_none() && times.gpu("VPL gather").is_none());
    // VPLs lying on the surfaces the camera sees (every light-path VPL does): the clamp holds.
    let (img, _) = gpu
        .render(
            &ctx,
            &view,
            &vpls[..4096],
            &GpuParams {
                g_max: 1.0,
                ..GpuParams::default()
            },
        )
        .expect("render");
    assert!(img.pixels.iter().all(|p| p.is_finite()));
    // Bad parameters are errors, not panics.
    for bad in [
        GpuParams {
            g_max: 0.0,
            ..GpuParams::default()
        },
        GpuParams {
            shadows: ShadowParams {
                size: 1,
                ..ShadowParams::default()
            },
            ..GpuParams::default()
        },
        GpuParams::with_mode(GpuMode::PerVplShadowMaps(PerVplParams {
            batch: 0,
            ..PerVplParams::default()
        })),
    ] {
        assert!(gpu.render(&ctx, &view, &[], &bad).is_err(), "{bad:?}");
    }
}

/// `n` RSM VPLs of `scene`'s lights and their summed flux beside that of `n` light paths'.
fn rsm_and_path_flux(
    ctx: &GpuContext,
    gpu: &mut GpuRenderer,
    scene: &visgate_formats::Scene,
    n: u32,
) -> (Vec<visgate_runtime::vpl::Vpl>, Vec3, Vec3) {
    let rsm = gpu.rsm_vpls(ctx, n, 256, 1).expect("rsm vpls");
    let paths = path_vpls(
        &Tracer::new(scene),
        &scene.lights,
        &PathParams {
            paths: n,
            bounces: 1,
            seed: 1,
        },
    )
    .expect("paths");
    let sum =
        |v: &[visgate_runtime::vpl::Vpl]| -> Vec3 { v.iter().map(|v| Vec3::from(v.flux)).sum() };
    let (a, b) = (sum(&rsm), sum(&paths));
    (rsm, a, b)
}

#[test]
fn rsm_vpls_of_a_spot_wider_than_one_frustum_carry_its_power() {
    // An 89° spot in a closed box: its RSM is a cube of six layers (no clamped frustum), and
    // the VPLs hold what light paths from the same spot hold.
    let ctx = context();
    let mut scene = Builtin::EmptyBox.scene().expect("scene");
    let p = visgate_runtime::lights::light_position(&scene.lights[0]);
    scene.lights = vec![visgate_formats::Light::Spot {
        position: p,
        direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
        intensity: Vec3::splat(4.0),
        cutoff_rad: 89f32.to_radians(),
        beam_rad: 70f32.to_radians(),
    }];
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let (_, a, b) = rsm_and_path_flux(&ctx, &mut gpu, &scene, 4096);
    eprintln!("89° spot: RSM flux {a}, path flux {b}");
    assert!(((a - b) / b).abs().max_element() < 0.02, "{a} vs {b}");
}

#[test]
fn rsm_vpls_carry_the_reflected_power_and_do_not_flicker() {
    // A point light inside a closed box: the RSM sees walls in every direction, so the VPLs
    // hold ρ × the light's power, as the light paths do.
    let ctx = context();
    let scene = Builtin::EmptyBox.scene().expect("scene");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let tracer = Tracer::new(&scene);
    let n = 4096;
    let (rsm, a, b) = rsm_and_path_flux(&ctx, &mut gpu, &scene, n);
    assert_eq!(rsm.len(), n as usize);
    eprintln!("RSM flux {a}, path flux {b}");
    assert!(((a - b) / b).abs().max_element() < 0.02, "{a} vs {b}");
    // The same light gives the same VPLs.
    assert_eq!(rsm, gpu.rsm_vpls(&ctx, n, 256, 1).expect("again"));
    // Every VPL with flux lies on a wall, its normal facing the light.
    let light = visgate_runtime::lights::light_position(&scene.lights[0]);
    for v in rsm.iter().filter(|v| v.flux[0] > 0.0) {
        let p = Vec3::from(v.position);
        assert!(Vec3::from(v.normal).dot(light - p) > 0.0, "{v:?}");
    }
    // And the GPU `none` image with RSM VPLs agrees with its CPU twin.
    let view = View::new(scene.cameras.first().expect("camera"), [48, 32]).expect("view");
    let (img, _) = gpu
        .render(&ctx, &view, &rsm[..1024], &GpuParams::default())
        .expect("render");
    let (cpu, _) = render_reference(
        &tracer,
        &scene.lights,
        &rsm[..1024],
        &view,
        &ReferenceParams {
            samples_per_pixel: 1,
            indirect_visibility: false,
            ..ReferenceParams::default()
        },
        &|_, _| {},
    )
    .expect("cpu");
    let e = errors(&img, &cpu).expect("same size");
    assert!(e.rel_mse < 0.02, "{e:?}");
}

#[test]
fn gpu_scene_scales_from_1e_minus_3_to_1e4_give_the_same_image_after_scaling_the_light() {
    let ctx = context();
    let render = |scale: f32| {
        let (scene, cam) = scaled_four_rooms(scale);
        let tracer = Tracer::new(&scene);
        let vpls = path_vpls(
            &tracer,
            &scene.lights,
            &PathParams {
                paths: 256,
                bounces: 1,
                seed: 3,
            },
        )
        .expect("vpls");
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        let view = View::new(&cam, [32, 24]).expect("view");
        let params = GpuParams {
            g_max: 10.0 / (scale * scale),
            ..GpuParams::default()
        };
        gpu.render(&ctx, &view, &vpls, &params).expect("render").0
    };
    let base = render(1.0);
    for scale in [1e-3f32, 1e-1, 10.0, 1e4] {
        let e = errors(&render(scale), &base).expect("same size");
        assert!(e.rel_mse < 1e-3, "scale {scale}: {e:?}");
    }
}

#[test]
fn gpu_a_light_inside_geometry_lights_nothing_outside_it() {
    use visgate_formats::{Camera, Light};
    // A closed 0.4 m box around a point light at 1 m, over a 20 m floor.
    let mut faces = closed_box(0.2);
    faces
        .iter_mut()
        .flatten()
        .for_each(|p| *p += Vec3::new(0.0, 1.0, 0.0));
    faces.push(floor(10.0));
    let scene = quads(
        &faces,
        0.7,
        vec![Light::Point {
            position: Vec3::new(0.0, 1.0, 0.0),
            intensity: Vec3::splat(50.0),
        }],
    );
    let ctx = context();
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let cam = Camera {
        name: "floor".into(),
        eye: Vec3::new(3.0, 2.0, 0.0),
        target: Vec3::new(1.5, 0.0, 0.0),
        up: Vec3::Y,
        fov_x_rad: 0.5,
    };
    let view = View::new(&cam, [16, 12]).expect("view");
    let (img, _) = gpu
        .render(
            &ctx,
            &view,
            &[],
            &GpuParams {
                mode: GpuMode::DirectOnly,
                ..GpuParams::default()
            },
        )
        .expect("render");
    assert!(
        img.pixels.iter().all(|p| *p == Vec3::ZERO),
        "light leaks: {}",
        img.mean()
    );
}

#[test]
fn gpu_samples_albedo_textures_as_the_reference_does() {
    use visgate_formats::{Camera, Light, Texture};
    // A floor with a 4 × 4 sRGB checker of red and dark blue, repeated twice, under a light.
    let mut rgba8 = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            rgba8.extend(if (x + y) % 2 == 0 {
                [230, 40, 40, 255]
            } else {
                [20, 30, 120, 255]
            });
        }
    }
    let mut scene = quads(
        &[floor(2.0)],
        0.9,
        vec![Light::Point {
            position: Vec3::new(0.3, 2.0, 0.2),
            intensity: Vec3::splat(10.0),
        }],
    );
    scene.meshes[0].uvs = vec![
        glam::Vec2::new(0.0, 0.0),
        glam::Vec2::new(0.0, 2.0),
        glam::Vec2::new(2.0, 2.0),
        glam::Vec2::new(2.0, 0.0),
    ];
    scene.materials[0].texture = Some(0);
    scene.textures = vec![Texture {
        name: "checker".into(),
        width: 4,
        height: 4,
        rgba8,
    }];
    let cam = Camera {
        name: "down".into(),
        eye: Vec3::new(0.0, 3.0, 0.01),
        target: Vec3::ZERO,
        up: Vec3::Z,
        fov_x_rad: 1.0,
    };
    let view = View::new(&cam, [40, 40]).expect("view");
    let (img, cpu) = direct_on_gpu_and_cpu(&context(), &scene, &view);
    // Both show the checker: red and blue dominate in different pixels.
    let red = img.pixels.iter().filter(|p| p.x > 3.0 * p.z).count();
    let blue = img.pixels.iter().filter(|p| p.z > 2.0 * p.x).count();
    assert!(red > 200 && blue > 200, "{red} red, {blue} blue pixels");
    let e = errors(&img, &cpu).expect("same size");
    // Pixels on checker edges may pick the neighbouring texel on one side only.
    assert!(e.rel_mse < 0.02, "{e:?}");
    assert!(
        (e.image_mean / e.reference_mean - 1.0).abs() < 0.02,
        "{e:?}"
    );
}

//! Spot falloff, distant cameras and lights, a dark box, validation errors, leaning normals and zero-thickness walls on the GPU.

use super::*;

#[test]
fn gpu_spot_falloff_matches_the_conventions_at_beam_mid_ramp_and_cutoff() {
    use visgate_formats::{Camera, Light};
    use visgate_runtime::lights::spot_falloff;
    // A 40° spot (one shadow layer), and an 89° one (wider than one frustum spans: a cube of
    // six layers, probed past 86°, where a clamped frustum would leave the floor dark).
    for (beam_deg, cutoff_deg, probes_deg) in [
        (20f32, 40f32, vec![0.0f32, 19.0, 30.0, 44.0]),
        (80.0, 89.0, vec![0.0, 60.0, 87.0, 89.5]),
    ] {
        let (beam, cutoff, h, i) = (beam_deg.to_radians(), cutoff_deg.to_radians(), 2.0f32, 5.0);
        let scene = floor_scene(
            1.0,
            vec![Light::Spot {
                position: Vec3::new(0.0, h, 0.0),
                direction: -Vec3::Y,
                intensity: Vec3::splat(i),
                cutoff_rad: cutoff,
                beam_rad: beam,
            }],
        );
        let ctx = context();
        let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        for angle in probes_deg.iter().map(|a| a.to_radians()) {
            let x = h * angle.tan();
            // A narrow camera straight above the point at `angle` from the spot's axis.
            let cam = Camera {
                name: "probe".into(),
                eye: Vec3::new(x, 0.5, 0.0),
                target: Vec3::new(x, 0.0, 0.0),
                up: Vec3::Z,
                fov_x_rad: 0.01,
            };
            let view = View::new(&cam, [3, 3]).expect("view");
            let (img, _) = gpu
                .render(&ctx, &view, &[], &GpuParams::with_mode(GpuMode::DirectOnly))
                .expect("render");
            let d2 = x * x + h * h;
            let want = 1.0 / PI * i * spot_falloff(angle, beam, cutoff) * angle.cos() / d2;
            let got = img.at(1, 1).x;
            assert!(
                // Relative: past 86° the light is 1e-5 of the axis's.
                (got - want).abs() <= 5e-3 * want + 1e-8,
                "cutoff {cutoff_deg}°, angle {angle}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn gpu_a_camera_ten_diagonals_away_sees_the_level_as_the_cpu_does() {
    // The camera's depth is reversed with no far plane: nothing is clipped however far the
    // camera stands (with a far plane at 4 diagonals this image was black).
    use visgate_formats::Camera;
    let ctx = context();
    let scene = Builtin::CornellBox.scene().expect("scene");
    let (lo, hi) = scene.bounds().expect("bounds");
    let (centre, diagonal) = ((lo + hi) * 0.5, (hi - lo).length());
    let cam = Camera {
        name: "far".into(),
        eye: centre + Vec3::new(0.2, 0.1, 1.0).normalize() * 10.0 * diagonal,
        target: centre,
        up: Vec3::Y,
        fov_x_rad: 0.12,
    };
    let view = View::new(&cam, [48, 48]).expect("view");
    let (img, cpu) = direct_on_gpu_and_cpu(&ctx, &scene, &view);
    let e = errors(&img, &cpu).expect("same size");
    eprintln!("10 diagonals away: {e:?}");
    assert!(
        img.mean().x > 0.5 * cpu.mean().x,
        "{} vs {}",
        img.mean(),
        cpu.mean()
    );
    assert!(e.rel_mse < 0.05, "{e:?}");
}

#[test]
fn gpu_a_closed_box_with_no_light_is_black() {
    let ctx = context();
    let mut scene = Builtin::EmptyBox.scene().expect("scene");
    scene.lights.clear();
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let view = View::new(scene.cameras.first().expect("camera"), [16, 12]).expect("view");
    for mode in [GpuMode::None, per_vpl(), GpuMode::DirectOnly] {
        let (img, _) = gpu
            .render(
                &ctx,
                &view,
                &[],
                &GpuParams {
                    mode,
                    ..GpuParams::default()
                },
            )
            .expect("render");
        assert!(img.pixels.iter().all(|p| *p == Vec3::ZERO), "{mode:?}");
    }
    assert!(gpu.rsm_vpls(&ctx, 64, 64, 1).expect("rsm").is_empty());
}

#[test]
fn a_gpu_validation_error_comes_back_as_an_error_not_a_panic() {
    let ctx = context();
    let e = visgate_runtime::gpu::context::scoped(&ctx, || {
        // MAP_READ with STORAGE is invalid without a feature adapters rarely have.
        let _invalid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("invalid on purpose"),
            size: 64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(())
    })
    .expect_err("a validation error");
    assert!(e.to_string().contains("refused"), "{e}");
    // And the device goes on working.
    let scene = Builtin::CornellBox.scene().expect("scene");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let view = View::new(scene.cameras.first().expect("camera"), [8, 8]).expect("view");
    gpu.render(&ctx, &view, &[], &GpuParams::default())
        .expect("render after an error");
}

#[test]
fn gpu_a_spot_far_outside_the_level_casts_its_shadows() {
    // A sun placed as a spot 9.5 diagonals from the sun window's centre (as a glTF's
    // directional light is: formats/src/gltf_nodes.rs), shining in through the window. The
    // shadow maps' far plane was 4 diagonals: the walls beyond it cast nothing and the whole
    // floor was lit (the GPU's mean 5 times the reference's: 0.510 against 0.103); and their near plane, 1e-4 of
    // a diagonal, left the depth test half a metre of precision at 90 m.
    use visgate_formats::Light;
    let ctx = context();
    let mut scene = Builtin::SunWindow.scene().expect("scene");
    let (lo, hi) = scene.bounds().expect("bounds");
    let (centre, diagonal) = ((lo + hi) * 0.5, (hi - lo).length());
    let dir = Vec3::new(-0.3, -0.5, -0.8).normalize();
    let distance = 9.5 * diagonal;
    let beam = (0.5 / 9.5f32).asin() * 1.05;
    scene.lights = vec![Light::Spot {
        position: centre - dir * distance,
        direction: dir,
        intensity: Vec3::splat(10.0 * distance * distance),
        cutoff_rad: beam * 1.1,
        beam_rad: beam,
    }];
    let view = View::new(scene.camera("window").expect("camera"), [160, 120]).expect("view");
    let (gpu, cpu) = direct_on_gpu_and_cpu(&ctx, &scene, &view);
    let (g, c) = (gpu.mean().x, cpu.mean().x);
    let e = errors(&gpu, &cpu).expect("same size");
    eprintln!("GPU mean {g}, reference {c}, rel. MSE {}", e.rel_mse);
    assert!(c > 0.01, "a lit patch: {c}");
    assert!((g / c - 1.0).abs() < 0.05, "GPU {g}, reference {c}");
}

#[test]
fn gpu_normals_that_lean_far_from_their_faces_light_as_the_cpu_does() {
    // Real meshes carry vertex normals far off their faces (Crytek Sponza's arches: up to 90°).
    // The G-buffer once turned the shading normal itself towards the camera, the CPU tracer
    // turns the face's normal towards the ray and the shading normal to its side. A floor whose
    // normals lean 80° away from the camera, under a point light: the CPU lights it (the
    // normal's upward part), the old G-buffer turned the normal down and left it black.
    use visgate_formats::{Camera, Light};
    let mut scene = floor_scene(
        1.0,
        vec![Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: Vec3::splat(10.0),
        }],
    );
    let lean = 80f32.to_radians();
    for n in &mut scene.meshes[0].normals {
        *n = Vec3::new(lean.sin(), lean.cos(), 0.0);
    }
    let cam = Camera {
        name: "oblique".into(),
        eye: Vec3::new(-3.0, 1.0, 0.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_x_rad: 0.5,
    };
    let view = View::new(&cam, [16, 16]).expect("view");
    let ctx = context();
    let (gpu, cpu) = direct_on_gpu_and_cpu(&ctx, &scene, &view);
    let e = errors(&gpu, &cpu).expect("same size");
    eprintln!("{e:?}");
    assert!(cpu.mean().x > 0.0);
    assert!(
        (e.image_mean / e.reference_mean - 1.0).abs() < 0.02,
        "{e:?}"
    );
    assert!(e.rel_mse < 0.01, "{e:?}");
}

#[test]
fn gpu_the_dark_side_of_a_zero_thickness_walls_joins_stays_dark() {
    // The ajar door from room A, its lamp in room B: the dividing wall (zero thickness) meets
    // the floor and the outer walls, which run on under and past it into the lit room. A
    // shadow map's bias and its PCF taps past the wall's edge lit a line along each join on the
    // dark side: 131 of the 69,975 pixels dark in the reference and away from its lit ones
    // (0.19 %); the receiver's own texel tested against its plane left 17 (0.02 %), and from
    // `main` 55 of 71,833 (0.08 %), dots along the joins of the walls and ceiling with the
    // dividing wall, on receivers millimetres behind it (all nine taps lit by the bias); with
    // the own texel tested wherever it is nearer than the receiver too, 10 and 5.
    let ctx = context();
    let scene = Builtin::AjarDoor.scene().expect("scene");
    for camera in ["door", "main"] {
        let (leaks, dark) = leaks_on_the_dark_side(&ctx, &scene, camera);
        let share = leaks as f64 / dark as f64;
        eprintln!(
            "{camera}: {leaks} of {dark} dark pixels lit on the GPU ({:.3} %)",
            100.0 * share
        );
        assert!(dark > 30_000, "{dark}");
        assert!(
            share < 2.5e-4,
            "{camera}: {leaks} of {dark} dark pixels lit"
        );
    }
}

/// Of the pixels dark in the reference's direct light from `camera` at 320 × 240, with every
/// neighbour within two pixels dark too (not a shadow's edge), how many the GPU lights, and
/// how many there are.
fn leaks_on_the_dark_side(
    ctx: &GpuContext,
    scene: &visgate_formats::Scene,
    camera: &str,
) -> (usize, usize) {
    let cam = scene.camera(camera).expect("camera");
    let [w, h] = [320u32, 240];
    let view = View::new(cam, [w, h]).expect("view");
    let (gpu, cpu) = direct_on_gpu_and_cpu(ctx, scene, &view);
    let lit = |img: &visgate_runtime::hdr::HdrImage, x: i64, y: i64| {
        x >= 0
            && y >= 0
            && x < i64::from(w)
            && y < i64::from(h)
            && img.pixels[(x + y * i64::from(w)) as usize].max_element() > 1e-4
    };
    // Dark in the reference with every neighbour dark too (not a shadow's edge), lit on the GPU.
    let (mut dark, mut leaks) = (0, 0);
    for y in 0..i64::from(h) {
        for x in 0..i64::from(w) {
            let near_lit = (-2..=2).any(|dy| (-2..=2).any(|dx| lit(&cpu, x + dx, y + dy)));
            if near_lit {
                continue;
            }
            dark += 1;
            leaks += usize::from(lit(&gpu, x, y));
        }
    }
    (leaks, dark)
}

#[test]
fn of_two_faces_of_one_plane_the_cpu_and_the_gpu_show_the_one_turned_to_the_eye() {
    // The stairwell's floor between its storeys is one plane of two faces: the floor's on top,
    // the ceiling's (a lighter albedo) under it. Which one a ray met was rounding's pick: the
    // reference speckled between them and the G-buffer striped.
    let scene = Builtin::Stairwell.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let albedo = |m: usize| Vec3::from(visgate_scenes::quads::QUAD_MATERIALS[m].1);
    let (floor, ceiling) = (albedo(0), albedo(1));
    let (mut tried, mut wrong) = (0, 0);
    for k in 0..400 {
        // Points of the floor between the storeys away from the hole, rays slanted every way.
        let p = Vec3::new(0.2 + 0.011 * k as f32, 3.0, 0.3 + 0.013 * k as f32 % 5.4);
        let tilt = Vec3::new((k as f32 * 0.7).sin(), 0.0, (k as f32 * 1.3).cos()) * 0.5;
        for (side, want) in [(1.0f32, floor), (-1.0, ceiling)] {
            let eye = p + (Vec3::Y * side + tilt) * 1.5;
            let Some(s) = tracer.trace(eye, (p - eye).normalize()) else {
                continue;
            };
            if (s.position.y - 3.0).abs() > 1e-3 {
                continue; // the stairs or the table in the way
            }
            tried += 1;
            wrong += usize::from((s.albedo - want).abs().max_element() > 1e-4);
        }
    }
    assert!(tried > 600, "{tried}");
    assert_eq!(wrong, 0, "{wrong} of {tried} rays met the face turned away");
    // The GPU's direct light from upstairs, against the CPU's: the same face at every pixel.
    let ctx = context();
    let view = View::new(scene.camera("up").expect("camera"), [160, 120]).expect("view");
    let (gpu, cpu) = direct_on_gpu_and_cpu(&ctx, &scene, &view);
    let lit = cpu.pixels.iter().filter(|c| c.max_element() > 1e-3).count();
    let differ = gpu
        .pixels
        .iter()
        .zip(&cpu.pixels)
        .filter(|(g, c)| {
            c.max_element() > 1e-3 && (**g - **c).abs().max_element() > 0.05 * c.max_element()
        })
        .count();
    eprintln!("{differ} of {lit} lit pixels differ by over 5 %");
    assert!(lit > 15_000, "{lit}");
    assert!(
        differ * 100 < lit,
        "{differ} of {lit} lit pixels differ by over 5 %"
    );
    // The lamp's reflective shadow map sees the floor's top: its VPLs there reflect the
    // floor's albedo (red over blue 1.13), not the ceiling's (1.0); so do the light paths'.
    let mut renderer = GpuRenderer::new(&ctx, &scene).expect("upload");
    let rsm = renderer.rsm_vpls(&ctx, 4096, 256, 1).expect("rsm vpls");
    let params = PathParams {
        paths: 4096,
        bounces: 1,
        seed: 1,
    };
    let paths = path_vpls(&tracer, &scene.lights, &params).expect("paths");
    for (what, vpls) in [("rsm", &rsm), ("paths", &paths)] {
        let on_floor: Vec<_> = vpls
            .iter()
            .filter(|v| (v.position[1] - 3.0).abs() < 1e-3 && v.flux[2] > 0.0)
            .collect();
        let n = on_floor.len();
        let ceiling = on_floor
            .iter()
            .filter(|v| v.flux[0] / v.flux[2] < 1.06)
            .count();
        eprintln!("{what}: {ceiling} of {n} VPLs on the floor take the ceiling's albedo");
        assert!(n > 200, "{what}: {n}");
        assert_eq!(ceiling, 0, "{what}: {ceiling} of {n} VPLs");
    }
}

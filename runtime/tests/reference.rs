//! Known answers and extremes of the CPU side: direct light radiometry, spot falloff, the
//! light-path VPLs' energy, the gather's clamp, and stability at scale extremes.

mod common;

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use visgate_formats::{Camera, Light, Scene};
use visgate_runtime::camera::View;
use visgate_runtime::cpu::reference::{
    ReferenceParams, mixed_pixels, render_reference, shade_point,
};
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::lights::{light_power, spot_falloff};
use visgate_runtime::vpl::{GatherParams, PathParams, Vpl, clamp_loss, gather_one, path_vpls};

use common::{closed_box, floor, quads, scaled_four_rooms};

fn direct_only() -> ReferenceParams {
    ReferenceParams {
        indirect: false,
        ..ReferenceParams::default()
    }
}

fn rel(a: f32, b: f32) -> f32 {
    (a - b).abs() / b.abs().max(1e-30)
}

#[test]
fn a_white_plane_under_a_point_light_has_radiance_rho_over_pi_i_over_h2() {
    for (rho, i, h) in [
        (0.8f32, 10.0f32, 2.0f32),
        (0.5, 3.0, 0.5),
        (1.0, 100.0, 7.0),
    ] {
        let s = quads(
            &[floor(100.0)],
            rho,
            vec![Light::Point {
                position: Vec3::new(0.0, h, 0.0),
                intensity: Vec3::splat(i),
            }],
        );
        let t = Tracer::new(&s);
        // Seen from above at an angle: Lambertian, the view direction does not matter.
        let l = shade_point(
            &t,
            &s.lights,
            &[],
            Vec3::new(1.0, 3.0, 0.0),
            Vec3::new(-1.0, -3.0, 0.0).normalize(),
            &direct_only(),
        )
        .expect("hit");
        let want = rho / PI * i / (h * h);
        assert!(rel(l.x, want) < 1e-4, "{l} vs {want}");
        // Off-axis: cos θ / d².
        let x = 1.5 * h;
        let l = shade_point(
            &t,
            &s.lights,
            &[],
            Vec3::new(x, 1.0, 0.0),
            -Vec3::Y,
            &direct_only(),
        )
        .expect("hit");
        let d2 = x * x + h * h;
        let want = rho / PI * i * (h / d2.sqrt()) / d2;
        assert!(rel(l.x, want) < 1e-4, "{l} vs {want}");
    }
}

#[test]
fn a_spot_light_falls_off_as_the_conventions_say_at_beam_mid_ramp_and_cutoff() {
    let (beam, cutoff) = (20f32.to_radians(), 40f32.to_radians());
    let h = 2.0;
    let s = quads(
        &[floor(100.0)],
        1.0,
        vec![Light::Spot {
            position: Vec3::new(0.0, h, 0.0),
            direction: -Vec3::Y,
            intensity: Vec3::splat(5.0),
            cutoff_rad: cutoff,
            beam_rad: beam,
        }],
    );
    let t = Tracer::new(&s);
    for (angle, falloff) in [
        (0.0f32, 1.0f32),
        (beam * 0.99, 1.0),
        (0.5 * (beam + cutoff), 0.5),
        (cutoff * 0.999, 0.0),
        (cutoff * 1.2, 0.0),
    ] {
        assert!((spot_falloff(angle, beam, cutoff) - falloff).abs() < 0.01);
        let x = h * angle.tan();
        let l = shade_point(
            &t,
            &s.lights,
            &[],
            Vec3::new(x, 1.0, 0.0),
            -Vec3::Y,
            &direct_only(),
        )
        .expect("hit");
        let d2 = x * x + h * h;
        let want = 1.0 / PI * 5.0 * spot_falloff(angle, beam, cutoff) * angle.cos() / d2;
        assert!(
            (l.x - want).abs() <= 1e-4 * (1.0 + want),
            "angle {angle}: {l} vs {want}"
        );
    }
    // The spot's power integrates its falloff: between the beam's and the cutoff's cones.
    let p = light_power(&s.lights[0]).x / 5.0;
    let cone = |a: f32| 2.0 * PI * (1.0 - a.cos());
    assert!(p > cone(beam) && p < cone(cutoff), "{p}");
}

#[test]
fn a_closed_box_with_no_light_is_black() {
    let s = quads(&closed_box(1.0), 0.8, Vec::new());
    let t = Tracer::new(&s);
    let vpls = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: 1024,
            bounces: 3,
            seed: 1,
        },
    )
    .expect("vpls");
    assert!(vpls.is_empty());
    let cam = Camera {
        name: "in".into(),
        eye: Vec3::ZERO,
        target: Vec3::Z,
        up: Vec3::Y,
        fov_x_rad: 1.2,
    };
    let view = View::new(&cam, [16, 12]).expect("view");
    let (img, _) = render_reference(
        &t,
        &s.lights,
        &vpls,
        &view,
        &ReferenceParams::default(),
        &|_, _| {},
    )
    .expect("render");
    assert!(img.pixels.iter().all(|p| *p == Vec3::ZERO));
}

#[test]
fn light_path_vpls_carry_the_reflected_power_of_each_bounce() {
    // A point light inside a closed box of albedo ρ: every path hits, so bounce k's VPLs hold
    // ρ^k of the light's power.
    let rho = 0.6;
    let i = 2.0;
    let s = quads(
        &closed_box(1.0),
        rho,
        vec![Light::Point {
            position: Vec3::new(0.1, 0.2, -0.3),
            intensity: Vec3::splat(i),
        }],
    );
    let t = Tracer::new(&s);
    let n = 4096;
    let vpls = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: n,
            bounces: 3,
            seed: 7,
        },
    )
    .expect("vpls");
    assert_eq!(vpls.len(), 3 * n as usize);
    let power = 4.0 * PI * i;
    let total: f32 = vpls.iter().map(|v| v.flux[0]).sum();
    let want = power * (rho + rho * rho + rho * rho * rho);
    assert!(rel(total, want) < 1e-3, "{total} vs {want}");
    // Deterministic for a seed; another seed moves the VPLs.
    let again = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: n,
            bounces: 3,
            seed: 7,
        },
    )
    .expect("vpls");
    assert_eq!(vpls, again);
    let other = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: n,
            bounces: 3,
            seed: 8,
        },
    )
    .expect("vpls");
    assert_ne!(vpls, other);
    // Every VPL lies on the box, its normal facing inwards.
    for v in &vpls {
        let p = Vec3::from(v.position);
        assert!((p.abs().max_element() - 1.0).abs() < 1e-3, "{p}");
        assert!(Vec3::from(v.normal).dot(-p) > 0.0);
    }
    // Bad parameters are errors.
    assert!(
        path_vpls(
            &t,
            &s.lights,
            &PathParams {
                paths: 16,
                bounces: 0,
                seed: 0
            }
        )
        .is_err()
    );
    assert!(
        path_vpls(
            &t,
            &s.lights,
            &PathParams {
                paths: u32::MAX,
                bounces: 1,
                seed: 0
            }
        )
        .is_err()
    );
}

#[test]
fn a_vpl_on_the_receiving_surface_gives_no_nan_and_the_clamp_bounds_g() {
    let g = GatherParams { g_max: 4.0 };
    let x = Vec3::ZERO;
    let n = Vec3::Y;
    // On the surface itself, in its plane, and a hair above it.
    for pos in [
        Vec3::ZERO,
        Vec3::new(1e-3, 0.0, 0.0),
        Vec3::new(0.0, 1e-20, 0.0),
        Vec3::new(1e-6, 1e-6, 0.0),
    ] {
        let v = Vpl::new(pos, -Vec3::Y, Vec3::ONE);
        let l = gather_one(&v, x, n, Vec3::ONE, &g);
        assert!(l.is_finite(), "{pos}: {l}");
        assert!(l.x <= 1.0 / PI / PI * g.g_max * 1.0001, "{pos}: {l}");
    }
    // The clamp's loss: 0 far away, large right above.
    let far = [Vpl::new(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y, Vec3::ONE)];
    assert_eq!(clamp_loss(&far, x, n, &g), 0.0);
    let near = [Vpl::new(Vec3::new(0.0, 0.1, 0.0), -Vec3::Y, Vec3::ONE)];
    let loss = clamp_loss(&near, x, n, &g);
    assert!((loss - (1.0 - 4.0 / 100.0)).abs() < 1e-4, "{loss}");
}

/// The built-in four rooms seen by its first camera, with `n` path VPLs.
fn four_rooms(n: u32, size: [u32; 2], scale: f32) -> (Scene, Vec<Vpl>, View) {
    let (s, cam) = scaled_four_rooms(scale);
    let t = Tracer::new(&s);
    let vpls = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: n,
            bounces: 1,
            seed: 3,
        },
    )
    .expect("vpls");
    let view = View::new(&cam, size).expect("view");
    (s, vpls, view)
}

#[test]
fn scene_scales_from_1e_minus_3_to_1e4_give_the_same_image_after_scaling_the_light() {
    let render = |scale: f32| {
        let (s, vpls, view) = four_rooms(256, [24, 16], scale);
        let t = Tracer::new(&s);
        let params = ReferenceParams {
            samples_per_pixel: 1,
            gather: GatherParams {
                g_max: 10.0 / (scale * scale),
            },
            ..ReferenceParams::default()
        };
        render_reference(&t, &s.lights, &vpls, &view, &params, &|_, _| {})
            .expect("render")
            .0
    };
    let base = render(1.0);
    assert!(base.mean().x > 0.0);
    for scale in [1e-3f32, 1e-1, 10.0, 1e4] {
        let img = render(scale);
        let e = visgate_runtime::metrics::errors(&img, &base).expect("same size");
        assert!(e.rel_mse < 1e-4, "scale {scale}: {e:?}");
    }
}

#[test]
fn zero_one_and_65536_vpls_and_degenerate_triangles_render_finite_images() {
    let (s, vpls, view) = four_rooms(65536, [8, 6], 1.0);
    assert!(vpls.len() > 60000, "{}", vpls.len());
    let t = Tracer::new(&s);
    let params = ReferenceParams {
        samples_per_pixel: 1,
        indirect_visibility: false,
        ..ReferenceParams::default()
    };
    for v in [&vpls[..0], &vpls[..1], &vpls[..]] {
        let (img, _) =
            render_reference(&t, &s.lights, v, &view, &params, &|_, _| {}).expect("render");
        assert!(
            img.pixels
                .iter()
                .all(|p| p.is_finite() && p.min_element() >= 0.0)
        );
    }
    // Degenerate triangles (zero area, repeated vertices) are skipped by the tracer.
    let mut s2 = s.clone();
    let m = &mut s2.meshes[0];
    let p = m.positions[0];
    m.positions.push(p);
    let k = m.positions.len() as u32 - 1;
    m.normals.push(Vec3::Y);
    m.uvs.push(Vec2::ZERO);
    m.triangles.push([0, k, k]);
    m.material.push(0);
    let t2 = Tracer::new(&s2);
    assert_eq!(t2.triangle_count(), t.triangle_count());
}

#[test]
fn a_light_inside_geometry_lights_nothing_outside_it() {
    // The light sits inside a small closed box placed on a floor: nothing reaches the floor.
    let mut q = closed_box(0.2);
    for f in &mut q {
        // Turn the box's faces outwards too: surfaces are two-sided anyway.
        f.iter_mut().for_each(|p| *p += Vec3::new(0.0, 1.0, 0.0));
    }
    q.push(floor(10.0));
    let s = quads(
        &q,
        0.7,
        vec![Light::Point {
            position: Vec3::new(0.0, 1.0, 0.0),
            intensity: Vec3::splat(50.0),
        }],
    );
    let t = Tracer::new(&s);
    let vpls = path_vpls(
        &t,
        &s.lights,
        &PathParams {
            paths: 2048,
            bounces: 2,
            seed: 1,
        },
    )
    .expect("vpls");
    // All VPLs lie on the inner box.
    assert!(vpls.iter().all(|v| Vec3::from(v.position).y > 0.7));
    let l = shade_point(
        &t,
        &s.lights,
        &vpls,
        Vec3::new(3.0, 2.0, 0.0),
        Vec3::new(0.0, -1.0, 0.0),
        &ReferenceParams::default(),
    )
    .expect("hit");
    assert_eq!(l, Vec3::ZERO);
}

#[test]
fn metrics_are_zero_for_equal_images_and_grow_with_the_difference() {
    use visgate_runtime::hdr::HdrImage;
    use visgate_runtime::metrics::{errors, flip};
    let mut a = HdrImage::new(32, 24);
    for (i, p) in a.pixels.iter_mut().enumerate() {
        *p = Vec3::splat((i % 7) as f32 * 0.1);
    }
    let e = errors(&a, &a).expect("same size");
    assert_eq!((e.mse, e.rel_mse), (0.0, 0.0));
    assert_eq!(flip(&a, &a, 0.0).expect("same size").0, 0.0);
    let mut b = a.clone();
    b.pixels.iter_mut().for_each(|p| *p *= 1.1);
    let mut c = a.clone();
    c.pixels.iter_mut().for_each(|p| *p *= 2.0);
    let (eb, ec) = (errors(&b, &a).expect("ok"), errors(&c, &a).expect("ok"));
    assert!(eb.mse > 0.0 && ec.mse > eb.mse && ec.rel_mse > eb.rel_mse);
    let (fb, fc) = (
        flip(&b, &a, 0.0).expect("ok").0,
        flip(&c, &a, 0.0).expect("ok").0,
    );
    assert!(fb > 0.0 && fc > fb && fc <= 1.0, "{fb} {fc}");
    assert!(errors(&HdrImage::new(3, 3), &a).is_err());
}

#[test]
fn a_cancelled_reference_stops_with_an_error_and_an_uncancelled_one_is_render_with() {
    use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
    use visgate_runtime::cpu::reference::{IndirectVisibility, render_cancellable, render_with};
    let (scene, vpls, view) = four_rooms(32, [24, 16], 1.0);
    let tracer = Tracer::new(&scene);
    let p = ReferenceParams {
        samples_per_pixel: 1,
        ..ReferenceParams::default()
    };
    let exact = IndirectVisibility::Exact;
    let (want, _) =
        render_with(&tracer, &scene.lights, &vpls, &view, &p, exact, &|_, _| {}).expect("render");
    let go = AtomicBool::new(false);
    let (got, _) = render_cancellable(
        &tracer,
        &scene.lights,
        &vpls,
        &view,
        &p,
        exact,
        &|_, _| {},
        &go,
    )
    .expect("render");
    assert_eq!(got.pixels, want.pixels);
    // Set after the first rows: the rest are skipped and the call says it was cancelled.
    let stop = AtomicBool::new(false);
    let rows = AtomicU32::new(0);
    let progress = |done: u32, _| {
        rows.store(done, Ordering::Relaxed);
        stop.store(true, Ordering::Relaxed);
    };
    let e = render_cancellable(
        &tracer,
        &scene.lights,
        &vpls,
        &view,
        &p,
        exact,
        &progress,
        &stop,
    )
    .expect_err("cancelled");
    assert!(e.to_string().contains("cancelled"), "{e}");
    assert!(rows.load(Ordering::Relaxed) < 16, "every row ran");
}

#[test]
fn pixels_whose_samples_see_a_panel_and_what_lies_behind_it_are_mixed() {
    // A panel standing on a 20 m floor, seen square on from 5 m at eye height 1.03 m: 64 × 48
    // pixels of 60°, 11.09 pixels a metre at the panel. Its edges fall between the samples of
    // a pixel (at 1/8–3/4 across, 1/9–2/3 down) and its centre: left at column 18.37, right
    // 41.64, top at row 15.4, foot 35.42; the floor ends 10 m behind it, where the void
    // begins. Its right part, from column 30.4, is 25 times darker.
    let (x0, x1, split, top) = (-1.23, 0.87, -0.1443, 1.806);
    let quad = |a: f32, b: f32| {
        [
            Vec3::new(a, 0.0, 0.0),
            Vec3::new(b, 0.0, 0.0),
            Vec3::new(b, top, 0.0),
            Vec3::new(a, top, 0.0),
        ]
    };
    let mut s = quads(
        &[floor(10.0), quad(x0, split), quad(split, x1)],
        0.5,
        Vec::new(),
    );
    let mut dark = s.materials[0].clone();
    dark.albedo = Vec3::splat(0.02);
    s.materials.push(dark);
    s.meshes[0].material[4..].fill(1);
    let camera = Camera {
        name: "front".into(),
        eye: Vec3::new(0.0, 1.03, 5.0),
        target: Vec3::new(0.0, 1.03, 0.0),
        up: Vec3::Y,
        fov_x_rad: 60f32.to_radians(),
    };
    let view = View::new(&camera, [64, 48]).expect("view");
    let tracer = Tracer::new(&s);
    let mixed = mixed_pixels(&tracer, &view, 4);
    let at = |x: usize, y: usize| mixed[y * 64 + x];
    // Its sides against the floor and the void behind, its top against the void, its foot
    // against the floor it stands on (a crease), and where its two albedos meet.
    assert!((16..35).all(|y| at(18, y) && at(41, y)), "sides");
    assert!((19..41).all(|x| at(x, 15)), "top");
    assert!((19..41).all(|x| at(x, 35)), "foot");
    assert!((17..34).all(|y| at(30, y)), "albedos");
    // Inside the panel's two parts and on the near floor: one surface a pixel.
    let inside = |x: usize| x == 30 || (17..34).all(|y| !at(x, y));
    assert!((20..40).all(inside), "panel");
    assert!((0..64).all(|x| (38..48).all(|y| !at(x, y))), "near floor");
    // Outlines only: 105 pixels of 3,072 (the far edge of the floor falls after the samples).
    let n = mixed.iter().filter(|&&m| m).count();
    assert!((100..140).contains(&n), "{n} mixed pixels");
    // One sample a pixel sees one surface.
    assert!(mixed_pixels(&tracer, &view, 1).iter().all(|&m| !m));
}

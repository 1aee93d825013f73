//! Virtual area lights: the GPU k-means against its CPU twin, and the edge cases.

use glam::Vec3;
use visgate_runtime::gpu::{GpuContext, GpuRenderer, centres_of};
use visgate_runtime::tracer::Tracer;
use visgate_runtime::val::{Clustering, ValParams, cluster};
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

fn context() -> GpuContext {
    GpuContext::new()
        .unwrap_or_else(|e| panic!("GPU tests need an adapter (CI installs lavapipe): {e}"))
}

fn vpls_of(b: Builtin, paths: u32) -> (visgate_formats::Scene, Vec<Vpl>) {
    let scene = b.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths,
            bounces: 1,
            seed: 3,
        },
    )
    .expect("vpls");
    (scene, vpls)
}

fn assert_sane(c: &Clustering, n: usize, m: u32) {
    assert_eq!(c.vals.len(), m as usize);
    assert_eq!(c.mapping.len(), n);
    assert!(c.mapping.iter().all(|&k| k < m));
    let counted: u32 = c.vals.iter().map(|v| v.vpl_count()).sum();
    assert_eq!(counted as usize, n);
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
        let (scene, vpls) = vpls_of(b, 1024);
        let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
        for m in [1, 4, 30, 64] {
            let params = ValParams {
                count: m,
                ..ValParams::default()
            };
            let cpu = cluster(&vpls, &params, None).expect("cpu");
            let got = gpu.cluster_vals(&ctx, &vpls, &params).expect("gpu");
            assert_sane(&cpu, vpls.len(), m);
            assert_sane(&got, vpls.len(), m);
            let differ = cpu
                .mapping
                .iter()
                .zip(&got.mapping)
                .filter(|(a, b)| a != b)
                .count();
            eprintln!(
                "{} M = {m}: {} live VALs, {differ} of {} VPLs mapped differently",
                b.name(),
                cpu.live(),
                vpls.len()
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
    let (scene, vpls) = vpls_of(Builtin::FourRooms, 256);
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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
    let (scene, vpls) = vpls_of(Builtin::FourRooms, 1024);
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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

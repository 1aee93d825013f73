//! The GPU's k-means against its CPU twin, at the extremes, frame to frame, to its stop, and with samples that find nothing.

use super::*;

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

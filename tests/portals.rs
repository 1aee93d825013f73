//! Portals against ray-cast visibility: on the ajar-door level (zero-thickness walls, a door
//! 20° ajar, a table), every pixel–VPL pair of a 64×48 view that could exchange light, the
//! portal walk's answer against the exact shadow ray, beside the disks' (the known
//! answer), and the bake's boundary check on every built-in scene.

use glam::{Vec2, Vec3};
use visgate_formats::vgate::BakeParams;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::{End, GateLevel, GateParams, GateShape, Walk};
use visgate_runtime::cpu::portal_walk::facing_pairs;
use visgate_scenes::Builtin;

#[path = "support/gates.rs"]
mod gate_support;

use gate_support::{baked, fixture, fixture_with, params_at};

/// Pairs, disagreements with the shadow ray (false visible, false occluded) for `params`.
#[derive(Debug, Default, Clone, Copy)]
struct Agreement {
    pairs: u64,
    false_visible: u64,
    false_occluded: u64,
}

impl Agreement {
    fn rate(&self) -> f64 {
        1.0 - (self.false_visible + self.false_occluded) as f64 / self.pairs.max(1) as f64
    }
}

/// Per camera of built-in `b` baked at `res` (once), per entry of `params`: the gate test's
/// agreement with the shadow ray over every pixel–VPL pair of the 64×48 view that could
/// exchange light.
fn agreement(b: Builtin, res: u32, params: &[GateParams]) -> Vec<Vec<Agreement>> {
    agreement_with(b, &params_at(res), params)
}

/// [`agreement`] on a level baked with `bake`.
fn agreement_with(b: Builtin, bake: &BakeParams, params: &[GateParams]) -> Vec<Vec<Agreement>> {
    let (scene, gates, tracer, vpls, _) = fixture_with(b, bake, 0);
    let mut all = Vec::new();
    for camera in &scene.cameras {
        let view = View::new(camera, [64, 48]).expect("view");
        let mut out = vec![Agreement::default(); params.len()];
        facing_pairs(&tracer, &gates, &view, &vpls, |pair| {
            for (a, p) in out.iter_mut().zip(params) {
                let vis = gates.visible(&pair.vpl_end(), &pair.point_end(), p);
                a.pairs += 1;
                a.false_visible += u64::from(vis && !pair.exact);
                a.false_occluded += u64::from(!vis && pair.exact);
            }
        });
        all.push(out);
    }
    all
}

/// Portals, disks, voxels, then voxels with the closed voxels' triangles.
fn shapes() -> [GateParams; 4] {
    let [p, d, v] =
        [GateShape::Portal, GateShape::Disk, GateShape::Voxels].map(|shape| GateParams {
            shape,
            ..GateParams::default()
        });
    [
        p,
        d,
        v,
        GateParams {
            triangles: true,
            ..v
        },
    ]
}

fn print(name: &str, camera: usize, [p, d, v, t]: [&Agreement; 4]) {
    println!(
        "{name} camera {camera}: {} pairs; portals agree {:.2} % ({} false visible, {} false \
         occluded); disks {:.2} % ({} / {}); voxels {:.2} % ({} / {}); with triangles {:.2} % \
         ({} / {})",
        p.pairs,
        100.0 * p.rate(),
        p.false_visible,
        p.false_occluded,
        100.0 * d.rate(),
        d.false_visible,
        d.false_occluded,
        100.0 * v.rate(),
        v.false_visible,
        v.false_occluded,
        100.0 * t.rate(),
        t.false_visible,
        t.false_occluded
    );
}

#[test]
fn ajar_door_portal_visibility_agrees_with_shadow_rays() {
    let cameras = agreement(Builtin::AjarDoor, 128, &shapes());
    assert_eq!(cameras.len(), 3);
    for (camera, found) in cameras.iter().enumerate() {
        let [p, d, v, t] = found[..] else {
            unreachable!()
        };
        print("ajar-door", camera, [&p, &d, &v, &t]);
        assert!(p.pairs > 10_000, "{p:?}");
        // Measured 95.6, 93.2 and 98.2 % (disks 93.8, 86.8, 97.0 %; 95.9, 92.3 and 98.3 %
        // before clusters were split where their nodes do not see each other and a voxel kept
        // its cluster where it sees its own node); the target is 99 %.
        assert!(p.rate() >= 0.93, "camera {camera}: {p:?}");
        assert!(
            p.rate() > d.rate(),
            "camera {camera}: portals {p:?} disks {d:?}"
        );
        // The voxel walk on the level's 512 sight grid (1.6 cm), voxelized thin: measured
        // 99.14, 98.29 and 99.90 %, almost every disagreement a pair the voxels close (the
        // door's 33 cm gap narrows by under half a voxel at each edge, the 5 cm slit above it
        // by more). The conservative voxelization gave 98.84, 97.69 and 99.85 %, under these
        // floors on every camera.
        let floor = [0.99, 0.98, 0.9987][camera];
        assert!(v.rate() >= floor, "camera {camera}: {v:?}");
        assert!(
            v.rate() > p.rate(),
            "camera {camera}: voxels {v:?} portals {p:?}"
        );
        // Along the true segment, with the triangles in the closed voxels it meets: 100.00 %
        // on each camera (3 to 6 pairs differ).
        assert!(t.rate() >= 0.999, "camera {camera}: {t:?}");
    }
}

#[test]
fn a_level_refined_from_a_coarser_partition_agrees_with_shadow_rays_better_than_its_own_grid() {
    // The ajar door at 256: by default its partition is its 128 grid's (1/128 of the level),
    // refined; partitioned on its own 256 grid instead, its many small clusters agree less.
    let portals = &shapes()[..1];
    let coarse = agreement(Builtin::AjarDoor, 128, portals);
    let refined = agreement(Builtin::AjarDoor, 256, portals);
    let own = BakeParams {
        partition_voxel_m: Some(0.0),
        ..params_at(256)
    };
    let own = agreement_with(Builtin::AjarDoor, &own, portals);
    for (camera, ((c, r), o)) in coarse.iter().zip(&refined).zip(&own).enumerate() {
        let (c, r, o) = (c[0], r[0], o[0]);
        println!(
            "ajar-door camera {camera}, {} pairs: 256 refined from its 128 partition agrees \
             {:.2} %, on its own grid {:.2} %; the 128 bake {:.2} %",
            r.pairs,
            100.0 * r.rate(),
            100.0 * o.rate(),
            100.0 * c.rate()
        );
        assert!(r.pairs > 10_000, "{r:?}");
        assert!(r.rate() >= o.rate(), "camera {camera}: {r:?} against {o:?}");
        assert!(
            r.rate() >= c.rate() - 0.02,
            "camera {camera}: {r:?} against {c:?}"
        );
    }
}

#[test]
fn four_rooms_portal_visibility_agrees_with_shadow_rays_on_99_percent_of_pairs() {
    // Thick walls and plain doorways: the portals are the doorways, one plane each.
    let found = agreement(Builtin::FourRooms, 128, &shapes());
    let [p, d, v, t] = found[0][..] else {
        unreachable!()
    };
    print("four-rooms", 0, [&p, &d, &v, &t]);
    assert!(p.pairs > 100_000, "{p:?}");
    assert!(p.rate() >= 0.99 && p.rate() > d.rate(), "{p:?} {d:?}");
    // The voxels close a doorway's edges a voxel wide: 99.35 % (56 false visible pairs).
    assert!(v.rate() >= 0.99 && v.rate() > p.rate(), "{v:?} {p:?}");
    // With the triangles in the closed voxels: 100.00 % (2 pairs differ).
    assert!(t.rate() >= 0.999, "{t:?}");
}

#[test]
fn pillared_hall_portal_visibility_agrees_with_shadow_rays_past_the_columns() {
    // A row of columns down the hall: the grown hall cluster wrapped them, and light passed a
    // column inside one cluster. Clusters whose nodes do not see each other are now split
    // (convex.rs), and the gaps between the columns are cut at the gates (a voxel keeps its
    // cluster where it sees its own node, flatten.rs): measured 85.4 and 93.8 % of pairs agree
    // (78.0 and 76.9 % before; disks 84.6 and 96.8 %). What is left: from the part of a gap on
    // one side of its gate, a segment can reach the column's flank inside that side's cluster.
    let cameras = agreement(Builtin::PillaredHall, 128, &shapes());
    // The voxel walk sees the columns themselves: 99.1 and 99.8 %.
    let floor = [0.85, 0.93];
    for (camera, found) in cameras.iter().enumerate() {
        let [p, d, v, t] = found[..] else {
            unreachable!()
        };
        print("pillared-hall", camera, [&p, &d, &v, &t]);
        assert!(p.pairs > 10_000, "{p:?}");
        assert!(p.rate() >= floor[camera], "camera {camera}: {p:?}");
        assert!(v.rate() >= [0.99, 0.995][camera], "camera {camera}: {v:?}");
        // With the triangles: 99.96 and 100.00 %.
        assert!(t.rate() >= 0.999, "camera {camera}: {t:?}");
    }
}

#[test]
fn every_interface_face_of_every_builtin_belongs_to_a_portal() {
    for b in Builtin::ALL {
        let (_, baked) = baked(b, 96);
        let s = &baked.report.summary;
        println!(
            "{}: {} clusters, {} portals, {} gates",
            b.name(),
            s.clusters,
            s.portals,
            s.gates
        );
        assert_eq!(s.uncovered_interface_faces, 0, "{}", b.name());
        // Every portal opens somewhere; n clusters in c components need n − c portals at least.
        let level = &baked.level;
        for p in &level.topology.portals {
            assert!(p.open_cells() > 0 && p.faces > 0, "{}: {p:?}", b.name());
        }
        assert!(
            s.portals + s.components >= s.clusters,
            "{}: {s:?}",
            b.name()
        );
    }
}

#[test]
fn a_walk_over_its_limit_is_counted_and_occluded_never_visible() {
    let (_, gates, tracer, vpls, view) = fixture(Builtin::AjarDoor, 128, 0);
    // A pixel–VPL pair whose walk passes two portals or more.
    let found = (0..64 * 48).find_map(|k| {
        let dir = view.ray_dir(Vec2::new((k % 64) as f32 + 0.5, (k / 64) as f32 + 0.5));
        let s = tracer.trace(view.eye, dir)?;
        let here = gates.cluster_at(s.position, s.normal)?;
        vpls.iter().find_map(|v| {
            let (vp, vn) = (Vec3::from(v.position), Vec3::from(v.normal));
            let there = gates.cluster_at(vp, vn)?;
            match gates.walk(vp, there, s.position, here, 64) {
                Walk::Visible(n) if n >= 2 => Some(((vp, vn), there, s, here, n)),
                _ => None,
            }
        })
    });
    let ((a, na), ca, s, cb, n) = found.expect("a walk through two portals on ajar-door");
    let b = s.position;
    let from = End {
        position: a,
        normal: na,
        cluster: Some(ca),
    };
    let to = End {
        position: b,
        normal: s.normal,
        cluster: Some(cb),
    };
    assert_eq!(gates.walk(a, ca, b, cb, n - 1), Walk::Limit);
    gates.take_walks_over_limit();
    let short = GateParams {
        shape: GateShape::Portal,
        max_walk: n - 1,
        ..GateParams::default()
    };
    assert!(!gates.visible(&from, &to, &short));
    assert_eq!(gates.take_walks_over_limit(), 1);
    let long = GateParams {
        shape: GateShape::Portal,
        ..GateParams::default()
    };
    assert!(gates.visible(&from, &to, &long));
    assert_eq!(gates.take_walks_over_limit(), 0);
}

/// The walk of `GateLevel::walk` with every portal of a cluster tested at each step (no
/// hierarchy): what the hierarchy must find.
fn walk_every_portal(gates: &GateLevel, a: Vec3, ca: u32, b: Vec3, cb: u32) -> Walk {
    let portals = &gates.baked().topology.portals;
    let d = b - a;
    let len = d.length();
    let slack = 1.5 * gates.voxel_size() / len;
    let (mut c, mut t0, mut last) = (ca, -slack, usize::MAX);
    for step in 0..64 {
        let mut best: Option<(f32, usize)> = None;
        for (pi, p) in portals.iter().enumerate() {
            if pi == last || !p.clusters.contains(&c) {
                continue;
            }
            let n = Vec3::from(p.normal) * if p.clusters[0] == c { 1.0 } else { -1.0 };
            let den = d.dot(n);
            if den <= f32::EPSILON * len {
                continue;
            }
            let t = (Vec3::from(p.origin_m) - a).dot(n) / den;
            if t < t0 || t > 1.0 + slack || best.is_some_and(|(bt, _)| bt <= t) {
                continue;
            }
            if p.covers((a + d * t).to_array()) {
                best = Some((t, pi));
            }
        }
        let Some((t, pi)) = best else {
            return Walk::Blocked;
        };
        let other = portals[pi].clusters[usize::from(portals[pi].clusters[0] == c)];
        if other == cb {
            return Walk::Visible(step + 1);
        }
        (c, t0, last) = (other, t, pi);
    }
    Walk::Limit
}

#[test]
fn the_portal_hierarchy_finds_what_testing_every_portal_finds() {
    let (_, gates, tracer, vpls, view) = fixture(Builtin::PillaredHall, 128, 0);
    let bvh = gates.portal_bvh();
    assert!(bvh.depth() <= visgate_runtime::cpu::portal_walk::MAX_DEPTH);
    let (mut walks, mut visible, mut same) = (0, 0, 0);
    for k in 0..64 * 48 {
        let dir = view.ray_dir(Vec2::new((k % 64) as f32 + 0.5, (k / 64) as f32 + 0.5));
        let Some(s) = tracer.trace(view.eye, dir) else {
            continue;
        };
        let Some(here) = gates.cluster_at(s.position, s.normal) else {
            continue;
        };
        for v in vpls.iter().step_by(4) {
            let (vp, vn) = (Vec3::from(v.position), Vec3::from(v.normal));
            let Some(there) = gates.cluster_at(vp, vn) else {
                continue;
            };
            if there == here {
                continue;
            }
            let found = gates.walk(vp, there, s.position, here, 64);
            walks += 1;
            visible += u32::from(matches!(found, Walk::Visible(_)));
            same += u32::from(found == walk_every_portal(&gates, vp, there, s.position, here));
        }
    }
    println!(
        "pillared-hall: {} portals, hierarchy depth {}; {walks} walks, {visible} visible, {same} \
         the same without the hierarchy",
        gates.baked().topology.portals.len(),
        bvh.depth()
    );
    assert!(walks > 10_000 && visible > walks / 10, "{walks} {visible}");
    // Two portals crossed at the very same t may be taken in another order: all but a few.
    assert!(same as f64 >= 0.9999 * walks as f64, "{same} of {walks}");
}

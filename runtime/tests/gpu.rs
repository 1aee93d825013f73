//! The wgpu renderer against the CPU reference with the same VPLs and the same visibility
//! choice, on whatever adapter wgpu finds (lavapipe in CI). A missing adapter fails the test.

use std::f32::consts::PI;

use glam::Vec3;
use visgate_runtime::camera::View;
use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer, SHADERS};
use visgate_runtime::metrics::{errors, flip};
use visgate_runtime::reference::{ReferenceParams, render_reference};
use visgate_runtime::tracer::Tracer;
use visgate_runtime::vpl::{GatherParams, PathParams, path_vpls};
use visgate_scenes::Builtin;

mod common;
use common::{closed_box, floor, quads, scaled_four_rooms};

fn context() -> GpuContext {
    match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("GPU tests need an adapter (CI installs lavapipe): {e}"),
    }
}

#[test]
fn every_shader_parses_and_validates_without_a_gpu() {
    for (name, src) in SHADERS {
        let module = naga::front::wgsl::parse_str(src)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}

/// CPU (spp 1, pixel centres) and GPU images of a built-in scene's first camera.
fn both(
    b: Builtin,
    size: [u32; 2],
    paths: u32,
    mode: GpuMode,
) -> (
    visgate_runtime::hdr::HdrImage,
    visgate_runtime::hdr::HdrImage,
) {
    let ctx = context();
    let scene = b.scene().expect("scene");
    let tracer = Tracer::new(&scene);
    let vpls = path_vpls(
        &tracer,
        &scene.lights,
        &PathParams {
            paths,
            bounces: 1,
            seed: 2,
        },
    )
    .expect("vpls");
    let view = View::new(scene.cameras.first().expect("camera"), size).expect("view");
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let (img, _) = gpu
        .render(
            &ctx,
            &view,
            &vpls,
            &GpuParams {
                mode,
                ..GpuParams::default()
            },
        )
        .expect("render");
    let (cpu, _) = render_reference(
        &tracer,
        &scene.lights,
        &vpls,
        &view,
        &ReferenceParams {
            samples_per_pixel: 1,
            indirect: mode != GpuMode::DirectOnly,
            indirect_visibility: mode == GpuMode::PerVplShadowMaps,
            gather: GatherParams::default(),
            ..ReferenceParams::default()
        },
        &|_, _| {},
    )
    .expect("reference");
    (img, cpu)
}

#[test]
fn gpu_modes_agree_with_the_cpu_reference_with_the_same_vpls_and_visibility() {
    for (b, mode) in [
        (Builtin::FourRooms, GpuMode::None),
        (Builtin::FourRooms, GpuMode::DirectOnly),
        (Builtin::CornellBox, GpuMode::None),
        (Builtin::FourRooms, GpuMode::PerVplShadowMaps),
        (Builtin::CornellBox, GpuMode::PerVplShadowMaps),
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
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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

/// Size and member offsets of struct `name` in `src`, as naga lays it out.
fn wgsl_layout(src: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = naga::front::wgsl::parse_str(src).expect("parses");
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).expect("layout");
    let (h, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    (
        layouter[h].size,
        members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
            .collect(),
    )
}

#[test]
fn gpu_structs_match_their_wgsl_layouts() {
    use std::mem::{offset_of, size_of};
    use visgate_runtime::gpu::{
        Batch, ClusterFrame, CssmFrame, Globals, GpuGeometryCluster, GpuLight, GridUniform,
        RsmSample, ShadowView, ValFrame, ValGather, ValMaps, VplView,
    };
    use visgate_runtime::val::Val;
    use visgate_runtime::vpl::Vpl;
    let shade = SHADERS[2].1;
    let check = |src: &str, name: &str, size: usize, offsets: &[(&str, usize)]| {
        let (s, members) = wgsl_layout(src, name);
        assert_eq!(s as usize, size, "{name} size");
        assert_eq!(members.len(), offsets.len(), "{name} members {members:?}");
        for ((m, o), (want_name, want)) in members.iter().zip(offsets) {
            assert_eq!((m.as_str(), *o as usize), (*want_name, *want), "{name}");
        }
    };
    check(
        shade,
        "Globals",
        size_of::<Globals>(),
        &[
            ("view_proj", offset_of!(Globals, view_proj)),
            ("eye", offset_of!(Globals, eye)),
            ("params", offset_of!(Globals, params)),
            ("counts", offset_of!(Globals, counts)),
        ],
    );
    check(
        SHADERS[0].1,
        "Globals",
        size_of::<Globals>(),
        &[
            ("view_proj", 0),
            ("eye", 64),
            ("params", 80),
            ("counts", 96),
        ],
    );
    check(
        shade,
        "Light",
        size_of::<GpuLight>(),
        &[
            ("position", offset_of!(GpuLight, position)),
            ("intensity", offset_of!(GpuLight, intensity)),
            ("direction", offset_of!(GpuLight, direction)),
            ("layers", offset_of!(GpuLight, layers)),
        ],
    );
    for src in [shade, SHADERS[4].1] {
        check(
            src,
            "Vpl",
            size_of::<Vpl>(),
            &[
                ("position", offset_of!(Vpl, position)),
                ("pad0", offset_of!(Vpl, _pad0)),
                ("normal", offset_of!(Vpl, normal)),
                ("pad1", offset_of!(Vpl, _pad1)),
                ("flux", offset_of!(Vpl, flux)),
                ("pad2", offset_of!(Vpl, _pad2)),
            ],
        );
    }
    check(
        SHADERS[1].1,
        "ShadowView",
        size_of::<ShadowView>(),
        &[
            ("view_proj", offset_of!(ShadowView, view_proj)),
            ("light", offset_of!(ShadowView, light)),
        ],
    );
    check(
        SHADERS[3].1,
        "VplView",
        size_of::<VplView>(),
        &[
            ("position", offset_of!(VplView, position)),
            ("tangent", offset_of!(VplView, tangent)),
            ("bitangent", offset_of!(VplView, bitangent)),
            ("normal", offset_of!(VplView, normal)),
        ],
    );
    check(
        shade,
        "Grid",
        size_of::<GridUniform>(),
        &[
            ("origin", offset_of!(GridUniform, origin)),
            ("dims", offset_of!(GridUniform, dims)),
            ("params", offset_of!(GridUniform, params)),
        ],
    );
    // Gates go up as 12 words each (GateLevel::tables): centre + radius, normal, clusters.
    check(
        shade,
        "Gate",
        48,
        &[("centre", 0), ("normal", 16), ("clusters", 32)],
    );
    check(
        SHADERS[5].1,
        "Sample",
        size_of::<RsmSample>(),
        &[
            ("texel", offset_of!(RsmSample, texel)),
            ("power", offset_of!(RsmSample, power)),
        ],
    );
    check(
        SHADERS[5].1,
        "Vpl",
        size_of::<Vpl>(),
        &[
            ("position", 0),
            ("pad0", 12),
            ("normal", 16),
            ("pad1", 28),
            ("flux", 32),
            ("pad2", 44),
        ],
    );
    check(
        SHADERS[4].1,
        "Batch",
        size_of::<Batch>(),
        &[
            ("range", offset_of!(Batch, range)),
            ("params", offset_of!(Batch, params)),
        ],
    );
    let clusters = SHADERS[6].1;
    check(
        clusters,
        "Frame",
        size_of::<ClusterFrame>(),
        &[
            ("eye", offset_of!(ClusterFrame, eye)),
            ("forward", offset_of!(ClusterFrame, forward)),
            ("size", offset_of!(ClusterFrame, size)),
            ("counts", offset_of!(ClusterFrame, counts)),
        ],
    );
    let cluster_members = [
        ("key", offset_of!(GpuGeometryCluster, key)),
        ("lo", offset_of!(GpuGeometryCluster, lo)),
        ("hi", offset_of!(GpuGeometryCluster, hi)),
        ("list", offset_of!(GpuGeometryCluster, list)),
    ];
    let size = size_of::<GpuGeometryCluster>();
    check(clusters, "GeometryCluster", size, &cluster_members);
    check(shade, "ClusterLists", size, &cluster_members);
    check(
        clusters,
        "Grid",
        size_of::<GridUniform>(),
        &[("origin", 0), ("dims", 16), ("params", 32)],
    );
    let vals = SHADERS[7].1;
    check(
        vals,
        "Val",
        size_of::<Val>(),
        &[
            ("position", offset_of!(Val, position)),
            ("normal", offset_of!(Val, normal)),
            ("flux", offset_of!(Val, flux)),
            ("rect", offset_of!(Val, rect)),
        ],
    );
    check(
        SHADERS[8].1,
        "ValGather",
        size_of::<ValGather>(),
        &[
            ("counts", offset_of!(ValGather, counts)),
            ("params", offset_of!(ValGather, params)),
            ("cssm", offset_of!(ValGather, cssm)),
            ("interleave", offset_of!(ValGather, interleave)),
            ("blur", offset_of!(ValGather, blur)),
        ],
    );
    check(
        SHADERS[9].1,
        "CssmFrame",
        size_of::<CssmFrame>(),
        &[
            ("counts", offset_of!(CssmFrame, counts)),
            ("level", offset_of!(CssmFrame, level)),
        ],
    );
    check(
        SHADERS[3].1,
        "ValMaps",
        size_of::<ValMaps>(),
        &[("params", offset_of!(ValMaps, params))],
    );
    for src in [vals, SHADERS[3].1, SHADERS[8].1] {
        check(
            src,
            "Val",
            size_of::<Val>(),
            &[("position", 0), ("normal", 16), ("flux", 32), ("rect", 48)],
        );
    }
    check(
        vals,
        "ValFrame",
        size_of::<ValFrame>(),
        &[
            ("counts", offset_of!(ValFrame, counts)),
            ("weights", offset_of!(ValFrame, weights)),
        ],
    );
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
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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
    // Timestamp queries, where the adapter has them (lavapipe does): every stage that ran took
    // GPU time, and the stages that did not run took none.
    let (_, times) = gpu
        .render(
            &ctx,
            &view,
            &vpls[..64],
            &GpuParams {
                mode: GpuMode::PerVplShadowMaps,
                vpl_batch: 16,
                ..GpuParams::default()
            },
        )
        .expect("render");
    match (ctx.timestamp_period, times.gpu) {
        (Some(_), Some(g)) => {
            assert!(g.shadows > 0.0 && g.gbuffer > 0.0 && g.shade > 0.0, "{g:?}");
            assert!(g.vpl_maps > 0.0 && g.vpl_gather > 0.0, "{g:?}");
        }
        (None, None) => eprintln!("adapter without timestamp queries: CPU times only"),
        other => panic!("timestamp support and times disagree: {other:?}"),
    }
    let (_, times) = gpu
        .render(&ctx, &view, &vpls[..64], &GpuParams::default())
        .expect("render");
    if let Some(g) = times.gpu {
        assert_eq!((g.vpl_maps, g.vpl_gather), (0.0, 0.0));
    }
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
            shadow_size: 1,
            ..GpuParams::default()
        },
        GpuParams {
            vpl_batch: 0,
            ..GpuParams::default()
        },
    ] {
        assert!(gpu.render(&ctx, &view, &[], &bad).is_err(), "{bad:?}");
    }
}

#[test]
fn rsm_vpls_carry_the_reflected_power_and_do_not_flicker() {
    // A point light inside a closed box: the RSM sees walls in every direction, so the VPLs
    // hold ρ × the light's power, as the light paths do.
    let ctx = context();
    let scene = Builtin::EmptyBox.scene().expect("scene");
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let tracer = Tracer::new(&scene);
    let n = 4096;
    let rsm = gpu.rsm_vpls(&ctx, n, 256, 1).expect("rsm vpls");
    assert_eq!(rsm.len(), n as usize);
    let paths = path_vpls(
        &tracer,
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
        let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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
    let ctx = context();
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
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
    let tracer = Tracer::new(&scene);
    let (cpu, _) = render_reference(
        &tracer,
        &scene.lights,
        &[],
        &view,
        &ReferenceParams {
            samples_per_pixel: 1,
            indirect: false,
            ..ReferenceParams::default()
        },
        &|_, _| {},
    )
    .expect("cpu");
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

/// A 100 m floor of albedo `rho` with `lights`, for the GPU known answers.
fn floor_scene(rho: f32, lights: Vec<visgate_formats::Light>) -> visgate_formats::Scene {
    quads(&[floor(50.0)], rho, lights)
}

#[test]
fn gpu_spot_falloff_matches_the_conventions_at_beam_mid_ramp_and_cutoff() {
    use visgate_formats::{Camera, Light};
    use visgate_runtime::lights::spot_falloff;
    let (beam, cutoff, h, i) = (20f32.to_radians(), 40f32.to_radians(), 2.0f32, 5.0f32);
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
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    for angle in [0.0f32, beam * 0.95, 0.5 * (beam + cutoff), cutoff * 1.1] {
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
        let d2 = x * x + h * h;
        let want = 1.0 / PI * i * spot_falloff(angle, beam, cutoff) * angle.cos() / d2;
        let got = img.at(1, 1).x;
        assert!(
            (got - want).abs() <= 2e-3 * (1.0 + want),
            "angle {angle}: {got} vs {want}"
        );
    }
}

#[test]
fn gpu_a_closed_box_with_no_light_is_black() {
    let ctx = context();
    let mut scene = Builtin::EmptyBox.scene().expect("scene");
    scene.lights.clear();
    let gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let view = View::new(scene.cameras.first().expect("camera"), [16, 12]).expect("view");
    for mode in [
        GpuMode::None,
        GpuMode::PerVplShadowMaps,
        GpuMode::DirectOnly,
    ] {
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

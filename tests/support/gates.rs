//! What the gate and portal tests share: a built-in scene baked at a resolution, and the
//! fixture they test on (gate level, tracer, 256 light-path VPLs, a 64×48 view).

use visgate_formats::Scene;
use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_preprocess::bake::{BakeOptions, Baked, bake};
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};
use visgate_scenes::Builtin;

/// Default bake parameters at `res` voxels on the longest axis.
pub fn params_at(res: u32) -> BakeParams {
    BakeParams {
        resolution: Resolution::LongestAxisVoxels(res),
        ..BakeParams::default()
    }
}

/// `scene` baked at `res` voxels on its longest axis, default parameters otherwise.
pub fn bake_at(scene: &Scene, res: u32) -> Baked {
    bake(scene, &params_at(res), &BakeOptions::default(), &|_| {}).expect("bake")
}

/// Built-in `b` and its bake at `res`.
pub fn baked(b: Builtin, res: u32) -> (Scene, Baked) {
    let scene = b.scene().expect("scene");
    let baked = bake_at(&scene, res);
    (scene, baked)
}

/// 256 one-bounce light paths from `scene`'s lights (seed 4).
pub fn light_paths(tracer: &Tracer, scene: &Scene) -> Vec<Vpl> {
    let paths = PathParams {
        paths: 256,
        bounces: 1,
        seed: 4,
    };
    path_vpls(tracer, &scene.lights, &paths).expect("vpls")
}

/// Built-in `b` baked at `res`: its gate level, tracer, 256 path VPLs and the 64×48 view of
/// its camera `camera`.
pub fn fixture(b: Builtin, res: u32, camera: usize) -> (Scene, GateLevel, Tracer, Vec<Vpl>, View) {
    fixture_with(b, &params_at(res), camera)
}

/// [`fixture`] baked with `params`.
pub fn fixture_with(
    b: Builtin,
    params: &BakeParams,
    camera: usize,
) -> (Scene, GateLevel, Tracer, Vec<Vpl>, View) {
    let scene = b.scene().expect("scene");
    let baked = bake(&scene, params, &BakeOptions::default(), &|_| {}).expect("bake");
    let gates = GateLevel::new(baked.level, &scene).expect("level");
    let tracer = Tracer::new(&scene);
    let vpls = light_paths(&tracer, &scene);
    let view = View::new(&scene.cameras[camera], [64, 48]).expect("view");
    (scene, gates, tracer, vpls, view)
}

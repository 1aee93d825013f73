//! What the pair examples share (`portal_agreement`, `closed_voxel_triangles`, `dominant_vpls`):
//! from the command line `SCENE LEVEL.vgate CAMERA [WxH] [PATHS]`, the scene, its gates, the
//! tracer, the VPLs of one-bounce light paths (seed 1, as `visgate compare`) and the camera's
//! view.

use visgate_formats::ImportOptions;
use visgate_formats::vgate::BakedLevel;
use visgate_runtime::camera::View;
use visgate_runtime::cpu::gates::GateLevel;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_runtime::vpl::{PathParams, Vpl, path_vpls};

/// A view of a level and the VPLs that light it.
pub struct Pairs {
    /// The level's gates (not read by `dominant_vpls`, hence the allow).
    #[allow(dead_code)]
    pub gates: GateLevel,
    pub tracer: Tracer,
    pub vpls: Vec<Vpl>,
    pub view: View,
    /// The camera's name and the view's size.
    pub camera: String,
    pub size: [u32; 2],
    /// The scene (read by `closed_voxel_triangles` alone, hence the allow).
    #[allow(dead_code)]
    pub scene: visgate_formats::Scene,
}

/// Reads the command line (`name` for the usage line). Defaults: 160x90, 1,024 paths.
pub fn from_args(name: &str) -> anyhow::Result<Pairs> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, level, camera, ..] = args.as_slice() else {
        anyhow::bail!("usage: {name} SCENE LEVEL.vgate CAMERA [WxH] [PATHS]");
    };
    let size = args.get(3).map_or("160x90", String::as_str);
    let (w, h) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .ok_or_else(|| anyhow::anyhow!("size {size}: WIDTHxHEIGHT"))?;
    let paths = args.get(4).map_or(Ok(1024), |p| p.parse::<u32>())?;
    let scene = visgate_scenes::load(scene, &ImportOptions::default())?;
    let gates = GateLevel::new(BakedLevel::read(std::path::Path::new(level))?, &scene)?;
    let tracer = Tracer::new(&scene);
    let params = PathParams {
        paths,
        bounces: 1,
        seed: 1,
    };
    let vpls = path_vpls(&tracer, &scene.lights, &params)?;
    let cam = scene
        .cameras
        .iter()
        .find(|c| &c.name == camera)
        .ok_or_else(|| anyhow::anyhow!("no camera '{camera}'"))?;
    let view = View::new(cam, [w, h])?;
    Ok(Pairs {
        gates,
        tracer,
        vpls,
        view,
        camera: camera.clone(),
        size: [w, h],
        scene,
    })
}

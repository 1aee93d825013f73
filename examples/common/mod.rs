//! What the gate examples share: a scene and its baked level from the command line.

use visgate_formats::vgate::{BakeParams, Resolution};
use visgate_formats::{BakedLevel, ImportOptions, Scene};
use visgate_preprocess::bake::{BakeOptions, bake};

/// The scene named by the next argument (a file or builtin:NAME; default the built-in four
/// rooms) and the level of the one after it (a .vgate file; `-` or none: baked here at 128).
pub fn scene_and_level(
    args: &mut impl Iterator<Item = String>,
) -> Result<(String, Scene, BakedLevel), Box<dyn std::error::Error>> {
    let scene_arg = args.next().unwrap_or_else(|| "builtin:four-rooms".into());
    let scene = visgate_scenes::load(
        &scene_arg,
        &ImportOptions {
            load_textures: true,
            ..ImportOptions::default()
        },
    )?;
    let level = match args.next() {
        Some(p) if p != "-" => BakedLevel::read(std::path::Path::new(&p))?,
        _ => {
            let params = BakeParams {
                resolution: Resolution::LongestAxisVoxels(128),
                ..BakeParams::default()
            };
            bake(&scene, &params, &BakeOptions::default(), &|_| {})?.level
        }
    };
    Ok((scene_arg, scene, level))
}

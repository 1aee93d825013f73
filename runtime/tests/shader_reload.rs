//! Shader hot reload (`visgate view --shader-dir`): shaders read from a folder replace the
//! built-in ones; an error names its file and line and leaves the last good pipelines drawing.

use visgate_runtime::camera::View;
use visgate_runtime::gpu::shaders;
use visgate_runtime::gpu::{GpuContext, GpuMode, GpuParams, GpuRenderer, ShaderSources};
use visgate_scenes::Builtin;

/// The built-in text of shader `name`.
fn builtin(name: &str) -> String {
    ShaderSources::builtin()
        .text(name)
        .expect("a built-in shader")
}

/// `text` with line `n` (1-based) replaced by `line`.
fn with_line(text: &str, n: usize, line: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[n - 1] = line;
    lines.join("\n")
}

#[test]
fn a_folder_of_shaders_replaces_the_builtin_ones_and_errors_name_file_and_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let e = ShaderSources::read_dir(dir.path()).expect_err("an empty folder");
    assert!(e.to_string().contains("holds none"), "{e}");
    // An include in shaders/, as in the repository's runtime/src/gpu.
    std::fs::create_dir(dir.path().join("shaders")).expect("mkdir");
    let portals = dir.path().join("shaders/portals.wgsl");
    std::fs::write(&portals, builtin("portals.wgsl")).expect("write");
    let s = ShaderSources::read_dir(dir.path()).expect("read");
    assert_eq!(s.overridden().count(), 1);
    assert_eq!(
        s.compose("shade.wgsl").ok(),
        shaders::compose("shade.wgsl").ok()
    );
    s.validate().expect("the built-in text validates");
    // A syntax error on line 20 of the include.
    let broken = with_line(&builtin("portals.wgsl"), 20, "fn broken( {");
    std::fs::write(&portals, broken).expect("write");
    let e = ShaderSources::read_dir(dir.path())
        .expect("read")
        .validate()
        .expect_err("a syntax error");
    assert!(e.to_string().starts_with("portals.wgsl:20:"), "{e}");
    // A type error in a pass shader, flat in the folder.
    std::fs::write(&portals, builtin("portals.wgsl")).expect("write");
    let blur = builtin("blur.wgsl");
    let line = blur
        .lines()
        .position(|l| l.contains("fn compose("))
        .expect("the blur's function")
        + 2;
    let bad = with_line(&blur, line, "    let wrong: u32 = 1.5;");
    std::fs::write(dir.path().join("blur.wgsl"), bad).expect("write");
    let e = ShaderSources::read_dir(dir.path())
        .expect("read")
        .validate()
        .expect_err("a type error");
    assert!(
        e.to_string().starts_with(&format!("blur.wgsl:{line}:")),
        "{e}"
    );
}

#[test]
fn reloaded_shaders_draw_the_next_frame_and_a_broken_one_keeps_the_last_good() {
    let ctx = match GpuContext::new() {
        Ok(c) => c,
        Err(e) => panic!("GPU tests need an adapter (CI installs lavapipe): {e}"),
    };
    let scene = Builtin::CornellBox.scene().expect("scene");
    let view = View::new(scene.cameras.first().expect("camera"), [16, 12]).expect("view");
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let params = GpuParams::with_mode(GpuMode::DirectOnly);
    let frame = |gpu: &mut GpuRenderer| gpu.render(&ctx, &view, &[], &params).expect("render").0;
    let before = frame(&mut gpu);
    let total = |img: &visgate_runtime::hdr::HdrImage| {
        img.pixels.iter().map(|p| p.x + p.y + p.z).sum::<f32>()
    };
    assert!(total(&before) > 0.0);

    let dir = tempfile::tempdir().expect("temp dir");
    let shade = builtin("shade.wgsl");
    let end = "    return vec4<f32>(radiance, 1.0);";
    assert_eq!(shade.matches(end).count(), 1, "the shading pass's return");
    let half = shade.replace(end, "    return vec4<f32>(radiance * 0.5, 1.0);");
    std::fs::write(dir.path().join("shade.wgsl"), &half).expect("write");
    let s = ShaderSources::read_dir(dir.path()).expect("read");
    gpu.reload_shaders(&ctx, &s).expect("reload");
    let halved = frame(&mut gpu);
    for (a, b) in before.pixels.iter().zip(&halved.pixels) {
        assert!(
            (*a * 0.5 - *b).abs().max_element() <= 1e-6 * a.max_element().max(1.0),
            "{a} {b}"
        );
    }

    let broken = with_line(&half, 40, "this is not WGSL");
    std::fs::write(dir.path().join("shade.wgsl"), broken).expect("write");
    let s = ShaderSources::read_dir(dir.path()).expect("read");
    let e = gpu.reload_shaders(&ctx, &s).expect_err("a broken shader");
    assert!(e.to_string().starts_with("shade.wgsl:40:"), "{e}");
    assert_eq!(
        frame(&mut gpu).pixels,
        halved.pixels,
        "the last good pipelines draw on"
    );

    gpu.reload_shaders(&ctx, &ShaderSources::builtin())
        .expect("back");
    assert_eq!(frame(&mut gpu).pixels, before.pixels);
}

//! The frame kept on the GPU for a window (`GpuRenderer::render_kept` + `display`): the
//! display texture holds the bytes `HdrImage::to_srgb8` writes to a PNG, at any exposure,
//! without the HDR readback.

mod common;

use visgate_runtime::camera::View;
use visgate_runtime::gpu::{
    DISPLAY_FORMAT, GpuContext, GpuMode, GpuParams, GpuRenderer, VplInput, read_display,
};
use visgate_scenes::Builtin;

/// Pixels whose channels differ, and the largest difference, between two 8-bit images.
fn differences(a: &image::RgbImage, b: &image::RgbImage) -> (usize, u8) {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut count = 0;
    let mut worst = 0u8;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|k| p[k].abs_diff(q[k])).max().unwrap_or(0);
        count += usize::from(d > 0);
        worst = worst.max(d);
    }
    (count, worst)
}

#[test]
fn the_display_texture_is_the_png_of_the_frame_at_every_exposure_without_a_readback() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let (scene, vpls) = common::vpls_of(Builtin::CornellBox, 64);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("renderer");
    let e = gpu.display(&ctx, 0.0).expect_err("nothing rendered yet");
    assert!(e.to_string().contains("no frame rendered"), "{e}");
    let view = View::new(&scene.cameras[0], [72, 54]).expect("view");
    let params = GpuParams {
        mode: GpuMode::None,
        ..GpuParams::default()
    };
    let (img, _) = gpu
        .render_frame(&ctx, &view, VplInput::Given(&vpls), &params)
        .expect("frame");
    for exposure in [-2.0, 0.0, 1.5, 6.0] {
        let tex = gpu.display(&ctx, exposure).expect("display");
        assert_eq!(tex.format(), DISPLAY_FORMAT);
        assert_eq!((tex.width(), tex.height()), (72, 54));
        let shown = read_display(&ctx, &tex).expect("read");
        let (count, worst) = differences(&shown, &img.to_srgb8(exposure));
        // The GPU's pow may round a channel to the next level; never more.
        assert!(worst <= 1, "exposure {exposure}: off by {worst}");
        assert!(
            count * 100 <= 72 * 54,
            "exposure {exposure}: {count} pixels differ"
        );
    }
    // Kept on the GPU only: no image back, the same texture contents.
    let (none, times) = gpu
        .render_kept(&ctx, &view, VplInput::Given(&vpls), &params, false)
        .expect("frame");
    assert!(none.is_none());
    assert!(!times.passes.is_empty());
    let shown = read_display(&ctx, &gpu.display(&ctx, 0.0).expect("display")).expect("read");
    let (_, worst) = differences(&shown, &img.to_srgb8(0.0));
    assert!(worst <= 1, "kept frame off by {worst}");
    // A new size makes a new texture; a bad exposure is refused.
    let small = View::new(&scene.cameras[0], [20, 10]).expect("view");
    gpu.render_kept(&ctx, &small, VplInput::Given(&vpls), &params, false)
        .expect("frame");
    let tex = gpu.display(&ctx, 0.0).expect("display");
    assert_eq!((tex.width(), tex.height()), (20, 10));
    let e = gpu.display(&ctx, f32::NAN).expect_err("NaN exposure");
    assert!(e.to_string().contains("must be finite"), "{e}");
}

//! An adapter whose storage binding the closed voxels' triangle lists overflow (Crytek Sponza
//! subdivided to 4.2 M triangles on its 4 cm sight grid: 337 MB of lists on lavapipe's 128
//! MiB): the default walk, which reads them, failed the render. It walks on the closed voxels'
//! planes instead, and says so.

use super::*;
use visgate_runtime::gpu::{GatesParams, GpuContext, GpuMode, GpuParams, GpuRenderer};

/// A device on the first adapter whose storage bindings hold at most `limit` bytes.
fn small_binding(limit: u64) -> GpuContext {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let mut desc = GpuContext::device_descriptor(&adapter);
    desc.required_limits.max_storage_buffer_binding_size = limit;
    let (device, queue) = pollster::block_on(adapter.request_device(&desc)).expect("device");
    GpuContext::from_device(adapter.get_info(), device, queue)
}

#[test]
fn triangle_lists_over_the_binding_give_way_to_the_planes() {
    let (scene, gates, _, vpls, view) = fixture(Builtin::FourRooms, 128);
    gates.list_triangles();
    gates.fit_planes();
    // The largest of the walk's tables, each a binding of its own.
    let tables = |lists, planes| {
        let t = gates.tables(lists, planes);
        4 * [
            t.sight_words.base.len(),
            t.voxel_words.len(),
            t.sight_words.extra.len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0) as u64
    };
    // A binding that holds every table but the lists.
    let (with_lists, without) = (tables(true, false), tables(false, true));
    assert!(with_lists > without, "{with_lists} {without}");
    let limit = without.next_multiple_of(256).max(1 << 20);
    assert!(
        limit < with_lists,
        "the four rooms' lists: {with_lists} bytes"
    );
    let ctx = small_binding(limit);
    let mut gpu = GpuRenderer::new(&ctx, &scene).expect("upload");
    let balanced = GpuMode::Gates(GatesParams::default().balanced());
    let mut mode = balanced;
    let note = gpu
        .level_for_mode_or_planes(&ctx, &gates, &mut mode)
        .expect("the planes fit")
        .expect("a note");
    assert!(
        note.contains("the closed voxels' triangle lists") && note.contains("planes instead"),
        "{note}"
    );
    let GpuMode::Gates(p) = mode else {
        panic!("{mode:?}")
    };
    assert!(!p.gates.triangles && p.gates.planes, "{p:?}");
    assert!(p.interleave.tent, "the rest of the balanced setting kept");
    let image = gpu.render(&ctx, &view, &vpls, &GpuParams::with_mode(mode));
    assert!(image.is_ok_and(|(img, _)| img.mean().length() > 0.0));
    // The walk it asked for alone is refused, as before.
    let mut other = GpuRenderer::new(&ctx, &scene).expect("upload");
    assert!(other.level_for_mode(&ctx, &gates, &balanced).is_err());
}

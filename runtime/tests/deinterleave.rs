//! The deinterleaved layout of the interleaved indirect target (`vpl.wgsl`'s
//! `deinterleave_axis` and `interleave_axis`), run on the GPU: for every block size and axis
//! length tried, a bijection of [0, n) whose inverse is `interleave_axis`, with each residue's
//! pixels side by side in order, which the blur's stepped form (`axis_run_next`, `axis_run_place`)
//! finds too. The gates' indirect pass shades in this layout and the blur
//! reads through it: a pixel mapped twice or never would be lit twice or left black.

use visgate_runtime::gpu::context::{bind_group, compute_pipelines, init_buffer, read_buffer};
use visgate_runtime::gpu::shaders::compose_with;
use visgate_runtime::gpu::{GpuContext, ShaderSources};

const ENTRY: &str = "//! include: vpl.wgsl
struct Case { b: u32, n: u32 };
@group(0) @binding(0) var<storage, read> case_: Case;
@group(0) @binding(1) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = id.x;
    if x >= case_.n {
        return;
    }
    let s = deinterleave_axis(x, case_.b, case_.n);
    out[3u * x] = s;
    out[3u * x + 1u] = interleave_axis(s, case_.b, case_.n);
    // The blur's stepped form, from up to 2b + 1 pixels before x.
    let x0 = x - min(x, 2u * case_.b + 1u);
    var rk = vec2<u32>(x0 % case_.b, x0 / case_.b);
    for (var k = x0; k < x; k++) {
        rk = axis_run_next(rk, case_.b);
    }
    out[3u * x + 2u] = axis_run_place(rk, case_.n / case_.b, case_.n % case_.b);
}
";

/// For each (b, n): where `deinterleave_axis` sends every x, `interleave_axis` of that, and
/// where the blur's stepped form (`axis_run_next`, `axis_run_place`) puts x.
fn run(ctx: &GpuContext, cases: &[(u32, u32)]) -> Vec<Vec<[u32; 3]>> {
    let sources = ShaderSources::builtin();
    let src = compose_with("deinterleave test", ENTRY, &|n| sources.text(n)).expect("compose");
    let d = &ctx.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("deinterleave test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let [pipeline] = compute_pipelines(d, &module, ["main"]);
    cases
        .iter()
        .map(|&(b, n)| {
            let case = init_buffer(
                d,
                "case",
                bytemuck::cast_slice(&[b, n]),
                wgpu::BufferUsages::STORAGE,
            );
            let out = init_buffer(
                d,
                "out",
                &vec![0xffu8; 12 * n as usize],
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            );
            let group = bind_group(
                d,
                &pipeline.get_bind_group_layout(0),
                "deinterleave test",
                vec![(0, case.as_entire_binding()), (1, out.as_entire_binding())],
            );
            let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(n.div_ceil(64), 1, 1);
            }
            ctx.queue.submit([enc.finish()]);
            let bytes = read_buffer(ctx, &out).expect("read back");
            let words: &[u32] = bytemuck::cast_slice(&bytes);
            (0..n as usize)
                .map(|x| [words[3 * x], words[3 * x + 1], words[3 * x + 2]])
                .collect()
        })
        .collect()
}

#[test]
fn the_deinterleaved_layout_is_a_bijection_inverted_by_interleave_axis_on_the_gpu() {
    let ctx = GpuContext::new().expect("a GPU adapter (lavapipe in CI)");
    let mut cases = Vec::new();
    for b in [1, 2, 3, 4, 8, 16] {
        for n in (1..=40).chain([64, 100, 127, 180, 720, 1080, 1280, 1920]) {
            cases.push((b, n));
        }
    }
    for ((b, n), got) in cases.iter().zip(run(&ctx, &cases)) {
        let mut hit = vec![false; *n as usize];
        for (x, [s, back, stepped]) in got.iter().enumerate() {
            assert!(*s < *n, "b {b} n {n}: {x} -> {s}, outside");
            assert_eq!(
                stepped, s,
                "b {b} n {n}: the blur's stepping puts {x} elsewhere"
            );
            assert!(!hit[*s as usize], "b {b} n {n}: {s} taken twice");
            hit[*s as usize] = true;
            assert_eq!(
                *back as usize, x,
                "b {b} n {n}: interleave_axis({s}) is not {x}"
            );
            // Residue by residue, each in order: x + b lies just after x.
            if x + (*b as usize) < *n as usize {
                assert_eq!(got[x + *b as usize][0], s + 1, "b {b} n {n}: {x}");
            }
        }
    }
}

//! include: globals.wgsl vpl.wgsl face.wgsl far.wgsl ratio.wgsl
// The ratio estimator's other half (GatesParams::ratio; Heitz et al. 2018): the unshadowed far
// light, every VPL's but the near field's share (far.wgsl), no visibility, at the pixels of
// its grid and those that sum their own (ratio.wgsl), each written at its pixel; blur.wgsl's
// compose takes it at every pixel and scales it by the visible share of its taps' subsets.
//
// Three entry points, the VPLs in runs of RATIO_RUN (injected from runtime::gpu::passes::
// unshadowed; run.x the run; llvmpipe's loop limit), each run
// adding to the runs before (earlier_runs): cs_far_grid sums the grid pixels' light (an
// invocation a grid texel), run after run; cs_own_list, once, lists the pixels between that sum
// their own (ratio_own: off their grid pixels' surface, or where those's light spreads); then
// cs_far_own sums the listed pixels', run after run (dispatched indirect, an invocation a
// listed pixel: on a software rasterizer's SIMD rows, a row of a tile with one such pixel
// costs what a row of eight does).

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var g_normal: texture_2d<f32>;
@group(0) @binding(9) var g_albedo: texture_2d<f32>;
@group(0) @binding(4) var earlier_runs: texture_2d<f32>;
@group(0) @binding(5) var out_image: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var<uniform> run: vec4<u32>;
// Word 0 the pixels listed, then each one's index (x + y × width).
@group(0) @binding(7) var<storage, read_write> own_list: array<atomic<u32>>;
// cs_far_own's indirect dispatch: its workgroups (x, y, z), rows of OWN_ROW.
@group(0) @binding(8) var<storage, read_write> own_args: array<atomic<u32>, 4>;
// cs_own_list: the grid pixels' light, all runs summed (each at its pixel).
@group(0) @binding(10) var grid_light: texture_2d<f32>;

const OWN_GROUP: u32 = 64u;
const OWN_ROW: u32 = 65535u;

@compute @workgroup_size(8, 8)
fn cs_own_list(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(g_position);
    if any(id.xy >= size) {
        return;
    }
    let px = vec2<i32>(id.xy);
    let pos = textureLoad(g_position, px, 0);
    if pos.w == 0.0 {
        return;
    }
    let n = normalize(textureLoad(g_normal, px, 0).xyz);
    let s = i32(max(globals.ratio_stride, 1u));
    if ratio_own(grid_light, px, pos.xyz, n, s, vec2<i32>(size), RATIO_SLACK) {
        let slot = atomicAdd(&own_list[0], 1u);
        atomicStore(&own_list[1u + slot], id.x + id.y * size.x);
        let g = slot / OWN_GROUP;
        atomicMax(&own_args[0], min(g + 1u, OWN_ROW));
        atomicMax(&own_args[1], g / OWN_ROW + 1u);
    }
}

@compute @workgroup_size(8, 8)
fn cs_far_grid(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(g_position);
    let s = max(globals.ratio_stride, 1u);
    if any(id.xy >= ratio_grid_size(size, s)) {
        return;
    }
    far_run(ratio_grid_pixel(vec2<i32>(id.xy), i32(s), vec2<i32>(size)));
}

@compute @workgroup_size(OWN_GROUP)
fn cs_far_own(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let k = (wg.x + wg.y * OWN_ROW) * OWN_GROUP + li;
    if k >= atomicLoad(&own_list[0]) {
        return;
    }
    let i = atomicLoad(&own_list[1u + k]);
    let w = textureDimensions(g_position).x;
    far_run(vec2<i32>(i32(i % w), i32(i / w)));
}

// This run's VPLs' unshadowed far light at pixel px added to the runs' before, written there.
fn far_run(px: vec2<i32>) {
    var sum = vec3<f32>(0.0);
    if run.x > 0u {
        sum = textureLoad(earlier_runs, px, 0).xyz;
    }
    let pos = textureLoad(g_position, px, 0);
    if pos.w != 0.0 {
        let n = normalize(textureLoad(g_normal, px, 0).xyz);
        let end = min(globals.vpl_count, (run.x + 1u) * RATIO_RUN);
        sum += far_unshadowed(pos.xyz, n, run.x * RATIO_RUN, end);
    }
    textureStore(out_image, px, vec4<f32>(sum, 1.0));
}

//! Interleaved gates' second gather (starved.wgsl's pairs, dispatch and sums around shade.wgsl's
//! `cs_starved_walks`): the pixels whose blur block holds too few taps that agree with them
//! ([`InterleaveParams::starved_taps`]), or whose agreeing taps found no light
//! ([`InterleaveParams::starved_dark`]), walk the VPL subsets of the taps that do not, a
//! (pixel, subset) pair an invocation, so that a starved pixel's walks spread over as many
//! lanes as it has subsets instead of holding up its warp.

use super::interleave_blur::InterleaveParams;
use super::shade::{Inputs, Shade, frame_target};
use crate::RenderError;
use crate::cpu::gates::GateShape;
use crate::gpu::context::{Pool, bind_group, slice};
use crate::gpu::layout::{UNIFORM_STRIDE, strided};
use crate::gpu::shaders::{self, ShaderSources};
use crate::gpu::timing::Recorder;
use crate::gpu::{Frame, GpuContext};

/// The pairs' list's first capacity: four a pixel (the pillared hall's side room at T = 48
/// needed 1.7, e2m3's hall 6.8, Crytek Sponza's gallery at T = 64 6.4; a frame that needs more
/// is rendered again with room, once). [Units: pairs per pixel]
pub const FIRST_PAIRS_PER_PIXEL: u64 = 4;
/// A pair's bytes: in the list in pixel order (its place in the other and its pixel × 256 +
/// subset) and in the one in subset order, which the walks read (its light and its pixel × 256
/// + subset), 16 each.
pub const PAIR_BYTES: u64 = 32;
/// The most pixels a frame with starved pixels may have: a pair holds its pixel × 256 + its
/// subset in 32 bits (4,096 × 4,096).
pub const MAX_STARVED_PIXELS: u64 = 1 << 24;

/// The bindings of starved.wgsl's `cs_starved_pairs`: globals, the G-buffer's positions and
/// normals, the starved test's constants (26), the count, pairs and runs (27–29), the first
/// gather's indirect target (32), the subsets' counts (33).
const PAIRS_BINDINGS: [u32; 3] = [0, 5, 6];
/// The bindings of `cs_starved_walks` from the shading's resources (the walks' without the
/// disks' lists); the batch index (24), count (27) and pairs (28) besides.
const WALKS_BINDINGS: [u32; 11] = [0, 2, 5, 6, 7, 8, 15, 16, 22, 23, 31];

/// What the starved pixels' passes leave: the image the blur reads (xyz the walked subsets'
/// light, w 1 where starved) and the counters (pairs needed, pixels that did not fit, starved
/// pixels) for the readback.
pub struct StarvedOutput {
    /// In pixel order.
    pub sums: wgpu::Texture,
    /// Four words: pairs reserved, pixels whose pairs did not fit, starved pixels, pairs walked.
    pub count: wgpu::Buffer,
    /// The pairs' list's capacity.
    pub capacity: u32,
}

/// The pairs' list's first capacity for an image of `size`, within the adapter's storage
/// binding limit.
pub fn first_capacity(ctx: &GpuContext, [w, h]: [u32; 2]) -> u32 {
    let pairs = u64::from(w) * u64::from(h) * FIRST_PAIRS_PER_PIXEL;
    pairs.min(max_capacity(ctx)) as u32
}

/// The most pairs the list may hold on the adapter.
pub fn max_capacity(ctx: &GpuContext) -> u64 {
    let binding = ctx.device.limits().max_storage_buffer_binding_size;
    (binding / PAIR_BYTES).min(u64::from(u32::MAX))
}

/// Refuses an image of more than [`MAX_STARVED_PIXELS`] pixels (checked before a frame
/// allocates anything).
pub fn check_size([w, h]: [u32; 2]) -> Result<(), RenderError> {
    let pixels = u64::from(w) * u64::from(h);
    if pixels > MAX_STARVED_PIXELS {
        return Err(RenderError::Param(format!(
            "the starved pixels' walks (--starved-taps, --starved-dark: in the balanced setting, \
             the default) take images of at most {MAX_STARVED_PIXELS} pixels; this one has \
             {pixels} ({w} x {h}): render it smaller, or without them (--fast)"
        )));
    }
    Ok(())
}

/// The starved pixels' buffers for one frame.
struct Buffers {
    /// The starved test's constants (26).
    test: wgpu::Buffer,
    /// Pairs reserved, pixels that did not fit, starved pixels, pairs walked (27).
    count: wgpu::Buffer,
    /// The pairs (28).
    pairs: wgpu::Buffer,
    /// Each pixel's run of pairs (29).
    runs: wgpu::Buffer,
    /// The walks' dispatch (30).
    args: wgpu::Buffer,
    /// Each subset's pairs, then its first place in the pairs in subset order (33).
    subsets: wgpu::Buffer,
    /// Each batch's index (24), strided.
    batches: wgpu::Buffer,
}

impl Buffers {
    /// The buffers of frame `f`, its walks in `batches` batches.
    fn new(f: &Frame, pool: &mut Pool, il: &InterleaveParams, batches: u32) -> Buffers {
        let d = &f.ctx.device;
        let [w, h] = f.view.size;
        let constants = [
            il.blur_distance_m(f),
            il.blur_normal,
            il.starved_taps as f32,
            f32::from(u8::from(il.starved_dark)),
        ];
        let uniform = wgpu::BufferUsages::UNIFORM;
        let storage = wgpu::BufferUsages::STORAGE;
        let indices: Vec<[u32; 4]> = (0..batches).map(|i| [i, 0, 0, 0]).collect();
        let copies = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        Buffers {
            test: pool.upload(
                f.ctx,
                "starved pixels' test",
                bytemuck::cast_slice(&constants),
                uniform,
            ),
            count: pool.buffer(d, "starved pixels' count", 16, storage | copies),
            pairs: pool.buffer(
                d,
                "starved pixels' pairs",
                u64::from(f.starved_pairs) * PAIR_BYTES,
                storage,
            ),
            runs: pool.buffer(
                d,
                "starved pixels' runs",
                u64::from(w) * u64::from(h) * 8,
                storage,
            ),
            args: pool.buffer(
                d,
                "starved walks' dispatch",
                12,
                storage | wgpu::BufferUsages::INDIRECT,
            ),
            subsets: pool.buffer(d, "starved pixels' subsets", 256 * 4, storage | copies),
            batches: pool.upload(f.ctx, "starved walk batches", &strided(&indices), uniform),
        }
    }
}

/// The bind groups of the five passes, the walks' one a batch.
struct Groups {
    pairs: wgpu::BindGroup,
    args: wgpu::BindGroup,
    order: wgpu::BindGroup,
    walks: Vec<wgpu::BindGroup>,
    sums: wgpu::BindGroup,
}

fn whole(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
    b.as_entire_binding()
}

impl Shade {
    /// Records interleaved gates' second gather ([`InterleaveParams::starved_taps`]): at the
    /// pixels whose blur block holds fewer than that many taps that agree with them, the VPL
    /// subsets of the taps that do not, walked, a pair an invocation; in pixel order (w 1
    /// there), for the blur to add to the agreeing taps' subsets. The pairs' list holds
    /// `f.starved_pairs`; a frame that needs more says so in its counters.
    pub fn record_starved(
        &self,
        f: &Frame,
        pool: &mut Pool,
        rec: &mut Recorder,
        inputs: Inputs,
        (shape, il, indirect): (GateShape, &InterleaveParams, &wgpu::Texture),
    ) -> StarvedOutput {
        // The renderer refused an image too large for the pairs ([`check_size`]) before the
        // frame made anything.
        let [w, h] = f.view.size;
        // The walks' batches: a pair walks one subset, up to ⌈VPLs / B⌉ VPLs.
        let batches = super::shade::batch_count(f, f.vpl_count.div_ceil(il.subsets()));
        let b = Buffers::new(f, pool, il, batches);
        let sums = frame_target(f, pool, "starved pixels' irradiance");
        let walks = self.gates_pipeline(f, super::shade::GatesGather::Starved, shape);
        let g = self.starved_groups(f, inputs, (&b, batches), walks, (&sums, indirect));
        let p = &self.starved;
        rec.enc.clear_buffer(&b.count, 0, None);
        rec.enc.clear_buffer(&b.subsets, 0, None);
        let span = "indirect lighting: starved pixels";
        let timed = rec.begin(span);
        {
            let mut pass = rec.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(span),
                timestamp_writes: timed.compute(),
            });
            let tiles = [w.div_ceil(8), h.div_ceil(8)];
            pass.set_pipeline(&p.pairs);
            pass.set_bind_group(0, &g.pairs, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
            pass.set_pipeline(&p.args);
            pass.set_bind_group(0, &g.args, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&p.order);
            pass.set_bind_group(0, &g.order, &[]);
            pass.dispatch_workgroups_indirect(&b.args, 0);
            pass.set_pipeline(walks);
            for group in &g.walks {
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups_indirect(&b.args, 0);
            }
            pass.set_pipeline(&p.sums);
            pass.set_bind_group(0, &g.sums, &[]);
            pass.dispatch_workgroups(tiles[0], tiles[1], 1);
        }
        rec.end();
        StarvedOutput {
            sums,
            count: b.count,
            capacity: f.starved_pairs,
        }
    }

    /// The starved passes' bind groups: the shading's resources each reads, and `b`'s.
    fn starved_groups(
        &self,
        f: &Frame,
        inputs: Inputs,
        (b, batches): (&Buffers, u32),
        walks: &wgpu::ComputePipeline,
        (sums, indirect): (&wgpu::Texture, &wgpu::Texture),
    ) -> Groups {
        let d = &f.ctx.device;
        let p = &self.starved;
        let views = super::shade::Views::new(f, inputs);
        let sums_view = sums.create_view(&Default::default());
        let indirect_view = indirect.create_view(&Default::default());
        let group = |pipeline: &wgpu::ComputePipeline, used: &[u32], extra: Vec<_>| {
            let mut resources = views.resources(f, inputs, None, Some(used));
            resources.extend(extra);
            bind_group(d, &pipeline.get_bind_group_layout(0), "starved", resources)
        };
        Groups {
            pairs: group(
                &p.pairs,
                &PAIRS_BINDINGS,
                vec![
                    (26, whole(&b.test)),
                    (27, whole(&b.count)),
                    (28, whole(&b.pairs)),
                    (29, whole(&b.runs)),
                    (32, wgpu::BindingResource::TextureView(&indirect_view)),
                    (33, whole(&b.subsets)),
                ],
            ),
            args: group(
                &p.args,
                &[],
                vec![
                    (27, whole(&b.count)),
                    (30, whole(&b.args)),
                    (33, whole(&b.subsets)),
                ],
            ),
            order: group(
                &p.order,
                &[],
                vec![
                    (27, whole(&b.count)),
                    (28, whole(&b.pairs)),
                    (33, whole(&b.subsets)),
                ],
            ),
            walks: (0..batches as usize)
                .map(|i| {
                    let index = slice(&b.batches, (i * UNIFORM_STRIDE) as u64, 16);
                    group(
                        walks,
                        &WALKS_BINDINGS,
                        vec![(24, index), (27, whole(&b.count)), (28, whole(&b.pairs))],
                    )
                })
                .collect(),
            sums: group(
                &p.sums,
                &[5],
                vec![
                    (25, wgpu::BindingResource::TextureView(&sums_view)),
                    (28, whole(&b.pairs)),
                    (29, whole(&b.runs)),
                ],
            ),
        }
    }
}

/// The pipelines of the starved pixels' passes but the walks' (shade.wgsl's, made per gate
/// shape as the gathers', [`Shade`]).
pub struct StarvedPipelines {
    pairs: wgpu::ComputePipeline,
    args: wgpu::ComputePipeline,
    order: wgpu::ComputePipeline,
    sums: wgpu::ComputePipeline,
}

impl StarvedPipelines {
    /// Built from starved.wgsl.
    pub fn new(d: &wgpu::Device, s: &ShaderSources) -> Result<StarvedPipelines, RenderError> {
        let module = shaders::module(d, s, "starved.wgsl")?;
        let [pairs, args, order, sums] = crate::gpu::context::compute_pipelines(
            d,
            &module,
            [
                "cs_starved_pairs",
                "cs_starved_args",
                "cs_starved_order",
                "cs_starved_sums",
            ],
        );
        Ok(StarvedPipelines {
            pairs,
            args,
            order,
            sums,
        })
    }
}

/// How a frame's starved pixels came out (`PassTimes::starved`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StarvedStats {
    /// Pixels that walked what their block lacks.
    pub pixels: u32,
    /// (pixel, subset) pairs they walked.
    pub pairs: u64,
    /// The pairs' list's capacity.
    pub capacity: u32,
}

/// A frame's stats from the count's words and the list's `capacity`; an error with the pairs
/// needed when some pixels' did not fit (the renderer then renders the frame again with room).
pub fn stats(c: &[u32], capacity: u32) -> Result<StarvedStats, RenderError> {
    if c[1] > 0 {
        return Err(RenderError::StarvedPairsFull {
            needed: u64::from(c[0]),
            capacity,
        });
    }
    Ok(StarvedStats {
        pixels: c[2],
        pairs: u64::from(c[0]),
        capacity,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_too_short_says_how_many_pairs_the_frame_needs() {
        let fits = stats(&[1_200, 0, 40, 0], 2_000).expect("fits");
        assert_eq!((fits.pixels, fits.pairs, fits.capacity), (40, 1_200, 2_000));
        match stats(&[2_600, 3, 40, 0], 2_000) {
            Err(
                e @ RenderError::StarvedPairsFull {
                    needed: 2_600,
                    capacity: 2_000,
                },
            ) => {
                let said = e.to_string();
                assert!(
                    said.contains("2600") && said.contains("--starved-taps"),
                    "{said}"
                );
            }
            other => panic!("{other:?}"),
        }
    }
}

//! A frame's command recording and its timing, as labelled spans.
//!
//! A [`Recorder`] holds the frame's one command encoder. Each pass opens a [`Span`] with the
//! pass's name; where the adapter has timestamp queries, the span's first and last GPU pass
//! write a timestamp and the whole frame is **one submission**, with one wait at its readback.
//! Where it has none, each span is submitted and waited for on its own, so that its CPU wall
//! time means something. Either way [`PassTimes::passes`] lists the spans that ran, in order,
//! so printing the passes is a loop.

use std::time::Instant;

use super::GpuContext;
use super::context::Pool;

/// Timestamp pairs a frame can hold (more spans than this run untimed).
const MAX_SPANS: u32 = 2048;

/// The time of one pass (span) of a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTime {
    /// The pass's name (the papers' names where they have one).
    pub name: &'static str,
    /// GPU time from timestamp queries, summed over the span's passes. [Units: s]
    pub gpu_s: Option<f64>,
    /// CPU wall time of the span, submitted and waited for alone (only where the adapter has no
    /// timestamp queries). [Units: s]
    pub cpu_s: Option<f64>,
}

/// How full the light lists of mode gates came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LightListStats {
    /// Geometry clusters in view.
    pub geometry_clusters: u32,
    /// Entries over all lists (needed, even when they did not fit).
    pub entries: u64,
    /// The pool's capacity.
    pub capacity: u32,
    /// Pixels with a surface outside every visibility cluster (inside geometry, or outside the
    /// baked grid): every VPL lights them unoccluded.
    pub pixels_outside: u32,
    /// VPLs outside every visibility cluster: they light every pixel unoccluded.
    pub vpls_outside: u32,
}

/// What a frame took.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PassTimes {
    /// The passes that ran, in order (a name may repeat: batches).
    pub passes: Vec<PassTime>,
    /// CPU wall time of the whole frame, recording to readback. [Units: s]
    pub frame_s: f64,
    /// CPU wall time of the final submission's wait and the readback. [Units: s]
    pub readback_s: f64,
    /// Mode gates: how full the light lists came out.
    pub lists: Option<LightListStats>,
    /// The VAL modes: how the clustering converged.
    pub vals: Option<ValIterations>,
    /// `--direct lightcluster`: the lights' clusters.
    pub direct_clusters: Option<LcCounts>,
    /// Mode vpl-clusters: the VPLs' clusters.
    pub vpl_clusters: Option<LcCounts>,
    /// Interleaved gates with `--starved-taps`: the starved pixels' walks.
    pub starved: Option<crate::gpu::passes::starved::StarvedStats>,
    /// Interleaved walks with the ratio estimator: where its unshadowed light was summed.
    pub ratio: Option<crate::gpu::passes::unshadowed::RatioStats>,
}

/// How LightCluster clustered a frame's lights (or VPLs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LcCounts {
    /// Clusters (cube shadow maps) made.
    pub clusters: u32,
    /// Lights culled by range and frustum (not shaded); VPLs of no flux.
    pub culled: u32,
    /// Lights in the scene (VPLs in the frame).
    pub lights: u32,
}

/// How the VAL clustering's iterations went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ValIterations {
    /// Centre updates run.
    pub iterations: u32,
    /// The most allowed (`ValParams::iterations`).
    pub max: u32,
    /// Whether the assignment stopped changing within them.
    pub converged: bool,
    /// VALs that hold VPLs (of `ValParams::count`).
    pub live: u32,
    /// VALs in all.
    pub count: u32,
}

impl PassTimes {
    /// Summed GPU time of the passes named `name` (None without timestamps or if it did not
    /// run). [Units: s]
    pub fn gpu(&self, name: &str) -> Option<f64> {
        let mut it = self.passes.iter().filter(|p| p.name == name).peekable();
        it.peek()?;
        it.map(|p| p.gpu_s).sum()
    }

    /// Summed GPU time of every pass (None without timestamps). [Units: s]
    pub fn gpu_total(&self) -> Option<f64> {
        self.passes.iter().map(|p| p.gpu_s).sum()
    }

    /// The passes merged by name, in order of first appearance: (name, GPU s, CPU s).
    pub fn by_name(&self) -> Vec<(&'static str, Option<f64>, Option<f64>)> {
        let mut out: Vec<(&'static str, Option<f64>, Option<f64>)> = Vec::new();
        for p in &self.passes {
            match out.iter_mut().find(|(n, _, _)| *n == p.name) {
                Some(e) => {
                    e.1 = e.1.zip(p.gpu_s).map(|(a, b)| a + b);
                    e.2 = e.2.zip(p.cpu_s).map(|(a, b)| a + b);
                }
                None => out.push((p.name, p.gpu_s, p.cpu_s)),
            }
        }
        out
    }
}

/// A span's timestamp slots (inactive where the adapter has none or the frame is full).
#[derive(Clone)]
pub struct Span {
    set: Option<wgpu::QuerySet>,
    index: u32,
}

impl Span {
    /// The writes of a render pass that is the `first` and/or `last` of the span.
    pub fn render(&self, first: bool, last: bool) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let set = self.set.as_ref()?;
        (first || last).then_some(wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: first.then_some(self.index),
            end_of_pass_write_index: last.then_some(self.index + 1),
        })
    }

    /// The writes of a compute pass that is the whole span.
    pub fn compute(&self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        Some(wgpu::ComputePassTimestampWrites {
            query_set: self.set.as_ref()?,
            beginning_of_pass_write_index: Some(self.index),
            end_of_pass_write_index: Some(self.index + 1),
        })
    }
}

/// A frame being recorded: its encoder and its spans.
pub struct Recorder<'c> {
    ctx: &'c GpuContext,
    /// The frame's encoder: passes record into it.
    pub enc: wgpu::CommandEncoder,
    set: Option<wgpu::QuerySet>,
    spans: Vec<(&'static str, Option<u32>, Option<f64>)>,
    open: Option<Instant>,
}

impl<'c> Recorder<'c> {
    /// A new frame; the query set comes from `pool` where the adapter has timestamps.
    pub fn new(ctx: &'c GpuContext, pool: &mut Pool) -> Recorder<'c> {
        let set = ctx
            .timestamp_period
            .map(|_| pool.query_set(ctx, MAX_SPANS * 2));
        Recorder {
            ctx,
            enc: encoder(ctx),
            set,
            spans: Vec::new(),
            open: None,
        }
    }

    /// Opens the span of pass `name`; its GPU passes take their timestamp writes from the
    /// result. Close it with [`Recorder::end`].
    pub fn begin(&mut self, name: &'static str) -> Span {
        let index = match &self.set {
            Some(_) if (self.spans.len() as u32) < MAX_SPANS => Some(self.spans.len() as u32 * 2),
            _ => None,
        };
        self.spans.push((name, index, None));
        if self.set.is_none() {
            self.open = Some(Instant::now());
        }
        Span {
            set: index.and(self.set.clone()),
            index: index.unwrap_or(0),
        }
    }

    /// Closes the open span: without timestamps, submits what it recorded and waits, for its
    /// CPU wall time.
    pub fn end(&mut self) {
        if let Some(t0) = self.open.take() {
            self.submit();
            self.ctx.wait();
            if let Some(last) = self.spans.last_mut() {
                last.2 = Some(t0.elapsed().as_secs_f64());
            }
        }
    }

    /// Submits what is recorded so far and starts a new encoder (the recorder's one submission
    /// point besides [`Recorder::finish`]).
    pub fn submit(&mut self) {
        let enc = std::mem::replace(&mut self.enc, encoder(self.ctx));
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Resolves the timestamps, submits, waits once, and returns the pass times (without
    /// `frame_s`). Record readback copies into `enc` before; map them after.
    pub fn finish(mut self, pool: &mut Pool) -> Result<PassTimes, crate::RenderError> {
        let t0 = Instant::now();
        let used = self.spans.iter().filter(|s| s.1.is_some()).count() as u64 * 2;
        let read = match (&self.set, used) {
            (Some(set), 1..) => {
                let d = &self.ctx.device;
                let resolve = pool.buffer(
                    d,
                    "timestamps",
                    MAX_SPANS as u64 * 16,
                    wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                );
                let read = pool.buffer(
                    d,
                    "timestamps readback",
                    MAX_SPANS as u64 * 16,
                    wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                );
                self.enc.resolve_query_set(set, 0..used as u32, &resolve, 0);
                self.enc
                    .copy_buffer_to_buffer(&resolve, 0, &read, 0, used * 8);
                Some(read)
            }
            _ => None,
        };
        self.submit();
        self.ctx.wait();
        let ticks: Vec<u64> = match &read {
            Some(r) => bytemuck::cast_slice(&super::context::map_read(self.ctx, r)?).to_vec(),
            None => Vec::new(),
        };
        let period = self.ctx.timestamp_period.unwrap_or(0.0) as f64 * 1e-9;
        let passes = self
            .spans
            .iter()
            .map(|&(name, index, cpu_s)| PassTime {
                name,
                gpu_s: index.and_then(|b| {
                    let (a, z) = (*ticks.get(b as usize)?, *ticks.get(b as usize + 1)?);
                    Some(z.saturating_sub(a) as f64 * period)
                }),
                cpu_s,
            })
            .collect();
        Ok(PassTimes {
            passes,
            frame_s: 0.0,
            readback_s: t0.elapsed().as_secs_f64(),
            lists: None,
            vals: None,
            direct_clusters: None,
            vpl_clusters: None,
            starved: None,
            ratio: None,
        })
    }
}

fn encoder(ctx: &GpuContext) -> wgpu::CommandEncoder {
    ctx.device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        })
}

impl Pool {
    /// The frame's timestamp query set of `count` queries (kept).
    pub fn query_set(&mut self, ctx: &GpuContext, count: u32) -> wgpu::QuerySet {
        if let Some(q) = &self.queries
            && q.count() == count
        {
            return q.clone();
        }
        self.note_created();
        let q = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        self.queries = Some(q.clone());
        q
    }
}

//! # visgate-runtime
//!
//! The real-time half: wgpu passes and their WGSL (G-buffer, direct light with shadow maps,
//! VPL generation from reflective shadow maps or traced light paths, the visibility modes for
//! indirect light — none, per-VPL shadow maps, visibility gates with clustered shading, virtual
//! area lights with convolution soft shadow maps — the indirect gather and tone mapping), the
//! CPU reference renderer with exact visibility, and image metrics.
//!
//! It reads baked levels through `visgate-formats` and never imports `visgate-preprocess`.
//!
//! Where things live:
//!
//! - [`gpu`]: the renderer ([`gpu::GpuRenderer`], made once per scene, keeping its resources),
//!   its passes (`gpu/passes/`, each beside its WGSL), the methods and their typed parameters
//!   with the registry the CLI, viewer and `compare` read ([`gpu::methods`]), every struct
//!   shared with WGSL ([`gpu::layout`]), the WGSL include step ([`gpu::shaders`]), timing.
//! - [`cpu`]: the tracer, the exact reference, and the CPU twin of each method.
//! - [`job`]: what `visgate render` does — CPU or GPU, VPLs, animation frames — as one library
//!   call the CLI, the viewer and `compare` share.
//! - [`vpl`] (VPLs, light paths, the gather term), [`vpl_order`] (their order for interleaved
//!   sampling), [`lights`], [`camera`], [`hdr`],
//!   [`metrics`].
//!
//! A frame: VPLs (uploaded, or made from the lights' RSMs on the GPU) → shadow maps → G-buffer
//! → the method's passes → shading → readback, one command encoder and (with timestamp
//! queries) one submission; see [`gpu`]. To add a method: a pass module beside its WGSL, a
//! [`gpu::GpuMode`] variant with its params, its line in [`gpu::METHODS`], its branch in the
//! frame.

pub mod camera;
pub mod compare;
pub mod cpu;
pub mod gpu;
pub mod hdr;
pub mod job;
pub mod lights;
pub mod metrics;
pub mod vpl;
pub mod vpl_order;

use std::path::Path;

/// What can go wrong in the runtime.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A parameter outside its limits, or inputs that do not fit together.
    #[error("{0}")]
    Param(String),
    /// No GPU adapter, or it could not be opened.
    #[error("no usable GPU adapter: {0}")]
    NoAdapter(String),
    /// The GPU failed at something it should do.
    #[error("GPU: {0}")]
    Gpu(String),
    /// The light lists of mode gates need more entries than a pool of fixed capacity holds
    /// (the light is never cut: the frame fails).
    #[error(
        "the light lists of {clusters} geometry clusters need {needed} entries, more than the \
         pool's {capacity} ({lists} lists did not fit): raise --light-entries \
         (GatesParams::light_entries) to at least {needed}, leave it unset to let the pool \
         grow, or use fewer VPLs"
    )]
    LightListsFull {
        /// Entries the frame needs.
        needed: u64,
        /// The pool's capacity.
        capacity: u32,
        /// Lists that did not fit.
        lists: u32,
        /// Geometry clusters in view.
        clusters: u32,
    },
    /// The starved pixels' walks need more (pixel, subset) pairs than their list holds (the
    /// renderer grows it and renders the frame again; the light is never cut).
    #[error(
        "the starved pixels' walks need {needed} (pixel, subset) pairs, more than the list's \
         {capacity}: lower --starved-taps, use a smaller image or a smaller --interleave block"
    )]
    StarvedPairsFull {
        /// Pairs the frame needs.
        needed: u64,
        /// The list's capacity.
        capacity: u32,
    },
    /// Reading or writing a file.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What happened.
        message: String,
    },
}

impl RenderError {
    /// An I/O error on `path`.
    pub fn io(path: &Path, e: impl std::fmt::Display) -> RenderError {
        RenderError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

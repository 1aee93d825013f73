//! # visgate-runtime
//!
//! The real-time half: wgpu passes and their WGSL (G-buffer, direct light with shadow maps,
//! VPL generation from reflective shadow maps or traced light paths, the visibility modes for
//! indirect light — none, per-VPL shadow maps, visibility gates with clustered shading, virtual
//! area lights with convolution soft shadow maps — the indirect gather and tone mapping), the
//! CPU reference renderer with exact visibility, image metrics, and the egui viewer.
//!
//! It reads baked levels through `visgate-formats` and never imports `visgate-preprocess`.
//!
//! What stands so far: the CPU side — [`tracer`] (BVH ray casting), [`camera`], [`lights`]
//! (radiometry and direct light), [`vpl`] (the VPL struct, light-path VPLs, the gather term),
//! [`reference`] (the exact-visibility renderer), [`hdr`] (EXR/PNG), [`metrics`], the CPU twins
//! [`gates`] and [`clustered`] (gate visibility and clustered light lists), [`val`] (VAL
//! clustering) and [`cssm`] (the Fourier shadow test) — and the GPU renderer [`gpu`] with every
//! mode. The viewer comes later.

pub mod camera;
pub mod clustered;
pub mod cssm;
pub mod gates;
pub mod gpu;
pub mod hdr;
pub mod lights;
pub mod metrics;
pub mod reference;
pub mod tracer;
pub mod val;
pub mod vpl;

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

//! # visgate-runtime
//!
//! The real-time half: wgpu passes and their WGSL (G-buffer, direct light with shadow maps,
//! VPL generation from reflective shadow maps or traced light paths, the visibility modes for
//! indirect light — none, per-VPL shadow maps, visibility gates with clustered shading, virtual
//! area lights with convolution soft shadow maps — the indirect gather and tone mapping), the
//! CPU reference renderer with exact visibility, image metrics, and the egui viewer.
//!
//! It reads baked levels through `visgate-formats` and never imports `visgate-preprocess`.
//! (The passes land with the runtime issues.)

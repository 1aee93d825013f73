//! # visgate-preprocess
//!
//! The bake, on the CPU (rayon, petgraph): static meshes → conservative voxelization → empty
//! space (border solid, enclosed voids and small unlit components dropped, leaks reported) →
//! exact Euclidean distance transform → topology-preserving curvilinear thinning (asymmetric
//! critical kernels with 1D isthmuses and persistence) → skeleton graph and nearest-node grid
//! → segmentation (topology, curvature and coverage nodes) → visibility clusters (greedy, α)
//! → visibility gates → the runtime layout of `visgate_formats::vgate`.
//!
//! Each stage is a function from plain data to new plain data with its own params struct,
//! timed and counted in a bake context. This crate never imports `visgate-runtime`; what the
//! two share is a type in `visgate-formats`. (The stages land with the bake issue.)

//! One module per pass, each beside its WGSL (`NAME.wgsl` in this folder): what it owns (its
//! pipelines, its parameters' checks) and how it records into a frame.

pub mod clustered_gates;
pub mod cssm;
pub mod display;
pub mod gates_params;
pub mod gbuffer;
pub mod interleave_blur;
pub mod ism;
pub mod ism_params;
pub mod lc_params;
pub mod light_cluster;
pub mod per_vpl_maps;
pub mod roulette;
pub mod rsm_vpls;
pub mod shade;
pub mod shadow_maps;
pub mod sight_ends;
pub mod starved;
pub mod unshadowed;
pub mod val_gather;
pub mod vals;

// A virtual point light, as runtime::vpl::Vpl (48 bytes). Put in front of the shaders that read
// VPLs (WGSL has no includes).
struct Vpl {
    position: vec3<f32>,
    pad0: f32,
    normal: vec3<f32>,
    pad1: f32,
    flux: vec3<f32>,
    pad2: f32,
};


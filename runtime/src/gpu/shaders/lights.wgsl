// The scene's point and spot lights as the shading and LightCluster passes read them.

// As runtime::gpu::layout::Light.
struct Light {
    // xyz position (m), w kind (LIGHT_POINT or LIGHT_SPOT).
    position: vec4<f32>,
    // rgb intensity (W/sr), w beam half-angle (rad).
    intensity: vec4<f32>,
    // xyz unit axis, w cutoff half-angle (rad).
    direction: vec4<f32>,
    // x first shadow layer, y layers, z, w unused.
    layers: vec4<u32>,
};

fn spot_falloff(angle: f32, beam: f32, cutoff: f32) -> f32 {
    if angle <= beam {
        return 1.0;
    }
    if angle >= cutoff || cutoff <= beam {
        return 0.0;
    }
    return (cutoff - angle) / (cutoff - beam);
}


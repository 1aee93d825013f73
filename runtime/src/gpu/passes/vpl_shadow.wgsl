//! include: vpl.wgsl val.wgsl
// Per-VPL paraboloid shadow maps (the brute-force baseline): each layer of a 2D array holds,
// per texel, the distance from one VPL to the nearest surface over the hemisphere around the
// VPL's normal. Paraboloid projection (Brabec et al.): a direction d in the VPL's frame
// (t, b, n) maps to d.xy / (1 + d.z). The projection is not linear, so a long edge would be
// bent wrongly: the renderer splits the scene's triangles until no edge is longer than a
// fraction of the scene (see `gpu::VPL_SHADOW_MAX_EDGE`); vertices behind the VPL's plane go to
// the map's rim, and fragments behind or in the plane are discarded. The map's VPL (or VAL)
// is the draw's instance.

// As runtime::gpu::layout::MapParams.
struct MapParams {
    // Far distance (m): depth is distance / far.
    far: f32,
    // A VAL's centre is moved this far off its surface along its normal (m).
    centre_offset: f32,
    pad0: vec2<f32>,
};

@group(0) @binding(0) var<uniform> map_params: MapParams;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read> vals: array<Val>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
};

// The paraboloid projection of `local` (in the map's frame: t, b, n) with distances over
// `far` in depth.
fn project(local: vec3<f32>, far: f32) -> VsOut {
    let d = max(length(local), 1e-12);
    let dir = local / d;
    var o: VsOut;
    // A vertex behind the map's plane would project far outside the map and drag its
    // triangle across it: put it on the rim instead (its fragments behind are discarded).
    var uv = dir.xy / max(1.0 + dir.z, 1e-4);
    if local.z < 0.0 {
        let r = length(local.xy);
        uv = select(vec2<f32>(1.0, 0.0), local.xy / r, r > 0.0);
    }
    o.clip = vec4<f32>(uv, clamp(d / far, 0.0, 1.0), 1.0);
    o.local = local;
    return o;
}

// A VPL's map (mode per-vpl-shadow-maps): VPL `k`, in the frame of basis(normal).
@vertex
fn vs(@location(0) position: vec3<f32>, @builtin(instance_index) k: u32) -> VsOut {
    let n = vpls[k].normal;
    let tb = basis(n);
    let v = position - vpls[k].position;
    return project(vec3<f32>(dot(v, tb[0]), dot(v, tb[1]), dot(v, n)), map_params.far);
}

// A VAL's map (modes val-hard, val-cssm): VAL `k` of the VALs the GPU clustered, its centre
// moved off its surface by `map_params.centre_offset`.

@vertex
fn vs_val(@location(0) position: vec3<f32>, @builtin(instance_index) k: u32) -> VsOut {
    let n = vals[k].normal.xyz;
    let tb = basis(n);
    let v = position - (vals[k].position.xyz + n * map_params.centre_offset);
    return project(vec3<f32>(dot(v, tb[0]), dot(v, tb[1]), dot(v, n)), map_params.far);
}

@fragment
fn fs(i: VsOut) -> @location(0) f32 {
    // Behind the VPL's plane, or in it: the surface the VPL lies on projects to the rim, but a
    // triangle around the VPL would fill the map's middle with near distances.
    if i.local.z <= 1e-3 * length(i.local) {
        discard;
    }
    return length(i.local);
}

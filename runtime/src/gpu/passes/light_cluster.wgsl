//! include: lights.wgsl lc.wgsl vpl.wgsl
// LightCluster (../shared/papers/lightcluster-pcss.txt) on the GPU, as its CPU twin
// runtime::cpu::lightcluster clusters:
//
// 1. `cull` (a thread per light): the light's range (range_scale · sqrt(I)) against the view
//    frustum; a light kept gets its eye distance as its key, a culled one -1;
// 2. `rank` (a thread per light): the kept lights ordered by (eye distance, index);
//    `centres_pass` (one workgroup): the minimum-distance pass in that order — a light becomes a centre unless a centre lies
//    within min_distance · (1 + distance_scale · d); it writes the clusters, the indirect draw
//    of their cube faces and the indirect dispatch of the PCSS pass;
// 3. `assign` (a thread per light): every other kept light joins its nearest centre, and
//    widens its cluster's reach (the farthest point any of its lights lights) and extent (its
//    farthest light from the centre);
// 4. `vs_atlas`: a depth-only draw of the scene per atlas tile (a cluster's cube face, drawn
//    where the cluster exists: indirect), reversed depth near / z without a far plane;
// 5. `pcss` (8 × 8 pixels × 4 clusters): each cluster's visibility at each pixel, PCSS with
//    the cluster as a disk of its radius — blocker search, penumbra estimate, PCF — into an
//    rgba8 array, four clusters a texel.

@group(0) @binding(0) var<uniform> frame: LcFrame;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
// Each light's eye distance, -1 where culled.
@group(0) @binding(2) var<storage, read_write> light_key: array<f32>;
// Each light's cluster, NONE where culled.
@group(0) @binding(3) var<storage, read_write> light_cluster: array<u32>;
// The kept lights in the order of the first pass.
@group(0) @binding(4) var<storage, read_write> order: array<u32>;
// Each cluster's centre (xyz) and disk radius (w).
@group(0) @binding(5) var<storage, read_write> clusters: array<vec4<f32>>;
// Each cluster's centre light.
@group(0) @binding(6) var<storage, read_write> centres: array<u32>;
// Each cluster's reach (m, as f32 bits: positive floats order as their bits).
@group(0) @binding(7) var<storage, read_write> reach: array<atomic<u32>>;
// The PCSS pass's dispatch args (x, y, z), clusters, culled lights, 3 unused; from word 8 a
// draw's args (vertices, instances 0 or 1, 0, 0) per atlas tile (cluster k's face f: tile
// 6k + f).
@group(0) @binding(8) var<storage, read_write> args: array<u32>;
// Each cluster's extent: its farthest light from its centre (m, as f32 bits).
@group(0) @binding(9) var<storage, read_write> extent: array<atomic<u32>>;
// VPLs clustered as lights (mode vpl-clusters): the VPLs, and the lights `vpl_lights` makes
// of them (bound as `lights` to the clustering passes).
@group(0) @binding(10) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(11) var<storage, read_write> vpl_as_light: array<Light>;

// VPL i as a point light of intensity Φ/π (its peak, along its normal), lifted off its
// surface by 10 near distances so that its cube map does not start inside it; its normal is
// the light's `direction`.
@compute @workgroup_size(WG_LINEAR)
fn vpl_lights(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= frame.light_count {
        return;
    }
    let v = vpls[i];
    var l: Light;
    l.position = vec4<f32>(v.position + v.normal * 10.0 * frame.near_m, LIGHT_POINT);
    l.intensity = vec4<f32>(v.flux / PI, 0.0);
    l.direction = vec4<f32>(v.normal, 0.0);
    l.layers = vec4<u32>(0u);
    vpl_as_light[i] = l;
}

fn light_range(l: Light) -> f32 {
    let i = max(max(l.intensity.x, l.intensity.y), l.intensity.z);
    return frame.range_scale * sqrt(max(i, 0.0));
}

// As runtime::cpu::lightcluster::sphere_in_view.
fn sphere_in_view(p: vec3<f32>, r: f32) -> bool {
    let d = p - frame.eye.xyz;
    let x = dot(d, frame.right.xyz);
    let y = dot(d, frame.up.xyz);
    let z = dot(d, frame.forward.xyz);
    let h = frame.half_fov;
    return !(z < -r || x * h.x - z * h.y > r || -x * h.x - z * h.y > r
        || y * h.z - z * h.w > r || -y * h.z - z * h.w > r);
}

@compute @workgroup_size(WG_LINEAR)
fn cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= frame.light_count {
        return;
    }
    let l = lights[i];
    let range = light_range(l);
    var key = -1.0;
    if range > 0.0 && sphere_in_view(l.position.xyz, range) {
        key = length(l.position.xyz - frame.eye.xyz);
    }
    light_key[i] = key;
    light_cluster[i] = NONE;
}

var<workgroup> live: atomic<u32>;
var<workgroup> live_count: u32;
var<workgroup> blocked: atomic<u32>;
var<workgroup> count: u32;
var<workgroup> centre_at: array<vec4<f32>, MAX_LC_CLUSTERS>;
var<workgroup> centre_dir: array<vec3<f32>, MAX_LC_CLUSTERS>;

// Whether emitters of axes a and b may share a cluster: lights always; VPLs (hemisphere) only
// when their normals are within 60° (a cluster does not mix a floor's VPLs with a wall's).
fn alike(a: vec3<f32>, b: vec3<f32>) -> bool {
    return frame.hemisphere == 0u || dot(a, b) > 0.5;
}

// Whether kept light j comes before kept light i in the first pass's order.
fn before(j: u32, i: u32) -> bool {
    let kj = light_key[j];
    let ki = light_key[i];
    return kj >= 0.0 && (kj < ki || (kj == ki && j < i));
}

// A kept light's place in the first pass's order (a thread per light, every pair: n² work
// spread over the GPU, n steps a thread).
@compute @workgroup_size(WG_LINEAR)
fn rank(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= frame.light_count || light_key[i] < 0.0 {
        return;
    }
    var r = 0u;
    for (var j = 0u; j < frame.light_count; j++) {
        r += select(0u, 1u, before(j, i));
    }
    order[r] = i;
}

@compute @workgroup_size(WG_WIDE)
fn centres_pass(@builtin(local_invocation_index) t: u32) {
    let n = frame.light_count;
    if t == 0u {
        atomicStore(&live, 0u);
        atomicStore(&blocked, 0u);
        count = 0u;
    }
    workgroupBarrier();
    for (var i = t; i < n; i += WG_WIDE) {
        if light_key[i] >= 0.0 {
            atomicAdd(&live, 1u);
        }
    }
    workgroupBarrier();
    if t == 0u {
        live_count = atomicLoad(&live);
    }
    let kept = workgroupUniformLoad(&live_count);
    for (var r = 0u; r < kept; r++) {
        let c = workgroupUniformLoad(&count);
        if c >= frame.max_clusters {
            break;
        }
        let i = order[r];
        let p = lights[i].position.xyz;
        let radius = frame.min_distance_m * (1.0 + frame.distance_scale * light_key[i]);
        let axis = lights[i].direction.xyz;
        for (var k = t; k < c; k += WG_WIDE) {
            if alike(centre_dir[k], axis) && distance(centre_at[k].xyz, p) < radius {
                atomicStore(&blocked, 1u);
            }
        }
        workgroupBarrier();
        if t == 0u {
            if atomicLoad(&blocked) == 0u {
                centre_at[c] = vec4<f32>(p, radius);
                centre_dir[c] = axis;
                centres[c] = i;
                light_cluster[i] = c;
                count = c + 1u;
            }
            atomicStore(&blocked, 0u);
        }
    }
    let c = workgroupUniformLoad(&count);
    for (var k = t; k < c; k += WG_WIDE) {
        clusters[k] = centre_at[k];
        atomicStore(&reach[k], bitcast<u32>(light_range(lights[centres[k]])));
        atomicStore(&extent[k], 0u);
    }
    for (var tile = t; tile < 6u * frame.max_clusters; tile += WG_WIDE) {
        args[8u + 4u * tile] = frame.vertex_count;
        args[9u + 4u * tile] = select(0u, 1u, tile < 6u * c);
        args[10u + 4u * tile] = 0u;
        args[11u + 4u * tile] = 0u;
    }
    if t == 0u {
        args[0] = (frame.width + 7u) / 8u;
        args[1] = (frame.height + 7u) / 8u;
        args[2] = (c + 3u) / 4u;
        args[3] = c;
        args[4] = n - kept;
    }
}

@compute @workgroup_size(WG_LINEAR)
fn assign(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= frame.light_count || light_key[i] < 0.0 || light_cluster[i] != NONE {
        return;
    }
    let p = lights[i].position.xyz;
    let axis = lights[i].direction.xyz;
    // The nearest centre alike (see `alike`); the nearest of all where none is.
    var best = 0u;
    var best_d2 = 3.4e38;
    var any_best = 0u;
    var any_d2 = 3.4e38;
    for (var k = 0u; k < args[3]; k++) {
        let d = clusters[k].xyz - p;
        let d2 = dot(d, d);
        if d2 < any_d2 {
            any_d2 = d2;
            any_best = k;
        }
        if d2 < best_d2 && alike(lights[centres[k]].direction.xyz, axis) {
            best_d2 = d2;
            best = k;
        }
    }
    if best_d2 == 3.4e38 {
        best = any_best;
        best_d2 = any_d2;
    }
    light_cluster[i] = best;
    let d = sqrt(best_d2);
    atomicMax(&reach[best], bitcast<u32>(d + light_range(lights[i])));
    atomicMax(&extent[best], bitcast<u32>(d));
}

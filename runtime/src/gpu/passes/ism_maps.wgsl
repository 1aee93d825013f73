//! include: vpl.wgsl val.wgsl ism.wgsl
// Imperfect shadow maps (Ritschel et al. 2008; Weinzierl-Heigl §5), as compute passes:
//   emit      each map's centre and axis: a VPL, or a VAL's centre moved off its surface
//   sample    the scene as random points: point i picks a triangle by area (a hash through the
//             triangles' cumulative area) and a uniform barycentric point in it, from the
//             triangles of this frame (moved meshes move their points); kept up to 2²² points,
//             beyond that drawn again by the splat
//   splat     point i goes to map i mod N (the paper's round robin) as a surfel — a disk of
//             the radius it stands for in its triangle's plane —, its size in texels by its
//             distance to the emitter, each texel the distance where its ray meets the surfel,
//             the nearest kept by atomicMax of the encoded distance
//   pull      level l + 1 of a map: the mean of the filled texels of its 2 × 2 below
//   push      a hole of level l: its parent's value (the pull-push of the paper's Figure 4)

@group(0) @binding(0) var<uniform> frame: IsmFrame;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read> vals: array<Val>;
// Per emitter: centre (xyz), axis (xyz) at 2k, 2k + 1.
@group(0) @binding(3) var<storage, read_write> emitters: array<vec4<f32>>;
// Per triangle: 3 corners (xyz) at 3t…3t + 2.
@group(0) @binding(4) var<storage, read> triangles: array<vec4<f32>>;
// The triangles' cumulative area, the last 1.
@group(0) @binding(5) var<storage, read> area_cdf: array<f32>;
// Per kept point: position (xyz), its triangle's normal (xyz) at 2i, 2i + 1.
@group(0) @binding(6) var<storage, read_write> points: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> atlas: array<atomic<u32>>;
// Levels 1… of every map, as f32 (0: a hole).
@group(0) @binding(8) var<storage, read_write> pyramid: array<f32>;

// As runtime::gpu::layout::IsmLevel: the level written, its side, where it starts in the
// pyramid, and where the level it reads starts (pull: below, push: above).
struct IsmLevel {
    level: u32,
    side: u32,
    offset: u32,
    other: u32,
};
@group(1) @binding(0) var<uniform> lvl: IsmLevel;

@compute @workgroup_size(WG_LINEAR)
fn emit(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x;
    if k >= frame.emitters {
        return;
    }
    if frame.kind == 0u {
        emitters[2u * k] = vec4<f32>(vpls[k].position, 0.0);
        emitters[2u * k + 1u] = vec4<f32>(vpls[k].normal, 0.0);
    } else {
        let n = vals[k].normal.xyz;
        emitters[2u * k] = vec4<f32>(vals[k].position.xyz + n * frame.centre_offset, 0.0);
        emitters[2u * k + 1u] = vec4<f32>(n, 0.0);
    }
}

// PCG (O'Neill), as a hash.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn unit(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Point i of the scene and its triangle's unit normal (a surfel).
fn scene_point(i: u32) -> array<vec3<f32>, 2> {
    let h0 = pcg(i ^ pcg(frame.seed));
    let h1 = pcg(h0);
    let h2 = pcg(h1);
    let u = unit(h0);
    var lo = 0u;
    var hi = frame.triangles - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if area_cdf[mid] <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let a = triangles[3u * lo].xyz;
    let b = triangles[3u * lo + 1u].xyz;
    let c = triangles[3u * lo + 2u].xyz;
    let r1 = sqrt(unit(h1));
    let r2 = unit(h2);
    let p = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
    return array(p, normalize(cross(b - a, c - a)));
}

@compute @workgroup_size(WG_LINEAR)
fn sample(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * WG_LINEAR;
    if i >= frame.points {
        return;
    }
    let s = scene_point(i);
    points[2u * i] = vec4<f32>(s[0], 0.0);
    points[2u * i + 1u] = vec4<f32>(s[1], 0.0);
}

@compute @workgroup_size(WG_LINEAR)
fn splat(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * WG_LINEAR;
    if i >= frame.points {
        return;
    }
    let k = i % frame.emitters;
    let c = emitters[2u * k].xyz;
    let n = emitters[2u * k + 1u].xyz;
    let tb = basis(n);
    // Kept by `sample`, or (too many to keep) drawn again here.
    let kept = min(i, arrayLength(&points) / 2u - 1u);
    var surfel = array(points[2u * kept].xyz, points[2u * kept + 1u].xyz);
    if arrayLength(&points) < 2u * frame.points {
        surfel = scene_point(i);
    }
    let pt = surfel[0];
    let v = pt - c;
    let local = vec3<f32>(dot(v, tb[0]), dot(v, tb[1]), dot(v, n));
    let d = length(local);
    if local.z <= 1e-3 * d || d <= 0.0 {
        return;
    }
    let s = frame.map_size;
    let sf = f32(s);
    let at = ism_coords(local, sf);
    let r = min(frame.point_radius / d * ism_texels_per_rad(local.z / d, sf), frame.max_splat);
    let own = vec2<i32>(floor(at));
    let lo = vec2<i32>(floor(at - vec2<f32>(r)));
    let hi = vec2<i32>(floor(at + vec2<f32>(r)));
    // The surfel: a disk of the point's radius in its triangle's plane. A texel takes the
    // distance where its ray meets that plane (a surface seen at a grazing angle keeps its
    // slope across the splat, instead of the point's one depth), if within the disk; the
    // point's own texel takes the point's distance in any case.
    let sn = surfel[1];
    let plane = dot(sn, v);
    for (var y = max(lo.y, 0); y <= min(hi.y, i32(s) - 1); y++) {
        for (var x = max(lo.x, 0); x <= min(hi.x, i32(s) - 1); x++) {
            let o = vec2<f32>(f32(x), f32(y)) + 0.5 - at;
            if dot(o, o) > (r + 0.7072) * (r + 0.7072) {
                continue;
            }
            var dist = d;
            if x != own.x || y != own.y {
                let w = ism_texel_direction(vec2<f32>(f32(x), f32(y)) + 0.5, sf, tb, n);
                let den = dot(sn, w);
                if abs(den) < 1e-4 {
                    continue;
                }
                dist = plane / den;
                if dist <= 0.0 || length(w * dist - v) > frame.point_radius {
                    continue;
                }
            }
            atomicMax(&atlas[ism_index(k, vec2<u32>(u32(x), u32(y)), s)], ism_encode(dist));
        }
    }
}

// Level l's value at texel t of map k (level 0: the atlas), 0 for a hole.
fn level_value(l: u32, offset: u32, k: u32, t: vec2<u32>) -> f32 {
    let side = frame.map_size >> l;
    if l == 0u {
        let w = atomicLoad(&atlas[ism_index(k, t, side)]);
        return select(ism_decode(w), 0.0, w == 0u);
    }
    return pyramid[offset + ism_index(k, t, side)];
}

// Texel `i` of this dispatch's level: (map, texel), or map ≥ emitters past the last.
struct LevelTexel {
    k: u32,
    t: vec2<u32>,
};

fn level_texel(i: u32) -> LevelTexel {
    let side = lvl.side;
    let per_map = side * side;
    return LevelTexel(i / per_map, vec2<u32>(i % per_map % side, i % per_map / side));
}

@compute @workgroup_size(WG_LINEAR)
fn pull(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * WG_LINEAR;
    let k = level_texel(i).k;
    let t = level_texel(i).t;
    if k >= frame.emitters {
        return;
    }
    var sum = 0.0;
    var found = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let v = level_value(lvl.level - 1u, lvl.other, k, 2u * t + vec2<u32>(j % 2u, j / 2u));
        if v > 0.0 {
            sum += v;
            found += 1.0;
        }
    }
    pyramid[lvl.offset + i] = select(0.0, sum / found, found > 0.0);
}

@compute @workgroup_size(WG_LINEAR)
fn push(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = lvl.side;
    let i = id.x + id.y * 65535u * WG_LINEAR;
    let k = level_texel(i).k;
    let t = level_texel(i).t;
    if k >= frame.emitters {
        return;
    }
    let parent = pyramid[lvl.other + ism_index(k, t / 2u, side / 2u)];
    if parent <= 0.0 {
        return;
    }
    if lvl.level == 0u {
        let at = ism_index(k, t, side);
        if atomicLoad(&atlas[at]) == 0u {
            atomicStore(&atlas[at], ism_encode(parent));
        }
    } else if pyramid[lvl.offset + i] <= 0.0 {
        pyramid[lvl.offset + i] = parent;
    }
}

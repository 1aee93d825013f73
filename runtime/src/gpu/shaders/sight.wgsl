// The voxel walk (runtime::cpu::sight::VoxelSight is its CPU twin): whether the segment between
// a VPL and a surface point crosses open voxels alone. It reads the including pass's
// `sight_words: array<u32>` (VoxelSight::words: [nx, ny, nz, bricks x, y, z, offset of the
// clearances, 0, origin xyz (m), voxel edge (m)], the open bits 32 a word, then each brick's
// chessboard distance in bricks to the nearest brick holding a closed voxel, a byte each). A
// step crosses the cube of bricks that a brick's clearance proves open, or one open voxel.

// SIGHT_BRICK (voxels along a brick's side) and SIGHT_BITS (VoxelSight's header words) are
// injected from runtime::cpu::sight.

fn sight_dims() -> vec3<i32> {
    return vec3<i32>(i32(sight_words[0]), i32(sight_words[1]), i32(sight_words[2]));
}

// Whether voxel v is open (false outside the grid).
fn sight_open(v: vec3<i32>) -> bool {
    let dims = sight_dims();
    if any(v < vec3<i32>(0)) || any(v >= dims) {
        return false;
    }
    let i = u32(v.x + dims.x * (v.y + dims.y * v.z));
    return ((sight_words[SIGHT_BITS + i / 32u] >> (i % 32u)) & 1u) == 1u;
}

// Where the walk from or to surface point p (normal n) starts, in voxel coordinates; w = 0:
// no open voxel near (VoxelSight::end).
fn sight_end(p: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let origin = bitcast<vec3<f32>>(vec3<u32>(sight_words[8], sight_words[9], sight_words[10]));
    let q = (p - origin) / bitcast<f32>(sight_words[11]);
    // END_OFFSETS_VOXELS: 1.25, 2.25, 3.25.
    for (var k = 0; k < 3; k++) {
        let s = q + n * (1.25 + f32(k));
        if sight_open(vec3<i32>(floor(s))) {
            return vec4<f32>(s, 1.0);
        }
    }
    let out = q + n;
    let base = vec3<i32>(floor(out));
    var best = vec4<f32>(0.0);
    var best_d2 = 3.4e38;
    for (var dz = -1; dz <= 1; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let v = base + vec3<i32>(dx, dy, dz);
                let centre = vec3<f32>(v) + 0.5;
                let d2 = dot(centre - out, centre - out);
                if sight_open(v) && dot(centre - q, n) > 0.0 && d2 < best_d2 {
                    best_d2 = d2;
                    best = vec4<f32>(centre, 1.0);
                }
            }
        }
    }
    return best;
}

// Whether the segment a → b (voxel coordinates, both in open voxels) crosses open voxels alone
// (VoxelSight::clear, step for step).
fn sight_clear(a: vec3<f32>, b: vec3<f32>) -> bool {
    let d = b - a;
    let moves = d != vec3<f32>(0.0);
    let up = d > vec3<f32>(0.0);
    let inv = select(vec3<f32>(0.0), 1.0 / select(vec3<f32>(1.0), d, moves), moves);
    let end = vec3<i32>(floor(b));
    var v = vec3<i32>(floor(a));
    let dims = sight_dims();
    let bricks = vec3<i32>(i32(sight_words[3]), i32(sight_words[4]), i32(sight_words[5]));
    let clear_at = sight_words[6];
    let most = dims.x + dims.y + dims.z + 1;
    for (var step = 0; step < most; step++) {
        if any(v < vec3<i32>(0)) || any(v >= dims) {
            return false;
        }
        let brick = v / SIGHT_BRICK;
        let k = u32(brick.x + bricks.x * (brick.y + bricks.y * brick.z));
        let c = i32((sight_words[clear_at + k / 4u] >> (8u * (k % 4u))) & 0xffu);
        var lo = v;
        var hi = v;
        if c > 0 {
            lo = (brick - (c - 1)) * SIGHT_BRICK;
            hi = (brick + c) * SIGHT_BRICK - 1;
        } else {
            let i = u32(v.x + dims.x * (v.y + dims.y * v.z));
            if ((sight_words[SIGHT_BITS + i / 32u] >> (i % 32u)) & 1u) == 0u {
                return false;
            }
        }
        if all(end >= lo) && all(end <= hi) {
            return true;
        }
        let face = select(vec3<f32>(lo), vec3<f32>(hi + 1), up);
        let t = select(vec3<f32>(3.4e38), (face - a) * inv, moves);
        let te = min(t.x, min(t.y, t.z));
        if te >= 1.0 {
            return true;
        }
        var across = vec3<bool>(false, false, true);
        if t.x <= t.y && t.x <= t.z {
            across = vec3<bool>(true, false, false);
        } else if t.y <= t.z {
            across = vec3<bool>(false, true, false);
        }
        let inside = clamp(vec3<i32>(floor(a + d * te)), lo, hi);
        v = select(inside, select(lo - 1, hi + 1, up), across);
    }
    return false;
}

// Whether light passes between surface points a (normal na) and b (normal nb): the walk
// between their ends; unoccluded when either has no open voxel near (VoxelSight::visible).
fn voxel_sight(a: vec3<f32>, na: vec3<f32>, b: vec3<f32>, nb: vec3<f32>) -> bool {
    let x = sight_end(a, na);
    let y = sight_end(b, nb);
    if x.w == 0.0 || y.w == 0.0 {
        return true;
    }
    return sight_clear(x.xyz, y.xyz);
}

// The ratio estimator's grid (GatesParams::ratio_stride s): its unshadowed far light is summed
// at every s-th pixel across and down and the last of each axis (the grid pixels), and at each
// pixel between them whose four grid pixels around it do not all lie on its surface (its own
// sum); every other pixel takes it bilinearly from those four. unshadowed.wgsl sums it,
// blur.wgsl's compose reads it. It reads the including pass's g_position, g_normal and
// g_albedo (face.wgsl's face normal); no bindings of its own.

// A grid pixel lies on a pixel's surface (p, shading normal n) where their shading normals'
// cosine is at least RATIO_COSINE and it lies off the plane of p's face (the G-buffer's face
// normal: a curved surface's facets lie off the plane of its smooth normals, which left a
// vault's pixels every other row on their own) by at most RATIO_PLANE of their distance: the
// unshadowed light changes smoothly between them. Across a crease, an edge or a step it does
// not: taken from there the light is another face's (stride 2 without the own sums: the
// pillared hall's `main` +37 % indirect MSE, Crytek Sponza's gallery +45 %).
const RATIO_COSINE: f32 = 0.9;
const RATIO_PLANE: f32 = 0.1;
// And where the grid pixels' light (summed over the channels) spreads by more than this share
// of the least of it, the light curves between them more than bilinear follows (beside a
// light, or across the near field's edge): the pixel sums its own.
const RATIO_SPREAD: f32 = 0.25;
// The list's tests are this much looser than the blur's (ratio_own's `slack`): the two passes
// are compiled apart, and a pixel that the blur takes as its own but the list left out would
// read a texel nothing wrote. Within the slack a pixel is summed and not read: harmless.
const RATIO_SLACK: f32 = 1e-3;

// The grid's texels for a frame of `size` pixels with stride s: pixels 0, s, 2s, … and the
// last (as runtime::gpu::passes::unshadowed::ratio_grid_size).
fn ratio_grid_size(size: vec2<u32>, s: u32) -> vec2<u32> {
    return (max(size, vec2<u32>(1u)) - 1u + s - 1u) / s + 1u;
}

// The pixel that grid texel c stands for.
fn ratio_grid_pixel(c: vec2<i32>, s: i32, size: vec2<i32>) -> vec2<i32> {
    return min(c * s, size - 1);
}

// Pixel px's place among the grid: its cell's first texel (xy) and its bilinear position in
// the cell (zw, 0 at the first texel's pixel, 1 at the next one's).
fn ratio_cell(px: vec2<i32>, s: i32, size: vec2<i32>) -> vec4<f32> {
    let c0 = px / s;
    let q0 = ratio_grid_pixel(c0, s, size);
    let q1 = ratio_grid_pixel(c0 + 1, s, size);
    let t = vec2<f32>(px - q0) / vec2<f32>(max(q1 - q0, vec2<i32>(1)));
    return vec4<f32>(vec2<f32>(c0), t);
}

// A corner of a pixel's cell: its grid texel and bilinear weight.
struct RatioCorner {
    texel: vec2<i32>,
    weight: f32,
};

// Corner k (0-3: a texel on along x for k & 1, along y for k >> 1) of cell `cell` (ratio_cell).
fn ratio_corner(cell: vec4<f32>, k: i32) -> RatioCorner {
    let o = vec2<i32>(k & 1, k >> 1);
    let w = mix(1.0 - cell.zw, cell.zw, vec2<f32>(o));
    return RatioCorner(vec2<i32>(cell.xy) + o, w.x * w.y);
}

// Whether pixel px (surface p, normal n; a frame of `size`, stride s) sums its own unshadowed
// light: a grid pixel that weighs in its bilinear sum lies off its surface, or their light in
// `light` (each at its pixel) spreads by more than RATIO_SPREAD; the tests loosened by `slack`
// (RATIO_SLACK for the list, 0 for the blur). Never a grid pixel: its own texel weighs alone.
fn ratio_own(light: texture_2d<f32>, px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, s: i32, size: vec2<i32>, slack: f32) -> bool {
    if s <= 1 {
        return false;
    }
    let face = decode_face_normal(vec2<f32>(textureLoad(g_normal, px, 0).w, textureLoad(g_albedo, px, 0).w));
    let cell = ratio_cell(px, s, size);
    var lo = 3.4e38;
    var hi = 0.0;
    for (var k = 0; k < 4; k++) {
        let c = ratio_corner(cell, k);
        if c.weight <= 0.0 {
            continue;
        }
        let q = ratio_grid_pixel(c.texel, s, size);
        let qp = textureLoad(g_position, q, 0);
        let qn = textureLoad(g_normal, q, 0).xyz;
        let d = qp.xyz - p;
        let off_plane = abs(dot(d, face)) > (RATIO_PLANE - slack) * length(d);
        if qp.w == 0.0 || dot(qn, n) < RATIO_COSINE + slack || off_plane {
            return true;
        }
        let u = textureLoad(light, q, 0).xyz;
        lo = min(lo, u.x + u.y + u.z);
        hi = max(hi, u.x + u.y + u.z);
    }
    return hi > lo * (1.0 + RATIO_SPREAD - slack);
}

// Pixel px's unshadowed far light (surface p, normal n; a frame of `size`, stride s) from
// `unshadowed`, where unshadowed.wgsl wrote it: its own (ratio_own, or every pixel's at stride
// 1), or bilinear between the four grid pixels around it.
fn ratio_unshadowed(unshadowed: texture_2d<f32>, px: vec2<i32>, p: vec3<f32>, n: vec3<f32>, s: i32, size: vec2<i32>) -> vec3<f32> {
    if s <= 1 || ratio_own(unshadowed, px, p, n, s, size, 0.0) {
        return textureLoad(unshadowed, px, 0).xyz;
    }
    let cell = ratio_cell(px, s, size);
    var sum = vec3<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let c = ratio_corner(cell, k);
        if c.weight > 0.0 {
            sum += c.weight * textureLoad(unshadowed, ratio_grid_pixel(c.texel, s, size), 0).xyz;
        }
    }
    return sum;
}

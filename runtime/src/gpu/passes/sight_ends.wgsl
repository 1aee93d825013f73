//! include: vpl.wgsl sight.wgsl
// Each VPL's end of the voxel walk off its surface (sight.wgsl's sight_end; w = 0: no open
// voxel near), once a frame: mode gates with voxels reads them for every pixel's walks instead
// of finding each VPL's end again (shade.wgsl's portal_gather; runtime::cpu::sight::VoxelSight
// is the CPU twin). The walk along the true segment takes only w from it.

@group(0) @binding(0) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(1) var<storage, read> sight_words: array<u32>;
// The closed voxels' triangle lists and planes (sight.wgsl).
@group(0) @binding(3) var<storage, read> sight_extra: array<u32>;
// xyz: the end in the sight grid's voxel coordinates; w: 1, or 0 where no open voxel is near.
@group(0) @binding(2) var<storage, read_write> vpl_ends: array<vec4<f32>>;

// The voxel walk passes closed voxels on their planes (runtime::cpu::sight_planes): the ends
// start 0.3 voxels off their surfaces where the planes allow (1), or not (0).
override SIGHT_END_PLANES: u32 = 0u;

@compute @workgroup_size(WG_LINEAR)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < min(arrayLength(&vpls), arrayLength(&vpl_ends)) {
        let v = vpls[id.x];
        vpl_ends[id.x] = sight_end(v.position, v.normal, SIGHT_END_PLANES == 1u);
    }
}

use super::*;
use crate::cpu::sight_triangles::TRIANGLE_WORDS;

fn grid(dims: [u32; 3]) -> GridMeta {
    GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 1.0,
        dims,
    }
}

/// The plain DDA: every voxel the segment touches, in order.
fn dda_clear(s: &VoxelSight, a: Vec3, b: Vec3) -> bool {
    let d = b - a;
    let mut v = a.floor().as_ivec3();
    let end = b.floor().as_ivec3();
    let mut t_max = Vec3::INFINITY;
    let mut t_delta = Vec3::INFINITY;
    let mut step = IVec3::ZERO;
    for k in 0..3 {
        if d[k] != 0.0 {
            step[k] = d[k].signum() as i32;
            let face = if d[k] > 0.0 { v[k] + 1 } else { v[k] } as f32;
            t_max[k] = (face - a[k]) / d[k];
            t_delta[k] = 1.0 / d[k].abs();
        }
    }
    loop {
        if !s.open(v) {
            return false;
        }
        if v == end {
            return true;
        }
        let k = t_max.min_position();
        if t_max[k] >= 1.0 {
            return true;
        }
        v[k] += step[k];
        t_max[k] += t_delta[k];
    }
}

#[test]
fn brick_march_agrees_with_the_plain_dda_on_random_levels() {
    // Random boxes of closed voxels in a 40 × 23 × 31 grid (sizes not multiples of a
    // brick), segments between random open voxels, some along axes and diagonals.
    let dims = [40u32, 23, 31];
    let mut rnd = crate::cpu::xorshift32(0x2545_f491u32);
    for level in 0..12 {
        let mut open = vec![true; (dims[0] * dims[1] * dims[2]) as usize];
        for _ in 0..(4 + level * 3) {
            let lo = [rnd(dims[0]), rnd(dims[1]), rnd(dims[2])];
            let size = [1 + rnd(6), 1 + rnd(9), 1 + rnd(4)];
            for z in lo[2]..(lo[2] + size[2]).min(dims[2]) {
                for y in lo[1]..(lo[1] + size[1]).min(dims[1]) {
                    for x in lo[0]..(lo[0] + size[0]).min(dims[0]) {
                        open[(x + dims[0] * (y + dims[1] * z)) as usize] = false;
                    }
                }
            }
        }
        let bits = VoxelBits::from_fn(open.len(), |i| open[i]);
        let s = VoxelSight::new(&grid(dims), &bits);
        let mut pairs = 0;
        while pairs < 400 {
            let p = |r: &mut dyn FnMut(u32) -> u32| {
                Vec3::new(
                    r(dims[0] * 64) as f32 / 64.0,
                    r(dims[1] * 64) as f32 / 64.0,
                    r(dims[2] * 64) as f32 / 64.0,
                )
            };
            let a = p(&mut rnd);
            let mut b = p(&mut rnd);
            match pairs % 5 {
                0 => b.y = a.y,
                1 => (b.y, b.z) = (a.y, a.z),
                2 => b = a + Vec3::splat(b.x - a.x) * Vec3::new(1.0, 0.5, 0.25),
                _ => {}
            }
            if !s.open(a.floor().as_ivec3()) || !s.open(b.floor().as_ivec3()) {
                continue;
            }
            pairs += 1;
            assert_eq!(
                s.clear(a, b, Closed::Blocks),
                dda_clear(&s, a, b),
                "level {level}: {a} → {b}"
            );
        }
    }
}

#[test]
fn a_wall_blocks_its_own_surface_does_not_and_an_opening_passes() {
    // A room 20 voxels long, a wall one voxel thick at x = 10 with a hole at y, z in 4..6.
    let dims = [20u32, 10, 10];
    let open = VoxelBits::from_fn(2000, |i| {
        let (x, y, z) = (i % 20, (i / 20) % 10, i / 200);
        let border = x == 0 || y == 0 || z == 0 || x == 19 || y == 9 || z == 9;
        let wall = x == 10 && !((4..6).contains(&y) && (4..6).contains(&z));
        !border && !wall
    });
    let s = VoxelSight::new(&grid(dims), &open);
    // Two floor points (the floor is the closed layer y = 0, its surface at y = 1).
    let floor = |x: f32, z: f32| Vec3::new(x, 1.0, z);
    assert!(!s.visible(floor(3.0, 5.0), Vec3::Y, floor(16.0, 5.0), Vec3::Y));
    // Grazing along the floor, then up the far wall of the same side: clear.
    assert!(s.visible(floor(2.0, 5.0), Vec3::Y, Vec3::new(9.0, 1.2, 5.0), -Vec3::X));
    // Through the hole.
    assert!(s.visible(
        Vec3::new(1.0, 5.0, 5.0),
        Vec3::X,
        Vec3::new(19.0, 5.0, 5.0),
        -Vec3::X
    ));
    // Beside it.
    assert!(!s.visible(
        Vec3::new(1.0, 2.5, 5.0),
        Vec3::X,
        Vec3::new(19.0, 2.5, 5.0),
        -Vec3::X
    ));
    // An end on the wall's face starts 1.25 voxels out; one with no open voxel near knows
    // nothing, so its light is unoccluded.
    assert_eq!(
        s.end(Vec3::new(10.0, 2.5, 5.0), -Vec3::X),
        Some(Vec3::new(8.75, 2.5, 5.0))
    );
    assert_eq!(s.end(Vec3::new(-5.0, -5.0, -5.0), Vec3::X), None);
    assert!(s.visible(
        Vec3::new(-5.0, -5.0, -5.0),
        Vec3::X,
        floor(3.0, 5.0),
        Vec3::Y
    ));
}

#[test]
fn a_segment_over_a_walls_top_passes_its_closed_voxels_and_one_through_it_does_not() {
    // A single-sided wall in the plane x = 10.1, 5.2 high, across the whole depth; the
    // voxels its triangles touch are closed (the top ones are crossed by no segment that
    // meets the wall).
    let dims = [20u32, 10, 10];
    let wall = [
        [
            Vec3::new(10.1, 0.0, 0.0),
            Vec3::new(10.1, 5.2, 0.0),
            Vec3::new(10.1, 0.0, 10.0),
        ],
        [
            Vec3::new(10.1, 5.2, 0.0),
            Vec3::new(10.1, 5.2, 10.0),
            Vec3::new(10.1, 0.0, 10.0),
        ],
    ];
    let touched = |v: IVec3| {
        wall.iter().any(|t| {
            visgate_formats::geom::tri_box_overlap(v.as_dvec3() + 0.5, 0.5, t.map(|p| p.as_dvec3()))
        })
    };
    let open = VoxelBits::from_fn(2000, |i| !touched(voxel_of(i, IVec3::new(20, 10, 10))));
    let bare = VoxelSight::new(&grid(dims), &open);
    let s = bare.clone().with_triangles(&wall);
    let (a, b) = (Vec3::new(8.5, 6.5, 5.0), Vec3::new(11.5, 5.4, 5.0));
    // The walk that blocks at every closed voxel never lists the triangles.
    assert!(!s.clear(a, b, Closed::Blocks));
    s.visible_off_surfaces(a, Vec3::X, b, -Vec3::X, false);
    assert!(!s.triangles_listed() && !s.planes_fitted());
    // Every closed voxel touched by the same one or two triangles: a few shared lists.
    let lists = s.triangles();
    assert!(lists.voxels() >= 60 && lists.lists() <= 3 && lists.references() <= 4);
    assert!(!bare.open(IVec3::new(10, 5, 5)));
    assert!(
        !bare.clear(a, b, Closed::Triangles),
        "no lists: closed voxels block"
    );
    assert!(!bare.clear(a, b, Closed::Planes), "no triangles: no planes");
    assert!(
        !s.clear(a, b, Closed::Blocks),
        "lists not read: closed voxels block"
    );
    assert!(s.clear(a, b, Closed::Triangles));
    assert!(s.visible(a, Vec3::X, b, -Vec3::X));
    // The planes hold the wall's plane, not its top edge: the voxels above 5.2 block a
    // segment that crosses the plane there, and pass one beside the wall.
    assert!(!s.clear(a, b, Closed::Planes));
    assert!(s.planes_fitted() && s.planes().counts() == [60, 0]);
    let (e, f) = (Vec3::new(10.3, 2.5, 1.5), Vec3::new(10.3, 2.5, 8.5));
    assert!(!s.clear(e, f, Closed::Blocks) && s.clear(e, f, Closed::Planes));
    // Through the wall.
    let (c, d) = (Vec3::new(8.5, 3.5, 5.0), Vec3::new(11.5, 3.5, 5.0));
    assert!(!s.clear(c, d, Closed::Triangles) && !s.clear(c, d, Closed::Planes));
    // From a point on the wall, whose walk starts in the wall's closed voxels: its own side
    // sees the room and not past the wall, the other side the reverse.
    let on = Vec3::new(10.1, 2.0, 5.0);
    let (room, beyond) = (Vec3::new(3.0, 5.0, 5.0), Vec3::new(16.0, 3.0, 7.0));
    assert!(s.visible(on, -Vec3::X, room, Vec3::X));
    assert!(!s.visible(on, -Vec3::X, beyond, -Vec3::X));
    assert!(s.visible(on, Vec3::X, beyond, -Vec3::X));
    assert!(!s.visible(on, Vec3::X, room, Vec3::X));
    // The packed words end with the clearances; the extra words carry the lists after a
    // word 0, then the planes: a count per block of 256 voxels, a word per closed voxel
    // (each of these one plane).
    let SightWords { base: w, extra } = s.words();
    assert_eq!(w[7], TRIANGLE_TESTS_PER_WALK);
    assert_eq!(w.len(), w[6] as usize + bare.clear.len().div_ceil(4));
    assert_eq!((w[12], extra[0]), (1, 0));
    assert_eq!(w[16] as usize, w[15] as usize + TRIANGLE_WORDS * wall.len());
    assert_eq!(w[17] as usize, w[16] as usize + 2000usize.div_ceil(256));
    assert_eq!(w[17] as usize + 60, extra.len());
    assert_eq!(s.words_with(true, false).extra.len(), w[16] as usize);
    // The planes alone start after the word 0.
    let planes = s.words_with(false, true);
    assert_eq!(&planes.base[12..18], &[0, 0, 0, 0, 1, 1 + w[17] - w[16]]);
    assert_eq!(planes.extra[1..], extra[w[16] as usize..]);
    let bare = bare.words();
    assert_eq!(
        (&bare.base[12..18], &bare.extra[..]),
        (&[0; 6][..], &[0][..])
    );
}

#[test]
fn the_packed_words_hold_the_bits_and_the_clearances() {
    let dims = [9u32, 5, 6];
    let open = VoxelBits::from_fn(270, |i| i % 11 != 0);
    let s = VoxelSight::new(&grid(dims), &open);
    let w = s.words().base;
    assert_eq!(&w[..6], &[9, 5, 6, 5, 3, 3]);
    assert_eq!(&w[8..12], &[0.0f32, 0.0, 0.0, 1.0].map(f32::to_bits));
    // A true end's offset, at the origin 1e-3 voxels.
    let hair = crate::cpu::sight_triangles::TRUE_END_OFFSET_VOXELS;
    assert_eq!(w[18], hair.to_bits());
    let at = w[6] as usize;
    assert_eq!(at, SIGHT_HEADER_WORDS + 270usize.div_ceil(32));
    for i in 0..270 {
        let k = SIGHT_HEADER_WORDS + i / 32;
        assert_eq!((w[k] >> (i % 32)) & 1 == 1, open.get(i));
    }
    for (k, &c) in s.clear.iter().enumerate() {
        assert_eq!((w[at + k / 4] >> (8 * (k % 4))) & 0xff, u32::from(c));
    }
}

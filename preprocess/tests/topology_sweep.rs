//! Topology preservation over random box-room voxel layouts at several resolutions: the
//! skeleton keeps the components and independent cycles of the empty space (counted
//! independently, by Euler characteristic), it is one voxel thin, every empty voxel maps to a
//! node of its own component, floating objects are hung without changing the topology, and the
//! result does not depend on the number of threads.

use visgate_formats::vgate::GridMeta;
use visgate_preprocess::betti::betti;
use visgate_preprocess::distance::squared_distance;
use visgate_preprocess::empty::{EmptySpaceParams, empty_space};
use visgate_preprocess::graph::{nearest_node, skeleton_graph};
use visgate_preprocess::neighbourhood::{Conn, bit, is_simple, label_components};
use visgate_preprocess::thin::{ThinParams, Thinned, thin};

/// A tiny deterministic generator (xorshift), so the sweep needs no extra crate.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next() % (hi - lo) as u64) as usize
    }
}

/// Random rooms and corridors on a coarse cell grid, scaled so the longest axis has `res`
/// voxels; a few floating blocks, wall bumps and one-voxel corridors.
fn layout(seed: u64, res: usize) -> ([u32; 3], Vec<bool>) {
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let cells = [8usize, 4, 8];
    let k = (res / 8).max(2);
    let dims = [cells[0] * k + 2, cells[1] * k + 2, cells[2] * k + 2];
    let idx = |x: usize, y: usize, z: usize| x + dims[0] * (y + dims[1] * z);
    let mut empty = vec![false; dims[0] * dims[1] * dims[2]];
    let carve = |lo: [usize; 3], hi: [usize; 3], v: bool, e: &mut Vec<bool>| {
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    if x > 0
                        && y > 0
                        && z > 0
                        && x + 1 < dims[0]
                        && y + 1 < dims[1]
                        && z + 1 < dims[2]
                    {
                        e[idx(x, y, z)] = v;
                    }
                }
            }
        }
    };
    let rooms = rng.range(2, 6);
    for _ in 0..rooms {
        let lo = [rng.range(0, 6), 0, rng.range(0, 6)];
        let hi = [
            lo[0] + rng.range(1, 3),
            rng.range(2, 4),
            lo[2] + rng.range(1, 3),
        ];
        carve(
            [1 + lo[0] * k + k / 4, 1 + k / 4, 1 + lo[2] * k + k / 4],
            [
                1 + hi[0] * k - k / 4,
                1 + hi[1] * k - k / 4,
                1 + hi[2] * k - k / 4,
            ],
            true,
            &mut empty,
        );
    }
    // Corridors, some one voxel wide.
    for _ in 0..rng.range(1, 5) {
        let a = [
            rng.range(1, dims[0] - 2),
            1 + k / 4 + 1,
            rng.range(1, dims[2] - 2),
        ];
        let len = rng.range(k, 4 * k);
        let w = if rng.next().is_multiple_of(3) {
            1
        } else {
            (k / 3).max(1)
        };
        let (lo, hi) = if rng.next().is_multiple_of(2) {
            ([a[0], a[1], a[2]], [a[0] + len, a[1] + w, a[2] + w])
        } else {
            ([a[0], a[1], a[2]], [a[0] + w, a[1] + w, a[2] + len])
        };
        carve(
            lo,
            [hi[0].min(dims[0]), hi[1].min(dims[1]), hi[2].min(dims[2])],
            true,
            &mut empty,
        );
    }
    // Half the layouts get a rectangular ring corridor (a loop).
    if rng.next().is_multiple_of(2) {
        let w = (k / 3).max(1);
        let (x0, z0) = (rng.range(1, dims[0] / 2), rng.range(1, dims[2] / 2));
        let (x1, z1) = (
            rng.range(x0 + w + 2, dims[0] - 1),
            rng.range(z0 + w + 2, dims[2] - 1),
        );
        let y = 1 + k / 4;
        carve([x0, y, z0], [x1, y + w, z0 + w], true, &mut empty);
        carve([x0, y, z1 - w], [x1, y + w, z1], true, &mut empty);
        carve([x0, y, z0], [x0 + w, y + w, z1], true, &mut empty);
        carve([x1 - w, y, z0], [x1, y + w, z1], true, &mut empty);
    }
    // Floating blocks (cavities) and wall bumps.
    for _ in 0..rng.range(0, 3) {
        let c = [
            rng.range(2, dims[0] - 3),
            rng.range(2, dims[1] - 3),
            rng.range(2, dims[2] - 3),
        ];
        let s = rng.range(1, (k / 2).max(2));
        carve(c, [c[0] + s, c[1] + s, c[2] + s], false, &mut empty);
    }
    for _ in 0..rng.range(0, 20) {
        let c = [
            rng.range(1, dims[0] - 1),
            rng.range(1, dims[1] - 1),
            rng.range(1, dims[2] - 1),
        ];
        empty[idx(c[0], c[1], c[2])] = !empty[idx(c[0], c[1], c[2])];
    }
    (dims.map(|d| d as u32), empty)
}

fn meta(dims: [u32; 3]) -> GridMeta {
    GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 0.1,
        dims,
    }
}

fn run(dims: [u32; 3], empty: &[bool]) -> (Vec<bool>, Thinned) {
    let solid: Vec<bool> = empty.iter().map(|&e| !e).collect();
    let es = empty_space(
        &meta(dims),
        &solid,
        &[],
        &[],
        &EmptySpaceParams {
            min_component_voxels: 0,
            closed: false,
            allow_leaks: true,
            locate_inside_leaks: true,
        },
    )
    .expect("the layout has empty space");
    let not_empty: Vec<bool> = es.empty.iter().map(|&e| !e).collect();
    let d2 = squared_distance(dims, &not_empty);
    let t = thin(
        dims,
        &es.empty,
        &d2,
        &ThinParams { persistence: 3 },
        &|_, _| {},
    );
    (es.empty, t)
}

/// Checks one layout; returns its cycles and cavities before hanging.
fn check(seed: u64, res: usize) -> (u64, u64) {
    let (dims, raw) = layout(seed, res);
    if !raw.iter().any(|&e| e) {
        return (0, 0);
    }
    let before = betti(dims, &raw);
    let (empty, t) = run(dims, &raw);
    let after = betti(dims, &empty);
    let ctx = format!("seed {seed} res {res} dims {dims:?}");
    // Hanging floating objects removes cavities and nothing else.
    assert_eq!(after.cavities, 0, "{ctx}");
    assert_eq!(
        (after.components, after.cycles),
        (before.components, before.cycles),
        "{ctx}"
    );
    // Same topology as the empty space.
    let mut skel = vec![false; empty.len()];
    t.skeleton.iter().for_each(|&i| skel[i as usize] = true);
    let sb = betti(dims, &skel);
    assert_eq!(
        (sb.components, sb.cycles, sb.cavities),
        (after.components, after.cycles, 0),
        "{ctx}"
    );
    // The graph has the voxel set's cycles.
    let g = skeleton_graph(dims, &t.skeleton);
    assert_eq!(g.cycles(), sb.cycles, "graph cycles, {ctx}");
    // One voxel thin: every voxel is an end or not simple.
    let [nx, ny, _] = dims.map(|d| d as isize);
    for &i in &t.skeleton {
        let mut m = 0u32;
        let mut count = 0;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let j = i as isize + dx + nx * (dy + ny * dz);
                    if (dx, dy, dz) != (0, 0, 0) && skel[j as usize] {
                        m |= 1 << bit(dx as i32, dy as i32, dz as i32);
                        count += 1;
                    }
                }
            }
        }
        assert!(
            count <= 1 || !is_simple(m),
            "removable skeleton voxel {i}, {ctx}"
        );
    }
    // Every empty voxel maps to a node of its own component.
    let node = nearest_node(dims, &empty, &t.skeleton);
    let (label, _) = label_components(dims, &empty, Conn::C26);
    for (i, &e) in empty.iter().enumerate() {
        if e {
            let n = node[i];
            assert_ne!(n, u32::MAX, "empty voxel {i} has no node, {ctx}");
            assert_eq!(label[t.skeleton[n as usize] as usize], label[i], "{ctx}");
        }
    }
    (before.cycles, before.cavities)
}

#[test]
fn random_layouts_keep_their_topology_from_16_to_128() {
    let (mut cycles, mut cavities) = (0, 0);
    for res in [16, 24, 32, 48, 64, 128] {
        for seed in 0..if res >= 64 { 4 } else { 12 } {
            let (c, v) = check(seed, res);
            cycles += c;
            cavities += v;
        }
    }
    // The sweep must exercise loops and floating objects, not only trees.
    assert!(
        cycles > 0 && cavities > 0,
        "cycles {cycles}, cavities {cavities}"
    );
    eprintln!("sweep: {cycles} cycles and {cavities} cavities in total");
}

#[test]
fn a_random_layout_keeps_its_topology_at_256() {
    check(7, 256);
}

#[test]
fn one_and_many_threads_give_the_same_skeleton() {
    let (dims, raw) = layout(3, 64);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .expect("pool");
    let a = one.install(|| run(dims, &raw));
    let b = four.install(|| run(dims, &raw));
    assert_eq!(a.1, b.1);
    assert_eq!(a.0, b.0);
}

#[test]
fn a_one_voxel_corridor_survives_thinning() {
    // Two rooms joined by a corridor one voxel wide and one voxel high.
    let dims = [40u32, 12, 12];
    let idx = |x: u32, y: u32, z: u32| (x + 40 * (y + 12 * z)) as usize;
    let mut e = vec![false; 40 * 12 * 12];
    for z in 1..11 {
        for y in 1..11 {
            for x in 1..39 {
                if !(12..28).contains(&x) || (y == 5 && z == 5) {
                    e[idx(x, y, z)] = true;
                }
            }
        }
    }
    let (_, t) = run(dims, &e);
    let mut skel = vec![false; e.len()];
    t.skeleton.iter().for_each(|&i| skel[i as usize] = true);
    assert_eq!(betti(dims, &skel).components, 1);
    for x in 12..28 {
        assert!(skel[idx(x, 5, 5)], "corridor voxel {x} kept");
    }
}

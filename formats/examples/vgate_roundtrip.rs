//! Benchmark: write and read a baked file with an N³ grid (default 256³).
//!
//! `cargo run --release -p visgate-formats --example vgate_roundtrip [-- N]`
//!
//! The worst case for the file: about 60 % of the voxels empty, each mapped at random to one of
//! 120 clusters (u8), so no two neighbours share a run and the grid is stored dense. A real
//! level's grid is stored as runs (`visgate inspect LEVEL.vgate` prints its size and read
//! time).

use std::time::Instant;

use visgate_formats::GeometryHash;
use visgate_formats::vgate::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: u32 = match std::env::args().nth(1) {
        Some(a) => a
            .parse()
            .map_err(|_| format!("N must be a whole number, got '{a}'"))?,
        None => 256,
    };
    if !(2..=1024).contains(&n) {
        return Err(format!("N = {n} must be in 2..=1024").into());
    }
    let grid = GridMeta {
        origin_m: [0.0; 3],
        voxel_size_m: 0.05,
        dims: [n; 3],
    };
    let voxels = grid.voxel_count().ok_or("grid too large")? as usize;
    let n_nodes = (n * n / 2).max(1);
    let nodes: Vec<SkeletonNode> = (0..n_nodes)
        .map(|i| {
            let v = [i % n, (i / n) % n, n / 2];
            SkeletonNode {
                voxel: v,
                position_m: grid.voxel_to_world(v),
                radius_m: 0.3,
            }
        })
        .collect();
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let mut vc = vec![NONE; voxels];
    for c in vc.iter_mut() {
        let r = next();
        if r % 10 < 6 {
            *c = ((r >> 40) % 120) as u32;
        }
    }
    let clusters = (0..120)
        .map(|i| Cluster {
            seed: i % 2,
            bounds_min_m: [0.0; 3],
            bounds_max_m: [1.0; 3],
        })
        .collect();
    let level = BakedLevel {
        info: BakeInfo {
            params: BakeParams::default(),
            geometry_hash: GeometryHash([0xab; 16]),
            grid,
            sight_grid: grid,
            tool_version: env!("CARGO_PKG_VERSION").into(),
        },
        topology: Topology {
            skeleton: Skeleton {
                edges: (0..n_nodes - 1).map(|i| [i, i + 1]).collect(),
                nodes,
            },
            segmented: SegmentedSkeleton {
                nodes: vec![
                    SegNode {
                        skeleton_node: 0,
                        kind: SegNodeKind::Topology,
                    },
                    SegNode {
                        skeleton_node: n_nodes - 1,
                        kind: SegNodeKind::Topology,
                    },
                ],
                edges: vec![SegEdge {
                    nodes: [0, 1],
                    path: (0..n_nodes).collect(),
                }],
            },
            node_cluster: vec![0, 1],
            clusters,
            gates: vec![],
            portals: vec![],
        },
        voxel_cluster: VoxelValues::pack(&vc),
        open: VoxelBits::from_fn(vc.len(), |i| vc[i] != NONE),
    };
    let dir = std::env::temp_dir().join(format!("visgate-roundtrip-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("level.vgate");
    let t = Instant::now();
    level.write(&path)?;
    let write_s = t.elapsed().as_secs_f64();
    let size = std::fs::metadata(&path)?.len();
    let t = Instant::now();
    let back = BakedLevel::read(&path)?;
    let read_s = t.elapsed().as_secs_f64();
    let bytes = std::fs::read(&path)?;
    let t = Instant::now();
    let _ = BakedLevel::read_header(&bytes)?;
    let header_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let _ = BakedLevel::from_bytes(&bytes)?;
    let decode_s = t.elapsed().as_secs_f64();
    println!(
        "in memory: header {header_s:.4} s, decode + validate {decode_s:.3} s, crc32 alone {:.3} s",
        crc_speed(&bytes)
    );
    let same = back == level;
    std::fs::remove_dir_all(&dir)?;
    println!(
        "{n}^3 grid: {voxels} voxels, {n_nodes} skeleton nodes; voxel_cluster {:?}",
        level.voxel_cluster.elem()
    );
    println!(
        "file {:.1} MiB; write {:.3} s; read + validate {:.3} s ({:.0} MiB/s); identical: {same}",
        size as f64 / (1 << 20) as f64,
        write_s,
        read_s,
        size as f64 / (1 << 20) as f64 / read_s
    );
    if !same {
        return Err("the level read back differs".into());
    }
    Ok(())
}

fn crc_speed(bytes: &[u8]) -> f64 {
    let t = Instant::now();
    let c = crc32fast::hash(bytes);
    std::hint::black_box(c);
    t.elapsed().as_secs_f64()
}

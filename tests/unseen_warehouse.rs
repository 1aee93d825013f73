//! A warehouse, as a user brings one: a 24 × 14 m hall 7 m high in metres, every wall, the
//! floor and the ceiling one single-sided quad, two skylights to the void, four rows of thin
//! shelving (2 cm boards on 5 cm posts, boxes on every other bay: many small cycles), a
//! mezzanine slab on columns over an office with zero-thickness walls, a door opening and a
//! desk on legs; a lamp over the aisles. Baked at 128, 256 and 512 voxels, its partition is
//! the same (the partition voxel is one size at every resolution: 18.75 cm, where the least
//! whole multiple of the 512 voxel, 14.1 cm, made 58 clusters against 201), and so is its OBJ
//! read bare; gates light its views as the reference does (README, Scenes: a warehouse).

#[path = "support/mod.rs"]
mod support;

use std::fmt::Write as _;
use std::path::Path;

use support::{gates_and_none, stderr, stdout, summary_count, visgate};

/// The hall's length (x), width (z) and height (y). [Units: m]
const HALL: [f32; 3] = [24.0, 7.0, 14.0];

/// The OBJ being written: corners and faces.
#[derive(Default)]
struct Obj {
    text: String,
    corners: usize,
}

impl Obj {
    /// A quad, counter-clockwise seen from its front.
    fn quad(&mut self, q: [[f32; 3]; 4]) {
        for [x, y, z] in q {
            writeln!(self.text, "v {x} {y} {z}").expect("write");
        }
        let c = self.corners;
        writeln!(self.text, "f {} {} {} {}", c + 1, c + 2, c + 3, c + 4).expect("write");
        self.corners += 4;
    }

    /// An axis-aligned box, its faces out.
    fn cuboid(&mut self, lo: [f32; 3], hi: [f32; 3]) {
        let ([x0, y0, z0], [x1, y1, z1]) = (lo, hi);
        self.quad([[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]]);
        self.quad([[x0, y1, z0], [x0, y1, z1], [x1, y1, z1], [x1, y1, z0]]);
        self.quad([[x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [x1, y0, z0]]);
        self.quad([[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]);
        self.quad([[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]]);
        self.quad([[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]]);
    }
}

/// The hall's shell: the floor, four walls facing in, the ceiling facing down around two
/// skylights 2 × 4 m (x 6–8 and 15–17, z 5–9).
fn shell(o: &mut Obj) {
    let [l, h, w] = HALL;
    o.quad([[0., 0., 0.], [0., 0., w], [l, 0., w], [l, 0., 0.]]);
    o.quad([[0., 0., 0.], [l, 0., 0.], [l, h, 0.], [0., h, 0.]]);
    o.quad([[0., 0., w], [0., h, w], [l, h, w], [l, 0., w]]);
    o.quad([[0., 0., 0.], [0., h, 0.], [0., h, w], [0., 0., w]]);
    o.quad([[l, 0., 0.], [l, 0., w], [l, h, w], [l, h, 0.]]);
    let xs = [0.0, 6.0, 8.0, 15.0, 17.0, l];
    for (i, pair) in xs.windows(2).enumerate() {
        let (x0, x1) = (pair[0], pair[1]);
        let spans: &[(f32, f32)] = match i % 2 {
            1 => &[(0.0, 5.0), (9.0, w)],
            _ => &[(0.0, w)],
        };
        for &(z0, z1) in spans {
            o.quad([[x0, h, z0], [x1, h, z0], [x1, h, z1], [x0, h, z1]]);
        }
    }
}

/// Four rows of shelving along x (8–22 m), 0.6 m deep and 3 m tall: posts every 2 m, five
/// boards, a box on every other bay of each board.
fn shelving(o: &mut Obj) {
    for row in 0..4 {
        let zc = 3.0 + row as f32 * 2.6;
        let (z0, z1) = (zc - 0.3, zc + 0.3);
        for k in 0..8 {
            let x = 8.0 + 2.0 * k as f32;
            for zz in [z0, z1 - 0.05] {
                o.cuboid([x, 0.0, zz], [x + 0.05, 3.0, zz + 0.05]);
            }
        }
        for level in 0..5 {
            let y = 0.15 + level as f32 * 0.7;
            o.cuboid([8.0, y, z0], [22.05, y + 0.02, z1]);
            for k in (0..7).step_by(2) {
                let x = 8.3 + 2.0 * k as f32 + 0.3 * (level % 2) as f32;
                o.cuboid([x, y + 0.02, z0 + 0.05], [x + 0.8, y + 0.5, z1 - 0.05]);
            }
        }
    }
}

/// The mezzanine (a 10 cm slab at 3 m over x, z 0–6 on three columns) and the office under
/// it: walls of single quads facing out at x = 6 and z = 6, a door opening 1 m wide with a
/// lintel, a desk on four legs.
fn mezzanine(o: &mut Obj) {
    o.cuboid([0.0, 3.0, 0.0], [6.0, 3.1, 6.0]);
    for (x, z) in [(5.7, 5.7), (5.7, 0.0), (0.0, 5.7)] {
        o.cuboid([x, 0.0, z], [x + 0.3, 3.0, z + 0.3]);
    }
    o.quad([[6., 0., 0.], [6., 0., 6.], [6., 3., 6.], [6., 3., 0.]]);
    o.quad([[0., 0., 6.], [2., 0., 6.], [2., 3., 6.], [0., 3., 6.]]);
    o.quad([[3., 0., 6.], [6., 0., 6.], [6., 3., 6.], [3., 3., 6.]]);
    o.quad([[2., 2.1, 6.], [3., 2.1, 6.], [3., 3., 6.], [2., 3., 6.]]);
    o.cuboid([1.0, 0.74, 1.0], [2.6, 0.77, 1.8]);
    for (x, z) in [(1.0, 1.0), (2.55, 1.0), (1.0, 1.75), (2.55, 1.75)] {
        o.cuboid([x, 0.0, z], [x + 0.05, 0.74, z + 0.05]);
    }
}

fn warehouse() -> String {
    let mut o = Obj::default();
    o.text.push_str("o warehouse\n");
    shell(&mut o);
    shelving(&mut o);
    mezzanine(&mut o);
    o.text
}

const SCENE: &str = r#"name = "warehouse"
up = "y"
metres_per_unit = 1.0

[[mesh]]
path = "warehouse.obj"

[[light]]
type = "point"
position = [12.0, 4.0, 5.6]
intensity = [300, 290, 270]

[[camera]]
name = "aisle"
eye = [23.0, 1.7, 4.3]
target = [8.0, 1.2, 4.3]
fov_deg = 70

[[camera]]
name = "office"
eye = [0.6, 1.6, 0.6]
target = [3.0, 1.2, 6.0]
fov_deg = 75

[[camera]]
name = "mezzanine"
eye = [1.0, 4.6, 1.0]
target = [14.0, 1.0, 9.0]
fov_deg = 70
"#;

/// warehouse.obj and warehouse.toml into `dir`.
fn write_warehouse(dir: &Path) {
    std::fs::write(dir.join("warehouse.obj"), warehouse()).expect("write warehouse.obj");
    std::fs::write(dir.join("warehouse.toml"), SCENE).expect("write warehouse.toml");
}

/// What a bake of the warehouse printed: its clusters and gates, the partition's line, and
/// its warnings.
struct Baked {
    clusters: f64,
    gates: f64,
    partition: String,
    said: String,
}

/// `file` (warehouse.toml or the bare warehouse.obj) in `dir` baked at `resolution`, into
/// `file`-`resolution`.vgate there.
fn bake(dir: &Path, file: &str, resolution: &str) -> Baked {
    let level = dir.join(format!("{}-{resolution}.vgate", file.replace('.', "-")));
    let o = visgate(&[
        "bake",
        dir.join(file).to_str().expect("utf8"),
        "-o",
        level.to_str().expect("utf8"),
        "--resolution",
        resolution,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = stdout(&o);
    let partition = (report.lines())
        .find(|l| l.starts_with("partition:"))
        .unwrap_or_else(|| panic!("no partition line:\n{report}"))
        .to_string();
    Baked {
        clusters: summary_count(&report, "clusters"),
        gates: summary_count(&report, "gates"),
        partition,
        said: stderr(&o),
    }
}

#[test]
fn a_warehouse_of_shelving_is_partitioned_alike_at_every_resolution_and_gates_light_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_warehouse(dir.path());
    // To look at it (README: a warehouse), the files written there too.
    if let Some(keep) = std::env::var_os("VISGATE_WAREHOUSE_DIR") {
        std::fs::create_dir_all(&keep).expect("VISGATE_WAREHOUSE_DIR");
        write_warehouse(Path::new(&keep));
    }

    // The partition is the level's: on 18.75 cm voxels at 128 (its own grid), 256 and 512
    // (two and four of theirs), so the same clusters and gates.
    let bakes: Vec<_> = ["128", "256", "512"]
        .iter()
        .map(|r| bake(dir.path(), "warehouse.toml", r))
        .collect();
    let coarse = &bakes[0];
    assert!(
        coarse.partition.contains("the level's grid"),
        "{}",
        coarse.partition
    );
    for b in &bakes[1..] {
        assert!(
            b.partition.contains("made on a 0.188 m grid"),
            "{}",
            b.partition
        );
        assert_eq!(
            (b.clusters, b.gates),
            (coarse.clusters, coarse.gates),
            "128 against {}",
            b.partition
        );
    }
    assert!(
        coarse.clusters > 20.0,
        "clusters at 128: {}",
        coarse.clusters
    );

    // Read bare, as a user drops the OBJ in: its metres and Y up kept, the same partition, and
    // the skylights named as openings to the outside (no light or camera says where it is).
    let bare = bake(dir.path(), "warehouse.obj", "128");
    let said = &bare.said;
    assert!(
        !said.contains("read in") && !said.contains("Z up"),
        "{said}"
    );
    assert_eq!(bare.clusters, coarse.clusters);
    assert!(
        said.matches("leak:").count() >= 2,
        "the two skylights: {said}"
    );

    let out = dir.path().join("compare");
    let level = dir.path().join("warehouse-toml-128.vgate");
    let row = gates_and_none(&dir.path().join("warehouse.toml"), &level, "96x72", &out);
    for camera in ["aisle", "mezzanine"] {
        let (energy, black) = row(camera, "gates");
        assert!(
            (0.9..=1.1).contains(&energy) && black <= 0.01,
            "{camera}: gates' indirect energy {energy}, black where lit {black}"
        );
    }
    // The office, lit through its door opening: without visibility its walls let the hall's
    // light in.
    let (office, _) = row("office", "gates");
    assert!(
        (0.9..=1.1).contains(&office),
        "office: gates' energy {office}"
    );
    let (none, _) = row("office", "none");
    assert!(none > 2.0, "none's indirect energy in the office {none}");
}

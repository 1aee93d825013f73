//! The `visgate render` command line of the methods with many settings (LightCluster, the ISM
//! modes), run as a user runs it: their passes printed, their limits enforced.

mod support;

use support::{stderr, stdout, visgate};

#[test]
fn render_lightcluster_prints_its_passes_and_clusters_and_refuses_bad_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("lc.exr");
    let out = out.to_str().expect("utf-8");
    let base = [
        "render",
        "builtin:lamp-hall",
        "--size",
        "48x32",
        "--direct",
        "lightcluster",
        "--out",
        out,
    ];
    let mut a = base.to_vec();
    a.extend(["--mode", "direct-only"]);
    let o = visgate(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    for p in [
        "light culling",
        "light clustering",
        "cluster shadow maps",
        "PCSS visibility",
        "LightCluster: 51 lights in",
    ] {
        assert!(stdout(&o).contains(p), "{p}: {}", stdout(&o));
    }
    assert!(!stdout(&o).contains("  shadow maps"), "{}", stdout(&o));
    let mut v = base.to_vec();
    v.extend(["--mode", "vpl-clusters", "--vpls", "64"]);
    let o = visgate(&v);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("VPL PCSS visibility"), "{}", stdout(&o));
    assert!(stdout(&o).contains("VPL clusters: "), "{}", stdout(&o));
    for (flag, value, says) in [
        ("--lc-max-clusters", "300", "at most 256 clusters"),
        (
            "--lc-min-distance",
            "-1",
            "minimum distance must be finite and >= 0",
        ),
        ("--lc-cutoff", "0", "range cutoff must be in (0, 1]"),
        ("--lc-map-size", "8", "cube face size 8 must be 16..=2048"),
        (
            "--pcss-blocker-samples",
            "0",
            "blocker samples 0 must be 1..=64",
        ),
    ] {
        let mut b = a.clone();
        b.extend([flag, value]);
        let o = visgate(&b);
        assert!(!o.status.success(), "{flag} {value} was taken");
        assert!(stderr(&o).contains(says), "{flag}: {}", stderr(&o));
    }
}

#[test]
fn render_ism_modes_print_the_papers_passes_and_refuse_bad_settings() {
    // `render --help` describes every mode of the registry, these two included.
    let help = visgate(&["render", "--help"]);
    for mode in ["  per-vpl-ism  GPU:", "  val-ism      GPU:"] {
        assert!(stdout(&help).contains(mode), "{mode}: {}", stdout(&help));
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("ism.exr");
    let out = out.to_str().expect("utf-8");
    let base = [
        "render",
        "builtin:cornell-box",
        "--size",
        "48x32",
        "--vpls",
        "64",
        "--ism-points",
        "512",
        "--out",
        out,
    ];
    for (mode, passes) in [
        (
            "per-vpl-ism",
            &["ISM points", "ISM atlas", "pull-push", "indirect lighting"][..],
        ),
        (
            "val-ism",
            &["VAL clustering", "ISM atlas", "pull-push", "blur + compose"][..],
        ),
    ] {
        let mut a = base.to_vec();
        // The clustering's weights as one comma list (the paper's, written out).
        a.extend(["--mode", mode, "--ism-val-weights", "0.6,0.3,0.1"]);
        let o = visgate(&a);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        for p in passes {
            assert!(stdout(&o).contains(p), "{mode} {p}: {}", stdout(&o));
        }
    }
    for (flag, value, says) in [
        (
            "--ism-map-size",
            "100",
            "ISM map size 100 must be a power of two",
        ),
        ("--ism-max-splat", "9", "max splat 9 0..=8 texels"),
        ("--ism-coverage", "0", "coverage 0 0.25..=64"),
        ("--ism-val-splat", "0", "VAL splat 0 must be > 0"),
        ("--ism-val-weights", "1,0", "gives 2 weights; give three"),
        ("--ism-val-weights", "1,x,0", "give three numbers P,N,F"),
    ] {
        let mut b = base.to_vec();
        b.extend(["--mode", "val-ism", flag, value]);
        let o = visgate(&b);
        assert!(!o.status.success(), "{flag} {value} was taken");
        assert!(stderr(&o).contains(says), "{flag}: {}", stderr(&o));
    }
}

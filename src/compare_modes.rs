//! The rows of `visgate compare`: the modes `--modes` names (gates with one setting changed
//! among them: a shape, the starved pixels' walks, the blur's fill, the walks' roulette, the
//! accurate setting), each VAL mode at every `--val-counts`, the `--variant` rows, and each
//! with LightCluster at every `--lc-min-distances`.

use anyhow::{Result, bail};
use visgate_runtime::compare::CompareMode;
use visgate_runtime::cpu::gates::GateShape;
use visgate_runtime::gpu::{DirectLight, GpuMode, METHODS, WalkRoulette, method};

use crate::settings::MethodArgs;

/// The modes `names` ask for ([`named_modes`]), each VAL mode
/// once per count of `val_counts` (labelled `val-hard-m16`, …) when it is given.
pub(crate) fn modes(
    names: &[String],
    settings: &MethodArgs,
    val_counts: &[u32],
) -> Result<Vec<CompareMode>> {
    let mut out = Vec::new();
    for m in named_modes(names, settings)? {
        if val_counts.is_empty() || !matches!(m.mode, GpuMode::ValHard(_) | GpuMode::ValCssm(..)) {
            out.push(m);
            continue;
        }
        for &count in val_counts {
            let mut mode = m.mode;
            if let GpuMode::ValHard(v) | GpuMode::ValCssm(v, _) = &mut mode {
                v.vals.count = count;
            }
            mode.check()
                .map_err(|e| anyhow::anyhow!("--val-counts {count}: {e}"))?;
            out.push(CompareMode {
                label: format!("{}-m{count}", m.label),
                mode,
                direct: m.direct,
            });
        }
    }
    Ok(out)
}

/// The rows of `--variant LABEL=MODE FLAGS…`: `command_line` (this run's) parsed again with
/// FLAGS after it, later flags replacing earlier ones, and MODE made with those settings.
pub(crate) fn variant_modes(
    variants: &[String],
    command_line: &[String],
) -> Result<Vec<CompareMode>> {
    let shape = "write LABEL=MODE [FLAGS…], e.g. --variant \"gates-2hops=gates --gate-hops 2\"";
    variants
        .iter()
        .map(|v| {
            let (label, spec) = v
                .split_once('=')
                .filter(|(l, _)| !l.trim().is_empty())
                .ok_or_else(|| anyhow::anyhow!("--variant {v:?}: {shape}"))?;
            let mut words = spec.split_whitespace().map(String::from);
            let name = words
                .next()
                .ok_or_else(|| anyhow::anyhow!("--variant {v:?}: no mode; {shape}"))?;
            let argv = command_line.iter().cloned().chain(words);
            let args = crate::compare_args_from(argv)
                .map_err(|e| anyhow::anyhow!("--variant {label}: {e}"))?;
            let mut m = named_modes(&[name], &args.method)
                .map_err(|e| anyhow::anyhow!("--variant {label}: {e}"))?
                .remove(0);
            m.label = label.trim().to_string();
            Ok(m)
        })
        .collect()
}

/// Each of `modes` with its lights' own shadow maps, then with LightCluster at each of
/// `min_distances` (labelled `-lc0.5`, …); `modes` as they are without distances.
pub(crate) fn lightcluster_modes(
    modes: Vec<CompareMode>,
    settings: &MethodArgs,
    min_distances: &[f32],
) -> Result<Vec<CompareMode>> {
    if min_distances.is_empty() {
        return Ok(modes);
    }
    let mut out = Vec::new();
    for m in modes {
        let variants = min_distances.iter().map(|&d| {
            let mut p = settings.light_cluster();
            p.clustering.min_distance_m = d;
            p.check()
                .map_err(|e| anyhow::anyhow!("--lc-min-distances {d}: {e}"))?;
            Ok(CompareMode {
                label: format!("{}-lc{d}", m.label),
                mode: m.mode,
                direct: DirectLight::LightCluster(p),
            })
        });
        let variants: Vec<CompareMode> = variants.collect::<Result<_>>()?;
        out.push(CompareMode {
            direct: DirectLight::PerLight,
            ..m
        });
        out.extend(variants);
    }
    Ok(out)
}

/// The shaped gate modes of `visgate compare`, each gates with one --gate-shape (and the voxel
/// walk with and without --closed-voxel-triangles).
const SHAPED: [(&str, GateShape, bool); 4] = [
    ("gates-voxels", GateShape::Voxels, false),
    ("gates-triangles", GateShape::Voxels, true),
    ("gates-portal", GateShape::Portal, false),
    ("gates-disk", GateShape::Disk, false),
];

/// Mode gates with its starved pixels walking what their blur block lacks, in `visgate
/// compare`: the gates' own --starved-taps, or 3/4 of the block's pixels where that is 0.
const STARVED: &str = "gates-starved";
/// Mode gates in the accurate setting (--accurate: the closed voxels' triangles, the tent
/// blur, the starved pixels' walks), in `visgate compare`; not in `all` (its frame is several
/// times the default's).
const ACCURATE: &str = "gates-accurate";
/// Mode gates in the balanced setting (--balanced, the default: the closed voxels' triangles,
/// the tent blur, the dark pixels' walks, the near field), in `visgate compare`: gates itself unless --fast
/// or --accurate; not in `all`.
const BALANCED: &str = "gates-balanced";
/// Mode gates in the fast setting (`render --fast` with the same flags: the walk with the
/// closed voxels' planes, the box blur, no dark pixels' walks, no near field unless
/// --near-field), in `visgate compare`; in `all`
/// where gates are not that already.
const FAST: &str = "gates-fast";
/// Mode gates with its blur filled from the next blocks (--blur-fill), in `visgate compare`.
const FILLED: &str = "gates-filled";
/// Mode gates with Russian roulette on its walks: the gates' own --walk-roulette, or
/// [`ROULETTE_SHARE`] where that is 0 or auto.
const ROULETTE: &str = "gates-roulette";
/// The share of a pixel's light under which gates-roulette walks a VPL by chance, unless told:
/// on the Quake level at 4,096 VPLs it made gates faster than val-hard with the indirect MSE
/// unchanged (README).
const ROULETTE_SHARE: f32 = 0.05;

/// The modes `names` ask for (`all` expanded: gates with --gate-shape, then gates-fast where
/// gates are not fast, then each other shape by its own name, then gates-filled and
/// gates-starved where gates interleave without them, gates-roulette where gates walk without
/// it;
/// `gates-voxels`, `gates-triangles`, `gates-portal` and `gates-disk` are gates with that
/// shape).
fn named_modes(names: &[String], settings: &MethodArgs) -> Result<Vec<CompareMode>> {
    let s = settings.settings();
    let shaped = |shape, triangles| {
        let mut g = s.gates;
        g.gates.shape = shape;
        g.gates.triangles = triangles;
        GpuMode::Gates(g)
    };
    // Gates with one setting changed (the starved pixels' walks, the blur's fill or the walks'
    // roulette), or in one of the three settings as `render --fast`, `--balanced`,
    // `--accurate` give them with the same flags.
    let flagged = settings.flagged_gates();
    let varied = |name: &str| {
        let mut g = s.gates;
        let il = &mut g.interleave;
        match name {
            ACCURATE => g = settings.over_setting(flagged.accurate()),
            BALANCED => g = settings.over_setting(flagged.balanced()),
            FAST => g = flagged,
            STARVED if il.starved_taps == 0 => il.starved_taps = il.three_quarters(),
            FILLED => il.fill = true,
            ROULETTE if !g.walk_roulette.is_fixed() => {
                g.walk_roulette = WalkRoulette::Share(ROULETTE_SHARE)
            }
            _ => {}
        }
        GpuMode::Gates(g)
    };
    let named = |name: &str| -> Result<CompareMode> {
        let shape = SHAPED.iter().find(|(n, ..)| *n == name);
        let mode = match (shape, method(name)) {
            (Some(&(_, g, t)), _) => shaped(g, t),
            _ if [STARVED, FILLED, ROULETTE, ACCURATE, BALANCED, FAST].contains(&name) => {
                varied(name)
            }
            (_, Some(m)) => (m.make)(&s),
            (None, None) => bail!(
                "--modes {name}: give all or some of {}, {}, {FILLED}, {STARVED}, {ROULETTE}, \
                 {FAST}, {BALANCED}, {ACCURATE}",
                METHODS.map(|m| m.name).join(", "),
                SHAPED.map(|(n, ..)| n).join(", ")
            ),
        };
        Ok(CompareMode {
            label: name.to_string(),
            mode,
            direct: settings.direct(),
        })
    };
    let mut out = Vec::new();
    for n in names {
        if n == "all" {
            for m in METHODS.iter().filter(|m| m.name != "direct-only") {
                out.push(named(m.name)?);
                if m.name == "gates" {
                    if flagged != s.gates {
                        out.push(named(FAST)?);
                    }
                    let gates = s.gates.gates;
                    let same =
                        |g, t| g == gates.shape && (g != GateShape::Voxels || t == gates.triangles);
                    for (n, g, t) in SHAPED {
                        if !same(g, t) {
                            out.push(named(n)?);
                        }
                    }
                    let il = s.gates.interleave;
                    if il.block > 1 && !il.fill {
                        out.push(named(FILLED)?);
                    }
                    if il.block > 1 && il.starved_taps == 0 {
                        out.push(named(STARVED)?);
                    }
                    if gates.shape != GateShape::Disk && !s.gates.walk_roulette.is_fixed() {
                        out.push(named(ROULETTE)?);
                    }
                }
            }
        } else {
            out.push(named(n)?);
        }
    }
    out.dedup_by(|a, b| a.label == b.label);
    if out.is_empty() {
        bail!("--modes: give at least one mode, or all");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use visgate_runtime::gpu::GatesParams;

    /// The modes `names` give with `flags` after a compare command line.
    fn modes_with(names: &str, flags: &[&str]) -> Vec<CompareMode> {
        let argv = ["visgate", "compare", "builtin:four-rooms", "--out", "x"]
            .iter()
            .chain(flags);
        let args = crate::compare_args_from(argv.map(|s| s.to_string())).expect("args");
        named_modes(&[names.to_string()], &args.method).expect("modes")
    }

    /// The mode labels `--modes all` gives with `flags` after a compare command line.
    fn all_with(flags: &[&str]) -> Vec<String> {
        modes_with("all", flags)
            .into_iter()
            .map(|m| m.label)
            .collect()
    }

    /// The gates' settings of mode `name` with `flags`.
    fn gates_of(name: &str, flags: &[&str]) -> GatesParams {
        match modes_with(name, flags)[0].mode {
            GpuMode::Gates(g) => g,
            ref m => panic!("{name} is not gates: {}", m.name()),
        }
    }

    #[test]
    fn gates_starved_walks_three_quarters_of_the_block_unless_told() {
        let taps = |flags: &[&str]| gates_of(STARVED, flags).interleave.starved_taps;
        assert_eq!(taps(&[]), 48, "8 x 8 by default");
        assert_eq!(taps(&["--interleave", "4"]), 12);
        assert_eq!(taps(&["--starved-taps", "20"]), 20);
    }

    #[test]
    fn gates_accurate_walks_the_triangles_with_the_tent_and_the_starved_pixels() {
        let g = gates_of(ACCURATE, &[]);
        assert!(g.gates.triangles && g.interleave.tent);
        assert_eq!(g.interleave.starved_taps, 48, "3/4 of 8 x 8");
        assert_eq!(g.gates.shape, GateShape::Voxels);
        let g = gates_of(ACCURATE, &["--interleave", "4", "--walk-roulette", "0.1"]);
        assert_eq!(g.interleave.starved_taps, 12);
        assert_eq!(g.walk_roulette, WalkRoulette::Share(0.1), "the rest as set");
        let g = gates_of(ACCURATE, &["--starved-taps", "20"]);
        assert_eq!(g.interleave.starved_taps, 20, "a count given is kept");
        // The same settings as `render --accurate`; not in `all`, and plain gates balanced.
        assert_eq!(
            g,
            gates_of("gates", &["--starved-taps", "20", "--accurate"])
        );
        assert!(!all_with(&[]).contains(&ACCURATE.to_string()));
        let plain = gates_of("gates", &[]);
        assert_eq!(plain.interleave.starved_taps, 0);
        assert_eq!(plain, gates_of(BALANCED, &[]));
    }

    #[test]
    fn gates_balanced_walks_the_triangles_with_the_tent_and_the_dark_pixels() {
        let g = gates_of(BALANCED, &[]);
        assert!(g.gates.triangles && g.interleave.tent && g.interleave.starved_dark);
        assert_eq!(g.interleave.starved_taps, 0, "no count of its own");
        assert_eq!(g.gates.shape, GateShape::Voxels);
        let g = gates_of(
            BALANCED,
            &["--starved-taps", "20", "--walk-roulette", "0.1"],
        );
        assert_eq!(g.interleave.starved_taps, 20, "a count given is kept");
        assert_eq!(g.walk_roulette, WalkRoulette::Share(0.1), "the rest as set");
        // The same settings as `render --balanced`, as plain gates (the default), and as
        // --starved-dark with the other two flags on the fast setting; not in `all`; the
        // accurate setting without the dark pixels' walks.
        let flags = ["--starved-taps", "20", "--walk-roulette", "0.1"];
        assert_eq!(
            g,
            gates_of("gates", &[&flags[..], &["--balanced"]].concat())
        );
        assert_eq!(g, gates_of("gates", &flags));
        let spelled = [
            "--fast",
            "--closed-voxel-triangles",
            "--blur-tent",
            "--starved-dark",
            "--near-field",
            "4",
            "--ratio",
            "--ratio-stride",
            "3",
        ];
        assert_eq!(g, gates_of("gates", &[&flags[..], &spelled].concat()));
        assert!(!all_with(&[]).contains(&BALANCED.to_string()));
        assert!(!gates_of(ACCURATE, &[]).interleave.starved_dark);
        // And back: --fast, or gates-fast, undoes the five and keeps the rest.
        assert_eq!(
            g.fast(),
            gates_of("gates", &[&flags[..], &["--fast"]].concat())
        );
        assert_eq!(g.fast(), gates_of(FAST, &flags));
        assert_eq!(gates_of("gates", &["--fast"]), GatesParams::default());
    }

    #[test]
    fn gates_fast_walks_the_planes_with_the_box_and_no_second_walks() {
        let g = gates_of(FAST, &[]);
        assert!(g.gates.planes && !g.gates.triangles);
        assert!(!g.interleave.tent && !g.interleave.starved_dark);
        assert_eq!(g.gates.shape, GateShape::Voxels);
        // In `all` beside the default, not beside gates that are fast already.
        assert!(all_with(&[]).contains(&FAST.to_string()));
        assert!(!all_with(&["--fast"]).contains(&FAST.to_string()));
        // Its row is `render --fast` with the same flags: a flag added to it counts there too.
        assert!(!all_with(&["--fast", "--blur-tent"]).contains(&FAST.to_string()));
        assert!(gates_of(FAST, &["--blur-tent"]).interleave.tent);
    }

    #[test]
    fn gates_roulette_walks_by_chance_under_a_twentieth_unless_told() {
        let share = |flags: &[&str]| gates_of(ROULETTE, flags).walk_roulette;
        assert_eq!(share(&[]), WalkRoulette::Share(ROULETTE_SHARE));
        assert_eq!(share(&["--walk-roulette", "0"]), share(&[]));
        assert_eq!(share(&["--walk-roulette", "0.2"]), WalkRoulette::Share(0.2));
    }

    #[test]
    fn all_runs_gates_once_a_shape_the_triangles_included() {
        let gates = |labels: &[String]| -> Vec<String> {
            labels
                .iter()
                .filter(|l| l.starts_with("gates-") && *l != "gates-per-pixel")
                .cloned()
                .collect()
        };
        let plain = all_with(&[]);
        assert!(plain.contains(&"gates".to_string()));
        // The default walks with the triangles: gates-voxels walks without them, and
        // gates-fast is the fast setting.
        assert_eq!(
            gates(&plain),
            [
                "gates-fast",
                "gates-voxels",
                "gates-portal",
                "gates-disk",
                "gates-filled",
                "gates-starved",
                "gates-roulette"
            ]
        );
        let fast = all_with(&["--fast"]);
        assert_eq!(
            gates(&fast),
            [
                "gates-triangles",
                "gates-portal",
                "gates-disk",
                "gates-filled",
                "gates-starved",
                "gates-roulette"
            ]
        );
        let portal = all_with(&["--fast", "--gate-shape", "portal"]);
        assert_eq!(
            gates(&portal),
            [
                "gates-voxels",
                "gates-triangles",
                "gates-disk",
                "gates-filled",
                "gates-starved",
                "gates-roulette"
            ]
        );
        // Gates starved or filled already, or not interleaved: no second row of the same.
        let has = |flags: &[&str], label: &str| all_with(flags).contains(&label.to_string());
        assert!(!has(&["--starved-taps", "16"], "gates-starved"));
        assert!(has(&["--starved-taps", "16"], "gates-filled"));
        assert!(!has(&["--blur-fill"], "gates-filled"));
        assert!(has(&["--blur-fill"], "gates-starved"));
        for label in ["gates-starved", "gates-filled"] {
            assert!(!has(&["--interleave", "1"], label), "{label}");
        }
        // Roulette: where gates walk (not with disks), and not twice.
        assert!(has(&["--interleave", "1"], "gates-roulette"));
        assert!(!has(&["--gate-shape", "disk"], "gates-roulette"));
        assert!(!has(&["--walk-roulette", "0.1"], "gates-roulette"));
    }
}

//! The report of a comparison: `report.json` (everything measured), `report.md` and
//! `report.html` (the same tables, the Pareto plot and the panels inline), `pareto.png`.

use std::fmt::Write as _;
use std::path::Path;

use super::{CompareReport, ReferenceRow, Row};
use crate::RenderError;
use crate::hdr::HdrImage;

/// The Pareto plot's file in the folder.
pub const PLOT: &str = "pareto.png";

/// Writes the report's files into `dir`.
pub fn write(report: &CompareReport, dir: &Path) -> Result<(), RenderError> {
    let put = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| RenderError::io(&p, e))
    };
    let json = serde_json::to_string_pretty(report)
        .map_err(|e| RenderError::io(&dir.join("report.json"), e))?;
    put("report.json", json)?;
    let plot = super::plot::pareto(
        &report.points,
        &report.answers,
        &format!("{}: frame time vs error", report.scene),
        report.metric.name(),
        [960, 640],
    )?;
    plot.save(dir.join(PLOT))
        .map_err(|e| RenderError::io(&dir.join(PLOT), e))?;
    put("report.md", markdown(report))?;
    put("report.html", html(report))
}

/// `x` with three significant digits in scientific notation.
fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// The pass times in a cell.
fn passes(r: &Row) -> String {
    r.passes
        .iter()
        .filter(|p| p.ms >= 0.005)
        .map(|p| format!("{} {:.2}", p.name, p.ms))
        .collect::<Vec<_>>()
        .join(" · ")
}

/// The marks of a row: on the front, the answers.
fn marks(r: &Row) -> String {
    let mut m = Vec::new();
    if r.pareto {
        m.push("◆ front".to_string());
    }
    m.extend(r.answers.iter().map(|a| format!("★ {a}")));
    m.join(", ")
}

/// Lit pixels under this share of the frame are counted beside black where lit. [Units: share]
const FEW_LIT: f64 = 0.05;

/// Black where lit, and in brackets over every pixel where the mixed ones change it; where the
/// reference lights few pixels, how many the share is of.
fn black_cell(r: &Row) -> String {
    let (b, all) = (r.black_where_lit * 100.0, r.black_where_lit_all * 100.0);
    let mut cell = format!("{b:.1} %");
    if (r.lit_pixels as f64) < FEW_LIT * r.pixels as f64 {
        cell += &format!(" of {} px", r.lit_pixels);
    }
    if format!("{b:.1}") != format!("{all:.1}") {
        cell += &format!(" ({all:.1} %)");
    }
    cell
}

/// A reference's line: its VPLs, time, rays, error against the ground truth and mixed pixels.
fn reference_text(rf: &ReferenceRow) -> String {
    let mut t = format!(
        "reference at {} VPLs: {:.2} s on the CPU, {} shadow rays",
        rf.vpl_count, rf.seconds, rf.shadow_rays
    );
    if let Some(g) = rf.ground_truth_rel_mse {
        t += &format!("; its rel. MSE against the ground truth {}", sci(g));
    }
    if let Some(map) = rf.mixed_map.as_ref().filter(|_| rf.mixed_share > 0.0) {
        t += &format!(
            "; {:.1} % of its pixels mixed, seeing several surfaces or albedos (left out of black \
             where lit; white in {map})",
            rf.mixed_share * 100.0
        );
    }
    if let Some(w) = &rf.warning {
        t += &format!(". **Warning**: {w}");
    }
    t
}

/// What a user must read about a reference of `vpls` light paths that made `vpl_count` VPLs:
/// with none, or with a black image, every method matches it to the digit and the figures
/// prove nothing (a scene whose lights or camera were written in the wrong units).
pub(super) fn reference_warning(vpls: u32, vpl_count: usize, image: &HdrImage) -> Option<String> {
    if vpls > 0 && vpl_count == 0 {
        return Some(crate::vpl::no_light_paths(
            vpls,
            "there is no indirect light to compare, and every method matches this reference to \
             the digit",
        ));
    }
    (image.mean().max_element() <= 0.0).then(|| {
        "the reference is black: nothing lit is in view, so every error is 0 and proves \
         nothing. Is the camera inside the level, facing lit geometry?"
            .to_string()
    })
}

/// The cells of a row's line, in [`HEADER`]'s order (the last only with ground truth).
fn cells(r: &Row, ground_truth: bool) -> Vec<String> {
    let mut c = vec![
        r.mode.clone(),
        r.settings.clone(),
        r.vpl_count.to_string(),
        passes(r),
        format!("{:.2}", r.total_ms),
        r.speedup.map_or("-".into(), |s| format!("{s:.1}×")),
        sci(r.mse),
        sci(r.indirect_mse),
        sci(r.rel_mse),
        format!("{:.4}", r.flip),
        format!("{:.3}", r.energy_ratio),
        black_cell(r),
    ];
    if ground_truth {
        c.push(r.ground_truth_rel_mse.map_or("-".into(), sci));
    }
    c.push(marks(r));
    c
}

const HEADER: [&str; 12] = [
    "mode",
    "settings",
    "VPLs",
    "passes (ms)",
    "total (ms)",
    "× per-VPL maps",
    "MSE",
    "indirect MSE",
    "rel. MSE",
    "FLIP",
    "indirect energy",
    "black where lit",
];

/// The header of a camera's table.
fn header(ground_truth: bool) -> Vec<String> {
    let mut h: Vec<String> = HEADER.iter().map(|s| s.to_string()).collect();
    if ground_truth {
        h.push("rel. MSE vs ground truth".into());
    }
    h.push("".into());
    h
}

/// What the figures mean, for both formats.
const LEGEND: &str = "Every method renders the very VPLs of the CPU reference (a shadow ray \
per VPL and pixel sample), so each error is the method's visibility alone (val-ism lights \
with virtual area lights made of them: its error is also the VALs' light). Times: GPU \
timestamps per pass after a warm-up frame (CPU wall time per pass where the adapter has none); \
the total is the frame. Indirect energy: the method's mean indirect light over the reference's \
(its own direct light taken out). Indirect MSE: the MSE of the image with its own direct light \
replaced by the reference's, the error of the indirect light alone (GPU shadow maps and CPU \
shadow rays differ at shadow edges alike for every method). Black where lit: of the pixels the reference lights \
indirectly at ≥ 0.1 of its mean, the share where the method gives < 0.1 of the reference, \
leaving out the pixels whose reference samples and centre see several surfaces or albedos \
tenfold apart (silhouettes, creases, sharp texels: the reference averages them where a method \
shades one point a pixel; in brackets the share \
over every pixel where they change it; dark yellow in the panels' black map; where those lit \
pixels are under 5 % of the frame, how many follows the share: in a dark view a line of pixels \
moves it by whole percents). \
◆ front: no other setting is both faster and more accurate (means over the cameras). \
× per-VPL maps: per-VPL shadow maps' frame time over this one's.";

/// The summary lines above the tables.
fn summary(r: &CompareReport) -> Vec<String> {
    let mut s = vec![
        format!("`{}`", r.command),
        format!(
            "{}×{} px, {} spp for the CPU renders, on {}; error metric of the plot and the \
             answers: {}.",
            r.size[0],
            r.size[1],
            r.spp,
            r.adapter,
            r.metric.name()
        ),
        format!(
            "{} renders made, {} read back from an earlier run.",
            r.resumed[1], r.resumed[0]
        ),
    ];
    s.extend(
        r.answers
            .iter()
            .map(|a| format!("**Answer ({})**: {}.", a.kind, a.text)),
    );
    let mut on: Vec<_> = r.points.iter().filter(|p| p.pareto).collect();
    on.sort_by(|a, b| a.ms.total_cmp(&b.ms));
    let front: Vec<String> = on
        .iter()
        .map(|p| {
            format!(
                "{} at {} VPLs ({:.2} ms, {:.3e})",
                p.mode, p.vpls, p.ms, p.error
            )
        })
        .collect();
    s.push(format!(
        "On the front, fastest first: {}.",
        front.join("; ")
    ));
    s
}

/// What the stability table means.
const STABILITY: &str = "Mean absolute frame-to-frame change of the indirect light; ratio 1: \
as steady as the reference; excess: the change that is the method's alone, over the \
reference's mean indirect light; live VALs (the VAL modes): VALs holding VPLs, mean / fewest / \
last frame of the M asked for.";

const STABILITY_HEADER: [&str; 9] = [
    "camera",
    "mode",
    "VPLs",
    "frames",
    "change",
    "reference's",
    "ratio",
    "excess",
    "live VALs",
];

/// The cells of a stability row, in [`STABILITY_HEADER`]'s order.
fn stability_cells(s: &super::StabilityRow) -> Vec<String> {
    vec![
        s.camera.clone(),
        s.mode.clone(),
        s.vpls.to_string(),
        s.frames.to_string(),
        sci(s.change),
        sci(s.reference_change),
        format!("{:.2}", s.ratio),
        format!("{:.3}", s.excess),
        s.live_vals.map_or("–".into(), |v| {
            format!("{:.1} / {} / {} of {}", v.mean, v.min, v.last, v.count)
        }),
    ]
}

fn markdown(r: &CompareReport) -> String {
    let mut md = format!("# visgate compare: {}\n\n", r.scene);
    for line in summary(r) {
        let _ = writeln!(md, "{line}\n");
    }
    let _ = writeln!(md, "![Pareto plot]({})\n\n{LEGEND}\n", PLOT);
    let gt = r.rows.iter().any(|x| x.ground_truth_rel_mse.is_some());
    for cam in &r.cameras {
        let _ = writeln!(md, "## Camera {cam}\n");
        for rf in r.references.iter().filter(|x| &x.camera == cam) {
            let _ = writeln!(md, "- {}", reference_text(rf));
        }
        let h = header(gt);
        let _ = writeln!(md, "\n| {} |", h.join(" | "));
        let _ = writeln!(md, "|{}", "---|".repeat(h.len()));
        for row in r.rows.iter().filter(|x| &x.camera == cam) {
            let _ = writeln!(md, "| {} |", cells(row, gt).join(" | "));
        }
        md.push('\n');
        for row in r.rows.iter().filter(|x| &x.camera == cam) {
            let _ = writeln!(
                md,
                "![{} at {} VPLs: reference, method, FLIP]({})\n",
                row.mode, row.vpls, row.panel
            );
        }
    }
    if !r.stability.is_empty() {
        let _ = writeln!(md, "## Temporal stability\n\n{STABILITY}\n");
        let _ = writeln!(
            md,
            "| {} |\n|{}",
            STABILITY_HEADER.join(" | "),
            "---|".repeat(STABILITY_HEADER.len())
        );
        for s in &r.stability {
            let _ = writeln!(md, "| {} |", stability_cells(s).join(" | "));
        }
        md.push('\n');
    }
    if !r.failures.is_empty() {
        md += "## Failed\n\n";
        for f in &r.failures {
            let _ = writeln!(
                md,
                "- {} at {} VPLs, camera {}: {}",
                f.mode, f.vpls, f.camera, f.error
            );
        }
    }
    md
}

/// `s` safe in HTML text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Markdown's `**x**` and `` `x` `` as HTML, the rest escaped.
fn inline(s: &str) -> String {
    let mut out = String::new();
    let (mut bold, mut code) = (false, false);
    let mut rest = esc(s);
    while let Some(i) = rest.find(['*', '`']) {
        out += &rest[..i];
        if rest[i..].starts_with("**") {
            out += if bold { "</b>" } else { "<b>" };
            bold = !bold;
            rest = rest[i + 2..].to_string();
        } else if rest[i..].starts_with('`') {
            out += if code { "</code>" } else { "<code>" };
            code = !code;
            rest = rest[i + 1..].to_string();
        } else {
            out.push('*');
            rest = rest[i + 1..].to_string();
        }
    }
    out + &rest
}

fn html(r: &CompareReport) -> String {
    let mut h = format!(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>visgate compare: {0}</title>\
         <style>body{{font-family:sans-serif;margin:2em;max-width:110em}}table{{border-collapse:\
         collapse;font-size:90%}}td,th{{border:1px solid #ccc;padding:3px 6px}}img{{max-width:\
         100%}}</style></head><body><h1>visgate compare: {0}</h1>\n",
        esc(&r.scene)
    );
    for line in summary(r) {
        let _ = writeln!(h, "<p>{}</p>", inline(&line));
    }
    let _ = writeln!(
        h,
        "<img src=\"{}\" alt=\"Pareto plot\"><p>{}</p>",
        PLOT,
        esc(LEGEND)
    );
    let gt = r.rows.iter().any(|x| x.ground_truth_rel_mse.is_some());
    for cam in &r.cameras {
        let _ = writeln!(h, "<h2>Camera {}</h2><ul>", esc(cam));
        for rf in r.references.iter().filter(|x| &x.camera == cam) {
            let _ = writeln!(h, "<li>{}</li>", esc(&reference_text(rf)));
        }
        h += "</ul><table><tr>";
        for c in header(gt) {
            let _ = write!(h, "<th>{}</th>", esc(&c));
        }
        h += "</tr>\n";
        for row in r.rows.iter().filter(|x| &x.camera == cam) {
            h += "<tr>";
            for c in cells(row, gt) {
                let _ = write!(h, "<td>{}</td>", esc(&c));
            }
            h += "</tr>\n";
        }
        h += "</table>\n";
        for row in r.rows.iter().filter(|x| &x.camera == cam) {
            let _ = writeln!(
                h,
                "<p><img src=\"{}\" alt=\"{} at {} VPLs\"></p>",
                esc(&row.panel),
                esc(&row.mode),
                row.vpls
            );
        }
    }
    if !r.stability.is_empty() {
        let _ = write!(
            h,
            "<h2>Temporal stability</h2><p>{}</p><table><tr>",
            esc(STABILITY)
        );
        for c in STABILITY_HEADER {
            let _ = write!(h, "<th>{}</th>", esc(c));
        }
        h += "</tr>\n";
        for s in &r.stability {
            let cells: Vec<String> = stability_cells(s).iter().map(|c| esc(c)).collect();
            let _ = writeln!(h, "<tr><td>{}</td></tr>", cells.join("</td><td>"));
        }
        h += "</table>\n";
    }
    if !r.failures.is_empty() {
        h += "<h2>Failed</h2><ul>";
        for f in &r.failures {
            let _ = writeln!(
                h,
                "<li>{} at {} VPLs, camera {}: {}</li>",
                esc(&f.mode),
                f.vpls,
                esc(&f.camera),
                esc(&f.error)
            );
        }
        h += "</ul>";
    }
    h + "</body></html>\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_without_light_paths_or_light_is_said_to_prove_nothing() {
        let mut lit = HdrImage::new(4, 3);
        lit.pixels
            .iter_mut()
            .for_each(|p| *p = glam::Vec3::splat(0.2));
        assert_eq!(reference_warning(256, 250, &lit), None);
        // Direct light alone (no VPLs asked) is a fair reference.
        assert_eq!(reference_warning(0, 0, &lit), None);
        let w = reference_warning(256, 0, &lit).expect("no path met the geometry");
        assert!(w.contains("0 VPLs of 256 asked"), "{w}");
        let w = reference_warning(256, 250, &HdrImage::new(4, 3)).expect("black");
        assert!(w.starts_with("the reference is black"), "{w}");
    }

    #[test]
    fn black_where_lit_says_how_many_pixels_it_is_of_where_few_are_lit() {
        let row = |lit_pixels: u64, all: f64| Row {
            camera: "door".into(),
            mode: "gates".into(),
            settings: String::new(),
            vpls: 1024,
            vpl_count: 189,
            passes: vec![],
            total_ms: 1.0,
            gpu_timed: false,
            mse: 0.0,
            indirect_mse: 0.0,
            rel_mse: 0.0,
            flip: 0.0,
            energy_ratio: 1.0,
            black_where_lit: 0.336,
            black_where_lit_all: all,
            lit_pixels,
            pixels: 76_800,
            speedup: None,
            ground_truth_rel_mse: None,
            pareto: false,
            answers: vec![],
            image: String::new(),
            panel: String::new(),
        };
        // sun-window's dark room A: a third of 1,200 pixels.
        assert_eq!(black_cell(&row(1_200, 0.387)), "33.6 % of 1200 px (38.7 %)");
        assert_eq!(black_cell(&row(1_200, 0.336)), "33.6 % of 1200 px");
        // A lit view: the share alone.
        assert_eq!(black_cell(&row(50_000, 0.387)), "33.6 % (38.7 %)");
    }
}

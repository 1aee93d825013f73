//! `visgate compare`: the report holds every table, the plot and the panels; its figures are
//! those `visgate render` + `visgate diff` give on the same settings; a second run resumes.

#[path = "../support/mod.rs"]
mod support;

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn visgate(args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_visgate"))
        .args(args)
        .env("RUST_LOG", "error")
        .output()
        .expect("runs visgate");
    assert!(
        o.status.success(),
        "visgate {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The number after `label` on its line of `text`.
fn figure(text: &str, label: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no '{label}' in:\n{text}"));
    line[label.len()..]
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number in '{line}'"))
}

/// Equal to the digits `diff` prints: six significant digits, FLIP five decimals.
fn close(a: f64, b: f64, what: &str) {
    let printed = if what == "FLIP" { 6e-6 } else { 1e-12 };
    assert!(
        (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + printed,
        "{what}: compare {a} vs render + diff {b}"
    );
}

const SETTINGS: [&str; 6] = ["--size", "48x36", "--spp", "1", "--camera", "main"];

mod modes;
mod report;

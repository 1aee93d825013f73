//! The trade-off over the cameras: each method and VPL count as one point (mean frame time,
//! mean error), the points no other beats in both, and the answers to a time budget and an
//! error bound.

use serde::Serialize;

use super::{CompareReport, CompareSpec, ErrorMetric};
use crate::gpu::GpuMode;

/// One method at one VPL count, over every camera.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// The method's label.
    pub mode: String,
    /// Light paths asked.
    pub vpls: u32,
    /// Mean frame time over the cameras. [Units: ms]
    pub ms: f64,
    /// Mean error over the cameras (the report's metric).
    pub error: f64,
    /// No other point is at least as fast and as accurate, and better in one.
    pub pareto: bool,
}

/// An answer to `--budget-ms` or `--max-error`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Answer {
    /// `budget` or `max-error`.
    pub kind: String,
    /// The bound. [Units: ms for a budget, the metric's for an error]
    pub bound: f64,
    /// The point that answers it, if any does.
    pub point: Option<Point>,
    /// The answer in words.
    pub text: String,
}

/// The points of `report`'s rows: a method and VPL count that rendered from every camera.
pub fn points(report: &CompareReport, metric: ErrorMetric) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::new();
    for r in &report.rows {
        if out.iter().any(|p| p.mode == r.mode && p.vpls == r.vpls) {
            continue;
        }
        let same: Vec<_> = report
            .rows
            .iter()
            .filter(|s| s.mode == r.mode && s.vpls == r.vpls)
            .collect();
        if same.len() != report.cameras.len() {
            continue;
        }
        let n = same.len() as f64;
        out.push(Point {
            mode: r.mode.clone(),
            vpls: r.vpls,
            ms: same.iter().map(|s| s.total_ms).sum::<f64>() / n,
            error: same.iter().map(|s| metric.of(s)).sum::<f64>() / n,
            pareto: false,
        });
    }
    front(&mut out);
    out
}

/// Marks the points that no other is at least as fast and as accurate as, and better in one.
pub fn front(points: &mut [Point]) {
    let all = points.to_vec();
    for p in points {
        p.pareto = !all
            .iter()
            .any(|q| q.ms <= p.ms && q.error <= p.error && (q.ms < p.ms || q.error < p.error));
    }
}

/// The answers to the spec's bounds among `points`.
pub fn answers(spec: &CompareSpec, points: &[Point]) -> Vec<Answer> {
    let metric = spec.metric.name();
    let mut out = Vec::new();
    if let Some(b) = spec.budget_ms {
        let best = points
            .iter()
            .filter(|p| p.ms <= b)
            .min_by(|a, c| a.error.total_cmp(&c.error));
        out.push(Answer {
            kind: "budget".into(),
            bound: b,
            point: best.cloned(),
            text: match best {
                Some(p) => format!(
                    "within {b} ms a frame, the most accurate is {} at {} VPLs: {:.2} ms, {metric} \
                     {:.3e}",
                    p.mode, p.vpls, p.ms, p.error
                ),
                None => format!(
                    "no setting renders within {b} ms a frame (the fastest takes {:.2} ms)",
                    points.iter().map(|p| p.ms).fold(f64::INFINITY, f64::min)
                ),
            },
        });
    }
    if let Some(e) = spec.max_error {
        let best = points
            .iter()
            .filter(|p| p.error <= e)
            .min_by(|a, c| a.ms.total_cmp(&c.ms));
        out.push(Answer {
            kind: "max-error".into(),
            bound: e,
            point: best.cloned(),
            text: match best {
                Some(p) => format!(
                    "with {metric} at most {e:.3e}, the fastest is {} at {} VPLs: {:.2} ms, \
                     {metric} {:.3e}",
                    p.mode, p.vpls, p.ms, p.error
                ),
                None => format!(
                    "no setting reaches {metric} {e:.3e} (the most accurate: {:.3e})",
                    points.iter().map(|p| p.error).fold(f64::INFINITY, f64::min)
                ),
            },
        });
    }
    out
}

/// Fills in the report's points, answers, each row's speed-up over per-VPL shadow maps, its
/// Pareto flag and the answers it is.
pub fn mark(report: &mut CompareReport, spec: &CompareSpec) {
    report.points = points(report, spec.metric);
    report.answers = answers(spec, &report.points);
    let per_vpl: Vec<&str> = spec
        .modes
        .iter()
        .filter(|m| matches!(m.mode, GpuMode::PerVplShadowMaps(_)))
        .map(|m| m.label.as_str())
        .collect();
    let base: Vec<(String, u32, f64)> = report
        .rows
        .iter()
        .filter(|r| per_vpl.contains(&r.mode.as_str()))
        .map(|r| (r.camera.clone(), r.vpls, r.total_ms))
        .collect();
    for r in &mut report.rows {
        r.speedup = base
            .iter()
            .find(|(c, v, _)| *c == r.camera && *v == r.vpls)
            .map(|(_, _, ms)| ms / r.total_ms.max(1e-9));
        let point = |p: &Point| p.mode == r.mode && p.vpls == r.vpls;
        r.pareto = report.points.iter().any(|p| point(p) && p.pareto);
        r.answers = report
            .answers
            .iter()
            .filter(|a| a.point.as_ref().is_some_and(point))
            .map(|a| a.kind.clone())
            .collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(mode: &str, ms: f64, error: f64) -> Point {
        Point {
            mode: mode.into(),
            vpls: 1,
            ms,
            error,
            pareto: false,
        }
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_and_the_answers_pick_from_it() {
        let mut ps = vec![
            point("fast", 1.0, 0.5),
            point("slow", 10.0, 0.01),
            point("dominated", 5.0, 0.6),
            point("tie", 1.0, 0.5),
            point("middle", 4.0, 0.1),
            point("slower and worse", 11.0, 0.01),
        ];
        front(&mut ps);
        let on: Vec<&str> = ps
            .iter()
            .filter(|p| p.pareto)
            .map(|p| p.mode.as_str())
            .collect();
        assert_eq!(on, ["fast", "slow", "tie", "middle"]);
        let spec = CompareSpec {
            scene: String::new(),
            level_key: String::new(),
            modes: Vec::new(),
            vpls: vec![1],
            cameras: Vec::new(),
            base: crate::job::RenderJob::default(),
            metric: ErrorMetric::Mse,
            budget_ms: Some(4.5),
            max_error: Some(0.2),
            ground_truth: Vec::new(),
            stability_frames: 0,
            exposure: 0.0,
            command: String::new(),
        };
        let a = answers(&spec, &ps);
        let picked: Vec<Option<&str>> = a
            .iter()
            .map(|a| a.point.as_ref().map(|p| p.mode.as_str()))
            .collect();
        assert_eq!(picked, [Some("middle"), Some("middle")]);
        let tight = CompareSpec {
            budget_ms: Some(0.5),
            max_error: Some(1e-3),
            ..spec
        };
        let none = answers(&tight, &ps);
        assert!(none.iter().all(|a| a.point.is_none()), "{none:?}");
        assert!(
            none[0].text.contains("fastest takes 1.00 ms"),
            "{}",
            none[0].text
        );
        assert!(
            none[1].text.contains("most accurate: 1.000e-2"),
            "{}",
            none[1].text
        );
    }
}

//! The sweep's table: `sweep.ron` (schema `sweep` 1, with the artifact
//! header every pipeline file carries) and the same rows as `sweep.csv`.
//!
//! Everything in it is a measurement, so the whole file is volatile:
//! times change from run to run, and so do errors wherever the reference
//! is itself a run.

use super::knobs::{Gather, Solver};
use super::pareto::Spread;
use schemas::header::{Header, Provenance, Schema};
use schemas::ron_io::RonArtifact;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The whole sweep.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Header with the sweep's provenance (command line, parameters, the
    /// prepared mesh and manifest, a foreign reference).
    pub header: Header,
    /// The scene as given (`--scene`).
    pub scene: String,
    /// Its triangles after mesh-prep.
    pub triangles: usize,
    /// What the errors are measured against.
    pub reference: Reference,
    /// The error each point reports.
    pub error_metric: String,
    /// Runs per point; each figure is the median over them.
    pub reps: usize,
    /// Stages run once for the whole sweep (mesh-prep), not in any total.
    pub shared: Vec<StageTime>,
    /// One row per (solver, gather mode, knob setting).
    pub points: Vec<Point>,
    /// Anything else worth knowing about the sweep.
    pub notes: Vec<String>,
}

impl Schema for Sweep {
    const NAME: &'static str = "sweep";
    const VERSION: u32 = 1;
}

impl RonArtifact for Sweep {
    fn provenance(&self) -> &Provenance {
        &self.header.provenance
    }
}

/// The kind of reference, in the order the sweep looks for one.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceKind {
    /// The scene's radiosity per element in closed form (integrating
    /// sphere); errors are the solutions' per triangle.
    ClosedForm,
    /// The `exact` stage's image (paper 002: Lambert's formula and
    /// quadrature, to a stated bound), for the scenes it can solve;
    /// errors are the images'.
    Exact,
    /// An EXR image given with `--reference` (another renderer's, say);
    /// errors are the images'.
    ForeignExr,
    /// A run of the pipeline at settings stricter than every point's: not
    /// converged truth, only the best this sweep can afford.
    StrictestRun,
}

/// The reference of a sweep.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Its kind.
    pub kind: ReferenceKind,
    /// One line saying what it is, as the plot's title shows it.
    pub label: String,
    /// The reference file the points were compared with.
    pub file: String,
    /// For a strictest run: what ran, and its time.
    pub run: Option<ReferenceRun>,
}

/// The settings and cost of a strictest-run reference.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReferenceRun {
    /// Its solver.
    pub solver: Solver,
    /// Its gather mode.
    pub gather: Gather,
    /// Every knob it set.
    pub knobs: Vec<KnobValue>,
    /// Its stages' times, seconds (one run).
    pub stages: Vec<StageTime>,
}

/// A knob's value at a point.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct KnobValue {
    /// The Makefile's name, e.g. `EPS`.
    pub name: String,
    /// Its value.
    pub value: f64,
}

/// The time of one stage over a point's repetitions.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StageTime {
    /// The stage binary, e.g. `hierarchical-solve`.
    pub stage: String,
    /// Its reported wall time, seconds.
    pub seconds: Spread,
}

/// One point of the sweep: a solver, a gather mode and a knob setting.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// The solver.
    pub solver: Solver,
    /// The gather mode.
    pub gather: Gather,
    /// The swept knobs' values.
    pub knobs: Vec<KnobValue>,
    /// Each stage of the point, in pipeline order (cluster, solve, gather).
    pub stages: Vec<StageTime>,
    /// Per run, the sum of the point's stages; median and range over runs.
    pub total_s: Spread,
    /// The error against the reference; median and range over runs.
    pub error: Spread,
    /// The worst surface: the largest relative difference of an object's
    /// mean luminance from the reference's (`compare`'s per-object mean
    /// signed error, taken absolute); median and range over runs. None
    /// where the errors are per element (a closed form), and in tables
    /// written before it was measured.
    #[serde(default)]
    pub worst_surface: Option<Spread>,
    /// Whether no other point of the sweep is both faster and more
    /// accurate (median time and error).
    pub pareto: bool,
    /// The directory holding the point's runs.
    pub runs: String,
}

impl Point {
    /// The median time of the stage that plays `role` in the pipeline:
    /// `cluster`, `solve` (the point's solver stage) or `gather`.
    pub fn stage_median(&self, role: &str) -> Option<f64> {
        let wanted = |stage: &str| match role {
            "cluster" => stage == "cluster",
            "solve" => stage == self.solver.stage(),
            "gather" => stage == "grid-gather",
            _ => false,
        };
        self.stages.iter().find(|s| wanted(&s.stage)).map(|s| s.seconds.median)
    }

    /// The point's value of knob `name`.
    pub fn knob(&self, name: &str) -> Option<f64> {
        self.knobs.iter().find(|k| k.name == name).map(|k| k.value)
    }
}

impl Sweep {
    /// The table as CSV: one row per point; a column per knob swept in
    /// any point (empty where a point's solver does not have it), the
    /// median time of cluster, solve and gather (seconds; cluster empty
    /// where it did not run), the total, the error and the worst surface
    /// with their ranges (the worst surface empty where it is not
    /// measured), the Pareto flag and the reference's label.
    pub fn csv(&self) -> String {
        let mut knobs: Vec<&str> = Vec::new();
        for p in &self.points {
            for k in &p.knobs {
                if !knobs.contains(&k.name.as_str()) {
                    knobs.push(&k.name);
                }
            }
        }
        let mut out = String::from("solver,gather");
        for k in &knobs {
            let _ = write!(out, ",{k}");
        }
        out += ",cluster_s,solve_s,gather_s,total_s,total_min_s,total_max_s,error,error_min,error_max,worst_surface,worst_surface_min,worst_surface_max,pareto,reference\n";
        // Knob values as given; seconds to the microsecond, errors to 7
        // significant digits (the RON keeps every digit).
        let cell = |v: Option<f64>| v.map(|v| format!("{v}")).unwrap_or_default();
        let time = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
        let error = |v: f64| format!("{v:.6e}");
        let worst = |p: &Point, f: fn(&Spread) -> f64| p.worst_surface.as_ref().map(|w| error(f(w))).unwrap_or_default();
        for p in &self.points {
            let _ = write!(out, "{},{}", p.solver, p.gather);
            for k in &knobs {
                let _ = write!(out, ",{}", cell(p.knob(k)));
            }
            let _ = writeln!(
                out,
                ",{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
                time(p.stage_median("cluster")),
                time(p.stage_median("solve")),
                time(p.stage_median("gather")),
                time(Some(p.total_s.median)),
                time(Some(p.total_s.min)),
                time(Some(p.total_s.max)),
                error(p.error.median),
                error(p.error.min),
                error(p.error.max),
                worst(p, |w| w.median),
                worst(p, |w| w.min),
                worst(p, |w| w.max),
                p.pareto,
                self.reference.label.replace('"', "\"\"")
            );
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(solver: Solver, knobs: &[(&str, f64)], stages: &[(&str, f64)], error: f64) -> Point {
        let once = |v: f64| Spread { median: v, min: v, max: v };
        Point {
            solver,
            gather: Gather::Preview,
            knobs: knobs.iter().map(|(n, v)| KnobValue { name: n.to_string(), value: *v }).collect(),
            stages: stages.iter().map(|(n, t)| StageTime { stage: n.to_string(), seconds: once(*t) }).collect(),
            total_s: once(stages.iter().map(|s| s.1).sum()),
            error: once(error),
            worst_surface: (solver == Solver::Hierarchical).then(|| once(error / 10.0)),
            pareto: true,
            runs: String::new(),
        }
    }

    #[test]
    fn the_csv_has_a_column_per_knob_and_empty_cells_where_a_point_lacks_one() {
        let sweep = Sweep {
            header: Sweep::header(Provenance::in_memory("test")),
            scene: "cornell".into(),
            triangles: 46,
            reference: Reference { kind: ReferenceKind::StrictestRun, label: "reference: strictest run (not converged truth)".into(), file: String::new(), run: None },
            error_metric: String::new(),
            reps: 1,
            shared: Vec::new(),
            points: vec![
                point(Solver::Hierarchical, &[("EPS", 0.001)], &[("cluster", 0.5), ("hierarchical-solve", 1.0), ("grid-gather", 2.0)], 0.25),
                point(Solver::Gpu, &[("GPU_CONVERGENCE", 0.99)], &[("gpu-shoot", 4.0), ("grid-gather", 2.0)], 0.125),
            ],
            notes: Vec::new(),
        };
        let csv = sweep.csv();
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows[0], "solver,gather,EPS,GPU_CONVERGENCE,cluster_s,solve_s,gather_s,total_s,total_min_s,total_max_s,error,error_min,error_max,worst_surface,worst_surface_min,worst_surface_max,pareto,reference");
        assert_eq!(rows[1], "hierarchical,preview,0.001,,0.500000,1.000000,2.000000,3.500000,3.500000,3.500000,2.500000e-1,2.500000e-1,2.500000e-1,2.500000e-2,2.500000e-2,2.500000e-2,true,\"reference: strictest run (not converged truth)\"");
        assert!(rows[2].starts_with("gpu,preview,,0.99,,4.000000,2.000000,6.000000,"), "{}", rows[2]);
        // A point whose worst surface was not measured has empty cells.
        assert!(rows[2].ends_with("1.250000e-1,,,,true,\"reference: strictest run (not converged truth)\""), "{}", rows[2]);
        // The table reads back through its schema.
        let text = schemas::ron_io::to_ron_text(&sweep);
        let back: Sweep = schemas::ron_io::parse_ron(std::path::Path::new("sweep.ron"), &text).unwrap();
        assert_eq!(back, sweep);
    }
}

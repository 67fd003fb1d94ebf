//! The benchmark's table (paper 002's Tables 2 and 3 in shape): what one
//! run measured ([`RunFigures`]), which hierarchical-solve runs stand
//! beside structured sampling ([`select`]: same speed, same quality, fewest
//! samples per surface for structured sampling's figure), and the table
//! as RON (schema `bench-structured` 1), CSV and printed text.
//!
//! Everything in it is a measurement, so the whole file is volatile.

use crate::sweep::knobs::Solver;
use schemas::header::{Header, Provenance, Schema};
use schemas::ron_io::RonArtifact;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The benchmark of one scene.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Bench {
    /// Header with the benchmark's provenance.
    pub header: Header,
    /// The scene as given.
    pub scene: String,
    /// What the errors are measured against, one line.
    pub reference: String,
    /// The tolerances measured: a pixel is "over tau" when its luminance
    /// differs from the reference's by more than tau of the reference's.
    pub taus: Vec<f64>,
    /// Every run: structured sampling first, then hierarchical-solve's.
    pub runs: Vec<RunFigures>,
    /// One comparison per tau quality is compared at.
    pub comparisons: Vec<Comparison>,
    /// Anything else worth knowing.
    pub notes: Vec<String>,
}

/// Structured sampling and the runs chosen beside it, with quality
/// compared at one tau (paper 002: 10% on the simple environment, Table 2;
/// 15% on the moderate scene, Table 3).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Comparison {
    /// The tau quality is compared at.
    pub quality_tau: f64,
    /// The rows: structured sampling, then the runs chosen ([`select`]).
    pub rows: Vec<Row>,
    /// The claims measured, one line each.
    pub findings: Vec<String>,
}

impl Schema for Bench {
    const NAME: &'static str = "bench-structured";
    const VERSION: u32 = 1;
}

impl RonArtifact for Bench {
    fn provenance(&self) -> &Provenance {
        &self.header.provenance
    }
}

/// The share of pixels over one tau.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OverTau {
    /// The tolerance, a fraction.
    pub tau: f64,
    /// Percent of the measured pixels over it.
    pub percent: f64,
}

/// One named time, seconds.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    /// A stage, or a phase a stage's report times (`stage/phase`).
    pub name: String,
    /// Seconds.
    pub seconds: f64,
}

/// A surface (one or more objects of the scene) in one run.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceFigures {
    /// The surface's name (`A`, `B`, `walls`, ...).
    pub name: String,
    /// Its pixels measured (emitters and edges left out).
    pub pixels: usize,
    /// Percent of those pixels over each tau.
    pub over_tau: Vec<OverTau>,
    /// structured-sample: its samples there; hierarchical-solve: its leaf
    /// elements there.
    pub samples: usize,
    /// hierarchical-solve: the distinct corners of its leaf elements there
    /// (the points a Gouraud display interpolates, paper 002's "element
    /// vertices").
    pub vertices: Option<usize>,
    /// structured-sample: its secondary emitter polygons there.
    pub emitters: Option<usize>,
}

impl SurfaceFigures {
    /// Percent over `tau`, if measured.
    pub fn over(&self, tau: f64) -> Option<f64> {
        percent_at(&self.over_tau, tau)
    }

    /// The count comparable across solvers: structured sampling's samples,
    /// hierarchical-solve's element vertices (paper 002 Table 2 sets them
    /// side by side).
    pub fn display_points(&self) -> usize {
        self.vertices.unwrap_or(self.samples)
    }
}

fn percent_at(over: &[OverTau], tau: f64) -> Option<f64> {
    over.iter().find(|o| o.tau == tau).map(|o| o.percent)
}

/// What one run measured.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunFigures {
    /// The solver.
    pub solver: Solver,
    /// Its setting, e.g. `EPS=0.001`.
    pub setting: String,
    /// Percent of the image's measured pixels over each tau.
    pub image: Vec<OverTau>,
    /// Per surface.
    pub surfaces: Vec<SurfaceFigures>,
    /// Each stage's time and the phases its report times, seconds.
    pub phases: Vec<Phase>,
    /// Time of the light's transfer from the sources to the first
    /// receivers (paper 002's "LS -> A"), where the solver's report
    /// separates it.
    pub light_to_a_s: Option<f64>,
    /// Time of the transfer between surfaces (paper 002's "A -> B"), where
    /// the report separates it.
    pub a_to_b_s: Option<f64>,
    /// The sum of the run's stages' times (the picture's cost).
    pub total_s: f64,
    /// Where the run's files are.
    pub dir: String,
}

impl RunFigures {
    /// Percent of the image over `tau`, if measured.
    pub fn over(&self, tau: f64) -> Option<f64> {
        percent_at(&self.image, tau)
    }

    /// The surface named `name`.
    pub fn surface(&self, name: &str) -> Option<&SurfaceFigures> {
        self.surfaces.iter().find(|s| s.name == name)
    }
}

/// What a row of the comparison stands for.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub enum Role {
    /// Structured sampling.
    Structured,
    /// The hierarchical-solve run whose total time is nearest structured
    /// sampling's (by ratio).
    SameSpeed,
    /// The fastest hierarchical-solve run whose share of image pixels over
    /// the quality tau is at most structured sampling's.
    SameQuality,
    /// The hierarchical-solve run with the fewest element vertices on a
    /// surface among those whose share of that surface's pixels over the
    /// quality tau is at most structured sampling's there.
    FewestOn(String),
}

impl Role {
    /// The column heading.
    pub fn heading(&self) -> String {
        match self {
            Role::Structured => "structured".into(),
            Role::SameSpeed => "same speed".into(),
            Role::SameQuality => "same quality".into(),
            Role::FewestOn(surface) => format!("same on {surface}"),
        }
    }
}

/// One row of the comparison.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Row {
    /// What the row stands for.
    pub role: Role,
    /// The run (index into [`Bench::runs`]); `None` when no swept run
    /// qualifies.
    pub run: Option<usize>,
}

/// The comparison rows and the claims measured, from the runs: structured
/// sampling's run (the first of its solver) against hierarchical-solve's
/// runs at the same speed, at the same quality over the whole image, and
/// for each surface at the same quality there with the fewest element
/// vertices (paper 002's "fewer samples on B"). Returns no row for a
/// role no run qualifies for, with a finding saying so.
pub fn select(runs: &[RunFigures], quality_tau: f64) -> Comparison {
    let Some(s) = runs.iter().position(|r| r.solver == Solver::Structured) else {
        return Comparison { quality_tau, rows: Vec::new(), findings: vec!["no structured-sample run".into()] };
    };
    let structured = &runs[s];
    let others: Vec<usize> = (0..runs.len()).filter(|&i| runs[i].solver == Solver::Hierarchical).collect();
    let mut rows = vec![Row { role: Role::Structured, run: Some(s) }];
    let mut findings = Vec::new();
    let tau = percent_label(quality_tau);

    let ratio = |i: usize| (runs[i].total_s / structured.total_s).ln().abs();
    let same_speed = others.iter().copied().filter(|&i| ratio(i).is_finite()).min_by(|&a, &b| ratio(a).total_cmp(&ratio(b)));
    rows.push(Row { role: Role::SameSpeed, run: same_speed });
    if let Some(i) = same_speed {
        let (a, b) = (structured.over(quality_tau), runs[i].over(quality_tau));
        findings.push(format!(
            "same speed: hierarchical-solve {} in {:.3} s (structured {:.3} s) has {} of the image's pixels over {tau}, structured sampling {}",
            runs[i].setting,
            runs[i].total_s,
            structured.total_s,
            percent_text(b),
            percent_text(a)
        ));
    }

    let target = structured.over(quality_tau);
    let qualifying = |figure: &dyn Fn(&RunFigures) -> Option<f64>, target: Option<f64>| -> Vec<usize> {
        others.iter().copied().filter(|&i| matches!((figure(&runs[i]), target), (Some(f), Some(t)) if f <= t)).collect()
    };
    let same_quality = qualifying(&|r| r.over(quality_tau), target).into_iter().min_by(|&a, &b| runs[a].total_s.total_cmp(&runs[b].total_s));
    rows.push(Row { role: Role::SameQuality, run: same_quality });
    findings.push(match same_quality {
        Some(i) => format!(
            "same quality ({} over {tau}): hierarchical-solve {} takes {:.3} s, {:.2}x structured sampling's {:.3} s",
            percent_text(target),
            runs[i].setting,
            runs[i].total_s,
            runs[i].total_s / structured.total_s,
            structured.total_s
        ),
        None => format!("same quality: no hierarchical-solve run swept has at most {} of the image over {tau}{}", percent_text(target), best_text(runs, &others, &|r| r.over(quality_tau))),
    });

    for surface in &structured.surfaces {
        let name = surface.name.clone();
        let figure = |r: &RunFigures| r.surface(&name).and_then(|f| f.over(quality_tau));
        let points = |i: usize| runs[i].surface(&name).map_or(usize::MAX, SurfaceFigures::display_points);
        let fewest = qualifying(&figure, surface.over(quality_tau)).into_iter().min_by_key(|&i| (points(i), (runs[i].total_s * 1e9) as u64));
        rows.push(Row { role: Role::FewestOn(name.clone()), run: fewest });
        findings.push(match fewest {
            Some(i) => {
                let theirs = runs[i].surface(&name).expect("a qualifying run has the surface");
                let verdict = if surface.samples < theirs.display_points() { "fewer samples for structured sampling" } else { "not fewer samples for structured sampling" };
                format!(
                    "{name}: structured sampling has {} over {tau} with {} samples; the hierarchical-solve run swept with the fewest element vertices there at most that has {} ({} leaves, {}): {verdict}",
                    percent_text(surface.over(quality_tau)),
                    surface.samples,
                    theirs.display_points(),
                    theirs.samples,
                    runs[i].setting
                )
            }
            None => format!(
                "{name}: no hierarchical-solve run swept has at most {} of {name}'s pixels over {tau} (structured sampling, {} samples){}",
                percent_text(surface.over(quality_tau)),
                surface.samples,
                best_text(runs, &others, &figure)
            ),
        });
    }
    Comparison { quality_tau, rows, findings }
}

/// `; the best swept, <setting>, has <p>` for the runs `among`, or nothing.
fn best_text(runs: &[RunFigures], among: &[usize], figure: &dyn Fn(&RunFigures) -> Option<f64>) -> String {
    among
        .iter()
        .filter_map(|&i| figure(&runs[i]).map(|f| (i, f)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or_else(String::new, |(i, f)| format!("; the best swept, {}, has {}", runs[i].setting, percent_text(Some(f))))
}

/// A tau as a percentage: `10%`, `15%`, `2.5%`.
pub fn percent_label(tau: f64) -> String {
    let text = format!("{:.3}", 100.0 * tau);
    format!("{}%", text.trim_end_matches('0').trim_end_matches('.'))
}

fn percent_text(p: Option<f64>) -> String {
    p.map_or_else(|| "-".into(), |p| format!("{p:.2}%"))
}

impl Bench {
    /// The benchmark as printed text: per comparison, one column per row
    /// (paper 002's Tables 2 and 3 turned on their side), one line per
    /// figure, then its findings; the notes last.
    pub fn text(&self) -> String {
        let mut out = format!("{}: {}\n", self.scene, self.reference);
        for comparison in &self.comparisons {
            let _ = writeln!(out, "\nquality compared at tau = {}:", percent_label(comparison.quality_tau));
            out += &self.table_text(&comparison.rows);
            for line in &comparison.findings {
                let _ = writeln!(out, "- {line}");
            }
        }
        if !self.notes.is_empty() {
            out.push('\n');
        }
        for line in &self.notes {
            let _ = writeln!(out, "- {line}");
        }
        out
    }

    /// The figures of `rows`' runs, aligned, with a heading line.
    fn table_text(&self, rows: &[Row]) -> String {
        let columns: Vec<(String, Option<&RunFigures>)> = rows.iter().map(|r| (r.role.heading(), r.run.map(|i| &self.runs[i]))).collect();
        let mut lines: Vec<(String, Vec<String>)> = Vec::new();
        let cell = |f: &dyn Fn(&RunFigures) -> String| columns.iter().map(|(_, r)| r.map_or_else(|| "none".into(), f)).collect::<Vec<_>>();
        lines.push(("run".into(), cell(&|r| r.setting.clone())));
        for &tau in &self.taus {
            lines.push((format!("% px > {} (image)", percent_label(tau)), cell(&|r| percent_cell(r.over(tau)))));
        }
        let surfaces = self.surface_names();
        for name in &surfaces {
            for &tau in &self.taus {
                lines.push((format!("% px > {} ({name})", percent_label(tau)), cell(&|r| percent_cell(r.surface(name).and_then(|s| s.over(tau))))));
            }
        }
        for name in &surfaces {
            lines.push((format!("samples {name}"), cell(&|r| r.surface(name).map_or_else(|| "-".into(), samples_cell))));
        }
        let seconds = |v: Option<f64>| v.map_or_else(|| "not split".into(), |v| format!("{v:.3}"));
        lines.push(("time direct, light->A (s)".into(), cell(&|r| seconds(r.light_to_a_s))));
        lines.push(("time reflected, A->B (s)".into(), cell(&|r| seconds(r.a_to_b_s))));
        lines.push(("time total (s)".into(), cell(&|r| format!("{:.3}", r.total_s))));

        let label_width = lines.iter().map(|(l, _)| l.len()).max().unwrap_or(0);
        let widths: Vec<usize> =
            columns.iter().enumerate().map(|(c, (heading, _))| lines.iter().map(|(_, cells)| cells[c].len()).chain([heading.len()]).max().unwrap_or(0)).collect();
        let mut out = format!("{:label_width$}", "");
        for ((heading, _), w) in columns.iter().zip(&widths) {
            let _ = write!(out, "  {heading:>w$}");
        }
        out.push('\n');
        for (label, cells) in &lines {
            let _ = write!(out, "{label:label_width$}");
            for (c, w) in cells.iter().zip(&widths) {
                let _ = write!(out, "  {c:>w$}");
            }
            out.push('\n');
        }
        out
    }

    /// The surfaces' names, as the first run has them.
    fn surface_names(&self) -> Vec<String> {
        self.runs.first().map(|r| r.surfaces.iter().map(|s| s.name.clone()).collect()).unwrap_or_default()
    }

    /// Every run as CSV: solver, setting, the roles it plays (`role@tau`,
    /// `;`-separated), percent over
    /// each tau (image, then each surface), per surface samples, element
    /// vertices and secondary emitters (empty where the solver has none),
    /// the light-to-A, A-to-B and total times (empty where not split), and
    /// every phase as `name=seconds` separated by spaces (names have none).
    pub fn csv(&self) -> String {
        let surfaces = self.surface_names();
        let mut out = String::from("solver,setting,roles");
        for &tau in &self.taus {
            let _ = write!(out, ",image_over_{tau}");
        }
        for name in &surfaces {
            for &tau in &self.taus {
                let _ = write!(out, ",{name}_over_{tau}");
            }
            let _ = write!(out, ",{name}_samples,{name}_vertices,{name}_emitters");
        }
        out += ",light_to_a_s,a_to_b_s,total_s,phases\n";
        let option = |v: Option<f64>, digits: usize| v.map_or_else(String::new, |v| format!("{v:.digits$}"));
        for (i, r) in self.runs.iter().enumerate() {
            let roles: Vec<String> = self
                .comparisons
                .iter()
                .flat_map(|c| c.rows.iter().filter(|row| row.run == Some(i)).map(|row| format!("{}@{}", row.role.heading(), percent_label(c.quality_tau))))
                .collect();
            let _ = write!(out, "{},{},{}", r.solver, r.setting, roles.join(";"));
            for &tau in &self.taus {
                let _ = write!(out, ",{}", option(r.over(tau), 4));
            }
            for name in &surfaces {
                let s = r.surface(name);
                for &tau in &self.taus {
                    let _ = write!(out, ",{}", option(s.and_then(|s| s.over(tau)), 4));
                }
                let count = |v: Option<usize>| v.map_or_else(String::new, |v| v.to_string());
                let _ = write!(out, ",{},{},{}", count(s.map(|s| s.samples)), count(s.and_then(|s| s.vertices)), count(s.and_then(|s| s.emitters)));
            }
            let phases: Vec<String> = r.phases.iter().map(|p| format!("{}={:.6}", p.name, p.seconds)).collect();
            let _ = writeln!(out, ",{},{},{:.6},{}", option(r.light_to_a_s, 6), option(r.a_to_b_s, 6), r.total_s, phases.join(" "));
        }
        out
    }
}

fn percent_cell(p: Option<f64>) -> String {
    p.map_or_else(|| "-".into(), |p| format!("{p:.2}"))
}

/// `48 (4 polys)` for structured sampling, `100 v (64 el)` for
/// hierarchical-solve.
fn samples_cell(s: &SurfaceFigures) -> String {
    match (s.vertices, s.emitters) {
        (Some(v), _) => format!("{v} v ({} el)", s.samples),
        (None, Some(e)) => format!("{} ({e} polys)", s.samples),
        (None, None) => s.samples.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface(name: &str, over10: f64, samples: usize, vertices: Option<usize>) -> SurfaceFigures {
        SurfaceFigures { name: name.into(), pixels: 100, over_tau: vec![OverTau { tau: 0.1, percent: over10 }], samples, vertices, emitters: vertices.is_none().then_some(4) }
    }

    fn run(solver: Solver, setting: &str, image: f64, a: (f64, usize), b: (f64, usize), total_s: f64) -> RunFigures {
        let hier = solver == Solver::Hierarchical;
        // Hierarchical: leaves are half the vertices (any fixed relation will do).
        let vertices = |n: usize| hier.then_some(n);
        let count = |n: usize| if hier { n / 2 } else { n };
        RunFigures {
            solver,
            setting: setting.into(),
            image: vec![OverTau { tau: 0.1, percent: image }],
            surfaces: vec![surface("A", a.0, count(a.1), vertices(a.1)), surface("B", b.0, count(b.1), vertices(b.1))],
            phases: vec![Phase { name: "x".into(), seconds: total_s }],
            light_to_a_s: (!hier).then_some(0.25 * total_s),
            a_to_b_s: (!hier).then_some(0.5 * total_s),
            total_s,
            dir: String::new(),
        }
    }

    /// Structured: 1.5% of the image, A 2% with 48 samples, B 0.5% with 10,
    /// 1 s. Hierarchical runs, coarse to fine.
    fn runs() -> Vec<RunFigures> {
        vec![
            run(Solver::Structured, "STRUCTURED_LEVELS=8", 1.5, (2.0, 48), (0.5, 10), 1.0),
            run(Solver::Hierarchical, "EPS=0.01", 9.0, (8.0, 20), (0.4, 8), 0.5),
            run(Solver::Hierarchical, "EPS=0.003", 3.0, (3.0, 60), (0.5, 16), 1.5),
            run(Solver::Hierarchical, "EPS=0.001", 1.0, (1.9, 100), (0.1, 36), 4.0),
            run(Solver::Hierarchical, "EPS=0.0003", 0.5, (0.5, 400), (0.0, 100), 12.0),
        ]
    }

    #[test]
    fn the_rows_are_the_nearest_time_the_fastest_at_least_as_good_and_the_fewest_vertices_per_surface() {
        let runs = runs();
        let Comparison { rows, findings, .. } = select(&runs, 0.1);
        let of = |role: Role| rows.iter().find(|r| r.role == role).unwrap().run;
        assert_eq!(of(Role::Structured), Some(0));
        assert_eq!(of(Role::SameSpeed), Some(2), "1.5 s is nearer 1 s by ratio than 0.5 s");
        assert_eq!(of(Role::SameQuality), Some(3), "the fastest with image <= 1.5%");
        assert_eq!(of(Role::FewestOn("A".into())), Some(3), "A <= 2%: EPS 0.001 (100 v) and 0.0003 (400 v)");
        assert_eq!(of(Role::FewestOn("B".into())), Some(1), "B <= 0.5%: 8 vertices at EPS 0.01 are the fewest");
        assert_eq!(findings.len(), 4);
        assert!(findings[1].contains("EPS=0.001 takes 4.000 s, 4.00x"), "{}", findings[1]);
        assert!(findings[2].contains("48 samples") && findings[2].contains("at most that has 100 (50 leaves, EPS=0.001)") && findings[2].ends_with(": fewer samples for structured sampling"), "{}", findings[2]);
        assert!(findings[3].contains("at most that has 8 (4 leaves, EPS=0.01)") && findings[3].ends_with("not fewer samples for structured sampling"), "{}", findings[3]);
    }

    #[test]
    fn a_role_no_run_qualifies_for_has_no_run_and_a_finding_naming_the_best() {
        let mut runs = runs();
        runs.truncate(3);
        let Comparison { rows, findings, .. } = select(&runs, 0.1);
        assert_eq!(rows.iter().find(|r| r.role == Role::SameQuality).unwrap().run, None);
        assert!(findings[1].contains("no hierarchical-solve run swept has at most 1.50%") && findings[1].ends_with("the best swept, EPS=0.003, has 3.00%"), "{}", findings[1]);
        // Not measured at the quality tau: nothing qualifies.
        let rows = select(&runs, 0.15).rows;
        assert!(rows.iter().filter(|r| r.role != Role::Structured && r.role != Role::SameSpeed).all(|r| r.run.is_none()));
    }

    #[test]
    fn the_table_prints_one_column_per_row_and_the_csv_one_line_per_run() {
        let runs = runs();
        let comparisons = vec![select(&runs, 0.1)];
        let bench = Bench {
            header: Bench::header(Provenance::in_memory("test")),
            scene: "simple-environment".into(),
            reference: "reference: exact image".into(),
            taus: vec![0.1],
            runs,
            comparisons,
            notes: vec!["a note".into()],
        };
        let text = bench.text();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[..3], ["simple-environment: reference: exact image", "", "quality compared at tau = 10%:"]);
        let words = |l: &str| l.split("  ").map(str::trim).filter(|w| !w.is_empty()).map(String::from).collect::<Vec<_>>();
        assert_eq!(words(lines[3]), ["structured", "same speed", "same quality", "same on A", "same on B"]);
        assert_eq!(words(lines[4]), ["run", "STRUCTURED_LEVELS=8", "EPS=0.003", "EPS=0.001", "EPS=0.001", "EPS=0.01"]);
        assert_eq!(words(lines[5]), ["% px > 10% (image)", "1.50", "3.00", "1.00", "1.00", "9.00"]);
        assert_eq!(words(lines[7]), ["% px > 10% (B)", "0.50", "0.50", "0.10", "0.10", "0.40"]);
        assert_eq!(words(lines[8]), ["samples A", "48 (4 polys)", "60 v (30 el)", "100 v (50 el)", "100 v (50 el)", "20 v (10 el)"]);
        assert_eq!(words(lines[10]), ["time direct, light->A (s)", "0.250", "not split", "not split", "not split", "not split"]);
        assert_eq!(words(lines[12]), ["time total (s)", "1.000", "1.500", "4.000", "4.000", "0.500"]);
        assert!(lines[13].starts_with("- same speed: hierarchical-solve EPS=0.003"), "{}", lines[13]);
        assert_eq!(lines.last().copied(), Some("- a note"));

        let csv = bench.csv();
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows.len(), 6);
        assert_eq!(rows[0], "solver,setting,roles,image_over_0.1,A_over_0.1,A_samples,A_vertices,A_emitters,B_over_0.1,B_samples,B_vertices,B_emitters,light_to_a_s,a_to_b_s,total_s,phases");
        assert_eq!(rows[1], "structured,STRUCTURED_LEVELS=8,structured@10%,1.5000,2.0000,48,,4,0.5000,10,,4,0.250000,0.500000,1.000000,x=1.000000");
        assert_eq!(rows[4], "hierarchical,EPS=0.001,same quality@10%;same on A@10%,1.0000,1.9000,50,100,,0.1000,18,36,,,,4.000000,x=4.000000");
        // The table reads back through its schema.
        let back: Bench = schemas::ron_io::parse_ron(std::path::Path::new("bench.ron"), &schemas::ron_io::to_ron_text(&bench)).unwrap();
        assert_eq!(back, bench);
    }
}

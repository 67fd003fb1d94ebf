//! `compare A.exr B.exr`: error of A against reference B, with tolerances.

use clap::Parser;
use compare::files::{compare_files, Request};
use compare::Params;
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Compares two images or two solutions; B is the reference. Images may come
/// from any renderer (any RGB(A) EXR); errors are given over the whole
/// image and per object and material. Exit 0: match (or no tolerance
/// given), 1: a given tolerance is exceeded, 2: error.
#[derive(Parser, Debug)]
#[command(name = "compare", version, about)]
struct Args {
    /// The approximation (`image` or `solution` artifact, or any RGB(A) EXR).
    #[arg(required_unless_present = "print_params")]
    a: Option<PathBuf>,
    /// The reference, of the same kind.
    #[arg(required_unless_present = "print_params")]
    b: Option<PathBuf>,
    /// Write the report (RON) here; without it the report goes to stdout.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write a false-colour picture of the relative luminance difference, with a scale bar (PNG; images only).
    #[arg(long)]
    diff: Option<PathBuf>,
    /// The scene's manifest: names objects and materials in the report (else they are numbered).
    #[arg(long)]
    manifest: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (vec![self.a.as_deref(), self.b.as_deref(), self.manifest.as_deref()], vec![self.output.as_deref(), self.diff.as_deref()])
    }

    fn settle(&self, params: &mut Params) -> schemas::Result<()> {
        params.validate()
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let request = Request { a: required(&self.a, "A")?, b: required(&self.b, "B")?, manifest: self.manifest.as_deref(), diff: self.diff.as_deref() };
        let outcome = compare_files(&request, params, run)?;
        let exceeded = params.exceeded(&outcome.metrics);
        let verdict = match (exceeded.is_empty(), params.has_tolerance()) {
            (false, _) => format!("differ: {}", exceeded.join(", ")),
            (true, true) => "match: within every given tolerance".to_string(),
            (true, false) => "no tolerance given".to_string(),
        };
        let mut notes = vec![format!("mode: {}", outcome.mode), format!("verdict: {verdict}")];
        notes.extend(outcome.notes);
        if outcome.metrics.samples == 0 {
            notes.push("no visible sample: every metric is 0".to_string());
        }
        if let (Some(path), Some(png)) = (request.diff, &outcome.diff_png) {
            outputs.write_bytes(path, png)?;
        }
        let report = run.report(params, outcome.counters.clone(), Vec::new(), notes.clone());
        match self.output.as_deref() {
            Some(path) => outputs.write(path, |p| schemas::ron_io::write_ron(p, &report))?,
            None => println!("{}", schemas::ron_io::to_ron_text(&report)),
        }
        let (m, tau) = (&outcome.metrics, params.tau_max());
        let summary = format!("{} samples: rmse {:.6}, relative_rmse {:.6}, mean_signed_error {:+.6}", m.samples, m.rmse, m.relative_rmse, m.mean_signed_error);
        eprintln!("compare: {verdict} ({}, {summary}, {:.3}% over tau {tau})", outcome.mode, m.percent_over(tau));
        for line in &outcome.table {
            eprintln!("{line}");
        }
        Ok(Done { counters: outcome.counters, notes, negative: !exceeded.is_empty(), ..Done::default() })
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

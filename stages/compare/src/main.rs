//! `compare A.exr B.exr`: error of A against reference B, with tolerances.

use clap::Parser;
use compare::{CompareError, Params, Which};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::report::Report;
use schemas::solution::Solution;
use schemas::stage::{bad_parameter, exit_code, load_params, print_params, Run};
use schemas::Error;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Compares two images or two solutions; B is the reference. Exit 0: match
/// (or no tolerance given), 1: a given tolerance is exceeded, 2: error.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// The approximation (`image` or `solution` artifact, EXR).
    #[arg(required_unless_present = "print_params")]
    a: Option<PathBuf>,
    /// The reference, of the same kind.
    #[arg(required_unless_present = "print_params")]
    b: Option<PathBuf>,
    /// Write the report (RON) here; without it the report goes to stdout.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write a false-colour luminance difference picture (PNG; images only).
    #[arg(long)]
    diff: Option<PathBuf>,
    /// Thresholds tau, comma-separated, as fractions of the reference's mean luminance.
    #[arg(long, value_delimiter = ',')]
    tau: Option<Vec<f64>>,
    /// Tolerance on the relative RMSE.
    #[arg(long)]
    max_rel_rmse: Option<f64>,
    /// Tolerance on the RMSE, in the data's unit.
    #[arg(long)]
    max_rmse: Option<f64>,
    /// Tolerance, in percent, on the samples over the largest tau.
    #[arg(long)]
    max_pixels_over_tau: Option<f64>,
    /// Parameters file (RON); flags given here override it.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Print the effective parameters as RON and exit.
    #[arg(long)]
    print_params: bool,
}

fn params(args: &Args) -> schemas::Result<Params> {
    let mut params: Params = load_params(args.params.as_deref())?;
    if let Some(tau) = &args.tau {
        params.tau = tau.clone();
    }
    params.max_rel_rmse = args.max_rel_rmse.or(params.max_rel_rmse);
    params.max_rmse = args.max_rmse.or(params.max_rmse);
    params.max_pixels_over_tau = args.max_pixels_over_tau.or(params.max_pixels_over_tau);
    params.validate()?;
    Ok(params)
}

/// Everything computed, nothing written yet.
struct Outcome {
    counters: BTreeMap<String, f64>,
    mode: &'static str,
    metrics: compare::metrics::Metrics,
    notes: Vec<String>,
    diff_png: Option<Vec<u8>>,
}

fn named(error: CompareError, a: &Path, b: &Path) -> Error {
    let path = match error.which() {
        Which::A => a,
        Which::B => b,
    };
    Error::invalid(path, None, error.to_string())
}

fn compare_files(args: &Args, params: &Params, run: &mut Run, a: &Path, b: &Path) -> schemas::Result<Outcome> {
    // The kind is decided by A: an image, or else (when A's schema says it
    // is no image) a solution; B must then be of the same kind.
    let (image_a, record_a) = match HdrImage::read(a) {
        Ok(read) => read,
        Err(image_error @ Error::Schema { .. }) => return compare_solution_files(args, params, run, a, b, image_error),
        Err(other) => return Err(other),
    };
    run.input(record_a);
    let (image_b, record_b) = HdrImage::read(b)?;
    run.input(record_b);
    let result = compare::compare_images(&image_a, &image_b, params).map_err(|e| named(e, a, b))?;
    let diff_png = match args.diff.as_deref() {
        Some(path) => {
            let picture = compare::images::difference_picture(
                &image_a,
                &image_b,
                result.metrics.mean_reference_luminance,
                params.tau_max(),
            );
            Some(
                schemas::png::encode_png(image_b.width, image_b.height, &picture)
                    .map_err(|e| Error::invalid(path, None, e))?,
            )
        }
        None => None,
    };
    let mut notes = Vec::new();
    if result.coverage_mismatches > 0 {
        notes.push(format!("{} pixels are covered in one image only", result.coverage_mismatches));
    }
    Ok(Outcome { counters: result.counters(), mode: "images", metrics: result.metrics, notes, diff_png })
}

fn compare_solution_files(
    args: &Args,
    params: &Params,
    run: &mut Run,
    a: &Path,
    b: &Path,
    image_error: Error,
) -> schemas::Result<Outcome> {
    let (solution_a, record_a) = match Solution::read(a) {
        Ok(read) => read,
        Err(Error::Schema { .. }) => {
            let what =
                format!("is neither an '{}' nor a '{}' artifact ({image_error})", HdrImage::NAME, Solution::NAME);
            return Err(Error::schema(a, what));
        }
        Err(other) => return Err(other),
    };
    if args.diff.is_some() {
        return Err(bad_parameter("--diff applies to images only; the inputs are solutions"));
    }
    run.input(record_a);
    let (solution_b, record_b) = Solution::read(b)?;
    run.input(record_b);
    let result = compare::compare_solutions(&solution_a, &solution_b, params).map_err(|e| named(e, a, b))?;
    Ok(Outcome {
        counters: result.counters(),
        mode: result.mode.describe(),
        metrics: result.metrics,
        notes: Vec::new(),
        diff_png: None,
    })
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let started = Instant::now();
    let params = params(&args)?;
    if args.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(a), Some(b)) = (args.a.as_deref(), args.b.as_deref()) else {
        unreachable!("clap requires A and B without --print-params")
    };
    let mut run = Run::start("compare", env!("CARGO_PKG_VERSION"));
    let outcome = compare_files(&args, &params, &mut run, a, b)?;
    let exceeded = params.exceeded(&outcome.metrics);
    let verdict = if !exceeded.is_empty() {
        format!("differ: {}", exceeded.join(", "))
    } else if params.has_tolerance() {
        "match: within every given tolerance".to_string()
    } else {
        "no tolerance given".to_string()
    };
    let mut notes = vec![format!("mode: {}", outcome.mode), format!("verdict: {verdict}")];
    notes.extend(outcome.notes);
    if outcome.metrics.samples == 0 {
        notes.push("no visible sample: every metric is 0".to_string());
    }

    if let (Some(path), Some(png)) = (args.diff.as_deref(), &outcome.diff_png) {
        schemas::atomic::write_bytes_atomically(path, png)?;
    }
    match args.output.as_deref() {
        Some(path) => run.write_report(path, &params, outcome.counters, Vec::new(), notes)?,
        None => {
            let report = Report {
                header: Report::header(run.provenance(&params)),
                wall_time_s: started.elapsed().as_secs_f64(),
                counters: outcome.counters,
                skipped: Vec::new(),
                notes,
            };
            println!("{}", schemas::ron_io::to_ron_text(&report));
        }
    }
    let m = &outcome.metrics;
    eprintln!(
        "compare: {verdict} ({}, {} samples: rmse {:.6}, relative_rmse {:.6}, {:.3}% over tau {})",
        outcome.mode,
        m.samples,
        m.rmse,
        m.relative_rmse,
        m.percent_over_tau.iter().find(|(t, _)| *t == params.tau_max()).map_or(0.0, |(_, p)| *p),
        params.tau_max()
    );
    Ok(if exceeded.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn main() -> ExitCode {
    exit_code("compare", run(Args::parse()))
}

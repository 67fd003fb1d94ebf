//! `bench-gather`: the summary table of `make bench-gather` from the runs'
//! reports (see [`bench::gather`] for the figures): each run's work and
//! time from its `NAME.report.ron`, its error from `compare` of `NAME.exr`
//! against the reference (`NAME.compare.ron`), and the brute-force rays
//! that reach the same error.
//!
//! Reproduce: `make bench-gather` runs the gathers and then this, e.g.
//! `target/release/bench-gather --dir out/bench-gather -o
//! out/bench-gather/summary.txt brute4 brute8 full0.02 masked`.

use bench::gather::{summary, GatherRun};
use bench::sweep::stages::Stages;
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use stage_kit::cli::main_of;
use schemas::report::Report;
use schemas::ron_io::read_ron;
use stage_kit::run::{bad_parameter, check_writable};
use schemas::{Error, Result};
use std::path::PathBuf;
use std::process::ExitCode;

/// Tabulates grid-gather runs against a reference: rays, form factors,
/// time, relative RMSE, equal-error brute-force rays and their ratio.
#[derive(Parser, Debug)]
#[command(name = "bench-gather", version)]
struct Args {
    /// The directory holding each run's NAME.exr and NAME.report.ron.
    #[arg(long)]
    dir: PathBuf,
    /// The runs, in table order; names starting with `brute` make the equal-error line.
    #[arg(required = true, value_name = "RUN")]
    runs: Vec<String>,
    /// The reference image [default: DIR/reference.exr].
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Output: the summary table (also printed on stdout).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
}

fn run(args: Args) -> Result<ExitCode> {
    check_writable(&args.output)?;
    let reference = args.reference.clone().unwrap_or_else(|| args.dir.join("reference.exr"));
    if !reference.is_file() {
        return Err(bad_parameter(format!("--reference {}: no such file", reference.display())));
    }
    let stages = Stages::beside_this_executable()?;
    let mut runs = Vec::new();
    for name in &args.runs {
        let report: Report = read_ron(&args.dir.join(format!("{name}.report.ron")))?.value;
        let image = args.dir.join(format!("{name}.exr"));
        let compare_report = args.dir.join(format!("{name}.compare.ron"));
        let compared = stages.run("compare", &[image.display().to_string(), reference.display().to_string()], &compare_report)?;
        let error = compared.counters.get("relative_rmse").copied().ok_or_else(|| Error::invalid(&compare_report, None, "no relative_rmse counter"))?;
        runs.push(GatherRun::of(name, &report, error));
    }
    let table = summary(&runs);
    write_bytes_atomically(&args.output, table.as_bytes())?;
    print!("{table}");
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-gather", run)
}

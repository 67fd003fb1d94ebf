//! `bench-structured`: paper 002's Tables 2 and 3 in shape, structured
//! sampling against hierarchical-solve on one scene (see
//! [`bench::structured`] for what is measured).
//!
//! Reproduce: `make bench-structured` (the simple environment against the
//! exact image, then the Cornell box), or e.g. `target/release/bench-structured
//! --scene simple-environment -o out/bench-structured/simple-environment`.
//! Writes `bench.ron`, `bench.csv` and `bench.txt` (the printed table) in
//! the output directory, each run's files under `runs/`, the reference
//! under `reference/`.

use bench::structured::{run, Config};
use bench::sweep::stages::Stages;
use bench::PipelineArgs;
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use stage_kit::cli::main_of;
use stage_kit::run::{bad_parameter, check_writable};
use schemas::{Error, Result};
use std::process::ExitCode;

/// Structured sampling (structured-sample) against hierarchical radiosity
/// (hierarchical-solve, preview gather) at the same speed and the same
/// quality: percent of pixels over tau, per surface, samples and element
/// vertices per surface, time split.
#[derive(Parser, Debug)]
#[command(name = "bench-structured", version)]
struct Args {
    /// Scene: `simple-environment`, `cornell`, another built-in scene or a scene.ron path.
    #[arg(long, default_value = "simple-environment")]
    scene: String,
    /// A surface of the table, NAME=object,object,...; repeat for more [default: every non-emitting object].
    #[arg(long, value_name = "NAME=OBJECTS")]
    surface: Vec<String>,
    /// hierarchical-solve's EPS values, comma-separated (the default brackets structured sampling's figures on the simple environment).
    #[arg(long, value_delimiter = ',', default_value = "0.0125,0.008,0.006,0.004,0.002,0.0008,0.0004,0.000125,0.00004")]
    eps: Vec<f64>,
    /// structured-sample's isolux levels.
    #[arg(long, default_value_t = 8)]
    levels: usize,
    /// Tolerances measured, comma-separated fractions.
    #[arg(long, value_delimiter = ',', default_value = "0.02,0.05,0.1,0.15")]
    tau: Vec<f64>,
    /// Tolerances quality is compared at, comma-separated, each one of --tau (paper 002: 0.1 in Table 2, 0.15 in Table 3).
    #[arg(long, value_delimiter = ',', default_value = "0.1")]
    quality_tau: Vec<f64>,
    #[command(flatten)]
    pipeline: PipelineArgs,
}

/// `NAME=object,object` as a surface of the table.
fn parse_surface(text: &str) -> Result<(String, Vec<String>)> {
    let (name, objects) = text.split_once('=').ok_or_else(|| bad_parameter(format!("--surface {text}: expected NAME=object,object,...")))?;
    let objects: Vec<String> = objects.split(',').map(str::trim).filter(|o| !o.is_empty()).map(String::from).collect();
    if name.trim().is_empty() || objects.is_empty() {
        return Err(bad_parameter(format!("--surface {text}: expected NAME=object,object,...")));
    }
    Ok((name.trim().to_string(), objects))
}

fn run_args(args: Args) -> Result<ExitCode> {
    if let Some(bad) = args.eps.iter().chain(&args.tau).find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(bad_parameter(format!("--eps and --tau take positive numbers, not {bad}")));
    }
    let config = Config {
        scene: args.scene.clone(),
        surfaces: args.surface.iter().map(|s| parse_surface(s)).collect::<Result<_>>()?,
        eps: args.eps.clone(),
        levels: args.levels,
        reference: args.pipeline.reference.clone(),
        taus: args.tau.clone(),
        quality_taus: args.quality_tau.clone(),
        clusters: !args.pipeline.no_clusters,
        width: args.pipeline.width,
        height: args.pipeline.height,
        out: args.pipeline.output.clone(),
    };
    let out = &config.out;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let paths = ["bench.ron", "bench.csv", "bench.txt"].map(|name| out.join(name));
    for path in &paths {
        check_writable(path)?;
    }
    let stages = Stages::beside_this_executable()?;
    let bench = run(&config, &stages, &mut |line| eprintln!("bench-structured: {line}"))?;
    let text = bench.text();
    schemas::ron_io::write_ron(&paths[0], &bench)?;
    write_bytes_atomically(&paths[1], bench.csv().as_bytes())?;
    write_bytes_atomically(&paths[2], text.as_bytes())?;
    eprint!("{text}");
    eprintln!("bench-structured: wrote {}", paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-structured", run_args)
}

//! `bench-mirror`: the table of `make bench-mirror` (see [`bench::mirror`]):
//! per scene directory `DIR/SCENE` (the pipelines' outputs for that scene,
//! `OUT` of `make`), hierarchical-solve's `solve.report.ron` and
//! gpu-shoot's `gpu/gpu-shoot.report.ron`, with the triangle count from
//! `manifest.ron`; a solver whose report is missing is left out.
//!
//! Reproduce: `make bench-mirror` (figures in README, Performance).

use bench::mirror::{table, MirrorRun};
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use schemas::mesh::Manifest;
use schemas::report::Report;
use schemas::ron_io::read_ron;
use schemas::Result;
use stage_kit::cli::main_of;
use stage_kit::run::{bad_parameter, check_writable};
use std::path::PathBuf;
use std::process::ExitCode;

/// Tabulates the solvers' runs on scenes with mirrors: paper 004 Table 4.1's columns and the time spent on specular paths.
#[derive(Parser, Debug)]
#[command(name = "bench-mirror", version)]
struct Args {
    /// The directory holding one folder per scene.
    #[arg(long)]
    dir: PathBuf,
    /// The scenes' folders, in table order.
    #[arg(required = true, value_name = "SCENE")]
    scenes: Vec<String>,
    /// Output: the table (also printed on stdout).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
}

fn run(args: Args) -> Result<ExitCode> {
    check_writable(&args.output)?;
    let mut runs = Vec::new();
    for scene in &args.scenes {
        let dir = args.dir.join(scene);
        let manifest = dir.join("manifest.ron");
        if !manifest.is_file() {
            return Err(bad_parameter(format!("{}: no such file (run the scene's pipelines first)", manifest.display())));
        }
        let triangles = read_ron::<Manifest>(&manifest)?.value.statistics.triangles;
        for (solver, report) in [("hierarchical-solve", dir.join("solve.report.ron")), ("gpu-shoot", dir.join("gpu").join("gpu-shoot.report.ron"))] {
            if report.is_file() {
                let report: Report = read_ron(&report)?.value;
                runs.push(MirrorRun { scene: scene.clone(), triangles, solver, wall_s: report.wall_time_s, counters: report.counters });
            }
        }
    }
    let table = table(&runs);
    write_bytes_atomically(&args.output, table.as_bytes())?;
    print!("{table}");
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-mirror", run)
}

//! `sweep`: error against time over a grid of knob values, for one scene
//! and one or more solvers (see [`bench::sweep`] for what is computed).
//!
//! Reproduce: `make sweep` (Cornell box, hierarchical, EPS from 1e-3 to
//! 1e-5, preview and full gathers, 3 runs a point), or e.g.
//! `target/release/sweep --scene sphere-300 --knob EPS=0.1,0.01 --reps 1
//! -o out/sphere-300/sweep`. Writes `sweep.ron`, `sweep.csv`, `sweep.svg`
//! and `sweep.png` in the output directory, each point's runs under
//! `runs/`, the reference under `reference/`.

use bench::sweep::knobs::{format_value, knob, Gather, Knob, Solver, KNOBS};
use bench::sweep::stages::Stages;
use bench::sweep::{plot, Config};
use bench::PipelineArgs;
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use stage_kit::run::{bad_parameter, check_writable, exit_code};
use schemas::{Error, Result};
use std::process::ExitCode;

/// Runs the pipeline's stages over a grid of knob values and tabulates and
/// plots error against time. Knobs (Makefile names): EPS, MIN_AREA,
/// VISIBILITY_RAYS, TOLERANCE (hierarchical); GPU_TEXELS, GPU_CONVERGENCE,
/// GPU_RESOLUTION, GPU_SHOOT_LEVEL (gpu); SPP (both); LATTICE_SPACING (the
/// full gather's).
#[derive(Parser, Debug)]
#[command(name = "sweep", version)]
struct Args {
    /// Scene: `cornell`, a built-in scene (sphere-300, box-10k, ...) or a scene.ron path.
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Solvers, comma-separated: hierarchical, gpu, photon, structured.
    #[arg(long, value_delimiter = ',', default_value = "hierarchical")]
    solver: Vec<String>,
    /// Gather modes, comma-separated: preview, full [default: every mode the solver's solution allows].
    #[arg(long, value_delimiter = ',')]
    gather: Option<Vec<String>>,
    #[arg(long, value_name = "NAME=V1,V2,...", help = knob_help())]
    knob: Vec<String>,
    /// Runs per point; each figure is their median.
    #[arg(long, default_value_t = 3)]
    reps: usize,
    #[command(flatten)]
    pipeline: PipelineArgs,
}

/// `--knob`'s help, with each solver's default grid ([`Solver::default_knobs`]).
fn knob_help() -> String {
    let defaults: Vec<String> = Solver::ALL
        .into_iter()
        .flat_map(Solver::default_knobs)
        .map(|(knob, values)| format!("{}={}", knob.name, values.iter().map(|&v| format_value(v, knob.integer)).collect::<Vec<_>>().join(",")))
        .collect();
    format!("A knob and its values, NAME=v1,v2,...; repeat for a grid (the cartesian product) [default per solver: {}]", defaults.join("; "))
}

/// `NAME=v1,v2,...` as a knob and its values.
fn parse_knob(text: &str) -> Result<(&'static Knob, Vec<f64>)> {
    let names = || KNOBS.iter().map(|k| k.name).collect::<Vec<_>>().join(", ");
    let (name, values) = text.split_once('=').ok_or_else(|| bad_parameter(format!("--knob {text}: expected NAME=v1,v2,... (knobs: {})", names())))?;
    let knob = knob(name.trim()).ok_or_else(|| bad_parameter(format!("--knob {text}: unknown knob {name:?} (knobs: {})", names())))?;
    let values = values
        .split(',')
        .filter(|v| !v.trim().is_empty())
        .map(|v| knob.parse_value(v).map_err(|e| bad_parameter(format!("--knob {e}"))))
        .collect::<Result<Vec<f64>>>()?;
    if values.is_empty() {
        return Err(bad_parameter(format!("--knob {text}: no value")));
    }
    Ok((knob, values))
}

fn config(args: &Args) -> Result<Config> {
    let solvers = args
        .solver
        .iter()
        .map(|n| Solver::parse(n.trim()).ok_or_else(|| bad_parameter(format!("--solver {n}: expected hierarchical, gpu, photon or structured"))))
        .collect::<Result<Vec<_>>>()?;
    let gathers = match &args.gather {
        None => None,
        Some(names) => Some(
            names
                .iter()
                .map(|n| Gather::parse(n.trim()).ok_or_else(|| bad_parameter(format!("--gather {n}: expected preview or full"))))
                .collect::<Result<Vec<_>>>()?,
        ),
    };
    let knobs = args.knob.iter().map(|k| parse_knob(k)).collect::<Result<Vec<_>>>()?;
    Ok(Config {
        scene: args.scene.clone(),
        solvers,
        gathers,
        knobs,
        reps: args.reps,
        reference: args.pipeline.reference.clone(),
        clusters: !args.pipeline.no_clusters,
        width: args.pipeline.width,
        height: args.pipeline.height,
        out: args.pipeline.output.clone(),
    })
}

fn run(args: Args) -> Result<ExitCode> {
    let config = config(&args)?;
    let plans = bench::sweep::plan(&config)?;
    let out = &config.out;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let paths = ["sweep.ron", "sweep.csv", "sweep.svg", "sweep.png"].map(|name| out.join(name));
    for path in &paths {
        check_writable(path)?;
    }
    let stages = Stages::beside_this_executable()?;
    let sweep = bench::sweep::run(&config, &plans, &stages, &mut |line| eprintln!("sweep: {line}"))?;
    let svg = plot::svg(&sweep).map_err(|e| Error::invalid(&paths[2], None, e))?;
    let png = plot::png(&sweep).map_err(|e| Error::invalid(&paths[3], None, e))?;
    schemas::ron_io::write_ron(&paths[0], &sweep)?;
    write_bytes_atomically(&paths[1], sweep.csv().as_bytes())?;
    write_bytes_atomically(&paths[2], svg.as_bytes())?;
    write_bytes_atomically(&paths[3], &png)?;
    eprintln!("sweep: {} points; {}", sweep.points.len(), sweep.reference.label);
    for p in &sweep.points {
        let knobs: Vec<String> = p.knobs.iter().map(|k| format!("{}={}", k.name, k.value)).collect();
        eprintln!(
            "  {:<12} {:<7} {:<24} total {:>8.3} s  error {:.3e}{}{}",
            p.solver.name(),
            p.gather.name(),
            knobs.join(" "),
            p.total_s.median,
            p.error.median,
            p.worst_surface.as_ref().map(|w| format!("  worst surface {:.2}%", 100.0 * w.median)).unwrap_or_default(),
            if p.pareto { "  (Pareto front)" } else { "" }
        );
    }
    eprintln!("sweep: wrote {}", paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    exit_code("sweep", run(Args::parse()))
}

//! `bench-gpu`: times gpu-shoot on the built-in Cornell box at about 127k
//! covered texels (the size of paper 004's "Cornell box high") to 90%
//! convergence: hemicube vs stereographic, with and without ambient
//! overshooting (004 Table 4.1). Table on stderr, RON on stdout or `-o`.

use clap::Parser;
use gpu_shoot::{gpu, solve, Params, Visibility};
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;

/// Benchmark arguments.
#[derive(Parser, Debug)]
#[command(name = "bench-gpu", version)]
struct Args {
    /// Output: the RON report (default: stdout).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Covered texels to aim for.
    #[arg(long, default_value_t = 127_000.0)]
    texels: f64,
    /// Convergence to reach.
    #[arg(long, default_value_t = 0.9)]
    convergence: f64,
}

/// One configuration's result.
#[derive(Serialize, Debug)]
struct Row {
    visibility: String,
    overshoot: bool,
    texels: usize,
    shots: usize,
    unshot_fraction: f64,
    setup_seconds: f64,
    shoot_seconds: f64,
}

/// The report.
#[derive(Serialize, Debug)]
struct Bench {
    adapter: String,
    rows: Vec<Row>,
}

fn run(args: Args) -> Result<ExitCode, String> {
    let (mesh, manifest) = mesh_prep::prepare_builtin("cornell-box", "bench-gpu").map_err(|e| e.to_string())?;
    let (device, queue, info) = gpu::acquire()?;
    let adapter = gpu::describe(&info);
    let mut rows = Vec::new();
    eprintln!("bench-gpu: Cornell box, {} triangles, to {:.0}% on {adapter}", mesh.triangles.len(), 100.0 * args.convergence);
    eprintln!("{:>14} {:>9} {:>8} {:>6} {:>9} {:>9}", "visibility", "overshoot", "texels", "shots", "setup s", "shoot s");
    for visibility in [Visibility::Hemicube, Visibility::Stereographic] {
        for overshoot in [false, true] {
            let params = Params { texels: args.texels, visibility, overshoot, convergence_target: args.convergence, ..Params::default() };
            let solved = solve(&device, &queue, &mesh, &manifest, None, &[], &params, &mut |_| {})?;
            let row = Row {
                visibility: format!("{visibility:?}").to_lowercase(),
                overshoot,
                texels: solved.atlas.texels.len(),
                shots: solved.work.shots,
                unshot_fraction: solved.shots.last().map(|s| s.unshot_fraction).unwrap_or(1.0),
                setup_seconds: solved.work.setup_seconds,
                shoot_seconds: solved.work.shoot_seconds,
            };
            eprintln!("{:>14} {:>9} {:>8} {:>6} {:>9.3} {:>9.3}", row.visibility, row.overshoot, row.texels, row.shots, row.setup_seconds, row.shoot_seconds);
            rows.push(row);
        }
    }
    let text = ron::ser::to_string_pretty(&Bench { adapter, rows }, Default::default()).map_err(|e| e.to_string())?;
    match &args.output {
        Some(p) => std::fs::write(p, text + "\n").map_err(|e| format!("{}: {e}", p.display()))?,
        None => println!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bench-gpu: error: {e}");
            ExitCode::from(2)
        }
    }
}

//! `bench-scale`: how hierarchical radiosity with clustering scales.
//!
//! For each size of the procedural plant room (`plants-<n>`: a room of
//! randomly oriented leaves, the kind of scene paper 000 targets), in one
//! process and in increasing order: prepare the scene in memory, build the
//! cluster hierarchy (`cluster` stage's library), solve with clusters, and
//! record cluster time, solve time, links and the solve's peak memory
//! (VmHWM reset before each size). Where the scene is small enough, the
//! unclustered solver runs too, for the speed-up. The growth exponents of
//! time and memory are least-squares slopes of log(value) over
//! log(triangles); the goal is about n log n time (exponent a little above
//! 1) and linear memory.
//!
//! Reproduce: `make bench-scale` (or `target/release/bench-scale --sizes
//! 10k,100k,1m -o out/bench-scale.ron`).

use bench::{peak_memory_mib, reset_peak_memory};
use clap::Parser;
use hierarchical_solve::{solve, Params};
use stage_kit::scene::mesh_triangles;
use schemas::cluster::Clusters;
use schemas::header::{Provenance, Schema};
use stage_kit::run::{check_writable, exit_code};
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Scaling benchmark of clustered hierarchical radiosity on plant rooms.
#[derive(Parser, Debug)]
#[command(name = "bench-scale")]
struct Args {
    /// Scene sizes (triangles), e.g. 10k,100k,1m.
    #[arg(long, value_delimiter = ',', default_value = "10k,100k,1m")]
    sizes: Vec<String>,
    /// Refinement threshold (the plant scenes' default in the Makefile).
    #[arg(long, default_value_t = 1e-2)]
    eps: f64,
    /// Also solve without clustering up to this many triangles.
    #[arg(long, default_value_t = 10_000)]
    unclustered_up_to: usize,
    /// Write the figures as RON here.
    #[arg(short = 'o', long)]
    output: Option<PathBuf>,
}

/// Figures of one size.
#[derive(Serialize, Debug)]
struct Row {
    scene: String,
    triangles: usize,
    prepare_seconds: f64,
    cluster_seconds: f64,
    clusters: usize,
    solve_seconds: f64,
    links: usize,
    cluster_links: usize,
    leaves: usize,
    rays: u64,
    peak_memory_mib: Option<f64>,
    unclustered_solve_seconds: Option<f64>,
    unclustered_links: Option<usize>,
}

/// The whole report.
#[derive(Serialize, Debug)]
struct Report {
    command: Vec<String>,
    threads: usize,
    eps: f64,
    rows: Vec<Row>,
    time_exponent: Option<f64>,
    memory_exponent: Option<f64>,
}

/// Least-squares slope of log y over log x.
fn exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

fn measure(size: &str, args: &Args) -> schemas::Result<Row> {
    let scene = format!("plants-{size}");
    let started = Instant::now();
    let (mesh, manifest) = mesh_prep::prepare_builtin(&scene, "bench-scale")?;
    let prepare_seconds = started.elapsed().as_secs_f64();
    let triangles = mesh_triangles(&mesh);
    let reflectance: Vec<[f64; 3]> = mesh.triangles.iter().map(|t| manifest.materials[t.material as usize].diffuse).collect();
    let params = Params { eps: args.eps, ..Params::default() };
    let unclustered = if triangles.len() <= args.unclustered_up_to {
        let started = Instant::now();
        let solved = solve(&mesh, &manifest, None, &params, &|_| {}).map_err(|e| schemas::Error::invalid(std::path::Path::new(&scene), None, e))?;
        Some((started.elapsed().as_secs_f64(), solved.work.links))
    } else {
        None
    };
    let memory_reset = reset_peak_memory();
    let started = Instant::now();
    let hierarchy = cluster::build(&triangles, &reflectance, &cluster::Params::default());
    let cluster_seconds = started.elapsed().as_secs_f64();
    let clusters = Clusters { header: Clusters::header(Provenance::in_memory("bench-scale")), nodes: hierarchy.nodes, order: hierarchy.order };
    let count = clusters.nodes.len();
    let started = Instant::now();
    let solved = solve(&mesh, &manifest, Some(clusters), &params, &|_| {}).map_err(|e| schemas::Error::invalid(std::path::Path::new(&scene), None, e))?;
    let solve_seconds = started.elapsed().as_secs_f64();
    let w = &solved.work;
    Ok(Row {
        scene,
        triangles: triangles.len(),
        prepare_seconds,
        cluster_seconds,
        clusters: count,
        solve_seconds,
        links: w.links,
        cluster_links: w.cluster_links,
        leaves: w.leaves,
        rays: w.rays,
        peak_memory_mib: if memory_reset { peak_memory_mib() } else { None },
        unclustered_solve_seconds: unclustered.map(|u| u.0),
        unclustered_links: unclustered.map(|u| u.1),
    })
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    if let Some(path) = &args.output {
        check_writable(path)?;
    }
    let mut rows = Vec::new();
    for size in &args.sizes {
        eprintln!("bench-scale: plants-{size} ...");
        let row = measure(size, &args)?;
        eprintln!(
            "  {} triangles: cluster {:.2} s ({} clusters), solve {:.1} s, {} links ({} with a cluster end), {} leaves, peak {:.0} MiB{}",
            row.triangles,
            row.cluster_seconds,
            row.clusters,
            row.solve_seconds,
            row.links,
            row.cluster_links,
            row.leaves,
            row.peak_memory_mib.unwrap_or(f64::NAN),
            row.unclustered_solve_seconds
                .map(|u| format!("; unclustered {u:.1} s, speed-up {:.1}x", u / row.solve_seconds))
                .unwrap_or_default()
        );
        rows.push(row);
    }
    let time_exponent = exponent(&rows.iter().map(|r| (r.triangles as f64, r.cluster_seconds + r.solve_seconds)).collect::<Vec<_>>());
    let memory_exponent = exponent(&rows.iter().filter_map(|r| Some((r.triangles as f64, r.peak_memory_mib?))).collect::<Vec<_>>());
    eprintln!("growth exponents: time {time_exponent:.2?}, memory {memory_exponent:.2?}");
    let report = Report { command: std::env::args().collect(), threads: rayon::current_num_threads(), eps: args.eps, rows, time_exponent, memory_exponent };
    let text = schemas::ron_io::to_ron_text(&report);
    match &args.output {
        Some(path) => schemas::atomic::write_bytes_atomically(path, text.as_bytes())?,
        None => println!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    exit_code("bench-scale", run(Args::parse()))
}

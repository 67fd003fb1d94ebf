//! `bench-residual`: a solution's surfaces, leaves and links against one
//! bounce of a radiosity field, ray-traced apart from the solvers (see
//! [`bench::residual`]): with the solution itself as the field, the
//! residual of the radiosity equation over its own leaves, where a
//! solver's transport errs; with a finer solve, the leaves' error
//! against it.
//!
//! Reproduce: README, "Measuring" (hierarchical-solve).

use bench::residual::{Attribution, Gather, Sampling};
use bench::SceneFiles;
use bench::surfaces::{check_mesh, table, Unit};
use clap::Parser;
use radiometry::color::luminance;
use schemas::atomic::write_bytes_atomically;
use schemas::cluster::Clusters;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::{Node, Solution};
use schemas::{Error, Result};
use stage_kit::cli::main_of;
use stage_kit::run::{bad_parameter, check_writable};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Tabulates a solution's surfaces (and its worst links) against a ray-traced gather of a radiosity field: the solution's own, by default.
#[derive(Parser, Debug)]
#[command(name = "bench-residual", version)]
struct Args {
    #[command(flatten)]
    scene: SceneFiles,
    /// The solution measured (hierarchical-solve's).
    #[arg(long, value_name = "SOLUTION.exr")]
    solution: PathBuf,
    /// The radiosity gathered: another solution of the same mesh (e.g. a finer solve) [default: the solution itself].
    #[arg(long, value_name = "SOLUTION.exr")]
    field: Option<PathBuf>,
    /// The cluster hierarchy the solution was solved with: credits light to links with a cluster at an end too (`--links`).
    #[arg(long, value_name = "CLUSTERS.exr")]
    clusters: Option<PathBuf>,
    /// What a surface is: an object of the manifest, or an input triangle.
    #[arg(long, value_enum, default_value_t = Unit::Object)]
    by: Unit,
    /// Gather only this surface's leaves (an object's name, or a triangle's index with `--by triangle`).
    #[arg(long)]
    surface: Option<String>,
    /// Stratified points per leaf.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    points: u32,
    /// Cosine-distributed rays per point (the light of the surfaces that do not emit).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65536))]
    rays: u32,
    /// Points on each emitting triangle per point, each with a shadow ray (the light of the emitters).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65536))]
    emitter_points: u32,
    /// Also list the links whose own flux differs most from the light the gather credits them with, at most this many.
    #[arg(long, value_name = "N")]
    links: Option<usize>,
    /// Output: the tables, Markdown (also printed on stdout).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Output: every gathered leaf as a CSV row (its element, surface, level, open area, centroid, and the luminance of the solution and of the gather), for plots and for sorting leaves by place.
    #[arg(long, value_name = "LEAVES.csv")]
    leaves: Option<PathBuf>,
}

fn run(args: Args) -> Result<ExitCode> {
    check_writable(&args.output)?;
    if let Some(path) = &args.leaves {
        check_writable(path)?;
    }
    let (mesh, _) = Mesh::read(&args.scene.mesh)?;
    let manifest = read_ron::<Manifest>(&args.scene.manifest)?.value;
    let (solution, _) = Solution::read(&args.solution)?;
    let field = match &args.field {
        Some(path) => Some(Solution::read(path)?.0),
        None => None,
    };
    let invalid = |path: &Path, message: String| Error::invalid(path, None, message);
    for (path, s) in std::iter::once((&args.solution, &solution)).chain(args.field.as_ref().zip(field.as_ref())) {
        check_mesh(&mesh, s, "the solution").map_err(|m| invalid(path, m))?;
    }
    let clusters = match &args.clusters {
        Some(path) => Some(Clusters::read(path, mesh.triangles.len())?.0),
        None => None,
    };
    let gather = Gather::new(&mesh, &manifest, field.as_ref().unwrap_or(&solution)).map_err(|m| invalid(&args.scene.manifest, m))?;
    let surface_of = |t: u32| args.by.of(&mesh, t);
    let names = args.by.names(&mesh, &manifest);
    let only = match &args.surface {
        None => None,
        Some(name) => {
            let found = match args.by {
                Unit::Object => names.iter().position(|n| n == name),
                Unit::Triangle => name.parse::<usize>().ok().filter(|&t| t < mesh.triangles.len()),
            };
            Some(found.ok_or_else(|| bad_parameter(format!("--surface '{name}' names no {} of the scene", if args.by == Unit::Object { "object" } else { "triangle" })))?)
        }
    };
    let keep = |t: u32| only.is_none_or(|s| surface_of(t) == s);
    let attribution = args.links.map(|_| Attribution::new(&solution, clusters.as_ref(), mesh.triangles.len()));
    let sampling = Sampling { points: args.points as usize, rays: args.rays as usize, emitter_points: args.emitter_points as usize };
    let gathered = gather.leaves(&solution, &keep, sampling, attribution.as_ref());

    // Per surface: open-area means of the solution and of the gather.
    let mut sums = vec![(0.0, 0.0, 0.0); names.len()];
    let (mut squared, mut area) = (0.0, 0.0);
    for (leaf, g) in &gathered {
        let e = &solution.elements[*leaf];
        let (a, b, r) = (f64::from(e.area), luminance(e.radiosity.map(f64::from)), luminance(g.radiosity));
        let s = &mut sums[surface_of(e.triangle)];
        (s.0, s.1, s.2) = (s.0 + a * b, s.1 + a * r, s.2 + a);
        if r > 0.0 {
            squared += a * (b / r - 1.0).powi(2);
            area += a;
        }
    }
    let measured: Vec<usize> = (0..names.len()).filter(|&o| sums[o].2 > 0.0).collect();
    let mean = |o: usize, k: usize| Some(if k == 0 { sums[o].0 } else { sums[o].1 } / sums[o].2);
    let mut text = format!(
        "Solution `{}` against a ray-traced gather of `{}` ({} leaves, {} points of {} rays and {} emitter points each); leaves' rms of solution / gathered - 1: {:.2}%\n\n",
        args.solution.display(),
        args.field.as_ref().unwrap_or(&args.solution).display(),
        gathered.len(),
        args.points,
        args.rays,
        args.emitter_points,
        100.0 * (squared / area.max(f64::MIN_POSITIVE)).sqrt()
    );
    let series = [("solution".to_string(), measured.iter().map(|&o| mean(o, 0)).collect())];
    text += &table(&measured.iter().map(|&o| names[o].as_str()).collect::<Vec<_>>(), &measured.iter().map(|&o| mean(o, 1)).collect::<Vec<_>>(), &series)
        .replacen("| surface | reference |", "| surface | gathered |", 1);
    if let Some(n) = args.links {
        let mut fluxes = gather.link_fluxes(&solution, &gathered);
        let (credited, own): (f64, f64) = fluxes.iter().fold((0.0, 0.0), |(c, o), l| (c + l.1, o + l.2));
        fluxes.sort_by(|a, b| (b.2 - b.1).abs().total_cmp(&(a.2 - a.1).abs()));
        let node = |n: Node| match n {
            Node::Element(e) => {
                let el = &solution.elements[e as usize];
                format!("{} el {e} (level {})", names[surface_of(el.triangle)], el.level)
            }
            Node::Cluster(c) => format!("cluster {c}"),
        };
        text += &format!("\nLinks into elements: own flux {own:.4e} W against {credited:.4e} W credited ({:+.2}%); the {} that differ most:\n\n| link | receiver | sender | visibility | credited, W | own, W | own / credited - 1 |\n|---|---|---|---|---|---|---|\n", 100.0 * (own / credited - 1.0), n.min(fluxes.len()));
        for &(l, c, o) in fluxes.iter().take(n) {
            let link = &solution.links[l];
            text += &format!("| {l} | {} | {} | {:.3} | {c:.4e} | {o:.4e} | {:+.2}% |\n", node(link.receiver), node(link.sender), link.visibility, 100.0 * (o / c - 1.0));
        }
    }
    if let Some(path) = &args.leaves {
        write_bytes_atomically(path, gather.leaves_csv(&solution, &gathered, &|t| names[surface_of(t)].clone()).as_bytes())?;
    }
    write_bytes_atomically(&args.output, text.as_bytes())?;
    print!("{text}");
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-residual", run)
}

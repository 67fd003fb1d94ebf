//! `exact --mesh M --manifest F -o image.exr`: the exact reference image.

use clap::Parser;
use exact::{Exact, Params};
use stage_kit::cli::{check_outputs, main_of};
use schemas::exr_io::Channel;
use schemas::header::Schema;
use schemas::image::HdrImage;
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, Outputs, Run, StageArgs};
use schemas::Error;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

const STAGE: &str = "exact";

/// Render the exact image of a simple scene (paper 002 Sec. 2): direct
/// light by Lambert's formula, one bounce by adaptive Gauss quadrature,
/// further bounces between two planes; R, G, B radiance in W/(m^2 sr), A
/// coverage, and error_bound.R/G/B, a bound of each pixel's error.
#[derive(Parser, Debug)]
#[command(name = STAGE, version)]
struct Args {
    /// Mesh (mesh.exr from mesh-prep).
    #[arg(long, value_name = "MESH.exr", required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Manifest (manifest.ron from mesh-prep): camera, materials.
    #[arg(long, value_name = "MANIFEST.ron", required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output image.
    #[arg(short = 'o', long = "output", value_name = "IMAGE.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Bounces after the direct light: 0, 1 (the paper's one bounce), or more between two planes [default: 1].
    #[arg(long, value_name = "N")]
    bounces: Option<u32>,
    /// Relative tolerance of each pixel's one-bounce integral [default: 1e-6].
    #[arg(long, value_name = "FRACTION")]
    tolerance: Option<f64>,
    /// Gauss-Legendre points per direction of the triangle rule [default: 6].
    #[arg(long, value_name = "N")]
    gauss_order: Option<u32>,
    /// Deepest 1:4 refinement of the adaptive quadrature [default: 12].
    #[arg(long, value_name = "N")]
    max_depth: Option<u32>,
    /// 1:4 splits of the reflectors for the iterated bounces' nodes [default: 2].
    #[arg(long, value_name = "N")]
    nystrom_level: Option<u32>,
    /// Image width [default: the camera's].
    #[arg(long)]
    width: Option<u32>,
    /// Image height [default: the camera's].
    #[arg(long)]
    height: Option<u32>,
    #[command(flatten)]
    stage: StageArgs,
}

fn params(args: &Args) -> schemas::Result<Params> {
    let mut p: Params = load_params(args.stage.params.as_deref())?;
    p.bounces = args.bounces.unwrap_or(p.bounces);
    p.tolerance = args.tolerance.unwrap_or(p.tolerance);
    p.gauss_order = args.gauss_order.unwrap_or(p.gauss_order);
    p.max_depth = args.max_depth.unwrap_or(p.max_depth);
    p.nystrom_level = args.nystrom_level.unwrap_or(p.nystrom_level);
    p.width = args.width.or(p.width);
    p.height = args.height.or(p.height);
    p.validate().map_err(bad_parameter)?;
    Ok(p)
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let params = params(&args)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output)) = (args.mesh.as_deref(), args.manifest.as_deref(), args.output.as_deref()) else {
        unreachable!("clap requires the inputs and -o without --print-params")
    };
    check_outputs(&[Some(mesh_path), Some(manifest_path)], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start(STAGE, env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let exact = Exact::new(&mesh, &manifest, &params).map_err(|why| Error::invalid(manifest_path, None, format!("no exact image: {why}")))?;
    let (width, height) = exact.size();
    let nodes = progress(exact::transport::Transport::nodes_to_build(&exact.config, params.accuracy()), "nodes");
    let rows = progress(height as u64, "rows");
    let started = std::time::Instant::now();
    let image = exact.render(&params, &|n| nodes.inc(n), &|n| rows.inc(n));
    nodes.finish_and_clear();
    rows.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    let header = HdrImage::header(run.provenance(&params));
    let hdr = HdrImage {
        header,
        width,
        height,
        rgb: image.radiance.iter().map(|p| p.map(|v| v as f32)).collect(),
        coverage: image.coverage.clone(),
        surfaces: Some(image.surfaces.clone()),
    };
    let bound = |k: usize, name: &str| {
        Channel::f32(name, "bound of the radiance error, W/(m^2 sr), of the f64 value before its f32 rounding", image.bound.iter().map(|b| b[k] as f32).collect())
    };
    let extra = vec![bound(0, "error_bound.R"), bound(1, "error_bound.G"), bound(2, "error_bound.B")];
    let mut outputs = Outputs::new();
    outputs.write(output, |path| hdr.write_with(path, extra))?;
    outputs.keep()?;
    if let Some(report) = args.stage.report.as_deref() {
        let covered = image.coverage.iter().filter(|&&c| c > 0.0).count();
        let relative = image.radiance.iter().zip(&image.bound).filter(|(r, _)| r.iter().any(|v| *v > 0.0)).map(|(r, b)| (0..3).map(|k| b[k] / r[k].max(f64::MIN_POSITIVE)).fold(0.0, f64::max)).fold(0.0, f64::max);
        let counters = BTreeMap::from([
            ("pixels".to_string(), (width * height) as f64),
            ("covered_pixels".to_string(), covered as f64),
            ("integrand_evaluations".to_string(), image.evaluations as f64),
            ("largest_error_bound".to_string(), image.bound.iter().flatten().fold(0.0, |m: f64, b| m.max(*b))),
            ("largest_relative_error_bound".to_string(), relative),
            ("render_s".to_string(), seconds),
        ]);
        let notes = vec![format!(
            "{} surfaces on {} planes; bounces {}; pixels point-sampled at their centres",
            exact.config.surfaces.len(),
            exact.config.planes.len(),
            params.bounces
        )];
        run.write_report(report, &params, counters, Vec::new(), notes)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of(STAGE, run)
}

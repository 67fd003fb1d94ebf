//! `compare A.exr B.exr`: error of A against reference B, with tolerances.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use compare::{CompareError, Params, Which};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::mesh::Manifest;
use schemas::report::Report;
use schemas::solution::Solution;
use stage_kit::run::{bad_parameter, load_params, print_params, Run};
use schemas::Error;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Compares two images or two solutions; B is the reference. Images may come
/// from any renderer (any RGB(A) EXR); errors are given over the whole
/// image and per object and material. Exit 0: match (or no tolerance
/// given), 1: a given tolerance is exceeded, 2: error.
#[derive(Parser, Debug)]
#[command(version, about)]
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
    /// Thresholds tau on |L_a - L_b| / L_b per pixel, comma-separated [default: 0.02,0.05,0.1].
    #[arg(long, value_delimiter = ',')]
    tau: Option<Vec<f64>>,
    /// Leave out pixels whose surface emits (needs a surface layer in A or B).
    #[arg(long)]
    exclude_emitters: bool,
    /// Leave out pixels within N px of a silhouette or crease between surfaces (and of an emitter, with --exclude-emitters).
    #[arg(long, value_name = "N")]
    exclude_edges: Option<u32>,
    /// The scene's manifest: names objects and materials in the report (else they are numbered).
    #[arg(long)]
    manifest: Option<PathBuf>,
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
    params.exclude_emitters |= args.exclude_emitters;
    params.exclude_edges = args.exclude_edges.or(params.exclude_edges);
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
    /// Per-surface lines for stderr.
    table: Vec<String>,
}

fn named(error: CompareError, a: &Path, b: &Path) -> Error {
    let path = match error.which() {
        Which::A => a,
        Which::B => b,
    };
    Error::invalid(path, None, error.to_string())
}

/// Reads an image of this pipeline or a foreign EXR; a foreign one gets a
/// note (here and on stderr) that it carries no provenance.
fn read_image(path: &Path, run: &mut Run, notes: &mut Vec<String>) -> schemas::Result<HdrImage> {
    let (image, record, origin) = HdrImage::read_any(path)?;
    if let Some(note) = origin.foreign_note(path, &record) {
        eprintln!("compare: note: {note}");
        notes.push(note);
    }
    run.input(record)?;
    Ok(image)
}

/// Labels of object or material indices: the manifest's names where one
/// is given, else `#<index>`; [`schemas::image::NO_SURFACE`] never appears
/// (such pixels are not compared).
fn labeller(names: Option<Vec<String>>) -> impl Fn(u32) -> String {
    move |i| names.as_ref().and_then(|n| n.get(i as usize).cloned()).unwrap_or_else(|| format!("#{i}"))
}

fn compare_files(args: &Args, params: &Params, run: &mut Run, a: &Path, b: &Path) -> schemas::Result<Outcome> {
    // The kind is decided by A: an image, or else (when A's schema says it
    // is no image) a solution; B must then be of the same kind.
    let mut notes = Vec::new();
    let image_a = match read_image(a, run, &mut notes) {
        Ok(image) => image,
        Err(image_error @ Error::Schema { .. }) => return compare_solution_files(args, params, run, a, b, image_error),
        Err(other) => return Err(other),
    };
    let image_b = read_image(b, run, &mut notes)?;
    let manifest = match args.manifest.as_deref() {
        Some(path) => {
            let loaded = schemas::ron_io::read_ron::<Manifest>(path)?;
            run.input(loaded.input)?;
            Some(loaded.value)
        }
        None => None,
    };
    let result = compare::compare_images(&image_a, &image_b, params).map_err(|e| named(e, a, b))?;
    if let (Some(m), Some((s, which))) = (&manifest, compare::images::surfaces(&image_a, &image_b)) {
        let out_of_range = |list: &[u32], len: usize| list.iter().any(|&i| i != schemas::image::NO_SURFACE && i as usize >= len);
        if out_of_range(&s.object, m.objects.len()) || out_of_range(&s.material, m.materials.len()) {
            let path = if which == Which::A { a } else { b };
            return Err(Error::invalid(path, None, "surface layer names objects or materials the manifest does not have: is it this image's scene?"));
        }
    }
    let diff_png = match args.diff.as_deref() {
        Some(path) => {
            let picture = compare::images::difference_picture(&image_a, &image_b, &result.compared, params.tau_max());
            let (w, h, pixels) = compare::scale_bar::with_scale_bar(image_b.width, image_b.height, &picture, params.tau_max());
            Some(stage_kit::png::encode_png(w, h, &pixels).map_err(|e| Error::invalid(path, None, e))?)
        }
        None => None,
    };
    if result.coverage_mismatches > 0 {
        notes.push(format!("{} pixels are covered in one image only", result.coverage_mismatches));
    }
    if let Some(which) = result.surfaces_from {
        notes.push(format!("surfaces (objects, materials, edges) from {}", if which == Which::A { "A" } else { "B" }));
    }
    let object_label = labeller(manifest.as_ref().map(|m| m.objects.clone()));
    let material_label = labeller(manifest.as_ref().map(|m| m.materials.iter().map(|m| m.name.clone()).collect()));
    let table = surface_table(&result, params.tau_max(), &object_label, &material_label);
    Ok(Outcome { counters: result.counters(&object_label, &material_label), mode: "images", metrics: result.metrics, notes, diff_png, table })
}

/// The per-object and per-material lines printed on stderr.
fn surface_table(result: &compare::ImageComparison, tau_max: f64, object: &dyn Fn(u32) -> String, material: &dyn Fn(u32) -> String) -> Vec<String> {
    let mut lines = Vec::new();
    for (group, list, label) in [("object", &result.by_object, object), ("material", &result.by_material, material)] {
        if list.is_empty() {
            continue;
        }
        let over_tau = format!("over {}", compare::scale_bar::percent(tau_max));
        lines.push(format!("  {group:<24} {:>8} {:>13} {:>12} {over_tau:>10}", "pixels", "relative_rmse", "mean_signed"));
        for (index, m) in list {
            let over = m.percent_over(tau_max);
            lines.push(format!("  {:<24} {:>8} {:>13.5} {:>+11.3}% {:>9.2}%", label(*index), m.samples, m.relative_rmse, 100.0 * m.mean_signed_error, over));
        }
    }
    lines
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
    if params.exclusions().any() || args.manifest.is_some() {
        return Err(bad_parameter("--exclude-emitters, --exclude-edges and --manifest apply to images only; the inputs are solutions"));
    }
    run.input(record_a)?;
    let (solution_b, record_b) = Solution::read(b)?;
    run.input(record_b)?;
    let result = compare::compare_solutions(&solution_a, &solution_b, params).map_err(|e| named(e, a, b))?;
    Ok(Outcome {
        counters: result.counters(),
        mode: result.mode.describe(),
        metrics: result.metrics,
        notes: Vec::new(),
        diff_png: None,
        table: Vec::new(),
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
    check_outputs(&[Some(a), Some(b), args.manifest.as_deref()], &[args.output.as_deref(), args.diff.as_deref()])?;
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
        "compare: {verdict} ({}, {} samples: rmse {:.6}, relative_rmse {:.6}, mean_signed_error {:+.6}, {:.3}% over tau {})",
        outcome.mode,
        m.samples,
        m.rmse,
        m.relative_rmse,
        m.mean_signed_error,
        m.percent_over(params.tau_max()),
        params.tau_max()
    );
    for line in &outcome.table {
        eprintln!("{line}");
    }
    Ok(if exceeded.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn main() -> ExitCode {
    main_of("compare", run)
}

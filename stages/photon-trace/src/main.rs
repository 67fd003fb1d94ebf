//! `photon-trace`: see the library's documentation and `--help`.

use clap::Parser;
use photon_trace::{solve, Observer, Params, Progress, Snapshot, Stage};
use stage_kit::cli::{check_outputs, main_of};
use schemas::header::Schema;
use schemas::mesh::Effects;
use schemas::solution::Solution;
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

/// Paper 001's progressive hybrid solver: (1) photons from every emitter
/// bucketed into the mesh vertices, filtered over a kd-tree of the
/// vertices; (2) exact direct light (Lambert's formula with shadow rays;
/// I cos / r² for goniometric lights) on a mesh split where the Stevens
/// brightness differs across an element; (3) photons for the indirect
/// light until every vertex's estimated relative error is under
/// --target-error (or --max-photons, or --time-budget-s). Writes
/// solution.exr like the other solvers; with --snapshot-dir, the solutions
/// of the way there: DIR/stochastic.exr (end of stage 1), DIR/direct.exr
/// (end of stage 2), and, with --snapshot-every N, DIR/<stage>-<photons>.exr
/// about every N photons of stages 1 and 3.
#[derive(Parser, Debug)]
#[command(name = "photon-trace", version)]
struct Args {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output: the solution (EXR tables of elements; no links).
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Directory (existing) for the progressive solutions.
    #[arg(long)]
    snapshot_dir: Option<PathBuf>,
    /// With --snapshot-dir: a solution about every this many photons.
    #[arg(long, default_value_t = 0)]
    snapshot_every: u64,
    #[command(flatten)]
    stage: StageArgs,
    /// Seed of every photon and shadow ray.
    #[arg(long)]
    seed: Option<u64>,
    /// Photons per batch (the unit of the variance estimate).
    #[arg(long)]
    batch_photons: Option<usize>,
    /// Batches per round (traced in parallel; stop tests between rounds).
    #[arg(long)]
    batches_per_round: Option<usize>,
    /// Photons of stage 1 (every hit deposited).
    #[arg(long)]
    preview_photons: Option<u64>,
    /// Stop once every vertex's estimated relative standard error of radiosity is under this.
    #[arg(long)]
    target_error: Option<f64>,
    /// Stop stage 3 after this many photons.
    #[arg(long)]
    max_photons: Option<u64>,
    /// Stop stage 3 after this many seconds of the run (the result then depends on the machine).
    #[arg(long)]
    time_budget_s: Option<f64>,
    /// Errors are relative to the larger of a vertex's radiosity and this fraction of the mean.
    #[arg(long)]
    relative_floor: Option<f64>,
    /// Corners (and filter neighbours) whose normals differ by more than this, degrees, stay apart.
    #[arg(long)]
    crease_angle_deg: Option<f64>,
    /// Largest filter radius, a fraction of the bounding-box diagonal (0: no filtering).
    #[arg(long)]
    filter_radius: Option<f64>,
    /// Shadow rays per vertex and emitting triangle in the direct pass.
    #[arg(long)]
    visibility_rays: Option<usize>,
    /// Split an element when the Stevens brightness at an edge midpoint departs from its edge's interpolation by more than this.
    #[arg(long)]
    brightness_threshold: Option<f64>,
    /// Exponent of Stevens' power law.
    #[arg(long)]
    stevens_exponent: Option<f64>,
    /// Splitting passes at most.
    #[arg(long)]
    max_splits: Option<u32>,
    /// Smallest element area, a fraction of the scene's total area.
    #[arg(long)]
    min_area: Option<f64>,
    /// Before stage 1, split elements until none is larger than this fraction of the total area.
    #[arg(long)]
    initial_area: Option<f64>,
    /// Bounces after which a photon is dropped.
    #[arg(long)]
    max_bounces: Option<u32>,
}

fn params_of(args: &Args) -> schemas::Result<Params> {
    let mut p: Params = load_params(args.stage.params.as_deref())?;
    p.seed = args.seed.unwrap_or(p.seed);
    p.batch_photons = args.batch_photons.unwrap_or(p.batch_photons);
    p.batches_per_round = args.batches_per_round.unwrap_or(p.batches_per_round);
    p.preview_photons = args.preview_photons.unwrap_or(p.preview_photons);
    p.target_error = args.target_error.unwrap_or(p.target_error);
    p.max_photons = args.max_photons.unwrap_or(p.max_photons);
    p.time_budget_s = args.time_budget_s.or(p.time_budget_s);
    p.relative_floor = args.relative_floor.unwrap_or(p.relative_floor);
    p.crease_angle_deg = args.crease_angle_deg.unwrap_or(p.crease_angle_deg);
    p.filter_radius = args.filter_radius.unwrap_or(p.filter_radius);
    p.visibility_rays = args.visibility_rays.unwrap_or(p.visibility_rays);
    p.brightness_threshold = args.brightness_threshold.unwrap_or(p.brightness_threshold);
    p.stevens_exponent = args.stevens_exponent.unwrap_or(p.stevens_exponent);
    p.max_splits = args.max_splits.unwrap_or(p.max_splits);
    p.min_area = args.min_area.unwrap_or(p.min_area);
    p.initial_area = args.initial_area.unwrap_or(p.initial_area);
    p.max_bounces = args.max_bounces.unwrap_or(p.max_bounces);
    match p.problem() {
        Some(problem) => Err(bad_parameter(problem)),
        None => Ok(p),
    }
}

/// What this stage does not simulate, for the effects the scene has.
fn skipped(effects: &Effects) -> Vec<String> {
    Effects::skipped(&[
        (effects.specular_reflection, "specular reflection: photons reflect off mirrors, but solution.exr holds diffuse radiosity only, so the preview shows a mirror's diffuse part"),
        (effects.specular_transmission, "specular transmission: photons pass through as through a thin sheet (no refraction: materials carry no index); the preview shows the glass's diffuse part"),
        (effects.diffuse_transmission, "diffuse transmission: not simulated by photon-trace"),
        (effects.textures, "textures: photons use each material's mean diffuse reflectance"),
        (effects.alpha_masks, "alpha masks: surfaces are treated as opaque"),
        (effects.normal_maps, "normal maps: photons bounce about geometric normals"),
    ])
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let params = params_of(&args)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output)) = (&args.mesh, &args.manifest, &args.output) else {
        unreachable!("clap requires the inputs and output without --print-params")
    };
    if args.snapshot_every > 0 && args.snapshot_dir.is_none() {
        return Err(bad_parameter("--snapshot-every needs --snapshot-dir"));
    }
    let probe = args.snapshot_dir.as_ref().map(|d| d.join("direct.exr"));
    check_outputs(&[args.mesh.as_deref(), args.manifest.as_deref()], &[Some(output), args.stage.report.as_deref(), probe.as_deref()])?;
    let mut run = Run::start("photon-trace", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let skipped = skipped(&manifest.effects);
    for note in &skipped {
        eprintln!("photon-trace: skipped: {note}");
    }
    let header = Solution::header(run.provenance(&params));
    let bar = progress(params.max_photons, "photons");
    let mut on_progress = |p: &Progress| {
        bar.set_position(if p.stage == Stage::Indirect { p.photons } else { 0 });
        bar.set_message(format!("{}: {} photons, error {:.2e}", p.stage, p.photons, p.max_error));
    };
    let mut snapshots: Vec<(String, Stage, u64, f64, f64)> = Vec::new();
    let mut on_snapshot = |s: &Snapshot| -> Result<(), String> {
        let Some(dir) = &args.snapshot_dir else { return Ok(()) };
        let name = match s.stage {
            Stage::Direct => "direct.exr".to_string(),
            Stage::Stochastic if s.photons >= params.preview_photons => "stochastic.exr".to_string(),
            stage => format!("{stage}-{:012}.exr", s.photons),
        };
        let path = dir.join(&name);
        let solution = Solution { header: header.clone(), elements: s.elements.clone(), clusters: Vec::new(), links: Vec::new() };
        let mut outputs = Outputs::new();
        outputs.write(&path, |p| solution.write(p)).and_then(|()| outputs.keep()).map_err(|e| e.to_string())?;
        snapshots.push((name, s.stage, s.photons, s.seconds, s.max_error));
        Ok(())
    };
    let mut observer = Observer { progress: &mut on_progress, snapshot_every: args.snapshot_every, snapshot: &mut on_snapshot };
    let solved = solve(&mesh, &manifest, &params, &mut observer).map_err(|message| schemas::Error::invalid(manifest_path, None, message))?;
    bar.finish_and_clear();
    let w = &solved.work;
    eprintln!(
        "photon-trace: {} + {} photons, {} splits, {} vertices, {} leaves; first image {:.2} s, direct done {:.2} s, final {:.2} s ({})",
        w.stage1_photons, w.stage3_photons, w.splits, w.vertices, w.leaves, w.first_image_s, w.direct_s, w.final_s, w.stopped_by
    );
    let mut notes = Vec::new();
    if !w.converged {
        let last = w.curve.last().map_or(f64::NAN, |p| p.max_error);
        let note = format!("target_error {} not reached: stopped by {} with a largest vertex error of {last:.3e}", params.target_error, w.stopped_by);
        eprintln!("photon-trace: warning: {note}");
        notes.push(note);
    }
    if w.capped_photons > 0 {
        notes.push(format!("{} photons reached max_bounces = {} and were dropped (their remaining power is lost)", w.capped_photons, params.max_bounces));
    }
    for (name, stage, photons, seconds, error) in &snapshots {
        let error = if error.is_finite() { format!(", largest vertex error {error:.3e}") } else { String::new() };
        notes.push(format!("snapshot {name}: {stage} stage, {photons} photons, {seconds:.3} s{error}"));
    }
    let solution = Solution { header, elements: solved.elements, clusters: Vec::new(), links: Vec::new() };
    let mut outputs = Outputs::new();
    outputs.write(output, |p| solution.write(p))?;
    if let Some(report) = &args.stage.report {
        let mut counters = BTreeMap::from([
            ("stage1_photons".to_string(), w.stage1_photons as f64),
            ("stage3_photons".to_string(), w.stage3_photons as f64),
            ("photon_rays".to_string(), w.photon_rays as f64),
            ("direct_rays".to_string(), w.direct_rays as f64),
            ("capped_photons".to_string(), w.capped_photons as f64),
            ("splits".to_string(), w.splits as f64),
            ("elements".to_string(), w.elements as f64),
            ("leaves".to_string(), w.leaves as f64),
            ("vertices".to_string(), w.vertices as f64),
            ("converged".to_string(), f64::from(u8::from(w.converged))),
            ("first_image_s".to_string(), w.first_image_s),
            ("stage1_s".to_string(), w.stage1_s),
            ("direct_s".to_string(), w.direct_s),
            ("final_s".to_string(), w.final_s),
        ]);
        // The error against time: curve.NNN.{stage,photons,seconds,max_error,mean_error}
        // (stage 1 = stochastic, 3 = indirect).
        for (k, p) in w.curve.iter().enumerate() {
            let stage = if p.stage == Stage::Stochastic { 1.0 } else { 3.0 };
            for (field, value) in [("stage", stage), ("photons", p.photons as f64), ("seconds", p.seconds), ("max_error", p.max_error), ("mean_error", p.mean_error)] {
                counters.insert(format!("curve.{k:03}.{field}"), value);
            }
        }
        if let Some(p) = w.curve.last() {
            counters.insert("max_relative_error".to_string(), p.max_error);
            counters.insert("mean_relative_error".to_string(), p.mean_error);
        }
        outputs.write(report, |p| run.write_report(p, &params, counters, skipped.clone(), notes.clone()))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("photon-trace", run)
}

//! `structured-sample`: see the library's documentation and `--help`.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::mesh::Effects;
use schemas::samples::{Reason, Samples};
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use structured_sample::{structured, Params, Progress};

/// Paper 002's structured sampling on a prepared mesh: samples placed
/// along the direct light's isolux contours (by curvature), across shadow
/// boundaries and by screen density, each tagged with its reason; exact
/// direct light at each; secondary emitter polygons of isolux regions shot
/// progressively with vertex-ray occlusion; grid resampling with the
/// conical filter (tag-aware at shadow boundaries) for display. Writes the
/// samples (samples.exr) and the displayed image (an HDR image EXR).
#[derive(Parser, Debug)]
#[command(name = "structured-sample", version)]
struct Args {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output: the samples (EXR tables).
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Output: the displayed image (HDR EXR, radiance).
    #[arg(long, required_unless_present = "print_params")]
    image: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// Probe grid cells along a surface's longer side.
    #[arg(long)]
    probe_resolution: Option<usize>,
    /// Isolux bands per surface.
    #[arg(long)]
    levels: Option<usize>,
    /// Sample spacing along a straight contour, fraction of the surface's extent.
    #[arg(long)]
    contour_spacing: Option<f64>,
    /// Turning of a contour between two samples, degrees.
    #[arg(long)]
    turn_angle_deg: Option<f64>,
    /// Lattice spacing in smooth regions, fraction of the extent.
    #[arg(long)]
    lattice_spacing: Option<f64>,
    /// Sample spacing in a penumbra, fraction of the extent.
    #[arg(long)]
    shadow_spacing: Option<f64>,
    /// Sample spacing in an umbra, fraction of the extent.
    #[arg(long)]
    umbra_spacing: Option<f64>,
    /// One display sample per this many pixels squared.
    #[arg(long)]
    screen_spacing: Option<u32>,
    /// Rays per light-source triangle for the direct light's visibility.
    #[arg(long)]
    visibility_rays: Option<usize>,
    /// Least area of a secondary emitter, fraction of its surface's.
    #[arg(long)]
    emitter_min_area: Option<f64>,
    /// At most this many of a secondary emitter's vertices cast occlusion rays.
    #[arg(long)]
    occlusion_vertices: Option<usize>,
    /// Stop shooting under this fraction of the emitted power.
    #[arg(long)]
    threshold: Option<f64>,
    /// Most shots.
    #[arg(long)]
    max_shots: Option<usize>,
    /// Reflections off secondary emitters (0: all).
    #[arg(long)]
    bounces: Option<u32>,
    /// Display grid cells along a surface's longer side.
    #[arg(long)]
    display_resolution: Option<usize>,
    /// Display filter: conical (paper 002's) or conical-linear (first-order corrected).
    #[arg(long, value_enum)]
    filter: Option<structured_sample::display::Filter>,
    /// Conical filter radius, fraction of the extent.
    #[arg(long)]
    filter_radius: Option<f64>,
    /// Filter radius near shadow-boundary samples, fraction of the extent.
    #[arg(long)]
    shadow_filter_radius: Option<f64>,
    /// Image width (default: the camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (default: the camera's).
    #[arg(long)]
    height: Option<u32>,
    /// Rays per pixel along each side.
    #[arg(long)]
    spp_side: Option<u32>,
    /// Seed of the visibility rays.
    #[arg(long)]
    seed: Option<u64>,
}

fn params_of(args: &Args) -> schemas::Result<Params> {
    let mut p: Params = load_params(args.stage.params.as_deref())?;
    p.probe_resolution = args.probe_resolution.unwrap_or(p.probe_resolution);
    p.levels = args.levels.unwrap_or(p.levels);
    p.contour_spacing = args.contour_spacing.unwrap_or(p.contour_spacing);
    p.turn_angle_deg = args.turn_angle_deg.unwrap_or(p.turn_angle_deg);
    p.lattice_spacing = args.lattice_spacing.unwrap_or(p.lattice_spacing);
    p.shadow_spacing = args.shadow_spacing.unwrap_or(p.shadow_spacing);
    p.umbra_spacing = args.umbra_spacing.unwrap_or(p.umbra_spacing);
    p.screen_spacing = args.screen_spacing.unwrap_or(p.screen_spacing);
    p.visibility_rays = args.visibility_rays.unwrap_or(p.visibility_rays);
    p.emitter_min_area = args.emitter_min_area.unwrap_or(p.emitter_min_area);
    p.occlusion_vertices = args.occlusion_vertices.unwrap_or(p.occlusion_vertices);
    p.threshold = args.threshold.unwrap_or(p.threshold);
    p.max_shots = args.max_shots.unwrap_or(p.max_shots);
    p.bounces = args.bounces.unwrap_or(p.bounces);
    p.display_resolution = args.display_resolution.unwrap_or(p.display_resolution);
    p.filter = args.filter.unwrap_or(p.filter);
    p.filter_radius = args.filter_radius.unwrap_or(p.filter_radius);
    p.shadow_filter_radius = args.shadow_filter_radius.unwrap_or(p.shadow_filter_radius);
    p.width = args.width.or(p.width);
    p.height = args.height.or(p.height);
    p.spp_side = args.spp_side.unwrap_or(p.spp_side);
    p.seed = args.seed.unwrap_or(p.seed);
    match p.problem() {
        Some(problem) => Err(bad_parameter(problem)),
        None => Ok(p),
    }
}

/// What this stage does not simulate, for the effects the scene has.
fn skipped(effects: &Effects) -> Vec<String> {
    Effects::skipped(&[
        (effects.goniometric_lights, "goniometric lights: structured-sample lights the scene by its emitting surfaces only"),
        (effects.specular_reflection, "specular reflection: not simulated; mirrors keep their diffuse part only"),
        (effects.specular_transmission, "specular transmission: not simulated"),
        (effects.diffuse_transmission, "diffuse transmission: not simulated"),
        (effects.textures, "textures: each material's mean diffuse reflectance is used"),
        (effects.alpha_masks, "alpha masks: surfaces are treated as opaque"),
        (effects.normal_maps, "normal maps: geometric normals are used"),
    ])
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let params = params_of(&args)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output), Some(image_path)) = (&args.mesh, &args.manifest, &args.output, &args.image) else {
        unreachable!("clap requires the inputs and outputs without --print-params")
    };
    check_outputs(&[Some(mesh_path), Some(manifest_path)], &[Some(output), Some(image_path), args.stage.report.as_deref()])?;
    let mut run = Run::start("structured-sample", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    // One bar per phase; the step callback ticks whichever is current.
    let bar = std::sync::Mutex::new(progress(0, "starting"));
    let phase = |name: &str, steps: u64| std::mem::replace(&mut *bar.lock().expect("progress lock"), progress(steps, name)).finish_and_clear();
    let step = || bar.lock().expect("progress lock").inc(1);
    let result = structured(&mesh, &manifest, &params, &Progress { phase: &phase, step: &step }).map_err(|m| schemas::Error::invalid(mesh_path, None, m))?;
    bar.lock().expect("progress lock").finish_and_clear();
    let w = &result.work;
    let count = |r: Reason| w.samples_by_reason[r as usize];
    eprintln!(
        "structured-sample: {} samples ({} contour, {} penumbra, {} umbra, {} edge, {} lattice, {} screen), {} secondary emitters, {} shots",
        result.samples.len(),
        count(Reason::IsoluxContour),
        count(Reason::Penumbra),
        count(Reason::Umbra),
        count(Reason::SurfaceEdge),
        count(Reason::SmoothLattice),
        count(Reason::ScreenDensity),
        result.emitters.len(),
        w.shooting.shots
    );
    let mut notes = Vec::new();
    if !w.shooting.converged {
        let note = format!("threshold not reached: max_shots = {} stopped the shooting with {:.3e} of the emitted power unshot", params.max_shots, w.shooting.remaining);
        eprintln!("structured-sample: warning: {note}");
        notes.push(note);
    }
    let provenance = run.provenance(&params);
    let samples = Samples { header: Samples::header(provenance.clone()), samples: result.samples, surfaces: result.surfaces, emitters: result.emitters };
    let film = result.film;
    let image = HdrImage {
        header: HdrImage::header(provenance),
        width: result.size.0 as usize,
        height: result.size.1 as usize,
        rgb: film.rgb,
        coverage: film.coverage,
        surfaces: Some(film.surfaces),
    };
    let mut outputs = Outputs::new();
    outputs.write(output, |p| samples.write(p))?;
    outputs.write(image_path, |p| image.write(p))?;
    if let Some(report) = &args.stage.report {
        let mut counters = BTreeMap::from([
            ("samples".to_string(), samples.samples.len() as f64),
            ("secondary_emitters".to_string(), samples.emitters.len() as f64),
            ("probes".to_string(), w.probes as f64),
            ("direct_rays".to_string(), w.direct_rays as f64),
            ("shots".to_string(), w.shooting.shots as f64),
            ("shooting_rays".to_string(), w.shooting.rays as f64),
            ("unshot_fraction".to_string(), w.shooting.remaining),
            ("converged".to_string(), f64::from(u8::from(w.shooting.converged))),
            ("placement_seconds".to_string(), w.placement_seconds),
            ("direct_seconds".to_string(), w.direct_seconds),
            ("shooting_seconds".to_string(), w.shooting_seconds),
            ("indirect_rays".to_string(), w.indirect_rays as f64),
            ("indirect_placement_seconds".to_string(), w.indirect_placement_seconds),
            ("display_seconds".to_string(), w.display_seconds),
        ]);
        for r in Reason::ALL {
            counters.insert(format!("samples_{r:?}"), count(r) as f64);
        }
        outputs.write(report, |p| run.write_report(p, &params, counters, skipped(&manifest.effects), notes.clone()))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("structured-sample", run)
}

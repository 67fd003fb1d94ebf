//! `grid-gather`: renders a radiosity solution to an HDR image (preview
//! mode: Gouraud interpolation of element radiosity). See the library docs.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use grid_gather::contrast::ContrastImage;
use grid_gather::{gather_with, image_size, Extras, GridKind, Mode, Params, Scene};
use schemas::cluster::Clusters;
use schemas::diagnostics::GatherDiagnostics;
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use schemas::surface::Surface;
use grid_gather::detail::Detail;
use schemas::threshold::ThresholdImage;
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, read_surface, Outputs, Run, StageArgs};
use schemas::Result;
use std::path::PathBuf;
use std::process::ExitCode;

const STAGE: &str = "grid-gather";

/// The mask's contrast channel (schema `threshold`), as the gather uses it.
fn read_threshold(path: &std::path::Path) -> Result<(ContrastImage, schemas::header::Input)> {
    let (t, input) = ThresholdImage::read(path)?;
    Ok((ContrastImage { width: t.width, height: t.height, contrast: t.contrast }, input))
}

/// Render the radiosity solution through the manifest camera to a linear HDR
/// image (R, G, B radiance in W/(m^2 sr), A coverage).
#[derive(Parser, Debug)]
#[command(name = STAGE, version)]
struct Args {
    /// Mesh (mesh.exr from mesh-prep).
    #[arg(long, value_name = "MESH.exr", required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Manifest (manifest.ron from mesh-prep): camera, effects.
    #[arg(long, value_name = "MANIFEST.ron", required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Surface detail (surface.exr from mesh-prep --surface): textures,
    /// alpha masks and normal maps, read only when the scene has some.
    #[arg(long, value_name = "SURFACE.exr")]
    surface: Option<PathBuf>,
    /// Radiosity solution (solution.exr from hierarchical-solve).
    #[arg(long, value_name = "SOLUTION.exr", required_unless_present = "print_params")]
    solution: Option<PathBuf>,
    /// Output image.
    #[arg(short = 'o', long = "output", value_name = "IMAGE.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Gather mode: preview interpolates the solution; full classifies and
    /// resamples critical senders (paper 000); brute resamples every link.
    #[arg(long, value_enum)]
    mode: Option<Mode>,
    /// The classic brute-force final gather (same as --mode brute).
    #[arg(long)]
    brute: bool,
    /// Threshold image from the mask stage steering the full gather.
    #[arg(long, value_name = "THRESHOLD.exr")]
    threshold: Option<PathBuf>,
    /// Cluster hierarchy (clusters.exr) of a clustered solution.
    #[arg(long, value_name = "CLUSTERS.exr")]
    clusters: Option<PathBuf>,
    /// Per-pixel samples and classes, per-vertex class counts (full, brute).
    #[arg(long, value_name = "DIAGNOSTICS.exr")]
    diagnostics: Option<PathBuf>,
    /// Full: grid kind [default: perspective].
    #[arg(long, value_enum)]
    grid: Option<GridKind>,
    /// Full: grid spacing on screen, pixels [default: 16].
    #[arg(long, value_name = "PIXELS")]
    grid_pixels: Option<u32>,
    /// Full: cells along the view axis [default: 16].
    #[arg(long, value_name = "N")]
    grid_depth: Option<u32>,
    /// Full: N of Eq. 1, classification samples per vertex [default: 128].
    #[arg(long, value_name = "N")]
    samples: Option<u32>,
    /// Full: fewest samples per sender [default: 4].
    #[arg(long, value_name = "N")]
    min_samples: Option<u32>,
    /// Full: most shadow samples per resampled sender [default: 128].
    #[arg(long, value_name = "N")]
    max_shadow_samples: Option<u32>,
    /// Full: smallest visible contrast without a mask [default: 0.02].
    #[arg(long, value_name = "FRACTION")]
    contrast: Option<f64>,
    /// Full: surfaces a classification ray may cross unblocked, 1 or 2 [default: 1].
    #[arg(long, value_name = "N")]
    allowed_hits: Option<u32>,
    /// Full: rays per leaf to check a fully visible or occluded link of the surface-based gather, 0 to trust the solver [default: 8].
    #[arg(long, value_name = "N")]
    leaf_check_rays: Option<u32>,
    /// Full: rays from a vertex inside a sender cluster [default: 100].
    #[arg(long, value_name = "N")]
    interior_rays: Option<u32>,
    /// Full: surface-based gather where leaves are finer than the grid [default: on].
    #[arg(long, overrides_with = "no_surface_gather")]
    surface_gather: bool,
    /// Full: grid gather everywhere.
    #[arg(long, overrides_with = "surface_gather")]
    no_surface_gather: bool,
    /// Full: view-dependent shadow samples [default: on].
    #[arg(long, overrides_with = "no_view_dependent")]
    view_dependent: bool,
    /// Full: shadow samples from Eq. 1 only.
    #[arg(long, overrides_with = "view_dependent")]
    no_view_dependent: bool,
    /// Brute: visibility rays per link per camera sample [default: 64].
    #[arg(long, value_name = "N")]
    brute_samples: Option<u32>,
    /// Most mirror reflections and glass passages along a camera ray [default: 8].
    #[arg(long, value_name = "N")]
    specular_depth: Option<u32>,
    /// A ray through mirrors and glass stops when its weight (product of rho_s, tau_s) falls under this [default: 1e-3].
    #[arg(long, value_name = "FRACTION")]
    specular_min_weight: Option<f64>,
    /// Image width in pixels [default: the manifest camera's].
    #[arg(long, value_name = "W")]
    width: Option<u32>,
    /// Image height in pixels [default: the manifest camera's].
    #[arg(long, value_name = "H")]
    height: Option<u32>,
    /// Camera rays per pixel, stratified and jittered [default: 4].
    #[arg(long, value_name = "N")]
    spp: Option<u32>,
    /// Seed of the per-pixel random streams [default: 0].
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// Leaves whose normals differ by more than this do not blend at a
    /// shared corner, degrees [default: 30].
    #[arg(long, value_name = "DEG")]
    crease_angle_deg: Option<f64>,
    /// Corners closer than this fraction of the scene diagonal are one
    /// point [default: 1e-7].
    #[arg(long, value_name = "FRACTION")]
    weld_tolerance: Option<f64>,
    /// Leaves of different materials do not blend at a shared corner
    /// [default: on].
    #[arg(long, overrides_with = "no_material_seams")]
    material_seams: bool,
    /// Let leaves of different materials blend (only the crease angle
    /// separates them).
    #[arg(long, overrides_with = "material_seams")]
    no_material_seams: bool,
    #[command(flatten)]
    stage: StageArgs,
}

impl Args {
    /// Parameters from `--params` (or defaults), overridden by flags.
    fn params(&self) -> Result<Params> {
        let mut p: Params = load_params(self.stage.params.as_deref())?;
        if let Some(mode) = self.mode {
            p.mode = mode;
        }
        if self.width.is_some() {
            p.width = self.width;
        }
        if self.height.is_some() {
            p.height = self.height;
        }
        if let Some(spp) = self.spp {
            p.spp = spp;
        }
        if let Some(seed) = self.seed {
            p.seed = seed;
        }
        if let Some(angle) = self.crease_angle_deg {
            p.crease_angle_deg = angle;
        }
        if let Some(tolerance) = self.weld_tolerance {
            p.weld_tolerance = tolerance;
        }
        if self.material_seams {
            p.material_seams = true;
        }
        if self.no_material_seams {
            p.material_seams = false;
        }
        if self.brute {
            p.mode = Mode::Brute;
        }
        if let Some(g) = self.grid {
            p.grid = g;
        }
        macro_rules! set {
            ($($f:ident),*) => { $(if let Some(v) = self.$f { p.$f = v; })* };
        }
        set!(grid_pixels, grid_depth, samples, min_samples, max_shadow_samples, contrast, allowed_hits, leaf_check_rays, interior_rays, brute_samples, specular_depth, specular_min_weight);
        if self.surface_gather {
            p.surface_gather = true;
        }
        if self.no_surface_gather {
            p.surface_gather = false;
        }
        if self.view_dependent {
            p.view_dependent = true;
        }
        if self.no_view_dependent {
            p.view_dependent = false;
        }
        p.validate()?;
        Ok(p)
    }
}

fn run(args: &Args) -> Result<ExitCode> {
    let params = args.params()?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    if args.threshold.is_some() && params.mode != Mode::Full {
        return Err(bad_parameter("--threshold is read only by --mode full"));
    }
    if args.diagnostics.is_some() && params.mode == Mode::Preview {
        return Err(bad_parameter("--diagnostics is written only by --mode full and brute"));
    }
    // clap requires these unless --print-params.
    let (Some(mesh_path), Some(manifest_path), Some(solution_path), Some(output)) =
        (&args.mesh, &args.manifest, &args.solution, &args.output)
    else {
        return Err(bad_parameter("--mesh, --manifest, --solution and -o are required"));
    };

    check_outputs(
        &[args.mesh.as_deref(), args.manifest.as_deref(), args.solution.as_deref(), args.surface.as_deref()],
        &[Some(output), args.diagnostics.as_deref(), args.stage.report.as_deref()],
    )?;
    let mut run = Run::start(STAGE, env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let (solution, input) = Solution::read(solution_path)?;
    run.input(input)?;

    let clusters = match &args.clusters {
        Some(path) => {
            let (c, input) = Clusters::read(path, mesh.triangles.len())?;
            run.input(input)?;
            Some(c)
        }
        None => None,
    };
    let threshold = match &args.threshold {
        Some(path) => {
            let (t, input) = read_threshold(path)?;
            run.input(input)?;
            Some(t)
        }
        None => None,
    };

    let surface = match &args.surface {
        Some(path) if manifest.effects.surface_detail() => Some(read_surface_for(&mut run, path, mesh_path, &mesh, &manifest, &solution)?),
        _ => None,
    };
    let detail = surface.as_ref().map(|(s, solved_with)| Detail::new(s, &mesh, &manifest, *solved_with));
    let scene = Scene { mesh: &mesh, manifest: &manifest, manifest_path, solution: &solution, solution_path };
    let extras = Extras { clusters: clusters.as_ref(), threshold: threshold.as_ref(), detail: detail.as_ref() };
    let bar = progress(image_size(&params, &manifest).1.into(), "rows");
    let rendered = gather_with(&params, &scene, extras, &|rows| bar.inc(rows));
    bar.finish_and_clear();
    let (rendered, diagnostics) = rendered?;

    let mut outputs = Outputs::new();
    let image = HdrImage {
        header: HdrImage::header(run.provenance(&params)),
        width: rendered.width,
        height: rendered.height,
        rgb: rendered.rgb,
        coverage: rendered.coverage,
        surfaces: Some(rendered.surfaces),
    };
    outputs.write(output, |p| image.write(p))?;
    if let (Some(path), Some(d)) = (&args.diagnostics, &diagnostics) {
        outputs.write(path, |p| d.write(p, GatherDiagnostics::header(run.provenance(&params))))?;
    }
    let warnings = back_face_warning(&rendered.counters).into_iter().collect::<Vec<_>>();
    for warning in &warnings {
        eprintln!("{STAGE}: warning: {warning}");
    }
    if let Some(report) = &args.stage.report {
        outputs.write(report, |p| run.write_report(p, &params, rendered.counters, rendered.skipped, warnings))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

/// Reads the surface artifact at `path` for `mesh`: it must come from the
/// mesh-prep run that wrote the mesh. Also says whether `solution` was
/// solved with it (an input of the solve has the same content), so that its
/// element radiosity reflects the texture averages ([`Detail::new`]).
fn read_surface_for(run: &mut Run, path: &std::path::Path, mesh_path: &std::path::Path, mesh: &Mesh, manifest: &Manifest, solution: &Solution) -> Result<(Surface, bool)> {
    let (surface, input) = read_surface(path, mesh_path, mesh, manifest)?;
    let solved_with = solution.header.provenance.inputs.iter().any(|i| i.sha256 == input.sha256);
    // Recorded without the provenance it carries, which is the mesh's
    // (checked above, and recorded with the mesh): a solution solved
    // without the surface artifact (a solver that does not read it) then
    // is not refused as made from another mesh-prep run.
    run.input(schemas::header::Input { made_by: None, ..input })?;
    Ok((surface, solved_with))
}

/// A warning when more than 1% of the camera's hits are back faces, which
/// show black: the camera sits outside a wall, or thin surfaces (leaves,
/// paper) are one-sided where they should be two-sided.
fn back_face_warning(counters: &std::collections::BTreeMap<String, f64>) -> Option<String> {
    let (hits, back) = (counters.get("ray_hits")?, counters.get("back_face_hits")?);
    (*back > 0.01 * hits).then(|| {
        format!(
            "{:.1}% of the camera's hits are back faces, shown black: a camera outside a wall, or thin surfaces (leaves, paper) that need `two_sided: Some(true)` in the scene's material overrides",
            100.0 * back / hits
        )
    })
}

fn main() -> ExitCode {
    main_of(STAGE, |args: Args| run(&args))
}

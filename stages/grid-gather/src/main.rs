//! `grid-gather`: renders a radiosity solution to an HDR image (preview
//! mode: Gouraud interpolation of element radiosity). See the library docs.

use clap::Parser;
use grid_gather::{gather, image_size, Mode, Params, Scene, FULL_NOT_IMPLEMENTED};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use schemas::stage::{bad_parameter, exit_code, load_params, print_params, progress, Run};
use schemas::Result;
use std::path::PathBuf;
use std::process::ExitCode;

const STAGE: &str = "grid-gather";

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
    /// Radiosity solution (solution.exr from hierarchical-solve).
    #[arg(long, value_name = "SOLUTION.exr", required_unless_present = "print_params")]
    solution: Option<PathBuf>,
    /// Output image.
    #[arg(short = 'o', long = "output", value_name = "IMAGE.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Gather mode: preview interpolates the solution; full (not implemented
    /// yet) resamples critical senders.
    #[arg(long, value_enum)]
    mode: Option<Mode>,
    /// Threshold-elevation image steering the full gather (full mode only).
    #[arg(long, value_name = "IMAGE.exr")]
    threshold: Option<PathBuf>,
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
    /// Parameters file (RON); flags override its values.
    #[arg(long, value_name = "PARAMS.ron")]
    params: Option<PathBuf>,
    /// Print the effective parameters as RON on stdout and exit.
    #[arg(long)]
    print_params: bool,
    /// Write a report (work counters, what was skipped, wall time).
    #[arg(long, value_name = "REPORT.ron")]
    report: Option<PathBuf>,
}

impl Args {
    /// Parameters from `--params` (or defaults), overridden by flags.
    fn params(&self) -> Result<Params> {
        let mut p: Params = load_params(self.params.as_deref())?;
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
        p.validate()?;
        Ok(p)
    }
}

fn run(args: &Args) -> Result<ExitCode> {
    let params = args.params()?;
    if args.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    if params.mode == Mode::Full {
        return Err(bad_parameter(FULL_NOT_IMPLEMENTED));
    }
    if args.threshold.is_some() {
        return Err(bad_parameter("--threshold is read only by --mode full"));
    }
    // clap requires these unless --print-params.
    let (Some(mesh_path), Some(manifest_path), Some(solution_path), Some(output)) =
        (&args.mesh, &args.manifest, &args.solution, &args.output)
    else {
        return Err(bad_parameter("--mesh, --manifest, --solution and -o are required"));
    };

    let mut run = Run::start(STAGE, env!("CARGO_PKG_VERSION"));
    let (mesh, input) = Mesh::read(mesh_path)?;
    run.input(input);
    let manifest = read_ron::<Manifest>(manifest_path)?;
    run.input(manifest.input);
    let manifest = manifest.value;
    manifest.check_mesh(mesh_path, &mesh)?;
    let (solution, input) = Solution::read(solution_path)?;
    run.input(input);

    let scene = Scene { mesh: &mesh, manifest: &manifest, manifest_path, solution: &solution, solution_path };
    let bar = progress(image_size(&params, &manifest).1.into(), "rows");
    let rendered = gather(&params, &scene, &|rows| bar.inc(rows));
    bar.finish_and_clear();
    let rendered = rendered?;

    HdrImage {
        header: HdrImage::header(run.provenance(&params)),
        width: rendered.width,
        height: rendered.height,
        rgb: rendered.rgb,
        coverage: rendered.coverage,
    }
    .write(output)?;
    if let Some(report) = &args.report {
        run.write_report(report, &params, rendered.counters, rendered.skipped, Vec::new())?;
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    let args = Args::parse();
    exit_code(STAGE, run(&args))
}

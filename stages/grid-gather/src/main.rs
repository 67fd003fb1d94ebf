//! `grid-gather`: renders a radiosity solution to an HDR image. See the
//! library docs and `grid-gather --help`.

use clap::Parser;
use grid_gather::detail::Detail;
use grid_gather::{back_face_warning, gather_with, image_size, Extras, Mode, Params, Scene};
use schemas::cluster::Clusters;
use schemas::diagnostics::GatherDiagnostics;
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::solution::Solution;
use schemas::threshold::ThresholdImage;
use schemas::Result;
use stage_kit::run::{bad_parameter, progress, read_surface, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Render the radiosity solution through the manifest camera to a linear HDR
/// image (R, G, B radiance in W/(m^2 sr), A coverage).
#[derive(Parser, Debug)]
#[command(name = "grid-gather", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Surface detail (surface.exr from mesh-prep --surface: textures, alpha masks, normal maps), read only when the scene has some.
    #[arg(long, value_name = "SURFACE.exr")]
    surface: Option<PathBuf>,
    /// Radiosity solution (solution.exr from hierarchical-solve).
    #[arg(long, value_name = "SOLUTION.exr", required_unless_present = "print_params")]
    solution: Option<PathBuf>,
    /// Output image.
    #[arg(short = 'o', long = "output", value_name = "IMAGE.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
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
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        let [mesh, manifest] = self.scene.paths();
        (vec![mesh, manifest, self.solution.as_deref(), self.surface.as_deref()], vec![self.output.as_deref(), self.diagnostics.as_deref()])
    }

    fn settle(&self, params: &mut Params) -> Result<()> {
        if self.brute {
            params.mode = Mode::Brute;
        }
        params.validate()?;
        if self.threshold.is_some() && params.mode != Mode::Full {
            return Err(bad_parameter("--threshold is read only by --mode full"));
        }
        if self.diagnostics.is_some() && params.mode == Mode::Preview {
            return Err(bad_parameter("--diagnostics is written only by --mode full and brute"));
        }
        Ok(())
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let solution_path = required(&self.solution, "--solution")?;
        let (solution, input) = Solution::read(solution_path)?;
        run.input(input)?;
        let clusters = self.clusters.as_deref().map(|path| Clusters::read(path, mesh.triangles.len()).and_then(|(c, input)| run.input(input).map(|_| c))).transpose()?;
        let threshold = self.threshold.as_deref().map(|path| ThresholdImage::read(path).and_then(|(t, input)| run.input(input).map(|_| t))).transpose()?;
        let surface = match &self.surface {
            Some(path) if manifest.effects.surface_detail() => Some(read_surface(path, required(&self.scene.mesh, "--mesh")?, &mesh, &manifest)?),
            _ => None,
        };
        // Recorded without the provenance it carries (the mesh's), so that
        // a solution solved without it is not refused as another run's.
        if let Some((_, input)) = &surface {
            run.input(schemas::header::Input { made_by: None, ..input.clone() })?;
        }
        let detail = surface.as_ref().map(|(s, input)| Detail::new(s, &mesh, &manifest, Detail::solved_with(&solution, input)));
        let scene = Scene { mesh: &mesh, manifest: &manifest, manifest_path: required(&self.scene.manifest, "--manifest")?, solution: &solution, solution_path };
        let extras = Extras { clusters: clusters.as_ref(), threshold: threshold.as_ref(), detail: detail.as_ref() };
        let bar = progress(image_size(params, &manifest).1.into(), "rows");
        let rendered = gather_with(params, &scene, extras, &|rows| bar.inc(rows));
        bar.finish_and_clear();
        let (rendered, diagnostics) = rendered?;
        let image = HdrImage { header: HdrImage::header(run.provenance(params)), width: rendered.width, height: rendered.height, rgb: rendered.rgb, coverage: rendered.coverage, surfaces: Some(rendered.surfaces) };
        outputs.write(required(&self.output, "-o")?, |p| image.write(p))?;
        if let (Some(path), Some(d)) = (&self.diagnostics, &diagnostics) {
            outputs.write(path, |p| d.write(p, GatherDiagnostics::header(run.provenance(params))))?;
        }
        let notes: Vec<String> = back_face_warning(&rendered.counters).into_iter().collect();
        notes.iter().for_each(|note| eprintln!("grid-gather: warning: {note}"));
        Ok(Done { counters: rendered.counters, skipped: rendered.skipped, notes, negative: false })
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

//! `grid-gather`: renders a radiosity solution to an HDR image. See the
//! library docs and `grid-gather --help`.

use clap::Parser;
use grid_gather::files::{Given, Written};
use grid_gather::{gather_with, image_size, Mode, Params, Scene};
use schemas::Result;
use stage_kit::run::{bad_parameter, progress, Outputs, Run};
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
    /// Lightmap (lightmap.exr) of the gpu-shoot run that wrote the solution: the preview shows it, bilinear between texel centres, instead of the solution's leaves (a textured surface keeps the leaves' irradiance times its texture).
    #[arg(long, value_name = "LIGHTMAP.exr")]
    lightmap: Option<PathBuf>,
    /// Per-pixel samples and classes, per-vertex class counts (full, brute).
    #[arg(long, value_name = "DIAGNOSTICS.exr")]
    diagnostics: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        let [mesh, manifest] = self.scene.paths();
        (vec![mesh, manifest, self.solution.as_deref(), self.surface.as_deref(), self.lightmap.as_deref()], vec![self.output.as_deref(), self.diagnostics.as_deref()])
    }

    fn settle(&self, params: &mut Params) -> Result<()> {
        if self.brute {
            params.mode = Mode::Brute;
        }
        params.validate()?;
        if self.threshold.is_some() && params.mode != Mode::Full {
            return Err(bad_parameter("--threshold is read only by --mode full"));
        }
        if self.lightmap.is_some() && params.mode != Mode::Preview {
            return Err(bad_parameter("--lightmap is read only by --mode preview"));
        }
        if self.diagnostics.is_some() && params.mode == Mode::Preview {
            return Err(bad_parameter("--diagnostics is written only by --mode full and brute"));
        }
        Ok(())
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let solution_path = required(&self.solution, "--solution")?;
        let given = Given { mesh: required(&self.scene.mesh, "--mesh")?, solution: solution_path, clusters: self.clusters.as_deref(), threshold: self.threshold.as_deref(), surface: self.surface.as_deref(), lightmap: self.lightmap.as_deref() };
        let read = given.read(run, &mesh, &manifest)?;
        let detail = read.detail(&mesh, &manifest);
        let scene = Scene { mesh: &mesh, manifest: &manifest, manifest_path: required(&self.scene.manifest, "--manifest")?, solution: &read.solution, solution_path };
        let extras = read.extras(detail.as_ref());
        let bar = progress(image_size(params, &manifest).1.into(), "rows");
        let rendered = gather_with(params, &scene, extras, &|rows| bar.inc(rows));
        bar.finish_and_clear();
        let (rendered, diagnostics) = rendered?;
        let written = Written { image: required(&self.output, "-o")?, diagnostics: self.diagnostics.as_deref() };
        written.write(outputs, run, params, rendered, diagnostics.as_ref())
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main_parallel::<Args>()
}

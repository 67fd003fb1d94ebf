//! `exact --mesh M --manifest F -o image.exr`: the exact reference image.

use clap::Parser;
use exact::{Exact, Params};
use schemas::exr_io::Channel;
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::Error;
use stage_kit::run::{progress, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Render the exact image of a simple scene (paper 002 Sec. 2): direct
/// light by Lambert's formula, one bounce by adaptive Gauss quadrature,
/// further bounces between two planes; R, G, B radiance in W/(m^2 sr), A
/// coverage, and error_bound.R/G/B, a bound of each pixel's error.
#[derive(Parser, Debug)]
#[command(name = "exact", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image.
    #[arg(short = 'o', long = "output", value_name = "IMAGE.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (self.scene.paths().to_vec(), vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let manifest_path = required(&self.scene.manifest, "--manifest")?;
        let exact = Exact::new(&mesh, &manifest, params).map_err(|why| Error::invalid(manifest_path, None, format!("no exact image: {why}")))?;
        let (width, height) = exact.size();
        let nodes = progress(exact::transport::Transport::nodes_to_build(&exact.config, params.accuracy()), "nodes");
        let rows = progress(height as u64, "rows");
        let started = std::time::Instant::now();
        let image = exact.render(params, &|n| nodes.inc(n), &|n| rows.inc(n));
        nodes.finish_and_clear();
        rows.finish_and_clear();
        let seconds = started.elapsed().as_secs_f64();
        let hdr = HdrImage {
            header: HdrImage::header(run.provenance(params)),
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
        outputs.write(required(&self.output, "-o")?, |path| hdr.write_with(path, extra))?;
        let covered = image.coverage.iter().filter(|&&c| c > 0.0).count();
        let relative = image.radiance.iter().zip(&image.bound).filter(|(r, _)| r.iter().any(|v| *v > 0.0)).map(|(r, b)| (0..3).map(|k| b[k] / r[k].max(f64::MIN_POSITIVE)).fold(0.0, f64::max)).fold(0.0, f64::max);
        let mut done = Done::counted([
            ("pixels", (width * height) as f64),
            ("covered_pixels", covered as f64),
            ("integrand_evaluations", image.evaluations as f64),
            ("largest_error_bound", image.bound.iter().flatten().fold(0.0, |m: f64, b| m.max(*b))),
            ("largest_relative_error_bound", relative),
            ("render_s", seconds),
        ]);
        let (surfaces, planes) = (exact.config.surfaces.len(), exact.config.planes.len());
        done.notes.push(format!("{surfaces} surfaces on {planes} planes; bounces {}; pixels point-sampled at their centres", params.bounces));
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main_parallel::<Args>()
}

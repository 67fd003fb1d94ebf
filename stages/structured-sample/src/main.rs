//! `structured-sample`: see the library's documentation and `--help`.

use clap::Parser;
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::samples::Samples;
use stage_kit::run::{progress, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
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
    #[command(flatten)]
    scene: SceneArgs,
    /// Output: the samples (EXR tables).
    #[arg(short = 'o', long = "output", value_name = "SAMPLES.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Output: the displayed image (HDR EXR, radiance).
    #[arg(long, value_name = "IMAGE.exr", required_unless_present = "print_params")]
    image: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (self.scene.paths().to_vec(), vec![self.output.as_deref(), self.image.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let mesh_path = required(&self.scene.mesh, "--mesh")?;
        // One bar per phase; the step callback ticks whichever is current.
        let bar = std::sync::Mutex::new(progress(0, "starting"));
        let phase = |name: &str, steps: u64| std::mem::replace(&mut *bar.lock().expect("progress lock"), progress(steps, name)).finish_and_clear();
        let step = || bar.lock().expect("progress lock").inc(1);
        let result = structured(&mesh, &manifest, params, &Progress { phase: &phase, step: &step }).map_err(|m| schemas::Error::invalid(mesh_path, None, m))?;
        bar.lock().expect("progress lock").finish_and_clear();
        eprintln!("structured-sample: {}", result.summary());
        let done = result.done(params, &manifest.effects);
        for note in &done.notes {
            eprintln!("structured-sample: warning: {note}");
        }
        let provenance = run.provenance(params);
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
        outputs.write(required(&self.output, "-o")?, |p| samples.write(p))?;
        outputs.write(required(&self.image, "--image")?, |p| image.write(p))?;
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main_parallel::<Args>()
}

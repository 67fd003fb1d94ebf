//! `gpu-shoot`: see the library's documentation and `--help`.

use clap::Parser;
use gpu_shoot::output::Artifacts;
use gpu_shoot::{gpu, solve, Params};
use schemas::Error;
use stage_kit::run::{bad_parameter, progress, read_surface, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Progressive radiosity on the GPU (paper 004): per-triangle float
/// lightmaps, shooter selection by GPU reduction, hemicube or stereographic
/// visibility, disc-approximation form factors, ambient overshooting,
/// goniometric lights (the manifest's tables, from .ldt/.ies files). Writes the lightmap atlas (EXR), a
/// solution.exr that grid-gather previews, and a convergence record.
/// Runs on any Vulkan adapter, Mesa's lavapipe included.
#[derive(Parser, Debug)]
#[command(name = "gpu-shoot", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Input: surface.exr from mesh-prep --surface (textures, alpha masks,
    /// normal maps), read only when the manifest says the scene has one of
    /// them; without it those effects are skipped.
    #[arg(long, value_name = "SURFACE.exr")]
    surface: Option<PathBuf>,
    /// Output: the solution (elements averaging the atlas; no links).
    #[arg(short = 'o', long = "output", value_name = "SOLUTION.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Output: the lightmap atlas and its region table (EXR).
    #[arg(long, value_name = "LIGHTMAP.exr")]
    lightmap: Option<PathBuf>,
    /// Output: the convergence log, shot by shot: unshot fraction and time (RON; timings are volatile).
    #[arg(long, value_name = "CONVERGENCE.ron")]
    convergence_log: Option<PathBuf>,
    /// Output: a plot of the unshot fraction against time (SVG).
    #[arg(long, value_name = "PLOT.svg")]
    plot: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        let [mesh, manifest] = self.scene.paths();
        (vec![mesh, manifest, self.surface.as_deref()], vec![self.output.as_deref(), self.lightmap.as_deref(), self.convergence_log.as_deref(), self.plot.as_deref()])
    }

    fn settle(&self, params: &mut Params) -> schemas::Result<()> {
        if let Some(conflict) = params.conflict() {
            return Err(bad_parameter(conflict));
        }
        if params.adaptive.is_some() && self.lightmap.is_some() {
            return Err(bad_parameter("--lightmap is not written with adaptive subdivision: its regions would be the subdivided tiles', not the mesh's triangles"));
        }
        Ok(())
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let (mesh_path, manifest_path) = (required(&self.scene.mesh, "--mesh")?, required(&self.scene.manifest, "--manifest")?);
        let surface = self.surface.as_deref().filter(|_| manifest.effects.surface_detail()).map(|path| read_surface(path, mesh_path, &mesh, &manifest)).transpose()?;
        let surface = surface.map(|(read, input)| run.input(input).map(|()| read)).transpose()?;
        let lights = stage_kit::scene::luminaires(&manifest.goniometric_lights).map_err(|m| Error::invalid(manifest_path, None, m))?;
        let (device, queue, info) = gpu::acquire().map_err(|m| Error::invalid(Path::new("gpu"), None, m))?;
        let adapter = gpu::describe(&info);
        let bar = progress(1000, "converged");
        let mut fired = 0usize;
        let solved = solve(&device, &queue, &mesh, &manifest, surface.as_ref(), &lights, params, &mut |shot| {
            fired += 1;
            bar.set_position(((1.0 - shot.unshot_magnitude_fraction).clamp(0.0, 1.0) * 1000.0) as u64);
            bar.set_message(format!("{fired} shots"));
        })
        .map_err(|m| Error::invalid(mesh_path, None, m))?;
        bar.finish_and_clear();
        let artifacts = Artifacts::of(&solved, &mesh, &manifest, params, run.provenance(params), &adapter);
        // The radiosity is shot in 32-bit floats: one beyond their range is
        // inf, a file every reader refuses; refuse it here, writing nothing.
        let radiosities = artifacts.solution.elements.iter().map(|e| e.radiosity).chain(artifacts.lightmap.radiosity.iter().copied());
        if let Some(v) = radiosities.flatten().find(|v| !v.is_finite()) {
            return Err(Error::invalid(mesh_path, None, format!("a radiosity of {v} W/m² does not fit 32-bit floats (largest {:e}): scale the emission down", f32::MAX)));
        }
        eprintln!("gpu-shoot: {}", solved.summary(&adapter));
        artifacts.write(outputs, required(&self.output, "-o")?, self.lightmap.as_deref(), self.convergence_log.as_deref(), self.plot.as_deref())?;
        Ok(solved.done(&manifest.effects, surface.is_some(), self.surface.is_some(), &adapter))
    }
}

fn main() -> ExitCode {
    gpu::quiet_device_select_layer();
    stage_kit::stage::main::<Args>()
}

//! `gpu-shoot`: see the library's documentation and `--help`.

use clap::Parser;
use gpu_shoot::{convergence, gpu, output, solve, Params};
use schemas::header::Schema;
use schemas::lightmap::{Convergence, Lightmap};
use schemas::ron_io::write_ron;
use schemas::solution::Solution;
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
        let surface = match self.surface.as_ref().filter(|_| manifest.effects.surface_detail()) {
            Some(path) => {
                let (surface, input) = read_surface(path, mesh_path, &mesh, &manifest)?;
                run.input(input)?;
                Some(surface)
            }
            None => None,
        };
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
        eprintln!("gpu-shoot: {}", solved.summary(&adapter));
        let provenance = run.provenance(params);
        let lightmap = output::lightmap(&solved, &solved.tile_mesh(&mesh), Lightmap::header(provenance.clone()));
        let ambient = params.ambient.then_some(solved.ambient);
        let solution = output::solution(&lightmap, &mesh, &manifest, &solved.tiles, ambient, params.texels_per_leaf, Solution::header(provenance.clone()));
        let convergence = solved.convergence(Convergence::header(provenance), &adapter);
        outputs.write(required(&self.output, "-o")?, |p| solution.write(p))?;
        if let Some(path) = &self.lightmap {
            outputs.write(path, |p| lightmap.write(p))?;
        }
        if let Some(path) = &self.convergence_log {
            outputs.write(path, |p| write_ron(p, &convergence))?;
        }
        if let Some(path) = &self.plot {
            outputs.write_bytes(path, convergence::plot(&convergence).as_bytes())?;
        }
        let mut done = solved.done(&manifest.effects, surface.is_some());
        done.notes.push(format!("adapter: {adapter}"));
        if self.surface.is_some() && !manifest.effects.surface_detail() {
            done.notes.push("surface.exr not read: the scene has no texture, alpha mask or normal map".into());
        }
        Ok(done)
    }
}

fn main() -> ExitCode {
    gpu::quiet_device_select_layer();
    stage_kit::stage::main::<Args>()
}

//! `hierarchical-solve`: see the library's documentation and `--help`.

use clap::Parser;
use hierarchical_solve::{report, solve_with_surface, Params, Phase};
use schemas::cluster::Clusters;
use schemas::header::Schema;
use schemas::solution::Solution;
use stage_kit::run::{progress, read_surface, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Hierarchical radiosity (Hanrahan, Salzman, Aupperle 1991) on a prepared
/// mesh: refinement of each link whose estimated error exceeds a fraction of
/// its receiver's radiosity (or, `--criterion absolute`, of the largest
/// emission), down to a minimum element area,
/// Lambert's closed-form form factors, ray-cast visibility per link, Jacobi
/// gather with push-pull. Writes solution.exr: the element hierarchy with
/// radiosity, and every link (form factor, visibility, unoccluded
/// irradiance, nearest occluder distance).
#[derive(Parser, Debug)]
#[command(name = "hierarchical-solve", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Input: clusters.exr from cluster; without it every pair of input
    /// triangles starts linked (no clustering).
    #[arg(long)]
    clusters: Option<PathBuf>,
    /// Input: surface.exr from mesh-prep --surface: elements transport with
    /// their texture-averaged reflectance, and alpha masks cut surfaces.
    #[arg(long)]
    surface: Option<PathBuf>,
    /// Output: the solution (EXR tables of elements and links).
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        let [mesh, manifest] = self.scene.paths();
        (vec![mesh, manifest, self.clusters.as_deref(), self.surface.as_deref()], vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let (mesh_path, manifest_path) = (required(&self.scene.mesh, "--mesh")?, required(&self.scene.manifest, "--manifest")?);
        stage_kit::scene::luminaires(&manifest.goniometric_lights).map_err(|m| schemas::Error::invalid(manifest_path, None, m))?;
        // The optional inputs, each recorded in the provenance.
        let clusters = self.clusters.as_deref().map(|path| Clusters::read(path, mesh.triangles.len())).transpose()?.map(|(read, input)| run.input(input).map(|()| read)).transpose()?;
        let surface = self.surface.as_deref().map(|path| read_surface(path, mesh_path, &mesh, &manifest)).transpose()?.map(|(read, input)| run.input(input).map(|()| read)).transpose()?;
        let (with_surface, clustered) = (surface.is_some(), clusters.is_some());
        let bar = progress(params.max_passes as u64, "passes");
        // Ticking, so a long phase shows it is alive.
        bar.enable_steady_tick(std::time::Duration::from_millis(250));
        let solved = solve_with_surface(&mesh, &manifest, clusters, surface, params, &|p| {
            bar.set_position(p.pass as u64 - u64::from(p.phase != Phase::Done));
            bar.set_message(format!("pass {}: {} ({} links, {} elements)", p.pass, p.phase, p.links, p.elements));
        })
        .map_err(|message| schemas::Error::invalid(mesh_path, None, message))?;
        bar.finish_and_clear();
        let w = &solved.work;
        eprintln!("hierarchical-solve: {} passes, {} links, {} elements ({} leaves), {} rays, {} iterations", w.passes, w.links, w.elements, w.leaves, w.rays, w.iterations);
        let done = report::done(w, params, &mesh, &manifest, with_surface, clustered);
        done.notes.iter().for_each(|note| eprintln!("hierarchical-solve: warning: {note}"));
        let solution = Solution { header: Solution::header(run.provenance(params)), elements: solved.elements, clusters: solved.clusters, links: solved.links, slopes: solved.slopes };
        outputs.write(required(&self.output, "-o")?, |p| solution.write(p))?;
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main_parallel::<Args>()
}

//! `photon-trace`: see the library's documentation and `--help`.

use clap::Parser;
use photon_trace::report::{skipped, summarise};
use photon_trace::snapshot::SnapshotDir;
use photon_trace::{solve, Observer, Params, Progress, Snapshot, Stage};
use schemas::header::Schema;
use schemas::solution::Solution;
use stage_kit::run::{bad_parameter, progress, Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Paper 001's progressive hybrid solver: (1) photons from every emitter
/// bucketed into the mesh vertices, filtered over a kd-tree of the
/// vertices; (2) exact direct light (Lambert's formula with shadow rays;
/// I cos / r² for goniometric lights) on a mesh split where the Stevens
/// brightness differs across an element; (3) photons for the indirect
/// light until every vertex's estimated relative error is under
/// --target-error (or --max-photons, or --time-budget-s). Writes
/// solution.exr like the other solvers; with --snapshot-dir, the solutions
/// of the way there: DIR/stochastic.exr (end of stage 1), DIR/direct.exr
/// (end of stage 2), and, with --snapshot-every N, DIR/<stage>-<photons>.exr
/// about every N photons of stages 1 and 3.
#[derive(Parser, Debug)]
#[command(name = "photon-trace", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output: the solution (EXR tables of elements; no links).
    #[arg(short = 'o', long = "output", value_name = "SOLUTION.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Directory (existing) for the progressive solutions.
    #[arg(long, value_name = "DIR")]
    snapshot_dir: Option<SnapshotDir>,
    /// With --snapshot-dir: a solution about every this many photons.
    #[arg(long, value_name = "N", default_value_t = 0)]
    snapshot_every: u64,
}

impl stage_kit::stage::Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (self.scene.paths().to_vec(), vec![self.output.as_deref(), self.snapshot_dir.as_ref().map(SnapshotDir::direct)])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        if self.snapshot_every > 0 && self.snapshot_dir.is_none() {
            return Err(bad_parameter("--snapshot-every needs --snapshot-dir"));
        }
        let (mesh, manifest) = self.scene.read(run)?;
        let skipped = skipped(&manifest.effects);
        // Said now, before the photons, not only when they are done.
        run.say_skipped(&skipped);
        let header = Solution::header(run.provenance(params));
        let bar = progress(params.max_photons, "photons");
        let mut on_progress = |p: &Progress| {
            bar.set_position(if p.stage == Stage::Indirect { p.photons } else { 0 });
            bar.set_message(format!("{}: {} photons, error {:.2e}", p.stage, p.photons, p.max_error));
        };
        let mut snapshots = Vec::new();
        let mut on_snapshot = |s: &Snapshot| -> Result<(), String> {
            if let Some(dir) = &self.snapshot_dir {
                snapshots.push(dir.write(s, params.preview_photons, &header)?);
            }
            Ok(())
        };
        let mut observer = Observer { progress: &mut on_progress, snapshot_every: self.snapshot_every, snapshot: &mut on_snapshot };
        let manifest_path = required(&self.scene.manifest, "--manifest")?;
        let solved = solve(&mesh, &manifest, params, &mut observer).map_err(|message| schemas::Error::invalid(manifest_path, None, message))?;
        bar.finish_and_clear();
        let done = summarise(&solved.work, params, skipped, snapshots);
        let solution = Solution { header, elements: solved.elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() };
        outputs.write(required(&self.output, "-o")?, |p| solution.write(p))?;
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main_parallel::<Args>()
}

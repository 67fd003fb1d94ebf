//! The common start and end of a stage's run, so that a stage's `main.rs`
//! says only what is particular to it: its files ([`Stage::files`]) and
//! its work ([`Stage::run`]).
//!
//! [`main`] parses the command line ([`crate::cli::main_with`]: one-line
//! errors, exit 2), prints the knob table for `--print-knobs` (hidden, for
//! the README), settles the effective parameters (`--params`, the knobs'
//! flags, their ranges, [`Stage::settle`]), prints them for
//! `--print-params`, checks the outputs against the inputs before any work
//! ([`crate::cli::check_outputs`], the report included), starts the
//! [`Run`] (provenance, signal handlers), runs the stage, says on stderr
//! what it skipped ([`Run::say_skipped`]), writes the report (`--report`)
//! from what it returns ([`Done`]) and puts every output in place at once
//! ([`Outputs::keep`]).

use crate::cli::{check_outputs, main_with};
use clap::{Args, FromArgMatches};
use crate::knobs::{table, Knobs};
use crate::run::{bad_parameter, read_prepared, Outputs, Run, StageArgs};
use schemas::error::Result;
use schemas::mesh::{Manifest, Mesh};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The hidden flag that prints a stage's knob table (markdown) and exits.
pub const PRINT_KNOBS: &str = "--print-knobs";

/// A stage's own command line (its paths and flags that are not knobs),
/// which the kit runs (see the module). The kit adds the flags every stage
/// has ([`StageArgs`]: `--report`, `--params`, `--print-params` and one per
/// knob of [`Stage::Params`]), so a path clap requires except with
/// `--print-params` says `required_unless_present = "print_params"`.
pub trait Stage: clap::Parser {
    /// The stage's knobs, declared with [`knobs!`](crate::knobs!).
    type Params: Knobs;

    /// The files it reads and the files it writes (the report aside),
    /// `None` for optional ones not given: no output may be an input, and
    /// each must be writable.
    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>);

    /// Settles what depends on flags beyond the knobs' own, or on several
    /// knobs together (default: nothing).
    fn settle(&self, _params: &mut Self::Params) -> Result<()> {
        Ok(())
    }

    /// The work: reads its inputs into `run` (each [`Run::input`]) and
    /// writes its outputs through `outputs`.
    fn run(self, params: &Self::Params, run: &mut Run, outputs: &mut Outputs) -> Result<Done>;
}

/// What a run did, for its report; `negative` for a run whose answer is
/// "no" (exit 1, e.g. `compare` over its bounds).
#[derive(Debug, Default)]
pub struct Done {
    /// Work counters.
    pub counters: BTreeMap<String, f64>,
    /// What was skipped, and why (the report's `skipped`, and said on
    /// stderr by the kit: [`Run::say_skipped`]).
    pub skipped: Vec<String>,
    /// Anything else worth a line.
    pub notes: Vec<String>,
    /// Whether the run's answer is "no".
    pub negative: bool,
}

impl Done {
    /// A run that counted `counters`.
    pub fn counted<const N: usize>(counters: [(&str, f64); N]) -> Done {
        Done { counters: counters.into_iter().map(|(k, v)| (k.to_string(), v)).collect(), ..Done::default() }
    }
}

/// [`main`] for a stage that works in rayon's thread pool: the main thread
/// joins the pool as one of its workers (rayon's `use_current_thread`)
/// instead of handing each parallel loop to a worker and waiting for it.
/// The pool has as many threads as before (`RAYON_NUM_THREADS`, else one
/// per core), and the results are the same to the bit. With one thread,
/// every parallel loop had cost two thread switches: hierarchical-solve on
/// the built-in Cornell box switched 551 times and spent 56 ms in the
/// kernel of its 0.42 s (33 times and 12 ms now), and solves 8-11% faster
/// at `EPS` 1e-3 to 6.5e-4 (medians of 9 interleaved).
pub fn main_parallel<S: Stage>() -> ExitCode {
    // Fails only where a global pool exists already, which then serves.
    let _ = rayon::ThreadPoolBuilder::new().use_current_thread().build_global();
    main::<S>()
}

/// A stage binary's `main`: `fn main() -> ExitCode { stage_kit::stage::main::<Args>() }`.
/// The stage's name and version are its clap command's (`#[command(name =
/// "...", version)]`).
pub fn main<S: Stage>() -> ExitCode {
    let command = S::command();
    let (name, version) = (command.get_name().to_string(), command.get_version().unwrap_or_default().to_string());
    if std::env::args_os().skip(1).any(|a| a == PRINT_KNOBS) {
        print!("{}", table::<S::Params>());
        return ExitCode::SUCCESS;
    }
    let label = name.clone();
    let command = StageArgs::<S::Params>::augment_args(command);
    let from = |m: &clap::ArgMatches| Ok((S::from_arg_matches(m)?, StageArgs::<S::Params>::from_arg_matches(m)?));
    main_with(&label, command, from, move |(stage, common)| run(stage, &common, name, version))
}

/// The run of `stage`, from its parsed command line to its outputs in place.
fn run<S: Stage>(stage: S, common: &StageArgs<S::Params>, name: String, version: String) -> Result<ExitCode> {
    let mut params = common.knobs()?;
    stage.settle(&mut params)?;
    if common.print_params {
        // RON, in the form `--params` reads back.
        println!("{}", schemas::ron_io::to_ron_text(&params));
        return Ok(ExitCode::SUCCESS);
    }
    let report = common.report.clone();
    let (inputs, mut outputs) = stage.files();
    outputs.push(report.as_deref());
    check_outputs(&inputs, &outputs)?;
    let mut run = Run::start(name, version).writing(&outputs);
    let mut outputs = Outputs::new();
    let done = stage.run(&params, &mut run, &mut outputs)?;
    run.say_skipped(&done.skipped);
    if let Some(report) = &report {
        outputs.write(report, |p| run.write_report(p, &params, done.counters, done.skipped, done.notes))?;
    }
    outputs.keep()?;
    Ok(if done.negative { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// The path of a flag clap requires unless `--print-params` is given.
pub fn required<'a>(path: &'a Option<PathBuf>, flag: &str) -> Result<&'a Path> {
    path.as_deref().ok_or_else(|| bad_parameter(format!("{flag} is required")))
}

/// The prepared scene a stage starts from (`--mesh`, `--manifest`, from
/// mesh-prep), flattened into its `Args`.
#[derive(clap::Args, Debug, Clone)]
pub struct SceneArgs {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, value_name = "MESH.exr", required_unless_present = "print_params")]
    pub mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep (materials, camera, effects).
    #[arg(long, value_name = "MANIFEST.ron", required_unless_present = "print_params")]
    pub manifest: Option<PathBuf>,
}

impl SceneArgs {
    /// The two paths, as inputs for [`Stage::files`].
    pub fn paths(&self) -> [Option<&Path>; 2] {
        [self.mesh.as_deref(), self.manifest.as_deref()]
    }

    /// Reads the mesh and its manifest, checked against each other and
    /// recorded as inputs of `run` ([`read_prepared`]).
    pub fn read(&self, run: &mut Run) -> Result<(Mesh, Manifest)> {
        read_prepared(run, required(&self.mesh, "--mesh")?, required(&self.manifest, "--manifest")?)
    }
}

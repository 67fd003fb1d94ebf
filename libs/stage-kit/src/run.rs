//! The grammar every stage binary shares: provenance capture, `--params`
//! files, `--print-params`, reports, progress bars and exit codes
//! (0 ok, 1 a negative answer, 2 error).

use schemas::atomic::Staged;
use schemas::error::{Error, Result};
use schemas::header::{Input, Provenance};
use schemas::report::Report;
use schemas::ron_io::{parse_ron, read_bytes, write_ron};
use schemas::header::Schema;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use crate::knobs::Knobs;
use clap::{Arg, ArgAction, ArgMatches};
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The options every stage binary has, with one flag per knob of `P` (see
/// [`crate::knobs`](mod@crate::knobs)): [`crate::stage::main`] adds them to a stage's own
/// `Args`.
#[derive(Debug, Clone)]
pub struct StageArgs<P> {
    /// Output: a report of the run.
    pub report: Option<PathBuf>,
    /// The `--params` file.
    pub params: Option<PathBuf>,
    /// Whether `--print-params` was given.
    pub print_params: bool,
    /// The parsed command line, from which [`StageArgs::knobs`] reads the
    /// knobs' flags.
    given: ArgMatches,
    knobs: PhantomData<P>,
}

impl<P: Knobs> StageArgs<P> {
    /// The effective parameters: the `--params` file (or the defaults),
    /// with each knob's flag over it where given, every knob checked.
    pub fn knobs(&self) -> Result<P> {
        let mut params: P = load_params(self.params.as_deref())?;
        params.overlay(&self.given, "");
        params.check("")?;
        Ok(params)
    }
}

impl<P: Knobs> clap::FromArgMatches for StageArgs<P> {
    fn from_arg_matches(m: &ArgMatches) -> std::result::Result<Self, clap::Error> {
        Ok(StageArgs {
            report: m.get_one::<PathBuf>("report").cloned(),
            params: m.get_one::<PathBuf>("params").cloned(),
            print_params: m.get_flag("print_params"),
            given: m.clone(),
            knobs: PhantomData,
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> std::result::Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl<P: Knobs> clap::Args for StageArgs<P> {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        let path = || Arg::new("").value_parser(clap::value_parser!(PathBuf)).action(ArgAction::Set);
        let cmd = cmd
            .arg(path().id("report").long("report").value_name("REPORT.ron").help("Output: a report of the run (RON: work done, what was skipped, wall time)"))
            .arg(path().id("params").long("params").value_name("PARAMS.ron").help("Read parameters from this RON file; flags override its values"))
            .arg(Arg::new("print_params").long("print-params").action(ArgAction::SetTrue).help("Print the effective parameters as RON on stdout and exit"));
        P::flags(cmd, "")
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// Exit code of a run that failed.
pub const EXIT_ERROR: u8 = 2;

/// One run of a stage: collects its inputs, then stamps its outputs.
pub struct Run {
    stage: String,
    version: String,
    started: Instant,
    inputs: Vec<Input>,
    outputs: Vec<PathBuf>,
    /// The skipped notes already said on stderr ([`Run::say_skipped`]).
    said: Vec<String>,
}

impl Run {
    /// Starts the clock for `stage` at crate `version`, and makes sure no
    /// temporary file outlives the run where that can be helped: a write
    /// over a file-size limit (`ulimit -f`) becomes an error instead of a
    /// kill (SIGXFSZ, whose default action ends the process before any
    /// cleanup, gets a handler that does nothing, so the write returns
    /// EFBIG and the run ends in its normal error path), and an interrupt
    /// removes them (see [`schemas::atomic::remove_temporaries_on_interrupt`]).
    pub fn start(stage: impl Into<String>, version: impl Into<String>) -> Self {
        static HANDLERS: std::sync::Once = std::sync::Once::new();
        HANDLERS.call_once(|| {
            // Failing to install the handler only keeps the default action.
            let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, std::sync::Arc::default());
            schemas::atomic::remove_temporaries_on_interrupt();
        });
        Run { stage: stage.into(), version: version.into(), started: Instant::now(), inputs: Vec::new(), outputs: Vec::new(), said: Vec::new() }
    }

    /// Records the files this run writes (the kit does, after checking
    /// them against the inputs given on the command line), for
    /// [`Run::check_outputs_against`].
    pub fn writing(mut self, outputs: &[Option<&Path>]) -> Self {
        self.outputs = outputs.iter().flatten().map(|p| p.to_path_buf()).collect();
        self
    }

    /// Checks this run's outputs against inputs found only while it runs
    /// (the files a scene names): none may be one of them
    /// ([`crate::cli::check_outputs`]).
    pub fn check_outputs_against(&self, inputs: &[&Path]) -> Result<()> {
        let inputs: Vec<Option<&Path>> = inputs.iter().map(|p| Some(*p)).collect();
        let outputs: Vec<Option<&Path>> = self.outputs.iter().map(|p| Some(p.as_path())).collect();
        crate::cli::check_outputs(&inputs, &outputs)
    }

    /// Says on stderr what the run does not simulate, one line
    /// `<stage>: skipped: <note>` per note not said before: a stage that
    /// would say it before long work calls this early, and
    /// [`crate::stage::main`] calls it with [`crate::stage::Done::skipped`]
    /// when the stage is done, so each note is said once, report or not.
    pub fn say_skipped(&mut self, notes: &[String]) {
        for note in notes {
            if !self.said.contains(note) {
                eprintln!("{}: skipped: {note}", self.stage);
                self.said.push(note.clone());
            }
        }
    }

    /// Records an input file, refusing one that does not belong with the
    /// inputs recorded before it: where one of two inputs was made from an
    /// output of the stage that made the other, it must have been made from
    /// that very file (the check of `made_from_another`). So a clusters file made
    /// from another mesh than the one given, or a solution made from
    /// another run's manifest, is refused naming both files.
    pub fn input(&mut self, input: Input) -> Result<()> {
        for earlier in &self.inputs {
            made_from_another(&input, earlier).or_else(|| made_from_another(earlier, &input)).map_or(Ok(()), Err)?;
        }
        self.inputs.push(input);
        Ok(())
    }

    /// The provenance of this run's outputs, with `params` as effective
    /// parameters.
    pub fn provenance<P: Serialize>(&self, params: &P) -> Provenance {
        Provenance {
            stage: self.stage.clone(),
            stage_version: self.version.clone(),
            command_line: std::env::args().collect(),
            parameters: ron::value::RawValue::from_rust(params).expect("parameter types serialize to RON"),
            inputs: self.inputs.clone(),
        }
    }

    /// This run's report: its provenance with `params`, the wall time so
    /// far, and what it counted, skipped and noted.
    pub fn report<P: Serialize>(&self, params: &P, counters: BTreeMap<String, f64>, skipped: Vec<String>, notes: Vec<String>) -> Report {
        Report {
            header: Report::header(self.provenance(params)),
            wall_time_s: self.started.elapsed().as_secs_f64(),
            counters,
            skipped,
            notes,
        }
    }

    /// Writes this run's [report](Run::report) to `path`.
    pub fn write_report<P: Serialize>(
        &self,
        path: &Path,
        params: &P,
        counters: BTreeMap<String, f64>,
        skipped: Vec<String>,
        notes: Vec<String>,
    ) -> Result<()> {
        write_ron(path, &self.report(params, counters, skipped, notes))
    }
}

/// The stage's parameters: defaults, or the `--params` file (strict: an
/// unknown field is an error naming the file and line).
fn load_params<P: DeserializeOwned + Default>(path: Option<&Path>) -> Result<P> {
    match path {
        None => Ok(P::default()),
        Some(path) => {
            let bytes = read_bytes(path)?;
            let text = std::str::from_utf8(&bytes).map_err(|e| Error::parse(path, None, format!("not UTF-8 text: {e}")))?;
            parse_ron(path, text)
        }
    }
}

/// Runs a stage's body and turns its outcome into the process exit code;
/// an error is printed as one line `stage: error: ...` on stderr.
pub fn exit_code(stage: &str, outcome: Result<ExitCode>) -> ExitCode {
    match outcome {
        Ok(code) => code,
        Err(e) => {
            eprintln!("{stage}: error: {e}");
            ExitCode::from(EXIT_ERROR)
        }
    }
}

/// A progress bar on stderr for `len` steps of `what` (hidden when stderr is
/// not a terminal, as in `make` logs and tests).
pub fn progress(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
            .expect("valid progress template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// A usage error (bad parameter value) as a contract error naming the
/// parameter source.
pub fn bad_parameter(message: impl Into<String>) -> Error {
    Error::invalid(Path::new("parameters"), None, message)
}

/// The error for `derived` if it records inputs made by the stage that
/// made `source`, none of which is `source` itself (by SHA-256) nor a
/// sibling output of the same run (same provenance: mesh-prep's surface
/// file belongs with a clusters file made from that run's mesh): the two
/// files come from different runs. `None` where they may belong together,
/// or where either carries no provenance (a foreign file, a photometric
/// file) and nothing can be told.
fn made_from_another(derived: &Input, source: &Input) -> Option<Error> {
    let (made, source_made) = (derived.made_by.as_deref()?, source.made_by.as_deref()?);
    let stage = &source_made.stage;
    let siblings: Vec<&Input> = made.inputs.iter().filter(|i| i.made_by.as_ref().is_some_and(|m| &m.stage == stage)).collect();
    if siblings.is_empty() || siblings.iter().any(|i| i.sha256 == source.sha256 || i.made_by.as_deref() == Some(source_made)) {
        return None;
    }
    let recorded: Vec<String> = siblings.iter().map(|i| format!("{} (SHA-256 {:.12})", i.path, i.sha256)).collect();
    Some(Error::invalid(
        Path::new(&derived.path),
        None,
        format!(
            "does not belong with {} (SHA-256 {:.12}): it was made from {} of another {stage} run; remake it from the given files",
            source.path,
            source.sha256,
            recorded.join(" and ")
        ),
    ))
}

/// Reads the prepared scene a stage starts from: `mesh.exr` and
/// `manifest.ron`, checked against each other, both recorded as inputs of
/// `run`. The two must be outputs of one mesh-prep run (equal provenance):
/// a kill between mesh-prep's renames, or a copy of one file from another
/// output directory, leaves a pair whose indices may still fit but whose
/// materials and objects do not, which is refused naming both files.
pub fn read_prepared(run: &mut Run, mesh: &Path, manifest: &Path) -> Result<(schemas::mesh::Mesh, schemas::mesh::Manifest)> {
    let (mesh_value, mesh_input) = schemas::mesh::Mesh::read(mesh)?;
    let loaded = schemas::ron_io::read_ron::<schemas::mesh::Manifest>(manifest)?;
    if mesh_value.header.provenance != loaded.value.header.provenance {
        return Err(Error::invalid(
            mesh,
            None,
            format!(
                "does not belong with {}: they come from different {} runs (their provenance differs); rerun it to write both",
                manifest.display(),
                loaded.value.header.provenance.stage
            ),
        ));
    }
    loaded.value.check_mesh(mesh, &mesh_value)?;
    run.input(mesh_input)?;
    run.input(loaded.input)?;
    Ok((mesh_value, loaded.value))
}

/// Reads the surface artifact at `path` (`mesh-prep --surface`) for
/// `mesh`, read from `mesh_path` with its manifest, refusing one that
/// another mesh-prep run wrote (its provenance differs from the mesh's,
/// which the clusters' input check cannot see where no input was made from
/// either). The caller records the returned input.
pub fn read_surface(path: &Path, mesh_path: &Path, mesh: &schemas::mesh::Mesh, manifest: &schemas::mesh::Manifest) -> Result<(schemas::surface::Surface, Input)> {
    let (surface, input) = schemas::surface::Surface::read(path, mesh.triangles.len(), manifest.materials.len())?;
    if surface.header.provenance != mesh.header.provenance {
        return Err(Error::invalid(
            path,
            None,
            format!(
                "does not belong with the mesh {}: not written by the mesh-prep run that wrote the mesh (their provenance differs); rerun mesh-prep to write both",
                mesh_path.display()
            ),
        ));
    }
    Ok((surface, input))
}

/// Checks, before any work, that `path` can be written: its directory
/// exists and accepts a new file. A stage that would fail only after
/// minutes of computing fails at once instead.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let probe = dir.join(format!(".{}.probe", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| Error::invalid(path, None, format!("cannot write into {}: {e}", dir.display())))?;
    std::fs::remove_file(&probe).map_err(|e| Error::io(path, e))
}

/// The environment variable that makes [`Outputs::keep`] pause for a
/// minute after putting this many outputs in place, saying so on stderr
/// (`paused after N renames`): a test-only hook for the kill and interrupt
/// tests, which signal a stage between two of its renames. Unset in
/// normal runs.
pub const PAUSE_AFTER_COMMITS: &str = "PIPELINE_TEST_PAUSE_AFTER_COMMITS";

/// The outputs of one run, one unit: each is written completely beside its
/// target first ([`Outputs::write`]), and only when all are written does
/// [`Outputs::keep`] rename them into place, in the order written. A run
/// that fails, or panics, before that leaves every old output as it was
/// and no temporary file; an interrupt (SIGINT, SIGTERM) the same; a
/// SIGKILL while writing leaves the old outputs (and at worst a hidden
/// `.NAME.PID.tmp` file); a kill between two renames
/// leaves a mixed set, which the next stage refuses because the outputs'
/// provenance differs (see [`read_prepared`]).
#[derive(Default)]
pub struct Outputs {
    staged: Vec<Staged>,
}

impl Outputs {
    /// No output written yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes one output through `write`, which writes a complete file at
    /// the path it is given (a temporary one beside `path`), and keeps it
    /// there until [`Outputs::keep`].
    pub fn write(&mut self, path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        self.staged.push(Staged::written_by(path, write)?);
        Ok(())
    }

    /// Writes one output holding `bytes`, kept until [`Outputs::keep`].
    pub fn write_bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.staged.push(Staged::write(path, |w| std::io::Write::write_all(w, bytes).map_err(|e| Error::io(path, e)))?);
        Ok(())
    }

    /// The run succeeded: puts every output in place. Should a rename fail,
    /// the outputs already renamed are removed again, so that `make` sees
    /// none of this run's outputs, and the error names the file.
    pub fn keep(self) -> Result<()> {
        let pause_after = std::env::var(PAUSE_AFTER_COMMITS).ok().and_then(|n| n.parse::<usize>().ok());
        let mut placed: Vec<std::path::PathBuf> = Vec::new();
        for staged in self.staged {
            if pause_after == Some(placed.len()) {
                eprintln!("paused after {} renames ({PAUSE_AFTER_COMMITS})", placed.len());
                std::thread::sleep(std::time::Duration::from_secs(60));
            }
            let target = staged.target().to_path_buf();
            if let Err(e) = staged.commit() {
                for path in &placed {
                    let _ = std::fs::remove_file(path);
                }
                return Err(e);
            }
            placed.push(target);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn made_by(stage: &str, inputs: Vec<Input>) -> Option<Box<Provenance>> {
        Some(Box::new(Provenance { stage: stage.into(), inputs, ..Provenance::in_memory(stage) }))
    }

    fn input(path: &str, sha256: &str, made: Option<Box<Provenance>>) -> Input {
        Input { path: path.into(), sha256: sha256.into(), made_by: made }
    }

    #[test]
    fn an_input_made_from_another_run_is_refused_naming_both_files() {
        // A mesh-prep run's provenance records its scene's hash.
        let mesh = |path: &str, sha: &str| input(path, sha, made_by("mesh-prep", vec![input("scene.ron", sha, None)]));
        let clusters = |from: Input| input("out/clusters.exr", "c1", made_by("cluster", vec![from, input("scene.ron", "s", None)]));
        let mut run = Run::start("test", "0");
        run.input(mesh("out/mesh.exr", "aaaa")).unwrap();
        let message = run.input(clusters(mesh("old/mesh.exr", "bbbb"))).unwrap_err().to_string();
        assert_eq!(
            message,
            "out/clusters.exr: does not belong with out/mesh.exr (SHA-256 aaaa): it was made from old/mesh.exr (SHA-256 bbbb) of another mesh-prep run; remake it from the given files"
        );
        // In the other order, the same refusal; made from the given file, accepted.
        let mut run = Run::start("test", "0");
        run.input(clusters(mesh("old/mesh.exr", "bbbb"))).unwrap();
        assert!(run.input(mesh("out/mesh.exr", "aaaa")).unwrap_err().to_string().starts_with("out/clusters.exr: does not belong with out/mesh.exr"));
        let mut run = Run::start("test", "0");
        run.input(mesh("out/mesh.exr", "aaaa")).unwrap();
        run.input(clusters(mesh("elsewhere/mesh.exr", "aaaa"))).unwrap();
        // Files without provenance (foreign, photometric) tell nothing.
        run.input(input("lamp.ldt", "dddd", None)).unwrap();
        // Another output of the mesh's own run (surface.exr) belongs with
        // clusters made from that mesh; one of another run does not.
        let surface = |sha_of_run: &str| input("out/surface.exr", "eeee", made_by("mesh-prep", vec![input("scene.ron", sha_of_run, None)]));
        let mut run = Run::start("test", "0");
        run.input(clusters(mesh("out/mesh.exr", "aaaa"))).unwrap();
        run.input(surface("aaaa")).unwrap();
        let mut run = Run::start("test", "0");
        run.input(clusters(mesh("out/mesh.exr", "aaaa"))).unwrap();
        assert!(run.input(surface("bbbb")).unwrap_err().to_string().starts_with("out/clusters.exr: does not belong with out/surface.exr"));
    }

    #[test]
    fn a_skipped_note_said_early_is_not_said_again() {
        let mut run = Run::start("test", "0");
        let notes = vec!["glossy reflection".to_string(), "refraction".to_string()];
        run.say_skipped(&notes[..1]);
        run.say_skipped(&notes);
        assert_eq!(run.said, notes, "each note said once, in order");
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("stage-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn listing(dir: &Path) -> Vec<(String, String)> {
        let mut files: Vec<(String, String)> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let path = e.unwrap().path();
                (path.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&path).unwrap())
            })
            .collect();
        files.sort();
        files
    }

    #[test]
    fn outputs_appear_together_on_keep_and_not_at_all_on_failure() {
        let dir = scratch("outputs");
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        let write = |outputs: &mut Outputs, path: &Path, text: &'static str| outputs.write(path, |p| schemas::atomic::write_bytes_atomically(p, text.as_bytes()));
        let old = vec![("a.txt".to_string(), "old a".to_string()), ("b.txt".to_string(), "old b".to_string())];
        let mut outputs = Outputs::new();
        write(&mut outputs, &a, "old a").unwrap();
        write(&mut outputs, &b, "old b").unwrap();
        outputs.keep().unwrap();
        assert_eq!(listing(&dir), old);
        // A run that fails after its first output: the old pair, no temporary.
        let mut outputs = Outputs::new();
        write(&mut outputs, &a, "new a").unwrap();
        let failed = outputs.write(&b, |p| Err(Error::invalid(p, None, "disk full")));
        assert_eq!(failed.unwrap_err().to_string(), format!("{}: disk full", b.display()), "the error names the output, not its temporary");
        drop(outputs);
        assert_eq!(listing(&dir), old);
        let mut outputs = Outputs::new();
        write(&mut outputs, &a, "new a").unwrap();
        write(&mut outputs, &b, "new b").unwrap();
        assert_eq!(listing(&dir).len(), 4, "both staged beside the old pair");
        outputs.keep().unwrap();
        assert_eq!(listing(&dir), vec![("a.txt".to_string(), "new a".to_string()), ("b.txt".to_string(), "new b".to_string())]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

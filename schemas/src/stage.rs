//! The grammar every stage binary shares: provenance capture, `--params`
//! files, `--print-params`, reports, progress bars and exit codes
//! (0 ok, 1 a negative answer, 2 error).

use crate::error::{Error, Result};
use crate::header::{Input, Provenance};
use crate::report::Report;
use crate::ron_io::{parse_ron, read_bytes, to_ron_text, write_ron};
use crate::header::Schema;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// The options every stage binary has, flattened into its clap `Args`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct StageArgs {
    /// Output: a report of the run (RON: work done, what was skipped, wall time).
    #[arg(long, value_name = "REPORT.ron")]
    pub report: Option<std::path::PathBuf>,
    /// Read parameters from this RON file; flags override its values.
    #[arg(long, value_name = "PARAMS.ron")]
    pub params: Option<std::path::PathBuf>,
    /// Print the effective parameters as RON on stdout and exit.
    #[arg(long)]
    pub print_params: bool,
}

/// Exit code of a run that failed.
pub const EXIT_ERROR: u8 = 2;

/// One run of a stage: collects its inputs, then stamps its outputs.
pub struct Run {
    stage: &'static str,
    version: &'static str,
    started: Instant,
    inputs: Vec<Input>,
}

impl Run {
    /// Starts the clock for `stage` at crate `version`.
    pub fn start(stage: &'static str, version: &'static str) -> Self {
        Run { stage, version, started: Instant::now(), inputs: Vec::new() }
    }

    /// Records an input file.
    pub fn input(&mut self, input: Input) {
        self.inputs.push(input);
    }

    /// The provenance of this run's outputs, with `params` as effective
    /// parameters.
    pub fn provenance<P: Serialize>(&self, params: &P) -> Provenance {
        Provenance {
            stage: self.stage.into(),
            stage_version: self.version.into(),
            command_line: std::env::args().collect(),
            parameters: ron::value::RawValue::from_rust(params).expect("parameter types serialize to RON"),
            inputs: self.inputs.clone(),
        }
    }

    /// Writes this run's report to `path`.
    pub fn write_report<P: Serialize>(
        &self,
        path: &Path,
        params: &P,
        counters: BTreeMap<String, f64>,
        skipped: Vec<String>,
        notes: Vec<String>,
    ) -> Result<()> {
        let report = Report {
            header: Report::header(self.provenance(params)),
            wall_time_s: self.started.elapsed().as_secs_f64(),
            counters,
            skipped,
            notes,
        };
        write_ron(path, &report)
    }
}

/// The stage's parameters: defaults, or the `--params` file (strict: an
/// unknown field is an error naming the file and line).
pub fn load_params<P: DeserializeOwned + Default>(path: Option<&Path>) -> Result<P> {
    match path {
        None => Ok(P::default()),
        Some(path) => {
            let bytes = read_bytes(path)?;
            let text = std::str::from_utf8(&bytes).map_err(|e| Error::parse(path, None, format!("not UTF-8 text: {e}")))?;
            parse_ron(path, text)
        }
    }
}

/// Prints the effective parameters as RON on stdout, in a form `--params`
/// reads back.
pub fn print_params<P: Serialize>(params: &P) {
    println!("{}", to_ron_text(params));
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

/// Reads the prepared scene a stage starts from: `mesh.exr` and
/// `manifest.ron`, checked against each other, both recorded as inputs of
/// `run`.
pub fn read_prepared(run: &mut Run, mesh: &Path, manifest: &Path) -> Result<(crate::mesh::Mesh, crate::mesh::Manifest)> {
    let (mesh_value, mesh_input) = crate::mesh::Mesh::read(mesh)?;
    let loaded = crate::ron_io::read_ron::<crate::mesh::Manifest>(manifest)?;
    loaded.value.check_mesh(mesh, &mesh_value)?;
    run.input(mesh_input);
    run.input(loaded.input);
    Ok((mesh_value, loaded.value))
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

/// The outputs of one run, all or none: every file written through it is
/// removed again unless [`Outputs::keep`] is called, so a run that fails
/// half-way through its writes leaves no partial output for `make`.
#[derive(Default)]
pub struct Outputs {
    written: Vec<std::path::PathBuf>,
    kept: bool,
}

impl Outputs {
    /// No output written yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes one output (atomically, through `write`) and remembers it.
    pub fn write(&mut self, path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        write(path)?;
        self.written.push(path.to_path_buf());
        Ok(())
    }

    /// The run succeeded: keep everything written.
    pub fn keep(mut self) {
        self.kept = true;
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        if !self.kept {
            for path in &self.written {
                let _ = std::fs::remove_file(path);
            }
        }
    }
}

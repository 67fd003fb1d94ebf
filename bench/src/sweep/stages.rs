//! Running the pipeline's stage binaries as subprocesses, as `make` does,
//! and reading back the time each one reports.
//!
//! A stage's time is the `wall_time_s` of its own report (`--report`):
//! from the start of its `run` to the end of its writes, inputs read and
//! outputs written included, process start-up and exit excluded (a few
//! milliseconds, the same for every point).

use schemas::report::Report;
use schemas::ron_io::read_ron;
use schemas::{Error, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Where the stage binaries are.
#[derive(Clone, Debug)]
pub struct Stages {
    dir: PathBuf,
}

impl Stages {
    /// The stages in `dir` (normally `target/release`).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Stages { dir: dir.into() }
    }

    /// The stages beside the running executable: the sweep is built into
    /// the same `target/release` as they are.
    pub fn beside_this_executable() -> Result<Self> {
        let exe = std::env::current_exe().map_err(|e| Error::io(Path::new("sweep"), e))?;
        Ok(Stages::new(exe.parent().unwrap_or(Path::new("."))))
    }

    /// The path of stage `name`, which must exist.
    pub fn binary(&self, name: &str) -> Result<PathBuf> {
        let path = self.dir.join(name);
        if path.exists() {
            Ok(path)
        } else {
            Err(Error::invalid(&path, None, "stage binary missing: run `cargo build --release --bins` (`make` does)"))
        }
    }

    /// Runs stage `name` with `args` and `--report report`; returns the
    /// report. Exit codes 0 and 1 (`compare`'s "differ") count as success;
    /// anything else is an error carrying the stage's own last line of
    /// stderr.
    pub fn run(&self, name: &str, args: &[String], report: &Path) -> Result<Report> {
        let mut all = args.to_vec();
        all.extend(["--report".to_string(), report.display().to_string()]);
        // compare writes its report with -o and has no --report.
        if name == "compare" {
            let n = all.len();
            all[n - 2] = "-o".to_string();
        }
        self.output(name, &all)?;
        Ok(read_ron::<Report>(report)?.value)
    }

    /// Checks `args` with the stage itself (`--print-params`), before any
    /// run: a bad value fails in a second rather than minutes into a sweep.
    pub fn check(&self, name: &str, args: &[String]) -> Result<()> {
        let mut all = vec!["--print-params".to_string()];
        all.extend_from_slice(args);
        self.output(name, &all).map(|_| ())
    }

    fn output(&self, name: &str, args: &[String]) -> Result<String> {
        let binary = self.binary(name)?;
        let out = Command::new(&binary).args(args).output().map_err(|e| Error::io(&binary, e))?;
        let stderr = String::from_utf8_lossy(&out.stderr);
        match out.status.code() {
            Some(0 | 1) => Ok(String::from_utf8_lossy(&out.stdout).into_owned()),
            code => {
                // The stage's one error line (clap's usage errors add lines
                // after it), else its last line.
                let mut lines = stderr.lines().filter(|l| !l.trim().is_empty());
                let line = lines.clone().find(|l| l.contains("error")).or_else(|| lines.next_back()).unwrap_or("no message");
                let status = code.map_or("killed".to_string(), |c| format!("exit {c}"));
                Err(Error::invalid(&binary, None, format!("{status}: {line}")))
            }
        }
    }
}

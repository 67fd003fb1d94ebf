//! What the drivers' end-to-end tests share: running a driver binary (after
//! checking the stage binaries it runs are built) and a scratch directory.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the driver `exe` with `args`, once the `stages` beside it exist
/// (`make test` builds every stage binary before the tests).
pub fn run_driver(exe: &str, stages: &[&str], args: &[&str]) -> Output {
    let exe = Path::new(exe);
    let dir = exe.parent().expect("target directory");
    for stage in stages {
        assert!(dir.join(stage).exists(), "{} is missing: run `make test` (it builds the stages first)", dir.join(stage).display());
    }
    Command::new(exe).args(args).output().unwrap_or_else(|e| panic!("{} runs: {e}", exe.display()))
}

/// An empty directory `name` under the test target's temporary directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

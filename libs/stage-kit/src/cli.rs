//! The command line every stage shares: one-line usage errors and output
//! paths checked against the inputs before any work.

use schemas::error::{Error, Result};
use crate::run::{check_writable, exit_code, EXIT_ERROR};
use std::path::Path;
use std::process::ExitCode;

/// A stage's `main`: parses the command line into `A`, runs `run` on it and
/// turns the outcome into the exit code ([`exit_code`]).
///
/// A command line clap rejects (a bad flag value, a missing input, an
/// unknown flag) is reported as one line `stage: error: ...` on stderr with
/// exit code 2, like every other error of a stage, instead of clap's
/// several-line usage text; `--help` and `--version` print as usual.
/// Negative numbers are values, not flags, so `--eps -1` reaches the
/// stage's own range check and its message.
pub fn main_of<A: clap::Parser>(stage: &str, run: impl FnOnce(A) -> Result<ExitCode>) -> ExitCode {
    main_with(stage, A::command(), |m| A::from_arg_matches(m), run)
}

/// [`main_of`] for a command line `command` whose matches `from` turns into
/// the run's arguments (the stage kit adds the common flags to a stage's).
pub fn main_with<A>(
    stage: &str,
    command: clap::Command,
    from: impl FnOnce(&clap::ArgMatches) -> std::result::Result<A, clap::Error>,
    run: impl FnOnce(A) -> Result<ExitCode>,
) -> ExitCode {
    let parsed = command.allow_negative_numbers(true).try_get_matches().and_then(|m| from(&m));
    match parsed {
        Ok(args) => exit_code(stage, run(args)),
        Err(e) if !e.use_stderr() => {
            // --help / --version: clap's own text on stdout.
            let _ = e.print();
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{stage}: error: {}", usage_line(&e.render().to_string()));
            ExitCode::from(EXIT_ERROR)
        }
    }
}

/// clap's rendered error folded into one line: its `error:` prefix, the
/// usage block and the "for more information" hint dropped, the remaining
/// lines (such as a list of missing arguments) joined by spaces, and a
/// pointer to `--help` appended.
fn usage_line(rendered: &str) -> String {
    let mut parts = Vec::new();
    for line in rendered.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        let line = line.strip_prefix("error:").unwrap_or(line).trim();
        if !line.is_empty() {
            parts.push(line);
        }
    }
    format!("{} (see --help)", parts.join(" "))
}

/// Checks every output before any work: each can be written
/// ([`check_writable`]), none is one of the inputs (a stage must never
/// overwrite what it reads, e.g. `tonemap p.exr -o p.exr`), and no two
/// outputs are the same file. "The same file" is decided on the file
/// system (device and inode), so `./a.exr`, `a.exr` and a symbolic link to
/// it are all caught.
/// Optional inputs and outputs (flags not given) are `None` and skipped.
pub fn check_outputs(inputs: &[Option<&Path>], outputs: &[Option<&Path>]) -> Result<()> {
    let inputs: Vec<&Path> = inputs.iter().flatten().copied().collect();
    let outputs: Vec<&Path> = outputs.iter().flatten().copied().collect();
    for (i, output) in outputs.iter().enumerate() {
        if let Some(input) = inputs.iter().find(|input| same_file(input, output)) {
            return Err(Error::invalid(output, None, format!("output is the input {}; refusing to overwrite it", input.display())));
        }
        if let Some(other) = outputs[..i].iter().find(|other| same_file(other, output) || other == &output) {
            return Err(Error::invalid(output, None, format!("named twice as an output (also {})", other.display())));
        }
        check_writable(output)?;
    }
    Ok(())
}

/// Whether `a` and `b` name one existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clap_errors_fold_to_one_line() {
        let rendered = "error: the following required arguments were not provided:\n  --mesh <MESH>\n  --output <OUTPUT>\n\nUsage: stage --mesh <MESH> --output <OUTPUT>\n\nFor more information, try '--help'.\n";
        assert_eq!(usage_line(rendered), "the following required arguments were not provided: --mesh <MESH> --output <OUTPUT> (see --help)");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_by_any_name() {
        let dir = std::env::temp_dir().join(format!("cli-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("p.exr");
        std::fs::write(&input, b"x").unwrap();
        let link = dir.join("link.exr");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let dotted = dir.join(".").join("p.exr");
        for output in [&input, &link, &dotted] {
            let e = check_outputs(&[Some(&input)], &[Some(output)]).unwrap_err().to_string();
            assert!(e.contains("refusing to overwrite"), "{e}");
        }
        let fresh = dir.join("q.exr");
        assert!(check_outputs(&[Some(&input)], &[Some(&fresh)]).is_ok());
        let e = check_outputs(&[Some(&input)], &[Some(&fresh), None, Some(&fresh)]).unwrap_err().to_string();
        assert!(e.contains("named twice"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

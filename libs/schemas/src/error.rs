//! The one error type of every file contract: each variant names the file,
//! and its `Display` is a single line a user can act on.

use std::path::{Path, PathBuf};

/// Result with the contract error.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What went wrong with a file. Every variant carries the path it concerns.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The operating system refused a read, write or rename.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file's text does not parse; `line` is 1-based where known.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line number, where the parser knows it.
        line: Option<usize>,
        /// What is wrong, in one line.
        message: String,
    },
    /// The file is an artifact of another kind, or of a version this build
    /// does not understand.
    #[error("{}: {what}", path.display())]
    Schema {
        /// The file concerned.
        path: PathBuf,
        /// Found versus wanted, in one line.
        what: String,
    },
    /// The file parses but its content is unusable (non-finite numbers,
    /// out-of-range indices, missing channels, ...).
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line number, where known.
        line: Option<usize>,
        /// What is wrong, in one line.
        message: String,
    },
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }

    /// Unusable content in `path`, at `line` where known.
    pub fn invalid(path: &Path, line: Option<usize>, message: impl Into<String>) -> Self {
        Error::Invalid { path: path.to_path_buf(), line, message: message.into() }
    }

    /// A parse failure in `path`.
    pub fn parse(path: &Path, line: Option<usize>, message: impl Into<String>) -> Self {
        Error::Parse { path: path.to_path_buf(), line, message: message.into() }
    }

    /// A schema mismatch in `path`.
    pub fn schema(path: &Path, what: impl Into<String>) -> Self {
        Error::Schema { path: path.to_path_buf(), what: what.into() }
    }
}

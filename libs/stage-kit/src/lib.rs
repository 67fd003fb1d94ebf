//! # stage-kit: what every stage binary shares
//!
//! The file contracts live in `schemas`; this crate holds the grammar of a
//! stage's run around them: the command line ([`cli`]: one-line usage
//! errors, outputs checked against inputs before any work), the run itself
//! ([`run`]: provenance capture, `--params` files, `--print-params`,
//! reports, atomic outputs, progress bars, exit codes) and the PNG writer
//! ([`png`]) for the stages' 8-bit pictures, and the adapters from the
//! prepared scene's artifacts to `radiometry`'s data ([`scene`]).

pub mod cli;
pub mod png;
pub mod run;
pub mod scene;

//! # stage-kit: what every stage binary shares
//!
//! The file contracts live in `schemas`; this crate holds the grammar of a
//! stage's run around them: its knobs, declared once ([`knobs`](mod@knobs): the
//! `Params` struct, defaults, ranges, flags, the knob table), the common
//! start and end of a run ([`stage`]: parse, `--print-params`, outputs
//! checked, the prepared scene read, report, outputs kept), the command
//! line ([`cli`]: one-line usage errors, outputs checked against inputs
//! before any work), the run itself ([`run`]: provenance capture,
//! `--params` files, reports, atomic outputs, progress bars, exit codes)
//! the PNG writer ([`png`]) for the stages' 8-bit pictures, and the
//! adapters from the prepared scene's artifacts to `radiometry`'s data
//! ([`scene`]).

pub mod cli;
pub mod knobs;
pub mod png;
pub mod run;
pub mod scene;
pub mod stage;

/// clap, for the code [`knobs!`] writes in the stages.
#[doc(hidden)]
pub use clap;

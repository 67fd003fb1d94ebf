//! Provenance: how every artifact was made, so a file always tells how to
//! remake it (the idea of Radiance's picture headers, plus input hashes).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The format tag at the start of every artifact's header.
pub const FORMAT: &str = "radiosity-pipeline";

/// The header every artifact carries: what kind of file it is, and how it
/// was made. RON artifacts hold it as their `header` field; EXR artifacts as
/// the `pipeline` header attribute (see [`crate::exr_io`]).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Header {
    /// Always [`FORMAT`]; readers refuse anything else.
    pub format: String,
    /// Schema name, e.g. `"manifest"`, `"solution"`.
    pub schema: String,
    /// Schema version; readers refuse versions they do not understand.
    pub version: u32,
    /// The run that produced the file.
    pub provenance: Provenance,
}

/// One run of one stage. Deliberately free of timings and dates, so that the
/// same inputs and parameters give a byte-identical artifact; wall time lives
/// in the stage's report (see [`crate::report`]).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// Producing stage, e.g. `"hierarchical-solve"`.
    pub stage: String,
    /// The producing stage's crate version.
    pub stage_version: String,
    /// The full command line, program name first.
    pub command_line: Vec<String>,
    /// The effective parameters, as RON text a `--params` file may hold
    /// (kept as text: an untyped RON value would lose enum variant names).
    pub parameters: Box<ron::value::RawValue>,
    /// Each input file: path, content hash, and the provenance it carried.
    pub inputs: Vec<Input>,
}

impl Provenance {
    /// The provenance of data made in memory by `maker` (a test, an
    /// example) rather than by a stage run: no command line, no inputs.
    pub fn in_memory(maker: &str) -> Self {
        Provenance {
            stage: maker.into(),
            stage_version: "0".into(),
            command_line: Vec::new(),
            parameters: ron::value::RawValue::from_rust(&()).expect("unit serializes"),
            inputs: Vec::new(),
        }
    }
}

/// One input file of a run.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Input {
    /// The path as given on the command line.
    pub path: String,
    /// SHA-256 of the file's bytes, lower-case hex.
    pub sha256: String,
    /// The provenance the input carried, if it is an artifact of this
    /// pipeline: the history travels forward with the data.
    pub made_by: Option<Box<Provenance>>,
}

impl Input {
    /// Records `bytes` read from `path`, with the provenance they carried.
    pub fn new(path: &Path, bytes: &[u8], made_by: Option<Provenance>) -> Self {
        Input { path: path.display().to_string(), sha256: sha256_hex(bytes), made_by: made_by.map(Box::new) }
    }
}

/// Lower-case hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// Which schema a Rust type is the contract of.
pub trait Schema {
    /// Schema name written into and checked in the header.
    const NAME: &'static str;
    /// The version this build writes and reads.
    const VERSION: u32;

    /// A header of this schema for `provenance`.
    fn header(provenance: Provenance) -> Header {
        Header { format: FORMAT.into(), schema: Self::NAME.into(), version: Self::VERSION, provenance }
    }
}

/// The identifying part of any header, read leniently (unknown fields are
/// ignored) so that a newer file's version can be reported before its body
/// fails to parse.
#[derive(Deserialize)]
pub(crate) struct HeaderTag {
    #[serde(default)]
    pub format: String,
    #[serde(default)]
    pub schema: String,
    /// 0 when absent: no schema has version 0.
    #[serde(default)]
    pub version: u32,
}

impl HeaderTag {
    /// Refuses a file that is not of schema `S`, naming what was found.
    pub(crate) fn check<S: Schema>(&self, path: &Path) -> Result<()> {
        if self.format != FORMAT {
            return Err(Error::schema(path, format!("not a {FORMAT} artifact (format tag {:?})", self.format)));
        }
        if self.schema != S::NAME {
            return Err(Error::schema(path, format!("is a '{}' artifact, expected '{}'", self.schema, S::NAME)));
        }
        if self.version != S::VERSION {
            return Err(Error::schema(
                path,
                format!(
                    "'{}' schema version {} is not supported; this build reads version {}",
                    S::NAME,
                    self.version,
                    S::VERSION
                ),
            ));
        }
        Ok(())
    }
}

//! RON artifacts: small structured files a person reads (manifests, reports,
//! parameters). Written pretty and atomically; read with the header checked
//! before the body, so a version mismatch is reported as such.

use crate::atomic::write_bytes_atomically;
use crate::error::{Error, Result};
use crate::header::{HeaderTag, Input, Provenance, Schema};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::Path;

/// A RON artifact: a serde type with a `header` field of schema `Self`.
pub trait RonArtifact: Schema + Serialize + DeserializeOwned {
    /// The artifact's provenance, carried forward by its readers.
    fn provenance(&self) -> &Provenance;
}

/// A value read from a file, with the record of that input for provenance.
#[derive(Debug)]
pub struct Loaded<T> {
    /// The parsed content.
    pub value: T,
    /// Path, hash and carried provenance of the file it came from.
    pub input: Input,
}

/// Reads a file's bytes, naming it in the error.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// Serializes `value` as pretty RON text, fields in declaration order.
pub fn to_ron_text<T: Serialize>(value: &T) -> String {
    let config = ron::ser::PrettyConfig::new().struct_names(true).indentor("  ".to_string());
    // Serializing our own plain data types cannot fail: no maps with
    // non-string keys, no non-finite floats are rejected by RON.
    ron::ser::to_string_pretty(value, config).expect("RON serialization of a plain data type")
}

/// Parses RON `text` from `path` as `T`, turning parser errors into a
/// one-line error with the line number.
pub fn parse_ron<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    ron::from_str(text).map_err(|e| Error::parse(path, Some(e.span.start.line), e.code.to_string()))
}

/// Reads the RON artifact at `path`: checks format tag, schema name and
/// version first, then parses the body strictly (unknown fields are errors).
pub fn read_ron<T: RonArtifact>(path: &Path) -> Result<Loaded<T>> {
    let bytes = read_bytes(path)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::schema(path, format!("not a text file; expected a '{}' artifact (RON)", T::NAME)))?;
    let untyped: ron::Value = parse_ron(path, text)?;
    let tag: HeaderTag = header_of(&untyped)
        .and_then(|h| h.clone().into_rust().ok())
        .ok_or_else(|| Error::schema(path, format!("no artifact header; expected a '{}' artifact", T::NAME)))?;
    tag.check::<T>(path)?;
    let value: T = parse_ron(path, text)?;
    let input = Input::new(path, &bytes, Some(value.provenance().clone()));
    Ok(Loaded { value, input })
}

/// The `header` entry of a RON struct read as an untyped value.
fn header_of(value: &ron::Value) -> Option<&ron::Value> {
    match value {
        ron::Value::Map(map) => map.get(&ron::Value::String("header".into())),
        _ => None,
    }
}

/// Writes `value` as RON to `path`, atomically.
pub fn write_ron<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let mut text = to_ron_text(value);
    text.push('\n');
    write_bytes_atomically(path, text.as_bytes())
}

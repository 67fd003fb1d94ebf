//! EXR artifacts: everything that grows with the scene. A file is a set of
//! named layers; a layer is either an image (pixels) or a table (records).
//!
//! Tables: records fill scan lines of [`TABLE_WIDTH`] pixels in order
//! (record `i` at `x = i % width`, `y = i / width`); each field is a named
//! channel, `f32` or `u32`. A single row of a million pixels would be a valid
//! EXR but one no viewer opens, hence the fixed width. The record count, and
//! what every channel means, are written into the header.
//!
//! The header: one text attribute, `pipeline`, holds [`ExrMeta`] as RON
//! (format tag, schema, version, provenance, per-layer channel meanings).
//! One attribute only, because `exr` stores extra attributes in a hash map
//! whose iteration order is random: several would break byte-identical
//! reruns. Chunks are written in increasing line order for the same reason.

use crate::error::{Error, Result};
use crate::header::{Header, HeaderTag, Input, Schema};
use crate::ron_io::{parse_ron, read_bytes, to_ron_text};
use crate::atomic::write_atomically;
use exr::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Records per scan line of a table layer.
pub const TABLE_WIDTH: usize = 1024;

/// Name of the EXR header attribute that holds [`ExrMeta`].
pub const META_ATTRIBUTE: &str = "pipeline";

/// The samples of one channel.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// Physical quantities.
    F32(Vec<f32>),
    /// Indices and counts.
    U32(Vec<u32>),
}

impl Samples {
    fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U32(v) => v.len(),
        }
    }
}

/// One named channel and what it means.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Channel name, layered as EXR viewers expect (`B.R`, `P.X`).
    pub name: String,
    /// What the values are, with units.
    pub meaning: String,
    /// Row-major samples.
    pub samples: Samples,
}

impl Channel {
    /// An `f32` channel.
    pub fn f32(name: &str, meaning: &str, samples: Vec<f32>) -> Self {
        Channel { name: name.into(), meaning: meaning.into(), samples: Samples::F32(samples) }
    }
    /// A `u32` channel.
    pub fn u32(name: &str, meaning: &str, samples: Vec<u32>) -> Self {
        Channel { name: name.into(), meaning: meaning.into(), samples: Samples::U32(samples) }
    }
}

/// What a layer holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerKind {
    /// Pixels of a `width` x `height` image.
    Image {
        /// Pixels per row.
        width: usize,
        /// Rows.
        height: usize,
    },
    /// `records` rows of a table.
    Table {
        /// Number of records.
        records: usize,
    },
}

/// One layer: an image or a table.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Layer name (empty for the single layer of a plain image, so viewers
    /// show its R, G, B directly).
    pub name: String,
    /// Image or table.
    pub kind: LayerKind,
    /// The channels, each with `width * height` or `records` samples.
    pub channels: Vec<Channel>,
}

/// Per-layer description written into the header.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LayerMeta {
    /// Layer name.
    pub name: String,
    /// Image size or record count.
    pub kind: LayerKind,
    /// `(channel, meaning)` pairs.
    pub channels: Vec<(String, String)>,
}

/// The content of the `pipeline` header attribute.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExrMeta {
    /// Format tag, schema, version, provenance.
    pub header: Header,
    /// What each layer and channel holds.
    pub layers: Vec<LayerMeta>,
}

impl Layer {
    /// A table layer of `records` records.
    pub fn table(name: &str, records: usize, channels: Vec<Channel>) -> Self {
        Layer { name: name.into(), kind: LayerKind::Table { records }, channels }
    }

    /// The layer's channel `name`, as `f32` samples; `path` names the file in
    /// the error.
    pub fn f32s(&self, path: &Path, name: &str) -> Result<&[f32]> {
        match &self.channel(path, name)?.samples {
            Samples::F32(v) => Ok(v),
            Samples::U32(_) => Err(self.wrong_type(path, name, "f32")),
        }
    }

    /// The layer's channel `name`, as `u32` samples.
    pub fn u32s(&self, path: &Path, name: &str) -> Result<&[u32]> {
        match &self.channel(path, name)?.samples {
            Samples::U32(v) => Ok(v),
            Samples::F32(_) => Err(self.wrong_type(path, name, "u32")),
        }
    }

    /// Number of records (tables) or pixels (images).
    pub fn len(&self) -> usize {
        self.kind.len()
    }

    /// Whether the layer holds no record.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn channel(&self, path: &Path, name: &str) -> Result<&Channel> {
        self.channels
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| Error::invalid(path, None, format!("layer '{}' has no channel '{name}'", self.name)))
    }

    fn wrong_type(&self, path: &Path, name: &str, wanted: &str) -> Error {
        Error::invalid(path, None, format!("channel '{name}' of layer '{}' is not {wanted}", self.name))
    }

}

impl LayerKind {
    /// Number of records (tables) or pixels (images).
    fn len(self) -> usize {
        match self {
            LayerKind::Image { width, height } => width * height,
            LayerKind::Table { records } => records,
        }
    }

    /// Pixel dimensions of a layer of this kind in the file.
    fn stored_size(self) -> (usize, usize) {
        match self {
            LayerKind::Image { width, height } => (width, height),
            LayerKind::Table { records } => {
                let width = records.clamp(1, TABLE_WIDTH);
                (width, records.div_ceil(width).max(1))
            }
        }
    }
}

/// Refuses a table whose `f32` channels `names` hold a value that is not
/// finite, naming the first such record: `record 12: field area is NaN`.
/// `record` is what one row of the layer is (`cluster`, `element`).
pub(crate) fn check_finite(path: &Path, layer: &Layer, record: &str, names: &[&str]) -> Result<()> {
    for name in names {
        let values = layer.f32s(path, name)?;
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(path, None, format!("{record} {i}: field {name} is {}", values[i])));
        }
    }
    Ok(())
}

/// Checks that the `count` records of a hierarchy table form a forest
/// whose roots are the records `roots`, so that a walk from them visits
/// every record exactly once and ends: `children(i)` gives record `i`'s
/// children as `(first, number)`, the records `first .. first + number`;
/// `parent(i)` the parent record `i` names. Refused, naming the record and
/// the field: a child range past the end of the table (`first_child`), a
/// record reached twice, which a cycle or a child of two parents gives
/// (`first_child`), a child whose `parent` is another record, and a record
/// no root reaches (`parent`). `record` is what one row is (`cluster`).
/// The walk keeps its own stack, so a deep or cyclic file cannot overflow
/// or hang it. `roots` must lie in `0..count`.
pub(crate) fn check_forest(
    path: &Path,
    record: &str,
    count: usize,
    roots: std::ops::Range<usize>,
    children: impl Fn(usize) -> (u32, u32),
    parent: impl Fn(usize) -> u32,
) -> Result<()> {
    let invalid = |message: String| Err(Error::invalid(path, None, message));
    let mut reached = vec![false; count];
    let mut stack: Vec<usize> = roots.collect();
    for &root in &stack {
        reached[root] = true;
    }
    while let Some(i) = stack.pop() {
        let (first, number) = children(i);
        let end = first as u64 + number as u64;
        if number > 0 && end > count as u64 {
            return invalid(format!("{record} {i}: children {first}..{end} run past the end of the table of {count} (field first_child)"));
        }
        for (child, seen) in reached.iter_mut().enumerate().skip(first as usize).take(number as usize) {
            if *seen {
                return invalid(format!(
                    "{record} {child}: reached twice from the root, through {record} {i} (a cycle or a shared child; field first_child)"
                ));
            }
            let named = parent(child);
            if named as usize != i {
                return invalid(format!("{record} {child}: field parent is {named}, but {record} {i} lists it as a child"));
            }
            *seen = true;
            stack.push(child);
        }
    }
    match reached.iter().position(|r| !r) {
        Some(lost) => invalid(format!("{record} {lost}: not reachable from the root (field parent is {})", parent(lost))),
        None => Ok(()),
    }
}

/// An EXR artifact in memory: header plus layers.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrArtifact {
    /// Format tag, schema, version, provenance.
    pub header: Header,
    /// Image and table layers.
    pub layers: Vec<Layer>,
}

impl ExrArtifact {
    /// The layer called `name`; `path` names the file in the error.
    pub fn layer(&self, path: &Path, name: &str) -> Result<&Layer> {
        self.optional_layer(name).ok_or_else(|| Error::invalid(path, None, format!("no layer '{name}' in this {}", self.header.schema)))
    }

    /// The layer called `name`, or `None` where the file has none: for a
    /// layer that older files of the same schema version lack.
    pub fn optional_layer(&self, name: &str) -> Option<&Layer> {
        self.layers.iter().find(|l| l.name == name)
    }
}

/// Writes `artifact` to `path` atomically, ZIP-compressed, chunks in
/// increasing order, so identical content gives identical bytes.
pub fn write_exr(path: &Path, artifact: &ExrArtifact) -> Result<()> {
    let meta = ExrMeta {
        header: artifact.header.clone(),
        layers: artifact
            .layers
            .iter()
            .map(|l| LayerMeta {
                name: l.name.clone(),
                kind: l.kind,
                channels: l.channels.iter().map(|c| (c.name.clone(), c.meaning.clone())).collect(),
            })
            .collect(),
    };
    let encoding = Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
    let mut exr_layers = Vec::with_capacity(artifact.layers.len());
    let mut bounds = (1, 1);
    for layer in &artifact.layers {
        let (width, height) = layer.kind.stored_size();
        bounds = (bounds.0.max(width), bounds.1.max(height));
        let stored = width * height;
        let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = layer
            .channels
            .iter()
            .map(|c| {
                if c.samples.len() != layer.len() {
                    return Err(Error::invalid(
                        path,
                        None,
                        format!("internal: channel '{}' has {} samples for {} records", c.name, c.samples.len(), layer.len()),
                    ));
                }
                let samples = match &c.samples {
                    Samples::F32(v) => FlatSamples::F32(padded(v, stored)),
                    Samples::U32(v) => FlatSamples::U32(padded(v, stored)),
                };
                Ok(AnyChannel::new(c.name.as_str(), samples))
            })
            .collect::<Result<_>>()?;
        let attributes = if layer.name.is_empty() { LayerAttributes::default() } else { LayerAttributes::named(layer.name.as_str()) };
        exr_layers.push(exr::image::Layer::new((width, height), attributes, encoding, AnyChannels::sort(channels)));
    }
    let mut image = Image::from_layers(ImageAttributes::new(IntegerBounds::from_dimensions(bounds)), exr_layers);
    let text = to_ron_text(&meta);
    image
        .attributes
        .other
        .insert(Text::from(META_ATTRIBUTE), AttributeValue::Text(Text::from_slice_unchecked(text.as_bytes())));
    write_atomically(path, |writer| {
        image
            .write()
            .non_parallel()
            .to_buffered(writer)
            .map_err(|e| Error::invalid(path, None, format!("cannot encode EXR: {e}")))
    })
}

fn padded<T: Copy + Default>(values: &[T], len: usize) -> Vec<T> {
    let mut out = values.to_vec();
    out.resize(len, T::default());
    out
}

/// What [`read_exr_or_foreign`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum ExrFile {
    /// An artifact of this pipeline, of the schema asked for.
    Artifact(ExrArtifact),
    /// An EXR with no `pipeline` header, written by another program: its
    /// image layers (parts), every channel converted to `f32` (half and
    /// float) or kept as `u32`, no meanings and no provenance.
    Foreign(Vec<Layer>),
}

/// Reads the EXR artifact at `path` and checks that it is of schema `S`.
/// Returns it with the input record (hash, carried provenance).
pub fn read_exr<S: Schema>(path: &Path) -> Result<(ExrArtifact, Input)> {
    match read_exr_or_foreign::<S>(path)? {
        (ExrFile::Artifact(artifact), input) => Ok((artifact, input)),
        (ExrFile::Foreign(_), _) => Err(Error::schema(
            path,
            format!("EXR without a '{META_ATTRIBUTE}' header; expected a '{}' artifact of this pipeline", S::NAME),
        )),
    }
}

/// Reads the EXR at `path`: an artifact of schema `S` (checked as
/// [`read_exr`] does), or any other readable EXR (scan lines or tiles, any
/// compression, half, float or uint channels; the largest mip level), as
/// [`ExrFile::Foreign`] whose input record carries no provenance. A file
/// that claims to be this pipeline's (has the header) and is of another
/// schema is refused, never read as foreign.
pub fn read_exr_or_foreign<S: Schema>(path: &Path) -> Result<(ExrFile, Input)> {
    let bytes = read_bytes(path)?;
    check_declared_size(path, &bytes)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(&bytes))
        .map_err(|e| Error::parse(path, None, format!("not a readable EXR file: {e}")))?;
    // `exr` may file an attribute written as shared under any layer on read.
    let key = Text::from(META_ATTRIBUTE);
    let found = std::iter::once(&image.attributes.other)
        .chain(image.layer_data.iter().map(|l| &l.attributes.other))
        .find_map(|attributes| attributes.get(&key));
    let text = match found {
        Some(AttributeValue::Text(t)) => String::from_utf8_lossy(t.bytes()).into_owned(),
        Some(_) => return Err(Error::schema(path, format!("EXR attribute '{META_ATTRIBUTE}' is not text"))),
        None => return Ok((ExrFile::Foreign(foreign_layers(&image)), Input::new(path, &bytes, None))),
    };
    let untyped: ron::Value = parse_ron(path, &text)?;
    let tag: Option<HeaderTag> = match &untyped {
        ron::Value::Map(m) => m.get(&ron::Value::String("header".into())).and_then(|h| h.clone().into_rust().ok()),
        _ => None,
    };
    tag.ok_or_else(|| Error::schema(path, "EXR header attribute holds no artifact header"))?.check::<S>(path)?;
    let meta: ExrMeta = parse_ron(path, &text)?;
    let mut layers = Vec::with_capacity(meta.layers.len());
    for described in &meta.layers {
        let stored = image
            .layer_data
            .iter()
            .find(|l| layer_name(l) == described.name)
            .ok_or_else(|| Error::invalid(path, None, format!("layer '{}' described but absent", described.name)))?;
        // The described size must be the stored one: it bounds every index
        // computed from it by data that was actually decoded.
        let size = (stored.size.width(), stored.size.height());
        if described.kind.stored_size() != size {
            return Err(Error::invalid(
                path,
                None,
                format!("layer '{}': header says {:?}, but the stored layer is {}x{} pixels", described.name, described.kind, size.0, size.1),
            ));
        }
        let layer_len = described.kind.len();
        let mut channels = Vec::with_capacity(described.channels.len());
        for (name, meaning) in &described.channels {
            let data = stored
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == *name)
                .ok_or_else(|| Error::invalid(path, None, format!("channel '{name}' described but absent")))?;
            if data.sample_data.len() < layer_len {
                return Err(Error::invalid(path, None, format!("channel '{name}' holds fewer samples than its layer's size")));
            }
            channels.push(Channel { name: name.clone(), meaning: meaning.clone(), samples: samples(&data.sample_data, layer_len) });
        }
        layers.push(Layer { name: described.name.clone(), kind: described.kind, channels });
    }
    let input = Input::new(path, &bytes, Some(meta.header.provenance.clone()));
    Ok((ExrFile::Artifact(ExrArtifact { header: meta.header, layers }), input))
}

/// How many times its own size an EXR file may hold once decoded: deflate
/// (ZIP, what this pipeline writes) tops out near 1032:1; the rest is room
/// for the RLE and PIZ files of other programs.
const MAX_EXPANSION: u128 = 4096;

/// Decoded bytes any file may hold whatever its size, so that a small file
/// of a constant image still reads.
const EXPANSION_SLACK: u128 = 64 << 20;

/// Refuses an EXR whose headers declare more pixel data than a file of its
/// size can hold decoded, before the decoder allocates it: a corrupt size
/// field would otherwise make it ask for gigabytes and abort the process.
/// Counts every channel at full resolution, and four times the base level
/// for mip and rip maps (their levels sum to less).
fn check_declared_size(path: &Path, bytes: &[u8]) -> Result<()> {
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| Error::parse(path, None, format!("not a readable EXR file: {e}")))?;
    let limit = bytes.len() as u128 * MAX_EXPANSION + EXPANSION_SLACK;
    for header in meta.headers.iter() {
        let (width, height) = (header.layer_size.width() as u128, header.layer_size.height() as u128);
        let levels = match header.blocks {
            exr::meta::BlockDescription::Tiles(tiles) if tiles.level_mode != exr::meta::attribute::LevelMode::Singular => 4,
            _ => 1,
        };
        let per_pixel: u128 = header.channels.list.iter().map(|c| c.sample_type.bytes_per_sample() as u128).sum();
        if width * height * per_pixel * levels > limit {
            return Err(Error::invalid(
                path,
                None,
                format!("EXR header declares {width}x{height} pixels of {} channels, more than a file of {} bytes can hold", header.channels.list.len(), bytes.len()),
            ));
        }
    }
    Ok(())
}

/// A stored layer's name; the empty string for an unnamed one.
fn layer_name(layer: &exr::image::Layer<AnyChannels<FlatSamples>>) -> String {
    layer.attributes.layer_name.as_ref().map(|n| n.to_string()).unwrap_or_default()
}

/// The first `len` samples of a stored channel, half widened to `f32`.
fn samples(data: &FlatSamples, len: usize) -> Samples {
    match data {
        FlatSamples::F32(v) => Samples::F32(v[..len].to_vec()),
        FlatSamples::U32(v) => Samples::U32(v[..len].to_vec()),
        FlatSamples::F16(v) => Samples::F32(v[..len].iter().map(|h| h.to_f32()).collect()),
    }
}

/// Every layer of a foreign EXR as an image layer of its stored size, with
/// its channels' full names (`R`, `albedo.R`) and no meanings.
fn foreign_layers(image: &Image<Layers<AnyChannels<FlatSamples>>>) -> Vec<Layer> {
    image
        .layer_data
        .iter()
        .map(|stored| {
            let (width, height) = (stored.size.width(), stored.size.height());
            let channels = stored
                .channel_data
                .list
                .iter()
                .map(|c| Channel {
                    name: c.name.to_string(),
                    meaning: String::new(),
                    samples: samples(&c.sample_data, (width * height).min(c.sample_data.len())),
                })
                .collect();
            Layer { name: layer_name(stored), kind: LayerKind::Image { width, height }, channels }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    struct Demo;
    impl Schema for Demo {
        const NAME: &'static str = "demo";
        const VERSION: u32 = 1;
    }

    fn provenance() -> Provenance {
        Provenance::in_memory("test")
    }

    #[test]
    fn tables_round_trip_with_padding_and_identical_bytes() {
        let records = TABLE_WIDTH + 3;
        let artifact = ExrArtifact {
            header: Demo::header(provenance()),
            layers: vec![
                Layer::table(
                    "rows",
                    records,
                    vec![
                        Channel::f32("x", "a value", (0..records).map(|i| i as f32 * 0.5).collect()),
                        Channel::u32("i", "an index", (0..records as u32).rev().collect()),
                    ],
                ),
                Layer::table("empty", 0, vec![Channel::u32("i", "nothing", vec![])]),
            ],
        };
        let dir = std::env::temp_dir().join(format!("exr-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
        write_exr(&a, &artifact).unwrap();
        write_exr(&b, &artifact).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        let (back, input) = read_exr::<Demo>(&a).unwrap();
        assert_eq!(back, artifact);
        assert_eq!(input.sha256.len(), 64);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_header_declaring_more_pixels_than_the_file_holds_is_refused_before_decoding() {
        let artifact = ExrArtifact {
            header: Demo::header(provenance()),
            layers: vec![Layer::table("rows", 3, vec![Channel::f32("x", "a value", vec![1.0, 2.0, 3.0])])],
        };
        let path = std::env::temp_dir().join(format!("exr-io-size-{}.exr", std::process::id()));
        write_exr(&path, &artifact).unwrap();
        // dataWindow: xMin, yMin, xMax, yMax as i32 after name, type and size.
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        bytes[at + 8..at + 16].copy_from_slice(&[0xff, 0xff, 0x0f, 0x00, 0xff, 0xff, 0x0f, 0x00]);
        std::fs::write(&path, &bytes).unwrap();
        let message = read_exr::<Demo>(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).unwrap();
        assert!(message.contains("EXR header declares 1048576x1048576 pixels of 1 channels, more than a file of"), "{message}");
    }

    #[test]
    fn wrong_version_is_refused_with_both_versions_named() {
        struct DemoV2;
        impl Schema for DemoV2 {
            const NAME: &'static str = "demo";
            const VERSION: u32 = 2;
        }
        let artifact = ExrArtifact {
            header: Demo::header(provenance()),
            layers: vec![Layer::table("rows", 1, vec![Channel::u32("i", "an index", vec![7])])],
        };
        let path = std::env::temp_dir().join(format!("exr-io-v-{}.exr", std::process::id()));
        write_exr(&path, &artifact).unwrap();
        let message = read_exr::<DemoV2>(&path).unwrap_err().to_string();
        assert!(message.contains("version 1") && message.contains("version 2"), "{message}");
        std::fs::remove_file(&path).unwrap();
    }
}

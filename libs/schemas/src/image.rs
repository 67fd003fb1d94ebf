//! HDR images (`*.exr` written by `grid-gather`, read by `tonemap`, `mask`
//! and `compare`).
//!
//! One unnamed layer (a single-part file, as every EXR viewer reads):
//! - linear R, G, B radiance and the coverage A (fraction of the pixel's
//!   samples that hit a surface);
//! - optionally (grid-gather always writes them) the `surface.` channels,
//!   u32: what each pixel saw, so that errors can be told per object and
//!   per material and silhouettes and emitters left out
//!   ([`PixelSurfaces`]): `surface.object` and `surface.material`
//!   (indices into the manifest's lists, [`NO_SURFACE`] where no sample
//!   hit a front face) and `surface.flags` ([`SINGLE_SURFACE`],
//!   [`EMITTER`]).
//!
//! Version 2 added the `surface.` channels.
//!
//! [`HdrImage::read_any`] also reads EXRs written by other programs
//! (Mitsuba, Blender, pbrt, cameras): the channels `R`, `G`, `B` of any
//! part, `A` as coverage where present (else every pixel counts as
//! covered), with no provenance.

use crate::error::{Error, Result};
use crate::exr_io::{read_exr_or_foreign, write_exr, Channel, ExrArtifact, ExrFile, Layer, LayerKind};
use crate::header::{Header, Input, Provenance, Schema};
use std::path::Path;

/// `object` / `material` of a pixel where no sample hit a front face.
pub const NO_SURFACE: u32 = u32::MAX;
/// Flag: every sample of the pixel hit the front face of the same object
/// with the same material (no silhouette, no miss, no back face inside).
pub const SINGLE_SURFACE: u32 = 1;
/// Flag: the pixel's surface emits (its material's exitance is > 0).
pub const EMITTER: u32 = 2;

/// What each pixel saw, row-major like the pixels.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct PixelSurfaces {
    /// Object index of the surface most of the pixel's samples hit (ties:
    /// the smaller index pair), or [`NO_SURFACE`].
    pub object: Vec<u32>,
    /// Material index of that surface, or [`NO_SURFACE`].
    pub material: Vec<u32>,
    /// [`SINGLE_SURFACE`] | [`EMITTER`] bits.
    pub flags: Vec<u32>,
}

/// Where an image read by [`HdrImage::read_any`] came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// An `image` artifact of this pipeline, with its provenance.
    Pipeline,
    /// An EXR of another program: pixels only, no provenance.
    Foreign,
}

impl Origin {
    /// For a foreign image read from `path` (input record `input`), the
    /// one-line note a stage prints and reports: it carries no provenance,
    /// and its SHA-256; `None` for an image of this pipeline.
    pub fn foreign_note(self, path: &Path, input: &Input) -> Option<String> {
        (self == Origin::Foreign).then(|| format!("{} is a foreign EXR (no provenance; SHA-256 {})", path.display(), input.sha256))
    }
}

/// A linear HDR image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    /// Header with provenance.
    pub header: Header,
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Radiance per pixel, W/(m² sr), linear RGB.
    pub rgb: Vec<[f32; 3]>,
    /// Coverage per pixel in [0, 1]: 0 where every camera ray missed.
    pub coverage: Vec<f32>,
    /// What each pixel saw, where the writer knew it.
    pub surfaces: Option<PixelSurfaces>,
}

impl Schema for HdrImage {
    const NAME: &'static str = "image";
    const VERSION: u32 = 2;
}

/// The channels holding [`PixelSurfaces`].
const SURFACE_CHANNELS: [&str; 3] = ["surface.object", "surface.material", "surface.flags"];

impl HdrImage {
    /// Writes the image atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        self.write_with(path, Vec::new())
    }

    /// Writes the image atomically with `extra` channels of the same size
    /// after its own (a stage's per-pixel extras, such as `exact`'s error
    /// bound); readers of the image ignore them.
    pub fn write_with(&self, path: &Path, extra: Vec<Channel>) -> Result<()> {
        let channel = |name: &str, k: usize| Channel::f32(name, "radiance, W/(m^2 sr), linear", self.rgb.iter().map(|p| p[k]).collect());
        let mut channels = vec![
            channel("R", 0),
            channel("G", 1),
            channel("B", 2),
            Channel::f32("A", "coverage: fraction of camera rays that hit a surface", self.coverage.clone()),
        ];
        if let Some(s) = &self.surfaces {
            let [object, material, flags] = SURFACE_CHANNELS;
            channels.extend([
                Channel::u32(object, "index into manifest objects of the surface most samples hit; 4294967295: none", s.object.clone()),
                Channel::u32(material, "index into manifest materials of that surface; 4294967295: none", s.material.clone()),
                Channel::u32(flags, "bit 0: every sample hit this one surface's front face; bit 1: the surface emits", s.flags.clone()),
            ]);
        }
        channels.extend(extra);
        let layer = Layer { name: String::new(), kind: LayerKind::Image { width: self.width, height: self.height }, channels };
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![layer] })
    }

    /// Reads an image written by this pipeline.
    pub fn read(path: &Path) -> Result<(HdrImage, Input)> {
        match HdrImage::read_any(path)? {
            (image, input, Origin::Pipeline) => Ok((image, input)),
            (_, _, Origin::Foreign) => Err(Error::schema(
                path,
                format!("EXR without a '{}' header; expected a '{}' artifact of this pipeline", crate::exr_io::META_ATTRIBUTE, Self::NAME),
            )),
        }
    }

    /// Reads an image of this pipeline or any RGB(A) EXR (see the module
    /// documentation). A foreign image gets a header whose provenance says
    /// so (stage `foreign EXR`, no inputs); its input record has the file's
    /// SHA-256 and no carried provenance.
    pub fn read_any(path: &Path) -> Result<(HdrImage, Input, Origin)> {
        match read_exr_or_foreign::<HdrImage>(path)? {
            (ExrFile::Artifact(artifact), input) => Ok((from_artifact(path, artifact)?, input, Origin::Pipeline)),
            (ExrFile::Foreign(layers), input) => Ok((from_foreign(path, &layers)?, input, Origin::Foreign)),
        }
    }
}

fn from_artifact(path: &Path, artifact: ExrArtifact) -> Result<HdrImage> {
    let layer = artifact.layer(path, "")?;
    let LayerKind::Image { width, height } = layer.kind else {
        return Err(Error::invalid(path, None, "image layer is a table"));
    };
    let (r, g, b) = (layer.f32s(path, "R")?, layer.f32s(path, "G")?, layer.f32s(path, "B")?);
    let rgb = (0..width * height).map(|i| [r[i], g[i], b[i]]).collect();
    let coverage = layer.f32s(path, "A")?.to_vec();
    let [object, material, flags] = SURFACE_CHANNELS;
    let surfaces = match layer.channels.iter().any(|c| c.name == object) {
        true => {
            let surfaces = PixelSurfaces {
                object: layer.u32s(path, object)?.to_vec(),
                material: layer.u32s(path, material)?.to_vec(),
                flags: layer.u32s(path, flags)?.to_vec(),
            };
            if let Some(i) = surfaces.flags.iter().position(|f| f & !(SINGLE_SURFACE | EMITTER) != 0) {
                return Err(Error::invalid(path, None, format!("channel '{flags}': unknown flag bits at pixel (x {}, y {})", i % width, i / width)));
            }
            Some(surfaces)
        }
        false => None,
    };
    Ok(HdrImage { header: artifact.header, width, height, rgb, coverage, surfaces })
}

/// The first part with channels `R`, `G` and `B` (exact names; AOVs such
/// as `albedo.R` are not the image), `A` as coverage clamped to [0, 1].
fn from_foreign(path: &Path, layers: &[Layer]) -> Result<HdrImage> {
    let has = |l: &Layer, name: &str| l.channels.iter().any(|c| c.name == name);
    let Some(layer) = layers.iter().find(|l| ["R", "G", "B"].iter().all(|n| has(l, n))) else {
        let found: Vec<String> = layers.iter().flat_map(|l| l.channels.iter().map(|c| c.name.clone())).collect();
        return Err(Error::invalid(path, None, format!("EXR has no R, G, B channels (found: {})", found.join(", "))));
    };
    let LayerKind::Image { width, height } = layer.kind else { unreachable!("foreign layers are images") };
    let channel = |name: &str| -> Result<&[f32]> {
        let values = layer.f32s(path, name)?;
        if values.len() != width * height {
            return Err(Error::invalid(path, None, format!("channel '{name}' is subsampled ({} samples for {width}x{height} pixels)", values.len())));
        }
        Ok(values)
    };
    let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
    let coverage = if has(layer, "A") { channel("A")?.iter().map(|a| a.clamp(0.0, 1.0)).collect() } else { vec![1.0; width * height] };
    Ok(HdrImage {
        header: HdrImage::header(Provenance::in_memory("foreign EXR")),
        width,
        height,
        rgb: (0..width * height).map(|i| [r[i], g[i], b[i]]).collect(),
        coverage,
        surfaces: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use exr::prelude::*;

    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("image-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join("image.exr")
    }

    #[test]
    fn surfaces_round_trip() {
        let image = HdrImage {
            header: HdrImage::header(Provenance::in_memory("test")),
            width: 2,
            height: 1,
            rgb: vec![[1.0, 2.0, 3.0], [0.5; 3]],
            coverage: vec![1.0, 0.25],
            surfaces: Some(PixelSurfaces { object: vec![3, NO_SURFACE], material: vec![1, NO_SURFACE], flags: vec![SINGLE_SURFACE | EMITTER, 0] }),
        };
        let path = temp("surfaces");
        image.write(&path).unwrap();
        let (back, input, origin) = HdrImage::read_any(&path).unwrap();
        assert_eq!((back, origin), (image, Origin::Pipeline));
        assert!(input.made_by.is_some());
    }

    #[test]
    fn foreign_half_tiled_rgb_reads_without_provenance() {
        // Half floats, tiles, no alpha, no custom attribute: as other
        // renderers write them. 1.5 and 0.25 are exact in half.
        let (w, h) = (3usize, 2usize);
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| (f16::from_f32(1.5), f16::from_f32(p.x() as f32), f16::from_f32(0.25 * p.y() as f32)));
        let encoding = Encoding { compression: Compression::PIZ, blocks: Blocks::Tiles(Vec2(2, 2)), line_order: LineOrder::Increasing };
        let layer = exr::image::Layer::new((w, h), LayerAttributes::default(), encoding, channels);
        let path = temp("foreign");
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let (image, input, origin) = HdrImage::read_any(&path).unwrap();
        assert_eq!(origin, Origin::Foreign);
        assert!(input.made_by.is_none() && input.sha256.len() == 64);
        assert_eq!((image.width, image.height), (w, h));
        assert_eq!(image.rgb[w + 2], [1.5, 2.0, 0.25]);
        assert_eq!(image.coverage, vec![1.0; w * h]);
        assert!(image.surfaces.is_none());
        let message = HdrImage::read(&path).unwrap_err().to_string();
        assert!(message.contains("without a 'pipeline' header"), "{message}");
    }

    #[test]
    fn foreign_without_rgb_names_the_channels_found() {
        let channels = SpecificChannels::build().with_channel("Y").with_pixel_fn(|_p: Vec2<usize>| (0.5f32,));
        let layer = exr::image::Layer::new((2, 2), LayerAttributes::default(), Encoding::FAST_LOSSLESS, channels);
        let path = temp("luminance");
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let message = HdrImage::read_any(&path).unwrap_err().to_string();
        assert!(message.contains("no R, G, B channels (found: Y)"), "{message}");
    }
}

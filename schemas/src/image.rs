//! HDR images (`*.exr` written by `grid-gather`, read by `tonemap`, `mask`
//! and `compare`): one unnamed layer with linear R, G, B radiance and the
//! coverage A (fraction of the pixel's samples that hit a surface).

use crate::error::{Error, Result};
use crate::exr_io::{read_exr, write_exr, Channel, ExrArtifact, Layer, LayerKind};
use crate::header::{Header, Input, Schema};
use std::path::Path;

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
}

impl Schema for HdrImage {
    const NAME: &'static str = "image";
    const VERSION: u32 = 1;
}

impl HdrImage {
    /// Writes the image atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let channel = |name: &str, k: usize| Channel::f32(name, "radiance, W/(m^2 sr), linear", self.rgb.iter().map(|p| p[k]).collect());
        let layer = Layer {
            name: String::new(),
            kind: LayerKind::Image { width: self.width, height: self.height },
            channels: vec![
                channel("R", 0),
                channel("G", 1),
                channel("B", 2),
                Channel::f32("A", "coverage: fraction of camera rays that hit a surface", self.coverage.clone()),
            ],
        };
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![layer] })
    }

    /// Reads an image written by this pipeline.
    pub fn read(path: &Path) -> Result<(HdrImage, Input)> {
        let (artifact, input) = read_exr::<HdrImage>(path)?;
        let layer = artifact.layer(path, "")?;
        let LayerKind::Image { width, height } = layer.kind else {
            return Err(Error::invalid(path, None, "image layer is a table"));
        };
        let (r, g, b) = (layer.f32s(path, "R")?, layer.f32s(path, "G")?, layer.f32s(path, "B")?);
        let rgb = (0..width * height).map(|i| [r[i], g[i], b[i]]).collect();
        let coverage = layer.f32s(path, "A")?.to_vec();
        Ok((HdrImage { header: artifact.header, width, height, rgb, coverage }, input))
    }
}

//! Visibility thresholds (`threshold.exr`, written by `mask`, read by
//! `grid-gather --threshold`): one unnamed image layer, row-major, top row
//! first, with the channels
//!
//! | channel | meaning | unit |
//! |---|---|---|
//! | `L` | display luminance of the tone-mapped pixel | cd/m² |
//! | `La` | adaptation luminance (about one degree of visual angle) | cd/m² |
//! | `elevation` | masking threshold elevation (Ramasubramanian et al. 1999), >= 1 | - |
//! | `threshold` | `TVI(La) x elevation`, smallest visible luminance step | cd/m² |
//! | `contrast` | `threshold / max(L, display black)`: smallest visible contrast | - |
//!
//! A reader that needs only the contrast (the full gather, paper 000 Sec.
//! 5.2) still gets every channel checked for length by the EXR layer.

use crate::error::{Error, Result};
use crate::exr_io::{read_exr, write_exr, Channel, ExrArtifact, Layer, LayerKind};
use crate::header::{Header, Input, Schema};
use std::path::Path;

/// The per-pixel visibility threshold of a tone-mapped image.
#[derive(Clone, Debug, PartialEq)]
pub struct ThresholdImage {
    /// Header with provenance.
    pub header: Header,
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Display luminance `L`, cd/m².
    pub luminance: Vec<f32>,
    /// Adaptation luminance `La`, cd/m².
    pub adaptation: Vec<f32>,
    /// Masking threshold elevation, >= 1.
    pub elevation: Vec<f32>,
    /// `TVI(La) x elevation`, cd/m².
    pub threshold: Vec<f32>,
    /// `threshold / max(L, display black)`: the threshold as a contrast.
    pub contrast: Vec<f32>,
}

impl Schema for ThresholdImage {
    const NAME: &'static str = "threshold";
    const VERSION: u32 = 1;
}

impl ThresholdImage {
    /// Writes the image atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let layer = Layer {
            name: String::new(),
            kind: LayerKind::Image { width: self.width, height: self.height },
            channels: vec![
                Channel::f32("L", "display luminance, cd/m^2", self.luminance.clone()),
                Channel::f32("La", "adaptation luminance (about 1 degree), cd/m^2", self.adaptation.clone()),
                Channel::f32("elevation", "masking threshold elevation (Ramasubramanian et al. 1999), >= 1", self.elevation.clone()),
                Channel::f32("threshold", "TVI(La) x elevation, cd/m^2", self.threshold.clone()),
                Channel::f32("contrast", "threshold / max(L, display black): smallest visible contrast", self.contrast.clone()),
            ],
        };
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![layer] })
    }

    /// Reads a threshold image written by this pipeline; refuses an empty
    /// one.
    pub fn read(path: &Path) -> Result<(ThresholdImage, Input)> {
        let (artifact, input) = read_exr::<ThresholdImage>(path)?;
        let layer = artifact.layer(path, "")?;
        let LayerKind::Image { width, height } = layer.kind else {
            return Err(Error::invalid(path, None, "threshold layer is a table"));
        };
        if width == 0 || height == 0 {
            return Err(Error::invalid(path, None, "threshold image is empty"));
        }
        let channel = |name: &str| layer.f32s(path, name).map(<[f32]>::to_vec);
        Ok((
            ThresholdImage {
                header: artifact.header.clone(),
                width,
                height,
                luminance: channel("L")?,
                adaptation: channel("La")?,
                elevation: channel("elevation")?,
                threshold: channel("threshold")?,
                contrast: channel("contrast")?,
            },
            input,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    #[test]
    fn round_trips_and_refuses_another_schema() {
        let dir = std::env::temp_dir().join(format!("schemas-threshold-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.exr");
        let v = |k: f32| (0..6).map(|i| k + i as f32).collect::<Vec<f32>>();
        let t = ThresholdImage {
            header: ThresholdImage::header(Provenance::in_memory("test")),
            width: 3,
            height: 2,
            luminance: v(1.0),
            adaptation: v(2.0),
            elevation: v(3.0),
            threshold: v(4.0),
            contrast: v(5.0),
        };
        t.write(&path).unwrap();
        let (back, _) = ThresholdImage::read(&path).unwrap();
        assert_eq!(back, t);
        let err = crate::image::HdrImage::read(&path).unwrap_err().to_string();
        assert!(err.contains("t.exr"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

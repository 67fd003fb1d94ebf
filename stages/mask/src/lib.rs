//! # mask: where the eye cannot see small errors
//!
//! Paper 000 Sec. 5.1-5.2: the final gather may interpolate a sender
//! wherever its error stays below what a viewer can see. This stage turns a
//! tone-mapped preview (grid-gather `--mode preview`, then `tonemap`) into a
//! per-pixel visibility threshold:
//!
//! ```text
//! dL_thr(x) = TVI(L_a(x)) * T_e(x)        (cd/m², display luminance)
//! c_thr(x)  = dL_thr(x) / max(L_d(x), L_black)   (dimensionless)
//! ```
//!
//! - `L_d` is the display luminance of the pixel: the sRGB pixel decoded to
//!   linear, Rec. 709 luminance, times the display's peak luminance
//!   (`display_max_cd_m2`).
//! - `L_a` is the adaptation luminance: `L_d` blurred over about one
//!   degree of visual angle (the pyramid level whose blur radius is closest
//!   to `pixels_per_degree` pixels).
//! - `TVI` is the threshold-versus-intensity function of Ferwerda,
//!   Pattanaik, Shirley and Greenberg 1996 ([`tvi`]).
//! - `T_e >= 1` is the threshold elevation of the masking model of
//!   Ramasubramanian, Pattanaik and Greenberg 1999, paper 000's reference
//!   [15] ([`elevation`]).
//! - `c_thr`, the threshold as a contrast (a Weber fraction), is what
//!   grid-gather reads: it multiplies it by its own radiance estimate at a
//!   grid vertex. That equals mapping `dL_thr` back through a tone curve
//!   that is linear through the origin; for a compressive curve (Reinhard)
//!   the true slope is lower than the ratio, so the radiance threshold it
//!   gives is smaller than the exact one: conservative.
//!
//! ## What the mask sees: textures come with the preview
//!
//! The stage reads only the tone-mapped preview, never the scene: surface
//! detail masks errors exactly as far as the preview shows it. The
//! pipelines render that preview with grid-gather `--surface surface.exr`
//! (`make`, `make full MASK=1`, `make gpu`, `make photon`), which shades
//! each pixel with its texel's reflectance `rho(x)`, so a textured floor's
//! pattern reaches the contrast pyramid and raises `T_e` over it; the
//! stage needs no texture of its own. A preview made without `--surface`
//! shows each material's mean reflectance and the mask then sees no
//! texture. `make bench-mask` (bench/src/mask/) measures what this buys on
//! a checkerboard floor (paper 000 Table 1 in shape).
//!
//! ## Parameters
//!
//! [`Params`] (`mask --print-knobs`, the README's "Stage knobs"): the
//! display (white and black luminance), the viewing distance (pixels per
//! degree), the pyramid's depth and the masking slope.
//!
//! Everything here takes data, not paths, and never prints.

pub mod model;

use model::{band_frequency_cpd, contrast_sensitivity, elevation_image, luminance_pyramid, tvi};
use schemas::error::Result;
use schemas::header::Header;
use stage_kit::run::bad_parameter;
use schemas::threshold::ThresholdImage;
use stage_kit::knobs::Knobs;
use std::collections::BTreeMap;

pub use model::elevation;

stage_kit::knobs! {
    /// The stage's parameters (`--params file.ron`, overridden by flags).
    pub struct Params {
        /// Luminance of display white (sRGB 255).
        display_max_cd_m2: f64 = 100.0, "cd/m²", value(positive());
        /// Darkest luminance the display shows, as a fraction of white; floors `L_d` and `L_a`.
        display_black: f64 = 0.005, "fraction of white", value(open(0.0, 1.0));
        /// Image pixels per degree of visual angle (a 512-pixel image 16 degrees wide: 32).
        pixels_per_degree: f64 = 32.0, "pixels", value(positive());
        /// Band-pass levels of the contrast pyramid.
        levels: u32 = 6, "", value(1..=12);
        /// Exponent `s` of the masking function `max(1, C^s)`.
        masking_slope: f64 = 0.7, "", value(left_open(0.0, 1.0));
    }
}


/// The model's thresholds of an image, as the stage writes them, and the
/// figures its report gives.
#[derive(Clone, Debug, PartialEq)]
pub struct Thresholds {
    /// The per-pixel threshold, row-major, top row first.
    pub image: ThresholdImage,
    /// Work counters for the report.
    pub counters: BTreeMap<String, f64>,
}

/// The sRGB electro-optical transfer (IEC 61966-2-1): an encoded value in
/// [0, 1] to linear light in [0, 1].
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Display luminance, cd/m², of 8-bit sRGB pixels on a display whose white
/// is `display_max_cd_m2`.
pub fn display_luminance(pixels: &[[u8; 3]], display_max_cd_m2: f64) -> Vec<f64> {
    pixels
        .iter()
        .map(|p| display_max_cd_m2 * radiometry::color::luminance(p.map(|c| srgb_decode(f64::from(c) / 255.0))))
        .collect()
}

/// Runs the model over a `width` x `height` image of display luminances
/// (cd/m², row-major); `header` heads the threshold image.
pub fn thresholds(params: &Params, header: Header, width: usize, height: usize, luminance: &[f64]) -> Result<Thresholds> {
    params.check("")?;
    if width == 0 || height == 0 || luminance.len() != width * height {
        return Err(bad_parameter(format!("image of {width}x{height} pixels with {} values", luminance.len())));
    }
    let black = params.display_black * params.display_max_cd_m2;
    let floored: Vec<f64> = luminance.iter().map(|&l| l.max(black)).collect();
    // Enough blur levels for the adaptation scale, at least the bands.
    let adaptation_level = (params.pixels_per_degree.log2().round().max(1.0) as usize).min(14);
    let depth = (params.levels as usize + 1).max(adaptation_level + 1);
    let pyramid = luminance_pyramid(width, height, &floored, depth);
    let elevation = elevation_image(&pyramid, params.levels as usize, params.pixels_per_degree, params.masking_slope);
    let adaptation = &pyramid[adaptation_level];
    let mut image = ThresholdImage {
        header,
        width,
        height,
        luminance: luminance.iter().map(|&l| l as f32).collect(),
        adaptation: adaptation.iter().map(|&l| l as f32).collect(),
        elevation: elevation.iter().map(|&e| e as f32).collect(),
        threshold: Vec::with_capacity(luminance.len()),
        contrast: Vec::with_capacity(luminance.len()),
    };
    for i in 0..luminance.len() {
        let threshold = tvi(adaptation[i].max(black)) * elevation[i];
        image.threshold.push(threshold as f32);
        image.contrast.push((threshold / floored[i]) as f32);
    }
    let n = luminance.len() as f64;
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let mut counters = BTreeMap::new();
    counters.insert("pixels".into(), n);
    counters.insert("bands".into(), f64::from(params.levels));
    counters.insert("mean_elevation".into(), mean(&image.elevation));
    counters.insert("max_elevation".into(), image.elevation.iter().fold(0.0f64, |m, &e| m.max(f64::from(e))));
    counters.insert("mean_contrast_threshold".into(), mean(&image.contrast));
    counters.insert("peak_band_cpd".into(), {
        let bands: Vec<f64> = (0..params.levels as usize).map(|k| band_frequency_cpd(k, params.pixels_per_degree)).collect();
        bands.iter().copied().fold((0.0, 0.0), |(bf, bs), f| if contrast_sensitivity(f) > bs { (f, contrast_sensitivity(f)) } else { (bf, bs) }).0
    });
    Ok(Thresholds { image, counters })
}

#[cfg(test)]
mod tests;

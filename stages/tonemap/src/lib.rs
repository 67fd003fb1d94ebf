//! # tonemap: linear HDR radiance to an 8-bit sRGB picture
//!
//! The last stage of the pipeline and the only one that leaves linear,
//! physical units: it maps an [`HdrImage`] (radiance, W/(m² sr), with
//! coverage) to display values, applies the sRGB transfer function and
//! quantises to 8 bits. Pixels no camera ray hit (coverage 0) stay black.
//!
//! The knobs are [`Params`] (`tonemap --print-knobs`, the README's
//! "Stage knobs"): the operator, and its key or exposure, each estimated
//! from the image (`auto`) or given.
//!
//! Operators (see [`operators`] for each equation):
//! - `Reinhard`: the global operator of Reinhard, Stark, Shirley and
//!   Ferwerda 2002, "Photographic tone reproduction for digital images"
//!   (SIGGRAPH), Eq. 1, 2 and 4, with `L_white` the largest scaled luminance;
//!   the automatic key from Reinhard 2002, "Parameter estimation for
//!   photographic tone reproduction" (JGT 7(1)), with the 1st and 99th
//!   luminance percentiles as robust minimum and maximum.
//! - `Exposure`: `y = 1 − exp(−k x)` per channel, `k = 1 / L_avg` when
//!   automatic (the log-average luminance maps to `1 − 1/e ≈ 0.63`).
//!
//! ```
//! use tonemap::{tonemap, Params};
//! # use schemas::header::{Schema, Provenance};
//! # let provenance = Provenance::in_memory("doc");
//! let image = schemas::image::HdrImage {
//!     header: schemas::image::HdrImage::header(provenance),
//!     width: 2, height: 1,
//!     rgb: vec![[0.5, 0.5, 0.5], [9.0, 9.0, 9.0]],
//!     coverage: vec![1.0, 0.0],
//!     surfaces: None,
//! };
//! let out = tonemap(&image, &Params::default()).unwrap();
//! assert_eq!(out.pixels[0], [255, 255, 255]); // the brightest covered pixel is white
//! assert_eq!(out.pixels[1], [0, 0, 0]); // uncovered: black
//! ```

#![deny(missing_docs)]

pub mod operators;

use operators::{
    auto_key, exposure, log_average_luminance, luminance, percentile, reinhard_display, srgb_oetf, to_8bit, DELTA,
    ROBUST_PERCENTILES,
};
use schemas::image::HdrImage;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

/// Which tone curve maps radiance to display values.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Operator {
    /// Reinhard et al. 2002 global photographic operator, on luminance.
    #[default]
    Reinhard,
    /// `1 − exp(−k x)` per channel.
    Exposure,
}

stage_kit::show_by_name!(Operator);

/// A scale estimated from the image, or given.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub enum Setting {
    /// Estimated from the image.
    #[default]
    Auto,
    /// This value.
    Fixed(f64),
}

impl FromStr for Setting {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Setting::Auto);
        }
        s.parse::<f64>().map(Setting::Fixed).map_err(|_| format!("'{s}' is neither 'auto' nor a number"))
    }
}

impl stage_kit::knobs::Show for Setting {
    fn show(&self) -> String {
        match self {
            Setting::Auto => "auto".to_string(),
            Setting::Fixed(v) => v.to_string(),
        }
    }
}

impl Setting {
    /// Whether the setting is `auto` or a positive finite number.
    fn valid(&self) -> bool {
        match *self {
            Setting::Auto => true,
            Setting::Fixed(v) => v.is_finite() && v > 0.0,
        }
    }
}

stage_kit::knobs! {
    /// The stage's parameters.
    pub struct Params {
        /// The tone curve.
        operator: Operator = Operator::Reinhard, "", value;
        /// Reinhard's key `a`, the display value of the log-average luminance
        /// (middle grey); used by `reinhard` only.
        key: Setting = Setting::Auto, "", value(custom("a positive number or 'auto'", Setting::valid));
        /// Exposure `k` (`auto`: 1 / log-average luminance); used by `exposure` only.
        exposure: Setting = Setting::Auto, "1/(W/(m² sr))", value(custom("a positive number or 'auto'", Setting::valid));
    }
}

/// Why an image cannot be tone mapped; the caller adds the file name.
#[derive(Clone, Debug, PartialEq)]
pub enum InputError {
    /// A radiance or coverage value is NaN or infinite (the first one, in
    /// row-major order).
    NonFinite {
        /// Column, 0 at the left.
        x: usize,
        /// Row, 0 at the top.
        y: usize,
        /// The channel: `R`, `G`, `B` or `A`.
        channel: &'static str,
        /// The value found.
        value: f32,
    },
    /// The pixel arrays do not hold `width * height` entries.
    Size {
        /// Pixels the size calls for.
        expected: usize,
        /// RGB pixels held.
        rgb: usize,
        /// Coverage values held.
        coverage: usize,
    },
    /// The image has no pixel (a PNG cannot be empty).
    Empty,
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::NonFinite { x, y, channel, value } => {
                write!(f, "non-finite value {value} in channel {channel} at pixel (x {x}, y {y})")
            }
            InputError::Size { expected, rgb, coverage } => {
                write!(f, "image size calls for {expected} pixels, found {rgb} RGB and {coverage} coverage values")
            }
            InputError::Empty => write!(f, "image has no pixels"),
        }
    }
}

/// The curve actually applied, with its estimated or given constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Curve {
    /// Reinhard: key `a` and white point `L_white` (in scaled luminance).
    Reinhard {
        /// Key `a`.
        key: f64,
        /// Largest scaled luminance `L_white`.
        white: f64,
    },
    /// Exposure `k`, 1/(W/(m² sr)).
    Exposure {
        /// Exposure `k`.
        k: f64,
    },
}

/// What the mapping measured and did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Pixels in the image.
    pub pixels: usize,
    /// Pixels with coverage > 0 (the ones the statistics are taken over).
    pub covered_pixels: usize,
    /// Log-average luminance `L_avg` of the covered pixels (0 if none).
    pub log_average_luminance: f64,
    /// Robust minimum (1st percentile) luminance of the covered pixels.
    pub min_luminance: f64,
    /// Robust maximum (99th percentile) luminance of the covered pixels.
    pub max_luminance: f64,
    /// The curve and its constants.
    pub curve: Curve,
    /// Negative radiance values set to 0 before mapping (interpolation can
    /// overshoot below zero; a display cannot show it).
    pub negative_values_clamped: usize,
    /// Covered-pixel channels that reached the top 8-bit value 255.
    pub saturated_channels: usize,
}

impl Stats {
    /// The counters of the stage's report.
    pub fn counters(&self) -> BTreeMap<String, f64> {
        let mut c = BTreeMap::new();
        c.insert("pixels".to_string(), self.pixels as f64);
        c.insert("covered_pixels".to_string(), self.covered_pixels as f64);
        c.insert("log_average_luminance".to_string(), self.log_average_luminance);
        c.insert("min_luminance_p01".to_string(), self.min_luminance);
        c.insert("max_luminance_p99".to_string(), self.max_luminance);
        c.insert("negative_values_clamped".to_string(), self.negative_values_clamped as f64);
        c.insert("saturated_channels".to_string(), self.saturated_channels as f64);
        match self.curve {
            Curve::Reinhard { key, white } => {
                c.insert("key".to_string(), key);
                c.insert("white_luminance".to_string(), white);
            }
            Curve::Exposure { k } => {
                c.insert("exposure".to_string(), k);
            }
        }
        c
    }
}

/// An 8-bit sRGB picture, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Tonemapped {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// sRGB-encoded 8-bit pixels.
    pub pixels: Vec<[u8; 3]>,
    /// What was measured and applied.
    pub stats: Stats,
}

/// Checks sizes and finiteness: the first non-finite value, row-major, is
/// the error.
fn check(image: &HdrImage) -> Result<(), InputError> {
    let expected = image.width * image.height;
    if image.rgb.len() != expected || image.coverage.len() != expected {
        return Err(InputError::Size { expected, rgb: image.rgb.len(), coverage: image.coverage.len() });
    }
    if expected == 0 {
        return Err(InputError::Empty);
    }
    for (i, (rgb, &a)) in image.rgb.iter().zip(&image.coverage).enumerate() {
        let values = [("R", rgb[0]), ("G", rgb[1]), ("B", rgb[2]), ("A", a)];
        if let Some(&(channel, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            return Err(InputError::NonFinite { x: i % image.width, y: i / image.width, channel, value });
        }
    }
    Ok(())
}

/// Tone maps `image` with `params` (assumed [checked](stage_kit::knobs::Knobs::check)).
///
/// Statistics (log-average, percentiles, white point) are taken over the
/// covered pixels only, so the background does not darken the key. Pixel
/// values are linear radiance; negative values are clamped to 0 first.
/// Colour under `Reinhard` is preserved by scaling RGB by `L_d / L_w`;
/// channels above 1 after that clip in the 8-bit quantisation.
pub fn tonemap(image: &HdrImage, params: &Params) -> Result<Tonemapped, InputError> {
    check(image)?;
    let mut negative_values_clamped = 0;
    let radiance: Vec<[f64; 3]> = image
        .rgb
        .iter()
        .map(|p| {
            p.map(|v| {
                if v < 0.0 {
                    negative_values_clamped += 1;
                }
                f64::from(v.max(0.0))
            })
        })
        .collect();
    let covered: Vec<usize> = (0..radiance.len()).filter(|&i| image.coverage[i] > 0.0).collect();
    let mut luminances: Vec<f64> = covered.iter().map(|&i| luminance(radiance[i])).collect();
    let l_avg = log_average_luminance(&luminances);
    luminances.sort_by(f64::total_cmp);
    let l_min = percentile(&luminances, ROBUST_PERCENTILES.0);
    let l_max = percentile(&luminances, ROBUST_PERCENTILES.1);

    let curve = match params.operator {
        Operator::Reinhard => {
            let key = match params.key {
                Setting::Fixed(a) => a,
                Setting::Auto => auto_key(l_avg, l_min + DELTA, l_max + DELTA),
            };
            // `luminances` is sorted: its last entry is the largest L_w.
            let white = if l_avg > 0.0 { key / l_avg * luminances.last().copied().unwrap_or(0.0) } else { 0.0 };
            Curve::Reinhard { key, white }
        }
        Operator::Exposure => {
            let k = match params.exposure {
                Setting::Fixed(k) => k,
                Setting::Auto if l_avg > 0.0 => 1.0 / l_avg,
                Setting::Auto => 0.0,
            };
            Curve::Exposure { k }
        }
    };

    let mut pixels = vec![[0u8; 3]; radiance.len()];
    let mut saturated_channels = 0;
    for &i in &covered {
        let rgb = radiance[i];
        let display = match curve {
            Curve::Reinhard { key, white } => {
                let l_w = luminance(rgb);
                if l_w > 0.0 {
                    let l_d = reinhard_display(key / l_avg * l_w, white);
                    rgb.map(|v| v * l_d / l_w)
                } else {
                    [0.0; 3]
                }
            }
            Curve::Exposure { k } => rgb.map(|v| exposure(v, k)),
        };
        pixels[i] = display.map(|v| to_8bit(srgb_oetf(v)));
        saturated_channels += pixels[i].iter().filter(|&&v| v == 255).count();
    }

    let stats = Stats {
        pixels: radiance.len(),
        covered_pixels: covered.len(),
        log_average_luminance: l_avg,
        min_luminance: l_min,
        max_luminance: l_max,
        curve,
        negative_values_clamped,
        saturated_channels,
    };
    Ok(Tonemapped { width: image.width, height: image.height, pixels, stats })
}


#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::{Provenance, Schema};

    fn image(width: usize, height: usize, rgb: Vec<[f32; 3]>, coverage: Vec<f32>) -> HdrImage {
        let provenance = Provenance::in_memory("test");
        HdrImage { header: HdrImage::header(provenance), width, height, rgb, coverage, surfaces: None }
    }

    fn grey(values: &[f32]) -> HdrImage {
        image(values.len(), 1, values.iter().map(|&v| [v, v, v]).collect(), vec![1.0; values.len()])
    }

    #[test]
    fn uniform_image_with_auto_key_maps_to_white() {
        // Key guard a = 0.18; L = 0.18 (to 1e-6) = L_white, so
        // L_d = 0.18 (1 + 0.18 / 0.0324) / 1.18 = 1 -> 255.
        let out = tonemap(&grey(&[0.7; 6]), &Params::default()).unwrap();
        let Curve::Reinhard { key, white } = out.stats.curve else { panic!("not Reinhard") };
        assert_eq!(key, 0.18);
        assert!((white - 0.18).abs() < 1e-6);
        assert!(out.pixels.iter().all(|p| *p == [255, 255, 255]));
        // A coloured uniform image keeps its chromaticity: RGB scaled by
        // 1 / L_w, here L_w = 0.2126 * 0.4 + 0.7152 * 0.2 + 0.0722 * 0.1.
        let out = tonemap(&image(1, 1, vec![[0.4, 0.2, 0.1]], vec![1.0]), &Params::default()).unwrap();
        let l_w = 0.2126 * 0.4 + 0.7152 * 0.2 + 0.0722 * 0.1;
        let expected = [0.4, 0.2, 0.1].map(|v: f64| to_8bit(srgb_oetf(v / l_w)));
        assert_eq!(out.pixels[0], expected);
        assert_eq!(expected, [255, 237, 174]);
    }

    #[test]
    fn exposure_operator_exact_value() {
        // k = ln 2, x = 1: y = 1/2, sRGB 0.735357 -> 187.52 -> 188.
        let params = Params {
            operator: Operator::Exposure,
            exposure: Setting::Fixed(std::f64::consts::LN_2),
            ..Params::default()
        };
        let out = tonemap(&grey(&[1.0, 0.0]), &params).unwrap();
        assert_eq!(out.pixels, vec![[188, 188, 188], [0, 0, 0]]);
        // Auto: k = 1 / L_avg; a uniform image at 2 maps to 1 - 1/e = 0.632 -> sRGB 0.81647 -> 208.2 -> 208.
        let params = Params { operator: Operator::Exposure, ..Params::default() };
        let out = tonemap(&grey(&[2.0; 3]), &params).unwrap();
        let Curve::Exposure { k } = out.stats.curve else { panic!("not exposure") };
        assert!((k - 0.5).abs() < 1e-6);
        assert_eq!(out.pixels[0], [208, 208, 208]);
    }

    #[test]
    fn auto_key_on_an_image_by_hand() {
        // 25 pixels at 1/16, 75 at 4: log2 L_avg = (25 (-4) + 75 (2)) / 100 = 0.5,
        // 1st / 99th percentiles 1/16 and 4, f = (1 + 4 - 2) / 6 = 0.5, a = 0.36.
        // Scaled: 0.36 / sqrt 2 * 4 = 1.01823 (= L_white -> 1 -> 255) and
        // 0.36 / sqrt 2 / 16 = 0.0159098 -> L_d = 0.0159010 -> sRGB 0.13286 -> 33.88 -> 34.
        let mut values = vec![1.0 / 16.0; 25];
        values.extend([4.0; 75]);
        let out = tonemap(&grey(&values), &Params::default()).unwrap();
        let Curve::Reinhard { key, white } = out.stats.curve else { panic!("not Reinhard") };
        assert!((key - 0.36).abs() < 1e-5, "key {key}");
        assert!((white - 0.36 / 2f64.sqrt() * 4.0).abs() < 1e-5, "white {white}");
        assert!((out.stats.log_average_luminance - 2f64.sqrt()).abs() < 1e-5);
        assert_eq!(out.pixels[0], [34, 34, 34]);
        assert_eq!(out.pixels[99], [255, 255, 255]);
        let counters = out.stats.counters();
        assert_eq!(counters["covered_pixels"], 100.0);
        assert!((counters["key"] - 0.36).abs() < 1e-5);
    }

    #[test]
    fn both_operators_are_monotone_on_a_ramp() {
        let ramp: Vec<f32> = (0..200).map(|i| 0.001 * 1.05f32.powi(i)).collect();
        for operator in [Operator::Reinhard, Operator::Exposure] {
            let out = tonemap(&grey(&ramp), &Params { operator, ..Params::default() }).unwrap();
            for pair in out.pixels.windows(2) {
                assert!(pair[1][0] >= pair[0][0], "{operator:?}: {pair:?}");
            }
            assert!(out.pixels[0][0] < out.pixels[199][0], "{operator:?} maps the ramp flat");
        }
    }

    #[test]
    fn uncovered_pixels_stay_black_and_do_not_enter_statistics() {
        let img = image(3, 1, vec![[1.0; 3], [1000.0; 3], [1.0; 3]], vec![1.0, 0.0, 0.5]);
        let out = tonemap(&img, &Params::default()).unwrap();
        assert_eq!(out.pixels[1], [0, 0, 0]);
        assert_eq!(out.stats.covered_pixels, 2);
        assert!((out.stats.log_average_luminance - 1.0).abs() < 1e-5);
        assert_eq!(out.pixels[0], [255, 255, 255]);
    }

    #[test]
    fn non_finite_value_names_the_first_bad_pixel() {
        let mut rgb = vec![[1.0; 3]; 6];
        rgb[4][1] = f32::NAN;
        rgb[5][0] = f32::INFINITY;
        let err = tonemap(&image(3, 2, rgb, vec![1.0; 6]), &Params::default()).unwrap_err();
        assert!(matches!(err, InputError::NonFinite { x: 1, y: 1, channel: "G", .. }), "{err:?}");
        assert!(err.to_string().contains("(x 1, y 1)"));
    }

    #[test]
    fn parameters_parse_and_validate() {
        assert_eq!("auto".parse::<Setting>(), Ok(Setting::Auto));
        assert_eq!("0.5".parse::<Setting>(), Ok(Setting::Fixed(0.5)));
        assert!("bright".parse::<Setting>().is_err());
        use stage_kit::knobs::Knobs;
        let refused = |params: Params| params.check("").unwrap_err().to_string();
        assert_eq!(refused(Params { key: Setting::Fixed(-1.0), ..Params::default() }), "parameters: key must be a positive number or 'auto', not -1");
        assert_eq!(refused(Params { exposure: Setting::Fixed(f64::NAN), ..Params::default() }), "parameters: exposure must be a positive number or 'auto', not NaN");
        assert!(Params { key: Setting::Fixed(0.18), exposure: Setting::Auto, ..Params::default() }.check("").is_ok());
        let text = "(operator: Exposure, exposure: Fixed(2.0))";
        let params: Params = ron::from_str(text).unwrap();
        assert_eq!(params.exposure, Setting::Fixed(2.0));
        assert_eq!(params.key, Setting::Auto);
        assert!(ron::from_str::<Params>("(operatr: Exposure)").is_err());
    }

    #[test]
    fn png_encoding_is_deterministic_and_sized() {
        let pixels = vec![[1, 2, 3], [4, 5, 6]];
        let a = stage_kit::png::encode_png(2, 1, &pixels).unwrap();
        assert_eq!(a, stage_kit::png::encode_png(2, 1, &pixels).unwrap());
        assert_eq!(&a[1..4], b"PNG");
        // IHDR width and height, big-endian, at bytes 16..24.
        assert_eq!(&a[16..24], &[0, 0, 0, 2, 0, 0, 0, 1]);
    }
}

//! Image comparison: the samples are the pixels the reference sees, and the
//! difference picture.

use crate::metrics::{luminance, Sample};
use crate::{CompareError, Which};
use schemas::image::HdrImage;

/// Grey of pixels the reference does not see, in the difference picture.
pub const UNCOVERED_GREY: [u8; 3] = [128, 128, 128];

/// Checks that the image holds `width · height` finite values in every
/// channel; the first bad pixel, row-major, is the error.
fn check(image: &HdrImage, which: Which) -> Result<(), CompareError> {
    let expected = image.width * image.height;
    if image.rgb.len() != expected || image.coverage.len() != expected {
        return Err(CompareError::Malformed {
            which,
            what: format!(
                "size calls for {expected} pixels, found {} RGB and {} coverage values",
                image.rgb.len(),
                image.coverage.len()
            ),
        });
    }
    for (i, (rgb, &a)) in image.rgb.iter().zip(&image.coverage).enumerate() {
        let values = [("R", rgb[0]), ("G", rgb[1]), ("B", rgb[2]), ("A", a)];
        if let Some((channel, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            return Err(CompareError::Malformed {
                which,
                what: format!(
                    "non-finite value {value} in channel {channel} at pixel (x {}, y {})",
                    i % image.width,
                    i / image.width
                ),
            });
        }
    }
    Ok(())
}

/// Checks both images and that they have the same size.
pub fn check_pair(a: &HdrImage, b: &HdrImage) -> Result<(), CompareError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CompareError::Malformed {
            which: Which::A,
            what: format!("is {}x{} pixels but the reference is {}x{}", a.width, a.height, b.width, b.height),
        });
    }
    check(a, Which::A)?;
    check(b, Which::B)
}

/// The visible samples: pixels whose reference coverage is > 0, weight 1.
/// Both images must have passed [`check_pair`].
pub fn samples(a: &HdrImage, b: &HdrImage) -> Vec<Sample> {
    (0..b.rgb.len())
        .filter(|&i| b.coverage[i] > 0.0)
        .map(|i| Sample { a: a.rgb[i].map(f64::from), b: b.rgb[i].map(f64::from), weight: 1.0 })
        .collect()
}

/// Pixels seen by one image and not by the other (coverage > 0 in exactly
/// one): a geometry or camera mismatch, which the metrics see only where
/// the reference is covered.
pub fn coverage_mismatches(a: &HdrImage, b: &HdrImage) -> usize {
    a.coverage.iter().zip(&b.coverage).filter(|(x, y)| (**x > 0.0) != (**y > 0.0)).count()
}

/// Diverging colour map for `t` in [−1, 1] (clamped), in 8-bit sRGB
/// values: white at 0, towards pure blue (0, 0, 255) at −1 and pure red
/// (255, 0, 0) at +1, linear in the encoded values.
pub fn diverging(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 1.0) };
    let fade = ((1.0 - t.abs()) * 255.0).round() as u8;
    if t < 0.0 {
        [fade, fade, 255]
    } else {
        [255, fade, fade]
    }
}

/// The difference picture: per pixel, `d = (L_a − L_b) / mean_reference_luminance`
/// shown with [`diverging`] at `t = d / tau_max` (saturating at ±τ_max;
/// blue where A is darker than B, red where brighter); pixels the
/// reference does not cover are [`UNCOVERED_GREY`]. With a zero mean
/// reference luminance any non-zero difference saturates.
pub fn difference_picture(a: &HdrImage, b: &HdrImage, mean_reference_luminance: f64, tau_max: f64) -> Vec<[u8; 3]> {
    let scale = mean_reference_luminance * tau_max;
    (0..b.rgb.len())
        .map(|i| {
            if b.coverage[i] <= 0.0 {
                return UNCOVERED_GREY;
            }
            let difference = luminance(a.rgb[i].map(f64::from)) - luminance(b.rgb[i].map(f64::from));
            let t = if scale > 0.0 {
                difference / scale
            } else {
                difference.signum() * f64::from(u8::from(difference != 0.0))
            };
            diverging(t)
        })
        .collect()
}

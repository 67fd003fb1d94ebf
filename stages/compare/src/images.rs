//! Image comparison: which pixels are compared (the visible surfaces,
//! less emitters and edges where asked), and the difference picture.

use crate::metrics::{luminance, Sample};
use crate::{CompareError, Which};
use schemas::image::{HdrImage, PixelSurfaces, EMITTER, NO_SURFACE, SINGLE_SURFACE};

/// Grey of pixels the reference does not see, in the difference picture.
pub const UNCOVERED_GREY: [u8; 3] = [128, 128, 128];
/// Grey of pixels left out by `exclude_emitters` / `exclude_edges`.
pub const EXCLUDED_GREY: [u8; 3] = [64, 64, 64];

/// Checks that the image holds `width · height` finite values in every
/// channel; the first bad pixel, row-major, is the error.
fn check(image: &HdrImage, which: Which) -> Result<(), CompareError> {
    let expected = image.width * image.height;
    let malformed = |what: String| CompareError::Malformed { which, what };
    if image.rgb.len() != expected || image.coverage.len() != expected {
        return Err(malformed(format!(
            "size calls for {expected} pixels, found {} RGB and {} coverage values",
            image.rgb.len(),
            image.coverage.len()
        )));
    }
    if let Some(s) = &image.surfaces {
        if [s.object.len(), s.material.len(), s.flags.len()].iter().any(|&n| n != expected) {
            return Err(malformed(format!("surface layer does not hold {expected} pixels")));
        }
    }
    for (i, (rgb, &a)) in image.rgb.iter().zip(&image.coverage).enumerate() {
        let values = [("R", rgb[0]), ("G", rgb[1]), ("B", rgb[2]), ("A", a)];
        if let Some((channel, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            return Err(malformed(format!(
                "non-finite value {value} in channel {channel} at pixel (x {}, y {})",
                i % image.width,
                i / image.width
            )));
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

/// Which pixels to leave out besides those nobody sees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Exclusions {
    /// Leave out the pixels whose surface emits.
    pub emitters: bool,
    /// Leave out the pixels within this many pixels (Chebyshev distance:
    /// the `(2n+1)²` square around) of a pixel not covered by one surface
    /// alone (a silhouette, a crease between objects or materials, the
    /// scene's outline), and, with `emitters`, of an emitter pixel.
    /// `Some(0)` leaves out the mixed pixels themselves.
    pub edges: Option<u32>,
}

impl Exclusions {
    /// Whether any exclusion is asked for.
    pub fn any(&self) -> bool {
        self.emitters || self.edges.is_some()
    }
}

/// The surface layer the comparison uses: the reference's, else A's (a
/// foreign reference has none), with which input it came from.
pub fn surfaces<'a>(a: &'a HdrImage, b: &'a HdrImage) -> Option<(&'a PixelSurfaces, Which)> {
    b.surfaces.as_ref().map(|s| (s, Which::B)).or(a.surfaces.as_ref().map(|s| (s, Which::A)))
}

/// Per pixel, whether it is compared: the reference covers it, a surface
/// layer (if any) says some sample hit a front face there, and
/// `exclusions` do not remove it. Exclusions without a surface layer in
/// either input are an error.
pub fn compared_pixels(a: &HdrImage, b: &HdrImage, exclusions: Exclusions) -> Result<Vec<bool>, CompareError> {
    let (w, h) = (b.width, b.height);
    let mut keep: Vec<bool> = b.coverage.iter().map(|&c| c > 0.0).collect();
    let Some((s, _)) = surfaces(a, b) else {
        if exclusions.any() {
            return Err(CompareError::Malformed {
                which: Which::B,
                what: "excluding emitters or edges needs a surface layer (object, material, flags), and neither image has one; render A with grid-gather".into(),
            });
        }
        return Ok(keep);
    };
    let emitter: Vec<bool> = s.flags.iter().map(|f| f & EMITTER != 0).collect();
    for (k, &object) in keep.iter_mut().zip(&s.object) {
        *k &= object != NO_SURFACE;
    }
    if exclusions.emitters {
        keep.iter_mut().zip(&emitter).for_each(|(k, e)| *k &= !e);
    }
    if let Some(n) = exclusions.edges {
        let edge: Vec<bool> =
            s.flags.iter().zip(&emitter).map(|(f, &e)| f & SINGLE_SURFACE == 0 || (exclusions.emitters && e)).collect();
        let near = dilate(&edge, w, h, n as usize);
        keep.iter_mut().zip(near).for_each(|(k, n)| *k &= !n);
    }
    Ok(keep)
}

/// `mask` grown by `n` pixels in the Chebyshev metric: a pixel is set when
/// some set pixel lies within `n` rows and `n` columns of it (a row pass,
/// then a column pass, each with a running count over the window).
pub fn dilate(mask: &[bool], w: usize, h: usize, n: usize) -> Vec<bool> {
    let pass = |input: &[bool], len: usize, lines: usize, at: &dyn Fn(usize, usize) -> usize| {
        let mut out = vec![false; input.len()];
        for line in 0..lines {
            let mut count = 0usize;
            // Window [i - n, i + n]: add i + n, drop i - n - 1.
            for i in 0..n.min(len) {
                count += usize::from(input[at(line, i)]);
            }
            for i in 0..len {
                if i + n < len {
                    count += usize::from(input[at(line, i + n)]);
                }
                if i > n {
                    count -= usize::from(input[at(line, i - n - 1)]);
                }
                out[at(line, i)] = count > 0;
            }
        }
        out
    };
    let rows = pass(mask, w, h, &|y, x| y * w + x);
    pass(&rows, h, w, &|x, y| y * w + x)
}

/// The compared samples, weight 1 each, with their pixel index. Both
/// images must have passed [`check_pair`].
pub fn samples(a: &HdrImage, b: &HdrImage, keep: &[bool]) -> Vec<(usize, Sample)> {
    (0..b.rgb.len())
        .filter(|&i| keep[i])
        .map(|i| (i, Sample { a: a.rgb[i].map(f64::from), b: b.rgb[i].map(f64::from), weight: 1.0 }))
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

/// The difference picture's pixels: per compared pixel the relative
/// difference `d = (L_a − L_b) / L_b` (the quantity paper 002's τ measure
/// thresholds) shown with [`diverging`] at `t = d / τ_max`, saturating at
/// ±τ_max (blue where A is darker than B, red where brighter; a black
/// reference saturates by the sign of the difference); [`UNCOVERED_GREY`]
/// where the reference sees nothing, [`EXCLUDED_GREY`] where an exclusion
/// removed the pixel.
pub fn difference_picture(a: &HdrImage, b: &HdrImage, keep: &[bool], tau_max: f64) -> Vec<[u8; 3]> {
    (0..b.rgb.len())
        .map(|i| {
            if b.coverage[i] <= 0.0 {
                return UNCOVERED_GREY;
            }
            if !keep[i] {
                return EXCLUDED_GREY;
            }
            let lb = luminance(b.rgb[i].map(f64::from));
            let difference = luminance(a.rgb[i].map(f64::from)) - lb;
            let t = if lb > 0.0 { difference / (lb * tau_max) } else { difference.signum() * f64::from(u8::from(difference != 0.0)) };
            diverging(t)
        })
        .collect()
}

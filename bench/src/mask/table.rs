//! The table of `make bench-mask` (paper 000 Table 1 in shape): per
//! full-gather run (without and with the mask) its visibility rays, form
//! factors and time from its report ([`GatherRun`]), and its error against
//! the brute-force reference per pixel on Rec. 709 luminance `Y`:
//!
//! ```text
//! relative RMSE over pixels P = sqrt(mean_P (Y - Y_ref)^2) / mean_P Y_ref
//! over the mask              = share of P with |Y - Y_ref| > c_thr Y_ref
//! ```
//!
//! with `P` every pixel the reference covers (`Y_ref > 0`), or only those
//! wholly on the floor (the reference's per-pixel surface is the floor
//! material, single surface), and `c_thr` the mask's per-pixel threshold
//! contrast (threshold.exr's `contrast`): the errors paper 000 claims a
//! viewer cannot see stay under it.

use crate::gather::GatherRun;
use schemas::image::{HdrImage, SINGLE_SURFACE};
use std::fmt::Write as _;

/// Rec. 709 luminance of an image's linear RGB pixel.
fn luminance(rgb: [f32; 3]) -> f64 {
    radiometry::color::luminance(rgb.map(f64::from))
}

/// One run's error against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaskError {
    /// Relative RMSE over every covered pixel.
    pub image: f64,
    /// Relative RMSE over the floor's pixels.
    pub floor: f64,
    /// Share (0..1) of covered pixels whose error exceeds the mask's threshold.
    pub over_mask: f64,
}

/// Which pixels of `reference` lie wholly on material `floor`; an image
/// without per-pixel surfaces has none.
pub fn floor_pixels(reference: &HdrImage, floor: u32) -> Vec<bool> {
    match &reference.surfaces {
        Some(s) => s.material.iter().zip(&s.flags).map(|(&m, &f)| m == floor && f & SINGLE_SURFACE != 0).collect(),
        None => vec![false; reference.rgb.len()],
    }
}

/// The relative RMSE of `image` against `reference` over the covered
/// pixels `keep` selects; 0 where it selects none.
fn relative_rmse(image: &HdrImage, reference: &HdrImage, keep: impl Fn(usize) -> bool) -> f64 {
    let (mut squares, mut sum, mut n) = (0.0, 0.0, 0usize);
    for (k, (&a, &r)) in image.rgb.iter().zip(&reference.rgb).enumerate() {
        let y = luminance(r);
        if y > 0.0 && keep(k) {
            squares += (luminance(a) - y).powi(2);
            sum += y;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (squares / n as f64).sqrt() / (sum / n as f64)
    }
}

/// The error of `image` against `reference`: over the image, over the
/// `floor` pixels, and the share of covered pixels over the threshold
/// contrasts `contrast` (one per pixel). The caller checks the sizes.
pub fn errors(image: &HdrImage, reference: &HdrImage, floor: &[bool], contrast: &[f32]) -> MaskError {
    let covered = reference.rgb.iter().filter(|&&r| luminance(r) > 0.0).count();
    let over = image
        .rgb
        .iter()
        .zip(&reference.rgb)
        .zip(contrast)
        .filter(|((&a, &r), &c)| {
            let y = luminance(r);
            y > 0.0 && (luminance(a) - y).abs() > f64::from(c) * y
        })
        .count();
    MaskError {
        image: relative_rmse(image, reference, |_| true),
        floor: relative_rmse(image, reference, |k| floor[k]),
        over_mask: if covered == 0 { 0.0 } else { over as f64 / covered as f64 },
    }
}

/// The mean of `values` over the pixels `keep` selects; 0 where none.
pub fn mean_over(values: &[f32], keep: &[bool]) -> f64 {
    let (sum, n) = values.iter().zip(keep).filter(|(_, &k)| k).fold((0.0, 0usize), |(s, n), (&v, _)| (s + f64::from(v), n + 1));
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// The table: a heading, per run its rays, form factors, time and errors,
/// and, for two or more runs, the last run's rays and time over the
/// first's (the masked run over the unmasked one, as `make bench-mask`
/// orders them).
pub fn summary(runs: &[(GatherRun, MaskError)]) -> String {
    let mut out = format!("{:<17} {:>12} {:>12} {:>12} {:>8} {:>10} {:>10} {:>10}\n", "run", "vis_rays", "class_rays", "ff_evals", "time_s", "rel_rmse", "floor_rmse", "over_mask");
    for (r, e) in runs {
        let _ = writeln!(
            out,
            "{:<17} {:>12} {:>12} {:>12} {:>8.2} {:>10.3e} {:>10.3e} {:>9.2}%",
            r.name, r.visibility_rays as i64, r.classification_rays as i64, r.form_factors as i64, r.time_s, e.image, e.floor, 100.0 * e.over_mask
        );
    }
    if let [(first, _), .., (last, _)] = runs {
        let rays = |r: &GatherRun| r.visibility_rays + r.classification_rays;
        let _ = writeln!(out, "{} / {}: visibility rays {:.3}, time {:.3}", last.name, first.name, rays(last) / rays(first), last.time_s / first.time_s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::Provenance;
    use schemas::header::Schema;
    use schemas::image::PixelSurfaces;
    use schemas::report::Report;

    fn grey(values: [f32; 4]) -> HdrImage {
        HdrImage { header: HdrImage::header(Provenance::in_memory("test")), width: 2, height: 2, rgb: values.map(|v| [v; 3]).to_vec(), coverage: vec![1.0; 4], surfaces: None }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs()
    }

    #[test]
    fn errors_are_per_pixel_over_covered_pixels_the_floor_and_the_mask() {
        let mut reference = grey([1.0, 2.0, 0.0, 4.0]);
        // Pixel 1 is floor material but straddles an edge; pixel 2 is not covered.
        reference.surfaces = Some(PixelSurfaces { object: vec![0; 4], material: vec![7, 7, 3, 7], flags: vec![SINGLE_SURFACE, 0, SINGLE_SURFACE, SINGLE_SURFACE] });
        let floor = floor_pixels(&reference, 7);
        assert_eq!(floor, [true, false, false, true]);
        let image = grey([1.25, 2.0, 5.0, 3.0]);
        let e = errors(&image, &reference, &floor, &[0.2, 0.5, 0.0, 0.3]);
        // Covered: pixels 0, 1, 3 with differences 0.25, 0, -1 and mean reference 7/3.
        assert!(close(e.image, ((0.0625 + 1.0) / 3.0f64).sqrt() / (7.0 / 3.0)), "{e:?}");
        assert!(close(e.floor, ((0.0625 + 1.0) / 2.0f64).sqrt() / 2.5), "{e:?}");
        // Over the threshold: pixel 0 (0.25 > 0.2), pixel 3 (1 > 1.2: no); pixel 2 is not covered.
        assert!(close(e.over_mask, 1.0 / 3.0), "{e:?}");
        assert_eq!(floor_pixels(&grey([1.0; 4]), 7), [false; 4], "no surfaces, no floor");
        assert_eq!((mean_over(&[1.0, 5.0, 7.0, 2.0], &floor), mean_over(&[1.0; 4], &[false; 4])), (1.5, 0.0));
    }

    #[test]
    fn the_table_ends_with_the_masked_runs_share_of_rays_and_time() {
        let counters = [("visibility_rays".to_string(), 800.0), ("classification_visibility_rays".to_string(), 200.0)].into();
        let report = Report { header: Report::header(Provenance::in_memory("test")), wall_time_s: 4.0, counters, skipped: vec![], notes: vec![] };
        let unmasked = GatherRun::of("unmasked", &report, 0.0);
        let masked = GatherRun { name: "masked".into(), visibility_rays: 100.0, classification_rays: 150.0, time_s: 1.0, ..unmasked.clone() };
        let e = MaskError { image: 1e-3, floor: 2e-3, over_mask: 0.125 };
        let table = summary(&[(unmasked, e), (masked, e)]);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines[1], "unmasked                   800          200            0     4.00   1.000e-3   2.000e-3     12.50%");
        assert_eq!(lines[3], "masked / unmasked: visibility rays 0.250, time 0.250");
    }
}

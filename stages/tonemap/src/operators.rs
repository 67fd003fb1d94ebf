//! The scalar curves of tone reproduction: luminance, log-average, the
//! automatic key, the two operators and the sRGB transfer function. All in
//! `f64`; every function here is pure and total on finite input.

/// Offset δ inside the logarithms, so that black pixels do not send the
/// log-average to zero (Reinhard et al. 2002, Eq. 1: δ is "a small value").
pub const DELTA: f64 = 1e-6;

/// The key (middle grey) used when the automatic estimate has no range to
/// work from, and Reinhard et al. 2002's default for "normal-key" scenes.
pub const DEFAULT_KEY: f64 = 0.18;

/// Bounds of the automatic key, two zones either side of middle grey
/// (0.18 / 4 and 0.18 · 4), as in Reinhard 2002, "Parameter estimation for
/// photographic tone reproduction", JGT 7(1).
pub const KEY_RANGE: (f64, f64) = (0.045, 0.72);

/// Percentiles of luminance taken as the robust minimum and maximum for the
/// automatic key (1st and 99th: a few outlier pixels, such as a light
/// source seen directly, do not decide the key).
pub const ROBUST_PERCENTILES: (f64, f64) = (0.01, 0.99);

pub use radiometry::color::luminance;

/// Log-average luminance (Reinhard et al. 2002, "Photographic tone
/// reproduction for digital images", SIGGRAPH, Eq. 1):
/// `L_avg = exp( (1/N) Σ ln(δ + L_w(x, y)) )` over the `N` given
/// luminances, δ = [`DELTA`]. Returns 0 for an empty slice.
pub fn log_average_luminance(luminances: &[f64]) -> f64 {
    if luminances.is_empty() {
        return 0.0;
    }
    let sum: f64 = luminances.iter().map(|&l| (DELTA + l).ln()).sum();
    (sum / luminances.len() as f64).exp()
}

/// The `p`-quantile (`p` in [0, 1]) of ascending `sorted` values, linearly
/// interpolated between the two closest ranks: position `p (n - 1)`
/// (Hyndman and Fan's definition 7, the default of R and NumPy).
/// Returns 0 for an empty slice.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let position = p.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(sorted.len() - 1);
    let t = position - below as f64;
    sorted[below] + t * (sorted[above] - sorted[below])
}

/// Automatic key `a` (Reinhard 2002, "Parameter estimation for
/// photographic tone reproduction", JGT 7(1), the key estimate):
///
/// `a = 0.18 · 4^f`, `f = (2 log2 L_avg − log2 L_min − log2 L_max) / (log2 L_max − log2 L_min)`,
///
/// clamped to [`KEY_RANGE`]. `f` measures where the log-average sits in
/// the scene's dynamic range: an image darker than the middle of its range
/// (low key) gets a smaller `a`. All three luminances must be positive
/// (callers add [`DELTA`]); when `L_max <= L_min` the range is empty and the
/// key is [`DEFAULT_KEY`].
pub fn auto_key(l_avg: f64, l_min: f64, l_max: f64) -> f64 {
    if l_max <= l_min {
        return DEFAULT_KEY;
    }
    let (log_avg, log_min, log_max) = (l_avg.log2(), l_min.log2(), l_max.log2());
    let f = (2.0 * log_avg - log_min - log_max) / (log_max - log_min);
    (DEFAULT_KEY * 4f64.powf(f)).clamp(KEY_RANGE.0, KEY_RANGE.1)
}

/// Reinhard et al. 2002 global operator, display luminance (Eq. 4):
/// `L_d = L (1 + L / L_white²) / (1 + L)` for scaled luminance
/// `L = (a / L_avg) L_w` (Eq. 2). `L_white` is the smallest scaled
/// luminance mapped to 1 (here the largest in the image, so nothing burns
/// out); `L_d` is monotone increasing in `L` for `L <= L_white`. Returns 0
/// when `L_white <= 0` (an all-black image).
pub fn reinhard_display(scaled: f64, white: f64) -> f64 {
    if white <= 0.0 {
        return 0.0;
    }
    scaled * (1.0 + scaled / (white * white)) / (1.0 + scaled)
}

/// Exposure operator, per channel: `y = 1 − exp(−k x)`, computed as
/// `−expm1(−k x)` for accuracy at small `k x`. Monotone increasing in `x`
/// for `k > 0`, 0 at 0, and approaching 1 (film-like saturation).
pub fn exposure(x: f64, k: f64) -> f64 {
    -(-k * x).exp_m1()
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1:1999,
/// linear to non-linear R'G'B'): `V = 12.92 x` for `x <= 0.0031308`, else
/// `V = 1.055 x^(1/2.4) − 0.055`. Input clamped to [0, 1] first.
pub fn srgb_oetf(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Quantises an encoded value in [0, 1] to 8 bits: `round(255 v)`, after
/// clamping (NaN maps to 0).
pub fn to_8bit(v: f64) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    (v * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_oetf_matches_the_standard() {
        assert_eq!(srgb_oetf(0.0), 0.0);
        // Linear segment at the breakpoint: 12.92 * 0.0031308.
        assert!((srgb_oetf(0.0031308) - 0.040449936).abs() < 1e-12);
        // Both segments meet at the breakpoint to within 3e-8.
        assert!((1.055 * 0.0031308f64.powf(1.0 / 2.4) - 0.055 - srgb_oetf(0.0031308)).abs() < 3e-8);
        assert!((srgb_oetf(0.5) - 0.735356983052449).abs() < 1e-12);
        assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-12);
        assert_eq!(to_8bit(srgb_oetf(0.5)), 188);
        assert_eq!(to_8bit(srgb_oetf(1.0)), 255);
        assert_eq!(to_8bit(srgb_oetf(2.0)), 255);
        assert_eq!(to_8bit(f64::NAN), 0);
    }

    #[test]
    fn exposure_has_the_exact_value() {
        // 1 - exp(-ln 2 * 1) = 1/2; 1 - exp(-2 * 0.5) = 1 - 1/e.
        assert!((exposure(1.0, std::f64::consts::LN_2) - 0.5).abs() < 1e-15);
        assert!((exposure(0.5, 2.0) - (1.0 - (-1.0f64).exp())).abs() < 1e-15);
        assert_eq!(exposure(0.0, 3.0), 0.0);
    }

    #[test]
    fn curves_are_monotone() {
        let white = 5.0;
        let xs: Vec<f64> = (0..=500).map(|i| i as f64 * 0.01).collect();
        for pair in xs.windows(2) {
            assert!(exposure(pair[1], 0.7) > exposure(pair[0], 0.7));
            assert!(reinhard_display(pair[1], white) > reinhard_display(pair[0], white));
            assert!(srgb_oetf(pair[1].min(1.0)) >= srgb_oetf(pair[0].min(1.0)));
        }
        assert!((reinhard_display(white, white) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn uniform_grey_maps_to_white_with_the_key_guard() {
        // Key guard: L_min == L_max gives a = 0.18; L = 0.18 = L_white, so
        // L_d = 0.18 (1 + 0.18 / 0.0324) / 1.18 = 1.
        assert_eq!(auto_key(0.3, 0.3, 0.3), 0.18);
        let scaled = 0.18;
        let expected = 0.18 * (1.0 + 0.18 / 0.0324) / 1.18;
        assert!((reinhard_display(scaled, scaled) - expected).abs() < 1e-15);
        assert!((expected - 1.0).abs() < 1e-15);
    }

    #[test]
    fn auto_key_by_hand() {
        // L_min = 2^-4, L_max = 2^2, L_avg = 2^0.5:
        // f = (1 + 4 - 2) / 6 = 0.5, a = 0.18 * 4^0.5 = 0.36.
        assert!((auto_key(2f64.sqrt(), 1.0 / 16.0, 4.0) - 0.36).abs() < 1e-12);
        // L_avg at the geometric middle of the range: f = 0, a = 0.18.
        assert!((auto_key(0.5, 1.0 / 16.0, 4.0) - 0.18).abs() < 1e-12);
        // L_avg = L_max: f = 1, a = 0.72 (upper bound, reached exactly).
        assert!((auto_key(4.0, 1.0 / 16.0, 4.0) - 0.72).abs() < 1e-12);
        // Outside the range: clamped.
        assert_eq!(auto_key(16.0, 1.0 / 16.0, 4.0), 0.72);
        assert_eq!(auto_key(1.0 / 256.0, 1.0 / 16.0, 4.0), 0.045);
    }

    #[test]
    fn log_average_and_percentile_by_hand() {
        // exp(mean(ln 1, ln 4)) = 2 (δ moves it by ~1e-6).
        assert!((log_average_luminance(&[1.0, 4.0]) - 2.0).abs() < 3e-6);
        let sorted = [0.0, 10.0, 20.0, 30.0, 40.0];
        assert_eq!(percentile(&sorted, 0.0), 0.0);
        assert_eq!(percentile(&sorted, 1.0), 40.0);
        // Position 0.01 * 4 = 0.04 -> 0.4; 0.99 * 4 = 3.96 -> 39.6.
        assert!((percentile(&sorted, 0.01) - 0.4).abs() < 1e-12);
        assert!((percentile(&sorted, 0.99) - 39.6).abs() < 1e-12);
        assert!((luminance([1.0, 1.0, 1.0]) - 1.0).abs() < 1e-15);
    }
}

//! Error metrics between an approximation A and a reference B, over
//! weighted samples (pixels with weight 1, or elements weighted by area).

use std::collections::BTreeMap;

/// Relative floor of the relative error's denominator, as a fraction of the
/// reference's mean luminance: `floor = 1e-3 · mean(L_b)`, so that black
/// reference samples do not make the relative error infinite.
pub const RELATIVE_FLOOR: f64 = 1e-3;

/// One compared sample: A's and B's linear RGB (radiance or radiosity) and
/// its weight (1 for a pixel, the area in m² for an element).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Approximation, linear RGB.
    pub a: [f64; 3],
    /// Reference, linear RGB.
    pub b: [f64; 3],
    /// Weight: 1 per pixel, area per element.
    pub weight: f64,
}

pub use radiometry::color::luminance;

/// The error of A against reference B. With weights `w` (all 1 for
/// images), sums over the samples `s` and channels `c`:
///
/// - `rmse = sqrt( Σ_s w_s Σ_c (a − b)² / (3 Σ_s w_s) )`, in the data's unit;
/// - `relative_rmse = sqrt( Σ w (a − b)² / Σ w b² )`, dimensionless;
/// - per sample, on luminance, `e_s = |L_a − L_b| / max(L_b, floor)` with
///   `floor = 1e-3 · mean_reference_luminance` ([`RELATIVE_FLOOR`]):
///   `mean_relative_error = Σ w e / Σ w`, `max_relative_error = max e`;
/// - `mean_signed_error = Σ w (L_a − L_b) / Σ w L_b`: the bias of the mean
///   luminance, relative (−0.1: A is 10% too dark on average; 0 when the
///   reference is black and A equals it);
/// - for each τ, the percentage (of samples, weighted) with
///   `|L_a − L_b| > τ · L_b`, τ relative to *that sample's* reference
///   luminance: the measure of paper 002 (structured sampling, Section 4.1
///   and Table 3, "Error (>15%)": the percentage of visible pixels whose
///   difference from the exact image exceeds a tolerance τ). Relative per
///   pixel, so a dim wall counts as much as a bright one; a black
///   reference sample is over every τ unless A is black there too.
///
/// `mean_reference_luminance = Σ w L_b / Σ w`.
#[derive(Clone, Debug, PartialEq)]
pub struct Metrics {
    /// Number of samples compared.
    pub samples: usize,
    /// Σ w: the sample count for images, the area (m²) for solutions.
    pub total_weight: f64,
    /// Root-mean-square difference over samples and channels.
    pub rmse: f64,
    /// RMS difference relative to the reference's RMS.
    pub relative_rmse: f64,
    /// Relative bias of the mean luminance, signed.
    pub mean_signed_error: f64,
    /// Weighted mean of the per-sample relative luminance error.
    pub mean_relative_error: f64,
    /// Largest per-sample relative luminance error.
    pub max_relative_error: f64,
    /// Weighted mean luminance of the reference.
    pub mean_reference_luminance: f64,
    /// `(τ, percentage of samples over τ)`, in the order τ was given.
    pub percent_over_tau: Vec<(f64, f64)>,
}

/// `x / y`, taking 0/0 as 0 and x/0 as +∞ (a difference against a zero
/// reference is infinitely large relatively).
fn ratio(x: f64, y: f64) -> f64 {
    if y > 0.0 {
        x / y
    } else if x > 0.0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// `x / y` for a signed `x`: 0/0 is 0, x/0 is ±∞.
fn signed_ratio(x: f64, y: f64) -> f64 {
    ratio(x.abs(), y).copysign(x)
}

/// Computes [`Metrics`] over `samples` for each τ in `taus`. With no
/// samples (or zero total weight) every metric is 0.
pub fn metrics(samples: &[Sample], taus: &[f64]) -> Metrics {
    let total_weight: f64 = samples.iter().map(|s| s.weight).sum();
    let mean = |f: &dyn Fn(&Sample) -> f64| ratio(samples.iter().map(|s| s.weight * f(s)).sum(), total_weight);
    let mean_reference_luminance = mean(&|s| luminance(s.b));
    let squared_difference = |s: &Sample| (0..3).map(|c| (s.a[c] - s.b[c]).powi(2)).sum::<f64>();
    let sum_squared_difference: f64 = samples.iter().map(|s| s.weight * squared_difference(s)).sum();
    let sum_squared_reference: f64 = samples.iter().map(|s| s.weight * s.b.iter().map(|v| v * v).sum::<f64>()).sum();
    let floor = RELATIVE_FLOOR * mean_reference_luminance;
    let relative_error = |s: &Sample| {
        let lb = luminance(s.b);
        ratio((luminance(s.a) - lb).abs(), lb.max(floor))
    };
    let percent_over_tau = taus
        .iter()
        .map(|&tau| {
            let over = |s: &Sample| {
                let lb = luminance(s.b);
                f64::from(u8::from((luminance(s.a) - lb).abs() > tau * lb))
            };
            (tau, 100.0 * mean(&over))
        })
        .collect();
    Metrics {
        samples: samples.len(),
        total_weight,
        rmse: ratio(sum_squared_difference, 3.0 * total_weight).sqrt(),
        relative_rmse: ratio(sum_squared_difference, sum_squared_reference).sqrt(),
        mean_signed_error: signed_ratio(
            samples.iter().map(|s| s.weight * (luminance(s.a) - luminance(s.b))).sum(),
            samples.iter().map(|s| s.weight * luminance(s.b)).sum(),
        ),
        mean_relative_error: mean(&relative_error),
        max_relative_error: samples.iter().map(relative_error).fold(0.0, f64::max),
        mean_reference_luminance,
        percent_over_tau,
    }
}

/// The name of the counter holding the percentage over `tau`:
/// `percent_over_tau_0.05`.
pub fn tau_counter(tau: f64) -> String {
    format!("percent_over_tau_{tau}")
}

impl Metrics {
    /// The percentage of samples over `tau`, 0 when `tau` was not measured.
    pub fn percent_over(&self, tau: f64) -> f64 {
        self.percent_over_tau.iter().find(|(t, _)| *t == tau).map_or(0.0, |(_, p)| *p)
    }

    /// The report counters: `samples`, `total_weight`, `rmse`,
    /// `relative_rmse`, `mean_signed_error`, `mean_relative_error`, `max_relative_error`,
    /// `mean_reference_luminance` and one `percent_over_tau_<τ>` per τ.
    pub fn counters(&self) -> BTreeMap<String, f64> {
        let mut c = BTreeMap::new();
        c.insert("samples".to_string(), self.samples as f64);
        c.insert("total_weight".to_string(), self.total_weight);
        c.insert("rmse".to_string(), self.rmse);
        c.insert("relative_rmse".to_string(), self.relative_rmse);
        c.insert("mean_signed_error".to_string(), self.mean_signed_error);
        c.insert("mean_relative_error".to_string(), self.mean_relative_error);
        c.insert("max_relative_error".to_string(), self.max_relative_error);
        c.insert("mean_reference_luminance".to_string(), self.mean_reference_luminance);
        for &(tau, percent) in &self.percent_over_tau {
            c.insert(tau_counter(tau), percent);
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn weights_act_as_repetition() {
        // One sample of weight 3 equals three copies of weight 1.
        let s = |a: f64, w| Sample { a: [a, 0.5 * a, 0.0], b: [1.0, 1.0, 1.0], weight: w };
        let weighted = metrics(&[s(2.0, 3.0), s(1.0, 1.0)], &[0.3]);
        let repeated = metrics(&[s(2.0, 1.0), s(2.0, 1.0), s(2.0, 1.0), s(1.0, 1.0)], &[0.3]);
        assert!(close(weighted.rmse, repeated.rmse));
        assert!(close(weighted.relative_rmse, repeated.relative_rmse));
        assert!(close(weighted.mean_relative_error, repeated.mean_relative_error));
        assert_eq!(weighted.percent_over_tau, repeated.percent_over_tau);
        // By hand: sample 1 differs by (1, 0, -1): Σ w d² = 3 * 2 + (0 + 0.25 + 1) = 7.25
        // over 3 * 4 channel samples; reference Σ w b² = 4 * 3 = 12.
        assert!(close(weighted.rmse, (7.25f64 / 12.0).sqrt()));
        assert!(close(weighted.relative_rmse, (7.25f64 / 12.0).sqrt()));
    }

    #[test]
    fn relative_error_has_a_floor_and_zero_reference_is_handled() {
        // Reference luminances 0 and 2: mean 1, floor 1e-3.
        let samples =
            [Sample { a: [0.01; 3], b: [0.0; 3], weight: 1.0 }, Sample { a: [2.0; 3], b: [2.0; 3], weight: 1.0 }];
        let m = metrics(&samples, &[]);
        assert!(close(m.max_relative_error, 0.01 / 1e-3));
        assert!(close(m.mean_relative_error, 5.0));
        let black = [Sample { a: [0.0; 3], b: [0.0; 3], weight: 1.0 }];
        let m = metrics(&black, &[0.1]);
        assert_eq!((m.rmse, m.relative_rmse, m.max_relative_error), (0.0, 0.0, 0.0));
        assert_eq!(m.percent_over_tau, vec![(0.1, 0.0)]);
        let m = metrics(&[], &[0.1]);
        assert_eq!((m.samples, m.rmse, m.relative_rmse), (0, 0.0, 0.0));
        assert_eq!(tau_counter(0.05), "percent_over_tau_0.05");
    }
}

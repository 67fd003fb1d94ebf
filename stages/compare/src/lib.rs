//! # compare: error of an image or a solution against a reference
//!
//! Modelled on Radiance's `radcompare`: explicit tolerances, exit 0 when the
//! data match within them, 1 when a given tolerance is exceeded, 2 on error;
//! only pixel and element data are compared, never headers (provenance,
//! command lines and timings differ between runs that agree).
//!
//! Two kinds of input, both EXR artifacts of this pipeline:
//! - two [`HdrImage`]s of the same size: the samples are the pixels the
//!   reference (B) covers, coverage > 0 ([`images`]);
//! - two [`Solution`]s on the same mesh: per leaf element when both
//!   hierarchies are identical, else per input triangle, weighted by area
//!   ([`solutions`]).
//!
//! The metrics (RMSE, relative RMSE, relative luminance error, and paper
//! 002's percentage of samples over τ) are defined in [`metrics::Metrics`].
//!
//! | parameter | type | meaning | default |
//! |---|---|---|---|
//! | `tau` | list of f64 | thresholds τ, fractions of the reference's mean luminance | `[0.01, 0.05, 0.1]` |
//! | `max_rel_rmse` | optional f64 | tolerance on `relative_rmse` | none |
//! | `max_rmse` | optional f64 | tolerance on `rmse`, in the data's unit | none |
//! | `max_pixels_over_tau` | optional f64 | tolerance, in percent, on the share of samples over the largest τ | none |
//!
//! ```
//! use compare::metrics::{metrics, Sample};
//! let same = [Sample { a: [1.0; 3], b: [1.0; 3], weight: 1.0 }];
//! let m = metrics(&same, &[0.05]);
//! assert_eq!((m.rmse, m.relative_rmse), (0.0, 0.0));
//! assert!(compare::Params::default().exceeded(&m).is_empty());
//! ```

#![deny(missing_docs)]

pub mod images;
pub mod metrics;
pub mod solutions;

use metrics::Metrics;
use schemas::image::HdrImage;
use schemas::solution::Solution;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// Which of the two inputs an error concerns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Which {
    /// The approximation, first argument.
    A,
    /// The reference, second argument.
    B,
}

/// Why two inputs cannot be compared; the caller names the file
/// ([`CompareError::which`]).
#[derive(Clone, Debug, PartialEq)]
pub enum CompareError {
    /// The input is unusable or does not match the other one.
    Malformed {
        /// The input concerned.
        which: Which,
        /// What is wrong, one line, without the file name.
        what: String,
    },
}

impl CompareError {
    /// The input the error concerns.
    pub fn which(&self) -> Which {
        match self {
            CompareError::Malformed { which, .. } => *which,
        }
    }
}

impl fmt::Display for CompareError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompareError::Malformed { what, .. } => f.write_str(what),
        }
    }
}

/// The stage's parameters (see the table in the crate documentation).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Thresholds τ for the percentage-over-τ metric, each a fraction of
    /// the reference's mean visible luminance.
    pub tau: Vec<f64>,
    /// Largest allowed `relative_rmse`.
    pub max_rel_rmse: Option<f64>,
    /// Largest allowed `rmse`, in the data's unit (W/(m² sr) for images,
    /// W/m² for solutions).
    pub max_rmse: Option<f64>,
    /// Largest allowed percentage (0-100) of samples whose luminance
    /// difference exceeds the largest τ.
    pub max_pixels_over_tau: Option<f64>,
}

impl Default for Params {
    fn default() -> Self {
        Params { tau: vec![0.01, 0.05, 0.1], max_rel_rmse: None, max_rmse: None, max_pixels_over_tau: None }
    }
}

impl Params {
    /// Refuses an empty τ list, a τ that is not positive and finite, and a
    /// tolerance that is negative or not finite.
    pub fn validate(&self) -> schemas::Result<()> {
        if self.tau.is_empty() {
            return Err(schemas::stage::bad_parameter("tau needs at least one value"));
        }
        if let Some(tau) = self.tau.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
            return Err(schemas::stage::bad_parameter(format!("tau must be positive, got {tau}")));
        }
        for (name, tolerance) in self.tolerances() {
            if let Some(t) = tolerance.filter(|t| !(t.is_finite() && *t >= 0.0)) {
                return Err(schemas::stage::bad_parameter(format!("{name} must be a non-negative number, got {t}")));
            }
        }
        Ok(())
    }

    /// The largest τ (0 for an empty list).
    pub fn tau_max(&self) -> f64 {
        self.tau.iter().copied().fold(0.0, f64::max)
    }

    fn tolerances(&self) -> [(&'static str, Option<f64>); 3] {
        [
            ("max_rel_rmse", self.max_rel_rmse),
            ("max_rmse", self.max_rmse),
            ("max_pixels_over_tau", self.max_pixels_over_tau),
        ]
    }

    /// Whether any tolerance is given.
    pub fn has_tolerance(&self) -> bool {
        self.tolerances().iter().any(|(_, t)| t.is_some())
    }

    /// Each given tolerance that `m` exceeds, as `metric value > tolerance`;
    /// empty when the inputs match. A metric equal to its tolerance passes.
    pub fn exceeded(&self, m: &Metrics) -> Vec<String> {
        let tau_max = self.tau_max();
        let over_tau_max =
            m.percent_over_tau.iter().filter(|(t, _)| *t == tau_max).map(|(_, p)| *p).next().unwrap_or(0.0);
        let checks = [
            ("relative_rmse".to_string(), m.relative_rmse, self.max_rel_rmse),
            ("rmse".to_string(), m.rmse, self.max_rmse),
            (metrics::tau_counter(tau_max), over_tau_max, self.max_pixels_over_tau),
        ];
        checks
            .into_iter()
            .filter_map(|(name, value, tolerance)| {
                let tolerance = tolerance?;
                (value > tolerance || value.is_nan()).then(|| format!("{name} {value:.6} > {tolerance}"))
            })
            .collect()
    }
}

/// The outcome of comparing two images.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageComparison {
    /// The metrics over the reference's covered pixels.
    pub metrics: Metrics,
    /// Pixels covered in exactly one of the two images.
    pub coverage_mismatches: usize,
    /// Pixels per image.
    pub pixels: usize,
}

impl ImageComparison {
    /// Report counters: the metrics' plus `pixels` and
    /// `coverage_mismatch_pixels`.
    pub fn counters(&self) -> BTreeMap<String, f64> {
        let mut c = self.metrics.counters();
        c.insert("pixels".to_string(), self.pixels as f64);
        c.insert("coverage_mismatch_pixels".to_string(), self.coverage_mismatches as f64);
        c
    }
}

/// Compares image `a` with reference `b` (same size, finite values).
pub fn compare_images(a: &HdrImage, b: &HdrImage, params: &Params) -> Result<ImageComparison, CompareError> {
    images::check_pair(a, b)?;
    let samples = images::samples(a, b);
    Ok(ImageComparison {
        metrics: metrics::metrics(&samples, &params.tau),
        coverage_mismatches: images::coverage_mismatches(a, b),
        pixels: b.rgb.len(),
    })
}

/// The outcome of comparing two solutions.
#[derive(Clone, Debug, PartialEq)]
pub struct SolutionComparison {
    /// The metrics over leaves or triangles, area-weighted.
    pub metrics: Metrics,
    /// Leaves or triangles.
    pub mode: solutions::Mode,
    /// Elements in A and in B.
    pub elements: (usize, usize),
}

impl SolutionComparison {
    /// Report counters: the metrics' plus `elements_a` and `elements_b`
    /// (`total_weight` is the compared area, m²).
    pub fn counters(&self) -> BTreeMap<String, f64> {
        let mut c = self.metrics.counters();
        c.insert("elements_a".to_string(), self.elements.0 as f64);
        c.insert("elements_b".to_string(), self.elements.1 as f64);
        c
    }
}

/// Compares solution `a` with reference `b` (see [`solutions::samples`]).
pub fn compare_solutions(a: &Solution, b: &Solution, params: &Params) -> Result<SolutionComparison, CompareError> {
    let (mode, samples) = solutions::samples(a, b)?;
    Ok(SolutionComparison {
        metrics: metrics::metrics(&samples, &params.tau),
        mode,
        elements: (a.elements.len(), b.elements.len()),
    })
}


#[cfg(test)]
mod tests;

//! # compare: error of an image or a solution against a reference
//!
//! Modelled on Radiance's `radcompare`: explicit tolerances, exit 0 when the
//! data match within them, 1 when a given tolerance is exceeded, 2 on error;
//! only pixel and element data are compared, never headers (provenance,
//! command lines and timings differ between runs that agree).
//!
//! Two kinds of input:
//! - two images of the same size, each an [`HdrImage`] of this pipeline or
//!   any RGB(A) EXR of another renderer (read with a note that it carries
//!   no provenance): the samples are the pixels the reference (B) covers,
//!   coverage > 0, on a visible surface where a surface layer says so,
//!   less emitters and edges where asked ([`images`]). The errors are also
//!   given per object and per material, from the surface layer of B, or
//!   of A when B (a foreign reference) has none;
//! - two [`Solution`]s on the same mesh: per leaf element when both
//!   hierarchies are identical, else per input triangle, weighted by area
//!   ([`solutions`]).
//!
//! The metrics (RMSE, relative RMSE, mean signed error, relative luminance
//! error, and paper 002's percentage of samples over τ, relative per
//! sample) are defined in [`metrics::Metrics`].
//!
//! The knobs are [`Params`] (`compare --print-knobs`, the README's "Stage
//! knobs"): the thresholds τ, the pixels left out, and the tolerances.
//!
//! ```
//! use compare::metrics::{metrics, Sample};
//! let same = [Sample { a: [1.0; 3], b: [1.0; 3], weight: 1.0 }];
//! let m = metrics(&same, &[0.05]);
//! assert_eq!((m.rmse, m.relative_rmse), (0.0, 0.0));
//! assert!(compare::Params::default().exceeded(&m).is_empty());
//! ```

#![deny(missing_docs)]

pub mod files;
pub mod images;
pub mod metrics;
pub mod scale_bar;
pub mod solutions;

use metrics::Metrics;
use schemas::image::HdrImage;
use schemas::solution::Solution;
use stage_kit::knobs::Knobs;
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

stage_kit::knobs! {
    /// The stage's parameters.
    pub struct Params {
        /// Thresholds τ for the percentage-over-τ metric, each on the
        /// sample's relative luminance difference `|L_a − L_b| / L_b`.
        tau: Vec<f64> = vec![0.02, 0.05, 0.1], "", list(positive());
        /// Images: leave out the pixels whose surface emits (needs a surface layer in A or B).
        exclude_emitters: bool = false, "", switch;
        /// Images: leave out the pixels within this many pixels of a pixel not covered by one surface
        /// (and of an emitter, with `exclude_emitters`).
        exclude_edges: Option<u32> = None, "pixels", optional;
        /// Largest allowed `relative_rmse`.
        max_rel_rmse: Option<f64> = None, "", optional(at_least(0.0));
        /// Largest allowed `rmse`, in the data's unit (W/(m² sr) for images,
        /// W/m² for solutions).
        max_rmse: Option<f64> = None, "", optional(at_least(0.0));
        /// Largest allowed percentage (0-100) of samples whose luminance
        /// difference exceeds the largest τ.
        max_pixels_over_tau: Option<f64> = None, "%", optional(at_least(0.0));
    }
}

impl Params {
    /// Checks every knob's range ([`Knobs::check`]) and that τ has at
    /// least one value.
    pub fn validate(&self) -> schemas::Result<()> {
        self.check("")?;
        if self.tau.is_empty() {
            return Err(stage_kit::run::bad_parameter("tau needs at least one value"));
        }
        Ok(())
    }

    /// The pixel exclusions asked for.
    pub fn exclusions(&self) -> images::Exclusions {
        images::Exclusions { emitters: self.exclude_emitters, edges: self.exclude_edges }
    }

    /// The largest τ (0 for an empty list).
    pub fn tau_max(&self) -> f64 {
        self.tau.iter().copied().fold(0.0, f64::max)
    }

    /// Whether any tolerance is given.
    pub fn has_tolerance(&self) -> bool {
        [self.max_rel_rmse, self.max_rmse, self.max_pixels_over_tau].iter().any(Option::is_some)
    }

    /// Each given tolerance that `m` exceeds, as `metric value > tolerance`;
    /// empty when the inputs match. A metric equal to its tolerance passes.
    pub fn exceeded(&self, m: &Metrics) -> Vec<String> {
        let tau_max = self.tau_max();
        let over_tau_max = m.percent_over(tau_max);
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
    /// The metrics over the compared pixels.
    pub metrics: Metrics,
    /// The metrics per object index, over the compared pixels of each
    /// (empty without a surface layer).
    pub by_object: Vec<(u32, Metrics)>,
    /// The metrics per material index.
    pub by_material: Vec<(u32, Metrics)>,
    /// Which input's surface layer was used, if any.
    pub surfaces_from: Option<Which>,
    /// Pixels the reference covers that were not compared: no visible
    /// surface, or left out by an exclusion.
    pub excluded: usize,
    /// Pixels covered in exactly one of the two images.
    pub coverage_mismatches: usize,
    /// Pixels per image.
    pub pixels: usize,
    /// Per pixel, whether it was compared.
    pub compared: Vec<bool>,
}

/// The counter name of metric `name` of group `group` (`object`,
/// `material`) `label`: `object[tall block].relative_rmse`.
pub fn group_counter(group: &str, label: &str, name: &str) -> String {
    format!("{group}[{label}].{name}")
}

impl ImageComparison {
    /// Report counters: the metrics', `pixels`, `coverage_mismatch_pixels`,
    /// `excluded_pixels`, and for each object and material (labelled by
    /// `object_label` / `material_label` from the index) its metrics as
    /// [`group_counter`]s.
    pub fn counters(&self, object_label: &dyn Fn(u32) -> String, material_label: &dyn Fn(u32) -> String) -> BTreeMap<String, f64> {
        let mut c = self.metrics.counters();
        c.insert("pixels".to_string(), self.pixels as f64);
        c.insert("coverage_mismatch_pixels".to_string(), self.coverage_mismatches as f64);
        c.insert("excluded_pixels".to_string(), self.excluded as f64);
        for (group, list, label) in [("object", &self.by_object, object_label), ("material", &self.by_material, material_label)] {
            for (index, m) in list {
                for (name, value) in m.counters() {
                    if name != "total_weight" {
                        c.insert(group_counter(group, &label(*index), &name), value);
                    }
                }
            }
        }
        c
    }
}

/// Compares image `a` with reference `b` (same size, finite values).
pub fn compare_images(a: &HdrImage, b: &HdrImage, params: &Params) -> Result<ImageComparison, CompareError> {
    images::check_pair(a, b)?;
    let compared = images::compared_pixels(a, b, params.exclusions())?;
    let samples = images::samples(a, b, &compared);
    let surfaces = images::surfaces(a, b);
    let group = |index: &dyn Fn(usize) -> u32| {
        let mut groups: BTreeMap<u32, Vec<metrics::Sample>> = BTreeMap::new();
        for (pixel, sample) in &samples {
            groups.entry(index(*pixel)).or_default().push(*sample);
        }
        groups.into_iter().map(|(k, v)| (k, metrics::metrics(&v, &params.tau))).collect::<Vec<_>>()
    };
    let (by_object, by_material) = match surfaces {
        Some((s, _)) => (group(&|i| s.object[i]), group(&|i| s.material[i])),
        None => (Vec::new(), Vec::new()),
    };
    let all: Vec<metrics::Sample> = samples.iter().map(|(_, s)| *s).collect();
    Ok(ImageComparison {
        metrics: metrics::metrics(&all, &params.tau),
        by_object,
        by_material,
        surfaces_from: surfaces.map(|(_, w)| w),
        excluded: b.coverage.iter().filter(|&&c| c > 0.0).count() - all.len(),
        coverage_mismatches: images::coverage_mismatches(a, b),
        pixels: b.rgb.len(),
        compared,
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

//! The summary of `make bench-gather` (paper 000's Tables 1-2 in shape):
//! per run of grid-gather (brute force at several sample counts, the full
//! gather at several contrast thresholds, the masked full gather), its
//! work from its report, its error against the high-sample brute-force
//! reference, and the brute-force ray count that would reach the same
//! error.
//!
//! The equal-error ray count comes from the brute runs: a least-squares
//! line `ln e = a + b ln n` through their (visibility rays `n`, relative
//! RMSE `e`), inverted at each run's error, `n_eq = exp((ln e - a) / b)`;
//! a run's ratio is its rays (visibility plus classification) over
//! `n_eq`: under 1, it costs fewer rays than brute force at its error.

use schemas::report::Report;
use std::fmt::Write as _;

/// What one run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct GatherRun {
    /// The run's name (`brute16`, `full0.02`, `masked`).
    pub name: String,
    /// Visibility rays of the gather (report counter `visibility_rays`).
    pub visibility_rays: f64,
    /// Visibility rays of the classification (`classification_visibility_rays`).
    pub classification_rays: f64,
    /// Form factors evaluated (`form_factor_evaluations`).
    pub form_factors: f64,
    /// The report's wall time, seconds.
    pub time_s: f64,
    /// compare's relative RMSE against the reference.
    pub relative_rmse: f64,
}

impl GatherRun {
    /// The figures of run `name` from its report and its error; a counter
    /// the report lacks counts 0 (brute force classifies nothing).
    pub fn of(name: &str, report: &Report, relative_rmse: f64) -> GatherRun {
        let counter = |key: &str| report.counters.get(key).copied().unwrap_or(0.0);
        GatherRun {
            name: name.to_string(),
            visibility_rays: counter("visibility_rays"),
            classification_rays: counter("classification_visibility_rays"),
            form_factors: counter("form_factor_evaluations"),
            time_s: report.wall_time_s,
            relative_rmse,
        }
    }

    /// Whether the run is a brute-force one (its name starts with `brute`).
    pub fn is_brute(&self) -> bool {
        self.name.starts_with("brute")
    }
}

/// The least-squares line `(a, b)` of `ln e = a + b ln n` through the
/// brute runs' (visibility rays, error); `None` with fewer than two
/// distinct ray counts.
pub fn brute_fit(runs: &[GatherRun]) -> Option<(f64, f64)> {
    let points: Vec<(f64, f64)> = runs.iter().filter(|r| r.is_brute()).map(|r| (r.visibility_rays.ln(), r.relative_rmse.ln())).collect();
    let n = points.len() as f64;
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(sx, sy), (x, y)| (sx + x, sy + y));
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(sxx, sxy), (x, y)| (sxx + x * x, sxy + x * y));
    let denominator = n * sxx - sx * sx;
    if points.len() < 2 || denominator == 0.0 {
        return None;
    }
    let b = (n * sxy - sx * sy) / denominator;
    Some(((sy - b * sx) / n, b))
}

/// The summary table, as `make bench-gather` has printed it: a heading,
/// then per run its rays, form factors, time, error, the equal-error
/// brute-force rays and the ratio (empty where the brute runs give no
/// line).
pub fn summary(runs: &[GatherRun]) -> String {
    let mut out = format!("{:<9} {:>14} {:>14} {:>14} {:>8} {:>12} {:>14} {:>8}\n", "run", "vis_rays", "class_rays", "ff_evals", "time_s", "rel_rmse", "brute_rays@err", "ratio");
    let fit = brute_fit(runs);
    for r in runs {
        let _ = write!(
            out,
            "{:<9} {:>14} {:>14} {:>14} {:>8.2} {:>12}",
            r.name,
            r.visibility_rays as i64,
            r.classification_rays as i64,
            r.form_factors as i64,
            r.time_s,
            c_exponent(r.relative_rmse, 3)
        );
        if let Some((a, b)) = fit {
            let equal = ((r.relative_rmse.ln() - a) / b).exp();
            let _ = write!(out, " {:>14} {:>8.3}", equal as i64, (r.visibility_rays + r.classification_rays) / equal);
        }
        out.push('\n');
    }
    out
}

/// `x` as C's `%.{digits}e` writes it (`1.234e-02`): Rust's `{:e}` writes
/// `1.234e-2`, and the table keeps the form it has always had.
fn c_exponent(x: f64, digits: usize) -> String {
    let text = format!("{x:.digits$e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let (sign, magnitude) = exponent.strip_prefix('-').map_or(('+', exponent), |m| ('-', m));
            format!("{mantissa}e{sign}{magnitude:0>2}")
        }
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(name: &str, rays: f64, class: f64, error: f64) -> GatherRun {
        GatherRun { name: name.into(), visibility_rays: rays, classification_rays: class, form_factors: 10.0 * rays, time_s: 1.234, relative_rmse: error }
    }

    #[test]
    fn the_brute_line_is_fitted_in_log_log_and_inverted_at_each_error() {
        // Brute force on an exact 1/sqrt(n) line, e = 0.5 / sqrt(n / 100): a = ln(5), b = -1/2.
        let runs = [run("brute4", 100.0, 0.0, 0.5), run("brute16", 400.0, 0.0, 0.25), run("brute64", 1600.0, 0.0, 0.125), run("full0.02", 150.0, 50.0, 0.3)];
        let (a, b) = brute_fit(&runs).unwrap();
        assert!((a - 5f64.ln()).abs() < 1e-12 && (b + 0.5).abs() < 1e-12, "a {a} b {b}");
        let table = summary(&runs);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines[0], "run             vis_rays     class_rays       ff_evals   time_s     rel_rmse brute_rays@err    ratio");
        assert_eq!(lines[1], "brute4               100              0           1000     1.23    5.000e-01            100    1.000");
        // Brute force needs (0.5 / 0.3)^2 x 100 = 277.8 rays for the full
        // gather's error, which it reaches with 150 + 50: 0.72 of them.
        assert_eq!(lines[4], "full0.02             150             50           1500     1.23    3.000e-01            277    0.720");
        assert_eq!(brute_fit(&runs[3..]), None, "no brute run, no line");
        assert_eq!(summary(&runs[3..]).lines().nth(1), Some("full0.02             150             50           1500     1.23    3.000e-01"));
    }

    #[test]
    fn errors_are_written_as_c_writes_them() {
        assert_eq!(c_exponent(0.0123456, 3), "1.235e-02");
        assert_eq!(c_exponent(123.0, 3), "1.230e+02");
        assert_eq!(c_exponent(2.5e-10, 3), "2.500e-10");
    }
}

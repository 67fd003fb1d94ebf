//! Summaries of repeated runs (median and range) and the Pareto front of
//! error against time.

use serde::{Deserialize, Serialize};

/// The median and range of one figure over a point's repetitions.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Spread {
    /// The median (mean of the two middle values for an even count).
    pub median: f64,
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl Spread {
    /// The spread of `values` (at least one).
    pub fn of(values: &[f64]) -> Spread {
        assert!(!values.is_empty(), "a spread of no value");
        Spread {
            median: crate::median(values.to_vec()),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// Which of the `(time, error)` points are on the Pareto front: those that
/// no other point dominates, i.e. no other point is at most as slow and at
/// most as wrong and strictly better in one of the two. Equal points are
/// all on the front. A point with a non-finite coordinate is never on it
/// and dominates nothing.
pub fn front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let dominates = |q: &(f64, f64), p: &(f64, f64)| q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1);
    points
        .iter()
        .map(|p| finite(p) && !points.iter().any(|q| finite(q) && dominates(q, p)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_range_of_odd_and_even_counts() {
        assert_eq!(Spread::of(&[3.0, 1.0, 2.0]), Spread { median: 2.0, min: 1.0, max: 3.0 });
        assert_eq!(Spread::of(&[4.0, 1.0, 3.0, 2.0]), Spread { median: 2.5, min: 1.0, max: 4.0 });
        assert_eq!(Spread::of(&[7.0]), Spread { median: 7.0, min: 7.0, max: 7.0 });
        // An outlier moves the mean, not the median.
        assert_eq!(Spread::of(&[1.0, 1.1, 100.0]).median, 1.1);
    }

    #[test]
    fn the_front_keeps_exactly_the_undominated_points() {
        // (time, error): a staircase of three, one point behind it, one
        // equal to a front point, one non-finite.
        let points = [(1.0, 1e-1), (2.0, 1e-2), (4.0, 1e-3), (3.0, 2e-2), (2.0, 1e-2), (0.5, f64::NAN)];
        assert_eq!(front(&points), vec![true, true, true, false, true, false]);
        // Same time, lower error wins; same error, lower time wins.
        assert_eq!(front(&[(1.0, 2.0), (1.0, 1.0), (0.5, 1.0)]), vec![false, false, true]);
        assert!(front(&[]).is_empty());
    }
}

//! The angle between two vectors from their cross and dot products,
//! `atan2(|a x b|, a . b)`, without libm's `atan2`.
//!
//! Lambert's factor ([`crate::form_factor::point_to_polygon`]) takes one
//! such angle per polygon edge, and it is the solver's hottest call: on the
//! built-in Cornell box at `EPS` 1e-3, libm's `atan2` alone was 11% of
//! hierarchical-solve's time (one thread, `perf`). glibc's is correctly
//! rounded and pays for it; this one is within 2 units in the last place
//! of it (10 million random pairs; tested below to 4) at half the cost,
//! 10.2 ns a call against 19.3 ns in a loop on this project's machine,
//! since the angle here is in `[0, pi]` and one division serves the whole
//! reduction. The solve of the Cornell box came out 4.7% faster at `EPS`
//! 1e-3 and 2.8% at 6e-4 (one thread, interleaved medians of 9 and 7),
//! its solution the same to the f32 it is written in (rmse 0).
//!
//! # Method
//!
//! With `s = |a x b| >= 0` and `c = a . b`, the angle folds into `[0, pi/4]`
//! by symmetry: `theta = atan(n / d)` with `n = min(s, |c|)`, `d = max(s,
//! |c|)`, then `pi/2 - theta` where `s > |c|` and `pi - theta` where `c <
//! 0`. `[0, pi/4]` splits into four arcs centred on `k pi/16`, `k = 0..4`;
//! with `t_k = tan(k pi/16)` the addition formula gives
//!
//! ```text
//! atan(n / d) = k pi/16 + atan(x),   x = (n - t_k d) / (d + t_k n),   |x| <= tan(pi/32) < 0.0985
//! ```
//!
//! (one division; where `n / d` is near `t_k` the numerator cancels, and
//! the rounding of `t_k d` costs at most `1.2e-16 t_k / (1 + t_k^2)`, two
//! units in the last place of the angle there). Plain products and sums:
//! without a `target-cpu` that has FMA, `mul_add` calls libm. On `|x| <= 0.0985` eight terms of
//! the Taylor series `atan x = x - x^3/3 + x^5/5 - ...` leave a truncation
//! below `x^17 / 17 < 5e-18 |x|`, a twentieth of an ulp, so no fitted
//! coefficients are needed. The `t_k` are rounded to f64; that moves the
//! result by at most `1e-17 / (1 + t_k^2)`.

use std::f64::consts::{FRAC_PI_2, PI};

/// `tan(k pi/16)` for `k = 0..=4`, rounded to f64: the centres of the
/// four arcs.
const CENTRES: [f64; 5] = [0.0, 0.198_912_367_379_658, 0.414_213_562_373_095_03, 0.668_178_637_919_298_9, 1.0];

/// `tan((2k + 1) pi/32)` for `k = 0..4`: the borders between the arcs.
const BORDERS: [f64; 4] = [0.098_491_403_357_164_25, 0.303_346_683_607_342_4, 0.534_511_135_950_791_7, 0.820_678_790_828_660_4];

/// The angle `atan2(s, c)` in `[0, pi]` for `s >= 0` (module docs): the
/// angle between two vectors whose cross product has length `s` and whose
/// dot product is `c`. `(0, 0)` gives 0, as `atan2` does.
#[inline]
pub fn from_sin_cos(s: f64, c: f64) -> f64 {
    let ac = c.abs();
    let (n, d) = if s <= ac { (s, ac) } else { (ac, s) };
    if d == 0.0 {
        return 0.0;
    }
    let k = BORDERS.iter().filter(|&&b| n > b * d).count();
    let t = CENTRES[k];
    let x = (n - t * d) / (d + t * n);
    let folded = k as f64 * (PI / 16.0) + atan_small(x);
    let octant = if s > ac { FRAC_PI_2 - folded } else { folded };
    if c < 0.0 {
        PI - octant
    } else {
        octant
    }
}

/// `atan x` for `|x| <= tan(pi/32)`: the Taylor series to `x^15` (module
/// docs), `x + x z p(z)` with `z = x^2` and `p` by Horner's rule, so the
/// last addition carries the rounding of a term under a three-hundredth
/// of `x`.
#[inline]
fn atan_small(x: f64) -> f64 {
    /// The series' coefficients after its first, highest power first:
    /// `-1/15, 1/13, ..., -1/3`.
    const SERIES: [f64; 7] = [-1.0 / 15.0, 1.0 / 13.0, -1.0 / 11.0, 1.0 / 9.0, -1.0 / 7.0, 1.0 / 5.0, -1.0 / 3.0];
    let z = x * x;
    let p = SERIES[1..].iter().fold(SERIES[0], |acc, &coefficient| acc * z + coefficient);
    x + x * z * p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Stream;

    /// Units in the last place of `expected` by which `got` differs.
    fn ulps(got: f64, expected: f64) -> f64 {
        (got - expected).abs() / (expected.abs().max(f64::MIN_POSITIVE) * f64::EPSILON)
    }

    #[test]
    fn agrees_with_libm_to_a_few_units_in_the_last_place() {
        let mut stream = Stream::new(7, 0, 0);
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            // Magnitudes over 40 decades, either sign of the cosine.
            let scale = |u: f64| 10f64.powf(40.0 * u - 20.0);
            let s = scale(stream.next_f64()) * stream.next_f64();
            let c = scale(stream.next_f64()) * (stream.next_f64() - 0.5);
            let c = if i % 3 == 0 { s * (2.0 * stream.next_f64() - 1.0) } else { c };
            worst = worst.max(ulps(from_sin_cos(s, c), s.atan2(c)));
        }
        assert!(worst <= 4.0, "worst {worst} ulp");
    }

    #[test]
    fn is_exact_where_the_answer_is() {
        assert_eq!(from_sin_cos(0.0, 0.0), 0.0);
        assert_eq!(from_sin_cos(0.0, 3.0), 0.0);
        assert_eq!(from_sin_cos(0.0, -3.0), PI);
        assert_eq!(from_sin_cos(2.0, 0.0), FRAC_PI_2);
        assert_eq!(from_sin_cos(2.0, -0.0), FRAC_PI_2);
        assert!(ulps(from_sin_cos(1.0, 1.0), PI / 4.0) <= 1.0);
        assert!(ulps(from_sin_cos(1.0, -1.0), 3.0 * PI / 4.0) <= 1.0);
    }

    #[test]
    fn each_arc_border_and_centre_agrees_with_libm() {
        // Ratios on and beside the borders between arcs and at their
        // centres, where the reduced argument is largest and smallest.
        for &r in BORDERS.iter().chain(&CENTRES) {
            for nudge in [-1e-12, 0.0, 1e-12] {
                let (s, c) = (r + nudge, 1.0);
                for (s, c) in [(s, c), (c, s), (s, -c), (c, -s)] {
                    assert!(ulps(from_sin_cos(s.abs(), c), s.abs().atan2(c)) <= 4.0, "{s} {c}");
                }
            }
        }
    }
}

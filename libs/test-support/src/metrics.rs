//! Error measures of a result against a reference, value by value.

/// Relative RMSE of `values` against `reference`,
/// `sqrt(mean_i ((a_i - b_i) / b_i)²)` over the entries where `b_i > 0`
/// (NaN where there is none).
pub fn relative_rmse(values: &[f64], reference: &[f64]) -> f64 {
    let (mut e, mut n) = (0.0, 0.0);
    for (x, y) in values.iter().zip(reference) {
        if *y > 0.0 {
            e += ((x - y) / y).powi(2);
            n += 1.0;
        }
    }
    (e / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_rmse_is_the_root_mean_square_of_the_relative_errors_where_the_reference_is_positive() {
        // Errors +10% and -30% where the reference is positive; the zero
        // reference entry is left out: sqrt((0.01 + 0.09) / 2).
        let e = relative_rmse(&[1.1, 1.4, 5.0], &[1.0, 2.0, 0.0]);
        assert!((e - 0.05f64.sqrt()).abs() < 1e-15, "{e}");
    }
}

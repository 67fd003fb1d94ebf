//! Per-vertex irradiance estimates from batches of photons, with their
//! variance.
//!
//! Batch `b` of `n` photons gives vertex `v` the estimate
//! `x_bv = D_bv / (n A_v)`, W/m² per channel, where `D_bv` is the power the
//! batch deposited on `v` and `A_v` its hat area ([`crate::mesh`]). The
//! batches are independent and identically distributed, so the estimate
//! after `B` batches is their mean and its variance is estimated by
//! `s² / B` with `s²` the sample variance of the batches (of the
//! luminance, [`radiometry::color::luminance`]). Batches are added in their
//! index order, so the sums do not depend on how many threads traced them.
//!
//! The values the stage shows are not these lumped estimates but their
//! projection onto the hat functions ([`crate::projection`]), which
//! carries more of the noise from vertex to vertex. So the variance is
//! taken of each batch's projected luminance, `y_b = M^-1 (D_b / n)`: the
//! spread of what is shown, at the cost of one sparse solve a batch.

use crate::projection::{MassMatrix, VARIANCE_TOLERANCE};
use crate::tracing::Batch;
use radiometry::color::luminance;

/// Sums over batches for every vertex.
#[derive(Clone, Debug)]
pub struct Tally {
    /// Batches added.
    pub batches: u64,
    /// Photons per batch.
    pub batch_photons: usize,
    /// Sum of the batch estimates, W/m² per channel.
    sum: Vec<[f64; 3]>,
    /// Sum of the batches' projected luminances (module docs).
    projected_sum: Vec<f64>,
    /// Sum of their squares.
    projected_sum_sq: Vec<f64>,
    /// One batch's deposits per vertex (scratch, zero between batches).
    scratch: Vec<[f64; 3]>,
    /// 1 / A_v (0 for a vertex without area).
    inverse_area: Vec<f64>,
}

impl Tally {
    /// An empty tally over vertices of hat areas `hat_area`.
    pub fn new(hat_area: &[f64], batch_photons: usize) -> Self {
        let n = hat_area.len();
        let inverse_area = hat_area.iter().map(|&a| if a > 0.0 { 1.0 / a } else { 0.0 }).collect();
        Tally { batches: 0, batch_photons, sum: vec![[0.0; 3]; n], projected_sum: vec![0.0; n], projected_sum_sq: vec![0.0; n], scratch: vec![[0.0; 3]; n], inverse_area }
    }

    /// Adds one batch: its indirect deposits, and its first hits too when
    /// `with_first_hits`; `mass` projects its luminance (module docs).
    pub fn add(&mut self, batch: &Batch, with_first_hits: bool, mass: &MassMatrix) {
        let first: &[(u32, [f64; 3])] = if with_first_hits { &batch.first_hits } else { &[] };
        for &(v, p) in batch.deposits.iter().chain(first) {
            let s = &mut self.scratch[v as usize];
            for c in 0..3 {
                s[c] += p[c];
            }
        }
        let scale = 1.0 / self.batch_photons as f64;
        let mut load = vec![0.0; self.sum.len()];
        for &(v, _) in batch.deposits.iter().chain(first) {
            let v = v as usize;
            let d = self.scratch[v];
            if d == [0.0; 3] {
                continue; // already added (a vertex hit twice in the batch)
            }
            let x = d.map(|d| d * scale * self.inverse_area[v]);
            for (s, x) in self.sum[v].iter_mut().zip(x) {
                *s += x;
            }
            load[v] = luminance(d) * scale;
            self.scratch[v] = [0.0; 3];
        }
        for (v, y) in mass.solve(&load, VARIANCE_TOLERANCE).into_iter().enumerate() {
            self.projected_sum[v] += y;
            self.projected_sum_sq[v] += y * y;
        }
        self.batches += 1;
    }

    /// Photons traced.
    pub fn photons(&self) -> u64 {
        self.batches * self.batch_photons as u64
    }

    /// The mean irradiance at vertex `v`, W/m² per channel (0 before any
    /// batch).
    pub fn mean(&self, v: usize) -> [f64; 3] {
        match self.batches {
            0 => [0.0; 3],
            b => self.sum[v].map(|s| s / b as f64),
        }
    }

    /// The standard error of the projected mean's luminance at `v`
    /// (infinite with fewer than two batches).
    pub fn standard_error(&self, v: usize) -> f64 {
        let b = self.batches as f64;
        if self.batches < 2 {
            return f64::INFINITY;
        }
        let mean = self.projected_sum[v] / b;
        let variance = ((self.projected_sum_sq[v] / b - mean * mean) * b / (b - 1.0)).max(0.0);
        (variance / b).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_standard_error_follow_the_batches() {
        // Vertex 0 (area 2) gets 4 W then 8 W from batches of 2 photons:
        // estimates 1 and 2 W/m² (grey), mean 1.5, standard error of the
        // mean sqrt(0.5 / 2) = 0.5. A vertex hit twice in one batch sums.
        // Two vertices without a leaf in common: the projection is the
        // lumped estimate.
        let mass = MassMatrix::lumped(&[2.0, 1.0]);
        let mut t = Tally::new(&[2.0, 1.0], 2);
        t.add(&Batch { deposits: vec![(0, [2.0; 3])], first_hits: vec![(0, [2.0; 3])], ..Default::default() }, true, &mass);
        t.add(&Batch { deposits: vec![(0, [8.0; 3]), (1, [1.0; 3])], first_hits: vec![(1, [5.0; 3])], ..Default::default() }, false, &mass);
        assert_eq!(t.mean(0), [1.5; 3]);
        assert!((t.standard_error(0) - 0.5).abs() < 1e-12);
        assert_eq!(t.mean(1), [0.25; 3]);
        assert_eq!(t.photons(), 4);
    }
}

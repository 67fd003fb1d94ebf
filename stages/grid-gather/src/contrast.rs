//! The contrast threshold `c` of the full gather: the smallest visible
//! contrast (a Weber fraction), from the `contrast` channel of the mask
//! stage's threshold image (paper 000 Sec. 5.2) or the `contrast`
//! parameter.
//!
//! Where it goes: [`vertex_contrast`] gives each grid vertex its `c`
//! (recorded in the vertex's diagnostics); a vertex classifies its senders
//! under `tau = c B_v` ([`crate::classification`]); at a surface point
//! [`FullGather::contrast_at`] interpolates the vertices' `c`, which the
//! surface-based gather spends as `tau = c sum rho B_s F V` and a leaf
//! check as `c` times the leaf's radiosity ([`crate::surface_gather`]); the
//! view-dependent shadow sample counts divide by that `tau`
//! ([`crate::shadow_samples`]).

use crate::full_gather::FullGather;
use crate::grid::{Grid, Location};
use glam::DVec3;
use schemas::threshold::ThresholdImage;

/// Per grid vertex, the contrast threshold: the mask's contrast averaged
/// over the pixels whose centre ray hits one of the (up to eight) cells
/// around the vertex (000 Sec. 5.2, "the average masking values in the
/// adjacent grid cells"); `default` (the `contrast` parameter) where no
/// mask is given or no pixel sees those cells. `centres` holds each pixel's
/// centre hit of a `w` x `h` image.
pub fn vertex_contrast(default: f64, grid: &Grid, centres: &[Option<DVec3>], w: usize, h: usize, threshold: Option<&ThresholdImage>) -> Vec<f64> {
    let mut out = vec![default; grid.vertex_count()];
    let Some(t) = threshold else { return out };
    let cells = grid.n[0] * grid.n[1] * grid.n[2];
    let mut sum = vec![(0.0f64, 0u64); cells];
    for (i, p) in centres.iter().enumerate() {
        let Some(p) = p else { continue };
        let Some(g) = grid.coordinates(*p) else { continue };
        let cell: [usize; 3] = std::array::from_fn(|a| (g[a].floor().max(0.0) as usize).min(grid.n[a] - 1));
        let (x, y) = (i % w, i / w);
        let (tx, ty) = ((x * t.width / w).min(t.width - 1), (y * t.height / h).min(t.height - 1));
        let c = f64::from(t.contrast[ty * t.width + tx]);
        if !c.is_finite() {
            continue;
        }
        let s = &mut sum[(cell[2] * grid.n[1] + cell[1]) * grid.n[0] + cell[0]];
        s.0 += c;
        s.1 += 1;
    }
    for (index, value) in out.iter_mut().enumerate() {
        let v = grid.vertex_of(index);
        let (mut total, mut count) = (0.0, 0u64);
        for m in 0..8 {
            let c: [i64; 3] = std::array::from_fn(|a| v[a] as i64 - 1 + ((m >> a) & 1) as i64);
            if (0..3).any(|a| c[a] < 0 || c[a] >= grid.n[a] as i64) {
                continue;
            }
            let s = sum[(c[2] as usize * grid.n[1] + c[1] as usize) * grid.n[0] + c[0] as usize];
            total += s.0;
            count += s.1;
        }
        if count > 0 {
            *value = total / count as f64;
        }
    }
    out
}

impl FullGather<'_> {
    /// The contrast threshold at a point at `location` in the grid: the
    /// vertices' thresholds blended with the interpolation weights.
    pub fn contrast_at(&self, location: &Location) -> f64 {
        let w = location.interpolation_weights();
        (0..4).map(|i| w[i] * self.vertex_contrast[location.vertices[i]]).sum()
    }
}

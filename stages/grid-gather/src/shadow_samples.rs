//! View-dependent shadow sample counts (paper 000 Sec. 5.3), for a sender
//! whose visibility is resampled.
//!
//! The penumbra width on the receiver, `w = size_s d_o / (d_s - d_o)`
//! (similar triangles; `d_o` the link's occluder distance, `d_s` the
//! sender's), in pixels at the receiver's depth, bounds the count (more
//! samples than pixels across the penumbra give sub-pixel steps), and so
//! does `rho B_s F_avg / tau` (one of `n` equal steps of the penumbra then
//! stays below the visible contrast `tau`). The count is the smaller bound,
//! in `[min_samples, max_shadow_samples]`; without `view_dependent`, Eq. 1's
//! count in that range.

use crate::full_gather::FullGather;
use glam::DVec3;
use schemas::solution::Node;

impl FullGather<'_> {
    /// Visibility samples for a sender `node` of radiosity contribution
    /// `rho_b_f` (W/m², luminance) seen from `p` with nearest occluder
    /// distance `occluder`, under the threshold `tau` (W/m²); `eq1` is the
    /// count Eq. 1 gave (module docs).
    pub(crate) fn shadow_samples(&self, p: DVec3, node: Node, occluder: f64, rho_b_f: f64, tau: f64, eq1: u32) -> u32 {
        let (lo, hi) = (self.params.min_samples, self.params.max_shadow_samples);
        if !self.params.view_dependent {
            return eq1.clamp(lo, hi);
        }
        let mut bound = f64::from(hi);
        let d_s = p.distance(self.senders.centre(node));
        if occluder.is_finite() && occluder < d_s {
            let penumbra = self.senders.size(node) * occluder / (d_s - occluder);
            if let Some(pixel) = self.grid.pixel_size_at(p, self.width) {
                if pixel > 0.0 {
                    bound = bound.min((penumbra / pixel).ceil());
                }
            }
        }
        if tau > 0.0 {
            bound = bound.min((rho_b_f / tau).ceil());
        }
        (bound.max(0.0) as u32).clamp(lo, hi)
    }
}

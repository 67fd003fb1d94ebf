//! Irradiance at a pixel's surface point from the grid (paper 000
//! Sec. 4.4).
//!
//! The camera ray's hit `p` lies in one grid cell and one of its five
//! tetrahedra, with barycentric weights `w_i` of the tetrahedron's four
//! vertices ([`crate::grid::Location::interpolation_weights`]). For every
//! link arriving at `p`'s element chain (the same links the brute-force
//! gather resamples), from sender `s`, vertex `i` gives
//!
//! ```text
//! F_i = F(p, n_p, s)                 if i resamples the form factor
//!     = F_avg,i max(0, n_p . d_i)    otherwise (d_i: direction to s)
//! V_i = fraction of n(p) fixed samples of s visible from p   if i resamples visibility
//!     = vis_i                                                otherwise
//! ```
//!
//! with `n(p) = ceil(sum_i w_i n_i)` over the vertices that resample
//! visibility, and `H(p) += B_s sum_i w_i F_i V_i`: where one vertex
//! resamples a sender and another interpolates it, both are done and
//! blended (Sec. 4.4.2), so nothing switches at a tetrahedron face. The
//! visibility is kernel-weighted over the sender's fixed samples
//! ([`crate::full_gather`]).

use crate::classification::{LinkClass, VertexData};
use crate::diagnostics::Work;
use crate::full_gather::FullGather;
use crate::grid::Location;
use glam::DVec3;

impl FullGather<'_> {
    /// `H(p)`, W/m² RGB, on `triangle` (normal `normal`) at `location` in
    /// the grid, from the links `links`, for camera sample `pass` (module
    /// docs).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn interpolated_irradiance(&self, p: DVec3, normal: DVec3, triangle: u32, location: &Location, links: &[usize], pass: u32, work: &mut Work) -> [f64; 3] {
        let mut h = [0.0; 3];
        let w = location.interpolation_weights();
        let data: [&VertexData; 4] = location.vertices.map(|v| self.vertex(v));
        let heaviest = (0..4).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
        for &l in links {
            let link = &self.senders.solution.links[l];
            if link.visibility <= 0.0 {
                continue;
            }
            let s = link.sender;
            let entries = data.map(|d| d.find(s));
            // A vertex without the sender (none, unless round-off put p just
            // outside its region) resamples both terms.
            let fallback = self.params.max_shadow_samples;
            let need_f = entries.iter().any(|e| e.is_none_or(|e| e.resample_form_factor));
            let n_vis: f64 = (0..4)
                .map(|i| match entries[i] {
                    None => w[i] * f64::from(fallback),
                    Some(e) if e.resample_visibility => w[i] * f64::from(e.shadow_samples),
                    _ => 0.0,
                })
                .sum();
            let need_v = entries.iter().any(|e| e.is_none_or(|e| e.resample_visibility));
            let f_exact = if need_f {
                let (f, evals) = self.senders.form_factor(s, p, normal);
                work.form_factors += evals;
                f
            } else {
                0.0
            };
            let v_exact = if need_v { self.fixed_visibility(p, normal, triangle, s, (n_vis.ceil() as u32).max(1), pass, work) } else { 1.0 };
            let mut fv = 0.0;
            for i in 0..4 {
                let (f, v) = match entries[i] {
                    None => (f_exact, v_exact),
                    Some(e) => (
                        if e.resample_form_factor { f_exact } else { e.factor * normal.dot(e.direction).max(0.0) },
                        if e.resample_visibility { v_exact } else { e.visibility },
                    ),
                };
                fv += w[i] * f * v;
            }
            work.count(entries[heaviest].map_or(LinkClass::ResampleBoth, |e| e.class()));
            let b = self.senders.link_radiosity(l);
            (0..3).for_each(|c| h[c] += b[c] * fv);
        }
        h
    }
}

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
use crate::full_gather::{FullGather, Plan, PlanTerm};
use crate::grid::Location;
use glam::DVec3;

impl FullGather<'_> {
    /// The plan of `H(p)` on `triangle` (normal `normal`) at `location` in
    /// the grid, from the links `links` (module docs): per link, the sum
    /// over the vertices that resample visibility of `w_i F_i` (to be
    /// multiplied by the visibility resampled at each camera sample) and
    /// over the others of `w_i F_i vis_i`.
    pub(crate) fn interpolated_plan(&self, p: DVec3, normal: DVec3, location: &Location, links: &[usize], work: &mut Work) -> Plan {
        let mut plan = Plan { terms: Vec::with_capacity(links.len()), surface: false };
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
            let (mut resampled, mut fixed) = (0.0, 0.0);
            for i in 0..4 {
                match entries[i] {
                    None => resampled += w[i] * f_exact,
                    Some(e) => {
                        let f = if e.resample_form_factor { f_exact } else { e.factor * normal.dot(e.direction).max(0.0) };
                        if e.resample_visibility {
                            resampled += w[i] * f;
                        } else {
                            fixed += w[i] * f * e.visibility;
                        }
                    }
                }
            }
            plan.terms.push(PlanTerm {
                sender: s,
                radiosity: self.senders.link_radiosity(l),
                resampled,
                fixed,
                samples: if need_v { (n_vis.ceil() as u32).max(1) } else { 0 },
                class: entries[heaviest].map_or(LinkClass::ResampleBoth, |e| e.class()),
            });
        }
        plan
    }
}

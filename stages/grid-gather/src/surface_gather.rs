//! The surface-based gather (paper 000 Sec. 4.5).
//!
//! Where the solver refined the surface finer than the grid (the leaf's
//! longest edge is shorter than the cell size at `p`), the element mesh
//! already follows the lighting: every link of the chain gets the exact
//! point form factor `F` at `p`, and its visibility `V` comes from the
//! link. Of the links with `0 < V < 1`, those whose visibility error
//! `rho B_s F max(V, 1 - V)` (Eq. 3 with `V` as the interpolated value)
//! fits in the threshold budget ([`budget`]) keep `V`; the rest resample
//! visibility with the view-dependent count ([`crate::shadow_samples`]).
//! The threshold is `c sum_links rho B_s F V`, with `c` the grid's vertex
//! threshold interpolated at `p` ([`crate::contrast`]). The error terms use
//! the point factor, not the link's `Eu`: a cluster link's `Eu` averages
//! the receiver cluster's surfaces, and where it is near 0 while `F(p)` is
//! not, links escaped resampling (3.4% relative RMSE on the clustered
//! plant room of `make bench-gather`, 0.75% with the point factor).
//!
//! The paper takes `V = 1` and `V = 0` on trust ("the risk of missing a
//! sender which was wrongly classified as occluded"). With the solver's 16
//! rays per link that set an error floor near 4e-4 relative RMSE on the
//! Cornell box, so each leaf checks the links it would trust, once, built
//! on first use like a grid vertex ([`LeafCheck`]): the trusted links whose
//! `rho B_s F` at the leaf's centre does not fit the budget (the threshold
//! at the centre times the leaf's radiosity from its links) cast
//! `leaf_check_rays` rays from random points of the leaf to the sender's
//! fixed samples; where the rays contradict the link, their visible
//! fraction replaces `V` and the link is partly occluded from then on.
//!
//! Every point a camera ray meets is exposed, and a leaf across a solid's
//! footprint (a floor leaf under a block's face) is buried over part `1 -
//! x` of it: the link's `V` counts the rays from there as blocked, so each
//! link is taken at its exposed part's visibility `min(1, V / x)`
//! ([`crate::senders::Senders::exposed_visibility`]), and the check casts
//! `m / x` rays ([`BURIED_CHECK_FACTOR`] times `m` at most), about `m` of
//! them from the exposed part, and divides their visible fraction by `x`
//! alike. Where the solver found no exposed point on the leaf (`x` = 0:
//! the exposed sliver is thinner than its points could find, yet a camera
//! ray met it) the links' `V` say nothing of the point and every link is
//! resampled there, as the brute-force gather does. On `make
//! bench-gather`'s Cornell box (seed 1) a floor point 0.5 mm in front of
//! the tall block's face, on a leaf of exposure 0, got a third of its
//! light: the links it sees from there are hidden from the buried part,
//! the solver's 16 rays and the check's 8 all started there, and the full
//! gather's pixel came out 16% dark.

use crate::classification::{budget, LinkClass};
use crate::diagnostics::Work;
use crate::full_gather::FullGather;
use glam::DVec3;
use radiometry::color::luminance;
use radiometry::form_factor::WeightedVisibility;
use radiometry::sampling::{square_to_triangle, Stream};

/// Most times `leaf_check_rays` a partly buried leaf's check casts per
/// link (module docs): a leaf under a sixteenth exposed casts `16 m`,
/// about `16 m x` of them from its exposed part.
pub const BURIED_CHECK_FACTOR: f64 = 16.0;

/// A link whose solver visibility (0 or 1) a leaf's check contradicted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contradiction {
    /// The link.
    pub link: usize,
    /// The visible fraction the check found.
    pub visibility: f64,
}

/// What the surface-based gather learnt about one leaf element by checking
/// its trusted links (module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LeafCheck {
    /// The links the check contradicted, sorted by link.
    pub contradicted: Vec<Contradiction>,
    /// Visibility rays cast.
    pub rays: u64,
    /// Form-factor evaluations made.
    pub factors: u64,
}

impl LeafCheck {
    /// The checked visibility of link `l`, if the check contradicted the
    /// solver's.
    fn visibility(&self, l: usize) -> Option<f64> {
        self.contradicted.binary_search_by(|c| c.link.cmp(&l)).ok().map(|i| self.contradicted[i].visibility)
    }
}

/// One link at a surface point.
#[derive(Clone, Copy, Debug)]
struct LinkTerm {
    /// The link.
    link: usize,
    /// Its visibility: the leaf check's where it contradicted the solver,
    /// else the link's.
    visibility: f64,
    /// The point form factor at `p`.
    factor: f64,
    /// `rho B_s F`, W/m², luminance.
    contribution: f64,
}

impl FullGather<'_> {
    /// The links of `leaf`'s chain `links` whose solver visibility, 0 or 1,
    /// the leaf's check contradicts, with the checked visibility, sorted by
    /// link; built on first use (see [`LeafCheck`]).
    fn leaf_check(&self, leaf: u32, triangle: u32, links: &[usize]) -> &LeafCheck {
        self.leaf(leaf, || {
            let mut check = LeafCheck::default();
            let m = self.params.leaf_check_rays;
            let exposure = self.senders.exposure(leaf);
            // A wholly buried leaf resamples every link instead.
            if m == 0 || exposure <= 0.0 {
                return check;
            }
            let corners = self.senders.element_corners(leaf);
            let centre = corners.iter().sum::<DVec3>() / 3.0;
            let normal = self.senders.triangles[triangle as usize].normal;
            let rho = luminance(self.surfaces[triangle as usize].reflectance);
            let solution = &self.senders.solution;
            let b_local: f64 = links.iter().map(|&l| rho * luminance(solution.links[l].unoccluded_irradiance.map(f64::from)) * self.senders.exposed_visibility(l)).sum();
            let contrast = self.grid.locate(centre).map_or(self.params.contrast, |location| self.contrast_at(&location));
            let trusted: Vec<usize> = links
                .iter()
                .copied()
                .filter(|&l| {
                    let v = self.senders.exposed_visibility(l);
                    v <= 0.0 || v >= 1.0
                })
                .collect();
            let d: Vec<f64> = trusted
                .iter()
                .map(|&l| {
                    let (f, evals) = self.senders.form_factor(solution.links[l].sender, centre, normal);
                    check.factors += evals;
                    rho * luminance(self.senders.radiosity(solution.links[l].sender)) * f
                })
                .collect();
            let verify = budget(&d, contrast * b_local);
            let mut points = Stream::new(self.params.seed, u64::from(leaf), 0x1eaf);
            // About m of them from the exposed part (module docs).
            let partly_buried = exposure > 0.0 && exposure < 1.0;
            let count = if partly_buried { (f64::from(m) / exposure).min(BURIED_CHECK_FACTOR * f64::from(m)).ceil() as usize } else { m as usize };
            for (k, &l) in trusted.iter().enumerate() {
                if !verify[k] {
                    continue;
                }
                let link = &solution.links[l];
                let samples = self.senders.samples(link.sender);
                let mut visible = WeightedVisibility::default();
                for j in 0..count {
                    let b = square_to_triangle(points.next_f64(), points.next_f64());
                    let x = corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2];
                    let y = samples.at(j);
                    let weight = self.sample_weight(x, normal, y);
                    if weight > 0.0 {
                        check.rays += 1;
                        visible.add(weight, self.rays.segment_clear(x, y.point, [triangle, y.triangle]));
                    }
                }
                // No ray of positive weight: nothing to contradict with.
                let Some(v) = visible.fraction() else { continue };
                let v = self.senders.on_exposed_part(leaf, v);
                if v != self.senders.exposed_visibility(l) {
                    check.contradicted.push(Contradiction { link: l, visibility: v });
                }
            }
            check
        })
    }

    /// The surface-based gather at `p` (module docs) with contrast
    /// threshold `contrast`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn surface_irradiance(&self, p: DVec3, normal: DVec3, triangle: u32, leaf: u32, links: &[usize], contrast: f64, pass: u32, work: &mut Work) -> [f64; 3] {
        work.surface = 1;
        let solution = &self.senders.solution;
        let check = self.leaf_check(leaf, triangle, links);
        // A leaf the solver found wholly buried (module docs): its links'
        // visibility says nothing of `p`, and every link is resampled.
        let unexposed = self.senders.exposure(leaf) <= 0.0;
        let rho = luminance(self.surfaces[triangle as usize].reflectance);
        let terms: Vec<LinkTerm> = links
            .iter()
            .map(|&l| {
                let link = &solution.links[l];
                let visibility = if unexposed { 1.0 } else { check.visibility(l).unwrap_or_else(|| self.senders.exposed_visibility(l)) };
                if visibility <= 0.0 {
                    return LinkTerm { link: l, visibility: 0.0, factor: 0.0, contribution: 0.0 };
                }
                let (factor, evals) = self.senders.form_factor(link.sender, p, normal);
                work.form_factors += evals;
                LinkTerm { link: l, visibility, factor, contribution: rho * luminance(self.senders.radiosity(link.sender)) * factor }
            })
            .collect();
        let tau = contrast * terms.iter().map(|t| t.visibility * t.contribution).sum::<f64>();
        // Eq. 3 per partly occluded link, with the leaf's visibility as the
        // interpolated value: the point's differs from it by at most
        // max(V, 1 - V).
        let partial: Vec<usize> = (0..terms.len()).filter(|&k| terms[k].visibility > 0.0 && terms[k].visibility < 1.0).collect();
        let d_vis: Vec<f64> = partial.iter().map(|&k| terms[k].contribution * terms[k].visibility.max(1.0 - terms[k].visibility)).collect();
        let mut resample: Vec<bool> = terms.iter().map(|t| unexposed && t.factor > 0.0).collect();
        if !unexposed {
            for (k, r) in partial.iter().zip(budget(&d_vis, tau)) {
                resample[*k] = r;
            }
        }
        let mut h = [0.0; 3];
        for (term, resampled) in terms.iter().zip(resample) {
            if term.visibility <= 0.0 {
                continue;
            }
            let sender = solution.links[term.link].sender;
            let v = if resampled {
                work.count(LinkClass::ResampleBoth);
                let occluder = f64::from(solution.links[term.link].occluder_distance);
                let n = self.shadow_samples(p, sender, occluder, term.contribution, tau, self.params.max_shadow_samples);
                self.fixed_visibility(p, normal, triangle, sender, n, pass, work)
            } else {
                work.count(LinkClass::ResampleFormFactor);
                term.visibility
            };
            let b = self.senders.link_radiosity(term.link);
            (0..3).for_each(|c| h[c] += b[c] * term.factor * v);
        }
        h
    }
}

//! Solving for radiosity on the linked hierarchy: Jacobi gather over the
//! links, then push-pull (Hanrahan et al. 1991, Section 4; with clusters,
//! Sillion 1995):
//!
//! ```text
//! G_n      = sum over links l into n of  V_l F_l B_{s(l)}        (irradiance, W/m²)
//! G_t     += sum over links l into clusters above t of  V_l F_l sum_p w_tp B_p
//! H_n      = G_n + H_{parent(n)}                                 (push down)
//! B_leaf   = S_leaf + rho_leaf H_leaf,  S = E + rho D               (D: luminaires, crate::luminaires)
//! B_inner  = sum over children c of (A_c / A_n) B_c              (pull up)
//! ```
//!
//! repeated until a bound of the remaining error falls below `tolerance`
//! times the largest radiosity ([`solve`]). `B_{s(l)}` of an inner element
//! or cluster sender is, in the last pass, the kernel-weighted mean of its
//! parts ([`SenderTerms`]), not their area mean. The light of a
//! link into a cluster of at most [`crate::receivers::MAX_RECEIVER_TRIANGLES`]
//! triangles goes to each input triangle `t` below it by the triangle's own
//! factor to each part `p` of the sender, `w_tp` ([`ReceiverTerms`]), not
//! to all alike; the link's flux is conserved. A larger cluster still gathers its links and
//! pushes their irradiance to all its children alike. In the last pass a
//! link into an inner element likewise lights the element's parts each by
//! its own factor to the sender ([`ReceiverTerms`]).
//!
//! Nodes are indexed densely, clusters first, then elements
//! ([`Hierarchy::flat`]). A parent always has a smaller index than its
//! children (and an input triangle's leaf cluster comes before it), so push
//! is one forward sweep and pull one backward sweep: every sum has a fixed
//! order, and the result does not depend on threads.

use glam::DVec3;
use crate::elements::{exposed, Hierarchy};
use crate::links::Link;
use crate::mirrors::Couplings;
use crate::receivers::{PartSource, ReceiverTerms};
use crate::rows::Rows;
use crate::visibility::{self, Tracer, PART_VISIBILITY_RAYS};
use rayon::prelude::*;
use schemas::solution::Node;

/// Outcome of one solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Jacobi iterations run.
    pub iterations: usize,
    /// Largest leaf change of the last iteration, relative to the largest
    /// radiosity.
    pub relative_change: f64,
    /// Bound of the remaining error of the last iterate (largest over
    /// leaves and channels), relative to the largest radiosity: `change q /
    /// (1 - q)` (see [`solve`]); +inf where no contraction below 1 was
    /// known.
    pub error_bound: f64,
    /// Contraction factor `q` the bound used (largest over channels).
    pub contraction: f64,
    /// Whether `error_bound` reached the tolerance; `false` means the
    /// iteration cap stopped the solve.
    pub converged: bool,
    /// Geometric extrapolations made (see [`solve`]).
    pub extrapolations: usize,
    /// Estimated ratio of successive changes per channel at the end (0:
    /// none known), for the next solve over refined links.
    pub rates: [f64; 3],
}

/// The hierarchy flattened once per solve: parent, children and area per
/// dense index, so the sweeps neither allocate nor branch on node kinds.
struct Topology {
    parent: Vec<usize>,
    child_start: Vec<usize>,
    children: Vec<usize>,
    area: Vec<f64>,
    /// Exposed fraction of each node's area ([`crate::exposure`]): a
    /// leaf's as measured, an inner node's its children's weighted by
    /// area.
    exposure: Vec<f64>,
    /// Reflectance and source (emission plus reflected luminaire light,
    /// [`Hierarchy::source`]) of leaf elements; `None` for inner nodes.
    leaf: Vec<Option<([f64; 3], [f64; 3])>>,
    /// Transmittance and the dense index of the twin leaf of the leaves of
    /// translucent faces ([`crate::transmission`]); empty without any.
    transmit: Vec<Option<([f64; 3], usize)>>,
}

impl Topology {
    fn new(h: &Hierarchy, n: usize) -> Self {
        let mut t = Topology { parent: vec![usize::MAX; n], child_start: vec![0; n + 1], children: Vec::new(), area: vec![0.0; n], exposure: vec![1.0; n], leaf: vec![None; n], transmit: Vec::new() };
        if h.transmission.is_some() {
            t.transmit = (0..n)
                .map(|i| match h.node(i) {
                    Node::Element(e) if h.elements[e as usize].is_leaf() => h.transmission_of(e).map(|(tau, twin)| (tau, h.flat(Node::Element(twin)))),
                    _ => None,
                })
                .collect();
        }
        for i in 0..n {
            let this = h.node(i);
            t.area[i] = h.area(this);
            if let Some(p) = h.parent(this) {
                t.parent[i] = h.flat(p);
            }
            match this {
                Node::Element(e) if h.elements[e as usize].is_leaf() => {
                    t.leaf[i] = Some((h.reflectance_of(e), h.source(e)));
                }
                _ => t.children.extend(h.children(this).into_iter().map(|c| h.flat(c))),
            }
            t.child_start[i + 1] = t.children.len();
        }
        // Children follow their parents in the dense order.
        for i in (0..n).rev() {
            t.exposure[i] = match h.node(i) {
                Node::Element(e) if h.elements[e as usize].is_leaf() => h.exposure(e),
                _ => crate::exposure::of_children(t.children[t.child_start[i]..t.child_start[i + 1]].iter().map(|&c| (t.area[c], t.exposure[c]))),
            };
        }
        t
    }

    /// Pull: every inner node's radiosity from its children, leaves kept:
    /// their mean weighted by exposed area `A x` (the radiosity of the
    /// node's exposed part, [`crate::exposure`]).
    fn pull(&self, b: &mut [[f64; 3]]) {
        for i in (0..b.len()).rev() {
            if self.leaf[i].is_some() {
                continue;
            }
            let mut mean = [0.0; 3];
            let open_area = self.area[i] * self.exposure[i];
            for &child in &self.children[self.child_start[i]..self.child_start[i + 1]] {
                let weight = if open_area > 0.0 {
                    self.area[child] * self.exposure[child] / open_area
                } else if self.area[i] > 0.0 {
                    self.area[child] / self.area[i]
                } else {
                    0.0
                };
                for c in 0..3 {
                    mean[c] += weight * b[child][c];
                }
            }
            b[i] = mean;
        }
    }
}

/// Pull: every inner node's radiosity from its children, leaves unchanged.
pub fn pull(h: &Hierarchy, b: &mut [[f64; 3]]) {
    Topology::new(h, b.len()).pull(b);
}

/// Ratios of successive changes left out of the rate estimate after the
/// start of a solve or an extrapolation: the first changes mix modes (the
/// direct light with its first bounces, or an extrapolation's error) whose
/// ratios are not the asymptotic one.
pub const TRANSIENT_RATIOS: usize = 3;

/// Smallest change ratio at which a solve extrapolates (see [`solve`]):
/// below it plain iteration converges in a few dozen steps anyway.
pub const EXTRAPOLATE_FROM: f64 = 0.9;

/// How steady the ratio must be to extrapolate: the last
/// [`TRANSIENT_RATIOS`] ratios within this fraction of `1 - q` of each
/// other.
pub const STEADY_RATIO: f64 = 1e-2;

/// Iterates radiosity `b` (one RGB value per node, dense index) to
/// convergence over `links`, which must be sorted by receiver's dense index,
/// with `offsets[i]..offsets[i + 1]` the links into node `i`.
///
/// # Stopping rule
///
/// Jacobi's iterate `x_k` (the leaves' radiosities, one channel) follows
/// `x_{k+1} = E + M x_k`, with `M >= 0` the reflectance times the
/// visibility-weighted factors of the links into a leaf and its ancestors,
/// applied to senders that are area-weighted means of leaves. With the
/// change `delta_k = x_k - x_{k-1}` and any `q` with `||M|| <= q < 1`, the
/// remaining error is
///
/// ```text
/// ||x_inf - x_k|| = ||sum_{j >= 1} M^j delta_k|| <= ||delta_k|| q / (1 - q)
/// ```
///
/// whatever `x_{k-1}` was, and the solve stops when that bound, over the
/// largest radiosity, is at most `tolerance` (per channel; the largest over
/// channels counts). The old rule, `||delta_k||` alone under the tolerance,
/// leaves an error of about `||delta_k|| / (1 - rho)`: 1% on a closed box
/// at `rho` 0.999.
///
/// `q` per channel, in the max-norm over leaves:
///
/// - where `m < 1`, `q = m`, the norm of `M` computed from the links: `m =
///   max over leaves of rho_leaf sum V_l F_l` over the links into the leaf
///   and its ancestors (push adds irradiance down the chain, pull is an
///   area-weighted mean, so every row of `M` sums to at most `m`). The
///   bound is then rigorous. It overestimates the rate where most of the
///   scene reflects less, or sees less, than its most enclosed bright leaf,
///   which costs an iteration or two, not accuracy.
/// - otherwise (a closed scene: the factors out of a leaf sum to 1, up to
///   quadrature error, so `m` is about `rho_max`, and at or over 1 for `rho`
///   near 1) `q` is estimated from the ratios of successive changes,
///   `||delta_k|| / ||delta_{k-1}||`: the largest of the last
///   [`TRANSIENT_RATIOS`], leaving out the first [`TRANSIENT_RATIOS`] of a
///   series (after the start and after each extrapolation) and any whose
///   changes are at round-off level ([`ROUND_OFF_ULPS`]), and at least the
///   ratio known from before the series (`prior_rate`, the previous pass's
///   estimate over the coarser links, or the ratio of the last
///   extrapolation). The ratio converges to the spectral radius of `M` (for
///   a closed uniform room, its reflectance) and never exceeds `||M||`. It
///   is an estimate, not a bound: it assumes the changes decay
///   geometrically, which holds once the slowest mode dominates them, and
///   it underestimates while the ratio still climbs towards its limit; a
///   small change is reached only late in that climb, where the ratio is
///   close to its limit. Where no ratio is known yet, or it is 1 or more,
///   there is no bound (+inf).
///
/// # Extrapolation
///
/// Near `rho = 1` the slowest mode decays by `q` per iteration, so Jacobi
/// needs `ln(tolerance) / ln(q)` iterations: 11,500 at `q` = 0.999. Once
/// the ratio of a channel is at least [`EXTRAPOLATE_FROM`] and steady (the
/// last [`TRANSIENT_RATIOS`] ratios agree to [`STEADY_RATIO`] `(1 - q)`),
/// the changes are one geometric series, and its sum is added (Aitken's
/// extrapolation with a global ratio):
///
/// ```text
/// x_leaf <- max(S_leaf, x_leaf + delta_leaf q / (1 - q))
/// ```
///
/// An error `e` in `q` leaves `e / (1 - q)` of the slowest mode; the faster
/// modes still in `delta` are amplified by `q / (1 - q)` but die within a
/// few iterations. The extrapolated state is just a new starting point:
/// Jacobi converges from any, and the stopping rule above holds for any, so
/// extrapolation changes only how many iterations the tolerance costs (the
/// closed box at 0.999 of `tests/tests/solver_closed_forms.rs` at the
/// default settings: 3 passes of 2,000 iterations, all at the cap, and a
/// bound of 2.4e-3 without; under 100 iterations and 1e-8 with).
///
/// Stopping at `max_iterations` is reported ([`Convergence::converged`]
/// `false`, with the bound reached); the caller says so.
///
/// `senders` says what radiosity each link's sender sends: its area mean,
/// or its parts weighted by the kernel ([`SenderTerms`]).
#[allow(clippy::too_many_arguments)]
pub fn solve(
    h: &Hierarchy,
    links: &[Link],
    offsets: &[usize],
    specular: Option<&Couplings>,
    b: &mut [[f64; 3]],
    tolerance: f64,
    max_iterations: usize,
    prior_rate: [f64; 3],
    senders: &SenderTerms,
    receivers: &ReceiverTerms,
) -> Convergence {
    let n = b.len();
    let topology = Topology::new(h, n);
    // Each link's visibility-weighted form factor, once per solve.
    let coupling: Vec<f64> = links.iter().map(|l| l.form_factor * f64::from(l.visibility.unwrap_or(1.0))).collect();
    let clusters = h.cluster_count();
    let (caps, norm) = capped_norm(&topology, &coupling, offsets, specular, receivers, clusters);
    let mut h_down = vec![[0.0f64; 3]; n];
    let mut delta = vec![[0.0f64; 3]; n];
    let mut convergence =
        Convergence { iterations: 0, relative_change: f64::INFINITY, error_bound: f64::INFINITY, contraction: f64::NAN, converged: false, extrapolations: 0, rates: [0.0; 3] };
    let mut rate = Rate::new(prior_rate);
    while convergence.iterations < max_iterations {
        // What lights the parts of inner elements, once for all of them
        // (crate::receivers::PartSource).
        let sent_to_parts: Vec<[f64; 3]> = receivers
            .part_sources
            .par_iter()
            .map(|source| match source {
                PartSource::Link(l) => senders.radiosity(*l, b),
                PartSource::Parts { terms, .. } => weighted(terms.iter().copied(), b),
            })
            .collect();
        let gathered: Vec<[f64; 3]> = (0..n)
            .into_par_iter()
            .map(|i| {
                // Light through mirrors and glass (crate::mirrors).
                let mut g = specular.map_or([0.0; 3], |s| s.gather(i, b));
                // Each link's factor, capped where it exceeds what one
                // sender can bring (capped_norm); the plain loop where no
                // link into the node is.
                let lighting = Lighting { i, clusters, offsets, receivers, senders, b, sent_to_parts: &sent_to_parts };
                match caps[i].as_slice() {
                    [] => lighting.add(&mut g, |l| coupling[l]),
                    capped => lighting.add(&mut g, |l| coupling[l] * capped.iter().find(|c| c.0 == l).map_or(1.0, |c| c.1)),
                }
                // The exposed part's irradiance (crate::exposure).
                g.map(|x| x / exposed(topology.exposure[i]))
            })
            .collect();
        let (mut change, mut largest) = ([0.0f64; 3], 0.0f64);
        for i in 0..n {
            let above = if topology.parent[i] == usize::MAX { [0.0; 3] } else { h_down[topology.parent[i]] };
            h_down[i] = [0, 1, 2].map(|c| gathered[i][c] + above[c]);
            if let Some((rho, source)) = topology.leaf[i] {
                let mut new = [0, 1, 2].map(|c| source[c] + rho[c] * h_down[i][c]);
                // A translucent face also leaves what its twin receives
                // (this iteration's where the twin comes first, else the
                // last one's).
                if let Some(Some((tau, twin))) = topology.transmit.get(i) {
                    (0..3).for_each(|c| new[c] += tau[c] * h_down[*twin][c]);
                }
                for c in 0..3 {
                    delta[i][c] = new[c] - b[i][c];
                    change[c] = change[c].max(delta[i][c].abs());
                    largest = largest.max(new[c]);
                }
                b[i] = new;
            }
        }
        topology.pull(b);
        convergence.iterations += 1;
        rate.push(change, largest);
        let relative = |x: f64| if largest > 0.0 { x / largest } else { 0.0 };
        convergence.relative_change = relative(change.into_iter().fold(0.0, f64::max));
        let (bound, q) = rate.bound(norm);
        convergence.error_bound = relative(bound);
        convergence.contraction = q;
        if convergence.error_bound <= tolerance {
            convergence.converged = true;
            break;
        }
        let steady = rate.steady();
        if steady.iter().any(Option::is_some) && convergence.iterations < max_iterations {
            for i in 0..n {
                if let Some((_, source)) = topology.leaf[i] {
                    for c in 0..3 {
                        if let Some(q) = steady[c] {
                            b[i][c] = (b[i][c] + delta[i][c] * q / (1.0 - q)).max(source[c]);
                        }
                    }
                }
            }
            topology.pull(b);
            rate.restart(steady);
            convergence.extrapolations += 1;
        }
    }
    convergence.rates = rate.estimates();
    convergence
}

/// What lights node `i` in one iteration of [`solve`].
struct Lighting<'a> {
    i: usize,
    clusters: usize,
    offsets: &'a [usize],
    receivers: &'a ReceiverTerms,
    senders: &'a SenderTerms,
    b: &'a [[f64; 3]],
    sent_to_parts: &'a [[f64; 3]],
}

impl Lighting<'_> {
    /// Adds to `g` the irradiance of the terms into the node
    /// ([`for_each_term`]), each link `l` taken with factor `factor(l)`.
    #[inline]
    fn add(&self, g: &mut [f64; 3], factor: impl Fn(usize) -> f64) {
        for_each_term(self.i, self.clusters, self.offsets, self.receivers, |l, w, source| {
            let f = w * factor(l);
            let sent = match source {
                Source::Sender => self.senders.radiosity(l, self.b),
                Source::Node(p) => self.b[p],
                Source::Part(k) => self.sent_to_parts[k],
            };
            g.iter_mut().zip(sent).for_each(|(g, s)| *g += f * s);
        });
    }
}

/// Parts a link's sender is first resolved into by [`SenderTerms`], level
/// by level, before `open_near_parts` opens those its receiver needs
/// finer: on the Cornell box 16 gave within 0.01% of 64's surface means,
/// in 2/3 of its time, at the default settings of `223d650`; 4 left a
/// third of the gain.
pub const MAX_SENDER_PARTS: usize = 16;

/// A sender whose every leaf's radiosity lies within this fraction of its
/// mean (per channel), times `1 - q` ([`Senders::Resolved`]), sends its
/// mean ([`SenderTerms`]): the kernel-weighted mean of its parts could
/// differ from it by at most that, the links into a receiver together by
/// at most that fraction of its reflected radiosity, and the solution,
/// which interreflection multiplies such an error by up to `1 / (1 - q)`,
/// by at most this fraction.
pub const UNIFORM_SENDER: f64 = 1e-3;

/// `1 - q` in [0, 1], `q` a solve's rate of convergence: how much a
/// one-signed error per link must shrink for the solution's to stay within
/// it, as interreflection multiplies it by up to `1 / (1 - q)` (0 where
/// `q` is 1 or more). Scales [`UNIFORM_SENDER`] and the form factors'
/// quadrature tolerance ([`crate::links::Allowance::quadrature`]).
pub fn damping(q: f64) -> f64 {
    (1.0 - q).clamp(0.0, 1.0)
}

/// What radiosity a link's sender sends in a solve.
#[derive(Clone, Copy)]
pub enum Senders<'a> {
    /// The sender's area mean `B_s` (one term per link): enough to decide
    /// refinement, and the cheapest.
    Means,
    /// Its parts weighted by the kernel ([`SenderTerms`]), where its
    /// leaves stray from its mean (`resolution`): for the final solve; up
    /// to [`MAX_SENDER_PARTS`] terms per link.
    Resolved {
        /// The solved radiosity, and where it is uniform.
        resolution: Resolution<'a>,
        /// What the parts' visibility is traced with.
        tracer: Tracer<'a>,
    },
}

/// What the last solve resolves senders by: a solved radiosity and how far
/// each element's leaves stray from it.
#[derive(Clone, Copy)]
pub struct Resolution<'a> {
    /// Radiosity per node, dense index (a solved iterate).
    radiosity: &'a [[f64; 3]],
    /// Per element, its leaves' largest deviation from its radiosity
    /// ([`crate::links::leaf_deviation`] of `radiosity`).
    deviation: &'a [[f64; 3]],
    /// Per channel, the fraction of its mean a sender's leaves may stray
    /// by and it still send its mean: [`UNIFORM_SENDER`] times
    /// [`damping`] of the rate the solve that gave `radiosity` converged
    /// at ([`Convergence::rates`]; 0 unknown).
    uniform: [f64; 3],
}

impl<'a> Resolution<'a> {
    /// `radiosity` with its `deviation`, solved at per-channel rates `rates`.
    pub fn new(radiosity: &'a [[f64; 3]], deviation: &'a [[f64; 3]], rates: [f64; 3]) -> Self {
        Resolution { radiosity, deviation, uniform: rates.map(|q| UNIFORM_SENDER * damping(q)) }
    }

    /// Whether link `l`'s sender is an element whose leaves all lie within
    /// `uniform` (per channel, a fraction) of its mean.
    pub fn uniform_sender(&self, h: &Hierarchy, l: &Link) -> bool {
        let Node::Element(e) = l.sender else { return false };
        let (mean, spread) = (self.radiosity[h.flat(l.sender)], self.deviation[e as usize]);
        (0..3).all(|c| spread[c] <= self.uniform[c] * mean[c])
    }
}

/// What each link's sender sends, as the gather reads it. A link carries
/// `F_rs` (exact over the whole sender) times one radiosity; the area mean
/// `B_s` of an inner element sender is exact only where its radiosity is
/// uniform. Where it varies, the receiver gets
///
/// ```text
/// sum over parts j of s of  F_rj B_j  =  F_rs sum_j w_j B_j,   w_j = F_rj / sum_k F_rk
/// ```
///
/// so its parts `j` (its clusters opened down to input triangles and its
/// elements to their descendants, level by level while they are at most
/// [`MAX_SENDER_PARTS`], then further where the kernel and the radiosity
/// vary over a part together, `open_near_parts`) are weighted by their share of the kernel seen from
/// an element receiver's centroid, Lambert's point-to-polygon factor (002
/// Eq. 3, one-sided: the parts of a cluster that face away weigh nothing;
/// a part that touches the receiver, over the whole receiver,
/// [`Hierarchy::weight_between`])
/// times the part's opaque fraction under an alpha mask
/// ([`Hierarchy::factor_to_element`], as the link's own factor counts it:
/// a part's radiosity is per opaque area, so a transparent part, radiosity
/// 0, weighed by its geometry alone diluted what the opaque ones send, a
/// receiver of an alpha-striped floor 0.41% dark in all, test
/// `surface_solver.rs`), not by their area. The two differ by the covariance over the sender of
/// the kernel and the radiosity, which has one sign wherever the parts of a
/// sender nearer the receiver are brighter (or darker) than its mean, and
/// so adds up over the links into a receiver instead of averaging out: on
/// the Cornell box without its blocks, the area means made every surface's
/// mean radiosity 0.24% (floor) to 0.66% (ceiling) darker than the
/// radiosity equation over the same leaves with a quadrature kernel (issue
/// 10; the leaves' residual in that equation, +0.10% to +0.31% per
/// surface, is now +0.02% to +0.05%). On the Cornell box at the default
/// settings, against Mitsuba: the preview's mean error -1.16% -> -0.76%
/// (every surface within 0.9%), the full gather's relative RMSE 0.99% ->
/// 0.81% (ceiling -1.14% -> -0.81%, tall block -1.49% -> -1.12%), for a
/// last solve of about 9 s more on 2 loaded cores. Only the last pass
/// resolves senders: refinement needs the radiosity's shape, not this
/// last fraction of a percent. Cluster receivers, leaf senders, clusters
/// of more input triangles than that and links no part of which the
/// receiver sees keep the sender's mean. The weights are computed once per
/// solve and sum to 1, so `||M||` and the stopping rule are unchanged.
///
/// **Partly occluded links weigh each part by its own visibility.** The
/// transfer is `sum_j F_rj V_rj B_j` and the link carries `F_rs V_rs`, so
/// where `0 < V_rs < 1` the weights are `w_j = F_rj V_rj / sum_k F_rk
/// V_rk`, `V_rj` the kernel-weighted visible fraction between the receiver
/// and part `j` ([`visibility::visible_factor`]). Visibility and radiosity are correlated over a sender: an
/// occluder hides from a receiver the parts it also shadows from the
/// light (the floor behind a block, seen from the ceiling beside the
/// lamp), so the unoccluded weights send a mean darker than the visible
/// parts', and the error has one sign on every such link. On the built-in
/// Cornell box (full gather against Mitsuba) the relative RMSE went from
/// 1.74% to 1.36% at `EPS` 5e-3, 1.62% to 1.30% at 3e-3 and 1.08% to
/// 0.85% at 1e-3 (ceiling -1.95% -> -1.12% at 3e-3); the leaves' reflected
/// power at 3e-3, unclustered, from 0.55% to 0.17% under the fine solve's.
///
/// **Uniform senders keep their mean.** With weights `w_j >= 0` summing
/// to 1, `|sum_j w_j B_j - B_s| <= max_j |B_j - B_s|`, at most the largest
/// deviation of a leaf below the sender from its mean. Where that is under
/// [`UNIFORM_SENDER`] `B_s` in every channel, the link sends `B_s`: its
/// receiver's radiosity moves by at most that fraction of what the link
/// brings it, and by all such links together by at most that fraction of
/// its reflected radiosity. The deviation is read from a solved iterate
/// (the last pass solves with means first, then with these terms). On the
/// Cornell box at `EPS` 1e-3 this resolves 322k of the 544k links (4.46M
/// terms before), every leaf within 1.5e-5 of resolving them all, the
/// full gather's relative RMSE the same to 4 digits (1.194%), the last
/// solve's terms about 40% cheaper.
///
/// **Times `1 - q`.** Each such link errs with the same sign wherever the
/// parts nearer its receiver are brighter (or darker) than the mean, and
/// interreflection multiplies what they miss by up to `1 / (1 - q)`, `q`
/// the rate the means' solve converged at (per channel). With the fraction
/// alone a closed box of reflectance 0.999 lost 0.86% of its mean
/// radiosity at `EPS` 1e-3, 0.32% at 1e-4 and 0.07% at 1.5e-5 (which had
/// set the default `EPS`); times `1 - q` (0.999 there), 0.009% and 0.003%
/// at 1e-3 and 1e-4, 1.15M of its 1.25M links resolved at 1e-3 and the
/// last solve 0.9 s longer. On the Cornell box `q` is 0.43 to 0.55 per
/// channel and the solution is unchanged (721k links of 1.22M resolved
/// at the default `EPS`, 718k before).
pub struct SenderTerms {
    /// Dense index of each link's sender (its area mean).
    senders: Vec<usize>,
    /// Per link, its sender's kernel-weighted parts; none: the mean.
    parts: Rows<f64>,
    /// Visibility rays cast for the parts.
    rays: usize,
    /// Per link, what its sender sends beyond its parts' (or its own)
    /// radiosity, W/m² RGB: the measured slopes inside them as the
    /// receiver sees them ([`crate::slopes::sender_offsets`]); empty: none.
    offsets: Vec<[f64; 3]>,
}

impl SenderTerms {
    /// The terms of every link of `links` (in order), resolved or not.
    pub fn new(h: &Hierarchy, links: &[Link], senders: Senders) -> Self {
        let (parts, rays) = match senders {
            Senders::Means => (Rows::default(), 0),
            Senders::Resolved { resolution, tracer } => {
                let (lists, rays): (Vec<_>, Vec<usize>) = links
                    .par_iter()
                    .map(|l| if resolution.uniform_sender(h, l) { (Vec::new(), 0) } else { Self::of_link(h, l, resolution, tracer) })
                    .unzip();
                (Rows::from_lists(lists), rays.iter().sum())
            }
        };
        SenderTerms { senders: links.iter().map(|l| h.flat(l.sender)).collect(), parts, rays, offsets: Vec::new() }
    }

    /// Visibility rays cast for the parts of partly occluded links.
    pub fn rays(&self) -> usize {
        self.rays
    }

    /// How many links send their sender's parts rather than its mean.
    pub fn resolved(&self) -> usize {
        (0..self.senders.len()).filter(|&l| self.parts.row(l).next().is_some()).count()
    }

    /// The terms `(dense index, w_j)` of link `l`'s sender, and the rays
    /// cast for them (a partly occluded link's parts' visibility, traced
    /// with `tracer` within the link's shaft). The parts are opened as far as
    /// `open_near_parts` needs before any visibility ray is cast.
    fn of_link(h: &Hierarchy, l: &Link, resolution: Resolution, tracer: Tracer) -> (Vec<(usize, f64)>, usize) {
        let Node::Element(r) = l.receiver else { return (vec![(h.flat(l.sender), 1.0)], 0) };
        Self::seen_from(h, r, l, resolution, tracer)
    }

    /// [`Self::of_link`] as element `r`, the link's receiver or a part of
    /// it, sees the sender from its centroid (a part touching `r`, from
    /// all of `r`: [`Hierarchy::weight_between`];
    /// [`crate::receivers::NEAR_RECEIVER`]).
    pub(crate) fn seen_from(h: &Hierarchy, r: u32, l: &Link, resolution: Resolution, tracer: Tracer) -> (Vec<(usize, f64)>, usize) {
        let whole = (vec![(h.flat(l.sender), 1.0)], 0);
        let x = h.centroid(r);
        let partly_occluded = l.partly_occluded();
        let tracer = if partly_occluded { tracer.within(h, l.receiver, l.sender) } else { tracer };
        let mut rays = 0;
        // A part's weight `F_rj V_rj` and visible fraction `V_rj`: traced
        // where the link is partly occluded, unless its parent part was
        // wholly visible or wholly hidden.
        let mut weigh = |e: u32, parent: Option<f64>| {
            let factor = h.weight_between(r, e);
            match parent {
                _ if !partly_occluded => (factor, 1.0),
                Some(v) if v == 0.0 || v == 1.0 => (factor * v, v),
                _ => {
                    let (seen, cast) = visibility::visible_factor(h, tracer, r, e, factor, if parent.is_some() { CHILD_PART_RAYS } else { SENDER_PART_RAYS }, None);
                    rays += cast;
                    (seen, if factor > 0.0 { seen / factor } else { 1.0 })
                }
            }
        };
        let parts: Option<Vec<Part>> = h.parts(l.sender, MAX_SENDER_PARTS).into_iter().map(|p| if let Node::Element(e) = p { Some(Part::new(e, weigh(e, None))) } else { None }).collect();
        let Some(mut parts) = parts else { return whole };
        open_near_parts(h, &mut parts, x, resolution, &mut weigh);
        let total: f64 = parts.iter().map(|p| p.weight).sum();
        if parts.len() < 2 || total <= 0.0 || !total.is_finite() {
            return (whole.0, rays);
        }
        (parts.iter().map(|p| (h.flat(Node::Element(p.element)), p.weight / total)).collect(), rays)
    }

    /// The radiosity each link sends with radiosity `b`, as the solve
    /// that used these terms sent it: the links' unoccluded irradiance in
    /// the solution is `F_rs` times this (with the last pass's resolved
    /// terms), so that a leaf's radiosity is what its links bring.
    pub fn sent(&self, b: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.senders.len()).into_par_iter().map(|l| self.radiosity(l, b)).collect()
    }

    /// The terms `(flat node index, w_j)` of what link `l` sends: its
    /// sender's kernel-weighted parts, or the sender itself at weight 1.
    pub fn terms(&self, l: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let mut parts = self.parts.row(l).map(|(node, &w)| (node, w)).peekable();
        let whole = parts.peek().is_none().then_some((self.senders[l], 1.0));
        whole.into_iter().chain(parts)
    }

    /// Adds `offsets` (per link, in order) to what each link sends.
    pub fn set_offsets(&mut self, offsets: Vec<[f64; 3]>) {
        self.offsets = offsets;
    }

    /// The radiosity link `l` sends, `sum_j w_j B_j`, plus its offset if
    /// any (not below 0).
    fn radiosity(&self, l: usize, b: &[[f64; 3]]) -> [f64; 3] {
        // Self::terms by hand, with no iterator chain: this runs per link
        // per iteration (the chain cost 1% to 2% of the solve).
        let mut parts = self.parts.row(l).peekable();
        let sent = if parts.peek().is_none() { b[self.senders[l]] } else { weighted(parts.map(|(node, &w)| (node, w)), b) };
        match self.offsets.get(l) {
            Some(offset) => std::array::from_fn(|c| (sent[c] + offset[c]).max(0.0)),
            None => sent,
        }
    }
}

/// Visibility rays for each part of a partly occluded link's sender
/// ([`SenderTerms::seen_from`]), half of [`PART_VISIBILITY_RAYS`]: the
/// receiver's parts' rays decide where its light goes, the sender's only
/// how its parts' radiosities mix. On the built-in Cornell box (preview
/// against Mitsuba, seeds 1-8, each leaf's own value shown) 2, 4, 8 and
/// 32 rays gave 1.876%, 1.864%, 1.861% and 1.864% relative RMSE at `EPS`
/// 1e-3, and 4 1.269% against 1.268% for 8 at 6e-4; with the leaf
/// gradients shown, 4 against 8: 1.599% and 1.597% at 1e-3 (the worst
/// surface per seed 0.39-1.07% and 0.42-1.07%), 1.111% and 1.109% at
/// 6e-4 (0.21-0.39% and 0.23-0.41%), the solve 1.4% and 2.6% faster (one
/// thread, interleaved medians of 9 and 7); the receivers' parts at 4
/// rays instead of 8 gave 2.165% (own values).
pub const SENDER_PART_RAYS: usize = PART_VISIBILITY_RAYS / 2;

/// Visibility rays for each child of a part `open_near_parts` opens
/// where the part's own [`SENDER_PART_RAYS`] found it partly visible
/// (a child of a wholly visible or wholly hidden part takes its
/// fraction): the four children together cast twice what their parent
/// does (what it did when this was measured, with 8). On
/// the built-in Cornell box (preview against Mitsuba, `EPS` 4e-4, seeds
/// 1-5) the surface means came out within 0.02% of 8 rays per child, for
/// 236k fewer rays (of 1.13M part rays).
pub const CHILD_PART_RAYS: usize = PART_VISIBILITY_RAYS / 4;

/// Most parts `open_near_parts` opens a sender into.
pub const MAX_NEAR_PARTS: usize = 64;

/// Opens the parts `(element, w_j)` of a sender (weights from point `x`,
/// normal `n`, not yet normalised) into their children where a part's
/// area mean stands for its leaves too coarsely: part `j` sends `B_j`
/// where its leaves send their kernel-weighted mean, which differs from it
/// by at most `d_j` (its leaves' largest deviation from `B_j`,
/// [`crate::links::leaf_deviation`]) times the kernel's relative variation
/// over the part, about `min(1, 2 r_j / |x - c_j|)` (`r_j` its radius,
/// `c_j` its centroid); weighted, by
///
/// ```text
/// e_j = w_j d_j min(1, 2 r_j / |x - c_j|) / sum_k w_k
/// ```
///
/// A part opens while `e_j` exceeds `uniform` (per channel, the fraction
/// [`UNIFORM_SENDER`] that a uniform sender may err by) times what the
/// parts send, largest first, until there are [`MAX_NEAR_PARTS`]. Where a
/// sender passes under a receiver (a floor element at the base of a
/// block's face) its parts next to the receiver hold the contact shadow
/// and are dim, and the kernel is largest there: sixteen parts of the
/// same level let the bright far side of each near part count as near. On
/// the built-in Cornell box at `EPS` 7e-4 (seed 1) a level-1 floor element
/// sent the short block's camera face 0.225 where its 40 leaves, each
/// under the kernel, send 0.188 (+20%; +40% into the leaves at the
/// face's base), and the face's light from the floor was 2.5% high
/// against a brute-force sum over the same leaves (0.03% with the parts
/// opened). Over every surface (preview against Mitsuba, seeds 1-5, mean
/// per surface): at `EPS` 4e-4 the ceiling went from -0.49% to -0.05%,
/// the tall block from -0.45% to -0.23%, the walls from -0.26..-0.32% to
/// -0.10..-0.16% (the short block +0.55% -> +0.61%), the worst surface
/// per seed from 0.52-0.69% to 0.35-0.74%; at 7e-4 from 1.70-2.51% to
/// 0.94-2.09% (ceiling -0.92% -> -0.07%, short block +2.00% -> +1.41%);
/// at 1e-4 from 0.21-0.35% to 0.14-0.28%. The solve takes about 15% longer
/// at 4e-4 (one thread, medians of 5 interleaved: 0.60 s against 0.52 s),
/// 4% at 1e-4. Opening only down from 4 parts instead of 16 was cheaper
/// (+7%) but left the partly occluded links' visibility too coarse at
/// coarse `EPS` (ceiling -3.7% at 7e-4); a looser bound (4 or 16 times
/// [`UNIFORM_SENDER`]) kept part of the ceiling's error (-0.16%, -0.30%
/// at 4e-4).
fn open_near_parts(h: &Hierarchy, parts: &mut Vec<Part>, x: DVec3, resolution: Resolution, weigh: &mut impl FnMut(u32, Option<f64>) -> (f64, f64)) {
    let Resolution { radiosity, deviation, uniform } = resolution;
    // `total` and what the parts send are those of the first parts: the
    // opened parts change them by about the error they remove.
    let total: f64 = parts.iter().map(|p| p.weight).sum();
    if !(total > 0.0 && total.is_finite()) {
        return;
    }
    let sent: [f64; 3] = std::array::from_fn(|c| parts.iter().map(|p| p.weight * radiosity[h.flat(Node::Element(p.element))][c]).sum::<f64>() / total);
    // `e_j` over its allowance.
    let excess = |p: &Part| {
        let variation = (2.0 * h.radius(p.element) / h.centroid(p.element).distance(x)).min(1.0);
        (0..3).map(|k| p.weight / total * deviation[p.element as usize][k] * variation / (uniform[k] * sent[k])).filter(|r| r.is_finite()).fold(0.0, f64::max)
    };
    h.open_parts(parts, MAX_NEAR_PARTS, |p| p.element, |p| Some(excess(p)).filter(|&e| e > 1.0), |c, parent| Part::new(c, weigh(c, Some(parent.visible))));
}

/// A part of a sender as [`SenderTerms`] weighs it.
struct Part {
    element: u32,
    /// Its factor from the receiver times its visible fraction (not
    /// normalised).
    weight: f64,
    /// Its visible fraction from the receiver (1 where not traced).
    visible: f64,
}

impl Part {
    fn new(element: u32, (weight, visible): (f64, f64)) -> Self {
        Part { element, weight, visible }
    }
}

/// `sum_j w_j B_j` over `terms` `(j, w_j)`, `j` a dense node index into
/// `b`: what a sender's parts send ([`SenderTerms`]), and what they send a
/// cluster's triangle ([`PartSource::Parts`]).
fn weighted(terms: impl Iterator<Item = (usize, f64)>, b: &[[f64; 3]]) -> [f64; 3] {
    let mut sent = [0.0; 3];
    for (node, w) in terms {
        for c in 0..3 {
            sent[c] += w * b[node][c];
        }
    }
    sent
}


/// Changes below this many units of round-off of the largest radiosity say
/// nothing about the rate: sums over thousands of links jitter by about a
/// thousand ulps.
pub const ROUND_OFF_ULPS: f64 = 1e4;

/// What a solve knows of its rate of convergence, per channel.
struct Rate {
    /// Largest leaf changes since the start or the last extrapolation.
    changes: Vec<[f64; 3]>,
    /// Round-off level of a change (see [`ROUND_OFF_ULPS`]), of the newest
    /// iterate.
    noise: f64,
    /// A ratio known from before the newest series of changes: the previous
    /// pass's, or the one the last extrapolation used (0: none).
    floor: [f64; 3],
}

impl Rate {
    fn new(prior: [f64; 3]) -> Self {
        Rate { changes: Vec::new(), noise: 0.0, floor: prior.map(|q| if q.is_finite() && q < 1.0 { q.max(0.0) } else { 0.0 }) }
    }

    fn push(&mut self, change: [f64; 3], largest: f64) {
        self.changes.push(change);
        self.noise = ROUND_OFF_ULPS * f64::EPSILON * largest;
    }

    /// Ratio of change `k` to change `k - 1` in channel `c`, if both are
    /// above round-off and `k` is past the transient.
    fn ratio(&self, k: usize, c: usize) -> Option<f64> {
        let (before, now) = (self.changes[k - 1][c], self.changes[k][c]);
        (k > TRANSIENT_RATIOS && before > self.noise && now > self.noise).then(|| now / before)
    }

    /// The ratio `q` of channel `c` (see [`solve`]): the largest of the last
    /// [`TRANSIENT_RATIOS`] trusted ratios and the floor; `None` if neither
    /// is known.
    fn estimate(&self, c: usize) -> Option<f64> {
        let k = self.changes.len();
        let recent = (k.saturating_sub(TRANSIENT_RATIOS).max(1)..k).filter_map(|j| self.ratio(j, c)).fold(0.0f64, f64::max);
        let q = recent.max(self.floor[c]);
        (q > 0.0).then_some(q)
    }

    /// After an extrapolation with ratios `q`: the changes start a new
    /// series, whose first ratios are transient; `q` stands in for them.
    fn restart(&mut self, q: [Option<f64>; 3]) {
        self.changes.clear();
        for c in 0..3 {
            if let Some(q) = q[c] {
                self.floor[c] = q;
            }
        }
    }

    /// The bound `change q / (1 - q)` of the remaining error (absolute,
    /// largest over channels) and the largest `q` used; `q` per channel is
    /// the matrix norm where it is under 1, else [`Rate::estimate`] (see
    /// [`solve`]). A channel that did not change has no error left.
    fn bound(&self, norm: [f64; 3]) -> (f64, f64) {
        let change = self.changes[self.changes.len() - 1];
        let (mut bound, mut largest_q) = (0.0f64, 0.0f64);
        for c in 0..3 {
            if change[c] == 0.0 {
                continue;
            }
            let q = if norm[c] < 1.0 {
                norm[c]
            } else if let Some(q) = self.estimate(c) {
                q
            } else {
                return (f64::INFINITY, f64::NAN);
            };
            largest_q = largest_q.max(q);
            if q >= 1.0 || q.is_nan() {
                return (f64::INFINITY, q);
            }
            bound = bound.max(change[c] * q / (1.0 - q));
        }
        (bound, largest_q)
    }

    /// The ratio estimates per channel, to carry to the next pass.
    fn estimates(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.estimate(c).unwrap_or(0.0))
    }

    /// Per channel, the ratio to extrapolate with, where the last
    /// [`TRANSIENT_RATIOS`] ratios are trusted, steady and at least
    /// [`EXTRAPOLATE_FROM`] (see [`solve`]).
    fn steady(&self) -> [Option<f64>; 3] {
        let k = self.changes.len();
        if k < 2 * TRANSIENT_RATIOS + 1 {
            return [None; 3];
        }
        std::array::from_fn(|c| {
            let ratios: Option<Vec<f64>> = (k - TRANSIENT_RATIOS..k).map(|j| self.ratio(j, c)).collect();
            let ratios = ratios?;
            let q = ratios[ratios.len() - 1];
            let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
            ((EXTRAPOLATE_FROM..1.0).contains(&q) && hi - lo <= STEADY_RATIO * (1.0 - q)).then_some(q)
        })
    }
}

/// Where the radiosity of a term of the gather comes from
/// ([`for_each_term`]).
#[derive(Clone, Copy)]
enum Source {
    /// What the term's link sends ([`SenderTerms`]).
    Sender,
    /// Node `p` (dense index): a part of the sender of a link into a
    /// cluster above the node, which is one of the cluster's input
    /// triangles.
    Node(usize),
    /// Part source `k` ([`ReceiverTerms::part_sources`]): the node is a
    /// part of the receiver of a link into an inner element above it.
    Part(usize),
}

/// Calls `visit(l, w, source)` for each term the gather sums into node `i`
/// (dense index), link `l` bringing `w` times its factor `V F` of what
/// `source` sends: the node's own links not distributed by weight (`w` 1),
/// then its weights as an input triangle of a cluster receiver (`w_tp`),
/// then as a part of an element receiver (`w_j`). The gather
/// ([`Lighting::add`]) and the norm ([`terms_sum`], [`link_factors`]) see
/// the same terms through it.
#[inline]
fn for_each_term(i: usize, clusters: usize, offsets: &[usize], receivers: &ReceiverTerms, mut visit: impl FnMut(usize, f64, Source)) {
    for l in (offsets[i]..offsets[i + 1]).filter(|&l| !receivers.distributed(l)) {
        visit(l, 1.0, Source::Sender);
    }
    let element = i.checked_sub(clusters);
    for (l, &(p, w)) in element.into_iter().flat_map(|e| receivers.of_triangle(e)) {
        visit(l, w, Source::Node(p));
    }
    for (k, &w) in element.into_iter().flat_map(|e| receivers.of_element(e)) {
        visit(receivers.part_sources[k].link(), w, Source::Part(k));
    }
}

/// Calls `visit(l, f, source)` with each term's total factor into node `i`
/// ([`for_each_term`]): `w V F`, where a part source's `w_j` also takes
/// what its own weights sum to ([`PartSource::weight`]).
fn for_each_factor(i: usize, clusters: usize, coupling: &[f64], offsets: &[usize], receivers: &ReceiverTerms, mut visit: impl FnMut(usize, f64, Source)) {
    for_each_term(i, clusters, offsets, receivers, |l, w, source| {
        let f = w * coupling[l];
        visit(l, if let Source::Part(k) = source { f * receivers.part_sources[k].weight() } else { f }, source);
    });
}

/// The sum of the factors into node `i` ([`for_each_factor`]), added as
/// the norm always added them (the own links' sum, then the two weights'
/// sums together), so that where no link is capped the norm, the stopping
/// rule and the solution keep every bit.
fn terms_sum(i: usize, clusters: usize, coupling: &[f64], offsets: &[usize], receivers: &ReceiverTerms) -> f64 {
    let (mut own, mut triangles, mut parts) = (0.0, 0.0, 0.0);
    for_each_factor(i, clusters, coupling, offsets, receivers, |_, f, source| match source {
        Source::Sender => own += f,
        Source::Node(_) => triangles += f,
        Source::Part(_) => parts += f,
    });
    own + (triangles + parts)
}

/// Each link's total factor into node `i` (dense index), over the terms
/// the gather sums ([`for_each_factor`]), sorted by link.
fn link_factors(i: usize, clusters: usize, coupling: &[f64], offsets: &[usize], receivers: &ReceiverTerms) -> Vec<(usize, f64)> {
    let mut factors = Vec::new();
    for_each_factor(i, clusters, coupling, offsets, receivers, |l, f, _| factors.push((l, f)));
    factors.sort_unstable_by_key(|f: &(usize, f64)| f.0);
    factors.dedup_by(|next, kept| {
        let same = next.0 == kept.0;
        if same {
            kept.1 += next.1;
        }
        same
    });
    factors
}

/// The links whose factor into a node exceeds what its exposed part can
/// receive from one sender, each with the scale that brings it down to
/// that, per node (dense index; mostly empty), and the max-norm of the
/// iteration matrix so capped, per channel (see [`solve`]).
///
/// A point's factor to a sender is at most 1 (the sender covering its
/// whole hemisphere), so the irradiance one link brings to node `i`'s
/// exposed part is at most the sender's radiosity: the link's factor into
/// `i`, averaged over all of `i`, at most `exposed(x_i)` before the gather
/// divides by it ([`crate::exposure`]). Estimates can exceed it where a
/// kernel is a step: a floor under a box's bottom face 0.1 mm above it
/// (McGuire's `CornellBox-Glossy`) sees that face with factor 1 over the
/// footprint and 0 beside it, the link's factor is right, and the parts
/// that share it by their centroids' factors ([`crate::receivers`]) found
/// an eighth of the footprint, so two floor leaves each took a factor of
/// 2.08 from the face. With the face lighting them back, a leaf's row of
/// the iteration matrix reached 1.5 and Jacobi diverged (radiosity 5e26
/// after 2,000 iterations). Capped, no link brings a node more light than
/// its sender's radiosity, and the iteration converges (134 iterations at
/// `EPS` 1e-4). On the built-in Cornell box no link reaches the cap: its
/// solutions keep every bit.
///
/// The norm is the largest `rho_leaf sum V F` over the links into a leaf
/// and its ancestors, each term capped (a cluster's links counted on its
/// input triangles, times their weights `w_tp`).
fn capped_norm(topology: &Topology, coupling: &[f64], offsets: &[usize], specular: Option<&Couplings>, receivers: &ReceiverTerms, clusters: usize) -> (Vec<Vec<(usize, f64)>>, [f64; 3]) {
    let n = topology.parent.len();
    let mut caps = vec![Vec::new(); n];
    // Visibility-weighted factor sum into each node and its ancestors
    // (parents come first, one forward sweep).
    let mut chain = vec![0.0f64; n];
    let mut norm = [0.0f64; 3];
    for i in 0..n {
        let most = exposed(topology.exposure[i]);
        let mut links = terms_sum(i, clusters, coupling, offsets, receivers);
        // Terms that together stay under the cap leave every link under it.
        if links > most {
            let factors = link_factors(i, clusters, coupling, offsets, receivers);
            caps[i] = factors.iter().filter(|f| f.1 > most).map(|&(l, f)| (l, most / f)).collect();
            links = factors.iter().map(|f| f.1.min(most)).sum();
        }
        let own = (links + specular.map_or(0.0, |s| s.row_sum(i))) / most;
        chain[i] = own + if topology.parent[i] == usize::MAX { 0.0 } else { chain[topology.parent[i]] };
        if let Some((rho, _)) = topology.leaf[i] {
            for c in 0..3 {
                norm[c] = norm[c].max(rho[c] * chain[i]);
            }
        }
    }
    // A translucent leaf's row also holds tau times its twin's chain.
    for (i, transmit) in topology.transmit.iter().enumerate() {
        if let (Some((rho, _)), Some((tau, twin))) = (topology.leaf[i], transmit) {
            for c in 0..3 {
                norm[c] = norm[c].max(rho[c] * chain[i] + tau[c] * chain[*twin]);
            }
        }
    }
    (caps, norm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::links::leaf_deviation;
    use crate::test_scenes::{split_levels, FloorAndWall};
    use radiometry::form_factor::point_to_polygon;
    use test_support::closed_form::mean_over_triangle;

    /// A floor triangle subdivided five levels (1,024 leaves) whose leaves
    /// are dim within 0.25 m of the wall it meets (a contact shadow: 0.05
    /// at the wall, 1 from 0.25 m out), sending to a wall element at the
    /// wall's base. What the link sends against the floor leaves' radiosity
    /// weighted by Lambert's factor to each leaf averaged over the receiver
    /// (002 Eq. 3, a 64-point midpoint rule), summed here leaf by leaf
    /// apart from the solver: within 4% (+3.2%, its 64 parts; the sixteen
    /// of the first level alone -1.6%). With every part weighed from the
    /// receiver's centroid, as before [`Hierarchy::weight_between`], +5.9%;
    /// with the parts near but not touching it weighed over all of it too,
    /// -0.2%.
    #[test]
    fn a_sender_passing_under_its_receiver_sends_its_leaves_kernel_weighted_mean() {
        let mut scene = FloorAndWall::new(1.5);
        let h = &mut scene.h;
        let leaves = split_levels(h, 0, 5);
        let receiver = split_levels(h, 2, 1).into_iter().min_by(|&a, &b| h.centroid(a).z.total_cmp(&h.centroid(b).z)).unwrap();
        let mut b = vec![[0.0; 3]; h.cluster_count() + h.elements.len()];
        for &e in &leaves {
            let from_wall = 1.0 - h.centroid(e).x;
            b[h.flat(Node::Element(e))] = [0.05 + 0.95 * (from_wall / 0.25).min(1.0); 3];
        }
        pull(h, &mut b);
        let deviation = leaf_deviation(h, &b);
        let (scene, occluders) = crate::test_scenes::traced(h);
        let link = Link { receiver: Node::Element(receiver), sender: Node::Element(0), form_factor: 0.1, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: false };
        let senders = Senders::Resolved { resolution: Resolution::new(&b, &deviation, [0.0; 3]), tracer: Tracer::new(&scene, &occluders, 1, 16) };
        let sent = SenderTerms::new(h, &[link], senders).sent(&b)[0][0];
        let corners = h.elements[receiver as usize].points.map(|p| p.to_array());
        let (mut weighted, mut total) = (0.0, 0.0);
        for &e in &leaves {
            let leaf = &h.elements[e as usize].points;
            let f = mean_over_triangle(&corners, 3, &|x| point_to_polygon(DVec3::from(x), -DVec3::X, leaf));
            weighted += f * b[h.flat(Node::Element(e))][0];
            total += f;
        }
        let reference = weighted / total;
        assert!((sent / reference - 1.0).abs() < 4e-2, "sent {sent} against {reference}");
    }
}

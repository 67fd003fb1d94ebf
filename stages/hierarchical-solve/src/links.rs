//! Links and the refinement oracle of hierarchical radiosity (Hanrahan,
//! Salzman, Aupperle, "A rapid hierarchical radiosity algorithm", SIGGRAPH
//! 1991): a link carries light from a sender to a receiver element; a link
//! whose transport is too coarse is replaced by links from or to the
//! children of one of the two.

use crate::detail::Detail;
use crate::elements::Hierarchy;
use crate::transfer;
use glam::DVec3;
use radiometry::form_factor::{point_to_one_sided_polygon, triangle_to_polygon, AreaFactor, Quadrature, QUADRATURE_TOLERANCE};
use schemas::solution::Node;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A link: `receiver` gathers from `sender`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    /// Receiving element or cluster.
    pub receiver: Node,
    /// Sending element or cluster.
    pub sender: Node,
    /// Unoccluded form factor F_rs: between elements, the receiver-area
    /// mean of Lambert's point-to-polygon factor to the sender (002 Eq. 3);
    /// with a cluster at either end, the Monte Carlo estimate of
    /// [`transfer`], which a link into a cluster of few triangles then
    /// replaces by their own measure in every solve ([`crate::receivers`]).
    pub form_factor: f64,
    /// Largest minus smallest point factor over the receiver's quadrature
    /// points: how much the transport varies over the receiver.
    pub spread: f64,
    /// Visible fraction, `None` until rays were cast.
    pub visibility: Option<f32>,
    /// Distance from the receiver to the nearest occluder, +inf if none.
    pub occluder_distance: f32,
    /// Proven unoccluded: no other triangle meets the shaft between its two
    /// elements ([`crate::shaft`]), nor, then, those of the links that
    /// refine it.
    pub clear: bool,
}

impl Link {
    /// Whether its rays found it partly occluded (`0 < V < 1`).
    pub fn partly_occluded(&self) -> bool {
        self.visibility.is_some_and(|v| v > 0.0 && v < 1.0)
    }

    /// Its visible fraction, 1 until rays were cast.
    pub fn visible(&self) -> f64 {
        f64::from(self.visibility.unwrap_or(1.0))
    }

    /// Its factor and visible fraction as its receiver's exposed part sees
    /// them, `(F_e, V_e)` with `F_e V_e = F V / x`, `x` the receiver
    /// element's exposure ([`crate::exposure`]; 1 for a cluster, or an
    /// element not measured yet): the solve divides what the link brings
    /// by `x`, so its errors land on the exposed part `1 / x` times as
    /// large, and `V` counts the rays from buried points as occluded where
    /// the kernel reaches them. Where it does (a lamp above a floor element
    /// that a block stands on), `F` is about the exposed part's own factor,
    /// `V_e = V / x` and `F_e = F`; where it does not (the block's own face,
    /// which the buried part is behind), `V` is that of the exposed part
    /// already, `V_e = min(1, V / x) = 1` and `F_e = F V / x`. Judged on
    /// `V`, a link into a partly buried element looked nearly occluded
    /// (`V` about `x`) and its shadow term `2 min(V, 1 - V)` small where
    /// its exposed part was in the open, so refinement kept the links whose
    /// few rays from the exposed part had happened to be blocked: on the
    /// built-in Cornell box at `EPS` 4e-4 (seed 1) the lamp links into a
    /// floor element across the short block's base, exposure 0.14, had `V`
    /// 0.06 where its exposed part sees the lamp at 0.89 (0.12 expected),
    /// and a leaf below it was 20% under the `EPS` 5e-5 solve; over seeds
    /// 1-5 the floor 5 to 10 cm in front of the tall block was 1.2% to
    /// 3.1% under it (now -1.5% to +0.8%). Judged on `V_e`, the links kept
    /// are those whose `V_e` came out near 1 or 0, as for any receiver.
    fn on_exposed(&self, h: &Hierarchy) -> (f64, f64) {
        let v = self.visible();
        let x = match self.receiver {
            Node::Element(e) => h.exposure(e),
            Node::Cluster(_) => 1.0,
        };
        if !(x > 0.0 && x < 1.0) {
            return (self.form_factor, v);
        }
        let v_e = (v / x).min(1.0);
        let f_e = if v_e > 0.0 { self.form_factor * v / (x * v_e) } else { self.form_factor };
        (f_e, v_e)
    }

    /// The oracle's shadow term, `2 min(V_e, 1 - V_e) rho_r B_s F_e`, with
    /// `reflected` = `rho_r B_s` ([`Link::on_exposed`]): what a shadow edge
    /// across the link may misplace on its receiver's exposed part
    /// ([`decide`]).
    fn shadow_error(&self, h: &Hierarchy, reflected: f64) -> f64 {
        let (f, v) = self.on_exposed(h);
        2.0 * v.min(1.0 - v) * reflected * f
    }

    /// The oracle's shadow term ([`Self::shadow_error`]) of a link into
    /// element `r`, with `r`'s reflectance and the sender's radiosity in
    /// `radiosity` (dense index), as [`decide`] takes it.
    pub(crate) fn shadow_term(&self, h: &Hierarchy, r: u32, radiosity: &[[f64; 3]]) -> f64 {
        self.shadow_error(h, brightest_reflected(h.reflectance_of(r), radiosity[h.flat(self.sender)]))
    }

    /// Its share of `allowance` ([`Allowance::for_link`]) with its receiver's
    /// radiosity and what it brings the receiver's exposed part, `rho_r V_e
    /// F_e B_s` (`reflected` = `rho_r B_s`, [`Link::on_exposed`]), both
    /// scaled by `dim` ([`dimming`]).
    fn share(&self, h: &Hierarchy, allowance: &Allowance, receiver: [f64; 3], reflected: f64, dim: f64) -> f64 {
        let (f, v) = self.on_exposed(h);
        allowance.for_link(receiver.map(|x| dim * x), dim * reflected * v * f)
    }
}

/// What to do with a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Accurate enough, or too small to split.
    Keep,
    /// Replace by links from the sender's children.
    Sender,
    /// Replace by links to the receiver's children.
    Receiver,
    /// Split whichever of the two is larger (oracle's wish only; resolved
    /// to `Sender` or `Receiver` before any link is split).
    Larger,
    /// A cluster's self-link: replace by links between all pairs of its
    /// children (and their self-links).
    Both,
}

/// How a solve links nodes: rays and samples for cluster links.
#[derive(Clone, Copy, Debug)]
pub struct Linking {
    /// Point pairs per link with a cluster end.
    pub cluster_samples: usize,
    /// Seed of their random streams.
    pub seed: u64,
    /// The adaptive receiver quadrature of the form factors between
    /// elements ([`Allowance::quadrature`]).
    pub quadrature: Quadrature,
}

/// What a link's estimated error is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// Against `eps` times the largest emitted radiosity, the same for
    /// every receiver (BF-style).
    Absolute,
    /// Against `eps_relative` times what the link brings its receiver, or
    /// at least `share_floor` of the receiver's own radiosity (its
    /// brightest channel, in the current iterate, floored at
    /// `relative_floor` times the scene's area-mean reflected radiosity):
    /// the errors of all the links into an element then add up to about
    /// `eps_relative` of its radiosity ([`Allowance::for_link`]); and never
    /// more than the absolute threshold ([`crate::RELATIVE_AT`]). Into an
    /// inner element or a cluster, both are scaled to its dimmest leaf
    /// ([`dimming`]).
    Relative,
}

/// Share of the relative criterion's `eps` that a receiver's error through
/// its links' form factors may take ([`Allowance::quadrature`]).
pub const QUADRATURE_SHARE: f64 = 1.0 / 16.0;

/// The oracle's allowance: how much error a link may make on its receiver.
#[derive(Clone, Copy, Debug)]
pub enum Allowance {
    /// The same threshold (W/m²) for every receiver.
    Absolute(f64),
    /// `eps` times the receiver's brightest radiosity channel, at least
    /// `floor` (W/m²), shared among its links ([`Allowance::for_link`]),
    /// at most `most`.
    Relative {
        /// Fraction of the receiver's radiosity.
        eps: f64,
        /// Least radiosity it is taken to have.
        floor: f64,
        /// Least share of the receiver's radiosity a link's allowance is
        /// computed from.
        share: f64,
        /// The absolute threshold (W/m²): no link may err by more, however
        /// bright its receiver ([`crate::RELATIVE_AT`]: an element's error as
        /// a sender reaches what it lights in absolute terms).
        most: f64,
    },
}

impl Allowance {
    /// The error (W/m², any channel) allowed on a receiver of radiosity `b`
    /// in all.
    pub fn at(&self, b: [f64; 3]) -> f64 {
        self.allowed(b, 0.0, 1.0)
    }

    /// The error (W/m², any channel) one link between elements may make on
    /// a receiver of radiosity `b` when it brings it `transport` (`rho_r V
    /// F_rs B_s`, brightest channel). Relative:
    ///
    /// ```text
    /// min(eps (T_l + s max(B_r, floor)), most)
    /// ```
    ///
    /// so the `n` links into an element err by at most `eps (sum_l T_l + n
    /// s B_r) <= eps B_r (1 + n s)` together, the links that bring most of
    /// its light most of it. An allowance of `eps B_r` for every link (the
    /// former rule) let `n` same-signed errors add to `n eps B_r`: on paper
    /// 002's one-bounce receiver, whose light comes from every part of the
    /// receiver above it through links each within `eps B_r`, leaves were
    /// up to 8.9% off the quadrature reference (rms 2.1%) at `eps_relative`
    /// 0.9%, and tightening `eps_relative` did not help (the links were
    /// each within it). `s` (`share_floor`) keeps links that bring almost
    /// nothing from being refined for their relative error alone; at 1/16
    /// the worst leaf of B is 1.1% off (rms 0.17%). On the Cornell box
    /// (full gather, against Mitsuba) the relative RMSE went from 3.2% to
    /// 2.3% for 6.7x the links (122k to 823k).
    pub fn for_link(&self, b: [f64; 3], transport: f64) -> f64 {
        let share = match *self {
            Allowance::Absolute(_) => 0.0,
            Allowance::Relative { share, .. } => share,
        };
        self.allowed(b, transport, share)
    }

    /// The receiver quadrature for the links between elements that a pass
    /// makes under this allowance, `q` the previous solve's rate of
    /// convergence (per channel): at most `depth` levels, to a relative
    /// tolerance of
    ///
    /// ```text
    /// max(QUADRATURE_SHARE eps (1 - q), QUADRATURE_TOLERANCE)
    /// ```
    ///
    /// under the relative criterion, [`QUADRATURE_TOLERANCE`] otherwise.
    /// A link errs by `rho_r V B_s dF` where its factor errs by `dF`, at
    /// most `tolerance` times what it brings (`T_l`). Near a shared edge
    /// the rule's error has one sign (its points miss the peak of the
    /// kernel's logarithmic singularity), so it adds up over the links into
    /// a receiver, to at most the tolerance times the receiver's reflected
    /// radiosity, and interreflection multiplies it by up to `1 / (1 - q)`:
    /// the receiver then errs by at most `QUADRATURE_SHARE eps` through its
    /// form factors, a sixteenth of the `eps` the criterion allows it.
    /// (Where the absolute cap `most` binds, on receivers bright enough that
    /// `eps` of what they get exceeds it, the criterion allows less; the
    /// quadrature is not tightened for them: at coarse `EPS`, where `eps`
    /// is near 1, their links' factors may err by a few percent, the same
    /// order as the 7-point rule's own error on touching elements.)
    ///
    /// The fixed tolerance alone (the floor) took the quadrature of nearly
    /// every pair of near elements down to its deepest level: 37% of a
    /// solve's time on the Cornell box at `EPS` 2e-4 (one thread, perf).
    /// With this one (about 7e-3 there) the solve takes 0.79 of the time,
    /// and no triangle's mean radiosity moves by more than 0.13%; 0.53 of
    /// it with the pairs refined only as near as the tolerance needs
    /// (radiometry's `triangle_to_polygon`). A closed box at rho 0.999
    /// keeps the floor: its relative `eps` is a few 1e-6 (its mean
    /// radiosity is a hundred times its lamp's emission).
    pub fn quadrature(&self, q: [f64; 3], depth: u32) -> Quadrature {
        let q = q.into_iter().fold(0.0, f64::max);
        let tolerance = match *self {
            Allowance::Relative { eps, .. } => (QUADRATURE_SHARE * eps * crate::gather::damping(q)).max(QUADRATURE_TOLERANCE),
            Allowance::Absolute(_) => QUADRATURE_TOLERANCE,
        };
        Quadrature { depth, tolerance }
    }

    /// Relative: `min(eps (transport + share max(B_r, floor)), most)`;
    /// absolute: the threshold.
    fn allowed(&self, b: [f64; 3], transport: f64, share: f64) -> f64 {
        match *self {
            Allowance::Absolute(threshold) => threshold,
            Allowance::Relative { eps, floor, most, .. } => (eps * (transport + share * b.into_iter().fold(floor, f64::max))).min(most),
        }
    }
}

/// Most triangles a cluster sender may hold for a link from it into an
/// element to take its form factor as the sum of the element's factors to
/// each of them ([`link`]).
pub const EXACT_CLUSTER_SENDER: usize = 16;

/// The link `receiver <- sender`, or `None` where no light can pass.
///
/// Between elements the form factor is the receiver-area mean of
/// Lambert's factor to the sender ([`element_link`]). With a cluster at an
/// end it is [`transfer`]'s Monte Carlo estimate, except from a cluster of
/// at most [`EXACT_CLUSTER_SENDER`] triangles into an element, where it is
/// the sum of the element's factors to each triangle, each as between
/// elements: the same quantity (one-sided at both ends), without the
/// estimate's noise. That noise (a standard deviation of about 6% of the
/// factor with 16 pairs, `transfer`'s test) lands on the receiver whole:
/// on the built-in Cornell box at `EPS` 7e-4 a link from the cluster of
/// the short block's faces brought a ceiling leaf 13% of its light, and
/// the ceiling's triangles came out 1-4% off the `EPS` 2.5e-5 solve, a
/// different sign from seed to seed; its mean -0.68% to +0.75% over seeds
/// 1-8 against Mitsuba, now -0.27% to +0.03% (the worst surface per seed
/// 0.37-0.75% -> 0.19-0.77%, the short block now the worst), for no
/// measurable time (`plants-2k` at its default `EPS`: 3% more, 1% fewer
/// links). A link into a cluster takes its triangles' own factors in the
/// solves ([`crate::receivers`]).
pub fn link(h: &Hierarchy, receiver: Node, sender: Node, linking: Linking) -> Option<Link> {
    match (receiver, sender) {
        (Node::Element(r), Node::Element(s)) => element_link(h, r, s, linking.quadrature),
        (Node::Element(r), Node::Cluster(_)) if h.triangles_below(sender).len() <= EXACT_CLUSTER_SENDER => {
            let (form_factor, spread) = h
                .triangles_below(sender)
                .iter()
                .filter_map(|&t| element_link(h, r, t, linking.quadrature))
                .fold((0.0, 0.0), |(f, s), l| (f + l.form_factor, s + l.spread));
            (form_factor > 0.0).then_some(Link { receiver, sender, form_factor, spread, visibility: None, occluder_distance: f32::INFINITY, clear: false })
        }
        _ => {
            if behind(h, receiver, sender) || behind(h, sender, receiver) {
                return None;
            }
            let e = transfer::estimate(h, None, receiver, sender, linking.cluster_samples, linking.seed);
            Some(Link { receiver, sender, form_factor: e.form_factor, spread: e.spread, visibility: None, occluder_distance: f32::INFINITY, clear: false })
        }
    }
}

/// A cluster's self-link: it carries no light itself and is always split.
pub fn self_link(cluster: Node) -> Link {
    Link { receiver: cluster, sender: cluster, form_factor: 0.0, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: false }
}

/// Whether `other` lies wholly behind the plane of `node`'s surfaces (the
/// corners of its bounding box all on the back side), when `node` is flat:
/// an element, or a cluster whose triangles all lie in one plane (a normal
/// cone of zero width and a box without thickness along its axis, as the
/// clusters of a tessellated wall have). Such pairs exchange no light, and
/// their boxes touch, so the conservative bound alone would refine them all
/// the way down to element pairs.
fn behind(h: &Hierarchy, node: Node, other: Node) -> bool {
    let Some((origin, normal)) = plane(h, node) else { return false };
    let (lo, hi) = h.bounds(other);
    let (nlo, nhi) = h.bounds(node);
    let tolerance = 1e-9 * (hi - lo).length().max((nhi - nlo).length());
    (0..8).all(|i| {
        let corner = DVec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z });
        (corner - origin).dot(normal) <= tolerance
    })
}

/// A point and the front normal of the plane holding all of `node`'s
/// surfaces, if there is one.
fn plane(h: &Hierarchy, node: Node) -> Option<(DVec3, DVec3)> {
    match node {
        Node::Element(e) => Some((h.elements[e as usize].points[0], h.normal(e))),
        Node::Cluster(c) => {
            let cluster = &h.clusters.as_ref()?.clusters.nodes[c as usize];
            let axis = DVec3::from(cluster.normal_axis.map(f64::from));
            if cluster.normal_cos < 1.0 - 1e-6 || axis == DVec3::ZERO {
                return None;
            }
            let (lo, hi) = h.bounds(node);
            let half = 0.5 * (hi - lo);
            let thickness = axis.abs().dot(half);
            (thickness <= 1e-6 * half.length().max(f64::MIN_POSITIVE)).then_some((0.5 * (lo + hi), axis))
        }
    }
}

/// Distance between two axis-aligned boxes (0 where they overlap).
pub(crate) fn box_distance(a: (DVec3, DVec3), b: (DVec3, DVec3)) -> f64 {
    let gap = (b.0 - a.1).max(a.0 - b.1).max(DVec3::ZERO);
    gap.length()
}

/// The link between two elements, or `None` where no light can pass: the
/// sender lies wholly behind the receiver's plane or the receiver wholly
/// behind the sender's (both are one-sided), which includes coplanar
/// elements and an element with itself.
fn element_link(h: &Hierarchy, receiver: u32, sender: u32, quadrature: Quadrature) -> Option<Link> {
    let (r, s) = (&h.elements[receiver as usize], &h.elements[sender as usize]);
    let (nr, ns) = (h.normal(receiver), h.normal(sender));
    // Heights above the other's plane, against a tolerance scaled to the
    // elements, so round-off on coplanar elements does not count as "in front".
    let size = (r.area + s.area).sqrt();
    let tolerance = 1e-9 * size;
    let in_front = |points: &[glam::DVec3; 3], origin: glam::DVec3, normal: glam::DVec3| {
        points.iter().any(|p| (*p - origin).dot(normal) > tolerance)
    };
    if receiver == sender || !in_front(&s.points, r.points[0], nr) || !in_front(&r.points, s.points[0], ns) {
        return None;
    }
    let f = match &h.detail {
        None => triangle_to_polygon(&r.points, nr, &s.points, ns, quadrature),
        Some(detail) => {
            if h.coverage(receiver) == 0.0 || h.coverage(sender) == 0.0 {
                return None;
            }
            detailed_factor(h, detail, receiver, sender, quadrature)
        }
    };
    (f.mean > 0.0).then_some(Link {
        receiver: Node::Element(receiver),
        sender: Node::Element(sender),
        form_factor: f.mean,
        spread: f.max - f.min,
        visibility: None,
        occluder_distance: f32::INFINITY,
        clear: false,
    })
}

/// The factor from element `receiver` to the opaque part of element
/// `sender` ([`crate::detail`]): summed over the polygons of the sender's
/// opaque texel runs, or, where it has no mask or too many runs, the factor
/// to the whole element times its coverage; each polygon's by
/// [`triangle_to_polygon`], or by [`normal_mapped_factor`] where the
/// receiver has a normal map. The spread is the summed pieces' (an upper
/// bound of the point values' spread).
fn detailed_factor(h: &Hierarchy, detail: &Detail, receiver: u32, sender: u32, quadrature: Quadrature) -> AreaFactor {
    let (r, s) = (&h.elements[receiver as usize], &h.elements[sender as usize]);
    let (nr, ns) = (h.normal(receiver), h.normal(sender));
    let (parts, scale) = match detail.opaque_parts(s.triangle, &s.corners, &h.triangles[s.triangle as usize]) {
        Some(parts) => (parts, 1.0),
        None => (vec![s.points.to_vec()], h.coverage(sender)),
    };
    let factor = |part: &[DVec3]| {
        if detail.normal_mapped(r.triangle) {
            normal_mapped_factor(h, detail, receiver, part, ns)
        } else {
            triangle_to_polygon(&r.points, nr, part, ns, quadrature)
        }
    };
    parts.iter().map(|p| factor(p)).fold(AreaFactor { mean: 0.0, min: 0.0, max: 0.0 }, |a, f| AreaFactor {
        mean: a.mean + scale * f.mean,
        min: a.min + scale * f.min,
        max: a.max + scale * f.max,
    })
}

/// The factor from normal-mapped element `receiver` to the one-sided
/// polygon `sender` (front `front`): Lambert's point factor with the
/// perturbed normal, averaged by the centroid rule of [`crate::detail`].
fn normal_mapped_factor(h: &Hierarchy, detail: &Detail, receiver: u32, sender: &[DVec3], front: DVec3) -> AreaFactor {
    let r = &h.elements[receiver as usize];
    let (g, n) = (&h.triangles[r.triangle as usize], h.normal(receiver));
    let mut parts = vec![r.corners];
    for _ in 0..crate::detail::NORMAL_MAP_LEVELS {
        parts = parts.iter().flat_map(radiometry::subdivision::children).collect();
    }
    let mut f = AreaFactor { mean: 0.0, min: f64::INFINITY, max: 0.0 };
    for p in &parts {
        let at = [0, 1].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
        let value = point_to_one_sided_polygon(g.point(at), detail.normal_at(r.triangle, at, n), sender, front);
        f.mean += value / parts.len() as f64;
        f.min = f.min.min(value);
        f.max = f.max.max(value);
    }
    f
}

/// The smallest element areas a split may make (m²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Floors {
    /// For every split, but see `shadow`.
    pub area: f64,
    /// For a shadow edge across a link between elements (the oracle's
    /// occlusion term): `area / 4^shadow_levels`. A piecewise-constant
    /// solution needs its finest elements where visibility changes (the
    /// contact shadows at a block's base, penumbrae), not where only the
    /// kernel varies, which the full gather evaluates per pixel anyway; the
    /// one area floor for both kept the Cornell box's floor 7.7% rms off
    /// Mitsuba in the preview (31% of its pixels over 10%). Two levels
    /// below it: 1.9% (3.9%), full gather 1.2% -> 1.0% relative RMSE, for
    /// 1.5x the links (1.31M -> 1.99M) and 7.5x the leaves (4.2k -> 31k).
    pub shadow: f64,
}

/// The refinement oracle. A cluster's self-link always splits. A link with
/// a cluster at an end uses the BF criterion with the conservative bound of
/// Smits, Arvo and Greenberg (1994): no point of the sender can contribute a
/// form factor larger than `A_s / (pi d_min^2)`, `d_min` the distance
/// between the two bounding boxes, so the link may misplace at most
/// `rho_r B_s A_s / (pi d_min^2)`; above `threshold` the larger node (by
/// bounding box) is split, or the other where the larger cannot be. And,
/// as between elements, the link spreads the sender's mean radiosity over
/// the sender: where its children's radiosities differ from that mean by
/// more than `threshold / (rho_r F_rs)` the sender is split. Without this
/// term a cluster holding a lamp and the dim ceiling around it sends the
/// mean of the two to the floor, which the lamp sees better than the
/// ceiling does: a closed box lost 2.7% of its energy at eps 5e-2.
///
/// A partly occluded link with a cluster at an end (`0 < V < 1`, its rays
/// cast) also splits the larger node where its shadow term, `2 min(V, 1 -
/// V) rho_r B_s F_rs` as between elements, exceeds the link's share of the
/// allowance ([`Allowance::for_link`], at the dimmest leaf): the link lights
/// every leaf below its receiver with the mean visibility, while an
/// occluder hides the sender from some of them, and the conservative bound
/// (which holds the whole allowance, not a share) keeps a link whose
/// bound is small while many such links into one receiver add up. On the
/// built-in Cornell box at `EPS` 4e-4, fourteen links from the ceiling
/// into the clusters holding the floor and the short block, each within
/// the whole allowance of their dimmest leaf, lit the floor in the block's
/// umbra as if the block hid none of the ceiling: those floor leaves were
/// up to 53% above the `EPS` 2.5e-5 solution, and the block's camera face,
/// which that floor lights, up to 28% along its base. Preview against
/// Mitsuba, over seeds 1-5 (the visibility noise of the few large links
/// that light that face moves it by a percent or two from seed to seed):
/// the short block +2.0% -> +1.3% on average, relative RMSE 1.56% ->
/// 1.47%, 1% more links; at 2e-4 every surface within 0.7% for every seed
/// (four of five before). The shadow term never
/// exceeds the bound (`F_rs <= A_s / (pi d_min^2)`), so under the absolute
/// criterion, whose share is the whole threshold, it changes nothing.
///
/// Between elements, see `decide_elements` below.
///
/// `allowance` says what the error is compared with: one threshold for all
/// receivers, or a fraction of each receiver's radiosity ([`Allowance`]),
/// then taken at the dimmest leaf below the receiver where `dimmest`
/// ([`dimmest_leaf`]) is given ([`dimming`]).
///
/// `range[e]`, where given, is how far apart the radiosities of the leaves
/// below element `e` lie (per channel, [`leaf_range`]): the sender
/// variation of an element sender then sees every level below it, not only
/// its children, whose means can hide a bright spot.
pub fn decide(h: &Hierarchy, link: &Link, radiosity: &[[f64; 3]], range: &[[f64; 3]], dimmest: &[f64], allowance: &Allowance, floors: Floors) -> Split {
    let (r, s) = (link.receiver, link.sender);
    if r == s {
        return Split::Both;
    }
    let size = |n: Node| {
        let (lo, hi) = h.bounds(n);
        (hi - lo).length_squared()
    };
    let larger = if size(s) > size(r) { Split::Sender } else { Split::Receiver };
    // Resolves a wish given which of the two ends may split.
    let feasible = |wanted: Split, (can_r, can_s): (bool, bool)| match (wanted, can_r, can_s) {
        (Split::Receiver, true, _) | (Split::Sender, _, true) => Some(wanted),
        (Split::Larger, true, true) => Some(larger),
        (Split::Larger, true, false) => Some(Split::Receiver),
        (Split::Larger, false, true) => Some(Split::Sender),
        _ => None,
    };
    let area_floor = (h.can_split(r, floors.area), h.can_split(s, floors.area));
    // Between elements, `Larger` is a shadow edge, which may go below the
    // area floor ([`Floors::shadow`]).
    let shadow_floor = (h.can_split(r, floors.shadow), h.can_split(s, floors.shadow));
    let dim = dimming(h, r, radiosity, dimmest);
    match (r, s) {
        // The largest error over the link's share that a split can reduce.
        (Node::Element(_), Node::Element(_)) => decide_elements(h, link, radiosity, range, dim, allowance)
            .into_iter()
            .find_map(|wanted| feasible(wanted, if wanted == Split::Larger { shadow_floor } else { area_floor }))
            .unwrap_or(Split::Keep),
        _ => {
            let threshold = allowance.at(radiosity[h.flat(r)].map(|x| dim * x));
            let rho = h.node_reflectance(r);
            let b = radiosity[h.flat(s)];
            let reflected = brightest_reflected(rho, b);
            let distance = box_distance(h.bounds(r), h.bounds(s));
            let bound = if distance > 0.0 { h.area(s) / (PI * distance * distance) } else { f64::INFINITY };
            let sender_variation = h
                .children_if_any(s)
                .iter()
                .flat_map(|&child| (0..3).map(move |c| (child, c)))
                .map(|(child, c)| rho[c] * (radiosity[h.flat(child)][c] - b[c]).abs())
                .fold(0.0, f64::max);
            let shadow_over_share = link.shadow_error(h, reflected) > link.share(h, allowance, radiosity[h.flat(r)], reflected, dim);
            let wanted = if sender_variation * link.form_factor > threshold && sender_variation * link.form_factor >= reflected * bound {
                Split::Sender
            } else if reflected * bound > threshold || shadow_over_share {
                Split::Larger
            } else {
                Split::Keep
            };
            feasible(wanted, area_floor).unwrap_or(Split::Keep)
        }
    }
}

/// The refinement oracle: HSA's BF criterion, with the "F" replaced by an
/// estimate of the link's error rather than its size. A link makes the
/// receiver's radiosity `rho_r V F_rs B_s` constant over the receiver; it
/// misplaces at most (W/m²)
///
/// - `rho_r B_s (F_max - F_min)` where the kernel varies over the receiver
///   (the spread of the point factors): only splitting the **receiver**
///   reduces it;
/// - `rho_r (B_s_max - B_s_min) F_e` where the sender's radiosity varies
///   (known from its leaves, [`leaf_range`], or from its children): splitting the **sender**
///   reduces it. It is the range, the largest leaf less the smallest, as
///   the kernel's term is a range. Weighed by how far a leaf strayed from
///   the sender's mean (about half the range), as it was before, the
///   sender's variation counted half as much as the kernel's and the
///   shadow's for the same error, and the passes kept links from varying
///   senders that a finer `EPS` then split. On the built-in Cornell box
///   (preview against Mitsuba, seeds 1-8, one thread, interleaved medians)
///   the relative RMSE at `EPS` 1.5e-3, 1.25e-3, 1e-3 and 8e-4 went from
///   2.101%, 1.819%, 1.400% and 1.191% to 1.986%, 1.674%, 1.263% and
///   1.107%, for 4% more time (links +11% and +13% at 1.5e-3 and 1e-3,
///   leaves +0.5% and -5%): the old rule took 1.05 and 1.16 times as long
///   for the same error at 1.5e-3 and 1e-3. `F_e` is the factor as the receiver's exposed part sees
///   it ([`Link::on_exposed`]), where the shadow term and the share are
///   measured too: from a block's own face into a floor element the block
///   half buries, `F_e = F_rs / x`, and judged on `F_rs` the term was `x`
///   times too small for the error it leaves on the exposed part (on the
///   built-in Cornell box the change is within the seeds' spread: preview
///   against Mitsuba at `EPS` 4e-4, seeds 1-8, worst surface 0.34-0.71%
///   -> 0.37-0.69%, 0.35% more links);
/// - `2 min(V, 1 - V) rho_r B_s F_rs` where the link is partly occluded (a
///   shadow edge crosses it): splitting the **larger** of the two reduces it.
///
/// Plain BF (`rho_r B_s F_rs`, split the larger) would also split senders
/// whose every part sends the same light: our form factor is exact over
/// the sender, so that buys nothing, and it multiplies links whose small
/// same-signed errors then add up on the receiver. Returned: the splits
/// whose terms exceed the link's share of the receiver's allowance
/// ([`Allowance::for_link`]), largest term first; [`decide`] takes the
/// first whose children would not be smaller than the area floor (a
/// shadow edge: its own floor, [`Floors::shadow`]; it splits the other
/// element when the larger cannot be). So a link
/// whose receiver is at the floor but whose sender's radiosity varies too
/// much still splits the sender: keeping it because the larger term (the
/// kernel's spread over the receiver) could not be reduced left block
/// faces next to the floor lit by the mean of a sender whose part near the
/// crease is in the block's contact shadow (Cornell box, full gather
/// against Mitsuba: tall block -4.1% -> -1.8%, short block +2.9% -> +0.2%,
/// relative RMSE 2.3% -> 1.2%, for 1.6x the links and the same leaves).
/// Links with a cluster at an end keep the whole
/// allowance ([`Allowance::at`]) for their conservative bound: it is a
/// bound, not an estimate, and shared, it refined a 99k-triangle closed box
/// without end (their shadow term takes the share, [`decide`]).
fn decide_elements(h: &Hierarchy, link: &Link, radiosity: &[[f64; 3]], range: &[[f64; 3]], dim: f64, allowance: &Allowance) -> Vec<Split> {
    let (Node::Element(receiver), Node::Element(sender)) = (link.receiver, link.sender) else {
        unreachable!("an element link")
    };
    let rho = h.reflectance_of(receiver);
    let b = radiosity[h.flat(link.sender)];
    let reflected = brightest_reflected(rho, b);
    let sender_element = &h.elements[sender as usize];
    // Its leaves' range, or without ranges (the absolute criterion) its
    // children's.
    let sender_range = match range.get(sender as usize) {
        _ if sender_element.is_leaf() => [0.0; 3],
        Some(&r) => r,
        None => {
            let children = (sender_element.first_child..sender_element.first_child + 4).map(|child| radiosity[h.flat(Node::Element(child))]);
            let (lo, hi) = children.fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), x| (std::array::from_fn(|c| lo[c].min(x[c])), std::array::from_fn(|c| hi[c].max(x[c]))));
            std::array::from_fn(|c| hi[c] - lo[c])
        }
    };
    let sender_variation = (0..3).map(|c| rho[c] * sender_range[c]).fold(0.0, f64::max);
    let threshold = link.share(h, allowance, radiosity[h.flat(link.receiver)], reflected, dim);
    let errors = [
        (reflected * link.spread, Split::Receiver),
        (sender_variation * link.on_exposed(h).0, Split::Sender),
        (link.shadow_error(h, reflected), Split::Larger),
    ];
    let mut over: Vec<(f64, Split)> = errors.into_iter().filter(|e| e.0 > threshold).collect();
    over.sort_by(|a, b| b.0.total_cmp(&a.0));
    over.into_iter().map(|e| e.1).collect()
}

/// How many times the least visibility ray count a link may be given
/// ([`visibility_rays`]).
pub const MOST_RAYS_FACTOR: usize = 16;

/// Visibility rays for `link`, decided before any is cast (so its estimate
/// of `V` stays unbiased): at least `least`, and as many as keep the
/// estimate's noise on its receiver within half the link's share of the
/// allowance ([`Allowance::for_link`], at the dimmest leaf, as [`decide`] takes it),
/// at most [`MOST_RAYS_FACTOR`] times `least`. The link brings its
/// receiver's exposed part `V_e T`, `T = rho_r F_e B_s` (brightest
/// channel; `Link::on_exposed` with `V` 1, `F_e = F_rs / x`: the noise of
/// `V` lands on that part `1 / x` times as large); `n` rays
/// estimate `V` with a standard deviation of at most `sqrt(V (1 - V) / n)
/// <= 1 / (2 sqrt n)` (stratified pairs do better), so
///
/// ```text
/// n = (T / a)^2        gives        T / (2 sqrt n) <= a / 2,
/// ```
///
/// `a` its share with `V = 1` (`Link::share`: its rays are not cast
/// yet). A fixed count gave every link the same
/// noise whatever it carried: on the built-in Cornell box the preview's
/// error below 1% relative RMSE was mostly the visibility noise of a few
/// large, partly occluded links (a surface lit through about 200 links
/// took it whole: 1.3% over 4,096-ray recasts at `EPS` 4e-4), and 64 rays
/// on every link cost half again the solve time of 16 for it. With this
/// count the preview against Mitsuba (relative RMSE) went from 1.00% to
/// 0.94% at `EPS` 2e-4, 0.91% to 0.70% at 1e-4 and 0.72% to 0.59% at
/// 2.5e-5, for 10-13% more solve time at 2e-4 and 1e-4 (one thread; 2%
/// at 4e-4, where 16 rays already keep the noise within the allowance).
pub fn visibility_rays(h: &Hierarchy, link: &Link, radiosity: &[[f64; 3]], dimmest: &[f64], allowance: &Allowance, least: usize) -> usize {
    let r = link.receiver;
    let dim = dimming(h, r, radiosity, dimmest);
    let rho = h.node_reflectance(r);
    let b = radiosity[h.flat(link.sender)];
    let reflected = brightest_reflected(rho, b);
    // On the receiver's exposed part, with `V` 1 (no ray cast yet).
    let transport = dim * reflected * link.on_exposed(h).0;
    let allowed = link.share(h, allowance, radiosity[h.flat(r)], reflected, dim);
    if allowed.is_nan() || allowed <= 0.0 {
        return least;
    }
    let wanted = (transport / allowed).powi(2).ceil();
    (wanted.min((MOST_RAYS_FACTOR * least) as f64) as usize).max(least)
}

/// Fraction of a part's allowance that the noise of its visibility may
/// take ([`Budget::part_rays`]). A link's own rays keep their noise within
/// half its share ([`visibility_rays`]); its parts' rays, in the last
/// solve, decide where on its receiver its light lands, and each part's
/// noise is then all of that part's error from the link: with 8 rays a
/// part, seed to seed, that noise was 43% of the preview's squared error
/// on the built-in Cornell box at `EPS` 1e-3 (against Mitsuba, seeds
/// 1-16). The preview over seeds 1-16 (relative RMSE) at `EPS` 1.5e-3,
/// 1e-3 and 6.5e-4 went from 2.304%, 1.560% and 1.185% to 2.101%, 1.392%
/// and 1.027%, for 1.07, 1.10 and 1.15 times the solve time (one thread,
/// interleaved medians over seeds 1-8): the fixed counts reach 1.392% in
/// 1.25 times their time at 1e-3 (log-log towards 6.5e-4), so the same
/// error costs 12% less time, 3.6% less at 1.5e-3. 1/8 gave 1.523% at
/// 1e-3 for about 1.07 times the time, on the fixed counts' curve; 1/32
/// 1.297% and 0.976% at 1e-3 and 6.5e-4 for 1.33 and 1.40 times, 2% to
/// 4% under it. A count that kept the noise within a fixed fraction of
/// the part's own radiosity instead (not of its allowance, which follows
/// `EPS` as the links' errors do) gained as much at 1e-3 and 6.5e-4 but
/// lost at 1.5e-3.
pub const PART_NOISE_SHARE: f64 = 1.0 / 16.0;

/// What the last solve's parts' visibility rays are counted by: the
/// solved radiosity (dense index), its dimmest leaves ([`dimmest_leaf`]
/// under the relative criterion) and the pass's allowance.
pub struct Budget<'a> {
    radiosity: &'a [[f64; 3]],
    dimmest: Vec<f64>,
    allowance: Allowance,
}

impl<'a> Budget<'a> {
    /// The budget of a solve that gave `radiosity`, under `allowance`.
    pub fn new(h: &Hierarchy, radiosity: &'a [[f64; 3]], allowance: Allowance) -> Self {
        let dimmest = match allowance {
            Allowance::Relative { .. } => dimmest_leaf(h, radiosity),
            Allowance::Absolute(_) => Vec::new(),
        };
        Budget { radiosity, dimmest, allowance }
    }

    /// Visibility rays for element `part` of a partly occluded link's
    /// receiver, whose factor to the link's `sender` is `factor`, the link
    /// `v` visible: as many as keep the noise of the part's visible
    /// fraction within [`PART_NOISE_SHARE`] of the allowance a link into
    /// the part would have ([`Allowance::for_link`], scaled to its dimmest
    /// leaf as [`decide`] takes it), at least `least` and at most
    /// [`MOST_RAYS_FACTOR`] times it. The part takes `T V_p` of the link's
    /// light, `T = rho_p F_ps B_s` (brightest channel); `n` rays estimate
    /// `V_p` with a standard deviation of at most `sqrt(V_p (1 - V_p) / n)`,
    /// and the link's `v` stands for `V_p` (the parts' rays are not cast
    /// yet, and the link's, cast before, are not theirs), so
    ///
    /// ```text
    /// n = v (1 - v) (T / (s a))^2        gives        T sqrt(v (1 - v) / n) <= s a,
    /// ```
    ///
    /// `s` = [`PART_NOISE_SHARE`], `a` the part's allowance, rounded up to
    /// a square (a prime count would stratify its pairs in one row,
    /// [`radiometry::sampling::strata`]; a square at 1/16 gave 1.392%
    /// against 1.415% unrounded at `EPS` 1e-3).
    pub fn part_rays(&self, h: &Hierarchy, part: u32, sender: Node, factor: f64, v: f64, least: usize) -> usize {
        let p = Node::Element(part);
        let dim = dimming(h, p, self.radiosity, &self.dimmest);
        let transport = dim * factor * brightest_reflected(h.reflectance_of(part), self.radiosity[h.flat(sender)]);
        let allowed = self.allowance.for_link(self.radiosity[h.flat(p)].map(|x| dim * x), transport);
        let wanted = v * (1.0 - v) * (transport / (PART_NOISE_SHARE * allowed)).powi(2);
        if !(wanted.is_finite() && allowed > 0.0) {
            return least;
        }
        let side = wanted.sqrt().ceil().min(((MOST_RAYS_FACTOR * least) as f64).sqrt().floor()) as usize;
        (side * side).max(least)
    }
}

/// `rho_r B_s` in its brightest channel: what a link's error terms and
/// its share of the allowance are made of ([`decide`], [`visibility_rays`]).
fn brightest_reflected(rho: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|c| rho[c] * b[c]).fold(0.0, f64::max)
}

/// How much dimmer than node `r` the dimmest exposed leaf below it is, in
/// what the relative criterion bounds: [`light_scale`] of that leaf
/// ([`dimmest_leaf`]) over `r`'s, in [0, 1]; 1 where `dimmest` is empty
/// (the absolute criterion).
///
/// The relative criterion bounds each element's error against its own
/// radiosity. A link into an inner element or a cluster lights all the
/// leaves below it alike, so its error lands on each of them; an
/// allowance taken from the receiver's mean let the leaves darker than
/// that mean (the floor in a block's contact shadow) take errors many
/// times what their own radiosity allows. [`decide`] therefore scales the
/// receiver's radiosity and the link's transport, which make its
/// allowance, by this factor: the allowance of the dimmest leaf, were the
/// link's share of its light the same as of the mean's. On the built-in
/// Cornell box at `EPS` 2e-4 a floor leaf beside the short block's
/// shadowed face was 41% above the `EPS` 2.5e-5 solution's, most of it
/// brought by links into the floor triangle's cluster and top element,
/// and the leaves along the bottom of the face, which that floor lights,
/// 7% to 38% (now 22%, and 6% to 24%). The
/// preview against Mitsuba (relative RMSE, 2 threads): `EPS` 4e-4 1.74%
/// -> 1.47% (38k -> 41k links), 2e-4 1.14% -> 0.96% (90k -> 98k), 1e-4
/// 0.97% -> 0.90% (196k -> 213k links; short block +0.49% -> +0.25%,
/// every surface within 0.26%).
fn dimming(h: &Hierarchy, r: Node, radiosity: &[[f64; 3]], dimmest: &[f64]) -> f64 {
    let Some(&low) = dimmest.get(h.flat(r)) else { return 1.0 };
    let top = light_scale(radiosity[h.flat(r)], h.node_reflectance(r));
    if top > 0.0 && top.is_finite() && low.is_finite() {
        (low / top).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// What a link's error on a node is measured against, per unit of the
/// irradiance it brings: the node's radiosity over its reflectance,
/// `max_c B_c / rho_c` over the channels that reflect (+inf where none
/// does). A leaf's error is `rho ΔH` and its allowance `eps B`, so the
/// leaf with the smallest `B / rho`, not the smallest `B`, binds: a black
/// or dark-coloured leaf in a cluster is dim but errs as little.
fn light_scale(b: [f64; 3], rho: [f64; 3]) -> f64 {
    (0..3).filter(|&c| rho[c] > 0.0).map(|c| (b[c] / rho[c]).max(0.0)).reduce(f64::max).unwrap_or(f64::INFINITY)
}

/// Per node (dense index), the [`light_scale`] of the dimmest leaf element
/// below it with any exposed area ([`crate::exposure`]; a buried leaf shows
/// nothing) and a reflectance, +inf where there is none. Children follow
/// their parents in the dense order, so one backward sweep gathers it.
pub fn dimmest_leaf(h: &Hierarchy, radiosity: &[[f64; 3]]) -> Vec<f64> {
    let mut low = vec![f64::INFINITY; radiosity.len()];
    for i in (0..radiosity.len()).rev() {
        let node = h.node(i);
        if let Node::Element(e) = node {
            if h.elements[e as usize].is_leaf() && h.exposure(e) > 0.0 {
                low[i] = light_scale(radiosity[i], h.reflectance_of(e));
            }
        }
        if let Some(p) = h.parent(node) {
            let p = h.flat(p);
            low[p] = low[p].min(low[i]);
        }
    }
    low
}

/// Per element, the largest difference (per channel) between the radiosity
/// of a leaf below it and the element's own, in `radiosity`: whether the
/// element may send its mean ([`crate::gather::Resolution`]).
pub fn leaf_deviation(h: &Hierarchy, radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let (lo, hi) = leaf_bounds(h, radiosity);
    (0..h.elements.len())
        .map(|e| {
            let b = radiosity[h.flat(Node::Element(e as u32))];
            std::array::from_fn(|c| (hi[e][c] - b[c]).max(b[c] - lo[e][c]).max(0.0))
        })
        .collect()
}

/// Per element, how far apart (per channel) the radiosities of the leaves
/// below it lie in `radiosity`, the largest less the smallest (0 for a
/// leaf): the sender's variation that [`decide`] weighs, a range as the
/// kernel's spread over the receiver is.
pub fn leaf_range(h: &Hierarchy, radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let (lo, hi) = leaf_bounds(h, radiosity);
    lo.iter().zip(&hi).map(|(lo, hi)| std::array::from_fn(|c| (hi[c] - lo[c]).max(0.0))).collect()
}

/// Per element, the smallest and the largest radiosity (per channel) of a
/// leaf below it (children are stored after their parents, so one backward
/// sweep gathers them).
fn leaf_bounds(h: &Hierarchy, radiosity: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = h.elements.len();
    let mut lo = vec![[f64::INFINITY; 3]; n];
    let mut hi = vec![[f64::NEG_INFINITY; 3]; n];
    for e in (0..n).rev() {
        let element = &h.elements[e];
        if element.is_leaf() {
            let b = radiosity[h.flat(Node::Element(e as u32))];
            (lo[e], hi[e]) = (b, b);
        }
        if element.parent != schemas::solution::NONE {
            let p = element.parent as usize;
            for c in 0..3 {
                lo[p][c] = lo[p][c].min(lo[e][c]);
                hi[p][c] = hi[p][c].max(hi[e][c]);
            }
        }
    }
    (lo, hi)
}

/// The most links [`children_links`] can make of `link`, whatever the
/// split: an end's children (four of an element, a cluster's children or
/// its triangles), the larger end's, or their square for a cluster's
/// self-link.
pub fn most_children_links(h: &Hierarchy, link: &Link) -> usize {
    let children = |n: Node| match n {
        Node::Element(_) => 4,
        Node::Cluster(_) => h.children(n).len(),
    };
    if link.receiver == link.sender {
        children(link.receiver).pow(2)
    } else {
        children(link.receiver).max(children(link.sender))
    }
}

/// The links replacing `link` after `split` (children already exist); they
/// inherit its proof of being unoccluded ([`Link::clear`]).
pub fn children_links(h: &Hierarchy, link: &Link, split: Split, linking: Linking) -> Vec<Link> {
    let inherit = |l: Link| Link { clear: link.clear, ..l };
    match split {
        Split::Keep | Split::Larger => vec![*link],
        Split::Sender => h.children(link.sender).into_iter().filter_map(|s| self::link(h, link.receiver, s, linking)).map(inherit).collect(),
        Split::Receiver => h.children(link.receiver).into_iter().filter_map(|r| self::link(h, r, link.sender, linking)).map(inherit).collect(),
        Split::Both => {
            let children = h.children(link.receiver);
            let mut links = Vec::new();
            for &r in &children {
                for &s in &children {
                    if r != s {
                        links.extend(self::link(h, r, s, linking));
                    } else if matches!(r, Node::Cluster(_)) {
                        links.push(self_link(r));
                    }
                }
            }
            links
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use test_support::meshes::{manifest, material, quads};

    /// A link from a cluster of few triangles into an element carries the
    /// sum of the element's factors to them: from the lamp triangle of
    /// `FloorAndWall` (its edge touching the wall's top) to the cluster of
    /// the floor and the wall, by reciprocity `(A_floor F_floor,lamp +
    /// A_wall F_wall,lamp) / A_lamp` with each factor a 400 x 400 midpoint
    /// grid of Lambert's formula written in the test scene. Within 0.1%,
    /// where the 16-pair estimate it replaces has a standard deviation of
    /// 6.4% (`transfer`'s test); the same at every seed.
    #[test]
    fn a_link_from_a_small_cluster_into_an_element_sums_the_elements_factors() {
        let scene = crate::test_scenes::FloorAndWall::new(1.0);
        let q = scene.quad_factors(400);
        let reference = (q[0] + q[1]) / 0.5;
        for seed in [1, 2] {
            let linking = Linking { cluster_samples: 16, seed, quadrature: Quadrature::to_depth(6) };
            let l = link(&scene.h, Node::Element(scene.lamp_triangle), Node::Cluster(1), linking).expect("the lamp sees the floor");
            assert!((l.form_factor / reference - 1.0).abs() < 1e-3, "seed {seed}: {} against {reference}", l.form_factor);
        }
    }

    /// A unit floor (triangles 0, 1; reflectance 0.5) under a lamp 1 m up
    /// (triangles 2, 3), the floor's element 0 split twice: children 4..7,
    /// and 4's children 8..11. Leaf radiosities `1 + 0.1 i` for leaf `i`
    /// except leaf 9 (0.05) and leaf 8, buried (exposure 0, radiosity 0).
    fn floor_under_a_lamp() -> (Hierarchy, Vec<[f64; 3]>) {
        let mesh = quads(&[
            (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), 0, 0),
            (dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 0.0), dvec3(1.0, 0.0, 0.0), 1, 1),
        ]);
        let manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3])]);
        let mut h = Hierarchy::new(&mesh, &manifest, None, None);
        h.ensure_children(Node::Element(0));
        h.ensure_children(Node::Element(4));
        h.exposure = vec![1.0; h.elements.len()];
        h.exposure[8] = 0.0;
        let mut b: Vec<[f64; 3]> = (0..h.elements.len()).map(|i| [1.0 + 0.1 * i as f64; 3]).collect();
        b[8] = [0.0; 3];
        b[9] = [0.05, 0.04, 0.03];
        crate::gather::pull(&h, &mut b);
        (h, b)
    }

    /// Every node's dimmest exposed leaf, against the leaves' parent
    /// chains walked one by one: element 0 holds the dim leaf 9 (0.05 over
    /// its reflectance 0.5), not the buried leaf 8; element 1 and the
    /// leaves are their own; the black lamp never binds.
    #[test]
    fn the_dimmest_leaf_is_the_dimmest_exposed_leaf_below_each_node() {
        let (h, b) = floor_under_a_lamp();
        let low = dimmest_leaf(&h, &b);
        let mut want = vec![f64::INFINITY; b.len()];
        for e in (0..h.elements.len()).filter(|&e| h.elements[e].is_leaf() && h.exposure(e as u32) > 0.0) {
            let bright = (0..3).map(|c| b[e][c] / h.reflectance_of(e as u32)[c]).fold(0.0, f64::max);
            let mut node = Some(Node::Element(e as u32));
            while let Some(n) = node {
                want[h.flat(n)] = want[h.flat(n)].min(bright);
                node = h.parent(n);
            }
        }
        assert_eq!(low, want);
        assert_eq!(low[0], 0.05 / 0.5, "B / rho of leaf 9's brightest channel");
        assert_eq!(low[h.flat(Node::Element(2))], f64::INFINITY, "a black leaf never binds");
        let mean = b[0][0];
        assert!((dimming(&h, Node::Element(0), &b, &low) - 0.05 / mean).abs() < 1e-15);
        assert_eq!(dimming(&h, Node::Element(0), &b, &[]), 1.0, "the absolute criterion does not dim");
    }

    /// The rays of a part of a partly occluded link's receiver keep the
    /// noise of its light within 1/16 of its allowance, with the fewest
    /// square counts that do: leaf 5 of the floor under the lamp (radiosity
    /// 1.5, reflectance 0.5), lit by the lamp triangle (radiosity 1.2) at
    /// factors from 0.001 to 0.4, `V` from 0.05 to 0.95, under the relative
    /// criterion (its allowance `eps (T + s B_p)`) and the absolute one.
    /// Where the bound needs more than 16 times the fewest, they stop at the
    /// largest square within that; a link seen whole or not at all (no
    /// noise) takes the fewest.
    #[test]
    fn a_parts_rays_keep_its_noise_within_its_share_of_the_allowance() {
        let (h, b) = floor_under_a_lamp();
        let (part, lamp, least) = (5, Node::Element(2), 8);
        assert!(h.elements[part as usize].is_leaf());
        for (allowance, allowed) in [
            (Allowance::Relative { eps: 0.2, floor: 1e-3, share: 0.0625, most: 10.0 }, Box::new(|t: f64| 0.2 * (t + 0.0625 * 1.5)) as Box<dyn Fn(f64) -> f64>),
            (Allowance::Absolute(0.01), Box::new(|_: f64| 0.01)),
        ] {
            let budget = Budget::new(&h, &b, allowance);
            let (mut capped, mut raised) = (0, 0);
            for factor in [0.001, 0.01, 0.03, 0.1, 0.4] {
                let transport = 0.5 * 1.2 * factor;
                let a = allowed(transport);
                for v in [0.05, 0.3, 0.5, 0.95] {
                    let n = budget.part_rays(&h, part, lamp, factor, v, least);
                    let noise = |n: usize| transport * (v * (1.0 - v) / n as f64).sqrt();
                    let side = (n as f64).sqrt().round() as usize;
                    assert!(n == least || side * side == n, "{n} rays: a square or the fewest");
                    if n == 121 {
                        capped += 1;
                        assert!(noise(n) > a / 16.0, "capped only where the bound needs more");
                    } else {
                        assert!(noise(n) <= a / 16.0 * (1.0 + 1e-12), "factor {factor}, V {v}: {n} rays leave {} over {}", noise(n), a / 16.0);
                        assert!(n == least || noise((side - 1) * (side - 1)) > a / 16.0, "factor {factor}, V {v}: {n} rays where fewer do");
                    }
                    raised += usize::from(n > least);
                }
                assert_eq!(budget.part_rays(&h, part, lamp, factor, 1.0, least), least);
                assert_eq!(budget.part_rays(&h, part, lamp, factor, 0.0, least), least);
            }
            assert!(capped > 0 && raised > capped, "the cases reach every regime: {capped} capped, {raised} raised");
        }
    }

    /// A link from a lamp triangle into the floor's cluster (two triangles,
    /// 1 m below): its conservative bound fits the whole allowance of the
    /// floor's radiosity, so it is kept when nothing occludes it (and when
    /// everything does), but half occluded its shadow term exceeds its
    /// share of the allowance and a node splits.
    #[test]
    fn a_partly_occluded_cluster_link_splits_on_its_share_of_the_allowance() {
        let mesh = quads(&[
            (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), 0, 0),
            (dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 0.0), dvec3(1.0, 0.0, 0.0), 1, 1),
        ]);
        let manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3])]);
        let mut clusters = test_support::artifacts::clusters_over(&mesh);
        // Cluster 1 holds the floor's triangles 0 and 1, cluster 2 the lamp's.
        (clusters.nodes[1].bounds_min, clusters.nodes[1].bounds_max) = ([0.0; 3], [1.0, 1.0, 0.0]);
        (clusters.nodes[2].bounds_min, clusters.nodes[2].bounds_max) = ([0.0, 0.0, 1.0], [1.0; 3]);
        let mut h = Hierarchy::new(&mesh, &manifest, Some(clusters), None);
        h.exposure = vec![1.0; h.elements.len()];
        let b = vec![[1.0; 3]; h.cluster_count() + h.elements.len()];
        let linking = Linking { cluster_samples: 64, seed: 1, quadrature: Quadrature::to_depth(3) };
        let mut link = link(&h, Node::Cluster(1), Node::Element(2), linking).expect("the lamp faces the floor");
        let allowance = Allowance::Relative { eps: 0.2, floor: 1e-3, share: 0.0625, most: 10.0 };
        let floors = Floors { area: 1e-3, shadow: 1e-4 };
        let (range, low) = (leaf_range(&h, &b), dimmest_leaf(&h, &b));
        // Bound: rho B_s A_s / (pi d^2) = 0.5 x 0.5 / pi = 0.080, under the
        // whole allowance 0.2 x 1; the shadow term at V = 0.5, 0.5 F (F about
        // 0.1), over the share 0.2 (0.25 F + 0.0625).
        assert!(0.25 / PI < allowance.at([1.0; 3]));
        assert!(0.5 * link.form_factor > allowance.for_link([1.0; 3], 0.25 * link.form_factor));
        for (v, kept) in [(1.0, true), (0.5, false), (0.0, true)] {
            link.visibility = Some(v);
            assert_eq!(decide(&h, &link, &b, &range, &low, &allowance, floors) == Split::Keep, kept, "V = {v}");
        }
    }

    /// A lamp link into a floor leaf a quarter exposed (a block stands on
    /// the rest): its rays from the buried part are stopped, so `V` = 0.24
    /// where the exposed part sees the lamp at 0.96. Judged on that part
    /// (`V_e` = 0.96, `F_e` = F) the link is kept: its shadow term `2 (1 -
    /// V_e) rho B F` = 0.008 is under its share of the allowance, 0.2 (0.5
    /// x 0.96 x 0.2 + 0.1 / 16) = 0.0205, where `2 V rho B F` = 0.048
    /// against 0.006 had split it. At `V` = 0.12 (`V_e` = 0.48, a shadow
    /// edge across the exposed part) it splits. A block's own face, which
    /// the buried part is behind, reaches only the exposed part: its `V` is
    /// 1 and it brings that part `F / x`.
    #[test]
    fn a_link_into_a_partly_buried_leaf_is_judged_on_the_exposed_part() {
        let (mut h, mut b) = floor_under_a_lamp();
        let leaf = Node::Element(1);
        h.exposure[1] = 0.25;
        b[h.flat(Node::Element(2))] = [1.0; 3];
        b[h.flat(leaf)] = [0.1; 3];
        let allowance = Allowance::Relative { eps: 0.2, floor: 1e-3, share: 0.0625, most: 10.0 };
        let floors = Floors { area: 1e-3, shadow: 1e-4 };
        let range = leaf_range(&h, &b);
        let mut lamp = Link { receiver: leaf, sender: Node::Element(2), form_factor: 0.2, spread: 0.0, visibility: Some(0.24), occluder_distance: 0.01, clear: false };
        let (f, v) = lamp.on_exposed(&h);
        // V is stored in single precision.
        assert!((f - 0.2).abs() < 1e-12 && (v - 0.96).abs() < 1e-7, "({f}, {v})");
        assert!((lamp.shadow_error(&h, 0.5) - 0.008).abs() < 1e-8);
        assert_eq!(decide(&h, &lamp, &b, &range, &[], &allowance, floors), Split::Keep);
        lamp.visibility = Some(0.12);
        assert_ne!(decide(&h, &lamp, &b, &range, &[], &allowance, floors), Split::Keep);
        let face = Link { visibility: Some(1.0), form_factor: 0.05, ..lamp };
        let (f, v) = face.on_exposed(&h);
        assert!((f - 0.2).abs() < 1e-12 && v == 1.0, "({f}, {v})");
    }

    /// A sender whose leaves lie at `1 - d` and `1 + d` about its mean 1
    /// (a floor element, reflectance 0.5, lighting a ceiling leaf through
    /// `F` = 0.2): its variation is the range `2 d`, so the link splits the
    /// sender where `rho 2 d F` exceeds the link's share of the allowance,
    /// though no leaf strays more than `d` from the mean. At eps 0.2 and
    /// the ceiling's radiosity 0.1 the share is 0.2 (0.1 + 0.1 / 16) =
    /// 0.02125: `d` = 0.15 gives 0.03, split (0.015 by the deviation from
    /// the mean, which kept it); `d` = 0.1 gives 0.02, kept.
    #[test]
    fn a_senders_variation_is_the_range_of_its_leaves() {
        let mesh = quads(&[
            (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), 0, 0),
            (dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 0.0), dvec3(1.0, 0.0, 0.0), 0, 1),
        ]);
        let mut h = Hierarchy::new(&mesh, &manifest(2, vec![material([0.5; 3], [0.0; 3])]), None, None);
        h.ensure_children(Node::Element(0));
        h.exposure = vec![1.0; h.elements.len()];
        let link = Link { receiver: Node::Element(2), sender: Node::Element(0), form_factor: 0.2, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: true };
        let allowance = Allowance::Relative { eps: 0.2, floor: 1e-3, share: 0.0625, most: 10.0 };
        let floors = Floors { area: 1e-3, shadow: 1e-4 };
        for (d, split) in [(0.15, true), (0.1, false)] {
            let mut b = vec![[0.1; 3]; h.elements.len()];
            for (k, child) in (4..8).enumerate() {
                b[child] = [if k % 2 == 0 { 1.0 - d } else { 1.0 + d }; 3];
            }
            crate::gather::pull(&h, &mut b);
            assert!((b[0][0] - 1.0).abs() < 1e-12, "the children's areas are equal");
            let range = leaf_range(&h, &b);
            assert!((range[0][0] - 2.0 * d).abs() < 1e-12 && range[4] == [0.0; 3]);
            assert!((leaf_deviation(&h, &b)[0][0] - d).abs() < 1e-12);
            let wanted = if split { Split::Sender } else { Split::Keep };
            assert_eq!(decide(&h, &link, &b, &range, &[], &allowance, floors), wanted, "d = {d}");
            // Without the ranges (the absolute criterion's case) the
            // children give the same.
            assert_eq!(decide(&h, &link, &b, &[], &[], &allowance, floors), wanted, "d = {d}, children");
        }
    }

    /// The ray count follows `(T / a)^2`, worked by hand: a lamp triangle
    /// (B = 1) lights a floor leaf (rho 0.5) through F = 0.2, so T = 0.1;
    /// at eps 0.2, share 1/16 and B_r = 0.1 the share is 0.2 (0.1 +
    /// 0.00625) = 0.02125, and (0.1 / 0.02125)^2 = 22.1 -> 23 rays. A
    /// tighter eps hits the ceiling (16 x 16), a bright receiver or a loose
    /// absolute threshold keeps the least.
    #[test]
    fn a_link_gets_the_rays_that_keep_its_noise_within_half_its_share() {
        let (h, mut b) = floor_under_a_lamp();
        b[h.flat(Node::Element(2))] = [1.0; 3];
        let leaf = Node::Element(1);
        let lamp = Link { receiver: leaf, sender: Node::Element(2), form_factor: 0.2, spread: 0.0, visibility: None, occluder_distance: f32::INFINITY, clear: false };
        let relative = |eps| Allowance::Relative { eps, floor: 1e-3, share: 0.0625, most: 10.0 };
        let rays = |b: &[[f64; 3]], allowance| visibility_rays(&h, &lamp, b, &[], &allowance, 16);
        b[h.flat(leaf)] = [0.1; 3];
        assert_eq!(rays(&b, relative(0.2)), 23);
        assert_eq!(rays(&b, relative(0.01)), 256);
        assert_eq!(rays(&b, Allowance::Absolute(0.5)), 16);
        b[h.flat(leaf)] = [10.0; 3];
        assert_eq!(rays(&b, relative(0.2)), 16);
    }

    /// A partly occluded link from the lamp into the floor's top element
    /// whose shadow term (`2 (1 - V) rho B_s F`) fits the allowance of the
    /// element's mean but not of its dimmest leaf, 20x darker: kept
    /// without `dimmest`, split with it.
    #[test]
    fn a_link_into_an_element_with_a_dim_leaf_fits_that_leafs_allowance() {
        let (h, mut b) = floor_under_a_lamp();
        b[h.flat(Node::Element(2))] = [1.0; 3];
        let link = Link { receiver: Node::Element(0), sender: Node::Element(2), form_factor: 0.2, spread: 0.0, visibility: Some(0.9), occluder_distance: 0.1, clear: false };
        let allowance = Allowance::Relative { eps: 0.3, floor: 1e-3, share: 0.0625, most: 10.0 };
        let floors = Floors { area: 1e-4, shadow: 1e-5 };
        let range = leaf_range(&h, &b);
        // Shadow term 2 x 0.1 x 0.5 x 1 x 0.2 = 0.02; allowance at the mean
        // (about 1.7) 0.3 (0.09 + 0.0625 x 1.7) = 0.059.
        assert_eq!(decide(&h, &link, &b, &range, &[], &allowance, floors), Split::Keep);
        let low = dimmest_leaf(&h, &b);
        assert_ne!(decide(&h, &link, &b, &range, &low, &allowance, floors), Split::Keep);
    }
}

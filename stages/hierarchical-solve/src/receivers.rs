//! How the light of a link into a cluster reaches the cluster's surfaces:
//! each input triangle below it by its own orientation to the sender
//! (Smits, Arvo, Greenberg 1994, Section 4; Sillion 1995: a cluster
//! receiver's irradiance is distributed to its contents, not taken as one
//! value for all of them). Triangle `t` below a cluster receiver `r` of a
//! link `r <- s` gets, from the sender's parts `p` ([`Hierarchy::parts`],
//! at most [`MAX_PARTS`]),
//!
//! ```text
//! E_t = V F_rs sum_p w_tp B_p,   w_tp = F_tp A_r / sum over u below r, q of A_u F_uq,
//! F_rs = sum over u below r, q of A_u F_uq / A_r
//! ```
//!
//! so that `E_t = V sum_p F_tp B_p`: each triangle gets its own factor to
//! each part rather than a share by area, and the link carries the area
//! mean of its triangles' factors, as they measure it ([`Measured`]: the
//! 16 point pairs of its estimate, [`crate::transfer`], decided whether
//! refinement kept it, which biases them). `F_tp` is Lambert's factor
//! (002 Eq. 3, one-sided) over the triangle by Dunavant's degree-5 rule
//! ([`DUNAVANT_5`]) to the part: an element part by its polygon times its
//! coverage, a cluster part by [`CLUSTER_PART_SAMPLES`] points of its
//! surfaces; a face turned away from every part gets nothing. Each part
//! sends its own radiosity `B_p`, as a link into an element resolves its
//! sender ([`crate::gather::SenderTerms`]): with the sender's area mean
//! `B_s` instead, the open box's surfaces were 0.05% darker against the
//! radiosity equation (ceiling -0.166%, now -0.112%;
//! `tests/tests/radiosity_equation.rs`). Where no triangle sees the sender
//! (the estimate's light then comes from the triangles' edges) every
//! triangle gets the same, `w_tp = A_p / A_s`, of the link's own estimate.
//!
//! In the last solve (after the means' solve that decides refinement) a
//! partly occluded link (`0 < V < 1`) also weighs each pair by its own
//! visibility, `F_tp V_tp` in place of `F_tp` ([`visibility::visible_factor`]
//! between triangle `t` and an element part; a part that is still a
//! cluster takes the link's `V`), and takes for `V` the visible share
//! they measure, `sum A_t F_tp V_tp / sum A_t F_tp`: the link's own `V`
//! says how much of its light gets through, not to which of the cluster's
//! faces, and a face hidden from the sender by another object got its
//! unoccluded share. On the built-in Cornell box at `EPS`
//! 3e-3 (full gather against Mitsuba) the relative RMSE went from 1.30% to
//! 1.16% (short block +1.43% -> +0.69%, back wall -1.00% -> -0.72%; the
//! unclustered solve: 1.00%). Only in the last solve because of its cost
//! on large clustered scenes: plants-10k at `EPS` 1e-2 solved in 14.6 s
//! instead of 12.5 s; in every pass, 22.9 s (and 1.08% on the Cornell
//! box); both before the weights without visibility were kept from pass
//! to pass ([`WeightCache`]: 14.9 s -> 10.5 s, the same solution).
//!
//! Only clusters of at most [`MAX_RECEIVER_TRIANGLES`] triangles are
//! distributed so in every solve. In the last solve a link into a larger
//! cluster, of at most [`MAX_ORIENTED_TRIANGLES`], whose triangles do not
//! all face one way ([`FLAT_CLUSTER`]), is distributed to its triangles
//! by their own factors to the whole sender (one part, `w_t = F_ts A_r /
//! sum_u A_u F_us`, Dunavant's rule over each triangle), its visibility
//! the link's; larger and flat ones keep the isotropic push (below). In
//! `plants-2k` at its default `EPS` 1e-3 a floor leaf got 56% of the
//! light of a ceiling triangle it sees whole, through a link into a
//! cluster of 249 triangles, a floor triangle and a plant's leaves, whose
//! irradiance, the mean over leaves that face every way, went to the floor
//! by area: the floor was 2.0% under a gather of the solution's own
//! leaves for its light from the ceiling and walls, and in the preview
//! against Mitsuba the floor -1.74%, the ceiling -2.31% and the walls
//! +0.62% to +1.47%; now +0.26%, -1.86% and -0.40% to -0.02% (relative
//! RMSE 2.70% -> 1.90%; the floor's light now +0.12% against that
//! gather), the solve 3.45 -> 3.82 s on one thread (medians of 3
//! interleaved), where the old solve reaches 2.52% in 4.63 s (at `EPS`
//! 7e-4). The box of 100k triangles (`tests/tests/clustering.rs`, flat
//! walls, `EPS` 1e-2, 2 threads) solves in 7.50 s instead of 6.90 s, 4%
//! more memory; in a single run where the old solve took 7.9 s, 9.2 s
//! with flat clusters distributed too, and 12.6 s with twice the memory
//! without the bound on triangles; a bound of 64 left `plants-2k` at
//! 2.47%. The Cornell box's solves at `EPS` 4e-4 and 7e-4 keep every
//! leaf's bits (no link into a large cluster is left there).
//!
//! # Links into inner elements
//!
//! The same holds for a link into an element with children: its factor
//! `F_rs` is exact over the receiver, but pushed to every leaf below alike
//! it misplaces `rho B_s (F_max - F_min)`, which the refinement threshold
//! allows at coarse `EPS` and every leaf then shows (the preview directly,
//! the full gather through the senders of its last bounce). In the last
//! solve such a link lights the receiver's parts `j` ([`Hierarchy::parts`],
//! at most [`MAX_RECEIVER_PARTS`], descendants level by level) by
//!
//! ```text
//! E_j = V F_rs B_sent w_j,   w_j = A_r F_js / sum_u A_u F_us
//! ```
//!
//! (`B_sent` what the link sends, [`crate::gather::SenderTerms`];
//! `F_js` Lambert's factor from part `j`'s centroid to the sender (over
//! all of `j` where `j` touches an element sender,
//! [`Hierarchy::weight_between`]), or to a
//! cluster sender's sampled points; times `j`'s own visibility of an
//! element sender where the link is partly occluded), so
//! `sum_j A_j E_j = A_r V F_rs B_sent`: the link's flux, shared by factor.
//! Below a part its light is shared by the factors of the elements there
//! (from their centroids, over them where they touch an element sender),
//! untraced ([`SPREAD_PARTS`] of them, `spread_below`), and pushed alike
//! below those; where the link is partly
//! occluded, a part that a shadow edge crosses opens into its children
//! first (`part_weights`, at most [`MAX_SHADOWED_PARTS`] parts), and the
//! link's visible fraction becomes what its parts measured,
//!
//! ```text
//! V = sum_j A_j F_js V_js / sum_j A_j F_js
//! ```
//!
//! (`V_js` part `j`'s own visibility of the sender), as a link into a
//! cluster takes what its triangles measured ([`Measured`]). The parts
//! cast 8 to 16 rays each, tens of parts a link, where the link's own
//! estimate had 16 rays over the whole receiver: with `V` about 1/4 that
//! is 44% noise, and kept as the flux that the parts share it lifted or
//! sank every part below the link alike. On the built-in Cornell box at
//! `EPS` 5e-4 (seed 8) a floor leaf 2.7 cm from the short block's face, in
//! its umbra, got 25% more light from a ceiling triangle it sees whole
//! than that triangle's factor brings it, through a link into a coarse
//! floor element with `V` 0.244; the floor within 5 cm of the face was 5.1%
//! over what a gather of the solution's own leaves gives its exposed
//! points (1.7% now), and the face it lights 3.1% over the `EPS` 2.5e-5
//! solve (2.2% now).
//! Over seeds 1-5 the preview against Mitsuba went from 1.252% to 1.164%
//! relative RMSE at 4e-4 (the worst surface per seed 0.34-0.52% ->
//! 0.18-0.28%) and from 1.486% to 1.375% at 5e-4 (0.51-1.04% ->
//! 0.36-0.56%), for no more rays; `plants-2k` at its default `EPS` 1e-3
//! from 2.93% to 2.70%. Test `receiver_parts.rs` (a
//! floor under a small lamp, against Lambert's closed form per leaf):
//! worst leaf 14.8% -> 0.46% at `EPS` 1e-2, 6.0% -> 0.14% at 3e-3. The
//! Cornell box (full gather against Mitsuba, relative RMSE): 1.77% ->
//! 1.43% at `EPS` 1e-2, 0.93% -> 0.80% at 2e-3; the preview 7.9% -> 5.2%
//! at 1e-2. Doing it in every pass's solve (the refinement then judges the
//! distributed radiosity) gave the same (1.40%, 0.81%) at 15% more time;
//! 64 parts instead of 16, or four points per part instead of the
//! centroid, changed the figures by less than 0.02%. Later, with finer
//! solves, 64 parts took the preview's relative RMSE 7%, 5% and 3% lower
//! at `EPS` 4e-4, 2e-4 and 1e-4 (seeds 1-3; 256 parts a little more) for
//! 9-10% more solve time (one thread, a third more part rays), about
//! what the next finer `EPS` buys in that time, so 16 stayed.
//!
//! A link into a cluster lights each triangle alike in its turn, and the
//! Cornell box's floor is two triangles: the ceiling's light through the
//! cluster of the floor and the short block reached the floor in the
//! blocks' sky shadow as brightly as in the open, and the short block,
//! whose face towards the camera that floor lights, was +0.86% in the
//! preview against Mitsuba at `EPS` 4e-4 (mean over seeds 1-5), +4.0% at
//! 7e-4. So in
//! the last solve a link's light on a triangle with children
//! ([`PartSource::Parts`]) goes on to the triangle's parts by the same
//! weights, as a link into that triangle would: the short block +0.51%
//! at 4e-4 and +2.3% at 7e-4, the worst surface over seeds 1-5 0.60% to
//! 0.96% at 4e-4 (0.73% to 1.48% before); about 2% more solve time at
//! 4e-4 (one thread), none measurable on `plants-2k`.
//!
//! Pushing the cluster's irradiance to all its triangles alike instead (the
//! isotropic push) lit the faces of the Cornell box's short block that face
//! away from the lamp like the ones that face it: at `EPS` 1e-2 the faces
//! were -18% to +235% off the unclustered solve at `EPS` 2e-4, the block
//! +85% in the preview against Mitsuba (issue 10).

use crate::elements::{Hierarchy, FAR_PART};
use crate::links::{box_distance, Link};
use crate::nodes::key;
use crate::rows::Rows;
use crate::slopes::{self, DirectSlope, VisibilitySlope};
use crate::gather::{Resolution, SenderTerms};
use crate::visibility::{self, Tracer};
use radiometry::form_factor::{point_kernel, DUNAVANT_5};
use radiometry::sampling::Stream;
use rayon::prelude::*;
use schemas::solution::Node;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Most parts a sender is opened into to weigh a cluster receiver's
/// triangles.
pub const MAX_PARTS: usize = 16;

/// Points sampled on a sender part that is still a cluster.
pub const CLUSTER_PART_SAMPLES: usize = 16;

/// Most triangles below a cluster receiver whose links are distributed by
/// weight: a cluster of more gathers its links' irradiance and pushes it to
/// all its triangles alike, as before. The weights cost `triangles x parts`
/// Lambert factors per link: distributing every cluster link of the 99k
/// triangle box (591k links) took 236 s per solve, against seconds.
pub const MAX_RECEIVER_TRIANGLES: usize = 16;

/// Most triangles below a cluster receiver whose links the last solve
/// distributes to them by their own factors to the whole sender, where
/// the cluster holds more than [`MAX_RECEIVER_TRIANGLES`] and is not flat
/// (module docs): each such link costs seven Lambert factors per triangle.
pub const MAX_ORIENTED_TRIANGLES: usize = 256;

/// A cluster whose triangles' normals all lie within this cosine of one
/// another (about 8 degrees) is flat: its triangles face a sender alike,
/// and the last solve pushes a large one's light to them by area.
pub const FLAT_CLUSTER: f64 = 0.99;

/// Whether link `l`'s light goes to its cluster receiver's triangles by
/// weight: a cluster of at most [`MAX_RECEIVER_TRIANGLES`], in every
/// build; in the `last` solve also one of at most
/// [`MAX_ORIENTED_TRIANGLES`] that is not flat ([`FLAT_CLUSTER`]).
fn to_triangles(h: &Hierarchy, l: &Link, last: bool) -> bool {
    if !matches!(l.receiver, Node::Cluster(_)) {
        return false;
    }
    let triangles = h.triangles_below(l.receiver);
    let flat = || {
        let n = h.triangles[triangles[0] as usize].normal;
        triangles.iter().all(|&t| h.triangles[t as usize].normal.dot(n) >= FLAT_CLUSTER)
    };
    triangles.len() <= MAX_RECEIVER_TRIANGLES || (last && triangles.len() <= MAX_ORIENTED_TRIANGLES && !flat())
}

/// What one build of [`ReceiverTerms`] leaves for the next.
///
/// The weights of the links into clusters of the last build, by link ends,
/// with the sender's parts they were computed for: a link that refinement
/// kept, whose sender still opens into the same parts, has the same weights
/// (those without visibility), so the next pass's build takes them from
/// here instead of computing the Lambert factors again (on plants-10k at
/// `EPS` 1e-2 a build took about 1 s of every pass).
///
/// And the traced part weights of the links into the leaves a
/// [`Build::Opened`] opened, by link ends: the last build, which follows it
/// on the same hierarchy, weighs those links' parts again with the same
/// arguments and the same random streams, so it takes them from here where
/// it traces the link too (a link whose parts measured it wholly visible or
/// wholly hidden is no longer partly occluded, and is weighed anew). The
/// same solution to the bit, but for the parts' ray counts where a budget
/// sets them ([`crate::links::Budget`]): the opened build counted them on
/// the radiosity before its own solve. On the built-in Cornell box the last build
/// casts 9% to 15% fewer part rays, and the solve is 1.9%, 1.2% and 3.5%
/// faster at `EPS` 1.5e-3, 1e-3 and 6e-4 (one thread, interleaved medians
/// of 11, 11 and 7).
#[derive(Default)]
pub struct WeightCache {
    clusters: HashMap<(Node, Node), (Vec<Node>, Weights, Measured)>,
    opened: HashMap<(Node, Node), Weighing>,
}

/// Per input triangle, the links into clusters above it, each with its
/// sender's parts and their weights `w_tp`.
pub struct ReceiverTerms {
    /// Visibility rays cast for the weights.
    pub rays: usize,
    /// Row `t`: `(link index, (part's flat node index, w_tp))`.
    rows: Rows<(usize, f64)>,
    /// Per link, whether its light goes to its receiver's triangles or parts
    /// by weight (and not to the receiver).
    distributed: Vec<bool>,
    /// Row `e` (element index): `(k, w_j)` for the links into an inner
    /// element above `e` of which `e` is a part ([`part_weights`]), `k`
    /// indexing `part_sources`.
    element_rows: Rows<f64>,
    /// What lights the parts, in the order of `k`.
    pub part_sources: Vec<PartSource>,
    /// Emitters' visibility slopes on the leaves their partly occluded
    /// links' parts traced ([`crate::slopes`]).
    pub slopes: Vec<DirectSlope>,
}

/// What lights the parts of an inner element by weight
/// ([`ReceiverTerms::of_element`]).
pub enum PartSource {
    /// A link into the element: what its sender sends
    /// ([`crate::gather::SenderTerms`]).
    Link(usize),
    /// A link's light on one part of its receiver (the element) as that
    /// part sees the sender's parts, `(flat node index, w_tp)`: a triangle
    /// of a cluster receiver, or a part of an element receiver next to the
    /// sender ([`NEAR_RECEIVER`]).
    Parts {
        /// The link.
        link: usize,
        /// The sender's parts and their weights on the element.
        terms: Vec<(usize, f64)>,
    },
}

impl PartSource {
    /// The link whose light it is.
    pub fn link(&self) -> usize {
        match self {
            PartSource::Link(l) | PartSource::Parts { link: l, .. } => *l,
        }
    }

    /// The sum of the weights of what it sends: 1 for a link (its
    /// sender's terms sum to 1), `sum_p w_tp` on a triangle.
    pub fn weight(&self) -> f64 {
        match self {
            PartSource::Link(_) => 1.0,
            PartSource::Parts { terms, .. } => terms.iter().map(|t| t.1).sum(),
        }
    }
}

impl ReceiverTerms {
    /// The terms of every link of `links` whose receiver is a cluster, and
    /// of the links into inner elements that `build` distributes to their
    /// parts (module docs); a traced build weighs the pairs of partly
    /// occluded links by their visibility. Weights without visibility come
    /// from `cache` where it holds them, and a build without visibility
    /// leaves its own there for the next. Each link distributed to its
    /// triangles takes the factor, and with visibility the visible
    /// fraction, that its triangles' weights measured ([`Measured`]); a
    /// link whose parts were weighed by their own visibility takes the
    /// visible fraction they measured (module docs).
    pub fn new(h: &Hierarchy, links: &mut [Link], build: Build, cache: &mut WeightCache) -> Self {
        let to_parts: Vec<bool> = links.iter().map(|l| build.sends_to_parts(h, l)).collect();
        let tracer = build.tracer();
        // Which links' parts this build weighs by their visibility.
        let traced: Vec<bool> = links.iter().zip(&to_parts).map(|(l, &d)| d && tracer.is_some() && l.partly_occluded()).collect();
        // The opened build's traced weights, for the links this build traces.
        let mut from_opened = std::mem::take(&mut cache.opened);
        let reused: Vec<Option<Weighing>> = links.iter().zip(&traced).map(|(l, &t)| if t { from_opened.remove(&(l.receiver, l.sender)) } else { None }).collect();
        let part_built: Vec<Option<Weighing>> = links
            .par_iter()
            .zip(&to_parts)
            .zip(&traced)
            .zip(reused)
            .map(|(((l, &d), &t), reused)| d.then(|| reused.unwrap_or_else(|| part_weights(h, l.receiver, l.sender, tracer.filter(|_| t), l.visible()))))
            .collect();
        let mut seen: Vec<Option<PartViews>> = links
            .par_iter()
            .zip(&part_built)
            .map(|(l, built)| near_sender_terms(h, l, &built.as_ref()?.shares, build.resolution()?, tracer?))
            .collect();
        let mut by_element: Vec<Vec<(usize, f64)>> = vec![Vec::new(); h.elements.len()];
        let mut part_sources = Vec::new();
        for (l, weighing) in part_built.iter().enumerate().filter_map(|(l, b)| Some((l, b.as_ref()?))) {
            if let Some(v) = weighing.measured {
                links[l].visibility = Some(v as f32);
            }
            if let Some(seen) = seen[l].take() {
                // One source per part, shared by the elements below it.
                for (shares, terms) in by_part(&weighing.shares).zip(seen) {
                    for &(e, w, _) in shares {
                        by_element[e as usize].push((part_sources.len(), w));
                    }
                    part_sources.push(PartSource::Parts { link: l, terms });
                }
                continue;
            }
            for &(e, w, _) in &weighing.shares {
                by_element[e as usize].push((part_sources.len(), w));
            }
            part_sources.push(PartSource::Link(l));
        }
        // Links into clusters are traced in the last solve only.
        let last = matches!(build, Build::Last { .. });
        let visibility = tracer.filter(|_| last);
        let to_triangles: Vec<bool> = links.iter().map(|l| to_triangles(h, l, last)).collect();
        let built: Vec<Option<Built>> = links
            .par_iter()
            .zip(&to_triangles)
            .map(|(l, &d)| {
                if !d {
                    return None;
                }
                // A cluster of more triangles weighs them by their factor
                // to the whole sender, untraced (module docs).
                let whole = h.triangles_below(l.receiver).len() > MAX_RECEIVER_TRIANGLES;
                let nodes = if whole { vec![l.sender] } else { h.parts(l.sender, MAX_PARTS) };
                let visibility = visibility.filter(|_| l.partly_occluded() && !whole);
                Some(match cache.clusters.get(&(l.receiver, l.sender)) {
                    Some((cached, w, measured)) if visibility.is_none() && *cached == nodes => (nodes, w.clone(), *measured, 0),
                    _ => {
                        let (w, measured, rays) = weights(h, l, &nodes, visibility);
                        (nodes, w, measured, rays)
                    }
                })
            })
            .collect();
        // In the last solve a distributed link's light on a triangle with
        // children goes on to the triangle's parts, as a link into it would.
        let triangle_parts: Vec<Vec<(u32, Weighing)>> = links
            .par_iter()
            .zip(&built)
            .map(|(l, b)| match (b, visibility) {
                (Some((_, list, _, _)), Some(_)) => {
                    let mut triangles: Vec<u32> = list.iter().map(|x| x.0).filter(|&t| !h.elements[t as usize].is_leaf()).collect();
                    triangles.dedup();
                    triangles
                        .into_iter()
                        .map(|t| (t, part_weights(h, Node::Element(t), l.sender, visibility.filter(|_| l.partly_occluded()), l.visible())))
                        .collect()
                }
                _ => Vec::new(),
            })
            .collect();
        let rays = built.iter().flatten().map(|b| b.3).sum::<usize>()
            + part_built.iter().flatten().map(|b| b.rays).sum::<usize>()
            + triangle_parts.iter().flatten().map(|x| x.1.rays).sum::<usize>();
        let slopes = part_built.iter().flatten().chain(triangle_parts.iter().flatten().map(|x| &x.1)).flat_map(|w| w.slopes.iter().copied()).collect();
        let mut lists: Vec<Vec<(usize, (usize, f64))>> = vec![Vec::new(); h.triangles.len()];
        for (l, (_, list, measured, _)) in built.iter().enumerate().filter_map(|(l, b)| Some((l, b.as_ref()?))) {
            let parted = &triangle_parts[l];
            for &(t, p, w) in list.iter().filter(|x| !parted.iter().any(|y| y.0 == x.0)) {
                lists[t as usize].push((l, (p, w)));
            }
            for (t, weighing) in parted {
                let terms = list.iter().filter(|x| x.0 == *t).map(|&(_, p, w)| (p, w)).collect();
                for &(e, u, _) in &weighing.shares {
                    by_element[e as usize].push((part_sources.len(), u));
                }
                part_sources.push(PartSource::Parts { link: l, terms });
            }
            measured.apply(&mut links[l]);
        }
        let element_rows = Rows::from_lists(by_element);
        if matches!(build, Build::Opened { .. }) {
            // Cast already: the last build casts none for them.
            cache.opened = links
                .iter()
                .zip(&traced)
                .zip(part_built)
                .filter_map(|((l, &t), w)| Some(((l.receiver, l.sender), Weighing { rays: 0, ..w.filter(|_| t)? })))
                .collect();
        }
        // The next pass reads the weights of a build without visibility.
        if visibility.is_none() {
            cache.clusters = links.iter().zip(built).filter_map(|(l, b)| b.map(|(nodes, w, measured, _)| ((l.receiver, l.sender), (nodes, w, measured)))).collect();
        }
        let distributed = to_triangles.iter().zip(&to_parts).map(|(a, b)| *a || *b).collect();
        ReceiverTerms { rays, rows: Rows::from_lists(lists), distributed, element_rows, part_sources, slopes }
    }

    /// Whether link `l`'s light goes to its receiver's triangles or parts by
    /// weight.
    pub fn distributed(&self, l: usize) -> bool {
        self.distributed.get(l).copied().unwrap_or(false)
    }

    /// The links into clusters above input triangle `t`, each with a part
    /// of its sender (flat node index) and its weight `w_tp`.
    pub fn of_triangle(&self, t: usize) -> impl Iterator<Item = (usize, &(usize, f64))> {
        self.rows.row(t)
    }

    /// What lights element `e` as a part of an inner element above it,
    /// each as its place `k` in [`Self::part_sources`] with its weight
    /// `w_j`.
    pub fn of_element(&self, e: usize) -> impl Iterator<Item = (usize, &f64)> {
        self.element_rows.row(e)
    }
}

/// Which links a build of [`ReceiverTerms`] distributes by weight, and
/// what it traces.
#[derive(Clone, Copy)]
pub enum Build<'a> {
    /// A pass's means' solve: the links into clusters, by their factors
    /// alone.
    Means,
    /// The solve that lights the leaves the last solve opens
    /// ([`crate::shadowed`]; `opened[e]`, element index): as
    /// [`Build::Means`], and the links into those leaves to their
    /// children, partly occluded ones by each child's visibility.
    Opened {
        /// What the children's visibility is traced with.
        tracer: Tracer<'a>,
        /// Per element, whether the last solve opened it.
        opened: &'a [bool],
    },
    /// The last solve: every link into a cluster or an inner element,
    /// partly occluded ones by visibility; with `resolution`, the parts of
    /// a receiver next to its sender see the sender for themselves
    /// (`near_sender_terms`).
    Last {
        /// What the visibility is traced with.
        tracer: Tracer<'a>,
        /// The solved radiosity the senders are resolved by.
        resolution: Option<Resolution<'a>>,
    },
}

impl<'a> Build<'a> {
    /// Whether link `l`'s light goes to its receiver's parts by weight.
    fn sends_to_parts(&self, h: &Hierarchy, l: &Link) -> bool {
        let Node::Element(e) = l.receiver else { return false };
        let inner = !h.elements[e as usize].is_leaf();
        match self {
            Build::Means => false,
            Build::Opened { opened, .. } => inner && opened[e as usize],
            Build::Last { .. } => inner,
        }
    }

    /// What it traces with, if it traces.
    fn tracer(&self) -> Option<Tracer<'a>> {
        match *self {
            Build::Means => None,
            Build::Opened { tracer, .. } | Build::Last { tracer, .. } => Some(tracer),
        }
    }

    /// The solved radiosity it resolves senders by, if any.
    fn resolution(&self) -> Option<Resolution<'a>> {
        match *self {
            Build::Last { resolution, .. } => resolution,
            _ => None,
        }
    }
}

/// Most parts an inner element receiver is opened into.
pub const MAX_RECEIVER_PARTS: usize = 16;

/// Most parts an inner element receiver has once the parts a shadow edge
/// crosses are opened further.
pub const MAX_SHADOWED_PARTS: usize = 64;

/// How near, in radii of an element receiver, its centroid must come to
/// its sender's bounding box for each of its parts to weigh the sender's
/// parts from its own centroid (`near_sender_terms`).
pub const NEAR_RECEIVER: f64 = 1.0;

/// The sender terms of a link into an inner element, one list per part of
/// its receiver (`parts`, as [`part_weights`] gave them), each as that
/// part sees the sender ([`SenderTerms`] from the part's centroid), where
/// the receiver lies within [`NEAR_RECEIVER`] radii of the sender, the
/// sender's radiosity is not uniform (`resolution`) and the link is not
/// partly occluded; else `None`: every part takes what the link sends its
/// receiver's centroid.
///
/// The sender's parts are weighed by the kernel from the receiver's
/// centroid, and next to the sender that is not what its parts see: where
/// a wall stands on a floor, a floor element along the wall's base sees
/// the wall's base, in the floor's contact shadow and dark, under nearly
/// half its sky, and the parts of the floor element at the crease see it
/// more than its centroid does. In `tests/tests/contact_shadow.rs` (a wall
/// lit only by the floor, which the wall shadows from a lamp behind it)
/// at `EPS` 4e-4, one link from a whole wall triangle into a floor
/// element at the crease sent 0.00466 from the element's centroid where
/// the element's area sees 0.00417 of the wall's leaves on average and
/// its part at the crease 0.00299: that part's leaves were 51% to 58%
/// over the reference, and the wall's leaves along its base, lit by them,
/// 8% to 21% (worst wall leaf +236%, the base's mean +7.8%). With each
/// part seeing for itself: worst +50%, the base +2.9%; at 2e-4 +6.7% and
/// +0.42% -> +5.8% and +0.28%; with the wall's reflectance 0.1 and a
/// smaller lamp, at 2e-4, worst +111% -> +26%. Two radii instead of one
/// changed these by under 0.1% for twice the added time. On the built-in
/// Cornell box at `EPS` 4e-4 the preview against Mitsuba is the same
/// (seeds 1-5: relative RMSE 1.355% -> 1.352%), for 4% more solve time on
/// one thread. Partly occluded links keep the one list: each part's view
/// would need its own visibility to each sender part.
fn near_sender_terms(h: &Hierarchy, l: &Link, parts: &PartWeights, resolution: Resolution, tracer: Tracer) -> Option<PartViews> {
    let Node::Element(r) = l.receiver else { return None };
    if l.partly_occluded() || resolution.uniform_sender(h, l) {
        return None;
    }
    let c = h.centroid(r);
    (box_distance((c, c), h.bounds(l.sender)) <= NEAR_RECEIVER * h.radius(r)).then(|| by_part(parts).map(|shares| SenderTerms::seen_from(h, shares[0].2, l, resolution, tracer).0).collect())
}

/// `f`, receiving element `receiver`'s factor to sender part `part`,
/// weighed where `visibility` is given (a partly occluded link, `v_link`
/// its visible fraction) by visibility: an element part's own
/// ([`visibility::visible_factor`] with `pairs` rays), a cluster part the
/// link's; and the rays cast.
fn seen_factor(h: &Hierarchy, visibility: Option<Tracer>, receiver: u32, part: Node, f: f64, v_link: f64, pairs: usize) -> (f64, usize) {
    match (visibility, part) {
        (Some(tracer), Node::Element(e)) => visibility::visible_factor(h, tracer, receiver, e, f, pairs, None),
        (Some(_), Node::Cluster(_)) => (f * v_link, 0),
        (None, _) => (f, 0),
    }
}

/// `(e, w_e, j)`: an element at or below part `j` of a receiving element
/// (element indices) and its weight ([`part_weights`]), grouped by part.
type PartWeights = Vec<(u32, f64, u32)>;

/// The groups of `shares` that share one part, in order.
fn by_part(shares: &[(u32, f64, u32)]) -> impl Iterator<Item = &[(u32, f64, u32)]> {
    shares.chunk_by(|a, b| a.2 == b.2)
}

/// Per part of a receiver, the sender terms `(flat node index, w)` it sees.
type PartViews = Vec<Vec<(usize, f64)>>;

/// `(e, w_e, j)` ([`PartWeights`]: `spread_below` shares each part's
/// weight among the elements below it) for the parts `j` of an inner
/// element `receiver` lit by
/// `sender` (a link's ends, or a cluster link's sender and one of the
/// cluster's triangles), `w_j = A_r F_js / sum_u A_u F_us` with `F_js` the
/// factor from part `j`'s centroid to the sender (over all of `j` where it
/// touches an element sender, [`Hierarchy::weight_between`]; times their visibility,
/// with `visibility`, given where the link is partly occluded and its
/// sender is an element), and the rays cast. Where no part sees the
/// sender, every part gets the same (`w_j = 1`). With `visibility` and an
/// element sender, also the link's visible fraction as the parts measure
/// it, `sum_j A_j F_js V_js / sum_j A_j F_js` (module docs). With `visibility`, a
/// part that a shadow edge crosses (its visible factor strictly between 0
/// and its factor) opens into its children, the parts that carry most
/// light first, while the parts number at most [`MAX_SHADOWED_PARTS`]:
/// below a part the visibility is the part's (the light was then pushed
/// alike there), and on the built-in Cornell box
/// at `EPS` 4e-4 the floor within 5 cm of the short block's face, in its
/// umbra, got the ceiling's light of the 16 parts of the floor's coarse
/// elements it lies in, 5% to 6% over the `EPS` 5e-5 solve (seeds 1 and 3;
/// 0.9% to 1.6% now). Over seeds 1-5 the preview against Mitsuba went from
/// 1.43% to 1.39% relative RMSE at 4e-4 (short block +0.69% -> +0.55%,
/// the worst surface per seed 0.48-0.81% -> 0.54-0.71%) and 1.02% to
/// 0.98% at 2.5e-4, for 6-7% more solve time (one thread; `plants-2k`
/// 2%, its relative RMSE 2.96% -> 2.95%). 256 parts everywhere gave the
/// same band for much more.
fn part_weights(h: &Hierarchy, receiver: Node, sender: Node, visibility: Option<Tracer>, v_link: f64) -> Weighing {
    let Node::Element(r) = receiver else { return Weighing { shares: Vec::new(), rays: 0, measured: None, slopes: Vec::new() } };
    let visibility = visibility.map(|t| t.within(h, receiver, sender));
    let sending = Part::new(h, sender, key(receiver));
    // An emitter's rays to a leaf right below the receiver measure the
    // slope of its light there too (crate::slopes).
    let emitter = visibility.zip(slopes::emitting(h, sender));
    let (mut rays, mut slopes) = (0, Vec::new());
    let mut weigh = |j: u32| {
        let factor = sending.weight(h, j);
        let pairs = part_rays(h, r, j, sender, factor, v_link, visibility);
        let part = &h.elements[j as usize];
        let (seen, cast) = match emitter.filter(|_| part.parent == r && part.is_leaf()) {
            Some((tracer, s)) => {
                let mut slope = VisibilitySlope::over(h, j);
                let seen = visibility::visible_factor(h, tracer, j, s, factor, pairs, Some(&mut slope));
                if let Some(g) = slope.gradient() {
                    slopes.push(DirectSlope { leaf: j, sender, factor_slope: g * factor });
                }
                seen
            }
            // A cluster sender: every part sees the same one, so the link's
            // fraction would scale all weights alike; it is left out.
            None => seen_factor(h, visibility, j, sender, factor, 1.0, pairs),
        };
        rays += cast;
        Weighed { element: j, area: h.area(Node::Element(j)), factor, seen }
    };
    let mut parts: Vec<Weighed> = h.parts(receiver, MAX_RECEIVER_PARTS).into_iter().filter_map(|p| if let Node::Element(j) = p { Some(weigh(j)) } else { None }).collect();
    // Parts a shadow edge crosses open into their children, the parts that
    // carry most light first, while the parts number at most
    // MAX_SHADOWED_PARTS.
    h.open_parts(&mut parts, MAX_SHADOWED_PARTS, |p| p.element, |p| p.crossed().then_some(p.area * p.factor), |c, _| weigh(c));
    let area: f64 = parts.iter().map(|p| p.area).sum();
    let seen: f64 = parts.iter().map(|p| p.area * p.seen).sum();
    let reached: f64 = parts.iter().map(|p| p.area * p.factor).sum();
    let even = !(seen > 0.0 && seen.is_finite());
    let measured = (visibility.is_some() && matches!(sender, Node::Element(_)) && reached > 0.0).then(|| (seen / reached).clamp(0.0, 1.0));
    let mut shares = Vec::with_capacity(parts.len());
    for p in &parts {
        spread_below(h, &sending, p.element, if even { 1.0 } else { p.seen * area / seen }, &mut shares);
    }
    Weighing { shares, rays, measured, slopes }
}

/// What [`part_weights`] found for a link's receiver.
struct Weighing {
    /// The shares of its parts.
    shares: PartWeights,
    /// Rays cast.
    rays: usize,
    /// The link's visible fraction as the parts measured it.
    measured: Option<f64>,
    /// An emitter's visibility slopes on the leaves right below the
    /// receiver ([`crate::slopes`]).
    slopes: Vec<DirectSlope>,
}

/// Most elements below a part of a receiving element that share its light
/// by their own factors ([`spread_below`]), level by level.
pub const SPREAD_PARTS: usize = 16;

/// Appends to `shares` part `j`'s weight `w` shared among the elements
/// below it, at most [`SPREAD_PARTS`] ([`Hierarchy::parts`]), each `e` by
/// its own factor to the sender, `F_e` (as the parts are weighed:
/// [`Part::weight`]), and its exposure `x_e` ([`crate::exposure`]: the
/// light lands on the exposed parts), keeping the part's light:
///
/// ```text
/// w_e = w F_e x_e sum_d A_d / sum_d A_d F_d x_d,      sum_e A_e w_e = w sum_d A_d
/// ```
///
/// The solve divides each element's light by its exposure, so an element
/// half buried under a solid now shows the light per exposed area that
/// its neighbours do; shared by factor alone it took a whole element's
/// share onto half the area and showed twice its light. On the built-in
/// Cornell box (preview against Mitsuba, seeds 1-8, interleaved medians
/// on one thread) the relative RMSE at `EPS` 1.5e-3, 1e-3 and 6.5e-4
/// went from 1.986%, 1.263% and 0.988% to 1.983%, 1.255% and 0.984%, in
/// the same time.
///
/// (`j` itself where it is a leaf, or where none of them sees the sender).
/// The part's visibility, traced, is what it is; only the kernel, which
/// costs no ray, is resolved below it. Pushed alike, the light of a part
/// reached its elements next to the sender as weakly as those far from
/// it, and the reverse. On the built-in Cornell box at `EPS` 1e-3 the
/// leaves along the room's creases were +0.86% over a ray-traced gather of
/// the solution's own field (seed 1, `bench-residual --leaves`; seed 2
/// +1.17%), those away from them -0.30% (-0.10%); now +0.31% (+0.63%) and
/// -0.14% (+0.06%), the leaves' rms 3.45% -> 3.18% (3.52% -> 3.47%).
/// Against the `EPS` 2.5e-5 solve, the leaves along the creases went from
/// +1.44% to +0.57% (seed 1). The preview against Mitsuba over seeds 1-8:
/// relative RMSE 2.016% -> 1.861% at 1e-3 (the worst surface per seed
/// 0.54-1.05% -> 0.42-0.98%) and 1.391% -> 1.268% at 6e-4 (0.28-0.47% ->
/// 0.25-0.42%), for 5.0% and 3.8% more solve time (one thread, interleaved
/// medians of 9 and 7), where a tighter `EPS` buys about 3% for 5%;
/// `plants-2k` solves in the same time. 4 elements instead of 16 gave
/// 1.875% at 1e-3, 64 the same as 16.
fn spread_below(h: &Hierarchy, sending: &Part, j: u32, w: f64, shares: &mut PartWeights) {
    if h.elements[j as usize].is_leaf() {
        shares.push((j, w, j));
        return;
    }
    let below: Vec<(u32, f64, f64)> = h
        .parts(Node::Element(j), SPREAD_PARTS)
        .into_iter()
        .filter_map(|d| if let Node::Element(d) = d { Some(d) } else { None })
        .map(|d| (d, h.area(Node::Element(d)), sending.weight(h, d) * h.exposure(d)))
        .collect();
    let reached: f64 = below.iter().map(|&(_, a, f)| a * f).sum();
    if !(reached > 0.0 && reached.is_finite()) {
        shares.push((j, w, j));
        return;
    }
    let area: f64 = below.iter().map(|&(_, a, _)| a).sum();
    shares.extend(below.iter().map(|&(d, _, f)| (d, w * f * area / reached, j)));
}

/// Visibility rays for part `j` of receiver `r` ([`part_weights`]), whose
/// factor to `sender` is `factor`, of a link `v_link` visible: at least
/// [`visibility::PART_VISIBILITY_RAYS`], more where the tracer's budget
/// wants them for the light the part takes ([`Tracer::part_rays`]), and
/// at least what a link's own visibility takes for a leaf right below `r`
/// (`visibility`'s [`Tracer::link_rays`]): it is what refinement would have made the
/// receiver of a link had it split this one, and where the last solve
/// opens a leaf a shadow edge crosses ([`crate::shadowed`]) its children
/// are the leaves that show the shadow. With 8 rays for them the floor
/// under a lamp and an occluder in `tests/tests/receiver_parts.rs` went
/// from 0.35% to 0.39% (L2 over the leaves, against the quadrature) at
/// `EPS` 4e-4 as the leaves in its penumbra opened, 0.31% with 16.
fn part_rays(h: &Hierarchy, r: u32, j: u32, sender: Node, factor: f64, v_link: f64, visibility: Option<Tracer>) -> usize {
    let part = &h.elements[j as usize];
    match visibility {
        Some(tracer) => {
            let least = if part.parent == r && part.is_leaf() { tracer.link_rays() } else { visibility::PART_VISIBILITY_RAYS };
            tracer.part_rays(h, j, sender, factor, v_link, least)
        }
        None => visibility::PART_VISIBILITY_RAYS,
    }
}

/// A part of a receiving element as [`part_weights`] weighs it.
struct Weighed {
    element: u32,
    /// Its area, m².
    area: f64,
    /// Its factor to the sender.
    factor: f64,
    /// That factor times its visibility of the sender, where traced.
    seen: f64,
}

impl Weighed {
    /// Whether a shadow edge crosses it: it sees part of what its factor
    /// reaches.
    fn crossed(&self) -> bool {
        self.seen > 0.0 && self.seen < self.factor
    }
}

/// `(t, p, w_tp)`: triangle, part (flat node index), weight.
type Weights = Vec<(u32, usize, f64)>;

/// What a link into a cluster is distributed by: its sender's parts, their
/// weights, the link as they measure it, and the rays cast for them.
type Built = (Vec<Node>, Weights, Measured, usize);

/// A link into a cluster as its triangles measure it: the area mean over
/// them of their factors to the sender's parts (`sum_t A_t sum_p F_tp /
/// A_r`), and where the pairs' visibility was traced, the visible share of
/// that (`sum_t A_t sum_p F_tp V_tp` over the same sum without `V_tp`).
/// The link's transport takes these rather than the 16 point pairs of its
/// estimate ([`crate::transfer`]) because refinement kept the link on that
/// estimate: links whose pairs happened to see more of the sender look
/// less occluded, pass the oracle and stay, so the kept ones' estimates
/// are biased. On the built-in Cornell box at `EPS` 4e-4 (seeds 1-4) the
/// ten links that stayed into the cluster of the floor and the short block
/// had `V` 0.77 to 0.94 where 16,384 pairs give 0.71 to 0.76 (and the
/// mean of their 16-pair `V` over 400 seeds is within 0.01 of that): their
/// `F V` was 1.07 to 1.31 times the 16,384 pairs' (0.54 to 7.3 over all 50
/// partly occluded cluster links), as their triangles measure it 0.94 to
/// 1.08 (0.69 to 1.13), the factor alone within 0.5%. The short block,
/// whose camera face that cluster lights, went from +1.31% to +0.86% in
/// the preview against Mitsuba (mean over seeds 1-5) with this alone.
#[derive(Clone, Copy, Debug)]
pub struct Measured {
    /// Unoccluded factor; `None` where no triangle sees the sender (the
    /// link's own estimate then stands).
    form_factor: Option<f64>,
    /// Visible fraction, where traced.
    visibility: Option<f32>,
}

impl Measured {
    /// Puts the measured factor and visibility on `link`.
    fn apply(&self, link: &mut Link) {
        if let Some(f) = self.form_factor {
            link.form_factor = f;
        }
        if let Some(v) = self.visibility {
            link.visibility = Some(v);
        }
    }
}

/// `(t, p, w_tp)` for the triangles `t` below link `l`'s cluster receiver
/// and the parts `p` (flat node index) of its sender, `nodes`, the link as
/// they measure it ([`Measured`]), and the rays cast for them (with
/// `visibility`, given where the link is partly occluded).
fn weights(h: &Hierarchy, l: &Link, nodes: &[Node], visibility: Option<Tracer>) -> (Weights, Measured, usize) {
    let v_link = f64::from(l.visibility.unwrap_or(1.0));
    let mut rays = 0;
    let triangles = h.triangles_below(l.receiver);
    let sender_area = h.area(l.sender);
    let parts: Vec<Part> = nodes.iter().map(|&p| Part::new(h, p, key(l.receiver))).collect();
    // Per triangle: its area and, per part, its factor and its seen factor.
    let factors: Vec<(f64, Vec<(f64, f64)>)> = triangles
        .iter()
        .map(|&t| {
            let g = &h.triangles[t as usize];
            let points = DUNAVANT_5.map(|(b, w)| (g.corners[0] * b[0] + g.corners[1] * b[1] + g.corners[2] * b[2], w));
            let f = parts
                .iter()
                .zip(nodes)
                .map(|(p, &node)| {
                    let f = points.iter().map(|&(x, w)| w * p.factor(h, x, g.normal)).sum::<f64>();
                    let (seen, cast) = seen_factor(h, visibility, t, node, f, v_link, visibility::PART_VISIBILITY_RAYS);
                    rays += cast;
                    (f, seen)
                })
                .collect();
            (h.area(Node::Element(t)), f)
        })
        .collect();
    let area: f64 = factors.iter().map(|f| f.0).sum();
    let total = |seen: bool| factors.iter().map(|f| f.0 * f.1.iter().map(|&(u, s)| if seen { s } else { u }).sum::<f64>()).sum::<f64>();
    let (unoccluded, seen) = (total(false), total(true));
    let even = !(unoccluded > 0.0 && unoccluded.is_finite());
    let measured = if even {
        Measured { form_factor: None, visibility: None }
    } else {
        Measured { form_factor: Some(unoccluded / area), visibility: visibility.map(|_| (seen / unoccluded) as f32) }
    };
    let mut out = Vec::new();
    for (&t, (_, f)) in triangles.iter().zip(&factors) {
        for (k, &p) in nodes.iter().enumerate() {
            let w = if even {
                h.area(p) / sender_area
            } else if seen > 0.0 {
                f[k].1 * area / seen
            } else {
                0.0
            };
            out.push((t, h.flat(p), w));
        }
    }
    (out, measured, rays)
}

/// A sender part, as a receiving triangle's points see it.
enum Part {
    /// An element.
    Element(u32),
    /// A cluster: its area and points `(position, normal)` on its surfaces.
    Points(f64, Vec<(glam::DVec3, glam::DVec3)>),
}

impl Part {
    fn new(h: &Hierarchy, node: Node, seed: u64) -> Self {
        match node {
            Node::Element(e) => Part::Element(e),
            Node::Cluster(_) => {
                let mut stream = Stream::new(seed ^ 0x7ece_1e5e, key(node), 0);
                let points = (0..CLUSTER_PART_SAMPLES).map(|k| h.sample(node, k, CLUSTER_PART_SAMPLES, &mut stream)).map(|p| (p.point, p.normal)).collect();
                Part::Points(h.area(node), points)
            }
        }
    }

    /// Element `j`'s factor to the part as a weight ([`part_weights`]):
    /// over all of `j` where it touches an element part
    /// ([`Hierarchy::weight_between`]), else from its centroid.
    fn weight(&self, h: &Hierarchy, j: u32) -> f64 {
        match *self {
            Part::Element(e) => h.weight_between(j, e),
            _ => self.factor(h, h.centroid(j), h.normal(j)),
        }
    }

    /// Factor from point `x` (normal `n`) to the part: taken as it is
    /// (the link's measured factor, [`Measured`]), so an element part from
    /// [`FAR_PART`] radii only by the three-point rule, not from
    /// [`crate::elements::SIBLING_PART`] as a weight among siblings.
    fn factor(&self, h: &Hierarchy, x: glam::DVec3, n: glam::DVec3) -> f64 {
        match self {
            Part::Element(e) => h.factor_beyond(x, n, *e, FAR_PART),
            Part::Points(area, points) => area * points.iter().map(|&(y, ny)| point_kernel(x, n, y, ny)).sum::<f64>() / (PI * points.len() as f64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scenes::{split_levels, FloorAndWall};
    use glam::DVec3;

    /// A cluster of a unit floor and a unit wall on its edge (triangles
    /// 0-3) under a lamp triangle (4) half a metre above the wall's top,
    /// and a link from the lamp into the cluster whose factor, the
    /// estimate refinement kept it on, is 40% high. The link takes the
    /// factor its triangles measure, and each quad gets its own: both
    /// within 0.1% of a 200 x 200 midpoint grid of Lambert's factor (they
    /// are within 0.015%; the centroids of each triangle's four 1:4
    /// subtriangles, as before, gave the factor +0.63%, the floor +1.6%
    /// and the wall -0.7%).
    #[test]
    fn a_link_into_a_cluster_delivers_its_triangles_factors_not_the_estimate_it_was_kept_on() {
        let scene = FloorAndWall::new(1.5);
        let quads = scene.quad_factors(200);
        let reference = (quads[0] + quads[1]) / 2.0;
        let kept = Link { receiver: Node::Cluster(1), sender: Node::Element(4), form_factor: 1.4 * reference, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: false };
        let mut links = [kept];
        let terms = ReceiverTerms::new(&scene.h, &mut links, Build::Means, &mut WeightCache::default());
        let f = links[0].form_factor;
        assert!((f / reference - 1.0).abs() < 1e-3, "factor {f} against {reference}");
        for (q, want) in quads.iter().enumerate() {
            // Triangles 2q and 2q + 1, of equal area: the quad's factor is
            // their mean.
            let got: f64 = (2 * q..2 * q + 2).flat_map(|t| terms.of_triangle(t)).map(|(_, &(_, w))| w * f).sum::<f64>() / 2.0;
            assert!((got / want - 1.0).abs() < 1e-3, "quad {q}: {got} against {want}");
        }
    }

    /// A floor triangle split three levels (64 leaves below its 16 parts)
    /// lit by the wall standing on its edge, through one unoccluded link
    /// into the floor's root. Each leaf's share of the link's light against
    /// its own factor to the wall's triangle over the leaf's area (adaptive
    /// Dunavant, 6 levels), relative to the leaves' mean factor: pushed
    /// alike below the parts, the leaves would get their part's mean, an
    /// L2 error of 18.6% (the crease's leaves far under their share);
    /// shared by their own factors it is 1.2%, the worst leaf 3.2% (what
    /// the centroid factors of the leaves near the crease miss).
    #[test]
    fn the_light_of_a_part_is_shared_below_it_by_the_elements_own_factors() {
        use radiometry::form_factor::{triangle_to_polygon, Quadrature};
        let FloorAndWall { mut h, .. } = FloorAndWall::new(2.0);
        let level = split_levels(&mut h, 0, 3);
        let (scene, occluders) = crate::test_scenes::traced(&h);
        let wall = 2;
        let link = Link { receiver: Node::Element(0), sender: Node::Element(wall), form_factor: 0.1, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: true };
        let mut links = [link];
        let terms = ReceiverTerms::new(&h, &mut links, Build::Last { tracer: Tracer::new(&scene, &occluders, 1, 16), resolution: None }, &mut WeightCache::default());
        let share = |leaf: u32| terms.of_element(leaf as usize).map(|(_, &w)| w).sum::<f64>();
        let factor = |e: u32| triangle_to_polygon(&h.elements[e as usize].points, h.normal(e), &h.elements[wall as usize].points, h.normal(wall), Quadrature::to_depth(6)).mean;
        let reference: Vec<f64> = level.iter().map(|&e| factor(e)).collect();
        let mean = reference.iter().sum::<f64>() / reference.len() as f64;
        let want: Vec<f64> = reference.iter().map(|r| r / mean).collect();
        let got: Vec<f64> = level.iter().map(|&e| share(e)).collect();
        // Pushed alike: each group of four leaves (a part's children) at
        // their mean.
        let alike: Vec<f64> = (0..want.len()).map(|k| want[k / 4 * 4..k / 4 * 4 + 4].iter().sum::<f64>() / 4.0).collect();
        let l2 = |v: &[f64]| (v.iter().zip(&want).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / want.iter().map(|b| b * b).sum::<f64>()).sqrt();
        let (shared, pushed) = (l2(&got), l2(&alike));
        assert!(shared < 0.1 * pushed, "L2 {shared} against {pushed} pushed alike");
        let worst = got.iter().zip(&want).map(|(g, w)| (g / w - 1.0).abs()).fold(0.0, f64::max);
        assert!(worst < 0.05, "worst leaf {worst}; L2 {shared} against {pushed} pushed alike");
    }

    /// The same link with one leaf half buried (exposure 1/2, its parent's
    /// 7/8): below its part that leaf takes half the share its factor
    /// alone gives it, so that the solve's division by its exposure shows
    /// it the light per exposed area its siblings get, and the part's light
    /// is kept (`spread_below`).
    #[test]
    fn the_light_of_a_part_lands_on_the_exposed_parts_below_it() {
        let FloorAndWall { mut h, .. } = FloorAndWall::new(2.0);
        let level = split_levels(&mut h, 0, 3);
        let (scene, occluders) = crate::test_scenes::traced(&h);
        let link = Link { receiver: Node::Element(0), sender: Node::Element(2), form_factor: 0.1, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: true };
        let shares = |h: &Hierarchy| -> Vec<f64> {
            let terms = ReceiverTerms::new(h, &mut [link], Build::Last { tracer: Tracer::new(&scene, &occluders, 1, 16), resolution: None }, &mut WeightCache::default());
            level.iter().map(|&e| terms.of_element(e as usize).map(|(_, &w)| w).sum()).collect()
        };
        h.exposure = vec![1.0; h.elements.len()];
        let open = shares(&h);
        let half = level[1];
        h.exposure[half as usize] = 0.5;
        h.exposure[h.elements[half as usize].parent as usize] = 0.875;
        let buried = shares(&h);
        // The leaves of one part: `level`'s first four, of equal area.
        let ratio = buried[1] / buried[0] / (open[1] / open[0]);
        assert!((ratio - 0.5).abs() < 1e-12, "the half-buried leaf's share against its sibling's, over the open ones': {ratio}");
        let (kept, was) = (buried[..4].iter().sum::<f64>(), open[..4].iter().sum::<f64>());
        assert!((kept - was).abs() < 1e-12 * was, "the part's light {kept} against {was}");
        assert_eq!(buried[4..], open[4..], "the other parts' leaves");
    }

    /// The scene of the next test: a unit floor (triangles 0 and 1, the
    /// first split to level 3, whose 64 leaves are returned), a lamp quad
    /// 1 m up facing down (triangles 2 and 3) and a black sheet 10 cm up
    /// over `x < 0.4` (4 and 5); and a partly occluded link from the lamp's
    /// triangle 2 into floor triangle 0.
    fn floor_under_sheet() -> (Hierarchy, Vec<u32>, Link) {
        use glam::dvec3;
        use test_support::meshes::{manifest, material, quads};
        let mesh = quads(&[
            (DVec3::ZERO, DVec3::X, DVec3::Y, 0, 0),
            (dvec3(0.25, 0.25, 1.0), DVec3::Y * 0.5, DVec3::X * 0.5, 1, 1),
            (dvec3(-1.0, -1.0, 0.1), DVec3::X * 1.4, DVec3::Y * 3.0, 2, 2),
        ]);
        let manifest = manifest(3, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3]), material([0.0; 3], [0.0; 3])]);
        let mut h = Hierarchy::new(&mesh, &manifest, None, None);
        let level = split_levels(&mut h, 0, 3);
        let link = Link { receiver: Node::Element(0), sender: Node::Element(2), form_factor: 0.1, spread: 0.0, visibility: Some(0.5), occluder_distance: 0.5, clear: false };
        (h, level, link)
    }

    /// The last build takes the part weights that an opened build traced
    /// for a link from the cache ([`WeightCache`]), casting no ray for
    /// them: the same terms on every element and the same measured visible
    /// fraction, to the bit, as a last build on its own, which casts rays.
    #[test]
    fn the_last_build_takes_the_opened_builds_traced_part_weights() {
        let (h, _, link) = floor_under_sheet();
        let (scene, occluders) = crate::test_scenes::traced(&h);
        let tracer = Tracer::new(&scene, &occluders, 1, 16);
        let mut alone = [link];
        let own = ReceiverTerms::new(&h, &mut alone, Build::Last { tracer, resolution: None }, &mut WeightCache::default());
        let mut opened = vec![false; h.elements.len()];
        opened[0] = true;
        let (mut links, mut cache) = ([link], WeightCache::default());
        let first = ReceiverTerms::new(&h, &mut links, Build::Opened { tracer, opened: &opened }, &mut cache);
        let last = ReceiverTerms::new(&h, &mut links, Build::Last { tracer, resolution: None }, &mut cache);
        assert!(own.rays > 0 && first.rays == own.rays, "rays: alone {}, opened {}", own.rays, first.rays);
        assert_eq!(last.rays, 0, "the last build cast rays again");
        assert_eq!(links[0].visibility, alone[0].visibility);
        let rows = |t: &ReceiverTerms, e: usize| t.of_element(e).map(|(k, w)| (k, w.to_bits())).collect::<Vec<_>>();
        for e in 0..h.elements.len() {
            assert_eq!(rows(&last, e), rows(&own, e), "element {e}");
        }
        assert_eq!(last.slopes.len(), own.slopes.len());
    }

    /// A lamp (`x, y` in [0.25, 0.75], 1 m up, facing down) over a unit
    /// floor, and a black sheet 10 cm up over `x < 0.4`: the floor's
    /// shadow edge, 5 cm wide, runs across the parts of the floor's
    /// triangle 0 along `x = 0.4`. A partly occluded link from the lamp's
    /// triangle into triangle 0, opened to level 3 (64 leaves), lights its
    /// 16 parts (level 2) by their own visibility, and those the edge
    /// crosses open into their children, so the light below them follows
    /// the edge. Each leaf's share against its own visible factor (a 24 x
    /// 24 midpoint grid over the leaf and 16 x 16 over the lamp, with the
    /// segment test against the sheet written here): the relative L2 over
    /// the leaves must be under half of what the best share constant over
    /// each of the 16 parts (the mean of the reference over it) reaches,
    /// as the parts alone gave. It is 0.066 against 0.200. The link, given
    /// a visible fraction of 0.5, takes the one its parts measured: within
    /// 1% of the leaves' visible factor over their unoccluded one (0.8447
    /// against 0.8429).
    #[test]
    fn a_partly_occluded_link_into_an_element_follows_the_shadow_edge_below_its_parts() {
        use glam::dvec3;
        let (h, level, link) = floor_under_sheet();
        let (scene, occluders) = crate::test_scenes::traced(&h);
        let mut links = [link];
        let terms = ReceiverTerms::new(&h, &mut links, Build::Last { tracer: Tracer::new(&scene, &occluders, 1, 16), resolution: None }, &mut WeightCache::default());
        // Each leaf's share: its own part's weight, or the part above it.
        let share = |leaf: u32| {
            let mut e = leaf;
            loop {
                let w: f64 = terms.of_element(e as usize).map(|(_, &w)| w).sum();
                if w > 0.0 || h.elements[e as usize].parent == schemas::solution::NONE {
                    return w;
                }
                e = h.elements[e as usize].parent;
            }
        };
        // The factor from `p` to the lamp's triangle the sheet leaves
        // visible (all of it without `sheet`).
        let visible = |p: DVec3, sheet: bool| {
            let (m, mut sum) = (16, 0.0);
            for i in 0..m {
                for j in 0..m {
                    let q = dvec3(0.25 + 0.5 * (i as f64 + 0.5) / m as f64, 0.25 + 0.5 * (j as f64 + 0.5) / m as f64, 1.0);
                    // The link's sender is the lamp's triangle 2, its
                    // half y >= x; a segment crosses z = 0.1 a tenth of
                    // the way up.
                    if q.y >= q.x && (!sheet || p.x + 0.1 * (q.x - p.x) >= 0.4) {
                        sum += point_kernel(p, DVec3::Z, q, -DVec3::Z) * 0.25 / (m * m) as f64 / PI;
                    }
                }
            }
            sum
        };
        let mean_over = |e: u32, sheet: bool| {
            let c = h.elements[e as usize].points;
            let m = 24;
            let mut sum = 0.0;
            for i in 0..m {
                for j in 0..m - i {
                    let b = [(i as f64 + 1.0 / 3.0) / m as f64, (j as f64 + 1.0 / 3.0) / m as f64];
                    sum += visible(c[0] + (c[1] - c[0]) * b[0] + (c[2] - c[0]) * b[1], sheet);
                    if i + j + 1 < m {
                        let b = [(i as f64 + 2.0 / 3.0) / m as f64, (j as f64 + 2.0 / 3.0) / m as f64];
                        sum += visible(c[0] + (c[1] - c[0]) * b[0] + (c[2] - c[0]) * b[1], sheet);
                    }
                }
            }
            sum / (m * m) as f64
        };
        let reference: Vec<f64> = level.iter().map(|&e| mean_over(e, true)).collect();
        let total: f64 = reference.iter().sum::<f64>() / reference.len() as f64;
        // The link's visible fraction is what its parts measured, not the
        // 0.5 it was given: the leaves' visible factor over their
        // unoccluded one.
        let unoccluded: f64 = level.iter().map(|&e| mean_over(e, false)).sum::<f64>() / level.len() as f64;
        let measured = f64::from(links[0].visibility.unwrap_or(1.0));
        assert!((measured / (total / unoccluded) - 1.0).abs() < 0.01, "visible fraction {measured} against {}", total / unoccluded);
        let want: Vec<f64> = reference.iter().map(|r| r / total).collect();
        let got: Vec<f64> = level.iter().map(|&e| share(e)).collect();
        // The best share constant over each part of 16 leaves' parent at level 2.
        let best: Vec<f64> = (0..level.len()).map(|k| {
            let group = k / 4 * 4;
            want[group..group + 4].iter().sum::<f64>() / 4.0
        }).collect();
        let l2 = |v: &[f64]| (v.iter().zip(&want).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / want.iter().map(|b| b * b).sum::<f64>()).sqrt();
        let (adaptive, constant) = (l2(&got), l2(&best));
        assert!(adaptive < 0.5 * constant, "L2 {adaptive} against {constant}");
    }

    /// In the last solve the light that link brings a triangle with
    /// children goes on to the triangle's parts, each by its own factor to
    /// the sender, as a link into the triangle would: the 16 parts (level
    /// 2) of one floor triangle get within 0.5% of their own factors (the
    /// centroids of a 60 x 60 subdivision of each; they are within 0.09%,
    /// and the triangle's mean, which every part got before, is up to 29%
    /// off), their flux sums to the triangle's, and the triangle keeps
    /// none of it itself.
    #[test]
    fn a_link_into_a_cluster_lights_each_part_of_a_triangle_by_its_own_factor() {
        let mut scene = FloorAndWall::new(1.5);
        scene.h.ensure_children(Node::Element(0));
        let first = scene.h.elements[0].first_child;
        for c in first..first + 4 {
            scene.h.ensure_children(Node::Element(c));
        }
        let (rays, occluders) = crate::test_scenes::traced(&scene.h);
        let kept = Link { receiver: Node::Cluster(1), sender: Node::Element(4), form_factor: 0.02, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: false };
        let mut links = [kept];
        let terms = ReceiverTerms::new(&scene.h, &mut links, Build::Last { tracer: Tracer::new(&rays, &occluders, 1, 16), resolution: None }, &mut WeightCache::default());
        assert_eq!(terms.of_triangle(0).count(), 0, "the triangle's own share");
        let whole = scene.triangle_factor(&scene.h.elements[0].points, DVec3::Z, 60);
        let parts = scene.h.parts(Node::Element(0), MAX_RECEIVER_PARTS);
        assert_eq!(parts.len(), 16);
        let mut flux = 0.0;
        for part in parts {
            let Node::Element(j) = part else { panic!("{part:?}") };
            let got: f64 = terms.of_element(j as usize).map(|(k, &u)| u * links[0].form_factor * terms.part_sources[k].weight()).sum();
            let want = scene.triangle_factor(&scene.h.elements[j as usize].points, DVec3::Z, 60);
            assert!((got / want - 1.0).abs() < 0.005, "part {j}: {got} against {want}");
            flux += scene.h.area(part) * got;
        }
        let area = scene.h.area(Node::Element(0));
        assert!((flux / (area * whole) - 1.0).abs() < 1e-3, "flux {flux} against {}", area * whole);
    }

    /// A cluster of more than [`MAX_RECEIVER_TRIANGLES`] triangles that do
    /// not all face one way (the unit floor and a wall of 3 x 3 quads on
    /// its edge, 20 triangles) under a lamp 1.5 m up: the refinement
    /// passes push a link's light to its triangles by area, and the last
    /// solve gives each triangle its own factor to the whole lamp
    /// triangle: every triangle within 0.5% of a 60 x 60 subdivision of
    /// Lambert's factor (they are within 0.007%; the area mean, which every
    /// triangle got before, is 0.81 to 0.95 times the floor triangles'
    /// factors and 0.59 to 2.4 times the wall's).
    #[test]
    fn a_link_into_a_large_cluster_lights_each_triangle_by_its_own_factor_in_the_last_solve() {
        let scene = FloorAndWall::with_wall_quads(1.5, 3);
        let triangles = scene.h.triangles_below(Node::Cluster(1)).to_vec();
        assert!(triangles.len() > MAX_RECEIVER_TRIANGLES, "{} triangles", triangles.len());
        let (rays, occluders) = crate::test_scenes::traced(&scene.h);
        let kept = Link { receiver: Node::Cluster(1), sender: Node::Element(scene.lamp_triangle), form_factor: 0.05, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: false };
        let mut means = [kept];
        let pushed = ReceiverTerms::new(&scene.h, &mut means, Build::Means, &mut WeightCache::default());
        assert!(!pushed.distributed(0), "the refinement passes push by area");
        let mut links = [kept];
        let terms = ReceiverTerms::new(&scene.h, &mut links, Build::Last { tracer: Tracer::new(&rays, &occluders, 1, 16), resolution: None }, &mut WeightCache::default());
        assert!(terms.distributed(0));
        for &t in &triangles {
            let g = &scene.h.triangles[t as usize];
            let want = scene.triangle_factor(&g.corners, g.normal, 60);
            let got: f64 = terms.of_triangle(t as usize).map(|(_, &(_, w))| w * links[0].form_factor).sum();
            assert!((got / want - 1.0).abs() < 0.005, "triangle {t}: {got} against {want}");
        }
    }
}

//! Sender classification at a grid vertex (paper 000 Sec. 4.3, Eq. 1-3,
//! Fig. 2), built on first use and cached ([`FullGather::vertex`]).
//!
//! 1. The links arriving at every receiver (cluster, element) overlapping
//!    the eight cells around the vertex, and their ancestors
//!    ([`crate::senders::Senders::links_near`]), grouped by sender
//!    (`SenderLinks`): the largest unoccluded irradiance `I_s`
//!    (luminance of the links' `Eu`), whether every link calls it fully
//!    occluded (then it is skipped), whether one calls it partly occluded,
//!    the largest visibility of its links, and the nearest occluder
//!    distance (each link's visibility as its receiver's exposed part
//!    sees it, [`crate::senders::Senders::exposed_visibility`]). The
//!    receivers near the vertex are the triangles overlapping the cells
//!    ([`crate::senders::Senders::triangles_near`]): a cluster receiver's
//!    own triangles lie anywhere in the scene.
//! 2. `N_s = max(n_min, round(N I_s / sum_S I))` (Eq. 1) sample pairs: a
//!    uniform point `x_k` in the eight cells around the vertex and the
//!    sender's fixed sample `y_k`. At each, the form factor without the
//!    receiver cosine (Lambert's factor for a receiver facing the sender's
//!    centre), and visibility by the hit-count rule of Fig. 2
//!    ([`blocked_by_count`]): the segment `x_k -> y_k` is blocked when it
//!    crosses more than `allowed_hits` surfaces (1: double-sided sheets, 2:
//!    single-sided closed objects), so a sample point that fell behind the
//!    receiving surface is not in shadow of it. The visible fraction is
//!    kernel-weighted ([`crate::full_gather`]), with the receiver facing the
//!    sender's centre.
//! 3. `D^F = rho B_s (F_max - F_min + e_F) max(vis, V_max)` (Eq. 2, with
//!    `e_F` below, `V_max` the largest visibility of the sender's links
//!    near the vertex) and `D^vis = rho B_s F_avg` where the visibility
//!    varies (Eq. 3; `rho` is the mean reflectance of the triangles
//!    overlapping the eight cells: both estimate a radiosity change, W/m²,
//!    luminance). A sender is resampled for a term whose error exceeds the
//!    threshold `tau = c B_v`, `c` the vertex's contrast threshold
//!    ([`crate::contrast`]), spent as a budget ([`budget`]). The
//!    visibility counts as varying where `0 < vis < 1`, where a link says
//!    the sender is partly hidden (`0 < V < 1`: a thin shadow can slip
//!    between the vertex's few samples), and where the samples see less of
//!    the sender than a link does (`vis < V_max`): volume samples inside a
//!    solid, behind the face whose pixels the vertex serves, see little of
//!    what the face sees.
//!
//!    `B_v` is the radiosity of the dimmest receiver near the vertex,
//!    `min_n sum_s rho B_s F_n(s) vis`, over the distinct normals `n` of
//!    the triangles overlapping the cells (at most [`MOST_NORMALS`]), with
//!    `F_n` Lambert's factor for a receiver of normal `n` at the first
//!    [`FACTORING_SAMPLES`] samples; the Weber fraction `c` is a fraction
//!    of what that receiver shows. `sum_s rho B_s F_avg vis`, each sender
//!    seen by a receiver that faces it, bounds every receiver's radiosity
//!    and took the threshold from the brightest receiver the senders could
//!    light: on a face lit only from in front, next to the top of a block
//!    that the lamp lights, the threshold was several times that face's
//!    radiosity, and every interpolated sender erred the same way (the
//!    factored form below misses the parts of a wide sender in front of
//!    the face whose centre lies behind it). The built-in Cornell box's
//!    short block, its face towards the camera seen from 0.5 m at `EPS`
//!    1.25e-3 (`tests/tests/grid_gather_full.rs`), was 2.4% darker than the
//!    brute-force gather of the same solution (5% of its pixels by more
//!    than 5.7%), now +0.05%; in McGuire's `CornellBox-Original` at `EPS`
//!    1e-3 (unclustered) the top of that face was 8% to 12% dark against
//!    Mitsuba (17,408 samples a pixel), now within 2%, as brute force.
//!    Against Mitsuba, the Cornell box's full gather at `EPS` 1e-3 went
//!    from 1.176% and 1.170% relative RMSE (seeds 1, 2) to 1.126% and
//!    1.109%, McGuire's box at 7e-4 from 1.014% and 0.990% to 0.969% and
//!    0.964%, for 9% and 3% more gather time (two threads, medians of 3
//!    interleaved). A tighter contrast buys about as much: at `EPS`
//!    1.25e-3, `c` 0.01 instead of 0.02 took the Cornell box from 1.532%
//!    to 1.430% for 14% more time, where this change gives 1.477% for 14%,
//!    but leaves the dim face dark.
//!
//!    `e_F` is what the interpolation's factoring misses: a pixel takes
//!    `F_avg max(0, n_p . d)` ([`crate::interpolation`]), the factor
//!    towards the sender's centre times its own cosine to that centre,
//!    which is Lambert's factor only where the sender is small as seen from
//!    the pixel. For a wide or near sender the receiver's cosine varies
//!    over it, however little the factor varies from point to point:
//!    under a floor 12 m wide 1 m below, 0.5 m off its centre line, that
//!    product is 19% under Lambert's factor. So at the first
//!    [`FACTORING_SAMPLES`] samples the factored form is set against
//!    Lambert's factor for each receiver normal near the vertex (at most
//!    [`MOST_NORMALS`]), and the largest difference is `e_F`
//!    ([`factoring_error`]). In `tests/tests/hung_sheet.rs` the ceiling
//!    near the camera was up to 49% dark, now within 4e-5 of the closed
//!    form; the Cornell box's full gather against Mitsuba went from 1.207%
//!    to 1.177% relative RMSE at `EPS` 1e-3 and from 0.732% to 0.731% at
//!    2.5e-4, McGuire's `CornellBox-Original` at 7e-4 (against the full
//!    gather of its `EPS` 2.5e-5 solve) from 0.961% to 0.921%, for 8%, 2%
//!    and 4% more gather time (medians of 3 interleaved, two threads).
//!    Resampling every form factor instead gave 1.118% at 1e-3 for 31%
//!    more time.
//! 4. A cluster sender that contains the vertex is always interpolated; its
//!    irradiance comes from `interior_rays` uniform rays from the vertex.
//! 5. Resampled visibility gets its view-dependent sample count
//!    ([`crate::shadow_samples`]).

use crate::full_gather::FullGather;
use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::color::luminance;
use radiometry::form_factor::WeightedVisibility;
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;
use schemas::solution::{Link, Node, NONE};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// The four classes of a sender at a vertex (Sec. 4.3): which of its two
/// terms, visibility and form factor, are resampled at render time and
/// which interpolated from the grid vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkClass {
    /// Resample visibility and the form factor.
    ResampleBoth,
    /// Resample visibility, interpolate the form factor.
    ResampleVisibility,
    /// Interpolate visibility, resample the form factor.
    ResampleFormFactor,
    /// Interpolate both.
    InterpolateBoth,
}

impl LinkClass {
    /// Every class, in the order of the diagnostics' channels
    /// ([`schemas::diagnostics::CLASSES`]) and of [`Self::index`].
    pub const ALL: [LinkClass; 4] = [LinkClass::ResampleBoth, LinkClass::ResampleVisibility, LinkClass::ResampleFormFactor, LinkClass::InterpolateBoth];

    /// The class of a sender that resamples what the two flags say.
    pub fn of(resample_visibility: bool, resample_form_factor: bool) -> LinkClass {
        match (resample_visibility, resample_form_factor) {
            (true, true) => LinkClass::ResampleBoth,
            (true, false) => LinkClass::ResampleVisibility,
            (false, true) => LinkClass::ResampleFormFactor,
            (false, false) => LinkClass::InterpolateBoth,
        }
    }

    /// Position in [`Self::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The class's name in the report's counters.
    pub fn name(self) -> &'static str {
        match self {
            LinkClass::ResampleBoth => "resample_vis_resample_ff",
            LinkClass::ResampleVisibility => "resample_vis_interpolate_ff",
            LinkClass::ResampleFormFactor => "interpolate_vis_resample_ff",
            LinkClass::InterpolateBoth => "interpolate_vis_interpolate_ff",
        }
    }
}

/// One sender as one vertex sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexSender {
    /// The sender.
    pub node: Node,
    /// Resample visibility at render time.
    pub resample_visibility: bool,
    /// Resample the form factor at render time.
    pub resample_form_factor: bool,
    /// Visibility samples when resampled (view-dependent, Sec. 5.3).
    pub shadow_samples: u32,
    /// Mean form factor without the receiver cosine, at the vertex.
    pub factor: f64,
    /// Mean visibility at the vertex, in [0, 1].
    pub visibility: f64,
    /// Unit direction from the vertex to the sender.
    pub direction: DVec3,
}

impl VertexSender {
    /// The sender's class.
    pub fn class(&self) -> LinkClass {
        LinkClass::of(self.resample_visibility, self.resample_form_factor)
    }
}

/// What one grid vertex knows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexData {
    /// Senders, sorted by node.
    pub senders: Vec<VertexSender>,
    /// Senders skipped as fully occluded by every link.
    pub skipped: u32,
    /// Visibility rays cast to classify.
    pub rays: u64,
    /// Form-factor evaluations made to classify.
    pub factors: u64,
    /// The contrast threshold used.
    pub contrast: f64,
    /// Each sender's [`node_key`], in the order of `senders`: the pixels
    /// look every link's sender up at four vertices, and a search over this
    /// dense array instead of the 56-byte entries (7.7% of the full
    /// gather's time on the Cornell box at `EPS` 1e-3) saves 5% of it.
    keys: Vec<u64>,
}

/// A sender's place in the order of [`Node`] (elements, then clusters) as
/// one integer.
fn node_key(node: Node) -> u64 {
    match node {
        Node::Element(e) => u64::from(e),
        Node::Cluster(c) => 1 << 32 | u64::from(c),
    }
}

impl VertexData {
    /// The entry of sender `node`, if the vertex has one.
    pub fn find(&self, node: Node) -> Option<&VertexSender> {
        self.keys.binary_search(&node_key(node)).ok().map(|i| &self.senders[i])
    }

    /// Number of senders in each class, indexed by [`LinkClass::index`].
    pub fn class_counts(&self) -> [u32; 4] {
        let mut c = [0; 4];
        for s in &self.senders {
            c[s.class().index()] += 1;
        }
        c
    }
}

/// What the links near a vertex say of one sender (step 1).
#[derive(Clone, Copy, Debug)]
struct SenderLinks {
    /// Largest unoccluded irradiance `I_s` of its links, luminance, W/m².
    irradiance: f64,
    /// Every link calls it fully occluded.
    all_occluded: bool,
    /// Some link calls it partly occluded (`0 < V < 1`).
    partial: bool,
    /// Nearest occluder distance of its links that are not fully visible,
    /// m (+inf: none).
    occluder: f64,
    /// Largest visible fraction `V` of its links.
    most_visible: f64,
}

/// One sender's estimates at a vertex (steps 2 and 3).
struct Estimate {
    node: Node,
    /// Classification samples, `N_s` of Eq. 1.
    n: u32,
    /// Mean form factor without the receiver cosine.
    f_avg: f64,
    /// `F_max - F_min` over the samples.
    spread: f64,
    /// Largest error of the factored form factor over the samples and
    /// the receivers' normals near the vertex ([`factoring_error`]).
    factoring: f64,
    /// Kernel-weighted visible fraction.
    vis: f64,
    /// Visibility varies (the samples disagree, or a link says partial).
    partial: bool,
    /// A cluster holding the vertex (step 4): never resampled.
    interior: bool,
    /// Nearest occluder distance, m.
    occluder: f64,
    /// Sender radiosity, luminance, W/m².
    b: f64,
    /// Largest visible fraction of its links.
    most_visible: f64,
    /// Per receiver normal near the vertex, the mean of Lambert's factor
    /// over the samples [`factoring_error`] checks (for a cluster holding
    /// the vertex, its factor times the normal's cosine to its direction).
    facing: Vec<f64>,
}

/// Whether the segment from `from` to `to` is blocked by the hit-count
/// rule of 000 Fig. 2: more than `allowed` surfaces crossed (the
/// triangles in `skip` not counted). Returns (blocked, rays cast).
pub fn blocked_by_count(rays: &SceneRays, from: DVec3, to: DVec3, skip: [u32; 2], allowed: u32) -> (bool, u64) {
    let d = to - from;
    let length = d.length();
    if length <= 0.0 {
        return (false, 0);
    }
    let dir = d / length;
    let t_max = ((1.0 - 1e-6) * length) as f32;
    let mut t_min = (1e-6 * length) as f32;
    let (mut hits, mut cast) = (0, 0);
    while hits <= allowed {
        cast += 1;
        let Some(hit) = rays.closest_hit(from, dir, t_min, t_max, skip) else { return (false, cast) };
        hits += 1;
        t_min = hit.t + (1e-6 * length as f32).max(hit.t * 1e-6);
    }
    (true, cast)
}

/// Classification samples of a sender at which its factored form factor
/// is checked against the exact one ([`factoring_error`]).
pub const FACTORING_SAMPLES: usize = 4;

/// Most receiver normals near a vertex the factoring is checked for.
pub const MOST_NORMALS: usize = 4;

/// The distinct unit normals among `normals` (two within 1e-6 in cosine
/// are one), at most [`MOST_NORMALS`], in order.
fn receiver_normals(normals: impl Iterator<Item = DVec3>) -> Vec<DVec3> {
    let mut distinct: Vec<DVec3> = Vec::new();
    for n in normals {
        if distinct.len() < MOST_NORMALS && distinct.iter().all(|d| d.dot(n) < 1.0 - 1e-6) {
            distinct.push(n);
        }
    }
    distinct
}

/// The largest error, over the receiver normals `normals`, of the form
/// factor as the grid interpolates it at a point `x`,
///
/// ```text
/// F(x, d) max(0, n . d)      (d: unit direction from x to the sender's centre),
/// ```
///
/// against Lambert's `F(x, n)`, which `exact(n)` gives with its kernel
/// evaluations; `toward_factor` is `F(x, d)`. Adds each normal's `F(x, n)`
/// to its place in `facing`. Returns the error and the evaluations.
fn factoring_error(exact: impl Fn(DVec3) -> (f64, u64), toward_factor: f64, toward: DVec3, normals: &[DVec3], facing: &mut [f64]) -> (f64, u64) {
    normals.iter().zip(facing).fold((0.0, 0), |(worst, evals), (&n, sum)| {
        let (f, e) = exact(n);
        *sum += f;
        (f64::max(worst, (f - toward_factor * n.dot(toward).max(0.0)).abs()), evals + e)
    })
}

/// Which of the senders with error estimates `d` (W/m²) to resample under
/// the threshold `tau` (W/m²): the smallest estimates are interpolated while
/// their running sum stays at most `tau`, every other one is resampled; an
/// estimate of 0 is always interpolated.
///
/// Paper 000 compares each sender's estimate with the threshold on its
/// own. That bounds the error one sender makes; with the many senders of a
/// refined or clustered solution (hundreds of links per vertex) the errors
/// of the interpolated senders add up to many times the threshold (3.6%
/// relative RMSE against brute force on a clustered convex room at a 2%
/// contrast). Spending the threshold as a budget bounds the sum instead,
/// and with one dominant sender it is the paper's rule. Ties are broken by
/// position, so the choice is deterministic.
pub fn budget(d: &[f64], tau: f64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..d.len()).collect();
    order.sort_by(|&a, &b| d[a].total_cmp(&d[b]).then(a.cmp(&b)));
    let mut resample = vec![false; d.len()];
    let mut spent = 0.0;
    for i in order {
        if d[i] <= 0.0 {
            continue;
        }
        if spent + d[i] <= tau {
            spent += d[i];
        } else {
            resample[i] = true;
        }
    }
    resample
}

impl FullGather<'_> {
    /// The grid box of the eight cells around vertex `v`, clamped.
    fn around(&self, v: [usize; 3]) -> ([f64; 3], [f64; 3]) {
        let lo = std::array::from_fn(|a| (v[a] as f64 - 1.0).max(0.0));
        let hi = std::array::from_fn(|a| (v[a] as f64 + 1.0).min(self.grid.n[a] as f64));
        (lo, hi)
    }

    /// Classifies the senders of vertex `index` (module docs).
    pub(crate) fn classify(&self, index: usize) -> VertexData {
        let p = self.params;
        let v = self.grid.vertex_of(index);
        let position = self.grid.vertex(v);
        let (lo, hi) = self.around(v);
        let corners = (0..8).map(|m| self.grid.point(std::array::from_fn(|a| if (m >> a) & 1 == 0 { lo[a] } else { hi[a] })));
        let region = Aabb::around(corners);
        let receivers = self.senders.triangles_near(&region);
        let links = self.senders.links_near(&region, &receivers);
        let mut by_sender: BTreeMap<Node, SenderLinks> = BTreeMap::new();
        let (mut rho_area, mut area) = (0.0, 0.0);
        for &l in &links {
            let link: &Link = &self.senders.solution.links[l];
            let s = by_sender.entry(link.sender).or_insert(SenderLinks { irradiance: 0.0, all_occluded: true, partial: false, occluder: f64::INFINITY, most_visible: 0.0 });
            s.irradiance = s.irradiance.max(luminance(link.unoccluded_irradiance.map(f64::from)));
            let visibility = self.senders.exposed_visibility(l);
            s.all_occluded &= visibility <= 0.0;
            s.partial |= visibility > 0.0 && visibility < 1.0;
            s.most_visible = s.most_visible.max(visibility);
            if visibility < 1.0 {
                s.occluder = s.occluder.min(f64::from(link.occluder_distance));
            }
        }
        let normals = receiver_normals(receivers.iter().map(|&t| self.senders.triangles[t as usize].normal));
        for &t in &receivers {
            let a = self.senders.triangles[t as usize].area;
            rho_area += a * luminance(self.surfaces[t as usize].reflectance);
            area += a;
        }
        let rho = if area > 0.0 { rho_area / area } else { 0.0 };
        let total: f64 = by_sender.values().filter(|s| !s.all_occluded).map(|s| s.irradiance).sum();
        let mut stream = Stream::new(p.seed, index as u64, 0xc1a5);
        let mut data = VertexData { contrast: self.vertex_contrast[index], ..VertexData::default() };
        let mut estimates = Vec::new();
        for (&node, s) in &by_sender {
            if s.all_occluded {
                data.skipped += 1;
                continue;
            }
            let b = luminance(self.senders.radiosity(node));
            let centre = self.senders.centre(node);
            let interior = matches!(node, Node::Cluster(c) if self.senders.cluster_box(c).is_some_and(|b| b.contains(position)));
            if interior {
                // 000 Sec. 4.3: irradiance from rays into random directions.
                let (mut e_vec, rays) = (DVec3::ZERO, p.interior_rays.max(1));
                for _ in 0..rays {
                    let z = 1.0 - 2.0 * stream.next_f64();
                    let phi = 2.0 * PI * stream.next_f64();
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let dir = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                    data.rays += 1;
                    let Some(hit) = self.rays.closest_hit(position, dir, 0.0, f32::INFINITY, [NONE; 2]) else { continue };
                    let tri = &self.senders.triangles[hit.triangle as usize];
                    if dir.dot(tri.normal) < 0.0 && self.senders.covers(node, Node::Element(hit.triangle)) {
                        // Radiance B/pi over solid angle 4 pi / rays, as a factor of B.
                        e_vec += dir * (4.0 / f64::from(rays));
                    }
                }
                let f = e_vec.length();
                let direction = if f > 0.0 { e_vec / f } else { (centre - position).normalize_or_zero() };
                data.senders.push(VertexSender {
                    node,
                    resample_visibility: false,
                    resample_form_factor: false,
                    shadow_samples: 0,
                    factor: f,
                    visibility: 1.0,
                    direction,
                });
                let facing = normals.iter().map(|n| f * n.dot(direction).max(0.0)).collect();
                estimates.push(Estimate { node, n: 0, f_avg: f, spread: 0.0, factoring: 0.0, vis: 1.0, partial: false, interior: true, occluder: s.occluder, b, most_visible: s.most_visible, facing });
                continue;
            }
            let share = if total > 0.0 { p.samples as f64 * s.irradiance / total } else { 0.0 };
            let n = (share.round() as u32).clamp(p.min_samples, p.samples.max(p.min_samples)); // Eq. 1
            let (mut f_sum, mut f_min, mut f_max, mut factoring) = (0.0, f64::INFINITY, 0.0f64, 0.0f64);
            let mut facing = vec![0.0; normals.len()];
            let mut visible = WeightedVisibility::default();
            let samples = self.senders.samples(node);
            for k in 0..n as usize {
                let g: [f64; 3] = std::array::from_fn(|a| lo[a] + (hi[a] - lo[a]) * stream.next_f64());
                let x = self.grid.point(g);
                let y = samples.at(k);
                let toward = (centre - x).normalize_or_zero();
                let (f, evals) = self.senders.form_factor(node, x, toward);
                data.factors += evals;
                f_sum += f;
                f_min = f_min.min(f);
                f_max = f_max.max(f);
                if k < FACTORING_SAMPLES {
                    let (error, evals) = factoring_error(|n| self.senders.form_factor(node, x, n), f, toward, &normals, &mut facing);
                    data.factors += evals;
                    factoring = factoring.max(error);
                }
                let weight = self.sample_weight(x, toward, y);
                if weight > 0.0 {
                    let (blocked, cast) = blocked_by_count(self.rays, x, y.point, [y.triangle, NONE], p.allowed_hits);
                    data.rays += cast;
                    visible.add(weight, !blocked);
                }
            }
            let vis = visible.fraction().unwrap_or(1.0);
            let partial = s.partial || (vis > 0.0 && vis < 1.0) || vis < s.most_visible;
            let checked = (n as usize).clamp(1, FACTORING_SAMPLES) as f64;
            facing.iter_mut().for_each(|f| *f /= checked);
            estimates.push(Estimate { node, n, f_avg: f_sum / f64::from(n), spread: f_max - f_min, factoring, vis, partial, interior: false, occluder: s.occluder, b, most_visible: s.most_visible, facing });
        }
        // B_v: the radiosity of the dimmest receiver orientation near the
        // vertex (module docs, step 3).
        let b_toward: f64 = estimates.iter().map(|e| rho * e.b * e.f_avg * e.vis).sum();
        let b_v = (0..normals.len()).map(|i| estimates.iter().map(|e| rho * e.b * e.facing[i] * e.vis).sum::<f64>()).fold(b_toward, f64::min);
        let tau = data.contrast * b_v;
        // Eq. 2 and 3 per sender; then the threshold as a budget per term:
        // interpolation errors of different senders add, so the senders
        // with the smallest estimates are interpolated while their sum stays
        // within tau, the rest resampled (see `budget`).
        let classified: Vec<&Estimate> = estimates.iter().filter(|e| !e.interior).collect();
        let d_f: Vec<f64> = classified.iter().map(|e| rho * e.b * (e.spread + e.factoring) * e.vis.max(e.most_visible)).collect(); // Eq. 2
        let d_vis: Vec<f64> = classified.iter().map(|e| if e.partial { rho * e.b * e.f_avg } else { 0.0 }).collect(); // Eq. 3
        let (resample_f, resample_v) = (budget(&d_f, tau), budget(&d_vis, tau));
        for (k, e) in classified.iter().enumerate() {
            let resample_visibility = resample_v[k];
            let shadow_samples =
                if resample_visibility { self.shadow_samples(position, e.node, e.occluder, rho * e.b * e.f_avg, tau, e.n) } else { 0 };
            data.senders.push(VertexSender {
                node: e.node,
                resample_visibility,
                resample_form_factor: resample_f[k],
                shadow_samples,
                factor: e.f_avg,
                visibility: e.vis,
                direction: (self.senders.centre(e.node) - position).normalize_or_zero(),
            });
        }
        data.senders.sort_by_key(|s| s.node);
        data.keys = data.senders.iter().map(|s| node_key(s.node)).collect();
        data
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use radiometry::form_factor::point_to_polygon;

    /// A floor 12 m wide 1 m under a ceiling facing down (the sender of
    /// `tests/tests/hung_sheet.rs`): over its centre the factor towards
    /// its centre times the cosine to it is Lambert's factor, but 0.5 m
    /// off the centre line it misses it by 19% of the factor, which
    /// the factor's spread over the samples (the same at every point) does
    /// not show, so the ceiling near that test's camera came out up to 49%
    /// dark.
    #[test]
    fn a_wide_sender_off_its_centre_line_is_not_its_factor_towards_the_centre_times_a_cosine() {
        let floor = [dvec3(-6.0, -6.0, -1.0), dvec3(6.0, -6.0, -1.0), dvec3(6.0, 6.0, -1.0), dvec3(-6.0, 6.0, -1.0)];
        let centre = dvec3(0.0, 0.0, -1.0);
        let error = |x: DVec3| {
            let toward = (centre - x).normalize();
            let (e, evals) = factoring_error(|n| (point_to_polygon(x, n, &floor), 1), point_to_polygon(x, toward, &floor), toward, &[DVec3::NEG_Z], &mut [0.0]);
            assert_eq!(evals, 1);
            e / point_to_polygon(x, DVec3::NEG_Z, &floor)
        };
        let (over, off) = (error(DVec3::ZERO), error(dvec3(0.25, -0.45, 0.0)));
        assert!(over < 1e-12, "over the centre: {over}");
        assert!((0.15..0.22).contains(&off), "0.5 m off the centre line: {off}");
    }

    /// Receiver normals: parallel ones counted once, in order, at most
    /// [`MOST_NORMALS`].
    #[test]
    fn receiver_normals_are_the_distinct_ones_in_order() {
        let tilted = dvec3(0.6, 0.0, 0.8);
        let normals = [DVec3::Z, DVec3::X, DVec3::Z, tilted, DVec3::X, DVec3::Y, DVec3::NEG_Z, DVec3::NEG_X];
        assert_eq!(receiver_normals(normals.into_iter()), vec![DVec3::Z, DVec3::X, tilted, DVec3::Y]);
        assert_eq!(receiver_normals([DVec3::Z, DVec3::Z].into_iter()), vec![DVec3::Z]);
    }
}

//! # hierarchical-solve: hierarchical radiosity on the scene's patches
//!
//! After Hanrahan, Salzman and Aupperle (SIGGRAPH 1991). Every pair of input
//! triangles that can exchange light starts with one link; links are refined
//! by the BF oracle ([`links::decide`]) down to a minimum element area; form
//! factors are Lambert's closed form (paper 002 Eq. 3) averaged over the
//! receiver ([`radiometry::form_factor`]); visibility is a ray-cast fraction
//! per link ([`visibility`]); radiosity is gathered with push-pull
//! ([`gather`]). Refinement needs radiosity and radiosity needs links, so
//! the two alternate in passes until a pass refines nothing. Goniometric
//! point lights shoot first: their direct light, with shadow rays, is a
//! source term of every element.
//!
//! Parameters: [`Params`], declared once with `stage_kit::knobs!`
//! (`hierarchical-solve --print-knobs` prints their table, which the
//! README's "Stage knobs" holds).
//!
//! **Why `relative` is the default.** The absolute criterion bounds each
//! link's error in units of the brightest emitter, so on a surface lit only
//! by reflection (the Cornell box's block faces, paper 002's receiver B)
//! links carrying a large sender's *mean* radiosity are never split, however
//! large that error is next to what the surface shows: the short block's
//! front face was 15% too bright (full gather), 42% (preview). `relative`
//! compares each link's error with its receiver's own radiosity (brightest
//! channel) in the current iterate of the refine-and-solve passes (the
//! first pass, before any solve, refines with the absolute criterion), with
//! a floor of `relative_floor` times the mean reflected radiosity so that
//! black receivers terminate, and it sees a sender's radiosity variation at
//! every level below it ([`links::leaf_range`]), not only at its
//! children, whose means can hide a bright spot. On the Cornell box at the
//! default `eps` it moved the surfaces' means toward the reference (full
//! gather: short block +15.5% -> +3.7%, tall block -7.5% -> -5.3%, floor
//! +2.8% -> -0.2%, ceiling -4.4% -> -2.6%; relative RMSE 4.3% -> 2.9%;
//! preview short block +42% -> +3.4%) for 3.1x the links (38.9k -> 122k,
//! leaves 4051 -> 4192) and 2.4x the solve time (0.9 s -> 2.2 s).
//! `--criterion absolute` gives the former links and radiosity exactly.
//!
//! **A link's share.** Between elements, a link may err by `eps_relative`
//! times what it brings its receiver, or times `share_floor` (1/16) of the
//! receiver's radiosity if that is more ([`links::Allowance::for_link`]),
//! not by `eps_relative` of the receiver's radiosity each: a receiver's
//! light comes through many links whose errors (the kernel's variation over
//! the receiver, alike for senders in one direction) add up with one sign.
//! On paper 002's one-bounce receiver the worst leaf went from 8.9% to 1.1%
//! off an independent quadrature (rho_B 0.05; 0.5% at rho_B 0.5), and on the
//! Cornell box (full gather, against Mitsuba) the relative RMSE from 3.2% to
//! 2.3% (walls and ceiling within 1%, short block +2.9%, tall block -4.1%),
//! for 6.7x the links (122k to 823k) and about 2.5x the solve time.

pub mod cluster_tree;
pub mod detail;
pub mod elements;
pub mod exposure;
pub mod gather;
pub mod links;
pub mod luminaires;
pub mod mirrors;
pub mod nodes;
pub mod receivers;
pub mod report;
pub mod rows;
pub mod shadowed;
pub mod shaft;
pub mod slopes;
#[cfg(test)]
mod test_scenes;
pub mod transfer;
pub mod transmission;
pub mod visibility;

use elements::Hierarchy;
use links::{children_links, decide, link, self_link, Allowance, Floors, Link, Linking, Split};
pub use links::Criterion;
use schemas::cluster::Clusters;
use schemas::solution::Node;
use radiometry::form_factor::Quadrature;
use radiometry::photometry::DirectLight;
use radiometry::rays::SceneRays;
use rayon::prelude::*;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution;
use schemas::surface::Surface;
use std::time::Instant;

stage_kit::knobs! {
    /// The solver's knobs.
    pub struct Params {
        /// What a link's estimated error is compared with: `relative` (`eps_relative` times what the link brings its receiver, never more than `eps` times the largest source radiosity) or `absolute` (`eps` times the largest source radiosity alone, HSA's BF criterion).
        criterion: Criterion = Criterion::Relative, "", value;
        /// Largest error a link may make, as a fraction of the largest source radiosity (emission, or the reflected direct light of luminaires), under either criterion; the relative criterion's first pass uses it alone.
        eps: f64 = 1.5e-5, "", value(positive());
        /// Relative criterion: a link's error as a fraction of what it brings its receiver (brightest channel, current iterate; see `share_floor`); `none`: 8 x `eps` x largest source / mean reflected radiosity, so that `eps` stays the one accuracy knob (1.6% on the Cornell box).
        eps_relative: Option<f64> = None, "", optional(positive());
        /// Least receiver radiosity the relative criterion assumes, as a fraction of the scene's area-mean reflected radiosity (black receivers terminate).
        relative_floor: f64 = 1e-2, "", value(positive());
        /// Relative criterion: a link may err by `eps_relative` times what it brings its receiver, or times this share of the receiver's radiosity if more.
        share_floor: f64 = 1.0 / 16.0, "", value(custom("in [0, 1]", |v: &f64| (0.0..=1.0).contains(v)));
        /// Smallest element area, as a fraction of the scene's total area.
        min_area: f64 = 1e-4, "", value(left_open(0.0, 1.0));
        /// How many 1:4 levels below `min_area` a shadow edge across a link between elements may split.
        shadow_levels: u32 = 2, "levels", value(0..=8);
        /// Least visibility rays per link between two elements; up to 16 times as many where the noise of its visible fraction would exceed half its share of the allowance.
        visibility_rays: usize = 16, "rays", value(1..=4096);
        /// Point pairs (and rays) per link with a cluster at an end.
        cluster_samples: usize = 16, "pairs", value(1..=4096);
        /// Deepest split of the adaptive receiver quadrature near touching elements (to a tolerance that follows the relative criterion's eps: a sixteenth of it, times 1 - q), and of the near-field quadrature of a luminaire's direct light over an element.
        quadrature_depth: u32 = 3, "levels", value(0..=8);
        /// Convergence: gathering stops when a bound of every leaf's remaining error is under this fraction of the largest radiosity.
        tolerance: f64 = 1e-5, "", value(positive());
        /// Jacobi iterations per solve, at most.
        max_iterations: usize = 2000, "", value(at_least(1));
        /// Refine-and-solve passes, at most.
        max_passes: usize = 8, "", value(at_least(1));
        /// Links at most (about 600 bytes each in a solve): refinement keeps the links it would split once this many could result, says so, and runs no further pass.
        max_links: usize = 16_000_000, "links", value(at_least(1));
        /// Seed of the visibility rays.
        seed: u64 = 1, "", value;
        /// Rays per coupling through a mirror or pane.
        specular_rays: usize = 16, "rays", value(1..=4096);
        /// Couplings through a mirror or pane whose `rho_s F` or `tau_s F` is under this are dropped.
        specular_min_factor: f64 = 1e-6, "", value(at_least(0.0));
        /// Levels below each input triangle the senders through mirrors and panes are taken at (their leaves where coarser).
        specular_sender_level: u32 = 2, "levels", value(0..=8);
        /// Most mirrors and panes along a path of light (virtual senders of virtual senders).
        specular_depth: u32 = 2, "", value(0..=16);
    }
}

stage_kit::show_by_name!(Criterion);

/// Where `eps_relative` is not given, the relative criterion allows on a
/// receiver of `RELATIVE_AT` times the scene's mean reflected radiosity
/// the error the absolute one allows everywhere (`eps` times the largest
/// source): `eps_relative = eps E_max / (RELATIVE_AT B_mean)`, from the
/// current iterate, so `eps` stays the one accuracy knob (`make sweep`'s
/// `EPS`) and means about the same in any scene. A link's allowance is the
/// smaller of the two ([`links::Allowance::Relative`]): links into
/// receivers brighter than about `RELATIVE_AT B_mean`, and the links that
/// bring a receiver most of its light, are held to the absolute threshold;
/// links into dimmer receivers to `eps_relative` of what they bring.
///
/// Why both. An element's error as a sender reaches every surface it
/// lights in absolute terms, so the bright elements that light a scene
/// need an absolute bound; a surface lit only by reflection needs the
/// relative one, which the absolute threshold never gives it (paper 002's
/// one-bounce receiver, `tests/tests/solver_closed_forms.rs`). Measured on
/// the Cornell box (full gather, lattice every 2 px, against Mitsuba):
/// the relative bound alone at `RELATIVE_AT` 3 (the former rule) reached
/// 1.00% relative RMSE in 1.38 s and had every surface's mean within 1%
/// only from 2.8 s (the short block stayed 1.2-2.9% bright at coarser
/// points); the absolute alone 0.96% in 1.36 s, short block +1.2%; both,
/// at 1/8: 1.14% in 0.93 s with every surface within 0.95%, 0.87% in
/// 1.47 s within 0.46% (1/16 about the same, 1/4 slower). The default
/// `eps` was set by the closed box at rho 0.999, which multiplies every
/// link's error about a thousandfold (its mean was 0.07% low at 1.5e-5,
/// 0.32% at 1e-4, until the uniform senders' shortcut was scaled by `1 -
/// q`, [`gather::UNIFORM_SENDER`]: now 3e-7 and 0.003%); it stays for the
/// Cornell box, whose full gather it brings to 0.48% against Mitsuba
/// (0.51% at 2.5e-5, 0.59% at 1e-4).
pub const RELATIVE_AT: f64 = 0.125;

impl Params {
    /// Why the parameters are unusable, if they are: the first knob out of
    /// its declared range (`NAME must be RANGE, not VALUE`).
    pub fn problem(&self) -> Option<String> {
        use stage_kit::knobs::Knobs;
        self.check("").err().map(|e| match e {
            schemas::Error::Invalid { message, .. } => message,
            other => other.to_string(),
        })
    }
}

/// Most input-triangle pairs linked before refinement: without clustering
/// the solver starts from every pair, which past this costs more memory than
/// a workstation has.
pub const MAX_INITIAL_PAIRS: usize = 200_000_000;

/// Work done by a solve, for the report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Work {
    /// Refine-and-solve passes run.
    pub passes: usize,
    /// Links in the result.
    pub links: usize,
    /// Of them, links with a cluster at an end.
    pub cluster_links: usize,
    /// Elements in the result, and of them leaves.
    pub elements: usize,
    /// Leaf elements.
    pub leaves: usize,
    /// Form factors evaluated (element pairs), including those of links
    /// later refined away.
    pub form_factors: u64,
    /// Visibility rays cast.
    pub rays: u64,
    /// Jacobi iterations, all passes.
    pub iterations: usize,
    /// Relative change of the last iteration.
    pub relative_change: f64,
    /// Bound of the remaining error of the last pass's solution, relative
    /// to the largest radiosity.
    pub error_bound: f64,
    /// Contraction factor the last pass's bound used.
    pub contraction: f64,
    /// Whether the last pass's bound reached the tolerance (`false`: it
    /// stopped at `max_iterations`).
    pub converged: bool,
    /// Passes whose solve stopped at `max_iterations`.
    pub capped_passes: usize,
    /// Whether refinement stopped at `max_links`.
    pub links_capped: bool,
    /// Geometric extrapolations of the Jacobi iterates, all passes.
    pub extrapolations: usize,
    /// Seconds refining links (form factors, oracle).
    pub refine_seconds: f64,
    /// Seconds casting visibility rays.
    pub visibility_seconds: f64,
    /// Seconds gathering.
    pub gather_seconds: f64,
    /// Shadow rays cast to luminaires.
    pub luminaire_rays: u64,
    /// Rays cast to measure the elements' exposure ([`exposure`]).
    pub exposure_rays: u64,
    /// Seconds lighting elements from luminaires.
    pub luminaire_seconds: f64,
    /// Links whose sender the last solve resolved into parts
    /// ([`gather::SenderTerms`]).
    pub resolved_links: usize,
    /// Leaves the last solve opened where a shadow edge crosses them
    /// ([`shadowed`]).
    pub opened_leaves: usize,
    /// Visibility rays the last solve cast to weigh a partly occluded
    /// link's sender parts and receiving faces ([`gather::SenderTerms`],
    /// [`receivers`]); not in `rays`, whose rate is the links' visibility.
    pub part_rays: u64,
    /// Couplings through mirrors and panes in the last pass.
    pub specular_couplings: usize,
    /// Rays cast to build them, all passes.
    pub specular_rays: u64,
    /// Seconds building them, all passes.
    pub specular_seconds: f64,
    /// Bound of the irradiance the specular depth bound leaves out, W/m²
    /// ([`mirrors::Couplings::truncation`]), last pass.
    pub specular_truncation: f64,
    /// The scene's windows where they are more than
    /// [`mirrors::MAX_WINDOWS`] and their specular light was left out; 0
    /// otherwise.
    pub specular_windows_left_out: usize,
}

/// Progress of a solve, reported as each phase of a pass begins and when
/// the pass ends.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Pass (1-based).
    pub pass: usize,
    /// What the pass is doing.
    pub phase: Phase,
    /// Links now.
    pub links: usize,
    /// Elements now.
    pub elements: usize,
}

/// The phases of one refinement pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Splitting links whose error bound exceeds the threshold.
    Refining,
    /// Casting shadow rays for the new links.
    Visibility,
    /// Jacobi gathering to convergence.
    Gathering,
    /// The pass is finished.
    Done,
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Phase::Refining => "refining links",
            Phase::Visibility => "casting shadow rays",
            Phase::Gathering => "gathering",
            Phase::Done => "done",
        })
    }
}

/// The solve's result: the solution's tables (without header) and the work.
pub struct Solved {
    /// Elements with radiosity.
    pub elements: Vec<solution::Element>,
    /// Radiosity per cluster (empty without clustering).
    pub clusters: Vec<solution::ClusterRadiosity>,
    /// Links, sorted by receiver then sender.
    pub links: Vec<solution::Link>,
    /// Emitters' direct-light slopes inside the leaves of penumbrae
    /// ([`slopes`]).
    pub slopes: Vec<solution::LeafSlope>,
    /// Work done.
    pub work: Work,
}

/// Solves the scene, with the cluster hierarchy `clusters` if given (then
/// one self-link of the root cluster starts the refinement; without, every
/// pair of input triangles). `progress` is called as each phase of a pass
/// begins and after the pass.
pub fn solve(mesh: &Mesh, manifest: &Manifest, clusters: Option<Clusters>, params: &Params, progress: &dyn Fn(&Progress)) -> Result<Solved, String> {
    solve_with_surface(mesh, manifest, clusters, None, params, progress)
}

/// [`solve`] with the textures and alpha masks of `surface` (from
/// `mesh-prep --surface`, read for this mesh and manifest) where given
/// ([`detail`]).
pub fn solve_with_surface(mesh: &Mesh, manifest: &Manifest, clusters: Option<Clusters>, surface: Option<Surface>, params: &Params, progress: &dyn Fn(&Progress)) -> Result<Solved, String> {
    if let Some(problem) = params.problem() {
        return Err(problem);
    }
    let n = mesh.triangles.len();
    let clustered = clusters.is_some();
    if !clustered && n.saturating_mul(n) > MAX_INITIAL_PAIRS {
        return Err(format!("{n} triangles need {} initial links without clustering (limit {MAX_INITIAL_PAIRS}); give a cluster hierarchy", n * n));
    }
    let mut h = Hierarchy::new(mesh, manifest, clusters, surface);
    let total_area: f64 = (0..n).map(|t| h.elements[t].area).sum();
    let min_area = params.min_area * total_area;
    let floors = Floors { area: min_area, shadow: min_area * 0.25f64.powi(params.shadow_levels as i32) };
    let linking = Linking { cluster_samples: params.cluster_samples, seed: params.seed, quadrature: Quadrature::to_depth(params.quadrature_depth) };
    let mut scene = SceneRays::new(&h.triangles.iter().map(|t| t.corners).collect::<Vec<_>>());
    if let Some(masks) = h.detail.as_ref().and_then(|d| d.alpha_masks(mesh)) {
        scene = scene.with_alpha_masks(masks);
    }
    let occluders = shaft::Occluders::new(&h.triangles.iter().map(|t| t.corners).collect::<Vec<_>>(), &scene);
    let mut work = Work::default();
    let knobs = mirrors::Knobs {
        rays: params.specular_rays,
        min_factor: params.specular_min_factor,
        quadrature: params.quadrature_depth,
        seed: params.seed,
        sender_level: params.specular_sender_level,
        max_events: params.specular_depth,
    };
    // More windows than can be traced: no specular light (mirrors::MAX_WINDOWS).
    let windows = mirrors::Windows::new(mesh, manifest, &h, knobs).unwrap_or_else(|count| {
        work.specular_windows_left_out = count;
        None
    });
    // Luminaires first (crate::luminaires): their direct light on the input
    // triangles, which joins the emission in the scale of the threshold,
    // then the elements refined for it.
    let lights = if manifest.effects.goniometric_lights { stage_kit::scene::luminaires(&manifest.goniometric_lights)? } else { Vec::new() };
    let direct = DirectLight { lights: &lights, rays: &scene };
    let started = Instant::now();
    work.luminaire_rays += luminaires::extend(&mut h, &direct, params.quadrature_depth);
    let largest_source = (0..n as u32).flat_map(|e| h.source(e)).fold(0.0, f64::max);
    let threshold = params.eps * largest_source;
    if !lights.is_empty() {
        // The direct light is known before any solve, so the relative
        // criterion can judge it from the start.
        let mut sources: Vec<[f64; 3]> = vec![[0.0; 3]; h.cluster_count()];
        sources.extend((0..n as u32).map(|e| h.source(e)));
        let allowance = allowance(params, threshold, Some(mean_reflected(&h, &sources)));
        work.luminaire_rays += luminaires::refine(&mut h, &direct, &allowance, min_area, params.quadrature_depth);
    }
    h.pair_faces();
    work.luminaire_seconds += started.elapsed().as_secs_f64();
    let mut b: Vec<[f64; 3]> = vec![[0.0; 3]; h.cluster_count()];
    b.extend((0..h.elements.len() as u32).map(|e| h.source(e)));
    gather::pull(&h, &mut b);

    let started = Instant::now();
    let mut all_links: Vec<Link> = if clustered {
        vec![self_link(Node::Cluster(0))]
    } else {
        work.form_factors += (n * n) as u64;
        (0..n as u32)
            .into_par_iter()
            .flat_map_iter(|r| {
                let h = &h;
                (0..n as u32).filter_map(move |s| link(h, Node::Element(r), Node::Element(s), linking))
            })
            .collect()
    };
    work.refine_seconds += started.elapsed().as_secs_f64();
    // A scene without reflectors needs one pass: direct light only.
    let passes = if manifest.effects.diffuse_interreflection { params.max_passes } else { 1 };
    // The rate of convergence of the previous pass's solve (gather::solve).
    let mut rates = [0.0; 3];
    // The couplings through mirrors and panes, rebuilt each pass (mirrors).
    let mut specular: Option<mirrors::Couplings> = None;
    // What each link's sender sent in the last solve (gather::SenderTerms).
    let mut senders = gather::SenderTerms::new(&h, &[], gather::Senders::Means);
    // The weights of the links into clusters, kept from pass to pass (receivers).
    let mut receiver_weights = receivers::WeightCache::default();
    // The last solve's measured slopes of emitters' light inside leaves
    // (slopes); none where it did not run.
    let mut direct_slopes = Vec::new();
    for pass in 1..=passes {
        let started = Instant::now();
        let mut refined_any = false;
        progress(&Progress { pass, phase: Phase::Refining, links: all_links.len(), elements: h.elements.len() });
        // Before the first solve no receiver's radiosity is known.
        let allowance = allowance(params, threshold, (pass > 1).then(|| mean_reflected(&h, &b)));
        // The relative criterion sees a sender's variation at every level
        // below it; the absolute one only at its children, as before.
        let (range, dimmest) = match allowance {
            Allowance::Relative { .. } => (links::leaf_range(&h, &b), links::dimmest_leaf(&h, &b)),
            Allowance::Absolute(_) => (Vec::new(), Vec::new()),
        };
        let linking = Linking { quadrature: allowance.quadrature(rates, params.quadrature_depth), ..linking };
        let mut active = std::mem::take(&mut all_links);
        // How many links at the front of all_links keep the order the
        // previous pass sorted them in: those it kept first (sort_links).
        let mut in_order = None;
        while !active.is_empty() {
            // Stop before a round of splits that could pass the cap.
            let most: usize = active.par_iter().map(|l| links::most_children_links(&h, l)).sum();
            if all_links.len() + most > params.max_links {
                work.links_capped = true;
                all_links.append(&mut active);
                break;
            }
            let decisions: Vec<Split> = active.par_iter().map(|l| decide(&h, l, &b, &range, &dimmest, &allowance, floors)).collect();
            for (l, d) in active.iter().zip(&decisions) {
                let node = match d {
                    Split::Sender => l.sender,
                    Split::Receiver => l.receiver,
                    _ => continue,
                };
                let before = h.elements.len();
                h.ensure_children(node);
                if h.elements.len() > before {
                    let parent_b = b[h.flat(node)];
                    b.resize(b.len() + 4, parent_b);
                }
            }
            let split = decisions.iter().filter(|d| **d != Split::Keep).count();
            refined_any |= decisions.iter().any(|d| matches!(d, Split::Sender | Split::Receiver));
            all_links.extend(active.iter().zip(&decisions).filter(|(_, d)| **d == Split::Keep).map(|(l, _)| *l));
            in_order.get_or_insert(if pass > 1 { all_links.len() } else { 0 });
            active = active
                .par_iter()
                .zip(&decisions)
                .filter(|(_, d)| **d != Split::Keep)
                .flat_map_iter(|(l, d)| children_links(&h, l, *d, linking))
                .collect();
            work.form_factors += active.len() as u64;
            if split == 0 {
                break;
            }
        }
        // Leaves the light through mirrors and panes varies over (mirrors).
        for e in specular.as_ref().map_or(Vec::new(), |s| s.to_split(&h, &b, &allowance, min_area)) {
            h.ensure_children(Node::Element(e));
            let parent_b = b[h.flat(Node::Element(e))];
            b.resize(b.len() + 4, parent_b);
            refined_any = true;
        }
        // The faces of translucent surfaces refine alike (crate::transmission).
        if h.pair_faces() {
            inherit_radiosity(&h, &mut b);
        }
        work.refine_seconds += started.elapsed().as_secs_f64();

        progress(&Progress { pass, phase: Phase::Visibility, links: all_links.len(), elements: h.elements.len() });
        let started = Instant::now();
        work.luminaire_rays += luminaires::extend(&mut h, &direct, params.quadrature_depth);
        work.luminaire_seconds += started.elapsed().as_secs_f64();

        work.exposure_rays += exposure::extend(&mut h, &scene, params.seed);
        let started = Instant::now();
        let rays: usize = all_links
            .par_iter_mut()
            .filter(|l| l.visibility.is_none())
            .map(|l| {
                let rays = links::visibility_rays(&h, l, &b, &dimmest, &allowance, params.visibility_rays);
                visibility::settle(&h, &scene, &occluders, l, rays, linking)
            })
            .sum();
        work.rays += rays as u64;
        work.visibility_seconds += started.elapsed().as_secs_f64();
        let started = Instant::now();
        specular = windows.as_ref().map(|w| w.couplings(&h, &scene, &b));
        if let Some(s) = &specular {
            work.specular_couplings = s.len();
            work.specular_truncation = s.truncation;
            work.specular_rays += s.rays;
            work.specular_seconds += started.elapsed().as_secs_f64();
        }

        progress(&Progress { pass, phase: Phase::Gathering, links: all_links.len(), elements: h.elements.len() });
        let started = Instant::now();
        all_links = sort_links(&h, all_links, in_order.unwrap_or(0));
        let mut offsets = csr_offsets(&h, &all_links, b.len());
        // The passes refine with senders' area means; the last one then
        // solves on with the senders whose radiosity varies resolved by the
        // kernel (gather::SenderTerms), judged on the means' solution,
        // within the same iteration cap (a capped solve keeps the means),
        // and partly occluded links into clusters weighing each face by
        // its visibility (receivers).
        senders = gather::SenderTerms::new(&h, &all_links, gather::Senders::Means);
        let mut receivers = receivers::ReceiverTerms::new(&h, &mut all_links, receivers::Build::Means, &mut receiver_weights);
        let mut convergence = gather::solve(&h, &all_links, &offsets, specular.as_ref(), &mut b, params.tolerance, params.max_iterations, rates, &senders, &receivers);
        let mut left = params.max_iterations - convergence.iterations;
        if (pass == passes || (!refined_any && pass > 1) || work.links_capped) && convergence.converged && left > 0 {
            let tracer = visibility::Tracer::new(&scene, &occluders, params.seed, params.visibility_rays);
            // Leaves a shadow edge crosses open into their children
            // (crate::shadowed), which a means' solve lights by their own
            // visibility before the senders are resolved.
            let opened = if specular.is_none() && h.transmission.is_none() { shadowed::shadowed_leaves(&h, &all_links, &b, floors.shadow) } else { Vec::new() };
            if !opened.is_empty() {
                for &e in &opened {
                    h.ensure_children(Node::Element(e));
                }
                let mut is_opened = vec![false; h.elements.len()];
                opened.iter().for_each(|&e| is_opened[e as usize] = true);
                work.opened_leaves = opened.len();
                inherit_radiosity(&h, &mut b);
                work.luminaire_rays += luminaires::extend(&mut h, &direct, params.quadrature_depth);
                work.exposure_rays += exposure::extend(&mut h, &scene, params.seed);
                offsets = csr_offsets(&h, &all_links, b.len());
                let budget = links::Budget::new(&h, &b, allowance);
                receivers = receivers::ReceiverTerms::new(&h, &mut all_links, receivers::Build::Opened { tracer: tracer.budgeted(&budget), opened: &is_opened }, &mut receiver_weights);
                work.part_rays += receivers.rays as u64;
                let means = convergence;
                convergence = gather::solve(&h, &all_links, &offsets, specular.as_ref(), &mut b, params.tolerance, left, means.rates, &senders, &receivers);
                left -= convergence.iterations;
                work.iterations += means.iterations;
                work.extrapolations += means.extrapolations;
            }
            if convergence.converged && left > 0 {
                let deviation = links::leaf_deviation(&h, &b);
                let resolution = gather::Resolution::new(&b, &deviation, convergence.rates);
                senders = gather::SenderTerms::new(&h, &all_links, gather::Senders::Resolved { resolution, tracer });
                let budget = links::Budget::new(&h, &b, allowance);
                receivers = receivers::ReceiverTerms::new(&h, &mut all_links, receivers::Build::Last { tracer: tracer.budgeted(&budget), resolution: Some(resolution) }, &mut receiver_weights);
                direct_slopes = std::mem::take(&mut receivers.slopes);
                // The leaves' slopes lit through their neighbours too (slopes).
                let sent_slopes = slopes::sender_offsets(&h, &all_links, &senders, &b, &direct_slopes);
                senders.set_offsets(sent_slopes);
                work.part_rays += (senders.rays() + receivers.rays) as u64;
                work.resolved_links = senders.resolved();
                let means = convergence;
                convergence = gather::solve(&h, &all_links, &offsets, specular.as_ref(), &mut b, params.tolerance, left, means.rates, &senders, &receivers);
                work.iterations += means.iterations;
                work.extrapolations += means.extrapolations;
            }
        }
        rates = convergence.rates;
        work.iterations += convergence.iterations;
        work.relative_change = convergence.relative_change;
        work.error_bound = convergence.error_bound;
        work.contraction = convergence.contraction;
        work.converged = convergence.converged;
        work.capped_passes += usize::from(!convergence.converged);
        work.extrapolations += convergence.extrapolations;
        work.gather_seconds += started.elapsed().as_secs_f64();
        work.passes = pass;
        progress(&Progress { pass, phase: Phase::Done, links: all_links.len(), elements: h.elements.len() });
        if (!refined_any && pass > 1) || work.links_capped {
            break;
        }
    }
    work.links = all_links.len();
    work.cluster_links = all_links.iter().filter(|l| matches!(l.receiver, Node::Cluster(_)) || matches!(l.sender, Node::Cluster(_))).count();
    work.elements = h.elements.len();
    work.leaves = h.elements.iter().filter(|e| e.is_leaf()).count();
    // Changes that do not shrink at the iteration cap mean the iterate is
    // no solution at all (a closed scene of reflectance 1, which never
    // absorbs its light, or a row of the iteration matrix over 1 that the
    // caps of crate::gather did not reach): refused rather than written.
    if !work.converged && work.contraction >= 1.0 {
        return Err(format!(
            "the radiosity iteration diverges: at max_iterations = {} each change was {:.3} times the one before (no steady state: light that is never absorbed, or a surface gathering more than it can receive); no solution written",
            params.max_iterations, work.contraction
        ));
    }
    // The solution stores 32-bit floats: a radiosity beyond their range
    // would be written as inf, and every reader would refuse the file.
    if let Some(v) = b.iter().flatten().find(|v| !(v.is_finite() && v.abs() <= f64::from(f32::MAX))) {
        return Err(format!("a radiosity of {v:e} W/m² does not fit the solution's 32-bit floats (largest {:e}): scale the emission down", f32::MAX));
    }
    let clusters_out = (0..h.cluster_count())
        .map(|c| solution::ClusterRadiosity { area: h.area(Node::Cluster(c as u32)) as f32, radiosity: f32x3(b[c]) })
        .collect();
    let slopes = slopes::leaf_slopes(&h, &b, &direct_slopes);
    Ok(Solved { elements: output_elements(&h, &b), clusters: clusters_out, links: output_links(&all_links, &senders.sent(&b)), slopes, work })
}

/// What a refinement may err by, given the absolute `threshold` and, once
/// a radiosity is known, the scene's mean reflected radiosity `mean`
/// ([`mean_reflected`]): the relative criterion's allowance where it is
/// chosen and `mean` is known, otherwise the absolute one.
fn allowance(params: &Params, threshold: f64, mean: Option<f64>) -> Allowance {
    match (params.criterion, mean) {
        (Criterion::Relative, Some(mean)) => {
            // Unset: the absolute threshold at a receiver of RELATIVE_AT
            // times the mean reflected radiosity.
            let eps = params.eps_relative.unwrap_or(if mean > 0.0 { threshold / (RELATIVE_AT * mean) } else { params.eps });
            Allowance::Relative { eps, floor: params.relative_floor * mean, share: params.share_floor, most: threshold }
        }
        _ => Allowance::Absolute(threshold),
    }
}

/// The area-mean over the input triangles of each one's brightest channel
/// of reflected radiosity (radiosity less emission): emitters do not raise
/// the floor, which is meant for the dimmest reflectors.
fn mean_reflected(h: &Hierarchy, b: &[[f64; 3]]) -> f64 {
    let n = h.triangles.len();
    let (sum, area) = (0..n as u32).fold((0.0, 0.0), |(sum, area), t| {
        let (a, e) = (h.elements[t as usize].area, h.emission[t as usize]);
        let bt = b[h.flat(Node::Element(t))];
        (sum + a * (0..3).map(|c| bt[c] - e[c]).fold(0.0, f64::max), area + a)
    });
    if area > 0.0 { sum / area } else { 0.0 }
}

/// `links` sorted by receiver then sender (dense indices, unique per link),
/// given that its first `in_order` are: the rest is sorted and merged in.
/// A pass keeps most of the previous pass's links, in their order, at the
/// front, so this costs a sort of the new links and one merge, not a sort
/// of all (8% of a solve's CPU at `EPS` 3e-4); the order is the same.
fn sort_links(h: &Hierarchy, mut links: Vec<Link>, in_order: usize) -> Vec<Link> {
    let key = |l: &Link| (h.flat(l.receiver), h.flat(l.sender));
    debug_assert!(links[..in_order].is_sorted_by_key(key));
    let mut rest = links.split_off(in_order);
    rest.par_sort_unstable_by_key(key);
    if links.is_empty() {
        return rest;
    }
    let mut merged = Vec::with_capacity(links.len() + rest.len());
    let (mut a, mut b) = (links.into_iter().peekable(), rest.into_iter().peekable());
    while let (Some(x), Some(y)) = (a.peek(), b.peek()) {
        let next = if key(x) <= key(y) { a.next() } else { b.next() };
        merged.extend(next);
    }
    merged.extend(a);
    merged.extend(b);
    merged
}

/// Gives each element that `b` (radiosity per node, dense index) has no
/// entry for yet, new ones at the end, its parent's radiosity.
fn inherit_radiosity(h: &Hierarchy, b: &mut Vec<[f64; 3]>) {
    while b.len() < h.cluster_count() + h.elements.len() {
        let parent = h.elements[b.len() - h.cluster_count()].parent;
        b.push(b[h.flat(Node::Element(parent))]);
    }
}

/// `offsets[i]..offsets[i + 1]` indexes the links into the node of dense
/// index `i` in `links` (sorted by receiver).
fn csr_offsets(h: &Hierarchy, links: &[Link], nodes: usize) -> Vec<usize> {
    let mut offsets = vec![0usize; nodes + 1];
    for l in links {
        offsets[h.flat(l.receiver) + 1] += 1;
    }
    for i in 0..nodes {
        offsets[i + 1] += offsets[i];
    }
    offsets
}

fn f32x3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn output_elements(h: &Hierarchy, b: &[[f64; 3]]) -> Vec<solution::Element> {
    h.elements
        .iter()
        .zip(&b[h.cluster_count()..])
        .zip(exposure::exposed_areas(h))
        .map(|((e, b), area)| solution::Element {
            triangle: e.triangle,
            parent: e.parent,
            first_child: e.first_child,
            level: e.level,
            corners: e.corners.map(|c| c.map(|x| x as f32)),
            area: area as f32,
            radiosity: f32x3(*b),
        })
        .collect()
}

/// The solution's links; `sent[l]`: the radiosity link `l` sent in the
/// last solve (its sender resolved by the kernel, gather::SenderTerms), not
/// the sender's area mean.
fn output_links(links: &[Link], sent: &[[f64; 3]]) -> Vec<solution::Link> {
    links
        .iter()
        .zip(sent)
        .map(|(l, s)| solution::Link {
            receiver: l.receiver,
            sender: l.sender,
            form_factor: l.form_factor as f32,
            visibility: l.visibility.unwrap_or(1.0),
            unoccluded_irradiance: f32x3(s.map(|x| x * l.form_factor)),
            occluder_distance: l.occluder_distance,
        })
        .collect()
}

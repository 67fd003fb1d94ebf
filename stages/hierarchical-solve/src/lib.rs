//! # hierarchical-solve: hierarchical radiosity on the scene's patches
//!
//! After Hanrahan, Salzman and Aupperle (SIGGRAPH 1991). Every pair of input
//! triangles that can exchange light starts with one link; links are refined
//! by the BF oracle ([`links::decide`]) down to a minimum element area; form
//! factors are Lambert's closed form (paper 002 Eq. 3) averaged over the
//! receiver ([`radiometry::form_factor`]); visibility is a ray-cast fraction
//! per link ([`visibility`]); radiosity is gathered with push-pull
//! ([`gather`]). Refinement needs radiosity and radiosity needs links, so
//! the two alternate in passes until a pass refines nothing.
//!
//! Parameters ([`Params`]):
//!
//! | name | meaning | default |
//! |---|---|---|
//! | `eps` | BF threshold, as a fraction of the largest emitted radiosity | 2e-4 |
//! | `min_area` | smallest element area, as a fraction of the scene's total area | 1e-4 |
//! | `visibility_rays` | rays per link for its visibility | 16 |
//! | `tolerance` | convergence: largest relative change of a leaf's radiosity | 1e-5 |
//! | `max_iterations` | Jacobi iterations per solve, at most | 2000 |
//! | `max_passes` | refine-and-solve passes, at most | 8 |
//! | `seed` | seed of the visibility rays | 1 |

pub mod elements;
pub mod gather;
pub mod links;
pub mod visibility;

use elements::Hierarchy;
use links::{children_links, decide, link, Link, Split};
use radiometry::rays::SceneRays;
use rayon::prelude::*;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The solver's knobs (see the table in the crate documentation).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// BF threshold relative to the largest emitted radiosity.
    pub eps: f64,
    /// Smallest element area relative to the total area.
    pub min_area: f64,
    /// Rays per link.
    pub visibility_rays: usize,
    /// Relative change at which gathering stops.
    pub tolerance: f64,
    /// Jacobi iterations per solve, at most.
    pub max_iterations: usize,
    /// Refine-and-solve passes, at most.
    pub max_passes: usize,
    /// Seed of the visibility rays.
    pub seed: u64,
}

impl Default for Params {
    fn default() -> Self {
        Params { eps: 2e-4, min_area: 1e-4, visibility_rays: 16, tolerance: 1e-5, max_iterations: 2000, max_passes: 8, seed: 1 }
    }
}

impl Params {
    /// Why the parameters are unusable, if they are.
    pub fn problem(&self) -> Option<String> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.eps) {
            return Some(format!("eps must be a positive number, not {}", self.eps));
        }
        if !positive(self.min_area) || self.min_area > 1.0 {
            return Some(format!("min_area must be in (0, 1], not {}", self.min_area));
        }
        if self.visibility_rays == 0 || self.visibility_rays > 4096 {
            return Some(format!("visibility_rays must be in 1..=4096, not {}", self.visibility_rays));
        }
        if !positive(self.tolerance) || self.max_iterations == 0 || self.max_passes == 0 {
            return Some("tolerance must be positive, max_iterations and max_passes at least 1".into());
        }
        None
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
    /// Seconds refining links (form factors, oracle).
    pub refine_seconds: f64,
    /// Seconds casting visibility rays.
    pub visibility_seconds: f64,
    /// Seconds gathering.
    pub gather_seconds: f64,
}

/// Progress of a solve, reported after each pass.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Pass just finished (1-based).
    pub pass: usize,
    /// Links now.
    pub links: usize,
    /// Elements now.
    pub elements: usize,
}

/// The solve's result: the solution's tables (without header) and the work.
pub struct Solved {
    /// Elements with radiosity.
    pub elements: Vec<solution::Element>,
    /// Radiosity per cluster (empty without clustering).
    pub clusters: Vec<solution::ClusterRadiosity>,
    /// Links, sorted by receiver then sender.
    pub links: Vec<solution::Link>,
    /// Work done.
    pub work: Work,
}

/// Solves the scene. `progress` is called after each pass.
pub fn solve(mesh: &Mesh, manifest: &Manifest, params: &Params, progress: &dyn Fn(&Progress)) -> Result<Solved, String> {
    if let Some(problem) = params.problem() {
        return Err(problem);
    }
    let n = mesh.triangles.len();
    if n.saturating_mul(n) > MAX_INITIAL_PAIRS {
        return Err(format!("{n} triangles need {} initial links without clustering; the limit is {MAX_INITIAL_PAIRS}", n * n));
    }
    let mut h = Hierarchy::new(mesh, manifest);
    let total_area: f64 = h.elements.iter().map(|e| e.area).sum();
    let min_area = params.min_area * total_area;
    let largest_emission = h.emission.iter().flatten().copied().fold(0.0, f64::max);
    let threshold = params.eps * largest_emission;
    let scene = SceneRays::new(&h.triangles.iter().map(|t| t.corners).collect::<Vec<_>>());
    let mut work = Work::default();
    let mut b: Vec<[f64; 3]> = h.emission.clone();

    let started = Instant::now();
    let mut all_links: Vec<Link> = (0..n as u32)
        .into_par_iter()
        .flat_map_iter(|r| {
            let h = &h;
            (0..n as u32).filter_map(move |s| link(h, r, s))
        })
        .collect();
    work.form_factors += (n * n) as u64;
    work.refine_seconds += started.elapsed().as_secs_f64();
    // A scene without reflectors needs one pass: direct light only.
    let passes = if manifest.effects.diffuse_interreflection { params.max_passes } else { 1 };
    let mut offsets = Vec::new();
    for pass in 1..=passes {
        let started = Instant::now();
        let mut refined_any = false;
        loop {
            let decisions: Vec<Split> = all_links.par_iter().map(|l| decide(&h, l, &b, threshold, min_area)).collect();
            if decisions.iter().all(|d| *d == Split::Keep) {
                break;
            }
            refined_any = true;
            for (l, d) in all_links.iter().zip(&decisions) {
                let split = match d {
                    Split::Keep | Split::Larger => continue,
                    Split::Sender => l.sender,
                    Split::Receiver => l.receiver,
                };
                if h.elements[split as usize].is_leaf() {
                    let first = h.subdivide(split) as usize;
                    b.resize(first + 4, b[split as usize]);
                }
            }
            work.form_factors += decisions.iter().filter(|d| **d != Split::Keep).count() as u64 * 4;
            all_links = all_links.par_iter().zip(&decisions).flat_map_iter(|(l, d)| children_links(&h, l, *d)).collect();
        }
        work.refine_seconds += started.elapsed().as_secs_f64();

        let started = Instant::now();
        let new_rays = all_links.iter().filter(|l| l.visibility.is_none()).count() as u64 * params.visibility_rays as u64;
        all_links.par_iter_mut().filter(|l| l.visibility.is_none()).for_each(|l| {
            let (v, d) = visibility::estimate(&h, &scene, l.receiver, l.sender, params.visibility_rays, params.seed);
            l.visibility = Some(v);
            l.occluder_distance = d;
        });
        work.rays += new_rays;
        work.visibility_seconds += started.elapsed().as_secs_f64();

        let started = Instant::now();
        all_links.par_sort_unstable_by_key(|l| (l.receiver, l.sender));
        offsets = csr_offsets(&all_links, h.elements.len());
        let convergence = gather::solve(&h, &all_links, &offsets, &mut b, params.tolerance, params.max_iterations);
        work.iterations += convergence.iterations;
        work.relative_change = convergence.relative_change;
        work.gather_seconds += started.elapsed().as_secs_f64();
        work.passes = pass;
        progress(&Progress { pass, links: all_links.len(), elements: h.elements.len() });
        if !refined_any && pass > 1 {
            break;
        }
    }
    debug_assert_eq!(offsets.len(), h.elements.len() + 1);
    work.links = all_links.len();
    work.elements = h.elements.len();
    work.leaves = h.elements.iter().filter(|e| e.is_leaf()).count();
    Ok(Solved { elements: output_elements(&h, &b), clusters: Vec::new(), links: output_links(&all_links, &b), work })
}

/// `offsets[e]..offsets[e + 1]` indexes the links into element `e` of
/// `links` (sorted by receiver).
fn csr_offsets(links: &[Link], elements: usize) -> Vec<usize> {
    let mut offsets = vec![0usize; elements + 1];
    for l in links {
        offsets[l.receiver as usize + 1] += 1;
    }
    for e in 0..elements {
        offsets[e + 1] += offsets[e];
    }
    offsets
}

fn f32x3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn output_elements(h: &Hierarchy, b: &[[f64; 3]]) -> Vec<solution::Element> {
    h.elements
        .iter()
        .zip(b)
        .map(|(e, b)| solution::Element {
            triangle: e.triangle,
            parent: e.parent,
            first_child: e.first_child,
            level: e.level,
            corners: e.corners.map(|c| c.map(|x| x as f32)),
            area: e.area as f32,
            radiosity: f32x3(*b),
        })
        .collect()
}

fn output_links(links: &[Link], b: &[[f64; 3]]) -> Vec<solution::Link> {
    links
        .iter()
        .map(|l| solution::Link {
            receiver: solution::Node::Element(l.receiver),
            sender: solution::Node::Element(l.sender),
            form_factor: l.form_factor as f32,
            visibility: l.visibility.unwrap_or(1.0),
            unoccluded_irradiance: f32x3(b[l.sender as usize].map(|x| x * l.form_factor)),
            occluder_distance: l.occluder_distance,
        })
        .collect()
}

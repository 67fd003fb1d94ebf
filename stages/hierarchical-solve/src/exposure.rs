//! Exposure: the fraction of an element's area that is not buried inside a
//! solid.
//!
//! A block standing on a floor hides the floor under it from everything:
//! no light reaches that part and none leaves it. An element that straddles
//! the block's footprint is lit only over its exposed fraction `x`, and
//! every link into it says so (its visibility rays from points under the
//! block are stopped by the block), so the irradiance the links bring,
//! averaged over the whole element, is `x H`, with `H` what the exposed
//! part receives. Spreading that over the whole element as one radiosity
//! `rho x H` shows the exposed part `x` times too dark, and when the
//! element sends, the links out of it are again stopped over the buried
//! part: its receivers get `rho x^2 H` where `rho x H` leaves it. The
//! buried part swallows light. On the built-in Cornell box at `EPS` 1e-2
//! the floor's leaves held 1.6% of the floor's radiosity-area on buried
//! parts (0.4% at 2e-4, where the leaves along the blocks' footprints are
//! small), and every surface the floor lights came out 0.5% to 2% dark
//! against the fine solve.
//!
//! So every node's gathered irradiance is divided by its exposure, which
//! makes it the irradiance of the exposed part, and that is what its
//! radiosity `B = E + rho H / x` describes; an inner node's radiosity is
//! the mean of its children's weighted by their *exposed* areas `A x`
//! ([`crate::gather`]). The flux an element sends, `B A x`, is then what it
//! reflects, `rho x H A`, and receivers see `B` through the visibility of
//! its exposed part. The direct light of luminaires, averaged over the
//! element with shadow rays, is divided alike ([`Hierarchy::source`]); the
//! emission is not (a buried part of a lamp is a lamp whose light the solid
//! absorbs).
//!
//! The division can lift a leaf's row of the iteration matrix (`rho sum V
//! F / x`) over 1 where its exposure and its links' visibility, estimated
//! apart, disagree by their noise; the stopping rule then takes the rate
//! from the ratios of successive changes ([`crate::gather::solve`]), as for
//! a closed scene.
//!
//! A point is buried as [`radiometry::burial`] tests it: all its rays
//! meet back faces first. `x` is the fraction of stratified points of the
//! element (those that exist under an alpha mask) that are not buried
//! (`of_element`); a fully buried element (`x = 0`) keeps the plain rule
//! (its links bring it nothing anyway).

use crate::elements::Hierarchy;
use crate::nodes::key;
use radiometry::burial::ProvenRoofs;
use radiometry::rays::SceneRays;
use radiometry::sampling::{Strata, Stream};
use rayon::prelude::*;
use schemas::solution::Node;

/// Points per element whose burial is tested first.
pub const EXPOSURE_POINTS: usize = 16;

/// Points per element where the first [`EXPOSURE_POINTS`] disagree (a
/// contact line crosses it): a 16 x 16 stratification, where the line
/// crosses about 16 strata and `x` is known to about 1/128 (4 x 4 left
/// about 1/16, a straddling leaf's radiosity 12% off at `x` = 1/2). Only
/// such elements pay for it.
pub const STRADDLING_POINTS: usize = 256;

/// Where the rays from a point of `element` start: past the rounding of
/// the f32 ray origin (a point near a coplanar neighbour's edge must not
/// meet that neighbour at `t = 0`).
fn t_min(element: &crate::elements::Element) -> f32 {
    let scale = element.points.iter().map(|p| p.abs().max_element()).fold(element.area.sqrt(), f64::max);
    (1e-6 * scale) as f32
}

/// Exposure of element `e` (module docs) and the rays cast:
/// [`EXPOSURE_POINTS`] points, and [`STRADDLING_POINTS`] where those
/// disagree, one ray each where a roof is known (`sampled`).
fn of_element(h: &Hierarchy, scene: &SceneRays, e: u32, seed: u64) -> (f64, u64) {
    let mut stream = Stream::new(seed ^ 0xe790_5ed0, key(Node::Element(e)), 0xb0);
    let first = sampled(h, scene, e, EXPOSURE_POINTS, &ProvenRoofs::default(), &mut stream);
    if first.exposure > 0.0 && first.exposure < 1.0 {
        let more = sampled(h, scene, e, STRADDLING_POINTS, &first.roofs, &mut stream);
        return (more.exposure, first.rays + more.rays);
    }
    (first.exposure, first.rays)
}

/// What `sampled` measured over an element.
struct Sampled {
    /// The exposed fraction of its points (1 where none exists).
    exposure: f64,
    /// Rays cast.
    rays: u64,
    /// The roofs over its points proven a solid's.
    roofs: ProvenRoofs,
}

/// The exposed fraction of `n` stratified points of element `e` (those
/// that exist; 1 where none does), the rays cast, and the roofs proven
/// ([`ProvenRoofs`]: given in `roofs`, or found earlier in this call).
///
/// A point buried under a sheet proves nothing for the points beside it
/// ([`radiometry::burial::Walls::Sheet`]). When it did, every point under the sheet's
/// triangles was buried once one was, and the leaves over the sheet's
/// edge took exposures a quarter of their open part: in
/// `tests/tests/hung_sheet.rs` two of them showed 0.70 where no point of
/// the ceiling gets more than 0.49, their light divided by that exposure,
/// and sent it into the room. Now every leaf there is within 1.6% of the
/// open ceiling's radiosity of the closed form. On McGuire's
/// `CornellBox-Original` at `EPS` 7e-4 the full gather's mean signed error
/// against the full gather of an `EPS` 2.5e-5 solve went from +0.29% and
/// +0.34% to +0.14% and +0.17% (seeds 1 and 2), for a third more exposure
/// rays (113k -> 150k) and no change in the solve time (single runs).
/// The built-in Cornell box's solutions are unchanged to the bit: the
/// grazing rays from under its blocks meet their walls.
fn sampled(h: &Hierarchy, scene: &SceneRays, e: u32, n: usize, roofs: &ProvenRoofs, stream: &mut Stream) -> Sampled {
    let element = &h.elements[e as usize];
    let normal = h.normal(e);
    let normal_of = |t: u32| h.triangles[t as usize].normal;
    let t_min = t_min(element);
    let (mut existing, mut exposed, mut rays, mut proven) = (0usize, 0usize, 0u64, roofs.clone());
    let strata = Strata::of(n);
    for k in 0..n {
        let point = strata.point(&element.points, k, stream);
        if !crate::visibility::exists(h, element.triangle, point) {
            continue;
        }
        existing += 1;
        let (is_buried, cast) = proven.buried(scene, &normal_of, point, normal, element.triangle, t_min, stream);
        rays += cast;
        exposed += usize::from(!is_buried);
    }
    Sampled { exposure: if existing == 0 { 1.0 } else { exposed as f64 / existing as f64 }, rays, roofs: proven }
}

/// The exposure of an inner node: its children's `(area, exposure)`
/// weighted by their (opaque) area, 1 where they have none. How the solve
/// weighs an inner node ([`crate::gather`]) and how [`extend`] gives one
/// to an element it does not measure.
pub fn of_children(children: impl Iterator<Item = (f64, f64)> + Clone) -> f64 {
    let area: f64 = children.clone().map(|(a, _)| a).sum();
    if area > 0.0 {
        children.map(|(a, x)| a * x).sum::<f64>() / area
    } else {
        1.0
    }
}

/// Measures the exposure of the elements that have none yet (those
/// created since the last call); returns the rays cast. Only the leaves
/// are measured: an element already split when this is called (made and
/// refined in one pass) takes [`of_children`] and casts no rays. Elements
/// along a contact line cost the most (each of their first points under
/// the solid casts all its [`radiometry::burial::EXPOSURE_RAYS`], and a
/// straddling element [`STRADDLING_POINTS`] points more, one ray each
/// where a roof is known, `sampled`), and a pass makes and splits several
/// levels of them at once.
pub fn extend(h: &mut Hierarchy, scene: &SceneRays, seed: u64) -> u64 {
    let first = h.exposure.len();
    let measured: Vec<(f64, u64)> = (first..h.elements.len()).into_par_iter().map(|e| if h.elements[e].is_leaf() { of_element(h, scene, e as u32, seed) } else { (f64::NAN, 0) }).collect();
    h.exposure.extend(measured.iter().map(|m| m.0));
    for e in (first..h.elements.len()).rev() {
        let element = &h.elements[e];
        if !element.is_leaf() {
            h.exposure[e] = of_children((element.first_child..element.first_child + 4).map(|c| (h.area(Node::Element(c)), h.exposure[c as usize])));
        }
    }
    measured.iter().map(|m| m.1).sum()
}

/// Each element's exposed area, m²: a leaf's area times its exposure, an
/// inner element's the sum of its children's (what the solution file's
/// `area` holds, so that area-weighted means over it, as every reader
/// takes them, weigh what a viewer can see: the radiosity of a leaf is its
/// exposed part's).
pub fn exposed_areas(h: &Hierarchy) -> Vec<f64> {
    let mut area: Vec<f64> = (0..h.elements.len() as u32).map(|e| h.elements[e as usize].area * h.exposure(e)).collect();
    for e in (0..h.elements.len()).rev() {
        let element = &h.elements[e];
        if !element.is_leaf() {
            area[e] = (element.first_child..element.first_child + 4).map(|c| area[c as usize]).sum();
        }
    }
    area
}

//! Goniometric point lights (luminaires) in the hierarchical solve: they
//! are shot first, as gpu-shoot does (paper 004 Sec. 3.4: a point source of
//! radiant intensity `I_e(C, gamma) = scale I_v(C, gamma) / 683` W/sr, the
//! table interpolated bicubically, Sec. 3.4.1), then the surfaces
//! interreflect. A point light has no area and no radiosity, so it takes
//! no links; its direct light is a source term of every leaf:
//!
//! ```text
//! D_e   = 1/A_e integral_{A_e} sum_lights I_e(d) cos(theta) / r^2 v dA     (W/m², [`Hierarchy::direct`])
//! B_e   = E_e + rho_e D_e + rho_e H_e                                      (gather.rs, with H_e from the links)
//! ```
//!
//! `D_e` is averaged over the element by the near-field-adaptive quadrature
//! of [`radiometry::photometry::Luminaire::element_irradiance`] (finite for
//! a light on or next to the surface; 0 behind a one-sided surface), with
//! a shadow ray per quadrature point ([`DirectLight`]).
//!
//! Elements are refined for the direct light before the links are
//! ([`refine`]): an element splits while replacing its four children's
//! `rho D` by its own would err by more than the links may
//! (`max_c rho_c max_k |D_k - D_e|` against the solver's [`Allowance`]: the
//! relative criterion's share of the element's own source `E + rho D`,
//! known here before any solve, or the absolute threshold `eps B_max`),
//! down to `min_area`, so the solution follows the light's pool and its
//! shadows. Elements the links create later get their `D_e` when they
//! appear ([`extend`]). Under a point light `D` falls off as `cos^2 /
//! r^2` everywhere, so a piecewise-constant element within a 1% share of
//! its own radiosity is small: on a 2 m room lit by one luminaire at
//! `make`'s defaults every lit element is refined to `min_area` (3,712
//! leaves of 28 triangles) by either criterion.

use crate::elements::Hierarchy;
use crate::links::Allowance;
use radiometry::photometry::DirectLight;
use radiometry::subdivision::children;
use rayon::prelude::*;

/// `D` of element `e`'s four would-be children and the rays cast.
fn children_direct(h: &Hierarchy, light: &DirectLight, e: u32, depth: u32) -> ([f64; 4], u64) {
    let element = &h.elements[e as usize];
    let geometry = &h.triangles[element.triangle as usize];
    let (mut d, mut rays) = ([0.0; 4], 0);
    for (k, corners) in children(&element.corners).iter().enumerate() {
        let (value, cast) = light.over_element(geometry.element(corners), geometry.normal, element.triangle, depth);
        d[k] = value;
        rays += cast;
    }
    (d, rays)
}

/// Computes `D_e` for every element that lacks it (those created since the
/// last call), in parallel; returns the rays cast.
pub fn extend(h: &mut Hierarchy, light: &DirectLight, depth: u32) -> u64 {
    let start = h.direct.len();
    let computed: Vec<(f64, u64)> = (start..h.elements.len())
        .into_par_iter()
        .map(|e| {
            let element = &h.elements[e];
            let geometry = &h.triangles[element.triangle as usize];
            light.over_element(element.points, geometry.normal, element.triangle, depth)
        })
        .collect();
    h.direct.extend(computed.iter().map(|c| c.0));
    computed.iter().map(|c| c.1).sum()
}

/// Subdivides elements where their direct light varies (module docs): in
/// rounds over a frontier, the children's `D` computed in parallel, the
/// splits made in element order, so element indices do not depend on
/// threads. Every element must have its `D` ([`extend`]) before. Returns
/// the rays cast.
pub fn refine(h: &mut Hierarchy, light: &DirectLight, allowance: &Allowance, min_area: f64, depth: u32) -> u64 {
    let mut rays = 0;
    let reflects = |h: &Hierarchy, e: u32| h.reflectance_of(e).into_iter().fold(0.0, f64::max);
    let mut frontier: Vec<u32> = (0..h.elements.len() as u32).filter(|&e| h.elements[e as usize].is_leaf()).collect();
    while !frontier.is_empty() {
        frontier.retain(|&e| reflects(h, e) > 0.0 && h.elements[e as usize].area / 4.0 >= min_area);
        let found: Vec<([f64; 4], u64)> = frontier.par_iter().map(|&e| children_direct(h, light, e, depth)).collect();
        let mut next = Vec::new();
        for (&e, (d, cast)) in frontier.iter().zip(found) {
            rays += cast;
            let parent = h.direct[e as usize];
            let error = reflects(h, e) * d.iter().map(|x| (x - parent).abs()).fold(0.0, f64::max);
            if error > allowance.at(h.source(e)) {
                let first = h.subdivide(e);
                h.direct.extend(d);
                next.extend(first..first + 4);
            }
        }
        frontier = next;
    }
    rays
}

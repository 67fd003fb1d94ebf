//! Solving for radiosity on the linked hierarchy: Jacobi gather over the
//! links, then push-pull (Hanrahan et al. 1991, Section 4):
//!
//! ```text
//! G_e      = sum over links l into e of  V_l F_l B_{s(l)}       (irradiance, W/m²)
//! H_e      = G_e + H_{parent(e)}                                 (push down)
//! B_leaf   = E_leaf + rho_leaf H_leaf
//! B_inner  = sum over children c of (A_c / A_e) B_c              (pull up)
//! ```
//!
//! repeated until the largest change of a leaf's radiosity falls below
//! `tolerance` times the largest radiosity. Parents always have smaller
//! indices than their children, so push is one forward sweep and pull one
//! backward sweep: no recursion, and every sum has a fixed order, so the
//! result does not depend on threads.

use crate::elements::Hierarchy;
use crate::links::Link;
use rayon::prelude::*;
use schemas::solution::NONE;

/// Outcome of one solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Jacobi iterations run.
    pub iterations: usize,
    /// Largest leaf change of the last iteration, relative to the largest
    /// radiosity.
    pub relative_change: f64,
}

/// Iterates radiosity `b` (one RGB value per element, updated in place)
/// to convergence over `links`, which must be sorted by receiver, with
/// `offsets[e]..offsets[e + 1]` the links into element `e`.
pub fn solve(h: &Hierarchy, links: &[Link], offsets: &[usize], b: &mut [[f64; 3]], tolerance: f64, max_iterations: usize) -> Convergence {
    let n = h.elements.len();
    let mut h_down = vec![[0.0f64; 3]; n];
    let mut convergence = Convergence { iterations: 0, relative_change: f64::INFINITY };
    while convergence.iterations < max_iterations {
        let gathered: Vec<[f64; 3]> = (0..n)
            .into_par_iter()
            .map(|e| {
                let mut g = [0.0; 3];
                for l in &links[offsets[e]..offsets[e + 1]] {
                    let weight = l.form_factor * f64::from(l.visibility.unwrap_or(1.0));
                    let bs = b[l.sender as usize];
                    for c in 0..3 {
                        g[c] += weight * bs[c];
                    }
                }
                g
            })
            .collect();
        for e in 0..n {
            let parent = h.elements[e].parent;
            let above = if parent == NONE { [0.0; 3] } else { h_down[parent as usize] };
            h_down[e] = [gathered[e][0] + above[0], gathered[e][1] + above[1], gathered[e][2] + above[2]];
        }
        let mut change = 0.0f64;
        let mut largest = 0.0f64;
        for e in (0..n).rev() {
            let element = &h.elements[e];
            let new = if element.is_leaf() {
                let (rho, emitted) = (h.reflectance[element.triangle as usize], h.emission[element.triangle as usize]);
                let new = [0, 1, 2].map(|c| emitted[c] + rho[c] * h_down[e][c]);
                for c in 0..3 {
                    change = change.max((new[c] - b[e][c]).abs());
                    largest = largest.max(new[c]);
                }
                new
            } else {
                let mut mean = [0.0; 3];
                for child in element.first_child..element.first_child + 4 {
                    let weight = h.elements[child as usize].area / element.area;
                    for c in 0..3 {
                        mean[c] += weight * b[child as usize][c];
                    }
                }
                mean
            };
            b[e] = new;
        }
        convergence.iterations += 1;
        convergence.relative_change = if largest > 0.0 { change / largest } else { 0.0 };
        if convergence.relative_change <= tolerance {
            break;
        }
    }
    convergence
}

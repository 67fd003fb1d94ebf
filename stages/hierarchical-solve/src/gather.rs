//! Solving for radiosity on the linked hierarchy: Jacobi gather over the
//! links, then push-pull (Hanrahan et al. 1991, Section 4; with clusters,
//! Sillion 1995):
//!
//! ```text
//! G_n      = sum over links l into n of  V_l F_l B_{s(l)}        (irradiance, W/m²)
//! H_n      = G_n + H_{parent(n)}                                 (push down)
//! B_leaf   = E_leaf + rho_leaf H_leaf
//! B_inner  = sum over children c of (A_c / A_n) B_c              (pull up)
//! ```
//!
//! repeated until the largest change of a leaf's radiosity falls below
//! `tolerance` times the largest radiosity. Irradiance gathered by a
//! cluster is pushed to all its children alike (the isotropic push: the
//! cluster's transfer was already averaged over its surfaces' real
//! orientations, see [`crate::transfer`]); flux is conserved.
//!
//! Nodes are indexed densely, clusters first, then elements
//! ([`Hierarchy::flat`]). A parent always has a smaller index than its
//! children (and an input triangle's leaf cluster comes before it), so push
//! is one forward sweep and pull one backward sweep: every sum has a fixed
//! order, and the result does not depend on threads.

use crate::elements::Hierarchy;
use crate::links::Link;
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
}

/// The node with dense index `i`.
fn node(h: &Hierarchy, i: usize) -> Node {
    let clusters = h.cluster_count();
    if i < clusters {
        Node::Cluster(i as u32)
    } else {
        Node::Element((i - clusters) as u32)
    }
}

/// The hierarchy flattened once per solve: parent, children and area per
/// dense index, so the sweeps neither allocate nor branch on node kinds.
struct Topology {
    parent: Vec<usize>,
    child_start: Vec<usize>,
    children: Vec<usize>,
    area: Vec<f64>,
    /// Reflectance and emission of leaf elements; `None` for inner nodes.
    leaf: Vec<Option<([f64; 3], [f64; 3])>>,
}

impl Topology {
    fn new(h: &Hierarchy, n: usize) -> Self {
        let mut t = Topology { parent: vec![usize::MAX; n], child_start: vec![0; n + 1], children: Vec::new(), area: vec![0.0; n], leaf: vec![None; n] };
        for i in 0..n {
            let this = node(h, i);
            t.area[i] = h.area(this);
            if let Some(p) = h.parent(this) {
                t.parent[i] = h.flat(p);
            }
            match this {
                Node::Element(e) if h.elements[e as usize].is_leaf() => {
                    let tri = h.elements[e as usize].triangle as usize;
                    t.leaf[i] = Some((h.reflectance[tri], h.emission[tri]));
                }
                _ => t.children.extend(h.children(this).into_iter().map(|c| h.flat(c))),
            }
            t.child_start[i + 1] = t.children.len();
        }
        t
    }

    /// Pull: every inner node's radiosity from its children, leaves kept.
    fn pull(&self, b: &mut [[f64; 3]]) {
        for i in (0..b.len()).rev() {
            if self.leaf[i].is_some() {
                continue;
            }
            let mut mean = [0.0; 3];
            for &child in &self.children[self.child_start[i]..self.child_start[i + 1]] {
                let weight = if self.area[i] > 0.0 { self.area[child] / self.area[i] } else { 0.0 };
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

/// Iterates radiosity `b` (one RGB value per node, dense index) to
/// convergence over `links`, which must be sorted by receiver's dense index,
/// with `offsets[i]..offsets[i + 1]` the links into node `i`.
pub fn solve(h: &Hierarchy, links: &[Link], offsets: &[usize], b: &mut [[f64; 3]], tolerance: f64, max_iterations: usize) -> Convergence {
    let n = b.len();
    let topology = Topology::new(h, n);
    let senders: Vec<usize> = links.iter().map(|l| h.flat(l.sender)).collect();
    let mut h_down = vec![[0.0f64; 3]; n];
    let mut convergence = Convergence { iterations: 0, relative_change: f64::INFINITY };
    while convergence.iterations < max_iterations {
        let gathered: Vec<[f64; 3]> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut g = [0.0; 3];
                for (l, &s) in links[offsets[i]..offsets[i + 1]].iter().zip(&senders[offsets[i]..offsets[i + 1]]) {
                    let weight = l.form_factor * f64::from(l.visibility.unwrap_or(1.0));
                    for c in 0..3 {
                        g[c] += weight * b[s][c];
                    }
                }
                g
            })
            .collect();
        let (mut change, mut largest) = (0.0f64, 0.0f64);
        for i in 0..n {
            let above = if topology.parent[i] == usize::MAX { [0.0; 3] } else { h_down[topology.parent[i]] };
            h_down[i] = [0, 1, 2].map(|c| gathered[i][c] + above[c]);
            if let Some((rho, emitted)) = topology.leaf[i] {
                let new = [0, 1, 2].map(|c| emitted[c] + rho[c] * h_down[i][c]);
                for c in 0..3 {
                    change = change.max((new[c] - b[i][c]).abs());
                    largest = largest.max(new[c]);
                }
                b[i] = new;
            }
        }
        topology.pull(b);
        convergence.iterations += 1;
        convergence.relative_change = if largest > 0.0 { change / largest } else { 0.0 };
        if convergence.relative_change <= tolerance {
            break;
        }
    }
    convergence
}

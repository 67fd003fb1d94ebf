//! Light transport between the planar surfaces of a [`Configuration`], in
//! radiosity (W/m²); radiance is radiosity over pi for these diffuse
//! surfaces.
//!
//! - Direct (paper 002 Eq. 2-3): `D(x) = rho(x) sum_e E_e F_{dx->e}`, with
//!   `F` Lambert's closed form to each emitting triangle, one-sided in the
//!   emitter ([`point_to_one_sided_polygon`]). Exact up to rounding.
//! - One bounce (Eq. 4-5): the light of the reflectors lit directly,
//!   `B_1(x) = rho(x) / pi  integral over the reflectors of D(y) G(x, y) dA_y`,
//!   `G = cos+ cos+ / r^2` ([`point_kernel`]), by adaptive Gauss quadrature
//!   ([`crate::quadrature::adaptive`]) to a relative tolerance, with its
//!   bound. Eq. 5 is this integral written out for a rectangular source;
//!   here `D` is Lambert's formula for any polygon.
//! - Further bounces (`B_k`, k >= 2), between two planes: by iteration on
//!   a fixed node set (Nystrom's method). The reflectors' triangles are
//!   split `level` times 1:4 and carry the conical-product rule; `B_1` at
//!   every node is the adaptive integral above, and
//!   `B_k(y_i) = rho(y_i) / pi sum_j w_j B_(k-1)(y_j) G(y_i, y_j)`; a
//!   pixel's `B_k(x)` is the same sum at `x`. Its bound is the difference
//!   between node sets of `level` and `level - 1`, plus the bounds of the
//!   `B_1` values carried through the sums. The kernel between two
//!   separated planes is smooth, so this converges fast; between planes
//!   that meet, it is singular at the shared edge and the bound says so.

use crate::configuration::Configuration;
use crate::quadrature::{adaptive, children, Adaptive, Estimate, TriangleRule};
use glam::DVec3;
use radiometry::form_factor::{point_kernel, point_to_one_sided_polygon};
use rayon::prelude::*;
use std::f64::consts::PI;

/// How accurately the integrals are taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// Relative tolerance of the one-bounce integral.
    pub tolerance: f64,
    /// Gauss-Legendre points per direction of the triangle rule.
    pub gauss_order: u32,
    /// Deepest adaptive refinement.
    pub max_depth: u32,
    /// Bounces: 0 direct light only, 1 the paper's one bounce, more by
    /// iteration between two planes.
    pub bounces: u32,
    /// 1:4 splits of the reflectors for the iterated bounces' nodes.
    pub nystrom_level: u32,
}

/// Radiosity at a point, split by bounce, with its bound (W/m²).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Radiosity {
    /// Emitted.
    pub emitted: [f64; 3],
    /// Direct (Lambert).
    pub direct: [f64; 3],
    /// First bounce.
    pub one_bounce: [f64; 3],
    /// Every further bounce asked for.
    pub further: [f64; 3],
    /// Bound of the error of the sum.
    pub bound: [f64; 3],
    /// Integrand evaluations spent.
    pub evaluations: u64,
}

impl Radiosity {
    /// The total.
    pub fn total(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| self.emitted[k] + self.direct[k] + self.one_bounce[k] + self.further[k])
    }
}

/// Rounding allowance of the closed form, relative: Lambert's sum loses a
/// few ulps per edge (cross products, atan2), far under this.
const DIRECT_ROUNDING: f64 = 1e-12;

/// The iterated bounces on one node set.
struct Nodes {
    /// `(point, weight m², surface)`.
    points: Vec<(DVec3, f64, usize)>,
    /// `B_(k-1)` at the nodes for k = 2..=bounces: `carried[k - 2]`.
    carried: Vec<Vec<[f64; 3]>>,
    /// The bound of `B_1` at the nodes.
    first_bound: Vec<[f64; 3]>,
}

/// The exact transport of a configuration.
pub struct Transport<'a> {
    config: &'a Configuration,
    accuracy: Accuracy,
    rule: TriangleRule,
    /// Emitting triangles: `(corners, front normal, exitance)`.
    emitters: Vec<([DVec3; 3], DVec3, [f64; 3])>,
    /// Brightest exitance, for the tolerance's floor.
    brightest: f64,
    /// Fine and coarse node sets, for bounces >= 2.
    nodes: Option<(Nodes, Nodes)>,
}

fn add(a: &mut [f64; 3], b: [f64; 3]) {
    (0..3).for_each(|k| a[k] += b[k]);
}

impl<'a> Transport<'a> {
    /// The transport of `config` at `accuracy`. For `bounces >= 2` the
    /// node sets are built here (the costly part); `progress` is called
    /// with each node done.
    pub fn new(config: &'a Configuration, accuracy: Accuracy, progress: &(dyn Fn(u64) + Sync)) -> Self {
        let emitters: Vec<_> = config.surfaces.iter().filter(|s| s.emits()).flat_map(|s| s.triangles.iter().map(move |t| (*t, s.normal, s.emission))).collect();
        let brightest = emitters.iter().flat_map(|e| e.2).fold(0.0, f64::max);
        let mut transport = Transport { config, accuracy, rule: TriangleRule::new(accuracy.gauss_order as usize), emitters, brightest, nodes: None };
        if accuracy.bounces >= 2 {
            let fine = transport.nodes(accuracy.nystrom_level, progress);
            let coarse = transport.nodes(accuracy.nystrom_level.saturating_sub(1), progress);
            transport.nodes = Some((fine, coarse));
        }
        transport
    }

    /// The node count of the iterated bounces (fine and coarse sets).
    pub fn node_count(&self) -> usize {
        self.nodes.as_ref().map_or(0, |(f, c)| f.points.len() + c.points.len())
    }

    /// The points of the node sets that [`Transport::new`] will build at
    /// `level` and one below: for a progress bar's length.
    pub fn nodes_to_build(config: &Configuration, accuracy: Accuracy) -> u64 {
        if accuracy.bounces < 2 {
            return 0;
        }
        let triangles: usize = config.surfaces.iter().filter(|s| s.reflects()).map(|s| s.triangles.len()).sum();
        let per = (accuracy.gauss_order * accuracy.gauss_order) as u64;
        let level = accuracy.nystrom_level;
        triangles as u64 * per * (4u64.pow(level) + 4u64.pow(level.saturating_sub(1)))
    }

    /// `rho(x) sum_e E_e F_{dx->e}` at `x` on `surface` (002 Eq. 2-3).
    pub fn direct(&self, x: DVec3, surface: usize) -> [f64; 3] {
        let s = &self.config.surfaces[surface];
        let mut sum = [0.0; 3];
        for (corners, front, exitance) in &self.emitters {
            let f = point_to_one_sided_polygon(x, s.normal, corners, *front);
            (0..3).for_each(|k| sum[k] += exitance[k] * f);
        }
        [0, 1, 2].map(|k| s.reflectance[k] * sum[k])
    }

    /// The reflecting triangles a point on `surface` can see: every
    /// reflecting surface off its plane, tagged with its surface.
    fn reflectors(&self, surface: usize) -> Vec<([DVec3; 3], usize)> {
        let plane = self.config.surfaces[surface].plane;
        let seen = |(_, s): &(usize, &crate::configuration::Surface)| s.reflects() && s.plane != plane;
        self.config.surfaces.iter().enumerate().filter(seen).flat_map(|(k, s)| s.triangles.iter().map(move |t| (*t, k))).collect()
    }

    /// `B_1(x)` on `surface` (002 Eq. 4), adaptive, with its bound.
    pub fn one_bounce(&self, x: DVec3, surface: usize) -> Estimate {
        let s = &self.config.surfaces[surface];
        if !s.reflects() {
            return Estimate::default();
        }
        let limits = Adaptive { rule: &self.rule, tolerance: self.accuracy.tolerance, floor: 1e-9 * self.brightest, max_depth: self.accuracy.max_depth };
        let mut e = adaptive(&self.reflectors(surface), limits, &mut |y, k| {
            let g = point_kernel(x, s.normal, y, self.config.surfaces[k].normal);
            if g == 0.0 {
                return [0.0; 3];
            }
            self.direct(y, k).map(|d| d * g)
        });
        let scale = s.reflectance.map(|r| r / PI);
        e.value = [0, 1, 2].map(|k| e.value[k] * scale[k]);
        e.bound = [0, 1, 2].map(|k| e.bound[k] * scale[k]);
        e
    }

    /// The node set at `level` with `B_1 .. B_(bounces-1)` at every node.
    fn nodes(&self, level: u32, progress: &(dyn Fn(u64) + Sync)) -> Nodes {
        let mut points = Vec::new();
        for (k, s) in self.config.surfaces.iter().enumerate().filter(|(_, s)| s.reflects()) {
            let mut triangles = s.triangles.clone();
            for _ in 0..level {
                triangles = triangles.iter().flat_map(children).collect();
            }
            for t in &triangles {
                points.extend(self.rule.points(t).map(|(p, w)| (p, w, k)));
            }
        }
        let first: Vec<Estimate> = points
            .par_iter()
            .map(|&(p, _, k)| {
                let e = self.one_bounce(p, k);
                progress(1);
                e
            })
            .collect();
        let mut carried = vec![first.iter().map(|e| e.value).collect::<Vec<_>>()];
        for _ in 3..=self.accuracy.bounces {
            let previous = carried.last().expect("B_1 is there");
            let next: Vec<[f64; 3]> = points.par_iter().map(|&(p, _, k)| self.sum_over_nodes(&points, previous, p, k)).collect();
            carried.push(next);
        }
        Nodes { points, carried, first_bound: first.iter().map(|e| e.bound).collect() }
    }

    /// `rho(x) / pi sum_j w_j values_j G(x, y_j)` at `x` on `surface`.
    fn sum_over_nodes(&self, points: &[(DVec3, f64, usize)], values: &[[f64; 3]], x: DVec3, surface: usize) -> [f64; 3] {
        let s = &self.config.surfaces[surface];
        let mut sum = [0.0; 3];
        for ((y, w, k), v) in points.iter().zip(values) {
            if self.config.surfaces[*k].plane == s.plane {
                continue;
            }
            let g = w * point_kernel(x, s.normal, *y, self.config.surfaces[*k].normal);
            (0..3).for_each(|c| sum[c] += g * v[c]);
        }
        [0, 1, 2].map(|c| sum[c] * s.reflectance[c] / PI)
    }

    /// The radiosity at `x` on `surface`, every asked bounce, with its bound.
    pub fn radiosity(&self, x: DVec3, surface: usize) -> Radiosity {
        let s = &self.config.surfaces[surface];
        let direct = self.direct(x, surface);
        let mut out = Radiosity { emitted: s.emission, direct, bound: direct.map(|d| DIRECT_ROUNDING * d.abs()), ..Default::default() };
        if self.accuracy.bounces == 0 {
            return out;
        }
        let first = self.one_bounce(x, surface);
        out.one_bounce = first.value;
        add(&mut out.bound, first.bound);
        out.evaluations = first.evaluations;
        if let Some((fine, coarse)) = &self.nodes {
            let total = |nodes: &Nodes| {
                let mut sum = [0.0; 3];
                nodes.carried.iter().for_each(|values| add(&mut sum, self.sum_over_nodes(&nodes.points, values, x, surface)));
                sum
            };
            let (f, c) = (total(fine), total(coarse));
            out.further = f;
            // B_1's bound at the nodes, carried into B_2 (and, by the same
            // factor at most, into later bounces: bounded by B_2's share).
            let carried = self.sum_over_nodes(&fine.points, &fine.first_bound, x, surface);
            let bounces = f64::from(self.accuracy.bounces - 1);
            add(&mut out.bound, [0, 1, 2].map(|k| (f[k] - c[k]).abs() + bounces * carried[k]));
            out.evaluations += (fine.points.len() * fine.carried.len()) as u64;
        }
        out
    }
}

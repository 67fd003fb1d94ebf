//! Adaptive filtering of the vertex estimates over a kd-tree (paper 001:
//! "we build a static and balanced 3D kd-tree structure for all vertices
//! ... filter size is adaptively reduced as variance of the illumination
//! estimate decreases for a given vertex").
//!
//! The tree (kiddo's `ImmutableKdTree`, balanced, built once per mesh)
//! holds every vertex position, so neighbours are found across separate
//! objects as well as along the mesh. The filtered irradiance at `v` is a
//! kernel-weighted density estimate over its neighbours `u` within radius
//! `r_v` that face the same way (`n_u . n_v >= cos(crease)`: no light from a
//! wall onto the floor it touches):
//!
//! ```text
//! E'_v = sum_u w_u E_u A_u / sum_u w_u A_u,   w_u = 1 - |x_u - x_v|² / r_v²   (Epanechnikov)
//! ```
//!
//! with `A_u` the hat areas: the photons deposited around `v` over the area
//! that collected them, so a constant irradiance stays unbiased whatever
//! the mesh density. The radius follows the vertex's own relative standard
//! error `s_v` and the target `s_t`: averaging over an area `A` cuts the
//! variance by about `A_v / A`, so reaching `s_t` needs `A = A_v (s_v /
//! s_t)²` and
//!
//! ```text
//! r_v = min(r_max, sqrt(A_v / pi) sqrt(max(0, (s_v / s_t)² - 1)))
//! ```
//!
//! which is 0 (no filtering) once the vertex meets the target, and `r_max`
//! where nothing has landed yet.

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

/// The kd-tree over the vertices.
pub struct VertexTree {
    tree: ImmutableKdTree<f64, 3>,
}

impl VertexTree {
    /// Builds the balanced tree over `positions`.
    pub fn new(positions: &[DVec3]) -> Self {
        let points: Vec<[f64; 3]> = positions.iter().map(|p| p.to_array()).collect();
        VertexTree { tree: ImmutableKdTree::new_from_slice(&points) }
    }

    /// The vertices within `radius` of `p`, in index order.
    fn within(&self, p: DVec3, radius: f64) -> Vec<(usize, f64)> {
        let mut found: Vec<(usize, f64)> =
            self.tree.within_unsorted::<SquaredEuclidean>(&p.to_array(), radius * radius).into_iter().map(|n| (n.item as usize, n.distance)).collect();
        found.sort_unstable_by_key(|&(i, _)| i);
        found
    }
}

/// The filter radius of a vertex (module documentation), m.
pub fn radius(hat_area: f64, relative_error: f64, target: f64, max_radius: f64) -> f64 {
    if !relative_error.is_finite() {
        return max_radius;
    }
    let ratio = relative_error / target;
    ((hat_area / std::f64::consts::PI).sqrt() * (ratio * ratio - 1.0).max(0.0).sqrt()).min(max_radius)
}

/// Inputs of the filter, per vertex.
pub struct Estimates<'a> {
    /// Position, m.
    pub position: &'a [DVec3],
    /// Unit normal.
    pub normal: &'a [DVec3],
    /// Hat area, m².
    pub hat_area: &'a [f64],
    /// Unfiltered irradiance, W/m² per channel.
    pub irradiance: &'a [[f64; 3]],
    /// Filter radius, m.
    pub radius: &'a [f64],
}

/// The filtered irradiance of every vertex (module documentation).
pub fn filter(tree: &VertexTree, e: &Estimates, cos_crease: f64) -> Vec<[f64; 3]> {
    (0..e.position.len())
        .into_par_iter()
        .map(|v| {
            let r = e.radius[v];
            if r <= 0.0 {
                return e.irradiance[v];
            }
            let (mut sum, mut weight) = ([0.0; 3], 0.0);
            for (u, d2) in tree.within(e.position[v], r) {
                if u != v && e.normal[u].dot(e.normal[v]) < cos_crease {
                    continue;
                }
                let w = (1.0 - d2 / (r * r)).max(0.0) * e.hat_area[u];
                for (s, x) in sum.iter_mut().zip(e.irradiance[u]) {
                    *s += w * x;
                }
                weight += w;
            }
            if weight > 0.0 {
                sum.map(|s| s / weight)
            } else {
                e.irradiance[v]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiometry::sampling::Stream;

    /// A 90-degree crease: a bright floor (z = 0, irradiance 10) and a dark
    /// wall (x = 0, irradiance 1), each a 21 x 21 grid of vertices 5 cm
    /// apart sharing the crease line, with ±30% noise. Filtered with a
    /// 0.3 m radius (six spacings), each surface's mean away from the crease
    /// line must stay within 1% of its unfiltered mean: the filter only
    /// averages noise (each filtered value is a weighted mean of its
    /// surface's values, which all have the same expectation), while one
    /// that took the floor's neighbours onto the wall would raise the
    /// wall's mean near the crease several-fold.
    #[test]
    fn no_light_bleeds_across_a_crease() {
        let mut s = Stream::new(9, 0, 0);
        let (mut position, mut normal, mut irradiance) = (Vec::new(), Vec::new(), Vec::new());
        for (n, level) in [(DVec3::Z, 10.0), (DVec3::X, 1.0)] {
            for i in 0..21 {
                for j in 0..21 {
                    let (a, b) = (i as f64 * 0.05, j as f64 * 0.05);
                    position.push(if n == DVec3::Z { DVec3::new(a, b, 0.0) } else { DVec3::new(0.0, b, a) });
                    normal.push(n);
                    irradiance.push([level * (1.0 + 0.6 * (s.next_f64() - 0.5)); 3]);
                }
            }
        }
        let n = position.len();
        let hat_area = vec![0.0025; n];
        let radius = vec![0.3; n];
        let tree = VertexTree::new(&position);
        let e = Estimates { position: &position, normal: &normal, hat_area: &hat_area, irradiance: &irradiance, radius: &radius };
        let mean = |values: &[[f64; 3]], surface: usize| {
            let ids: Vec<usize> = (surface * 441..(surface + 1) * 441).filter(|&k| (k % 441) / 21 > 0).collect();
            ids.iter().map(|&k| values[k][0]).sum::<f64>() / ids.len() as f64
        };
        let filtered = filter(&tree, &e, 0.5);
        for surface in 0..2 {
            let (f, u) = (mean(&filtered, surface), mean(&irradiance, surface));
            assert!((f / u - 1.0).abs() < 0.01, "surface {surface}: filtered {f}, unfiltered {u}");
        }
        // The same filter blind to orientation bleeds: the check can fail.
        let blind = filter(&tree, &e, -1.0);
        assert!(mean(&blind, 1) > 1.5 * mean(&irradiance, 1));
        // And it does smooth: the wall's spread shrinks.
        let spread = |values: &[[f64; 3]]| values[441..].iter().map(|x| (x[0] - 1.0).abs()).fold(0.0, f64::max);
        assert!(spread(&filtered) < 0.5 * spread(&irradiance));
    }

    #[test]
    fn the_radius_shrinks_to_zero_at_the_target() {
        let a = std::f64::consts::PI; // sqrt(A / pi) = 1
        assert_eq!(radius(a, 0.01, 0.01, 5.0), 0.0);
        assert!((radius(a, 0.02, 0.01, 5.0) - 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(radius(a, 1.0, 0.01, 5.0), 5.0);
        assert_eq!(radius(a, f64::INFINITY, 0.01, 5.0), 5.0);
    }
}

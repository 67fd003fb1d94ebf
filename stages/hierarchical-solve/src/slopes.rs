//! The slope of emitters' direct light inside the leaves of a penumbra,
//! for the preview to draw (the solution's `slope` table) and for what
//! those leaves send to receivers near them ([`sender_offsets`]).
//!
//! A leaf is one radiosity, its mean; the preview draws it as a plane
//! whose slope it fits to the neighbouring leaves' means. Where a shadow's
//! edge runs through a leaf that plane is wrong: on the built-in Cornell
//! box at `EPS` 1e-3 (seed 1) drawing each leaf on the plane a finer
//! solve's leaves inside it fit (on the solution's own means) took the
//! preview from 1.641% to 1.415% relative RMSE against Mitsuba, all of it
//! on leaves lit through partly occluded links, 70% on those below the
//! lamp's. The links' kernels give the unoccluded slope only; the shadow's
//! slope needs visibility inside the leaf.
//!
//! The last solve has it already. A partly occluded link into an inner
//! element weighs each part by its own visibility, and a leaf right below
//! the receiver is traced with the link's own ray count
//! ([`crate::receivers`]). Those rays' kernel-weighted least-squares plane
//! of the clear verdicts over the leaf,
//!
//! ```text
//! v(x) ~ v_0 + g . (x - x_0),   minimising  sum_k G_k (v_k - v(x_k))²
//! ```
//!
//! (`G_k` the kernel of ray `k`, as [`crate::visibility`] weighs it), gives
//! `g = grad V`, and the link's light on the leaf, `rho F_js V B_s / x` (its
//! own factor `F_js` to the sender, exposure `x`), changes across it by
//!
//! ```text
//! grad B_j = rho F_js B_s grad V / x      (per channel; summed over the links)
//! ```
//!
//! leaving out the kernel's own slope (the neighbours' plane has it). The
//! preview blends it half and half with the neighbours' plane (grid-gather's
//! `MEASURED_SLOPE`): on the Cornell box (preview against Mitsuba, mean over
//! seeds 1-8) the relative RMSE went from 1.599% to 1.525% at `EPS` 1e-3
//! (every seed better), 2.472% to 2.411% at 1.5e-3 and 1.111% to 1.098% at
//! 6e-4, for no more rays (solve time within 1.5%, interleaved medians).
//!
//! Only links from emitting elements count: their shadows are the sharp
//! ones, and their slope carries most of the leaf's light. With every
//! partly occluded link's slope summed the Cornell box came out at 1.739%
//! at 1e-3: the many weak indirect links' slopes are mostly the noise of
//! their rays. Nor are the rays' verdicts worth more than half: 16 of them
//! over a leaf measure its slope to about half its size (the
//! `receiver_parts` test: 58% relative L2 over a penumbra's leaves; 11%
//! with 1024 rays), and weighing each leaf's slope by its own estimated
//! variance against its disagreement with the neighbours' plane
//! (shrinkage) gave 1.529% to 1.536% at 1e-3 and 1.106% to 1.117% at 6e-4.
//! A leaf's lamp light through links into other ancestors, or into the
//! leaf itself, brings a slope that is not measured.

use crate::elements::{Hierarchy, FAR_PART};
use crate::gather::SenderTerms;
use crate::links::Link;
use glam::DVec3;
use radiometry::form_factor::point_to_polygon;
use radiometry::geometry::frame_with_normal;
use radiometry::subdivision::children;
use rayon::prelude::*;
use schemas::solution::{LeafSlope, Node};
use std::collections::HashMap;

/// The kernel-weighted least-squares plane of a link's visibility over
/// one receiving element, from its rays (module docs), accumulated as the
/// rays are cast: the weighted sums in the element's plane, about its
/// centroid.
#[derive(Clone, Copy, Debug)]
pub struct VisibilitySlope {
    /// Centroid of the element: the origin of the plane's coordinates.
    origin: DVec3,
    /// Orthonormal axes of the element's plane.
    axes: [DVec3; 2],
    /// Rays of positive weight.
    rays: usize,
    /// `sum G`, `sum G p`, `sum G v`, `sum G p p^T` (`xx, xy, yy`) and
    /// `sum G p v`, over the rays' receiver points `p` in plane
    /// coordinates and verdicts `v` (1 clear, 0 blocked).
    weight: f64,
    moment: [f64; 2],
    clear: f64,
    second: [f64; 3],
    cross: [f64; 2],
}

impl VisibilitySlope {
    /// An empty fit over element `e` of `h`, in the element's plane
    /// (radiometry's frame of its normal).
    pub fn over(h: &Hierarchy, e: u32) -> Self {
        let [t, b, _] = frame_with_normal(h.normal(e));
        Self::new(h.centroid(e), [t, b])
    }

    /// An empty fit in the plane through `origin` spanned by the
    /// orthonormal `axes`.
    fn new(origin: DVec3, axes: [DVec3; 2]) -> Self {
        VisibilitySlope { origin, axes, rays: 0, weight: 0.0, moment: [0.0; 2], clear: 0.0, second: [0.0; 3], cross: [0.0; 2] }
    }

    /// One ray from receiver point `point`, of kernel weight `weight`,
    /// clear or blocked.
    #[inline]
    pub fn add(&mut self, point: DVec3, weight: f64, clear: bool) {
        let d = point - self.origin;
        let (x, y) = (d.dot(self.axes[0]), d.dot(self.axes[1]));
        let v = if clear { weight } else { 0.0 };
        self.rays += 1;
        self.weight += weight;
        self.moment[0] += weight * x;
        self.moment[1] += weight * y;
        self.clear += v;
        self.second[0] += weight * x * x;
        self.second[1] += weight * x * y;
        self.second[2] += weight * y * y;
        self.cross[0] += v * x;
        self.cross[1] += v * y;
    }

    /// `grad V` in world space, 1/m, along the element's plane: the
    /// fitted plane's slope, from the sums' central moments (the normal
    /// equations of the fit with its intercept eliminated). `None` with
    /// fewer than three rays of weight, or points too close to a line
    /// for a plane (the central second moments' determinant under 1e-9 of
    /// their trace squared). Every ray clear, or every ray blocked, gives
    /// exactly 0.
    pub fn gradient(&self) -> Option<DVec3> {
        if self.rays < 3 || self.weight <= 0.0 {
            return None;
        }
        if self.clear == 0.0 || self.clear == self.weight {
            return Some(DVec3::ZERO);
        }
        let mean = [self.moment[0] / self.weight, self.moment[1] / self.weight];
        let (sxx, sxy, syy) = (self.second[0] - self.moment[0] * mean[0], self.second[1] - self.moment[0] * mean[1], self.second[2] - self.moment[1] * mean[1]);
        let (sxv, syv) = (self.cross[0] - mean[0] * self.clear, self.cross[1] - mean[1] * self.clear);
        let det = sxx * syy - sxy * sxy;
        if det.is_nan() || det <= 1e-9 * (sxx + syy).powi(2) {
            return None;
        }
        let gx = (syy * sxv - sxy * syv) / det;
        let gy = (sxx * syv - sxy * sxv) / det;
        Some(self.axes[0] * gx + self.axes[1] * gy)
    }
}

/// One link's measured visibility slope on a leaf: `F_js grad V` (1/m),
/// with the leaf and the sender whose radiosity it scales.
#[derive(Clone, Copy, Debug)]
pub struct DirectSlope {
    /// The leaf (element index).
    pub leaf: u32,
    /// The emitting sender.
    pub sender: Node,
    /// The leaf's factor to the sender times the slope of its visibility.
    pub factor_slope: DVec3,
}

/// `sender`'s element if it lies on an emitting triangle: the links whose
/// slopes are measured (module docs).
pub fn emitting(h: &Hierarchy, sender: Node) -> Option<u32> {
    match sender {
        Node::Element(s) if h.emission[h.elements[s as usize].triangle as usize].iter().any(|&c| c > 0.0) => Some(s),
        _ => None,
    }
}

/// Per leaf with measured `slopes`, ascending, its slope per channel
/// from the radiosity `b` (by [`Hierarchy::flat`] index): `sum rho F_js
/// B_s grad V / x` over its links (module docs); leaves with no exposure
/// left out.
fn leaf_gradients(h: &Hierarchy, b: &[[f64; 3]], slopes: &[DirectSlope]) -> Vec<(u32, [DVec3; 3])> {
    let mut sorted = slopes.to_vec();
    sorted.sort_by_key(|s| s.leaf);
    sorted
        .chunk_by(|a, b| a.leaf == b.leaf)
        .filter_map(|of_leaf| {
            let leaf = of_leaf[0].leaf;
            let exposure = h.exposure(leaf);
            if exposure <= 0.0 {
                return None;
            }
            let rho = h.reflectance_of(leaf);
            Some((leaf, std::array::from_fn(|c| of_leaf.iter().map(|s| s.factor_slope * (rho[c] * b[h.flat(s.sender)][c] / exposure)).sum())))
        })
        .collect()
}

/// The solution's slope table ([`leaf_gradients`]), without a slope the
/// table's 32-bit floats cannot hold (a sliver of a leaf under an emitter
/// near the floats' range), which the preview then draws on its
/// neighbours' plane alone rather than the solution being written with an
/// infinity every reader refuses.
pub fn leaf_slopes(h: &Hierarchy, b: &[[f64; 3]], slopes: &[DirectSlope]) -> Vec<LeafSlope> {
    leaf_gradients(h, b, slopes)
        .into_iter()
        .filter_map(|(leaf, g)| {
            let gradient = g.map(|g| g.as_vec3().to_array());
            gradient.as_flattened().iter().all(|g| g.is_finite()).then_some(LeafSlope { element: leaf, gradient })
        })
        .collect()
}

/// Per link of `links` (in order), what its sender sends beyond the
/// radiosity of its terms in `senders`: each term `j` with a measured slope
/// `g_j` ([`leaf_gradients`] of `slopes` on `b`) adds its slope at the
/// point the receiver sees it at,
///
/// ```text
/// offset = sum_j w_j g_j . (y_j - c_j),   y_j = sum_k F(c_r -> T_k) c_k / sum_k F(c_r -> T_k)
/// ```
///
/// (`c_j` the leaf's centroid, `T_k` the four children the hierarchy would
/// split it into, with centroids `c_k`, `F` Lambert's factor from the
/// receiver's centroid `c_r`): the sender's light as a plane, not a
/// constant, weighed by the kernel. A
/// block's face standing on a floor sees most the floor next to it, where
/// the block's own shadow on the floor is darkest, and the floor's leaves
/// there sent their means: the short block's camera face was the Cornell
/// box's worst surface. Over seeds 1-8 (preview against Mitsuba) the
/// short block's mean went from +0.67% to +0.37% at `EPS` 1e-3 (the worst
/// surface per seed from 0.39-1.07% to 0.38-0.72%, the tall block -0.27%
/// -> -0.10%, relative RMSE 1.525% -> 1.521%), +2.21% -> +1.48% at
/// 1.5e-3 (worst 1.53-3.05% -> 0.95-2.54%, 2.411% -> 2.398%) and +0.20%
/// -> +0.12% at 6e-4 (worst 0.21-0.39% -> 0.12-0.45%, the tall block of
/// seed 3 at +0.45%; 1.098% either way), for 1.5% more solve time at
/// 1e-3 (11 interleaved). `contact_shadow.rs` at 4e-4: the wall within 2
/// cm of the crease +0.20% -> +0.08%. Only receivers within [`FAR_PART`]
/// radii of the leaf (farther, `y_j` is `c_j` within a few percent of the
/// leaf's radius) and elements (a cluster receiver keeps the means).
pub fn sender_offsets(h: &Hierarchy, links: &[Link], senders: &SenderTerms, b: &[[f64; 3]], slopes: &[DirectSlope]) -> Vec<[f64; 3]> {
    let gradients: HashMap<usize, (u32, [DVec3; 3])> = leaf_gradients(h, b, slopes).into_iter().map(|(leaf, g)| (h.flat(Node::Element(leaf)), (leaf, g))).collect();
    links
        .par_iter()
        .enumerate()
        .map(|(l, link)| {
            let Node::Element(r) = link.receiver else { return [0.0; 3] };
            let (centre, normal) = (h.centroid(r), h.normal(r));
            let mut offset = [0.0; 3];
            for (node, w) in senders.terms(l) {
                let Some(&(j, g)) = gradients.get(&node) else { continue };
                let c_j = h.centroid(j);
                if centre.distance_squared(c_j) > (FAR_PART * h.radius(j)).powi(2) {
                    continue;
                }
                let leaf = &h.elements[j as usize];
                let quarters = children(&leaf.corners).map(|c| h.triangles[leaf.triangle as usize].element(&c));
                let factors = quarters.map(|q| point_to_polygon(centre, normal, &q));
                let total: f64 = factors.iter().sum();
                if total <= 0.0 {
                    continue;
                }
                let seen = quarters.iter().zip(factors).map(|(q, f)| (q[0] + q[1] + q[2]) / 3.0 * f).sum::<DVec3>() / total;
                for (o, g) in offset.iter_mut().zip(g) {
                    *o += w * g.dot(seen - c_j);
                }
            }
            offset
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gather::Senders;
    use crate::test_scenes::{split_levels, FloorAndWall};
    use radiometry::form_factor::point_kernel;
    use test_support::closed_form::mean_over_triangle;

    /// The kernel-weighted centroid of triangle `t` (normal `n`) as seen
    /// from point `x` (normal `nx`): means of the point kernel over the
    /// centroids of its `4^8` sub-triangles (test-support's quadrature).
    fn seen_centroid(t: &[DVec3; 3], n: DVec3, x: DVec3, nx: DVec3) -> DVec3 {
        let corners = t.map(|p| p.to_array());
        let mean = |f: &dyn Fn(DVec3) -> f64| mean_over_triangle(&corners, 8, &|p| f(DVec3::from(p)));
        let kernel = |p: DVec3| point_kernel(x, nx, p, n);
        DVec3::new(mean(&|p| p.x * kernel(p)), mean(&|p| p.y * kernel(p)), mean(&|p| p.z * kernel(p))) / mean(&kernel)
    }

    /// A floor leaf (level 3) at the foot of the wall standing on the
    /// floor's edge, its lamp light rising towards the wall by a measured
    /// slope (`F grad V` 0.2 /m along x, the floor's reflectance 0.5, the
    /// lamp's radiosity 1: 0.1 W/m² per m), and the wall's leaf beside it
    /// (4 cm up). A link from the floor leaf to the wall leaf sends its
    /// mean plus the slope at the point the wall leaf sees it at: against
    /// that point by the point kernel's means over 65,536 sub-triangles
    /// (7.41e-4 W/m²; 7.40e-4 by 4M random points), the four quarters'
    /// centroids weighed by their exact factors give 8.16e-4 (+10%; 16
    /// pieces +7.8%): the kernel is steep at a crease. A link to the lamp, farther than
    /// [`FAR_PART`] radii, and one to a cluster send none.
    #[test]
    fn a_sender_with_a_slope_sends_it_where_its_receiver_sees_it() {
        let FloorAndWall { mut h, lamp_triangle, .. } = FloorAndWall::new(2.0);
        let level = split_levels(&mut h, 0, 3);
        let leaf = *level.iter().max_by(|&&a, &&b| h.centroid(a).x.total_cmp(&h.centroid(b).x)).unwrap();
        let walls: Vec<u32> = [2, 3].iter().flat_map(|&t| split_levels(&mut h, t, 3)).collect();
        let wall = *walls.iter().min_by(|&&a, &&b| h.centroid(a).distance(h.centroid(leaf)).total_cmp(&h.centroid(b).distance(h.centroid(leaf)))).unwrap();
        let lamp = lamp_triangle;
        let slopes = [DirectSlope { leaf, sender: Node::Element(lamp), factor_slope: DVec3::X * 0.2 }];
        let mut b = vec![[0.0; 3]; h.cluster_count() + h.elements.len()];
        b[h.flat(Node::Element(lamp))] = [1.0; 3];
        let link = |receiver: Node| Link { receiver, sender: Node::Element(leaf), form_factor: 0.1, spread: 0.0, visibility: Some(1.0), occluder_distance: f32::INFINITY, clear: true };
        let links = [link(Node::Element(wall)), link(Node::Element(lamp)), link(Node::Cluster(2))];
        let senders = SenderTerms::new(&h, &links, Senders::Means);
        let offsets = sender_offsets(&h, &links, &senders, &b, &slopes);
        let seen = seen_centroid(&h.elements[leaf as usize].points, DVec3::Z, h.centroid(wall), h.normal(wall));
        let want = 0.1 * (seen - h.centroid(leaf)).x;
        assert!(want > 0.0 && (offsets[0][0] / want - 1.0).abs() < 0.15, "offset {:?} against {want}", offsets[0]);
        assert_eq!(offsets[0][0], offsets[0][2]);
        assert_eq!(&offsets[1..], &[[0.0; 3]; 2]);
    }

    /// A 4 x 4 grid of points at `x, y in {-1.5, -0.5, 0.5, 1.5}`, clear
    /// where `clear(x)`, weighted `weight(x)`, fitted in the plane z = 0.
    fn grid(clear: impl Fn(f64) -> bool, weight: impl Fn(f64) -> f64) -> VisibilitySlope {
        let mut fit = VisibilitySlope::new(DVec3::ZERO, [DVec3::X, DVec3::Y]);
        for x in [-1.5, -0.5, 0.5, 1.5] {
            for y in [-1.5, -0.5, 0.5, 1.5] {
                fit.add(DVec3::new(x, y, 0.0), weight(x), clear(x));
            }
        }
        fit
    }

    /// A shadow's edge along `x = 0` (clear for `x < 0`): the least-squares
    /// slope `cov(x, v) / var(x)` by hand, -0.5 / 1.25 = -0.4 with equal
    /// weights; with the clear half weighing 1 and the other 2, `x` has
    /// weighted mean 1/3 and `v` 1/3, `S_xx = 30 - 24/9 = 82/3`, `S_xv = -8 -
    /// 8/3 = -32/3`: -16/41. Nothing along `y`.
    #[test]
    fn a_shadows_edge_gives_the_least_squares_slope_by_hand() {
        let even = grid(|x| x < 0.0, |_| 1.0).gradient().unwrap();
        assert!((even - DVec3::new(-0.4, 0.0, 0.0)).length() < 1e-12, "{even}");
        let weighted = grid(|x| x < 0.0, |x| if x < 0.0 { 1.0 } else { 2.0 }).gradient().unwrap();
        assert!((weighted - DVec3::new(-16.0 / 41.0, 0.0, 0.0)).length() < 1e-12, "{weighted}");
    }

    /// Rays that all agree give a slope of exactly 0; fewer than three rays,
    /// or points on a line, none.
    #[test]
    fn agreeing_rays_give_no_slope_and_too_few_points_none() {
        assert_eq!(grid(|_| true, |_| 1.0).gradient(), Some(DVec3::ZERO));
        assert_eq!(grid(|_| false, |x| 1.0 + x * x).gradient(), Some(DVec3::ZERO));
        let mut two = VisibilitySlope::new(DVec3::ZERO, [DVec3::X, DVec3::Y]);
        two.add(DVec3::X, 1.0, true);
        two.add(DVec3::Y, 1.0, false);
        assert_eq!(two.gradient(), None);
        let mut line = VisibilitySlope::new(DVec3::ZERO, [DVec3::X, DVec3::Y]);
        for k in 0..8 {
            line.add(DVec3::new(f64::from(k), 0.0, 0.0), 1.0, k < 4);
        }
        assert_eq!(line.gradient(), None);
    }
}


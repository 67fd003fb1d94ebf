//! The solution as the full gather reads it: the links arriving at a
//! surface point (its leaf element, the leaf's ancestors, and, in a
//! clustered solution, the clusters holding its triangle), the links
//! arriving near a grid vertex, and the senders' shapes, radiosities and
//! fixed sample points.
//!
//! A sender is a link end ([`Node`]): an element (a sub-triangle of an
//! input triangle) or a cluster of `clusters.exr`. Elements are sampled
//! uniformly over their triangle; clusters over their triangles in
//! proportion to area. Either way sample `k` of a sender is the same point
//! for every pixel and every vertex (paper 000 Sec. 4.4.1: fixed positions
//! trade noise for a small bias), from the Sobol (0,2)-sequence (van der
//! Corput in base 2, and Sobol's second dimension) under a digital shift
//! keyed by the sender. Every block of `2^m` consecutive points starting at
//! a multiple of `2^m` is a (0,m,2)-net, one point in each of the square's
//! `2^m` elementary intervals of every shape, and the XOR shift keeps that:
//! a block of 4 points has exactly one in each quarter of either axis.
//! Halton points in bases 3 and 5 had no such balance for small blocks; a
//! sender's 4 fixed points sat off its centre the same way for every pixel,
//! which darkened the Cornell box by 0.2% against brute force. Clusters
//! take a third coordinate, radical inverse in base 3, to pick the triangle.

use glam::DVec3;
use radiometry::far_field::{beyond, triangle_factor};
use radiometry::form_factor::point_to_one_sided_polygon;
use radiometry::geometry::TriangleGeometry;
use radiometry::bounds::Aabb;
use radiometry::sampling::{radical_inverse, sobol_02, square_to_triangle, Stream};
use schemas::cluster::Clusters;
use schemas::solution::{Node, Solution, NONE};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::ops::Range;
use std::sync::OnceLock;

/// Form-factor samples used for a cluster sender, whose shape is not one
/// polygon: the point-to-area kernel summed over this many of its fixed
/// samples.
pub const CLUSTER_FACTOR_SAMPLES: usize = 32;

/// Distance, in radii of an element sender (its farthest corner's from its
/// centroid), beyond which [`Senders::form_factor`] takes Dunavant's
/// three-point rule of the point kernel over it (radiometry's
/// `far_field::triangle_factor`, exact for a quadratic kernel; within
/// 0.10% of Lambert's factor at 4 radii in its test, 0.97% at 2) instead
/// of Lambert's formula, an `atan2` per edge and about a quarter of the
/// full gather's profile. On the built-in Cornell box's default solution
/// the full gather took 4.25-4.28 s instead of 4.87-4.89 s (2 threads,
/// two runs each), its image within 0.0041% rms of the one before;
/// against Mitsuba 0.4624% relative RMSE against 0.4613% (at 8 radii 4.53
/// s, within 0.0001%).
pub const FAR_ELEMENT: f64 = 4.0;

/// How far under 1 an element's exposure ([`Senders::exposure`]) may come
/// from the f32 rounding of its stored area alone (a few units in the last
/// place; the solver measures exposure to about 1/256).
pub const EXPOSURE_ROUNDING: f64 = 1e-6;

/// One fixed sample on a sender.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SenderSample {
    /// The point, mesh frame.
    pub point: DVec3,
    /// The mesh triangle it lies on.
    pub triangle: u32,
}

/// The solution, indexed for the gather.
pub struct Senders<'a> {
    /// Triangle geometry, mesh frame.
    pub triangles: &'a [TriangleGeometry],
    /// The solution.
    pub solution: &'a Solution,
    /// The cluster hierarchy the solution was solved with, if any.
    pub clusters: Option<&'a Clusters>,
    links_of: HashMap<Node, Range<usize>>,
    /// World corners of every element, computed once: the gather asks for
    /// them at every form factor and sender sample (4.6% of a full gather's
    /// time when each call rebuilt them from the element's barycentrics).
    corners: Vec<[DVec3; 3]>,
    /// Leaf cluster of every triangle (clustered solutions).
    leaf_cluster: Vec<u32>,
    /// Per cluster: cumulative area over its triangles (in `order`), built
    /// on first use.
    cluster_cdf: Vec<OnceLock<Vec<f64>>>,
    /// Per cluster: its first [`CLUSTER_FACTOR_SAMPLES`] fixed samples,
    /// built on first use. Every form factor to a cluster sums the kernel
    /// over them; drawing them anew each time was most of that cost.
    cluster_factor_samples: Vec<OnceLock<Vec<SenderSample>>>,
    /// Triangles binned in a uniform grid over the scene's box.
    bins: Vec<Vec<u32>>,
    bin_box: Aabb,
    bin_n: usize,
    seed: u64,
}

impl<'a> Senders<'a> {
    /// Indexes `solution` (whose links are sorted by receiver) over
    /// `triangles`, with the cluster hierarchy if given; `seed` keys the
    /// senders' sample rotations.
    pub fn new(triangles: &'a [TriangleGeometry], solution: &'a Solution, clusters: Option<&'a Clusters>, seed: u64) -> Self {
        let mut links_of: HashMap<Node, Range<usize>> = HashMap::new();
        let mut start = 0;
        for i in 1..=solution.links.len() {
            if i == solution.links.len() || solution.links[i].receiver != solution.links[start].receiver {
                links_of.entry(solution.links[start].receiver).or_insert(start..i);
                start = i;
            }
        }
        let mut leaf_cluster = vec![NONE; triangles.len()];
        if let Some(c) = clusters {
            for (i, node) in c.nodes.iter().enumerate() {
                if node.is_leaf() {
                    for &t in &c.order[node.triangle_range()] {
                        leaf_cluster[t as usize] = i as u32;
                    }
                }
            }
        }
        let cluster_cdf = (0..clusters.map_or(0, |c| c.nodes.len())).map(|_| OnceLock::new()).collect();
        let cluster_factor_samples = (0..clusters.map_or(0, |c| c.nodes.len())).map(|_| OnceLock::new()).collect();
        let bin_box = Aabb::around(triangles.iter().flat_map(|t| t.corners));
        let bin_n = ((triangles.len() as f64).cbrt() * 2.0).ceil().clamp(1.0, 64.0) as usize;
        let corners = solution.elements.iter().map(|el| triangles[el.triangle as usize].element(&el.corners.map(|c| c.map(f64::from)))).collect();
        let mut senders =
            Senders { triangles, solution, clusters, links_of, corners, leaf_cluster, cluster_cdf, cluster_factor_samples, bins: vec![Vec::new(); bin_n.pow(3)], bin_box, bin_n, seed };
        for (t, tri) in triangles.iter().enumerate() {
            let b = Aabb::around(tri.corners);
            let (lo, hi) = (senders.bin(b.min), senders.bin(b.max));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        senders.bins[(z * bin_n + y) * bin_n + x].push(t as u32);
                    }
                }
            }
        }
        senders
    }

    fn bin(&self, p: DVec3) -> [usize; 3] {
        let extent = (self.bin_box.max - self.bin_box.min).max(DVec3::splat(1e-30));
        let g = (p - self.bin_box.min) / extent * self.bin_n as f64;
        g.to_array().map(|x| (x.floor().max(0.0) as usize).min(self.bin_n - 1))
    }

    /// Link indices arriving at `receiver`.
    pub fn links_of(&self, receiver: Node) -> Range<usize> {
        self.links_of.get(&receiver).cloned().unwrap_or(0..0)
    }

    /// World corners of element `e`.
    pub fn element_corners(&self, e: u32) -> [DVec3; 3] {
        self.corners[e as usize]
    }

    /// The leaf element under `triangle` holding barycentric `uv`, and the
    /// links arriving at it, its ancestors, and the clusters holding the
    /// triangle (leaf cluster up to the root): every link whose light
    /// reaches the point, each sender once (000 Sec. 4.1: "each link
    /// arriving at the hit object").
    pub fn chain(&self, triangle: u32, uv: [f64; 2], links: &mut Vec<usize>) -> u32 {
        links.clear();
        let mut local = radiometry::subdivision::clamped_local(uv);
        let mut element = triangle;
        links.extend(self.links_of(Node::Element(element)));
        while self.solution.elements[element as usize].first_child != NONE {
            let (k, child_local) = radiometry::subdivision::locate_child(local);
            local = child_local;
            element = self.solution.elements[element as usize].first_child + k as u32;
            links.extend(self.links_of(Node::Element(element)));
        }
        if let Some(c) = self.clusters {
            let mut cluster = self.leaf_cluster[triangle as usize];
            while cluster != NONE {
                links.extend(self.links_of(Node::Cluster(cluster)));
                cluster = c.nodes[cluster as usize].parent;
            }
        }
        element
    }

    /// The input triangles whose bounding boxes overlap `region`, sorted.
    pub fn triangles_near(&self, region: &Aabb) -> Vec<u32> {
        let (lo, hi) = (self.bin(region.min), self.bin(region.max));
        let mut candidates = Vec::new();
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    candidates.extend_from_slice(&self.bins[(z * self.bin_n + y) * self.bin_n + x]);
                }
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        candidates.retain(|&t| Aabb::around(self.triangles[t as usize].corners).overlaps(region));
        candidates
    }

    /// Link indices arriving at every receiver that overlaps `region`: the
    /// clusters overlapping it and the clusters above them (000 Sec. 4.3),
    /// and the elements overlapping it on the triangles `near` (those
    /// overlapping it, [`Self::triangles_near`], which the caller needs too)
    /// and their ancestors. Sorted, each once.
    pub fn links_near(&self, region: &Aabb, near: &[u32]) -> Vec<usize> {
        let mut out = Vec::new();
        if let Some(c) = self.clusters {
            let mut stack = vec![0u32];
            while let Some(i) = stack.pop() {
                let node = &c.nodes[i as usize];
                let b = Aabb { min: DVec3::from(node.bounds_min.map(f64::from)), max: DVec3::from(node.bounds_max.map(f64::from)) };
                if !b.overlaps(region) {
                    continue;
                }
                out.extend(self.links_of(Node::Cluster(i)));
                if !node.is_leaf() {
                    stack.extend(node.first_child..node.first_child + node.child_count);
                }
            }
        }
        for &t in near {
            let mut stack = vec![t];
            while let Some(e) = stack.pop() {
                if !Aabb::around(self.element_corners(e)).overlaps(region) {
                    continue;
                }
                out.extend(self.links_of(Node::Element(e)));
                let first = self.solution.elements[e as usize].first_child;
                if first != NONE {
                    stack.extend(first..first + 4);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Input triangles under a sender.
    pub fn triangles_of(&self, node: Node) -> &[u32] {
        match (node, self.clusters) {
            (Node::Cluster(c), Some(cl)) => cl.triangles_of(c),
            (Node::Element(e), _) => std::slice::from_ref(&self.solution.elements[e as usize].triangle),
            _ => &[],
        }
    }

    /// Radiosity of a sender, W/m², RGB.
    pub fn radiosity(&self, node: Node) -> [f64; 3] {
        match node {
            Node::Element(e) => self.solution.elements[e as usize].radiosity.map(f64::from),
            Node::Cluster(c) => self.solution.clusters.get(c as usize).map_or([0.0; 3], |c| c.radiosity.map(f64::from)),
        }
    }

    /// Radiosity link `l` sends, W/m², RGB: its unoccluded irradiance over
    /// its form factor, which is what the solve sent through it (the
    /// sender's parts weighted by the kernel, hierarchical-solve's
    /// `gather::SenderTerms`), or the sender's own where the factor is 0.
    /// The sender's area mean instead left the Cornell box's full gather
    /// 0.2-0.6% darker per surface.
    pub fn link_radiosity(&self, l: usize) -> [f64; 3] {
        let link = &self.solution.links[l];
        if link.form_factor > 0.0 {
            link.unoccluded_irradiance.map(|e| f64::from(e) / f64::from(link.form_factor))
        } else {
            self.radiosity(link.sender)
        }
    }

    /// Centre of a sender (element centroid, cluster box centre), m.
    pub fn centre(&self, node: Node) -> DVec3 {
        match node {
            Node::Element(e) => self.element_corners(e).iter().sum::<DVec3>() / 3.0,
            Node::Cluster(c) => self.cluster_box(c).map_or(DVec3::ZERO, |b| b.centre()),
        }
    }

    /// Size of a sender: its longest element edge, or its cluster box's
    /// diagonal, m.
    pub fn size(&self, node: Node) -> f64 {
        match node {
            Node::Element(e) => {
                let c = self.element_corners(e);
                (0..3).map(|i| c[i].distance(c[(i + 1) % 3])).fold(0.0, f64::max)
            }
            Node::Cluster(c) => self.cluster_box(c).map_or(0.0, |b| (b.max - b.min).length()),
        }
    }

    /// A cluster's bounding box.
    pub fn cluster_box(&self, c: u32) -> Option<Aabb> {
        let n = self.clusters?.nodes.get(c as usize)?;
        Some(Aabb { min: DVec3::from(n.bounds_min.map(f64::from)), max: DVec3::from(n.bounds_max.map(f64::from)) })
    }

    /// Surface area of a sender, m².
    pub fn area(&self, node: Node) -> f64 {
        match node {
            Node::Element(e) => {
                let el = &self.solution.elements[e as usize];
                self.triangles[el.triangle as usize].area * 0.25f64.powi(el.level as i32)
            }
            Node::Cluster(_) => self.triangles_of(node).iter().map(|&t| self.triangles[t as usize].area).sum(),
        }
    }

    /// The exposed fraction `x` of element `e`'s area, in `[0, 1]`: the
    /// solution's `area` is the part not buried inside a solid
    /// (hierarchical-solve's `exposure`), [`Self::area`] the whole. Within
    /// [`EXPOSURE_ROUNDING`] of 1 it is 1: the area is written as an f32.
    pub fn exposure(&self, e: u32) -> f64 {
        let whole = self.area(Node::Element(e));
        let x = if whole > 0.0 { f64::from(self.solution.elements[e as usize].area) / whole } else { 1.0 };
        if x > 1.0 - EXPOSURE_ROUNDING { 1.0 } else { x.max(0.0) }
    }

    /// Link `l`'s visible fraction as a point of its receiver's exposed
    /// part sees it, `min(1, V / x)` (`x` the receiver element's
    /// [`Self::exposure`], 1 for a cluster), as hierarchical-solve judges
    /// and gathers it (its `Link::on_exposed`): `V` counts the rays from
    /// the receiver's buried points as blocked, and every point a camera
    /// ray meets is exposed. A floor leaf across a block's base at
    /// exposure 0.1 otherwise lit its exposed sliver a tenth as brightly
    /// through every link the gather did not resample.
    pub fn exposed_visibility(&self, l: usize) -> f64 {
        let link = &self.solution.links[l];
        let v = f64::from(link.visibility).clamp(0.0, 1.0);
        match link.receiver {
            Node::Element(e) => self.on_exposed_part(e, v),
            Node::Cluster(_) => v,
        }
    }

    /// A visible fraction `v` measured from points over all of element `e`
    /// (those buried count as blocked), as its exposed part sees it:
    /// `min(1, v / x)` ([`Self::exposure`]), `v` where `x` is 0 or 1.
    pub fn on_exposed_part(&self, e: u32, v: f64) -> f64 {
        match self.exposure(e) {
            x if x > 0.0 && x < 1.0 => (v / x).min(1.0),
            _ => v,
        }
    }

    /// Fixed sample `k` on `node` (the same point for every caller).
    pub fn sample(&self, node: Node, k: usize) -> SenderSample {
        self.samples(node).at(k)
    }

    /// The fixed samples of `node`, with the sender's shift drawn once for
    /// a loop over several of them.
    pub fn samples(&self, node: Node) -> SenderSamples<'_> {
        let key = match node {
            Node::Element(e) => u64::from(e),
            Node::Cluster(c) => u64::from(c) | 1 << 40,
        };
        let mut rotation = Stream::new(self.seed, key, 0x5e4d);
        let shift = [0, 1].map(|_| (rotation.next_f64() * 4_294_967_296.0) as u32);
        SenderSamples { senders: self, node, shift, third_shift: rotation.next_f64() }
    }

    /// Form factor from a differential area at `p` with unit normal
    /// `normal` to the sender: Lambert's closed form (002 Eq. 3) for an
    /// element, 0 behind its plane (one-sided), from [`FAR_ELEMENT`] of its
    /// radii by Dunavant's three-point rule of the point kernel; for a cluster the point-to-area kernel
    /// `sum_k (A / K) cos+(theta_p) cos+(theta_k) / (pi r_k^2)` over its
    /// first [`CLUSTER_FACTOR_SAMPLES`] fixed samples (front faces only;
    /// the near singularity is cut at `r^2 >= A / K`, the area one sample
    /// stands for). Returns the factor and the number of kernel
    /// evaluations.
    pub fn form_factor(&self, node: Node, p: DVec3, normal: DVec3) -> (f64, u64) {
        match node {
            Node::Element(e) => {
                let (corners, front) = (self.element_corners(e), self.triangles[self.solution.elements[e as usize].triangle as usize].normal);
                let factor = if beyond(p, &corners, FAR_ELEMENT) {
                    triangle_factor(p, normal, &corners, self.area(node), front)
                } else {
                    point_to_one_sided_polygon(p, normal, &corners, front)
                };
                (factor, 1)
            }
            Node::Cluster(c) => {
                let area = self.area(node);
                let k = CLUSTER_FACTOR_SAMPLES;
                // A cluster the hierarchy does not hold has no triangles.
                let Some(cache) = self.cluster_factor_samples.get(c as usize) else { return (0.0, k as u64) };
                let samples = cache.get_or_init(|| {
                    let set = self.samples(node);
                    (0..k).map(|s| set.at(s)).collect()
                });
                let mut sum = 0.0;
                for &sample in samples {
                    if sample.triangle == NONE {
                        continue;
                    }
                    let d = sample.point - p;
                    let r2 = d.length_squared().max(area / k as f64);
                    let dir = d.normalize_or_zero();
                    let cos_p = normal.dot(dir).max(0.0);
                    let cos_s = (-dir).dot(self.triangles[sample.triangle as usize].normal).max(0.0);
                    sum += area / k as f64 * cos_p * cos_s / (PI * r2);
                }
                (sum.min(1.0), k as u64)
            }
        }
    }

    /// Whether sender `a` is `b` or lies above it in the hierarchy
    /// (elements: the parent chain; clusters: the cluster chain, and a
    /// cluster holds the elements on its triangles).
    pub fn covers(&self, a: Node, b: Node) -> bool {
        match (a, b) {
            (Node::Element(x), Node::Element(mut y)) => loop {
                if x == y {
                    return true;
                }
                y = self.solution.elements[y as usize].parent;
                if y == NONE {
                    return false;
                }
            },
            (Node::Cluster(x), Node::Element(y)) => {
                let t = self.solution.elements[y as usize].triangle;
                self.covers(a, Node::Cluster(self.leaf_cluster[t as usize])) || (x != NONE && self.leaf_cluster[t as usize] == x)
            }
            (Node::Cluster(x), Node::Cluster(mut y)) => {
                let Some(c) = self.clusters else { return false };
                loop {
                    if x == y {
                        return true;
                    }
                    if y == NONE || y as usize >= c.nodes.len() {
                        return false;
                    }
                    y = c.nodes[y as usize].parent;
                }
            }
            (Node::Element(_), Node::Cluster(_)) => false,
        }
    }
}

/// One sender's fixed samples ([`Senders::samples`]): its digital shift of
/// the Sobol points and, for a cluster, the shift of the third coordinate.
pub struct SenderSamples<'a> {
    senders: &'a Senders<'a>,
    node: Node,
    shift: [u32; 2],
    third_shift: f64,
}

impl SenderSamples<'_> {
    /// Fixed sample `k` (module docs).
    pub fn at(&self, k: usize) -> SenderSample {
        let senders = self.senders;
        let [u, v] = sobol_02(k as u32, self.shift);
        match self.node {
            Node::Element(e) => {
                let corners = senders.element_corners(e);
                let b = square_to_triangle(u, v);
                SenderSample { point: corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2], triangle: senders.solution.elements[e as usize].triangle }
            }
            Node::Cluster(c) => {
                let tris = senders.triangles_of(self.node);
                if tris.is_empty() {
                    return SenderSample { point: senders.centre(self.node), triangle: NONE };
                }
                let third = (radical_inverse(k as u64 + 1, 3) + self.third_shift).fract();
                let cdf = senders.cluster_cdf[c as usize].get_or_init(|| {
                    let mut acc = 0.0;
                    tris.iter().map(|&t| {
                        acc += senders.triangles[t as usize].area;
                        acc
                    }).collect()
                });
                let total = *cdf.last().unwrap_or(&0.0);
                let x = third * total;
                let i = cdf.partition_point(|&a| a <= x).min(tris.len() - 1);
                let t = &senders.triangles[tris[i] as usize];
                let b = square_to_triangle(u, v);
                SenderSample { point: t.corners[0] * b[0] + t.corners[1] * b[1] + t.corners[2] * b[2], triangle: tris[i] }
            }
        }
    }
}

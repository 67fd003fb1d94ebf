//! The cluster hierarchy above the input triangles as the solver uses it
//! (the `clusters.exr` artifact with f64 areas and reflectances): the
//! elements' [`crate::elements::Hierarchy`] holds one, and the link
//! hierarchy's nodes ([`crate::nodes`]) read it.

use schemas::cluster::Clusters;

/// The cluster hierarchy as the solver uses it: the artifact's nodes with
/// f64 areas and mean reflectances recomputed from the triangles, the leaf
/// cluster of each triangle, and prefix sums of triangle areas in cluster
/// order for area-weighted sampling.
pub struct ClusterTree {
    /// The artifact.
    pub clusters: Clusters,
    /// Surface area below each cluster, m².
    pub area: Vec<f64>,
    /// Area-weighted mean reflectance below each cluster.
    pub reflectance: Vec<[f64; 3]>,
    /// Leaf cluster holding each triangle.
    pub leaf_of_triangle: Vec<u32>,
    /// `cumulative[i]`: area of the triangles `order[..i]`.
    cumulative: Vec<f64>,
}

impl ClusterTree {
    /// Prepares `clusters` over triangles with these areas and reflectances.
    /// `clusters` must hold the invariants [`Clusters::read`] checks (a
    /// tree below the root, every cluster non-empty with its range inside
    /// `order`, `order` each triangle once): this indexes without checks
    /// of its own, and the link refinement descends the tree trusting that
    /// it ends.
    pub fn new(clusters: Clusters, triangle_area: &[f64], triangle_reflectance: &[[f64; 3]]) -> Self {
        let mut cumulative = Vec::with_capacity(clusters.order.len() + 1);
        cumulative.push(0.0);
        let mut sum = 0.0;
        for &t in &clusters.order {
            sum += triangle_area[t as usize];
            cumulative.push(sum);
        }
        let mut leaf_of_triangle = vec![0u32; triangle_area.len()];
        let mut area = Vec::with_capacity(clusters.nodes.len());
        let mut reflectance = Vec::with_capacity(clusters.nodes.len());
        for (c, node) in clusters.nodes.iter().enumerate() {
            let range = node.triangle_range();
            let a = cumulative[range.end] - cumulative[range.start];
            let mut rho = [0.0; 3];
            for &t in &clusters.order[range.clone()] {
                for k in 0..3 {
                    rho[k] += triangle_reflectance[t as usize][k] * triangle_area[t as usize];
                }
                if node.is_leaf() {
                    leaf_of_triangle[t as usize] = c as u32;
                }
            }
            area.push(a);
            reflectance.push(rho.map(|x| if a > 0.0 { x / a } else { 0.0 }));
        }
        ClusterTree { clusters, area, reflectance, leaf_of_triangle, cumulative }
    }

    /// Number of clusters.
    pub fn len(&self) -> usize {
        self.clusters.nodes.len()
    }

    /// Whether there is no cluster.
    pub fn is_empty(&self) -> bool {
        self.clusters.nodes.is_empty()
    }

    /// The input triangle below cluster `c` at `u` in [0, 1) of the
    /// cluster's area, its triangles laid end to end in the tree's order
    /// (so a uniform `u` draws each with probability proportional to its
    /// area), and where `u` falls along it, in [0, 1).
    pub fn triangle_at(&self, c: u32, u: f64) -> (u32, f64) {
        let node = &self.clusters.nodes[c as usize];
        let range = node.triangle_range();
        let (first, last) = (range.start, range.end);
        let (lo, hi) = (self.cumulative[first], self.cumulative[last]);
        let target = lo + u * (hi - lo);
        let k = self.cumulative[first + 1..last].partition_point(|&x| x <= target);
        let (start, end) = (self.cumulative[first + k], self.cumulative[first + k + 1]);
        let along = if end > start { ((target - start) / (end - start)).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.0 };
        (self.clusters.order[first + k], along)
    }
}

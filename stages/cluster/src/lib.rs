//! # cluster: the cluster hierarchy over the mesh's triangles
//!
//! Hierarchical radiosity with clustering (Sillion 1995; Smits, Arvo,
//! Greenberg 1994) needs a hierarchy *above* the input triangles, so that
//! light between two distant groups of triangles travels over one link.
//!
//! **Why a spatial median hierarchy, not face clustering.** Face clustering
//! groups connected triangles of similar normals; paper 000 (Section 3)
//! notes that on "fuzzy" objects like plants such regions are tiny, so it
//! builds a poor hierarchy exactly where clustering matters most. What the
//! transfer between clusters needs is *spatial compactness*: its error and
//! the oracle's bound grow with the clusters' size relative to their
//! distance. Splitting each node at the median of its triangles' centroids
//! along the longest axis of their bounds gives compact, balanced clusters
//! (depth log2 n) whatever the triangles' orientations; on a fine
//! tessellation of a smooth surface the clusters are nearly flat, and their
//! normal cones (recorded per node) tight.
//!
//! **Why not obvhs's BVH.** Its PLOC builder optimises boxes for tracing
//! rays, and measured on a closed box of 10k triangles it paired triangles
//! of *opposite* walls that share their other two coordinates: 43% of the
//! clusters mixed opposite normals, which cancels their mean normal, makes
//! them span the room and defeats the oracle's distance bound. obvhs still
//! casts every ray.
//!
//! Leaves hold at most `leaf_size` triangles; the build is O(n log n) and
//! deterministic.

use glam::{DVec3, Vec3};
use radiometry::bounds::Aabb;
use radiometry::geometry::TriangleGeometry;
use schemas::cluster::ClusterNode;
use schemas::solution::NONE;

stage_kit::knobs! {
    /// Knobs of the hierarchy.
    pub struct Params {
        /// Most triangles in a leaf cluster.
        leaf_size: u32 = 8, "triangles", value(1..=255);
    }
}

/// The hierarchy: nodes (root first, parents before children) and the
/// triangle order their ranges index.
#[derive(Clone, Debug, PartialEq)]
pub struct Hierarchy {
    /// Cluster nodes.
    pub nodes: Vec<ClusterNode>,
    /// Input triangles in cluster order.
    pub order: Vec<u32>,
}

/// Builds the hierarchy over `triangles` with per-triangle reflectance
/// `reflectance`. `triangles` must not be empty.
pub fn build(triangles: &[TriangleGeometry], reflectance: &[[f64; 3]], params: &Params) -> Hierarchy {
    let centroids: Vec<DVec3> = triangles.iter().map(|t| (t.corners[0] + t.corners[1] + t.corners[2]) / 3.0).collect();
    let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut out = Hierarchy { nodes: vec![empty_node(NONE)], order: Vec::new() };
    split(&mut order, 0, 0, &centroids, params.leaf_size.max(1) as usize, &mut out);
    out.order = order;
    bound(&mut out, triangles);
    summarise(&mut out, triangles, reflectance);
    out
}

fn empty_node(parent: u32) -> ClusterNode {
    ClusterNode {
        parent,
        first_child: NONE,
        child_count: 0,
        first_triangle: 0,
        triangle_count: 0,
        bounds_min: [0.0; 3],
        bounds_max: [0.0; 3],
        area: 0.0,
        reflectance_area: [0.0; 3],
        normal_axis: [0.0; 3],
        normal_cos: -1.0,
    }
}

/// Fills cluster `c` with the triangles `order[first .. first + slice.len()]`
/// (held in `slice`): a leaf if they are few, else two children split at
/// the median centroid along the longest axis of the centroids' bounds.
/// Children get consecutive indices, after their parent's.
fn split(slice: &mut [u32], first: usize, c: usize, centroids: &[DVec3], leaf_size: usize, out: &mut Hierarchy) {
    out.nodes[c].first_triangle = first as u32;
    out.nodes[c].triangle_count = slice.len() as u32;
    if slice.len() <= leaf_size {
        return;
    }
    let bounds = Aabb::around(slice.iter().map(|&t| centroids[t as usize]));
    let extent = bounds.max - bounds.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
    let middle = slice.len() / 2;
    // Ties broken by index, so the split does not depend on the input order.
    slice.select_nth_unstable_by(middle, |&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]).then(a.cmp(&b)));
    let children = out.nodes.len();
    out.nodes[c].first_child = children as u32;
    out.nodes[c].child_count = 2;
    out.nodes.push(empty_node(c as u32));
    out.nodes.push(empty_node(c as u32));
    let (left, right) = slice.split_at_mut(middle);
    split(left, first, children, centroids, leaf_size, out);
    split(right, first + middle, children + 1, centroids, leaf_size, out);
}

/// Bounding box of every node, from the corners of its triangles.
fn bound(h: &mut Hierarchy, triangles: &[TriangleGeometry]) {
    for node in &mut h.nodes {
        let range = &h.order[node.triangle_range()];
        let bounds = Aabb::around(range.iter().flat_map(|&t| triangles[t as usize].corners));
        node.bounds_min = bounds.min.as_vec3().to_array();
        node.bounds_max = bounds.max.as_vec3().to_array();
    }
}

/// Area, reflectance-weighted area and normal cone of every node, from the
/// triangles in its range. The cone axis is the area-weighted mean normal;
/// its cosine the smallest `n . axis` below. Where the normals cancel (a
/// mean normal shorter than a tenth of the area) or the cone opens past a
/// hemisphere, the cluster is marked isotropic (`cos = -1`).
fn summarise(h: &mut Hierarchy, triangles: &[TriangleGeometry], reflectance: &[[f64; 3]]) {
    for node in &mut h.nodes {
        let range = &h.order[node.triangle_range()];
        let (mut area, mut rho_area, mut normal_sum) = (0.0f64, [0.0f64; 3], glam::DVec3::ZERO);
        for &t in range {
            let g = &triangles[t as usize];
            area += g.area;
            for c in 0..3 {
                rho_area[c] += reflectance[t as usize][c] * g.area;
            }
            normal_sum += g.normal * g.area;
        }
        let length = normal_sum.length();
        let axis = if length > 0.1 * area && length > 0.0 { normal_sum / length } else { glam::DVec3::ZERO };
        let cos = if axis == glam::DVec3::ZERO {
            -1.0
        } else {
            range.iter().map(|&t| triangles[t as usize].normal.dot(axis)).fold(1.0, f64::min)
        };
        node.area = area as f32;
        node.reflectance_area = rho_area.map(|x| x as f32);
        node.normal_axis = axis.as_vec3().to_array();
        node.normal_cos = if cos <= 0.0 { -1.0 } else { cos as f32 };
    }
}

/// The bounding box of a node as vectors.
pub fn bounds(node: &ClusterNode) -> (Vec3, Vec3) {
    (Vec3::from(node.bounds_min), Vec3::from(node.bounds_max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use radiometry::sampling::Stream;

    fn random_triangles(n: usize) -> Vec<TriangleGeometry> {
        let mut s = Stream::new(5, 0, 0);
        (0..n)
            .map(|_| {
                let c = dvec3(s.next_f64(), s.next_f64(), s.next_f64()) * 10.0;
                let r = |s: &mut Stream| dvec3(s.next_f64() - 0.5, s.next_f64() - 0.5, s.next_f64() - 0.5) * 0.2;
                TriangleGeometry::new([c + r(&mut s), c + r(&mut s), c + r(&mut s)])
            })
            .collect()
    }

    #[test]
    fn hierarchy_invariants_hold() {
        let tris = random_triangles(1000);
        let rho = vec![[0.5, 0.25, 1.0]; tris.len()];
        let h = build(&tris, &rho, &Params { leaf_size: 4 });
        let mut seen = h.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..1000).collect::<Vec<u32>>(), "every triangle exactly once");
        let total: f64 = tris.iter().map(|t| t.area).sum();
        assert!((f64::from(h.nodes[0].area) - total).abs() < 1e-4 * total);
        for (i, n) in h.nodes.iter().enumerate() {
            assert!(n.is_leaf() == (n.first_child == NONE));
            if n.is_leaf() {
                assert!(n.triangle_count >= 1 && n.triangle_count <= 4, "leaf {i} holds {}", n.triangle_count);
            } else {
                let kids = &h.nodes[n.first_child as usize..(n.first_child + n.child_count) as usize];
                assert_eq!(kids.iter().map(|k| k.triangle_count).sum::<u32>(), n.triangle_count, "children split the range");
                assert_eq!(kids[0].first_triangle, n.first_triangle);
                assert!(kids.iter().all(|k| k.parent == i as u32));
                let area: f32 = kids.iter().map(|k| k.area).sum();
                assert!((area - n.area).abs() <= 1e-4 * n.area);
                assert!((kids.iter().map(|k| k.reflectance_area[1]).sum::<f32>() - 0.25 * n.area).abs() <= 1e-3 * n.area);
            }
            let (lo, hi) = bounds(n);
            for &t in &h.order[n.triangle_range()] {
                for p in tris[t as usize].corners {
                    let p = p.as_vec3();
                    assert!(p.cmpge(lo - 1e-4).all() && p.cmple(hi + 1e-4).all(), "triangle {t} outside cluster {i}");
                }
                if n.normal_cos > -1.0 {
                    assert!(tris[t as usize].normal.dot(glam::DVec3::from(n.normal_axis.map(f64::from))) >= f64::from(n.normal_cos) - 1e-5);
                }
            }
        }
    }

    #[test]
    fn a_flat_tessellation_has_tight_cones_and_random_leaves_do_not() {
        let mut flat = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (f64::from(i), f64::from(j));
                flat.push(TriangleGeometry::new([dvec3(x, y, 0.0), dvec3(x + 1.0, y, 0.0), dvec3(x, y + 1.0, 0.0)]));
            }
        }
        let h = build(&flat, &vec![[0.5; 3]; flat.len()], &Params::default());
        assert!(h.nodes.iter().all(|n| n.normal_cos > 0.9999), "a plane has one normal");
        let random = random_triangles(2000);
        let h = build(&random, &vec![[0.5; 3]; random.len()], &Params::default());
        assert_eq!(h.nodes[0].normal_cos, -1.0, "random orientations: isotropic root");
        // Two parallel walls facing each other: no cluster below the root
        // may hold triangles of both.
        let mut walls = Vec::new();
        for (x, flip) in [(0.0, false), (1.0, true)] {
            for i in 0..30 {
                for j in 0..30 {
                    let (y, z) = (f64::from(i) / 30.0, f64::from(j) / 30.0);
                    let mut c = [dvec3(x, y, z), dvec3(x, y + 1.0 / 30.0, z), dvec3(x, y, z + 1.0 / 30.0)];
                    if flip {
                        c.swap(1, 2);
                    }
                    walls.push(TriangleGeometry::new(c));
                }
            }
        }
        let h = build(&walls, &vec![[0.5; 3]; walls.len()], &Params::default());
        assert!(h.nodes[1..].iter().all(|n| n.normal_cos > 0.9999), "a cluster mixes the two walls");
    }
}

//! # cluster: the cluster hierarchy over the mesh's triangles
//!
//! Hierarchical radiosity with clustering (Sillion 1995; Smits, Arvo,
//! Greenberg 1994) needs a hierarchy *above* the input triangles, so that
//! light between two distant groups of triangles travels over one link.
//!
//! **Why a BVH, not face clustering.** Face clustering groups connected
//! triangles of similar normals; paper 000 (Section 3) notes that on
//! "fuzzy" objects like plants such regions are tiny, so it builds a poor
//! hierarchy exactly where clustering matters most. What the transfer
//! between clusters needs is *spatial compactness*: its error grows with the
//! clusters' size relative to their distance, and their visibility is
//! estimated by rays. A surface-area-heuristic BVH minimises the summed
//! surface area of the boxes, which is compactness measured the way rays
//! see it, whatever the triangles' orientations; on a fine tessellation of a
//! smooth surface it also yields nearly flat clusters, whose normal cones
//! (recorded per node) are tight. obvhs builds it (PLOC, Meister and
//! Bittner 2018) in O(n log n), deterministically on one thread.
//!
//! Pre-splitting is off (a cluster must own its triangles), and leaves hold
//! at most `leaf_size` triangles.

use glam::Vec3;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use radiometry::geometry::TriangleGeometry;
use schemas::cluster::ClusterNode;
use schemas::solution::NONE;
use serde::{Deserialize, Serialize};
use std::time::Duration;

/// Knobs of the hierarchy.
///
/// | parameter | meaning | default |
/// |---|---|---|
/// | `leaf_size` | most triangles in a leaf cluster (1..=255) | 8 |
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Most triangles in a leaf cluster.
    pub leaf_size: u32,
}

impl Default for Params {
    fn default() -> Self {
        Params { leaf_size: 8 }
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
    let tris: Vec<Triangle> = triangles
        .iter()
        .map(|t| {
            let v = t.corners.map(|p| p.as_vec3().into());
            Triangle { v0: v[0], v1: v[1], v2: v[2] }
        })
        .collect();
    let config = BvhBuildParams { pre_split: false, max_prims_per_leaf: params.leaf_size.clamp(1, 255), ..BvhBuildParams::medium_build() };
    let bvh = build_bvh2_from_tris(&tris, config, &mut Duration::default());
    let mut out = Hierarchy { nodes: Vec::with_capacity(bvh.nodes.len()), order: Vec::with_capacity(triangles.len()) };
    out.nodes.push(empty_node(NONE));
    visit(&bvh, 0, 0, &mut out);
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

/// Depth-first over BVH node `b`, filling cluster `c`: children get
/// consecutive indices, leaves append their triangles to the order, so
/// every subtree's triangles are contiguous.
fn visit(bvh: &Bvh2, b: usize, c: usize, out: &mut Hierarchy) {
    let node = &bvh.nodes[b];
    out.nodes[c].first_triangle = out.order.len() as u32;
    out.nodes[c].bounds_min = node.aabb.min.to_array();
    out.nodes[c].bounds_max = node.aabb.max.to_array();
    if node.prim_count > 0 {
        let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
        out.order.extend(range.map(|i| bvh.primitive_indices[i]));
    } else {
        let first = out.nodes.len();
        out.nodes[c].first_child = first as u32;
        out.nodes[c].child_count = 2;
        out.nodes.push(empty_node(c as u32));
        out.nodes.push(empty_node(c as u32));
        visit(bvh, node.first_index as usize, first, out);
        visit(bvh, node.first_index as usize + 1, first + 1, out);
    }
    out.nodes[c].triangle_count = out.order.len() as u32 - out.nodes[c].first_triangle;
}

/// Area, reflectance-weighted area and normal cone of every node, from the
/// triangles in its range. The cone axis is the area-weighted mean normal;
/// its cosine the smallest `n . axis` below. Where the normals cancel (a
/// mean normal shorter than a tenth of the area) or the cone opens past a
/// hemisphere, the cluster is marked isotropic (`cos = -1`).
fn summarise(h: &mut Hierarchy, triangles: &[TriangleGeometry], reflectance: &[[f64; 3]]) {
    for node in &mut h.nodes {
        let range = &h.order[node.first_triangle as usize..(node.first_triangle + node.triangle_count) as usize];
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
            for &t in &h.order[n.first_triangle as usize..(n.first_triangle + n.triangle_count) as usize] {
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
    }
}

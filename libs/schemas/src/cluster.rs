//! The cluster hierarchy artifact (`clusters.exr`), written by `cluster`
//! and read by `hierarchical-solve` (links between clusters) and
//! `grid-gather` (the clusters around a grid vertex, paper 000 Section 4.3).
//!
//! Node 0 is the root. The children of a node are `first_child ..
//! first_child + child_count`; the input triangles under a node are
//! `order[first_triangle .. first_triangle + triangle_count]`, contiguous
//! for every node (children split their parent's range). Leaf clusters
//! (`child_count == 0`) hold a few triangles, whose element hierarchies
//! continue below them in the solution.

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, check_forest, read_exr, write_exr, Channel, ExrArtifact, Layer};
use crate::header::{Header, Input, Schema};
use crate::solution::NONE;
use std::path::Path;

/// One cluster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterNode {
    /// Parent cluster, [`NONE`] for the root.
    pub parent: u32,
    /// First child cluster, [`NONE`] for a leaf.
    pub first_child: u32,
    /// Number of child clusters (0 for a leaf).
    pub child_count: u32,
    /// First index into [`Clusters::order`] of the triangles below.
    pub first_triangle: u32,
    /// Number of triangles below.
    pub triangle_count: u32,
    /// Bounding box, mesh frame, m.
    pub bounds_min: [f32; 3],
    /// Bounding box, mesh frame, m.
    pub bounds_max: [f32; 3],
    /// Total surface area below, m².
    pub area: f32,
    /// Sum of reflectance times area below, m², RGB.
    pub reflectance_area: [f32; 3],
    /// Axis of a cone holding every front normal below (unit).
    pub normal_axis: [f32; 3],
    /// Cosine of the cone's half angle; -1 for an isotropic cluster (its
    /// normals point everywhere), whose transfer is modelled as isotropic.
    pub normal_cos: f32,
}

impl ClusterNode {
    /// Whether the cluster has no child cluster.
    pub fn is_leaf(&self) -> bool {
        self.child_count == 0
    }

    /// Where its triangles lie in [`Clusters::order`].
    pub fn triangle_range(&self) -> std::ops::Range<usize> {
        self.first_triangle as usize..(self.first_triangle + self.triangle_count) as usize
    }
}

/// The hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct Clusters {
    /// Header with provenance.
    pub header: Header,
    /// Nodes, root first.
    pub nodes: Vec<ClusterNode>,
    /// Input triangle indices in cluster order.
    pub order: Vec<u32>,
}

impl Schema for Clusters {
    const NAME: &'static str = "clusters";
    const VERSION: u32 = 1;
}

impl Clusters {
    /// The input triangles below cluster `c`.
    pub fn triangles_of(&self, c: u32) -> &[u32] {
        &self.order[self.nodes[c as usize].triangle_range()]
    }

    /// Writes `clusters.exr`: layers `cluster` and `order`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let n = &self.nodes;
        let col = |f: &dyn Fn(&ClusterNode) -> f32| n.iter().map(f).collect::<Vec<f32>>();
        let ucol = |f: &dyn Fn(&ClusterNode) -> u32| n.iter().map(f).collect::<Vec<u32>>();
        let cluster = Layer::table(
            "cluster",
            n.len(),
            vec![
                Channel::u32("parent", "parent cluster, 4294967295 = root", ucol(&|c| c.parent)),
                Channel::u32("first_child", "first child cluster, 4294967295 = leaf", ucol(&|c| c.first_child)),
                Channel::u32("child_count", "number of child clusters", ucol(&|c| c.child_count)),
                Channel::u32("first_triangle", "first index into the order layer", ucol(&|c| c.first_triangle)),
                Channel::u32("triangle_count", "triangles below", ucol(&|c| c.triangle_count)),
                Channel::f32("min.X", "bounds min x, m", col(&|c| c.bounds_min[0])),
                Channel::f32("min.Y", "bounds min y, m", col(&|c| c.bounds_min[1])),
                Channel::f32("min.Z", "bounds min z, m", col(&|c| c.bounds_min[2])),
                Channel::f32("max.X", "bounds max x, m", col(&|c| c.bounds_max[0])),
                Channel::f32("max.Y", "bounds max y, m", col(&|c| c.bounds_max[1])),
                Channel::f32("max.Z", "bounds max z, m", col(&|c| c.bounds_max[2])),
                Channel::f32("area", "surface area below, m^2", col(&|c| c.area)),
                Channel::f32("rhoA.R", "sum of reflectance x area, m^2", col(&|c| c.reflectance_area[0])),
                Channel::f32("rhoA.G", "sum of reflectance x area, m^2", col(&|c| c.reflectance_area[1])),
                Channel::f32("rhoA.B", "sum of reflectance x area, m^2", col(&|c| c.reflectance_area[2])),
                Channel::f32("axis.X", "normal cone axis x", col(&|c| c.normal_axis[0])),
                Channel::f32("axis.Y", "normal cone axis y", col(&|c| c.normal_axis[1])),
                Channel::f32("axis.Z", "normal cone axis z", col(&|c| c.normal_axis[2])),
                Channel::f32("cos", "normal cone half-angle cosine, -1 = isotropic", col(&|c| c.normal_cos)),
            ],
        );
        let order = Layer::table("order", self.order.len(), vec![Channel::u32("triangle", "input triangle", self.order.clone())]);
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![cluster, order] })
    }

    /// Reads `clusters.exr` over a mesh of `triangles` input triangles and
    /// checks its structure (see [`Clusters::check`]), so that a stage may
    /// walk and index it without further checks.
    pub fn read(path: &Path, triangles: usize) -> Result<(Clusters, Input)> {
        let (artifact, input) = read_exr::<Clusters>(path)?;
        let l = artifact.layer(path, "cluster")?;
        let floats = ["min.X", "min.Y", "min.Z", "max.X", "max.Y", "max.Z", "area", "rhoA.R", "rhoA.G", "rhoA.B", "axis.X", "axis.Y", "axis.Z", "cos"];
        check_finite(path, l, "cluster", &floats)?;
        let u = |name: &str| l.u32s(path, name);
        let f = |name: &str| l.f32s(path, name);
        let (parent, first_child, child_count, first_triangle, triangle_count) =
            (u("parent")?, u("first_child")?, u("child_count")?, u("first_triangle")?, u("triangle_count")?);
        let (min, max) = ([f("min.X")?, f("min.Y")?, f("min.Z")?], [f("max.X")?, f("max.Y")?, f("max.Z")?]);
        let (area, rho) = (f("area")?, [f("rhoA.R")?, f("rhoA.G")?, f("rhoA.B")?]);
        let (axis, cos) = ([f("axis.X")?, f("axis.Y")?, f("axis.Z")?], f("cos")?);
        let order = artifact.layer(path, "order")?.u32s(path, "triangle")?.to_vec();
        let nodes: Vec<ClusterNode> = (0..l.len())
            .map(|i| ClusterNode {
                parent: parent[i],
                first_child: first_child[i],
                child_count: child_count[i],
                first_triangle: first_triangle[i],
                triangle_count: triangle_count[i],
                bounds_min: [min[0][i], min[1][i], min[2][i]],
                bounds_max: [max[0][i], max[1][i], max[2][i]],
                area: area[i],
                reflectance_area: [rho[0][i], rho[1][i], rho[2][i]],
                normal_axis: [axis[0][i], axis[1][i], axis[2][i]],
                normal_cos: cos[i],
            })
            .collect();
        Clusters::check(path, &nodes, &order, triangles)?;
        Ok((Clusters { header: artifact.header, nodes, order }, input))
    }

    /// The invariants every reader of a hierarchy relies on, checked on
    /// read; a file that breaks one is refused with the cluster and the
    /// field it concerns:
    ///
    /// - `order` holds every one of the mesh's `triangles` exactly once;
    /// - there is a root, cluster 0, whose `parent` is [`NONE`] and whose
    ///   range is all of `order`;
    /// - the clusters form a tree below the root: child ranges lie inside
    ///   the table, no cycle, every cluster reached exactly once, each child
    ///   naming its parent (see [`check_forest`]);
    /// - a cluster is a leaf exactly when `first_child` is [`NONE`];
    /// - every cluster is non-empty, its triangle range inside `order`;
    /// - the children of a cluster split its triangle range in order;
    /// - bounds, areas, reflectances and cone axes are finite (checked with
    ///   the channels), areas not negative, the cone cosine in [-1, 1].
    fn check(path: &Path, nodes: &[ClusterNode], order: &[u32], triangles: usize) -> Result<()> {
        let invalid = |message: String| Err(Error::invalid(path, None, message));
        if order.len() != triangles {
            return invalid(format!("layer 'order' lists {} triangles; the mesh has {triangles}", order.len()));
        }
        let mut listed = vec![false; triangles];
        for (k, &t) in order.iter().enumerate() {
            match listed.get_mut(t as usize) {
                None => return invalid(format!("order {k}: triangle {t} is not one of the mesh's {triangles}")),
                Some(true) => return invalid(format!("order {k}: triangle {t} is listed twice")),
                Some(seen) => *seen = true,
            }
        }
        let Some(root) = nodes.first() else { return invalid("layer 'cluster' has no root cluster".into()) };
        if root.parent != NONE || root.first_triangle != 0 || root.triangle_count as usize != triangles {
            return invalid(format!(
                "cluster 0: the root must have parent {NONE} and all {triangles} triangles, not parent {} and triangles {}+{} (fields parent, first_triangle, triangle_count)",
                root.parent, root.first_triangle, root.triangle_count
            ));
        }
        for (i, c) in nodes.iter().enumerate() {
            if (c.child_count == 0) != (c.first_child == NONE) {
                return invalid(format!("cluster {i}: first_child {} does not agree with child_count {}", c.first_child, c.child_count));
            }
            if c.triangle_count == 0 {
                return invalid(format!("cluster {i}: holds no triangle (field triangle_count)"));
            }
            if c.first_triangle as u64 + c.triangle_count as u64 > triangles as u64 {
                return invalid(format!(
                    "cluster {i}: triangles {}+{} run past the end of the order of {triangles} (fields first_triangle, triangle_count)",
                    c.first_triangle, c.triangle_count
                ));
            }
            if c.area < 0.0 || !(-1.0..=1.0).contains(&c.normal_cos) {
                return invalid(format!("cluster {i}: area {} or cone cosine {} out of range (fields area, cos)", c.area, c.normal_cos));
            }
        }
        check_forest(path, "cluster", nodes.len(), 0..1, |i| (nodes[i].first_child, nodes[i].child_count), |i| nodes[i].parent)?;
        for (i, c) in nodes.iter().enumerate().filter(|(_, c)| !c.is_leaf()) {
            let mut next = c.first_triangle;
            for k in c.first_child..c.first_child + c.child_count {
                let child = &nodes[k as usize];
                if child.first_triangle != next {
                    return invalid(format!(
                        "cluster {k}: triangles start at {}, but its parent cluster {i} has them start at {next} (field first_triangle)",
                        child.first_triangle
                    ));
                }
                next += child.triangle_count;
            }
            if next != c.first_triangle + c.triangle_count {
                return invalid(format!(
                    "cluster {i}: its children hold {} of its {} triangles (field triangle_count)",
                    next - c.first_triangle,
                    c.triangle_count
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    fn node(parent: u32, children: (u32, u32), triangles: (u32, u32)) -> ClusterNode {
        ClusterNode {
            parent,
            first_child: if children.1 == 0 { NONE } else { children.0 },
            child_count: children.1,
            first_triangle: triangles.0,
            triangle_count: triangles.1,
            bounds_min: [0.0; 3],
            bounds_max: [1.0; 3],
            area: 1.0,
            reflectance_area: [0.5; 3],
            normal_axis: [0.0, 0.0, 1.0],
            normal_cos: 1.0,
        }
    }

    /// A root over four triangles with two leaves of two each.
    fn clusters() -> Clusters {
        Clusters {
            header: Clusters::header(Provenance::in_memory("test")),
            nodes: vec![node(NONE, (1, 2), (0, 4)), node(0, (0, 0), (0, 2)), node(0, (0, 0), (2, 2))],
            order: vec![3, 1, 0, 2],
        }
    }

    /// Writes `clusters` with the writer, reads it back over 4 triangles.
    fn round_trip(name: &str, clusters: &Clusters) -> (std::path::PathBuf, Result<Clusters>) {
        let path = std::env::temp_dir().join(format!("clusters-{name}-{}.exr", std::process::id()));
        clusters.write(&path).unwrap();
        let back = Clusters::read(&path, 4).map(|(c, _)| c);
        (path, back)
    }

    /// Asserts that `clusters` after `edit` is refused with a message
    /// naming the file and ending in `expected`.
    fn assert_refused(name: &str, edit: impl FnOnce(&mut Clusters), expected: &str) {
        let mut edited = clusters();
        edit(&mut edited);
        let (path, back) = round_trip(name, &edited);
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.unwrap_err().to_string(), format!("{}: {expected}", path.display()));
    }

    #[test]
    fn a_valid_hierarchy_round_trips() {
        let (path, back) = round_trip("valid", &clusters());
        assert_eq!(back.unwrap(), clusters());
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn a_cycle_is_refused_naming_the_cluster_reached_twice() {
        let cycle = "cluster 0: reached twice from the root, through cluster 2 (a cycle or a shared child; field first_child)";
        assert_refused("cycle", |c| c.nodes[2] = node(0, (0, 1), (2, 2)), cycle);
        // A cycle the root does not reach: still refused, never walked forever.
        let detached = |c: &mut Clusters| c.nodes.extend([node(4, (4, 1), (0, 1)), node(3, (3, 1), (0, 1))]);
        assert_refused("detached", detached, "cluster 3: not reachable from the root (field parent is 4)");
    }

    #[test]
    fn an_empty_cluster_and_a_child_range_past_the_end_are_refused() {
        assert_refused("empty", |c| c.nodes[1].triangle_count = 0, "cluster 1: holds no triangle (field triangle_count)");
        let past = "cluster 0: children 1..6 run past the end of the table of 3 (field first_child)";
        assert_refused("past", |c| c.nodes[0].child_count = 5, past);
    }

    #[test]
    fn children_that_do_not_split_their_parent_and_bad_orders_and_numbers_are_refused() {
        let overlap = "cluster 2: triangles start at 1, but its parent cluster 0 has them start at 2 (field first_triangle)";
        assert_refused("overlap", |c| c.nodes[2].first_triangle = 1, overlap);
        assert_refused("twice", |c| c.order[3] = 3, "order 3: triangle 3 is listed twice");
        assert_refused("nan", |c| c.nodes[1].area = f32::NAN, "cluster 1: field area is NaN");
    }
}

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
use crate::exr_io::{read_exr, write_exr, Channel, ExrArtifact, Layer};
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

    /// Reads `clusters.exr` and checks its indices against `triangles`
    /// input triangles.
    pub fn read(path: &Path, triangles: usize) -> Result<(Clusters, Input)> {
        let (artifact, input) = read_exr::<Clusters>(path)?;
        let l = artifact.layer(path, "cluster")?;
        let u = |name: &str| l.u32s(path, name);
        let f = |name: &str| l.f32s(path, name);
        let (parent, first_child, child_count, first_triangle, triangle_count) =
            (u("parent")?, u("first_child")?, u("child_count")?, u("first_triangle")?, u("triangle_count")?);
        let (min, max) = ([f("min.X")?, f("min.Y")?, f("min.Z")?], [f("max.X")?, f("max.Y")?, f("max.Z")?]);
        let (area, rho) = (f("area")?, [f("rhoA.R")?, f("rhoA.G")?, f("rhoA.B")?]);
        let (axis, cos) = ([f("axis.X")?, f("axis.Y")?, f("axis.Z")?], f("cos")?);
        let order = artifact.layer(path, "order")?.u32s(path, "triangle")?.to_vec();
        let count = l.len();
        let nodes: Vec<ClusterNode> = (0..count)
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
        if order.len() != triangles || order.iter().any(|&t| t as usize >= triangles) {
            return Err(Error::invalid(path, None, format!("cluster order does not cover the mesh's {triangles} triangles")));
        }
        for (i, c) in nodes.iter().enumerate() {
            let children_ok = c.child_count == 0 || (c.first_child != NONE && (c.first_child + c.child_count) as usize <= count);
            let range_ok = (c.first_triangle as u64 + c.triangle_count as u64) <= order.len() as u64;
            let parent_ok = (i == 0) == (c.parent == NONE) && (c.parent == NONE || (c.parent as usize) < i);
            if !children_ok || !range_ok || !parent_ok {
                return Err(Error::invalid(path, None, format!("cluster {i} links outside the hierarchy")));
            }
        }
        Ok((Clusters { header: artifact.header, nodes, order }, input))
    }
}

//! The element hierarchy the photons land in, and its vertices.
//!
//! Elements are the input triangles and their regular 1:4 children
//! ([`radiometry::subdivision`], the layout of `solution.exr`), so the
//! result is a solution like hierarchical-solve's. Paper 001 buckets
//! photons "directly into a mesh" and filters "at the mesh vertices": here a
//! photon deposits its power on the three corners of the leaf it hits, in
//! proportion to the hit's barycentric coordinates in that leaf (the linear
//! hat functions of the leaf mesh). We choose vertices over elements
//! because the paper filters and splits at vertices, and because the hat
//! weights make the estimate continuous across elements: a vertex's
//! estimate is `E_v = sum_hits l_v(x) Phi / sum_leaves A_leaf / 3`, the
//! irradiance averaged with the weight of its hat function (exact for
//! constant irradiance, second order otherwise).
//!
//! # Vertex identity
//!
//! A leaf corner is a point of its input triangle with dyadic barycentric
//! weights `(1 - u - v, u, v)` over the triangle's three mesh vertices.
//! Two corners are the same point exactly when they have the same non-zero
//! weights over the same mesh vertices (a corner on a shared edge has two,
//! a mesh vertex one), so corners are matched by that key, without a
//! distance tolerance. At one point, corners of leaves whose normals differ
//! by more than the crease angle, or whose materials differ, are different
//! vertices: a wall and the floor it meets have their own irradiance.

use crate::exposure;
use glam::DVec3;
use radiometry::geometry::TriangleGeometry;
use radiometry::subdivision::{children, locate_child, Corners, ROOT};
use schemas::mesh::Mesh;
use schemas::solution::{Element, NONE};
use std::collections::HashMap;

/// A corner's identity: up to three `(mesh vertex, weight bits)` pairs,
/// sorted by vertex, unused entries `(u32::MAX, 0)`.
pub type PointKey = [(u32, u64); 3];

/// The element tree over the mesh's triangles.
#[derive(Clone, Debug)]
pub struct Elements {
    /// Elements in the layout of `solution.exr` (input triangle `t` is
    /// element `t`; children follow); radiosity is filled at output.
    pub elements: Vec<Element>,
    /// Barycentric corners of every element, f64.
    pub corners: Vec<Corners>,
}

impl Elements {
    /// One element per input triangle.
    pub fn new(mesh: &Mesh) -> Self {
        let elements = mesh.triangles.iter().enumerate().map(|(t, tri)| Element::root(t as u32, tri.area, [0.0; 3])).collect();
        Elements { elements, corners: vec![ROOT; mesh.triangles.len()] }
    }

    /// The area of element `e`, m²: its triangle's (`geometry`) over 4 per
    /// level (the 1:4 rule), in f64.
    pub fn area(&self, geometry: &[TriangleGeometry], e: usize) -> f64 {
        let element = &self.elements[e];
        geometry[element.triangle as usize].area / 4f64.powi(element.level as i32)
    }

    /// Splits leaf `e` 1:4; returns its first child.
    pub fn split(&mut self, e: usize) -> usize {
        let first = self.elements.len();
        let parent = self.elements[e];
        self.elements[e].first_child = first as u32;
        for child in children(&self.corners[e]) {
            self.elements.push(Element {
                triangle: parent.triangle,
                parent: e as u32,
                first_child: NONE,
                level: parent.level + 1,
                corners: child.map(|c| c.map(|x| x as f32)),
                area: parent.area / 4.0,
                radiosity: [0.0; 3],
            });
            self.corners.push(child);
        }
        first
    }

    /// The leaf of triangle `t` that holds the point with barycentric
    /// `(u, v)`, and the point's barycentric coordinates in that leaf.
    pub fn locate(&self, t: usize, uv: [f64; 2]) -> (usize, [f64; 3]) {
        let mut local = [1.0 - uv[0] - uv[1], uv[0], uv[1]];
        let mut e = t;
        while !self.elements[e].is_leaf() {
            let (k, child_local) = locate_child(local);
            e = self.elements[e].first_child as usize + k;
            local = child_local;
        }
        (e, local)
    }

    /// The exact identity of corner `k` of element `e` (see the module
    /// documentation).
    pub fn point_key(&self, mesh: &Mesh, e: usize, k: usize) -> PointKey {
        point_key(mesh, self.elements[e].triangle as usize, self.corners[e][k])
    }
}

/// The exact identity of the point with barycentric `uv` (dyadic) in
/// triangle `t` (see the module documentation).
pub fn point_key(mesh: &Mesh, t: usize, uv: [f64; 2]) -> PointKey {
    let tri = &mesh.triangles[t];
    let weights = [1.0 - uv[0] - uv[1], uv[0], uv[1]];
    let mut key = [(u32::MAX, 0u64); 3];
    let mut n = 0;
    for (vertex, w) in tri.vertices.iter().zip(weights) {
        if w != 0.0 {
            key[n] = (*vertex, w.to_bits());
            n += 1;
        }
    }
    key.sort_unstable();
    key
}

/// The vertices of the leaf mesh.
#[derive(Clone, Debug, Default)]
pub struct Vertices {
    /// Position, mesh frame, m.
    pub position: Vec<DVec3>,
    /// Unit normal: the direction of [`Vertices::mean_normal`].
    pub normal: Vec<DVec3>,
    /// The hat-area-weighted mean of the vertex's leaves' unit normals (not
    /// unit: shorter where the leaves bend). Lambert's factor and `I cos /
    /// r²` are linear in the receiver's normal, so a point value with this
    /// normal is the hat-weighted mean of the values each leaf's plane
    /// would give, which is what the photons' estimate at the vertex
    /// averages too (a tessellated sphere's vertex is lit as its facets
    /// are, on average, not as the first facet alone).
    pub mean_normal: Vec<DVec3>,
    /// Integral of the vertex's hat function over the open part of its
    /// leaves ([`crate::exposure`]), m²: `sum A_leaf / 3` where nothing is
    /// buried.
    pub hat_area: Vec<f64>,
    /// Material index.
    pub material: Vec<u32>,
    /// A mesh triangle the vertex lies on (its first leaf's).
    pub triangle: Vec<u32>,
    /// A point just inside the vertex's leaves, for point evaluations that
    /// are singular on an edge (see [`crate::direct`]).
    pub inside: Vec<DVec3>,
    /// Identity of each vertex: its point and its first leaf's triangle.
    pub key: Vec<(PointKey, u32)>,
    /// The three vertices of every element's corners (leaves only; inner
    /// elements hold `[u32::MAX; 3]`).
    pub of_element: Vec<[u32; 3]>,
}

impl Vertices {
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// The vertices of the leaves of `elements`: corners matched by their
    /// exact key, then grouped by material and by normal within
    /// `cos_crease` of the group's first leaf, in element order (so the
    /// numbering is reproducible). `open` is each element's mask of open
    /// burial points ([`crate::exposure::Exposure`]).
    pub fn new(mesh: &Mesh, geometry: &[TriangleGeometry], elements: &Elements, open: &[u16], cos_crease: f64) -> Self {
        let mut v = Vertices { of_element: vec![[u32::MAX; 3]; elements.elements.len()], ..Default::default() };
        let mut at_point: HashMap<PointKey, Vec<u32>> = HashMap::new();
        let mut inside_sum: Vec<DVec3> = Vec::new();
        let mut normal_sum: Vec<DVec3> = Vec::new();
        // Each vertex's first leaf's normal: corners join the vertex whose
        // first normal is within the crease angle of theirs.
        let mut first_normal: Vec<DVec3> = Vec::new();
        for (e, element) in elements.elements.iter().enumerate() {
            if !element.is_leaf() {
                continue;
            }
            let t = element.triangle as usize;
            let g = &geometry[t];
            let material = mesh.triangles[t].material;
            let world = g.element(&elements.corners[e]);
            let centroid = (world[0] + world[1] + world[2]) / 3.0;
            let area = elements.area(geometry, e);
            for (k, &corner) in world.iter().enumerate() {
                let key = elements.point_key(mesh, e, k);
                let candidates = at_point.entry(key).or_default();
                let found = candidates.iter().copied().find(|&c| v.material[c as usize] == material && first_normal[c as usize].dot(g.normal) >= cos_crease);
                let id = match found {
                    Some(id) => id,
                    None => {
                        let id = v.position.len() as u32;
                        v.position.push(corner);
                        first_normal.push(g.normal);
                        v.hat_area.push(0.0);
                        v.material.push(material);
                        v.triangle.push(t as u32);
                        v.key.push((key, t as u32));
                        inside_sum.push(DVec3::ZERO);
                        normal_sum.push(DVec3::ZERO);
                        candidates.push(id);
                        id
                    }
                };
                v.hat_area[id as usize] += exposure::open_points(open[e]).map(|l| l[k]).sum::<f64>() * area / exposure::POINTS as f64;
                inside_sum[id as usize] += area * centroid;
                normal_sum[id as usize] += area * g.normal;
                v.of_element[e][k] = id;
            }
        }
        for i in 0..v.hat_area.len() {
            let mean = if v.hat_area[i] > 0.0 { normal_sum[i] / (3.0 * v.hat_area[i]) } else { first_normal[i] };
            v.mean_normal.push(mean);
            v.normal.push(mean.try_normalize().unwrap_or(first_normal[i]));
        }
        // A point a ten-thousandth of the way from the vertex towards the
        // area-weighted centroid of its leaves' centroids.
        v.inside = (0..v.len())
            .map(|i| {
                let c = if v.hat_area[i] > 0.0 { inside_sum[i] / (3.0 * v.hat_area[i]) } else { v.position[i] };
                v.position[i] + 1e-4 * (c - v.position[i])
            })
            .collect();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stage_kit::scene::mesh_triangles;
    use schemas::header::{Provenance, Schema};
    use schemas::mesh::Triangle;

    /// Two triangles of the unit square (z = 0, facing +z) and one of a
    /// wall (x = 0, facing +x) on their shared edge x = 0.
    fn mesh() -> Mesh {
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tri = |vertices: [u32; 3], normal: [f32; 3], area: f32| Triangle { vertices, material: 0, object: 0, area, normal };
        Mesh {
            header: Mesh::header(Provenance::in_memory("test")),
            positions,
            triangles: vec![tri([0, 1, 2], [0.0, 0.0, 1.0], 0.5), tri([0, 2, 3], [0.0, 0.0, 1.0], 0.5), tri([0, 3, 4], [1.0, 0.0, 0.0], 0.5)],
        }
    }

    #[test]
    fn shared_corners_are_one_vertex_except_across_a_crease() {
        let mesh = mesh();
        let geometry = mesh_triangles(&mesh);
        let mut elements = Elements::new(&mesh);
        elements.split(0);
        elements.split(1);
        let v = Vertices::new(&mesh, &geometry, &elements, &vec![exposure::ALL_OPEN; elements.elements.len()], 0.5);
        // Floor: 4 square corners + 4 edge midpoints + the centre = 9
        // points; the wall: its 3 corners on its own.
        assert_eq!(v.len(), 12);
        let floor_area: f64 = (0..v.len()).filter(|&i| v.normal[i].z > 0.5).map(|i| v.hat_area[i]).sum();
        assert!((floor_area - 1.0).abs() < 1e-12, "hat areas tile the floor: {floor_area}");
        // The diagonal's midpoint (0.5, 0.5) is a corner of leaves of both
        // floor triangles and is one vertex.
        let centre: Vec<usize> = (0..v.len()).filter(|&i| (v.position[i] - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-12).collect();
        assert_eq!(centre.len(), 1);
        // The point (0, 0, 0) is a floor vertex and a wall vertex.
        assert_eq!((0..v.len()).filter(|&i| v.position[i].length() < 1e-12).count(), 2);
        let (leaf, local) = elements.locate(0, [0.6, 0.1]);
        assert_eq!(elements.elements[leaf].level, 1);
        let p = geometry[0].point([0.6, 0.1]);
        let back: DVec3 = (0..3).map(|k| local[k] * geometry[0].point(elements.corners[leaf][k])).sum();
        assert!((back - p).length() < 1e-12);
    }
}

//! The planar surfaces samples are placed on: the triangles of one object
//! and one material that share one plane, each with a 2-D frame `(u, v)`
//! in that plane. Paper 002 places samples "associated with the original
//! given geometry", surface by surface (A, B, the walls), and resamples
//! them for display on a grid over each surface (Section 3.2); a surface
//! here is what such a grid covers.

use crate::union_find::{find, union};
use glam::{DVec2, DVec3};
use radiometry::geometry::{frame_with_normal, TriangleGeometry};
use schemas::mesh::{Manifest, Mesh};
use std::collections::HashMap;

/// One planar surface.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Index into the manifest's objects.
    pub object: u32,
    /// Index into the manifest's materials.
    pub material: u32,
    /// Front-face unit normal.
    pub normal: DVec3,
    /// A point of the plane: the first triangle's first corner.
    pub origin: DVec3,
    /// In-plane axes `u`, `v` (with `normal`, a right-handed frame).
    pub axes: [DVec3; 2],
    /// Its mesh triangles.
    pub triangles: Vec<u32>,
    /// The triangles' corners in `(u, v)`.
    pub corners_uv: Vec<[DVec2; 3]>,
    /// Bounding rectangle in `(u, v)`: low corner.
    pub lo: DVec2,
    /// Bounding rectangle in `(u, v)`: high corner.
    pub hi: DVec2,
    /// Area, m².
    pub area: f64,
    /// Diffuse reflectance, RGB.
    pub reflectance: [f64; 3],
    /// Emitted radiosity, W/m², RGB.
    pub emission: [f64; 3],
    /// The least [`Surface::extent`]: that of the curved surface it is a
    /// facet of ([`smooth_patches`]), 0 for a surface of its own.
    pub least_extent: f64,
}

/// The cosine over which two unit normals count as parallel: triangles of
/// one object and material on one plane make one surface.
const PARALLEL_COS: f64 = 1.0 - 5e-13;

/// The largest angle between the normals of two surfaces of one material
/// that share a mesh edge for both to count as facets of one curved
/// surface ([`smooth_patches`]): a sphere of 32 x 32 facets turns by 11
/// degrees from one to the next, a 16-sided cylinder by 22.5; a box's
/// faces by 90, a chamfer by 45.
pub const SMOOTH_TURN_DEG: f64 = 30.0;

impl Surface {
    /// `(u, v)` of a point of the plane.
    pub fn uv(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.axes[0]), d.dot(self.axes[1]))
    }

    /// The mesh-frame point at `(u, v)`.
    pub fn point(&self, uv: DVec2) -> DVec3 {
        self.origin + self.axes[0] * uv.x + self.axes[1] * uv.y
    }

    /// The longer side of the bounding rectangle, m, or on a facet of a
    /// curved surface that surface's (`least_extent`, where longer): the
    /// length the stage's spacings are fractions of.
    pub fn extent(&self) -> f64 {
        self.longer_side().max(self.least_extent)
    }

    /// The longer side of the bounding rectangle, m.
    pub fn longer_side(&self) -> f64 {
        let size = self.hi - self.lo;
        size.x.max(size.y)
    }

    /// The mesh triangle containing `(u, v)` (edges included, to a
    /// relative 1e-9), if any.
    pub fn triangle_at(&self, uv: DVec2) -> Option<u32> {
        let tolerance = -1e-9;
        self.corners_uv.iter().zip(&self.triangles).find_map(|(c, &t)| {
            let (e1, e2, d) = (c[1] - c[0], c[2] - c[0], uv - c[0]);
            let det = e1.perp_dot(e2);
            if det == 0.0 {
                return None;
            }
            let (b1, b2) = (d.perp_dot(e2) / det, e1.perp_dot(d) / det);
            (b1 >= tolerance && b2 >= tolerance && 1.0 - b1 - b2 >= tolerance).then_some(t)
        })
    }

    /// Whether it emits (its exitance is > 0 in some channel).
    pub fn emits(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }

    /// Its boundary edges in `(u, v)`: the triangle edges no other of its
    /// triangles shares (matched by their mesh vertex indices).
    pub fn boundary(&self, mesh: &Mesh) -> Vec<[DVec2; 2]> {
        let mut count: HashMap<(u32, u32), u32> = HashMap::new();
        for &t in &self.triangles {
            let v = mesh.triangles[t as usize].vertices;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut edges = Vec::new();
        for (&t, c) in self.triangles.iter().zip(&self.corners_uv) {
            let v = mesh.triangles[t as usize].vertices;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                if count[&(a.min(b), a.max(b))] == 1 {
                    edges.push([c[k], c[(k + 1) % 3]]);
                }
            }
        }
        edges
    }
}

/// Groups the mesh's triangles into planar surfaces: the same object and
/// material, normals within 1e-6 rad, planes within 1e-6 of the scene's
/// size. Surfaces are numbered in the order of their first triangle, each
/// with its least extent ([`smooth_patches`]). Returns the surfaces and
/// each triangle's surface.
pub fn planar_surfaces(mesh: &Mesh, manifest: &Manifest, geometry: &[TriangleGeometry]) -> (Vec<Surface>, Vec<u32>) {
    let size = manifest.statistics.bounds_max.iter().zip(&manifest.statistics.bounds_min).map(|(a, b)| a - b).fold(1e-9, f64::max);
    let mut surfaces: Vec<Surface> = Vec::new();
    let mut by_key: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    let mut surface_of = Vec::with_capacity(geometry.len());
    for (i, (t, g)) in mesh.triangles.iter().zip(geometry).enumerate() {
        let candidates = by_key.entry((t.object, t.material)).or_default();
        let same_plane = |s: &Surface| s.normal.dot(g.normal) > PARALLEL_COS && (g.corners[0] - s.origin).dot(s.normal).abs() < 1e-6 * size;
        let index = match candidates.iter().find(|&&s| same_plane(&surfaces[s])) {
            Some(&s) => s,
            None => {
                let [u, v, n] = frame_with_normal(g.normal);
                let material = &manifest.materials[t.material as usize];
                surfaces.push(Surface {
                    object: t.object,
                    material: t.material,
                    normal: n,
                    origin: g.corners[0],
                    axes: [u, v],
                    triangles: Vec::new(),
                    corners_uv: Vec::new(),
                    lo: DVec2::splat(f64::INFINITY),
                    hi: DVec2::splat(f64::NEG_INFINITY),
                    area: 0.0,
                    reflectance: material.diffuse,
                    emission: material.emission,
                    least_extent: 0.0,
                });
                candidates.push(surfaces.len() - 1);
                surfaces.len() - 1
            }
        };
        let s = &mut surfaces[index];
        let uv = g.corners.map(|p| s.uv(p));
        for c in uv {
            s.lo = s.lo.min(c);
            s.hi = s.hi.max(c);
        }
        s.triangles.push(i as u32);
        s.corners_uv.push(uv);
        s.area += g.area;
        surface_of.push(index as u32);
    }
    for (s, least) in smooth_patches(mesh, geometry, &surfaces, &surface_of).into_iter().enumerate() {
        surfaces[s].least_extent = least;
    }
    (surfaces, surface_of)
}

/// Each surface's least extent: where it is a facet of a curved surface,
/// the longest side of that surface's bounding box, else 0. Facets of one
/// material whose normals turn across a mesh edge they share, by under
/// [`SMOOTH_TURN_DEG`], join one curved surface (transitively); pieces of
/// one plane (the same material in two objects) stay apart, each sampled
/// as before.
///
/// Paper 002 places samples on a few large surfaces; a curved object is
/// hundreds of small planar facets, each a surface here, and with the
/// spacings in fractions of each facet's own extent every facet took a
/// full set (probes, contours, edge samples at a quarter of its side):
/// McGuire's `CornellBox-Glossy`, whose sphere has a thousand facets,
/// had 59,000 samples, 42,000 of them on contours across facets a few
/// centimetres wide, and took 151 s. The light on a facet varies over
/// the curved surface's scale, not the facet's: taking that surface's
/// extent, each facet is sampled as the one surface it approximates
/// would be.
fn smooth_patches(mesh: &Mesh, geometry: &[TriangleGeometry], surfaces: &[Surface], surface_of: &[u32]) -> Vec<f64> {
    let mut root: Vec<usize> = (0..surfaces.len()).collect();
    let mut first: HashMap<(u32, u32), usize> = HashMap::new();
    let cos_turn = SMOOTH_TURN_DEG.to_radians().cos();
    for (t, triangle) in mesh.triangles.iter().enumerate() {
        let s = surface_of[t] as usize;
        for k in 0..3 {
            let (a, b) = (triangle.vertices[k], triangle.vertices[(k + 1) % 3]);
            let Some(&other) = first.get(&(a.min(b), a.max(b))) else {
                first.insert((a.min(b), a.max(b)), s);
                continue;
            };
            let turn = surfaces[other].normal.dot(surfaces[s].normal);
            let smooth = surfaces[other].material == surfaces[s].material && turn > cos_turn && turn <= PARALLEL_COS;
            if smooth {
                union(&mut root, other, s);
            }
        }
    }
    // Each curved surface's bounding box and facet count, at its root.
    let mut bounds = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY, 0); surfaces.len()];
    for (s, surface) in surfaces.iter().enumerate() {
        let entry = &mut bounds[find(&mut root, s)];
        entry.2 += 1;
        for &t in &surface.triangles {
            for c in geometry[t as usize].corners {
                entry.0 = entry.0.min(c);
                entry.1 = entry.1.max(c);
            }
        }
    }
    (0..surfaces.len())
        .map(|s| {
            let (lo, hi, count) = bounds[find(&mut root, s)];
            if count > 1 { (hi - lo).max_element() } else { 0.0 }
        })
        .collect()
}

/// A `width` x `height` m rectangle in the plane z = 0, facing +z, corner
/// at the origin, as one surface of two triangles (for tests).
#[cfg(test)]
pub fn rectangle(width: f64, height: f64) -> Surface {
    let corners = [DVec2::new(0.0, 0.0), DVec2::new(width, 0.0), DVec2::new(width, height), DVec2::new(0.0, height)];
    Surface {
        object: 0,
        material: 0,
        normal: DVec3::Z,
        origin: DVec3::ZERO,
        axes: [DVec3::X, DVec3::Y],
        triangles: vec![0, 1],
        corners_uv: vec![[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]],
        lo: corners[0],
        hi: corners[2],
        area: width * height,
        reflectance: [0.5; 3],
        emission: [0.0; 3],
        least_extent: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use schemas::header::Schema;
    use schemas::mesh::Triangle;
    use stage_kit::scene::mesh_triangles;
    use test_support::meshes::{manifest, material};

    /// Quads `[a, b, c, d]` (vertex indices, counter-clockwise from the
    /// front) of `material` and `object` over shared `positions`, each two
    /// triangles.
    fn mesh(positions: &[DVec3], quads: &[([u32; 4], u32, u32)]) -> Mesh {
        let triangles = quads
            .iter()
            .flat_map(|&(q, material, object)| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]].map(|vertices| Triangle { vertices, material, object, area: 0.0, normal: [0.0; 3] }))
            .collect();
        Mesh { header: Mesh::header(schemas::header::Provenance::in_memory("surfaces test")), positions: positions.iter().map(|p| p.as_vec3().to_array()).collect(), triangles }
    }

    /// Six facets of a quarter cylinder (radius 1, height 0.2, turning by
    /// 15 degrees) join one curved surface and each takes its bounding
    /// box's longest side (1) as its least extent; two squares at right
    /// angles, two at 10 degrees of different materials, and two of one
    /// plane and material in two objects stay surfaces of their own (0).
    #[test]
    fn facets_of_a_curve_join_and_a_boxs_faces_do_not() {
        let mut positions: Vec<DVec3> = (0..=6).flat_map(|k| {
            let a = (15.0 * k as f64).to_radians();
            [DVec3::new(a.cos(), a.sin(), 0.0), DVec3::new(a.cos(), a.sin(), 0.2)]
        }).collect();
        let mut quads: Vec<([u32; 4], u32, u32)> = (0..6).map(|k| ([2 * k + 2, 2 * k, 2 * k + 1, 2 * k + 3], 0, 0)).collect();
        // An L at x = 5: a floor square and a wall square sharing an edge.
        let l = positions.len() as u32;
        positions.extend([DVec3::new(5.0, 0.0, 0.0), DVec3::new(6.0, 0.0, 0.0), DVec3::new(6.0, 1.0, 0.0), DVec3::new(5.0, 1.0, 0.0), DVec3::new(6.0, 0.0, 1.0), DVec3::new(6.0, 1.0, 1.0)]);
        quads.extend([([l, l + 1, l + 2, l + 3], 0, 0), ([l + 1, l + 4, l + 5, l + 2], 0, 0)]);
        // Two squares at 10 degrees, of materials 0 and 1, at x = 10, z = 3.
        let m = positions.len() as u32;
        let (c, s) = (10f64.to_radians().cos(), 10f64.to_radians().sin());
        positions.extend([DVec3::new(10.0, 0.0, 3.0), DVec3::new(11.0, 0.0, 3.0), DVec3::new(11.0, 1.0, 3.0), DVec3::new(10.0, 1.0, 3.0), DVec3::new(11.0 + c, 0.0, 3.0 + s), DVec3::new(11.0 + c, 1.0, 3.0 + s)]);
        quads.extend([([m, m + 1, m + 2, m + 3], 0, 0), ([m + 1, m + 4, m + 5, m + 2], 1, 0)]);
        // Two squares of the plane z = 6, objects 0 and 1, at x = 10.
        let n = positions.len() as u32;
        positions.extend([0.0, 1.0, 2.0].into_iter().flat_map(|x| [DVec3::new(10.0 + x, 0.0, 6.0), DVec3::new(10.0 + x, 1.0, 6.0)]));
        quads.extend([([n, n + 2, n + 3, n + 1], 0, 0), ([n + 2, n + 4, n + 5, n + 3], 0, 1)]);
        let mesh = mesh(&positions, &quads);
        let mut manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.5; 3], [0.0; 3])]);
        manifest.statistics.bounds_max = [12.0, 1.0, 6.0];
        let (surfaces, _) = planar_surfaces(&mesh, &manifest, &mesh_triangles(&mesh));
        assert_eq!(surfaces.len(), 12, "six facets and six squares");
        let arc = positions[..14].iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p.as_vec3().as_dvec3()), hi.max(p.as_vec3().as_dvec3())));
        for facet in &surfaces[..6] {
            assert_eq!(facet.least_extent, (arc.1 - arc.0).max_element(), "a facet of the quarter cylinder");
            assert!(facet.longer_side() < 0.3 && facet.extent() == facet.least_extent);
        }
        for square in &surfaces[6..] {
            assert_eq!(square.least_extent, 0.0, "a square of its own");
        }
    }
}

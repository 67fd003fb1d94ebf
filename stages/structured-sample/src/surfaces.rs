//! The planar surfaces samples are placed on: the triangles of one object
//! and one material that share one plane, each with a 2-D frame `(u, v)`
//! in that plane. Paper 002 places samples "associated with the original
//! given geometry", surface by surface (A, B, the walls), and resamples
//! them for display on a grid over each surface (Section 3.2); a surface
//! here is what such a grid covers.

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
    /// The least [`Surface::extent`]: [`SMALLEST_EXTENT`] of the scene's
    /// size.
    pub least_extent: f64,
}

/// The least length the stage's spacings are fractions of, as a fraction
/// of the scene's size (the longest side of its bounding box). Paper 002
/// places samples on a few large surfaces; a curved object is hundreds of
/// small planar facets, and with spacings in fractions of each facet
/// every facet took a full set (probes, contours, edges at a quarter of
/// its side): McGuire's `CornellBox-Glossy`, whose sphere has a thousand
/// facets, had 59,000 samples, 42,000 of them on contours across facets
/// a few centimetres wide, and took 163 s. The light on a facet varies
/// with what lights it, whose scale is the room's, not the facet's. An
/// eighth: every surface of the Cornell boxes keeps its own extent (the
/// smallest, the lamps, are near a quarter of the room).
pub const SMALLEST_EXTENT: f64 = 0.125;

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

    /// The longer side of the bounding rectangle, m, but at least
    /// `least_extent`: the length the stage's spacings are fractions of.
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
/// size. Surfaces are numbered in the order of their first triangle.
/// Returns the surfaces and each triangle's surface.
pub fn planar_surfaces(mesh: &Mesh, manifest: &Manifest, geometry: &[TriangleGeometry]) -> (Vec<Surface>, Vec<u32>) {
    let size = manifest.statistics.bounds_max.iter().zip(&manifest.statistics.bounds_min).map(|(a, b)| a - b).fold(1e-9, f64::max);
    let mut surfaces: Vec<Surface> = Vec::new();
    let mut by_key: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    let mut surface_of = Vec::with_capacity(geometry.len());
    for (i, (t, g)) in mesh.triangles.iter().zip(geometry).enumerate() {
        let candidates = by_key.entry((t.object, t.material)).or_default();
        let same_plane = |s: &Surface| s.normal.dot(g.normal) > 1.0 - 5e-13 && (g.corners[0] - s.origin).dot(s.normal).abs() < 1e-6 * size;
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
                    least_extent: SMALLEST_EXTENT * size,
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
    (surfaces, surface_of)
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

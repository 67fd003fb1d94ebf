//! Triangle geometry in f64: corners, normals and areas of the mesh, and
//! the points of elements (sub-triangles given in barycentric coordinates).

use crate::subdivision::Corners;
use glam::DVec3;

/// Corners, unit normal and area of one triangle, f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleGeometry {
    /// Vertex positions, mesh frame.
    pub corners: [DVec3; 3],
    /// Front-face unit normal (right-hand rule on the corner order); zero
    /// for a degenerate triangle.
    pub normal: DVec3,
    /// Area, m².
    pub area: f64,
}

impl TriangleGeometry {
    /// Geometry of the triangle with these corners. The cross product is
    /// taken at the corner opposite the longest edge, where it cancels least.
    pub fn new(corners: [DVec3; 3]) -> Self {
        let edge = |i: usize| corners[(i + 2) % 3] - corners[(i + 1) % 3];
        let longest = (0..3).max_by(|&a, &b| edge(a).length_squared().total_cmp(&edge(b).length_squared())).unwrap_or(0);
        let at = corners[longest];
        let cross = (corners[(longest + 1) % 3] - at).cross(corners[(longest + 2) % 3] - at);
        let length = cross.length();
        let normal = if length > 0.0 { cross / length } else { DVec3::ZERO };
        TriangleGeometry { corners, normal, area: 0.5 * length }
    }

    /// The point at barycentric `(u, v)`: `P0 + u (P1 - P0) + v (P2 - P0)`.
    pub fn point(&self, uv: [f64; 2]) -> DVec3 {
        let [p0, p1, p2] = self.corners;
        p0 + (p1 - p0) * uv[0] + (p2 - p0) * uv[1]
    }

    /// World corners of the element with barycentric `corners`.
    pub fn element(&self, corners: &Corners) -> [DVec3; 3] {
        corners.map(|uv| self.point(uv))
    }

    /// Barycentric `(u, v)` of a point in the triangle's plane.
    pub fn uv_of(&self, p: DVec3) -> [f64; 2] {
        let [p0, p1, p2] = self.corners;
        let (e1, e2, d) = (p1 - p0, p2 - p0, p - p0);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d1, d2) = (d.dot(e1), d.dot(e2));
        let det = d11 * d22 - d12 * d12;
        if det <= 0.0 {
            return [0.0, 0.0];
        }
        [(d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det]
    }
}

/// A right-handed orthonormal frame `[t, b, n]` with `n` given (unit):
/// `t` is the mesh-frame x axis made perpendicular to `n` (the z axis when
/// `n` is nearly along x), `b = n x t`. A fixed rule, so a frame derived
/// from a normal alone is reproducible.
pub fn frame_with_normal(n: DVec3) -> [DVec3; 3] {
    let seed = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Z };
    let t = (seed - n * seed.dot(n)).normalize();
    [t, n.cross(t), n]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    #[test]
    fn sliver_and_far_away_triangles_keep_their_area() {
        // A 1 m x 1 um sliver: area 5e-7 m^2, any corner order.
        let sliver = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.5, 1e-6, 0.0)];
        for r in 0..3 {
            let c = [sliver[r], sliver[(r + 1) % 3], sliver[(r + 2) % 3]];
            let g = TriangleGeometry::new(c);
            assert!((g.area - 5e-7).abs() < 1e-16, "{}", g.area);
            assert!((g.normal - DVec3::Z).length() < 1e-9);
        }
        let degenerate = TriangleGeometry::new([DVec3::ZERO, DVec3::X, DVec3::X * 2.0]);
        assert_eq!((degenerate.area, degenerate.normal), (0.0, DVec3::ZERO));
        let g = TriangleGeometry::new([dvec3(0.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(0.0, 3.0, 0.0)]);
        let uv = g.uv_of(g.point([0.25, 0.5]));
        assert!((uv[0] - 0.25).abs() < 1e-15 && (uv[1] - 0.5).abs() < 1e-15);
    }
}

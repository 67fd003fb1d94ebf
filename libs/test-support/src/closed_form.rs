//! Closed-form answers from J. R. Howell's catalogue of radiation
//! configuration factors, implemented here from the catalogue's formulas,
//! independently of the stages' kernels.

use crate::vec3::{cross, dot, sub};
use std::f64::consts::PI;

/// C-11: between directly opposed parallel rectangles `a x b`, `c` apart.
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    let log = (((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln();
    let sx = (1.0 + x2).sqrt();
    let sy = (1.0 + y2).sqrt();
    2.0 / (PI * x * y) * (log + x * sy * (x / sy).atan() + y * sx * (y / sx).atan() - x * x.atan() - y * y.atan())
}

/// C-14: from a rectangle `w x l` to a rectangle `h x l` sharing the edge
/// of length `l`, at right angles.
pub fn perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
    let (w, h) = (w / l, h / l);
    let (w2, h2) = (w * w, h * h);
    let s = (w2 + h2).sqrt();
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s * (1.0 / s).atan() + 0.25 * (a * b * c).ln()) / (PI * w)
}

/// B-3: from a differential area to a parallel `a x b` rectangle at height
/// `c`, the area's normal through one corner of the rectangle.
pub fn point_to_corner_rectangle(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// From a differential area at `(x, y)` on the floor, facing up, to the
/// parallel rectangle `[x0, x1] x [y0, y1]` at height `c`: superposition of
/// four corner rectangles (signed, so the point may lie outside).
pub fn point_to_rectangle(x: f64, y: f64, rect: [f64; 4], c: f64) -> f64 {
    let [x0, x1, y0, y1] = rect;
    let corner = |dx: f64, dy: f64| dx.signum() * dy.signum() * point_to_corner_rectangle(dx.abs(), dy.abs(), c);
    corner(x1 - x, y1 - y) - corner(x0 - x, y1 - y) - corner(x1 - x, y0 - y) + corner(x0 - x, y0 - y)
}

/// Lambert's formula: the form factor from a differential area at `point`
/// with unit normal `normal` to a planar polygon wholly in front of it (at
/// or above its tangent plane),
///
/// ```text
/// F = 1/(2 pi) |sum_i beta_i n . g_i|
/// ```
///
/// `beta_i` the angle edge `i` subtends at the point and `g_i` the unit
/// normal of the plane through the point and that edge (Lambert's
/// contour-integral form of the point-to-area factor, paper 002 Eq. 3;
/// written here from the formula, apart from the stages' kernel).
pub fn lambert_polygon(point: [f64; 3], normal: [f64; 3], polygon: &[[f64; 3]]) -> f64 {
    let mut sum = 0.0;
    for i in 0..polygon.len() {
        let a = sub(polygon[i], point);
        let b = sub(polygon[(i + 1) % polygon.len()], point);
        let g = cross(a, b);
        let g_len = dot(g, g).sqrt();
        if g_len == 0.0 {
            continue;
        }
        let beta = g_len.atan2(dot(a, b));
        sum += beta * dot(normal, g) / g_len;
    }
    sum.abs() / (2.0 * PI)
}

/// The part of the convex planar `polygon` on the front side of the plane
/// through `origin` with normal `normal` (`(x - origin) . normal >= 0`):
/// Sutherland-Hodgman against one plane.
pub fn clip_to_front(polygon: &[[f64; 3]], origin: [f64; 3], normal: [f64; 3]) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        let (da, db) = (dot(sub(a, origin), normal), dot(sub(b, origin), normal));
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let t = da / (da - db);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]);
        }
    }
    out
}

/// The mean of `f` over a triangle: its centroids after `levels` midpoint
/// subdivisions (4^levels sub-triangles of equal area).
pub fn mean_over_triangle(c: &[[f64; 3]; 3], levels: u32, f: &dyn Fn([f64; 3]) -> f64) -> f64 {
    if levels == 0 {
        return f(std::array::from_fn(|a| (c[0][a] + c[1][a] + c[2][a]) / 3.0));
    }
    let mid = |i: usize, j: usize| std::array::from_fn::<f64, 3, _>(|a| 0.5 * (c[i][a] + c[j][a]));
    let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
    [[c[0], m01, m20], [m01, c[1], m12], [m20, m12, c[2]], [m01, m12, m20]].iter().map(|t| mean_over_triangle(t, levels - 1, f)).sum::<f64>() / 4.0
}

/// The least-squares plane of `f` over a triangle in the plane `z = 0`,
/// fitted at the centroids of [`mean_over_triangle`]`(c, levels, ..)`: its
/// slope `(d/dx, d/dy)` from the central moments, `cov(p, f) / var(p)`
/// solved over `x` and `y`, and the mean of `f`. What a leaf's measured
/// slope is checked against.
pub fn floor_plane(c: &[[f64; 3]; 3], levels: u32, f: &dyn Fn([f64; 3]) -> f64) -> ([f64; 2], f64) {
    let mean = |g: &dyn Fn([f64; 3]) -> f64| mean_over_triangle(c, levels, g);
    let (mx, my, mf) = (mean(&|p| p[0]), mean(&|p| p[1]), mean(f));
    let (sxx, sxy, syy) = (mean(&|p| (p[0] - mx).powi(2)), mean(&|p| (p[0] - mx) * (p[1] - my)), mean(&|p| (p[1] - my).powi(2)));
    let (sxf, syf) = (mean(&|p| (p[0] - mx) * (f(p) - mf)), mean(&|p| (p[1] - my) * (f(p) - mf)));
    let det = sxx * syy - sxy * sxy;
    ([(syy * sxf - sxy * syf) / det, (sxx * syf - sxy * sxf) / det], mf)
}

/// The factor from point `p` facing up (`+z`) to a square lamp facing down
/// at height `z`, `x, y in [lo, hi]`, by the midpoint rule over `n x n`
/// cells, leaving out the cells `blocked(p, q)` (`q` a cell's centre) says
/// are hidden: the quadrature reference of a floor shadowed by an occluder
/// that a test writes its own segment test for.
pub fn midpoint_square_lamp(p: [f64; 3], (lo, hi): (f64, f64), z: f64, n: usize, blocked: &dyn Fn([f64; 3], [f64; 3]) -> bool) -> f64 {
    let cell = (hi - lo) / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let q = [lo + (i as f64 + 0.5) * cell, lo + (j as f64 + 0.5) * cell, z];
            if !blocked(p, q) {
                let d = sub(q, p);
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                sum += d[2] * d[2] / (PI * r2 * r2) * cell * cell;
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_values() {
        // Howell's tabulated values: unit squares one apart 0.1998;
        // perpendicular unit squares sharing an edge 0.2000.
        assert!((parallel_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-4);
        assert!((perpendicular_rectangles(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-4);
        // A point under the middle of a square equals four corner squares.
        let centre = point_to_rectangle(0.0, 0.0, [-1.0, 1.0, -1.0, 1.0], 1.0);
        assert!((centre - 4.0 * point_to_corner_rectangle(1.0, 1.0, 1.0)).abs() < 1e-15);
        // Lambert's polygon formula agrees with the corner rectangles, and
        // clipping a square to the half-space through its middle halves it
        // for a point under that middle.
        let square = [[-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [-1.0, 1.0, 1.0]];
        assert!((lambert_polygon([0.0; 3], [0.0, 0.0, 1.0], &square) - centre).abs() < 1e-14);
        let corner = point_to_rectangle(0.3, -0.2, [-1.0, 1.0, -1.0, 1.0], 1.0);
        assert!((lambert_polygon([0.3, -0.2, 0.0], [0.0, 0.0, 1.0], &square) - corner).abs() < 1e-14);
        let half = clip_to_front(&square, [0.0; 3], [1.0, 0.0, 0.0]);
        assert_eq!(half.len(), 4);
        assert!((lambert_polygon([0.0; 3], [0.0, 0.0, 1.0], &half) - 0.5 * centre).abs() < 1e-14);
    }
}

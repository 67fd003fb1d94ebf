//! Closed-form answers from J. R. Howell's catalogue of radiation
//! configuration factors, implemented here from the catalogue's formulas,
//! independently of the stages' kernels.

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
    }
}

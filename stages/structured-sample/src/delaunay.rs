//! Delaunay triangulation of a surface's light-transfer samples in its
//! `(u, v)` plane (Bowyer-Watson: insert points one by one, remove the
//! triangles whose circumcircle holds the point, fan the hole's boundary
//! to it), the mesh the secondary emitter polygons are cut from. O(n²) in
//! the number of points, which is a few hundred per surface.

use glam::DVec2;

/// The triangles (point indices, counter-clockwise) of the Delaunay
/// triangulation of `points`, those of zero area dropped. Points are
/// inserted in their order, so the result is deterministic (cocircular
/// points, as on a regular lattice, are split the same way every run).
pub fn triangulate(points: &[DVec2]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    let (lo, hi) = points.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = 0.5 * (lo + hi);
    let size = (hi - lo).max_element().max(1e-300);
    // Coordinates relative to the centre, in units of the size: the
    // in-circle test then works on numbers near 1.
    let mut all: Vec<DVec2> = points.iter().map(|p| (*p - centre) / size).collect();
    // A super-triangle far enough out that no circumcircle of real points
    // is cut by it in practice.
    all.extend([DVec2::new(-1e3, -1e3), DVec2::new(1e3, -1e3), DVec2::new(0.0, 1e3)]);
    let mut triangles: Vec<[usize; 3]> = vec![[n, n + 1, n + 2]];
    for (p, &point) in all.iter().enumerate().take(n) {
        let (bad, good): (Vec<[usize; 3]>, Vec<[usize; 3]>) = triangles.into_iter().partition(|t| in_circumcircle(&all, t, point));
        triangles = good;
        let mut edges: Vec<[usize; 2]> = Vec::new();
        for t in &bad {
            for k in 0..3 {
                let e = [t[k], t[(k + 1) % 3]];
                match edges.iter().position(|f| f[0] == e[1] && f[1] == e[0]) {
                    Some(shared) => {
                        edges.swap_remove(shared);
                    }
                    None => edges.push(e),
                }
            }
        }
        triangles.extend(edges.into_iter().map(|e| [e[0], e[1], p]));
    }
    triangles.retain(|t| t.iter().all(|&k| k < n) && signed_area(&all, t) > 1e-14);
    triangles
}

fn signed_area(points: &[DVec2], t: &[usize; 3]) -> f64 {
    0.5 * (points[t[1]] - points[t[0]]).perp_dot(points[t[2]] - points[t[0]])
}

/// Whether `p` lies strictly inside the circumcircle of the
/// counter-clockwise triangle `t`.
fn in_circumcircle(points: &[DVec2], t: &[usize; 3], p: DVec2) -> bool {
    let [a, b, c] = t.map(|k| points[k] - p);
    let det = (a.length_squared()) * b.perp_dot(c) - (b.length_squared()) * a.perp_dot(c) + (c.length_squared()) * a.perp_dot(b);
    det > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lattice_is_covered_once_and_empty_circles_hold() {
        let points: Vec<DVec2> = (0..5).flat_map(|i| (0..4).map(move |j| DVec2::new(i as f64 * 0.5, j as f64 * 0.3 + 0.01 * (i * j) as f64))).collect();
        let triangles = triangulate(&points);
        let area: f64 = triangles.iter().map(|t| signed_area(&points, t)).sum();
        // The convex hull of the slightly sheared lattice.
        let hull = 0.5 * ((2.0 * 0.9) + (2.0 * (0.9 + 0.12)));
        assert!((area - hull).abs() < 1e-12, "{area} vs {hull}");
        assert_eq!(triangles.len(), 2 * 4 * 3);
        for t in &triangles {
            for (k, p) in points.iter().enumerate() {
                if !t.contains(&k) {
                    assert!(!in_circumcircle(&points, t, *p), "point {k} inside the circle of {t:?}");
                }
            }
        }
    }
}

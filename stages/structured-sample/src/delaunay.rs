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
///
/// The in-circle and orientation tests are exact ([`Quantised`]): with
/// them in floating point, the triangles whose circumcircle held a point
/// need not form a hole that point sees whole, and the fan then
/// overlapped what was left. Isolux contours round a lamp centred over a
/// panel are rings of nearly cocircular samples: one face of a two-sided
/// panel (612 samples, 1.44 m²) came out as 265,264 triangles covering
/// 207 m², its polygons shot far more than they received, and the
/// shooting's unshot power grew to 47 times the emitted power, where its
/// other face, the same samples mirrored, gave 1,206 triangles covering
/// 1.44 m².
pub fn triangulate(points: &[DVec2]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    let (lo, hi) = points.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = 0.5 * (lo + hi);
    let size = (hi - lo).max_element().max(1e-300);
    // Coordinates relative to the centre, in units of the size, within
    // [-1/2, 1/2], and a super-triangle far enough out that no
    // circumcircle of real points is cut by it in practice.
    let mut scaled: Vec<DVec2> = points.iter().map(|p| (*p - centre) / size).collect();
    scaled.extend([DVec2::new(-SUPER, -SUPER), DVec2::new(SUPER, -SUPER), DVec2::new(0.0, SUPER)]);
    let all: Vec<Quantised> = scaled.iter().map(|&p| Quantised::of(p)).collect();
    let mut triangles: Vec<[usize; 3]> = vec![[n, n + 1, n + 2]];
    for (p, &point) in all.iter().enumerate().take(n) {
        let (mut bad, mut good): (Vec<[usize; 3]>, Vec<[usize; 3]>) = triangles.into_iter().partition(|t| point.in_circumcircle(t.map(|k| all[k])));
        // The hole's boundary, each edge seen from the point on its left;
        // an edge the point does not see so (it lies on the edge's line)
        // takes the triangle beyond it into the hole.
        let edges = loop {
            let edges = boundary(&bad);
            let Some(blocked) = edges.iter().find(|e| Quantised::orientation(all[e[0]], all[e[1]], point) <= 0) else { break edges };
            match good.iter().position(|t| (0..3).any(|k| t[k] == blocked[1] && t[(k + 1) % 3] == blocked[0])) {
                Some(k) => bad.push(good.swap_remove(k)),
                None => break edges,
            }
        };
        triangles = good;
        triangles.extend(edges.into_iter().filter(|e| Quantised::orientation(all[e[0]], all[e[1]], point) > 0).map(|e| [e[0], e[1], p]));
    }
    triangles.retain(|t| t.iter().all(|&k| k < n) && signed_area(&scaled, t) > 1e-14);
    triangles
}

/// How far out the super-triangle's corners lie, in units of the points'
/// extent.
const SUPER: f64 = 1e3;

/// Steps of the grid the points are rounded to, per unit of their extent:
/// 2^20, a millionth of it (samples nearer than that count as one, and
/// only the first joins the triangulation).
const GRID: f64 = (1u64 << 20) as f64;

/// A point rounded to [`GRID`]: coordinates within `SUPER * GRID` < 2^30,
/// so that the in-circle determinant's products (under 2^123) are exact in
/// `i128`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Quantised([i64; 2]);

impl Quantised {
    fn of(p: DVec2) -> Self {
        Quantised([(p.x * GRID).round() as i64, (p.y * GRID).round() as i64])
    }

    /// Twice the signed area of `(a, b, c)`: > 0 counter-clockwise.
    fn orientation(a: Quantised, b: Quantised, c: Quantised) -> i128 {
        let (u, v) = (a.to(b), a.to(c));
        u[0] * v[1] - u[1] * v[0]
    }

    /// `other - self`.
    fn to(self, other: Quantised) -> [i128; 2] {
        [i128::from(other.0[0] - self.0[0]), i128::from(other.0[1] - self.0[1])]
    }

    /// Whether this point lies strictly inside the circumcircle of the
    /// counter-clockwise triangle `t`.
    fn in_circumcircle(self, t: [Quantised; 3]) -> bool {
        let [a, b, c] = t.map(|v| self.to(v));
        let length = |v: [i128; 2]| v[0] * v[0] + v[1] * v[1];
        let cross = |u: [i128; 2], v: [i128; 2]| u[0] * v[1] - u[1] * v[0];
        length(a) * cross(b, c) - length(b) * cross(a, c) + length(c) * cross(a, b) > 0
    }
}

/// The edges of the triangles `hole` that no other of them shares (each
/// in its triangle's direction).
fn boundary(hole: &[[usize; 3]]) -> Vec<[usize; 2]> {
    let mut edges: Vec<[usize; 2]> = Vec::new();
    for t in hole {
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
    edges
}

fn signed_area(points: &[DVec2], t: &[usize; 3]) -> f64 {
    0.5 * (points[t[1]] - points[t[0]]).perp_dot(points[t[2]] - points[t[0]])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `p` lies inside the circumcircle of the counter-clockwise
    /// triangle `(a, b, c)` by more than `slack` (the test's own formula,
    /// in floating point).
    fn inside(a: DVec2, b: DVec2, c: DVec2, p: DVec2, slack: f64) -> bool {
        let [a, b, c] = [a - p, b - p, c - p];
        a.length_squared() * b.perp_dot(c) - b.length_squared() * a.perp_dot(c) + c.length_squared() * a.perp_dot(b) > slack
    }

    /// Covered once (every triangle counter-clockwise, their areas summing
    /// to the hull's `hull`) and the empty-circle property.
    fn check(points: &[DVec2], triangles: &[[usize; 3]], hull: f64) {
        let area: f64 = triangles.iter().map(|t| signed_area(points, t)).sum();
        assert!(triangles.iter().all(|t| signed_area(points, t) > 0.0));
        assert!((area - hull).abs() < 1e-9 * hull, "{area} vs {hull}, {} triangles", triangles.len());
        for t in triangles {
            for (k, p) in points.iter().enumerate() {
                if !t.contains(&k) {
                    assert!(!inside(points[t[0]], points[t[1]], points[t[2]], *p, 1e-12), "point {k} inside the circle of {t:?}");
                }
            }
        }
    }

    #[test]
    fn a_lattice_is_covered_once_and_empty_circles_hold() {
        let points: Vec<DVec2> = (0..5).flat_map(|i| (0..4).map(move |j| DVec2::new(i as f64 * 0.5, j as f64 * 0.3 + 0.01 * (i * j) as f64))).collect();
        let triangles = triangulate(&points);
        // The convex hull of the slightly sheared lattice.
        check(&points, &triangles, 0.5 * ((2.0 * 0.9) + (2.0 * (0.9 + 0.12))));
        assert_eq!(triangles.len(), 2 * 4 * 3);
    }

    /// The area of the convex hull of `points` (the test's own monotone
    /// chain).
    fn hull_area(points: &[DVec2]) -> f64 {
        let mut sorted = points.to_vec();
        sorted.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        let half = |points: &mut dyn Iterator<Item = DVec2>| {
            let mut chain: Vec<DVec2> = Vec::new();
            for p in points {
                while chain.len() >= 2 && (chain[chain.len() - 1] - chain[chain.len() - 2]).perp_dot(p - chain[chain.len() - 2]) <= 0.0 {
                    chain.pop();
                }
                chain.push(p);
            }
            chain.pop();
            chain
        };
        let hull: Vec<DVec2> = half(&mut sorted.iter().copied()).into_iter().chain(half(&mut sorted.iter().rev().copied())).collect();
        0.5 * (0..hull.len()).map(|i| hull[i].perp_dot(hull[(i + 1) % hull.len()])).sum::<f64>()
    }

    /// Seven samples of isolux rings round a lamp centred over one face
    /// of a two-sided panel (the end-to-end test `gpu_elements_two_sided`'s
    /// scene, the few of its 612 that still fail): nearly cocircular, they
    /// made the floating-point in-circle test contradict itself, and the
    /// triangles covered 1.6 times their hull (the whole face: 144 times).
    #[test]
    fn nearly_cocircular_samples_are_covered_once() {
        let bits: [(u64, u64); 7] = [
            (0x3fe71772f338ce6d, 0x3fe59999a8000000),
            (0x3fe59999a8000000, 0x3fe71772f338ce6d),
            (0x3fe71772f338ce6c, 0x3fe0ccccd8000000),
            (0x3fde9de7198e6327, 0x3fe59999a8000000),
            (0x3fde9de7198e6327, 0x3fe0ccccd8000000),
            (0x3fe74700a1bdd870, 0x3fe5333341555556),
            (0x3fde3ecbbc844f21, 0x3fe5333341555556),
        ];
        let points: Vec<DVec2> = bits.iter().map(|&(x, y)| DVec2::new(f64::from_bits(x), f64::from_bits(y))).collect();
        let triangles = triangulate(&points);
        check(&points, &triangles, hull_area(&points));
    }

    /// Isolux contours round a lamp centred over a square: rings of points
    /// nearly cocircular (each ring's points on one circle up to
    /// rounding), inside a square of edge samples, in two frames (one
    /// mirrored). Covered once, as many triangles as Euler's formula
    /// gives (`2n - 2 - h` for `n` points, `h` on the hull).
    #[test]
    fn rings_of_cocircular_points_are_covered_once() {
        for mirror in [1.0, -1.0] {
            let mut points: Vec<DVec2> = (0..16).flat_map(|k| {
                let t = k as f64 / 16.0;
                [DVec2::new(t, 0.0), DVec2::new(1.0, t), DVec2::new(1.0 - t, 1.0), DVec2::new(0.0, 1.0 - t)]
            }).collect();
            for ring in 1..=11 {
                let count = 8 * ring;
                let radius = 0.042 * ring as f64;
                points.extend((0..count).map(|j| {
                    let angle = std::f64::consts::TAU * (j as f64 + 0.5) / count as f64;
                    DVec2::new(0.5 + radius * angle.cos(), 0.5 + radius * angle.sin())
                }));
            }
            let points: Vec<DVec2> = points.into_iter().map(|p| DVec2::new(mirror * (p.x - 0.5) * 1.2, (p.y - 0.5) * 1.2)).collect();
            let triangles = triangulate(&points);
            check(&points, &triangles, 1.44);
            assert_eq!(triangles.len(), 2 * points.len() - 2 - 64);
        }
    }
}

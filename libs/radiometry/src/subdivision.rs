//! Regular 1:4 subdivision of triangles in barycentric coordinates, shared by
//! the solver (which refines elements) and the gather (which finds the leaf
//! element under a hit point).
//!
//! An element is given by the barycentric `(u, v)` of its three corners in
//! its input triangle. Its children are the three corner triangles and the
//! middle one, in this order, all with the parent's winding:
//!
//! ```text
//! child 0: [c0, m01, m20]   child 1: [m01, c1, m12]
//! child 2: [m20, m12, c2]   child 3: [m12, m20, m01]
//! ```

/// Barycentric `(u, v)` corners of an element.
pub type Corners = [[f64; 2]; 3];

/// The corners of an input triangle.
pub const ROOT: Corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

fn midpoint(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// The four children of an element, in the order documented above.
pub fn children(c: &Corners) -> [Corners; 4] {
    let (m01, m12, m20) = (midpoint(c[0], c[1]), midpoint(c[1], c[2]), midpoint(c[2], c[0]));
    [[c[0], m01, m20], [m01, c[1], m12], [m20, m12, c[2]], [m12, m20, m01]]
}

/// Which child contains the point with barycentric coordinates `local`
/// relative to the parent's corners, and its coordinates relative to that
/// child's corners. Points on a shared child border go to a corner child.
pub fn locate_child(local: [f64; 3]) -> (usize, [f64; 3]) {
    let [l0, l1, l2] = local;
    if l0 >= 0.5 {
        (0, [2.0 * l0 - 1.0, 2.0 * l1, 2.0 * l2])
    } else if l1 >= 0.5 {
        (1, [2.0 * l0, 2.0 * l1 - 1.0, 2.0 * l2])
    } else if l2 >= 0.5 {
        (2, [2.0 * l0, 2.0 * l1, 2.0 * l2 - 1.0])
    } else {
        (3, [1.0 - 2.0 * l0, 1.0 - 2.0 * l1, 1.0 - 2.0 * l2])
    }
}

/// The barycentric coordinates `[1 - u - v, u, v]` of the point `(u, v)`
/// of an input triangle, clamped onto the triangle (a ray hit's round-off
/// may fall just outside it) and renormalised; the centroid where nothing
/// is left (NaN coordinates).
pub fn clamped_local(uv: [f64; 2]) -> [f64; 3] {
    let local = [1.0 - uv[0] - uv[1], uv[0], uv[1]].map(|l| l.max(0.0));
    let sum: f64 = local.iter().sum();
    if sum > 0.0 {
        local.map(|l| l / sum)
    } else {
        [1.0 / 3.0; 3]
    }
}

/// The leaf element holding the point `(u, v)` of an input triangle
/// ([`clamped_local`]), descending from its root element `root` by
/// [`locate_child`]; `first_child(e)` is the first of element `e`'s four
/// consecutive children, `None` for a leaf. Also returns the point's
/// barycentric coordinates in the leaf.
pub fn leaf_holding(root: usize, uv: [f64; 2], first_child: impl Fn(usize) -> Option<usize>) -> (usize, [f64; 3]) {
    let (mut element, mut local) = (root, clamped_local(uv));
    while let Some(first) = first_child(element) {
        let (k, child_local) = locate_child(local);
        (element, local) = (first + k, child_local);
    }
    (element, local)
}

/// The point with local barycentric coordinates `local` in element `c`, as
/// `(u, v)` in the input triangle.
pub fn to_triangle_uv(c: &Corners, local: [f64; 3]) -> [f64; 2] {
    [
        local[0] * c[0][0] + local[1] * c[1][0] + local[2] * c[2][0],
        local[0] * c[0][1] + local[1] * c[1][1] + local[2] * c[2][1],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{square_to_triangle, Stream};

    #[test]
    fn located_child_maps_the_point_back_to_the_same_place() {
        let mut s = Stream::new(3, 0, 0);
        let parent = children(&children(&ROOT)[3])[1];
        for _ in 0..10_000 {
            let local = square_to_triangle(s.next_f64(), s.next_f64());
            let here = to_triangle_uv(&parent, local);
            let (k, child_local) = locate_child(local);
            assert!(child_local.iter().all(|&x| x >= -1e-12), "{child_local:?}");
            assert!((child_local.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let there = to_triangle_uv(&children(&parent)[k], child_local);
            assert!((here[0] - there[0]).abs() < 1e-12 && (here[1] - there[1]).abs() < 1e-12);
        }
    }

    /// A root split once, its middle child split again (elements 0, 1-4,
    /// 5-8): points land in the leaf whose corners hold them, with local
    /// coordinates that map back to the same `(u, v)`; a point off the
    /// triangle is clamped onto it, and NaN coordinates go to the centroid.
    #[test]
    fn the_leaf_holding_a_point_holds_it() {
        let corners = {
            let mut c = vec![ROOT];
            c.extend(children(&ROOT));
            c.extend(children(&c[4]));
            c
        };
        let first_child = |e: usize| match e {
            0 => Some(1),
            4 => Some(5),
            _ => None,
        };
        let mut s = Stream::new(5, 0, 0);
        for _ in 0..10_000 {
            let l = square_to_triangle(s.next_f64(), s.next_f64());
            let uv = [l[1], l[2]];
            let (leaf, local) = leaf_holding(0, uv, first_child);
            assert!(first_child(leaf).is_none() && local.iter().all(|&x| x >= -1e-12), "{leaf} {local:?}");
            let back = to_triangle_uv(&corners[leaf], local);
            assert!((back[0] - uv[0]).abs() < 1e-12 && (back[1] - uv[1]).abs() < 1e-12);
        }
        assert_eq!(clamped_local([0.5, 0.5 + 1e-12]), [0.0, 0.5 / (1.0 + 1e-12), (0.5 + 1e-12) / (1.0 + 1e-12)]);
        assert_eq!(clamped_local([-1.0, -1.0]).map(|x| x * 3.0), [3.0, 0.0, 0.0]);
        assert_eq!(clamped_local([f64::NAN; 2]), [1.0 / 3.0; 3]);
    }

    #[test]
    fn children_tile_the_parent_with_a_quarter_area_each() {
        let area = |c: &Corners| 0.5 * ((c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]));
        for child in children(&ROOT) {
            assert_eq!(area(&child), 0.125, "same winding, a quarter of 0.5");
        }
    }
}

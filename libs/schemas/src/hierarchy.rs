//! The element hierarchy of a [`Solution`] checked against the mesh it
//! claims to belong to, beyond what reading the file checks (see
//! `Solution::read`): the roots are the mesh's triangles, and every
//! element's stored corners are the ones the subdivision rule gives.

use crate::solution::{Solution, NONE};

/// Barycentric `(u, v)` corners of an element in its input triangle.
type Corners = [[f64; 2]; 3];

/// Largest difference allowed between a stored corner and the rule's.
const CORNER_TOLERANCE: f64 = 1e-6;

/// One leaf element of a checked hierarchy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leaf {
    /// Element index in the solution.
    pub element: u32,
    /// Mesh triangle.
    pub triangle: u32,
    /// Subdivision depth.
    pub level: u32,
    /// Barycentric corners in the triangle, from the subdivision rule (not
    /// the stored f32 corners, which match them within 1e-6).
    pub corners: Corners,
}

impl Solution {
    /// The leaves of the hierarchy below every input triangle, triangle by
    /// triangle in depth-first order (children in order), with their
    /// corners from `root` (an input triangle's corners) and `split` (the
    /// four children of an element, in the order the file stores them: the
    /// 1:4 rule, `radiometry::subdivision::children`); checks on the way
    /// that the hierarchy is the one the rule and a mesh with
    /// `triangle_count` triangles give. The error says what does not fit.
    pub fn leaves(&self, triangle_count: usize, root: Corners, split: impl Fn(&Corners) -> [Corners; 4]) -> std::result::Result<Vec<Leaf>, String> {
        let elements = &self.elements;
        let n = elements.len();
        if n < triangle_count {
            return Err(format!("it has {n} elements, fewer than the mesh's {triangle_count} triangles"));
        }
        for (i, e) in elements.iter().enumerate() {
            if e.triangle as usize >= triangle_count {
                return Err(format!("element {i} lies on triangle {}, but the mesh has {triangle_count} triangles", e.triangle));
            }
            let is_root = i < triangle_count;
            if is_root && (e.triangle as usize != i || e.parent != NONE || e.level != 0) {
                return Err(format!("element {i} should be input triangle {i} (level 0, no parent), found triangle {} level {}", e.triangle, e.level));
            }
            if !is_root && e.parent == NONE {
                return Err(format!("element {i} has no parent but is not one of the mesh's {triangle_count} triangles"));
            }
        }
        let mut all = Vec::new();
        let mut reached = 0;
        for t in 0..triangle_count as u32 {
            reached += self.leaves_below(t, root, &split, &mut all)?;
        }
        if reached != n {
            return Err(format!("{} of its {n} elements lie below no input triangle", n - reached));
        }
        Ok(all)
    }

    /// Appends the leaves below root element `t` to `leaves`; returns the
    /// number of elements visited.
    fn leaves_below(&self, t: u32, root: Corners, split: &impl Fn(&Corners) -> [Corners; 4], leaves: &mut Vec<Leaf>) -> std::result::Result<usize, String> {
        let elements = &self.elements;
        let mut stack = vec![(t, root)];
        let mut visited = 0;
        while let Some((i, corners)) = stack.pop() {
            visited += 1;
            let e = &elements[i as usize];
            let stored_fits = e.corners.iter().zip(&corners).all(|(s, c)| {
                (f64::from(s[0]) - c[0]).abs() <= CORNER_TOLERANCE && (f64::from(s[1]) - c[1]).abs() <= CORNER_TOLERANCE
            });
            if !stored_fits {
                return Err(format!("element {i} has corners {:?}, but the 1:4 rule gives {corners:?}", e.corners));
            }
            if e.is_leaf() {
                leaves.push(Leaf { element: i, triangle: t, level: e.level, corners });
                continue;
            }
            let first = e.first_child as usize;
            if first + 4 > elements.len() {
                return Err(format!("element {i} has children beyond the element table"));
            }
            // Pushed in reverse so that children are visited in order.
            for (k, child_corners) in split(&corners).into_iter().enumerate().rev() {
                let c = &elements[first + k];
                if c.parent != i || c.triangle != t || c.level != e.level + 1 {
                    return Err(format!(
                        "element {} is listed as child {k} of element {i} but names parent {}, triangle {}, level {}",
                        first + k,
                        c.parent,
                        c.triangle,
                        c.level
                    ));
                }
                stack.push(((first + k) as u32, child_corners));
            }
        }
        Ok(visited)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::{Provenance, Schema};
    use crate::solution::Element;

    const ROOT: Corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

    /// The 1:4 rule written out: corner children 0-2, the middle one 3.
    fn split(c: &Corners) -> [Corners; 4] {
        let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let (m01, m12, m20) = (mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0]));
        [[c[0], m01, m20], [m01, c[1], m12], [m20, m12, c[2]], [m12, m20, m01]]
    }

    /// Two input triangles; the second split once (elements 2..6).
    fn solution() -> Solution {
        let element = |triangle, parent, first_child, level, corners: Corners| Element {
            triangle,
            parent,
            first_child,
            level,
            corners: corners.map(|c| c.map(|x| x as f32)),
            area: 0.5,
            radiosity: [1.0; 3],
        };
        let mut elements = vec![element(0, NONE, NONE, 0, ROOT), element(1, NONE, 2, 0, ROOT)];
        elements.extend(split(&ROOT).map(|c| element(1, 1, NONE, 1, c)));
        Solution { header: Solution::header(Provenance::in_memory("test")), elements, clusters: vec![], links: vec![], slopes: vec![] }
    }

    #[test]
    fn leaves_come_triangle_by_triangle_with_the_rules_corners() {
        let leaves = solution().leaves(2, ROOT, split).unwrap();
        let got: Vec<(u32, u32, u32)> = leaves.iter().map(|l| (l.element, l.triangle, l.level)).collect();
        assert_eq!(got, [(0, 0, 0), (2, 1, 1), (3, 1, 1), (4, 1, 1), (5, 1, 1)]);
        assert_eq!(leaves[4].corners, [[0.5, 0.5], [0.0, 0.5], [0.5, 0.0]]);
    }

    #[test]
    fn a_hierarchy_that_does_not_fit_the_mesh_or_the_rule_is_refused() {
        let refused = |triangles: usize, edit: &dyn Fn(&mut Solution)| {
            let mut s = solution();
            edit(&mut s);
            s.leaves(triangles, ROOT, split).unwrap_err()
        };
        assert!(refused(7, &|_| {}).contains("it has 6 elements, fewer than the mesh's 7 triangles"));
        assert!(refused(3, &|_| {}).contains("element 2 should be input triangle 2"));
        assert!(refused(1, &|_| {}).contains("element 1 lies on triangle 1, but the mesh has 1 triangles"));
        assert!(refused(2, &|s| s.elements[3].corners[0] = [0.25, 0.0]).contains("element 3 has corners"));
        assert!(refused(2, &|s| s.elements[4].level = 2).contains("element 4 is listed as child 2 of element 1"));
        assert!(refused(2, &|s| s.elements[1].first_child = NONE).contains("4 of its 6 elements lie below no input triangle"));
    }
}

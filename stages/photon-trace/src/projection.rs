//! The photon mesh's vertex values as the L2 projection of the photons'
//! irradiance onto the linear hat functions, not its lumped estimate.
//!
//! A vertex's tally is the load `b_v = sum_hits l_v(x) Phi`, an unbiased
//! estimate of `integral l_v E dA`. The lumped estimate ([`crate::tally`])
//! divides it by the hat's area, `E_v = b_v / integral l_v dA`: the mean of
//! `E` under the hat, exact for constant light only. On a surface's border
//! the hat lies on the inward side alone, so a border vertex takes the
//! light of the inside, and the linear interpolant between vertices
//! smooths again what the hats smoothed once: on the built-in Cornell box
//! the two triangles of a block's face came out up to 18% apart from
//! hierarchical-solve's, in opposite directions, and the image 4.5% off
//! Mitsuba's.
//!
//! The projection solves `M e = b` with the consistent mass matrix `M_uv
//! = integral l_u l_v dA` (over the open part of each leaf,
//! [`crate::exposure`]), so the interpolant `sum e_v l_v` has the same
//! integral against every hat as the photons: it keeps each surface's
//! power (the rows of `M` sum to the hat areas) and reproduces a linear
//! irradiance exactly. It is Galerkin's projection, as a hierarchical
//! solver's element values are. The price is noise: `M^-1 H` (`H` the hat
//! areas, the lumped operator) has its eigenvalues in `[1/2, 2]` on a
//! triangle mesh, so the vertex-to-vertex part of the noise grows by up
//! to 2. Values the projection takes below 0 next to a sharp drop (an
//! overshoot of the linear fit) are set to 0.
//!
//! Solved by conjugate gradients preconditioned by the diagonal, whose
//! condition number on these matrices is at most 4 (each element's `D^-1
//! M_e` has eigenvalues 2, 1/2, 1/2): each halving of the residual costs
//! about one iteration.

use crate::exposure;
use crate::mesh::{Elements, Vertices};
use radiometry::geometry::TriangleGeometry;

/// Residual, relative to the load's, at which the shown values' solve
/// stops.
pub const TOLERANCE: f64 = 1e-10;

/// Residual at which a batch's solve for the variance stops
/// ([`crate::tally`]): its error is a ten-thousandth of the batch's own
/// value, far under the spread between batches.
pub const VARIANCE_TOLERANCE: f64 = 1e-4;

/// The consistent mass matrix of the photon mesh's hat functions, in
/// compressed rows, with the inverse of its diagonal and its row sums
/// (the hat areas).
#[derive(Clone, Debug)]
pub struct MassMatrix {
    /// Row `v`'s entries are `entries[start[v]..start[v + 1]]`.
    start: Vec<usize>,
    /// `(column, value)`, sorted by column within a row.
    entries: Vec<(u32, f64)>,
    /// `1 / M_vv`, 0 for an empty row.
    inverse_diagonal: Vec<f64>,
    /// `sum_u M_vu`, the open area of `v`'s hat.
    row_sum: Vec<f64>,
}

impl MassMatrix {
    /// `M_uv = integral l_u l_v dA` over the open part of the leaves
    /// (`open`, per element, [`exposure::Exposure`]): the exact element
    /// matrix `A/12 (1 + [u = v])` for a leaf open all over, the burial
    /// points' rule `A/16 sum_open l_u l_v` for one partly buried.
    pub fn new(geometry: &[TriangleGeometry], elements: &Elements, vertices: &Vertices, open: &[u16]) -> Self {
        let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); vertices.len()];
        for (e, element) in elements.elements.iter().enumerate() {
            if !element.is_leaf() || open[e] == 0 {
                continue;
            }
            let area = elements.area(geometry, e);
            let corners = vertices.of_element[e];
            for a in 0..3 {
                for b in 0..3 {
                    let m = if open[e] == exposure::ALL_OPEN {
                        area / 12.0 * if a == b { 2.0 } else { 1.0 }
                    } else {
                        exposure::open_points(open[e]).map(|l| l[a] * l[b]).sum::<f64>() * area / exposure::POINTS as f64
                    };
                    rows[corners[a] as usize].push((corners[b], m));
                }
            }
        }
        Self::from_rows(rows)
    }

    /// The matrix of `rows` (entries in any order, repeated columns added).
    fn from_rows(mut rows: Vec<Vec<(u32, f64)>>) -> Self {
        let (mut start, mut entries) = (vec![0], Vec::new());
        for row in &mut rows {
            row.sort_unstable_by_key(|&(c, _)| c);
            let first = entries.len();
            for &(c, m) in row.iter() {
                let in_row = entries.len() > first;
                match entries.last_mut() {
                    Some((last, sum)) if in_row && *last == c => *sum += m,
                    _ => entries.push((c, m)),
                }
            }
            start.push(entries.len());
        }
        let row = |v: usize| &entries[start[v]..start[v + 1]];
        let inverse_diagonal = (0..rows.len()).map(|v| row(v).iter().find(|&&(c, _)| c as usize == v).map_or(0.0, |&(_, m)| 1.0 / m)).collect();
        let row_sum = (0..rows.len()).map(|v| row(v).iter().map(|&(_, m)| m).sum()).collect();
        MassMatrix { start, entries, inverse_diagonal, row_sum }
    }

    /// `y = M x`.
    fn times(&self, x: &[f64], y: &mut [f64]) {
        for (v, y) in y.iter_mut().enumerate() {
            *y = self.entries[self.start[v]..self.start[v + 1]].iter().map(|&(c, m)| m * x[c as usize]).sum();
        }
    }

    /// A matrix with the hat areas `hat_area` on its diagonal: the lumped
    /// estimate's, whose projection changes nothing.
    #[cfg(test)]
    pub fn lumped(hat_area: &[f64]) -> Self {
        Self::from_rows(hat_area.iter().enumerate().map(|(v, &a)| vec![(v as u32, a)]).collect())
    }

    /// The projection of the irradiance whose lumped estimates are
    /// `lumped`: `M^-1 (H lumped)`, `H` the hat areas, which are `M`'s row
    /// sums (so a constant maps to itself), each channel, negative values
    /// set to 0 (module docs). Vertices without a hat (`M`'s empty rows)
    /// get 0.
    pub fn project(&self, lumped: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; lumped.len()];
        for c in 0..3 {
            let load: Vec<f64> = (0..lumped.len()).map(|v| self.row_sum[v] * lumped[v][c]).collect();
            for (o, x) in out.iter_mut().zip(self.solve(&load, TOLERANCE)) {
                o[c] = x.max(0.0);
            }
        }
        out
    }

    /// `M x = load` by diagonally preconditioned conjugate gradients
    /// (module docs), from the lumped estimate `load / H`, until the
    /// residual is `tolerance` of the load's; 0 where `M`'s row is empty.
    pub fn solve(&self, load: &[f64], tolerance: f64) -> Vec<f64> {
        let n = load.len();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
        let mut x: Vec<f64> = (0..n).map(|v| if self.row_sum[v] > 0.0 { load[v] / self.row_sum[v] } else { 0.0 }).collect();
        let mut q = vec![0.0; n];
        self.times(&x, &mut q);
        let mut r: Vec<f64> = (0..n).map(|v| if self.inverse_diagonal[v] > 0.0 { load[v] - q[v] } else { 0.0 }).collect();
        let goal = tolerance * dot(load, load).sqrt();
        let mut z: Vec<f64> = r.iter().zip(&self.inverse_diagonal).map(|(r, d)| r * d).collect();
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        for _ in 0..n.max(1) {
            if dot(&r, &r).sqrt() <= goal {
                break;
            }
            self.times(&p, &mut q);
            let alpha = rz / dot(&p, &q);
            for v in 0..n {
                x[v] += alpha * p[v];
                r[v] -= alpha * q[v];
                z[v] = r[v] * self.inverse_diagonal[v];
            }
            let next = dot(&r, &z);
            let beta = next / rz;
            rz = next;
            for v in 0..n {
                p[v] = z[v] + beta * p[v];
            }
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exposure::ALL_OPEN;
    use glam::DVec3;
    use schemas::header::{Provenance, Schema};
    use schemas::mesh::{Mesh, Triangle};
    use stage_kit::scene::mesh_triangles;

    /// The unit square as two triangles, split twice (32 leaves, 25
    /// vertices).
    fn square() -> (Vec<TriangleGeometry>, Elements, Vertices) {
        let tri = |vertices: [u32; 3]| Triangle { vertices, material: 0, object: 0, area: 0.5, normal: [0.0, 0.0, 1.0] };
        let mesh = Mesh {
            header: Mesh::header(Provenance::in_memory("test")),
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![tri([0, 1, 2]), tri([0, 2, 3])],
        };
        let geometry = mesh_triangles(&mesh);
        let mut elements = Elements::new(&mesh);
        for _ in 0..2 {
            for e in 0..elements.elements.len() {
                if elements.elements[e].is_leaf() {
                    elements.split(e);
                }
            }
        }
        let vertices = Vertices::new(&mesh, &geometry, &elements, &vec![ALL_OPEN; elements.elements.len()], 0.5);
        (geometry, elements, vertices)
    }

    #[test]
    fn a_linear_irradiance_is_projected_exactly_where_the_lumped_estimate_misses_the_border() {
        let (geometry, elements, vertices) = square();
        assert_eq!(vertices.len(), 25);
        let open = vec![ALL_OPEN; elements.elements.len()];
        let m = MassMatrix::new(&geometry, &elements, &vertices, &open);
        let e = |p: DVec3| 1.0 + 2.0 * p.x + 0.5 * p.y;
        // The load integral l_v E dA, exact for the linear E by the
        // midpoint rule on each leaf's edges, and the lumped estimate.
        let mut load = vec![0.0; vertices.len()];
        for (k, element) in elements.elements.iter().enumerate().filter(|(_, el)| el.is_leaf()) {
            let w = geometry[element.triangle as usize].element(&elements.corners[k]);
            let area = 0.5 / 4f64.powi(element.level as i32);
            for (a, &v) in vertices.of_element[k].iter().enumerate() {
                // l_a E is quadratic: the mean of its values at the edge
                // midpoints, where l_a is 1/2 on the two edges at corner a.
                let mids = [(0, 1), (1, 2), (2, 0)].map(|(i, j)| (i == a || j == a, (w[i] + w[j]) / 2.0));
                load[v as usize] += area * mids.iter().map(|&(at_a, p)| if at_a { 0.5 * e(p) } else { 0.0 }).sum::<f64>() / 3.0;
            }
        }
        let lumped: Vec<[f64; 3]> = (0..vertices.len()).map(|v| [load[v] / vertices.hat_area[v]; 3]).collect();
        let projected = m.project(&lumped);
        let corner = (0..vertices.len()).find(|&v| vertices.position[v].length() < 1e-12).unwrap();
        for (v, (value, &p)) in projected.iter().zip(&vertices.position).enumerate() {
            assert!((value[0] - e(p)).abs() < 1e-9, "vertex {v}: {} vs {}", value[0], e(p));
        }
        // The corner's hat lies inward: the lumped estimate is the light
        // there, 1, plus a third of a leaf's width of the gradient.
        assert!(lumped[corner][0] - 1.0 > 0.05, "lumped corner {}", lumped[corner][0]);
    }
}

//! Closed-form radiosity per element, where a scene has one: the
//! integrating sphere.
//!
//! Inside a sphere the form factor from any point to any patch j is its
//! area fraction, `F_j = A_j / A` (the sphere's defining property), so
//! every surface receives the same irradiance `H = Σ_j B_j A_j / A`.
//! With one diffuse reflectance rho everywhere, the power balance
//! `Σ_j B_j A_j = Σ_j E_j A_j + rho H A` gives
//!
//! `H = Σ_j E_j A_j / (A (1 - rho))` and `B_i = E_i + rho H`,
//!
//! per colour channel, with `E` the emitted exitance (W/m²), `A_j` the
//! triangle areas (m²) and `A` their sum. The built-in `sphere-<n>` is a
//! geodesic polyhedron, not a sphere: a flat facet does not see itself
//! and its factors to the others deviate slightly from the area
//! fractions, so the closed form is exact only up to the faceting (the
//! end-to-end tests measured under 1% against converged solutions at 5k
//! triangles).
//!
//! The scene is recognised by its geometry, not its name: a watertight,
//! consistently wound mesh whose vertices all lie on one sphere, every
//! triangle facing its centre, one diffuse reflectance (per channel) and
//! nothing but diffuse reflection and emission. The closed box
//! (`box-<n>`) has a closed form only for its mean radiosity (energy
//! balance, `P / ((1 - rho) A)`), not per element: its walls differ
//! (corners are darker), so it has no per-element reference here and a
//! sweep of it falls through to the next kind of reference.

use schemas::header::{Provenance, Schema};
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::{Element, Solution};
use std::collections::HashMap;

/// Relative tolerance on the vertices' distance to the fitted centre.
pub const SPHERE_TOLERANCE: f64 = 1e-4;

/// The closed-form radiosity of each triangle (W/m², RGB) of an
/// integrating sphere, or why the scene is not one.
pub fn integrating_sphere(mesh: &Mesh, manifest: &Manifest) -> Result<Vec<[f64; 3]>, String> {
    if mesh.triangles.is_empty() {
        return Err("no triangles".into());
    }
    let e = &manifest.effects;
    if e.specular_reflection || e.specular_transmission || e.diffuse_transmission || e.goniometric_lights {
        return Err("the scene has more than diffuse reflection and emitting surfaces".into());
    }
    let rho = manifest.materials[mesh.triangles[0].material as usize].diffuse;
    if mesh.triangles.iter().any(|t| manifest.materials[t.material as usize].diffuse != rho) {
        return Err("the diffuse reflectance is not the same everywhere".into());
    }
    if rho.iter().any(|&r| !(0.0..1.0).contains(&r)) {
        return Err(format!("reflectance {rho:?} is not below 1"));
    }
    watertight(mesh)?;
    let (centre, radius) = fit_sphere(&mesh.positions).ok_or("the vertices are degenerate (coplanar)")?;
    let worst = mesh.positions.iter().map(|p| (distance(p, centre) - radius).abs() / radius).fold(0.0, f64::max);
    if worst > SPHERE_TOLERANCE {
        return Err(format!("the vertices are not on one sphere (worst relative deviation {worst:.1e})"));
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        let centroid = [0, 1, 2].map(|k| t.vertices.iter().map(|&v| f64::from(mesh.positions[v as usize][k])).sum::<f64>() / 3.0);
        let inward = (0..3).map(|k| f64::from(t.normal[k]) * (centre[k] - centroid[k])).sum::<f64>();
        if inward <= 0.0 {
            return Err(format!("triangle {i} faces away from the centre"));
        }
    }
    let statistics = &manifest.statistics;
    let irradiance: [f64; 3] = std::array::from_fn(|c| statistics.emitted_power[c] / (statistics.total_area * (1.0 - rho[c])));
    Ok(mesh
        .triangles
        .iter()
        .map(|t| {
            let emission = manifest.materials[t.material as usize].emission;
            std::array::from_fn(|c| emission[c] + rho[c] * irradiance[c])
        })
        .collect())
}

/// The closed form as a solution artifact: one leaf element per input
/// triangle with its constant radiosity, no links, so that `compare
/// solution.exr closed_form.exr` measures a solver per triangle
/// (area-weighted, leaves averaged over each triangle), with the
/// provenance of the run that computed it.
pub fn solution(mesh: &Mesh, radiosity: &[[f64; 3]], provenance: Provenance) -> Solution {
    let elements = mesh
        .triangles
        .iter()
        .zip(radiosity)
        .enumerate()
        .map(|(i, (t, b))| Element::root(i as u32, t.area, b.map(|x| x as f32)))
        .collect();
    Solution { header: Solution::header(provenance), elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() }
}

/// Every edge is shared by exactly two triangles that run along it in
/// opposite directions: the mesh is closed and consistently wound.
fn watertight(mesh: &Mesh) -> Result<(), String> {
    // Per undirected edge: how many triangles use it, and the sum of its
    // directions (+1 for low-to-high vertex index, -1 the other way).
    let mut edges: HashMap<(u32, u32), (u32, i32)> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t.vertices[k], t.vertices[(k + 1) % 3]);
            let edge = edges.entry((a.min(b), a.max(b))).or_default();
            edge.0 += 1;
            edge.1 += if a < b { 1 } else { -1 };
        }
    }
    match edges.iter().find(|(_, &(uses, direction))| uses != 2 || direction != 0) {
        Some(((a, b), (uses, _))) => Err(format!("not closed: edge {a}-{b} has {uses} triangle(s) or runs one way only")),
        None => Ok(()),
    }
}

/// The least-squares sphere through `points`: `|p|² = 2 p·c + d` solved
/// for the centre c and `d = r² - |c|²` by the normal equations, in f64.
fn fit_sphere(points: &[[f32; 3]]) -> Option<([f64; 3], f64)> {
    let mut m = [[0.0f64; 5]; 4];
    for p in points {
        let p = p.map(f64::from);
        let row = [2.0 * p[0], 2.0 * p[1], 2.0 * p[2], 1.0];
        let rhs = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += row[i] * row[j];
            }
            m[i][4] += row[i] * rhs;
        }
    }
    // Gauss-Jordan with partial pivoting on the 4 x 4 system.
    for col in 0..4 {
        let pivot = (col..4).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() < 1e-12 * (1.0 + m[col][col].abs()) {
            return None;
        }
        m.swap(col, pivot);
        let pivot_row = m[col];
        for (row, r) in m.iter_mut().enumerate() {
            if row != col {
                let f = r[col] / pivot_row[col];
                for (x, p) in r.iter_mut().zip(pivot_row).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let x: [f64; 4] = std::array::from_fn(|i| m[i][4] / m[i][i]);
    let centre = [x[0], x[1], x[2]];
    let r2 = x[3] + centre.iter().map(|c| c * c).sum::<f64>();
    (r2 > 0.0).then(|| (centre, r2.sqrt()))
}

fn distance(p: &[f32; 3], c: [f64; 3]) -> f64 {
    (0..3).map(|k| (f64::from(p[k]) - c[k]).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_sphere_has_the_closed_form_and_the_box_and_cornell_box_have_none() {
        let (mesh, manifest) = mesh_prep::prepare_builtin("sphere-300", "test").unwrap();
        let b = integrating_sphere(&mesh, &manifest).unwrap();
        let rho = 0.5;
        let (area, power) = (manifest.statistics.total_area, manifest.statistics.emitted_power[0]);
        let shell = rho * power / ((1.0 - rho) * area);
        for (t, b) in mesh.triangles.iter().zip(&b) {
            let emission = manifest.materials[t.material as usize].emission[0];
            assert!((b[0] - (emission + shell)).abs() <= 1e-9 * b[0] && b[0] > 0.0, "{b:?}");
        }
        // Power balance: what leaves is what is emitted plus what is reflected.
        let leaving: f64 = mesh.triangles.iter().zip(&b).map(|(t, b)| f64::from(t.area) * b[0]).sum();
        assert!((leaving - power / (1.0 - rho)).abs() < 1e-9 * leaving);
        for scene in ["box-100", "cornell-box"] {
            let (mesh, manifest) = mesh_prep::prepare_builtin(scene, "test").unwrap();
            let why = integrating_sphere(&mesh, &manifest).unwrap_err();
            eprintln!("{scene}: {why}");
        }
        // A sphere with one triangle missing is open.
        let (mut mesh, manifest) = mesh_prep::prepare_builtin("sphere-300", "test").unwrap();
        mesh.triangles.pop();
        assert!(integrating_sphere(&mesh, &manifest).unwrap_err().contains("not closed"));
    }

    #[test]
    fn the_sphere_fit_finds_centre_and_radius() {
        let c = [0.5, -2.0, 3.0];
        let points: Vec<[f32; 3]> = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.6, 0.0, -0.8]]
            .iter()
            .map(|d: &[f64; 3]| [0, 1, 2].map(|k| (c[k] + 2.0 * d[k]) as f32))
            .collect();
        let (centre, radius) = fit_sphere(&points).unwrap();
        assert!((0..3).all(|k| (centre[k] - c[k]).abs() < 1e-5), "{centre:?}");
        assert!((radius - 2.0).abs() < 1e-5, "{radius}");
        // Coplanar points fit no sphere.
        assert!(fit_sphere(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]).is_none());
    }
}

//! What the camera sees through mirrors and thin glass (issue 14 item 4).
//!
//! Paper 004 Sec. 4.3.3 renders view-dependent reflection maps because it
//! rasterises; this stage traces rays, so a camera ray that meets an ideal
//! specular surface is continued. A hit on triangle `t` carrying weight `w`
//! (RGB, 1 for the camera ray) adds `w L_d(hit)`, the surface's own diffuse
//! radiance (`B / pi`, black from behind), and spawns
//!
//! - on the front face, the mirror ray `d' = d - 2 (d . n) n` with weight
//!   `w rho_s`,
//! - on either face, the straight continuation with weight `w tau_s`: a
//!   thin plate, whose refraction bending is neglected (004 Sec. 4.3.2
//!   does the same for its transmissive nodes),
//!
//! so the pixel's radiance is `L = sum over the tree of w L_d`, i.e.
//! `L(x) = L_d(x) + rho_s L(x_r) + tau_s L(x_t)` recursively. A branch
//! stops after [`Specular::max_depth`] specular events or when its largest
//! channel weight falls under [`Specular::min_weight`]; what it would have
//! added is at most that weight times the radiance behind it.

use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::geometry::TriangleGeometry;
use radiometry::photometry::DirectLight;
use radiometry::rays::{Hit, SceneRays};
use crate::detail::Detail;
use crate::full_gather::Surface;
use crate::gouraud::{Gouraud, Smoothing};
use crate::senders::Senders;
use schemas::mesh::{Manifest, Mesh};

/// Ideal specular reflectance and transmittance of one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    /// `rho_s`, RGB.
    pub reflectance: [f64; 3],
    /// `tau_s`, RGB.
    pub transmittance: [f64; 3],
}

/// The specular surfaces of a scene and the bounds of the ray tree.
pub struct Specular {
    /// Per triangle, its coefficients if it is specular.
    per_triangle: Vec<Option<Coefficients>>,
    /// Most specular events along a path.
    pub max_depth: u32,
    /// Smallest largest-channel weight a branch is followed with.
    pub min_weight: f64,
    /// Rays start this far past the surface they leave, m (a millionth of
    /// the scene's bounding-box diagonal), so a coplanar neighbour of the
    /// triangle left is not hit at `t = 0`.
    t_min: f32,
}

/// One surface point a camera ray reaches, directly or through mirrors and
/// glass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seen {
    /// The hit.
    pub hit: Hit,
    /// The ray that found it: its origin and unit direction.
    pub origin: DVec3,
    /// Unit direction of that ray.
    pub direction: DVec3,
    /// Product of the specular coefficients along the path, RGB.
    pub weight: [f64; 3],
    /// Specular events before this hit (0: seen directly).
    pub depth: u32,
}

/// Work of the specular rays, for the report.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Followed {
    /// Rays cast past a specular surface.
    pub rays: u64,
    /// Branches stopped by the depth or weight bound while still carrying
    /// weight.
    pub truncated: u64,
}

impl Followed {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: Followed) {
        self.rays += o.rays;
        self.truncated += o.truncated;
    }
}

/// Writes the specular rays' work into a report's counters.
pub fn count(counters: &mut std::collections::BTreeMap<String, f64>, work: Followed) {
    counters.insert("specular_rays".into(), work.rays as f64);
    counters.insert("specular_branches_truncated".into(), work.truncated as f64);
}

impl Specular {
    /// The specular surfaces of `mesh`, or `None` when the scene has no
    /// specular reflection or transmission (then no code here runs).
    pub fn new(mesh: &Mesh, manifest: &Manifest, triangles: &[TriangleGeometry], max_depth: u32, min_weight: f64) -> Option<Specular> {
        let e = &manifest.effects;
        if !(e.specular_reflection || e.specular_transmission) {
            return None;
        }
        let per_triangle = mesh
            .triangles
            .iter()
            .map(|t| {
                let m = &manifest.materials[t.material as usize];
                let c = Coefficients { reflectance: m.specular_reflectance, transmittance: m.specular_transmittance };
                (c.reflectance.iter().chain(&c.transmittance).any(|&x| x > 0.0)).then_some(c)
            })
            .collect();
        let bounds = Aabb::around(triangles.iter().flat_map(|t| t.corners));
        let diagonal = if bounds.min.x.is_finite() { (bounds.max - bounds.min).length() } else { 1.0 };
        Some(Specular { per_triangle, max_depth, min_weight, t_min: (1e-6 * diagonal) as f32 })
    }

    /// Whether triangle `t` is specular.
    pub fn is_specular(&self, t: u32) -> bool {
        self.per_triangle[t as usize].is_some()
    }

    /// Visits every surface point the ray `origin + t direction` (unit
    /// direction), whose first hit is `first`, reaches through the
    /// specular surfaces (module docs), depth first, the direct hit first.
    pub fn follow(&self, rays: &SceneRays, triangles: &[TriangleGeometry], origin: DVec3, direction: DVec3, first: Hit, visit: &mut dyn FnMut(&Seen)) -> Followed {
        let mut work = Followed::default();
        let mut stack = vec![Seen { hit: first, origin, direction, weight: [1.0; 3], depth: 0 }];
        while let Some(seen) = stack.pop() {
            visit(&seen);
            let Some(c) = self.per_triangle[seen.hit.triangle as usize] else { continue };
            let n = triangles[seen.hit.triangle as usize].normal;
            let cos = seen.direction.dot(n);
            let point = seen.origin + seen.direction * f64::from(seen.hit.t);
            let reflected = seen.direction - 2.0 * cos * n;
            let branches = [(cos < 0.0, c.reflectance, reflected), (true, c.transmittance, seen.direction)];
            // Pushed in reverse, so the reflection is visited first.
            for (open, coefficient, direction) in branches.into_iter().rev() {
                let weight: [f64; 3] = std::array::from_fn(|k| seen.weight[k] * coefficient[k]);
                let largest = weight.iter().copied().fold(0.0, f64::max);
                if !open || largest <= 0.0 {
                    continue;
                }
                if seen.depth >= self.max_depth || largest < self.min_weight {
                    work.truncated += 1;
                    continue;
                }
                work.rays += 1;
                let skip = [seen.hit.triangle; 2];
                if let Some(hit) = rays.closest_hit(point, direction, self.t_min, f32::INFINITY, skip) {
                    stack.push(Seen { hit, origin: point, direction, weight, depth: seen.depth + 1 });
                }
            }
        }
        work
    }
}

/// The irradiance the solver's radiosity of each leaf holds beyond what
/// the links into it, its ancestors and clusters bring (the light
/// hierarchical-solve gathered through mirrors and glass by virtual
/// senders, which the solution's links do not carry), interpolated over
/// the surfaces like the preview's radiosity ([`Gouraud::of`]): per
/// channel `max(0, H_e - sum V E_unoccluded - E_lights)` (`V` as the
/// receiver's exposed part sees it,
/// [`crate::senders::Senders::exposed_visibility`], since `H_e` is the
/// exposed part's), `H_e = (B_e - E) / rho_e` the leaf's irradiance
/// (`rho_e` its texture average where `detail` has textures,
/// [`Detail::irradiance`]; 0 where `rho_e` is 0, such a leaf reflects
/// none of it). The full gather adds it to what it
/// gathers from the links. The solver's radiosity also holds the
/// goniometric lights' direct light, which the full gather adds per
/// point: `lights`' irradiance `E_lights` at the leaf's centroid is taken
/// off (the solver's is the leaf's mean).
#[allow(clippy::too_many_arguments)]
pub fn window_light(
    scene: &crate::Scene,
    triangles: &[TriangleGeometry],
    senders: &Senders,
    surfaces: &[Surface],
    detail: Option<&Detail>,
    lights: &DirectLight,
    smoothing: Smoothing,
) -> schemas::Result<Gouraud> {
    let materials: Vec<u32> = scene.mesh.triangles.iter().map(|t| t.material).collect();
    let solution = scene.solution;
    Gouraud::of(triangles, &materials, solution, scene.solution_path, smoothing, &|corners, e| {
        let centroid = [0, 1].map(|k| (0..3).map(|c| corners[c][k]).sum::<f64>() / 3.0);
        let mut links = Vec::new();
        senders.chain(e.triangle, centroid, &mut links);
        let t = &triangles[e.triangle as usize];
        let direct = if lights.lights.is_empty() { 0.0 } else { lights.at_point(t.point(centroid), t.normal, e.triangle).0 };
        let s = surfaces[e.triangle as usize];
        let b = e.radiosity.map(f64::from);
        let h: [f64; 3] = match detail {
            Some(detail) => detail.irradiance(e.triangle, corners, b, s.emission, s.reflectance),
            None => crate::detail::irradiance_of(b, s.emission, s.reflectance),
        };
        let from_links = |c: usize| links.iter().map(|&l| senders.exposed_visibility(l) * f64::from(solution.links[l].unoccluded_irradiance[c])).sum::<f64>();
        std::array::from_fn(|c| if h[c] > 0.0 { (h[c] - from_links(c) - direct).max(0.0) } else { 0.0 })
    }, &[])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    /// Two facing parallel mirrors of reflectance `rho` at z = 0 (facing
    /// up) and z = 1 (facing down), unit squares: a vertical ray bounces
    /// between them until the weight or depth bound.
    #[test]
    fn parallel_mirrors_give_the_geometric_series_to_the_bounds() {
        let square = |z: f64, up: bool| {
            let (a, b, c, d) = (dvec3(-1.0, -1.0, z), dvec3(1.0, -1.0, z), dvec3(1.0, 1.0, z), dvec3(-1.0, 1.0, z));
            if up {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, c, b], [a, d, c]]
            }
        };
        let corners: Vec<[DVec3; 3]> = square(0.0, true).into_iter().chain(square(1.0, false)).collect();
        let triangles: Vec<TriangleGeometry> = corners.iter().map(|&c| TriangleGeometry::new(c)).collect();
        let rays = SceneRays::new(&corners);
        let rho = 0.5;
        let c = Coefficients { reflectance: [rho; 3], transmittance: [0.0; 3] };
        let origin = dvec3(0.1, 0.2, 0.5);
        let direction = dvec3(0.0, 0.0, -1.0);
        let first = rays.closest_hit(origin, direction, 0.0, f32::INFINITY, [u32::MAX; 2]).unwrap();
        for (max_depth, min_weight, hits) in [(3, 0.0, 4), (20, 0.1, 4), (0, 0.0, 1)] {
            let specular = Specular { per_triangle: vec![Some(c); 4], max_depth, min_weight, t_min: 1e-6 };
            let mut seen = Vec::new();
            let work = specular.follow(&rays, &triangles, origin, direction, first, &mut |s| seen.push(*s));
            assert_eq!(seen.len(), hits, "depth {max_depth}, weight {min_weight}");
            for (k, s) in seen.iter().enumerate() {
                assert_eq!(s.depth, k as u32);
                assert!((s.weight[0] - rho.powi(k as i32)).abs() < 1e-15);
                // Alternately the bottom and the top mirror, at x, y kept.
                let p = s.origin + s.direction * f64::from(s.hit.t);
                assert!((p - dvec3(0.1, 0.2, (k % 2) as f64)).length() < 1e-5, "{p}");
            }
            assert_eq!((work.rays, work.truncated), (hits as u64 - 1, 1));
        }
    }

    /// A thin pane (tau 0.25, rho 0.5) seen from either side: the ray goes
    /// through with tau on both faces and reflects only off the front.
    #[test]
    fn a_pane_transmits_on_both_faces_and_reflects_on_its_front() {
        let corners = vec![
            [dvec3(-1.0, -1.0, 0.0), dvec3(1.0, -1.0, 0.0), dvec3(0.0, 1.0, 0.0)],
            [dvec3(-9.0, -9.0, -1.0), dvec3(9.0, -9.0, -1.0), dvec3(0.0, 9.0, -1.0)],
            [dvec3(-9.0, -9.0, 1.0), dvec3(0.0, 9.0, 1.0), dvec3(9.0, -9.0, 1.0)],
        ];
        let triangles: Vec<TriangleGeometry> = corners.iter().map(|&c| TriangleGeometry::new(c)).collect();
        let rays = SceneRays::new(&corners);
        let pane = Coefficients { reflectance: [0.5; 3], transmittance: [0.25; 3] };
        let specular = Specular { per_triangle: vec![Some(pane), None, None], max_depth: 4, min_weight: 0.0, t_min: 1e-6 };
        for (z, reached) in [(0.5f64, vec![(0u32, 1.0f64), (2, 0.5), (1, 0.25)]), (-0.5, vec![(0, 1.0), (2, 0.25)])] {
            let direction = dvec3(0.0, 0.0, -z.signum());
            let origin = dvec3(0.0, 0.0, z);
            let first = rays.closest_hit(origin, direction, 0.0, f32::INFINITY, [u32::MAX; 2]).unwrap();
            let mut seen = Vec::new();
            specular.follow(&rays, &triangles, origin, direction, first, &mut |s| seen.push((s.hit.triangle, s.weight[0])));
            assert_eq!(seen, reached, "from z = {z}");
        }
    }
}

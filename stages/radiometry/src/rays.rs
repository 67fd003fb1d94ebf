//! Ray casting over the scene's triangles with obvhs's compressed wide BVH
//! (CWBVH, Ylitie et al. 2017), f32 in the mesh frame (which `mesh-prep`
//! centres on the origin, so f32 keeps its precision).

use glam::{DVec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

/// The nearest surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Mesh triangle index.
    pub triangle: u32,
    /// Ray parameter of the hit (distance when the direction is unit).
    pub t: f32,
}

/// A BVH over the mesh's triangles, ready for rays.
pub struct SceneRays {
    bvh: CwBvh,
    /// Triangles in BVH primitive order.
    ordered: Vec<Triangle>,
    /// Mesh triangle index of each BVH primitive.
    mesh_index: Vec<u32>,
}

fn vec3a(p: DVec3) -> Vec3A {
    Vec3A::new(p.x as f32, p.y as f32, p.z as f32)
}

impl SceneRays {
    /// Builds the BVH over `triangles` (vertex positions, mesh frame).
    /// Must be given at least one triangle.
    pub fn new(triangles: &[[DVec3; 3]]) -> Self {
        let tris: Vec<Triangle> =
            triangles.iter().map(|t| Triangle { v0: vec3a(t[0]), v1: vec3a(t[1]), v2: vec3a(t[2]) }).collect();
        let bvh = build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
        let ordered = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        let mesh_index = bvh.primitive_indices.clone();
        SceneRays { bvh, ordered, mesh_index }
    }

    /// The nearest hit along `origin + t direction` for `t` in
    /// `(t_min, t_max)`, skipping the mesh triangles in `skip`.
    pub fn closest_hit(&self, origin: DVec3, direction: DVec3, t_min: f32, t_max: f32, skip: [u32; 2]) -> Option<Hit> {
        let ray = Ray::new(vec3a(origin), vec3a(direction), t_min, t_max);
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, id| {
            if skip.contains(&self.mesh_index[id]) {
                f32::INFINITY
            } else {
                self.ordered[id].intersect(ray)
            }
        });
        found.then(|| Hit { triangle: self.mesh_index[hit.primitive_id as usize], t: hit.t })
    }

    /// Distance from `from` to the first surface on the segment to `to`,
    /// ignoring the mesh triangles in `skip` (the segment's own end
    /// triangles) and the last millionth at each end; `None` if the segment
    /// is clear.
    pub fn first_blocker(&self, from: DVec3, to: DVec3, skip: [u32; 2]) -> Option<f64> {
        let d = to - from;
        let length = d.length();
        if length <= 0.0 {
            return None;
        }
        let hit = self.closest_hit(from, d / length, (1e-6 * length) as f32, ((1.0 - 1e-6) * length) as f32, skip)?;
        Some(f64::from(hit.t))
    }

    /// Whether the segment is clear: [`Self::first_blocker`] with an
    /// any-hit traversal, which stops at the first blocker.
    pub fn segment_clear(&self, from: DVec3, to: DVec3, skip: [u32; 2]) -> bool {
        let d = to - from;
        let length = d.length();
        if length <= 0.0 {
            return true;
        }
        let ray = Ray::new(vec3a(from), vec3a(d / length), (1e-6 * length) as f32, ((1.0 - 1e-6) * length) as f32);
        self.bvh.ray_traverse_miss(ray, |ray, id| {
            if skip.contains(&self.mesh_index[id]) {
                f32::INFINITY
            } else {
                self.ordered[id].intersect(ray)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    fn quad(z: f64, half: f64) -> [[DVec3; 3]; 2] {
        let (a, b, c, d) = (dvec3(-half, -half, z), dvec3(half, -half, z), dvec3(half, half, z), dvec3(-half, half, z));
        [[a, b, c], [a, c, d]]
    }

    #[test]
    fn nearest_of_two_planes_is_found_and_skipping_works() {
        let mut tris = quad(1.0, 1.0).to_vec();
        tris.extend(quad(2.0, 1.0));
        let rays = SceneRays::new(&tris);
        let hit = rays.closest_hit(dvec3(0.1, 0.2, 0.0), DVec3::Z, 0.0, f32::INFINITY, [u32::MAX; 2]).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-6 && hit.triangle < 2);
        let behind = rays.closest_hit(dvec3(0.1, 0.2, 0.0), DVec3::Z, 0.0, f32::INFINITY, [0, 1]).unwrap();
        assert!((behind.t - 2.0).abs() < 1e-6 && behind.triangle >= 2);
        assert_eq!(rays.first_blocker(dvec3(0.1, 0.2, 0.0), dvec3(0.1, 0.2, 3.0), [u32::MAX; 2]), Some(1.0));
        assert!(!rays.segment_clear(dvec3(0.1, 0.2, 0.0), dvec3(0.1, 0.2, 3.0), [u32::MAX; 2]));
        assert!(rays.segment_clear(dvec3(0.1, 0.2, 0.0), dvec3(0.1, 0.2, 0.9), [u32::MAX; 2]));
        assert!(rays.closest_hit(dvec3(5.0, 5.0, 0.0), DVec3::Z, 0.0, f32::INFINITY, [u32::MAX; 2]).is_none());
    }
}

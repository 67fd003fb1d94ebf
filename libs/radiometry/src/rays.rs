//! Ray casting over the scene's triangles with obvhs's compressed wide BVH
//! (CWBVH, Ylitie et al. 2017), f32 in the mesh frame (which `mesh-prep`
//! centres on the origin, so f32 keeps its precision). Each triangle is
//! tested with the watertight test of [`crate::watertight`] (Woop, Benthin
//! & Wald 2013): a ray through an edge or a vertex shared by triangles hits
//! one of them, so no light leaks between the triangles of a closed mesh or
//! of a triangulated quad.
//!
//! # Twins
//!
//! Two triangles with the same three corners wound opposite ways are
//! *twins*: the two faces of one two-sided surface (`mesh-prep` makes them
//! for two-sided materials; a model may also hold both windings). A ray
//! meets both at the same `t`, the front of one and the back of the other,
//! so which it reports would be a tie decided by traversal order. Rays
//! therefore ignore the back face of a triangle that has a twin (they see
//! the twin's front there, the face whose radiosity belongs to that side),
//! and skipping a triangle skips its twin too (a segment that starts on one
//! face must not be stopped by the other face at `t = 0`). Triangles
//! without a twin are hit from both sides, as before: their back faces
//! occlude.
//!
//! # Alpha masks
//!
//! Triangles given an alpha mask ([`SceneRays::with_alpha_masks`]) stop a
//! ray only where the hit lies on an opaque texel
//! ([`crate::texture::opaque`]); elsewhere the ray passes on (an any-hit
//! test inside the traversal, paper 004 Sec. 4.3.4: texels with alpha 0
//! do not exist). The hit's texture coordinates are interpolated from the
//! triangle's corners with barycentrics computed in f64 from the hit point.

use crate::watertight::ShearedRay;
use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use crate::texture::TexelGrid;
use std::collections::HashMap;
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
    /// BVH primitive of each mesh triangle.
    primitive: Vec<u32>,
    /// Per BVH primitive: the front normal (unnormalised) of a triangle
    /// that has a twin, whose back face rays ignore; `None` otherwise.
    culled_normal: Vec<Option<Vec3A>>,
    /// Per mesh triangle: its twin's mesh index, if it has one.
    twin: Vec<Option<u32>>,
    /// Alpha masks, when some triangle has one.
    alpha: Option<AlphaMasks>,
}

/// Which triangles a mask cuts, and the masks (the stage kit's
/// `scene::alpha_masks` reads them from a surface artifact).
#[derive(Clone, Debug)]
pub struct AlphaMasks {
    /// Per mesh triangle: its corners' texture coordinates and its mask's
    /// index in `textures`, if it has one.
    pub masked: Vec<Option<([[f64; 2]; 3], u32)>>,
    /// The alpha textures (coverage in channel A).
    pub textures: Vec<TexelGrid<Vec<[f32; 4]>>>,
}

/// The corners rotated to start at the smallest: one key for a triangle
/// whichever corner it starts at; its twin's is the key of `[c0, c2, c1]`.
fn rotated_to_smallest(c: [[u32; 3]; 3]) -> [[u32; 3]; 3] {
    let first = (0..3).min_by_key(|&i| c[i]).unwrap_or(0);
    std::array::from_fn(|k| c[(first + k) % 3])
}

/// Each triangle's twin (see the module documentation): the triangle with
/// the same corners, bit for bit in f32, wound the other way.
pub fn twins(triangles: &[Triangle]) -> Vec<Option<u32>> {
    let bits = |p: Vec3A| p.to_array().map(f32::to_bits);
    let corners: Vec<[[u32; 3]; 3]> = triangles.iter().map(|t| [bits(t.v0), bits(t.v1), bits(t.v2)]).collect();
    let mut first_of: HashMap<[[u32; 3]; 3], u32> = HashMap::with_capacity(triangles.len());
    for (i, c) in corners.iter().enumerate() {
        first_of.entry(rotated_to_smallest(*c)).or_insert(i as u32);
    }
    let twin_of = |(i, c): (usize, &[[u32; 3]; 3])| first_of.get(&rotated_to_smallest([c[0], c[2], c[1]])).copied().filter(|&j| j as usize != i);
    corners.iter().enumerate().map(twin_of).collect()
}

/// Relative padding of the triangles' bounding boxes, in units of the
/// mesh's largest coordinate magnitude (see [`padded_boxes`]).
const BOX_PADDING: f32 = 1e-6;

/// The triangles' bounding boxes grown on every side by [`BOX_PADDING`]
/// times the largest coordinate magnitude of the mesh. obvhs's slab test
/// rounds in f32 (and replaces direction components under `f32::EPSILON`
/// by `±1/EPSILON`), so a ray through a box's edge or face, as every ray
/// aimed at a shared edge of axis-aligned triangles is, can round to a
/// miss of the box and never reach the watertight triangle test: a few
/// ulps of the coordinates (16 at this padding) make the box test
/// conservative (the end Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2),
/// reaches by growing the slab interval inside the traversal).
fn padded_boxes(triangles: &[Triangle]) -> Vec<Aabb> {
    let largest = triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(0.0f32, |m, v| m.max(v.abs().max_element()));
    let pad = Vec3A::splat(BOX_PADDING * largest);
    triangles
        .iter()
        .map(|t| {
            let b = t.aabb();
            Aabb::new(b.min - pad, b.max + pad)
        })
        .collect()
}

fn vec3a(p: DVec3) -> Vec3A {
    Vec3A::new(p.x as f32, p.y as f32, p.z as f32)
}

/// A ray direction for obvhs, its negative zeros made positive (`-0 + 0 =
/// +0`). obvhs picks a node's near and far planes by the octant of the
/// direction (a component below 0) but inverts a zero component by its
/// sign bit (`signum(-0) = -1`): for a component of -0 the two disagree and
/// the ray misses every box. A floor's normal computed by a cross product
/// came out `(-0, 0, 1)`, and the ray straight up from under a block went
/// through the block.
fn direction(d: DVec3) -> Vec3A {
    vec3a(d) + Vec3A::ZERO
}

impl SceneRays {
    /// Builds the BVH over `triangles` (vertex positions, mesh frame).
    /// Must be given at least one triangle.
    pub fn new(triangles: &[[DVec3; 3]]) -> Self {
        let tris: Vec<Triangle> =
            triangles.iter().map(|t| Triangle { v0: vec3a(t[0]), v1: vec3a(t[1]), v2: vec3a(t[2]) }).collect();
        let bvh = build_cwbvh(&padded_boxes(&tris), BvhBuildParams::medium_build(), &mut Duration::default());
        let twin = twins(&tris);
        let ordered: Vec<Triangle> = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        let mesh_index = bvh.primitive_indices.clone();
        let mut primitive = vec![0; mesh_index.len()];
        for (id, &mesh) in mesh_index.iter().enumerate() {
            primitive[mesh as usize] = id as u32;
        }
        let culled_normal =
            mesh_index.iter().zip(&ordered).map(|(&i, t)| twin[i as usize].map(|_| (t.v1 - t.v0).cross(t.v2 - t.v0))).collect();
        SceneRays { bvh, ordered, mesh_index, primitive, culled_normal, twin, alpha: None }
    }

    /// The same BVH whose rays pass through the transparent texels of
    /// `masks` (module docs).
    pub fn with_alpha_masks(self, masks: AlphaMasks) -> Self {
        SceneRays { alpha: Some(masks), ..self }
    }

    /// Whether the hit at `t` on BVH primitive `id` lies where its alpha
    /// mask, if any, is transparent.
    fn cut_out(&self, ray: &Ray, id: usize, t: f32) -> bool {
        let Some(alpha) = &self.alpha else { return false };
        let Some((uv, texture)) = alpha.masked[self.mesh_index[id] as usize] else { return false };
        let tri = &self.ordered[id];
        let d = |v: Vec3A| DVec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z));
        let (p0, e1, e2) = (d(tri.v0), d(tri.v1 - tri.v0), d(tri.v2 - tri.v0));
        let hit = d(ray.origin) + d(ray.direction) * f64::from(t) - p0;
        let (d11, d12, d22, d1, d2) = (e1.dot(e1), e1.dot(e2), e2.dot(e2), hit.dot(e1), hit.dot(e2));
        let det = d11 * d22 - d12 * d12;
        if det <= 0.0 {
            return false;
        }
        let (b1, b2) = ((d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det);
        let at = std::array::from_fn(|k| (1.0 - b1 - b2) * uv[0][k] + b1 * uv[1][k] + b2 * uv[2][k]);
        !crate::texture::opaque(alpha.textures[texture as usize].view(), at)
    }

    /// The mesh triangle `i`'s twin, if it has one.
    pub fn twin(&self, i: u32) -> Option<u32> {
        self.twin[i as usize]
    }

    /// `t` of the ray's hit on BVH primitive `id`, or infinity where the
    /// primitive is skipped (it or its twin is in `skip`) or shows the ray
    /// a twin's back face. `sheared` is `ray` set up for the watertight
    /// test.
    #[inline]
    fn intersect(&self, ray: &Ray, sheared: &ShearedRay, id: usize, skip: [u32; 2]) -> f32 {
        let mesh = self.mesh_index[id];
        let skipped = skip.contains(&mesh) || self.twin[mesh as usize].is_some_and(|t| skip.contains(&t));
        let back_of_twin = self.culled_normal[id].is_some_and(|n| ray.direction.dot(n) > 0.0);
        if skipped || back_of_twin {
            return f32::INFINITY;
        }
        let t = sheared.intersect(&self.ordered[id], ray.tmin, ray.tmax);
        if t.is_finite() && self.cut_out(ray, id, t) {
            f32::INFINITY
        } else {
            t
        }
    }

    /// The nearest hit along `origin + t direction` for `t` in
    /// `(t_min, t_max)`, skipping the mesh triangles in `skip`.
    #[inline]
    pub fn closest_hit(&self, origin: DVec3, direction: DVec3, t_min: f32, t_max: f32, skip: [u32; 2]) -> Option<Hit> {
        let ray = Ray::new(vec3a(origin), self::direction(direction), t_min, t_max);
        let sheared = ShearedRay::new(ray.origin, ray.direction);
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, id| self.intersect(ray, &sheared, id, skip));
        found.then(|| Hit { triangle: self.mesh_index[hit.primitive_id as usize], t: hit.t })
    }

    /// Distance from `from` to the first surface on the segment to `to`,
    /// ignoring the mesh triangles in `skip` (the segment's own end
    /// triangles) and the last millionth at each end; `None` if the segment
    /// is clear.
    #[inline]
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
    #[inline]
    pub fn segment_clear(&self, from: DVec3, to: DVec3, skip: [u32; 2]) -> bool {
        let Some((ray, sheared)) = segment(from, to) else { return true };
        self.bvh.ray_traverse_miss(ray, |ray, id| self.intersect(ray, &sheared, id, skip))
    }

    /// [`Self::segment_clear`] with only the mesh triangles `among` tested,
    /// one by one, without the BVH: the same verdict wherever every
    /// triangle that may block the segment is among them (a shaft's
    /// possible occluders), found without a traversal.
    #[inline]
    pub fn segment_clear_among(&self, from: DVec3, to: DVec3, skip: [u32; 2], among: &[u32]) -> bool {
        let Some((ray, sheared)) = segment(from, to) else { return true };
        among.iter().all(|&t| self.intersect(&ray, &sheared, self.primitive[t as usize] as usize, skip).is_infinite())
    }
}

/// The ray of the segment from `from` to `to` without its last millionth
/// at each end, set up for the watertight test; `None` for a segment of
/// no length.
#[inline]
fn segment(from: DVec3, to: DVec3) -> Option<(Ray, ShearedRay)> {
    let d = to - from;
    let length = d.length();
    if length <= 0.0 {
        return None;
    }
    let ray = Ray::new(vec3a(from), direction(d / length), (1e-6 * length) as f32, ((1.0 - 1e-6) * length) as f32);
    Some((ray, ShearedRay::new(ray.origin, ray.direction)))
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
        // (0.2, 0.1) lies under triangles 0 and 2, not 1 and 3.
        let (from, to) = (dvec3(0.2, 0.1, 0.0), dvec3(0.2, 0.1, 3.0));
        assert!(!rays.segment_clear_among(from, to, [u32::MAX; 2], &[1, 2]), "a triangle the segment meets is among them");
        assert!(rays.segment_clear_among(from, to, [u32::MAX; 2], &[1, 3]), "none is");
        assert!(rays.segment_clear_among(from, to, [0, 2], &[0, 2]), "they are skipped");
        assert!(rays.closest_hit(dvec3(5.0, 5.0, 0.0), DVec3::Z, 0.0, f32::INFINITY, [u32::MAX; 2]).is_none());
    }

    #[test]
    fn a_direction_with_negative_zeros_hits_what_positive_zeros_hit() {
        let rays = SceneRays::new(&quad(1.0, 1.0));
        for d in [dvec3(-0.0, 0.0, 1.0), dvec3(0.0, -0.0, 1.0), dvec3(-0.0, -0.0, 1.0), dvec3(0.0, 0.0, 1.0)] {
            let hit = rays.closest_hit(dvec3(0.1, 0.2, 0.0), d, 0.0, f32::INFINITY, [u32::MAX; 2]);
            assert_eq!(hit.map(|h| h.t), Some(1.0), "direction {d:?}");
            assert!(!rays.segment_clear(dvec3(0.1, 0.2, 0.0), dvec3(0.1, 0.2, 0.0) + 2.0 * d, [u32::MAX; 2]), "direction {d:?}");
        }
    }

    #[test]
    fn rays_pass_through_the_transparent_texels_of_an_alpha_mask() {
        // A unit quad at z = 1 whose mask's left half (u < 1/2) is cut out,
        // above an unmasked one at z = 2.
        let mut tris = quad(1.0, 0.5).to_vec();
        tris.extend(quad(2.0, 0.5));
        let texture = TexelGrid { width: 2, height: 1, texels: vec![[0.0; 4], [1.0; 4]], scale: [1.0, 1.0], offset: [0.0, 0.0], clamp: true };
        // uv = xy + 1/2 on the quad's corners.
        let uv = |t: &[DVec3; 3]| t.map(|p| [p.x + 0.5, p.y + 0.5]);
        let masked = vec![Some((uv(&tris[0]), 0)), Some((uv(&tris[1]), 0)), None, None];
        let rays = SceneRays::new(&tris).with_alpha_masks(AlphaMasks { masked, textures: vec![texture] });
        let up = |x: f64| rays.closest_hit(dvec3(x, 0.1, 0.0), DVec3::Z, 0.0, f32::INFINITY, [u32::MAX; 2]).map(|h| h.t);
        assert_eq!(up(-0.25), Some(2.0), "through the cut-out half to the quad behind");
        assert_eq!(up(0.25), Some(1.0), "stopped by the opaque half");
        assert!(rays.segment_clear(dvec3(-0.3, -0.2, 0.0), dvec3(-0.1, 0.3, 1.5), [u32::MAX; 2]));
        assert!(!rays.segment_clear(dvec3(0.3, -0.2, 0.0), dvec3(0.1, 0.3, 1.5), [u32::MAX; 2]));
    }

    #[test]
    fn a_ray_sees_the_face_of_a_twin_pair_that_faces_it() {
        let front = quad(1.0, 1.0);
        let back = front.map(|[a, b, c]| [b, a, c]);
        // Twins listed in both orders, after an unpaired triangle, so that
        // neither the index order nor the BVH order can decide the tie.
        let mut tris = vec![[dvec3(5.0, 5.0, 0.0), dvec3(6.0, 5.0, 0.0), dvec3(5.0, 6.0, 0.0)], front[0], back[0]];
        tris.extend([back[1], front[1]]);
        let rays = SceneRays::new(&tris);
        assert_eq!([0, 1, 2, 3, 4].map(|i| rays.twin(i)), [None, Some(2), Some(1), Some(4), Some(3)]);
        for x in [-0.5, 0.5] {
            let up = rays.closest_hit(dvec3(x, 0.3, 0.0), DVec3::Z, 0.0, f32::INFINITY, [u32::MAX; 2]).unwrap();
            assert!([2, 3].contains(&up.triangle), "from below the back twins face the ray: {up:?}");
            for tilt in [DVec3::ZERO, dvec3(0.01, 0.02, 0.0)] {
                let down = rays.closest_hit(dvec3(x, 0.3, 2.0), (tilt - DVec3::Z).normalize(), 0.0, f32::INFINITY, [u32::MAX; 2]).unwrap();
                assert!([1, 4].contains(&down.triangle), "from above the front ones do: {down:?}");
            }
            // Skipping one face skips its twin: a segment that starts a
            // hair behind its own surface (rounding) is not stopped by the
            // other face, which faces it.
            let own = if x < 0.0 { [4, u32::MAX] } else { [1, u32::MAX] };
            let below = dvec3(x, 0.3, 1.0 - 1e-4);
            assert!(rays.segment_clear(below, below + DVec3::Z, own));
            assert!(!rays.segment_clear(below, below + DVec3::Z, [u32::MAX; 2]), "the pair occludes");
        }
    }
}

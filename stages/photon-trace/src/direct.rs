//! Deterministic direct light at the vertices (paper 001's second stage:
//! "deterministic calculations of direct lighting are performed").
//!
//! From an emitting triangle `j` of exitance `M_j` (a Lambertian emitter
//! of constant radiance), the irradiance at a point `x` with normal `n` is
//!
//! ```text
//! E_j(x) = M_j F_{dx -> j} V_j(x)
//! ```
//!
//! with `F` Lambert's point-to-polygon factor, one-sided in the sender
//! ([`radiometry::form_factor::point_to_one_sided_polygon`], paper 002 Eq.
//! 3), exact for the unoccluded triangle, and `V` the visible fraction,
//! weighted by the point kernel, of `visibility_rays` shadow rays to
//! stratified points of the emitter (`V = 1` exactly when none is blocked,
//! so an unoccluded receiver gets Lambert's value). A goniometric light
//! adds `I(d) cos(theta) / r²` with one shadow ray
//! ([`radiometry::photometry::DirectLight::at_point`]).
//!
//! The point is the vertex moved a ten-thousandth of the way into its own
//! leaves ([`crate::mesh::Vertices::inside`]): at a vertex on a crease
//! (floor meeting wall) Lambert's factor of the wall is undefined (the
//! point lies on the wall's edge), and the limit from inside the floor is
//! the value the photons' hat-weighted estimate approaches.

use crate::mesh::PointKey;
use glam::DVec3;
use radiometry::form_factor::{point_kernel, point_to_one_sided_polygon, WeightedVisibility};
use radiometry::geometry::TriangleGeometry;
use radiometry::photometry::DirectLight;
use radiometry::rays::SceneRays;
use radiometry::sampling::{mix64, stratified_point, Stream};
use rayon::prelude::*;

/// An emitting triangle.
#[derive(Clone, Copy, Debug)]
pub struct AreaLight {
    /// Mesh triangle.
    pub triangle: u32,
    /// Exitance, W/m² per channel.
    pub exitance: [f64; 3],
}

/// What the direct pass needs.
pub struct DirectScene<'a> {
    /// Triangle geometry.
    pub geometry: &'a [TriangleGeometry],
    /// Ray casting.
    pub rays: &'a SceneRays,
    /// Emitting triangles.
    pub area_lights: &'a [AreaLight],
    /// Goniometric lights with their shadow rays.
    pub luminaires: DirectLight<'a>,
    /// Shadow rays per emitting triangle.
    pub visibility_rays: usize,
    /// Seed of the shadow rays' jitter.
    pub seed: u64,
}

impl DirectScene<'_> {
    /// Direct irradiance at point `x` (normal `n`) of triangle `triangle`,
    /// W/m² per channel, the shadow rays' jitter drawn from `key`; and the
    /// rays cast.
    pub fn irradiance(&self, x: DVec3, n: DVec3, triangle: u32, key: u64) -> ([f64; 3], u64) {
        let mut e = [0.0; 3];
        let mut rays = 0;
        for light in self.area_lights {
            let g = &self.geometry[light.triangle as usize];
            if light.triangle == triangle {
                continue;
            }
            let f = point_to_one_sided_polygon(x, n, &g.corners, g.normal);
            if f <= 0.0 {
                continue;
            }
            let mut stream = Stream::new(self.seed, key, u64::from(light.triangle));
            let mut visible = WeightedVisibility::default();
            for k in 0..self.visibility_rays {
                let y = stratified_point(&g.corners, k, self.visibility_rays, &mut stream);
                let w = point_kernel(x, n, y, g.normal);
                if w > 0.0 {
                    rays += 1;
                    visible.add(w, self.rays.segment_clear(x, y, [triangle, light.triangle]));
                }
            }
            let v = visible.fraction().unwrap_or(1.0);
            for (e, m) in e.iter_mut().zip(light.exitance) {
                *e += m * f * v;
            }
        }
        let (goniometric, cast) = self.luminaires.at_point(x, n, triangle);
        (e.map(|x| x + goniometric), rays + cast)
    }

    /// Direct irradiance at every query, in parallel; and the rays cast.
    pub fn at(&self, queries: &[Query]) -> (Vec<[f64; 3]>, u64) {
        let computed: Vec<([f64; 3], u64)> = queries.par_iter().map(|q| self.irradiance(q.point, q.normal, q.triangle, stream_key(&q.key))).collect();
        let rays = computed.iter().map(|(_, r)| r).sum();
        (computed.into_iter().map(|(e, _)| e).collect(), rays)
    }
}

/// A point to light: where, facing where, on which triangle, and its
/// identity (which seeds its shadow rays).
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// The point, m.
    pub point: DVec3,
    /// Normal: unit, or a vertex's mean normal
    /// ([`crate::mesh::Vertices::mean_normal`]; the values are linear in
    /// it).
    pub normal: DVec3,
    /// Mesh triangle (skipped by its shadow rays).
    pub triangle: u32,
    /// Identity: the exact point and the triangle.
    pub key: (PointKey, u32),
}

/// The stream key of a point identity.
fn stream_key(key: &(PointKey, u32)) -> u64 {
    key.0.iter().fold(u64::from(key.1), |h, &(i, w)| mix64(h ^ mix64(u64::from(i) ^ w.rotate_left(17))))
}

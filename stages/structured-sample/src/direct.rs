//! Direct illumination from the primary light sources, exact where the
//! sources are unoccluded (paper 002 Section 2.1, Eq. 2-3):
//!
//! ```text
//! E(x) = sum_e B_e F_{dx->e} V_e(x),     l(x) = rho E(x) / pi
//! ```
//!
//! `B_e` the emitter triangle's exitance (W/m²), `F` Lambert's closed-form
//! point-to-polygon factor (radiometry's kernel, one-sided in the sender),
//! `V_e` the fraction of `e` seen from `x` by ray casting to stratified
//! points of `e`, weighted by the point kernel. Where every ray is clear
//! `V_e` is exactly 1 and `l` is Lambert's value to rounding; in a penumbra
//! `0 < V_e < 1`, in an umbra 0.

use glam::DVec3;
use radiometry::form_factor::{point_kernel, point_to_one_sided_polygon, WeightedVisibility};
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::SceneRays;
use radiometry::sampling::{stratified_point, Stream};

/// One emitting triangle.
#[derive(Clone, Debug)]
pub struct PrimaryEmitter {
    /// Its mesh triangle.
    pub triangle: u32,
    /// Its geometry.
    pub geometry: TriangleGeometry,
    /// Its exitance, W/m², RGB.
    pub exitance: [f64; 3],
}

/// What a point receives from the primary light sources.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Irradiance {
    /// Irradiance, W/m², RGB.
    pub rgb: [f64; 3],
    /// The visible fraction of the unoccluded irradiance's luminance
    /// (1 where lit, 0 in an umbra, between in a penumbra; 1 where no
    /// light reaches the point even unoccluded).
    pub visibility: f64,
    /// Rays cast.
    pub rays: u64,
}

/// The primary light sources of a scene and the rays to test them.
pub struct DirectLight<'a> {
    /// Every emitting triangle.
    pub emitters: Vec<PrimaryEmitter>,
    /// The scene's BVH.
    pub rays: &'a SceneRays,
    /// Rays per emitter triangle for `V_e`.
    pub visibility_rays: usize,
    /// Seed of the ray points.
    pub seed: u64,
}

impl DirectLight<'_> {
    /// The irradiance at `point` (unit normal `normal`, on mesh triangle
    /// `triangle`); `key` names the point for its random stream, so the
    /// result does not depend on the order points are evaluated in.
    pub fn at(&self, point: DVec3, normal: DVec3, triangle: u32, key: u64) -> Irradiance {
        let (mut rgb, mut rays) = ([0.0; 3], 0u64);
        let (mut seen, mut unoccluded) = (0.0, 0.0);
        for (index, e) in self.emitters.iter().enumerate() {
            if e.triangle == triangle {
                continue;
            }
            let factor = point_to_one_sided_polygon(point, normal, &e.geometry.corners, e.geometry.normal);
            if factor <= 0.0 {
                continue;
            }
            let mut visibility = WeightedVisibility::default();
            let mut stream = Stream::new(self.seed, key, index as u64);
            for k in 0..self.visibility_rays {
                let y = stratified_point(&e.geometry.corners, k, self.visibility_rays, &mut stream);
                let weight = point_kernel(point, normal, y, e.geometry.normal);
                if weight > 0.0 {
                    rays += 1;
                    visibility.add(weight, self.rays.segment_clear(point, y, [triangle, e.triangle]));
                }
            }
            let v = visibility.fraction().unwrap_or(1.0);
            let luminance = radiometry::color::luminance(e.exitance) * factor;
            seen += luminance * v;
            unoccluded += luminance;
            for (r, b) in rgb.iter_mut().zip(e.exitance) {
                *r += b * factor * v;
            }
        }
        let visibility = if unoccluded > 0.0 { (seen / unoccluded).clamp(0.0, 1.0) } else { 1.0 };
        Irradiance { rgb, visibility, rays }
    }
}

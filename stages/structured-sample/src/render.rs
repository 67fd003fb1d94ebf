//! The camera: the screen-space lattice of view-dependent display samples,
//! and the image of the resampled surfaces.

use crate::surfaces::Surface;
use glam::{DVec2, DVec3};
use radiometry::camera::Pinhole;
use radiometry::rays::SceneRays;
use rayon::prelude::*;
use schemas::image::{PixelSurfaces, EMITTER, NO_SURFACE, SINGLE_SURFACE};
use std::f64::consts::PI;

/// What the camera looks at.
pub struct View<'a> {
    /// The camera.
    pub camera: &'a Pinhole,
    /// The scene's BVH.
    pub rays: &'a SceneRays,
    /// The planar surfaces.
    pub surfaces: &'a [Surface],
    /// Each mesh triangle's surface.
    pub surface_of: &'a [u32],
}

impl View<'_> {
    /// What a camera ray through image point `(x, y)` sees: the surface,
    /// the hit's `(u, v)` on it, its triangle and distance; `None` for a
    /// miss or the back of a surface.
    pub fn look(&self, x: f64, y: f64) -> Option<(u32, DVec2, u32, f64)> {
        let direction = self.camera.direction(x, y);
        let hit = self.rays.closest_hit(self.camera.eye, direction, 0.0, f32::INFINITY, [u32::MAX; 2])?;
        let s = self.surface_of[hit.triangle as usize];
        let surface = &self.surfaces[s as usize];
        if direction.dot(surface.normal) >= 0.0 {
            return None;
        }
        let point: DVec3 = self.camera.eye + direction * f64::from(hit.t);
        Some((s, surface.uv(point), hit.triangle, f64::from(hit.t)))
    }
}

/// One view-dependent display sample candidate per `stride` x `stride`
/// pixels (at the block's centre) of a `width` x `height` image: the
/// surface, `(u, v)`, and the width of the block on the surface (m), its
/// wanted spacing. Row by row: deterministic.
pub fn screen_candidates(view: &View, size: (u32, u32), vertical_fov_deg: f64, stride: u32) -> Vec<(u32, DVec2, f64)> {
    let (width, height) = size;
    let pixel_angle = 2.0 * (0.5 * vertical_fov_deg.to_radians()).tan() / f64::from(height);
    let (nx, ny) = (width.div_ceil(stride), height.div_ceil(stride));
    (0..nx * ny)
        .filter_map(|k| {
            let (x, y) = (f64::from(k % nx * stride) + 0.5 * f64::from(stride), f64::from(k / nx * stride) + 0.5 * f64::from(stride));
            let (s, uv, _, t) = view.look(x, y)?;
            Some((s, uv, t * pixel_angle * f64::from(stride)))
        })
        .collect()
}

/// An image before its header.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Radiance, W/(m² sr), RGB, row-major.
    pub rgb: Vec<[f32; 3]>,
    /// Fraction of each pixel's rays that hit a front face.
    pub coverage: Vec<f32>,
    /// What each pixel saw.
    pub surfaces: PixelSurfaces,
}

/// Renders the surfaces through `camera`: `spp_side`² rays per pixel at
/// the centres of a regular grid of sub-pixels (no randomness), each
/// front-face hit given `reflected(surface, (u, v), mesh triangle, key)`,
/// the luminance it reflects (`key` numbers the ray: pixel by pixel, row
/// by row), plus the surface's emitted luminance `B_e / pi`. A pixel's
/// surface is the one most of its rays hit (ties: the lower surface
/// index), single when all of them did.
pub fn render(view: &View, reflected: &(dyn Fn(u32, DVec2, u32, u64) -> [f64; 3] + Sync), size: (u32, u32), spp_side: u32, row_done: &(dyn Fn() + Sync)) -> Film {
    let surfaces = view.surfaces;
    let (width, height) = size;
    let n = f64::from(spp_side * spp_side);
    let pixels: Vec<([f32; 3], f32, [u32; 3])> = (0..height)
        .into_par_iter()
        .flat_map_iter(|y| {
            let row: Vec<_> = (0..width)
                .map(|x| {
                    let mut sum = [0.0; 3];
                    let mut hits: Vec<(u32, u32)> = Vec::new();
                    for k in 0..spp_side * spp_side {
                        let (sx, sy) = ((f64::from(k % spp_side) + 0.5) / f64::from(spp_side), (f64::from(k / spp_side) + 0.5) / f64::from(spp_side));
                        let Some((s, uv, triangle, _)) = view.look(f64::from(x) + sx, f64::from(y) + sy) else { continue };
                        let surface = &surfaces[s as usize];
                        let key = (u64::from(y) * u64::from(width) + u64::from(x)) * u64::from(spp_side * spp_side) + u64::from(k);
                        let l = reflected(s, uv, triangle, key);
                        for c in 0..3 {
                            sum[c] += l[c] + surface.emission[c] / PI;
                        }
                        match hits.iter_mut().find(|h| h.0 == s) {
                            Some(h) => h.1 += 1,
                            None => hits.push((s, 1)),
                        }
                    }
                    let covered: u32 = hits.iter().map(|h| h.1).sum();
                    let best = hits.iter().max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)));
                    let id = match best {
                        None => [NO_SURFACE, NO_SURFACE, 0],
                        Some(&(s, count)) => {
                            let surface = &surfaces[s as usize];
                            let single = if f64::from(count) == n { SINGLE_SURFACE } else { 0 };
                            [surface.object, surface.material, single | if surface.emits() { EMITTER } else { 0 }]
                        }
                    };
                    (sum.map(|v| (v / n) as f32), (f64::from(covered) / n) as f32, id)
                })
                .collect();
            row_done();
            row
        })
        .collect();
    Film {
        rgb: pixels.iter().map(|p| p.0).collect(),
        coverage: pixels.iter().map(|p| p.1).collect(),
        surfaces: PixelSurfaces { object: pixels.iter().map(|p| p.2[0]).collect(), material: pixels.iter().map(|p| p.2[1]).collect(), flags: pixels.iter().map(|p| p.2[2]).collect() },
    }
}

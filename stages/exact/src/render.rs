//! The exact image: one camera ray through each pixel's centre finds the
//! surface (radiometry's [`SceneRays`]), the point is put on the
//! triangle's plane in f64 (the BVH's f32 distance would leave it 1e-7 off),
//! and its radiance is the transport's radiosity over pi.
//!
//! Pixels are point samples at their centres, not means over their area:
//! a mean over the pixel is an integral the image could only estimate, and
//! the point value is what has an exact answer. A pixel is marked
//! [`SINGLE_SURFACE`] when its four corners' rays hit the front of the
//! centre's surface too (no silhouette or edge inside), so `compare` can
//! leave edges out, where a supersampled image and this one differ by
//! design.

use crate::transport::{Radiosity, Transport};
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::rays::SceneRays;
use rayon::prelude::*;
use schemas::image::{PixelSurfaces, EMITTER, NO_SURFACE, SINGLE_SURFACE};
use std::f64::consts::PI;

/// What one camera ray saw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seen {
    /// Nothing.
    Miss,
    /// The back of a surface (one-sided: black).
    Back(usize),
    /// The front of surface `.1` at point `.0`, mesh frame.
    Front(DVec3, usize),
}

/// The exact image before it gets its header: f64, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactImage {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Radiance, W/(m² sr).
    pub radiance: Vec<[f64; 3]>,
    /// Bound of each pixel's radiance error, W/(m² sr).
    pub bound: Vec<[f64; 3]>,
    /// 1 where the centre ray hit a surface, else 0.
    pub coverage: Vec<f32>,
    /// What each pixel saw.
    pub surfaces: PixelSurfaces,
    /// Integrand evaluations spent.
    pub evaluations: u64,
}

/// The camera and the scene's rays.
pub struct Camera<'a> {
    /// The pinhole.
    pub pinhole: &'a Pinhole,
    /// The BVH over the mesh's triangles.
    pub rays: &'a SceneRays,
    /// Per mesh triangle, its surface.
    pub surface_of: &'a [usize],
    /// Per surface, its front normal and a point of its plane.
    pub planes: Vec<(DVec3, DVec3)>,
}

impl Camera<'_> {
    /// What the ray through image point `(x, y)` (pixels) sees.
    pub fn see(&self, x: f64, y: f64) -> Seen {
        let direction = self.pinhole.direction(x, y);
        let Some(hit) = self.rays.closest_hit(self.pinhole.eye, direction, 0.0, f32::INFINITY, [u32::MAX; 2]) else {
            return Seen::Miss;
        };
        let surface = self.surface_of[hit.triangle as usize];
        let (normal, on_plane) = self.planes[surface];
        let facing = direction.dot(normal);
        if facing >= 0.0 {
            return Seen::Back(surface);
        }
        let t = (on_plane - self.pinhole.eye).dot(normal) / facing;
        Seen::Front(self.pinhole.eye + direction * t, surface)
    }
}

/// Renders the `width` x `height` image; `rows_done` is called with 1 per row.
pub fn render(camera: &Camera, transport: &Transport, ids: &[(u32, u32, bool)], width: usize, height: usize, rows_done: &(dyn Fn(u64) + Sync)) -> ExactImage {
    let rows: Vec<Vec<(Radiosity, f32, [u32; 3])>> = (0..height)
        .into_par_iter()
        .map(|row| {
            let pixels = (0..width)
                .map(|column| {
                    let (x, y) = (column as f64, row as f64);
                    match camera.see(x + 0.5, y + 0.5) {
                        Seen::Miss => (Radiosity::default(), 0.0, [NO_SURFACE, NO_SURFACE, 0]),
                        Seen::Back(_) => (Radiosity::default(), 1.0, [NO_SURFACE, NO_SURFACE, 0]),
                        Seen::Front(p, s) => {
                            let corners = [(x, y), (x + 1.0, y), (x, y + 1.0), (x + 1.0, y + 1.0)];
                            let single = corners.iter().all(|&(cx, cy)| matches!(camera.see(cx, cy), Seen::Front(_, t) if ids[t].0 == ids[s].0 && ids[t].1 == ids[s].1));
                            let flags = if single { SINGLE_SURFACE } else { 0 } | if ids[s].2 { EMITTER } else { 0 };
                            (transport.radiosity(p, s), 1.0, [ids[s].0, ids[s].1, flags])
                        }
                    }
                })
                .collect();
            rows_done(1);
            pixels
        })
        .collect();
    let mut image = ExactImage { width, height, radiance: Vec::new(), bound: Vec::new(), coverage: Vec::new(), surfaces: PixelSurfaces::default(), evaluations: 0 };
    for (r, coverage, [object, material, flags]) in rows.into_iter().flatten() {
        image.radiance.push(r.total().map(|b| b / PI));
        image.bound.push(r.bound.map(|b| b / PI));
        image.coverage.push(coverage);
        image.surfaces.object.push(object);
        image.surfaces.material.push(material);
        image.surfaces.flags.push(flags);
        image.evaluations += r.evaluations;
    }
    image
}

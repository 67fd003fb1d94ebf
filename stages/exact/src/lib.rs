//! # exact: reference images from the formulas (paper 002 Sec. 2)
//!
//! For the camera of a prepared scene (mesh.exr, manifest.ron), the image
//! whose light transport has a closed form or a quadrature to any
//! accuracy: direct light from planar polygonal diffuse emitters by
//! Lambert's formula (002 Eq. 2-3), one bounce off the directly lit
//! reflectors by adaptive Gauss quadrature (Eq. 4-5, Sec. 2.3), and where
//! asked every further bounce between two planes by iteration; each pixel
//! with a bound of its error (see [`transport`]). Scenes outside that
//! (occluders, non-planar surfaces, mirrors, more than two reflecting
//! planes for further bounces) are refused naming why
//! ([`configuration`]). The image is the pipeline's `image` artifact with
//! the bound in extra channels, so `tonemap` and `compare` read it as
//! they read grid-gather's ([`render`] on how pixels are sampled).
//!
//! "Exact" is for the mesh as mesh.exr stores it (f32 positions, in the
//! mesh frame mesh-prep recentred): every figure is computed in f64 from
//! those positions, and the bound covers the quadrature and iteration, not
//! the scene file's rounding to f32 (about 6e-8 of the scene's size).
//!
//! The knobs are [`Params`] (`exact --print-knobs`, the README's "Stage
//! knobs"): the bounces, the quadrature's tolerance and depth, the
//! iterated bounces' nodes, the image size.

#![deny(missing_docs)]

pub mod configuration;
pub mod quadrature;
pub mod render;
pub mod transport;

use configuration::Configuration;
use quadrature::LOOSEST_TOLERANCE;
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::rays::SceneRays;
use transport::{Accuracy, Transport};

/// Largest image side and pixel count, as the other image stages allow.
const MAX_SIDE: u32 = 16_384;
const MAX_PIXELS: u64 = 64 << 20;

stage_kit::knobs! {
    /// The stage's parameters.
    pub struct Params {
        /// Bounces after the direct light: 0, 1 (the paper's one bounce), or more, iterated between two planes.
        bounces: u32 = 1, "", value(0..=1000);
        /// Relative tolerance of each pixel's one-bounce integral (looser than 1e-4, the error bound is not trusted).
        tolerance: f64 = 1e-6, "", value(left_open(0.0, LOOSEST_TOLERANCE));
        /// Gauss-Legendre points per direction of the triangle rule.
        gauss_order: u32 = 6, "", value(1..=32);
        /// Deepest 1:4 refinement of the adaptive quadrature.
        max_depth: u32 = 12, "", value(1..=30);
        /// 1:4 splits of the reflectors for the iterated bounces' nodes.
        nystrom_level: u32 = 2, "", value(1..=6);
        /// Image width; `none`: the manifest camera's.
        width: Option<u32> = None, "pixels", optional(1..=MAX_SIDE);
        /// Image height; `none`: the manifest camera's.
        height: Option<u32> = None, "pixels", optional(1..=MAX_SIDE);
    }
}

impl Params {
    /// The transport's accuracy settings.
    pub fn accuracy(&self) -> Accuracy {
        Accuracy { tolerance: self.tolerance, gauss_order: self.gauss_order, max_depth: self.max_depth, bounces: self.bounces, nystrom_level: self.nystrom_level }
    }
}

/// A scene ready to render: its configuration, camera and rays.
pub struct Exact {
    /// The surfaces.
    pub config: Configuration,
    rays: SceneRays,
    pinhole: Pinhole,
    width: usize,
    height: usize,
}

impl Exact {
    /// Checks the scene and the camera; `Err` says why there is no exact
    /// image (one line).
    pub fn new(mesh: &schemas::mesh::Mesh, manifest: &schemas::mesh::Manifest, params: &Params) -> Result<Self, String> {
        let config = Configuration::new(mesh, manifest)?;
        if params.bounces >= 2 && config.reflecting_planes() > 2 {
            return Err(format!(
                "--bounces {} iterates between two reflecting planes; this scene has {} (use --bounces 1 or 0)",
                params.bounces,
                config.reflecting_planes()
            ));
        }
        let (width, height) = (params.width.unwrap_or(manifest.camera.width), params.height.unwrap_or(manifest.camera.height));
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) || u64::from(width) * u64::from(height) > MAX_PIXELS {
            return Err(format!("image size {width}x{height} out of range (each side 1..={MAX_SIDE}, at most {MAX_PIXELS} pixels)"));
        }
        let pinhole = stage_kit::scene::pinhole(&manifest.camera, width, height).ok_or("the camera looks nowhere (zero view direction, view along up, or field of view outside (0, 180) degrees)")?;
        let triangles: Vec<[DVec3; 3]> = config.surfaces.iter().flat_map(|s| s.triangles.iter().copied()).collect();
        if triangles.is_empty() {
            return Err("the mesh has no triangle".into());
        }
        // SceneRays indexes the mesh's triangles; rebuild them in mesh order.
        let mut in_mesh_order = vec![[DVec3::ZERO; 3]; config.surface_of.len()];
        let mut next = vec![0usize; config.surfaces.len()];
        for (i, &s) in config.surface_of.iter().enumerate() {
            in_mesh_order[i] = config.surfaces[s].triangles[next[s]];
            next[s] += 1;
        }
        let rays = SceneRays::new(&in_mesh_order);
        Ok(Exact { config, rays, pinhole, width: width as usize, height: height as usize })
    }

    /// Image width and height.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The camera over this scene.
    pub fn camera(&self) -> render::Camera<'_> {
        render::Camera {
            pinhole: &self.pinhole,
            rays: &self.rays,
            surface_of: &self.config.surface_of,
            planes: self.config.surfaces.iter().map(|s| (s.normal, s.triangles[0][0])).collect(),
        }
    }

    /// Renders the image; `nodes_done` and `rows_done` report progress.
    pub fn render(&self, params: &Params, nodes_done: &(dyn Fn(u64) + Sync), rows_done: &(dyn Fn(u64) + Sync)) -> render::ExactImage {
        let transport = Transport::new(&self.config, params.accuracy(), nodes_done);
        let ids: Vec<(u32, u32, bool)> = self.config.surfaces.iter().map(|s| (s.ids.0, s.ids.1, s.emits())).collect();
        render::render(&self.camera(), &transport, &ids, self.width, self.height, rows_done)
    }
}

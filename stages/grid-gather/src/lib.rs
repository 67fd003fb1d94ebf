//! # grid-gather: from a radiosity solution to an HDR image
//!
//! The final gather renders the hierarchical radiosity solution through the
//! manifest's pinhole camera. Two modes are planned:
//!
//! - **preview** (built): camera rays find the visible surface point, whose
//!   radiosity is interpolated from the solution's leaf elements (Gouraud
//!   over vertex radiosity, see [`gouraud`]) and turned into radiance
//!   `L = B / pi`. Cheap, continuous, but only as sharp as the elements.
//! - **full** (a later issue): the final gather of paper 000 Sec. 4
//!   (perspective grid over the view frustum, sender
//!   classification per grid vertex, resampling of critical senders,
//!   interpolation of the rest), steered by a threshold-elevation image.
//!   Asking for it is an error for now.
//!
//! ## Parameters
//!
//! | name | type | meaning | default |
//! |---|---|---|---|
//! | `mode` | `"preview"` / `"full"` | gather mode | `"preview"` |
//! | `width`, `height` | pixels | image size | the manifest camera's |
//! | `spp` | count | camera rays per pixel (stratified, jittered) | 4 |
//! | `seed` | u64 | seed of the per-pixel random streams | 0 |
//! | `crease_angle_deg` | degrees | leaves whose normals differ more do not blend at a shared corner | 30 |
//! | `weld_tolerance` | fraction of the bounding-box diagonal | corners closer than this are one point | 1e-7 |
//! | `material_seams` | bool | leaves of different materials do not blend at a shared corner | true |
//!
//! Same inputs and parameters give bit-identical images, whatever the
//! number of threads.

pub mod gouraud;
pub mod render;

use gouraud::{Gouraud, Smoothing};
use radiometry::camera::Pinhole;
use radiometry::geometry::mesh_triangles;
use radiometry::rays::SceneRays;
use render::{Sampling, View};
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use schemas::stage::bad_parameter;
use schemas::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The message for `--mode full` until the full gather exists.
pub const FULL_NOT_IMPLEMENTED: &str = "full gather not implemented yet (preview only)";

/// Which gather to run. Written as the strings `"preview"` / `"full"` (the
/// CLI's values), so that the parameters recorded in provenance, which go
/// through `ron::Value` and would drop a unit variant's name, keep it.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
#[serde(into = "String", try_from = "String")]
pub enum Mode {
    /// Interpolate the solution's radiosity (Gouraud over element corners).
    #[default]
    Preview,
    /// Final gather with sender classification (not implemented yet).
    Full,
}

impl From<Mode> for String {
    fn from(mode: Mode) -> String {
        match mode {
            Mode::Preview => "preview".into(),
            Mode::Full => "full".into(),
        }
    }
}

impl TryFrom<String> for Mode {
    type Error = String;

    fn try_from(name: String) -> std::result::Result<Self, String> {
        match name.as_str() {
            "preview" => Ok(Mode::Preview),
            "full" => Ok(Mode::Full),
            _ => Err(format!("unknown mode {name:?}, expected \"preview\" or \"full\"")),
        }
    }
}

/// The stage's parameters (`--params file.ron`, overridden by flags).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Gather mode.
    pub mode: Mode,
    /// Image width in pixels; `None`: the manifest camera's.
    pub width: Option<u32>,
    /// Image height in pixels; `None`: the manifest camera's.
    pub height: Option<u32>,
    /// Camera rays per pixel, at least 1.
    pub spp: u32,
    /// Seed of the per-pixel random streams.
    pub seed: u64,
    /// Crease angle, degrees in [0, 180]: leaves meeting at a corner blend
    /// only if their normals differ by at most this.
    pub crease_angle_deg: f64,
    /// Corner weld tolerance, as a fraction of the scene's bounding-box
    /// diagonal, in (0, 1e-3].
    pub weld_tolerance: f64,
    /// Leaves of different materials do not blend at a shared corner (B
    /// jumps where emission or reflectance does, even on a flat surface).
    pub material_seams: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params { mode: Mode::Preview, width: None, height: None, spp: 4, seed: 0, crease_angle_deg: 30.0, weld_tolerance: 1e-7, material_seams: true }
    }
}

impl Params {
    /// Checks every value's range; the error names the parameter.
    pub fn validate(&self) -> Result<()> {
        if self.spp == 0 {
            return Err(bad_parameter("spp must be at least 1"));
        }
        if self.width == Some(0) || self.height == Some(0) {
            return Err(bad_parameter("width and height must be at least 1 pixel"));
        }
        if !(0.0..=180.0).contains(&self.crease_angle_deg) {
            return Err(bad_parameter(format!("crease_angle_deg must be in [0, 180], got {}", self.crease_angle_deg)));
        }
        if !(self.weld_tolerance > 0.0 && self.weld_tolerance <= 1e-3) {
            return Err(bad_parameter(format!("weld_tolerance must be in (0, 1e-3], got {}", self.weld_tolerance)));
        }
        Ok(())
    }
}

/// The inputs of a gather. The paths only name the files in error
/// messages; nothing is read from them.
pub struct Scene<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its manifest (camera, effects).
    pub manifest: &'a Manifest,
    /// Path the manifest was read from.
    pub manifest_path: &'a Path,
    /// The radiosity solution over the mesh.
    pub solution: &'a Solution,
    /// Path the solution was read from.
    pub solution_path: &'a Path,
}

/// A rendered image and the work it took.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Radiance per pixel, W/(m² sr), linear RGB, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// Coverage per pixel in [0, 1].
    pub coverage: Vec<f32>,
    /// Work counters for the report.
    pub counters: BTreeMap<String, f64>,
    /// What was skipped and why, for the report.
    pub skipped: Vec<String>,
}

/// The image size: `params`' where given, else the camera's.
pub fn image_size(params: &Params, manifest: &Manifest) -> (u32, u32) {
    (params.width.unwrap_or(manifest.camera.width), params.height.unwrap_or(manifest.camera.height))
}

/// Renders `scene` as `params` say. `rows_done` is called with the number
/// of image rows finished (from worker threads), for a progress display;
/// the image has [`image_size`]`.1` rows.
pub fn gather(params: &Params, scene: &Scene, rows_done: &(dyn Fn(u64) + Sync)) -> Result<Rendered> {
    params.validate()?;
    if params.mode == Mode::Full {
        return Err(bad_parameter(FULL_NOT_IMPLEMENTED));
    }
    let (width, height) = image_size(params, scene.manifest);
    let camera = Pinhole::new(&scene.manifest.camera, width, height).ok_or_else(|| {
        Error::invalid(
            scene.manifest_path,
            None,
            format!("camera is unusable for a {width}x{height} image (zero view direction, view parallel to up, field of view outside (0, 180) degrees, or zero size)"),
        )
    })?;
    let triangles = mesh_triangles(scene.mesh);
    let smoothing = Smoothing {
        crease_angle_deg: params.crease_angle_deg,
        weld_tolerance: params.weld_tolerance,
        material_seams: params.material_seams,
    };
    let materials: Vec<u32> = scene.mesh.triangles.iter().map(|t| t.material).collect();
    let shading = Gouraud::new(&triangles, &materials, scene.solution, scene.solution_path, smoothing)?;
    let rays = (!triangles.is_empty()).then(|| SceneRays::new(&triangles.iter().map(|t| t.corners).collect::<Vec<_>>()));
    let view = View { camera: &camera, triangles: &triangles, rays: rays.as_ref(), shading: &shading };
    let film = render::render(&view, Sampling { width, height, spp: params.spp, seed: params.seed }, rows_done);

    let pixels = f64::from(width) * f64::from(height);
    let counters = BTreeMap::from([
        ("pixels".to_string(), pixels),
        ("samples_per_pixel".to_string(), f64::from(params.spp)),
        ("rays_cast".to_string(), pixels * f64::from(params.spp)),
        ("ray_hits".to_string(), film.hits as f64),
        ("back_face_hits".to_string(), film.back_face_hits as f64),
        ("triangles".to_string(), triangles.len() as f64),
        ("elements".to_string(), scene.solution.elements.len() as f64),
        ("leaf_elements".to_string(), shading.leaves() as f64),
        ("vertices".to_string(), shading.vertices() as f64),
    ]);
    Ok(Rendered {
        width: width as usize,
        height: height as usize,
        rgb: film.rgb,
        coverage: film.coverage,
        counters,
        skipped: skipped_in_preview(scene.manifest),
    })
}

/// What preview mode leaves out, and why, given the scene's effects.
pub fn skipped_in_preview(manifest: &Manifest) -> Vec<String> {
    let e = &manifest.effects;
    let mut skipped = vec![
        "full gather (perspective grid, sender classification, resampling): preview mode interpolates the radiosity of the solution".to_string(),
    ];
    let present = [
        (e.textures, "diffuse textures: present but not applied; preview shows element radiosity only"),
        (e.normal_maps, "normal maps: present but not applied; preview shades with the triangle normals"),
        (e.alpha_masks, "alpha masks: present but not applied; camera rays hit the whole triangles"),
        (e.specular_reflection, "specular reflection: present but not traced; mirrors show their diffuse radiosity"),
        (e.specular_transmission, "specular transmission: present but not traced; glass shows its diffuse radiosity"),
        (e.diffuse_transmission, "diffuse transmission: back faces shade black, radiosity in the solution is one-sided"),
    ];
    skipped.extend(present.iter().filter(|(on, _)| *on).map(|(_, why)| why.to_string()));
    skipped
}

#[cfg(test)]
mod tests;

//! # grid-gather: from a radiosity solution to an HDR image
//!
//! The final gather renders the hierarchical radiosity solution through the
//! manifest's pinhole camera, in one of three modes:
//!
//! - **preview**: camera rays find the visible surface point, whose
//!   radiosity is interpolated from the solution's leaf elements (Gouraud
//!   over vertex radiosity, see [`gouraud`]) and turned into radiance
//!   `L = B / pi`. Cheap, continuous, but only as sharp as the elements.
//! - **full**: the final gather of paper 000 Sec. 4-5 (perspective grid
//!   over the view frustum, sender classification per grid vertex,
//!   resampling of critical senders, interpolation of the rest, the
//!   surface-based gather where the solution is finer than the grid,
//!   view-dependent shadow samples), optionally steered by the mask
//!   stage's threshold image. See [`full_gather`], which lists the sections' files.
//! - **brute**: the classic final gather it is measured against: every
//!   link of the hit point's element chain resampled at every camera
//!   sample ([`brute`]).
//!
//! With mesh-prep's surface artifact (`--surface`), every mode shows
//! textures (`B = E + rho(x) H` per hit) and lets rays through alpha-masked
//! holes, and the full and brute gathers take normal maps in their cosines
//! ([`detail`]). The full and brute gathers add a two-sided translucent
//! surface's transmitted light, `tau H_back` gathered on its other face
//! (paper 004 Eq. 4.4; [`full_image::FullScene::transmission`]).
//!
//! In every mode, a camera ray that meets an ideal mirror (`rho_s`) or thin
//! glass (`tau_s`) is continued, reflected or straight on, to the depth and
//! weight bounds below, and the diffuse surfaces it reaches are shaded as
//! if seen directly ([`specular`]); the full gather classifies senders at
//! the surface finally reached (by the grid where that point lies in it,
//! else by the brute gather).
//!
//! ## Parameters
//!
//! [`Params`], declared once with the stage kit's `knobs!`: `grid-gather
//! --print-knobs` prints their table (the README's "Stage knobs").
//!
//! Same inputs and parameters give bit-identical images, whatever the
//! number of threads.

pub mod brute;
pub mod classification;
pub mod contrast;
pub mod detail;
pub mod diagnostics;
pub mod files;
pub mod film;
pub mod full_image;
pub mod full_gather;
pub mod gouraud;
pub mod grid;
pub mod interpolation;
pub mod lattice;
pub mod pixel_surfaces;
pub mod preview;
pub mod senders;
pub mod shadow_samples;
pub mod specular;
pub mod surface_gather;

use gouraud::{Gouraud, Smoothing};
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use stage_kit::scene::{mesh_triangles, pinhole};
use radiometry::rays::SceneRays;
use schemas::diagnostics::Diagnostics;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use stage_kit::knobs::Knobs;
use stage_kit::run::bad_parameter;
use schemas::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Which gather to run. Written as the strings `"preview"` / `"full"` (the
/// CLI's values), so that the parameters recorded in provenance, which go
/// through `ron::Value` and would drop a unit variant's name, keep it.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
#[serde(into = "String", try_from = "String")]
pub enum Mode {
    /// Interpolate the solution's radiosity (Gouraud over element corners).
    #[default]
    Preview,
    /// Final gather with sender classification (paper 000).
    Full,
    /// Classic final gather: every link resampled at every camera sample.
    Brute,
}

impl From<Mode> for String {
    fn from(mode: Mode) -> String {
        match mode {
            Mode::Preview => "preview".into(),
            Mode::Full => "full".into(),
            Mode::Brute => "brute".into(),
        }
    }
}

impl TryFrom<String> for Mode {
    type Error = String;

    fn try_from(name: String) -> std::result::Result<Self, String> {
        match name.as_str() {
            "preview" => Ok(Mode::Preview),
            "full" => Ok(Mode::Full),
            "brute" => Ok(Mode::Brute),
            _ => Err(format!("unknown mode {name:?}, expected \"preview\", \"full\" or \"brute\"")),
        }
    }
}

/// The full gather's grid (000 Sec. 4.2). Written as strings, like
/// [`Mode`].
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
#[serde(into = "String", try_from = "String")]
pub enum GridKind {
    /// Uniform in post-perspective space: constant spacing on screen.
    #[default]
    Perspective,
    /// Cubes over the scene's bounding box.
    Regular,
}

impl From<GridKind> for String {
    fn from(kind: GridKind) -> String {
        match kind {
            GridKind::Perspective => "perspective".into(),
            GridKind::Regular => "regular".into(),
        }
    }
}

impl TryFrom<String> for GridKind {
    type Error = String;

    fn try_from(name: String) -> std::result::Result<Self, String> {
        match name.as_str() {
            "perspective" => Ok(GridKind::Perspective),
            "regular" => Ok(GridKind::Regular),
            _ => Err(format!("unknown grid {name:?}, expected \"perspective\" or \"regular\"")),
        }
    }
}

stage_kit::show_by_name!(Mode, GridKind);

stage_kit::knobs! {
    /// The stage's parameters (`--params file.ron`, overridden by flags).
    pub struct Params {
        /// Gather mode: preview interpolates the solution; full classifies and resamples critical senders (paper 000); brute resamples every link.
        mode: Mode = Mode::Preview, "", value;
        /// Image width; none: the manifest camera's.
        width: Option<u32> = None, "pixels", optional(1..=MAX_SIDE);
        /// Image height; none: the manifest camera's.
        height: Option<u32> = None, "pixels", optional(1..=MAX_SIDE);
        /// Camera rays per pixel, stratified and jittered.
        spp: u32 = 4, "", value(at_least(1));
        /// Seed of the per-pixel random streams.
        seed: u64 = 0, "", value;
        /// Leaves whose normals differ by more than this do not blend at a shared corner; a pixel whose hits differ more is an edge in the surface layer.
        crease_angle_deg: f64 = 30.0, "degrees", value(0.0..=180.0);
        /// Corners closer than this fraction of the scene's bounding-box diagonal (per coordinate) are one point.
        weld_tolerance: f64 = 1e-7, "", value(left_open(0.0, 1e-3));
        /// Leaves of different materials do not blend at a shared corner (B jumps where emission or reflectance does, even on a flat surface).
        material_seams: bool = true, "", switch;
        /// Passes correcting the vertex radiosity towards values whose interpolant has each leaf's radiosity as its mean over the leaf; 0: plain area-weighted means.
        mean_passes: u32 = 3, "", value(0..=64);
        /// Each leaf shown as its four children on the least-squares plane through its neighbours' values, keeping its own as their mean; off: each leaf's value alone.
        leaf_gradients: bool = true, "", switch;
        /// Full: the grid, uniform in post-perspective space or cubes (000 Sec. 4.2).
        grid: GridKind = GridKind::Perspective, "", value;
        /// Full: grid spacing on screen.
        grid_pixels: u32 = 16, "pixels", value(at_least(1));
        /// Full: cells along the view axis (perspective grid).
        grid_depth: u32 = 16, "", value(1..=4096);
        /// Full: N of 000 Eq. 1, the classification samples a vertex shares among its senders in proportion to their unoccluded irradiance.
        samples: u32 = 128, "", value;
        /// Full: fewest samples per sender (classification and shadows).
        min_samples: u32 = 4, "", value(at_least(1));
        /// Full: most visibility samples per resampled sender, at least min_samples.
        max_shadow_samples: u32 = 128, "", value;
        /// Full: smallest visible contrast (a Weber fraction) where no mask is given; a sender is resampled when its error exceeds contrast x the vertex's radiosity.
        contrast: f64 = 0.02, "", value(left_open(0.0, 1.0));
        /// Full: surfaces a classification ray may cross and still count as unblocked: 1 for double-sided sheets, 2 for single-sided solids (000 Fig. 2).
        allowed_hits: u32 = 1, "", value(1..=2);
        /// Full: rays from a vertex inside a sender cluster (000 Sec. 4.3).
        interior_rays: u32 = 100, "", value;
        /// Full: surface-based gather where leaves are finer than the grid (000 Sec. 4.5).
        surface_gather: bool = true, "", switch;
        /// Full: rays a leaf of the surface-based gather casts to check each link the solver called fully visible or occluded whose error would not fit the threshold; 0 trusts the solver.
        leaf_check_rays: u32 = 8, "", value;
        /// Full: shadow samples bounded by penumbra size and contrast (000 Sec. 5.3); off: Eq. 1's count.
        view_dependent: bool = true, "", switch;
        /// Full: gather once per point of a lattice over the image, with visibility blocks interleaved 2 x 2, and interpolate to every camera sample on the same surface and plane; off: gather at every camera sample.
        lattice: bool = true, "", switch;
        /// Full: pixels between lattice points (16 points per pixel at most); none: min(1, 2 / sqrt(spp)), about 4 camera samples per lattice cell.
        lattice_spacing: Option<f64> = None, "pixels", optional(lattice::FINEST_SPACING..=64.0);
        /// Full: a camera sample whose lattice points around it differ by more than this fraction of the brightest is gathered between the pixel centres where the lattice is coarser, else itself (a shadow's or a contact's edge in the cell); 1: never.
        lattice_spread: f64 = 0.2, "", value(left_open(0.0, 1.0));
        /// Brute: visibility rays per link per camera sample.
        brute_samples: u32 = 64, "", value(at_least(1));
        /// Most mirror reflections and glass passages along a camera ray.
        specular_depth: u32 = 8, "", value(0..=64);
        /// A ray through mirrors and glass stops when its largest channel weight (product of rho_s, tau_s) falls under this.
        specular_min_weight: f64 = 1e-3, "", value(0.0..=1.0);
    }
}

impl Params {
    /// Checks every knob's range, and that `max_shadow_samples` is at
    /// least `min_samples`; the error names the parameter.
    pub fn validate(&self) -> Result<()> {
        self.check("")?;
        if self.max_shadow_samples < self.min_samples {
            return Err(bad_parameter(format!("max_shadow_samples must be at least min_samples ({}), not {}", self.min_samples, self.max_shadow_samples)));
        }
        Ok(())
    }
}

/// What the full gather reads besides the scene: the cluster hierarchy of
/// a clustered solution, and the mask's threshold image.
#[derive(Clone, Copy, Default)]
pub struct Extras<'a> {
    /// The cluster hierarchy the solution was solved with.
    pub clusters: Option<&'a schemas::cluster::Clusters>,
    /// The mask stage's threshold image (its `contrast` per pixel).
    pub threshold: Option<&'a schemas::threshold::ThresholdImage>,
    /// Surface detail (textures, alpha masks, normal maps) from mesh-prep's
    /// surface artifact, for a scene that has some.
    pub detail: Option<&'a detail::Detail<'a>>,
    /// gpu-shoot's lightmap, which the preview shades with where given
    /// ([`preview`]).
    pub lightmap: Option<&'a schemas::lightmap::Lightmap>,
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

/// What every mode starts from.
pub struct Frame<'a> {
    /// The camera.
    pub camera: &'a Pinhole,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The mesh's triangles.
    pub triangles: &'a [TriangleGeometry],
    /// Material of each triangle.
    pub materials: &'a [u32],
    /// How leaf corners blend where element radiosity is interpolated.
    pub smoothing: Smoothing,
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
    /// What each pixel saw (the image's `surface` layer).
    pub surfaces: schemas::image::PixelSurfaces,
    /// Work counters for the report.
    pub counters: BTreeMap<String, f64>,
    /// What was skipped and why, for the report.
    pub skipped: Vec<String>,
}

/// Largest image side, pixels.
pub const MAX_SIDE: u32 = 16_384;
/// Largest image, pixels (64 Mpx: with the film's accumulators and the
/// surface channels about 3 GiB of memory).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Checks that a `width` x `height` image can be rendered: each side in
/// `1..=MAX_SIDE`, at most [`MAX_PIXELS`] in all, so a mistyped size is an
/// error at once rather than an hour of work or an allocation failure.
pub fn check_image_size(width: u32, height: u32) -> std::result::Result<(), String> {
    check_side("width", width)?;
    check_side("height", height)?;
    if u64::from(width) * u64::from(height) > MAX_PIXELS {
        return Err(format!("image size {width}x{height}: more than {MAX_PIXELS} pixels"));
    }
    Ok(())
}

/// One side of an image, named `name`, in `1..=MAX_SIDE`.
fn check_side(name: &str, side: u32) -> std::result::Result<(), String> {
    if (1..=MAX_SIDE).contains(&side) {
        Ok(())
    } else {
        Err(format!("{name} must be 1 to {MAX_SIDE} pixels, got {side}"))
    }
}

/// The image size: `params`' where given, else the camera's.
pub fn image_size(params: &Params, manifest: &Manifest) -> (u32, u32) {
    (params.width.unwrap_or(manifest.camera.width), params.height.unwrap_or(manifest.camera.height))
}

/// Renders `scene` as `params` say. `rows_done` is called with the number
/// of image rows finished (from worker threads), for a progress display;
/// the image has [`image_size`]`.1` rows.
pub fn gather(params: &Params, scene: &Scene, rows_done: &(dyn Fn(u64) + Sync)) -> Result<Rendered> {
    gather_with(params, scene, Extras::default(), rows_done).map(|(r, _)| r)
}

/// [`gather`] with the full gather's extra inputs; also returns the full
/// and brute gathers' diagnostics.
pub fn gather_with(params: &Params, scene: &Scene, extras: Extras, rows_done: &(dyn Fn(u64) + Sync)) -> Result<(Rendered, Option<Diagnostics>)> {
    params.validate()?;
    let (width, height) = image_size(params, scene.manifest);
    check_image_size(width, height).map_err(|e| Error::invalid(scene.manifest_path, None, format!("{e} (the camera's size, or --width/--height)")))?;
    let camera = pinhole(&scene.manifest.camera, width, height).ok_or_else(|| {
        Error::invalid(
            scene.manifest_path,
            None,
            format!("camera is unusable for a {width}x{height} image (zero view direction, view parallel to up, field of view outside (0, 180) degrees, or zero size)"),
        )
    })?;
    let triangles = mesh_triangles(scene.mesh);
    let materials: Vec<u32> = scene.mesh.triangles.iter().map(|t| t.material).collect();
    let smoothing = Smoothing { crease_angle_deg: params.crease_angle_deg, weld_tolerance: params.weld_tolerance, material_seams: params.material_seams, mean_passes: params.mean_passes, leaf_gradients: params.leaf_gradients };
    let frame = Frame { camera: &camera, width, height, triangles: &triangles, materials: &materials, smoothing };
    if params.mode != Mode::Preview {
        // The solution belongs to the mesh; only the preview shades it.
        gouraud::checked_leaves(&triangles, scene.solution, scene.solution_path)?;
        return full_image::gather(params, scene, extras, &frame, rows_done).map(|(r, d)| (r, Some(d)));
    }
    let shading = Gouraud::new(&triangles, &materials, scene.solution, scene.solution_path, smoothing)?;
    preview::render(params, scene, extras, &frame, &shading, rows_done).map(|r| (r, None))
}

/// The BVH over `triangles`, whose rays pass through alpha-masked holes
/// where `detail` has alpha masks.
pub fn scene_rays(triangles: &[TriangleGeometry], detail: Option<&detail::Detail>) -> SceneRays {
    let corners: Vec<_> = triangles.iter().map(|t| t.corners).collect();
    match detail {
        Some(detail) => detail.rays(&corners),
        None => SceneRays::new(&corners),
    }
}

/// Whether some translucent material is not two-sided.
fn one_sided_translucent(manifest: &Manifest) -> bool {
    manifest.materials.iter().any(|m| !m.two_sided && m.diffuse_transmittance.iter().any(|&x| x > 0.0))
}

/// What a gather in `mode` leaves out, and why, given the scene's effects;
/// `detail`: the surface artifact was given (`--surface`), so textures and
/// alpha masks are applied, and normal maps in the full and brute gathers,
/// which compute cosines (the preview shows the solver's).
pub fn skipped(manifest: &Manifest, mode: Mode, detail: bool) -> Vec<String> {
    let e = &manifest.effects;
    let mut skipped = Vec::new();
    if mode == Mode::Preview {
        skipped.push("full gather (perspective grid, sender classification, resampling): preview mode interpolates the radiosity of the solution".to_string());
    }
    let no_surface = "present but not applied: pass mesh-prep's surface artifact with --surface";
    let present = [
        (e.textures && !detail, format!("diffuse textures: {no_surface}; the image shows element radiosity only")),
        (e.normal_maps && !detail, format!("normal maps: {no_surface}; cosines use the triangle normals")),
        (e.normal_maps && detail && mode == Mode::Preview, "normal maps: the preview shows the solver's element radiosity; the full gather applies them".to_string()),
        (e.alpha_masks && !detail, format!("alpha masks: {no_surface}; rays hit the whole triangles")),
        (e.specular_reflection, "specular reflection: traced as ideal and planar per triangle (no glossy reflection; a curved mirror is its facets)".to_string()),
        (e.specular_transmission, "specular transmission: traced as thin glass (rays go straight on; no refraction bending by thick glass)".to_string()),
        (e.diffuse_transmission && mode == Mode::Preview, "diffuse transmission: the preview shows the radiosity the solver transmitted; a translucent material that is not two-sided has no back face and shows black from behind".to_string()),
        (e.diffuse_transmission && mode != Mode::Preview && one_sided_translucent(manifest), "diffuse transmission: a translucent material that is not two-sided has no back face, transmits nothing and shows black from behind".to_string()),
    ];
    skipped.extend(present.into_iter().filter(|(on, _)| *on).map(|(_, why)| why));
    skipped
}

/// A warning when more than 1% of the camera's hits (the report's
/// `counters`) are back faces, which show black: the camera sits outside a
/// wall, or thin surfaces (leaves, paper) are one-sided where they should
/// be two-sided.
pub fn back_face_warning(counters: &BTreeMap<String, f64>) -> Option<String> {
    let (hits, back) = (counters.get("ray_hits")?, counters.get("back_face_hits")?);
    (*back > 0.01 * hits).then(|| {
        format!(
            "{:.1}% of the camera's hits are back faces, shown black: a camera outside a wall, or thin surfaces (leaves, paper) that need `two_sided: Some(true)` in the scene's material overrides",
            100.0 * back / hits
        )
    })
}

#[cfg(test)]
mod tests;

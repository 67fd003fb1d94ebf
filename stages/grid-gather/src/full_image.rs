//! Driving the full and brute-force gathers over the image: the scene's
//! checks and tables, the pre-pass that sizes the grid and averages the
//! mask's threshold per vertex, and
//! the shader ([`crate::film::Shader`]) that shades the surface points the
//! camera rays reach, directly or through mirrors and glass.

use crate::brute::brute_irradiance;
use crate::contrast::vertex_contrast;
use crate::detail::Detail;
use crate::diagnostics::{record, Tally, Work};
use crate::film::{expose, CameraHit, Lens, Sampling, Shader};
use crate::full_gather::{FullGather, Surface};
use crate::grid::Grid;
use crate::lattice::{IrradianceLattice, LatticePoint, Target};
use crate::pixel_surfaces::{self, SurfaceId};
use crate::senders::Senders;
use crate::specular::{Followed, Seen, Specular};
use crate::{scene_rays, skipped, Extras, Frame, Mode, Params, Rendered, Scene};
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::photometry::{DirectLight, Luminaire};
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;
use rayon::prelude::*;
use schemas::cluster::Clusters;
use schemas::diagnostics::Diagnostics;
use schemas::solution::Solution;
use schemas::threshold::ThresholdImage;
use schemas::{Error, Result};
use stage_kit::scene::luminaires;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Everything the full gather reads.
pub struct FullScene<'a> {
    /// Triangle geometry.
    pub triangles: &'a [TriangleGeometry],
    /// Material per triangle.
    pub surfaces: &'a [Surface],
    /// Object and material of each triangle, for the surface layer.
    pub ids: &'a [SurfaceId],
    /// The solution.
    pub solution: &'a Solution,
    /// The cluster hierarchy, if the solution was clustered.
    pub clusters: Option<&'a Clusters>,
    /// The mask's threshold, if given.
    pub threshold: Option<&'a ThresholdImage>,
    /// The camera.
    pub camera: &'a Pinhole,
    /// Surface detail (textures, alpha masks, normal maps), where the scene
    /// has some and the surface artifact was given.
    pub detail: Option<&'a Detail<'a>>,
    /// Per triangle of a two-sided translucent material: its diffuse
    /// transmittance and its twin (the other face); empty for a scene
    /// without diffuse transmission.
    pub transmission: &'a [Option<([f64; 3], u32)>],
    /// The goniometric point lights (luminaires). The solution's element
    /// radiosity holds the light they reflect; their direct light on the
    /// receiver is not in the links (a point light is no sender), so each
    /// camera sample adds it here, with a shadow ray per light.
    pub lights: &'a [Luminaire],
    /// The mirrors and glass camera rays continue through, in a scene that
    /// has some.
    pub specular: Option<&'a Specular>,
    /// The light the solver gathered through mirrors and glass, beyond its
    /// links ([`crate::specular::window_light`]), in a scene that has them.
    pub window_light: Option<&'a crate::gouraud::Gouraud>,
}

/// The full or brute-force gather of `scene` in `frame` (whose solution
/// the caller checked against the mesh).
pub(crate) fn gather(params: &Params, scene: &Scene, extras: Extras, frame: &Frame, rows_done: &(dyn Fn(u64) + Sync)) -> Result<(Rendered, Diagnostics)> {
    let Frame { camera, width, height, triangles, smoothing, .. } = *frame;
    if let Some(c) = extras.clusters {
        if c.nodes.len() != scene.solution.clusters.len() && !scene.solution.clusters.is_empty() {
            return Err(Error::invalid(scene.solution_path, None, format!("solution has {} clusters, the hierarchy {}", scene.solution.clusters.len(), c.nodes.len())));
        }
    } else if scene.solution.links.iter().any(|l| matches!(l.receiver, schemas::solution::Node::Cluster(_)) || matches!(l.sender, schemas::solution::Node::Cluster(_))) {
        return Err(Error::invalid(scene.solution_path, None, "solution has links between clusters: pass the hierarchy with --clusters"));
    }
    let surfaces: Vec<Surface> = scene
        .mesh
        .triangles
        .iter()
        .map(|t| {
            let m = scene.manifest.materials.get(t.material as usize);
            Surface { reflectance: m.map_or([0.0; 3], |m| m.diffuse), emission: m.map_or([0.0; 3], |m| m.emission) }
        })
        .collect();
    if triangles.is_empty() {
        let n = width as usize * height as usize;
        let surfaces = pixel_surfaces::collect(std::iter::repeat_n(pixel_surfaces::NOTHING, n));
        let rendered = Rendered { width: width as usize, height: height as usize, rgb: vec![[0.0; 3]; n], coverage: vec![0.0; n], surfaces, counters: BTreeMap::new(), skipped: Vec::new() };
        return Ok((rendered, Diagnostics { width: width as usize, height: height as usize, ..Default::default() }));
    }
    let ids = pixel_surfaces::surface_ids(scene.mesh, scene.manifest);
    let lights = if scene.manifest.effects.goniometric_lights {
        luminaires(&scene.manifest.goniometric_lights).map_err(|m| Error::invalid(scene.manifest_path, None, m))?
    } else {
        Vec::new()
    };
    let transmission = transmission(scene);
    let specular = Specular::new(scene.mesh, scene.manifest, triangles, params.specular_depth, params.specular_min_weight);
    let window_light = match specular {
        Some(_) => {
            let senders = Senders::new(triangles, scene.solution, extras.clusters, params.seed);
            let rays = scene_rays(triangles, extras.detail);
            Some(crate::specular::window_light(scene, triangles, &senders, &surfaces, extras.detail, &DirectLight { lights: &lights, rays: &rays }, smoothing)?)
        }
        None => None,
    };
    let full_scene = FullScene {
        triangles,
        surfaces: &surfaces,
        ids: &ids,
        solution: scene.solution,
        clusters: extras.clusters,
        threshold: extras.threshold,
        camera,
        detail: extras.detail,
        transmission: &transmission,
        lights: &lights,
        specular: specular.as_ref(),
        window_light: window_light.as_ref(),
    };
    let image = render_full(params, &full_scene, width, height, rows_done);
    let mut counters = image.counters;
    counters.insert("triangles".into(), triangles.len() as f64);
    counters.insert("elements".into(), scene.solution.elements.len() as f64);
    counters.insert("links".into(), scene.solution.links.len() as f64);
    let skipped = skipped(scene.manifest, params.mode, extras.detail.is_some());
    Ok((
        Rendered { width: width as usize, height: height as usize, rgb: image.rgb, coverage: image.coverage, surfaces: image.surfaces, counters, skipped },
        image.diagnostics,
    ))
}

/// Per triangle of a two-sided translucent material, its diffuse
/// transmittance and its twin (see [`FullScene`]); empty for
/// a scene without diffuse transmission.
fn transmission(scene: &Scene) -> Vec<Option<([f64; 3], u32)>> {
    if !scene.manifest.effects.diffuse_transmission {
        return Vec::new();
    }
    let tau = |t: &schemas::mesh::Triangle| scene.manifest.materials[t.material as usize].diffuse_transmittance;
    let twins = scene.mesh.twins();
    scene.mesh.triangles.iter().zip(twins).map(|(t, twin)| twin.filter(|_| tau(t).iter().any(|&x| x > 0.0)).map(|twin| (tau(t), twin))).collect()
}

/// What shades one surface point a camera ray reaches in the full or
/// brute gather.
struct Shading<'a> {
    params: &'a Params,
    scene: &'a FullScene<'a>,
    senders: &'a Senders<'a>,
    rays: &'a SceneRays,
    gather: &'a FullGather<'a>,
    grid: &'a Grid,
    luminaires: &'a DirectLight<'a>,
    /// The links' irradiance on the image lattice, where the full gather
    /// interpolates it ([`crate::lattice`]).
    lattice: Option<&'a IrradianceLattice>,
}

/// A pixel's state in the full and brute gathers.
struct GatherPixel {
    /// The brute gather's random stream, keyed by the brute sample count
    /// too, so a high-sample reference shares the camera jitter of a
    /// cheaper run but not its gather noise.
    stream: Stream,
    /// The work of the pixel's camera samples.
    work: Work,
    /// The links arriving at a hit point and at its twin face (scratch).
    links: (Vec<usize>, Vec<usize>),
}

impl Shader for Shading<'_> {
    type Pixel = GatherPixel;

    fn pixel(&self, index: u64) -> GatherPixel {
        GatherPixel { stream: Stream::new(self.params.seed, index, 1 + u64::from(self.params.brute_samples)), work: Work::default(), links: (Vec::new(), Vec::new()) }
    }

    /// Shades the front face seen directly, or what the ray reaches through
    /// a specular surface (from either side); a back face is black.
    fn shade(&self, pixel: &mut GatherPixel, camera: &CameraHit, sum: &mut [f64; 3], followed: &mut Followed) -> bool {
        let (scene, hit, eye) = (self.scene, camera.hit, self.scene.camera.eye);
        let front = camera.direction.dot(scene.triangles[hit.triangle as usize].normal) <= 0.0;
        let mut sample = Work::default();
        let GatherPixel { stream, links: (links, back_links), .. } = pixel;
        let mut shade = |seen: &Seen, at: Option<[f64; 2]>| {
            let radiance = self.radiance(seen, camera.k, at, (&mut *links, &mut *back_links), stream, &mut sample);
            (0..3).for_each(|c| sum[c] += seen.weight[c] * radiance[c]);
        };
        match scene.specular.filter(|s| s.is_specular(hit.triangle)) {
            Some(specular) => followed.add(specular.follow(self.rays, scene.triangles, eye, camera.direction, hit, &mut |seen| shade(seen, None))),
            None if front => shade(&Seen { hit, origin: eye, direction: camera.direction, weight: [1.0; 3], depth: 0 }, Some(camera.at)),
            None => {}
        }
        pixel.work.add(&sample);
        front
    }
}

impl Shading<'_> {
    /// The normal `triangle` shades with at barycentric `uv`: its normal
    /// map's where it has one, else its face normal.
    fn shading_normal(&self, triangle: u32, uv: [f64; 2]) -> DVec3 {
        let face = self.scene.triangles[triangle as usize].normal;
        self.scene.detail.map_or(face, |detail| detail.normal(triangle, uv, face))
    }

    /// The lattice point at image position `at`: the links' irradiance where
    /// the camera ray through it meets the front of a surface that is no
    /// mirror or pane, gathered with visibility block `block`.
    fn lattice_point(&self, at: [f64; 2], block: u32, work: &mut Work) -> Option<LatticePoint> {
        let scene = self.scene;
        let direction = scene.camera.direction(at[0], at[1]);
        let hit = self.rays.closest_hit(scene.camera.eye, direction, 0.0, f32::INFINITY, [u32::MAX; 2])?;
        let (triangle, tri) = (hit.triangle, &scene.triangles[hit.triangle as usize]);
        if direction.dot(tri.normal) > 0.0 || scene.specular.is_some_and(|s| s.is_specular(triangle)) {
            return None;
        }
        let point = scene.camera.eye + direction * f64::from(hit.t);
        let uv = tri.uv_of(point);
        let normal = self.shading_normal(triangle, uv);
        let mut links = Vec::new();
        let leaf = self.senders.chain(triangle, uv, &mut links);
        let irradiance = self.gather.irradiance(point, normal, triangle, leaf, &links, block, work);
        let depth = (point - scene.camera.eye).dot(scene.camera.forward());
        Some(LatticePoint { point, normal, surface: scene.ids[triangle as usize], depth, irradiance })
    }

    /// Irradiance at `p` on `triangle` (normal `normal`) from the links in
    /// `links`: the brute gather in brute mode, and for a point seen
    /// through mirrors or glass that lies outside the grid (the grid covers
    /// the directly visible points); else the full gather.
    #[allow(clippy::too_many_arguments)]
    fn irradiance(&self, p: DVec3, normal: DVec3, triangle: u32, leaf: u32, links: &[usize], seen: &Seen, pass: u32, stream: &mut Stream, work: &mut Work) -> [f64; 3] {
        if self.params.mode == Mode::Brute || (seen.depth > 0 && !self.grid.contains(p)) {
            brute_irradiance(self.senders, self.rays, p, normal, triangle, links, self.params.brute_samples, stream, work)
        } else {
            self.gather.irradiance(p, normal, triangle, leaf, links, pass, work)
        }
    }

    /// Radiance `B / pi` leaving the point `seen` reached towards its ray,
    /// for camera sample `pass`: `E + rho (H + H_lights) + tau H_back`
    /// (004 Eq. 4.4 for the last term); black on a back face. A point the
    /// camera sees directly, at image position `at`, takes `H` from the
    /// lattice where the lattice can interpolate it there. (Where it cannot,
    /// taking the `H` another sample of the pixel gathered instead, on the
    /// same surface and plane, put 3.5% into pixels at a floor's far edge,
    /// where one pixel spans 15 cm of it.)
    #[allow(clippy::too_many_arguments)]
    fn radiance(&self, seen: &Seen, pass: u32, at: Option<[f64; 2]>, (links, back_links): (&mut Vec<usize>, &mut Vec<usize>), stream: &mut Stream, work: &mut Work) -> [f64; 3] {
        let (scene, triangle) = (self.scene, seen.hit.triangle);
        let tri = &scene.triangles[triangle as usize];
        if seen.direction.dot(tri.normal) > 0.0 {
            return [0.0; 3];
        }
        let p = seen.origin + seen.direction * f64::from(seen.hit.t);
        let uv = tri.uv_of(p);
        let normal = self.shading_normal(triangle, uv);
        let interpolated = self.lattice.zip(at).and_then(|(lattice, at)| lattice.interpolate(&Target { at, point: p, normal, surface: scene.ids[triangle as usize] }, &|at, block, work| self.lattice_point(at, block, work)));
        let mut irradiance = match interpolated {
            Some(h) => {
                work.interpolated += 1;
                h
            }
            None => {
                let leaf = self.senders.chain(triangle, uv, links);
                self.irradiance(p, normal, triangle, leaf, links, seen, pass, stream, work)
            }
        };
        if let Some(windows) = scene.window_light {
            let light = windows.radiosity(triangle, uv);
            (0..3).for_each(|c| irradiance[c] += light[c]);
        }
        let (direct, cast) = self.luminaires.at_point(p, normal, triangle);
        work.visibility_rays += cast;
        // 004 Eq. 4.4: a translucent surface also emits tau times the
        // irradiance of its other face, gathered there (the twin's links and
        // normal, the same point).
        let transmitted = scene.transmission.get(triangle as usize).copied().flatten().map(|(tau, twin)| {
            let back = &scene.triangles[twin as usize];
            let back_leaf = self.senders.chain(twin, back.uv_of(p), back_links);
            let h = self.irradiance(p, back.normal, twin, back_leaf, back_links, seen, pass, stream, work);
            let (direct, cast) = self.luminaires.at_point(p, back.normal, twin);
            work.visibility_rays += cast;
            std::array::from_fn::<f64, 3, _>(|c| tau[c] * (h[c] + direct))
        });
        let s = scene.surfaces[triangle as usize];
        let rho = scene.detail.and_then(|detail| detail.reflectance(triangle, uv)).unwrap_or(s.reflectance);
        let t = transmitted.unwrap_or([0.0; 3]);
        std::array::from_fn(|c| (s.emission[c] + rho[c] * (irradiance[c] + direct) + t[c]) / PI)
    }
}

/// The full (or brute-force) image.
pub struct FullImage {
    /// Radiance per pixel, W/(m² sr).
    pub rgb: Vec<[f32; 3]>,
    /// Coverage per pixel.
    pub coverage: Vec<f32>,
    /// What each pixel saw.
    pub surfaces: schemas::image::PixelSurfaces,
    /// Diagnostics.
    pub diagnostics: Diagnostics,
    /// Work counters.
    pub counters: BTreeMap<String, f64>,
}

/// Renders `scene` at `width` x `height` by `params.mode` (full or brute).
pub fn render_full(params: &Params, scene: &FullScene, width: u32, height: u32, rows_done: &(dyn Fn(u64) + Sync)) -> FullImage {
    let (w, h) = (width as usize, height as usize);
    let rays = scene_rays(scene.triangles, scene.detail);
    let senders = Senders::new(scene.triangles, scene.solution, scene.clusters, params.seed);
    let camera = scene.camera;
    // Pre-pass: one ray through each pixel centre, for the depth range and
    // the per-cell mask threshold.
    let centres: Vec<Option<DVec3>> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let d = camera.direction((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            rays.closest_hit(camera.eye, d, 0.0, f32::INFINITY, [u32::MAX; 2]).map(|hit| camera.eye + d * f64::from(hit.t))
        })
        .collect();
    let grid = Grid::fit(params, camera, (width, height), &centres, scene.triangles);
    let vertex_contrast = vertex_contrast(params.contrast, &grid, &centres, w, h, scene.threshold);
    let gather = FullGather::new(&senders, &grid, &rays, scene.surfaces, params, vertex_contrast, width);
    let luminaires = DirectLight { lights: scene.lights, rays: &rays };
    let mut shading = Shading { params, scene, senders: &senders, rays: &rays, gather: &gather, grid: &grid, luminaires: &luminaires, lattice: None };
    let lattice = (params.mode == Mode::Full && params.lattice).then(|| {
        let spacing = params.lattice_spacing.unwrap_or_else(|| IrradianceLattice::default_spacing(params.spp));
        IrradianceLattice::gather(width, height, spacing, params.crease_angle_deg, params.lattice_spread, &|at, block, work| shading.lattice_point(at, block, work))
    });
    shading.lattice = lattice.as_ref();
    let lens = Lens { camera, triangles: scene.triangles, rays: Some(&rays), surfaces: scene.ids, crease_angle_deg: params.crease_angle_deg };
    let film = expose(&lens, Sampling { width, height, spp: params.spp, seed: params.seed }, &shading, rows_done);
    let mut work: Vec<Work> = film.pixels.iter().map(|p| p.work).collect();
    if let Some(lattice) = &lattice {
        work.iter_mut().zip(lattice.work_per_pixel()).for_each(|(w, points)| w.add(&points));
    }
    let tally = Tally { width, height, spp: params.spp, pixels: &work, hits: film.hits, specular: scene.specular.map(|_| film.specular), lattice_points: lattice.as_ref().map(|l| l.point_count() as u64) };
    let (diagnostics, counters) = record(&tally, &gather);
    FullImage { rgb: film.rgb, coverage: film.coverage, surfaces: film.surfaces, diagnostics, counters }
}

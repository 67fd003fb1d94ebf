//! Driving the full and brute-force gathers over the image: the pre-pass
//! that sizes the grid and averages the mask's threshold per vertex, the
//! camera rays, the per-pixel diagnostics.

use crate::detail::Detail;
use crate::full::{brute_irradiance, FullGather, Surface, Work, CLASS_NAMES};
use crate::grid::Grid;
use crate::pixel_surfaces::{self, PixelTally, SurfaceId};
use crate::render::pixel_offset;
use crate::senders::Senders;
use radiometry::bounds::Aabb;
use crate::specular::{Followed, Seen, Specular};
use crate::{GridKind, Mode, Params};
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::SceneRays;
use radiometry::photometry::{DirectLight, Luminaire};
use radiometry::sampling::Stream;
use rayon::prelude::*;
use schemas::cluster::Clusters;
use schemas::solution::Solution;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Diagnostics channel names of the four classes (000 Sec. 4.3).
pub const CLASS_NAMES_PIXEL: [&str; 4] = ["class.rv_rf", "class.rv_if", "class.iv_rf", "class.iv_if"];

/// A per-pixel contrast threshold image (the mask stage's `contrast`).
#[derive(Clone, Debug, PartialEq)]
pub struct ContrastImage {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Smallest visible contrast per pixel, row-major.
    pub contrast: Vec<f32>,
}

/// Per-pixel and per-vertex records of a full or brute-force gather, for
/// redrawing paper 000's Figs. 4 and 6.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Diagnostics {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Visibility rays per camera sample, per pixel.
    pub visibility_rays: Vec<f32>,
    /// Form-factor evaluations per camera sample, per pixel.
    pub form_factors: Vec<f32>,
    /// Senders per camera sample in each class ([`CLASS_NAMES`]), per pixel.
    pub classes: [Vec<f32>; 4],
    /// Fraction of camera samples shaded by the surface-based gather.
    pub surface: Vec<f32>,
    /// Built vertices: `(i, j, k)`, position, class counts, skipped
    /// senders, contrast threshold, classification rays and factors.
    pub vertices: Vec<VertexRecord>,
}

/// One built grid vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexRecord {
    /// Grid coordinates.
    pub ijk: [u32; 3],
    /// Position, mesh frame, m.
    pub position: [f32; 3],
    /// Senders per class ([`CLASS_NAMES`]).
    pub classes: [u32; 4],
    /// Senders skipped as fully occluded.
    pub skipped: u32,
    /// Contrast threshold used.
    pub contrast: f32,
    /// Visibility rays cast to classify.
    pub rays: u32,
    /// Form-factor evaluations to classify.
    pub factors: u32,
}

/// One image row of the full gather: per pixel radiance, coverage, work
/// and surface; the row's hits and specular rays.
type Row = (Vec<([f32; 3], f32, Work, [u32; 3])>, u64, Followed);

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
    pub threshold: Option<&'a ContrastImage>,
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
}

impl Shading<'_> {
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
    /// (004 Eq. 4.4 for the last term); black on a back face.
    fn radiance(&self, seen: &Seen, pass: u32, (links, back_links): (&mut Vec<usize>, &mut Vec<usize>), stream: &mut Stream, work: &mut Work) -> [f64; 3] {
        let (scene, triangle) = (self.scene, seen.hit.triangle);
        let tri = &scene.triangles[triangle as usize];
        if seen.direction.dot(tri.normal) > 0.0 {
            return [0.0; 3];
        }
        let p = seen.origin + seen.direction * f64::from(seen.hit.t);
        let uv = tri.uv_of(p);
        let leaf = self.senders.chain(triangle, uv, links);
        let normal = scene.detail.map_or(tri.normal, |detail| detail.normal(triangle, uv, tri.normal));
        let mut irradiance = self.irradiance(p, normal, triangle, leaf, links, seen, pass, stream, work);
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
    let rays = crate::scene_rays(scene.triangles, scene.detail);
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
    let forward = camera.direction(0.5 * f64::from(width), 0.5 * f64::from(height));
    let depths = centres.iter().flatten().map(|p| (*p - camera.eye).dot(forward));
    let (near, far) = depths.fold((f64::INFINITY, 0.0f64), |(a, b), d| (a.min(d), b.max(d)));
    let scene_box = Aabb::around(scene.triangles.iter().flat_map(|t| t.corners));
    let nx = (width as usize).div_ceil(params.grid_pixels as usize).max(1);
    let ny = (height as usize).div_ceil(params.grid_pixels as usize).max(1);
    let grid = match params.grid {
        GridKind::Perspective => {
            let (near, far) = if near.is_finite() && far > near { (0.98 * near, 1.02 * far) } else { (1.0, 2.0) };
            Grid::perspective(camera, width, height, near.max(1e-6), far, [nx, ny, params.grid_depth as usize])
        }
        GridKind::Regular => {
            let extent = (scene_box.max - scene_box.min).max(DVec3::splat(1e-9));
            let size = extent.max_element() / nx.max(ny) as f64;
            let n = (extent / size).to_array().map(|e| (e.ceil() as usize).max(1));
            Grid::regular(scene_box.min, size, n)
        }
    };
    let vertex_contrast = vertex_contrast(params, &grid, &centres, w, h, scene.threshold);
    let gather = FullGather::new(&senders, &grid, &rays, scene.surfaces, params, vertex_contrast, width);
    let spp = params.spp;
    let luminaires = DirectLight { lights: scene.lights, rays: &rays };
    let shading = Shading { params, scene, senders: &senders, rays: &rays, gather: &gather, grid: &grid, luminaires: &luminaires };
    let rows: Vec<Row> = (0..height)
        .into_par_iter()
        .map(|y| {
            let (mut links, mut back_links) = (Vec::new(), Vec::new());
            let (mut hits, mut followed) = (0u64, Followed::default());
            let row = (0..width)
                .map(|x| {
                    let pixel = u64::from(y) * u64::from(width) + u64::from(x);
                    let mut stream = Stream::new(params.seed, pixel, 0);
                    // Keyed by the brute sample count too, so a high-sample reference
                    // shares the camera jitter of a cheaper run but not its gather noise.
                    let mut gather_stream = Stream::new(params.seed, pixel, 1 + u64::from(params.brute_samples));
                    let (mut sum, mut covered, mut work, mut tally) = ([0.0f64; 3], 0u32, Work::default(), PixelTally::new(params.crease_angle_deg));
                    for k in 0..spp {
                        let (jx, jy) = pixel_offset(k, spp, &mut stream);
                        let d = camera.direction(f64::from(x) + jx, f64::from(y) + jy);
                        let Some(hit) = rays.closest_hit(camera.eye, d, 0.0, f32::INFINITY, [u32::MAX; 2]) else {
                            tally.other();
                            continue;
                        };
                        covered += 1;
                        hits += 1;
                        let tri = &scene.triangles[hit.triangle as usize];
                        let front = d.dot(tri.normal) <= 0.0;
                        let specular = scene.specular.filter(|s| s.is_specular(hit.triangle));
                        if front {
                            tally.front(scene.ids[hit.triangle as usize], tri.normal);
                        } else {
                            tally.other();
                        }
                        let mut sample = Work::default();
                        let mut shade = |seen: &Seen| {
                            let radiance = shading.radiance(seen, k, (&mut links, &mut back_links), &mut gather_stream, &mut sample);
                            (0..3).for_each(|c| sum[c] += seen.weight[c] * radiance[c]);
                        };
                        match specular {
                            Some(specular) => followed.add(specular.follow(&rays, scene.triangles, camera.eye, d, hit, &mut shade)),
                            None if front => shade(&Seen { hit, origin: camera.eye, direction: d, weight: [1.0; 3], depth: 0 }),
                            None => {}
                        }
                        work.add(&sample);
                    }
                    let n = f64::from(spp);
                    (sum.map(|s| (s / n) as f32), (f64::from(covered) / n) as f32, work, tally.finish())
                })
                .collect();
            rows_done(1);
            (row, hits, followed)
        })
        .collect();

    let mut image = FullImage {
        rgb: Vec::with_capacity(w * h),
        coverage: Vec::with_capacity(w * h),
        surfaces: Default::default(),
        diagnostics: Diagnostics { width: w, height: h, ..Diagnostics::default() },
        counters: BTreeMap::new(),
    };
    let (mut total, mut hits, mut specular) = (Work::default(), 0u64, Followed::default());
    let per = 1.0 / f64::from(spp);
    let mut seen = Vec::with_capacity(w * h);
    for (row, row_hits, followed) in rows {
        hits += row_hits;
        specular.add(followed);
        for (rgb, coverage, work, surface) in row {
            image.rgb.push(rgb);
            image.coverage.push(coverage);
            seen.push(surface);
            let d = &mut image.diagnostics;
            d.visibility_rays.push((work.visibility_rays as f64 * per) as f32);
            d.form_factors.push((work.form_factors as f64 * per) as f32);
            for c in 0..4 {
                d.classes[c].push((work.classes[c] as f64 * per) as f32);
            }
            d.surface.push((work.surface as f64 * per) as f32);
            total.add(&work);
        }
    }
    image.surfaces = pixel_surfaces::collect(seen);
    let (mut class_rays, mut class_factors, mut vertex_classes, mut skipped) = (0u64, 0u64, [0u64; 4], 0u64);
    for (index, data) in gather.built() {
        class_rays += data.rays;
        class_factors += data.factors;
        let counts = data.class_counts();
        (0..4).for_each(|c| vertex_classes[c] += u64::from(counts[c]));
        skipped += u64::from(data.skipped);
        let ijk = grid.vertex_of(index);
        image.diagnostics.vertices.push(VertexRecord {
            ijk: ijk.map(|x| x as u32),
            position: grid.vertex(ijk).as_vec3().to_array(),
            classes: counts,
            skipped: data.skipped,
            contrast: data.contrast as f32,
            rays: data.rays as u32,
            factors: data.factors as u32,
        });
    }
    for check in gather.checked_leaves() {
        class_rays += check.rays;
        class_factors += check.factors;
    }
    let pixels = f64::from(width) * f64::from(height);
    let c = &mut image.counters;
    c.insert("pixels".into(), pixels);
    c.insert("samples_per_pixel".into(), f64::from(spp));
    c.insert("rays_cast".into(), pixels * f64::from(spp) + pixels);
    c.insert("ray_hits".into(), hits as f64);
    c.insert("visibility_rays".into(), total.visibility_rays as f64);
    c.insert("form_factor_evaluations".into(), total.form_factors as f64);
    c.insert("visibility_rays_per_hit".into(), total.visibility_rays as f64 / hits.max(1) as f64);
    c.insert("form_factors_per_hit".into(), total.form_factors as f64 / hits.max(1) as f64);
    c.insert("surface_gather_hits".into(), total.surface as f64);
    c.insert("classification_visibility_rays".into(), class_rays as f64);
    c.insert("classification_form_factors".into(), class_factors as f64);
    c.insert("grid_vertices".into(), grid.vertex_count() as f64);
    c.insert("grid_vertices_built".into(), image.diagnostics.vertices.len() as f64);
    c.insert("senders_skipped_occluded".into(), skipped as f64);
    if scene.specular.is_some() {
        crate::specular::count(c, specular);
    }
    for k in 0..4 {
        c.insert(format!("vertex_senders_{}", CLASS_NAMES[k]), vertex_classes[k] as f64);
        c.insert(format!("pixel_senders_{}", CLASS_NAMES[k]), total.classes[k] as f64);
    }
    image
}

/// Per grid vertex, the contrast threshold: the mask's contrast averaged
/// over the pixels whose centre ray hits one of the (up to eight) cells
/// around the vertex (000 Sec. 5.2, "the average masking values in the
/// adjacent grid cells"); the `contrast` parameter where no mask is given
/// or no pixel sees those cells.
fn vertex_contrast(params: &Params, grid: &Grid, centres: &[Option<DVec3>], w: usize, h: usize, threshold: Option<&ContrastImage>) -> Vec<f64> {
    let mut out = vec![params.contrast; grid.vertex_count()];
    let Some(t) = threshold else { return out };
    let cells = grid.n[0] * grid.n[1] * grid.n[2];
    let mut sum = vec![(0.0f64, 0u64); cells];
    for (i, p) in centres.iter().enumerate() {
        let Some(p) = p else { continue };
        let Some(g) = grid.coordinates(*p) else { continue };
        let cell: [usize; 3] = std::array::from_fn(|a| (g[a].floor().max(0.0) as usize).min(grid.n[a] - 1));
        let (x, y) = (i % w, i / w);
        let (tx, ty) = ((x * t.width / w).min(t.width - 1), (y * t.height / h).min(t.height - 1));
        let c = f64::from(t.contrast[ty * t.width + tx]);
        if !c.is_finite() {
            continue;
        }
        let s = &mut sum[(cell[2] * grid.n[1] + cell[1]) * grid.n[0] + cell[0]];
        s.0 += c;
        s.1 += 1;
    }
    for (index, value) in out.iter_mut().enumerate() {
        let v = grid.vertex_of(index);
        let (mut total, mut count) = (0.0, 0u64);
        for m in 0..8 {
            let c: [i64; 3] = std::array::from_fn(|a| v[a] as i64 - 1 + ((m >> a) & 1) as i64);
            if (0..3).any(|a| c[a] < 0 || c[a] >= grid.n[a] as i64) {
                continue;
            }
            let s = sum[(c[2] as usize * grid.n[1] + c[1] as usize) * grid.n[0] + c[0] as usize];
            total += s.0;
            count += s.1;
        }
        if count > 0 {
            *value = total / count as f64;
        }
    }
    out
}

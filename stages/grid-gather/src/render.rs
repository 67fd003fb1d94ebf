//! Camera rays through the pixels, closest hits, and the per-pixel mean.

use crate::detail::Detail;
use crate::gouraud::Gouraud;
use crate::pixel_surfaces::{self, PixelTally, SurfaceId};
use crate::specular::{Followed, Seen, Specular};
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::{Hit, SceneRays};
use radiometry::sampling::Stream;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// What the camera sees: the scene's triangles, their BVH, their shading.
pub struct View<'a> {
    /// The camera.
    pub camera: &'a Pinhole,
    /// Triangle geometry, mesh frame.
    pub triangles: &'a [TriangleGeometry],
    /// BVH over `triangles` (its rays pass through alpha-masked holes);
    /// `None` for an empty scene.
    pub rays: Option<&'a SceneRays>,
    /// Radiosity over the surfaces.
    pub shading: &'a Gouraud,
    /// Textures, in a scene that has them.
    pub textured: Option<Textured<'a>>,
    /// The surface of each triangle, for the image's surface layer.
    pub surfaces: &'a [SurfaceId],
    /// Hit normals further apart than this make a pixel an edge, degrees.
    pub crease_angle_deg: f64,
    /// The mirrors and glass camera rays continue through, in a scene
    /// that has some.
    pub specular: Option<&'a Specular>,
}

/// What the display of a textured scene adds ([`crate::detail`]): at a
/// hit on a textured triangle, `B(x) = E + rho(x) H(x)` with the texture's
/// `rho(x)` and `H` interpolated like the radiosity.
#[derive(Clone, Copy)]
pub struct Textured<'a> {
    /// The texture lookups.
    pub detail: &'a Detail<'a>,
    /// Irradiance `H` over the surfaces (Gouraud over the elements' `H_e`).
    pub irradiance: &'a Gouraud,
    /// Emitted radiosity of each triangle's material, W/m².
    pub emission: &'a [[f64; 3]],
}

/// How pixels are sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Samples per pixel, at least 1.
    pub spp: u32,
    /// Seed of the per-pixel random streams.
    pub seed: u64,
}

/// A rendered image before it gets its header.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Radiance per pixel, W/(m² sr), linear RGB, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// Fraction of each pixel's samples that hit a surface.
    pub coverage: Vec<f32>,
    /// Camera rays that hit a surface.
    pub hits: u64,
    /// Of those, hits on the back of a triangle (shaded black).
    pub back_face_hits: u64,
    /// What each pixel saw.
    pub surfaces: schemas::image::PixelSurfaces,
    /// Rays continued through mirrors and glass.
    pub specular: Followed,
}

/// One image row: per pixel radiance, coverage and surface; the row's
/// hits, back-face hits and specular rays.
type Row = (Vec<([f32; 3], f32, [u32; 3])>, u64, u64, Followed);

/// The `k`-th of `n` sample positions in the unit pixel: the first `m²`
/// samples (`m = floor(sqrt n)`) are jittered in an `m x m` grid of
/// strata, row by row; the remaining `n - m²` are uniform over the pixel.
/// Every sample is uniform over its stratum, so the equal-weight mean is an
/// unbiased estimate of the pixel's mean radiance.
pub fn pixel_offset(k: u32, n: u32, stream: &mut Stream) -> (f64, f64) {
    let m = (f64::from(n).sqrt().floor() as u32).max(1);
    let (jx, jy) = (stream.next_f64(), stream.next_f64());
    if k < m * m {
        ((f64::from(k % m) + jx) / f64::from(m), (f64::from(k / m) + jy) / f64::from(m))
    } else {
        (jx, jy)
    }
}

/// Renders the image: rows in parallel, each pixel from its own random
/// stream keyed by `(seed, pixel index)`, so the result does not depend on
/// the thread count. Radiance of a front-face hit is `L = B / pi`
/// (Lambertian exitance to radiance, W/(m² sr)); a back-face hit
/// (`direction . normal > 0`) is black, since radiosity is one-sided; a miss
/// is black with no coverage. `rows_done` is called with 1 after each row.
pub fn render(view: &View, sampling: Sampling, rows_done: &(dyn Fn(u64) + Sync)) -> Film {
    let Sampling { width, height, spp, seed } = sampling;
    let rows: Vec<Row> = (0..height)
        .into_par_iter()
        .map(|y| {
            let (mut hits, mut back, mut followed) = (0, 0, Followed::default());
            let row = (0..width)
                .map(|x| {
                    let pixel = u64::from(y) * u64::from(width) + u64::from(x);
                    let mut stream = Stream::new(seed, pixel, 0);
                    let (mut sum, mut covered, mut tally) = ([0.0f64; 3], 0u32, PixelTally::new(view.crease_angle_deg));
                    for k in 0..spp {
                        let (jx, jy) = pixel_offset(k, spp, &mut stream);
                        let Some((triangle, sample)) = trace(view, f64::from(x) + jx, f64::from(y) + jy, &mut followed) else {
                            tally.other();
                            continue;
                        };
                        covered += 1;
                        hits += 1;
                        match sample {
                            Some(radiance) => {
                                sum.iter_mut().zip(radiance).for_each(|(s, r)| *s += r);
                                tally.front(view.surfaces[triangle as usize], view.triangles[triangle as usize].normal);
                            }
                            None => {
                                back += 1;
                                tally.other();
                            }
                        }
                    }
                    let n = f64::from(spp);
                    (sum.map(|s| (s / n) as f32), (f64::from(covered) / n) as f32, tally.finish())
                })
                .collect();
            rows_done(1);
            (row, hits, back, followed)
        })
        .collect();
    let mut film = Film { rgb: Vec::new(), coverage: Vec::new(), hits: 0, back_face_hits: 0, surfaces: Default::default(), specular: Followed::default() };
    let mut seen = Vec::with_capacity(width as usize * height as usize);
    for (row, hits, back, followed) in rows {
        film.specular.add(followed);
        film.rgb.extend(row.iter().map(|p| p.0));
        film.coverage.extend(row.iter().map(|p| p.1));
        seen.extend(row.iter().map(|p| p.2));
        film.hits += hits;
        film.back_face_hits += back;
    }
    film.surfaces = pixel_surfaces::collect(seen);
    film
}

/// One camera ray through image point `(x, y)`: `None` for a miss, else
/// the triangle hit with `None` for a back-face hit or `Some(L)`, the
/// radiance of a front-face hit, plus what the ray sees through mirrors and
/// glass ([`Specular::follow`]; a specular surface seen from behind is not
/// black when it transmits).
fn trace(view: &View, x: f64, y: f64, followed: &mut Followed) -> Option<(u32, Option<[f64; 3]>)> {
    let direction = view.camera.direction(x, y);
    let hit = view.rays?.closest_hit(view.camera.eye, direction, 0.0, f32::INFINITY, [u32::MAX; 2])?;
    let Some(specular) = view.specular.filter(|s| s.is_specular(hit.triangle)) else {
        return Some((hit.triangle, shade(view, view.camera.eye, direction, hit)));
    };
    let mut sum = [0.0; 3];
    let visit = &mut |s: &Seen| {
        if let Some(radiance) = shade(view, s.origin, s.direction, s.hit) {
            (0..3).for_each(|c| sum[c] += s.weight[c] * radiance[c]);
        }
    };
    followed.add(specular.follow(view.rays?, view.triangles, view.camera.eye, direction, hit, visit));
    Some((hit.triangle, Some(sum)))
}

/// The diffuse radiance `B / pi` the ray `origin + t direction` sees at
/// `hit`: `None` on a back face (radiosity is one-sided).
fn shade(view: &View, origin: DVec3, direction: DVec3, hit: Hit) -> Option<[f64; 3]> {
    let triangle = &view.triangles[hit.triangle as usize];
    if direction.dot(triangle.normal) > 0.0 {
        return None;
    }
    let point = origin + direction * f64::from(hit.t);
    let uv = triangle.uv_of(point);
    let textured = view.textured.and_then(|t| Some((t, t.detail.reflectance(hit.triangle, uv)?)));
    let radiosity = match textured {
        Some((t, rho)) => {
            let (e, h) = (t.emission[hit.triangle as usize], t.irradiance.radiosity(hit.triangle, uv));
            std::array::from_fn(|c| e[c] + rho[c] * h[c])
        }
        None => view.shading.radiosity(hit.triangle, uv),
    };
    Some(radiosity.map(|b| b / PI))
}

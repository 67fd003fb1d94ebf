//! The camera loop, once for every mode: rows in parallel, `spp`
//! stratified and jittered camera rays per pixel from the pixel's own
//! random stream keyed by `(seed, pixel index)` (so the image does not
//! depend on the thread count), the closest hit of each, and the
//! per-pixel mean of what a [`Shader`] makes of the hits. A miss is black
//! with no coverage. The preview ([`crate::preview`]) and the full and
//! brute gathers ([`crate::full_image`]) are shaders.

use crate::pixel_surfaces::{self, PixelTally, SurfaceId};
use crate::specular::Followed;
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::{Hit, SceneRays};
use radiometry::sampling::Stream;
use rayon::prelude::*;

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

/// What the camera looks at.
#[derive(Clone, Copy)]
pub struct Lens<'a> {
    /// The camera.
    pub camera: &'a Pinhole,
    /// Triangle geometry, mesh frame.
    pub triangles: &'a [TriangleGeometry],
    /// BVH over `triangles`; `None` for an empty scene (every ray misses).
    pub rays: Option<&'a SceneRays>,
    /// The surface of each triangle, for the image's surface layer.
    pub surfaces: &'a [SurfaceId],
    /// Hit normals further apart than this make a pixel an edge, degrees.
    pub crease_angle_deg: f64,
}

/// One camera ray that hit a surface.
#[derive(Clone, Copy, Debug)]
pub struct CameraHit {
    /// The camera sample's number in its pixel, `0..spp`.
    pub k: u32,
    /// Its image position (pixels, `x` right, `y` down).
    pub at: [f64; 2],
    /// Unit direction of the ray from the eye.
    pub direction: DVec3,
    /// The closest hit.
    pub hit: Hit,
}

/// What turns a camera ray's hit into radiance.
pub trait Shader: Sync {
    /// What a pixel carries from one camera sample to the next besides the
    /// radiance (the full gather's random stream and work; nothing for
    /// the preview). It is kept per pixel in [`Film::pixels`].
    type Pixel: Send;

    /// The state of pixel `index` (row-major), before its first sample.
    fn pixel(&self, index: u64) -> Self::Pixel;

    /// Adds the radiance `camera` sees along the hit ray, W/(m² sr) RGB, to
    /// `sum` (through mirrors and glass too, counting the rays continued in
    /// `followed`). Returns whether the hit counts as a front-face hit for
    /// the surface layer; one that does not is counted in
    /// [`Film::back_face_hits`].
    fn shade(&self, pixel: &mut Self::Pixel, camera: &CameraHit, sum: &mut [f64; 3], followed: &mut Followed) -> bool;
}

/// A rendered image before it gets its header.
#[derive(Clone, Debug, PartialEq)]
pub struct Film<P> {
    /// Radiance per pixel, W/(m² sr), linear RGB, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// Fraction of each pixel's samples that hit a surface.
    pub coverage: Vec<f32>,
    /// What each pixel saw.
    pub surfaces: schemas::image::PixelSurfaces,
    /// Camera rays that hit a surface.
    pub hits: u64,
    /// Of those, hits the shader did not count as front-face hits.
    pub back_face_hits: u64,
    /// Rays continued through mirrors and glass.
    pub specular: Followed,
    /// Each pixel's shader state after its last sample, row-major.
    pub pixels: Vec<P>,
}

/// One pixel: mean radiance, coverage, surface, shader state.
struct Pixel<P> {
    rgb: [f32; 3],
    coverage: f32,
    surface: [u32; 3],
    state: P,
}

/// One image row and its hits, back-face hits and specular rays.
struct Row<P> {
    pixels: Vec<Pixel<P>>,
    hits: u64,
    back_face_hits: u64,
    followed: Followed,
}

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

/// Renders the image through `lens` with `shader`: each pixel's radiance
/// is the mean over its `spp` samples, its coverage the fraction that hit.
/// `rows_done` is called with 1 after each row.
pub fn expose<S: Shader>(lens: &Lens, sampling: Sampling, shader: &S, rows_done: &(dyn Fn(u64) + Sync)) -> Film<S::Pixel> {
    let Sampling { width, height, spp, seed } = sampling;
    let camera = lens.camera;
    let rows: Vec<Row<S::Pixel>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let mut row = Row { pixels: Vec::with_capacity(width as usize), hits: 0, back_face_hits: 0, followed: Followed::default() };
            for x in 0..width {
                let index = u64::from(y) * u64::from(width) + u64::from(x);
                let mut stream = Stream::new(seed, index, 0);
                let mut state = shader.pixel(index);
                let (mut sum, mut covered, mut tally) = ([0.0f64; 3], 0u32, PixelTally::new(lens.crease_angle_deg));
                for k in 0..spp {
                    let (jx, jy) = pixel_offset(k, spp, &mut stream);
                    let at = [f64::from(x) + jx, f64::from(y) + jy];
                    let direction = camera.direction(at[0], at[1]);
                    let Some(hit) = lens.rays.and_then(|rays| rays.closest_hit(camera.eye, direction, 0.0, f32::INFINITY, [u32::MAX; 2])) else {
                        tally.other();
                        continue;
                    };
                    covered += 1;
                    row.hits += 1;
                    if shader.shade(&mut state, &CameraHit { k, at, direction, hit }, &mut sum, &mut row.followed) {
                        tally.front(lens.surfaces[hit.triangle as usize], lens.triangles[hit.triangle as usize].normal);
                    } else {
                        row.back_face_hits += 1;
                        tally.other();
                    }
                }
                let n = f64::from(spp);
                row.pixels.push(Pixel { rgb: sum.map(|s| (s / n) as f32), coverage: (f64::from(covered) / n) as f32, surface: tally.finish(), state });
            }
            rows_done(1);
            row
        })
        .collect();
    let n = width as usize * height as usize;
    let mut film =
        Film { rgb: Vec::with_capacity(n), coverage: Vec::with_capacity(n), surfaces: Default::default(), hits: 0, back_face_hits: 0, specular: Followed::default(), pixels: Vec::with_capacity(n) };
    let mut seen = Vec::with_capacity(n);
    for row in rows {
        film.hits += row.hits;
        film.back_face_hits += row.back_face_hits;
        film.specular.add(row.followed);
        for pixel in row.pixels {
            film.rgb.push(pixel.rgb);
            film.coverage.push(pixel.coverage);
            seen.push(pixel.surface);
            film.pixels.push(pixel.state);
        }
    }
    film.surfaces = pixel_surfaces::collect(seen);
    film
}

//! Secondary light by progressive shooting (paper 002 Section 3.2,
//! "Light-transfer reconstruction"; the shooting of progressive radiosity,
//! Cohen, Chen, Wallace, Greenberg 1988):
//!
//! - each secondary emitter polygon `P` holds unshot radiosity `dB_P`, the
//!   average over its vertices of what they received and have not yet
//!   passed on ("the values at the vertices of each polygon are averaged");
//! - the polygon of highest unshot power `A_P Y(dB_P)` shoots next, to
//!   every sample `x` of the other surfaces, with Lambert's formula over
//!   its triangles:
//!
//!   ```text
//!   dE(x) = dB_P F_{dx->P} V_P(x),   V_P(x) = (clear rays from P's vertices to x) / (P's vertices)
//!   ```
//!
//!   the paper's occlusion: "a ray is cast from each v_i to every display
//!   sample ... the result at each display sample is weighted based on the
//!   ray intersection count". The paper's polygons are coarse (a few
//!   vertices); a merged region here may have a hundred, so at most
//!   `occlusion_vertices` of them cast rays, evenly spread over the
//!   vertex list (all of them where there are fewer);
//! - a sample of reflectance `rho` gains `rho dE` of radiosity, and every
//!   polygon it is a vertex of gains the vertex average of those gains as
//!   unshot radiosity;
//! - shooting stops when the unshot power of all polygons together is
//!   under `threshold` of the power the light sources emit, or after
//!   `max_shots`.
//!
//! `bounces` > 0 limits the light to that many reflections off secondary
//! emitters (the unshot light is kept per generation, and the last
//! generation is received but not shot on): `bounces = 1` is paper 002's
//! one-bounce configuration ("ignoring the interaction from B to A").

use crate::emitters::Polygon;
use glam::DVec3;
use radiometry::color::luminance;
use radiometry::form_factor::point_to_one_sided_polygon;
use radiometry::rays::SceneRays;
use rayon::prelude::*;

/// A sample as the shooting sees it.
#[derive(Clone, Copy, Debug)]
pub struct Collector {
    /// Position, mesh frame.
    pub position: DVec3,
    /// Front unit normal.
    pub normal: DVec3,
    /// Surface index.
    pub surface: u32,
    /// Mesh triangle.
    pub triangle: u32,
    /// Diffuse reflectance.
    pub reflectance: [f64; 3],
    /// Reflected radiosity from the light sources, W/m².
    pub direct: [f64; 3],
    /// Reflected radiosity from the secondary emitters, W/m².
    pub indirect: [f64; 3],
}

/// What the shooting did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShootingWork {
    /// Shots.
    pub shots: usize,
    /// Visibility rays cast.
    pub rays: u64,
    /// Unshot power left, as a fraction of the emitted power.
    pub remaining: f64,
    /// Whether it fell under the threshold (else `max_shots` stopped it).
    pub converged: bool,
    /// Radiosity each polygon shot in all, W/m².
    pub shot: Vec<[f64; 3]>,
}

/// The shooting's knobs.
#[derive(Clone, Copy, Debug)]
pub struct ShootingParams {
    /// Stop when the unshot power is under this fraction of the emitted
    /// power.
    pub threshold: f64,
    /// At most this many shots.
    pub max_shots: usize,
    /// Reflections off secondary emitters; 0 for all of them.
    pub bounces: u32,
    /// At most this many of a polygon's vertices cast occlusion rays.
    pub occlusion_vertices: usize,
}

/// Shoots until converged (see the module documentation); adds each
/// sample's received light to its `indirect`. `emitted_power` is the
/// light sources' luminous power weighting, W; `shot` is called after each
/// shot with the remaining fraction.
pub fn shoot(polygons: &[Polygon], samples: &mut [Collector], rays: &SceneRays, emitted_power: f64, params: ShootingParams, shot: &(dyn Fn(f64) + Sync)) -> ShootingWork {
    let generations = params.bounces.max(1) as usize;
    let mut unshot = vec![vec![[0.0; 3]; generations]; polygons.len()];
    for (p, polygon) in polygons.iter().enumerate() {
        unshot[p][0] = vertex_mean(polygon, |s| samples[s].direct);
    }
    let mut member_of: Vec<Vec<usize>> = vec![Vec::new(); samples.len()];
    for (p, polygon) in polygons.iter().enumerate() {
        for &v in &polygon.vertices {
            member_of[v as usize].push(p);
        }
    }
    let mut work = ShootingWork { shot: vec![[0.0; 3]; polygons.len()], ..Default::default() };
    let power = |p: usize, g: usize, unshot: &[Vec<[f64; 3]>]| polygons[p].area * luminance(unshot[p][g]);
    // Each polygon's transfer factors, kept from its first shot for the
    // next ones (its geometry and occlusion do not change).
    let mut transfer: Vec<Option<Vec<f64>>> = vec![None; polygons.len()];
    let mut cached = 0usize;
    let mut gains: Vec<[f64; 3]> = Vec::with_capacity(samples.len());
    loop {
        let best = (0..polygons.len()).flat_map(|p| (0..generations).map(move |g| (p, g))).max_by(|a, b| power(a.0, a.1, &unshot).total_cmp(&power(b.0, b.1, &unshot)));
        let Some((p, g)) = best else {
            work.converged = true;
            break;
        };
        let total: f64 = (0..polygons.len()).flat_map(|p| (0..generations).map(move |g| (p, g))).map(|(p, g)| power(p, g, &unshot)).sum();
        work.remaining = if emitted_power > 0.0 { total / emitted_power } else { 0.0 };
        if work.remaining < params.threshold || power(p, g, &unshot) <= 0.0 {
            work.converged = true;
            break;
        }
        if work.shots >= params.max_shots {
            break;
        }
        let db = std::mem::take(&mut unshot[p][g]);
        for (s, d) in work.shot[p].iter_mut().zip(db) {
            *s += d;
        }
        if transfer[p].is_none() {
            let (factors, rays_cast) = transfer_factors(&polygons[p], samples, rays, params.occlusion_vertices);
            work.rays += rays_cast;
            // Over the cache's bound, the factors serve this shot only.
            let keep = cached + factors.len() <= CACHE_ENTRIES;
            cached += if keep { factors.len() } else { 0 };
            transfer[p] = Some(factors);
            shoot_with(transfer[p].as_deref().expect("just set"), &db, samples, &mut gains);
            if !keep {
                transfer[p] = None;
            }
        } else {
            shoot_with(transfer[p].as_deref().expect("cached"), &db, samples, &mut gains);
        }
        spread(&gains, g, generations, params.bounces, &member_of, polygons, &mut unshot);
        work.shots += 1;
        shot(work.remaining);
    }
    work
}

/// Most transfer factors kept between shots (8 bytes each).
const CACHE_ENTRIES: usize = 1 << 25;

/// A polygon as a sender: its triangles' corners, its normal, and the
/// vertices that cast its occlusion rays (at most `occlusion_vertices`,
/// evenly spread over its vertex list).
pub struct Sender {
    surface: u32,
    corners: Vec<[DVec3; 3]>,
    normal: DVec3,
    vertices: Vec<(DVec3, u32)>,
}

impl Sender {
    /// The sender of `polygon`, whose vertices are `samples`.
    pub fn new(polygon: &Polygon, samples: &[Collector], occlusion_vertices: usize) -> Self {
        let n = polygon.vertices.len();
        let casting = n.min(occlusion_vertices.max(1));
        Sender {
            surface: polygon.surface,
            corners: polygon.triangles.iter().map(|t| t.map(|s| samples[s as usize].position)).collect(),
            normal: samples[polygon.vertices[0] as usize].normal,
            vertices: (0..casting).map(|k| polygon.vertices[k * n / casting] as usize).map(|v| (samples[v].position, samples[v].triangle)).collect(),
        }
    }

    /// `F_{dx->P} V_P(x)` at `position` (unit `normal`, on `surface` and
    /// mesh `triangle`; 0 on the sender's own surface), and the rays cast:
    /// Lambert's formula summed over the triangles, the visible fraction
    /// by one ray from each casting vertex.
    pub fn factor(&self, rays: &SceneRays, position: DVec3, normal: DVec3, surface: u32, triangle: u32) -> (f64, u64) {
        if surface == self.surface {
            return (0.0, 0);
        }
        let factor: f64 = self.corners.iter().map(|c| point_to_one_sided_polygon(position, normal, c, self.normal)).sum();
        if factor <= 0.0 {
            return (0.0, 0);
        }
        let clear = self.vertices.iter().filter(|(v, t)| rays.segment_clear(*v, position, [*t, triangle])).count();
        (factor * clear as f64 / self.vertices.len() as f64, self.vertices.len() as u64)
    }
}

/// Per sample, [`Sender::factor`] of `polygon`, and the rays cast.
fn transfer_factors(polygon: &Polygon, samples: &[Collector], rays: &SceneRays, occlusion_vertices: usize) -> (Vec<f64>, u64) {
    let sender = Sender::new(polygon, samples, occlusion_vertices);
    let factors: Vec<(f64, u64)> = samples.par_iter().map(|x| sender.factor(rays, x.position, x.normal, x.surface, x.triangle)).collect();
    let rays_cast = factors.iter().map(|f| f.1).sum();
    (factors.into_iter().map(|f| f.0).collect(), rays_cast)
}

/// Adds `rho dB F V` to every sample's `indirect` and leaves it in `gains`.
fn shoot_with(factors: &[f64], db: &[f64; 3], samples: &mut [Collector], gains: &mut Vec<[f64; 3]>) {
    gains.clear();
    for (x, f) in samples.iter_mut().zip(factors) {
        let gain = [0, 1, 2].map(|k| x.reflectance[k] * db[k] * f);
        for (i, d) in x.indirect.iter_mut().zip(gain) {
            *i += d;
        }
        gains.push(gain);
    }
}

/// Passes the samples' `gains` from a shot of generation `g` on to the
/// unshot radiosity of the polygons they are vertices of: generation
/// `g + 1`, or none past the last one `bounces` allows.
fn spread(gains: &[[f64; 3]], g: usize, generations: usize, bounces: u32, member_of: &[Vec<usize>], polygons: &[Polygon], unshot: &mut [Vec<[f64; 3]>]) {
    let next = if bounces == 0 { Some(0) } else { (g + 1 < generations).then_some(g + 1) };
    let Some(next) = next else { return };
    let mut touched: Vec<usize> = gains.iter().enumerate().filter(|(_, g)| **g != [0.0; 3]).flat_map(|(s, _)| member_of[s].iter().copied()).collect();
    touched.sort_unstable();
    touched.dedup();
    for q in touched {
        let mean = vertex_mean(&polygons[q], |s| gains[s]);
        for (u, m) in unshot[q][next].iter_mut().zip(mean) {
            *u += m;
        }
    }
}

/// The mean over `polygon`'s vertices of `value`.
fn vertex_mean(polygon: &Polygon, value: impl Fn(usize) -> [f64; 3]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for &v in &polygon.vertices {
        for (s, x) in sum.iter_mut().zip(value(v as usize)) {
            *s += x;
        }
    }
    sum.map(|s| s / polygon.vertices.len() as f64)
}

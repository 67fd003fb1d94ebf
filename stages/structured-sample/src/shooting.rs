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
//!   ray intersection count";
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
        let polygon = &polygons[p];
        let corners: Vec<[DVec3; 3]> = polygon.triangles.iter().map(|t| t.map(|s| samples[s as usize].position)).collect();
        let sender_normal = samples[polygon.vertices[0] as usize].normal;
        let vertices: Vec<(DVec3, u32)> = polygon.vertices.iter().map(|&v| (samples[v as usize].position, samples[v as usize].triangle)).collect();
        let gains: Vec<([f64; 3], u64)> = samples
            .par_iter()
            .map(|x| {
                if x.surface == polygon.surface {
                    return ([0.0; 3], 0);
                }
                let factor: f64 = corners.iter().map(|c| point_to_one_sided_polygon(x.position, x.normal, c, sender_normal)).sum();
                if factor <= 0.0 {
                    return ([0.0; 3], 0);
                }
                let clear = vertices.iter().filter(|(v, t)| rays.segment_clear(*v, x.position, [*t, x.triangle])).count();
                let visible = clear as f64 / vertices.len() as f64;
                ([0, 1, 2].map(|k| x.reflectance[k] * db[k] * factor * visible), vertices.len() as u64)
            })
            .collect();
        work.rays += gains.iter().map(|g| g.1).sum::<u64>();
        let next = if params.bounces == 0 { Some(0) } else { (g + 1 < generations).then_some(g + 1) };
        for (s, (gain, _)) in gains.iter().enumerate() {
            for (i, d) in samples[s].indirect.iter_mut().zip(gain) {
                *i += d;
            }
        }
        if let Some(next) = next {
            let mut touched: Vec<usize> = gains.iter().enumerate().filter(|(_, g)| g.0 != [0.0; 3]).flat_map(|(s, _)| member_of[s].iter().copied()).collect();
            touched.sort_unstable();
            touched.dedup();
            for q in touched {
                let mean = vertex_mean(&polygons[q], |s| gains[s].0);
                for (u, m) in unshot[q][next].iter_mut().zip(mean) {
                    *u += m;
                }
            }
        }
        work.shots += 1;
        shot(work.remaining);
    }
    work
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

//! Monte Carlo photon tracing (paper 001's stochastic stage; the particle
//! tracing of Pattanaik and Mudur 1993 that it builds on): photons leave
//! the emitters carrying power, bounce off diffuse surfaces by Russian
//! roulette, and each hit is bucketed into the leaf mesh ([`crate::mesh`]).
//!
//! # Emission
//!
//! Emitters are the front faces of emitting triangles (exitance `M`, power
//! `M A` per channel) and the goniometric lights (flux `Phi`, equal in R,
//! G, B). An emitter is chosen with probability `p_j = P_j / sum P`
//! (channels summed), and the photon carries `P_j / p_j`, so that the sum
//! over `N` photons divided by `N` is an unbiased estimate of every power.
//! On a triangle the origin is uniform by area and the direction cosine
//! distributed about the front normal (a Lambertian emitter's radiance is
//! constant). A luminaire's direction is drawn with density proportional to
//! its intensity `I(d)`, by rejection against the table's maximum from
//! uniform directions on the sphere: `pdf(d) = I(d) / Phi`, photon power
//! `Phi`.
//!
//! # Bounces
//!
//! At a hit on a front face the photon's power is deposited (the incident
//! flux; `E = deposited / area`, radiosity `B = M + rho_d E`, the diffuse
//! part being all a radiosity solution shows). Then one event is drawn
//! with probabilities `q_d = max_c rho_d`, `q_s = max_c rho_s`, `q_t =
//! max_c tau_s` (diffuse, ideal specular reflection, ideal specular
//! transmission; their sum is at most 1 for a physical material), the
//! rest absorption; the photon continues with power `rho_c / q` per
//! channel of the event drawn: in a cosine-distributed direction, in the
//! mirror direction `d - 2 (d . n) n`, or straight on. Transmission keeps
//! the direction because materials carry no index of refraction: a thin
//! sheet (a window pane's two refractions cancel). A hit on a back face is
//! absorbed, except that a transmitting material lets the photon through
//! with probability `q_t` there too: surfaces are one-sided (mesh-prep
//! gives two-sided materials a twin face), as the radiosity solvers treat
//! them. Photons reflected or transmitted specularly are indirect light
//! for stage 3 (the direct pass sees emitters only along straight lines).
//! A photon that leaves the scene is lost.

use crate::mesh::{Elements, Vertices};
use glam::DVec3;
use radiometry::color::max_channel;
use radiometry::geometry::{frame_with_normal, TriangleGeometry};
use radiometry::photometry::Luminaire;
use radiometry::rays::SceneRays;
use radiometry::sampling::{square_to_triangle, Stream};
use schemas::mesh::{Manifest, Mesh};

/// Which hits a batch deposits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Deposit {
    /// Every hit (stage 1: direct and indirect light).
    All,
    /// Only hits after at least one diffuse bounce (stage 3: the direct
    /// light is computed deterministically instead).
    Indirect,
}

/// One emitter.
#[derive(Clone, Debug)]
enum Source {
    /// An emitting triangle.
    Triangle(u32),
    /// A goniometric light.
    Luminaire(usize),
}

/// The emitters with their selection probabilities.
#[derive(Clone, Debug)]
pub struct Emitters {
    sources: Vec<Source>,
    /// Cumulative selection probability, last entry 1.
    cdf: Vec<f64>,
    /// Power a photon of each source carries, W per channel (`P_j / p_j`).
    photon_power: Vec<[f64; 3]>,
    /// Total emitted power, W per channel.
    pub power: [f64; 3],
}

impl Emitters {
    /// The emitters of a scene; `None` when nothing emits.
    pub fn new(mesh: &Mesh, manifest: &Manifest, geometry: &[TriangleGeometry], luminaires: &[Luminaire]) -> Option<Self> {
        let mut sources = Vec::new();
        let mut powers: Vec<[f64; 3]> = Vec::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let m = manifest.materials[tri.material as usize].emission;
            if m.iter().any(|&x| x > 0.0) && geometry[t].area > 0.0 {
                sources.push(Source::Triangle(t as u32));
                powers.push(m.map(|x| x * geometry[t].area));
            }
        }
        for (k, l) in luminaires.iter().enumerate() {
            if l.flux() > 0.0 {
                sources.push(Source::Luminaire(k));
                powers.push([l.flux(); 3]);
            }
        }
        let total: f64 = powers.iter().map(|p| p.iter().sum::<f64>()).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut cdf = Vec::with_capacity(powers.len());
        let mut acc = 0.0;
        let mut photon_power = Vec::with_capacity(powers.len());
        for p in &powers {
            let prob = p.iter().sum::<f64>() / total;
            acc += prob;
            cdf.push(acc);
            photon_power.push(p.map(|x| x / prob));
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let power = [0, 1, 2].map(|c| powers.iter().map(|p| p[c]).sum());
        Some(Emitters { sources, cdf, photon_power, power })
    }
}

/// A cosine-distributed direction about unit normal `n` (Malley's method:
/// a uniform point on the disc lifted to the hemisphere).
fn cosine_direction(n: DVec3, s: &mut Stream) -> DVec3 {
    let [t, b, n] = frame_with_normal(n);
    let (r, phi) = (s.next_f64().sqrt(), 2.0 * std::f64::consts::PI * s.next_f64());
    let z = (1.0 - r * r).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// A uniform direction on the unit sphere.
fn sphere_direction(s: &mut Stream) -> DVec3 {
    let z = 1.0 - 2.0 * s.next_f64();
    let phi = 2.0 * std::f64::consts::PI * s.next_f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Everything a batch of photons needs, read-only.
pub struct Scene<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The manifest (materials).
    pub manifest: &'a Manifest,
    /// Triangle geometry, f64.
    pub geometry: &'a [TriangleGeometry],
    /// Ray casting.
    pub rays: &'a SceneRays,
    /// Goniometric lights.
    pub luminaires: &'a [Luminaire],
    /// The emitters.
    pub emitters: &'a Emitters,
    /// The leaf elements.
    pub elements: &'a Elements,
    /// Their vertices.
    pub vertices: &'a Vertices,
    /// Bounces after which a photon is dropped, whatever its weight (only
    /// reached with reflectances near 1).
    pub max_bounces: u32,
    /// Nearest hit a ray accepts, m. Skipping the triangle a photon leaves
    /// is not enough: its origin, rounded to f32 for the BVH, may lie a
    /// hair behind its plane, where a coplanar neighbour triangle (the
    /// other half of a quad) would take it as a back-face hit and absorb
    /// it. A millionth of the scene's diagonal is far above that rounding
    /// and far below any gap between surfaces that matters.
    pub t_min: f32,
}

/// What one batch of photons left: `(vertex, power W per channel)` per
/// deposit, in the order made, and the rays counted.
#[derive(Clone, Debug, Default)]
pub struct Batch {
    /// Deposits of photons that bounced at least once (indirect light).
    pub deposits: Vec<(u32, [f64; 3])>,
    /// Deposits of first hits (direct light; [`Deposit::All`] only).
    pub first_hits: Vec<(u32, [f64; 3])>,
    /// Rays cast.
    pub rays: u64,
    /// Photons that reached the bounce limit.
    pub capped: u64,
}

impl Scene<'_> {
    /// Traces `photons` photons from the stream `stream`, depositing the
    /// hits `deposit` selects.
    pub fn trace(&self, photons: usize, deposit: Deposit, stream: &mut Stream) -> Batch {
        let mut batch = Batch::default();
        for _ in 0..photons {
            self.trace_one(deposit, stream, &mut batch);
        }
        batch
    }

    fn trace_one(&self, deposit: Deposit, s: &mut Stream, batch: &mut Batch) {
        let e = self.emitters;
        let x = s.next_f64();
        let j = e.cdf.partition_point(|&c| c <= x).min(e.sources.len() - 1);
        let mut power = e.photon_power[j];
        let (mut origin, mut direction, mut from) = match e.sources[j] {
            Source::Triangle(t) => {
                let g = &self.geometry[t as usize];
                let b = square_to_triangle(s.next_f64(), s.next_f64());
                let p = g.corners[0] * b[0] + g.corners[1] * b[1] + g.corners[2] * b[2];
                (p, cosine_direction(g.normal, s), t)
            }
            Source::Luminaire(k) => {
                let l = &self.luminaires[k];
                let i_max = l.i_max();
                let mut d = sphere_direction(s);
                // Rejection: accepted with probability I(d) / I_max. The
                // flux is positive, so some direction has I > 0.
                while s.next_f64() * i_max >= l.intensity(d) {
                    d = sphere_direction(s);
                }
                (l.position, d, u32::MAX)
            }
        };
        for bounce in 0..=self.max_bounces {
            batch.rays += 1;
            let Some(hit) = self.rays.closest_hit(origin, direction, self.t_min, f32::INFINITY, [from, u32::MAX]) else { return };
            let t = hit.triangle as usize;
            let g = &self.geometry[t];
            let material = &self.manifest.materials[self.mesh.triangles[t].material as usize];
            let p = origin + direction * f64::from(hit.t);
            let q_t = max_channel(material.specular_transmittance);
            if direction.dot(g.normal) >= 0.0 {
                if q_t > 0.0 && s.next_f64() < q_t {
                    power = [0, 1, 2].map(|c| power[c] * material.specular_transmittance[c] / q_t);
                    (origin, from) = (p, t as u32);
                    continue;
                }
                return;
            }
            if bounce > 0 || deposit == Deposit::All {
                let [u, v] = g.uv_of(p);
                let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
                let scale = if u + v > 1.0 { 1.0 / (u + v) } else { 1.0 };
                let (leaf, local) = self.elements.locate(t, [u * scale, v * scale]);
                let corners = self.vertices.of_element[leaf];
                let list = if bounce > 0 { &mut batch.deposits } else { &mut batch.first_hits };
                for k in 0..3 {
                    let w = local[k].clamp(0.0, 1.0);
                    if w > 0.0 {
                        list.push((corners[k], power.map(|x| x * w)));
                    }
                }
            }
            let (q_d, q_s) = (max_channel(material.diffuse), max_channel(material.specular_reflectance));
            let x = s.next_f64();
            let (weight, q) = if x < q_d {
                direction = cosine_direction(g.normal, s);
                (material.diffuse, q_d)
            } else if x < q_d + q_s {
                direction = (direction - 2.0 * direction.dot(g.normal) * g.normal).normalize();
                (material.specular_reflectance, q_s)
            } else if x < q_d + q_s + q_t {
                (material.specular_transmittance, q_t)
            } else {
                return;
            };
            power = [0, 1, 2].map(|c| power[c] * weight[c] / q);
            origin = p;
            from = t as u32;
        }
        batch.capped += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_have_the_lambertian_mean_cosine() {
        // E[cos theta] = 2/3 for pdf cos / pi; none below the surface.
        let mut s = Stream::new(5, 0, 0);
        let n = DVec3::new(0.0, 0.6, 0.8);
        let count = 200_000;
        let cosines: Vec<f64> = (0..count).map(|_| cosine_direction(n, &mut s).dot(n)).collect();
        assert!(cosines.iter().all(|&c| c >= 0.0));
        let mean = cosines.iter().sum::<f64>() / count as f64;
        assert!((mean - 2.0 / 3.0).abs() < 0.003, "{mean}");
    }
}

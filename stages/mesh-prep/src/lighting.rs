//! Does each emitter light the scene? A wrongly wound area light gives an
//! image tens of times darker with no error (auto exposure hides it), so
//! mesh-prep looks: it casts [`RAYS_PER_SIDE`] cosine-distributed rays
//! (the directions a Lambertian emitter's power leaves in) from each
//! emitter's front and as many from its back, over the kept triangles with
//! radiometry's BVH, and warns when
//!
//! - more than half of the front rays hit nothing: most of the power leaves
//!   the scene (all of them: the emitter faces away from every surface);
//! - more than half of the front rays hit the *back* of a surface: the
//!   emitter shines into the inside of a closed object;
//! - half of the front rays hit a surface within a tenth of the distance
//!   half of the back rays travel (the back seeing an enclosure): a light
//!   just under a ceiling, wound so that it emits into it.
//!
//! The last two suggest the winding is reversed (emission leaves the side
//! around which the corners turn counter-clockwise). All three are warnings,
//! not errors: a cove light aimed at a nearby wall is meant to be so.
//! Samples are stratified and seeded per emitter, so the figures are the
//! same on every run.

use glam::DVec3;
use radiometry::geometry::frame_with_normal;
use radiometry::rays::SceneRays;
use radiometry::sampling::{square_to_triangle, Stream};
use schemas::mesh::Triangle;
use std::f64::consts::PI;

/// Rays cast from each side of each emitter.
pub const RAYS_PER_SIDE: usize = 256;

/// One emitter: an object's triangles of one emitting material.
#[derive(Clone, Debug, PartialEq)]
pub struct Emitter {
    /// How messages name it (object, material, file and line).
    pub label: String,
    /// Its kept triangles (indices into the mesh's triangles).
    pub triangles: Vec<u32>,
}

/// Where the rays from one side of an emitter went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SideStatistics {
    /// Fraction that hit nothing.
    pub escaped: f64,
    /// Fraction that hit the back face of a surface.
    pub back_faces: f64,
    /// Median distance to the first hit, m (mesh frame); infinite when at
    /// least half escaped.
    pub median_distance: f64,
}

/// Where the rays from the `side` (+1 front, -1 back) of `emitter` go.
/// Each ray starts at an area-uniform stratified point of the emitter and
/// leaves in a cosine-distributed direction about the side's normal
/// (Malley's method: a uniform point of the unit disc lifted onto the
/// hemisphere, pdf `cos(theta) / pi` per steradian).
pub fn side_statistics(rays: &SceneRays, positions: &[[f32; 3]], triangles: &[Triangle], emitter: &Emitter, side: f64, seed: u64) -> SideStatistics {
    let total: f64 = emitter.triangles.iter().map(|&t| f64::from(triangles[t as usize].area)).sum();
    let mut cumulative = Vec::with_capacity(emitter.triangles.len());
    let mut running = 0.0;
    for &t in &emitter.triangles {
        running += f64::from(triangles[t as usize].area) / total;
        cumulative.push(running);
    }
    let corner = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    let (mut escaped, mut back_faces) = (0usize, 0usize);
    let mut distances = Vec::with_capacity(RAYS_PER_SIDE);
    for k in 0..RAYS_PER_SIDE {
        let mut stream = Stream::new(seed, k as u64, side.to_bits());
        let pick = (k as f64 + stream.next_f64()) / RAYS_PER_SIDE as f64;
        let slot = cumulative.partition_point(|&c| c < pick).min(emitter.triangles.len() - 1);
        let index = emitter.triangles[slot];
        let triangle = &triangles[index as usize];
        let b = square_to_triangle(stream.next_f64(), stream.next_f64());
        let origin = triangle.vertices.iter().zip(b).map(|(&v, w)| corner(v) * w).sum::<DVec3>();
        let normal = DVec3::from(triangle.normal.map(f64::from)) * side;
        let [t, s, n] = frame_with_normal(normal.normalize_or(DVec3::Z));
        let (u, phi) = (stream.next_f64(), 2.0 * PI * stream.next_f64());
        let r = u.sqrt();
        let direction = t * (r * phi.cos()) + s * (r * phi.sin()) + n * (1.0 - u).max(0.0).sqrt();
        match rays.closest_hit(origin, direction, 1e-6, f32::INFINITY, [index; 2]) {
            None => {
                escaped += 1;
                distances.push(f64::INFINITY);
            }
            Some(hit) => {
                let hit_normal = DVec3::from(triangles[hit.triangle as usize].normal.map(f64::from));
                if direction.dot(hit_normal) > 0.0 {
                    back_faces += 1;
                }
                distances.push(f64::from(hit.t));
            }
        }
    }
    distances.sort_by(f64::total_cmp);
    let n = RAYS_PER_SIDE as f64;
    SideStatistics { escaped: escaped as f64 / n, back_faces: back_faces as f64 / n, median_distance: distances[RAYS_PER_SIDE / 2] }
}

/// The warnings for `emitters` over the kept mesh (see the module doc), one
/// line each, naming the emitter.
pub fn check_emitters(positions: &[[f32; 3]], triangles: &[Triangle], emitters: &[Emitter]) -> Vec<String> {
    if emitters.is_empty() {
        return Vec::new();
    }
    let corners: Vec<[DVec3; 3]> = triangles.iter().map(|t| t.vertices.map(|v| DVec3::from(positions[v as usize].map(f64::from)))).collect();
    let rays = SceneRays::new(&corners);
    let mut warnings = Vec::new();
    for (e, emitter) in emitters.iter().enumerate() {
        let front = side_statistics(&rays, positions, triangles, emitter, 1.0, e as u64);
        let back = side_statistics(&rays, positions, triangles, emitter, -1.0, e as u64);
        let percent = |f: f64| format!("{:.0}%", 100.0 * f);
        let label = &emitter.label;
        if front.escaped == 1.0 {
            warnings.push(format!("{label} faces away from every surface: all {RAYS_PER_SIDE} rays from its front leave the scene"));
        } else if front.escaped > 0.5 {
            warnings.push(format!("{label}: {} of the rays from its front leave the scene, so most of its power is lost", percent(front.escaped)));
        }
        let wound = "is it wound the wrong way? (it emits on the side its corners turn counter-clockwise around)";
        if front.back_faces > 0.5 {
            warnings.push(format!("{label}: {} of the rays from its front hit the back of a surface; {wound}", percent(front.back_faces)));
        } else if back.median_distance.is_finite() && 10.0 * front.median_distance < back.median_distance {
            warnings.push(format!(
                "{label}: half the rays from its front hit a surface within {:.3} m, while half from its back travel over {:.3} m; {wound}",
                front.median_distance, back.median_distance
            ));
        }
    }
    warnings
}

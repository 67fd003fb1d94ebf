//! Watertight ray/triangle intersection (Woop, Benthin & Wald 2013,
//! "Watertight Ray/Triangle Intersection", JCGT 2(1), Sec. 3-4).
//!
//! The ray is turned into a frame where it runs along +z from the origin:
//! with `k_z` the axis of the direction's largest magnitude (`k_x`, `k_y`
//! the next two, swapped when `d[k_z] < 0` to keep the winding), each
//! vertex relative to the origin `a = v - o` is sheared to
//! `(a_x - S_x a_z, a_y - S_y a_z, S_z a_z)` with `S_x = d_x / d_z`,
//! `S_y = d_y / d_z`, `S_z = 1 / d_z` (Sec. 3, Eqs. 1-2). The ray then meets
//! the triangle where the 2D point (0, 0) lies inside the sheared triangle,
//! decided by the three edge functions (Sec. 3, Eq. 3)
//!
//! `U = C_x B_y - C_y B_x`, `V = A_x C_y - A_y C_x`, `W = B_x A_y - B_y A_x`:
//!
//! a hit when all three have the same sign (zero counts as either), at
//! `t = (U A_z + V B_z + W C_z) / (U + V + W)`.
//!
//! Each edge function depends only on the edge's two sheared vertices, and
//! the vertices are sheared independently of the triangle they belong to,
//! so two triangles sharing an edge evaluate it to the same number with
//! opposite signs: a ray through the edge (or a shared vertex) is inside
//! one of them, whatever the rounding; no ray slips between them. Where an
//! edge function rounds to exactly 0 its sign is undecided in f32, and the
//! three are evaluated again in f64 (Sec. 4), where the f32 products are
//! exact.

use glam::Vec3A;
use obvhs::triangle::Triangle;

/// A ray in the sheared frame of the module documentation, set up once and
/// tested against many triangles.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    origin: Vec3A,
    /// `k_x, k_y, k_z`.
    axes: [usize; 3],
    /// `S_x, S_y, S_z`.
    shear: [f32; 3],
}

impl ShearedRay {
    /// The ray `origin + t direction` (direction nonzero).
    pub fn new(origin: Vec3A, direction: Vec3A) -> Self {
        let kz = direction.abs().max_position();
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = direction[kz];
        ShearedRay { origin, axes: [kx, ky, kz], shear: [direction[kx] / dz, direction[ky] / dz, 1.0 / dz] }
    }

    /// Vertex `v` relative to the origin, sheared (`x`, `y`) and the
    /// relative coordinate along `k_z` (not yet scaled by `S_z`).
    fn sheared(&self, v: Vec3A) -> [f32; 3] {
        let a = v - self.origin;
        let [kx, ky, kz] = self.axes;
        [a[kx] - self.shear[0] * a[kz], a[ky] - self.shear[1] * a[kz], a[kz]]
    }

    /// The ray parameter of the hit on `triangle` within `[t_min, t_max]`,
    /// or infinity for a miss; both faces are hit.
    pub fn intersect(&self, triangle: &Triangle, t_min: f32, t_max: f32) -> f32 {
        let (a, b, c) = (self.sheared(triangle.v0), self.sheared(triangle.v1), self.sheared(triangle.v2));
        let edge = |p: [f32; 3], q: [f32; 3]| q[0] * p[1] - q[1] * p[0];
        let (mut u, mut v, mut w) = (edge(b, c), edge(c, a), edge(a, b));
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let edge64 = |p: [f32; 3], q: [f32; 3]| f64::from(q[0]) * f64::from(p[1]) - f64::from(q[1]) * f64::from(p[0]);
            (u, v, w) = (edge64(b, c) as f32, edge64(c, a) as f32, edge64(a, b) as f32);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return f32::INFINITY;
        }
        let det = u + v + w;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let sz = self.shear[2];
        let t = (u * sz * a[2] + v * sz * b[2] + w * sz * c[2]) / det;
        if t >= t_min && t <= t_max {
            t
        } else {
            f32::INFINITY
        }
    }
}

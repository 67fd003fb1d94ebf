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

use glam::{Vec3A, Vec3Swizzles};
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

    /// The ray parameter of the hit on `triangle` within `[t_min, t_max]`,
    /// or infinity for a miss; both faces are hit. The three vertices are
    /// processed side by side, one per SIMD lane, each with the scalar
    /// operations of the module documentation in the same order (so the
    /// same rounding).
    #[inline]
    pub fn intersect(&self, triangle: &Triangle, t_min: f32, t_max: f32) -> f32 {
        let (v0, v1, v2) = (triangle.v0, triangle.v1, triangle.v2);
        let relative = [
            Vec3A::new(v0.x, v1.x, v2.x) - self.origin.x,
            Vec3A::new(v0.y, v1.y, v2.y) - self.origin.y,
            Vec3A::new(v0.z, v1.z, v2.z) - self.origin.z,
        ];
        let [kx, ky, kz] = self.axes;
        let [sx, sy, sz] = self.shear;
        // Lanes: vertices A, B, C.
        let x = relative[kx] - sx * relative[kz];
        let y = relative[ky] - sy * relative[kz];
        // Lanes: U (edge BC), V (edge CA), W (edge AB).
        let mut uvw = x.zxy() * y.yzx() - y.zxy() * x.yzx();
        if uvw.cmpeq(Vec3A::ZERO).any() {
            let edge = |p: usize, q: usize| (f64::from(x[q]) * f64::from(y[p]) - f64::from(y[q]) * f64::from(x[p])) as f32;
            uvw = Vec3A::new(edge(1, 2), edge(2, 0), edge(0, 1));
        }
        if uvw.cmplt(Vec3A::ZERO).any() && uvw.cmpgt(Vec3A::ZERO).any() {
            return f32::INFINITY;
        }
        let det = uvw.x + uvw.y + uvw.z;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let t = uvw.dot(sz * relative[kz]) / det;
        if t >= t_min && t <= t_max {
            t
        } else {
            f32::INFINITY
        }
    }
}

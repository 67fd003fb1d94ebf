//! CPU references of the GPU kernels, in f64, for the tests that tie each
//! kernel to its definition: the residual reduction per triangle and the
//! receiver pass (disc-approximation form factor, 004 Eq. 2.2 / 4.1, and
//! the point-light lookup, Eq. 3.4) with visibility supplied by the caller.

use crate::atlas::Atlas;
use crate::photometry::{angles, Ldt};
use glam::DVec3;

/// Residual power of triangle `t`: `sum_k dB_k A_k` over its covered
/// texels, W, RGB.
pub fn triangle_power(atlas: &Atlas, residual: &[[f32; 3]], t: usize) -> [f64; 3] {
    let r = atlas.triangles[t];
    let mut sum = [0.0; 3];
    for k in r.first as usize..(r.first + r.count) as usize {
        for c in 0..3 {
            sum[c] += residual[k][c] as f64 * atlas.texels[k].area as f64;
        }
    }
    sum
}

/// Disc-approximation form factor from a receiving point to a sending disc
/// of area `a_s` (004 Eq. 2.2 with m = 1): `A_s cos_s cos_r / (pi d^2 +
/// A_s)`, 0 when either side faces away. Finite as `d -> 0` (it tends to
/// `cos_s cos_r`), which is why the paper prefers it next to shared edges.
pub fn disc_form_factor(receiver: DVec3, receiver_normal: DVec3, sender: DVec3, sender_normal: DVec3, a_s: f64) -> f64 {
    let v = receiver - sender;
    let d2 = v.length_squared();
    if d2 <= 0.0 {
        return 0.0;
    }
    let d = d2.sqrt();
    let cos_s = sender_normal.dot(v) / d;
    let cos_r = -receiver_normal.dot(v) / d;
    if cos_s <= 0.0 || cos_r <= 0.0 {
        return 0.0;
    }
    a_s * cos_s * cos_r / (std::f64::consts::PI * d2 + a_s)
}

/// Irradiance at a receiving point from a point light of intensity
/// `i_max LDT(C, gamma)` W/sr at `light`, frame `(r0, u0, n0)` (004 Eq.
/// 3.4 with the receiver's cosine): `I cos_r / d^2`.
pub fn light_irradiance(receiver: DVec3, receiver_normal: DVec3, light: DVec3, frame: [DVec3; 3], ldt: &Ldt, i_max: f64) -> f64 {
    let v = receiver - light;
    let d2 = v.length_squared();
    let d = d2.sqrt();
    let cos_r = -receiver_normal.dot(v) / d;
    if cos_r <= 0.0 {
        return 0.0;
    }
    let w = v / d;
    let (c, gamma) = angles(w.to_array(), frame[2].to_array(), frame[0].to_array(), frame[1].to_array());
    i_max * ldt.lookup(c, gamma) * cos_r / d2
}

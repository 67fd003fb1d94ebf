//! CPU references of the GPU kernels, in f64, for the tests that tie each
//! kernel to its definition: the residual reduction per triangle and the
//! receiver pass (disc-approximation form factor, 004 Eq. 2.2 / 4.1; the
//! point-light lookup, Eq. 3.4, is `radiometry::photometry::Luminaire`'s)
//! with visibility supplied by the caller.

use crate::atlas::Atlas;
use glam::DVec3;
use radiometry::form_factor::point_to_polygon;
use stage_kit::scene::triangle_corners;

/// Residual power of triangle `t`: `sum_k dB_k A_k` over its covered
/// texels, W, RGB.
pub fn triangle_power(atlas: &Atlas, residual: &[[f32; 3]], t: usize) -> [f64; 3] {
    let r = atlas.triangles[t];
    let mut sum = [0.0; 3];
    for (d_b, texel) in residual.iter().zip(&atlas.texels).skip(r.first as usize).take(r.count as usize) {
        for (s, d) in sum.iter_mut().zip(d_b) {
            *s += *d as f64 * texel.area as f64;
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

/// The corners of the patch a covered texel stands for, mesh frame:
/// texel `(i, j)` of a region of side `n` covers the barycentric square
/// `[i/n, (i+1)/n] x [j/n, (j+1)/n]`, a parallelogram with edges `e1 / n`
/// and `e2 / n` (`e1 = P1 - P0`, `e2 = P2 - P0`) around its centre; on the
/// hypotenuse (`i + j + 1 = n`) only its lower-left half, a triangle, lies
/// in the triangle, and the texel's position is that half's centroid
/// (`centre - (half_u + half_v) / 3`). Takes the texel's position and
/// returns the corner count (3 or 4) and the corners.
pub fn texel_patch(position: DVec3, half_u: DVec3, half_v: DVec3, hypotenuse: bool) -> (usize, [DVec3; 4]) {
    let (a, b) = (half_u, half_v);
    if hypotenuse {
        let centre = position + (a + b) / 3.0;
        (3, [centre - a - b, centre + a - b, centre - a + b, DVec3::ZERO])
    } else {
        let centre = position;
        (4, [centre - a - b, centre + a - b, centre + a + b, centre - a + b])
    }
}

/// Near field of the receiver pass: a receiver nearer than
/// `sqrt(NEAR_FIELD (A_r + A_s))` (`A_s` the sample's extent) gets the exact
/// point-to-patch factor.
/// Beyond it the disc approximation's loss `A_s / (pi d^2 + A_s)` is below
/// `1 / (100 pi) = 0.3%` of the pair's share, and the point-to-patch factor
/// differs from the point-to-point one by `O(A_r / d^2)`, so the closed box
/// keeps its energy within 0.05% per shot (measured) while the costly
/// contour integral runs on a few receivers per sample only.
pub const NEAR_FIELD: f64 = 100.0;

/// A near sample over this many times a texel's area gives it its power by
/// reciprocity ([`area_transfer`]). At equal sizes the sample's point is as
/// good, and it conserves power exactly: in the closed box's one-shot test
/// (texel areas up to 10:1 between its triangles) reciprocity between
/// single texels lost or gained up to 1% of a shot (cause not pinned
/// down), the point 0.05%. A group of the default 8 x 8 texels, and a
/// sliver's texel before anything, are far over it.
pub const RECIPROCAL: f64 = 16.0;

/// Irradiance per unit sender radiosity that the receiver pass gives a
/// texel at `receiver` (normal `receiver_normal`, area `a_r`, patch
/// `patch`) from the area sample `sender` (area `a_s`), visibility
/// aside. Far (beyond [`NEAR_FIELD`]) the disc approximation (004 Eq. 2.2
/// / 4.1 with one disc per sample), [`disc_form_factor`]. Near, the
/// larger patch is integrated exactly with Lambert's contour formula
/// ([`point_to_polygon`], Howell B-1 / Baum et al. 1989, the polygon clipped
/// to the point's hemisphere; exact for an unoccluded polygon, so the factors
/// of polygons that tile a hemisphere sum to 1, 004 Eq. 2.3) and the
/// smaller one taken as a point:
///
/// A sample's size in these two choices is its polygon's area (`extent`),
/// not its exposed area `A_s`: a floor group mostly buried under a block,
/// taken as the point of its exposed texels, gave the block's lowest
/// texels up to 1.8 times Lambert's value.
///
/// - sample over [`RECIPROCAL`] times the texel (a group of texels):
///   `F(receiver -> sender.polygon) - F(receiver -> sender.hidden)`, the
///   irradiance a uniform polygon less its buried part gives the texel's
///   point (reciprocity). The group's centroid as a
///   point put the power of the group's near part half a group away: the
///   texels next to a shared edge were off by up to +-90% in the period of
///   the groups (issue 10, item 7).
/// - otherwise: `A_s F(sender -> patch) / A_r`, the patch's
///   exact share of the sender's power spread over the patch, so that the
///   shares of a closed room sum to 1 (004 Eq. 2.3).
///
/// By reciprocity the factor from a point to a polygon is at most 1, so no
/// texel gets more than its sender's radiosity; a sliver's patch (1e-6 m
/// wide), whose solid angle f32 cancellation lost (21.6 times the
/// physical maximum), is never integrated from a larger sender. 0 when the receiver's point lies behind the
/// sender's plane or (except by reciprocity, which counts the part of the
/// sender in front of the receiver) the sender's point behind the
/// receiver's.
pub fn area_transfer(receiver: DVec3, receiver_normal: DVec3, a_r: f64, patch: &[DVec3], sender: &AreaSample) -> f64 {
    let v = receiver - sender.point;
    let d2 = v.length_squared();
    let d = d2.sqrt();
    // The side of the sender is its plane's (the point is a hair in front).
    if d2 <= 0.0 || sender.normal.dot(receiver - sender.polygon[0]) <= 0.0 {
        return 0.0;
    }
    let near = d2 < NEAR_FIELD * (a_r + sender.extent);
    let reciprocal = near && sender.extent > RECIPROCAL * a_r;
    // Behind the receiver's plane only a sample taken by reciprocity
    // counts, for its part in front (the clip in point_to_polygon).
    if -receiver_normal.dot(v) / d <= 0.0 && !reciprocal {
        return 0.0;
    }
    if !near {
        return disc_form_factor(receiver, receiver_normal, sender.point, sender.normal, sender.area);
    }
    if reciprocal {
        let hidden = if sender.hidden.is_empty() { 0.0 } else { point_to_polygon(receiver, receiver_normal, sender.hidden) };
        return (point_to_polygon(receiver, receiver_normal, sender.polygon) - hidden).max(0.0);
    }
    sender.area * point_to_polygon(sender.point, sender.normal, patch) / a_r
}

/// An area sample as the receiver pass sees it: a group of the shooter's
/// texels.
pub struct AreaSample<'a> {
    /// Its point (the group's centroid), m.
    pub point: DVec3,
    /// The shooter's normal.
    pub normal: DVec3,
    /// Its area, m².
    pub area: f64,
    /// Its polygon's area, m² ([`crate::atlas::Group::extent`]), which
    /// decides near and far, and reciprocity.
    pub extent: f64,
    /// The part of the shooter it stands for ([`crate::atlas::Group::polygon`]).
    pub polygon: &'a [DVec3],
    /// Its buried part ([`crate::atlas::Group::hidden`]; empty: none).
    pub hidden: &'a [DVec3],
}

/// The patch of covered texel `k` of `atlas` ([`texel_patch`] with its
/// triangle's half edges).
pub fn patch_of(atlas: &Atlas, mesh: &schemas::mesh::Mesh, k: usize) -> (usize, [DVec3; 4]) {
    let texel = atlas.texels[k];
    let t = texel.triangle as usize;
    let p = triangle_corners(mesh, t);
    let region = atlas.regions[t];
    let n = 2.0 * region.size as f64;
    texel_patch(DVec3::from(texel.position.map(f64::from)), (p[1] - p[0]) / n, (p[2] - p[0]) / n, texel.on_hypotenuse(region))
}

//! Goniometric point lights (luminaires): the light distribution on a full
//! sphere of type C angles, its bicubic Catmull-Rom lookup (paper 004 Sec.
//! 2.3.2, 3.4, 3.4.1), its total flux, and the point light placed in the
//! mesh frame that every solver shoots or gathers from. The photometric
//! files themselves are read by `mesh-prep` only; later stages get the
//! table from the manifest (the stage kit's `scene::luminaires` places
//! them).
//!
//! # Angles
//!
//! Type C photometry: `gamma` is the angle from the luminaire's nadir
//! (0 = straight down the nadir axis, 180 = straight up), `C` the azimuth
//! of the half-plane containing the direction, measured from the `C0`
//! reference direction `r0` towards `u0 = n0 x r0` (004 Eq. 3.1-3.3: `t =
//! phi / 2 pi` on the `u0 . d > 0` side, `1 - phi / 2 pi` on the other, that
//! is the azimuth in `[0, 2 pi)`).
//!
//! # Units
//!
//! Tables hold luminous intensity, cd. The radiosity solvers work in
//! radiometric units; following 004 Eq. 2.12 (a monochromatic 555 nm
//! source, `I_e = I_v / 683`), the radiant intensity of a light is `I_e =
//! scale x I_v / 683` W/sr, the same in R, G, B ([`Luminaire`]).

use crate::form_factor::DUNAVANT_5;
use crate::rays::SceneRays;
use glam::DVec3;

/// Luminous efficacy of 555 nm radiation, lm/W (004 Eq. 2.11-2.12).
pub const K_M: f64 = 683.0;

/// A light distribution on a full sphere: luminous intensity at every
/// `(C, gamma)` of a grid, cd.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution {
    /// C angles, degrees, strictly increasing, in `[0, 360)`; the grid wraps
    /// from the last back to the first (+360).
    pub c_angles: Vec<f64>,
    /// Gamma angles, degrees, strictly increasing, from 0 to 180.
    pub gamma_angles: Vec<f64>,
    /// Intensity, cd, `[c * gamma_angles.len() + gamma]`.
    pub intensity: Vec<f64>,
}

impl Distribution {
    /// The distribution of the measured C-planes `planes[c][gamma]` (cd) on
    /// the grid `c_angles` x `gamma_angles` (degrees), completed to a full
    /// sphere: gamma is extended to `[0, 180]` with zero intensity where not
    /// measured (a luminaire that emits nothing there: the zero sits at the
    /// next step of the grid past the measured range, so the interpolation
    /// does not smear the last measured value over the unmeasured rest, see
    /// [`Distribution::flux`]), and a C-plane at 360 (the same as 0) is
    /// dropped. Errors say what is wrong, without a file name.
    pub fn full_sphere(mut c_angles: Vec<f64>, mut gamma: Vec<f64>, mut planes: Vec<Vec<f64>>) -> Result<Distribution, String> {
        if c_angles.is_empty() || gamma.len() < 2 || planes.len() != c_angles.len() || planes.iter().any(|p| p.len() != gamma.len()) {
            return Err(format!("{} C angles and {} gamma angles do not match {} planes", c_angles.len(), gamma.len(), planes.len()));
        }
        check_increasing(&gamma, "gamma angles")?;
        check_increasing(&c_angles, "C angles")?;
        if gamma[0] < 0.0 || gamma[gamma.len() - 1] > 180.0 {
            return Err(format!("gamma angles {}..{} lie outside 0..180 degrees", gamma[0], gamma[gamma.len() - 1]));
        }
        if c_angles[0] < 0.0 || c_angles[c_angles.len() - 1] > 360.0 {
            return Err(format!("C angles {}..{} lie outside 0..360 degrees", c_angles[0], c_angles[c_angles.len() - 1]));
        }
        if c_angles.len() > 1 && c_angles[c_angles.len() - 1] == 360.0 {
            c_angles.pop();
            planes.pop();
        }
        if gamma[0] > 0.0 {
            let step = (gamma[1] - gamma[0]).min(gamma[0]);
            for (k, g) in [(0, 0.0), (1, gamma[0] - step)] {
                if k == 1 && gamma[0] - step <= 0.0 {
                    continue;
                }
                gamma.insert(k, g);
                planes.iter_mut().for_each(|p| p.insert(k, 0.0));
            }
        }
        let last = gamma[gamma.len() - 1];
        if last < 180.0 {
            let step = (last - gamma[gamma.len() - 2]).min(180.0 - last);
            if last + step < 180.0 {
                gamma.push(last + step);
                planes.iter_mut().for_each(|p| p.push(0.0));
            }
            gamma.push(180.0);
            planes.iter_mut().for_each(|p| p.push(0.0));
        }
        let intensity: Vec<f64> = planes.into_iter().flatten().collect();
        if let Some(v) = intensity.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(format!("intensity {v} cd is not a finite non-negative number"));
        }
        Ok(Distribution { c_angles, gamma_angles: gamma, intensity })
    }

    /// Checks the invariants [`Distribution::full_sphere`] establishes, for
    /// a table read back from a manifest.
    pub fn new(c_angles: Vec<f64>, gamma_angles: Vec<f64>, intensity: Vec<f64>) -> Result<Distribution, String> {
        let (nc, ng) = (c_angles.len(), gamma_angles.len());
        if nc == 0 || ng < 2 || intensity.len() != nc * ng {
            return Err(format!("{nc} C angles x {ng} gamma angles do not match {} intensities", intensity.len()));
        }
        check_increasing(&c_angles, "C angles")?;
        check_increasing(&gamma_angles, "gamma angles")?;
        if c_angles[0] < 0.0 || c_angles[nc - 1] >= 360.0 || gamma_angles[0] != 0.0 || gamma_angles[ng - 1] != 180.0 {
            return Err("the table must cover C in [0, 360) and gamma from 0 to 180 degrees".into());
        }
        if let Some(v) = intensity.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(format!("intensity {v} cd is not a finite non-negative number"));
        }
        Ok(Distribution { c_angles, gamma_angles, intensity })
    }

    /// Largest intensity of the table, cd.
    pub fn i_max(&self) -> f64 {
        self.intensity.iter().fold(0.0f64, |a, &b| a.max(b))
    }

    /// Intensity at `(c, gamma)` degrees, cd: bicubic Catmull-Rom over the
    /// grid's indices (004 Sec. 3.4.1), along gamma with clamped ends,
    /// along C periodically (C wraps at 360). Between measured angles of
    /// uneven spacing the spline runs in index space, as a texture would
    /// (and as gpu-shoot's shader does). Never negative: the cubic's
    /// overshoot below zero is clamped.
    pub fn lookup(&self, c: f64, gamma: f64) -> f64 {
        let ng = self.gamma_angles.len();
        let nc = self.c_angles.len();
        let (gi, gt) = interval(&self.gamma_angles, gamma);
        let row = |ci: usize| -> f64 {
            let at = |k: isize| self.intensity[ci * ng + k.clamp(0, ng as isize - 1) as usize];
            let k = gi as isize;
            catmull_rom(at(k - 1), at(k), at(k + 1), at(k + 2), gt)
        };
        if nc == 1 {
            return row(0).max(0.0);
        }
        let c = c.rem_euclid(360.0);
        let c = if c < self.c_angles[0] { c + 360.0 } else { c };
        let (ci, ct) = periodic_interval(&self.c_angles, c);
        let wrap = |k: isize| k.rem_euclid(nc as isize) as usize;
        let k = ci as isize;
        catmull_rom(row(wrap(k - 1)), row(wrap(k)), row(wrap(k + 1)), row(wrap(k + 2)), ct).max(0.0)
    }

    /// Total luminous flux of the table, lm: `Phi = integral I(C, gamma)
    /// sin(gamma) dgamma dC` over the sphere, with `I` the interpolated
    /// [`Distribution::lookup`] the solvers use, by the midpoint rule on a
    /// 0.25 degree grid (the quadrature error is far below the spline's).
    ///
    /// Where a file measures only part of the sphere (an IES file's 0..90
    /// vertical angles), the unmeasured part emits nothing: a single zero
    /// at 180 degrees would let the spline carry the last measured value
    /// across the whole gap (the LM-63 example file has 5000 cd at 90
    /// degrees), so [`Distribution::full_sphere`] puts the zero one grid
    /// step past the measured range. Against the flux Photometric Toolbox
    /// computed for three RAB files this is within 0.13% (mesh-prep's
    /// `flux_matches_photometric_toolbox_within_half_a_percent`).
    pub fn flux(&self) -> f64 {
        let (ng, nc) = (720, 1440);
        let (dg, dc) = (180.0 / ng as f64, 360.0 / nc as f64);
        let mut sum = 0.0;
        for g in 0..ng {
            let gamma = (g as f64 + 0.5) * dg;
            let ring: f64 = (0..nc).map(|c| self.lookup((c as f64 + 0.5) * dc, gamma)).sum();
            sum += ring * gamma.to_radians().sin();
        }
        sum * dg.to_radians() * dc.to_radians()
    }
}

fn check_increasing(v: &[f64], what: &str) -> Result<(), String> {
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("{what}: {x} is not a finite number"));
    }
    match v.windows(2).position(|w| w[1] <= w[0]) {
        Some(i) => Err(format!("{what} are not strictly increasing ({} then {})", v[i], v[i + 1])),
        None => Ok(()),
    }
}

/// Catmull-Rom interpolation of `p1 .. p2` at `t` in [0, 1] with the outer
/// neighbours `p0`, `p3` (004 Sec. 3.4.1: an interpolating cubic, so the
/// measured values are reproduced exactly at the measured angles).
pub fn catmull_rom(p0: f64, p1: f64, p2: f64, p3: f64, t: f64) -> f64 {
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * (2.0 * p1 + (p2 - p0) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

/// The interval `[i, i+1]` of `angles` holding `x` and the fraction within.
fn interval(angles: &[f64], x: f64) -> (usize, f64) {
    let n = angles.len();
    if n == 1 || x <= angles[0] {
        return (0, 0.0);
    }
    let k = angles.partition_point(|&a| a <= x).min(n - 1).max(1) - 1;
    let t = ((x - angles[k]) / (angles[k + 1] - angles[k])).clamp(0.0, 1.0);
    (k, t)
}

/// [`interval`] on the periodic grid `angles` + (first + 360), without
/// building it: `x` in `[angles[0], angles[0] + 360)`.
fn periodic_interval(angles: &[f64], x: f64) -> (usize, f64) {
    let n = angles.len();
    let last = angles[n - 1];
    if x >= last {
        let t = ((x - last) / (angles[0] + 360.0 - last)).clamp(0.0, 1.0);
        return (n - 1, t);
    }
    interval(angles, x)
}

/// The angles `(C, gamma)` in degrees of direction `d` (unit, from the
/// light) in the light's frame `(n0 nadir, r0 C0 direction, u0 = n0 x r0)`:
/// `gamma = acos(n0 . d)` (004 Eq. 3.1), `C` the azimuth from `r0` towards
/// `u0` (Eq. 3.2-3.3).
pub fn angles(d: DVec3, n0: DVec3, r0: DVec3, u0: DVec3) -> (f64, f64) {
    let gamma = d.dot(n0).clamp(-1.0, 1.0).acos().to_degrees();
    let c = d.dot(u0).atan2(d.dot(r0)).to_degrees().rem_euclid(360.0);
    (c, gamma)
}

/// A goniometric point light as the solvers use it, mesh frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Luminaire {
    /// The table, cd.
    pub distribution: Distribution,
    /// Position, m.
    pub position: DVec3,
    /// The light's frame `[r0, u0, n0]`: C0 direction, `n0 x r0`, nadir.
    pub frame: [DVec3; 3],
    /// Watts per steradian per candela: `scale / 683` (004 Eq. 2.12).
    pub w_per_sr_per_cd: f64,
}

impl Luminaire {
    /// The light of `distribution` at `position` with nadir `n0` and C0
    /// direction `r0`, its intensities times `scale`, the placement checked
    /// (finite position, unit nadir, C0 perpendicular to it, positive
    /// scale); the error says what is wrong.
    pub fn new(distribution: Distribution, position: DVec3, n0: DVec3, r0: DVec3, scale: f64) -> Result<Luminaire, String> {
        if !position.is_finite() {
            return Err(format!("position {:?} is not finite", position.to_array()));
        }
        if !(n0.is_finite() && (n0.length() - 1.0).abs() < 1e-6 && r0.is_finite() && (r0.length() - 1.0).abs() < 1e-6 && n0.dot(r0).abs() < 1e-6) {
            return Err("nadir and c0 must be perpendicular unit vectors".into());
        }
        if !(scale.is_finite() && scale > 0.0 && (scale * distribution.i_max()).is_finite()) {
            return Err(format!("scale {scale} must be finite and > 0 (and scale x largest intensity finite)"));
        }
        Ok(Luminaire { distribution, position, frame: [r0, n0.cross(r0), n0], w_per_sr_per_cd: scale / K_M })
    }

    /// Radiant intensity towards unit direction `d` (from the light),
    /// W/sr: `I_e = scale I_v(C, gamma) / 683`.
    pub fn intensity(&self, d: DVec3) -> f64 {
        let [r0, u0, n0] = self.frame;
        let (c, gamma) = angles(d, n0, r0, u0);
        self.w_per_sr_per_cd * self.distribution.lookup(c, gamma)
    }

    /// Radiant intensity at the table's maximum, W/sr.
    pub fn i_max(&self) -> f64 {
        self.w_per_sr_per_cd * self.distribution.i_max()
    }

    /// Radiant flux, W (the same in R, G, B).
    pub fn flux(&self) -> f64 {
        self.w_per_sr_per_cd * self.distribution.flux()
    }

    /// Unoccluded irradiance at a point `p` with unit front normal `n`,
    /// W/m²: `E = I_e(d) cos(theta) / r^2` (004 Eq. 3.4 with the receiver's
    /// cosine), 0 behind the surface (`cos(theta) <= 0`: one-sided) and at
    /// the light itself. Singular as `r -> 0`; [`Luminaire::element_irradiance`]
    /// integrates over an element instead of sampling it there.
    pub fn irradiance(&self, p: DVec3, n: DVec3) -> f64 {
        let v = p - self.position;
        let r2 = v.length_squared();
        if r2 <= 0.0 {
            return 0.0;
        }
        let r = r2.sqrt();
        let cos = -n.dot(v) / r;
        if cos <= 0.0 {
            return 0.0;
        }
        self.intensity(v / r) * cos / r2
    }

    /// Irradiance averaged over a triangle `corners` with unit front normal
    /// `n`, W/m², each quadrature point seen through `visible(point)`
    /// (shadow rays: 1 lit, 0 blocked):
    ///
    /// ```text
    /// E_avg = 1/A integral_A I_e(d(x)) cos(theta(x)) / r(x)^2 v(x) dA
    ///       = 1/A integral_Omega I_e(d) v dOmega      (over the solid angle the triangle subtends)
    /// ```
    ///
    /// The integral is finite however close the light is (the solid angle
    /// is at most 2 pi), but the integrand is not: point samples of `cos /
    /// r^2` blow up near the foot of the light. So the triangle is split
    /// 1:4 recursively where it is near the light (its size over the
    /// light's distance to its centroid above `1/2`), down to `depth`
    /// levels (each level quarters the area), and each piece uses a
    /// 7-point degree-5 rule ([`DUNAVANT_5`], Dunavant 1985). Below the last level, a piece
    /// still near the light contributes its exact unoccluded solid angle
    /// (Van Oosterom and Strackee 1983) times the intensity towards its
    /// centroid and the visibility of its centroid: bounded, and exact for
    /// an isotropic light. A light on the plane of the triangle (`r -> 0`
    /// along the surface) gives `cos = 0` there, 0 from the pieces beside it.
    pub fn element_irradiance(&self, corners: [DVec3; 3], n: DVec3, depth: u32, visible: &mut dyn FnMut(DVec3) -> f64) -> f64 {
        let area = 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
        if area <= 0.0 {
            return 0.0;
        }
        self.power_on(corners, n, depth, visible) / area
    }

    /// `integral I_e cos / r^2 v dA` over one piece (see
    /// [`Luminaire::element_irradiance`]), W.
    fn power_on(&self, c: [DVec3; 3], n: DVec3, depth: u32, visible: &mut dyn FnMut(DVec3) -> f64) -> f64 {
        let centroid = (c[0] + c[1] + c[2]) / 3.0;
        let size = (c[1] - c[0]).length().max((c[2] - c[1]).length()).max((c[0] - c[2]).length());
        let distance = (centroid - self.position).length();
        // Entirely behind the light's side of the plane: nothing arrives.
        if n.dot(self.position - centroid) <= 0.0 {
            return 0.0;
        }
        if size > 0.5 * distance {
            if depth > 0 {
                let m = [(c[0] + c[1]) / 2.0, (c[1] + c[2]) / 2.0, (c[2] + c[0]) / 2.0];
                return [[c[0], m[0], m[2]], [m[0], c[1], m[1]], [m[2], m[1], c[2]], [m[0], m[1], m[2]]]
                    .into_iter()
                    .map(|piece| self.power_on(piece, n, depth - 1, visible))
                    .sum();
            }
            let d = centroid - self.position;
            if d.length_squared() <= 0.0 || n.dot(d) >= 0.0 {
                return 0.0;
            }
            return solid_angle(c.map(|p| p - self.position)) * self.intensity(d.normalize()) * visible(centroid);
        }
        let area = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length();
        DUNAVANT_5
            .iter()
            .map(|&(b, w)| {
                let p = c[0] * b[0] + c[1] * b[1] + c[2] * b[2];
                let e = self.irradiance(p, n);
                if e > 0.0 {
                    w * e * visible(p)
                } else {
                    0.0
                }
            })
            .sum::<f64>()
            * area
    }
}

/// Direct light from luminaires with visibility by shadow rays over the
/// scene's BVH: each ray runs from a receiving point to the light's
/// position, skipping the receiver's own triangle; a light sitting on a
/// surface is not blocked by it (the segment's last millionth is not
/// tested, [`SceneRays::segment_clear`]).
pub struct DirectLight<'a> {
    /// The lights.
    pub lights: &'a [Luminaire],
    /// The scene's rays.
    pub rays: &'a SceneRays,
}

impl DirectLight<'_> {
    /// Irradiance at point `p` of mesh triangle `triangle` (unit front
    /// normal `n`) from every light, W/m², one shadow ray per light that
    /// faces the point; and the rays cast.
    pub fn at_point(&self, p: DVec3, n: DVec3, triangle: u32) -> (f64, u64) {
        let (mut e, mut cast) = (0.0, 0u64);
        for light in self.lights {
            let unoccluded = light.irradiance(p, n);
            if unoccluded > 0.0 {
                cast += 1;
                if self.rays.segment_clear(p, light.position, [triangle, u32::MAX]) {
                    e += unoccluded;
                }
            }
        }
        (e, cast)
    }

    /// Irradiance averaged over the element `corners` of mesh triangle
    /// `triangle` (unit front normal `n`) from every light, W/m²
    /// ([`Luminaire::element_irradiance`] with `depth` near-field levels
    /// and a shadow ray per quadrature point); and the rays cast.
    pub fn over_element(&self, corners: [DVec3; 3], n: DVec3, triangle: u32, depth: u32) -> (f64, u64) {
        let (mut e, mut cast) = (0.0, 0u64);
        for light in self.lights {
            e += light.element_irradiance(corners, n, depth, &mut |p| {
                cast += 1;
                f64::from(u8::from(self.rays.segment_clear(p, light.position, [triangle, u32::MAX])))
            });
        }
        (e, cast)
    }
}

/// Solid angle of the triangle with corners `r` seen from the origin, sr
/// (Van Oosterom and Strackee 1983): `tan(Omega / 2) = |r0 . (r1 x r2)| /
/// (r0 r1 r2 + (r0 . r1) r2 + (r0 . r2) r1 + (r1 . r2) r0)`.
pub fn solid_angle(r: [DVec3; 3]) -> f64 {
    let l = r.map(|v| v.length());
    let numerator = r[0].dot(r[1].cross(r[2])).abs();
    let denominator = l[0] * l[1] * l[2] + r[0].dot(r[1]) * l[2] + r[0].dot(r[2]) * l[1] + r[1].dot(r[2]) * l[0];
    2.0 * numerator.atan2(denominator)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    fn isotropic(cd: f64) -> Distribution {
        Distribution::full_sphere(vec![0.0], vec![0.0, 90.0, 180.0], vec![vec![cd; 3]]).unwrap()
    }

    fn light(distribution: Distribution, position: DVec3) -> Luminaire {
        Luminaire { distribution, position, frame: [DVec3::X, DVec3::Z, -DVec3::Y], w_per_sr_per_cd: 1.0 / K_M }
    }

    #[test]
    fn catmull_rom_interpolates_and_reproduces_lines() {
        assert_eq!(catmull_rom(1.0, 2.0, 5.0, 3.0, 0.0), 2.0);
        assert_eq!(catmull_rom(1.0, 2.0, 5.0, 3.0, 1.0), 5.0);
        // A straight line stays a straight line.
        assert!((catmull_rom(1.0, 2.0, 3.0, 4.0, 0.25) - 2.25).abs() < 1e-12);
        // Hand computation: t = 0.5 -> (-p0 + 9 p1 + 9 p2 - p3) / 16.
        assert!((catmull_rom(1.0, 2.0, 5.0, 3.0, 0.5) - (-1.0 + 18.0 + 45.0 - 3.0) / 16.0).abs() < 1e-12);
    }

    #[test]
    fn constant_distribution_has_flux_4_pi_i_and_angles_follow_the_frame() {
        let d = isotropic(7.0);
        assert!((d.flux() - 4.0 * std::f64::consts::PI * 7.0).abs() < 1e-6 * d.flux());
        let (c, g) = angles(DVec3::Y, -DVec3::Z, DVec3::X, DVec3::Y);
        assert!((c - 90.0).abs() < 1e-12 && (g - 90.0).abs() < 1e-12);
    }

    #[test]
    fn cosine_distribution_has_flux_pi_i0() {
        // I = I0 cos(gamma) on the lower hemisphere, 0 above: Phi = pi I0.
        let gamma: Vec<f64> = (0..=18).map(|k| 5.0 * k as f64).collect();
        let plane = gamma.iter().map(|g: &f64| 100.0 * g.to_radians().cos().max(0.0)).collect();
        let d = Distribution::full_sphere(vec![0.0], gamma, vec![plane]).unwrap();
        assert!((d.flux() / (std::f64::consts::PI * 100.0) - 1.0).abs() < 2e-3, "{}", d.flux());
    }

    #[test]
    fn unmeasured_gamma_is_dark_past_one_grid_step() {
        let d = Distribution::full_sphere(vec![0.0], vec![0.0, 45.0, 90.0], vec![vec![10.0, 10.0, 10.0]]).unwrap();
        assert_eq!(d.gamma_angles, vec![0.0, 45.0, 90.0, 135.0, 180.0]);
        assert_eq!(d.lookup(0.0, 90.0), 10.0);
        assert_eq!(d.lookup(0.0, 135.0), 0.0);
        assert_eq!(d.lookup(0.0, 160.0), 0.0);
        let upper = Distribution::full_sphere(vec![0.0], vec![90.0, 180.0], vec![vec![4.0, 4.0]]).unwrap();
        assert_eq!(upper.gamma_angles, vec![0.0, 90.0, 180.0]);
    }

    #[test]
    fn bad_tables_are_refused() {
        assert!(Distribution::new(vec![0.0], vec![0.0, 180.0], vec![1.0]).is_err());
        assert!(Distribution::new(vec![0.0], vec![0.0, 180.0], vec![1.0, f64::NAN]).is_err());
        assert!(Distribution::new(vec![0.0], vec![0.0, 180.0], vec![1.0, -1.0]).is_err());
        assert!(Distribution::new(vec![0.0, 0.0], vec![0.0, 180.0], vec![1.0; 4]).is_err());
        assert!(Distribution::new(vec![0.0], vec![10.0, 180.0], vec![1.0; 2]).is_err());
        assert!(Distribution::full_sphere(vec![0.0], vec![0.0, 200.0], vec![vec![1.0; 2]]).is_err());
    }

    #[test]
    fn element_irradiance_matches_the_closed_form_under_an_isotropic_light() {
        // A square floor of side 2 at distance h below an isotropic light of
        // I W/sr on its axis: E_avg = I Omega / A, Omega = 4 asin(a^2 / (a^2 + h^2))
        // for a square of half-side a (solid angle of a rectangle).
        let l = light(isotropic(K_M), dvec3(0.0, 0.0, 0.0));
        for h in [1.0, 0.1, 1e-3, 0.0] {
            let (a, y) = (1.0, -h);
            let corners = [dvec3(-a, y, -a), dvec3(a, y, -a), dvec3(a, y, a), dvec3(-a, y, a)];
            let halves = [[corners[0], corners[2], corners[1]], [corners[0], corners[3], corners[2]]];
            let n = DVec3::Y;
            let e: f64 = halves.iter().map(|t| l.element_irradiance(*t, n, 8, &mut |_| 1.0) * 2.0).sum::<f64>() / 4.0;
            let omega = 4.0 * (a * a / (a * a + h * h)).asin();
            let exact = if h > 0.0 { omega / 4.0 } else { 0.0 };
            assert!((e - exact).abs() <= 1e-3 * exact.max(1e-9), "h {h}: {e} vs {exact}");
        }
        // Behind the floor: nothing.
        let t = [dvec3(-1.0, -1.0, -1.0), dvec3(1.0, -1.0, 1.0), dvec3(1.0, -1.0, -1.0)];
        assert_eq!(l.element_irradiance(t, -DVec3::Y, 8, &mut |_| 1.0), 0.0);
    }
}

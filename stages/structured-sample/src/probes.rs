//! The fine probe grid per surface: exact direct luminance (with ray-cast
//! visibility) on a regular grid, the "lower resolution image" paper 002
//! Section 3.2 reads its isolux regions from (its Figure 3: the surface
//! seen from above, the illumination quantised to a few levels), here
//! computed rather than looked at, with the derivatives the placement
//! needs. The display shows the direct light from it too
//! ([`ProbeGrid::irradiance_at`]).

use crate::direct::DirectLight;
use crate::surfaces::Surface;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// One probe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The mesh triangle under it; `None` outside the surface.
    pub triangle: Option<u32>,
    /// The irradiance, W/m², RGB.
    pub irradiance: [f64; 3],
    /// Visible fraction of the light sources ([`crate::direct::Irradiance`]).
    pub visibility: f64,
    /// Inside a solid standing on the surface ([`crate::burial::mark_probes`]).
    pub buried: bool,
}

impl Probe {
    /// The irradiance's luminance weighting (Y of its RGB), W/m²: isolux
    /// contours are lines of constant illuminance, whatever the surface
    /// reflects of it.
    pub fn illuminance(&self) -> f64 {
        radiometry::color::luminance(self.irradiance)
    }
}

/// The probe grid over one surface's bounding rectangle: nodes
/// `lo + (i, j) h`, `i = 0..=nu`, `j = 0..=nv`.
#[derive(Clone, Debug)]
pub struct ProbeGrid {
    /// Low corner, `(u, v)`.
    pub lo: DVec2,
    /// Node spacing, m.
    pub h: f64,
    /// Nodes along `u`.
    pub nu: usize,
    /// Nodes along `v`.
    pub nv: usize,
    /// Probes, `i + j nu`.
    pub probes: Vec<Probe>,
    /// Rays cast.
    pub rays: u64,
}

impl ProbeGrid {
    /// Probes `surface`'s direct light with `resolution` cells along its
    /// extent ([`Surface::extent`]); `key` offsets the probes' random
    /// streams (one range per surface).
    pub fn new(surface: &Surface, direct: &DirectLight, resolution: usize, key: u64) -> Self {
        Self::of(surface, resolution, |point, triangle, k| {
            let e = direct.at(point, surface.normal, triangle, key + k);
            (e.rgb, e.visibility, e.rays)
        })
    }

    /// Probes `surface` with `resolution` cells along its extent by
    /// `light(point, triangle, probe index) -> (irradiance RGB, visibility,
    /// rays cast)`.
    pub fn of(surface: &Surface, resolution: usize, light: impl Fn(DVec3, u32, u64) -> ([f64; 3], f64, u64) + Sync) -> Self {
        let h = surface.extent() / resolution as f64;
        let size = surface.hi - surface.lo;
        let (nu, nv) = ((size.x / h).round() as usize + 1, (size.y / h).round() as usize + 1);
        let evaluated: Vec<(Probe, u64)> = (0..nu * nv)
            .into_par_iter()
            .map(|k| {
                let uv = surface.lo + DVec2::new((k % nu) as f64, (k / nu) as f64) * h;
                let Some(triangle) = surface.triangle_at(uv) else {
                    return (Probe { triangle: None, irradiance: [0.0; 3], visibility: 1.0, buried: false }, 0);
                };
                let (irradiance, visibility, rays) = light(surface.point(uv), triangle, k as u64);
                (Probe { triangle: Some(triangle), irradiance, visibility, buried: false }, rays)
            })
            .collect();
        let rays = evaluated.iter().map(|p| p.1).sum();
        ProbeGrid { lo: surface.lo, h, nu, nv, probes: evaluated.into_iter().map(|p| p.0).collect(), rays }
    }

    /// The probe at node `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> &Probe {
        &self.probes[i + j * self.nu]
    }

    /// The four nodes around `uv` with their bilinear weights (clamped to
    /// the grid).
    fn cell(&self, uv: DVec2) -> [((usize, usize), f64); 4] {
        let g = ((uv - self.lo) / self.h).clamp(DVec2::ZERO, DVec2::new((self.nu - 1) as f64, (self.nv - 1) as f64));
        let (i, j) = ((g.x.floor() as usize).min(self.nu.saturating_sub(2)), (g.y.floor() as usize).min(self.nv.saturating_sub(2)));
        let (fx, fy) = (g.x - i as f64, g.y - j as f64);
        let (i1, j1) = ((i + 1).min(self.nu - 1), (j + 1).min(self.nv - 1));
        [((i, j), (1.0 - fx) * (1.0 - fy)), ((i1, j), fx * (1.0 - fy)), ((i, j1), (1.0 - fx) * fy), ((i1, j1), fx * fy)]
    }

    /// The illuminance at `uv`, bilinear between the four nodes around it
    /// (clamped to the grid).
    pub fn illuminance_at(&self, uv: DVec2) -> f64 {
        self.cell(uv).iter().map(|&((i, j), w)| w * self.at(i, j).illuminance()).sum()
    }

    /// Whether `uv` lies in the open: the visibility of the nodes round it
    /// that lie on the surface, bilinear, at least a half (in the open
    /// where none does).
    pub fn open_at(&self, uv: DVec2) -> bool {
        let (mut seen, mut total) = (0.0, 0.0);
        for ((i, j), w) in self.cell(uv) {
            let p = self.at(i, j);
            if p.triangle.is_some() {
                seen += w * p.visibility;
                total += w;
            }
        }
        total <= 0.0 || seen >= 0.5 * total
    }

    /// The irradiance (RGB) at `uv` for display: bilinear between the four
    /// nodes around it where all four lie on the surface and in the open
    /// (not buried) and `uv` lies within the grid; `None` elsewhere (along
    /// the surface's border and a solid's footprint, within a cell), where
    /// the display evaluates the direct light itself.
    ///
    /// The display takes the direct light from here rather than from the
    /// samples (a choice; paper 002 Section 3.2 filters the samples' full
    /// luminance): the probes are finer than the samples everywhere but
    /// along shadow edges and hold the exact direct light, whose peaks and
    /// penumbrae the samples' filter could only approximate. Filtered with
    /// the rest, it put bands of +-5% between the isolux contours on the
    /// built-in Cornell box's floor, +1.2% on the floor's mean (README,
    /// Structured sampling).
    pub fn irradiance_at(&self, uv: DVec2) -> Option<[f64; 3]> {
        let g = (uv - self.lo) / self.h;
        if g.x < 0.0 || g.y < 0.0 || g.x > (self.nu - 1) as f64 || g.y > (self.nv - 1) as f64 {
            return None;
        }
        let mut sum = [0.0; 3];
        for ((i, j), w) in self.cell(uv) {
            let p = self.at(i, j);
            if p.triangle.is_none() || p.buried {
                return None;
            }
            for (a, e) in sum.iter_mut().zip(p.irradiance) {
                *a += w * e;
            }
        }
        Some(sum)
    }

    /// `(u, v)` of node `(i, j)`.
    pub fn uv(&self, i: usize, j: usize) -> DVec2 {
        self.lo + DVec2::new(i as f64, j as f64) * self.h
    }

    /// The curvature of the isolux line through an interior node (1/m),
    /// from central differences of the illuminance `f`:
    ///
    /// ```text
    /// kappa = |f_uu f_v² - 2 f_uv f_u f_v + f_vv f_u²| / |grad f|³
    /// ```
    ///
    /// 0 where a neighbour lies outside the surface or the gradient
    /// vanishes (no contour passes).
    pub fn curvature(&self, i: usize, j: usize) -> f64 {
        if i == 0 || j == 0 || i + 1 >= self.nu || j + 1 >= self.nv {
            return 0.0;
        }
        let mut f = [[0.0; 3]; 3];
        for (a, row) in f.iter_mut().enumerate() {
            for (b, value) in row.iter_mut().enumerate() {
                let p = self.at(i + a - 1, j + b - 1);
                if p.triangle.is_none() {
                    return 0.0;
                }
                *value = p.illuminance();
            }
        }
        let h = self.h;
        let (fu, fv) = ((f[2][1] - f[0][1]) / (2.0 * h), (f[1][2] - f[1][0]) / (2.0 * h));
        let fuu = (f[2][1] - 2.0 * f[1][1] + f[0][1]) / (h * h);
        let fvv = (f[1][2] - 2.0 * f[1][1] + f[1][0]) / (h * h);
        let fuv = (f[2][2] - f[2][0] - f[0][2] + f[0][0]) / (4.0 * h * h);
        let g2 = fu * fu + fv * fv;
        if g2 <= 0.0 {
            return 0.0;
        }
        (fuu * fv * fv - 2.0 * fuv * fu * fv + fvv * fu * fu).abs() / g2.powf(1.5)
    }

    /// `|grad f|` of the illuminance at an interior node (W/m³) by central
    /// differences; 0 at the border and where a neighbour lies outside.
    pub fn gradient(&self, i: usize, j: usize) -> f64 {
        if i == 0 || j == 0 || i + 1 >= self.nu || j + 1 >= self.nv {
            return 0.0;
        }
        let f = |a: usize, b: usize| self.at(a, b).triangle.map(|_| self.at(a, b).illuminance());
        match (f(i + 1, j), f(i - 1, j), f(i, j + 1), f(i, j - 1)) {
            (Some(e), Some(w), Some(n), Some(s)) => ((e - w).powi(2) + (n - s).powi(2)).sqrt() / (2.0 * self.h),
            _ => 0.0,
        }
    }

    /// The mean of [`Self::gradient`] over the interior nodes inside the
    /// surface.
    pub fn mean_gradient(&self) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for j in 1..self.nv.saturating_sub(1) {
            for i in 1..self.nu.saturating_sub(1) {
                if self.at(i, j).triangle.is_some() {
                    sum += self.gradient(i, j);
                    n += 1;
                }
            }
        }
        if n > 0 { sum / n as f64 } else { 0.0 }
    }

    /// Whether node `(i, j)` lies in a penumbra: the light sources partly
    /// visible there, or a neighbour's visibility differs from its own by
    /// more than 2% (a shadow edge passes between them).
    pub fn in_penumbra(&self, i: usize, j: usize) -> bool {
        let p = self.at(i, j);
        if p.triangle.is_none() {
            return false;
        }
        if p.visibility > 1e-9 && p.visibility < 1.0 - 1e-9 {
            return true;
        }
        let neighbours = [(i.wrapping_sub(1), j), (i + 1, j), (i, j.wrapping_sub(1)), (i, j + 1)];
        neighbours.iter().any(|&(a, b)| a < self.nu && b < self.nv && self.at(a, b).triangle.is_some() && (self.at(a, b).visibility - p.visibility).abs() > 0.02)
    }

    /// The smallest and largest illuminance over the surface's probes.
    pub fn range(&self) -> (f64, f64) {
        self.probes.iter().filter(|p| p.triangle.is_some()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.illuminance()), hi.max(p.illuminance())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surfaces::rectangle;

    /// On a 4 x 1.85 m rectangle probed 16 cells along its length (the
    /// rows stop at v = 1.75), a linear irradiance is read back exactly
    /// between open nodes; a cell with a buried corner, and the strip past
    /// the last row, are left to the caller.
    #[test]
    fn the_display_reads_the_probes_only_within_open_cells() {
        let light = |p: DVec3| [1.0 + p.x + 2.0 * p.y, 2.0 - p.x, 0.5];
        let mut grid = ProbeGrid::of(&rectangle(4.0, 1.85), 16, |p, _, _| (light(p), 1.0, 0));
        assert_eq!((grid.nu, grid.nv, grid.h), (17, 8, 0.25));
        for uv in [DVec2::new(0.1, 0.1), DVec2::new(2.13, 0.77), DVec2::new(3.99, 1.74), DVec2::new(0.0, 0.0)] {
            let e = grid.irradiance_at(uv).unwrap();
            let exact = light(DVec3::new(uv.x, uv.y, 0.0));
            assert!((0..3).all(|k| (e[k] - exact[k]).abs() < 1e-12), "{uv}: {e:?} vs {exact:?}");
        }
        assert_eq!(grid.irradiance_at(DVec2::new(1.0, 1.8)), None, "past the last row");
        grid.probes[8 + 4 * grid.nu].buried = true;
        for uv in [DVec2::new(1.9, 0.9), DVec2::new(2.1, 1.1), DVec2::new(1.8, 1.05)] {
            assert_eq!(grid.irradiance_at(uv), None, "{uv}: a buried corner");
        }
        assert!(grid.irradiance_at(DVec2::new(2.3, 1.1)).is_some(), "the cell beyond it is open");
    }
}

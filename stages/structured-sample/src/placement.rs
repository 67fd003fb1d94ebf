//! Automatic sample placement, following the guidelines paper 002 Section
//! 3.2 gives for its hand placement ("Sample selection"):
//!
//! - samples "correspond with the curvature" of the isolux contours: the
//!   probe grid's illuminance is cut at `levels` evenly spaced levels
//!   (its Figure 3 quantises the same way) and samples are placed where a
//!   contour crosses a grid edge, spaced along the contour by
//!   `s = s_c / (1 + s_c kappa / theta) * clamp((g_mean / g)², 1/4, 4)`:
//!   `s_c` on a straight contour of average steepness, one sample per
//!   `theta` of turning on a curved one. Evenly spaced levels lie closer
//!   together where the gradient `g` is large; the last factor (a choice:
//!   the paper's guideline "samples are placed to correspond with the
//!   curvature" says nothing of the spacing along a straight contour)
//!   makes them denser along the contour there too, so the samples follow
//!   the change of the light in both directions;
//! - "across the umbra and penumbra regions with varying density": dense
//!   (`shadow_spacing`) in the penumbra, sparse (`umbra_spacing`) in the
//!   umbra, which "does not contribute much";
//! - a coarse lattice (`lattice_spacing`) keeps smooth regions sampled,
//!   and the surface's corners and edges are sampled at the lattice's
//!   spacing, so that resampling never extrapolates far past the last
//!   sample;
//! - display samples "in a view-dependent manner": one per
//!   `screen_spacing` x `screen_spacing` pixels of the camera image, so
//!   denser where the surface is larger on screen ([`screen_candidates`]).
//!
//! Candidates are thinned in that order of priority (edges, penumbra,
//! contours by decreasing curvature, umbra, lattice, screen): one is kept
//! unless a kept sample lies closer than `0.7 min(s_p, s_q)` (spacings of
//! the two), contour samples of different levels only closer than
//! `0.25 min(s_p, s_q)`, so neighbouring contours keep their own samples.
//! Every step is in a fixed order: the placement is deterministic.

use crate::probes::ProbeGrid;
use crate::surfaces::Surface;
use crate::Params;
use glam::DVec2;
use schemas::samples::{Reason, NO_LEVEL};
use std::collections::HashMap;

/// A place a sample may go, with the spacing its reason asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// `(u, v)` on the surface.
    pub uv: DVec2,
    /// Why.
    pub reason: Reason,
    /// Isolux level, or [`NO_LEVEL`].
    pub level: u32,
    /// Wanted distance to the next sample, m.
    pub spacing: f64,
    /// Priority among candidates of one reason (larger first).
    pub priority: f64,
}

/// The isolux levels of a surface's probe grid: `levels - 1` cuts evenly
/// spaced between its least and greatest illuminance (none on a uniformly
/// lit surface).
pub fn isolux_levels(grid: &ProbeGrid, levels: usize) -> Vec<f64> {
    let (lo, hi) = grid.range();
    if hi <= lo || hi - lo <= 1e-12 * hi.abs() {
        return Vec::new();
    }
    (1..levels).map(|k| lo + (hi - lo) * k as f64 / levels as f64).collect()
}

/// The illumination-driven candidates of one surface (all but the screen
/// ones).
pub fn light_candidates(surface: &Surface, boundary: &[[DVec2; 2]], grid: &ProbeGrid, params: &Params) -> Vec<Candidate> {
    let extent = surface.extent();
    let s_c = params.contour_spacing * extent;
    let theta = params.turn_angle_deg.to_radians();
    let candidate = |uv, reason, spacing| Candidate { uv, reason, level: NO_LEVEL, spacing, priority: 0.0 };
    let mut out = Vec::new();
    let s_edge = params.lattice_spacing * extent;
    for edge in boundary {
        let pieces = ((edge[1] - edge[0]).length() / s_edge).ceil().max(1.0) as usize;
        for k in 0..=pieces {
            out.push(candidate(edge[0].lerp(edge[1], k as f64 / pieces as f64), Reason::SurfaceEdge, s_edge));
        }
    }
    for j in 0..grid.nv {
        for i in 0..grid.nu {
            if grid.in_penumbra(i, j) {
                out.push(candidate(grid.uv(i, j), Reason::Penumbra, params.shadow_spacing * extent));
            }
        }
    }
    let levels = isolux_levels(grid, params.levels);
    let g_mean = grid.mean_gradient();
    let mut contour = Vec::new();
    for j in 0..grid.nv {
        for i in 0..grid.nu {
            for (a, b) in [((i, j), (i + 1, j)), ((i, j), (i, j + 1))] {
                if b.0 >= grid.nu || b.1 >= grid.nv {
                    continue;
                }
                let (pa, pb) = (grid.at(a.0, a.1), grid.at(b.0, b.1));
                if pa.triangle.is_none() || pb.triangle.is_none() {
                    continue;
                }
                for (level, &t) in levels.iter().enumerate() {
                    let (fa, fb) = (pa.illuminance() - t, pb.illuminance() - t);
                    if fa * fb >= 0.0 && !(fa == 0.0 && fb != 0.0) {
                        continue;
                    }
                    let w = fa / (fa - fb);
                    let kappa = (1.0 - w) * grid.curvature(a.0, a.1) + w * grid.curvature(b.0, b.1);
                    let g = (1.0 - w) * grid.gradient(a.0, a.1) + w * grid.gradient(b.0, b.1);
                    let steepness = if g > 0.0 && g_mean > 0.0 { (g_mean / g).powi(2).clamp(0.25, 4.0) } else { 1.0 };
                    let uv = grid.uv(a.0, a.1).lerp(grid.uv(b.0, b.1), w);
                    let spacing = s_c / (1.0 + s_c * kappa / theta) * steepness;
                    contour.push(Candidate { uv, reason: Reason::IsoluxContour, level: level as u32, spacing, priority: kappa });
                }
            }
        }
    }
    // Stable: equal curvatures keep grid order.
    contour.sort_by(|a, b| b.priority.total_cmp(&a.priority));
    out.extend(contour);
    for j in 0..grid.nv {
        for i in 0..grid.nu {
            let p = grid.at(i, j);
            if p.triangle.is_some() && p.visibility <= 1e-9 {
                out.push(candidate(grid.uv(i, j), Reason::Umbra, params.umbra_spacing * extent));
            }
        }
    }
    for j in 0..grid.nv {
        for i in 0..grid.nu {
            if grid.at(i, j).triangle.is_some() {
                out.push(candidate(grid.uv(i, j), Reason::SmoothLattice, params.lattice_spacing * extent));
            }
        }
    }
    out
}

/// Kept samples of one surface, with a hash grid for the distance test.
pub struct Thinning {
    cell: f64,
    kept: Vec<Candidate>,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl Thinning {
    /// Nothing kept; `cell` is the hash cell size (m).
    pub fn new(cell: f64) -> Self {
        Thinning { cell, kept: Vec::new(), cells: HashMap::new() }
    }

    fn key(&self, uv: DVec2) -> (i64, i64) {
        ((uv.x / self.cell).floor() as i64, (uv.y / self.cell).floor() as i64)
    }

    /// Keeps `c` unless a kept sample is too close (see the module
    /// documentation); returns whether it was kept.
    pub fn offer(&mut self, c: Candidate) -> bool {
        // No conflict reaches further than 0.7 of c's own spacing.
        let span = (0.7 * c.spacing / self.cell).ceil() as i64;
        let (ci, cj) = self.key(c.uv);
        for di in -span..=span {
            for dj in -span..=span {
                for &k in self.cells.get(&(ci + di, cj + dj)).into_iter().flatten() {
                    let q = &self.kept[k];
                    let both_contours = c.reason == Reason::IsoluxContour && q.reason == Reason::IsoluxContour && c.level != q.level;
                    let factor = if both_contours { 0.25 } else { 0.7 };
                    if (q.uv - c.uv).length() < factor * c.spacing.min(q.spacing) {
                        return false;
                    }
                }
            }
        }
        let key = self.key(c.uv);
        self.cells.entry(key).or_default().push(self.kept.len());
        self.kept.push(c);
        true
    }

    /// The samples kept, in the order kept.
    pub fn kept(&self) -> &[Candidate] {
        &self.kept
    }
}

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

/// The isolux bands of `surface`: `levels` across a surface of its own,
/// fewer (at least one) on a facet of a curved surface, in proportion to
/// its share of that surface's extent, as its spacings are fractions of
/// that extent ([`Surface::extent`]): the curved surface has `levels`
/// bands across it. `levels` bands across each of a sphere's thousand
/// facets cut its light into a hundred from pole to pole and made five
/// secondary emitters of every facet.
fn bands(surface: &Surface, levels: usize) -> usize {
    ((levels as f64 * surface.longer_side() / surface.extent()).round() as usize).max(1)
}

/// The isolux cuts of `surface` whose probes are `grid`: `levels` bands
/// of its own, or its share of a curved surface's ([`bands`]).
pub fn contour_levels(surface: &Surface, grid: &ProbeGrid, levels: usize) -> Vec<f64> {
    isolux_levels(grid, bands(surface, levels))
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
    let corners = corner_spacings(boundary, s_edge);
    for edge in boundary {
        let pieces = ((edge[1] - edge[0]).length() / s_edge).ceil().max(1.0) as usize;
        for k in 0..=pieces {
            let uv = edge[0].lerp(edge[1], k as f64 / pieces as f64);
            let spacing = if k == 0 || k == pieces { corners.get(&key(uv)).copied().unwrap_or(s_edge) } else { s_edge };
            out.push(candidate(uv, Reason::SurfaceEdge, spacing));
        }
    }
    for j in 0..grid.nv {
        for i in 0..grid.nu {
            if grid.in_penumbra(i, j) {
                out.push(candidate(grid.uv(i, j), Reason::Penumbra, params.shadow_spacing * extent));
            }
        }
    }
    let levels = contour_levels(surface, grid, params.levels);
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

/// Two kept samples lie at least this fraction of the lesser of their
/// spacings apart (see the module documentation).
const APART: f64 = 0.7;

/// The exact position of an edge's end, for matching ends.
fn key(uv: DVec2) -> [u64; 2] {
    [uv.x.to_bits(), uv.y.to_bits()]
}

/// The spacing of each corner of a surface's `boundary` (an end where it
/// turns, or where other than two of its edges meet): `s_edge`, or the
/// distance to the nearest other corner where thinning would drop one of
/// them at `s_edge` (nearer than [`APART`] of it), so that it keeps every
/// corner. The secondary emitters are triangles between samples and
/// cover what the corners span: a corner thinned away leaves part of its
/// surface sending and receiving nothing (a small facet whose corners lie
/// closer than `APART s_edge` kept one or two, and its polygons covered
/// none of it).
fn corner_spacings(boundary: &[[DVec2; 2]], s_edge: f64) -> HashMap<[u64; 2], f64> {
    let mut directions: HashMap<[u64; 2], (DVec2, Vec<DVec2>)> = HashMap::new();
    for edge in boundary {
        let along = (edge[1] - edge[0]).normalize_or_zero();
        directions.entry(key(edge[0])).or_insert((edge[0], Vec::new())).1.push(along);
        directions.entry(key(edge[1])).or_insert((edge[1], Vec::new())).1.push(-along);
    }
    let corners: Vec<([u64; 2], DVec2)> = directions
        .into_iter()
        .filter(|(_, (_, d))| d.len() != 2 || d[0].perp_dot(d[1]).abs() > 1e-9 || d[0].dot(d[1]) > 0.0)
        .map(|(k, (uv, _))| (k, uv))
        .collect();
    let cell = |uv: DVec2| ((uv.x / s_edge).floor() as i64, (uv.y / s_edge).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<DVec2>> = HashMap::new();
    for &(_, uv) in &corners {
        grid.entry(cell(uv)).or_default().push(uv);
    }
    corners
        .iter()
        .map(|&(k, uv)| {
            let (i, j) = cell(uv);
            let nearest = (i - 1..=i + 1)
                .flat_map(|a| (j - 1..=j + 1).map(move |b| (a, b)))
                .flat_map(|c| grid.get(&c).into_iter().flatten())
                .filter(|&&q| q != uv)
                .map(|&q| (q - uv).length())
                .fold(s_edge, f64::min);
            (k, if nearest < APART * s_edge { nearest } else { s_edge })
        })
        .collect()
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
        // No conflict reaches further than APART of c's own spacing.
        let span = (APART * c.spacing / self.cell).ceil() as i64;
        let (ci, cj) = self.key(c.uv);
        for di in -span..=span {
            for dj in -span..=span {
                for &k in self.cells.get(&(ci + di, cj + dj)).into_iter().flatten() {
                    let q = &self.kept[k];
                    let both_contours = c.reason == Reason::IsoluxContour && q.reason == Reason::IsoluxContour && c.level != q.level;
                    let factor = if both_contours { 0.25 } else { APART };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surfaces::rectangle;

    /// The edges of `corners` in order, the first one split in two at its
    /// middle (a collinear boundary vertex, not a corner).
    fn outline(corners: &[DVec2]) -> Vec<[DVec2; 2]> {
        let middle = corners[0].lerp(corners[1], 0.5);
        let mut edges = vec![[corners[0], middle], [middle, corners[1]]];
        edges.extend((1..corners.len()).map(|k| [corners[k], corners[(k + 1) % corners.len()]]));
        edges
    }

    /// A 3 x 1 cm facet of a curved surface 1 m wide, whose spacings are
    /// fractions of that metre (edge samples 25 cm apart): the thinning
    /// keeps its four corners, where at 25 cm it kept the first alone. On a
    /// 4 x 2 m surface with 0.5 m edge spacing every corner keeps that
    /// spacing, and the split edge's middle is no corner.
    #[test]
    fn thinning_keeps_every_corner_of_a_small_surface() {
        let params = Params::default();
        let mut facet = rectangle(0.03, 0.01);
        facet.least_extent = 1.0;
        let corners = [DVec2::ZERO, DVec2::new(0.03, 0.0), DVec2::new(0.03, 0.01), DVec2::new(0.0, 0.01)];
        let grid = ProbeGrid::of(&facet, 8, |_, _, _| ([1.0; 3], 1.0, 0));
        let mut thinning = Thinning::new(params.contour_spacing * facet.extent());
        for c in light_candidates(&facet, &outline(&corners), &grid, &params) {
            thinning.offer(c);
        }
        for corner in corners {
            assert!(thinning.kept().iter().any(|c| c.uv == corner), "corner {corner} thinned away");
        }
        let large = [DVec2::ZERO, DVec2::new(4.0, 0.0), DVec2::new(4.0, 2.0), DVec2::new(0.0, 2.0)];
        let spacings = corner_spacings(&outline(&large), 0.5);
        assert_eq!(spacings.len(), 4, "corners of the large rectangle");
        assert!(large.iter().all(|&c| spacings[&key(c)] == 0.5), "{spacings:?}");
    }
}

//! Resampling and filtering for display (paper 002 Section 3.2): a regular
//! grid over each surface, its vertices given the conical filter of the
//! sparse irregular samples within radius `r` (the formula after its
//! Figure 4):
//!
//! ```text
//! L_uv = sum_i (1 - d_i / r) L_i / sum_i (1 - d_i / r),   d_i = |(u, v) - (u_i, v_i)| < r
//! ```
//!
//! The paper's text prints the denominator garbled (`sum d_i`); it is read
//! here as the sum of the weights, the only reading under which a constant
//! luminance is reproduced (a filter must keep a uniformly lit surface
//! uniform). With these normalised weights, a linear luminance is also
//! reproduced wherever the samples within `r` lie symmetrically about the
//! vertex (a regular sample set): the weighted mean of `a + g . x` over a
//! set symmetric about 0 is `a`.
//!
//! Tag-aware filtering (the paper's "different weights or kernels ...
//! depending on whether the samples represent discontinuities such as
//! shadows", named as the fix for its blurred shadow boundaries): where a
//! sample tagged shadow boundary lies within `r` of a vertex, the vertex
//! takes the cone of the smaller radius `r_shadow` instead, so the
//! penumbra's dense samples are not averaged with the lit and shadowed
//! regions beyond it. Where no sample lies within the radius, it is
//! doubled until one does.
//!
//! Where part of a surface lit only by reflection is hidden from the room
//! (the pocket over a lamp hung under a ceiling, which receives nothing),
//! a vertex takes the samples on its own side of that outline alone
//! ([`DisplayGrid::new`]'s `open`): a fit over both put a ring a few
//! percent too bright round McGuire's hung lamp, 20-30 cm out, where no
//! sample lies within the small radius and the large one reaches into
//! the pocket (README, Structured sampling).
//!
//! The default filter fits a quadric with the cone's weights
//! ([`conical_quadratic`]): a plane ([`conical_linear`]) keeps linear
//! luminance at a surface's edges, but misses a curved one by the
//! curvature its weights average, and the light of a room curves (bright
//! in a surface's middle, dark at its edges): on paper 002's simple
//! environment A's image was 2.7% dark, on the built-in Cornell box every
//! wall 2-4% (against hierarchical-solve's full gather); with the quadric
//! A's relative RMSE against the exact image went from 3.7% to 0.77%, B's
//! from 1.7% to 0.36%, the Cornell box's from 6.3% to 3.8% (README,
//! Structured sampling).
//!
//! The grid is then drawn as the paper draws its polygons: a pixel's
//! luminance is the bilinear interpolation of its cell's four vertices.
//!
//! What is filtered is the indirect light alone (a choice): the direct
//! light, whose peaks and penumbrae the samples follow but a filter of
//! them cannot reproduce between contours, is shown from the probe grid
//! ([`crate::probes::ProbeGrid::irradiance_at`]). The figures above were
//! measured filtering both.

use glam::DVec2;
use schemas::samples::Tag;

/// One sample as the filter sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// `(u, v)` on the surface.
    pub uv: DVec2,
    /// Luminance, RGB.
    pub luminance: [f64; 3],
    /// Its tag.
    pub tag: Tag,
}

/// The conical filter at `at`, radius `r`: `None` where no sample lies
/// closer than `r`.
pub fn conical(samples: &[FilterSample], at: DVec2, r: f64) -> Option<[f64; 3]> {
    let (mut sum, mut weight) = ([0.0; 3], 0.0);
    for s in samples {
        let d = (s.uv - at).length();
        if d < r {
            let w = 1.0 - d / r;
            weight += w;
            for (a, l) in sum.iter_mut().zip(s.luminance) {
                *a += w * l;
            }
        }
    }
    (weight > 0.0).then(|| sum.map(|a| a / weight))
}

/// The conical filter with a first-order correction: the plane
/// `L(p) = c + g . (p - at)` fitted to the samples within `r` by least
/// squares with the cone's weights `1 - d_i / r`, its value `c` at `at`.
/// On a set symmetric about `at` it equals [`conical`]; unlike it, it
/// reproduces a linear luminance on any set, so the one-sided
/// neighbourhoods at a surface's edges are not biased towards the
/// interior. Falls back to [`conical`] where the samples within `r` lie
/// on a line or fewer than three do. The value is clamped to the range of
/// the samples within `r` (per channel): a plane fitted across a steep
/// shadow edge would otherwise overshoot it, even below zero.
pub fn conical_linear(samples: &[FilterSample], at: DVec2, r: f64) -> Option<[f64; 3]> {
    Fit::of(samples, at, r, |d| [1.0, d.x, d.y]).value().or_else(|| conical(samples, at, r))
}

/// The conical filter with a second-order correction: the quadric
/// `L(p) = c + g . d + d^T H d` (`d = p - at`) fitted to the samples within
/// `r` by least squares with the cone's weights, its value `c` at `at`,
/// clamped to the samples' range as [`conical_linear`]. A plane fitted
/// over a curved luminance misses its value at `at` by the cone-weighted
/// mean of the curvature term; a quadric does not. Falls back to
/// [`conical_linear`] where fewer than six samples lie within `r` or they
/// do not determine a quadric: the plane's normal equations are the
/// quadric's leading block, so the samples are read once.
pub fn conical_quadratic(samples: &[FilterSample], at: DVec2, r: f64) -> Option<[f64; 3]> {
    let quadric = Fit::of(samples, at, r, |d| [1.0, d.x, d.y, d.x * d.x, d.x * d.y, d.y * d.y]);
    quadric.value().or_else(|| quadric.leading::<3>().value()).or_else(|| conical(samples, at, r))
}

/// The least pivot of a fit's normal equations ([`Fit::value`]), as a
/// fraction of its weights' sum: below it the samples do not determine
/// the fit. At 1e-9 a quadric fitted to samples that barely spread across
/// a surface's edge put a few of paper 002's B's pixels 75% off at 100 x
/// 100 (`bench/tests/structured.rs`); at 1e-4 none is 5% off.
pub const FIT_PIVOT: f64 = 1e-4;

/// The weighted least-squares fit of the `N` functions `basis` (of the
/// offset in units of `r`, the first one constant) to the samples within
/// `r` of a point, with the cone's weights `1 - d_i / r`: its normal
/// equations, and the count and range of those samples.
struct Fit<const N: usize> {
    m: [[f64; N]; N],
    rhs: [[f64; N]; 3],
    count: usize,
    lo: [f64; 3],
    hi: [f64; 3],
}

impl<const N: usize> Fit<N> {
    /// The fit at `at` (module docs).
    fn of(samples: &[FilterSample], at: DVec2, r: f64, basis: impl Fn(DVec2) -> [f64; N]) -> Self {
        let mut fit = Fit { m: [[0.0; N]; N], rhs: [[0.0; N]; 3], count: 0, lo: [f64::INFINITY; 3], hi: [f64::NEG_INFINITY; 3] };
        for s in samples {
            let d = (s.uv - at) / r;
            let distance = d.length();
            if distance < 1.0 {
                let w = 1.0 - distance;
                let basis = basis(d);
                for a in 0..N {
                    for b in 0..N {
                        fit.m[a][b] += w * basis[a] * basis[b];
                    }
                    for (k, l) in s.luminance.iter().enumerate() {
                        fit.rhs[k][a] += w * basis[a] * l;
                    }
                }
                for k in 0..3 {
                    fit.lo[k] = fit.lo[k].min(s.luminance[k]);
                    fit.hi[k] = fit.hi[k].max(s.luminance[k]);
                }
                fit.count += 1;
            }
        }
        fit
    }

    /// The fit of the first `K` functions alone: the leading block of the
    /// normal equations.
    fn leading<const K: usize>(&self) -> Fit<K> {
        Fit {
            m: std::array::from_fn(|a| std::array::from_fn(|b| self.m[a][b])),
            rhs: self.rhs.map(|y| std::array::from_fn(|a| y[a])),
            count: self.count,
            lo: self.lo,
            hi: self.hi,
        }
    }

    /// The fitted function's value at the point, clamped to the range of
    /// the samples within `r` (per channel: a fit across a steep shadow
    /// edge would otherwise overshoot it, even below zero); `None` where
    /// fewer than `N` samples lie within `r` or they do not determine the
    /// fit ([`FIT_PIVOT`]).
    fn value(&self) -> Option<[f64; 3]> {
        if self.count < N {
            return None;
        }
        let c = solve_first(self.m, self.rhs, FIT_PIVOT * self.m[0][0])?;
        Some([0, 1, 2].map(|k| c[k].clamp(self.lo[k], self.hi[k])))
    }
}

/// The first unknown of `m x = b` for each right-hand side `b` of `rhs`,
/// by Gaussian elimination with partial pivoting; `None` where a pivot
/// falls under `least`.
fn solve_first<const N: usize>(mut m: [[f64; N]; N], mut rhs: [[f64; N]; 3], least: f64) -> Option<[f64; 3]> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() <= least {
            return None;
        }
        m.swap(col, pivot);
        for b in rhs.iter_mut() {
            b.swap(col, pivot);
        }
        let (above, below) = m.split_at_mut(col + 1);
        let top = &above[col];
        for (i, row) in below.iter_mut().enumerate() {
            let f = row[col] / top[col];
            row.iter_mut().zip(top).skip(col).for_each(|(x, t)| *x -= f * t);
            for b in rhs.iter_mut() {
                b[col + 1 + i] -= f * b[col];
            }
        }
    }
    Some(rhs.map(|mut b| {
        for row in (0..N).rev() {
            let tail: f64 = (row + 1..N).map(|k| m[row][k] * b[k]).sum();
            b[row] = (b[row] - tail) / m[row][row];
        }
        b[0]
    }))
}

/// Which cone a display grid uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
pub enum Filter {
    /// Paper 002's conical filter, [`conical`].
    Conical,
    /// The conical filter with a first-order correction, [`conical_linear`].
    ConicalLinear,
    /// The conical filter with a second-order correction, [`conical_quadratic`].
    ConicalQuadratic,
}

impl Filter {
    fn apply(self, samples: &[FilterSample], at: DVec2, r: f64) -> Option<[f64; 3]> {
        match self {
            Filter::Conical => conical(samples, at, r),
            Filter::ConicalLinear => conical_linear(samples, at, r),
            Filter::ConicalQuadratic => conical_quadratic(samples, at, r),
        }
    }
}

/// The tag-aware filter at `at` (see the module documentation).
pub fn tag_aware(filter: Filter, samples: &[FilterSample], at: DVec2, r: f64, r_shadow: f64) -> [f64; 3] {
    let near_shadow = samples.iter().any(|s| s.tag == Tag::ShadowBoundary && (s.uv - at).length() < r);
    if near_shadow {
        if let Some(l) = filter.apply(samples, at, r_shadow) {
            return l;
        }
    }
    let mut radius = r;
    loop {
        if let Some(l) = filter.apply(samples, at, radius) {
            return l;
        }
        if samples.is_empty() || !radius.is_finite() {
            return [0.0; 3];
        }
        radius *= 2.0;
    }
}

/// The display grid of one surface: vertices `lo + (i, j) h`.
#[derive(Clone, Debug, PartialEq)]
pub struct DisplayGrid {
    lo: DVec2,
    h: f64,
    nu: usize,
    nv: usize,
    values: Vec<[f64; 3]>,
}

impl DisplayGrid {
    /// The grid over `[lo, hi]` with cells of side `h`, every vertex
    /// filtered by [`tag_aware`] from the samples on its side of `open`
    /// (whether a point lies in the open, module docs; from all of them
    /// where its side has none).
    #[allow(clippy::too_many_arguments)]
    pub fn new(filter: Filter, lo: DVec2, hi: DVec2, h: f64, samples: &[FilterSample], r: f64, r_shadow: f64, open: impl Fn(DVec2) -> bool) -> Self {
        let size = hi - lo;
        let (nu, nv) = ((size.x / h).ceil() as usize + 1, (size.y / h).ceil() as usize + 1);
        let (in_open, hidden): (Vec<FilterSample>, Vec<FilterSample>) = samples.iter().partition(|s| open(s.uv));
        let values = (0..nu * nv)
            .map(|k| {
                let at = lo + DVec2::new((k % nu) as f64, (k / nu) as f64) * h;
                let side = if open(at) { &in_open } else { &hidden };
                tag_aware(filter, if side.is_empty() { samples } else { side }, at, r, r_shadow)
            })
            .collect();
        DisplayGrid { lo, h, nu, nv, values }
    }

    /// Vertices: `(along u, along v)`.
    pub fn size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }

    /// The value of vertex `(i, j)`.
    pub fn vertex(&self, i: usize, j: usize) -> [f64; 3] {
        self.values[i + j * self.nu]
    }

    /// Bilinear interpolation of the vertices at `uv` (clamped to the grid).
    pub fn at(&self, uv: DVec2) -> [f64; 3] {
        let g = ((uv - self.lo) / self.h).clamp(DVec2::ZERO, DVec2::new((self.nu - 1) as f64, (self.nv - 1) as f64));
        let (i, j) = ((g.x.floor() as usize).min(self.nu.saturating_sub(2)), (g.y.floor() as usize).min(self.nv.saturating_sub(2)));
        let (fx, fy) = (g.x - i as f64, g.y - j as f64);
        let (i1, j1) = ((i + 1).min(self.nu - 1), (j + 1).min(self.nv - 1));
        let (a, b, c, d) = (self.vertex(i, j), self.vertex(i1, j), self.vertex(i, j1), self.vertex(i1, j1));
        [0, 1, 2].map(|k| (1.0 - fy) * ((1.0 - fx) * a[k] + fx * b[k]) + fy * ((1.0 - fx) * c[k] + fx * d[k]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(f: impl Fn(DVec2) -> f64, spacing: f64, n: i32, tag: impl Fn(DVec2) -> Tag) -> Vec<FilterSample> {
        (-n..=n)
            .flat_map(|i| (-n..=n).map(move |j| DVec2::new(i as f64, j as f64) * spacing))
            .map(|uv| FilterSample { uv, luminance: [f(uv); 3], tag: tag(uv) })
            .collect()
    }

    #[test]
    fn the_conical_filter_reproduces_a_linear_function_on_a_regular_sample_set() {
        let f = |p: DVec2| 2.0 + 0.7 * p.x - 1.3 * p.y;
        let samples = lattice(f, 0.1, 20, |_| Tag::Smooth);
        // Interior vertices on and off the sample lattice, at radii that
        // hold a symmetric set of samples.
        for at in [DVec2::new(0.0, 0.0), DVec2::new(0.3, -0.5), DVec2::new(0.05, 0.05), DVec2::new(-0.45, 0.25)] {
            for r in [0.15, 0.25, 0.4] {
                let l = conical(&samples, at, r).unwrap()[0];
                assert!((l - f(at)).abs() < 1e-12, "at {at:?}, r {r}: {l} vs {}", f(at));
            }
        }
        // A constant anywhere, even with a one-sided neighbourhood.
        let flat = lattice(|_| 3.5, 0.1, 5, |_| Tag::Smooth);
        assert!((conical(&flat, DVec2::new(0.5, 0.5), 0.3).unwrap()[0] - 3.5).abs() < 1e-12);
        assert_eq!(conical(&flat, DVec2::new(5.0, 5.0), 0.3), None);
    }

    #[test]
    fn the_corrected_cone_reproduces_a_linear_function_at_an_edge() {
        let f = |p: DVec2| 2.0 + 0.7 * p.x - 1.3 * p.y;
        // Only the quarter x, y >= 0: a corner vertex sees a one-sided set.
        let samples: Vec<FilterSample> = lattice(f, 0.1, 10, |_| Tag::Smooth).into_iter().filter(|s| s.uv.x >= 0.0 && s.uv.y >= 0.0).collect();
        let at = DVec2::ZERO;
        let corrected = conical_linear(&samples, at, 0.35).unwrap()[0];
        assert!((corrected - f(at)).abs() < 1e-12, "{corrected}");
        let plain = conical(&samples, at, 0.35).unwrap()[0];
        assert!((plain - f(at)).abs() > 0.01, "the plain cone is biased at a corner: {plain}");
    }

    /// A curved luminance (a concave quadric) seen from a corner, where
    /// only a quarter of the cone holds samples, and from the middle: the
    /// quadric fit gives its value at the vertex to 1e-10, where the plane
    /// fit misses it by the curvature its weights average (+0.24% at the
    /// corner, -3.7% and -10.8% inside at radii 0.35 and 0.6).
    #[test]
    fn the_quadratic_cone_reproduces_a_curved_function_at_an_edge_and_inside() {
        let f = |p: DVec2| 2.0 + 0.7 * p.x - 1.3 * p.y - 3.0 * p.x * p.x + 2.0 * p.x * p.y - p.y * p.y;
        let all = lattice(f, 0.1, 10, |_| Tag::Smooth);
        let corner: Vec<FilterSample> = all.iter().copied().filter(|s| s.uv.x >= 0.0 && s.uv.y >= 0.0).collect();
        for (samples, r) in [(&corner, 0.35), (&all, 0.35), (&all, 0.6)] {
            let at = DVec2::ZERO;
            let quadric = conical_quadratic(samples, at, r).unwrap()[0];
            assert!((quadric - f(at)).abs() < 1e-10, "r {r}: {quadric}");
            let plane = conical_linear(samples, at, r).unwrap()[0];
            assert!((plane / f(at) - 1.0).abs() > 2e-3, "r {r}: the plane fit is biased by the curvature: {plane}");
        }
    }

    #[test]
    fn the_tag_aware_filter_keeps_a_shadow_edge_sharp() {
        // A step at x = 0: lit (1) left, shadowed (0) right, shadow samples
        // densely across it.
        let step = |p: DVec2| if p.x < 0.0 { 1.0 } else { 0.0 };
        let mut samples = lattice(step, 0.2, 5, |_| Tag::Smooth);
        samples.extend((-10..=10).flat_map(|i| (-5..=5).map(move |j| DVec2::new(0.02 * i as f64 + 0.01, 0.2 * j as f64))).map(|uv| FilterSample { uv, luminance: [step(uv); 3], tag: Tag::ShadowBoundary }));
        let at = DVec2::new(-0.06, 0.0);
        let blurred = conical(&samples, at, 0.5).unwrap()[0];
        let sharp = tag_aware(Filter::Conical, &samples, at, 0.5, 0.05)[0];
        assert!((sharp - 1.0).abs() < 1e-12, "{sharp}");
        assert!(blurred < 0.8, "the plain cone blurs the edge: {blurred}");
    }

    #[test]
    fn the_grid_interpolates_bilinearly_between_its_vertices() {
        let f = |p: DVec2| 1.0 + p.x + 2.0 * p.y;
        let samples = lattice(f, 0.05, 40, |_| Tag::Smooth);
        let grid = DisplayGrid::new(Filter::Conical, DVec2::splat(-1.0), DVec2::splat(1.0), 0.25, &samples, 0.12, 0.05, |_| true);
        let p = DVec2::new(0.1, -0.3);
        assert!((grid.at(p)[0] - f(p)).abs() < 1e-12);
    }

    /// A surface whose part `x < 0` is hidden from the room (the pocket
    /// over a hung lamp: luminance 0 there, a quadratic rise from 1
    /// outside), samples every 0.1 untagged: every vertex in the open
    /// within a filter radius of the pocket keeps the open side's
    /// quadratic to 1e-9 when the filter takes each side's samples alone;
    /// with all of them, the fit across the step misses by up to 13%.
    #[test]
    fn vertices_in_the_open_are_filtered_from_the_open_samples() {
        let f = |p: DVec2| if p.x < 0.0 { 0.0 } else { 1.0 + p.x * p.x + 0.5 * p.y };
        let samples = lattice(f, 0.1, 10, |_| Tag::Smooth);
        let open = |p: DVec2| p.x >= 0.0;
        let [sided, mixed] = [DisplayGrid::new(Filter::ConicalQuadratic, DVec2::splat(-1.0), DVec2::splat(1.0), 0.05, &samples, 0.4, 0.1, open), DisplayGrid::new(Filter::ConicalQuadratic, DVec2::splat(-1.0), DVec2::splat(1.0), 0.05, &samples, 0.4, 0.1, |_| true)].map(|g| {
            (0..=40).flat_map(|i| (4..=36).map(move |j| DVec2::new(0.05 * i as f64 - 1.0, 0.05 * j as f64 - 1.0))).filter(|p| p.x > 0.0 && p.x < 0.4).map(|p| (g.at(p)[0] / f(p) - 1.0).abs()).fold(0.0, f64::max)
        });
        assert!(sided < 1e-9, "{sided}");
        assert!(mixed > 0.1, "{mixed}");
    }
}

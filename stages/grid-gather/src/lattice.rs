//! The full gather's irradiance on a lattice of image points, interpolated
//! to the camera samples (the `lattice` parameter).
//!
//! The gather of paper 000 evaluates the irradiance `H` at every camera
//! sample (Sec. 4.1); at 4 samples per pixel that is four resampled gathers
//! per pixel, most of a full image's time. `H` is smooth across a surface
//! except where a shadow or a contact crosses it, and a pixel's samples lie
//! within a pixel of each other, so the gather is made once per lattice
//! point instead: the points sit on a square lattice over the image,
//! `spacing` pixels apart (`lattice_spacing`; by default
//! `min(1, 2 / sqrt(spp))`, about four camera samples per lattice cell: the
//! pixel centres up to 4 samples per pixel, four points per pixel at 16).
//! A wider lattice trades detail at shadow edges for time.
//!
//! Each camera sample takes the interpolation of `H` between the four
//! lattice points around it, bilinear in the image and perspective-correct
//! (weights divided by each point's depth along the view, which makes it
//! exact for an `H` linear over a plane however grazing the view), where
//! all four lie on its surface (same object and material), face its way
//! (normals within the crease angle) and lie in its tangent plane (the
//! chord within [`PLANE_SLOPE`] of it). Where one of them does not (an edge
//! crosses the cell), a lattice coarser than the pixels interpolates
//! between the pixel centres instead, gathered where a sample needs them;
//! where that fails too (an edge within a pixel, a sliver, the image's
//! border) the sample is gathered itself, as without the lattice. The
//! lattice interpolates between its points and never extrapolates, which
//! had left a floor's far edge 4% off where a sample's only neighbours lay
//! on one side of it; nor does it interpolate over the half of a cell an
//! edge leaves whole, which added 60% to the darkening next to concave
//! creases (where the irradiance's slope is unbounded) for 1% of the
//! samples. The light of
//! luminaires, windows and translucent twins is added per sample as
//! before; only the links' gather is interpolated.
//!
//! **Where the points disagree.** Bilinear interpolation is exact for an
//! `H` linear over the cell; across a shadow's edge, or beside a concave
//! crease, a sample took a blend of the points around it. So where the
//! points around a sample differ by more than `spread` (`lattice_spread`)
//! of the brightest of them (`max - min > spread max`, each point's
//! brightest channel), that level does not interpolate it: the pixel
//! centres do where the lattice is coarser than the pixels, else the
//! sample is gathered itself. The points also differ by the noise of their
//! visibility blocks (below), hence a spread well above it. On the
//! built-in Cornell box at `EPS` 1e-3 (the full gather against Mitsuba,
//! 256 x 256, 4 samples per pixel) with the lattice every 1, 2 and 3
//! pixels the relative RMSE went from 1.126%, 1.194% and 1.387% to
//! 1.110%, 1.119% and 1.159%, for 4%, 16% and 23% more time: every 2
//! pixels is now as accurate as every pixel was, in 0.70 of its time.
//! `make bench-gather`'s unclustered box at `EPS` 2e-4, against its
//! brute-force reference: 5.72e-4 -> 4.66e-4 at contrast 0.02 and 4.26e-4
//! -> 2.90e-4 at 0.005, for 21% and 19% more rays (the full gather's rays
//! over brute force's at equal error, 0.39 -> 0.31 and 0.28 -> 0.15); its
//! plant room 9.23e-3 -> 8.78e-3 at 0.02 for 3% more. A spread of 0.3 did
//! about as well (1.127% every 2 pixels, 0.17 at contrast 0.005); 0.1
//! cast more rays for little (0.35 and 0.15).
//!
//! **Interleaved visibility.** Lattice point `(i, j)` draws its visibility
//! from block `(i mod 2) + 2 (j mod 2)` of each sender's fixed samples
//! ([`crate::full_gather::FullGather::fixed_visibility`]), so the four points
//! around any sample hold the four blocks, which the interpolation averages
//! (Keller and Heidrich's interleaved sampling, 2001): the visibility of a
//! pixel rests on four blocks, as with one gather per sample at 4 samples
//! per pixel, where one gather per pixel from one block left each sender's
//! few fixed points visible as blotches (1.17% against 2.07% relative RMSE
//! on the Cornell box at `EPS` 1e-2).

use crate::diagnostics::Work;
use crate::pixel_surfaces::SurfaceId;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Largest `|n . (q - p)| / |q - p|` for a lattice point `q` to count as in
/// the tangent plane at the sample `p` (the sine of 5 degrees): a curved
/// surface tessellated finer than about 12 pixels across passes, a step
/// between parallel faces of one object does not.
pub const PLANE_SLOPE: f64 = 0.087;

/// The finest lattice spacing, pixels (16 points per pixel): the bound of
/// `--lattice-spacing` and of [`IrradianceLattice::default_spacing`]. A
/// spacing of 1e-9 would have asked for 1e18 points per pixel.
pub const FINEST_SPACING: f64 = 1.0 / 16.0;

/// What gathers one lattice point: `(image position, visibility block,
/// work) -> what it saw`, `None` where there is nothing to gather.
pub type GatherPoint<'a> = dyn Fn([f64; 2], u32, &mut Work) -> Option<LatticePoint> + Sync + 'a;

/// What a lattice point saw and the irradiance gathered there.
#[derive(Clone, Copy, Debug)]
pub struct LatticePoint {
    /// The hit point, mesh frame.
    pub point: DVec3,
    /// The shading normal there.
    pub normal: DVec3,
    /// The surface hit.
    pub surface: SurfaceId,
    /// Depth along the view axis, m (> 0).
    pub depth: f64,
    /// Irradiance from the links, W/m², RGB.
    pub irradiance: [f64; 3],
}

/// A surface point to shade: where the camera sample hit, and what the
/// lattice must match.
#[derive(Clone, Copy, Debug)]
pub struct Target {
    /// Image position of the camera sample (pixels, `x` right, `y` down).
    pub at: [f64; 2],
    /// The hit point.
    pub point: DVec3,
    /// The shading normal there.
    pub normal: DVec3,
    /// The surface hit.
    pub surface: SurfaceId,
}

/// One level of the lattice: its points `spacing` pixels apart, the first
/// half a spacing from the image's top left corner, each gathered once
/// (eagerly for the coarse level, on first use for the fine one) with the
/// work it took.
struct Level {
    spacing: f64,
    columns: usize,
    rows: usize,
    points: Vec<OnceLock<(Option<LatticePoint>, Work)>>,
}

impl Level {
    fn new(width: u32, height: u32, spacing: f64) -> Self {
        let along = |pixels: u32| (f64::from(pixels) / spacing).ceil().max(1.0) as usize;
        let (columns, rows) = (along(width), along(height));
        Level { spacing, columns, rows, points: (0..columns * rows).map(|_| OnceLock::new()).collect() }
    }

    /// Image position of point `index`.
    fn at(&self, index: usize) -> [f64; 2] {
        [((index % self.columns) as f64 + 0.5) * self.spacing, ((index / self.columns) as f64 + 0.5) * self.spacing]
    }

    /// Point `index`, gathered by `gather` on first use with its
    /// interleaved visibility block (module docs).
    fn point(&self, index: usize, gather: &GatherPoint) -> Option<LatticePoint> {
        self.points[index]
            .get_or_init(|| {
                let block = (index % self.columns % 2 + 2 * (index / self.columns % 2)) as u32;
                let mut work = Work::default();
                (gather(self.at(index), block, &mut work), work)
            })
            .0
    }
}

/// The lattice over an image ([`IrradianceLattice::gather`]).
pub struct IrradianceLattice {
    /// The coarse level, then, where it is coarser than the pixels, the
    /// pixel centres.
    levels: Vec<Level>,
    /// Image width and height, pixels.
    size: [u32; 2],
    /// Cosine of the crease angle.
    crease_cos: f64,
    /// Largest spread of the points around a sample, as a fraction of the
    /// brightest, that a level interpolates over (module docs).
    spread: f64,
}

impl IrradianceLattice {
    /// The default spacing for `spp` camera samples per pixel, pixels
    /// (module docs), no finer than [`FINEST_SPACING`].
    pub fn default_spacing(spp: u32) -> f64 {
        (2.0 / f64::from(spp.max(1)).sqrt()).clamp(FINEST_SPACING, 1.0)
    }

    /// The lattice of a `width` x `height` image, its points `spacing`
    /// pixels apart, gathered by `gather` (`gather(at, block, work)` casts
    /// the camera ray through image position `at` and gathers there with
    /// visibility block `block`, or says there is nothing to gather). The
    /// points are gathered now, in parallel; the pixel centres of a lattice
    /// coarser than the pixels are gathered where a sample needs them. A
    /// level interpolates where the points around a sample differ by at
    /// most `spread` of the brightest (module docs). The values do not
    /// depend on the thread count.
    pub fn gather(width: u32, height: u32, spacing: f64, crease_angle_deg: f64, spread: f64, gather: &GatherPoint) -> Self {
        let coarse = Level::new(width, height, spacing);
        (0..coarse.points.len()).into_par_iter().for_each(|index| {
            coarse.point(index, gather);
        });
        let mut levels = vec![coarse];
        if spacing > 1.0 {
            levels.push(Level::new(width, height, 1.0));
        }
        IrradianceLattice { levels, size: [width, height], crease_cos: crease_angle_deg.to_radians().cos(), spread }
    }

    /// The number of points gathered.
    pub fn point_count(&self) -> usize {
        self.levels.iter().map(|l| l.points.iter().filter(|p| p.get().is_some()).count()).sum()
    }

    /// Per pixel (row-major), the work of the lattice points in it.
    pub fn work_per_pixel(&self) -> Vec<Work> {
        let [w, h] = self.size.map(|n| n as usize);
        let mut work = vec![Work::default(); w * h];
        for level in &self.levels {
            for (index, point) in level.points.iter().enumerate() {
                if let Some((_, done)) = point.get() {
                    let [x, y] = level.at(index).map(|c| c as usize);
                    work[y.min(h - 1) * w + x.min(w - 1)].add(done);
                }
            }
        }
        work
    }

    /// The irradiance at `target`, interpolated between the coarse level's
    /// points around it where they lie on its surface and plane and agree
    /// within the spread, else between the pixel centres' (gathered by
    /// `gather` where not yet) (module docs); `None` where neither can.
    pub fn interpolate(&self, target: &Target, gather: &GatherPoint) -> Option<[f64; 3]> {
        self.levels.iter().find_map(|level| self.interpolate_on(level, target, gather))
    }

    fn interpolate_on(&self, level: &Level, target: &Target, gather: &GatherPoint) -> Option<[f64; 3]> {
        let (fx, fy) = (target.at[0] / level.spacing - 0.5, target.at[1] / level.spacing - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        // The cell's corners (0, 0), (1, 0), (0, 1), (1, 1), where they
        // lie on the image and on the target's surface and plane, gathered
        // as needed.
        let corner = |k: usize| {
            let (x, y) = (x0 + (k % 2) as f64, y0 + (k / 2) as f64);
            let inside = x >= 0.0 && y >= 0.0 && x < level.columns as f64 && y < level.rows as f64;
            inside.then(|| level.point(y as usize * level.columns + x as usize, gather)).flatten().filter(|q| self.matches(q, target))
        };
        let bilinear = [(0, (1.0 - tx) * (1.0 - ty)), (1, tx * (1.0 - ty)), (2, (1.0 - tx) * ty), (3, tx * ty)];
        let (mut sum, mut total) = ([0.0; 3], 0.0);
        // The dimmest and the brightest of the points, brightest channel.
        let (mut dimmest, mut brightest) = (f64::INFINITY, 0.0f64);
        for (k, w) in bilinear.into_iter().filter(|(_, w)| *w > 0.0) {
            let q = corner(k)?;
            total += w / q.depth;
            (0..3).for_each(|c| sum[c] += w / q.depth * q.irradiance[c]);
            let h = q.irradiance.into_iter().fold(0.0, f64::max);
            dimmest = dimmest.min(h);
            brightest = brightest.max(h);
        }
        (brightest - dimmest <= self.spread * brightest).then(|| sum.map(|s| s / total))
    }

    /// Whether lattice point `q` lies on `target`'s surface, faces its way
    /// and lies in its tangent plane.
    fn matches(&self, q: &LatticePoint, target: &Target) -> bool {
        let chord = q.point - target.point;
        q.surface == target.surface && q.depth > 0.0 && q.normal.dot(target.normal) >= self.crease_cos && target.normal.dot(chord).abs() <= PLANE_SLOPE * chord.length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLOOR: SurfaceId = SurfaceId { object: 0, material: 0, emits: false };
    const WALL: SurfaceId = SurfaceId { object: 1, material: 0, emits: false };

    /// A 4 x 4 image whose left half sees a floor (z = 0, normal +z) with
    /// `H = 10 + x + 2 y` at image position (x, y), at a depth of 1, and
    /// whose right half sees a wall; the floor is raised by 0.5 at the
    /// points in `raised`.
    fn floor_and_wall(raised: &[[f64; 2]]) -> impl Fn([f64; 2], u32, &mut Work) -> Option<LatticePoint> + Sync + '_ {
        move |at, _, work| {
            work.visibility_rays += 1;
            let floor = at[0] < 2.0;
            let z = if raised.contains(&at) { 0.5 } else { 0.0 };
            Some(LatticePoint {
                point: if floor { DVec3::new(at[0], at[1], z) } else { DVec3::new(2.0, at[1], at[0]) },
                normal: if floor { DVec3::Z } else { DVec3::NEG_X },
                surface: if floor { FLOOR } else { WALL },
                depth: 1.0,
                irradiance: [10.0 + at[0] + 2.0 * at[1]; 3],
            })
        }
    }

    fn floor_at(x: f64, y: f64) -> Target {
        Target { at: [x, y], point: DVec3::new(x, y, 0.0), normal: DVec3::Z, surface: FLOOR }
    }

    fn exact(lattice: &IrradianceLattice, gather: &GatherPoint, x: f64, y: f64) {
        let h = lattice.interpolate(&floor_at(x, y), gather).unwrap_or_else(|| panic!("nothing at ({x}, {y})"))[0];
        assert!((h - (10.0 + x + 2.0 * y)).abs() < 1e-12, "({x}, {y}): {h}");
    }

    #[test]
    fn one_point_per_pixel_up_to_4_spp_then_a_finer_lattice() {
        assert_eq!([1, 2, 4, 16, 64, 1 << 20].map(IrradianceLattice::default_spacing), [1.0, 1.0, 1.0, 0.5, 0.25, 0.0625]);
    }

    /// Interpolation reproduces a linear function exactly between lattice
    /// points of the sample's surface; nothing comes where a point around
    /// the sample is off its surface (the edge), off its plane (a raised
    /// point: anywhere in the four cells around it) or off the image.
    #[test]
    fn interpolation_is_exact_for_linear_irradiance_and_stops_at_an_edge() {
        let gather = floor_and_wall(&[]);
        let lattice = IrradianceLattice::gather(4, 4, 1.0, 30.0, 1.0, &gather);
        for (x, y) in [(0.5, 0.5), (1.2, 1.7), (0.9, 3.3), (1.0, 2.25), (1.5, 3.5)] {
            exact(&lattice, &gather, x, y);
        }
        // At x = 1.8 the points at 1.5 (floor) and 2.5 (wall) surround it.
        assert!(lattice.interpolate(&floor_at(1.8, 1.5), &gather).is_none());
        // At y = 3.7 the points below the last row are off the image.
        assert!(lattice.interpolate(&floor_at(1.0, 3.7), &gather).is_none());
        let raised = [[1.5, 1.5]];
        let notched_gather = floor_and_wall(&raised);
        let notched = IrradianceLattice::gather(4, 4, 1.0, 30.0, 1.0, &notched_gather);
        for (x, y) in [(0.7, 0.6), (1.4, 1.3), (0.8, 2.4)] {
            assert!(notched.interpolate(&floor_at(x, y), &notched_gather).is_none(), "({x}, {y})");
        }
        exact(&notched, &notched_gather, 0.7, 2.6);
    }

    /// A floor whose irradiance steps from 10 to 20 at image column
    /// `step` (a shadow's edge), at a depth of 1.
    fn stepped_floor(step: f64) -> impl Fn([f64; 2], u32, &mut Work) -> Option<LatticePoint> + Sync {
        move |at, _, work| {
            work.visibility_rays += 1;
            let h = if at[0] < step { 10.0 } else { 20.0 };
            Some(LatticePoint { point: DVec3::new(at[0], at[1], 0.0), normal: DVec3::Z, surface: FLOOR, depth: 1.0, irradiance: [h, 0.5 * h, 0.0] })
        }
    }

    /// Across a step the points around a sample disagree: over the spread
    /// the sample is not interpolated (the caller gathers it), within it or
    /// beside the step it is; a lattice coarser than the pixels falls back
    /// on the pixel centres, which the step may leave on one side.
    #[test]
    fn points_that_disagree_by_more_than_the_spread_are_not_interpolated() {
        let gather = stepped_floor(1.7);
        let strict = IrradianceLattice::gather(4, 4, 1.0, 30.0, 0.2, &gather);
        // Points at x = 1.5 (10) and 2.5 (20) around x = 1.8: a spread of
        // (20 - 10) / 20 = 0.5.
        assert!(strict.interpolate(&floor_at(1.8, 1.0), &gather).is_none());
        assert_eq!(strict.interpolate(&floor_at(1.2, 1.0), &gather), Some([10.0, 5.0, 0.0]));
        let lenient = IrradianceLattice::gather(4, 4, 1.0, 30.0, 0.5, &gather);
        let h = lenient.interpolate(&floor_at(1.8, 1.0), &gather).expect("a spread of 0.5 is within 0.5")[0];
        assert!((h - 13.0).abs() < 1e-12, "{h}");
        // Every 2 pixels: coarse points at x = 1 and 3 straddle the step at
        // 2.2; the centres at 1.5 and 2.5 do too, at 0.5 and 1.5 not.
        let stepped = stepped_floor(2.2);
        let coarse = IrradianceLattice::gather(4, 4, 2.0, 30.0, 0.2, &stepped);
        assert_eq!(coarse.interpolate(&floor_at(1.2, 1.0), &stepped), Some([10.0, 5.0, 0.0]));
        assert!(coarse.interpolate(&floor_at(1.8, 1.0), &stepped).is_none());
    }

    /// Where a coarse lattice (every 2 pixels) has an edge in the cell, the
    /// pixel centres are gathered and interpolated instead; the points
    /// gathered then are the coarse ones and those centres only.
    #[test]
    fn a_coarse_lattice_falls_back_on_the_pixel_centres() {
        let gather = floor_and_wall(&[]);
        let lattice = IrradianceLattice::gather(4, 4, 2.0, 30.0, 1.0, &gather);
        assert_eq!(lattice.point_count(), 4);
        // Coarse points at x = 1 (floor) and 3 (wall): the cell holding
        // x = 1.2 crosses the edge; the centres at 0.5 and 1.5 do not.
        exact(&lattice, &gather, 1.2, 1.0);
        assert_eq!(lattice.point_count(), 4 + 4);
        exact(&lattice, &gather, 1.2, 1.0);
        assert_eq!(lattice.point_count(), 8, "a centre is gathered once");
    }

    /// Under perspective, `H` linear over a plane is linear in the image
    /// only after division by depth: a floor seen from a pinhole at height
    /// 1 (image row `v` sees depth `1 / v`, world distance `u / v` across)
    /// with `H = 3 + 2 X + Z` at world point `(X, Z)` is interpolated
    /// exactly between rows far apart in depth.
    #[test]
    fn interpolation_is_perspective_correct() {
        let world = |at: [f64; 2]| {
            let (u, v) = (at[0] - 2.0, at[1] + 0.1);
            (u / v, 1.0 / v)
        };
        let gather = |at: [f64; 2], _: u32, _: &mut Work| {
            let (x, z) = world(at);
            Some(LatticePoint { point: DVec3::new(x, z, 0.0), normal: DVec3::Z, surface: FLOOR, depth: z, irradiance: [3.0 + 2.0 * x + z; 3] })
        };
        let lattice = IrradianceLattice::gather(4, 4, 1.0, 30.0, 1.0, &gather);
        for at in [[1.1, 0.9], [2.3, 1.2], [0.7, 2.6]] {
            let (x, z) = world(at);
            let h = lattice.interpolate(&Target { at, point: DVec3::new(x, z, 0.0), normal: DVec3::Z, surface: FLOOR }, &gather).unwrap()[0];
            assert!((h - (3.0 + 2.0 * x + z)).abs() < 1e-9, "{at:?}: {h} vs {}", 3.0 + 2.0 * x + z);
        }
    }

    /// A sample off every neighbour's plane (a step of the same object) or
    /// facing another way gets no interpolation; nor does one on another
    /// surface.
    #[test]
    fn no_value_off_the_plane_or_facing_away() {
        let gather = floor_and_wall(&[]);
        let lattice = IrradianceLattice::gather(4, 4, 1.0, 30.0, 1.0, &gather);
        let raised = Target { point: DVec3::new(1.0, 1.0, 0.5), ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&raised, &gather).is_none());
        let tilted = Target { normal: DVec3::new(0.0, 0.6, 0.8), ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&tilted, &gather).is_none());
        let wall_surface_on_floor = Target { surface: WALL, ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&wall_surface_on_floor, &gather).is_none());
    }

    /// The four points around any sample hold the four visibility blocks,
    /// and every lattice point's work lands in its own pixel.
    #[test]
    fn neighbours_hold_every_block_and_work_lands_in_its_pixel() {
        let blocks = std::sync::Mutex::new(Vec::new());
        let lattice = IrradianceLattice::gather(3, 2, 0.5, 30.0, 1.0, &|at, block, work| {
            work.visibility_rays += 1;
            blocks.lock().unwrap().push(((at[0] * 2.0 - 0.5) as usize, (at[1] * 2.0 - 0.5) as usize, block));
            None
        });
        let blocks = blocks.into_inner().unwrap();
        let block_at = |i: usize, j: usize| blocks.iter().find(|b| (b.0, b.1) == (i, j)).unwrap().2;
        for j in 0..3 {
            for i in 0..5 {
                let mut four = [block_at(i, j), block_at(i + 1, j), block_at(i, j + 1), block_at(i + 1, j + 1)];
                four.sort_unstable();
                assert_eq!(four, [0, 1, 2, 3], "at ({i}, {j})");
            }
        }
        assert!(lattice.work_per_pixel().iter().all(|w| w.visibility_rays == 4));
    }
}

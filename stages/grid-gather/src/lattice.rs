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
//! chord within [`PLANE_SLOPE`] of it). Anywhere else (a silhouette, a
//! crease, a sliver, the image's border) the sample is gathered itself, as
//! without the lattice: the lattice interpolates between its points and
//! never extrapolates, which had left a floor's far edge 4% off where a
//! sample's only neighbours lay on one side of it. The light of
//! luminaires, windows and translucent twins is added per sample as
//! before; only the links' gather is interpolated.
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

/// Largest `|n . (q - p)| / |q - p|` for a lattice point `q` to count as in
/// the tangent plane at the sample `p` (the sine of 5 degrees): a curved
/// surface tessellated finer than about 12 pixels across passes, a step
/// between parallel faces of one object does not.
pub const PLANE_SLOPE: f64 = 0.087;

/// The visibility blocks interleaved over the lattice (2 x 2).
pub const BLOCKS: u32 = 4;

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

/// The lattice over an image ([`IrradianceLattice::gather`]).
pub struct IrradianceLattice {
    /// Pixels between neighbouring lattice points.
    spacing: f64,
    /// Lattice points per row.
    columns: usize,
    /// Rows of lattice points.
    rows: usize,
    /// Per lattice point, row-major: what it saw, `None` where it has no
    /// gather (a miss, a back face, a mirror or pane).
    points: Vec<Option<LatticePoint>>,
    /// Per pixel, row-major: the work of its lattice points.
    work: Vec<Work>,
    /// Cosine of the crease angle.
    crease_cos: f64,
}

impl IrradianceLattice {
    /// The default spacing for `spp` camera samples per pixel, pixels
    /// (module docs).
    pub fn default_spacing(spp: u32) -> f64 {
        (2.0 / f64::from(spp.max(1)).sqrt()).min(1.0)
    }

    /// Gathers the lattice of a `width` x `height` image, its points
    /// `spacing` pixels apart, the first half a spacing from the top left
    /// corner: `point(at, block, work)` casts the camera ray through image
    /// position `at` and gathers there with visibility block `block`, or
    /// says there is nothing to gather. Points in parallel; the result does
    /// not depend on the thread count.
    pub fn gather(
        width: u32,
        height: u32,
        spacing: f64,
        crease_angle_deg: f64,
        point: &GatherPoint,
    ) -> Self {
        let along = |pixels: u32| (f64::from(pixels) / spacing).ceil().max(1.0) as usize;
        let (columns, rows) = (along(width), along(height));
        let at = |index: usize| [((index % columns) as f64 + 0.5) * spacing, ((index / columns) as f64 + 0.5) * spacing];
        let gathered: Vec<(Option<LatticePoint>, Work)> = (0..columns * rows)
            .into_par_iter()
            .map(|index| {
                let block = (index % columns % 2 + 2 * (index / columns % 2)) as u32;
                let mut work = Work::default();
                (point(at(index), block, &mut work), work)
            })
            .collect();
        let mut work = vec![Work::default(); width as usize * height as usize];
        for (index, (_, w)) in gathered.iter().enumerate() {
            let [x, y] = at(index).map(|c| c as usize);
            work[y.min(height as usize - 1) * width as usize + x.min(width as usize - 1)].add(w);
        }
        let points = gathered.into_iter().map(|(p, _)| p).collect();
        IrradianceLattice { spacing, columns, rows, points, work, crease_cos: crease_angle_deg.to_radians().cos() }
    }

    /// The number of lattice points.
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// The work of pixel `index`'s lattice points (row-major).
    pub fn work_of_pixel(&self, index: usize) -> Work {
        self.work.get(index).copied().unwrap_or_default()
    }

    /// The irradiance at `target`, interpolated between the lattice points
    /// around it where they all lie on its surface and plane (module docs);
    /// `None` elsewhere.
    pub fn interpolate(&self, target: &Target) -> Option<[f64; 3]> {
        let (fx, fy) = (target.at[0] / self.spacing - 0.5, target.at[1] / self.spacing - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let (mut sum, mut total) = ([0.0; 3], 0.0);
        for (dy, wy) in [(0.0, 1.0 - ty), (1.0, ty)] {
            for (dx, wx) in [(0.0, 1.0 - tx), (1.0, tx)] {
                if wx * wy <= 0.0 {
                    continue;
                }
                let (x, y) = (x0 + dx, y0 + dy);
                if x < 0.0 || y < 0.0 || x >= self.columns as f64 || y >= self.rows as f64 {
                    return None;
                }
                let q = self.points[y as usize * self.columns + x as usize].filter(|q| self.matches(q, target))?;
                let w = wx * wy / q.depth;
                total += w;
                (0..3).for_each(|c| sum[c] += w * q.irradiance[c]);
            }
        }
        Some(sum.map(|s| s / total))
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

    /// A lattice over a 4 x 4 image, one point per pixel, whose left half
    /// sees a floor (z = 0, normal +z) with `H = 10 + x + 2 y` at image
    /// position (x, y), at a depth of 1, and whose right half sees a wall.
    fn half_floor() -> IrradianceLattice {
        IrradianceLattice::gather(4, 4, 1.0, 30.0, &|at, _, work| {
            work.visibility_rays += 1;
            let floor = at[0] < 2.0;
            Some(LatticePoint {
                point: if floor { DVec3::new(at[0], at[1], 0.0) } else { DVec3::new(2.0, at[1], at[0]) },
                normal: if floor { DVec3::Z } else { DVec3::NEG_X },
                surface: if floor { FLOOR } else { WALL },
                depth: 1.0,
                irradiance: [10.0 + at[0] + 2.0 * at[1]; 3],
            })
        })
    }

    fn floor_at(x: f64, y: f64) -> Target {
        Target { at: [x, y], point: DVec3::new(x, y, 0.0), normal: DVec3::Z, surface: FLOOR }
    }

    #[test]
    fn one_point_per_pixel_up_to_4_spp_then_a_finer_lattice() {
        assert_eq!([1, 2, 4, 16, 64].map(IrradianceLattice::default_spacing), [1.0, 1.0, 1.0, 0.5, 0.25]);
    }

    /// Interpolation reproduces a linear function exactly between lattice
    /// points of the sample's surface, and gives nothing where a point
    /// around the sample is off that surface (the edge) or off the image.
    #[test]
    fn interpolation_is_exact_for_linear_irradiance_and_stops_at_an_edge() {
        let lattice = half_floor();
        for (x, y) in [(0.5, 0.5), (1.2, 1.7), (0.9, 3.3), (1.0, 2.25), (1.5, 3.5)] {
            let h = lattice.interpolate(&floor_at(x, y)).unwrap()[0];
            assert!((h - (10.0 + x + 2.0 * y)).abs() < 1e-12, "({x}, {y}): {h}");
        }
        // At x = 1.8 the points at 1.5 (floor) and 2.5 (wall) surround it.
        assert!(lattice.interpolate(&floor_at(1.8, 1.5)).is_none());
        // At y = 3.7 the points below the last row are off the image.
        assert!(lattice.interpolate(&floor_at(1.0, 3.7)).is_none());
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
        let lattice = IrradianceLattice::gather(4, 4, 1.0, 30.0, &|at, _, _| {
            let (x, z) = world(at);
            Some(LatticePoint { point: DVec3::new(x, z, 0.0), normal: DVec3::Z, surface: FLOOR, depth: z, irradiance: [3.0 + 2.0 * x + z; 3] })
        });
        for at in [[1.1, 0.9], [2.3, 1.2], [0.7, 2.6]] {
            let (x, z) = world(at);
            let h = lattice.interpolate(&Target { at, point: DVec3::new(x, z, 0.0), normal: DVec3::Z, surface: FLOOR }).unwrap()[0];
            assert!((h - (3.0 + 2.0 * x + z)).abs() < 1e-9, "{at:?}: {h} vs {}", 3.0 + 2.0 * x + z);
        }
    }

    /// A sample off every neighbour's plane (a step of the same object) or
    /// facing another way gets no interpolation; so does one outside the
    /// image's lattice with no neighbour on its surface.
    #[test]
    fn no_value_off_the_plane_or_facing_away() {
        let lattice = half_floor();
        let raised = Target { point: DVec3::new(1.0, 1.0, 0.5), ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&raised).is_none());
        let tilted = Target { normal: DVec3::new(0.0, 0.6, 0.8), ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&tilted).is_none());
        let wall_surface_on_floor = Target { surface: WALL, ..floor_at(1.0, 1.0) };
        assert!(lattice.interpolate(&wall_surface_on_floor).is_none());
    }

    /// The four points around any sample hold the four visibility blocks,
    /// and every lattice point's work lands in its own pixel.
    #[test]
    fn neighbours_hold_every_block_and_work_lands_in_its_pixel() {
        let blocks = std::sync::Mutex::new(Vec::new());
        let lattice = IrradianceLattice::gather(3, 2, 0.5, 30.0, &|at, block, work| {
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
        assert!((0..6).all(|p| lattice.work_of_pixel(p).visibility_rays == 4));
    }
}

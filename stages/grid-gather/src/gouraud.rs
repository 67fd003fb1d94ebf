//! Preview shading: the solution's piecewise-constant element radiosity
//! made continuous by Gouraud interpolation over the leaf elements' corners.
//!
//! # Vertex radiosity
//!
//! Every leaf corner `c` of leaf `i` gets the value
//!
//! ```text
//! B_c = sum_{j in S(c)} A_j B_j / sum_{j in S(c)} A_j
//! ```
//!
//! where `S(c)` holds the leaves `j` that have a corner at the same world
//! point as `c` and whose normal lies within the crease angle of leaf `i`'s
//! normal (`n_i . n_j >= cos(crease)`; `i` itself always belongs), and,
//! with material seams on (the default), the same material as leaf `i`.
//! `A_j` is
//! the leaf's area in m² as the solution gives it: the part of the leaf
//! open to the scene (hierarchical-solve leaves out what lies buried under
//! a solid, whose leaf shows its exposed part's radiosity, so a leaf wholly
//! under a block does not darken the floor's corners around it), `B_j`
//! its radiosity in W/m². A crease (wall against floor)
//! therefore stays sharp, while the two triangles of a flat wall or the
//! facets of a tessellated sphere blend. Material seams keep a flat
//! boundary between materials sharp too: there the irradiance H is
//! continuous but `B = E + rho H` jumps with the emission E and the
//! reflectance rho (a ceiling light set into a ceiling, a rug on a floor);
//! blending would smear the light into the ceiling. Inside a leaf, radiosity is
//! `B(p) = sum_k l_k B_{c_k}` with `l` the point's barycentric coordinates
//! in the leaf (linear interpolation, Gouraud 1971).
//!
//! These are the values of `mean_passes` 0. With passes (3 by default)
//! the `B_j` in the sum are then corrected until each leaf's interpolated
//! mean is close to its own radiosity ([`mean_preserving`]): plain means
//! showed the border of a wall too bright and its interior too dark.
//!
//! # Leaf gradients
//!
//! By default (`leaf_gradients`) each leaf is shown as its four children
//! (the solver's subdivision rule), lying on the plane through the leaf's
//! value that fits its neighbours' values best (a least-squares gradient,
//! [`Shown::on_gradients`]), or, where the solution measured the leaf's
//! slope (its `slope` table: the light of emitters across the leaves of a
//! penumbra), half that plane's and half the measured
//! ([`MEASURED_SLOPE`]); the corners above are then those of the
//! children. A leaf's children keep its value as their mean, nearly, so
//! fewer passes are needed than for the leaves' own values (8, the
//! default before), and each pass also carries the noise of the solver's
//! leaves into the corners: on the built-in Cornell box (preview against
//! Mitsuba, seeds 1-8) 2, 3 and 8 passes gave 1.586%, 1.597% and 1.655%
//! relative RMSE at `EPS` 1e-3, 1.099%, 1.109% and 1.145% at 6e-4, 2.471%,
//! 2.464% and 2.510% at 1.5e-3; with exact means (the `EPS` 2.5e-5
//! solve's over the 1e-3 solve's leaves), where more passes converge
//! further, 1.116%, 1.087% and 1.081% (4: 1.075%).
//!
//! # Coincident corners
//!
//! Corners are compared in f64 world (mesh-frame) coordinates: two corners
//! are the same point when every coordinate differs by at most
//! `h = weld_tolerance x` the scene's bounding-box diagonal. Each corner is
//! hashed into the cube of side `h` that contains it (`round(p / h)`), and a
//! lookup scans that cube and its 26 neighbours, then checks the distance.
//! So one point computed twice with different rounding (from two triangles'
//! barycentrics) is never split across a cell border. Sums run over the
//! matched leaves sorted by leaf index, so every corner of one point gets
//! bit-identical values whatever the thread count.
//!
//! # Remaining discontinuities
//!
//! T-vertices are not resolved: where a fine leaf's corner lies on the edge
//! of a coarser neighbouring leaf (the solver refined one side of an edge
//! more than the other), the coarse leaf interpolates between its own two
//! corners along that edge and ignores the fine corner's value, so the image
//! can step slightly along such edges. This is a preview: the full final
//! gather (perspective grid, sender classification; paper 000 Sec. 4, a
//! later issue) replaces it and does not interpolate element radiosity.

use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::geometry::TriangleGeometry;
use radiometry::subdivision::{children, leaf_holding, Corners, ROOT};
use schemas::hierarchy::Leaf;
use rayon::prelude::*;
use schemas::solution::{LeafSlope, Solution, NONE};
use schemas::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// How leaf corners are merged into shading vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Smoothing {
    /// Leaves whose normals differ by more than this angle, degrees, do not
    /// blend at a shared corner.
    pub crease_angle_deg: f64,
    /// Corners closer than this fraction of the scene's bounding-box
    /// diagonal (per coordinate) are one point.
    pub weld_tolerance: f64,
    /// Leaves of different materials do not blend at a shared corner.
    pub material_seams: bool,
    /// Correction passes making each leaf's interpolated mean its
    /// radiosity ([`mean_preserving`]); 0: plain area-weighted means.
    pub mean_passes: u32,
    /// Each leaf shown as its four children on its least-squares plane
    /// ([`Shown::on_gradients`]); off: the leaves' own values alone.
    pub leaf_gradients: bool,
}

/// Gouraud-interpolated radiosity over the solution's leaf elements.
#[derive(Clone, Debug)]
pub struct Gouraud {
    /// `first_child` of every element.
    first_child: Vec<u32>,
    /// Leaf number of every element, [`NONE`] for inner elements.
    leaf_of_element: Vec<u32>,
    /// Radiosity at the three corners of every shown leaf (a leaf, or one
    /// of the four a leaf is shown as), W/m², RGB.
    corner_radiosity: Vec<[[f64; 3]; 3]>,
    /// Number of the solution's leaf elements.
    leaves: usize,
    /// Number of distinct corner points (welded positions) of the shown
    /// leaves.
    vertices: usize,
}

impl Gouraud {
    /// Checks that `solution` belongs to the mesh of `triangles` (whose
    /// material indices are `materials`) and computes the vertex radiosity.
    /// `solution_path` only names the file in errors.
    pub fn new(
        triangles: &[TriangleGeometry],
        materials: &[u32],
        solution: &Solution,
        solution_path: &Path,
        smoothing: Smoothing,
    ) -> Result<Self> {
        Self::of(triangles, materials, solution, solution_path, smoothing, &|_, e| e.radiosity.map(f64::from), &solution.slopes)
    }

    /// [`Self::new`] interpolating `value(corners, element)` of each leaf
    /// element (barycentric corners in its triangle) instead of its
    /// radiosity, with `slopes` the leaves' measured slopes of it
    /// ([`Shown::on_gradients`]): the display of a textured scene
    /// interpolates the irradiance this way ([`crate::detail`]), with no
    /// slopes (the solution's are of the radiosity).
    pub fn of(
        triangles: &[TriangleGeometry],
        materials: &[u32],
        solution: &Solution,
        solution_path: &Path,
        smoothing: Smoothing,
        value: &(dyn Fn(&Corners, &schemas::solution::Element) -> [f64; 3] + Sync),
        slopes: &[LeafSlope],
    ) -> Result<Self> {
        let leaves = checked_leaves(triangles, solution, solution_path)?;
        let elements = &solution.elements;
        // Per leaf: world corners, normal, area, radiosity.
        let own = Shown {
            positions: leaves.iter().flat_map(|l| triangles[l.triangle as usize].element(&l.corners)).collect(),
            normal: leaves.iter().map(|l| triangles[l.triangle as usize].normal).collect(),
            material: leaves.iter().map(|l| materials[l.triangle as usize]).collect(),
            area: leaves.iter().map(|l| f64::from(elements[l.element as usize].area)).collect(),
            value: leaves.par_iter().map(|l| value(&l.corners, &elements[l.element as usize])).collect(),
        };
        let cell = weld_cell(triangles, smoothing.weld_tolerance);
        let blends = own.blends(cell, smoothing);
        let mut first_child: Vec<u32> = elements.iter().map(|e| e.first_child).collect();
        let mut leaf_of_element = vec![NONE; elements.len()];
        let (shown, blends) = if smoothing.leaf_gradients {
            // Leaf k's four shown leaves follow the solution's elements,
            // as its children would (radiometry's subdivision rule).
            let split = own.on_gradients(&blends.lists, &leaves, triangles, &measured_slopes(&leaves, elements.len(), slopes));
            for (k, leaf) in leaves.iter().enumerate() {
                first_child[leaf.element as usize] = (elements.len() + 4 * k) as u32;
            }
            first_child.resize(elements.len() + 4 * leaves.len(), NONE);
            leaf_of_element.extend(0..4 * leaves.len() as u32);
            let blends = split.blends(cell, smoothing);
            (split, blends)
        } else {
            for (k, leaf) in leaves.iter().enumerate() {
                leaf_of_element[leaf.element as usize] = k as u32;
            }
            (own, blends)
        };
        let lists: Vec<&[u32]> = blends.lists.iter().map(Vec::as_slice).collect();
        let corner_radiosity = mean_preserving(&lists, &shown.area, &shown.value, smoothing.mean_passes);
        Ok(Gouraud { first_child, leaf_of_element, corner_radiosity, leaves: leaves.len(), vertices: blends.vertices })
    }

    /// Number of the solution's leaf elements.
    pub fn leaves(&self) -> usize {
        self.leaves
    }

    /// Number of distinct corner points of the shown leaves (shared
    /// corners counted once, whatever their normals).
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// Radiosity B, W/m² RGB, at the point with barycentric `uv` in mesh
    /// triangle `triangle`: descend from the triangle's root element to the
    /// leaf containing the point, then interpolate the leaf's corner values.
    /// Coordinates slightly outside the triangle (ray-hit round-off) are
    /// clamped onto it.
    pub fn radiosity(&self, triangle: u32, uv: [f64; 2]) -> [f64; 3] {
        let (element, local) = leaf_holding(triangle as usize, uv, |e| (self.first_child[e] != NONE).then(|| self.first_child[e] as usize));
        let corners = &self.corner_radiosity[self.leaf_of_element[element] as usize];
        std::array::from_fn(|channel| (0..3).map(|k| local[k] * corners[k][channel]).sum())
    }
}

/// The leaf elements of `solution`, checked to belong to the mesh of
/// `triangles` and to have a finite radiosity (`solution_path` only names
/// the file in errors).
pub fn checked_leaves(triangles: &[TriangleGeometry], solution: &Solution, solution_path: &Path) -> Result<Vec<Leaf>> {
    let leaves = solution.leaves(triangles.len(), ROOT, children).map_err(|why| {
        Error::invalid(solution_path, None, format!("solution does not belong to this mesh: {why}"))
    })?;
    if let Some(leaf) = leaves.iter().find(|l| !solution.elements[l.element as usize].radiosity.iter().all(|b| b.is_finite())) {
        return Err(Error::invalid(solution_path, None, format!("element {} has a non-finite radiosity", leaf.element)));
    }
    Ok(leaves)
}

/// Leaves as the preview shows them: per leaf its three world corners,
/// normal, material, area (m², open to the scene) and value (W/m², RGB).
struct Shown {
    positions: Vec<DVec3>,
    normal: Vec<DVec3>,
    material: Vec<u32>,
    area: Vec<f64>,
    value: Vec<[f64; 3]>,
}

/// How far past the range of a leaf's and its neighbours' values its
/// children may reach, as a fraction of that range's width
/// ([`Shown::on_gradients`]). On the built-in Cornell box (`EPS` 1e-3,
/// seeds 1 and 2, preview against Mitsuba, 8 passes) 1/4 never binds:
/// 1.702% and 1.579% relative RMSE, as with no bound; 1/10 gives 1.710%
/// and 1.591%; 0 (the limiter of Barth and Jespersen, at the children's
/// centroids) 1.840% and 1.733%. Beside a step from 0 to 1 (a hard
/// shadow edge across coarse leaves) the preview then shows at most 1.28
/// (1.32 with no bound, 1.17 at 1/10).
pub const SHOWN_RANGE: f64 = 0.25;

/// The weight of a leaf's measured slope (the solution's `slope` table:
/// hierarchical-solve's emitters' light across the leaves of a penumbra,
/// its `slopes` module) against the plane its neighbours fit
/// ([`Shown::on_gradients`]), which takes the rest. Two estimates of the
/// slope inside the leaf, with errors of different kinds: the neighbours'
/// plane spreads a shadow's edge over the leaves beside it, and the
/// measured slope carries the noise of its 16 rays and leaves out the
/// kernel's own slope and the other links'. On the built-in Cornell box
/// (preview against Mitsuba, relative RMSE, mean over seeds 1-8; 0 is the
/// neighbours' plane alone, as before):
///
/// | weight | `EPS` 1.5e-3 | 1e-3 | 6e-4 |
/// |---|---|---|---|
/// | 0 | 2.472% | 1.599% | 1.111% |
/// | 0.3 | 2.423% | 1.542% | 1.098% |
/// | 0.4 | 2.415% | 1.532% | 1.097% |
/// | 0.5 | 2.411% | 1.525% | 1.098% |
/// | 0.6 | 2.411% | 1.522% | 1.100% |
/// | 0.75 | 2.418% | 1.526% | 1.106% |
/// | 1 | 2.452% | 1.547% | 1.123% |
///
/// At a half every seed is better at 1e-3, 7 of 8 at 1.5e-3 and 6 of 8 at
/// 6e-4 (the other two within 0.006 points).
pub const MEASURED_SLOPE: f64 = 0.5;

/// Per leaf of `leaves` (of a solution of `elements` elements), its
/// measured slope from `slopes`, if any.
fn measured_slopes(leaves: &[Leaf], elements: usize, slopes: &[LeafSlope]) -> Vec<Option<[DVec3; 3]>> {
    let mut leaf_of = vec![NONE; elements];
    for (k, leaf) in leaves.iter().enumerate() {
        leaf_of[leaf.element as usize] = k as u32;
    }
    let mut measured = vec![None; leaves.len()];
    for s in slopes {
        if let Some(&k) = leaf_of.get(s.element as usize).filter(|&&k| k != NONE) {
            measured[k as usize] = Some(s.gradient.map(|g| DVec3::from(g.map(f64::from))));
        }
    }
    measured
}

/// Per corner of the shown leaves, the leaves it blends ([`Shown::blends`]).
struct Blends {
    /// Per corner (three per leaf, in leaf order), the leaves meeting there
    /// that blend with its own, sorted, its own included.
    lists: Vec<Vec<u32>>,
    /// Number of distinct corner points.
    vertices: usize,
}

impl Shown {
    /// The leaves each corner blends (module docs: the same point, within
    /// the crease angle, of one material with seams on). Sorted, so that
    /// sums over them are bit-identical whatever the thread count.
    fn blends(&self, cell: f64, smoothing: Smoothing) -> Blends {
        let positions = &self.positions;
        let key = |p: DVec3| -> [i64; 3] { (p / cell).round().to_array().map(|x| x as i64) };
        // Built sequentially in corner order: each cell's list is sorted.
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (c, &p) in positions.iter().enumerate() {
            grid.entry(key(p)).or_default().push(c as u32);
        }
        let cos_crease = smoothing.crease_angle_deg.to_radians().cos();
        // Per corner: its blend and whether it is the lowest-numbered
        // corner at its point.
        let per_corner: Vec<(Vec<u32>, bool)> = (0..positions.len())
            .into_par_iter()
            .map(|c| {
                let p = positions[c];
                let home = key(p);
                let mut same_point = Vec::new();
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let Some(ids) = grid.get(&[home[0] + dx, home[1] + dy, home[2] + dz]) else { continue };
                            same_point.extend(ids.iter().map(|&d| d as usize).filter(|&d| (positions[d] - p).abs().max_element() <= cell));
                        }
                    }
                }
                let representative = same_point.iter().all(|&d| d >= c);
                let me = c / 3;
                let mut blend: Vec<u32> = same_point
                    .into_iter()
                    .map(|d| d / 3)
                    .filter(|&j| {
                        let same_material = !smoothing.material_seams || self.material[j] == self.material[me];
                        j == me || (same_material && self.normal[me].dot(self.normal[j]) >= cos_crease)
                    })
                    .map(|j| j as u32)
                    .collect();
                blend.sort_unstable();
                blend.dedup();
                (blend, representative)
            })
            .collect();
        let vertices = per_corner.iter().filter(|(_, first)| *first).count();
        Blends { lists: per_corner.into_iter().map(|(b, _)| b).collect(), vertices }
    }

    /// Centroid of leaf `k`.
    fn centroid(&self, k: usize) -> DVec3 {
        (self.positions[3 * k] + self.positions[3 * k + 1] + self.positions[3 * k + 2]) / 3.0
    }

    /// Each leaf as its four children (`leaves`' corners split by
    /// radiometry's subdivision rule), lying on the leaf's least-squares
    /// plane through its neighbours' values ([`Shown::plane`]):
    ///
    /// ```text
    /// B_m = B_k + g_k . (c_m - c_k)
    /// ```
    ///
    /// (`c` centroids), each a quarter of the leaf's area; where the leaf
    /// has a `measured` slope, `g_k` is that blended with the plane's
    /// ([`MEASURED_SLOPE`]). The children's
    /// centroids average to the leaf's, so their mean is the leaf's value.
    /// Where a child would leave the range of the leaf's and its
    /// neighbours' values widened by [`SHOWN_RANGE`] of its width on either
    /// side (and not below 0 for a leaf of positive value), the gradient's
    /// channel is scaled down until none does: beside a step (a hard shadow
    /// edge across coarse leaves) the plane's slope is the step's, which
    /// the leaf on either side does not have.
    ///
    /// Gouraud over the leaves' own values draws each leaf's variation from
    /// its corners alone, which its neighbours share: inside it the
    /// interpolant is nearly flat, and along a falloff steeper than the
    /// leaves are fine (a crease, a penumbra) the corners' averages round
    /// the leaves off. The least-squares gradient (cell-centred finite
    /// volumes, Barth and Jespersen 1989, here with the looser bound above
    /// instead of their limiter, which flattened every extremum back)
    /// takes the slope from the neighbours' values; the children carry it, and Gouraud over them keeps it. On
    /// the built-in Cornell box (preview against Mitsuba, emitters and 2
    /// px round edges left out, seeds 1-8; the leaves' own values at 8
    /// passes, the gradients at the default 3, module docs) the relative
    /// RMSE went from 1.861% to 1.597% at `EPS` 1e-3, from 1.605% to
    /// 1.354% at 8e-4, from 1.268% to 1.109% at 6e-4, from 3.26% to 2.46%
    /// at 1.5e-3; with the `EPS` 2.5e-5 solve's means on the 1e-3 solve's
    /// leaves (seed 1), from 1.486% to 1.087%. Measured at 8 passes (seed
    /// 1): two levels of children instead of one 1.766% (1.702% with
    /// one), the gradient's neighbours weighed alike or by `1 / d` instead
    /// of `1 / d²` 1.750% and 1.723%, the gradient scaled by 0.75 or 1.25
    /// 1.847% and 1.729%, children without it 2.846%. RenderPark's
    /// solutions, linear per element and shown through the same preview
    /// as 16 leaves each, come out about as before (1.629% at its
    /// threshold 3e-5 with their own values at 8 passes, 1.660% with the
    /// gradients at 8, 1.65% at the default 3).
    fn on_gradients(&self, blends: &[Vec<u32>], leaves: &[Leaf], triangles: &[TriangleGeometry], measured: &[Option<[DVec3; 3]>]) -> Shown {
        let split: Vec<[([DVec3; 3], [f64; 3]); 4]> = leaves
            .par_iter()
            .enumerate()
            .map(|(k, leaf)| {
                let centre = self.centroid(k);
                let (fitted, range) = self.plane(k, blends);
                let gradient = match measured[k] {
                    Some(slope) => std::array::from_fn(|c| fitted[c] * (1.0 - MEASURED_SLOPE) + slope[c] * MEASURED_SLOPE),
                    None => fitted,
                };
                let b = self.value[k];
                let quarters = children(&leaf.corners).map(|c| triangles[leaf.triangle as usize].element(&c));
                let offsets: [[f64; 3]; 4] = quarters.map(|q| std::array::from_fn(|c| gradient[c].dot((q[0] + q[1] + q[2]) / 3.0 - centre)));
                // The largest share of each channel's gradient that keeps
                // every child within the widened range.
                let scale: [f64; 3] = std::array::from_fn(|c| {
                    let (lo, hi) = range[c];
                    let widening = SHOWN_RANGE * (hi - lo);
                    let lo = if b[c] >= 0.0 { (lo - widening).max(0.0) } else { lo - widening };
                    offsets.iter().map(|o| o[c]).fold(1.0, |s: f64, d| {
                        if d > 0.0 { s.min((hi + widening - b[c]) / d) } else if d < 0.0 { s.min((lo - b[c]) / d) } else { s }
                    }).max(0.0)
                });
                std::array::from_fn(|m| (quarters[m], std::array::from_fn(|c| b[c] + scale[c] * offsets[m][c])))
            })
            .collect();
        Shown {
            positions: split.iter().flatten().flat_map(|(q, _)| *q).collect(),
            normal: self.normal.iter().flat_map(|&n| [n; 4]).collect(),
            material: self.material.iter().flat_map(|&m| [m; 4]).collect(),
            area: self.area.iter().flat_map(|&a| [a / 4.0; 4]).collect(),
            value: split.iter().flatten().map(|&(_, v)| v).collect(),
        }
    }

    /// The gradient (per channel, in leaf `k`'s plane) of the plane through
    /// its value that fits its neighbours' values at their centroids best,
    /// each weighed by `1 / d²` (`d` its centroid's distance from `k`'s, in
    /// `k`'s plane): the leaves its corners blend with (`blends`) that are
    /// open to the scene. 0 where they do not span the plane (fewer than
    /// two, or all in a line), and for a leaf with nothing open. Also the
    /// range of the values of `k` and those neighbours, per channel.
    fn plane(&self, k: usize, blends: &[Vec<u32>]) -> ([DVec3; 3], [(f64, f64); 3]) {
        let mut neighbours: Vec<usize> = blends[3 * k..3 * k + 3].iter().flatten().map(|&j| j as usize).filter(|&j| j != k && self.area[j] > 0.0).collect();
        neighbours.sort_unstable();
        neighbours.dedup();
        let range = std::array::from_fn(|c| neighbours.iter().map(|&j| self.value[j][c]).fold((self.value[k][c], self.value[k][c]), |(lo, hi), b| (lo.min(b), hi.max(b))));
        let none = ([DVec3::ZERO; 3], range);
        let u = (self.positions[3 * k + 1] - self.positions[3 * k]).normalize_or_zero();
        if self.area[k] <= 0.0 || u == DVec3::ZERO {
            return none;
        }
        let v = self.normal[k].cross(u);
        let centre = self.centroid(k);
        let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
        let mut rhs = [[0.0; 2]; 3];
        for &j in &neighbours {
            let d = self.centroid(j) - centre;
            let (x, y) = (d.dot(u), d.dot(v));
            let w = 1.0 / (x * x + y * y);
            if !w.is_finite() {
                continue;
            }
            (xx, xy, yy) = (xx + w * x * x, xy + w * x * y, yy + w * y * y);
            for (r, (bj, bk)) in rhs.iter_mut().zip(self.value[j].iter().zip(self.value[k])) {
                r[0] += w * x * (bj - bk);
                r[1] += w * y * (bj - bk);
            }
        }
        let det = xx * yy - xy * xy;
        if det.is_nan() || det <= 1e-9 * xx * yy {
            return none;
        }
        (rhs.map(|[rx, ry]| u * ((yy * rx - xy * ry) / det) + v * ((xx * ry - xy * rx) / det)), range)
    }
}

/// The corner values of every leaf (three per leaf, in leaf order): the
/// area-weighted mean over each corner's `blends` of per-leaf values `r`,
///
/// ```text
/// v_c = sum_{j in S(c)} A_j r_j / sum_{j in S(c)} A_j,
/// ```
///
/// with `r` first the radiosity `B`, then corrected `passes` times by what
/// the interpolant's leaf means `m_i = (v_i1 + v_i2 + v_i3) / 3` miss:
/// `r_i += B_i - m_i`. Each pass is a Landweber step `v += A (B - M v)` on
/// `M v = B`, so the vertex values move towards those whose linear
/// interpolant has each leaf's radiosity as its mean over the leaf, which
/// is what a piecewise-constant (Galerkin) solution's element values are;
/// a linear radiosity is the fixed point. Plain means (`passes` 0) put a
/// leaf's mean at the corners it shares with no leaf across a crease:
/// where radiosity falls towards the crease (a wall at the floor, at the
/// ceiling), the border showed too bright and the interior, averaged with
/// it, too dark. Cornell box at the default EPS, against Mitsuba, 2 px
/// edges left out: relative RMSE 2.08% -> 0.73%, pixels over 10% 1.7% ->
/// 0.23%, every wall's mean from -0.44..-0.66% to within 0.17%; the full
/// gather gives 0.47%.
///
/// A step (a hard shadow edge across coarse leaves) has no continuous
/// piecewise-linear fit with the right means; the least-squares one rings,
/// up to 40% over the bright side and below 0 on the dark side. So each
/// corner value is kept within its leaves' radiosity range widened by that
/// range's width on either side (and not below 0, unless a leaf is): a
/// corner whose leaves
/// all agree keeps their value, while one whose leaves differ may reach
/// past them as far as a linear falloff towards a crease needs. That costs
/// 0.73% against 0.72% on the Cornell box.
fn mean_preserving(blends: &[&[u32]], area: &[f64], radiosity: &[[f64; 3]], passes: u32) -> Vec<[[f64; 3]; 3]> {
    // Per corner and channel, the range its value is kept in: its leaves'
    // radiosity range widened by its width on either side, and not below 0
    // unless a leaf already is (a linear basis's undershoot in a solution
    // converted from another program).
    let bounds: Vec<[(f64, f64); 3]> = blends
        .par_iter()
        .map(|blend| {
            std::array::from_fn(|c| {
                let (lo, hi) = blend.iter().map(|&j| radiosity[j as usize][c]).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), b| (lo.min(b), hi.max(b)));
                let floor = if lo < 0.0 { f64::NEG_INFINITY } else { 0.0 };
                ((lo - (hi - lo)).max(floor), hi + (hi - lo))
            })
        })
        .collect();
    let corners = |r: &[[f64; 3]]| -> Vec<[f64; 3]> {
        blends
            .par_iter()
            .zip(&bounds)
            .enumerate()
            .map(|(c, (blend, bounds))| {
                let (mut weighted, mut total) = ([0.0; 3], 0.0);
                for &j in blend.iter() {
                    let j = j as usize;
                    for (w, b) in weighted.iter_mut().zip(r[j]) {
                        *w += area[j] * b;
                    }
                    total += area[j];
                }
                let mean = if total > 0.0 { weighted.map(|w| w / total) } else { r[c / 3] };
                std::array::from_fn(|k| mean[k].clamp(bounds[k].0, bounds[k].1))
            })
            .collect()
    };
    let mut r = radiosity.to_vec();
    let mut v = corners(&r);
    for _ in 0..passes {
        for (i, (r, b)) in r.iter_mut().zip(radiosity).enumerate() {
            for c in 0..3 {
                r[c] += b[c] - (v[3 * i][c] + v[3 * i + 1][c] + v[3 * i + 2][c]) / 3.0;
            }
        }
        v = corners(&r);
    }
    v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Side of the weld cell: `tolerance x` the bounding-box diagonal of the
/// triangles (`tolerance` itself, in metres, for a scene of zero extent).
fn weld_cell(triangles: &[TriangleGeometry], tolerance: f64) -> f64 {
    let bounds = Aabb::around(triangles.iter().flat_map(|t| t.corners));
    let diagonal = (bounds.max - bounds.min).length();
    if diagonal.is_finite() && diagonal > 0.0 {
        tolerance * diagonal
    } else {
        tolerance
    }
}

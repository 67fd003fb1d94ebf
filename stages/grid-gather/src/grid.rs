//! The 3D grid of the full gather (paper 000 Sec. 4.2) and the point
//! location in its cells' five tetrahedra (Sec. 4.4, Fig. 3).
//!
//! # Perspective grid
//!
//! Uniform in post-perspective space: with `q = p - eye`, depth
//! `d = q . forward`, screen coordinates `sx = q . right / (d tan(fov_x/2))`,
//! `sy = q . up / (d tan(fov_y/2))` (both in [-1, 1] over the image), the
//! continuous grid coordinates are
//!
//! ```text
//! a = (sx + 1) / 2 * nx,   b = (1 - sy) / 2 * ny,
//! c = (1/near - 1/d) / (1/near - 1/far) * nz
//! ```
//!
//! `c` is linear in `1/d`, as the depth of a perspective projection is, so
//! cells are truncated pyramids whose screen size is constant (`nx` x `ny`
//! cells of equal pixel size) and whose depth grows with distance. Every
//! face of a cell lies in a plane (the side faces in planes through the
//! eye, the depth faces in planes `d = const`), so the cell's five
//! tetrahedra tile it exactly.
//!
//! # Regular grid
//!
//! The option Sec. 4.2 mentions: cubes of one size over the scene's
//! bounding box, `a = (p - origin) / size`.
//!
//! # Tetrahedra
//!
//! Corner `m` of a cell (bits `x + 2y + 4z`) is vertex `(i + x, j + y,
//! k + z)`. Cells with even `i + j + k` use the tetrahedra
//! `{0,3,5,6}` (middle), `{1,0,3,5}`, `{2,0,3,6}`, `{4,0,5,6}`, `{7,3,5,6}`;
//! odd cells the mirror image in x. Neighbouring cells then split their
//! common face along the same diagonal, so the piecewise-linear
//! interpolation is continuous across cells.

use crate::{GridKind, Params};
use glam::{DMat3, DVec3};
use radiometry::bounds::Aabb;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;

/// Tetrahedra of an even cell, as cell corner numbers.
const EVEN: [[usize; 4]; 5] = [[0, 3, 5, 6], [1, 0, 3, 5], [2, 0, 3, 6], [4, 0, 5, 6], [7, 3, 5, 6]];

/// The grid's shape.
#[derive(Clone, Debug)]
enum Shape {
    Perspective { eye: DVec3, forward: DVec3, right: DVec3, up: DVec3, inv_near: f64, inv_far: f64 },
    Regular { origin: DVec3, size: f64 },
}

/// A grid of `n[0] x n[1] x n[2]` cells.
#[derive(Clone, Debug)]
pub struct Grid {
    shape: Shape,
    /// Cells per axis.
    pub n: [usize; 3],
}

/// Where a point lies: its cell's tetrahedron and its weights there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    /// Grid vertex indices (see [`Grid::vertex_index`]) of the tetrahedron.
    pub vertices: [usize; 4],
    /// Barycentric weights of the point in the tetrahedron (sum 1).
    pub weights: [f64; 4],
    /// Which of the cell's five tetrahedra.
    pub tetrahedron: usize,
    /// The cell, `(i, j, k)`.
    pub cell: [usize; 3],
}

impl Location {
    /// The weights clamped at 0 and scaled to sum 1 (a point just outside
    /// its tetrahedron, by round-off or clamping, takes the nearest face's
    /// blend instead of extrapolating); 1/4 each where none is positive.
    pub fn interpolation_weights(&self) -> [f64; 4] {
        let w = self.weights.map(|x| x.max(0.0));
        let sum: f64 = w.iter().sum();
        if sum > 0.0 { w.map(|x| x / sum) } else { [0.25; 4] }
    }
}

impl Grid {
    /// The grid `params` ask for over a `width` x `height` image through
    /// `camera` of `triangles`, whose pixel centres' hits are `centres`:
    /// `ceil(width / grid_pixels)` x `ceil(height / grid_pixels)` cells on
    /// screen; the perspective grid's `grid_depth` cells span the hits'
    /// depths 2% beyond each end (depths 1 to 2 where nothing is hit); the
    /// regular grid's cubes cover the scene's box, as many along its
    /// longest side as the screen has cells along its longer one.
    pub fn fit(params: &Params, camera: &Pinhole, (width, height): (u32, u32), centres: &[Option<DVec3>], triangles: &[TriangleGeometry]) -> Grid {
        let depths = centres.iter().flatten().map(|p| (*p - camera.eye).dot(camera.forward()));
        let (near, far) = depths.fold((f64::INFINITY, 0.0f64), |(a, b), d| (a.min(d), b.max(d)));
        let nx = (width as usize).div_ceil(params.grid_pixels as usize).max(1);
        let ny = (height as usize).div_ceil(params.grid_pixels as usize).max(1);
        match params.grid {
            GridKind::Perspective => {
                let (near, far) = if near.is_finite() && far > near { (0.98 * near, 1.02 * far) } else { (1.0, 2.0) };
                Grid::perspective(camera, width, height, near.max(1e-6), far, [nx, ny, params.grid_depth as usize])
            }
            GridKind::Regular => {
                let scene_box = Aabb::around(triangles.iter().flat_map(|t| t.corners));
                let extent = (scene_box.max - scene_box.min).max(DVec3::splat(1e-9));
                let size = extent.max_element() / nx.max(ny) as f64;
                let n = (extent / size).to_array().map(|e| (e.ceil() as usize).max(1));
                Grid::regular(scene_box.min, size, n)
            }
        }
    }

    /// A perspective grid over the view of `camera` (rendering `width` x
    /// `height`) between depths `near` and `far` (m, along the view axis,
    /// `0 < near < far`), with `nx x ny x nz` cells.
    pub fn perspective(camera: &Pinhole, width: u32, height: u32, near: f64, far: f64, n: [usize; 3]) -> Grid {
        let (w, h) = (f64::from(width), f64::from(height));
        let forward = camera.forward();
        let on_plane = |d: DVec3| d / d.dot(forward) - forward;
        // right = right_unit * tan(fov_x / 2), up = up_unit * tan(fov_y / 2).
        let right = on_plane(camera.direction(w, 0.5 * h));
        let up = on_plane(camera.direction(0.5 * w, 0.0));
        Grid { shape: Shape::Perspective { eye: camera.eye, forward, right, up, inv_near: 1.0 / near, inv_far: 1.0 / far }, n }
    }

    /// A regular grid of cubes of side `size` from `origin`, `n` cells per
    /// axis.
    pub fn regular(origin: DVec3, size: f64, n: [usize; 3]) -> Grid {
        Grid { shape: Shape::Regular { origin, size }, n }
    }

    /// Number of grid vertices.
    pub fn vertex_count(&self) -> usize {
        (self.n[0] + 1) * (self.n[1] + 1) * (self.n[2] + 1)
    }

    /// Index of vertex `(i, j, k)`.
    pub fn vertex_index(&self, v: [usize; 3]) -> usize {
        (v[2] * (self.n[1] + 1) + v[1]) * (self.n[0] + 1) + v[0]
    }

    /// Vertex `(i, j, k)` of index `index`.
    pub fn vertex_of(&self, index: usize) -> [usize; 3] {
        let (nx, ny) = (self.n[0] + 1, self.n[1] + 1);
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    /// The world point of continuous grid coordinates `g`.
    pub fn point(&self, g: [f64; 3]) -> DVec3 {
        match &self.shape {
            Shape::Perspective { eye, forward, right, up, inv_near, inv_far } => {
                let inv_d = inv_near - g[2] / self.n[2] as f64 * (inv_near - inv_far);
                let sx = 2.0 * g[0] / self.n[0] as f64 - 1.0;
                let sy = 1.0 - 2.0 * g[1] / self.n[1] as f64;
                *eye + (*forward + *right * sx + *up * sy) / inv_d
            }
            Shape::Regular { origin, size } => *origin + DVec3::from(g) * *size,
        }
    }

    /// Continuous grid coordinates of world point `p` (outside `[0, n]`
    /// when `p` is outside the grid; `None` at or behind the eye of a
    /// perspective grid).
    pub fn coordinates(&self, p: DVec3) -> Option<[f64; 3]> {
        match &self.shape {
            Shape::Perspective { eye, forward, right, up, inv_near, inv_far } => {
                let q = p - *eye;
                let d = q.dot(*forward);
                if d <= 0.0 {
                    return None;
                }
                let sx = q.dot(*right) / (d * right.length_squared());
                let sy = q.dot(*up) / (d * up.length_squared());
                let c = (inv_near - 1.0 / d) / (inv_near - inv_far) * self.n[2] as f64;
                Some([(sx + 1.0) * 0.5 * self.n[0] as f64, (1.0 - sy) * 0.5 * self.n[1] as f64, c])
            }
            Shape::Regular { origin, size } => Some(((p - *origin) / *size).to_array()),
        }
    }

    /// World position of vertex `v`.
    pub fn vertex(&self, v: [usize; 3]) -> DVec3 {
        self.point(v.map(|x| x as f64))
    }

    /// The vertices of cell `c`, by corner number `x + 2y + 4z`.
    pub fn cell_vertices(&self, c: [usize; 3]) -> [[usize; 3]; 8] {
        std::array::from_fn(|m| [c[0] + (m & 1), c[1] + ((m >> 1) & 1), c[2] + ((m >> 2) & 1)])
    }

    /// The five tetrahedra of cell `c`, as cell corner numbers.
    pub fn tetrahedra(c: [usize; 3]) -> [[usize; 4]; 5] {
        if (c[0] + c[1] + c[2]).is_multiple_of(2) {
            EVEN
        } else {
            EVEN.map(|t| t.map(|m| m ^ 1))
        }
    }

    /// Whether `p` lies in the grid's domain (between its first and last
    /// vertices on every axis).
    pub fn contains(&self, p: DVec3) -> bool {
        self.coordinates(p).is_some_and(|g| (0..3).all(|a| (0.0..=self.n[a] as f64).contains(&g[a])))
    }

    /// The cell holding `p` (clamped into the grid) and `p`'s tetrahedron
    /// and weights in it: of the five, the one whose smallest barycentric
    /// weight is largest, so a point inside the cell gets the tetrahedron
    /// that contains it and a point just outside (round-off, clamping) the
    /// nearest one, with weights that extrapolate linearly.
    pub fn locate(&self, p: DVec3) -> Option<Location> {
        let g = self.coordinates(p)?;
        let cell: [usize; 3] = std::array::from_fn(|a| (g[a].floor().max(0.0) as usize).min(self.n[a] - 1));
        Some(self.locate_in(cell, p))
    }

    /// `p`'s tetrahedron and weights in cell `cell` (see [`Self::locate`]).
    pub fn locate_in(&self, cell: [usize; 3], p: DVec3) -> Location {
        let corners = self.cell_vertices(cell);
        let mut best: Option<Location> = None;
        let mut best_min = f64::NEG_INFINITY;
        for (t, tet) in Self::tetrahedra(cell).iter().enumerate() {
            let world = tet.map(|m| self.vertex(corners[m]));
            let weights = barycentric(&world, p);
            let min = weights.iter().copied().fold(f64::INFINITY, f64::min);
            if min > best_min {
                best_min = min;
                best = Some(Location { vertices: tet.map(|m| self.vertex_index(corners[m])), weights, tetrahedron: t, cell });
            }
        }
        best.expect("five tetrahedra")
    }

    /// Edge length of a cell near `p` across the view (perspective: the
    /// screen-parallel size of a cell at `p`'s depth; regular: the cube's
    /// side), m.
    pub fn spacing_at(&self, p: DVec3) -> f64 {
        match &self.shape {
            Shape::Perspective { eye, forward, right, .. } => {
                let d = (p - *eye).dot(*forward).max(0.0);
                2.0 * d * right.length() / self.n[0] as f64
            }
            Shape::Regular { size, .. } => *size,
        }
    }

    /// Size of one image pixel at `p`, m (perspective grids; `None` for a
    /// regular grid, which knows no image), for an image `width` pixels
    /// wide.
    pub fn pixel_size_at(&self, p: DVec3, width: u32) -> Option<f64> {
        match &self.shape {
            Shape::Perspective { eye, forward, right, .. } => {
                let d = (p - *eye).dot(*forward).max(0.0);
                Some(2.0 * d * right.length() / f64::from(width))
            }
            Shape::Regular { .. } => None,
        }
    }
}

/// Barycentric weights of `p` in the tetrahedron `t` (they sum to 1 and
/// reproduce every linear function: `f(p) = sum_i w_i f(t_i)`); all 1/4 for
/// a degenerate tetrahedron.
pub fn barycentric(t: &[DVec3; 4], p: DVec3) -> [f64; 4] {
    let m = DMat3::from_cols(t[1] - t[0], t[2] - t[0], t[3] - t[0]);
    let det = m.determinant();
    if det.abs() <= f64::MIN_POSITIVE || !det.is_finite() {
        return [0.25; 4];
    }
    let l = m.inverse() * (p - t[0]);
    [1.0 - l.x - l.y - l.z, l.x, l.y, l.z]
}

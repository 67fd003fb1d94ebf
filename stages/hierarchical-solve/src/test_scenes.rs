//! Scenes the unit tests share.

use crate::elements::Hierarchy;
use crate::shaft::Occluders;
use radiometry::rays::SceneRays;
use glam::{dvec3, DVec3};
use radiometry::form_factor::point_to_one_sided_polygon;
use schemas::solution::NONE;
use test_support::meshes::{manifest, material, quads};

/// A unit floor and a unit wall standing on its far edge, facing back over
/// it (triangles 0-1 and 2 onwards, cluster 1), under a unit lamp quad at
/// `height` facing down (the last two triangles, cluster 2).
pub struct FloorAndWall {
    /// The hierarchy over them.
    pub h: Hierarchy,
    /// The lamp's first triangle.
    pub lamp: [DVec3; 3],
    /// Its triangle (and root element) index.
    pub lamp_triangle: u32,
}

impl FloorAndWall {
    /// The scene with its lamp at `height` (the wall's top is at 1) and
    /// the wall one quad (triangles 0-3 below cluster 1, the lamp 4-5).
    pub fn new(height: f64) -> Self {
        Self::with_wall_quads(height, 1)
    }

    /// The scene with the wall made of `n` x `n` quads (cluster 1 holds
    /// `2 + 2 n^2` triangles).
    pub fn with_wall_quads(height: f64, n: usize) -> Self {
        let step = 1.0 / n as f64;
        let mut faces = vec![(dvec3(0.0, 0.0, 0.0), DVec3::X, DVec3::Y, 0, 0)];
        for i in 0..n {
            for j in 0..n {
                faces.push((dvec3(1.0, j as f64 * step, i as f64 * step), DVec3::Z * step, DVec3::Y * step, 0, 0));
            }
        }
        faces.push((dvec3(0.0, 0.0, height), DVec3::Y, DVec3::X, 1, 1));
        let mesh = quads(&faces);
        let lit = 2 + 2 * n * n;
        let mut clusters = test_support::artifacts::clusters_over(&mesh);
        clusters.nodes.truncate(3);
        for (c, first, count) in [(1, 0, lit), (2, lit, 2)] {
            let node = &mut clusters.nodes[c];
            (node.first_triangle, node.triangle_count, node.first_child, node.child_count) = (first as u32, count as u32, NONE, 0);
        }
        let manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3])]);
        let h = Hierarchy::new(&mesh, &manifest, Some(clusters), None);
        FloorAndWall { h, lamp: [dvec3(0.0, 0.0, height), dvec3(0.0, 1.0, height), dvec3(1.0, 1.0, height)], lamp_triangle: lit as u32 }
    }

    /// The floor's and the wall's mean factor to the lamp triangle: an
    /// `m` x `m` midpoint grid over each of Lambert's point-to-polygon
    /// factor (002 Eq. 3, one-sided), written apart from the solver's
    /// quadratures.
    pub fn quad_factors(&self, m: usize) -> [f64; 2] {
        let grid = |origin: DVec3, u: DVec3, v: DVec3, normal: DVec3| {
            let mut sum = 0.0;
            for i in 0..m {
                for j in 0..m {
                    let p = origin + u * ((i as f64 + 0.5) / m as f64) + v * ((j as f64 + 0.5) / m as f64);
                    sum += point_to_one_sided_polygon(p, normal, &self.lamp, -DVec3::Z);
                }
            }
            sum / (m * m) as f64
        };
        [grid(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z), grid(DVec3::X, DVec3::Z, DVec3::Y, -DVec3::X)]
    }

    /// The mean over triangle `corners` (normal `normal`) of Lambert's
    /// factor to the lamp triangle: the centroids of the `m^2` triangles of
    /// its regular subdivision.
    pub fn triangle_factor(&self, corners: &[DVec3; 3], normal: DVec3, m: usize) -> f64 {
        subdivision_centroids(corners, m).into_iter().map(|p| point_to_one_sided_polygon(p, normal, &self.lamp, -DVec3::Z)).sum::<f64>() / (m * m) as f64
    }
}

/// The centroids of the `m^2` triangles, all of one area, of triangle
/// `corners`' regular subdivision into `m` steps along each edge: the
/// midpoint rule the tests' quadratures over a triangle use.
pub fn subdivision_centroids(corners: &[DVec3; 3], m: usize) -> Vec<DVec3> {
    let point = |u: f64, v: f64| corners[0] + (corners[1] - corners[0]) * (u / m as f64) + (corners[2] - corners[0]) * (v / m as f64);
    let mut centroids = Vec::with_capacity(m * m);
    for i in 0..m {
        for j in 0..m - i {
            centroids.push(point(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0));
            if i + j + 1 < m {
                centroids.push(point(i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0));
            }
        }
    }
    centroids
}

/// The rays and the occluders' box tree over `h`'s triangles, for a
/// [`crate::visibility::Tracer`].
pub fn traced(h: &Hierarchy) -> (SceneRays, Occluders) {
    let corners: Vec<_> = h.triangles.iter().map(|t| t.corners).collect();
    let scene = SceneRays::new(&corners);
    let occluders = Occluders::new(&corners, &scene);
    (scene, occluders)
}

/// Splits element `e` of `h` `levels` times, 1:4 each time, and returns
/// the elements of its last level (`4^levels` leaves).
pub fn split_levels(h: &mut Hierarchy, e: u32, levels: u32) -> Vec<u32> {
    let mut level = vec![e];
    for _ in 0..levels {
        level = level
            .iter()
            .flat_map(|&e| {
                let first = h.subdivide(e);
                first..first + 4
            })
            .collect();
    }
    level
}

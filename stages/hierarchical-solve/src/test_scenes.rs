//! Scenes the unit tests share.

use crate::elements::Hierarchy;
use crate::shaft::Occluders;
use radiometry::rays::SceneRays;
use glam::{dvec3, DVec3};
use radiometry::form_factor::point_to_one_sided_polygon;
use schemas::solution::NONE;
use test_support::meshes::{manifest, material, quads};

/// A unit floor and a unit wall standing on its far edge, facing back over
/// it (triangles 0-3, cluster 1), under a unit lamp quad at `height`
/// facing down (triangles 4-5, cluster 2).
pub struct FloorAndWall {
    /// The hierarchy over them.
    pub h: Hierarchy,
    /// Triangle 4, the lamp's first.
    pub lamp: [DVec3; 3],
}

impl FloorAndWall {
    /// The scene with its lamp at `height` (the wall's top is at 1).
    pub fn new(height: f64) -> Self {
        let mesh = quads(&[
            (dvec3(0.0, 0.0, 0.0), DVec3::X, DVec3::Y, 0, 0),
            (dvec3(1.0, 0.0, 0.0), DVec3::Z, DVec3::Y, 0, 0),
            (dvec3(0.0, 0.0, height), DVec3::Y, DVec3::X, 1, 1),
        ]);
        let mut clusters = test_support::artifacts::clusters_over(&mesh);
        clusters.nodes.truncate(3);
        for (c, first, count) in [(1, 0, 4), (2, 4, 2)] {
            let node = &mut clusters.nodes[c];
            (node.first_triangle, node.triangle_count, node.first_child, node.child_count) = (first, count, NONE, 0);
        }
        let manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3])]);
        let h = Hierarchy::new(&mesh, &manifest, Some(clusters), None);
        FloorAndWall { h, lamp: [dvec3(0.0, 0.0, height), dvec3(0.0, 1.0, height), dvec3(1.0, 1.0, height)] }
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
        let point = |u: f64, v: f64| corners[0] + (corners[1] - corners[0]) * (u / m as f64) + (corners[2] - corners[0]) * (v / m as f64);
        let factor = |p: DVec3| point_to_one_sided_polygon(p, normal, &self.lamp, -DVec3::Z);
        let mut sum = 0.0;
        for i in 0..m {
            for j in 0..m - i {
                sum += factor(point(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0));
                if i + j + 1 < m {
                    sum += factor(point(i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0));
                }
            }
        }
        sum / (m * m) as f64
    }
}

/// The rays and the occluders' box tree over `h`'s triangles, for a
/// [`crate::visibility::Tracer`].
pub fn traced(h: &Hierarchy) -> (SceneRays, Occluders) {
    let corners: Vec<_> = h.triangles.iter().map(|t| t.corners).collect();
    let scene = SceneRays::new(&corners);
    let occluders = Occluders::new(&corners, &scene);
    (scene, occluders)
}

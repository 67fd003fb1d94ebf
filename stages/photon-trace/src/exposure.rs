//! Which parts of each leaf are open to the scene, and which lie buried
//! inside a solid (a floor under a block standing on it), where no photon
//! lands and no direct light arrives.
//!
//! A photon-mesh leaf that straddles a block's footprint gets photons over
//! its open part only, yet a vertex's estimate divides the power its hat
//! received by the hat's whole area, and a display leaf showed the mean
//! over its whole area: both spread the light of the open part over the
//! buried one. On the built-in Cornell box, whose floor is one quad under
//! both blocks, the floor's mean over its open part came out 18% under
//! hierarchical-solve's, which leaves the buried part out.
//!
//! So each leaf tests [`POINTS`] fixed points for burial
//! ([`radiometry::burial::ProvenRoofs::buried`]: a roof that one point
//! proves a solid's buries the leaf's other points under it for one ray
//! each): the centroids of its sixteen
//! sub-triangles two 1:4 levels down, which weigh each corner's hat
//! function equally (their barycentric coordinates average `1/3`). A
//! vertex's hat area is then the integral of its hat over the open points
//! only ([`crate::mesh::Vertices`]), and a leaf's radiosity and area in
//! `solution.exr` are its open part's, as hierarchical-solve writes them
//! (`Element::area`), so a viewer's area-weighted means leave the buried
//! part out. The mask is per leaf; the display mesh splits along a
//! footprint anyway (the direct light jumps to nothing there), so the
//! leaves that straddle one are small.

use crate::mesh::Elements;
use glam::DVec3;
use radiometry::burial::ProvenRoofs;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;
use radiometry::subdivision::{children, to_triangle_uv, ROOT};
use rayon::prelude::*;

/// Burial points per leaf.
pub const POINTS: usize = 16;

/// Every point of a leaf open.
pub const ALL_OPEN: u16 = u16::MAX;

/// The burial points' barycentric coordinates in their leaf: the
/// centroids of its sub-triangles two 1:4 levels down.
pub fn points() -> [[f64; 3]; POINTS] {
    let centroids: Vec<[f64; 3]> = children(&ROOT)
        .iter()
        .flat_map(children)
        .map(|c| {
            let (u, v) = ((c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0);
            [1.0 - u - v, u, v]
        })
        .collect();
    std::array::from_fn(|k| centroids[k])
}

/// The barycentric coordinates of the open [`points`] of a leaf with
/// open mask `mask`.
pub fn open_points(mask: u16) -> impl Iterator<Item = [f64; 3]> {
    points().into_iter().enumerate().filter(move |(k, _)| mask & (1 << k) != 0).map(|(_, l)| l)
}

/// The open fraction of a leaf with open mask `mask`.
pub fn fraction(mask: u16) -> f64 {
    f64::from(mask.count_ones()) / POINTS as f64
}

/// Per element, a mask of its open [`points`] (bit `k` for point `k`),
/// measured for leaves; elements carry their mask from the mesh they were
/// measured on, so a refined mesh measures only its new leaves.
#[derive(Clone, Debug, Default)]
pub struct Exposure {
    /// Open mask per element (inner elements: whatever they had as a leaf).
    pub open: Vec<u16>,
}

impl Exposure {
    /// Measures the leaves of `elements` created since the last call;
    /// returns the rays cast. Rays start `t_min` along (past the rounding
    /// of their f32 origins); each leaf draws the turn of its grazing rays
    /// from its own stream of `seed`.
    pub fn extend(&mut self, geometry: &[TriangleGeometry], rays: &SceneRays, elements: &Elements, t_min: f32, seed: u64) -> u64 {
        let first = self.open.len();
        let normal_of = |t: u32| geometry[t as usize].normal;
        let points = points();
        let measured: Vec<(u16, u64)> = (first..elements.elements.len())
            .into_par_iter()
            .map(|e| {
                let element = &elements.elements[e];
                if !element.is_leaf() {
                    return (ALL_OPEN, 0);
                }
                let t = element.triangle as usize;
                let g = &geometry[t];
                let mut stream = Stream::new(seed, 0xb0_71ed, e as u64);
                let (mut mask, mut cast, mut roofs) = (0u16, 0u64, ProvenRoofs::default());
                for (k, local) in points.iter().enumerate() {
                    let point: DVec3 = g.point(to_triangle_uv(&elements.corners[e], *local));
                    let (is_buried, n) = roofs.buried(rays, &normal_of, point, g.normal, t as u32, t_min, &mut stream);
                    cast += n;
                    if !is_buried {
                        mask |= 1 << k;
                    }
                }
                (mask, cast)
            })
            .collect();
        self.open.extend(measured.iter().map(|m| m.0));
        measured.iter().map(|m| m.1).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_points_weigh_every_corner_alike_and_lie_inside() {
        let p = points();
        for k in 0..3 {
            let mean: f64 = p.iter().map(|l| l[k]).sum::<f64>() / POINTS as f64;
            assert!((mean - 1.0 / 3.0).abs() < 1e-15, "corner {k}: {mean}");
        }
        assert!(p.iter().all(|l| l.iter().all(|&x| x > 0.0 && x < 1.0)));
        assert_eq!(fraction(ALL_OPEN), 1.0);
        assert_eq!(fraction(0b1111), 0.25);
    }
}

//! Samples inside a solid: the floor under a block standing on it.
//!
//! A surface's samples are placed over all of it, and where a block stands
//! on a floor some lie under the block, where no light arrives and none
//! leaves (their direct light is 0, and so is what they receive). Taken as
//! vertices like the others, they made the floor's isolux polygon along a
//! block's base a region of the dark band mostly under the block, whose
//! mean (a tenth of the open floor's) it sent from all of it, the strip in
//! front of the block included, which is what the block's face sees
//! nearest: on the built-in Cornell box the tall block's samples 3 mm
//! above the floor were 21% under the path-traced reference, the face's
//! lower half 3-5%. And the display filter averaged them into the open
//! floor beside the blocks (the dark smudges at their feet).
//!
//! So each sample is tested as hierarchical-solve and photon-trace test
//! their points ([`radiometry::burial::ProvenRoofs`], one surface's roofs
//! proven a solid's shared by its samples); the polygons leave out the
//! triangles whose corners are all buried
//! ([`crate::emitters::isolux_polygons`]), a triangle that straddles a
//! footprint takes its buried corners' values from its open ones
//! ([`crate::shooting`]), and the display leaves buried samples out.

use crate::shooting::Collector;
use glam::DVec3;
use radiometry::burial::ProvenRoofs;
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;

/// Marks the buried ones of `samples` (their `buried`) and returns the
/// rays cast: rays start `t_min` along, `normals[t]` is mesh triangle
/// `t`'s unit front normal, and each surface draws its grazing rays'
/// turns from its own stream of `seed` and `pass` (so the result does not
/// depend on the thread count).
pub fn mark(samples: &mut [Collector], rays: &SceneRays, normals: &[DVec3], t_min: f32, seed: u64, pass: u64) -> u64 {
    use rayon::prelude::*;
    let normal_of = |t: u32| normals[t as usize];
    let surfaces = samples.iter().map(|x| x.surface as usize + 1).max().unwrap_or(0);
    let mut of_surface: Vec<Vec<usize>> = vec![Vec::new(); surfaces];
    for (i, x) in samples.iter().enumerate() {
        of_surface[x.surface as usize].push(i);
    }
    let tested: Vec<(Vec<bool>, u64)> = of_surface
        .par_iter()
        .enumerate()
        .map(|(s, members)| {
            let mut stream = Stream::new(seed, 0x5a_b1ed + pass, s as u64);
            let (mut roofs, mut cast) = (ProvenRoofs::default(), 0);
            let buried = members
                .iter()
                .map(|&i| {
                    let x = &samples[i];
                    let (is_buried, n) = roofs.buried(rays, &normal_of, x.position, x.normal, x.triangle, t_min, &mut stream);
                    cast += n;
                    is_buried
                })
                .collect();
            (buried, cast)
        })
        .collect();
    for (members, (buried, _)) in of_surface.iter().zip(&tested) {
        for (&i, &b) in members.iter().zip(buried) {
            samples[i].buried = b;
        }
    }
    tested.iter().map(|t| t.1).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    /// A unit cube standing on a floor (surface 0) and a wall (surface 1)
    /// beside it: the floor's samples under the cube are buried, those
    /// beside it and the wall's are not, and the floor's second point
    /// under the cube's roof costs one ray (the roof proven by the first).
    #[test]
    fn samples_under_a_block_are_buried_and_the_rest_are_not() {
        let corner = |i: usize| dvec3((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        // Faces counter-clockwise seen from outside the cube.
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut triangles: Vec<[DVec3; 3]> = quads.iter().flat_map(|q| [[corner(q[0]), corner(q[1]), corner(q[2])], [corner(q[0]), corner(q[2]), corner(q[3])]]).collect();
        let floor = triangles.len() as u32;
        triangles.push([dvec3(-5.0, -5.0, 0.0), dvec3(5.0, -5.0, 0.0), dvec3(5.0, 5.0, 0.0)]);
        triangles.push([dvec3(-5.0, -5.0, 0.0), dvec3(5.0, 5.0, 0.0), dvec3(-5.0, 5.0, 0.0)]);
        let wall = triangles.len() as u32;
        triangles.push([dvec3(3.0, 5.0, 0.0), dvec3(3.0, -5.0, 0.0), dvec3(3.0, 5.0, 5.0)]);
        let normals: Vec<DVec3> = triangles.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize()).collect();
        assert!(normals[0].z < -0.99 && normals[wall as usize].x < -0.99, "outward cube, wall facing the cube");
        let rays = SceneRays::new(&triangles);
        let sample = |position: DVec3, normal: DVec3, surface: u32, triangle: u32| Collector { position, normal, surface, triangle, reflectance: [0.5; 3], direct: [0.0; 3], indirect: [0.0; 3], buried: false };
        let mut samples = [
            sample(dvec3(0.3, 0.2, 0.0), DVec3::Z, 0, floor),
            sample(dvec3(0.7, 0.1, 0.0), DVec3::Z, 0, floor),
            sample(dvec3(1.2, 0.5, 0.0), DVec3::Z, 0, floor),
            sample(dvec3(-2.0, 2.0, 0.0), DVec3::Z, 0, floor),
            sample(dvec3(3.0, 0.5, 0.5), -DVec3::X, 1, wall),
        ];
        let cast = mark(&mut samples, &rays, &normals, 1e-6, 1, 0);
        assert_eq!(samples.map(|x| x.buried), [true, true, false, false, false]);
        // 17 rays for the first point under the roof, 1 for the second, 1
        // for each open point whose ray along the normal meets nothing.
        assert_eq!(cast, radiometry::burial::EXPOSURE_RAYS as u64 + 4);
    }
}

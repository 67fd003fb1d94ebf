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
//! The probes in an umbra are tested the same way ([`mark_probes`]): the
//! display shows the direct light from the probes and leaves buried ones
//! out ([`crate::probes::ProbeGrid::irradiance_at`]), or the floor beside
//! a block would be darkened by the block's footprint for a probe cell.

use crate::probes::ProbeGrid;
use crate::shooting::Collector;
use crate::surfaces::Surface;
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
            let points = members.iter().map(|&i| (samples[i].position, samples[i].normal, samples[i].triangle));
            buried_on_surface(points, rays, &normal_of, t_min, Stream::new(seed, 0x5a_b1ed + pass, s as u64))
        })
        .collect();
    for (members, (buried, _)) in of_surface.iter().zip(&tested) {
        for (&i, &b) in members.iter().zip(buried) {
            samples[i].buried = b;
        }
    }
    tested.iter().map(|t| t.1).sum()
}

/// Marks the buried ones of `grid`'s probes in an umbra (a lit probe sees
/// a light source, so it is in the open) and returns the rays cast; the
/// grid is surface number `s`, `surface`, and draws from its own stream
/// (as [`mark`], pass `pass`).
#[allow(clippy::too_many_arguments)]
pub fn mark_probes(grid: &mut ProbeGrid, s: usize, surface: &Surface, rays: &SceneRays, normals: &[DVec3], t_min: f32, seed: u64, pass: u64) -> u64 {
    let dark: Vec<(usize, u32)> = grid.probes.iter().enumerate().filter_map(|(k, p)| p.triangle.filter(|_| p.visibility <= 1e-9).map(|t| (k, t))).collect();
    let points = dark.iter().map(|&(k, t)| (surface.point(grid.uv(k % grid.nu, k / grid.nu)), surface.normal, t));
    let (buried, cast) = buried_on_surface(points, rays, &|t: u32| normals[t as usize], t_min, Stream::new(seed, 0x5a_b1ed + pass, s as u64));
    for ((k, _), b) in dark.into_iter().zip(buried) {
        grid.probes[k].buried = b;
    }
    cast
}

/// Which of one surface's `points` (position, unit normal, mesh triangle)
/// are buried, in order, one [`ProvenRoofs`] shared by them, and the rays
/// cast.
fn buried_on_surface(points: impl Iterator<Item = (DVec3, DVec3, u32)>, rays: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, t_min: f32, mut stream: Stream) -> (Vec<bool>, u64) {
    let (mut roofs, mut cast) = (ProvenRoofs::default(), 0);
    let buried = points
        .map(|(position, normal, triangle)| {
            let (is_buried, n) = roofs.buried(rays, normal_of, position, normal, triangle, t_min, &mut stream);
            cast += n;
            is_buried
        })
        .collect();
    (buried, cast)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    /// A unit cube standing on a floor (surface 0) and a wall (surface 1)
    /// beside it: the floor's samples under the cube are buried, those
    /// beside it and the wall's are not, and the floor's second point
    /// under the cube's roof costs one ray (the roof proven by the first).
    /// A unit cube standing on the 10 x 10 m floor z = 0 (mesh triangles
    /// 12 and 13), and a wall (14) at x = 3 facing it: the triangles and
    /// their front normals.
    fn cube_on_floor() -> (Vec<[DVec3; 3]>, Vec<DVec3>) {
        let corner = |i: usize| dvec3((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        // Faces counter-clockwise seen from outside the cube.
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut triangles: Vec<[DVec3; 3]> = quads.iter().flat_map(|q| [[corner(q[0]), corner(q[1]), corner(q[2])], [corner(q[0]), corner(q[2]), corner(q[3])]]).collect();
        triangles.push([dvec3(-5.0, -5.0, 0.0), dvec3(5.0, -5.0, 0.0), dvec3(5.0, 5.0, 0.0)]);
        triangles.push([dvec3(-5.0, -5.0, 0.0), dvec3(5.0, 5.0, 0.0), dvec3(-5.0, 5.0, 0.0)]);
        triangles.push([dvec3(3.0, 5.0, 0.0), dvec3(3.0, -5.0, 0.0), dvec3(3.0, 5.0, 5.0)]);
        let normals: Vec<DVec3> = triangles.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize()).collect();
        assert!(normals[0].z < -0.99 && normals[14].x < -0.99, "outward cube, wall facing the cube");
        (triangles, normals)
    }

    #[test]
    fn samples_under_a_block_are_buried_and_the_rest_are_not() {
        let (triangles, normals) = cube_on_floor();
        let (floor, wall) = (12, 14);
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

    /// The floor's probes in an umbra round the cube (visibility 0 over
    /// [-0.5, 1.5]², 5 x 5 nodes at 27 cells along the floor): the 3 x 3
    /// under the cube are buried, the umbra's others not, and no lit probe
    /// is tested.
    #[test]
    fn probes_under_a_block_are_buried_and_lit_ones_are_not_tested() {
        let (triangles, normals) = cube_on_floor();
        let rays = SceneRays::new(&triangles);
        let mut floor = crate::surfaces::rectangle(10.0, 10.0);
        (floor.origin, floor.triangles) = (dvec3(-5.0, -5.0, 0.0), vec![12, 13]);
        let shade = |p: DVec3| (-0.5..=1.5).contains(&p.x) && (-0.5..=1.5).contains(&p.y);
        let mut grid = ProbeGrid::of(&floor, 27, |p, _, _| ([1.0; 3], if shade(p) { 0.0 } else { 1.0 }, 0));
        let cast = mark_probes(&mut grid, 0, &floor, &rays, &normals, 1e-6, 1, 2);
        let points: Vec<DVec3> = (0..grid.probes.len()).map(|k| floor.point(grid.uv(k % grid.nu, k / grid.nu))).collect();
        assert_eq!(points.iter().filter(|p| shade(**p)).count(), 25);
        for (p, probe) in points.iter().zip(&grid.probes) {
            let under = (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y);
            assert_eq!(probe.buried, under, "{p}");
        }
        // The first buried probe under each of the cube's two bottom
        // triangles proves that roof (EXPOSURE_RAYS), the other 7 cost 1
        // ray each, and so does each open one in the umbra.
        assert_eq!(cast, 2 * radiometry::burial::EXPOSURE_RAYS as u64 + 7 + 16);
    }
}

//! Burial: whether a point on a surface lies inside a closed solid (a
//! floor under a block standing on it), where no light reaches it and none
//! leaves it.
//!
//! A point is buried when every one of [`EXPOSURE_RAYS`] rays from it into
//! its front hemisphere (along its normal, and [`GRAZING_RAYS`] nearly
//! along its surface) meets the back face of a surface first: inside a
//! closed solid every ray does, and a ray that leaves the scene or meets a
//! front face shows the point open to the room. A two-sided surface has no
//! back face for rays (they see its twin's front, [`crate::rays`]), so
//! nothing is buried under a sheet, only inside solids. A solid may close
//! against another surface: a block flush against a wall has its face
//! where the wall's front is, and a grazing ray meets both at one distance
//! ([`COINCIDENT`]); the back face decides.
//!
//! A one-sided sheet lying low over a surface, its back towards it (a
//! lamp hung 1 cm under a ceiling), buries the points under its middle
//! too: light reaches them only within 6 degrees of their plane. But the
//! points under it near its edge are open, so a roof vouches for the other
//! points under it only where the grazing rays met walls across its plane,
//! a solid's ([`Walls`]).

use crate::rays::SceneRays;
use crate::sampling::Stream;
use glam::DVec3;
use std::f64::consts::PI;

/// Rays per point: one along the normal, then [`GRAZING_RAYS`]; a point is
/// buried when all of them meet a back face.
pub const EXPOSURE_RAYS: usize = 1 + GRAZING_RAYS;

/// Rays per point that leave it nearly along its surface (at
/// [`GRAZING_COS`] to its normal, evenly spread in azimuth under one
/// random turn): only a solid that closes down onto the surface around
/// the point, as a block on a floor does, stops them all with its back
/// faces. With 6 rays drawn by the cosine (mostly steep), 703 of the 9,000
/// one-sided leaves of `plants-10k` were found partly buried under the
/// backs of the leaves above them (false: light reaches them from the
/// sides); with 8 grazing rays 51, with 16 six (exposure 0.94 to 0.99),
/// for half the rays (the ray along the normal settles most open points
/// at once).
pub const GRAZING_RAYS: usize = 16;

/// Relative distance within which a grazing ray's front face and a back
/// face behind it count as one place ([`buried`]): past the f32 rounding
/// of two coplanar triangles' hits.
pub const COINCIDENT: f32 = 1e-5;

/// Cosine to the normal of the grazing rays (about 6 degrees above the
/// surface).
pub const GRAZING_COS: f64 = 0.1;

/// The triangle whose back face the ray from `point` along its unit
/// front `normal` meets first, if it does (rays start at `t_min`, and skip
/// `triangle`, the point's own): the first test of [`buried`], which
/// finds a point open to the room wherever this is `None`. Where a solid
/// stands on a surface it is the solid's roof over the point, the same
/// for the points of one element under one solid: a caller that has
/// proven some of them buried by [`buried`] may take the others under the
/// same roof for buried too, for one ray each.
pub fn roof(scene: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, point: DVec3, normal: DVec3, triangle: u32, t_min: f32) -> Option<u32> {
    scene.closest_hit(point, normal, t_min, f32::INFINITY, [triangle, u32::MAX]).map(|hit| hit.triangle).filter(|&t| normal_of(t).dot(normal) > 0.0)
}

/// Whether `point` on mesh triangle `triangle` (unit front normal
/// `normal`) is buried, and the rays cast; `normal_of(t)` is triangle
/// `t`'s unit front normal; rays start at `t_min` (past the rounding of
/// their f32 origin). It is under a [`roof`] and [`walled_in`]
/// ([`ProvenRoofs::buried`] with none proven: `stream`'s number is drawn
/// only where a roof is found).
pub fn buried(scene: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, point: DVec3, normal: DVec3, triangle: u32, t_min: f32, stream: &mut Stream) -> (bool, u64) {
    ProvenRoofs::default().buried(scene, normal_of, point, normal, triangle, t_min, stream)
}

/// The roofs ([`roof`]) that [`walled_in`] found a solid's over some
/// point of one element: the element's other points under one of them
/// are buried too, for one ray each. A roof alone proves nothing (under a
/// sheet facing up a ray meets its back too), but under a solid the
/// points of one element share a few roofs, and each buried point cast
/// all [`EXPOSURE_RAYS`] without them (on the built-in Cornell box at
/// `EPS` 1e-3 hierarchical-solve's exposure was a sixth of its solve,
/// 283k rays, most of them along the blocks' bases and under them).
///
/// A point buried under a sheet ([`Walls::Sheet`]: a lamp hung 1 cm under
/// a ceiling) proves nothing for the points beside it, which may see out
/// under the sheet's edge.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ProvenRoofs(pub Vec<u32>);

impl ProvenRoofs {
    /// [`buried`], with the roofs proven so far: the ray along the normal
    /// first, which settles an open point or one under a proven roof; the
    /// rest cast the grazing rays ([`walled_in`], which draws the one
    /// number of `stream` a point takes), and a roof over a point they find
    /// inside a solid ([`Walls::Solid`]) joins the proven ones.
    #[allow(clippy::too_many_arguments)]
    pub fn buried(&mut self, scene: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, point: DVec3, normal: DVec3, triangle: u32, t_min: f32, stream: &mut Stream) -> (bool, u64) {
        match roof(scene, normal_of, point, normal, triangle, t_min) {
            None => (false, 1),
            Some(over) if self.0.contains(&over) => (true, 1),
            Some(over) => {
                let (walls, cast) = walled_in(scene, normal_of, point, normal, triangle, over, t_min, stream);
                if walls == Walls::Solid {
                    self.0.push(over);
                }
                (walls.buried(), 1 + cast)
            }
        }
    }
}

/// What the grazing rays of a point under a roof found ([`walled_in`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Walls {
    /// A ray left the scene or met a front face first: the point is open.
    Open,
    /// Every ray met a back face first, and some of them one parallel to
    /// the roof: a sheet lies low over the surface (a lamp hung just under
    /// a ceiling), the point is buried, but the sheet's edge, open to the
    /// room, may lie near another point under the same roof.
    Sheet,
    /// Every ray met the back face of a wall across the roof's plane
    /// first: a solid closes down onto the surface round the point (a
    /// block on a floor), and every other point under the same roof lies
    /// inside it too.
    Solid,
}

impl Walls {
    /// Whether the point is buried.
    pub fn buried(self) -> bool {
        self != Walls::Open
    }
}

/// The rest of [`buried`] for a point whose [`roof`] `over` is known:
/// what its [`GRAZING_RAYS`] meet first, under one random turn drawn from
/// `stream`, and the rays cast. A caller that has cast the ray along the
/// normal itself need not cast it again.
#[allow(clippy::too_many_arguments)]
pub fn walled_in(scene: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, point: DVec3, normal: DVec3, triangle: u32, over: u32, t_min: f32, stream: &mut Stream) -> (Walls, u64) {
    let turn = 2.0 * PI * stream.next_f64();
    grazing(scene, normal_of, point, normal, triangle, over, t_min, turn)
}

/// Cosine above which a back face a grazing ray meets counts as parallel
/// to the roof ([`Walls::Sheet`]).
const PARALLEL: f64 = 1.0 - 1e-6;

/// [`walled_in`] with its turn in azimuth, radians.
#[allow(clippy::too_many_arguments)]
fn grazing(scene: &SceneRays, normal_of: &dyn Fn(u32) -> DVec3, point: DVec3, normal: DVec3, triangle: u32, over: u32, t_min: f32, turn: f64) -> (Walls, u64) {
    let helper = if normal.x.abs() > 0.5 { DVec3::Y } else { DVec3::X };
    let u = normal.cross(helper).normalize();
    let v = normal.cross(u);
    let sin_grazing = (1.0 - GRAZING_COS * GRAZING_COS).sqrt();
    let roof_normal = normal_of(over);
    // Second queries of the coincidence rule, counted as rays.
    let (mut extra, mut sheet) = (0, false);
    for k in 1..EXPOSURE_RAYS {
        let phi = turn + 2.0 * PI * k as f64 / GRAZING_RAYS as f64;
        let direction = normal * GRAZING_COS + u * (sin_grazing * phi.cos()) + v * (sin_grazing * phi.sin());
        let back = |t: u32| normal_of(t).dot(direction) > 0.0;
        let back_face = match scene.closest_hit(point, direction, t_min, f32::INFINITY, [triangle, u32::MAX]) {
            None => None,
            Some(hit) if back(hit.triangle) => Some(hit.triangle),
            // A front face with a back face in the same place (a block
            // pushed flush against a wall: the wall's front and the block's
            // face coincide) closes the solid: a grazing ray from the floor
            // under the block meets the two at one distance, whichever the
            // traversal returns first.
            Some(hit) => {
                extra += 1;
                scene.closest_hit(point, direction, t_min, hit.t * (1.0 + COINCIDENT) + t_min, [triangle, hit.triangle]).map(|other| other.triangle).filter(|&t| back(t))
            }
        };
        let Some(face) = back_face else { return (Walls::Open, k as u64 + extra) };
        sheet |= normal_of(face).dot(roof_normal) > PARALLEL;
    }
    (if sheet { Walls::Sheet } else { Walls::Solid }, GRAZING_RAYS as u64 + extra)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    /// A unit cube (outward faces) standing on a floor: floor points under
    /// it are buried, those beside it and in the open are not, and neither
    /// is a point under a sheet facing down (no solid).
    #[test]
    fn points_inside_a_solid_are_buried_and_points_beside_it_or_under_a_sheet_are_not() {
        let (a, b, c, d) = (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(1.0, 1.0, 0.0), dvec3(0.0, 1.0, 0.0));
        let up = |p: DVec3| p + DVec3::Z;
        // Quads counter-clockwise seen from outside the cube.
        let quads = [[a, d, c, b], [up(a), up(b), up(c), up(d)], [a, b, up(b), up(a)], [b, c, up(c), up(b)], [c, d, up(d), up(c)], [d, a, up(a), up(d)]];
        let mut triangles: Vec<[DVec3; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        let floor = triangles.len() as u32;
        let big = 5.0;
        triangles.push([dvec3(-big, -big, 0.0), dvec3(big, -big, 0.0), dvec3(big, big, 0.0)]);
        triangles.push([dvec3(-big, -big, 0.0), dvec3(big, big, 0.0), dvec3(-big, big, 0.0)]);
        let normals: Vec<DVec3> = triangles.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize()).collect();
        let scene = SceneRays::new(&triangles);
        let normal_of = |t: u32| normals[t as usize];
        let mut stream = Stream::new(1, 2, 3);
        let mut test = |p: DVec3| buried(&scene, &normal_of, p, DVec3::Z, floor, 1e-6, &mut stream).0;
        assert!(test(dvec3(0.5, 0.5, 0.0)), "under the cube");
        assert!(test(dvec3(0.02, 0.97, 0.0)), "under the cube, near its corner");
        assert!(!test(dvec3(1.03, 0.5, 0.0)), "beside the cube");
        assert!(!test(dvec3(-2.0, 2.0, 0.0)), "in the open");
        let sheet = SceneRays::new(&[[dvec3(0.0, 0.0, 1.0), dvec3(1.0, 1.0, 1.0), dvec3(1.0, 0.0, 1.0)], [dvec3(-big, -big, 0.0), dvec3(big, -big, 0.0), dvec3(big, big, 0.0)]]);
        let sheet_normals = [dvec3(0.0, 0.0, -1.0), DVec3::Z];
        let under = buried(&sheet, &|t| sheet_normals[t as usize], dvec3(0.7, 0.3, 0.0), DVec3::Z, 1, 1e-6, &mut Stream::new(1, 2, 3));
        assert!(!under.0, "a sheet facing down is a front face seen from below");
        // The cube pushed flush against a wall x = 0 facing +x: the wall's
        // front and the cube's face x = 0 coincide, and every floor point
        // under the cube stays buried, whichever of the two the grazing
        // rays towards the wall meet first (without the coincidence rule a
        // cube on an emitting floor against the wall of gpu-shoot's test
        // box left its floor unburied, and the room lost 6.4% of the power).
        let mut walled = triangles.clone();
        let wall = [dvec3(0.0, -big, 0.0), dvec3(0.0, big, 0.0), dvec3(0.0, big, big), dvec3(0.0, -big, big)];
        walled.push([wall[0], wall[1], wall[2]]);
        walled.push([wall[0], wall[2], wall[3]]);
        let walled_normals: Vec<DVec3> = walled.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize()).collect();
        assert!(walled_normals[walled.len() - 1].x > 0.99, "the wall faces +x");
        let walled_scene = SceneRays::new(&walled);
        let mut stream = Stream::new(4, 5, 6);
        for x in [0.5, 0.05, 0.01] {
            for y in [0.5, 0.03] {
                let (is_buried, _) = buried(&walled_scene, &|t| walled_normals[t as usize], dvec3(x, y, 0.0), DVec3::Z, floor, 1e-6, &mut stream);
                assert!(is_buried, "under the cube against the wall at ({x}, {y})");
            }
        }
        assert!(!buried(&walled_scene, &|t| walled_normals[t as usize], dvec3(0.05, 1.05, 0.0), DVec3::Z, floor, 1e-6, &mut stream).0, "beside it, by the wall");
        // The roof over a floor point: the cube's top (triangles 2 and 3,
        // seen from inside) under it, none beside it or in the open, and a
        // sheet facing up over a point (its back seen from below) is a roof
        // though nothing buries the point: a roof alone proves nothing.
        let roof_at = |p: DVec3| roof(&scene, &normal_of, p, DVec3::Z, floor, 1e-6);
        assert!(matches!(roof_at(dvec3(0.5, 0.2, 0.0)), Some(2 | 3)), "{:?}", roof_at(dvec3(0.5, 0.2, 0.0)));
        assert_eq!(roof_at(dvec3(1.03, 0.5, 0.0)), None, "beside the cube");
        assert_eq!(roof_at(dvec3(-2.0, 2.0, 0.0)), None, "in the open");
        let up_normals = [DVec3::Z, DVec3::Z];
        let up_sheet = SceneRays::new(&[[dvec3(0.0, 0.0, 1.0), dvec3(1.0, 0.0, 1.0), dvec3(1.0, 1.0, 1.0)], [dvec3(-big, -big, 0.0), dvec3(big, -big, 0.0), dvec3(big, big, 0.0)]]);
        let point = dvec3(0.7, 0.3, 0.0);
        assert_eq!(roof(&up_sheet, &|t| up_normals[t as usize], point, DVec3::Z, 1, 1e-6), Some(0));
        assert!(!buried(&up_sheet, &|t| up_normals[t as usize], point, DVec3::Z, 1, 1e-6, &mut Stream::new(1, 2, 3)).0, "under a sheet facing up");
        // The grazing rays from under the cube meet its walls: a solid,
        // whose roof holds every point under it.
        let (walls, _) = walled_in(&scene, &normal_of, dvec3(0.5, 0.5, 0.0), DVec3::Z, floor, 2, 1e-6, &mut Stream::new(7, 8, 9));
        assert_eq!(walls, Walls::Solid);
        // So the first point under the cube's top triangle 2 casts every
        // ray and proves that roof; the next under it casts one ray and is
        // buried, one under the other triangle proves that one, and the
        // points beside the cube and in the open stay open, as `buried`
        // has them.
        let mut proven = ProvenRoofs::default();
        let mut bury = |p: DVec3| proven.buried(&scene, &normal_of, p, DVec3::Z, floor, 1e-6, &mut stream);
        assert_eq!(bury(dvec3(0.5, 0.2, 0.0)), (true, EXPOSURE_RAYS as u64));
        assert_eq!(bury(dvec3(0.8, 0.3, 0.0)), (true, 1));
        assert_eq!(bury(dvec3(0.2, 0.8, 0.0)), (true, EXPOSURE_RAYS as u64));
        assert_eq!(bury(dvec3(0.3, 0.9, 0.0)), (true, 1));
        assert!(!bury(dvec3(1.03, 0.5, 0.0)).0, "beside the cube");
        assert_eq!(bury(dvec3(-2.0, 2.0, 0.0)), (false, 1), "in the open");
        assert_eq!(proven.0.len(), 2, "{proven:?}");
    }

    /// A sheet facing up 1 cm over a floor, 2 m wide (a lamp hung just
    /// under a ceiling, upside down): a point under its middle is buried,
    /// every grazing ray meeting the sheet's back, but that proves nothing
    /// for the other points under it ([`Walls::Sheet`]): one 5 cm inside
    /// its edge, under the same triangle, sees out under the edge.
    #[test]
    fn a_sheet_low_over_a_point_buries_it_without_burying_all_it_covers() {
        let big = 5.0;
        let triangles = [
            [dvec3(-1.0, -1.0, 0.01), dvec3(1.0, -1.0, 0.01), dvec3(1.0, 1.0, 0.01)],
            [dvec3(-1.0, -1.0, 0.01), dvec3(1.0, 1.0, 0.01), dvec3(-1.0, 1.0, 0.01)],
            [dvec3(-big, -big, 0.0), dvec3(big, -big, 0.0), dvec3(big, big, 0.0)],
        ];
        let normals = [DVec3::Z, DVec3::Z, DVec3::Z];
        let scene = SceneRays::new(&triangles);
        let normal_of = |t: u32| normals[t as usize];
        let (middle, edge) = (dvec3(0.3, -0.4, 0.0), dvec3(0.95, -0.5, 0.0));
        assert_eq!(roof(&scene, &normal_of, middle, DVec3::Z, 2, 1e-6), Some(0));
        assert_eq!(roof(&scene, &normal_of, edge, DVec3::Z, 2, 1e-6), Some(0), "the same roof");
        let mut stream = Stream::new(1, 2, 3);
        assert_eq!(walled_in(&scene, &normal_of, middle, DVec3::Z, 2, 0, 1e-6, &mut stream).0, Walls::Sheet);
        assert_eq!(walled_in(&scene, &normal_of, edge, DVec3::Z, 2, 0, 1e-6, &mut stream).0, Walls::Open);
        assert!(buried(&scene, &normal_of, middle, DVec3::Z, 2, 1e-6, &mut stream).0);
    }
}

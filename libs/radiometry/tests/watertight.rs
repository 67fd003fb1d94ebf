//! Watertightness of the ray caster: rays aimed at the shared edges and
//! vertices of closed triangulated meshes, from inside, never slip through
//! (Woop, Benthin & Wald 2013; `radiometry::watertight`).

use glam::{dvec3, DVec3};
use radiometry::rays::SceneRays;

const NO_SKIP: [u32; 2] = [u32::MAX; 2];

/// The cube `centre + [-h, h]^3`, two triangles a face, wound outward.
fn cube(centre: DVec3, h: f64) -> Vec<[DVec3; 3]> {
    let c = |i: usize| centre + h * dvec3(if i & 1 == 0 { -1.0 } else { 1.0 }, if i & 2 == 0 { -1.0 } else { 1.0 }, if i & 4 == 0 { -1.0 } else { 1.0 });
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    faces.iter().flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]]).collect()
}

/// Points on the surface of the cube `centre + [-h, h]^3` where faces'
/// triangles meet: on every face, a `n x n` lattice along its edges and
/// both diagonals (the triangulating one among them), corners included.
fn seams(centre: DVec3, h: f64, n: usize) -> Vec<DVec3> {
    let mut points = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            for i in 0..=n {
                let s = -1.0 + 2.0 * i as f64 / n as f64;
                for (u, v) in [(s, s), (s, -s), (s, -1.0), (s, 1.0), (-1.0, s), (1.0, s)] {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    points.push(centre + h * DVec3::from_array(p));
                }
            }
        }
    }
    points
}

/// Origins inside the cube: its centre (rays axis-aligned to the face
/// centres and the diagonals), and off-centre points (oblique rays).
fn origins(centre: DVec3, h: f64) -> Vec<DVec3> {
    [dvec3(0.0, 0.0, 0.0), dvec3(0.3, -0.2, 0.1), dvec3(-0.7, 0.55, -0.31), dvec3(0.5, 0.5, 0.5), dvec3(0.0, 0.0, 0.9)]
        .map(|o| centre + h * o)
        .to_vec()
}

/// Rays from inside the cube aimed at its seams that find no hit.
fn escapes(centre: DVec3, h: f64) -> (usize, usize) {
    let rays = SceneRays::new(&cube(centre, h));
    let (mut cast, mut missed) = (0, 0);
    for o in origins(centre, h) {
        for p in seams(centre, h, 64) {
            cast += 1;
            if rays.closest_hit(o, (p - o).normalize(), 0.0, f32::INFINITY, NO_SKIP).is_none() {
                missed += 1;
            }
        }
    }
    (missed, cast)
}

#[test]
fn rays_from_inside_a_closed_cube_at_its_edges_and_vertices_all_hit_it() {
    for (centre, h) in [(DVec3::ZERO, 1.0), (DVec3::ZERO, 0.37), (dvec3(1e4, -1e4, 1e4), 1.0), (dvec3(3.3e3, 0.0, -7.1e2), 2.5)] {
        let (missed, cast) = escapes(centre, h);
        eprintln!("cube at {centre} half {h}: {missed} of {cast} rays escaped");
        assert_eq!(missed, 0, "cube at {centre} half {h}: {missed} of {cast} rays escaped");
    }
}

/// The square `centre + [-h, h]^2` in the plane z = centre.z, split into
/// 2 x 2 cells of two triangles each (the cells' diagonals alternate, so
/// the middle vertex is shared by six triangles, the edge midpoints by
/// three).
fn tiled_quad(centre: DVec3, h: f64) -> Vec<[DVec3; 3]> {
    let p = |i: usize, j: usize| centre + h * dvec3(i as f64 - 1.0, j as f64 - 1.0, 0.0);
    let mut tris = Vec::new();
    for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
        tris.extend(if (i + j) % 2 == 0 { [[a, b, c], [a, c, d]] } else { [[a, b, d], [b, c, d]] });
    }
    tris
}

#[test]
fn rays_through_the_seams_of_a_tiled_quad_all_hit_it() {
    for centre in [DVec3::ZERO, dvec3(1e4, 1e4, 1e4), dvec3(-2.5e3, 7e2, 1.0)] {
        let h = 1.0;
        let rays = SceneRays::new(&tiled_quad(centre, h));
        let eyes = [dvec3(0.0, 0.0, 2.0), dvec3(0.5, 0.5, 1.0), dvec3(-0.3, 0.8, 0.7), dvec3(1.7, -1.3, -0.9), dvec3(0.0, 0.0, -3.0)];
        let n = 96;
        let (mut cast, mut missed) = (0, 0);
        for eye in eyes.map(|e| centre + h * e) {
            // The inner seams (x = 0, y = 0, the four cells' diagonals) and
            // a lattice over the quad's inside, both its diagonals on it.
            for i in 1..n {
                let s = -1.0 + 2.0 * i as f64 / n as f64;
                for j in 1..n {
                    let r = -1.0 + 2.0 * j as f64 / n as f64;
                    let p = centre + h * dvec3(s, r, 0.0);
                    cast += 1;
                    if rays.closest_hit(eye, (p - eye).normalize(), 0.0, f32::INFINITY, NO_SKIP).is_none() {
                        missed += 1;
                    }
                }
            }
        }
        eprintln!("tiled quad at {centre}: {missed} of {cast} rays through it missed");
        assert_eq!(missed, 0, "tiled quad at {centre}: {missed} of {cast} rays through it missed");
    }
}

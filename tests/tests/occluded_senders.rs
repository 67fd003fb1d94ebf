//! hierarchical-solve where an occluder hides from a receiver the same part
//! of a sender that it shadows from the light: visibility and radiosity
//! are correlated over the sender, and a link that sends the sender's parts
//! weighted by their unoccluded kernel alone (times the link's one
//! visible fraction) errs with one sign (issue 10).
//!
//! The scene: a floor A (`z = 0`, 1 m square, reflectance 0.5) lit by a
//! small lamp at `z = 1` on its left; a black double-sided wall at `x =
//! 0.5`, 0.4 m high, throws a shadow over the floor to its right. The
//! receiver B, a strip facing down in the lamp's plane just right of it,
//! gets only what the floor reflects (coplanar with the lamp), and sees
//! the floor right of the wall over the wall's top: the part nearest the
//! wall, which B cannot see, lies in the wall's shadow from the lamp (the
//! lamp is farther left than B, so its shadow is longer).
//!
//! The reference is written here, apart from the solver: the floor's
//! radiosity `rho_A E integral over the lamp of K v` and B's `rho_B
//! integral over the floor of B_A K v`, with `K = cos cos / (pi r^2)` and
//! `v` the segment test against the wall rectangle, by the midpoint rule
//! (lamp 2 cm, floor 5 mm). B reflects 10%; its light back on the floor,
//! about 0.1% of the floor's, is left out.

use end_to_end::{scratch, Solved};
use test_support::closed_form::mean_over_triangle;
use test_support::scenes::{rectangle, QuadScene};

const RHO_A: f64 = 0.5;
const RHO_B: f64 = 0.1;
const EMISSION: f64 = 10.0;
/// The lamp: `x in [0.1, 0.3]`, `y in [0.3, 0.7]`, `z = 1`.
const LAMP: ([f64; 2], [f64; 2], f64) = ([0.1, 0.3], [0.3, 0.7], 1.0);
/// The wall: `x = 0.5`, `y in [0, 1]`, `z in [0, 0.4]`.
const WALL: (f64, f64) = (0.5, 0.4);
/// B: `x in [0.32, 0.48]`, `y in [0, 1]`, `z = 1`, beside the lamp in its
/// plane.
const B: ([f64; 2], f64) = ([0.32, 0.48], 1.0);

fn scene() -> QuadScene {
    let mut scene = QuadScene { camera: ([0.5, -1.5, 0.5], [0.5, 0.5, 0.3]), ..Default::default() };
    scene.material("floor", RHO_A, 0.0).material("receiver", RHO_B, 0.0).material("black", 0.0, 0.0).material("lamp", 0.0, EMISSION);
    scene.quad("A", "floor", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("L", "lamp", rectangle(2, LAMP.2, [LAMP.0[0], LAMP.1[0]], [LAMP.0[1], LAMP.1[1]]), [0.0, 0.0, -1.0]);
    for sign in [1.0, -1.0] {
        scene.quad("wall", "black", rectangle(0, WALL.0, [0.0, 0.0], [1.0, WALL.1]), [sign, 0.0, 0.0]);
    }
    scene.quad("B", "receiver", rectangle(2, B.1, [B.0[0], 0.0], [B.0[1], 1.0]), [0.0, 0.0, -1.0]);
    scene
}

/// Whether the segment `p -> q` crosses the wall rectangle.
fn blocked(p: [f64; 3], q: [f64; 3]) -> bool {
    let (a, b) = (p[0] - WALL.0, q[0] - WALL.0);
    if a * b >= 0.0 {
        return false;
    }
    let t = a / (a - b);
    let (y, z) = (p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2]));
    (0.0..=1.0).contains(&y) && (0.0..=WALL.1).contains(&z)
}

/// Midpoints of an `n x m` grid over `[x0, x1] x [y0, y1]` at height `z`,
/// with the cell area.
fn grid(x: [f64; 2], y: [f64; 2], z: f64, cell: f64) -> (Vec<[f64; 3]>, f64) {
    let (n, m) = (((x[1] - x[0]) / cell).round() as usize, ((y[1] - y[0]) / cell).round() as usize);
    let (dx, dy) = ((x[1] - x[0]) / n as f64, (y[1] - y[0]) / m as f64);
    let points = (0..n).flat_map(|i| (0..m).map(move |j| [x[0] + (i as f64 + 0.5) * dx, y[0] + (j as f64 + 0.5) * dy, z])).collect();
    (points, dx * dy)
}

/// `cos cos / (pi r^2)` between two points on horizontal planes facing
/// each other (distance `dz` apart in height).
fn kernel(p: [f64; 3], q: [f64; 3]) -> f64 {
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    d[2] * d[2] / (std::f64::consts::PI * r2 * r2)
}

/// B's radiosity at each of `points` (module docs).
fn reference(points: &[[f64; 3]]) -> Vec<f64> {
    let (lamp, lamp_cell) = grid(LAMP.0, LAMP.1, LAMP.2, 0.02);
    let (floor, floor_cell) = grid([0.0, 1.0], [0.0, 1.0], 0.0, 0.005);
    let radiosity: Vec<f64> = floor
        .iter()
        .map(|&y| RHO_A * EMISSION * lamp.iter().filter(|&&z| !blocked(y, z)).map(|&z| kernel(y, z)).sum::<f64>() * lamp_cell)
        .collect();
    points
        .iter()
        .map(|&x| RHO_B * floor.iter().zip(&radiosity).filter(|(&y, _)| !blocked(x, y)).map(|(&y, b)| b * kernel(x, y)).sum::<f64>() * floor_cell)
        .collect()
}

/// B's total over its leaves against the reference (relative), and the
/// worst leaf's relative error, solved with `args`.
fn errors(test: &str, args: &[&str]) -> (f64, f64) {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &scene().write(&dir), args);
    let leaves = solved.leaves_of("B");
    let points = std::cell::RefCell::new(Vec::new());
    for (_, corners) in &leaves {
        mean_over_triangle(corners, 1, &|x| {
            points.borrow_mut().push(x);
            0.0
        });
    }
    let points = points.into_inner();
    let exact: Vec<f64> = reference(&points).chunks(4).map(|r| r.iter().sum::<f64>() / 4.0).collect();
    let (mut got, mut want, mut worst) = (0.0, 0.0, 0.0f64);
    for ((e, _), x) in leaves.iter().zip(&exact) {
        let (a, b) = (f64::from(e.area), f64::from(e.radiosity[0]));
        got += a * b;
        want += a * x;
        worst = worst.max((b - x).abs() / x);
    }
    (got / want - 1.0, worst)
}

/// At the coarse thresholds where links join large senders, B's total is
/// within 1.2% (EPS 5e-3, now 2e-4: the same relative threshold since
/// hierarchical-solve's `RELATIVE_AT` went from 3 to 1/8 with the absolute
/// one as a cap; measured -0.19%) and 0.4% (3e-3, now 1.25e-4: -0.18%) of
/// the reference; sending the
/// parts weighted by their unoccluded kernel alone it was 1.73% and 0.69%
/// low (8.1% at 1e-2, now 5.7%: what is left there is inside leaf
/// senders). At the default threshold the total is within 0.1% and every
/// leaf within 1.5%: 3.4% measured (B's leaves near the wall's penumbra)
/// while a link into an inner element lit all its leaves alike, 0.78%
/// since it lights each part by its own factor and visibility
/// (hierarchical-solve's `receivers`; totals -0.80% and -0.16% at 5e-3 and
/// 3e-3); at the default 1.5e-5 now +0.01%, worst leaf 0.98%.
#[test]
fn a_receiver_behind_an_occluder_that_also_shadows_the_sender_gets_the_visible_parts_light() {
    for (eps, limit, leaf_limit) in [("2e-4", 0.012, f64::INFINITY), ("1.25e-4", 0.004, f64::INFINITY), ("1.5e-5", 0.001, 0.015)] {
        let (total, worst) = errors(&format!("occluded_senders_{eps}"), &["--eps", eps]);
        eprintln!("occluded senders, EPS {eps}: B's total {:+.3}% off the quadrature, worst leaf {:.2}%", 100.0 * total, 100.0 * worst);
        assert!(total.abs() <= limit, "EPS {eps}: B's total is {:+.3}% off the reference", 100.0 * total);
        assert!(worst <= leaf_limit, "EPS {eps}: a leaf of B is {:.2}% off the reference", 100.0 * worst);
    }
}

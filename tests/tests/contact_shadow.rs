//! hierarchical-solve where a surface sees another's contact shadow at
//! close range: a wall standing on a floor, lit only by the floor, whose
//! strip along the wall's base the wall itself shadows from the lamp
//! (issue 10: the built-in Cornell box's short block, whose camera face
//! the floor's contact shadow lights, was its worst surface; a floor leaf
//! that holds the dark strip and the lit floor beside it sent the face's
//! base its mean).
//!
//! The scene: a floor `x in [0, 0.5]`, `y in [0.07, 1.07]`, `z = 0`
//! (reflectance 0.5), and a wall on its far edge, `x = 0.5`, `z in [0,
//! 0.3]`, facing the floor (reflectance 0.1), under a square lamp facing
//! down at `z = 0.6` behind the wall's plane, `x, y in [0.52, 0.62]`: the
//! floor within 2 cm of the wall sees none of the lamp, and the wall sees
//! only the floor. Its reference, written here apart from the solver: the
//! floor's direct light by Lambert's closed form (test-support's own) for
//! the part of the lamp above the plane through the point and the wall's
//! top edge, on cells 2 cm along the wall and graded in depth from 10 µm;
//! the wall's light by Lambert's factor to each floor cell; the floor once
//! more with what the wall sends back (the strip the wall shadows is lit by
//! the wall alone, and the wall's base sees that strip most: without it the
//! base's leaves read 3% high), the next term being under 1e-4; a leaf's
//! value the mean over 16 of its points (64 move the base's mean by
//! 0.04%, cells 1 cm along the wall by 0.01%).

use end_to_end::{scratch, Solved};
use test_support::closed_form::{clip_to_front, lambert_polygon, mean_over_triangle};
use test_support::scenes::{rectangle, QuadScene};

const FLOOR_RHO: f64 = 0.5;
const WALL_RHO: f64 = 0.1;
const EMISSION: f64 = 10.0;
/// The wall's plane and height; the floor's span along it.
const WALL_X: f64 = 0.5;
const WALL_HEIGHT: f64 = 0.3;
const SPAN: [f64; 2] = [0.07, 1.07];
/// The lamp: `x, y in [0.52, 0.62]`, `z = 0.6`, facing down.
const LAMP: ([f64; 2], f64) = ([0.52, 0.62], 0.6);

fn scene() -> QuadScene {
    let mut scene = QuadScene { camera: ([0.1, -0.6, 0.5], [0.4, 0.57, 0.1]), ..Default::default() };
    scene.material("floor", FLOOR_RHO, 0.0).material("wall", WALL_RHO, 0.0).material("lamp", 0.0, EMISSION);
    scene.quad("floor", "floor", rectangle(2, 0.0, [0.0, SPAN[0]], [WALL_X, SPAN[1]]), [0.0, 0.0, 1.0]);
    scene.quad("wall", "wall", rectangle(0, WALL_X, [SPAN[0], 0.0], [SPAN[1], WALL_HEIGHT]), [-1.0, 0.0, 0.0]);
    scene.quad("lamp", "lamp", rectangle(2, LAMP.1, [LAMP.0[0], LAMP.0[0]], [LAMP.0[1], LAMP.0[1]]), [0.0, 0.0, -1.0]);
    scene
}

/// `rho E` times the factor from floor point `p` to the part of the lamp
/// it sees over the wall: the lamp clipped by the plane through `p` and
/// the wall's top edge (the wall spans every line from the floor to the
/// lamp along `y`), by Lambert's closed form.
fn direct(p: [f64; 3]) -> f64 {
    let lamp = rectangle(2, LAMP.1, [LAMP.0[0], LAMP.0[0]], [LAMP.0[1], LAMP.0[1]]);
    let above = [-WALL_HEIGHT, 0.0, WALL_X - p[0]];
    FLOOR_RHO * EMISSION * lambert_polygon(p, [0.0, 0.0, 1.0], &clip_to_front(&lamp, [WALL_X, 0.0, WALL_HEIGHT], above))
}

/// Cell edges from 0 to `to`, their widths growing geometrically from
/// 10 µm by a quarter each up to `step`, then `step` each.
fn graded(to: f64, step: f64) -> Vec<f64> {
    let mut edges = vec![0.0, 1e-5];
    while *edges.last().unwrap() < to {
        let (a, b) = (edges[edges.len() - 2], edges[edges.len() - 1]);
        edges.push((b + (1.25 * (b - a)).min(step)).min(to));
    }
    edges
}

/// A surface as cells `(corners, centre, radiosity)`.
type Cells = Vec<([[f64; 3]; 4], [f64; 3], f64)>;

/// The cells of a surface 2 cm wide along `y`, graded away from the wall's
/// base (module docs): `at(u, y)` the point `u` away from the base.
fn cells(depth: f64, at: &dyn Fn(f64, f64) -> [f64; 3]) -> Cells {
    let edges = graded(depth, 0.02);
    let mut cells = Vec::new();
    for pair in edges.windows(2) {
        for j in 0..50 {
            let (y0, y1) = (SPAN[0] + 0.02 * j as f64, SPAN[0] + 0.02 * (j + 1) as f64);
            let corners = [at(pair[0], y0), at(pair[1], y0), at(pair[1], y1), at(pair[0], y1)];
            cells.push((corners, at(0.5 * (pair[0] + pair[1]), 0.5 * (y0 + y1)), 0.0));
        }
    }
    cells
}

/// What `from` (cells with radiosity) sends the point `p` of normal `n`,
/// times `rho`: Lambert's factor to each cell.
fn gathered(p: [f64; 3], n: [f64; 3], rho: f64, from: &Cells) -> f64 {
    rho * from.iter().map(|(corners, _, b)| b * lambert_polygon(p, n, corners)).sum::<f64>()
}

/// The floor's cells with their radiosity: the lamp's light (20 x 20
/// midpoint cells of the lamp, the wall hiding some), plus what the wall
/// sends back of that light's first reflection (the next term is under
/// 1e-4 of the wall's leaves).
fn floor_cells() -> Cells {
    let mut floor = cells(WALL_X, &|u, y| [WALL_X - u, y, 0.0]);
    for cell in &mut floor {
        cell.2 = direct(cell.1);
    }
    let mut wall = cells(WALL_HEIGHT, &|u, y| [WALL_X, y, u]);
    for cell in &mut wall {
        cell.2 = gathered(cell.1, [-1.0, 0.0, 0.0], WALL_RHO, &floor);
    }
    let back: Vec<f64> = floor.iter().map(|cell| gathered(cell.1, [0.0, 0.0, 1.0], FLOOR_RHO, &wall)).collect();
    for (cell, b) in floor.iter_mut().zip(back) {
        cell.2 += b;
    }
    floor
}

/// The wall's leaves' relative errors against the reference, with each
/// leaf's height (its centroid's `z`), solved with `args`.
fn wall_errors(test: &str, args: &[&str]) -> Vec<(f64, f64)> {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &scene().write(&dir), args);
    let cells = floor_cells();
    solved
        .leaves_of("wall")
        .into_iter()
        .map(|(e, corners)| {
            let want = mean_over_triangle(&corners, 2, &|x| gathered(x, [-1.0, 0.0, 0.0], WALL_RHO, &cells));
            let height = (corners[0][2] + corners[1][2] + corners[2][2]) / 3.0;
            (height, f64::from(e.radiosity[0]) / want - 1.0)
        })
        .collect()
}

/// Every wall leaf within 2% at the default settings (the issue's
/// measure for the leaves of a surface lit only by reflection), and the
/// leaves within 2 cm of the base, which see the contact shadow closest,
/// within 1% on average. Measured (worst leaf; the base's mean): +6.65%,
/// +0.64% at `EPS` 1e-4; +5.06%, -0.07% at 5e-5; +1.74%, -0.57% at 2e-5;
/// +1.48% (at the wall's top), -0.54% at the default 1.5e-5.
#[test]
fn a_wall_sees_the_contact_shadow_at_its_base_within_two_percent_per_leaf() {
    let errors = wall_errors("contact_shadow", &[]);
    let (worst_height, worst) = errors.iter().copied().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())).expect("wall leaves");
    let base: Vec<f64> = errors.iter().filter(|e| e.0 < 0.02).map(|e| e.1).collect();
    let base_mean = base.iter().sum::<f64>() / base.len() as f64;
    eprintln!("contact shadow: {} wall leaves, worst {:+.2}% at z {worst_height:.4} m, {} within 2 cm of the base, their mean {:+.2}%", errors.len(), 100.0 * worst, base.len(), 100.0 * base_mean);
    assert!(worst.abs() <= 0.02, "a wall leaf {:.4} m up is {:+.2}% off the reference", worst_height, 100.0 * worst);
    assert!(base_mean.abs() <= 0.01, "the wall's leaves within 2 cm of its base are {:+.2}% off the reference on average", 100.0 * base_mean);
}

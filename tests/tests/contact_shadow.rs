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
//! 0.3]`, facing the floor, under a square lamp facing down at `z = 0.6`
//! behind the wall's plane, from `x, y = 0.52`: the floor within 2 cm of
//! the wall sees none of the lamp, and the wall sees only the floor. Two
//! of them ([`Setup`]): a dim wall (reflectance 0.1) under a 10 cm lamp,
//! and a bright one (0.5) under a 20 cm lamp. Their reference, written
//! here apart from the solver: the floor's direct light by Lambert's
//! closed form (test-support's own) for the part of the lamp above the
//! plane through the point and the wall's top edge, on cells 2 cm along
//! the wall and graded in depth from 10 µm; the wall's light by Lambert's
//! factor to each floor cell; the floor again with what the wall sends
//! back, and so on until the wall's total moves by under 1e-7 (the strip
//! the wall shadows is lit by the wall alone, and the wall's base sees
//! that strip most: without it the dim wall's base reads 3% high); a
//! leaf's value the mean over 16 of its points (64 move the base's mean
//! by 0.04%, cells 1 cm along the wall by 0.01%).

use end_to_end::{scratch, Solved};
use test_support::closed_form::{clip_to_front, lambert_polygon, mean_over_triangle};
use test_support::scenes::{rectangle, QuadScene};

const FLOOR_RHO: f64 = 0.5;
const EMISSION: f64 = 10.0;
/// The wall's plane and height; the floor's span along it.
const WALL_X: f64 = 0.5;
const WALL_HEIGHT: f64 = 0.3;
const SPAN: [f64; 2] = [0.07, 1.07];
/// The lamp's height and its near corner's `x` and `y`.
const LAMP_Z: f64 = 0.6;
const LAMP_FROM: f64 = 0.52;

/// The wall's reflectance and the lamp's side.
#[derive(Clone, Copy)]
struct Setup {
    wall_rho: f64,
    lamp_side: f64,
}

const DIM: Setup = Setup { wall_rho: 0.1, lamp_side: 0.1 };
const BRIGHT: Setup = Setup { wall_rho: 0.5, lamp_side: 0.2 };

impl Setup {
    fn lamp(self) -> [[f64; 3]; 4] {
        let to = LAMP_FROM + self.lamp_side;
        rectangle(2, LAMP_Z, [LAMP_FROM, LAMP_FROM], [to, to])
    }

    fn scene(self) -> QuadScene {
        let mut scene = QuadScene { camera: ([0.1, -0.6, 0.5], [0.4, 0.57, 0.1]), ..Default::default() };
        scene.material("floor", FLOOR_RHO, 0.0).material("wall", self.wall_rho, 0.0).material("lamp", 0.0, EMISSION);
        scene.quad("floor", "floor", rectangle(2, 0.0, [0.0, SPAN[0]], [WALL_X, SPAN[1]]), [0.0, 0.0, 1.0]);
        scene.quad("wall", "wall", rectangle(0, WALL_X, [SPAN[0], 0.0], [SPAN[1], WALL_HEIGHT]), [-1.0, 0.0, 0.0]);
        scene.quad("lamp", "lamp", self.lamp(), [0.0, 0.0, -1.0]);
        scene
    }

/// `rho E` times the factor from floor point `p` to the part of the lamp
/// it sees over the wall: the lamp clipped by the plane through `p` and
/// the wall's top edge (the wall spans every line from the floor to the
/// lamp along `y`), by Lambert's closed form.
    fn direct(self, p: [f64; 3]) -> f64 {
        let above = [-WALL_HEIGHT, 0.0, WALL_X - p[0]];
        FLOOR_RHO * EMISSION * lambert_polygon(p, [0.0, 0.0, 1.0], &clip_to_front(&self.lamp(), [WALL_X, 0.0, WALL_HEIGHT], above))
    }
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

/// The floor's and the wall's cells with their radiosity: the lamp's
/// light on the floor, then what floor and wall send each other until the
/// wall's total moves by under 1e-7 of itself.
fn reference(setup: Setup) -> (Cells, Cells) {
    let mut floor = cells(WALL_X, &|u, y| [WALL_X - u, y, 0.0]);
    for cell in &mut floor {
        cell.2 = setup.direct(cell.1);
    }
    let direct: Vec<f64> = floor.iter().map(|c| c.2).collect();
    let mut wall = cells(WALL_HEIGHT, &|u, y| [WALL_X, y, u]);
    let mut total = 0.0;
    loop {
        for cell in &mut wall {
            cell.2 = gathered(cell.1, [-1.0, 0.0, 0.0], setup.wall_rho, &floor);
        }
        let now: f64 = wall.iter().map(|c| c.2).sum();
        if (now - total).abs() <= 1e-7 * now {
            return (floor, wall);
        }
        total = now;
        let back: Vec<f64> = floor.iter().map(|cell| gathered(cell.1, [0.0, 0.0, 1.0], FLOOR_RHO, &wall)).collect();
        for ((cell, b), d) in floor.iter_mut().zip(back).zip(&direct) {
            cell.2 = d + b;
        }
    }
}

/// The scene solved with `args` and its reference: each leaf of `objects`
/// ("wall", "floor") as `(distance from the crease, relative error)`, one
/// list per object.
fn errors(test: &str, setup: Setup, objects: &[&str], args: &[&str]) -> Vec<Vec<(f64, f64)>> {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &setup.scene().write(&dir), args);
    let (floor, wall) = reference(setup);
    let of = |object: &str| {
        let (normal, rho, from) = if object == "wall" { ([-1.0, 0.0, 0.0], setup.wall_rho, &floor) } else { ([0.0, 0.0, 1.0], FLOOR_RHO, &wall) };
        let own = |x: [f64; 3]| if object == "floor" { setup.direct(x) } else { 0.0 };
        solved
            .leaves_of(object)
            .into_iter()
            .map(|(e, corners)| {
                let want = mean_over_triangle(&corners, 2, &|x| own(x) + gathered(x, normal, rho, from));
                let centroid: [f64; 3] = std::array::from_fn(|a| (corners[0][a] + corners[1][a] + corners[2][a]) / 3.0);
                let distance = if object == "wall" { centroid[2] } else { WALL_X - centroid[0] };
                (distance, f64::from(e.radiosity[0]) / want - 1.0)
            })
            .collect()
    };
    objects.iter().map(|o| of(o)).collect()
}

/// The worst leaf `(distance, error)` and the mean error of the leaves
/// within 2 cm of the crease.
fn worst_and_crease(errors: &[(f64, f64)]) -> ((f64, f64), f64) {
    let worst = errors.iter().copied().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())).expect("leaves");
    let crease: Vec<f64> = errors.iter().filter(|e| e.0 < 0.02).map(|e| e.1).collect();
    (worst, crease.iter().sum::<f64>() / crease.len() as f64)
}

/// Every wall leaf within 2% at the default settings (the issue's
/// measure for the leaves of a surface lit only by reflection), and the
/// leaves within 2 cm of the base, which see the contact shadow closest,
/// within 1% on average. Measured on the dim wall (worst leaf; the base's
/// mean): +1.52% (at the wall's top), -0.58% at the default `EPS` 1.5e-5;
/// against the reference with one bounce back, +6.65%, +0.64% at 1e-4,
/// +5.06%, -0.07% at 5e-5 and +1.74%, -0.57% at 2e-5. The bright wall's
/// row along the base, at the area floor, reaches +3.2% at the default
/// (+3.7% at 5e-5).
#[test]
fn a_wall_sees_the_contact_shadow_at_its_base_within_two_percent_per_leaf() {
    let ((height, worst), base) = worst_and_crease(&errors("contact_shadow", DIM, &["wall"], &[])[0]);
    eprintln!("contact shadow, default settings: worst wall leaf {:+.2}% at z {height:.4} m, the base's mean {:+.2}%", 100.0 * worst, 100.0 * base);
    assert!(worst.abs() <= 0.02, "a wall leaf {height:.4} m up is {:+.2}% off the reference", 100.0 * worst);
    assert!(base.abs() <= 0.01, "the wall's leaves within 2 cm of its base are {:+.2}% off the reference on average", 100.0 * base);
}

/// At `EPS` 4e-4 on the bright wall, a link from a whole wall triangle
/// into a floor element along the crease is kept: the parts of that
/// element each weigh the wall's parts from their own centroid
/// (hierarchical-solve's `receivers::NEAR_RECEIVER`), and the floor
/// leaves the lamp's shadow edge crosses open in the last solve
/// (hierarchical-solve's `shadowed`). Measured: the floor leaves within 2
/// cm of the crease +3.29% on average (+7.37% with those leaves left
/// whole; +26.77% with every part also taking what the wall sends the
/// element's centroid, the leaves right at the crease +51% to +58%), the
/// wall's within 2 cm of the base +2.03% (+2.89%; +7.84%). Since the last
/// solve opens a leaf from a sixteenth of its radiosity, not a quarter:
/// the floor +2.54%, the wall +1.91%; the floor's limit, 3%, holds that.
#[test]
fn the_parts_of_a_floor_element_at_a_crease_each_see_the_wall_for_themselves() {
    let both = errors("contact_shadow_crease", BRIGHT, &["floor", "wall"], &["--eps", "4e-4"]);
    let ((_, floor), (_, wall)) = (worst_and_crease(&both[0]), worst_and_crease(&both[1]));
    eprintln!("contact shadow, EPS 4e-4: floor within 2 cm of the crease {:+.2}%, wall {:+.2}% on average", 100.0 * floor, 100.0 * wall);
    assert!(floor.abs() <= 0.03, "the floor's leaves along the crease are {:+.2}% off the reference on average", 100.0 * floor);
    assert!(wall.abs() <= 0.03, "the wall's leaves along its base are {:+.2}% off the reference on average", 100.0 * wall);
}

//! hierarchical-solve where a link joins a coarse receiver: the light it
//! brings must reach each part of the receiver by that part's own factor to
//! the sender, not alike over the whole receiver (issue 10: a coarse link
//! misplaces its light over the receiver by `rho B (F_max - F_min)`, which
//! the refinement threshold allows and the leaves then show).
//!
//! The scene: a floor (`z = 0`, 1 m square, reflectance 0.5) lit by a small
//! lamp facing down at `z = 0.4` over one corner. Nothing else reflects,
//! so every floor leaf's radiosity is `rho E F(leaf, lamp)` exactly, with
//! `F` the mean of Lambert's closed form (test-support's own, apart from
//! the solver's kernel) over the leaf. A second scene puts a black square
//! between them at `z = 0.2`, whose shadow and penumbra cross the floor;
//! its reference is the midpoint rule over the lamp (5 mm cells) with the
//! segment test against the square written here.

use end_to_end::{scratch, Solved};
use schemas::solution::{Node, NONE};
use std::collections::HashSet;
use test_support::artifacts::leaf_world_corners;
use test_support::closed_form::{floor_plane, lambert_polygon, mean_over_triangle, midpoint_square_lamp};
use test_support::scenes::{rectangle, QuadScene};

const RHO: f64 = 0.5;
const EMISSION: f64 = 10.0;
/// The lamp: `x, y in [0.1, 0.25]`, `z = 0.4`, facing down.
const LAMP: ([f64; 2], f64) = ([0.1, 0.25], 0.4);
/// The occluder: `x, y in [0.3, 0.5]`, `z = 0.2`.
const OCCLUDER: ([f64; 2], f64) = ([0.3, 0.5], 0.2);

fn scene(occluded: bool) -> QuadScene {
    let mut scene = QuadScene { camera: ([0.5, -1.5, 0.8], [0.5, 0.5, 0.0]), ..Default::default() };
    scene.material("floor", RHO, 0.0).material("lamp", 0.0, EMISSION).material("black", 0.0, 0.0);
    scene.quad("floor", "floor", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", rectangle(2, LAMP.1, [LAMP.0[0], LAMP.0[0]], [LAMP.0[1], LAMP.0[1]]), [0.0, 0.0, -1.0]);
    if occluded {
        for sign in [1.0, -1.0] {
            scene.quad("occluder", "black", rectangle(2, OCCLUDER.1, [OCCLUDER.0[0], OCCLUDER.0[0]], [OCCLUDER.0[1], OCCLUDER.0[1]]), [0.0, 0.0, sign]);
        }
    }
    scene
}

/// Whether the segment from floor point `p` to lamp point `q` crosses the
/// occluder (at height `OCCLUDER.1`, between the two).
fn blocked(p: [f64; 3], q: [f64; 3]) -> bool {
    let t = (OCCLUDER.1 - p[2]) / (q[2] - p[2]);
    let (x, y) = (p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
    let inside = |v: f64| (OCCLUDER.0[0]..=OCCLUDER.0[1]).contains(&v);
    inside(x) && inside(y)
}

/// `rho E` times the lamp's factor at floor point `p`: Lambert's closed
/// form, or with the occluder the midpoint rule over 5 mm cells of the
/// lamp with the segment test.
fn exact(p: [f64; 3], occluded: bool) -> f64 {
    let lamp = rectangle(2, LAMP.1, [LAMP.0[0], LAMP.0[0]], [LAMP.0[1], LAMP.0[1]]);
    if !occluded {
        return RHO * EMISSION * lambert_polygon(p, [0.0, 0.0, 1.0], &lamp);
    }
    RHO * EMISSION * midpoint_square_lamp(p, (LAMP.0[0], LAMP.0[1]), LAMP.1, 30, &blocked)
}

/// The floor leaves' relative L2 error against [`exact`] (`sqrt(sum A
/// (B - B*)^2 / sum A B*^2)`) and the worst leaf's relative error, solved
/// with `args`.
fn errors(test: &str, occluded: bool, args: &[&str]) -> (f64, f64) {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &scene(occluded).write(&dir), args);
    let (mut squares, mut area, mut worst) = (0.0, 0.0, 0.0f64);
    for (e, corners) in solved.leaves_of("floor") {
        let want = mean_over_triangle(&corners, 2, &|x| exact(x, occluded));
        let error = f64::from(e.radiosity[0]) - want;
        squares += f64::from(e.area) * error * error;
        area += f64::from(e.area) * want * want;
        worst = worst.max(error.abs() / want);
    }
    ((squares / area).sqrt(), worst)
}

/// Measured with a coarse link lighting all its receiver's leaves alike
/// (L2, worst leaf): 4.69%, 14.8% at `EPS` 1e-2; 1.34%, 6.0% at 3e-3;
/// 0.02%, 0.24% at the default. Each part by its own factor: 0.25%, 0.46%;
/// 0.05%, 0.14%; 0.00%, 0.00%. Those `EPS` were 24 times the ones below,
/// which have the same relative threshold since hierarchical-solve's
/// `RELATIVE_AT` went from 3 to 1/8 with the absolute threshold as a cap:
/// now 0.01%, 0.08%; 0.00%, 0.01%; 0.00%, 0.00%.
#[test]
fn a_coarse_link_lights_each_part_of_its_receiver_by_its_own_factor() {
    for (eps, l2_limit, leaf_limit) in [("4e-4", 0.005, 0.01), ("1.25e-4", 0.0015, 0.003), ("1.5e-5", 0.0005, 0.001)] {
        let (l2, worst) = errors(&format!("receiver_parts_{eps}"), false, &["--eps", eps]);
        eprintln!("receiver parts, EPS {eps}: floor leaves L2 {:.2}%, worst {:.2}%", 100.0 * l2, 100.0 * worst);
        assert!(l2 <= l2_limit, "EPS {eps}: the floor's leaves are {:.2}% off Lambert's (L2)", 100.0 * l2);
        assert!(worst <= leaf_limit, "EPS {eps}: a floor leaf is {:.2}% off Lambert's", 100.0 * worst);
    }
}

/// With the occluder, a partly occluded link weighs each part by its own
/// visibility too. Measured (L2): 2.14%, 2.05%, 0.45% at `EPS` 1e-2, 3e-3
/// and the default with all leaves alike; 0.87%, 0.40%, 0.27% by part
/// (0.39%, 0.30%, 0.29% at the thresholds below, the same relative ones:
/// see above; 0.27%, 0.15%, 0.07% since a link takes the visible fraction
/// its parts measured and the last solve opens the leaves a shadow edge
/// crosses). Single
/// leaves are not bounded here: in the penumbra a leaf at the area floor
/// whose 16 rays all hit the occluder is dark where a few percent of the
/// lamp shows (up to 100% of such a leaf's light, at any `EPS`).
#[test]
fn a_partly_occluded_coarse_link_lights_each_part_by_its_own_visibility() {
    for (eps, l2_limit) in [("4e-4", 0.012), ("1.25e-4", 0.006), ("1.5e-5", 0.0035)] {
        let (l2, _) = errors(&format!("receiver_parts_occluded_{eps}"), true, &["--eps", eps]);
        eprintln!("receiver parts, occluded, EPS {eps}: floor leaves L2 {:.2}%", 100.0 * l2);
        assert!(l2 <= l2_limit, "EPS {eps}: the floor's leaves are {:.2}% off the quadrature (L2)", 100.0 * l2);
    }
}

/// The solve's measured slopes of the lamp's light across the floor's
/// leaves in the occluder's penumbra (the solution's `slope` table,
/// hierarchical-solve's `slopes` module), `rho E F grad V`: the shadow's
/// slope without the kernel's own. The reference, per leaf, from the
/// quadrature written here: the least-squares plane of the occluded light
/// `rho E F V` over 256 points of the leaf, less the leaf's visible fraction
/// times the unoccluded light's plane (`grad (F V) - V grad F`, with `V`
/// the leaf's mean occluded over unoccluded light). Returns the relative L2
/// error of the slopes (`sqrt(sum A |g - g*|² / sum A |g*|²)`), their
/// component along the reference (`sum A g . g* / sum A |g*|²`) and the
/// leaves compared: the floor's leaves with a slope whose lamp light all
/// comes through links into their parent (the rays the slope is measured
/// from; a lamp link into the leaf or a farther ancestor brings light
/// whose slope is not measured).
fn penumbra_slopes(test: &str, args: &[&str]) -> (f64, f64, usize) {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &scene(true).write(&dir), args);
    let (mesh, elements) = (&solved.mesh, &solved.solution.elements);
    let lamp = solved.manifest.objects.iter().position(|o| o == "lamp").unwrap() as u32;
    let from_lamp = |n: Node| matches!(n, Node::Element(e) if mesh.triangles[elements[e as usize].triangle as usize].object == lamp);
    let lit: HashSet<Node> = solved.solution.links.iter().filter(|l| from_lamp(l.sender)).map(|l| l.receiver).collect();
    let covered = |leaf: u32| {
        let parent = elements[leaf as usize].parent;
        let ancestors = std::iter::successors(Some(leaf), |&e| Some(elements[e as usize].parent).filter(|&p| p != NONE));
        lit.contains(&Node::Element(parent)) && ancestors.filter(|&e| e != parent).all(|e| !lit.contains(&Node::Element(e))) && lit.iter().all(|n| matches!(n, Node::Element(_)))
    };
    let (mut squares, mut norms, mut along, mut count) = (0.0, 0.0, 0.0, 0);
    for slope in solved.solution.slopes.iter().filter(|s| covered(s.element)) {
        let element = &elements[slope.element as usize];
        let corners = leaf_world_corners(mesh, solved.manifest.world_from_mesh_translation, element);
        if corners.iter().any(|c| c[2].abs() > 1e-6) {
            continue;
        }
        let (occluded, unoccluded) = (floor_plane(&corners, 4, &|p| exact(p, true)), floor_plane(&corners, 4, &|p| exact(p, false)));
        let v = occluded.1 / unoccluded.1;
        let want = [occluded.0[0] - v * unoccluded.0[0], occluded.0[1] - v * unoccluded.0[1]];
        let got = [f64::from(slope.gradient[0][0]), f64::from(slope.gradient[0][1])];
        assert_eq!(slope.gradient[0][2], 0.0, "{test}: leaf {}: a slope across the floor has no z", slope.element);
        let area = f64::from(element.area);
        squares += area * ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2));
        norms += area * (want[0] * want[0] + want[1] * want[1]);
        along += area * (got[0] * want[0] + got[1] * want[1]);
        count += 1;
    }
    eprintln!("{test}: {count} floor leaves, slopes' relative L2 error {:.1}%, along the reference {:.3}", 100.0 * (squares / norms).sqrt(), along / norms);
    ((squares / norms).sqrt(), along / norms, count)
}

/// Measured (`EPS` 3e-3, area floor 1e-3 m², leaves of 3 to 12 cm, 36 to
/// 40 leaves compared): with 1024 rays a link 11.4% relative L2 and 0.995
/// along the reference, which checks the fit and the formula; with the
/// default 16, over seeds 1-8, 51% to 78% (mean 61%) and 0.82 to 1.10
/// along it (mean 0.97), the noise of the leaves' rays, which is why the
/// preview takes half of it (grid-gather's `MEASURED_SLOPE`). Those rays
/// are at least 16 a leaf, more where the lamp's light on it calls for
/// them (hierarchical-solve's `links::Budget`); with 16 everywhere the
/// eight seeds gave 51% to 129% (mean 82%) and 0.58 to 1.26 (mean 0.95),
/// and the bound on the mean, 75%, holds that gain. One seed alone swings
/// too far to test (the link rays' sampling moved seed 1 from 58% to
/// 129%), so the default is held to its mean over the eight.
#[test]
fn the_solve_measures_the_lamps_slope_across_the_leaves_of_a_penumbra() {
    let args = ["--eps", "3e-3", "--min-area", "1e-3"];
    let (error, along, count) = penumbra_slopes("receiver_parts_slopes_1024", &[&args[..], &["--visibility-rays", "1024"]].concat());
    assert!(count >= 20, "1024 rays: only {count} floor leaves have a measured slope");
    assert!(error <= 0.2, "1024 rays: the measured slopes are {:.0}% off the quadrature's (L2)", 100.0 * error);
    assert!((0.9..=1.1).contains(&along), "1024 rays: the measured slopes are {along:.3} times the quadrature's along it");
    let seeds = ["1", "2", "3", "4", "5", "6", "7", "8"];
    let (mut errors, mut alongs) = (0.0, 0.0);
    for seed in seeds {
        let (error, along, count) = penumbra_slopes(&format!("receiver_parts_slopes_16_seed_{seed}"), &[&args[..], &["--seed", seed]].concat());
        assert!(count >= 20, "16 rays, seed {seed}: only {count} floor leaves have a measured slope");
        (errors, alongs) = (errors + error, alongs + along);
    }
    let (error, along) = (errors / seeds.len() as f64, alongs / seeds.len() as f64);
    assert!(error <= 0.75, "16 rays: the measured slopes are {:.0}% off the quadrature's (L2, mean over seeds 1-8)", 100.0 * error);
    assert!((0.85..=1.15).contains(&along), "16 rays: the measured slopes are {along:.3} times the quadrature's along it (mean over seeds 1-8)");
}

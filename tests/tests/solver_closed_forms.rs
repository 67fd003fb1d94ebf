//! hierarchical-solve against closed forms: configuration factors of
//! rectangles (Howell C-11, C-14), irradiance under a square emitter
//! (Lambert), and energy balance of closed rooms; each without and with
//! clustering (clusters of one triangle, so that cluster nodes really sit
//! between the triangles and the root).

use end_to_end::{assert_refused, pixel_points_on_ground, run_ok, s, scratch, solve_prepared};
use schemas::mesh::{Manifest, Mesh};
use schemas::report::Report;
use schemas::ron_io::read_ron;
use schemas::solution::{Node, Solution};
use std::path::Path;
use test_support::artifacts::leaf_world_corners;
use test_support::closed_form::{clip_to_front, lambert_polygon, mean_over_triangle, parallel_rectangles, perpendicular_rectangles, point_to_rectangle};
use test_support::scenes::{closed_box, one_bounce, rectangle, straddled_receiver, QuadScene};

/// The solved scene, with each element's object name.
struct Solved {
    solution: Solution,
    object_of_element: Vec<String>,
}

/// Prepares and solves `scene` in a scratch directory; `clustered` adds a
/// cluster hierarchy of one triangle per leaf.
fn solve(test: &str, scene: &QuadScene, args: &[&str], clustered: bool) -> (Solved, std::path::PathBuf) {
    let dir = scratch(&format!("{test}{}", if clustered { "_clustered" } else { "" }));
    let scene_path = scene.write(&dir);
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(&scene_path), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let solution = solve_prepared(&dir, args, clustered.then_some(1));
    (load(&mesh, &manifest, &solution), dir)
}

fn load(mesh: &Path, manifest: &Path, solution: &Path) -> Solved {
    let (mesh, _) = Mesh::read(mesh).unwrap();
    let manifest = read_ron::<Manifest>(manifest).unwrap().value;
    let (solution, _) = Solution::read(solution).unwrap();
    let object_of_element = solution
        .elements
        .iter()
        .map(|e| manifest.objects[mesh.triangles[e.triangle as usize].object as usize].clone())
        .collect();
    Solved { solution, object_of_element }
}

impl Solved {
    /// The solver's factor from object `r` to object `s`: the area-weighted
    /// sum of the form factors of all links between their elements, at any
    /// level.
    fn form_factor(&self, r: &str, s: &str) -> f64 {
        let e = &self.solution.elements;
        let area_of = |name: &str| -> f64 {
            e.iter().zip(&self.object_of_element).filter(|(x, o)| x.parent == u32::MAX && *o == name).map(|(x, _)| f64::from(x.area)).sum()
        };
        let flux: f64 = self
            .solution
            .links
            .iter()
            .filter_map(|l| match (l.receiver, l.sender) {
                (Node::Element(re), Node::Element(se)) => Some((re as usize, se as usize, l)),
                _ => None,
            })
            .filter(|(re, se, _)| self.object_of_element[*re] == r && self.object_of_element[*se] == s)
            .map(|(re, _, l)| f64::from(e[re].area) * f64::from(l.form_factor))
            .sum();
        flux / area_of(r)
    }

    /// Area-weighted mean radiosity (grey) of the leaves of `object`.
    fn mean_radiosity(&self, object: &str) -> f64 {
        let (mut weighted, mut area) = (0.0, 0.0);
        for (o, a, b, _) in self.leaves() {
            if o == object {
                weighted += a * b;
                area += a;
            }
        }
        weighted / area
    }

    /// Leaves with their object, area and radiosity (grey: channel 0).
    fn leaves(&self) -> impl Iterator<Item = (&str, f64, f64, usize)> {
        self.solution
            .elements
            .iter()
            .enumerate()
            .filter(|(_, e)| e.first_child == u32::MAX)
            .map(|(i, e)| (self.object_of_element[i].as_str(), f64::from(e.area), f64::from(e.radiosity[0]), i))
    }

    /// The area-mean radiosity of the leaves (channel 0).
    fn mean(&self) -> f64 {
        let (weighted, area) = self.leaves().fold((0.0, 0.0), |(w, a), (_, area, b, _)| (w + area * b, a + area));
        weighted / area
    }
}

const FINE: [&str; 4] = ["--eps", "1e-4", "--min-area", "1e-4"];

fn assert_close(what: &str, got: f64, want: f64, relative: f64) {
    let error = (got - want).abs() / want.abs();
    eprintln!("{what}: relative error {error:.2e}");
    assert!(error <= relative, "{what}: {got} vs closed form {want} (relative error {error:.2e} > {relative:.0e})");
}

/// Rectangles R (reflectance 1/2) and S (emitting 1 W/m², black): the
/// solver's R-S factor summed over its element links must be the closed
/// form, and R's mean radiosity rho F_RS E with or without clusters (there
/// links may join clusters holding parts of both R and S, so only the
/// radiosity is compared).
fn check_pair(test: &str, scene: &QuadScene, exact: f64, what: &str) {
    let (solved, _) = solve(test, scene, &FINE, false);
    assert_close(&format!("F_RS for {what}"), solved.form_factor("R", "S"), exact, 0.01);
    for clustered in [false, true] {
        let (solved, _) = solve(test, scene, &FINE, clustered);
        assert_close(&format!("B_R for {what}, clustered {clustered}"), solved.mean_radiosity("R"), 0.5 * exact, 0.01);
    }
}

#[test]
fn parallel_rectangles_match_howell_c11() {
    for (k, (a, b, c)) in [(1.0, 1.0, 1.0), (2.0, 1.0, 0.5), (1.0, 3.0, 2.0)].into_iter().enumerate() {
        let mut scene = QuadScene { camera: ([-2.0, 0.5 * b, 0.5 * c], [0.5 * a, 0.5 * b, 0.5 * c]), ..Default::default() };
        scene.material("receiving", 0.5, 0.0).material("emitting", 0.0, 1.0);
        scene.quad("R", "receiving", rectangle(2, 0.0, [0.0, 0.0], [a, b]), [0.0, 0.0, 1.0]);
        scene.quad("S", "emitting", rectangle(2, c, [0.0, 0.0], [a, b]), [0.0, 0.0, -1.0]);
        let exact = parallel_rectangles(a, b, c);
        check_pair(&format!("c11_{k}"), &scene, exact, &format!("{a} x {b} at {c}"));
        let (solved, _) = solve(&format!("c11_{k}"), &scene, &FINE, false);
        assert_close(&format!("F_SR for {a} x {b} at {c}"), solved.form_factor("S", "R"), exact, 0.01);
    }
}

#[test]
fn perpendicular_rectangles_sharing_an_edge_match_howell_c14() {
    for (k, (w, h, l)) in [(1.0, 1.0, 1.0), (2.0, 0.5, 1.0), (0.5, 2.0, 3.0)].into_iter().enumerate() {
        // Floor R: x in [0, w], y in [0, l]; wall S: x = 0, y in [0, l], z in [0, h].
        let mut scene = QuadScene { camera: ([2.0 * w, 0.5 * l, 2.0 * h], [0.0, 0.5 * l, 0.0]), ..Default::default() };
        scene.material("receiving", 0.5, 0.0).material("emitting", 0.0, 1.0);
        scene.quad("R", "receiving", rectangle(2, 0.0, [0.0, 0.0], [w, l]), [0.0, 0.0, 1.0]);
        scene.quad("S", "emitting", rectangle(0, 0.0, [0.0, 0.0], [l, h]), [1.0, 0.0, 0.0]);
        check_pair(&format!("c14_{k}"), &scene, perpendicular_rectangles(w, h, l), &format!("w={w} h={h} l={l}"));
    }
}

#[test]
fn floor_irradiance_under_a_square_emitter_matches_lambert() {
    lambert(false);
}

#[test]
fn floor_irradiance_under_a_square_emitter_matches_lambert_with_clusters() {
    lambert(true);
}

fn lambert(clustered: bool) {
    let (rho, height) = (0.5, 1.0);
    let mut scene = QuadScene { camera: ([0.0, -3.0, 2.0], [0.0, 0.0, 0.0]), ..Default::default() };
    scene.material("floor", rho, 0.0).material("lamp", 0.0, 1.0);
    scene.quad("floor", "floor", rectangle(2, 0.0, [-2.0, -2.0], [2.0, 2.0]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", rectangle(2, height, [-0.5, -0.5], [0.5, 0.5]), [0.0, 0.0, -1.0]);
    let (solved, dir) = solve("lambert", &scene, &["--eps", "1e-4", "--min-area", "1e-5"], clustered);
    let (mesh_path, manifest_path) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    let (mesh, _) = Mesh::read(&mesh_path).unwrap();
    let manifest = read_ron::<Manifest>(&manifest_path).unwrap().value;
    let origin = manifest.world_from_mesh_translation;
    let mut checked = 0;
    for (object, _, b, i) in solved.leaves() {
        if object != "floor" {
            continue;
        }
        let e = &solved.solution.elements[i];
        let t = &mesh.triangles[e.triangle as usize];
        let p = |k: usize| mesh.positions[t.vertices[k] as usize].map(f64::from);
        let (p0, p1, p2) = (p(0), p(1), p(2));
        let centroid_uv = [0, 1].map(|axis| e.corners.iter().map(|c| f64::from(c[axis])).sum::<f64>() / 3.0);
        let world = |axis: usize| p0[axis] + (p1[axis] - p0[axis]) * centroid_uv[0] + (p2[axis] - p0[axis]) * centroid_uv[1] + origin[axis];
        let (x, y) = (world(0), world(1));
        let exact = point_to_rectangle(x, y, [-0.5, 0.5, -0.5, 0.5], height);
        if exact < 0.05 {
            continue;
        }
        assert_close(&format!("irradiance at ({x:.3}, {y:.3})"), b / rho, exact, 0.005);
        checked += 1;
    }
    assert!(checked > 100, "only {checked} floor elements under the lamp");
}

/// Issue 10, item 1: a receiver whose senders straddle its plane, with a
/// solid box behind it. Every leaf of R must have the irradiance of
/// Lambert's formula for the part of the emitter in front of R's plane,
/// averaged over the leaf (16 sub-triangle centroids), within 0.5%: R's
/// radiosity is `rho E F`, nothing else reflects. Visibility as the plain
/// clear fraction of rays to the whole emitter counts the rays to its back
/// half, which run through the box, as shadowed.
fn straddling_sender(clustered: bool) {
    let (rho, emission) = (0.5, 1.0);
    let scene = straddled_receiver(rho, emission);
    let (solved, dir) = solve("straddling", &scene, &[], clustered);
    let (mesh, _) = Mesh::read(&dir.join("mesh.exr")).unwrap();
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    let origin = manifest.world_from_mesh_translation;
    let lamp = [[-0.7, -0.5, 1.5], [1.3, -0.5, 1.5], [1.3, 1.5, 1.5], [-0.7, 1.5, 1.5]];
    let (r_origin, r_normal) = ([0.0; 3], [1.0, 0.0, 0.0]);
    let front = clip_to_front(&lamp, r_origin, r_normal);
    let mut errors = LeafErrors::default();
    for (object, _, b, i) in solved.leaves() {
        if object != "R" {
            continue;
        }
        let corners = leaf_world_corners(&mesh, origin, &solved.solution.elements[i]);
        let exact = mean_over_triangle(&corners, 2, &|x| lambert_polygon(x, r_normal, &front));
        errors.add((b / (rho * emission) - exact) / exact);
    }
    let (checked, worst) = (errors.checked, errors.worst);
    eprintln!("straddling, clustered {clustered}: {checked} leaves of R, largest relative error {worst:.2e}, rms {:.2e}", errors.rms());
    assert!(checked >= 8, "only {checked} leaves on R");
    assert!(worst <= 0.005, "clustered {clustered}: a leaf of R is {worst:.2e} off Lambert's formula for the emitter's part in front");
}

/// Relative errors of leaves against a closed form: how many, the
/// largest in magnitude, and their root mean square.
#[derive(Default)]
struct LeafErrors {
    checked: u32,
    worst: f64,
    sum_sq: f64,
}

impl LeafErrors {
    fn add(&mut self, error: f64) {
        self.worst = self.worst.max(error.abs());
        self.sum_sq += error * error;
        self.checked += 1;
    }

    fn rms(&self) -> f64 {
        (self.sum_sq / f64::from(self.checked.max(1))).sqrt()
    }
}

#[test]
fn straddling_senders_give_every_leaf_lamberts_irradiance_of_their_front_part() {
    straddling_sender(false);
}

#[test]
fn straddling_senders_give_every_leaf_lamberts_irradiance_of_their_front_part_with_clusters() {
    straddling_sender(true);
}

fn energy_balance(test: &str, rho: f64, clustered: bool) {
    energy_balance_with(test, rho, clustered, &["--eps", "1e-3", "--min-area", "1e-3", "--tolerance", "1e-7"], 0.01);
}

/// The closed box's mean radiosity against `E A_lamp / ((1 - rho) A)`,
/// solved with `args`, within `relative`.
fn energy_balance_with(test: &str, rho: f64, clustered: bool, args: &[&str], relative: f64) {
    let (size, emission) = (1.0, 10.0);
    let (solved, _) = solve(test, &closed_box(size, rho, emission), args, clustered);
    let total_area = 6.0 * size * size;
    let expected = box_mean(size, rho, emission);
    let (mut weighted, mut area) = (0.0, 0.0);
    for (_, a, b, i) in solved.leaves() {
        let rgb = solved.solution.elements[i].radiosity;
        assert!(rgb.iter().all(|x| x.is_finite() && *x >= 0.0), "element {i} has radiosity {rgb:?}");
        weighted += a * b;
        area += a;
    }
    assert_close("total area", area, total_area, 1e-6);
    assert_close(&format!("mean radiosity, rho = {rho}"), weighted / area, expected, relative);
}

/// Issue 10, item 5: a solve stopped by the iteration cap says so, on
/// stderr and in its report, with the bound it reached, and that bound
/// holds: the mean radiosity is off by no more than the bound times the
/// largest radiosity.
#[test]
fn iteration_cap_is_reported_with_an_honest_bound() {
    let (size, rho, emission) = CAPPED_BOX;
    let [mesh, manifest, solution, report] = prepared_box("iteration_cap", rho);
    let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--report", s(&report), "--eps", "1e-2", "--min-area", "1e-2"];
    let capped = [&args[..], &["--max-iterations", "12", "--max-passes", "1"]].concat();
    let out = run_ok("hierarchical-solve", &capped);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: tolerance not reached"), "no warning on stderr:\n{stderr}");
    let report = read_ron::<Report>(&report).unwrap().value;
    assert!(report.notes.iter().any(|n| n.contains("tolerance not reached")), "no note in the report: {:?}", report.notes);
    assert_eq!(report.counters["converged"], 0.0);
    let bound = report.counters["error_bound"];
    eprintln!("capped: bound {bound:.3e}; {stderr}");
    let solved = load(&mesh, &manifest, &solution);
    let largest = solved.leaves().map(|(_, _, b, _)| b).fold(0.0, f64::max);
    let error = (solved.mean() - box_mean(size, rho, emission)).abs();
    eprintln!("capped: mean off by {:.3e} of the largest radiosity, bound {bound:.3e}", error / largest);
    assert!(bound.is_finite() && error <= bound * largest, "error {error} over the bound {bound} x {largest}");
    // Uncapped, the same solve converges and says nothing.
    let out = run_ok("hierarchical-solve", &args);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A solve that would need more links than `--max-links` keeps the links
/// it would split, says so on stderr and in its report, and stays within
/// the cap; the closed box's mean, which any set of links conserves up to
/// their factors' sum, stays within 2% of the closed form.
#[test]
fn link_cap_is_kept_and_reported() {
    let (size, _, emission) = CAPPED_BOX;
    let rho = 0.9;
    let [mesh, manifest, solution, report] = prepared_box("link_cap", rho);
    let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--report", s(&report), "--eps", "1e-3", "--max-links", "3000"];
    let out = run_ok("hierarchical-solve", &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: refinement stopped at max_links = 3000"), "no warning on stderr:\n{stderr}");
    let noted = read_ron::<Report>(&report).unwrap().value;
    assert!(noted.notes.iter().any(|n| n.contains("max_links")), "no note in the report: {:?}", noted.notes);
    let links = noted.counters["links"];
    assert!((1.0..=3000.0).contains(&links), "{links} links under a cap of 3000");
    let (mean, expected) = (load(&mesh, &manifest, &solution).mean(), box_mean(size, rho, emission));
    assert!((mean / expected - 1.0).abs() < 0.02, "mean {mean} against {expected}");
    // Clustered, where a split of a cluster makes more than four links of
    // one, the cap holds too.
    solve_prepared(mesh.parent().unwrap(), &args[6..], Some(4));
    let links = read_ron::<Report>(&report).unwrap().value.counters["links"];
    assert!((1.0..=3000.0).contains(&links), "clustered: {links} links under a cap of 3000");
}

/// A closed box of reflectance 1 never absorbs its lamp's light: there is
/// no steady state, and the iteration's changes do not shrink. The solve
/// refuses (one line, exit 2, no file) instead of writing its last iterate
/// with a warning, as it did.
#[test]
fn a_closed_box_that_absorbs_nothing_is_refused() {
    let [mesh, manifest, solution, report] = prepared_box("absorbs_nothing", 1.0);
    let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--report", s(&report), "--eps", "1e-2", "--min-area", "1e-2"];
    assert_refused("hierarchical-solve", &args, &["diverges", "max_iterations = 2000", "no solution written"], &[&solution]);
}

/// Size, reflectance and emission of the closed box the cap tests solve.
const CAPPED_BOX: (f64, f64, f64) = (1.0, 0.999, 10.0);

/// [`CAPPED_BOX`] at reflectance `rho`, prepared in the scratch directory
/// of `test`: the paths of its mesh, manifest, solution and report.
fn prepared_box(test: &str, rho: f64) -> [std::path::PathBuf; 4] {
    let dir = scratch(test);
    let scene_path = closed_box(CAPPED_BOX.0, rho, CAPPED_BOX.2).write(&dir);
    let paths = ["mesh.exr", "manifest.ron", "solution.exr", "solve.report.ron"].map(|f| dir.join(f));
    run_ok("mesh-prep", &[s(&scene_path), "--mesh", s(&paths[0]), "--manifest", s(&paths[1])]);
    paths
}

/// The closed box's mean radiosity, `P / ((1 - rho) A)`, its lamp a ninth
/// of the ceiling.
fn box_mean(size: f64, rho: f64, emission: f64) -> f64 {
    emission * (size / 3.0) * (size / 3.0) / ((1.0 - rho) * 6.0 * size * size)
}

/// Issue 10, item 5: near `rho = 1` the old rule (stop when one iteration
/// changes little) stopped 1.04% low at the default tolerance; the bound of
/// the remaining error must bring the default solve within 0.1%.
#[test]
fn closed_box_rho_0_999_mean_within_0_1_percent_at_default_settings() {
    energy_balance_with("energy_0_999", 0.999, false, &[], 1e-3);
}

/// The uniform senders' shortcut scaled by `1 - q` (gather::UNIFORM_SENDER):
/// without the scaling the box lost 0.86% at this `EPS` (now 0.009%).
#[test]
fn closed_box_rho_0_999_conserves_energy_at_a_coarse_eps() {
    energy_balance_with("energy_0_999_coarse", 0.999, false, &["--eps", "1e-3"], 5e-4);
}

#[test]
fn closed_box_conserves_energy_rho_0_5() {
    energy_balance("energy_0_5", 0.5, false);
    energy_balance("energy_0_5", 0.5, true);
}

#[test]
fn closed_box_conserves_energy_rho_0_9() {
    energy_balance("energy_0_9", 0.9, false);
    energy_balance("energy_0_9", 0.9, true);
}

/// The one-bounce configuration ([`one_bounce`]), by quadrature written
/// here apart from the solver: A's radiosity is `rho_A E F_{x->L}` (Lambert's
/// formula, exact) plus what it reflects of B's; B's is `rho_B / pi` times
/// the integral over A of `B_A(x) cos cos / r^2` (parallel planes 0.5 m
/// apart: `h^2 / (pi r^4)`), midpoint rule on a 2 cm grid of A and of B.
/// The exchange between A and B is iterated until B changes by less than
/// 1e-9 of itself: every bounce (at rho_B 0.5 the bounces past the second
/// add 0.5% to B). Returns `B(y)` per point `y` of B.
fn one_bounce_reference(rho_a: f64, rho_b: f64, emission: f64, points: &[[f64; 3]]) -> Vec<f64> {
    let h = 0.5;
    let lamp = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let cell = 0.02;
    let grid = |x0: f64, nx: usize, ny: usize, z: f64| -> Vec<[f64; 3]> {
        (0..nx).flat_map(|i| (0..ny).map(move |j| [x0 + (i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell, z])).collect()
    };
    let a_grid = grid(0.0, 100, 50, h);
    let b_grid = grid(1.0, 50, 50, 0.0);
    let kernel = |x: &[f64; 3], y: &[f64; 3]| {
        let r2 = (x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + h * h;
        h * h / (std::f64::consts::PI * r2 * r2) * cell * cell
    };
    let direct_a: Vec<f64> = a_grid.iter().map(|x| rho_a * emission * lambert_polygon(*x, [0.0, 0.0, -1.0], &lamp)).collect();
    let gather = |from: &[[f64; 3]], values: &[f64], to: &[f64; 3]| from.iter().zip(values).map(|(x, b)| b * kernel(x, to)).sum::<f64>();
    let mut b_b = vec![0.0; b_grid.len()];
    let b_a = loop {
        let b_a: Vec<f64> = a_grid.iter().zip(&direct_a).map(|(x, d)| d + rho_a * gather(&b_grid, &b_b, x)).collect();
        let next: Vec<f64> = b_grid.iter().map(|y| rho_b * gather(&a_grid, &b_a, y)).collect();
        let change = next.iter().zip(&b_b).map(|(n, o)| (n - o).abs() / n.abs().max(1e-300)).fold(0.0, f64::max);
        b_b = next;
        if change < 1e-9 {
            break b_a;
        }
    };
    points.iter().map(|y| rho_b * gather(&a_grid, &b_a, y)).collect()
}

/// Per leaf of B: the relative error against [`one_bounce_reference`]
/// (the leaf's mean over 4 sub-triangles), for the solver's `args`.
fn one_bounce_errors(test: &str, rho_b: f64, args: &[&str]) -> Vec<f64> {
    let (rho_a, emission) = (0.5, 1.0);
    let (solved, dir) = solve(test, &one_bounce(rho_a, rho_b, emission), args, false);
    let (mesh, _) = Mesh::read(&dir.join("mesh.exr")).unwrap();
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    let origin = manifest.world_from_mesh_translation;
    let mut leaves = Vec::new();
    for (object, _, b, i) in solved.leaves() {
        if object != "B" {
            continue;
        }
        let corners = leaf_world_corners(&mesh, origin, &solved.solution.elements[i]);
        let points = std::cell::RefCell::new(Vec::new());
        mean_over_triangle(&corners, 1, &|x| {
            points.borrow_mut().push(x);
            0.0
        });
        leaves.push((b, points.into_inner()));
    }
    let all: Vec<[f64; 3]> = leaves.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    let reference = one_bounce_reference(rho_a, rho_b, emission, &all);
    leaves.iter().zip(reference.chunks(4)).map(|((b, _), r)| {
        let exact = r.iter().sum::<f64>() / 4.0;
        (b - exact) / exact
    }).collect()
}

/// Issue 10, item 2: B is lit only by what A reflects, its radiosity
/// ~2e-3 (rho_B 0.05) to 2e-2 (0.5) of the lamp's. Every leaf of B must be
/// within 2% of the quadrature reference at default settings, for rho_B 0.5
/// and 0.05. The absolute criterion (error in units of the lamp's
/// exitance) leaves links onto B carrying the mean radiosity of large parts
/// of A, whose radiosity falls off from above the lamp to above B's far
/// edge: measured, B's worst leaf 71% off while a coarse link lit all its
/// receiver's leaves alike; since it lights each part by its own factor
/// (hierarchical-solve's `receivers`), 11.6% at rho_B 0.05 and 1.4% at
/// 0.5 (`EPS` 2e-4), 36% and 3.4% at `EPS` 1e-3. A per-link allowance of
/// `eps_relative` of the receiver's radiosity let the links' same-signed
/// errors add up: worst leaf 8.9%, rms 2.1%. Shared among the links
/// (hierarchical-solve's `Allowance::for_link`): worst 1.1%; with the
/// absolute threshold as a cap (`RELATIVE_AT`), 0.34% at `EPS` 2e-4 and
/// 1.5% at 1e-3. At the default `EPS` (1.5e-5) the absolute threshold
/// alone is fine enough for B (1.2%), so the two criteria are told apart
/// at `EPS` 1e-3, where the relative one must still meet 2%.
#[test]
fn one_bounce_receiver_leaves_within_two_percent_of_quadrature() {
    for rho_b in [0.05, 0.5] {
        let worst_of = |label: &str, args: &[&str]| {
            let errors = one_bounce_errors(&format!("one_bounce_{label}_{rho_b}"), rho_b, args);
            let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
            let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
            eprintln!("one bounce, rho_B {rho_b}, {label}: {} leaves of B, largest relative error {worst:.2e}, rms {rms:.2e}", errors.len());
            worst
        };
        let default = worst_of("default", &[]);
        assert!(default <= 0.02, "rho_B {rho_b}: a leaf of B is {default:.2e} off the quadrature reference");
        let relative = worst_of("relative_1e-3", &["--eps", "1e-3", "--criterion", "relative"]);
        assert!(relative <= 0.02, "rho_B {rho_b}, EPS 1e-3: a leaf of B is {relative:.2e} off the quadrature reference");
        if rho_b < 0.1 {
            let absolute = worst_of("absolute_1e-3", &["--eps", "1e-3", "--criterion", "absolute"]);
            assert!(absolute > 0.02, "rho_B {rho_b}: the absolute criterion also meets 2% at EPS 1e-3 ({absolute:.2e}); the test no longer tells them apart");
        }
    }
}

/// Issue 10, item 2, per pixel (paper 002's measure): the default `make`
/// image (grid-gather's preview) and the full gather of the one-bounce
/// configuration's receiver B, seen from between the two planes, against
/// [`one_bounce_reference`] at 3 x 3 points per pixel of the camera model
/// of [`pixel_points_on_ground`]; pixels whose every sample saw B (no
/// silhouette, no emitter) only. No pixel may be more than 10% off, and
/// under 1% of them more than 2%, at rho_B 0.5 and 0.05.
#[test]
fn one_bounce_receiver_image_pixels_within_paper_002_bounds() {
    let (rho_a, emission, size) = (0.5, 1.0, 96u32);
    for rho_b in [0.05, 0.5] {
        let mut scene = one_bounce(rho_a, rho_b, emission);
        scene.camera = ([1.5, -0.4, 0.45], [1.5, 0.5, 0.0]);
        let (_, dir) = solve(&format!("one_bounce_pixels_{rho_b}"), &scene, &[], false);
        let (mesh, manifest, solution) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("solution.exr"));
        let manifest_value = read_ron::<Manifest>(&manifest).unwrap().value;
        let b_object = manifest_value.objects.iter().position(|o| o == "B").unwrap() as u32;
        let size_arg = size.to_string();
        let render = |mode: &str| {
            let image = dir.join(format!("{mode}.exr"));
            run_ok("grid-gather", &["--mode", mode, "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--width", &size_arg, "--height", &size_arg]);
            schemas::image::HdrImage::read(&image).unwrap().0
        };
        let images = [("preview", render("preview")), ("full", render("full"))];
        // Both modes trace the same camera samples, so they see B in the
        // same pixels.
        let surfaces = images[0].1.surfaces.clone().expect("a surface layer");
        assert_eq!(images[1].1.surfaces.as_ref(), Some(&surfaces));
        let width = images[0].1.width;
        let pixels: Vec<usize> = (0..surfaces.object.len())
            .filter(|&p| surfaces.object[p] == b_object && surfaces.flags[p] & schemas::image::SINGLE_SURFACE != 0 && surfaces.flags[p] & schemas::image::EMITTER == 0)
            .collect();
        assert!(pixels.len() > 1000, "rho_B {rho_b}: only {} pixels of B", pixels.len());
        let points: Vec<[f64; 3]> = pixels.iter().flat_map(|&p| pixel_points_on_ground(&manifest_value, size, size, (p % width) as u32, (p / width) as u32, 3)).collect();
        let reference: Vec<f64> = one_bounce_reference(rho_a, rho_b, emission, &points).chunks(9).map(|r| r.iter().sum::<f64>() / 9.0 / std::f64::consts::PI).collect();
        for (mode, image) in &images {
            let errors: Vec<f64> = pixels.iter().zip(&reference).map(|(&p, exact)| (f64::from(image.rgb[p][0]) - exact).abs() / exact).collect();
            let worst = errors.iter().fold(0.0f64, |w, e| w.max(*e));
            let over_2 = errors.iter().filter(|e| **e > 0.02).count() as f64 / errors.len() as f64;
            eprintln!("one bounce pixels, rho_B {rho_b}, {mode}: {} pixels of B, largest error {worst:.2e}, {:.2}% over 2%", errors.len(), 100.0 * over_2);
            assert!(worst <= 0.10, "rho_B {rho_b}, {mode}: a pixel of B is {worst:.2e} off the quadrature reference");
            assert!(over_2 < 0.01, "rho_B {rho_b}, {mode}: {:.2}% of B's pixels are over 2% off", 100.0 * over_2);
        }
    }
}

/// Issue 10, item 6: a one-sided lamp (0.5 m square, 0.6 m up) tilted to
/// face down and towards -y, front normal (0, -0.6, -0.8); its plane meets
/// the floor at y = 0.8. A floor point beyond that line sees only the
/// lamp's back, which sends nothing: leaves wholly beyond it must stay
/// dark, and every leaf must have Lambert's irradiance of the lamp averaged
/// over the leaf's part in front (64 sub-triangle centroids; the factor is
/// continuous across the line, so the average converges fast), within 1%
/// where lit and 1e-4 of the peak everywhere. A factor two-sided in the
/// sender lit floor elements beyond the line with up to 1.35e-3 of the
/// peak; a fixed rule across the kink of a straddling leaf was 1.1e-4 of
/// the peak (37% of that leaf) off.
fn tilted_lamp(clustered: bool) {
    let (rho, emission) = (0.5, 1.0);
    let (c, u, v) = ([0.0, 0.0, 0.6], [0.25, 0.0, 0.0], [0.0, -0.2, 0.15]);
    let corner = |su: f64, sv: f64| std::array::from_fn::<f64, 3, _>(|a| c[a] + su * u[a] + sv * v[a]);
    let lamp = [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
    let mut scene = QuadScene { camera: ([0.0, -3.0, 2.0], [0.0, 0.0, 0.0]), ..Default::default() };
    scene.material("floor", rho, 0.0).material("lamp", 0.0, emission);
    scene.quad("floor", "floor", rectangle(2, 0.0, [-2.0, -2.0], [2.0, 2.0]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", lamp, [0.0, -0.6, -0.8]);
    let (solved, dir) = solve("tilted_lamp", &scene, &[], clustered);
    let (mesh, _) = Mesh::read(&dir.join("mesh.exr")).unwrap();
    let origin = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value.world_from_mesh_translation;
    let in_front = |x: [f64; 3]| -0.6 * (x[1] - c[1]) - 0.8 * (x[2] - c[2]) > 0.0;
    let irradiance = |x: [f64; 3]| if in_front(x) { lambert_polygon(x, [0.0, 0.0, 1.0], &lamp) } else { 0.0 };
    let leaves: Vec<([[f64; 3]; 3], f64)> = solved
        .leaves()
        .filter(|(object, ..)| *object == "floor")
        .map(|(_, _, b, i)| (leaf_world_corners(&mesh, origin, &solved.solution.elements[i]), b / (rho * emission)))
        .collect();
    let peak = leaves.iter().map(|(_, e)| *e).fold(0.0, f64::max);
    let (mut dark, mut checked, mut worst, mut worst_absolute) = (0, 0, 0.0f64, 0.0f64);
    for (corners, got) in &leaves {
        if corners.iter().all(|x| x[1] > 0.8) {
            assert!(*got <= 1e-6 * peak, "clustered {clustered}: a leaf behind the lamp's plane gets {:.2e} of the peak", got / peak);
            dark += 1;
            continue;
        }
        let exact = mean_over_triangle(corners, 3, &irradiance);
        worst_absolute = worst_absolute.max((got - exact).abs() / peak);
        if exact < 0.05 * peak {
            continue;
        }
        worst = worst.max(((got - exact) / exact).abs());
        checked += 1;
    }
    eprintln!("tilted lamp, clustered {clustered}: {dark} dark leaves, {checked} lit leaves, largest relative error {worst:.2e}, largest error of any leaf {worst_absolute:.2e} of the peak");
    assert!(dark >= 20 && checked >= 20, "only {dark} dark and {checked} lit leaves");
    assert!(worst <= 0.01, "clustered {clustered}: a lit leaf is {worst:.2e} off Lambert's formula");
    assert!(worst_absolute <= 1e-4, "clustered {clustered}: a leaf is {worst_absolute:.2e} of the peak off Lambert's formula");
}

#[test]
fn a_tilted_one_sided_lamp_lights_nothing_behind_its_plane() {
    tilted_lamp(false);
}

#[test]
fn a_tilted_one_sided_lamp_lights_nothing_behind_its_plane_with_clusters() {
    tilted_lamp(true);
}


//! hierarchical-solve where a solid stands on a receiver: the part of the
//! receiver under the solid receives and sends nothing, and an element
//! crossing the solid's footprint must show its exposed part's radiosity,
//! not its light spread over the buried part too (issue 10: the Cornell
//! box's floor held 1.6% of its radiosity-area under the blocks at `EPS`
//! 1e-2, and every surface it lights came out 0.5-2% dark).
//!
//! The scene: a floor (`z = 0`, 1 m square, reflectance 0.5) under a lamp
//! facing down at `z = 0.4`, and on the floor a black slab, a closed box
//! of 2 mm (one-sided faces outward, no bottom), whose footprint edges cut
//! across the floor's elements. Every floor point outside the footprint
//! has radiosity `rho E F`, `F` the lamp's factor with the slab's
//! occlusion (the midpoint rule over the lamp with the segment test
//! against the slab's box written here); a leaf's reference is the mean of
//! that over its part outside the footprint.

use end_to_end::{pixel_points_on_ground, prepare_and_solve, run_ok, s, scratch, Solved};
use schemas::image::{HdrImage, SINGLE_SURFACE};
use schemas::mesh::Manifest;
use schemas::ron_io::read_ron;
use std::f64::consts::PI;
use test_support::closed_form::{mean_over_triangle, midpoint_square_lamp};
use test_support::scenes::{rectangle, QuadScene};

const RHO: f64 = 0.5;
const EMISSION: f64 = 10.0;
/// The lamp: `x, y in [0.4, 0.6]`, `z = 0.4`, facing down.
const LAMP: ([f64; 2], f64) = ([0.4, 0.6], 0.4);
/// The slab's footprint, `x in [0.23, 0.41]`, `y in [0.27, 0.43]`, and its
/// height: off the floor's subdivision lines, so leaves straddle it.
const SLAB: ([f64; 2], [f64; 2], f64) = ([0.23, 0.41], [0.27, 0.43], 0.002);

fn scene() -> QuadScene {
    let mut scene = QuadScene { camera: ([0.5, -1.5, 0.8], [0.5, 0.5, 0.0]), ..Default::default() };
    scene.material("floor", RHO, 0.0).material("lamp", 0.0, EMISSION).material("black", 0.0, 0.0);
    scene.quad("floor", "floor", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", rectangle(2, LAMP.1, [LAMP.0[0], LAMP.0[0]], [LAMP.0[1], LAMP.0[1]]), [0.0, 0.0, -1.0]);
    let ([x0, x1], [y0, y1], h) = SLAB;
    scene.quad("slab", "black", rectangle(2, h, [x0, y0], [x1, y1]), [0.0, 0.0, 1.0]);
    scene.quad("slab", "black", rectangle(0, x0, [y0, 0.0], [y1, h]), [-1.0, 0.0, 0.0]);
    scene.quad("slab", "black", rectangle(0, x1, [y0, 0.0], [y1, h]), [1.0, 0.0, 0.0]);
    scene.quad("slab", "black", rectangle(1, y0, [0.0, x0], [h, x1]), [0.0, -1.0, 0.0]);
    scene.quad("slab", "black", rectangle(1, y1, [0.0, x0], [h, x1]), [0.0, 1.0, 0.0]);
    scene
}

/// Whether floor point `p` lies outside the slab's footprint.
fn exposed(p: [f64; 3]) -> bool {
    let ([x0, x1], [y0, y1], _) = SLAB;
    !((x0..=x1).contains(&p[0]) && (y0..=y1).contains(&p[1]))
}

/// Whether the segment from `p` to `q` crosses the slab's box (slab test).
fn blocked(p: [f64; 3], q: [f64; 3]) -> bool {
    let ([x0, x1], [y0, y1], h) = SLAB;
    let (lo, hi) = ([x0, y0, 0.0], [x1, y1, h]);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for a in 0..3 {
        let d = q[a] - p[a];
        if d.abs() < 1e-15 {
            if p[a] < lo[a] || p[a] > hi[a] {
                return false;
            }
            continue;
        }
        let (ta, tb) = ((lo[a] - p[a]) / d, (hi[a] - p[a]) / d);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    t0 < t1
}

/// `rho E` times the lamp's factor at exposed floor point `p`, by the
/// midpoint rule over 16 x 16 cells of the lamp with the segment test.
fn radiosity(p: [f64; 3]) -> f64 {
    RHO * EMISSION * midpoint_square_lamp(p, (LAMP.0[0], LAMP.0[1]), LAMP.1, 16, &blocked)
}

/// Distance from floor point `p` to the slab's footprint, m.
fn distance_to_footprint(p: &[f64; 3]) -> f64 {
    let ([x0, x1], [y0, y1], _) = SLAB;
    let (dx, dy) = ((x0 - p[0]).max(p[0] - x1).max(0.0), (y0 - p[1]).max(p[1] - y1).max(0.0));
    dx.hypot(dy)
}

/// Per floor leaf with at least `min_exposure` of its area outside the
/// footprint: `(exposed fraction, whether it lies over 1 cm from the
/// footprint, relative error)` against the mean of [`radiosity`] over its
/// exposed part (64 points).
fn leaf_errors(test: &str, args: &[&str], min_exposure: f64) -> Vec<(f64, bool, f64)> {
    let dir = scratch(test);
    let solved = Solved::new(&dir, &scene().write(&dir), args);
    let mut out = Vec::new();
    for (e, corners) in solved.leaves_of("floor") {
        let fraction = mean_over_triangle(&corners, 3, &|p| f64::from(u8::from(exposed(p))));
        if fraction < min_exposure {
            continue;
        }
        let want = mean_over_triangle(&corners, 3, &|p| if exposed(p) { radiosity(p) } else { 0.0 }) / fraction;
        let far = corners.iter().all(|p| distance_to_footprint(p) > 0.01);
        out.push((fraction, far, f64::from(e.radiosity[0]) / want - 1.0));
    }
    out
}

/// The straddling leaves' bias (mean error weighted by exposed area), their
/// L2 error, and the open leaves' worst, solved at `eps`.
fn summary(eps: &str) -> (f64, f64, f64, usize) {
    let errors = leaf_errors(&format!("buried_parts_{eps}"), &["--eps", eps], 0.3);
    let (mut bias, mut squares, mut weight, mut open, mut count) = (0.0, 0.0, 0.0, 0.0f64, 0);
    for &(fraction, far, error) in &errors {
        if fraction < 0.999 {
            bias += fraction * error;
            squares += fraction * error * error;
            weight += fraction;
            count += 1;
        } else if far {
            open = open.max(error.abs());
        }
    }
    let (bias, l2) = if weight > 0.0 { (bias / weight, (squares / weight).sqrt()) } else { (0.0, 0.0) };
    eprintln!("buried parts, EPS {eps}: {count} straddling leaves, bias {:+.2}%, L2 {:.2}%; open leaves worst {:.2}%", 100.0 * bias, 100.0 * l2, 100.0 * open);
    (bias, l2, open, count)
}

/// Measured (straddling leaves: bias, L2; open leaves over 1 cm from the
/// footprint: worst): with the light spread over the buried part, -21.5%,
/// 29.5%, 2.6% at `EPS` 1e-2; divided by the exposure, +0.5%, 8.4%, 2.5%,
/// and at the default `EPS` -1.4%, 11.5%, 0.03%. Since hierarchical-solve's
/// `RELATIVE_AT` went from 3 to 1/8 with the absolute threshold as a cap,
/// `EPS` 1e-2 is 4e-4 (the same relative threshold): +0.35%, 10.6%, 0.03%;
/// and the default (1.5e-5) -2.0%, 12.5%, 0.03%; later +0.49%, 6.95% and
/// -1.94%, 6.33%. Since refinement judges a link into such a leaf by the
/// visibility of its exposed part (`V / x`, `links::Link::on_exposed`)
/// rather than by `V`, which the rays from the buried part pull down to
/// about `x`: +1.75%, 7.89% at 4e-4 and +0.81%, 2.73% at 1.5e-5; since a
/// link into an inner element takes the visible fraction its parts
/// measured (hierarchical-solve's `receivers`), +0.08%, 2.03% at 1.5e-5;
/// since the last solve opens the leaves a shadow edge crosses at a
/// sixteenth of their radiosity, not a quarter (the straddling leaves'
/// neighbours), +2.76%, 7.93% at 4e-4 (was +1.75%, 7.89%: within the
/// noise of 64 leaves' mean at that L2) and +0.10%, 2.03% at 1.5e-5.
/// Since the last solve opens such leaves too where a shadow edge crosses
/// them (hierarchical-solve's `shadowed`): -1.00%, 7.17% at 4e-4 and
/// -0.39%, 1.81% at 1.5e-5; since a leaf's points under a roof already
/// proven buried take one ray (hierarchical-solve's `exposure`, other
/// points of the same strata): -0.87%, 6.84% and -0.40%, 1.58%. What is
/// left on a single straddling leaf is
/// the noise of its links' visibility rays, of which the buried part
/// stops some.
#[test]
fn a_leaf_crossing_a_solids_footprint_shows_its_exposed_parts_radiosity() {
    for (eps, bias_limit, l2_limit, open_limit) in [("4e-4", 0.03, 0.12, 0.04), ("1.5e-5", 0.005, 0.03, 0.01)] {
        let (bias, l2, open, count) = summary(eps);
        assert!(count > 10, "EPS {eps}: {count} leaves cross the footprint; the scene does not test");
        assert!(bias.abs() <= bias_limit, "EPS {eps}: the leaves crossing the footprint are {:+.2}% off their open part's radiosity on average", 100.0 * bias);
        assert!(l2 <= l2_limit, "EPS {eps}: the leaves crossing the footprint are {:.2}% off (L2)", 100.0 * l2);
        assert!(open <= open_limit, "EPS {eps}: an open leaf is {:.2}% off", 100.0 * open);
    }
}

/// The full gather per pixel of the floor beside the slab's face towards
/// the camera, against [`radiosity`] over the pixel's 3 x 3 points (all
/// exposed, 1 to 10 mm from the footprint: the slab's shadow reaches 1.7
/// mm from it), at contrast 0.001 so that the perceptual threshold's
/// allowance does not hide what is tested. A camera ray meets only the
/// exposed part of a leaf across the footprint, and that leaf's links
/// count the rays from its buried part as blocked: taken at their `V`
/// the pixels there were up to 5.5% dark (mean -0.6% within 2 mm); at
/// the exposed part's `min(1, V / x)` (grid-gather's
/// `Senders::exposed_visibility`) and with the leaf check's rays scaled
/// by `1 / x`, at most 1.24% (the brute-force gather: 0.86%).
#[test]
fn the_full_gather_lights_the_exposed_part_of_a_leaf_across_the_footprint() {
    let dir = scratch("buried_parts_full_gather");
    // 10 cm from the slab's face towards -y: a pixel is about half a
    // millimetre on the floor there.
    let mut scene = scene();
    scene.camera = ([0.32, 0.17, 0.06], [0.32, 0.27, 0.0]);
    let (mesh, manifest_path, solution) = prepare_and_solve(&dir, &scene.write(&dir), &["--eps", "4e-4"]);
    let manifest = read_ron::<Manifest>(&manifest_path).unwrap().value;
    let floor = manifest.objects.iter().position(|o| o == "floor").unwrap() as u32;
    let size = 160u32;
    let (image_path, size_arg) = (dir.join("full.exr"), size.to_string());
    let image_args = ["--mesh", s(&mesh), "--manifest", s(&manifest_path), "--solution", s(&solution), "-o", s(&image_path), "--width", &size_arg, "--height", &size_arg];
    run_ok("grid-gather", &[&["--mode", "full", "--contrast", "0.001"], &image_args[..]].concat());
    let image = HdrImage::read(&image_path).unwrap().0;
    let surfaces = image.surfaces.clone().expect("a surface layer");
    let width = image.width as usize;
    let errors: Vec<f64> = (0..surfaces.object.len())
        .filter(|&p| surfaces.object[p] == floor && surfaces.flags[p] & SINGLE_SURFACE != 0)
        .filter_map(|p| {
            let points = pixel_points_on_ground(&manifest, size, size, (p % width) as u32, (p / width) as u32, 3);
            let d = points.iter().map(distance_to_footprint).fold(f64::INFINITY, f64::min);
            let exact = points.iter().map(|&x| radiosity(x)).sum::<f64>() / 9.0 / PI;
            (0.001..0.01).contains(&d).then(|| f64::from(image.rgb[p][0]) / exact - 1.0)
        })
        .collect();
    let worst = errors.iter().fold(0.0f64, |w, x| w.max(x.abs()));
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    eprintln!("buried parts, full gather: {} pixels 1-10 mm from the footprint, mean {mean:+.2e}, worst {worst:.2e}", errors.len());
    assert!(errors.len() > 1000, "the camera sees {} pixels beside the footprint", errors.len());
    assert!(worst <= 0.02, "a pixel beside the footprint is {worst:.2e} off");
}

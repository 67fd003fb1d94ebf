//! Two-sided materials (issue 11, item 8): a leaf lit from below shows its
//! lit underside to a camera below it, in the solution and in both
//! gathers, while its upper face, which sees nothing, stays dark; without
//! `two_sided` the same underside is the leaf's back face and is black.
//!
//! The scene: a 1 m square leaf (reflectance 1/2) 1 m above a 0.4 m square
//! lamp (exitance 1 W/m²) that faces up at it; nothing else. The leaf's
//! underside receives Lambert's irradiance of the lamp, `E(x)`, and
//! reflects `B = rho E`; its top sees only empty space: `B = 0`.

use end_to_end::{refused, run_ok, s, scratch, solve_prepared};
use schemas::image::HdrImage;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use std::path::{Path, PathBuf};
use test_support::artifacts::leaf_world_corners;
use test_support::closed_form::{lambert_polygon, mean_over_triangle};
use test_support::scenes::{rectangle, QuadScene};

const RHO: f64 = 0.5;
const LAMP: [[f64; 3]; 4] = [[-0.2, -0.2, 0.0], [0.2, -0.2, 0.0], [0.2, 0.2, 0.0], [-0.2, 0.2, 0.0]];

/// The leaf-over-lamp scene, the leaf two-sided or not, prepared by
/// mesh-prep in a scratch directory.
fn prepared(test: &str, two_sided: bool) -> PathBuf {
    let dir = scratch(test);
    let mut scene = QuadScene { camera: ([1.2, 0.4, 0.3], [0.0, 0.0, 0.8]), ..Default::default() };
    scene.material("leaf", RHO, 0.0).material("lamp", 0.0, 1.0);
    scene.quad("leaf", "leaf", rectangle(2, 1.0, [-0.5, -0.5], [0.5, 0.5]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", LAMP, [0.0, 0.0, 1.0]);
    if two_sided {
        scene.two_sided.push("leaf".into());
    }
    let path = scene.write(&dir);
    run_ok("mesh-prep", &[s(&path), "--mesh", s(&dir.join("mesh.exr")), "--manifest", s(&dir.join("manifest.ron"))]);
    dir
}

/// Every leaf element of the leaf with its face's normal z and its
/// radiosity relative to the closed form `rho E` averaged over the element
/// (64 sub-triangles); the peak of that closed form.
fn leaf_elements(dir: &Path, solution: &Path) -> (Vec<(f32, f64, f64)>, f64) {
    let (mesh, _) = Mesh::read(&dir.join("mesh.exr")).unwrap();
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    let (solution, _) = Solution::read(solution).unwrap();
    let leaf = manifest.objects.iter().position(|o| o == "leaf").unwrap() as u32;
    let origin = manifest.world_from_mesh_translation;
    let below = |x: [f64; 3]| RHO * lambert_polygon(x, [0.0, 0.0, -1.0], &LAMP);
    let elements = solution
        .elements
        .iter()
        .filter(|e| e.first_child == u32::MAX && mesh.triangles[e.triangle as usize].object == leaf)
        .map(|e| {
            let nz = mesh.triangles[e.triangle as usize].normal[2];
            let want = if nz < 0.0 { mean_over_triangle(&leaf_world_corners(&mesh, origin, e), 3, &below) } else { 0.0 };
            (nz, f64::from(e.radiosity[1]), want)
        })
        .collect();
    (elements, below([0.0, 0.0, 1.0]))
}

fn leaf_is_lit_from_below_on_its_underside_only(clustered: bool) {
    let dir = prepared(&format!("two_sided_leaf{}", if clustered { "_clustered" } else { "" }), true);
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    assert_eq!(manifest.statistics.two_sided_twins, 2, "the leaf's two triangles get a twin each");
    let solution = solve_prepared(&dir, &[], clustered.then_some(1));
    let (elements, peak) = leaf_elements(&dir, &solution);
    let (mut under, mut top, mut worst) = (0, 0, 0.0f64);
    for (nz, got, want) in elements {
        if nz < 0.0 {
            under += 1;
            worst = worst.max((got - want).abs() / want);
        } else {
            top += 1;
            assert!(got.abs() <= 1e-6 * peak, "a top element of the leaf, which sees nothing, has B = {got:e} (peak {peak:e})");
        }
    }
    eprintln!("two-sided leaf: {under} underside and {top} top elements; largest underside error {worst:.2e}");
    assert!(under >= 2 && top >= 2);
    assert!(worst <= 0.01, "an underside element is {worst:.2e} off rho E");
}

#[test]
fn a_two_sided_leaf_is_lit_from_below_on_its_underside_only() {
    leaf_is_lit_from_below_on_its_underside_only(false);
}

#[test]
fn a_two_sided_leaf_is_lit_from_below_on_its_underside_only_with_clusters() {
    leaf_is_lit_from_below_on_its_underside_only(true);
}

/// A gather of `dir`'s solution (`mode`: preview or full): the radiance
/// (green channel) of every pixel and whether it sees the leaf; the
/// stage's stderr.
fn gather(dir: &Path, mode: &str) -> (Vec<(f64, bool)>, String) {
    let image = dir.join(format!("{mode}.exr"));
    let [mesh, manifest, solution, clusters] = ["mesh.exr", "manifest.ron", "solution.exr", "clusters.exr"].map(|f| dir.join(f));
    let mut args = vec![
        "--mesh",
        s(&mesh),
        "--manifest",
        s(&manifest),
        "--solution",
        s(&solution),
        "--mode",
        mode,
        "-o",
        s(&image),
    ];
    if clusters.exists() {
        args.extend(["--clusters", s(&clusters)]);
    }
    let stderr = String::from_utf8_lossy(&run_ok("grid-gather", &args).stderr).into_owned();
    let manifest = read_ron::<Manifest>(&manifest).unwrap().value;
    let leaf = manifest.objects.iter().position(|o| o == "leaf").unwrap() as u32;
    let (image, _) = HdrImage::read(&image).unwrap();
    let surfaces = image.surfaces.expect("the gather writes its surface layer");
    (image.rgb.iter().zip(&surfaces.object).map(|(p, &o)| (f64::from(p[1]), o == leaf)).collect(), stderr)
}

/// Seen from below, every pixel of the two-sided leaf shows its lit
/// underside: radiance in (0, rho E_max / pi] (no pixel where a ray picked
/// the dark top face of the coincident pair), and the brightest within 2%
/// of that peak (the camera sees the leaf's centre); in the one-sided
/// leaf's image those pixels show its back face: all black, with a warning
/// that names the two-sided option.
#[test]
fn a_camera_below_sees_the_lit_underside_only_when_the_leaf_is_two_sided() {
    let dir = prepared("two_sided_leaf_gathers", true);
    solve_prepared(&dir, &[], Some(1));
    let peak = RHO * lambert_polygon([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], &LAMP) / std::f64::consts::PI;
    let mut seen = Vec::new();
    for mode in ["preview", "full"] {
        let (image, stderr) = gather(&dir, mode);
        assert!(!stderr.contains("back faces"), "{stderr}");
        seen = image.iter().map(|(_, leaf)| *leaf).collect();
        let pixels: Vec<f64> = image.iter().filter(|(_, leaf)| *leaf).map(|(p, _)| *p).collect();
        let (lo, hi) = pixels.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        eprintln!("{mode}: {} leaf pixels, radiance {lo:.4e} to {hi:.4e}, peak {peak:.4e}", pixels.len());
        assert!(pixels.len() > 200, "{mode}: the camera sees the leaf");
        assert!(lo > 0.05 * peak, "{mode}: a leaf pixel is dark ({lo:e}): a ray saw the top face");
        assert!((hi - peak).abs() <= 0.02 * peak, "{mode}: brightest leaf pixel {hi:e} vs rho E / pi {peak:e}");
    }
    let one_sided = prepared("one_sided_leaf_gathers", false);
    solve_prepared(&one_sided, &[], Some(1));
    let (image, stderr) = gather(&one_sided, "preview");
    assert!(stderr.contains("warning") && stderr.contains("back faces") && stderr.contains("two_sided"), "the black leaf gets a word: {stderr}");
    assert!(image.iter().zip(&seen).all(|((p, _), &leaf)| !leaf || *p == 0.0), "the one-sided leaf's back face is black");
}

/// A two-sided emitter is refused by name: emission is one-sided.
#[test]
fn a_two_sided_emitter_is_refused() {
    let dir = scratch("two_sided_emitter");
    let mut scene = QuadScene { camera: ([1.2, 0.4, 0.3], [0.0, 0.0, 0.8]), ..Default::default() };
    scene.material("lamp", 0.0, 1.0).quad("lamp", "lamp", LAMP, [0.0, 0.0, 1.0]);
    scene.two_sided.push("lamp".into());
    let path = scene.write(&dir);
    let mesh = dir.join("mesh.exr");
    let line = refused("mesh-prep", &[s(&path), "--mesh", s(&mesh), "--manifest", s(&dir.join("manifest.ron"))]);
    assert!(line.contains("material 'lamp'") && line.contains("cannot be two-sided"), "{line}");
    assert!(!mesh.exists());
}

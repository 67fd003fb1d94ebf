//! Hierarchical radiosity with clustering at scale, against closed forms:
//! energy balance of a finely tessellated closed box, the uniform radiosity
//! of an integrating sphere, and agreement with the unclustered solver.

use end_to_end::{run_ok, s, scratch, solve_prepared};
use schemas::mesh::Manifest;
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use std::path::{Path, PathBuf};

/// Prepares built-in scene `name` into a scratch directory.
fn builtin(test: &str, name: &str) -> PathBuf {
    let dir = scratch(test);
    run_ok("mesh-prep", &["--builtin", name, "--mesh", s(&dir.join("mesh.exr")), "--manifest", s(&dir.join("manifest.ron"))]);
    dir
}

/// The manifest and the solution's leaves as (triangle, area, radiosity).
fn leaves(dir: &Path, solution: &Path) -> (Manifest, Vec<(u32, f64, [f32; 3])>) {
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    let (solution, _) = Solution::read(solution).unwrap();
    let leaves = solution.elements.iter().filter(|e| e.is_leaf()).map(|e| (e.triangle, f64::from(e.area), e.radiosity)).collect();
    (manifest, leaves)
}

#[test]
fn a_closed_box_of_100k_triangles_conserves_energy_with_clusters() {
    // box-100k: walls of uniform reflectance 0.8, a ceiling square emitting.
    let dir = builtin("box_100k", "box-100k");
    let solution = solve_prepared(&dir, &["--eps", "1e-2"], Some(8));
    let (manifest, leaves) = leaves(&dir, &solution);
    assert!(manifest.statistics.triangles > 90_000, "{} triangles", manifest.statistics.triangles);
    let rho = manifest.materials.iter().map(|m| m.diffuse[0]).fold(0.0, f64::max);
    assert!(manifest.materials.iter().all(|m| m.diffuse == [rho; 3]), "uniform reflectance");
    let total_area = manifest.statistics.total_area;
    let expected = manifest.statistics.emitted_power[0] / ((1.0 - rho) * total_area);
    let (mut weighted, mut area) = (0.0, 0.0);
    for (t, a, b) in &leaves {
        assert!(b.iter().all(|x| x.is_finite() && *x >= 0.0), "triangle {t}: {b:?}");
        weighted += a * f64::from(b[0]);
        area += a;
    }
    let error = (weighted / area - expected).abs() / expected;
    eprintln!("box-100k: mean radiosity {} vs {expected}: relative error {error:.2e}", weighted / area);
    assert!((area - total_area).abs() < 1e-3 * total_area);
    assert!(error < 0.01, "mean radiosity {} vs closed form {expected}", weighted / area);
}

#[test]
fn every_surface_of_an_integrating_sphere_has_the_closed_form_radiosity() {
    // From any point of a sphere, every patch j subtends F = A_j / A, so the
    // irradiance is the same everywhere: H = P / A with P the total power
    // leaving all surfaces, P = Phi / (1 - rho); off the lamp B = rho H.
    let dir = builtin("sphere", "sphere-5k");
    let solution = solve_prepared(&dir, &["--eps", "1e-2"], Some(8));
    let (manifest, leaves) = leaves(&dir, &solution);
    let (mesh, _) = schemas::mesh::Mesh::read(&dir.join("mesh.exr")).unwrap();
    let lamp = manifest.materials.iter().position(|m| m.emission[0] > 0.0).unwrap() as u32;
    let rho = manifest.materials[lamp as usize].diffuse[0];
    let expected = rho * manifest.statistics.emitted_power[0] / ((1.0 - rho) * manifest.statistics.total_area);
    let mut worst = 0.0f64;
    for (t, _, b) in &leaves {
        if mesh.triangles[*t as usize].material == lamp {
            continue;
        }
        let error = (f64::from(b[0]) - expected).abs() / expected;
        worst = worst.max(error);
        assert!(error < 0.02, "triangle {t}: radiosity {} vs closed form {expected}", b[0]);
    }
    eprintln!("sphere: worst relative error {worst:.2e} over {} leaves", leaves.len());
}

#[test]
fn clustered_and_unclustered_previews_agree_on_a_tessellated_cornell_box() {
    let dir = builtin("cornell_2k", "cornell-box-2k");
    let args = ["--eps", "1e-3", "--visibility-rays", "4"];
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    let mut previews = Vec::new();
    for clustered in [false, true] {
        let solution = solve_prepared(&dir, &args, clustered.then_some(8));
        let kept = dir.join(format!("solution-{clustered}.exr"));
        std::fs::rename(&solution, &kept).unwrap();
        let preview = dir.join(format!("preview-{clustered}.exr"));
        run_ok("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&kept), "-o", s(&preview), "--width", "96", "--height", "96"]);
        previews.push(preview);
    }
    let report = dir.join("compare.ron");
    let out = end_to_end::run("compare", &[s(&previews[1]), s(&previews[0]), "-o", s(&report), "--max-rel-rmse", "0.02"]);
    let text = std::fs::read_to_string(&report).unwrap();
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "relative RMSE over 2%: {text}");
    assert!(text.contains("relative_rmse"), "{text}");
}

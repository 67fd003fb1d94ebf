//! Bad input gets a one-line error naming the file (and the line where
//! known), exit code 2, and no output file.

use end_to_end::{assert_refusal, assert_refused, gpu_missing, run, run_ok, s, scratch};
use std::path::{Path, PathBuf};
use test_support::scenes::{closed_box, rectangle, QuadScene};

/// A valid little scene in a fresh directory; returns (dir, scene path).
fn scene(test: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let path = closed_box(1.0, 0.5, 1.0).write(&dir);
    (dir, path)
}

fn prep_refused(dir: &Path, scene: &Path, needles: &[&str]) {
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    assert_refused("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)], needles, &[&mesh, &manifest]);
}

#[test]
fn missing_obj() {
    let (dir, scene) = scene("missing_obj");
    std::fs::remove_file(dir.join("scene.obj")).unwrap();
    prep_refused(&dir, &scene, &["scene.obj", "No such file"]);
}

#[test]
fn malformed_obj_line_is_named_by_line() {
    let (dir, scene) = scene("malformed_obj");
    let obj = std::fs::read_to_string(dir.join("scene.obj")).unwrap();
    let broken = obj.replacen("f -4 -3 -2 -1", "f -4 -3 -2 banana", 1);
    std::fs::write(dir.join("scene.obj"), &broken).unwrap();
    let line = broken.lines().position(|l| l.contains("banana")).unwrap() + 1;
    prep_refused(&dir, &scene, &[&format!("scene.obj:{line}:"), "banana"]);
}

#[test]
fn nan_coordinate_is_named_by_line() {
    let (dir, scene) = scene("nan_coordinate");
    let obj = std::fs::read_to_string(dir.join("scene.obj")).unwrap();
    let first_vertex = obj.lines().position(|l| l.starts_with("v ")).unwrap();
    let broken: Vec<String> =
        obj.lines().enumerate().map(|(i, l)| if i == first_vertex + 2 { "v 0.0 NaN 1.0".to_string() } else { l.to_string() }).collect();
    std::fs::write(dir.join("scene.obj"), broken.join("\n")).unwrap();
    prep_refused(&dir, &scene, &[&format!("scene.obj:{}:", first_vertex + 3), "not finite"]);
}

#[test]
fn misspelt_scene_field_is_named_by_line() {
    let (dir, scene) = scene("scene_typo");
    let text = std::fs::read_to_string(&scene).unwrap();
    let broken = text.replacen("vertical_fov_deg", "vertical_fov_degs", 1);
    std::fs::write(&scene, &broken).unwrap();
    let line = broken.lines().position(|l| l.contains("vertical_fov_degs")).unwrap() + 1;
    prep_refused(&dir, &scene, &[&format!("scene.ron:{line}:"), "vertical_fov_degs"]);
}

#[test]
fn unknown_material_override_is_refused() {
    let dir = scratch("override_typo");
    let mut scene = QuadScene { camera: ([0.0, -2.0, 0.5], [0.0, 0.0, 0.0]), ..Default::default() };
    scene.material("white", 0.5, 1.0);
    scene.quad("q", "white", test_support::scenes::rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    let path = scene.write(&dir);
    let text = std::fs::read_to_string(&path).unwrap().replace("\"white\":", "\"whtie\":");
    std::fs::write(&path, text).unwrap();
    prep_refused(&dir, &path, &["scene.ron", "whtie"]);
}

/// Prepares the scene of `dir` and returns (mesh, manifest).
fn prepared(dir: &Path, scene: &Path) -> (PathBuf, PathBuf) {
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    (mesh, manifest)
}

#[test]
fn unknown_schema_version_of_a_ron_artifact() {
    let (dir, scene) = scene("ron_version");
    let (mesh, manifest) = prepared(&dir, &scene);
    let current = format!("version: {},", <schemas::mesh::Manifest as schemas::header::Schema>::VERSION);
    let text = std::fs::read_to_string(&manifest).unwrap();
    assert!(text.contains(&current), "the manifest names its version as {current}");
    std::fs::write(&manifest, text.replacen(&current, "version: 99,", 1)).unwrap();
    let solution = dir.join("solution.exr");
    assert_refused(
        "hierarchical-solve",
        &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution)],
        &["manifest.ron", "version 99", &format!("version {}", <schemas::mesh::Manifest as schemas::header::Schema>::VERSION)],
        &[&solution],
    );
}

#[test]
fn unknown_schema_version_of_an_exr_artifact() {
    let (dir, scene) = scene("exr_version");
    let (mesh, manifest) = prepared(&dir, &scene);
    let mut bytes = std::fs::read(&mesh).unwrap();
    let at = bytes.windows(11).position(|w| w == b"version: 1,").expect("header text in the EXR");
    bytes[at..at + 11].copy_from_slice(b"version: 7,");
    std::fs::write(&mesh, bytes).unwrap();
    let solution = dir.join("solution.exr");
    assert_refused(
        "hierarchical-solve",
        &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution)],
        &["mesh.exr", "version 7", "version 1"],
        &[&solution],
    );
}

#[test]
fn a_wrong_kind_of_artifact_is_refused() {
    let (dir, scene) = scene("wrong_kind");
    let (mesh, manifest) = prepared(&dir, &scene);
    let solution = dir.join("solution.exr");
    assert_refused(
        "hierarchical-solve",
        &["--mesh", s(&mesh), "--manifest", s(&mesh), "-o", s(&solution)],
        &["mesh.exr"],
        &[&solution],
    );
    let _ = manifest;
}

#[test]
fn output_directory_that_cannot_be_written() {
    let (dir, scene) = scene("unwritable");
    let missing = dir.join("no").join("such").join("dir");
    let (mesh, manifest) = (missing.join("mesh.exr"), dir.join("manifest.ron"));
    assert_refused("mesh-prep", &[s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)], &["no/such/dir/mesh.exr"], &[&manifest]);
    // A file where a directory should be.
    std::fs::write(dir.join("file"), b"").unwrap();
    let (mesh_ok, manifest_ok) = prepared(&dir, &scene);
    let solution = dir.join("file").join("solution.exr");
    assert_refused(
        "hierarchical-solve",
        &["--mesh", s(&mesh_ok), "--manifest", s(&manifest_ok), "-o", s(&solution)],
        &["file/solution.exr"],
        &[],
    );
}

/// A scene whose emission is within f32's range but whose interreflected
/// radiosity is not (rho 0.9 multiplies it by up to 10): hierarchical-solve
/// wrote a solution holding inf, with exit 0, and grid-gather refused it
/// ("field B.R is inf"); the solver now refuses, saying what to change.
#[test]
fn a_radiosity_beyond_the_solutions_float_range_is_refused_by_the_solver() {
    let dir = scratch("radiosity_overflow");
    let (mesh, manifest) = prepared(&dir, &closed_box(1.0, 0.9, 3e38).write(&dir));
    let solution = dir.join("solution.exr");
    assert_refused(
        "hierarchical-solve",
        &["--mesh", s(&mesh), "--manifest", s(&manifest), "--eps", "1e-2", "-o", s(&solution)],
        &["mesh.exr", "32-bit floats", "scale the emission down"],
        &[&solution],
    );
}

/// gpu-shoot shoots in 32-bit floats: a lamp of 3.4e38 W/m² that also
/// reflects (rho 0.9) over a floor of rho 0.9 came out `inf`, written with
/// exit 0 (grid-gather then refused "field B.R is inf"); now refused,
/// nothing written.
#[test]
fn a_radiosity_beyond_32_bit_floats_is_refused_by_gpu_shoot() {
    let dir = scratch("radiosity_overflow_gpu");
    let mut scene = QuadScene { camera: ([0.5, -1.5, 0.8], [0.5, 0.5, 0.0]), ..Default::default() };
    scene.material("floor", 0.9, 0.0).material("lamp", 0.9, 3.4e38);
    scene.quad("floor", "floor", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", rectangle(2, 0.4, [0.1, 0.1], [0.25, 0.25]), [0.0, 0.0, -1.0]);
    let (mesh, manifest) = prepared(&dir, &scene.write(&dir));
    let solution = dir.join("solution.exr");
    let out = run("gpu-shoot", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution)]);
    if gpu_missing(&out, "a_radiosity_beyond_32_bit_floats_is_refused_by_gpu_shoot") {
        return;
    }
    assert_refusal("gpu-shoot", &out, &["mesh.exr", "32-bit floats", "scale the emission down"], &[&solution]);
}

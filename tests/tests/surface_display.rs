//! Surface detail in the display and diffuse transmission as a material
//! (issue 13, items 2 to 5 and 8 for grid-gather, item 5's parsing in
//! mesh-prep).
//!
//! mesh-prep: a translucent MTL material (`illum` 0 to 2, `d` < 1, `Tf`)
//! and a `scene.ron` override give the diffuse transmittance the manifest
//! records; a material that would scatter more than it receives is one line
//! naming the file, the material and the fields, exit 2, no output.

use end_to_end::scenes::closed_box;
use end_to_end::{assert_refused, run_ok, s, scratch};
use schemas::mesh::Manifest;
use schemas::ron_io::read_ron;
use std::path::{Path, PathBuf};

/// The closed box of `closed_box` in a fresh directory with `mtl` appended
/// to its MTL library (a material `sheet` used by a small quad inside the
/// box) and `overrides` added to scene.ron's materials; returns (dir,
/// scene path).
fn box_with_sheet(test: &str, mtl: &str, overrides: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let mut scene = closed_box(1.0, 0.5, 1.0);
    scene.quad("sheet", "sheet", end_to_end::scenes::rectangle(2, 0.5, [0.25, 0.25], [0.75, 0.75]), [0.0, 0.0, 1.0]);
    let path = scene.write(&dir);
    let library = dir.join("scene.mtl");
    let text = std::fs::read_to_string(&library).unwrap();
    std::fs::write(&library, format!("{text}newmtl sheet\n{mtl}")).unwrap();
    let ron = std::fs::read_to_string(&path).unwrap().replacen("materials: {\n", &format!("materials: {{\n{overrides}"), 1);
    std::fs::write(&path, ron).unwrap();
    (dir, path)
}

/// mesh-prep's mesh and manifest paths in `dir`.
fn outputs(dir: &Path) -> [PathBuf; 2] {
    [dir.join("mesh.exr"), dir.join("manifest.ron")]
}

/// The material `name` of the manifest mesh-prep writes for `scene`.
fn prepared_material(dir: &Path, scene: &Path, name: &str) -> (schemas::mesh::Material, bool) {
    let [mesh, manifest] = outputs(dir);
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let manifest = read_ron::<Manifest>(&manifest).unwrap().value;
    let m = manifest.materials.iter().find(|m| m.name == name).unwrap().clone();
    (m, manifest.effects.diffuse_transmission)
}

#[test]
fn a_dissolved_diffuse_mtl_material_transmits_diffusely() {
    let (dir, scene) = box_with_sheet("translucent_mtl", "Kd 0.3\nillum 2\nd 0.4\nTf 1 0.5 0.25\n", "");
    let (sheet, effect) = prepared_material(&dir, &scene, "sheet");
    assert_eq!((sheet.diffuse, sheet.diffuse_transmittance), ([0.3; 3], [0.6, 0.3, 0.15]), "tau_d = (1 - d) Tf");
    assert_eq!(sheet.specular_transmittance, [0.0; 3]);
    assert!(effect, "the manifest lists diffuse transmission");
}

#[test]
fn an_opaque_material_with_an_exporters_tf_transmits_nothing() {
    let (dir, scene) = box_with_sheet("opaque_tf", "Kd 0.8\nillum 2\nd 1\nTf 1 1 1\n", "");
    let (sheet, effect) = prepared_material(&dir, &scene, "sheet");
    assert_eq!(sheet.diffuse_transmittance, [0.0; 3]);
    assert!(!effect);
}

#[test]
fn the_scene_override_sets_the_diffuse_transmittance() {
    let overrides = "    \"sheet\": (diffuse: Some((0.25, 0.25, 0.25)), diffuse_transmittance: Some((0.5, 0.25, 0.75))),\n";
    let (dir, scene) = box_with_sheet("translucent_override", "Kd 0.9\n", overrides);
    let (sheet, effect) = prepared_material(&dir, &scene, "sheet");
    assert_eq!((sheet.diffuse, sheet.diffuse_transmittance), ([0.25; 3], [0.5, 0.25, 0.75]));
    assert!(effect);
}

#[test]
fn a_material_scattering_more_than_it_receives_is_refused_naming_file_material_and_fields() {
    let (dir, scene) = box_with_sheet("translucent_too_bright_mtl", "Kd 0.5\nd 0.25\n", "");
    let [mesh, manifest] = outputs(&dir);
    let args = [s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)];
    let needles = ["scene.mtl:", "material 'sheet'", "diffuse + diffuse_transmittance is 1.25 in channel 0, more than 1"];
    assert_refused("mesh-prep", &args, &needles, &[&mesh, &manifest]);

    let overrides = "    \"sheet\": (diffuse_transmittance: Some((0.0, 0.75, 0.0))),\n";
    let (dir, scene) = box_with_sheet("translucent_too_bright_override", "Kd 0.5\n", overrides);
    let [mesh, manifest] = outputs(&dir);
    let args = [s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)];
    let needles = ["scene.ron", "material 'sheet'", "diffuse + diffuse_transmittance is 1.25 in channel 1"];
    assert_refused("mesh-prep", &args, &needles, &[&mesh, &manifest]);
}

//! The binary end to end: files in, image and report out, exit codes,
//! one-line errors, no output on error, byte-identical reruns.

use schemas::header::{Provenance, Schema};
use schemas::image::HdrImage;
use schemas::mesh::{Camera, Effects, Manifest, Material, Mesh, MeshStatistics, Triangle};
use schemas::report::Report;
use schemas::ron_io::{read_ron, write_ron};
use schemas::solution::{Element, Solution};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn provenance() -> Provenance {
    Provenance::in_memory("test")
}

/// A fresh directory for one test.
fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("grid-gather-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The unit square facing +z (two triangles, radiosity 1 and 3, not
/// subdivided), a camera in front of it with textures in the effects, and
/// as many root elements as `roots`.
fn write_scene(dir: &Path, roots: u32) {
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let tri = |vertices| Triangle { vertices, material: 0, object: 0, area: 0.5, normal: [0.0, 0.0, 1.0] };
    let mesh = Mesh { header: Mesh::header(provenance()), positions, triangles: vec![tri([0, 1, 2]), tri([0, 2, 3])] };
    mesh.write(&dir.join("mesh.exr")).unwrap();
    let black = [0.0; 3];
    let manifest = Manifest {
        header: Manifest::header(provenance()),
        world_from_mesh_translation: [0.0; 3],
        camera: Camera { eye: [0.5, 0.5, 2.0], target: [0.5, 0.5, 0.0], up: [0.0, 1.0, 0.0], vertical_fov_deg: 40.0, width: 24, height: 16 },
        materials: vec![Material { diffuse_map: Some("wood.png".into()), ..Material::diffuse("grey", [0.5; 3], black) }],
        objects: vec!["square".into()],
        goniometric_lights: vec![],
        effects: Effects { textures: true, ..Effects::default() },
        statistics: MeshStatistics::default(),
    };
    write_ron(&dir.join("manifest.ron"), &manifest).unwrap();
    let root = |t: u32| Element::root(t, 0.5, [1.0 + 2.0 * t as f32; 3]);
    let solution = Solution { header: Solution::header(provenance()), elements: (0..roots).map(root).collect(), clusters: vec![], links: vec![], slopes: vec![] };
    solution.write(&dir.join("solution.exr")).unwrap();
}

fn gather(dir: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grid-gather"))
        .current_dir(dir)
        .args(["--mesh", "mesh.exr", "--manifest", "manifest.ron", "--solution", "solution.exr", "-o", "image.exr"])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn renders_the_scene_with_provenance_and_report_and_reruns_byte_identical() {
    let dir = workdir("ok");
    write_scene(&dir, 2);
    let out = gather(&dir, &["--report", "report.ron"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stdout.is_empty(), "stdout is data or nothing");
    let (image, _) = HdrImage::read(&dir.join("image.exr")).unwrap();
    assert_eq!((image.width, image.height), (24, 16), "the camera's size by default");
    let centre = image.rgb[8 * 24 + 12][0];
    assert!(image.coverage[8 * 24 + 12] == 1.0 && centre > 0.5 && centre < 0.8, "about 2/pi on the diagonal: {centre}");
    let p = &image.header.provenance;
    assert_eq!(p.stage, "grid-gather");
    assert_eq!(p.parameters.clone().into_rust::<grid_gather::Params>().unwrap(), grid_gather::Params::default());
    assert_eq!(p.inputs.iter().map(|i| i.path.as_str()).collect::<Vec<_>>(), ["mesh.exr", "manifest.ron", "solution.exr"]);
    let report = read_ron::<Report>(&dir.join("report.ron")).unwrap().value;
    assert_eq!(report.counters["rays_cast"], 24.0 * 16.0 * 4.0);
    assert_eq!(report.counters["leaf_elements"], 2.0);
    // The square's two leaves, each shown as four (leaf gradients): the
    // points of a 3 x 3 grid.
    assert_eq!(report.counters["vertices"], 9.0);
    assert!(report.skipped.iter().any(|s| s.starts_with("diffuse textures")), "{:?}", report.skipped);

    let first = std::fs::read(dir.join("image.exr")).unwrap();
    assert!(gather(&dir, &["--report", "report.ron"]).status.success());
    assert!(first == std::fs::read(dir.join("image.exr")).unwrap(), "reruns are byte-identical");

    assert!(gather(&dir, &["--width", "8", "--height", "6", "--spp", "1"]).status.success());
    let (small, _) = HdrImage::read(&dir.join("image.exr")).unwrap();
    assert_eq!((small.width, small.height), (8, 6));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_are_one_line_naming_the_file_and_leave_no_output() {
    let dir = workdir("err");
    write_scene(&dir, 1);
    let out = gather(&dir, &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("solution.exr") && stderr.contains("solution does not belong to this mesh"), "{stderr}");
    assert!(!dir.join("image.exr").exists());

    write_scene(&dir, 2);
    let out = gather(&dir, &["--mode", "full", "--threshold", "t.exr"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("t.exr") && stderr.lines().count() == 1, "{stderr}");
    let out = gather(&dir, &["--threshold", "t.exr"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--threshold"));
    assert!(!dir.join("image.exr").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn print_params_reads_back_through_params() {
    let dir = workdir("params");
    let run = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_grid-gather")).current_dir(&dir).args(args).output().unwrap();
    let out = run(&["--print-params", "--spp", "9", "--width", "100", "--no-material-seams"]);
    assert!(out.status.success());
    std::fs::write(dir.join("p.ron"), &out.stdout).unwrap();
    let again = run(&["--params", "p.ron", "--print-params"]);
    assert_eq!(out.stdout, again.stdout);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("spp: 9") && text.contains("width: Some(100)") && text.contains("material_seams: false"), "{text}");
    std::fs::write(dir.join("typo.ron"), "(spp: 2, sp: 3)").unwrap();
    let out = run(&["--params", "typo.ron", "--print-params"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("typo.ron"));
    std::fs::remove_dir_all(&dir).unwrap();
}

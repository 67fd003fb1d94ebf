//! Helpers for the end-to-end tests: where the stage binaries are, scratch
//! directories, running a stage and reading its refusal, the fuzz harness.
//! The scenes written from code, the closed forms the tests compare with
//! and the in-memory artifacts are the shared fixtures of `test-support`.
//!
//! The binaries are those of `cargo build --release`, which `make test`
//! runs before the tests.

pub mod fuzz;
pub mod stages;

use schemas::mesh::{Camera, Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::{Element, Solution};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use test_support::artifacts::leaf_world_corners;

/// Path of the stage binary `name` next to this test executable.
pub fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().and_then(Path::parent).expect("target profile directory");
    let path = dir.join(name);
    assert!(path.exists(), "{} is missing: run `make test` (it builds the stages first)", path.display());
    path
}

/// A fresh, empty scratch directory for one test.
pub fn scratch(test: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().and_then(Path::parent).expect("target profile directory").join("e2e").join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Runs stage `name` with `args`.
pub fn run(name: &str, args: &[&str]) -> Output {
    Command::new(bin(name)).args(args).output().expect("stage binary runs")
}

/// Runs stage `name` and panics with its stderr if it fails.
pub fn run_ok(name: &str, args: &[&str]) -> Output {
    let out = run(name, args);
    assert!(out.status.success(), "{name} {args:?} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Runs stage `name` with `args`, expecting a refusal: exit code 2 and
/// exactly one line on stderr, which it returns.
pub fn refused(name: &str, args: &[&str]) -> String {
    let out = run(name, args);
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_string();
    assert_eq!(out.status.code(), Some(2), "{name} {args:?} should exit 2; stderr: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{name}: one line expected, got:\n{stderr}");
    stderr
}

/// Whether a gpu-shoot run failed for want of a Vulkan adapter: then the
/// test `test` is skipped, loudly, except under CI (the environment
/// variable `CI` set), where it fails. Any other failure fails the test.
pub fn skipped_without_gpu(out: &Output, test: &str) -> bool {
    if gpu_missing(out, test) {
        return true;
    }
    assert!(out.status.success(), "gpu-shoot failed:\n{}", String::from_utf8_lossy(&out.stderr));
    false
}

/// Whether a gpu-shoot run failed for want of a Vulkan adapter (the test
/// `test` is then skipped, loudly, except under CI, where it fails); any
/// other outcome is the caller's to judge.
pub fn gpu_missing(out: &Output, test: &str) -> bool {
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("no GPU adapter") {
        assert!(std::env::var_os("CI").is_none(), "CI has no Vulkan adapter for gpu-shoot: {stderr}");
        eprintln!("\n*** SKIPPED {test}: {stderr} ***\n");
        return true;
    }
    false
}

/// Runs `stage`, expects failure with exit 2, one stderr line containing
/// every `needle`, and none of `outputs` on disk.
pub fn assert_refused(stage: &str, args: &[&str], needles: &[&str], outputs: &[&Path]) {
    assert_refusal(stage, &run(stage, args), needles, outputs);
}

/// [`assert_refused`] for a run of `stage` already made (`out`).
pub fn assert_refusal(stage: &str, out: &Output, needles: &[&str], outputs: &[&Path]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stage} should exit 2; stderr: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "one line expected, got:\n{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "error should mention {needle:?}: {stderr}");
    }
    for output in outputs {
        assert!(!output.exists(), "{} was written despite the error", output.display());
    }
}

/// Path as `&str` (test paths are UTF-8).
pub fn s(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// mesh-prep then hierarchical-solve on `scene` in `dir`, with extra
/// solver arguments; returns the paths of mesh, manifest and solution.
pub fn prepare_and_solve(dir: &Path, scene: &Path, solve_args: &[&str]) -> (PathBuf, PathBuf, PathBuf) {
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let solution = solve_prepared(dir, solve_args, None);
    (mesh, manifest, solution)
}

/// A scene prepared and solved by [`prepare_and_solve`], its artifacts read
/// back.
pub struct Solved {
    /// The prepared mesh.
    pub mesh: Mesh,
    /// Its manifest.
    pub manifest: Manifest,
    /// hierarchical-solve's solution.
    pub solution: Solution,
}

impl Solved {
    /// [`prepare_and_solve`] on `scene` in `dir` with `solve_args`.
    pub fn new(dir: &Path, scene: &Path, solve_args: &[&str]) -> Self {
        let (mesh, manifest, solution) = prepare_and_solve(dir, scene, solve_args);
        Solved { mesh: Mesh::read(&mesh).unwrap().0, manifest: read_ron::<Manifest>(&manifest).unwrap().value, solution: Solution::read(&solution).unwrap().0 }
    }

    /// The leaf elements on the triangles of object `name`, each with its
    /// world corners.
    pub fn leaves_of(&self, name: &str) -> Vec<(&Element, [[f64; 3]; 3])> {
        let object = self.manifest.objects.iter().position(|o| o == name).unwrap_or_else(|| panic!("no object {name}")) as u32;
        let on_object = |e: &&Element| e.is_leaf() && self.mesh.triangles[e.triangle as usize].object == object;
        self.solution.elements.iter().filter(on_object).map(|e| (e, leaf_world_corners(&self.mesh, self.manifest.world_from_mesh_translation, e))).collect()
    }
}

/// hierarchical-solve on the mesh and manifest already in `dir`, clustered
/// with clusters of at most `leaf_size` triangles if given; returns the
/// solution's path.
pub fn solve_prepared(dir: &Path, solve_args: &[&str], leaf_size: Option<u32>) -> PathBuf {
    let (mesh, manifest, clusters, solution) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("clusters.exr"), dir.join("solution.exr"));
    let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution)];
    let leaf = leaf_size.map(|l| l.to_string());
    if let Some(leaf) = &leaf {
        run_ok("cluster", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&clusters), "--leaf-size", leaf]);
        args.extend_from_slice(&["--clusters", s(&clusters)]);
    }
    args.extend_from_slice(solve_args);
    run_ok("hierarchical-solve", &args);
    solution
}

/// The direction (not of unit length) of the manifest's `camera` ray
/// through the point `(px, py)` of a `width` x `height` image, in pixels
/// from its top left corner: the pinhole written out here from the
/// camera's fields, not the renderer's.
pub fn camera_ray(camera: &Camera, width: u32, height: u32, px: f64, py: f64) -> [f64; 3] {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let unit = |a: [f64; 3]| {
        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|v| v / l)
    };
    let forward = unit(sub(camera.target, camera.eye));
    let right = unit(cross(forward, camera.up));
    let up = cross(right, forward);
    let half_h = (0.5 * camera.vertical_fov_deg.to_radians()).tan();
    let half_w = half_h * f64::from(width) / f64::from(height);
    let sx = (2.0 * px / f64::from(width) - 1.0) * half_w;
    let sy = (1.0 - 2.0 * py / f64::from(height)) * half_h;
    std::array::from_fn(|a| forward[a] + sx * right[a] + sy * up[a])
}

/// The world points a pinhole camera sees on the plane z = 0 through an
/// `n x n` grid of points inside pixel `(x, y)` of a `width` x `height`
/// image (pixel `(0, 0)` top left; the manifest's camera, mesh frame, with
/// `origin` the world position of the mesh frame's origin; [`camera_ray`]).
pub fn pixel_points_on_ground(manifest: &Manifest, width: u32, height: u32, x: u32, y: u32, n: u32) -> Vec<[f64; 3]> {
    let origin = manifest.world_from_mesh_translation;
    let eye: [f64; 3] = std::array::from_fn(|a| manifest.camera.eye[a] + origin[a]);
    let mut points = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let px = f64::from(x) + (f64::from(i) + 0.5) / f64::from(n);
            let py = f64::from(y) + (f64::from(j) + 0.5) / f64::from(n);
            let d = camera_ray(&manifest.camera, width, height, px, py);
            let t = -eye[2] / d[2];
            points.push(std::array::from_fn(|a| eye[a] + t * d[a]));
        }
    }
    points
}

//! Mirrors and glass (issue 14): the materials mesh-prep reads, and the
//! display that sees through them (grid-gather, item 4).
//!
//! The scene: a floor `[-0.5, 1.5] x [0, 1]` at z = 0 (`Kd 0.5`), a mirror
//! wall at y = 1 facing -y (`Kd 0`, `Ks 0.8`, `illum 3`), a square emitter
//! at z = 1.2 emitting down. The camera, at z = 0.8 looking down towards
//! the wall, sees the floor directly in the lower part of the image and
//! reflected in the upper part. Per pixel, against closed forms written
//! here: a floor pixel shows `rho E(p) / pi` (Lambert's polygon formula for
//! `E`), a mirror pixel `rho_s rho E(p_r) / pi`, `p_r` the floor point its
//! rays reach after the reflection (computed here from the camera's
//! geometry), averaged over the pixel.
//!
//! The floor sees the mirror image of the emitter too; hierarchical-solve
//! does not yet simulate mirrors (issue 14 item 3, it says so in its
//! report), so the floor's radiosity holds the direct light only
//! ([`SOLVER_MIRRORS`]); the floor sees its own mirror image edge-on (the
//! same plane), so no light goes floor-mirror-floor.

use end_to_end::{assert_refused, run_ok, s, scratch, solve_prepared};
use schemas::image::HdrImage;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::{Element, Solution, NONE};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use test_support::artifacts::leaf_world_corners;
use test_support::closed_form::{clip_to_front, lambert_polygon, mean_over_triangle};
use test_support::scenes::closed_box;

/// Image side, pixels.
const SIZE: u32 = 48;
/// Camera eye and target, world frame.
const EYE: [f64; 3] = [0.5, 0.2, 0.8];
/// The point the camera looks at.
const TARGET: [f64; 3] = [0.5, 1.0, 0.0];
/// Vertical field of view, degrees.
const FOV_DEG: f64 = 40.0;
/// Exitance of the emitter, W/m².
const EXITANCE: f64 = 10.0;
/// The emitter's corner and edges (normal `u x v` = -z: it emits down).
const EMITTER: ([f64; 3], [f64; 3], [f64; 3]) = ([0.3, 0.3, 1.2], [0.0, 0.4, 0.0], [0.4, 0.0, 0.0]);
/// Diffuse reflectance of the floor.
const RHO: f64 = 0.5;
/// Specular reflectance of the mirror.
const RHO_S: f64 = 0.8;
/// The floor's extent in x and y.
const FLOOR: ([f64; 2], [f64; 2]) = ([-0.5, 1.5], [0.0, 1.0]);
/// The mirror wall's plane y and its extent in x and z.
const MIRROR_Y: f64 = 1.0;
const MIRROR: ([f64; 2], [f64; 2]) = ([-0.5, 1.5], [0.0, 1.5]);
/// Whether hierarchical-solve lights the floor through the mirror (the
/// floor's irradiance then includes `rho_s` times the mirrored emitter's).
const SOLVER_MIRRORS: bool = true;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [a[0] + t * b[0], a[1] + t * b[1], a[2] + t * b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / l)
}

/// The emitter's corners, in order around it.
fn emitter() -> [[f64; 3]; 4] {
    let (c, u, v) = EMITTER;
    [c, add(c, u, 1.0), add(add(c, u, 1.0), v, 1.0), add(c, v, 1.0)]
}

/// Writes the scene, with the mirror wall spanning `mirror` (x and z), into
/// a fresh directory; returns it and the scene path.
fn mirror_scene(test: &str, mirror_mtl: &str, mirror: ([f64; 2], [f64; 2])) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let ([x0, x1], [y0, y1]) = FLOOR;
    let ([m0, m1], [z0, z1]) = mirror;
    let y = MIRROR_Y;
    let obj = format!(
        "mtllib scene.mtl\no floor\nusemtl floor\nv {x0} {y0} 0\nv {x1} {y0} 0\nv {x1} {y1} 0\nv {x0} {y1} 0\nf 1 2 3 4\n\
         o mirror\nusemtl mirror\nv {m0} {y} {z0}\nv {m1} {y} {z0}\nv {m1} {y} {z1}\nv {m0} {y} {z1}\nf 5 6 7 8\n"
    );
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), format!("newmtl floor\nKd {RHO}\nnewmtl mirror\n{mirror_mtl}")).unwrap();
    let (c, u, v) = EMITTER;
    let t = |a: [f64; 3]| (a[0], a[1], a[2]);
    let scene = format!(
        "Scene(meshes: [Obj(file: \"scene.obj\")], camera: Camera(eye: {eye:?}, target: {target:?}, up: (0.0, 0.0, 1.0), vertical_fov_deg: {FOV_DEG:?}, width: {SIZE}, height: {SIZE}), lights: [Area(corner: {c:?}, edge_u: {u:?}, edge_v: {v:?}, emission: ({EXITANCE:?}, {EXITANCE:?}, {EXITANCE:?}))])",
        eye = t(EYE),
        target = t(TARGET),
        c = t(c),
        u = t(u),
        v = t(v),
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene).unwrap();
    (dir, path)
}

/// Unit direction of the camera ray through image point `(x, y)`
/// (pixels, y down): forward, right = forward x up, up' = right x forward.
fn ray(x: f64, y: f64) -> [f64; 3] {
    let forward = unit(sub(TARGET, EYE));
    let right = unit(cross(forward, [0.0, 0.0, 1.0]));
    let up = cross(right, forward);
    let half = (0.5 * FOV_DEG.to_radians()).tan();
    let (sx, sy) = ((2.0 * x / f64::from(SIZE) - 1.0) * half, (1.0 - 2.0 * y / f64::from(SIZE)) * half);
    unit(add(add(forward, right, sx), up, sy))
}

/// Where a ray from `origin` along `d` (going down) meets the floor plane.
fn on_floor(origin: [f64; 3], d: [f64; 3]) -> [f64; 3] {
    add(origin, d, -origin[2] / d[2])
}

/// Whether floor point `p` lies on the floor, `margin` inside its edges.
fn inside_floor(p: [f64; 3], margin: f64) -> bool {
    let ([x0, x1], [y0, y1]) = FLOOR;
    (x0 + margin..=x1 - margin).contains(&p[0]) && (y0 + margin..=y1 - margin).contains(&p[1])
}

/// What the camera ray through `(x, y)` reaches: the floor point and
/// whether through the mirror; `None` where it leaves the floor or the
/// mirror, or passes within `margin` of an edge.
fn reached(x: f64, y: f64, margin: f64) -> Option<([f64; 3], bool)> {
    let d = ray(x, y);
    let direct = on_floor(EYE, d);
    if direct[1] < MIRROR_Y - margin {
        return inside_floor(direct, margin).then_some((direct, false));
    }
    let at_mirror = add(EYE, d, (MIRROR_Y - EYE[1]) / d[1]);
    let ([m0, m1], [z0, z1]) = MIRROR;
    if !((m0 + margin..=m1 - margin).contains(&at_mirror[0]) && (z0 + margin..=z1 - margin).contains(&at_mirror[2])) {
        return None;
    }
    let p = on_floor(at_mirror, [d[0], -d[1], d[2]]);
    inside_floor(p, margin).then_some((p, true))
}

/// Irradiance of floor point `p`, W/m²: Lambert's polygon formula over the
/// emitter, plus `rho_s` times that over its mirror image (y -> 2 - y)
/// where the solver simulates the mirror; the mirror wall is large enough
/// that the whole image is seen through it from every floor point.
fn irradiance(p: [f64; 3]) -> f64 {
    let up = [0.0, 0.0, 1.0];
    let direct = lambert_polygon(p, up, &emitter());
    let image = emitter().map(|c| [c[0], 2.0 * MIRROR_Y - c[1], c[2]]);
    let mirrored = if SOLVER_MIRRORS { RHO_S * lambert_polygon(p, up, &image) } else { 0.0 };
    EXITANCE * (direct + mirrored)
}

/// mesh-prep and hierarchical-solve with `solve_args` in `dir`.
fn prepare_and_solve(dir: &Path, scene: &Path, solve_args: &[&str]) -> Manifest {
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    solve_prepared(dir, solve_args, None);
    read_ron::<Manifest>(&manifest).unwrap().value
}

/// grid-gather in `mode`; the image and the report's text.
fn gather(dir: &Path, mode: &str) -> (HdrImage, String) {
    let (mesh, manifest, solution) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("solution.exr"));
    let (image, report) = (dir.join(format!("{mode}.exr")), dir.join(format!("{mode}.report.ron")));
    run_ok(
        "grid-gather",
        &["--mode", mode, "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--report", s(&report), "--spp", "16"],
    );
    (HdrImage::read(&image).unwrap().0, std::fs::read_to_string(&report).unwrap())
}

#[test]
fn a_camera_looking_into_a_mirror_sees_rho_s_times_the_reflected_floor_per_pixel() {
    let (dir, scene) = mirror_scene("mirror_display", "Kd 0\nKs 0.8\nillum 3\n", MIRROR);
    let manifest = prepare_and_solve(&dir, &scene, &["--eps", "1e-4"]);
    let mirror = manifest.materials.iter().find(|m| m.name == "mirror").unwrap();
    assert_eq!((mirror.diffuse, mirror.specular_reflectance, mirror.specular_transmittance), ([0.0; 3], [RHO_S; 3], [0.0; 3]));
    assert!(manifest.effects.specular_reflection && !manifest.effects.specular_transmission);
    for (mode, tolerance) in [("preview", 0.01), ("full", 0.01)] {
        let (image, report) = gather(&dir, mode);
        assert!(report.contains("specular reflection: traced"), "{mode}: {report}");
        assert!(report.contains("specular_rays"), "{mode}: {report}");
        let (mut checked, mut worst) = ([0usize; 2], [0.0f64; 2]);
        for y in 0..SIZE {
            for x in 0..SIZE {
                // The pixel's mean: the midpoint rule on 8 x 8 sub-pixels,
                // all of which must reach the floor the same way, away from
                // the edges.
                let mut expected = 0.0;
                let mut through = None;
                let all = (0..64).all(|k| {
                    let (sx, sy) = (f64::from(x) + (f64::from(k % 8) + 0.5) / 8.0, f64::from(y) + (f64::from(k / 8) + 0.5) / 8.0);
                    let Some((p, mirrored)) = reached(sx, sy, 0.02) else { return false };
                    expected += if mirrored { RHO_S } else { 1.0 } * RHO * irradiance(p) / PI / 64.0;
                    *through.get_or_insert(mirrored) == mirrored
                });
                let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
                if !all || !corners.iter().all(|(cx, cy)| reached(f64::from(x) + cx, f64::from(y) + cy, 0.02).map(|r| r.1) == through) {
                    continue;
                }
                let kind = usize::from(through == Some(true));
                let got = f64::from(image.rgb[(y * SIZE + x) as usize][0]);
                let error = (got - expected).abs() / expected;
                assert!(error < tolerance, "{mode}: pixel ({x}, {y}), {} floor: radiance {got}, expected {expected} (error {error})", ["direct", "mirrored"][kind]);
                checked[kind] += 1;
                worst[kind] = worst[kind].max(error);
            }
        }
        eprintln!("{mode}: {} direct floor pixels (largest error {:.4}), {} mirror pixels (largest error {:.4})", checked[0], worst[0], checked[1], worst[1]);
        assert!(checked[0] > 200 && checked[1] > 200, "{mode}: only {checked:?} pixels checked");
    }
}

#[test]
fn a_mirror_that_would_reflect_more_than_it_receives_is_refused() {
    let (dir, scene) = mirror_scene("mirror_refused", "Kd 0.3\nKs 0.8\nillum 3\n", MIRROR);
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    assert_refused(
        "mesh-prep",
        &[s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)],
        &["material 'mirror'", "diffuse + specular_reflectance", "more than 1"],
        &[&mesh, &manifest],
    );
}

/// The leaves of a solution, with their triangle's material.
struct Solved {
    mesh: Mesh,
    manifest: Manifest,
    solution: Solution,
    report: String,
}

impl Solved {
    /// mesh-prep and hierarchical-solve with `solve_args` in `dir`.
    fn new(dir: &Path, scene: &Path, solve_args: &[&str]) -> Solved {
        let p = |f: &str| dir.join(f);
        let (mesh, manifest, solution, report) = (p("mesh.exr"), p("manifest.ron"), p("solution.exr"), p("solve.report.ron"));
        run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
        let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--report", s(&report)];
        args.extend_from_slice(solve_args);
        run_ok("hierarchical-solve", &args);
        Solved {
            mesh: Mesh::read(&mesh).unwrap().0,
            manifest: read_ron::<Manifest>(&manifest).unwrap().value,
            solution: Solution::read(&solution).unwrap().0,
            report: std::fs::read_to_string(report).unwrap(),
        }
    }

    /// The leaves whose material is `name`.
    fn leaves_of(&self, name: &str) -> Vec<&Element> {
        let m = self.manifest.materials.iter().position(|m| m.name == name).unwrap() as u32;
        self.solution.elements.iter().filter(|e| e.first_child == NONE && self.mesh.triangles[e.triangle as usize].material == m).collect()
    }

    /// Mean of `f` over leaf `e` (world frame), on the centroids of
    /// `4^levels` sub-triangles.
    fn mean(&self, e: &Element, levels: u32, f: &dyn Fn([f64; 3]) -> f64) -> f64 {
        mean_over_triangle(&leaf_world_corners(&self.mesh, self.manifest.world_from_mesh_translation, e), levels, f)
    }

    /// Checks every leaf of material `name`: its irradiance `B / rho`
    /// against the area-mean of `expected` within `tolerance`; returns the
    /// leaves checked and the largest error.
    fn check(&self, name: &str, rho: f64, tolerance: f64, expected: &dyn Fn([f64; 3]) -> f64) -> (usize, f64) {
        let leaves = self.leaves_of(name);
        let mut worst = 0.0f64;
        for e in &leaves {
            let want = self.mean(e, 4, expected);
            let got = f64::from(e.radiosity[0]) / rho;
            let error = (got - want).abs() / want.max(1e-12);
            let at = leaf_world_corners(&self.mesh, self.manifest.world_from_mesh_translation, e);
            assert!(error < tolerance, "{name} leaf at {at:?}: irradiance {got}, expected {want} (error {error})");
            worst = worst.max(error);
        }
        (leaves.len(), worst)
    }
}

/// The part of `polygon` seen from `p` through the convex window `window`
/// (corners in order): clipped by the planes through `p` and each edge.
fn through_window(polygon: &[[f64; 3]], p: [f64; 3], window: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let centre = window.iter().fold([0.0; 3], |c, w| add(c, *w, 1.0 / window.len() as f64));
    let mut clipped = polygon.to_vec();
    for i in 0..window.len() {
        let (a, b) = (window[i], window[(i + 1) % window.len()]);
        let mut n = cross(sub(a, p), sub(b, p));
        if (0..3).map(|k| (centre[k] - p[k]) * n[k]).sum::<f64>() < 0.0 {
            n = n.map(|x| -x);
        }
        clipped = clip_to_front(&clipped, p, n);
    }
    clipped
}

#[test]
fn a_floor_beside_a_mirror_wall_gets_lambert_plus_rho_s_times_the_mirrored_emitter_through_the_window() {
    // A mirror too small to show the whole image of the emitter from the
    // far part of the floor: the image is clipped to the window.
    let mirror = ([0.0, 1.0], [0.0, 0.8]);
    let (dir, scene) = mirror_scene("mirror_solver", "Kd 0\nKs 0.8\nillum 3\n", mirror);
    let solved = Solved::new(&dir, &scene, &["--eps", "1e-4", "--specular-rays", "1024"]);
    assert!(solved.report.contains("planar mirrors by virtual senders"), "{}", solved.report);
    let ([m0, m1], [z0, z1]) = mirror;
    let window = [[m0, MIRROR_Y, z0], [m1, MIRROR_Y, z0], [m1, MIRROR_Y, z1], [m0, MIRROR_Y, z1]];
    let image = emitter().map(|c| [c[0], 2.0 * MIRROR_Y - c[1], c[2]]);
    let up = [0.0, 0.0, 1.0];
    let expected = |p: [f64; 3]| EXITANCE * (lambert_polygon(p, up, &emitter()) + RHO_S * lambert_polygon(p, up, &through_window(&image, p, &window)));
    let (leaves, worst) = solved.check("floor", RHO, 0.01, &expected);
    // The image is clipped somewhere, and seen somewhere.
    let clipped = |p: [f64; 3]| lambert_polygon(p, up, &through_window(&image, p, &window)) / lambert_polygon(p, up, &image);
    let fractions: Vec<f64> = solved.leaves_of("floor").iter().map(|e| solved.mean(e, 0, &clipped)).collect();
    assert!(fractions.iter().any(|&f| f < 0.5) && fractions.iter().any(|&f| f > 0.99), "{fractions:?}");
    eprintln!("floor beside a mirror: {leaves} leaves, largest irradiance error {worst:.4}");
}

/// The pane scene in `dir`: the floor `[0, 1]^2` at z = 0 (`Kd` RHO), the
/// emitter `[0.25, 0.75]^2` at z = 1 emitting down, a pane (MTL lines
/// `pane`) at z = 0.5 between them, facing down, a quad `[-1, 2]^2` larger
/// than both whose two triangles meet on the diagonal `x = y` under the
/// camera's centre (the camera samples on that line met neither triangle
/// before the ray caster was made watertight, one in 8 of a diagonal
/// pixel's), and a camera at [`PANE_EYE`] looking straight down through
/// it. Returns the scene path.
fn pane_scene(dir: &Path, pane: &str) -> PathBuf {
    let obj = "mtllib scene.mtl\no floor\nusemtl floor\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n\
               o pane\nusemtl pane\nv -1 -1 0.5\nv -1 2 0.5\nv 2 2 0.5\nv 2 -1 0.5\nf 5 6 7\nf 5 7 8\n";
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), format!("newmtl floor\nKd {RHO}\nnewmtl pane\n{pane}")).unwrap();
    let [x, y, z] = PANE_EYE;
    let scene = format!(
        "Scene(meshes: [Obj(file: \"scene.obj\")], camera: Camera(eye: ({x:?}, {y:?}, {z:?}), target: (0.5, 0.5, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: {PANE_FOV_DEG:?}, width: {SIZE}, height: {SIZE}), lights: [Area(corner: (0.25, 0.25, 1.0), edge_u: (0.0, 0.5, 0.0), edge_v: (0.5, 0.0, 0.0), emission: ({EXITANCE:?}, {EXITANCE:?}, {EXITANCE:?}))])"
    );
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    dir.join("scene.ron")
}

/// The pane scene's camera: above the floor's centre, under the emitter,
/// looking down.
const PANE_EYE: [f64; 3] = [0.5, 0.5, 0.9];
/// Its vertical field of view: the floor [0, 1]^2 just fills the image.
const PANE_FOV_DEG: f64 = 58.0;
/// The pane scene's emitter, corners in order.
const LAMP: [[f64; 3]; 4] = [[0.25, 0.25, 1.0], [0.25, 0.75, 1.0], [0.75, 0.75, 1.0], [0.75, 0.25, 1.0]];

/// Irradiance of floor point `p` from the pane scene's emitter, unoccluded.
fn lambert(p: [f64; 3]) -> f64 {
    EXITANCE * lambert_polygon(p, [0.0, 0.0, 1.0], &LAMP)
}

#[test]
fn a_camera_looking_through_a_pane_sees_tau_s_times_the_floor_behind_it() {
    let dir = scratch("mirror_pane_display");
    let tau = 0.6;
    let scene = pane_scene(&dir, "Kd 0\nTf 0.6\nillum 4\n");
    // The pane is 9 m², the floor 1 m²: a finer area floor than the
    // default lets the floor's elements resolve the light through the pane.
    prepare_and_solve(&dir, &scene, &["--eps", "1e-4", "--min-area", "1e-5"]);
    // Where the ray through image point (x, y) meets the plane z = at.
    let half = (0.5 * PANE_FOV_DEG.to_radians()).tan();
    let at = |x: f64, y: f64, z: f64| {
        let (sx, sy) = ((2.0 * x / f64::from(SIZE) - 1.0) * half, (1.0 - 2.0 * y / f64::from(SIZE)) * half);
        let t = PANE_EYE[2] - z;
        [PANE_EYE[0] + sx * t, PANE_EYE[1] + sy * t, z]
    };
    // 1%: a sample in 16 of the diagonal's pixels missing the pane (seeing
    // the floor unattenuated) is 4% too much there.
    for (mode, tolerance) in [("preview", 0.01), ("full", 0.01)] {
        let (image, report) = gather(&dir, mode);
        assert!(report.contains("specular transmission: traced"), "{mode}: {report}");
        let (mut checked, mut worst) = (0, 0.0f64);
        for y in 0..SIZE {
            for x in 0..SIZE {
                // Pixels whose rays reach the floor 0.02 inside its edges.
                let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(cx, cy)| (f64::from(x) + cx, f64::from(y) + cy));
                let on_floor = corners.iter().all(|&(cx, cy)| at(cx, cy, 0.0).iter().take(2).all(|&v| (0.02..=0.98).contains(&v)));
                if !on_floor {
                    continue;
                }
                let expected: f64 = (0..64)
                    .map(|k| at(f64::from(x) + (f64::from(k % 8) + 0.5) / 8.0, f64::from(y) + (f64::from(k / 8) + 0.5) / 8.0, 0.0))
                    .map(|p| tau * RHO * tau * lambert(p) / PI / 64.0)
                    .sum();
                let got = f64::from(image.rgb[(y * SIZE + x) as usize][0]);
                let error = (got - expected).abs() / expected;
                assert!(error < tolerance, "{mode}: pixel ({x}, {y}): radiance {got}, expected {expected} (error {error})");
                checked += 1;
                worst = worst.max(error);
            }
        }
        eprintln!("{mode}: {checked} floor pixels through the pane, largest error {worst:.4}");
        assert!(checked > 500, "{mode}: only {checked} pixels checked");
    }
}

#[test]
fn a_glass_pane_passes_tau_s_of_the_light_and_an_opaque_pane_none() {
    let tau = 0.6;
    let dir = scratch("mirror_glass");
    let glass = Solved::new(&dir, &pane_scene(&dir, "Kd 0\nTf 0.6\nillum 4\n"), &["--eps", "1e-4"]);
    let pane = &glass.manifest.materials[1];
    assert_eq!((pane.specular_transmittance, pane.specular_reflectance, pane.diffuse_transmittance), ([tau; 3], [0.0; 3], [0.0; 3]));
    let (leaves, worst) = glass.check("floor", RHO, 0.01, &|p| tau * lambert(p));
    eprintln!("floor under a glass pane: {leaves} leaves, largest error {worst:.4} against tau_s x Lambert");
    let dir = scratch("mirror_opaque_pane");
    let opaque = Solved::new(&dir, &pane_scene(&dir, "Kd 0\n"), &["--eps", "1e-4"]);
    for e in opaque.leaves_of("floor") {
        assert_eq!(e.radiosity, [0.0; 3], "an opaque pane lets light through");
    }
}

#[test]
fn a_closed_box_with_a_mirror_wall_conserves_energy() {
    let dir = scratch("mirror_box");
    let mut scene = closed_box(1.0, 0.5, 10.0);
    for quad in scene.quads.iter_mut().filter(|q| q.0 == "wall0true") {
        quad.1 = "mirror".into();
    }
    scene.material("mirror", 0.05, 0.0);
    let path = scene.write(&dir);
    // The mirror is the last material of the library: it reflects 0.9 specularly.
    let mtl = std::fs::read_to_string(dir.join("scene.mtl")).unwrap();
    std::fs::write(dir.join("scene.mtl"), format!("{mtl}Ks 0.9\nillum 3\n")).unwrap();
    let solved = Solved::new(&dir, &path, &["--eps", "1e-3", "--min-area", "1e-3", "--tolerance", "1e-7"]);
    // Absorbed: sum A (1 - rho_d - rho_s) H over the leaves, H = (B - E) / rho_d.
    let (mut emitted, mut absorbed) = (0.0, 0.0);
    for e in solved.solution.elements.iter().filter(|e| e.first_child == NONE) {
        let m = &solved.manifest.materials[solved.mesh.triangles[e.triangle as usize].material as usize];
        let area = f64::from(e.area);
        emitted += area * m.emission[0];
        absorbed += area * (1.0 - m.diffuse[0] - m.specular_reflectance[0]) * (f64::from(e.radiosity[0]) - m.emission[0]) / m.diffuse[0];
    }
    eprintln!("closed box with a mirror wall: absorbed / emitted = {:.5}", absorbed / emitted);
    assert!((absorbed / emitted - 1.0).abs() < 1e-2, "absorbed {absorbed} of {emitted} emitted");
}

#[test]
fn two_facing_mirrors_give_the_series_of_images_to_the_depth_bound_and_report_a_truncation_bound() {
    // Mirrors x = 0 (facing +x) and x = 1 (facing -x), 20 x 20 m; between
    // them a floor patch and, 2 m above it, an emitter facing down, so that
    // the images of order 1 to 3 bring 64%, 25% and 10% of the direct light.
    let dir = scratch("mirror_parallel");
    let (rho_s, depth) = (0.9f64, 3usize);
    let mut obj = String::from("mtllib scene.mtl\n");
    let quads: [(&str, &str, [[f64; 3]; 4]); 3] = [
        ("floor", "floor", [[0.3, -0.2, 0.0], [0.7, -0.2, 0.0], [0.7, 0.2, 0.0], [0.3, 0.2, 0.0]]),
        ("left", "mirror", [[0.0, -10.0, -10.0], [0.0, 10.0, -10.0], [0.0, 10.0, 10.0], [0.0, -10.0, 10.0]]),
        ("right", "mirror", [[1.0, -10.0, -10.0], [1.0, -10.0, 10.0], [1.0, 10.0, 10.0], [1.0, 10.0, -10.0]]),
    ];
    for (object, material, corners) in quads {
        obj += &format!("o {object}\nusemtl {material}\n");
        for v in corners {
            obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        }
        obj += "f -4 -3 -2 -1\n";
    }
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), format!("newmtl floor\nKd {RHO}\nnewmtl mirror\nKd 0\nKs {rho_s}\nillum 3\n")).unwrap();
    let scene = format!(
        "Scene(meshes: [Obj(file: \"scene.obj\")], camera: Camera(eye: (0.5, -2.0, 0.3), target: (0.5, 0.0, 0.2), up: (0.0, 0.0, 1.0), vertical_fov_deg: 60.0, width: 8, height: 8), lights: [Area(corner: (0.4, -0.1, 2.0), edge_u: (0.0, 0.2, 0.0), edge_v: (0.2, 0.0, 0.0), emission: ({EXITANCE:?}, {EXITANCE:?}, {EXITANCE:?}))])"
    );
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    let depth_arg = depth.to_string();
    let solved = Solved::new(&dir, &dir.join("scene.ron"), &["--eps-relative", "1e-5", "--min-area", "1e-6", "--specular-depth", &depth_arg]);
    let lamp = [[0.4, -0.1, 2.0], [0.4, 0.1, 2.0], [0.6, 0.1, 2.0], [0.6, -0.1, 2.0]];
    // The images after k reflections, starting in either mirror: x -> -x
    // in the left one, x -> 2 - x in the right one, alternately.
    let series = |p: [f64; 3], orders: usize| {
        let mut e = lambert_polygon(p, [0.0, 0.0, 1.0], &lamp);
        for first in [0, 1] {
            let mut image = lamp;
            for k in 1..=orders {
                let at = if (k + first) % 2 == 0 { 0.0 } else { 1.0 };
                image = image.map(|c| [2.0 * at - c[0], c[1], c[2]]);
                e += rho_s.powi(k as i32) * lambert_polygon(p, [0.0, 0.0, 1.0], &image);
            }
        }
        EXITANCE * e
    };
    let (leaves, worst) = solved.check("floor", RHO, 0.001, &|p| series(p, depth));
    eprintln!("floor between facing mirrors: {leaves} leaves, largest error {worst:.2e} against the series to order {depth}");
    assert!(leaves >= 8, "only {leaves} floor leaves");
    // One order less would be far outside that.
    let centre = [0.5, 0.0, 0.0];
    assert!(series(centre, depth) > 1.05 * series(centre, depth - 1));
    // The truncation the solver reports bounds the true one (the series
    // to order 60 less the series to the depth bound), on every leaf.
    let line = solved.report.lines().find(|l| l.contains("\"specular_truncation_bound\"")).unwrap_or_else(|| panic!("{}", solved.report));
    let bound: f64 = line.split(':').nth(1).unwrap().trim().trim_end_matches(',').parse().unwrap();
    let mut largest = 0.0f64;
    for e in solved.leaves_of("floor") {
        let truncated = solved.mean(e, 2, &|p| series(p, 60) - series(p, depth));
        largest = largest.max(truncated);
    }
    eprintln!("truncation: largest {largest:.3e} W/m2, reported bound {bound:.3e}");
    assert!(largest > 0.0 && largest <= bound, "truncation {largest} over the reported bound {bound}");
}

#[test]
fn out_of_range_specular_knobs_are_refused_in_one_line() {
    let (dir, scene) = mirror_scene("mirror_knobs", "Kd 0\nKs 0.8\nillum 3\n", MIRROR);
    let manifest = prepare_and_solve(&dir, &scene, &["--eps", "1e-3"]);
    assert!(manifest.effects.specular_reflection);
    let p = |f: &str| dir.join(f);
    let (mesh, manifest, solution) = (p("mesh.exr"), p("manifest.ron"), p("solution.exr"));
    let out = p("refused.exr");
    let solve = |flag: &str, value: &str| vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&out), flag, value].into_iter().map(String::from).collect::<Vec<_>>();
    for (flag, value, needle) in [("--specular-depth", "17", "specular_depth"), ("--specular-rays", "0", "specular_rays"), ("--specular-min-factor", "-1", "specular_min_factor")] {
        let args = solve(flag, value);
        assert_refused("hierarchical-solve", &args.iter().map(String::as_str).collect::<Vec<_>>(), &[needle], &[&out]);
    }
    for (flag, value, needle) in [("--specular-depth", "65", "specular_depth"), ("--specular-min-weight", "2", "specular_min_weight")] {
        assert_refused("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&out), flag, value], &[needle], &[&out]);
    }
}

#[test]
fn an_occluder_before_and_after_the_mirror_blocks_the_mirrored_light_where_it_lies() {
    // The large mirror wall and, against it, a black horizontal plate at
    // height H over y in [0.9, 1] (paper 004 Fig. 4.1's mirror-object
    // case: the plate can block the leg to the mirror and the leg back).
    const H: f64 = 0.6;
    let (dir, scene) = mirror_scene("mirror_occluder", "Kd 0\nKs 0.8\nillum 3\n", MIRROR);
    let obj = std::fs::read_to_string(dir.join("scene.obj")).unwrap();
    std::fs::write(dir.join("scene.obj"), format!("{obj}o plate\nusemtl plate\nv -0.5 0.9 {H}\nv 1.5 0.9 {H}\nv 1.5 1 {H}\nv -0.5 1 {H}\nf 9 10 11 12\n")).unwrap();
    let mtl = std::fs::read_to_string(dir.join("scene.mtl")).unwrap();
    std::fs::write(dir.join("scene.mtl"), format!("{mtl}newmtl plate\nKd 0\n")).unwrap();
    let solved = Solved::new(&dir, &scene, &["--eps", "1e-4", "--specular-rays", "1024"]);
    // Unfolded, the mirrored light comes from the emitter's image (y in
    // [1.3, 1.7] at z = 1.2) past the plate and the plate's image: the
    // strip y in [0.9, 1.1] at z = H, which from floor point p hides the
    // image's rows y in [p_y + (0.9 - p_y) 1.2 / H, p_y + (1.1 - p_y) 1.2 / H]
    // (the strip spans the floor's x range, so every column).
    let (c, u, v) = EMITTER;
    let (x0, x1, z) = (c[0], c[0] + v[0], c[2]);
    let (y0, y1) = (2.0 * MIRROR_Y - (c[1] + u[1]), 2.0 * MIRROR_Y - c[1]);
    let rectangle = |lo: f64, hi: f64| [[x0, lo, z], [x1, lo, z], [x1, hi, z], [x0, hi, z]];
    let up = [0.0, 0.0, 1.0];
    let visible = |p: [f64; 3]| {
        let (lo, hi) = (p[1] + (0.9 - p[1]) * z / H, p[1] + (1.1 - p[1]) * z / H);
        let mut f = 0.0;
        if lo > y0 {
            f += lambert_polygon(p, up, &rectangle(y0, lo.min(y1)));
        }
        if hi < y1 {
            f += lambert_polygon(p, up, &rectangle(hi.max(y0), y1));
        }
        f
    };
    let expected = |p: [f64; 3]| EXITANCE * (lambert_polygon(p, up, &emitter()) + RHO_S * visible(p));
    let (leaves, worst) = solved.check("floor", RHO, 0.01, &expected);
    // At leaf centroids the plate hides almost all of the image (under
    // y = 0.5, all of it) and none of it.
    let whole = |p: [f64; 3]| lambert_polygon(p, up, &rectangle(y0, y1));
    let shares: Vec<f64> = solved.leaves_of("floor").iter().map(|e| solved.mean(e, 0, &|p| visible(p) / whole(p))).collect();
    let (least, most) = shares.iter().fold((1.0f64, 0.0f64), |(a, b), &f| (a.min(f), b.max(f)));
    assert!(least < 0.05 && most == 1.0, "visible shares from {least} to {most}");
    eprintln!("floor beside a mirror with an occluder: {leaves} leaves, largest irradiance error {worst:.4}");
}

/// Issue 14 item 5: what the solver and the display do not simulate of
/// mirrors and glass stays said, in the report's `skipped` and on stderr:
/// glossy reflection (a curved mirror is its facets) and
/// refraction bending by thick glass, for a pane that both reflects and
/// transmits (`illum 6`: `Ks` a mirror, `Tf` glass).
#[test]
fn the_solver_and_the_display_say_what_of_mirrors_and_glass_they_do_not_simulate() {
    let dir = scratch("mirror_not_simulated");
    let scene = pane_scene(&dir, "Kd 0\nKs 0.2\nTf 0.6\nillum 6\n");
    let (mesh, manifest, solution, report) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("solution.exr"), dir.join("solve.report.ron"));
    run_ok("mesh-prep", &[s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let solved = run_ok("hierarchical-solve", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--report", s(&report)]);
    let said = |what: &str, skipped: &[String]| {
        let glossy = skipped.iter().any(|l| l.starts_with("specular reflection:") && l.contains("no glossy reflection") && l.contains("a curved mirror is its facets"));
        let bending = skipped.iter().any(|l| l.starts_with("specular transmission:") && l.contains("no refraction bending by thick glass"));
        assert!(glossy && bending, "{what}: {skipped:?}");
    };
    said("hierarchical-solve's report", &read_ron::<schemas::report::Report>(&report).unwrap().value.skipped);
    let skipped_lines = |stage: &str, stderr: &[u8]| -> Vec<String> {
        let prefix = format!("{stage}: skipped: ");
        String::from_utf8_lossy(stderr).lines().filter_map(|l| l.strip_prefix(prefix.as_str())).map(String::from).collect()
    };
    said("hierarchical-solve's stderr", &skipped_lines("hierarchical-solve", &solved.stderr));
    for mode in ["preview", "full"] {
        let (image, report) = (dir.join(format!("{mode}.exr")), dir.join(format!("{mode}.report.ron")));
        let gathered = run_ok("grid-gather", &["--mode", mode, "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--report", s(&report), "--spp", "1"]);
        said(&format!("grid-gather --mode {mode}'s report"), &read_ron::<schemas::report::Report>(&report).unwrap().value.skipped);
        said(&format!("grid-gather --mode {mode}'s stderr"), &skipped_lines("grid-gather", &gathered.stderr));
    }
}

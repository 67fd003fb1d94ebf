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

use end_to_end::closed_form::lambert_polygon;
use end_to_end::{assert_refused, run_ok, s, scratch, solve_prepared};
use schemas::image::HdrImage;
use schemas::mesh::Manifest;
use schemas::ron_io::read_ron;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

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
const SOLVER_MIRRORS: bool = false;

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

/// Writes the scene into a fresh directory; returns it and the scene path.
fn mirror_scene(test: &str, mirror_mtl: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let ([x0, x1], [y0, y1]) = FLOOR;
    let ([m0, m1], [z0, z1]) = MIRROR;
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

/// mesh-prep and hierarchical-solve in `dir`.
fn prepare_and_solve(dir: &Path, scene: &Path) -> Manifest {
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    solve_prepared(dir, &["--eps", "1e-4"], None);
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
    let (dir, scene) = mirror_scene("mirror_display", "Kd 0\nKs 0.8\nillum 3\n");
    let manifest = prepare_and_solve(&dir, &scene);
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
    let (dir, scene) = mirror_scene("mirror_refused", "Kd 0.3\nKs 0.8\nillum 3\n");
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    assert_refused(
        "mesh-prep",
        &[s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)],
        &["material 'mirror'", "diffuse + specular_reflectance", "more than 1"],
        &[&mesh, &manifest],
    );
}

//! Surface detail in the display and diffuse transmission as a material
//! (issue 13, items 2 to 5 and 8 for grid-gather, item 5's parsing in
//! mesh-prep).
//!
//! grid-gather, per pixel against closed forms written here: a floor of
//! 2 x 2 checks (a 64 x 64 texture) lit by a square emitter beside it, seen
//! from above, shows `rho(x) E(x) / pi` (Lambert's polygon formula for `E`)
//! in every pixel whose footprint lies in one check, preview and full
//! gather; an alpha-masked quad between the camera and the floor lets the
//! pixels through its cut-out half see the floor and shows its opaque half
//! (lit by nothing) black; a normal map tilting every normal by a known
//! angle gives the full gather `rho E(n') / pi` with the tilted normal; a
//! two-sided translucent sheet seen from behind shows `tau E / pi`; a
//! scene without detail renders the same pixels with and without the
//! surface artifact, which it does not read; one from another mesh-prep
//! run is refused.
//!
//! mesh-prep: a translucent MTL material (`illum` 0 to 2, `d` < 1, `Tf`)
//! and a `scene.ron` override give the diffuse transmittance the manifest
//! records; a material that would scatter more than it receives is one line
//! naming the file, the material and the fields, exit 2, no output.

use end_to_end::{assert_refused, run_ok, s, scratch, solve_prepared};
use schemas::image::HdrImage;
use schemas::mesh::Manifest;
use schemas::ron_io::read_ron;
use std::path::{Path, PathBuf};
use test_support::closed_form::{clip_to_front, lambert_polygon};
use test_support::scenes::closed_box;

/// Image side, pixels.
const SIZE: u32 = 48;
/// Texels per side of the floor's textures.
const TEXELS: usize = 64;
/// Camera: above the floor's centre, looking down, +y up in the image.
const EYE: [f64; 3] = [0.5, 0.5, 2.0];
/// Vertical field of view: the floor [0, 1]^2 just fills the image.
const FOV_DEG: f64 = 28.0;
/// Exitance of the emitter, W/m².
const EXITANCE: f64 = 10.0;
/// The emitter, world frame: a square beside the floor (out of view),
/// emitting down (its edges turn clockwise seen from above).
const EMITTER: [[f64; 3]; 4] = [[1.1, 0.2, 0.6], [1.1, 0.8, 0.6], [1.7, 0.8, 0.6], [1.7, 0.2, 0.6]];

/// Linear reflectance of an sRGB byte (IEC 61966-2-1), as mesh-prep must
/// decode a diffuse texture.
fn linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The floor's check bytes: `(u < 1/2) == (v < 1/2)` is the dark check.
const CHECKS: [u8; 2] = [90, 220];

/// The check of texture coordinates `(u, v)` (0 dark, 1 light).
fn check(u: f64, v: f64) -> usize {
    usize::from((u < 0.5) != (v < 0.5))
}

/// A `TEXELS`-square PNG whose texel at column `i`, row `j` (row 0 at v =
/// 1) is `colour(u, v)` at the texel's centre.
fn png(colour: impl Fn(f64, f64) -> [u8; 3]) -> Vec<u8> {
    let n = TEXELS;
    let texels: Vec<[u8; 3]> = (0..n * n).map(|k| colour(((k % n) as f64 + 0.5) / n as f64, 1.0 - ((k / n) as f64 + 0.5) / n as f64)).collect();
    stage_kit::png::encode_png(n, n, &texels).unwrap()
}

/// A scene in a fresh directory: the unit floor at z = 0 (texture
/// coordinates = x, y) of material `floor` with MTL lines `floor_mtl`,
/// optionally a unit quad `screen` at z = 1 (same coordinates) of material
/// `screen` with `screen_mtl`, the emitter, the camera; `files` written
/// beside. Returns the scene path.
fn display_scene(test: &str, floor_mtl: &str, screen_mtl: Option<&str>, files: &[(&str, Vec<u8>)]) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let quad = |z: f64, material: &str, first: usize| {
        format!(
            "usemtl {material}\nv 0 0 {z}\nv 1 0 {z}\nv 1 1 {z}\nv 0 1 {z}\nf {a}/1 {b}/2 {c}/3 {d}/4\n",
            a = first,
            b = first + 1,
            c = first + 2,
            d = first + 3
        )
    };
    let mut obj = String::from("mtllib scene.mtl\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\no floor\n");
    obj += &quad(0.0, "floor", 1);
    let mut mtl = format!("newmtl floor\n{floor_mtl}");
    if let Some(screen) = screen_mtl {
        obj += "o screen\n";
        obj += &quad(1.0, "screen", 5);
        mtl += &format!("newmtl screen\n{screen}");
    }
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), mtl).unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let [c, a, b] = [EMITTER[0], EMITTER[1], EMITTER[3]];
    let edge = |p: [f64; 3]| (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
    let scene = format!(
        "Scene(meshes: [Obj(file: \"scene.obj\")], camera: Camera(eye: {eye:?}, target: (0.5, 0.5, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: {FOV_DEG:?}, width: {SIZE}, height: {SIZE}), lights: [Area(corner: {corner:?}, edge_u: {u:?}, edge_v: {v:?}, emission: ({EXITANCE:?}, {EXITANCE:?}, {EXITANCE:?}))])",
        eye = (EYE[0], EYE[1], EYE[2]),
        corner = (c[0], c[1], c[2]),
        u = edge(a),
        v = edge(b),
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene).unwrap();
    (dir, path)
}

/// mesh-prep (with the surface artifact) and hierarchical-solve in `dir`,
/// the solve reading the surface artifact if `textured_solve` (its
/// elements then transport with their texture averages; else with the
/// materials' `Kd`: the display recovers the irradiance either way).
fn prepare_and_solve(dir: &Path, scene: &Path, textured_solve: bool) {
    let [mesh, manifest] = outputs(dir);
    let surface = dir.join("surface.exr");
    run_ok("mesh-prep", &[s(scene), "--mesh", s(&mesh), "--manifest", s(&manifest), "--surface", s(&surface)]);
    let mut args = vec!["--eps", "1e-4"];
    if textured_solve {
        args.extend(["--surface", s(&surface)]);
    }
    solve_prepared(dir, &args, None);
}

/// grid-gather in `mode` with the surface artifact; the image.
fn gather(dir: &Path, mode: &str) -> HdrImage {
    let [mesh, manifest] = outputs(dir);
    let (solution, surface, image) = (dir.join("solution.exr"), dir.join("surface.exr"), dir.join(format!("{mode}.exr")));
    let report = dir.join(format!("{mode}.report.ron"));
    run_ok(
        "grid-gather",
        &["--mode", mode, "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "--surface", s(&surface), "-o", s(&image), "--report", s(&report), "--spp", "16"],
    );
    let text = std::fs::read_to_string(&report).unwrap();
    // The preview shows the solver's cosines; the full gather applies the normal map.
    let simulated: &[&str] = if mode == "full" { &["diffuse textures", "alpha masks", "normal maps"] } else { &["diffuse textures", "alpha masks"] };
    for effect in simulated {
        assert!(!text.contains(effect), "the report lists {effect} as skipped: {text}");
    }
    HdrImage::read(&image).unwrap().0
}

/// Where the camera ray through image point `(x, y)` (pixels, y down)
/// meets the plane `z = at`, world frame.
fn ray_at(x: f64, y: f64, at: f64) -> [f64; 2] {
    let half = (0.5 * FOV_DEG.to_radians()).tan();
    let (sx, sy) = ((2.0 * x / f64::from(SIZE) - 1.0) * half, (1.0 - 2.0 * y / f64::from(SIZE)) * half);
    // Forward -z, right +x, up +y: the direction (sx, sy, -1).
    let t = EYE[2] - at;
    [EYE[0] + sx * t, EYE[1] + sy * t]
}

/// The floor points the four corners of pixel `(x, y)` see, world frame.
fn footprint(x: u32, y: u32, at: f64) -> [[f64; 2]; 4] {
    let (x, y) = (f64::from(x), f64::from(y));
    [ray_at(x, y, at), ray_at(x + 1.0, y, at), ray_at(x + 1.0, y + 1.0, at), ray_at(x, y + 1.0, at)]
}

/// Irradiance at floor point `p` with unit normal `n`, W/m²: Lambert's
/// polygon formula over the emitter's part in front of the point.
fn irradiance(p: [f64; 2], n: [f64; 3]) -> f64 {
    let point = [p[0], p[1], 0.0];
    EXITANCE * lambert_polygon(point, n, &clip_to_front(&EMITTER, point, n))
}

/// Checks every pixel whose footprint lies on the floor inside one check,
/// at least half a texel from the checks' edges (the bilinear blur), and
/// whose ray passes `clear(x, y)`: radiance `rho E(n) / pi`, averaged over
/// the pixel, within `tolerance` (relative). Returns the pixels checked and
/// the largest error.
fn per_pixel(image: &HdrImage, rho: impl Fn(f64, f64) -> f64, n: [f64; 3], clear: impl Fn(u32, u32) -> bool, tolerance: f64, what: &str) -> (usize, f64) {
    let margin = 0.5 / TEXELS as f64;
    let (mut checked, mut worst) = (0, 0.0f64);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let corners = footprint(x, y, 0.0);
            let inside = corners.iter().all(|c| c.iter().all(|&v| (margin..=1.0 - margin).contains(&v)) && (c[0] - 0.5).abs() > margin && (c[1] - 0.5).abs() > margin);
            let one_check = corners.iter().all(|c| check(c[0], c[1]) == check(corners[0][0], corners[0][1]));
            if !(inside && one_check && clear(x, y)) {
                continue;
            }
            // The pixel's mean: the midpoint rule on 8 x 8 sub-pixels.
            let mut expected = 0.0;
            for k in 0..64 {
                let p = ray_at(f64::from(x) + (f64::from(k % 8) + 0.5) / 8.0, f64::from(y) + (f64::from(k / 8) + 0.5) / 8.0, 0.0);
                expected += rho(p[0], p[1]) * irradiance(p, n) / std::f64::consts::PI / 64.0;
            }
            let p = ray_at(f64::from(x) + 0.5, f64::from(y) + 0.5, 0.0);
            let got = f64::from(image.rgb[(y * SIZE + x) as usize][0]);
            let error = (got - expected).abs() / expected;
            assert!(error < tolerance, "{what}: pixel ({x}, {y}) at floor point {p:?}: radiance {got}, expected {expected} (error {error})");
            checked += 1;
            worst = worst.max(error);
        }
    }
    (checked, worst)
}

#[test]
fn a_checkerboard_floor_shows_its_checks_per_pixel_in_preview_and_full_gathers() {
    let texture = png(|u, v| [CHECKS[check(u, v)]; 3]);
    let (dir, scene) = display_scene("display_checks", "Kd 0.5\nmap_Kd -clamp on checks.png\n", None, &[("checks.png", texture)]);
    let rho = |u: f64, v: f64| linear(CHECKS[check(u, v)]);
    for textured_solve in [true, false] {
        prepare_and_solve(&dir, &scene, textured_solve);
        for (mode, tolerance) in [("preview", 0.015), ("full", 0.0075)] {
            let image = gather(&dir, mode);
            let what = format!("{mode}, textured solve {textured_solve}");
            let (checked, worst) = per_pixel(&image, rho, [0.0, 0.0, 1.0], |_, _| true, tolerance, &what);
            eprintln!("{what}: {checked} pixels, largest error {worst:.4}");
            assert!(checked > (SIZE * SIZE) as usize / 2, "{what}: only {checked} pixels checked");
            // Every pixel on the floor, those the checks' edges touch
            // included: its reflectance, radiance x pi / E, is nearer the
            // check at its centre than the other check.
            let mut edge_pixels = 0;
            for y in 0..SIZE {
                for x in 0..SIZE {
                    let corners = footprint(x, y, 0.0);
                    if !corners.iter().all(|c| c.iter().all(|&v| (0.0..=1.0).contains(&v))) {
                        continue;
                    }
                    let p = ray_at(f64::from(x) + 0.5, f64::from(y) + 0.5, 0.0);
                    let seen = f64::from(image.rgb[(y * SIZE + x) as usize][0]) * std::f64::consts::PI / irradiance(p, [0.0, 0.0, 1.0]);
                    let right = check(p[0], p[1]);
                    let nearer = (seen - linear(CHECKS[right])).abs() < (seen - linear(CHECKS[1 - right])).abs();
                    assert!(nearer, "{what}: pixel ({x}, {y}) shows reflectance {seen}, the other check's");
                    edge_pixels += usize::from(corners.iter().any(|c| check(c[0], c[1]) != right || (c[0] - 0.5).abs() < 1e-9 || (c[1] - 0.5).abs() < 1e-9));
                }
            }
            assert!(edge_pixels >= 4 * (SIZE as usize - 4), "{what}: only {edge_pixels} pixels touch the checks' edges");
        }
    }
}

#[test]
fn pixels_through_an_alpha_masked_quads_holes_see_the_lit_floor() {
    // The screen's mask: u < 1/2 cut out (alpha 0), the rest opaque.
    let mask = png(|u, _| [if u < 0.5 { 0 } else { 255 }; 3]);
    let (dir, scene) = display_scene("display_alpha", "Kd 0.5\n", Some("Kd 0.5\nmap_d -imfchan l mask.png\n"), &[("mask.png", mask)]);
    prepare_and_solve(&dir, &scene, true);
    let margin = 0.5 / TEXELS as f64;
    // The pixel sees the screen's cut-out half all over, away from its edge.
    let through = |x: u32, y: u32| footprint(x, y, 1.0).iter().all(|c| c[0] < 0.5 - margin);
    let behind = |x: u32, y: u32| footprint(x, y, 1.0).iter().all(|c| (0.5 + margin..1.0).contains(&c[0]) && (0.0..1.0).contains(&c[1]));
    for (mode, tolerance) in [("preview", 0.015), ("full", 0.0075)] {
        let image = gather(&dir, mode);
        let (checked, worst) = per_pixel(&image, |_, _| 0.5, [0.0, 0.0, 1.0], through, tolerance, mode);
        eprintln!("{mode}: {checked} pixels through the holes, largest error {worst:.4}");
        assert!(checked > 100, "{mode}: only {checked} pixels through the holes");
        // The opaque half faces away from the emitter's light: black.
        let opaque: Vec<u32> = (0..SIZE * SIZE).filter(|&i| behind(i % SIZE, i / SIZE)).collect();
        assert!(opaque.len() > 100);
        for i in opaque {
            assert_eq!(image.rgb[i as usize], [0.0; 3], "{mode}: pixel {i} sees the opaque half of the screen");
        }
    }
}

#[test]
fn a_normal_map_tilts_the_full_gathers_cosines() {
    // Every texel's tangent-space normal tilted toward +x (the tangent,
    // along increasing u) and -y (against the bitangent, increasing v):
    // bytes (200, 90, 230), 38.5 degrees from the face normal.
    let bytes = [200u8, 90, 230];
    let map = png(|_, _| bytes);
    let (dir, scene) = display_scene("display_normal_map", "Kd 0.5\nnorm normal.png\n", None, &[("normal.png", map)]);
    prepare_and_solve(&dir, &scene, false);
    let image = gather(&dir, "full");
    // The tangent frame of the floor: T = +x, B = +y, N = +z.
    let t = bytes.map(|b| 2.0 * f64::from(b) / 255.0 - 1.0);
    let length = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    let n = t.map(|c| c / length);
    let (checked, worst) = per_pixel(&image, |_, _| 0.5, n, |_, _| true, 0.0075, "normal-mapped");
    eprintln!("normal map: {checked} pixels, largest error {worst:.4}");
    assert!(checked > (SIZE * SIZE) as usize / 2);
    // The tilt toward the emitter matters: the flat floor's answer is off.
    let p = ray_at(f64::from(SIZE) / 2.0, f64::from(SIZE) / 2.0, 0.0);
    assert!(irradiance(p, n) > 1.2 * irradiance(p, [0.0, 0.0, 1.0]));
}

/// The closed box of `closed_box` in a fresh directory with `mtl` appended
/// to its MTL library (a material `sheet` used by a small quad inside the
/// box) and `overrides` added to scene.ron's materials; returns (dir,
/// scene path).
fn box_with_sheet(test: &str, mtl: &str, overrides: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(test);
    let mut scene = closed_box(1.0, 0.5, 1.0);
    scene.quad("sheet", "sheet", test_support::scenes::rectangle(2, 0.5, [0.25, 0.25], [0.75, 0.75]), [0.0, 0.0, 1.0]);
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
    // Not simulated yet: the solve's and the display's reports say so.
    let solve_report = dir.join("solve.report.ron");
    solve_prepared(&dir, &["--report", s(&solve_report), "--eps", "1e-2", "--min-area", "1e-2"], None);
    let [mesh, manifest] = outputs(&dir);
    let (image, gather_report) = (dir.join("image.exr"), dir.join("gather.report.ron"));
    let solution = dir.join("solution.exr");
    run_ok("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--report", s(&gather_report), "--width", "8", "--height", "8"]);
    for report in [solve_report, gather_report] {
        let text = std::fs::read_to_string(&report).unwrap();
        assert!(text.contains("diffuse transmission"), "{} does not list diffuse transmission as skipped: {text}", report.display());
    }
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

#[test]
fn a_scene_without_surface_detail_renders_the_same_pixels_and_never_reads_the_surface_artifact() {
    let (dir, scene) = display_scene("display_plain", "Kd 0.5\n", None, &[]);
    prepare_and_solve(&dir, &scene, true);
    let [mesh, manifest] = outputs(&dir);
    let solution = dir.join("solution.exr");
    for mode in ["preview", "full"] {
        let render = |surface: Option<&Path>, name: &str| {
            let image = dir.join(name);
            let mut args = vec!["--mode", mode, "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--width", "24", "--height", "24"];
            if let Some(surface) = surface {
                args.extend(["--surface", s(surface)]);
            }
            run_ok("grid-gather", &args);
            HdrImage::read(&image).unwrap().0
        };
        let (plain, given) = (render(None, "plain.exr"), render(Some(&dir.join("surface.exr")), "given.exr"));
        assert_eq!((&plain.rgb, &plain.coverage, &plain.surfaces), (&given.rgb, &given.coverage, &given.surfaces), "{mode}");
        let inputs: Vec<&str> = given.header.provenance.inputs.iter().map(|i| i.path.as_str()).collect();
        assert!(!inputs.iter().any(|p| p.ends_with("surface.exr")), "{mode}: the surface artifact was read: {inputs:?}");
    }
}

#[test]
fn a_surface_artifact_from_another_mesh_prep_run_is_refused() {
    let texture = png(|u, v| [CHECKS[check(u, v)]; 3]);
    let (dir, scene) = display_scene("display_other_surface", "Kd 0.5\nmap_Kd checks.png\n", None, &[("checks.png", texture)]);
    prepare_and_solve(&dir, &scene, false);
    // Another run of the same scene (other flags) writes another surface.
    let other = dir.join("other.surface.exr");
    let (mesh2, manifest2) = (dir.join("other.mesh.exr"), dir.join("other.manifest.ron"));
    run_ok("mesh-prep", &[s(&scene), "--mesh", s(&mesh2), "--manifest", s(&manifest2), "--surface", s(&other)]);
    let [mesh, manifest] = outputs(&dir);
    let (image, solution) = (dir.join("image.exr"), dir.join("solution.exr"));
    let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "--surface", s(&other), "-o", s(&image)];
    assert_refused("grid-gather", &args, &["other.surface.exr", "does not belong with the mesh"], &[&image]);
    // The solver too (no clusters: no input made from either tells it).
    let fresh = dir.join("fresh.solution.exr");
    let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "--surface", s(&other), "-o", s(&fresh)];
    assert_refused("hierarchical-solve", &args, &["other.surface.exr", "does not belong with the mesh"], &[&fresh]);
}

#[test]
fn a_translucent_sheet_seen_from_behind_shows_the_light_it_transmits_in_the_full_gather() {
    // The floor as a two-sided sheet (rho 0.25, tau 0.5) seen from below:
    // its lower face receives nothing, so it shows tau E / pi, E the
    // upper face's irradiance from the lamp (004 Eq. 4.4).
    let (rho, tau) = (0.25, 0.5);
    let (dir, scene) = display_scene("display_translucent", &format!("Kd {rho}\n"), None, &[]);
    let text = std::fs::read_to_string(&scene).unwrap();
    let overrides = format!(", materials: {{ \"floor\": (two_sided: Some(true), diffuse_transmittance: Some(({tau:?}, {tau:?}, {tau:?}))) }})");
    let below = text.replacen("eye: (0.5, 0.5, 2.0)", "eye: (0.5, 0.5, -2.0)", 1);
    std::fs::write(&scene, format!("{}{overrides}", below.strip_suffix(')').unwrap())).unwrap();
    prepare_and_solve(&dir, &scene, false);
    let image = gather(&dir, "full");
    // Seen from below (up +y), the image's x runs along -x: the floor point
    // is the point from above mirrored in x.
    let under = |x: f64, y: f64| {
        let p = ray_at(x, y, 0.0);
        [1.0 - p[0], p[1]]
    };
    let (mut checked, mut worst) = (0, 0.0f64);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(a, b)| under(f64::from(x) + a, f64::from(y) + b));
            if !corners.iter().all(|c| c.iter().all(|&v| (0.0..=1.0).contains(&v))) {
                continue;
            }
            let mut expected = 0.0;
            for k in 0..64 {
                let p = under(f64::from(x) + (f64::from(k % 8) + 0.5) / 8.0, f64::from(y) + (f64::from(k / 8) + 0.5) / 8.0);
                expected += tau * irradiance(p, [0.0, 0.0, 1.0]) / std::f64::consts::PI / 64.0;
            }
            let got = f64::from(image.rgb[(y * SIZE + x) as usize][0]);
            let error = (got - expected).abs() / expected;
            assert!(error < 0.0075, "pixel ({x}, {y}): radiance {got}, expected tau E / pi = {expected} (error {error})");
            checked += 1;
            worst = worst.max(error);
        }
    }
    eprintln!("translucent sheet from below: {checked} pixels, largest error {worst:.4}");
    assert!(checked > (SIZE * SIZE) as usize / 2);
    let report = std::fs::read_to_string(dir.join("full.report.ron")).unwrap();
    assert!(!report.contains("diffuse transmission"), "simulated, yet listed as skipped: {report}");
}

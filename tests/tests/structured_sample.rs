//! structured-sample (paper 002 Section 3) on the simple environment
//! (paper 002 Table 1, `mesh-prep --builtin simple-environment`), against
//! references written here: Lambert's polygon formula for the direct light
//! (`closed_form::lambert_polygon`) and, for B's one-bounce light (002 Eq.
//! 4), a Gauss-Legendre quadrature over A of A's exact radiosity.

use end_to_end::{camera_ray, refused, run_ok, s, scratch};
use schemas::image::{HdrImage, SINGLE_SURFACE};
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::samples::{Samples, Tag};
use std::f64::consts::PI;
use std::path::PathBuf;
use test_support::closed_form::lambert_polygon;

/// The prepared simple environment and the stage's outputs.
struct Run {
    dir: PathBuf,
    mesh: Mesh,
    manifest: Manifest,
    samples: Samples,
    image: HdrImage,
}

/// mesh-prep and structured-sample (one bounce: the exact configuration
/// of 002 Section 2.2, "ignoring the interaction from B to A") in `test`'s
/// scratch directory, with `extra` arguments.
fn structured(test: &str, extra: &[&str]) -> Run {
    let dir = scratch(test);
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &["--builtin", "simple-environment", "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let (samples, image) = (dir.join("samples.exr"), dir.join("image.exr"));
    let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&samples), "--image", s(&image), "--bounces", "1"];
    args.extend_from_slice(extra);
    run_ok("structured-sample", &args);
    Run {
        mesh: Mesh::read(&mesh).unwrap().0,
        manifest: read_ron::<Manifest>(&manifest).unwrap().value,
        samples: Samples::read(&samples).unwrap().0,
        image: HdrImage::read(&image).unwrap().0,
        dir,
    }
}

/// The scene as the references see it, mesh frame.
struct Scene {
    /// LS's two triangles.
    light: Vec<[[f64; 3]; 3]>,
    exitance: f64,
    /// A: the plane z = a_z, facing down, over `[x0, x1] x [y0, y1]`.
    a_z: f64,
    a_rect: [f64; 4],
    rho_a: f64,
    /// B: the plane z = b_z, facing up.
    b_z: f64,
    rho_b: f64,
    object_a: u32,
    object_b: u32,
}

impl Scene {
    fn of(run: &Run) -> Scene {
        let object = |name: &str| run.manifest.objects.iter().position(|o| o == name).unwrap() as u32;
        let corners = |o: u32| -> Vec<[[f64; 3]; 3]> {
            run.mesh.triangles.iter().filter(|t| t.object == o).map(|t| t.vertices.map(|v| run.mesh.positions[v as usize].map(f64::from))).collect()
        };
        let rect = |o: u32| {
            let points: Vec<[f64; 3]> = corners(o).into_iter().flatten().collect();
            let (x, y): (Vec<f64>, Vec<f64>) = points.iter().map(|p| (p[0], p[1])).unzip();
            let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
            let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            ([min(&x), max(&x), min(&y), max(&y)], points[0][2])
        };
        let (a, b, ls) = (object("A"), object("B"), object("LS"));
        let material = |o: u32| &run.manifest.materials[run.mesh.triangles.iter().find(|t| t.object == o).unwrap().material as usize];
        let ((a_rect, a_z), (_, b_z)) = (rect(a), rect(b));
        Scene {
            light: corners(ls),
            exitance: material(ls).emission[0],
            a_z,
            a_rect,
            rho_a: material(a).diffuse[0],
            b_z,
            rho_b: material(b).diffuse[0],
            object_a: a,
            object_b: b,
        }
    }

    /// Direct radiance reflected at `p` (normal `n`): `rho E F / pi`, F by
    /// Lambert's formula over LS's triangles (002 Eq. 2-3).
    fn direct(&self, p: [f64; 3], n: [f64; 3], rho: f64) -> f64 {
        let f: f64 = self.light.iter().map(|t| lambert_polygon(p, n, t)).sum();
        rho * self.exitance * f / PI
    }

    /// A's radiosity at `(x, y)` on A.
    fn radiosity_a(&self, x: f64, y: f64) -> f64 {
        PI * self.direct([x, y, self.a_z], [0.0, 0.0, -1.0], self.rho_a)
    }
}

/// Gauss-Legendre nodes and weights on [-1, 1], 8 points.
const GAUSS_8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// B's one-bounce radiance by 002 Eq. 4, `l_B(y) = rho_B / pi * int_A
/// B_A(x) cos cos / (pi r²) dA`, the planes `d` apart (`cos cos / r² =
/// d² / r⁴`): composite Gauss-Legendre, 10 x 10 panels of 8 x 8 points over
/// A. The kernel is smooth (B is at least `d` from A), so this is exact to
/// far below the 10% the tests measure.
struct OneBounce {
    points: Vec<(f64, f64, f64)>,
}

impl OneBounce {
    fn new(scene: &Scene) -> Self {
        let [x0, x1, y0, y1] = scene.a_rect;
        let panels = 10;
        let (hx, hy) = ((x1 - x0) / panels as f64, (y1 - y0) / panels as f64);
        let mut points = Vec::new();
        for i in 0..panels {
            for j in 0..panels {
                for (u, wu) in GAUSS_8 {
                    for (v, wv) in GAUSS_8 {
                        let x = x0 + hx * (i as f64 + 0.5 + 0.5 * u);
                        let y = y0 + hy * (j as f64 + 0.5 + 0.5 * v);
                        points.push((x, y, scene.radiosity_a(x, y) * wu * wv * 0.25 * hx * hy));
                    }
                }
            }
        }
        OneBounce { points }
    }

    fn radiance(&self, scene: &Scene, x: f64, y: f64) -> f64 {
        let d2 = (scene.a_z - scene.b_z).powi(2);
        let integral: f64 = self.points.iter().map(|&(px, py, w)| {
            let r2 = (px - x).powi(2) + (py - y).powi(2) + d2;
            w * d2 / (PI * r2 * r2)
        }).sum();
        scene.rho_b * integral / PI
    }
}

/// The mesh-frame point where the camera ray through the centre of pixel
/// `(px, py)` meets the plane `z` ([`end_to_end::camera_ray`], a pinhole
/// written apart from radiometry's).
fn camera_hit(run: &Run, px: usize, py: usize, z: f64) -> Option<[f64; 3]> {
    let c = &run.manifest.camera;
    let d = camera_ray(c, run.image.width as u32, run.image.height as u32, px as f64 + 0.5, py as f64 + 0.5);
    let along = (z - c.eye[2]) / d[2];
    (along > 0.0).then(|| [0, 1, 2].map(|k| c.eye[k] + along * d[k]))
}

/// Every single-surface pixel of A (0) and B (1): which, its radiance and
/// the reference's there (A: Lambert's formula; B: [`OneBounce`]).
fn receiver_pixels(run: &Run) -> Vec<(usize, f64, f64)> {
    let scene = Scene::of(run);
    let bounce = OneBounce::new(&scene);
    let surfaces = run.image.surfaces.as_ref().unwrap();
    let mut pixels = Vec::new();
    for py in 0..run.image.height {
        for px in 0..run.image.width {
            let i = py * run.image.width + px;
            if surfaces.flags[i] & SINGLE_SURFACE == 0 {
                continue;
            }
            let object = surfaces.object[i];
            let reference = if object == scene.object_a {
                let Some(p) = camera_hit(run, px, py, scene.a_z) else { continue };
                (0, scene.direct(p, [0.0, 0.0, -1.0], scene.rho_a))
            } else if object == scene.object_b {
                let Some(p) = camera_hit(run, px, py, scene.b_z) else { continue };
                (1, bounce.radiance(&scene, p[0], p[1]))
            } else {
                continue;
            };
            pixels.push((reference.0, f64::from(run.image.rgb[i][1]), reference.1));
        }
    }
    pixels
}

/// Per receiver (A, B): the fraction of its single-surface pixels whose
/// radiance is more than `tau` (relative) off the reference, and the
/// number of such pixels. (002 Table 2's "% > 10% err", relative per pixel
/// as `compare` measures it.)
fn fractions_over(run: &Run, tau: f64) -> [(f64, usize); 2] {
    let mut tally = [(0usize, 0usize); 2];
    for (k, value, r) in receiver_pixels(run) {
        tally[k].0 += 1;
        if (value - r).abs() > tau * r {
            tally[k].1 += 1;
        }
    }
    tally.map(|(n, over)| (over as f64 / n.max(1) as f64, n))
}

#[test]
fn every_samples_direct_luminance_is_lamberts_to_1e_9() {
    let run = structured("structured_direct", &[]);
    let scene = Scene::of(&run);
    let brightest = run.samples.samples.iter().map(|s| s.direct[1]).fold(0.0, f64::max);
    assert!(brightest > 0.0);
    let mut checked = 0;
    for (i, sample) in run.samples.samples.iter().enumerate() {
        let surface = &run.samples.surfaces[sample.surface as usize];
        let rho = run.manifest.materials[surface.material as usize].diffuse[1];
        let exact = scene.direct(sample.position, surface.normal, rho);
        for k in 0..3 {
            let error = (sample.direct[k] - exact).abs();
            assert!(error <= 1e-9 * exact.abs().max(1e-3 * brightest), "sample {i} ({:?}) at {:?}: direct {} vs Lambert {exact}", sample.reason, sample.position, sample.direct[k]);
        }
        checked += 1;
    }
    assert!(checked > 50, "{checked} samples");
}

/// On A: the density of samples in the tenth of A where the exact direct
/// luminance's gradient is largest, over A's mean density; and the mean of
/// `|grad|^2` over that tenth over its mean on A (what a density
/// proportional to the squared gradient would give).
fn gradient_concentration(test: &str) -> (f64, f64) {
    let run = structured(test, &[]);
    let scene = Scene::of(&run);
    // |grad l| of A's exact direct luminance on a 50 x 50 grid of cells,
    // by central differences of Lambert's formula.
    let [x0, x1, y0, y1] = scene.a_rect;
    let n = 50;
    let (hx, hy) = ((x1 - x0) / n as f64, (y1 - y0) / n as f64);
    let l = |x: f64, y: f64| scene.direct([x, y, scene.a_z], [0.0, 0.0, -1.0], scene.rho_a);
    let mut cells: Vec<(f64, usize)> = (0..n * n)
        .map(|k| {
            let (x, y) = (x0 + hx * ((k % n) as f64 + 0.5), y0 + hy * ((k / n) as f64 + 0.5));
            let e = 1e-4;
            let g = (((l(x + e, y) - l(x - e, y)) / (2.0 * e)).powi(2) + ((l(x, y + e) - l(x, y - e)) / (2.0 * e)).powi(2)).sqrt();
            (g, k)
        })
        .collect();
    cells.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mean = |c: &[(f64, usize)], p: i32| c.iter().map(|c| c.0.powi(p)).sum::<f64>() / c.len() as f64;
    let squared = mean(&cells[..n * n / 10], 2) / mean(&cells, 2);
    eprintln!("A's steepest tenth: |grad| {:.2} x its mean, |grad|^2 {squared:.2} x", mean(&cells[..n * n / 10], 1) / mean(&cells, 1));
    let steep: std::collections::HashSet<usize> = cells[..n * n / 10].iter().map(|c| c.1).collect();
    let on_a: Vec<[f64; 3]> = run.samples.samples.iter().filter(|s| run.samples.surfaces[s.surface as usize].object == scene.object_a).map(|s| s.position).collect();
    let in_steep = on_a
        .iter()
        .filter(|p| {
            let (i, j) = (((p[0] - x0) / hx).floor().clamp(0.0, (n - 1) as f64) as usize, ((p[1] - y0) / hy).floor().clamp(0.0, (n - 1) as f64) as usize);
            steep.contains(&(i + j * n))
        })
        .count();
    // Densities per unit area: the steepest tenth against A as a whole.
    let ratio = (in_steep as f64 / 0.1) / on_a.len() as f64;
    eprintln!("A: {} samples, {in_steep} in the steepest 10%: density ratio {ratio:.2}", on_a.len());
    (ratio, squared)
}

/// The samples follow the light's change at least as a density
/// proportional to the squared gradient would (uniform samples give 1).
/// Issue 16's example figure, 3 x the mean density in the steepest tenth,
/// is not met: the defaults give 2.10 (A's steepest tenth holds 66 of its
/// 314 samples). On this surface the gradient there is only 1.22 x its
/// mean (its square 1.43 x), so 3 x would take a density growing like the
/// gradient's sixth power.
#[test]
fn samples_concentrate_where_the_direct_gradient_is_large() {
    let (ratio, squared) = gradient_concentration("structured_gradient");
    assert!(ratio >= squared && ratio > 1.5, "density in the steepest 10% of A is {ratio:.2} x the mean; |grad|^2 there is {squared:.2} x");
}

#[test]
fn table_2_in_shape_few_pixels_over_ten_percent() {
    let run = structured("structured_table2", &[]);
    let [(a, na), (b, nb)] = fractions_over(&run, 0.10);
    let on = |object: u32| run.samples.samples.iter().filter(|s| run.samples.surfaces[s.surface as usize].object == object).count();
    let scene = Scene::of(&run);
    eprintln!(
        "over 10%: A {:.2}% of {na} pixels ({} samples), B {:.2}% of {nb} pixels ({} samples)",
        100.0 * a,
        on(scene.object_a),
        100.0 * b,
        on(scene.object_b)
    );
    assert!(na > 1000 && nb > 1000, "A {na}, B {nb} pixels");
    assert!(a < 0.02, "A: {:.2}% of pixels over 10% (paper 002: 1.52%)", 100.0 * a);
    assert!(b < 0.01, "B: {:.2}% of pixels over 10% (paper 002: 0.02%)", 100.0 * b);
}

/// A's light is its direct light alone (one bounce, B's reflection not
/// returned), which the display shows from the probes or, along a
/// surface's border, evaluated where the camera's ray lands: every pixel
/// of A within 0.5% of Lambert's formula. Filtered from the samples with
/// the rest (before), 20.4% of A's pixels were over 0.5% and 1.7% over
/// 2%, along A's border and across its peak.
#[test]
fn the_direct_light_is_shown_per_pixel() {
    let run = structured("structured_shown", &[]);
    let [(a, n), _] = fractions_over(&run, 0.005);
    assert!(n > 1000, "A {n} pixels");
    assert_eq!(a, 0.0, "{:.3}% of A's pixels over 0.5%", 100.0 * a);
}

/// B, lit only by what A reflects: its pixels' sum within 0.4% of the
/// quadrature's over the same pixels. The samples placed after the
/// shooting gathered each polygon's mean radiosity from all of it, and A's
/// polygons (isolux bands round the peak over the light) are brightest on
/// the side away from B: B was +0.63%; gathering each triangle's own
/// light, +0.19%.
#[test]
fn b_receives_what_a_reflects() {
    let run = structured("structured_b_mean", &[]);
    let (sum, reference) = receiver_pixels(&run).iter().filter(|p| p.0 == 1).fold((0.0, 0.0), |(s, r), p| (s + p.1, r + p.2));
    assert!((sum / reference - 1.0).abs() < 0.004, "B: {:+.3}% against the quadrature", 100.0 * (sum / reference - 1.0));
}

#[test]
fn reruns_are_bit_identical_on_any_thread_count_and_tags_follow_reasons() {
    let first = structured("structured_rerun", &[]);
    let bytes = |name: &str| std::fs::read(first.dir.join(name)).unwrap();
    let (samples, image) = (bytes("samples.exr"), bytes("image.exr"));
    let again = structured("structured_rerun", &[]);
    assert_eq!(std::fs::read(again.dir.join("samples.exr")).unwrap(), samples);
    assert_eq!(std::fs::read(again.dir.join("image.exr")).unwrap(), image);
    // One thread: the same bytes (every parallel step is keyed by its
    // work item and collected in order).
    let (one, one_image) = (again.dir.join("one.exr"), again.dir.join("one-image.exr"));
    let (mesh, manifest) = (again.dir.join("mesh.exr"), again.dir.join("manifest.ron"));
    let out = std::process::Command::new(end_to_end::bin("structured-sample"))
        .args(["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&one), "--image", s(&one_image), "--bounces", "1"])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // (The headers differ by the output paths on the command line; the
    // content must not differ at all.)
    let (threaded, single) = (&again.samples, Samples::read(&one).unwrap().0);
    assert!(threaded.samples == single.samples && threaded.surfaces == single.surfaces && threaded.emitters == single.emitters, "one thread changes samples.exr");
    let single_image = HdrImage::read(&one_image).unwrap().0;
    assert!(again.image.rgb == single_image.rgb && again.image.coverage == single_image.coverage && again.image.surfaces == single_image.surfaces, "one thread changes image.exr");
    // View-dependent samples are display samples, never an emitter's
    // vertex; A (lit directly) has light-transfer samples, and B (lit
    // only by A) display samples on the contours of its indirect light.
    let scene = Scene::of(&first);
    let count = |object: u32, wanted: &dyn Fn(&schemas::samples::Sample) -> bool| {
        first.samples.samples.iter().filter(|s| first.samples.surfaces[s.surface as usize].object == object && wanted(s)).count()
    };
    for s in &first.samples.samples {
        assert!(s.reason.tag() != Tag::ViewDependent || s.emitter == schemas::samples::NO_EMITTER, "{s:?}");
    }
    assert!(count(scene.object_a, &|s| s.emitter != schemas::samples::NO_EMITTER) > 20);
    assert!(count(scene.object_b, &|s| s.reason == schemas::samples::Reason::IsoluxContour && s.emitter == schemas::samples::NO_EMITTER) > 5);
}

#[test]
fn a_bad_parameter_is_refused_naming_it() {
    let dir = scratch("structured_refused");
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &["--builtin", "simple-environment", "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let (samples, image) = (dir.join("samples.exr"), dir.join("image.exr"));
    let line = refused("structured-sample", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&samples), "--image", s(&image), "--filter-radius", "-1"]);
    assert!(line.contains("filter_radius must be in (0, 10]"), "{line}");
    assert!(!samples.exists() && !image.exists());
}


/// A shadow scene, axis-aligned: a 1 m square lamp facing down at z = 2
/// over `[1.5, 2.5]²`, a black 0.8 m square plate over `[1.6, 2.4]²` at
/// z = 0.3, a 4 m square floor at z = 0 (reflectance 0.5). From a floor
/// point `p` the plate hides the part of the lamp inside the plate's
/// projection from `p` onto the lamp's plane, `q = p + (o - p) h_lamp /
/// h_plate`: a rectangle, so the seen fraction of the lamp's area is
/// exact, and with it the umbra (none seen) and the penumbra (some).
/// Fully lit samples carry Lambert's value to 1e-9, umbra samples none,
/// and the samples crowd into the penumbra (at least 3 x the floor's mean
/// density; 18.5 x measured).
#[test]
fn shadow_samples_lie_across_the_exact_penumbra_and_umbra() {
    let dir = scratch("structured_shadow");
    let mut scene = test_support::scenes::QuadScene { camera: ([2.0, -2.5, 3.0], [2.0, 2.0, 0.0]), ..Default::default() };
    scene.material("floor", 0.5, 0.0).material("black", 0.0, 0.0).material("lamp", 0.0, 10.0);
    scene.quad("floor", "floor", test_support::scenes::rectangle(2, 0.0, [0.0, 0.0], [4.0, 4.0]), [0.0, 0.0, 1.0]);
    scene.quad("plate", "black", test_support::scenes::rectangle(2, 0.3, [1.6, 1.6], [2.4, 2.4]), [0.0, 0.0, 1.0]);
    scene.quad("lamp", "lamp", test_support::scenes::rectangle(2, 2.0, [1.5, 1.5], [2.5, 2.5]), [0.0, 0.0, -1.0]);
    let scene_path = scene.write(&dir);
    let (mesh_path, manifest_path, samples_path, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("samples.exr"), dir.join("image.exr"));
    run_ok("mesh-prep", &[s(&scene_path), "--mesh", s(&mesh_path), "--manifest", s(&manifest_path)]);
    run_ok("structured-sample", &["--mesh", s(&mesh_path), "--manifest", s(&manifest_path), "-o", s(&samples_path), "--image", s(&image)]);
    let mesh = Mesh::read(&mesh_path).unwrap().0;
    let manifest = read_ron::<Manifest>(&manifest_path).unwrap().value;
    let samples = Samples::read(&samples_path).unwrap().0;
    // Mesh-frame rectangles [x0, x1, y0, y1] and heights of each object.
    let object = |name: &str| manifest.objects.iter().position(|o| o == name).unwrap() as u32;
    let rect = |o: u32| {
        let p: Vec<[f64; 3]> = mesh.triangles.iter().filter(|t| t.object == o).flat_map(|t| t.vertices.map(|v| mesh.positions[v as usize].map(f64::from))).collect();
        let f = |k: usize, max: bool| p.iter().map(|q| q[k]).fold(if max { f64::NEG_INFINITY } else { f64::INFINITY }, |a, b| if max { a.max(b) } else { a.min(b) });
        ([f(0, false), f(0, true), f(1, false), f(1, true)], p[0][2])
    };
    let ((lamp, z_lamp), (plate, z_plate), (_, z_floor)) = (rect(object("lamp")), rect(object("plate")), rect(object("floor")));
    let lamp_triangles: Vec<[[f64; 3]; 3]> =
        mesh.triangles.iter().filter(|t| t.object == object("lamp")).map(|t| t.vertices.map(|v| mesh.positions[v as usize].map(f64::from))).collect();
    // The seen fraction of the lamp's area from floor point (x, y).
    let seen = |x: f64, y: f64| {
        let k = (z_lamp - z_floor) / (z_plate - z_floor);
        let hidden = |p: f64, o0: f64, o1: f64, l0: f64, l1: f64| ((p + (o1 - p) * k).min(l1) - (p + (o0 - p) * k).max(l0)).max(0.0);
        1.0 - hidden(x, plate[0], plate[1], lamp[0], lamp[1]) * hidden(y, plate[2], plate[3], lamp[2], lamp[3]) / ((lamp[1] - lamp[0]) * (lamp[3] - lamp[2]))
    };
    let floor = object("floor");
    let on_floor: Vec<&schemas::samples::Sample> = samples.samples.iter().filter(|s| samples.surfaces[s.surface as usize].object == floor).collect();
    let (mut lit, mut in_penumbra, mut penumbra_area) = (0, 0, 0.0);
    for s in &on_floor {
        let v = seen(s.position[0], s.position[1]);
        if v >= 1.0 {
            // Fully lit: the visibility rays are all clear, so Lambert's value.
            let exact = 0.5 * 10.0 * lamp_triangles.iter().map(|t| lambert_polygon(s.position, [0.0, 0.0, 1.0], t)).sum::<f64>() / PI;
            assert!((s.direct[1] - exact).abs() <= 1e-9 * exact, "lit sample at {:?}: {} vs {exact}", s.position, s.direct[1]);
            lit += 1;
        }
        if v <= 0.0 {
            assert_eq!(s.direct, [0.0; 3], "an umbra sample sees no light: {s:?}");
        }
        if v > 0.0 && v < 1.0 {
            in_penumbra += 1;
        }
        if s.reason == schemas::samples::Reason::Umbra {
            assert!(v <= 0.0 || s.direct[1] < 0.05 * 0.5 * 10.0 / PI, "an umbra-tagged sample in the light: {s:?} sees {v}");
        }
    }
    // The penumbra's area on a 200 x 200 grid over the floor.
    let [fx0, fx1, fy0, fy1] = rect(floor).0;
    let n = 200;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (fx0 + (fx1 - fx0) * (i as f64 + 0.5) / n as f64, fy0 + (fy1 - fy0) * (j as f64 + 0.5) / n as f64);
            let v = seen(x, y);
            if v > 0.0 && v < 1.0 {
                penumbra_area += (fx1 - fx0) * (fy1 - fy0) / (n * n) as f64;
            }
        }
    }
    let floor_area = (fx1 - fx0) * (fy1 - fy0);
    let ratio = (in_penumbra as f64 / penumbra_area) / (on_floor.len() as f64 / floor_area);
    let shadow_tagged = on_floor.iter().filter(|s| s.reason.tag() == Tag::ShadowBoundary).count();
    eprintln!("floor: {} samples, {lit} fully lit, {in_penumbra} in the penumbra ({penumbra_area:.3} of {floor_area:.1} m²): density {ratio:.2} x the mean; {shadow_tagged} tagged shadow boundary", on_floor.len());
    assert!(lit > 20 && shadow_tagged > 20);
    assert!(ratio >= 3.0, "penumbra density {ratio:.2} x the floor's mean");
}

/// A 1 m cube room, open at the front, whose lamp (the middle third of
/// the ceiling's span, facing down) hangs 1 cm under the ceiling: the
/// ceiling is lit only by reflection, and over the lamp it sees nothing.
/// Where a surface lit only by reflection receives less than half of
/// what it would unoccluded, its samples mark the outline as a shadow
/// boundary, so the display's filter does not spread the darkness over
/// the lamp into the ceiling round it (McGuire's boxes, whose lamps hang
/// so: the ceiling -1.9% -> -0.5% against hierarchical-solve). Every
/// shadow-boundary sample of the ceiling lies within 0.1 m of the lamp's
/// outline (61 samples, the farthest 0.083 m: a cell of the coarser
/// probing before the shooting, `OUTLINE_COARSENING`), and there are some
/// (none before); the closed room's ceiling, whose lamp is flush, has
/// none.
///
/// The outline's samples are vertices of the ceiling's polygons, which
/// take the visible fraction inside a triangle whose corners disagree,
/// and whose casting points over the lamp (sending nothing) hide
/// nothing: what the ceiling's polygons shoot in all is the same at
/// lattice spacings 0.25, 0.24 and 0.2, within 0.5% (0.2395, 0.2401 and
/// 0.2403 W; 0.2268, 0.2489 and 0.2442 W before, 9.7% apart).
#[test]
fn a_ceiling_over_a_hung_lamp_marks_the_lamps_outline() {
    use test_support::scenes::{closed_box, rectangle, QuadScene};
    let mut hung = QuadScene { camera: ([0.5, -1.5, 0.5], [0.5, 0.5, 0.7]), ..Default::default() };
    hung.material("wall", 0.8, 0.0).material("lamp", 0.0, 10.0);
    hung.quad("lamp", "lamp", rectangle(2, 0.99, [1.0 / 3.0, 1.0 / 3.0], [2.0 / 3.0, 2.0 / 3.0]), [0.0, 0.0, -1.0]);
    hung.quad("ceiling", "wall", rectangle(2, 1.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, -1.0]);
    hung.quad("floor", "wall", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    hung.quad("back", "wall", rectangle(1, 1.0, [0.0, 0.0], [1.0, 1.0]), [0.0, -1.0, 0.0]);
    hung.quad("left", "wall", rectangle(0, 0.0, [0.0, 0.0], [1.0, 1.0]), [1.0, 0.0, 0.0]);
    hung.quad("right", "wall", rectangle(0, 1.0, [0.0, 0.0], [1.0, 1.0]), [-1.0, 0.0, 0.0]);
    // The ceiling's shadow-boundary samples: how many, and the farthest
    // from the lamp's outline (x, y, in the mesh frame); and the power its
    // polygons shot (green), W.
    let marked = |test: &str, scene: &QuadScene, lattice_spacing: &str| -> (usize, f64, f64) {
        let dir = scratch(test);
        let scene_path = scene.write(&dir);
        let (mesh, manifest, samples, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("samples.exr"), dir.join("image.exr"));
        run_ok("mesh-prep", &[s(&scene_path), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
        run_ok("structured-sample", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--lattice-spacing", lattice_spacing, "-o", s(&samples), "--image", s(&image)]);
        let (mesh, manifest) = (Mesh::read(&mesh).unwrap().0, read_ron::<Manifest>(&manifest).unwrap().value);
        let object = |name: &str| manifest.objects.iter().position(|o| o == name).unwrap() as u32;
        let lamp = mesh.triangles.iter().filter(|t| t.object == object("lamp")).flat_map(|t| t.vertices.map(|v| mesh.positions[v as usize].map(f64::from)));
        let (lo, hi) = lamp.fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])]));
        let from_outline = |p: &[f64; 3]| {
            let (dx, dy) = ((lo[0] - p[0]).max(p[0] - hi[0]), (lo[1] - p[1]).max(p[1] - hi[1]));
            if dx <= 0.0 && dy <= 0.0 { -dx.max(dy) } else { dx.max(0.0).hypot(dy.max(0.0)) }
        };
        let samples = Samples::read(&samples).unwrap().0;
        let on_ceiling = |x: &&schemas::samples::Sample| samples.surfaces[x.surface as usize].object == object("ceiling");
        let marked: Vec<f64> = samples.samples.iter().filter(on_ceiling).filter(|x| x.reason.tag() == Tag::ShadowBoundary).map(|x| from_outline(&x.position)).collect();
        let ceiling = samples.surfaces.iter().position(|x| x.object == object("ceiling")).unwrap() as u32;
        let power = samples.emitters.iter().filter(|e| e.surface == ceiling).map(|e| e.area * e.shot[1]).sum();
        (marked.len(), marked.iter().copied().fold(0.0, f64::max), power)
    };
    let (count, farthest, power) = marked("structured_hung_lamp", &hung, "0.25");
    eprintln!("hung lamp: {count} shadow-boundary samples on the ceiling, the farthest {farthest:.3} m from the lamp's outline; the ceiling shot {power:.4} W");
    assert!(count >= 8, "{count} shadow-boundary samples on the ceiling");
    assert!(farthest < 0.1, "a shadow-boundary sample {farthest} m from the lamp's outline");
    for spacing in ["0.24", "0.2"] {
        let other = marked("structured_hung_lamp_lattice", &hung, spacing).2;
        eprintln!("lattice spacing {spacing}: the ceiling shot {other:.4} W");
        assert!((other / power - 1.0).abs() < 5e-3, "the ceiling shot {other} W at lattice spacing {spacing}, {power} W at 0.25");
    }
    assert_eq!(marked("structured_flush_lamp", &closed_box(1.0, 0.8, 10.0), "0.25").0, 0, "shadow-boundary samples on a ceiling with a flush lamp");
}

/// A closed cube room of reflectance 0.9 (the ceiling's middle ninth a
/// lamp of exitance 10 that reflects too) keeps all its light: its
/// surfaces reflect `R = rho (Phi + R)`, `R = rho Phi / (1 - rho)` = 10 W,
/// and the secondary emitters must shoot that power between them (the sum
/// of area times radiosity shot, within 1%; -0.35% measured, the shooting
/// stopping at a ten-thousandth of the emitted power unshot; -1.65%
/// before the receiving triangles a few lengths from the sender took the
/// midpoint rule, -1.75% stopping at a thousandth). Before the
/// samples on a surface's edges took the neighbouring surfaces' factors
/// as their limit and each polygon passed on what its area received,
/// 39% of it was lost (`structured_sample::shooting`).
#[test]
fn a_closed_room_shoots_all_the_light_it_reflects() {
    let (rho, exitance) = (0.9, 10.0);
    let (_, samples) = closed_room_run("structured_closed_room", &test_support::scenes::closed_box(1.0, rho, exitance));
    keeps_its_light(&samples, rho, exitance);
}

/// mesh-prep and structured-sample at its defaults on `scene` in `test`'s
/// scratch directory: the manifest and the samples.
fn closed_room_run(test: &str, scene: &test_support::scenes::QuadScene) -> (Manifest, Samples) {
    let dir = scratch(test);
    let scene_path = scene.write(&dir);
    let (mesh, manifest, samples, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("samples.exr"), dir.join("image.exr"));
    run_ok("mesh-prep", &[s(&scene_path), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    run_ok("structured-sample", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&samples), "--image", s(&image)]);
    (read_ron::<Manifest>(&manifest).unwrap().value, Samples::read(&samples).unwrap().0)
}

/// The secondary emitters of `closed_box(1.0, rho, exitance)` (with
/// anything of reflectance `rho` inside) shot `R = rho Phi / (1 - rho)`
/// between them, the sum of area times radiosity shot, within 1% in
/// every channel.
fn keeps_its_light(samples: &Samples, rho: f64, exitance: f64) {
    let reflected = rho * exitance / 9.0 / (1.0 - rho);
    for c in 0..3 {
        let shot: f64 = samples.emitters.iter().map(|e| e.area * e.shot[c]).sum();
        eprintln!("channel {c}: {shot:.5} W shot, {:+.3}%", 100.0 * (shot / reflected - 1.0));
        assert!((shot / reflected - 1.0).abs() < 0.01, "channel {c}: {shot} W shot against {reflected} W reflected");
    }
}

/// A closed room of reflectance 0.5 ([`a_closed_room_shoots_all_the_light_it_reflects`]'s,
/// darker so that its 700 secondary emitters converge within the default
/// `max_shots`) with a faceted ball hung in it: a band of a sphere (radius
/// 0.15, latitudes -60 to 60 degrees, 24 x 6 planar trapezoids a few
/// centimetres wide, facets of one curved surface whose extent, 0.3 m,
/// the stage's spacings are fractions of: `surfaces::smooth_patches`)
/// closed by two flat caps. Per facet, the secondary emitters must cover
/// the facet (their areas' sum against the facet's own, from its
/// corners, within 1e-6, the mesh's f32 positions; 7e-8 measured): with
/// the spacing along edges longer than a facet's sides, the thinning kept
/// one or two of its corners and its polygons covered none of it (the
/// sphere of McGuire's `CornellBox-Glossy` was covered over 36% of its
/// area). And the room keeps all its light, `rho Phi / (1 - rho)` shot in
/// all, within 1% (-0.09% measured).
#[test]
fn the_facets_of_a_ball_send_from_all_their_area() {
    use glam::DVec3;
    use test_support::scenes::closed_box;
    let (rho, exitance) = (0.5, 10.0);
    let mut scene = closed_box(1.0, rho, exitance);
    let (centre, radius, around) = (DVec3::new(0.5, 0.5, 0.45), 0.15, 24);
    let latitudes: Vec<f64> = (0..=6).map(|k| (-60.0 + 20.0 * k as f64).to_radians()).collect();
    let at = |latitude: f64, k: usize| {
        let longitude = 2.0 * PI * k as f64 / around as f64;
        centre + radius * DVec3::new(latitude.cos() * longitude.cos(), latitude.cos() * longitude.sin(), latitude.sin())
    };
    // Each facet's outward normal and area (two triangles of its corners).
    let mut facets: Vec<(DVec3, f64)> = Vec::new();
    for band in latitudes.windows(2) {
        for k in 0..around {
            let corners = [at(band[0], k), at(band[0], k + 1), at(band[1], k + 1), at(band[1], k)];
            let halves = [(corners[1] - corners[0]).cross(corners[2] - corners[0]), (corners[2] - corners[0]).cross(corners[3] - corners[0])];
            facets.push((halves[0].normalize(), 0.5 * (halves[0].length() + halves[1].length())));
            scene.quad("ball", "wall", corners.map(|c| c.to_array()), (corners.iter().sum::<DVec3>() / 4.0 - centre).to_array());
        }
    }
    for (latitude, normal) in [(latitudes[0], [0.0, 0.0, -1.0]), (latitudes[6], [0.0, 0.0, 1.0])] {
        for k in (0..around).step_by(2) {
            let corners = [DVec3::new(centre.x, centre.y, at(latitude, k).z), at(latitude, k), at(latitude, k + 1), at(latitude, k + 2)];
            scene.quad("cap", "wall", corners.map(|c| c.to_array()), normal);
        }
    }
    let (manifest, samples) = closed_room_run("structured_faceted_ball", &scene);
    let mut checked = 0;
    for (index, surface) in samples.surfaces.iter().enumerate().filter(|(_, x)| manifest.objects[x.object as usize] == "ball") {
        let (_, area) = facets.iter().find(|(n, _)| n.distance(DVec3::from(surface.normal)) < 1e-6).expect("a surface of the ball with no facet's normal");
        let covered: f64 = samples.emitters.iter().filter(|e| e.surface == index as u32).map(|e| e.area).sum();
        assert!((covered / area - 1.0).abs() < 1e-6, "a facet of {area:.9} m² with secondary emitters over {covered:.9} m² ({:.2e})", covered / area - 1.0);
        checked += 1;
    }
    assert_eq!(checked, facets.len(), "surfaces of the ball");
    keeps_its_light(&samples, rho, exitance);
}

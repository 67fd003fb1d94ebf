//! Tests over small in-memory scenes with known answers.

use crate::gouraud::{Gouraud, Smoothing};
use crate::film::pixel_offset;
use crate::{gather, Mode, Params, Rendered, Scene};
use glam::{dvec3, DVec3};
use radiometry::geometry::TriangleGeometry;
use stage_kit::scene::mesh_triangles;
use radiometry::sampling::Stream;
use radiometry::subdivision::{children, Corners, ROOT};
use schemas::header::{Provenance, Schema};
use schemas::mesh::{Camera, Effects, Manifest, Material, Mesh, MeshStatistics, Triangle};
use schemas::solution::{Element, LeafSlope, Solution, NONE};
use std::f64::consts::PI;
use test_support::closed_form::floor_plane;
use std::path::Path;

fn provenance() -> Provenance {
    Provenance::in_memory("test")
}

/// A mesh of the given triangles (corners counter-clockwise from the front).
fn mesh(triangles: &[[DVec3; 3]]) -> Mesh {
    let mut positions = Vec::new();
    let mut tris = Vec::new();
    for t in triangles {
        let base = positions.len() as u32;
        positions.extend(t.iter().map(|p| p.as_vec3().to_array()));
        let g = TriangleGeometry::new(*t);
        tris.push(Triangle {
            vertices: [base, base + 1, base + 2],
            material: 0,
            object: 0,
            area: g.area as f32,
            normal: g.normal.as_vec3().to_array(),
        });
    }
    Mesh { header: Mesh::header(provenance()), positions, triangles: tris }
}

fn manifest(eye: DVec3, target: DVec3, size: u32) -> Manifest {
    let black = [0.0; 3];
    Manifest {
        header: Manifest::header(provenance()),
        world_from_mesh_translation: [0.0; 3],
        camera: Camera { eye: eye.to_array(), target: target.to_array(), up: [0.0, 1.0, 0.0], vertical_fov_deg: 60.0, width: size, height: size },
        materials: vec![Material::diffuse("grey", [0.5; 3], black)],
        objects: vec!["square".into()],
        goniometric_lights: vec![],
        effects: Effects::default(),
        statistics: MeshStatistics::default(),
    }
}

/// Every triangle subdivided `depth` levels by the 1:4 rule; every element
/// gets the radiosity `b(triangle, its corners)`.
fn solution(triangle_count: usize, depth: u32, b: impl Fn(u32, &Corners) -> f32) -> Solution {
    let element = |triangle: u32, parent: u32, level: u32, c: &Corners| Element {
        triangle,
        parent,
        first_child: NONE,
        level,
        corners: c.map(|uv| uv.map(|x| x as f32)),
        area: 0.5f32.powi(2 * level as i32),
        radiosity: [b(triangle, c); 3],
    };
    let mut elements: Vec<Element> = (0..triangle_count as u32).map(|t| element(t, NONE, 0, &ROOT)).collect();
    let mut frontier: Vec<(u32, Corners)> = (0..triangle_count as u32).map(|t| (t, ROOT)).collect();
    for level in 1..=depth {
        let mut next = Vec::new();
        for (i, c) in frontier {
            let first = elements.len() as u32;
            elements[i as usize].first_child = first;
            let triangle = elements[i as usize].triangle;
            for (k, child) in children(&c).iter().enumerate() {
                elements.push(element(triangle, i, level, child));
                next.push((first + k as u32, *child));
            }
        }
        frontier = next;
    }
    Solution { header: Solution::header(provenance()), elements, clusters: vec![], links: vec![], slopes: vec![] }
}

/// The unit square in z = 0 facing +z, split along its diagonal (0,0)-(1,1):
/// triangle 0 below the diagonal (x > y), triangle 1 above.
fn square() -> [[DVec3; 3]; 2] {
    let (a, b, c, d) = (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(1.0, 1.0, 0.0), dvec3(0.0, 1.0, 0.0));
    [[a, b, c], [a, c, d]]
}

/// Camera 2 m in front of the square's centre: the square spans about 28
/// of the 64 rows, the image border sees nothing.
fn front_camera() -> Manifest {
    manifest(dvec3(0.5, 0.5, 2.0), dvec3(0.5, 0.5, 0.0), 64)
}

fn render(params: &Params, mesh: &Mesh, manifest: &Manifest, solution: &Solution) -> Rendered {
    let scene = Scene { mesh, manifest, manifest_path: Path::new("manifest.ron"), solution, solution_path: Path::new("solution.exr") };
    gather(params, &scene, &|_| {}).expect("render")
}

const SMOOTH: Smoothing = Smoothing { crease_angle_deg: 30.0, weld_tolerance: 1e-7, material_seams: true, mean_passes: 0, leaf_gradients: false };

/// Vertex radiosity over `triangles`, all of material 0.
fn gouraud(triangles: &[TriangleGeometry], solution: &Solution, smoothing: Smoothing) -> Gouraud {
    Gouraud::new(triangles, &vec![0; triangles.len()], solution, Path::new("s.exr"), smoothing).unwrap()
}

#[test]
fn uniform_radiosity_gives_b_over_pi_times_coverage() {
    let mesh = mesh(&square());
    let image = render(&Params::default(), &mesh, &front_camera(), &solution(2, 2, |_, _| 2.0));
    let expected = 2.0 / PI;
    for (rgb, &a) in image.rgb.iter().zip(&image.coverage) {
        for channel in rgb {
            assert!((f64::from(*channel) - expected * f64::from(a)).abs() < 1e-6, "{rgb:?} at coverage {a}");
        }
    }
    let full = image.coverage.iter().filter(|&&a| a == 1.0).count();
    assert!(full > 500, "the square covers the image centre: {full} pixels");
    assert_eq!(image.coverage[0], 0.0, "the corner pixel misses");
    assert_eq!(image.rgb[0], [0.0; 3]);
    assert!(image.coverage.iter().any(|&a| a > 0.0 && a < 1.0), "the square's outline is partly covered");
    assert_eq!(image.counters["rays_cast"], 64.0 * 64.0 * 4.0);
    assert_eq!(image.counters["leaf_elements"], 32.0);
    // Each leaf shown as four (leaf gradients, by default): 81 distinct
    // points on the 8 x 8 grid of the square; 25 on the leaves' 4 x 4.
    assert_eq!(image.counters["vertices"], 81.0);
    let own = render(&Params { leaf_gradients: false, ..Params::default() }, &mesh, &front_camera(), &solution(2, 2, |_, _| 2.0));
    assert_eq!(own.counters["vertices"], 25.0);
}

/// The red channel as radiosity: B = pi L.
fn b_of(image: &Rendered, x: usize, y: usize) -> f64 {
    f64::from(image.rgb[y * image.width + x][0]) * PI
}

#[test]
fn different_triangles_blend_continuously_across_the_flat_diagonal() {
    let mesh = mesh(&square());
    let two_values = solution(2, 2, |t, _| if t == 0 { 1.0 } else { 3.0 });
    // The leaves' own values: each leaf shown as four on its gradient
    // draws the step over half the width (leaf_gradients_* below).
    let image = render(&Params { spp: 16, leaf_gradients: false, ..Params::default() }, &mesh, &front_camera(), &two_values);
    let full = |x: usize, y: usize| image.coverage[y * image.width + x] == 1.0;
    let mut largest_step: f64 = 0.0;
    let mut on_diagonal = Vec::new();
    for y in 0..image.height {
        for x in 1..image.width {
            if full(x - 1, y) && full(x, y) {
                largest_step = largest_step.max((b_of(&image, x, y) - b_of(&image, x - 1, y)).abs());
            }
        }
        // World y grows upwards, image y downwards: the diagonal x = y of the
        // square is the image's anti-diagonal x + y = 63 around the centre.
        let x = 63 - y;
        if full(x, y) && (x as i64 - 32).abs() < 10 {
            on_diagonal.push(b_of(&image, x, y));
        }
    }
    // Flat shading would jump by 2 across the diagonal; the steepest
    // Gouraud slope is 1 per 0.177 m leaf height, 0.036 m per pixel.
    assert!(largest_step < 0.35, "adjacent pixels differ by {largest_step}");
    assert!(on_diagonal.len() > 10);
    for b in on_diagonal {
        assert!((b - 2.0).abs() < 0.25, "the diagonal is the area-weighted mean 2, got {b}");
    }
    // Far from the diagonal each triangle keeps its own radiosity: near
    // corner (1, 0) (image right, bottom) B = 1; near (0, 1) B = 3.
    let (lo, hi) = (b_of(&image, 44, 44), b_of(&image, 19, 19));
    assert!((lo - 1.0).abs() < 1e-5 && (hi - 3.0).abs() < 1e-5, "{lo} {hi}");
}

#[test]
fn vertex_values_are_area_weighted_means_and_a_crease_stays_sharp() {
    let two_values = |t: u32, _: &Corners| if t == 0 { 1.0 } else { 3.0 };
    // uv of the point (s, s) in each triangle: (u + v, v) in 0, (u, u + v) in 1.
    let on_diagonal = |t: u32, s: f64| if t == 0 { [0.0, s] } else { [s, 0.0] };
    let flat = mesh_triangles(&mesh(&square()));
    let g = gouraud(&flat, &solution(2, 2, two_values), SMOOTH);
    for s in [0.0, 0.1, 0.25, 0.4, 0.5, 0.8, 1.0] {
        for t in 0..2 {
            let b = g.radiosity(t, on_diagonal(t, s));
            assert!((b[0] - 2.0).abs() < 1e-12, "flat, triangle {t} at {s}: {b:?}");
        }
    }
    // Fold triangle 1 up by 90 degrees about the diagonal: a floor and a wall.
    let [floor, wall] = square();
    let folded = [floor, [wall[0], wall[1], dvec3(0.5, 0.5, 0.5f64.sqrt())]];
    let folded = mesh_triangles(&mesh(&folded));
    assert!(folded[0].normal.dot(folded[1].normal).abs() < 1e-12);
    let g = gouraud(&folded, &solution(2, 2, two_values), SMOOTH);
    for s in [0.0, 0.25, 0.4, 1.0] {
        assert!((g.radiosity(0, on_diagonal(0, s))[0] - 1.0).abs() < 1e-12);
        assert!((g.radiosity(1, on_diagonal(1, s))[0] - 3.0).abs() < 1e-12);
    }
    // A crease angle over 90 degrees blends them again.
    let wide = Smoothing { crease_angle_deg: 95.0, ..SMOOTH };
    let g = gouraud(&folded, &solution(2, 2, two_values), wide);
    let blended = g.radiosity(0, on_diagonal(0, 0.4))[0];
    assert!((blended - 2.0).abs() < 1e-6, "areas differ by the f32 rounding of the fold: {blended}");
}

#[test]
fn a_material_boundary_on_a_flat_surface_stays_sharp_unless_seams_are_off() {
    // A light set flush into a ceiling: flat, but B jumps with emission.
    let flat = mesh_triangles(&mesh(&square()));
    let sol = solution(2, 2, |t, _| if t == 0 { 1.0 } else { 3.0 });
    let seams = Gouraud::new(&flat, &[0, 1], &sol, Path::new("s.exr"), SMOOTH).unwrap();
    assert!((seams.radiosity(0, [0.0, 0.4])[0] - 1.0).abs() < 1e-12);
    assert!((seams.radiosity(1, [0.4, 0.0])[0] - 3.0).abs() < 1e-12);
    let blended = Smoothing { material_seams: false, ..SMOOTH };
    let g = Gouraud::new(&flat, &[0, 1], &sol, Path::new("s.exr"), blended).unwrap();
    assert!((g.radiosity(0, [0.0, 0.4])[0] - 2.0).abs() < 1e-12);
}

#[test]
fn interpolation_inside_a_subdivided_triangle_matches_the_hand_computation() {
    // One triangle, one level: children (corner 0, corner 1, corner 2,
    // middle) with B = a, b, c, d and equal areas.
    let (a, b, c, d) = (1.0, 2.0, 4.0, 8.0);
    let values = [a, b, c, d];
    let one = [square()[0]];
    let mut sol = solution(1, 1, |_, _| 0.0);
    for (element, value) in sol.elements[1..5].iter_mut().zip(values) {
        element.radiosity = [value as f32; 3];
    }
    let g = gouraud(&mesh_triangles(&mesh(&one)), &sol, SMOOTH);
    let (m01, m12, m20) = ((a + b + d) / 3.0, (b + c + d) / 3.0, (a + c + d) / 3.0);
    let cases = [
        ([0.0, 0.0], a),
        ([1.0, 0.0], b),
        ([0.0, 1.0], c),
        ([0.5, 0.0], m01),
        ([0.5, 0.5], m12),
        ([0.0, 0.5], m20),
        ([0.25, 0.0], 0.5 * (a + m01)),
        ([0.5, 0.25], 0.5 * (m01 + m12)),
        ([1.0 / 3.0, 1.0 / 3.0], (m01 + m12 + m20) / 3.0),
        // Inside corner child 1 at local (0.25, 0.5, 0.25) of [m01, c1, m12].
        ([0.25 * 0.5 + 0.5 + 0.25 * 0.5, 0.25 * 0.5], 0.25 * m01 + 0.5 * b + 0.25 * m12),
    ];
    for (uv, want) in cases {
        let got = g.radiosity(0, uv)[0];
        assert!((got - want).abs() < 1e-12, "at {uv:?}: {got} != {want}");
    }
    // Continuous across the border of the middle and corner-1 children.
    for e in [1e-9, -1e-9] {
        let got = g.radiosity(0, [0.5 + e, 0.1])[0];
        let want = 0.8 * m01 + 0.2 * m12; // on the segment m01 -> m12 at 1/5
        assert!((got - want).abs() < 1e-7, "{got} vs {want}");
    }
}

#[test]
fn back_faces_shade_black_and_misses_have_no_coverage() {
    let mesh = mesh(&square());
    let behind = manifest(dvec3(0.5, 0.5, -2.0), dvec3(0.5, 0.5, 0.0), 32);
    let image = render(&Params::default(), &mesh, &behind, &solution(2, 1, |_, _| 5.0));
    assert!(image.rgb.iter().all(|p| *p == [0.0; 3]), "back faces are black");
    assert_eq!(image.coverage[16 * 32 + 16], 1.0, "but they are covered");
    assert_eq!(image.coverage[0], 0.0);
    assert_eq!(image.counters["back_face_hits"], image.counters["ray_hits"]);
    assert!(image.counters["ray_hits"] > 0.0);

    let away = manifest(dvec3(0.5, 0.5, 2.0), dvec3(0.5, 0.5, 4.0), 16);
    let image = render(&Params::default(), &mesh, &away, &solution(2, 1, |_, _| 5.0));
    assert!(image.coverage.iter().all(|&a| a == 0.0) && image.rgb.iter().all(|p| *p == [0.0; 3]));
}

#[test]
fn renders_are_bit_identical_across_runs_and_thread_counts() {
    let mesh = mesh(&square());
    let sol = solution(2, 3, |t, c| (1 + t) as f32 * (1.0 + c[0][0] as f32 + 2.0 * c[1][1] as f32));
    let params = Params { spp: 5, seed: 7, ..Params::default() };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&params, &mesh, &front_camera(), &sol))
    };
    let (one, four, again) = (run(1), run(4), run(4));
    assert_eq!(one.rgb, four.rgb);
    assert_eq!(one.coverage, four.coverage);
    assert_eq!(four, again);
    let other_seed = render(&Params { seed: 8, ..params.clone() }, &mesh, &front_camera(), &sol);
    assert_ne!(other_seed.rgb, one.rgb, "the seed drives the jitter");
}

#[test]
fn pixel_samples_are_stratified_and_inside_the_pixel() {
    let mut stream = Stream::new(0, 0, 0);
    let strata: Vec<(u32, u32)> = (0..4)
        .map(|k| {
            let (x, y) = pixel_offset(k, 4, &mut stream);
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            ((x * 2.0) as u32, (y * 2.0) as u32)
        })
        .collect();
    assert_eq!(strata, [(0, 0), (1, 0), (0, 1), (1, 1)]);
    for n in [1, 2, 3, 5, 10] {
        for k in 0..n {
            let (x, y) = pixel_offset(k, n, &mut stream);
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
        }
    }
}

#[test]
fn a_solution_of_another_mesh_is_refused_naming_the_file() {
    let three = mesh(&[square()[0], square()[1], square()[0].map(|p| p + DVec3::Z)]);
    let m = front_camera();
    let check = |sol: &Solution| {
        let scene = Scene { mesh: &three, manifest: &m, manifest_path: Path::new("m.ron"), solution: sol, solution_path: Path::new("sol.exr") };
        gather(&Params::default(), &scene, &|_| {}).unwrap_err().to_string()
    };
    let too_few = check(&solution(2, 1, |_, _| 1.0));
    assert!(too_few.starts_with("sol.exr") && too_few.contains("solution does not belong to this mesh"), "{too_few}");
    let mut foreign = solution(3, 1, |_, _| 1.0);
    foreign.elements[5].triangle = 3;
    assert!(check(&foreign).contains("triangle 3, but the mesh has 3 triangles"), "{}", check(&foreign));
    let mut swapped = solution(3, 0, |_, _| 1.0);
    swapped.elements[0].triangle = 1;
    assert!(check(&swapped).contains("solution does not belong to this mesh"));
    let mut bent = solution(3, 1, |_, _| 1.0);
    bent.elements[4].corners[0] = [0.25, 0.0];
    assert!(check(&bent).contains("1:4 rule"), "{}", check(&bent));
    let ok = solution(3, 1, |_, _| 1.0);
    let scene = Scene { mesh: &three, manifest: &m, manifest_path: Path::new("m.ron"), solution: &ok, solution_path: Path::new("sol.exr") };
    assert!(gather(&Params::default(), &scene, &|_| {}).is_ok());
}

#[test]
fn params_round_trip_through_ron_and_refuse_typos() {
    let p = Params { width: Some(320), spp: 16, ..Params::default() };
    let text = schemas::ron_io::to_ron_text(&p);
    assert_eq!(ron::from_str::<Params>(&text).unwrap(), p);
    assert!(ron::from_str::<Params>("(spp: 2, sp: 3)").is_err());
    assert_eq!(ron::from_str::<Params>("(spp: 2)").unwrap().crease_angle_deg, 30.0);
    assert_eq!(ron::from_str::<Params>("(mode: \"full\")").unwrap().mode, Mode::Full);
    assert!(ron::from_str::<Params>("(mode: \"ful\")").is_err());
    // Provenance stores parameters as ron::Value: the mode must survive it.
    let value: ron::Value = ron::from_str(&text).unwrap();
    assert_eq!(value.into_rust::<Params>().unwrap(), p);
}

mod full;

#[test]
fn surface_layer_tells_objects_edges_and_emitters_apart() {
    // The square's two triangles as two objects; triangle 1 (above the
    // diagonal, x < y) emits. Pixel centres are projected back onto the
    // square plane to know which side they are on.
    let mut mesh = mesh(&square());
    mesh.triangles[1].object = 1;
    mesh.triangles[1].material = 1;
    let mut manifest = front_camera();
    manifest.objects.push("lamp".into());
    let mut lamp = manifest.materials[0].clone();
    lamp.emission = [1.0; 3];
    manifest.materials.push(lamp);
    let params = Params { spp: 16, ..Params::default() };
    let image = render(&params, &mesh, &manifest, &solution(2, 1, |_, _| 1.0));
    let s = &image.surfaces;
    let size = 64;
    let camera = stage_kit::scene::pinhole(&manifest.camera, size, size).unwrap();
    let on_plane = |x: f64, y: f64| {
        let d = camera.direction(x, y);
        camera.eye + d * (-camera.eye.z / d.z)
    };
    // 0: outside the square, 1: triangle 0 (x > y), 2: triangle 1.
    let region = |p: DVec3| if !((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)) { 0 } else if p.x < p.y { 2 } else { 1 };
    let (mut single, mut mixed) = (0, 0);
    for i in 0..(size * size) as usize {
        let (x, y) = ((i % 64) as f64, (i / 64) as f64);
        // The share of each region in the pixel, on a fine 16 x 16 grid.
        let mut share = [0.0f64; 3];
        for k in 0..256 {
            share[region(on_plane(x + (f64::from(k % 16) + 0.5) / 16.0, y + (f64::from(k / 16) + 0.5) / 16.0))] += 1.0 / 256.0;
        }
        let flags = s.flags[i];
        if let Some(r) = (0..3).find(|&r| share[r] == 1.0) {
            if r == 0 {
                assert_eq!((s.object[i], flags), (schemas::image::NO_SURFACE, 0), "pixel {i} sees nothing");
                continue;
            }
            let object = r as u32 - 1;
            assert_eq!(flags & schemas::image::SINGLE_SURFACE, 1, "pixel {i} lies on one triangle");
            assert_eq!((s.object[i], s.material[i]), (object, object));
            assert_eq!(flags & schemas::image::EMITTER != 0, object == 1);
            single += 1;
        } else if share.iter().filter(|&&f| f >= 0.4).count() == 2 {
            // Split about evenly by an edge: 16 stratified samples see both sides.
            assert_eq!(flags & schemas::image::SINGLE_SURFACE, 0, "pixel {i} straddles an edge: {share:?}");
            mixed += 1;
        }
    }
    assert!(single > 500 && mixed > 20, "{single} single, {mixed} mixed pixels");
}

/// The leaves of [`solution`]`(2, depth, ..)` over [`square`]: triangle,
/// barycentric corners, world corners.
fn square_leaves(depth: u32) -> Vec<(u32, Corners, [DVec3; 3])> {
    let world = |t: u32, uv: [f64; 2]| {
        let [a, b, c] = square()[t as usize];
        a + uv[0] * (b - a) + uv[1] * (c - a)
    };
    let mut leaves: Vec<(u32, Corners)> = vec![(0, ROOT), (1, ROOT)];
    for _ in 0..depth {
        leaves = leaves.iter().flat_map(|&(t, c)| children(&c).map(|child| (t, child))).collect();
    }
    leaves.into_iter().map(|(t, c)| (t, c, c.map(|uv| world(t, uv)))).collect()
}

/// Radiosity falling from the middle of the square towards two borders,
/// as on a wall between two creases: quadratic in x.
fn falloff(p: DVec3) -> f64 {
    1.0 + 4.0 * p.x * (1.0 - p.x)
}

/// [`falloff`]'s exact mean over the leaf with world corners `w`: a
/// quadratic's mean over a triangle is the mean of its values at the edge
/// midpoints.
fn falloff_mean(w: [DVec3; 3]) -> f64 {
    (falloff(0.5 * (w[0] + w[1])) + falloff(0.5 * (w[1] + w[2])) + falloff(0.5 * (w[2] + w[0]))) / 3.0
}

/// A dark strip along the border y = 0, a leaf wide at depth 3 (a contact
/// shadow), beside uniform light: 0 for the leaves within it, else 1.
fn dark_strip(w: [DVec3; 3]) -> f64 {
    if w.iter().all(|p| p.y <= 0.125 + 1e-9) { 0.0 } else { 1.0 }
}

/// The centroid of a leaf with corners `c`, in its triangle's barycentric
/// coordinates.
fn uv_centroid(c: &Corners) -> [f64; 2] {
    [0, 1].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0)
}

/// Gouraud over the square's leaves at `depth`, each with the radiosity
/// `mean(its world corners)`, with `passes` mean-preserving passes.
fn square_gouraud(depth: u32, passes: u32, mean: &dyn Fn([DVec3; 3]) -> f64) -> Gouraud {
    square_shown(depth, Smoothing { mean_passes: passes, ..SMOOTH }, mean)
}

/// [`square_gouraud`] with `smoothing`.
fn square_shown(depth: u32, smoothing: Smoothing, mean: &dyn Fn([DVec3; 3]) -> f64) -> Gouraud {
    square_sloped(depth, smoothing, mean, &|_| None)
}

/// [`square_shown`] with the solution's measured slope `slope(world
/// corners)` on the leaves it gives one for.
fn square_sloped(depth: u32, smoothing: Smoothing, mean: &dyn Fn([DVec3; 3]) -> f64, slope: &dyn Fn([DVec3; 3]) -> Option<DVec3>) -> Gouraud {
    let leaves = square_leaves(depth);
    let world = |e: &Element| {
        let (_, _, world) = leaves.iter().find(|(lt, lc, _)| *lt == e.triangle && *lc == e.corners.map(|uv| uv.map(f64::from))).expect("a leaf");
        *world
    };
    let mut sol = solution(2, depth, |_, _| 0.0);
    for e in sol.elements.iter_mut().filter(|e| e.first_child == NONE) {
        e.radiosity = [mean(world(e)) as f32; 3];
    }
    sol.slopes = (0..sol.elements.len() as u32)
        .filter(|&k| sol.elements[k as usize].first_child == NONE)
        .filter_map(|k| slope(world(&sol.elements[k as usize])).map(|g| LeafSlope { element: k, gradient: [g.as_vec3().to_array(); 3] }))
        .collect();
    gouraud(&mesh_triangles(&mesh(&square())), &sol, smoothing)
}

/// The preview's default passes ([`Params::default`]).
fn default_passes() -> u32 {
    Params::default().mean_passes
}

/// The passes the display of each leaf's own value (without leaf
/// gradients) was set at, the default before the gradients: the tests of
/// the passes themselves run there.
const OWN_VALUE_PASSES: u32 = 8;

/// A radiosity linear over the square: every leaf's value is its mean (its
/// centroid's). Plain area-weighted means put at each border corner the
/// mean of the leaves inside it, 0.125 off here (a gradient of 2 over
/// leaves 1/8 wide); after 8 passes the corrected corners are
/// within 0.05 (0.023 after 64), approaching the linear function's
/// own values, which are the fixed point (their interpolant is exact). The
/// square's four corners are left out: one or two leaves meet there, all
/// on one side, with nothing to extrapolate from.
#[test]
fn mean_passes_restore_a_linear_radiosity_at_the_border() {
    let f = |p: DVec3| 1.0 + 2.0 * p.x + 0.5 * p.y;
    let centroid = |w: [DVec3; 3]| f((w[0] + w[1] + w[2]) / 3.0);
    let leaves = square_leaves(3);
    let square_corner = |p: DVec3| [p.x, p.y].iter().all(|x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12);
    let worst_corner = |passes: u32| {
        let g = square_gouraud(3, passes, &centroid);
        let g = &g;
        leaves
            .iter()
            .flat_map(|(t, c, w)| (0..3).filter(|&k| !square_corner(w[k])).map(move |k| (g.radiosity(*t, c[k])[0] - f(w[k])).abs()))
            .fold(0.0, f64::max)
    };
    let (plain, corrected) = (worst_corner(0), worst_corner(OWN_VALUE_PASSES));
    assert!(plain > 0.12, "plain means are off at the border: {plain}");
    assert!(corrected < 0.05, "corrected corners off f by {corrected} (plain {plain})");
    assert!(worst_corner(64) < 0.5 * corrected, "more passes converge");
}

/// Leaves of negative radiosity (a solution converted from a linear basis
/// that undershoots) keep their corners within the range of their leaves
/// widened as for any other, with no floor at 0: a radiosity linear over
/// the square from -1 to 1 is shown within 0.05 of it after 8 passes, as
/// a positive one is (it panicked: the corner's range had its
/// floor, 0, over its top).
#[test]
fn negative_leaves_keep_their_corners_in_range() {
    let f = |p: DVec3| -1.0 + 2.0 * p.x;
    let g = square_gouraud(3, OWN_VALUE_PASSES, &|w| f((w[0] + w[1] + w[2]) / 3.0));
    for (t, c, w) in square_leaves(3) {
        let inner = |p: DVec3| p.x > 1e-9 && p.x < 1.0 - 1e-9;
        for k in (0..3).filter(|&k| inner(w[k])) {
            let shown = g.radiosity(t, c[k])[0];
            assert!((shown - f(w[k])).abs() < 0.05, "at {:?}: {shown} against {}", w[k], f(w[k]));
        }
    }
}

/// Radiosity falling from the middle towards two borders, as on a wall
/// between two creases: each leaf shows its mean (a quadratic's mean over
/// a triangle is the mean of its values at the edge midpoints, exactly),
/// within 3% of the range of [`falloff`] after 8 passes (1.3% without the
/// limit on the corners, [`mean_preserving`]), where plain means miss by
/// 13%; the whole square's mean within 1e-4.
#[test]
fn mean_passes_keep_each_leafs_mean() {
    let leaves = square_leaves(3);
    let shown_minus_mean = |passes: u32| -> Vec<f64> {
        let g = square_gouraud(3, passes, &falloff_mean);
        leaves
            .iter()
            .map(|(t, c, w)| g.radiosity(*t, uv_centroid(c))[0] - falloff_mean(*w))
            .collect()
    };
    for (passes, most) in [(0, 0.12), (OWN_VALUE_PASSES, 0.03)] {
        let errors = shown_minus_mean(passes);
        let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
        let total: f64 = errors.iter().sum::<f64>() / errors.len() as f64;
        assert!(total.abs() < 1e-4, "{passes} passes: the square's mean is off by {total}");
        assert!(if passes == 0 { worst > most } else { worst < most }, "{passes} passes: worst leaf {worst}");
    }
}

/// A dark strip along one border (a contact shadow) beside uniform light:
/// the least-squares corners ring, 0.70 below 0 on the dark side and 40%
/// over the bright one; kept within their leaves' range widened by its
/// width, the corners where all leaves agree keep their value.
#[test]
fn mean_passes_never_make_radiosity_negative() {
    let g = square_gouraud(3, OWN_VALUE_PASSES, &dark_strip);
    let lowest = square_leaves(3).iter().flat_map(|(t, c, _)| c.map(|uv| g.radiosity(*t, uv)[0])).fold(f64::INFINITY, f64::min);
    assert!(lowest == 0.0, "lowest corner {lowest}");
    let highest = square_leaves(3).iter().flat_map(|(t, c, _)| c.map(|uv| g.radiosity(*t, uv)[0])).fold(0.0, f64::max);
    assert!(highest == 1.0, "highest corner {highest}");
}

/// The preview's default smoothing, leaf gradients on.
fn shown_by_default() -> Smoothing {
    Smoothing { mean_passes: default_passes(), leaf_gradients: Params::default().leaf_gradients, ..SMOOTH }
}

/// Root-mean-square of `shown - f` over a 64 x 64 grid of points inside
/// the square (the image's pixels, as it were).
fn rms_off(g: &Gouraud, f: &dyn Fn(DVec3) -> f64) -> f64 {
    let n = 64;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            // The square's two triangles: (0,0)-(1,0)-(1,1) and (0,0)-(1,1)-(0,1).
            let (t, uv) = if x >= y { (0, [x - y, y]) } else { (1, [x, y - x]) };
            sum += (g.radiosity(t, uv)[0] - f(DVec3::new(x, y, 0.0))).powi(2);
        }
    }
    (sum / (n * n) as f64).sqrt()
}

/// A falloff steeper than the leaves are fine (a wall's radiosity towards
/// two creases, quadratic; each leaf its exact mean): shown on each
/// leaf's least-squares plane at the default passes the image is nearer
/// the function than each leaf's own value at the passes set for it (rms
/// over the square 0.0093 against 0.0120; 0.0077 with the gradients at
/// those passes, which exact means like these favour, and the own values
/// at the default 0.0194), and every leaf keeps its mean within 0.61% of
/// the range (2.7% with its own value alone,
/// `mean_passes_keep_each_leafs_mean`).
#[test]
fn leaf_gradients_show_a_falloff_closer() {
    let shown = square_shown(3, shown_by_default(), &falloff_mean);
    let own = square_shown(3, Smoothing { leaf_gradients: false, mean_passes: OWN_VALUE_PASSES, ..shown_by_default() }, &falloff_mean);
    let (with, without) = (rms_off(&shown, &falloff), rms_off(&own, &falloff));
    assert!(with < 0.85 * without, "rms {with} with leaf gradients, {without} without");
    let mut worst_mean: f64 = 0.0;
    for (t, c, w) in square_leaves(3) {
        // The interpolant's mean over the leaf: over its four shown leaves,
        // each the mean of its corners.
        let quarters = children(&c);
        let shown_mean = quarters.iter().map(|q| q.iter().map(|&uv| shown.radiosity(t, uv)[0]).sum::<f64>() / 3.0).sum::<f64>() / 4.0;
        worst_mean = worst_mean.max((shown_mean - falloff_mean(w)).abs());
    }
    assert!(worst_mean < 0.01, "a leaf's shown mean is off its own by {worst_mean}");
}

/// A dark strip along one border (a contact shadow) beside uniform light,
/// as `mean_passes_never_make_radiosity_negative` has it, each leaf shown
/// on its gradient: the leaves beside the step would take its slope, the
/// dark ones' children going below 0 and the bright ones' past 1. Kept
/// within the range of the leaf's and its neighbours' values widened by a
/// quarter of its width ([`crate::gouraud::SHOWN_RANGE`]) and not below 0, nothing is
/// shown below 0, nothing over 1.28 at the default
/// passes (at the shown leaves' centroids; 1.29 after 8 passes, 1.32 with
/// no bound on the range), and the bright leaves away from the step show
/// 1.
#[test]
fn leaf_gradients_stay_near_their_neighbours_beside_a_step() {
    let g = square_shown(3, shown_by_default(), &dark_strip);
    let shown: Vec<f64> = square_leaves(3).iter().flat_map(|(t, c, _)| children(c).map(|q| g.radiosity(*t, uv_centroid(&q))[0])).collect();
    let (lowest, highest) = shown.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &b| (lo.min(b), hi.max(b)));
    assert!(lowest == 0.0 && highest < 1.3, "shown from {lowest} to {highest}");
    let far = square_leaves(3).into_iter().filter(|(_, _, w)| w.iter().all(|p| p.y >= 0.5)).map(|(t, c, _)| g.radiosity(t, uv_centroid(&c))[0]);
    for b in far {
        assert!((b - 1.0).abs() < 1e-9, "a bright leaf away from the step shows {b}");
    }
}

/// A penumbra: light rising linearly from 0 to 1 across `x` in [0.40,
/// 0.55], narrower than two leaves at depth 3.
fn penumbra(p: DVec3) -> f64 {
    ((p.x - 0.40) / 0.15).clamp(0.0, 1.0)
}

/// [`penumbra`]'s least-squares plane over the leaf with world corners `w`
/// (in z = 0; test-support's `floor_plane` over 256 points): its mean, and
/// its slope where the rise crosses the leaf.
fn penumbra_plane(w: [DVec3; 3]) -> (f64, Option<DVec3>) {
    let ([dx, dy], mean) = floor_plane(&w.map(|p| p.to_array()), 4, &|p| penumbra(DVec3::from(p)));
    let slope = DVec3::new(dx, dy, 0.0);
    (mean, (slope != DVec3::ZERO).then_some(slope))
}

/// A penumbra across leaves wider than it (each leaf its exact mean):
/// where the solution measured the slope inside the leaves it crosses
/// (here the exact one, as many rays would), the preview takes half of
/// it against half of the plane the neighbours fit
/// ([`crate::gouraud::MEASURED_SLOPE`]) and comes nearer the penumbra: rms
/// over the square 0.0156 against 0.0198; with the slopes turned about
/// (wrong) 0.0381.
#[test]
fn measured_slopes_show_a_penumbra_closer() {
    let mean = |w: [DVec3; 3]| penumbra_plane(w).0;
    let crossed = |w: [DVec3; 3]| penumbra_plane(w).1;
    let plain = rms_off(&square_shown(3, shown_by_default(), &mean), &penumbra);
    let measured = rms_off(&square_sloped(3, shown_by_default(), &mean, &crossed), &penumbra);
    let turned = rms_off(&square_sloped(3, shown_by_default(), &mean, &|w| crossed(w).map(|g| -g)), &penumbra);
    eprintln!("penumbra: rms {plain:.4} from the neighbours' planes, {measured:.4} with measured slopes, {turned:.4} turned about");
    assert!(measured < 0.85 * plain, "rms {measured} with measured slopes, {plain} without");
    assert!(turned > plain, "rms {turned} with the slopes turned about, {plain} without");
}


//! Tests on in-memory images and solutions, against hand-computed numbers.

use super::*;
use schemas::header::{Provenance, Schema};
use schemas::solution::{Element, NONE};

fn provenance() -> Provenance {
    Provenance::in_memory("test")
}

fn image(width: usize, height: usize, rgb: Vec<[f32; 3]>, coverage: Vec<f32>) -> HdrImage {
    HdrImage { header: HdrImage::header(provenance()), width, height, rgb, coverage, surfaces: None }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn identical_images_give_zeros_and_match_even_at_zero_tolerance() {
    let rgb: Vec<[f32; 3]> = (0..12).map(|i| [i as f32, 0.5 * i as f32, 1.0]).collect();
    let a = image(4, 3, rgb.clone(), vec![1.0; 12]);
    let result = compare_images(&a, &a.clone(), &Params::default()).unwrap();
    let m = &result.metrics;
    assert_eq!(m.samples, 12);
    assert_eq!((m.rmse, m.relative_rmse, m.mean_relative_error, m.max_relative_error), (0.0, 0.0, 0.0, 0.0));
    assert!(m.percent_over_tau.iter().all(|&(_, p)| p == 0.0));
    let strict =
        Params { max_rel_rmse: Some(0.0), max_rmse: Some(0.0), max_pixels_over_tau: Some(0.0), ..Params::default() };
    assert!(strict.exceeded(m).is_empty());
    assert_eq!(result.coverage_mismatches, 0);
}

#[test]
fn known_perturbation_by_hand() {
    // B = 1 everywhere (4 pixels), A = 1.5 on half of them.
    let b = image(2, 2, vec![[1.0; 3]; 4], vec![1.0; 4]);
    let a = image(2, 2, vec![[1.5; 3], [1.0; 3], [1.5; 3], [1.0; 3]], vec![1.0; 4]);
    let params = Params { tau: vec![0.01, 0.1, 0.6], ..Params::default() };
    let m = compare_images(&a, &b, &params).unwrap().metrics;
    // Σ (a - b)² = 2 pixels * 3 channels * 0.25 = 1.5 over 12 channel samples;
    // Σ b² = 12. RMSE = sqrt(1.5 / 12) = relative RMSE.
    assert!(close(m.rmse, (0.125f64).sqrt()), "{}", m.rmse);
    assert!(close(m.relative_rmse, (0.125f64).sqrt()));
    // Luminance errors 0.5, 0, 0.5, 0 against L_b = 1.
    assert!(close(m.mean_relative_error, 0.25));
    assert!(close(m.max_relative_error, 0.5));
    assert!(close(m.mean_reference_luminance, 1.0));
    // |ΔL| = 0.5 on half the pixels: over τ = 0.01 and 0.1, not over 0.6.
    assert_eq!(m.percent_over_tau, vec![(0.01, 50.0), (0.1, 50.0), (0.6, 0.0)]);
    let counters = m.counters();
    assert_eq!(counters["percent_over_tau_0.1"], 50.0);
    assert_eq!(counters["samples"], 4.0);

    // Tolerances: relative RMSE 0.354 exceeds 0.3, not 0.4; the percentage
    // tolerance is checked at the largest τ (0.6): 0 %.
    let tight = Params { max_rel_rmse: Some(0.3), ..params.clone() };
    assert_eq!(tight.exceeded(&m).len(), 1);
    assert!(tight.exceeded(&m)[0].starts_with("relative_rmse 0.353553 > 0.3"), "{:?}", tight.exceeded(&m));
    let loose =
        Params { max_rel_rmse: Some(0.4), max_rmse: Some(0.4), max_pixels_over_tau: Some(0.0), ..params.clone() };
    assert!(loose.exceeded(&m).is_empty());
    let at_small_tau = Params { tau: vec![0.1], max_pixels_over_tau: Some(49.0), ..Params::default() };
    let m = compare_images(&a, &b, &at_small_tau).unwrap().metrics;
    assert_eq!(at_small_tau.exceeded(&m), vec!["percent_over_tau_0.1 50.000000 > 49".to_string()]);
}

#[test]
fn reference_coverage_masks_pixels() {
    // Pixel 1 differs hugely but the reference does not see it; pixel 2 is
    // seen by A only (a coverage mismatch, not a sample).
    let b = image(3, 1, vec![[2.0; 3], [0.0; 3], [0.0; 3]], vec![1.0, 0.0, 0.0]);
    let a = image(3, 1, vec![[2.0; 3], [100.0; 3], [7.0; 3]], vec![1.0, 0.0, 1.0]);
    let result = compare_images(&a, &b, &Params::default()).unwrap();
    assert_eq!(result.metrics.samples, 1);
    assert_eq!(result.metrics.rmse, 0.0);
    assert_eq!(result.coverage_mismatches, 1);
    assert_eq!(result.counters(&|i| i.to_string(), &|i| i.to_string())["coverage_mismatch_pixels"], 1.0);
}

#[test]
fn size_mismatch_is_an_error_naming_both_sizes() {
    let a = image(2, 3, vec![[1.0; 3]; 6], vec![1.0; 6]);
    let b = image(3, 2, vec![[1.0; 3]; 6], vec![1.0; 6]);
    let err = compare_images(&a, &b, &Params::default()).unwrap_err();
    assert_eq!(err.which(), Which::A);
    assert_eq!(err.to_string(), "is 2x3 pixels but the reference is 3x2");
}

#[test]
fn non_finite_pixel_is_an_error_naming_file_and_pixel() {
    let a = image(2, 2, vec![[1.0; 3]; 4], vec![1.0; 4]);
    let mut b = a.clone();
    b.rgb[3][2] = f32::INFINITY;
    let err = compare_images(&a, &b, &Params::default()).unwrap_err();
    assert_eq!(err.which(), Which::B);
    assert!(err.to_string().contains("channel B at pixel (x 1, y 1)"), "{err}");
}

/// `width` x `height` pixels of luminance 1 with a surface layer: object
/// `object(x, y)`, material 0, every pixel single except where `edge`.
fn with_surfaces(width: usize, height: usize, object: &dyn Fn(usize, usize) -> u32, edge: &dyn Fn(usize, usize) -> bool) -> HdrImage {
    let n = width * height;
    let mut img = image(width, height, vec![[1.0; 3]; n], vec![1.0; n]);
    let at = |i: usize| (i % width, i / width);
    img.surfaces = Some(schemas::image::PixelSurfaces {
        object: (0..n).map(|i| object(at(i).0, at(i).1)).collect(),
        material: vec![0; n],
        flags: (0..n).map(|i| if edge(at(i).0, at(i).1) { 0 } else { schemas::image::SINGLE_SURFACE }).collect(),
    });
    img
}

#[test]
fn tau_is_relative_per_pixel() {
    // 10 pixels of luminances 0.1 .. 1.0; exactly 3 off by 1.5 τ relative
    // (two brighter, one darker), whatever their brightness.
    let tau = 0.04;
    let b_rgb: Vec<[f32; 3]> = (1..=10).map(|k| [0.1 * k as f32; 3]).collect();
    let off = |i: usize| match i {
        0 | 9 => 1.0 + 1.5 * tau,
        4 => 1.0 - 1.5 * tau,
        _ => 1.0,
    };
    let a_rgb: Vec<[f32; 3]> = b_rgb.iter().enumerate().map(|(i, p)| p.map(|v| (f64::from(v) * off(i)) as f32)).collect();
    let (a, b) = (image(10, 1, a_rgb, vec![1.0; 10]), image(10, 1, b_rgb, vec![1.0; 10]));
    let params = Params { tau: vec![tau, 1.4 * tau, 1.6 * tau], ..Params::default() };
    let m = compare_images(&a, &b, &params).unwrap().metrics;
    assert_eq!(m.percent_over_tau.iter().map(|(_, p)| *p).collect::<Vec<_>>(), vec![30.0, 30.0, 0.0]);
}

#[test]
fn errors_per_object_and_material() {
    // Left half object 0 (exact), right half object 1, 10% too bright in A.
    let b = with_surfaces(4, 2, &|x, _| u32::from(x >= 2), &|_, _| false);
    let mut a = b.clone();
    for (i, p) in a.rgb.iter_mut().enumerate() {
        if i % 4 >= 2 {
            *p = [1.1; 3];
        }
    }
    let result = compare_images(&a, &b, &Params::default()).unwrap();
    assert_eq!(result.surfaces_from, Some(Which::B));
    let objects: Vec<(u32, usize, f64)> = result.by_object.iter().map(|(k, m)| (*k, m.samples, m.mean_signed_error)).collect();
    assert_eq!(objects[0], (0, 4, 0.0));
    assert_eq!((objects[1].0, objects[1].1), (1, 4));
    assert!((objects[1].2 - 0.1).abs() < 1e-6, "{objects:?}");
    assert!((result.metrics.mean_signed_error - 0.05).abs() < 1e-6);
    assert_eq!(result.by_material.len(), 1);
    let counters = result.counters(&|i| format!("o{i}"), &|i| format!("m{i}"));
    assert!((counters["object[o1].relative_rmse"] - 0.1).abs() < 1e-6);
    assert_eq!(counters["object[o0].relative_rmse"], 0.0);
    assert_eq!(counters["material[m0].samples"], 8.0);
    // A foreign reference has no surface layer: A's is used.
    let mut foreign = b.clone();
    foreign.surfaces = None;
    let from_a = compare_images(&a, &foreign, &Params::default()).unwrap();
    assert_eq!((from_a.surfaces_from, from_a.by_object.len()), (Some(Which::A), 2));
}

#[test]
fn exclude_edges_removes_the_square_around_mixed_pixels() {
    // One mixed pixel inside (3, 2) and one at the corner (0, 0) of a 7 x 5
    // image: N = 1 removes the 3 x 3 square around the first (9 pixels) and
    // the 2 x 2 inside the image around the second (4), 13 in all.
    let edge = |x: usize, y: usize| (x, y) == (3, 2) || (x, y) == (0, 0);
    let b = with_surfaces(7, 5, &|_, _| 0, &edge);
    let params = Params { exclude_edges: Some(1), ..Params::default() };
    let result = compare_images(&b, &b, &params).unwrap();
    assert_eq!(result.excluded, 13);
    let removed: Vec<(usize, usize)> = (0..35).filter(|&i| !result.compared[i]).map(|i| (i % 7, i / 7)).collect();
    let expected: Vec<(usize, usize)> = (0..35)
        .map(|i| (i % 7, i / 7))
        .filter(|&(x, y): &(usize, usize)| (x.abs_diff(3) <= 1 && y.abs_diff(2) <= 1) || (x <= 1 && y <= 1))
        .collect();
    assert_eq!(removed, expected);
    // N = 0: the mixed pixels only.
    let only = compare_images(&b, &b, &Params { exclude_edges: Some(0), ..Params::default() }).unwrap();
    assert_eq!(only.excluded, 2);
}

#[test]
fn dilation_matches_brute_force_chebyshev() {
    let (w, h) = (9, 6);
    let mut state = 12345u64;
    let mask: Vec<bool> = (0..w * h)
        .map(|_| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            state >> 60 == 0
        })
        .collect();
    for n in 0..4 {
        let fast = images::dilate(&mask, w, h, n);
        assert_eq!(fast.len(), w * h);
        for (i, &got) in fast.iter().enumerate() {
            let (x, y) = (i % w, i / w);
            let near = (0..w * h).any(|j| mask[j] && (j % w).abs_diff(x) <= n && (j / w).abs_diff(y) <= n);
            assert_eq!(got, near, "n {n} pixel ({x}, {y})");
        }
    }
}

#[test]
fn exclude_emitters_and_their_surroundings() {
    // Emitter pixels in column 0 of a 5 x 1 strip: excluded alone, then
    // with their neighbours within 1 px; without a surface layer: an error.
    let mut b = with_surfaces(5, 1, &|_, _| 0, &|_, _| false);
    b.surfaces.as_mut().unwrap().flags[0] |= schemas::image::EMITTER;
    let emitters = Params { exclude_emitters: true, ..Params::default() };
    assert_eq!(compare_images(&b, &b, &emitters).unwrap().excluded, 1);
    let around = Params { exclude_edges: Some(1), ..emitters.clone() };
    assert_eq!(compare_images(&b, &b, &around).unwrap().excluded, 2);
    let mut bare = b.clone();
    bare.surfaces = None;
    let err = compare_images(&bare, &bare, &emitters).unwrap_err();
    assert!(err.to_string().contains("needs a surface layer"), "{err}");
}

#[test]
fn difference_picture_diverges_from_white() {
    assert_eq!(images::diverging(0.0), [255, 255, 255]);
    assert_eq!(images::diverging(-1.0), [0, 0, 255]);
    assert_eq!(images::diverging(1.0), [255, 0, 0]);
    assert_eq!(images::diverging(7.0), [255, 0, 0]);
    assert_eq!(images::diverging(-0.5), [128, 128, 255]);
    // τ_max 0.5: relative ΔL = -0.25 (1.5 against 2) is half-way to blue,
    // +0.75 saturates red, equal is white, uncovered and excluded are greys.
    let b = image(5, 1, vec![[2.0; 3], [1.0; 3], [1.0; 3], [1.0; 3], [1.0; 3]], vec![1.0, 1.0, 1.0, 0.0, 1.0]);
    let a = image(5, 1, vec![[1.5; 3], [1.75; 3], [1.0; 3], [9.0; 3], [3.0; 3]], vec![1.0; 5]);
    let picture = images::difference_picture(&a, &b, &[true, true, true, false, false], 0.5);
    assert_eq!(picture[0], [128, 128, 255]);
    assert_eq!(picture[1], [255, 0, 0]);
    assert_eq!(picture[2], [255, 255, 255]);
    assert_eq!(picture[3], images::UNCOVERED_GREY);
    assert_eq!(picture[4], images::EXCLUDED_GREY);
}

fn element(triangle: u32, parent: u32, first_child: u32, level: u32, area: f32, radiosity: [f32; 3]) -> Element {
    Element { triangle, parent, first_child, level, corners: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], area, radiosity }
}

/// Two input triangles. Triangle 0 (area 4) is split into elements 2..5
/// (areas 0.5, 1, 1, 1.5), and element 5 again into 6..9 (0.375 each);
/// triangle 1 (area 2) is a leaf. Inner radiosities are deliberately wrong
/// (zero): the means must come from the leaves.
fn hierarchical() -> Solution {
    let elements = vec![
        element(0, NONE, 2, 0, 4.0, [0.0; 3]),
        element(1, NONE, NONE, 0, 2.0, [3.0, 3.0, 3.0]),
        element(0, 0, NONE, 1, 0.5, [2.0, 1.0, 0.0]),
        element(0, 0, NONE, 1, 1.0, [4.0, 1.0, 0.0]),
        element(0, 0, NONE, 1, 1.0, [6.0, 1.0, 0.0]),
        element(0, 0, 6, 1, 1.5, [0.0; 3]),
        element(0, 5, NONE, 2, 0.375, [4.0, 1.0, 0.0]),
        element(0, 5, NONE, 2, 0.375, [8.0, 1.0, 0.0]),
        element(0, 5, NONE, 2, 0.375, [8.0, 1.0, 4.0]),
        element(0, 5, NONE, 2, 0.375, [12.0, 1.0, 12.0]),
    ];
    Solution { header: Solution::header(provenance()), elements, clusters: vec![], links: vec![], slopes: vec![] }
}

fn flat(t0: [f32; 3], t1: [f32; 3]) -> Solution {
    let elements = vec![element(0, NONE, NONE, 0, 4.0, t0), element(1, NONE, NONE, 0, 2.0, t1)];
    Solution { header: Solution::header(provenance()), elements, clusters: vec![], links: vec![], slopes: vec![] }
}

#[test]
fn triangle_means_are_area_weighted_over_leaves() {
    // Triangle 0: R = (0.5·2 + 1·4 + 1·6 + 0.375·(4 + 8 + 8 + 12)) / 4 = 23 / 4,
    // G = 1, B = 0.375·(4 + 12) / 4 = 1.5. Triangle 1: its own (3, 3, 3).
    let means = solutions::triangle_means(&hierarchical().elements, Which::A).unwrap();
    assert_eq!(means, vec![([5.75, 1.0, 1.5], 4.0), ([3.0, 3.0, 3.0], 2.0)]);
}

#[test]
fn different_hierarchies_compare_per_triangle() {
    let result = compare_solutions(&hierarchical(), &flat([5.0, 1.0, 1.0], [3.0; 3]), &Params::default()).unwrap();
    assert_eq!(result.mode, solutions::Mode::Triangles);
    let m = &result.metrics;
    assert_eq!(m.samples, 2);
    assert_eq!(m.total_weight, 6.0);
    // Triangle 0 differs by (0.75, 0, 0.5) with weight 4; triangle 1 agrees.
    // RMSE = sqrt(4 (0.5625 + 0.25) / (3 · 6)); Σ w b² = 4 · 27 + 2 · 27 = 162.
    assert!(close(m.rmse, (3.25f64 / 18.0).sqrt()));
    assert!(close(m.relative_rmse, (3.25f64 / 162.0).sqrt()));
    // Luminance: L_b0 = 0.2126·5 + 0.7152 + 0.0722 = 1.8504,
    // L_a0 = 0.2126·5.75 + 0.7152 + 0.0722·1.5 = 2.04595, ΔL = 0.19555.
    assert!(close(m.max_relative_error, 0.19555 / 1.8504));
    assert!(close(m.mean_relative_error, 4.0 / 6.0 * 0.19555 / 1.8504));
    // Mean L_b = (4 · 1.8504 + 2 · 3) / 6 = 2.2336. Triangle 0's relative
    // difference 0.19555 / 1.8504 = 0.1057 is over τ = 0.05 and 0.1, not 0.2.
    assert!(close(m.mean_reference_luminance, (4.0 * 1.8504 + 6.0) / 6.0));
    assert_eq!(m.percent_over_tau[1].0, 0.05);
    assert!(close(m.percent_over_tau[1].1, 100.0 * 4.0 / 6.0));
    assert!(close(m.percent_over_tau[2].1, 100.0 * 4.0 / 6.0));
    let wider = Params { tau: vec![0.2], ..Params::default() };
    assert_eq!(compare_solutions(&hierarchical(), &flat([5.0, 1.0, 1.0], [3.0; 3]), &wider).unwrap().metrics.percent_over_tau, vec![(0.2, 0.0)]);
    // Mean signed error: Σ w ΔL / Σ w L_b = 4 · 0.19555 / (4 · 1.8504 + 6).
    assert!(close(m.mean_signed_error, 4.0 * 0.19555 / (4.0 * 1.8504 + 6.0)));
}

#[test]
fn same_hierarchies_compare_per_leaf() {
    let b = hierarchical();
    let mut a = b.clone();
    a.elements[8].radiosity = [8.0, 1.0, 6.0]; // B channel 4 -> 6 on a leaf of area 0.375
    let result = compare_solutions(&a, &b, &Params::default()).unwrap();
    assert_eq!(result.mode, solutions::Mode::Leaves);
    let m = &result.metrics;
    assert_eq!(m.samples, 8);
    assert!(close(m.total_weight, 6.0));
    // Σ w d² = 0.375 · 4 = 1.5 over 3 · 6: RMSE = sqrt(1.5 / 18).
    assert!(close(m.rmse, (1.5f64 / 18.0).sqrt()));
    assert!(close(compare_solutions(&b, &b, &Params::default()).unwrap().metrics.rmse, 0.0));
}

#[test]
fn different_meshes_and_bad_hierarchies_are_errors() {
    let mut other = flat([1.0; 3], [1.0; 3]);
    other.elements[1].area = 2.5;
    let err = compare_solutions(&other, &flat([1.0; 3], [1.0; 3]), &Params::default()).unwrap_err();
    assert!(err.to_string().contains("input triangle 1 has area 2.5"), "{err}");
    // The same areas from solutions that record one mesh-prep run: a
    // triangle partly buried under a solid, whose open part the solver
    // estimated differently at another EPS.
    let recorded = |mut s: Solution, scene: &str| {
        let prep = Provenance { stage: "mesh-prep".into(), inputs: vec![schemas::header::Input { path: "scene.ron".into(), sha256: scene.into(), made_by: None }], ..provenance() };
        s.header.provenance.inputs = vec![schemas::header::Input { path: "mesh.exr".into(), sha256: "m".into(), made_by: Some(Box::new(prep)) }];
        s
    };
    let (a, b) = (recorded(other.clone(), "0a"), recorded(flat([1.0; 3], [1.0; 3]), "0a"));
    assert!(solutions::mesh_record(&a).is_some() && solutions::mesh_record(&a) == solutions::mesh_record(&b));
    assert_eq!(compare_solutions(&a, &b, &Params::default()).unwrap().metrics.rmse, 0.0);
    let elsewhere = recorded(flat([1.0; 3], [1.0; 3]), "0b");
    let err = compare_solutions(&a, &elsewhere, &Params::default()).unwrap_err();
    assert!(err.to_string().contains("does not record one mesh-prep run"), "{err}");
    let mut cyclic = hierarchical();
    cyclic.elements[6].first_child = 2; // 6 -> 2..5 -> 6 ...
    let err = solutions::triangle_means(&cyclic.elements, Which::B).unwrap_err();
    assert!(err.to_string().contains("revisits"), "{err}");
}

#[test]
fn parameters_validate_and_parse_strictly() {
    assert!(Params::default().validate().is_ok());
    let refused = |p: Params| p.validate().unwrap_err().to_string();
    assert_eq!(refused(Params { tau: vec![], ..Params::default() }), "parameters: tau needs at least one value");
    assert_eq!(refused(Params { tau: vec![0.1, 0.0], ..Params::default() }), "parameters: tau must be a positive number, not 0");
    assert_eq!(refused(Params { max_rmse: Some(-1.0), ..Params::default() }), "parameters: max_rmse must be at least 0, not -1");
    assert_eq!(refused(Params { max_rel_rmse: Some(f64::NAN), ..Params::default() }), "parameters: max_rel_rmse must be at least 0, not NaN");
    let params: Params = ron::from_str("(max_rel_rmse: Some(0.02))").unwrap();
    assert_eq!(params.tau, vec![0.02, 0.05, 0.1]);
    assert_eq!(params.max_rel_rmse, Some(0.02));
    assert!(ron::from_str::<Params>("(max_relrmse: Some(0.02))").is_err());
    assert_eq!(Params::default().tau_max(), 0.1);
}

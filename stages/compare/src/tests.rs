//! Tests on in-memory images and solutions, against hand-computed numbers.

use super::*;
use schemas::header::{Provenance, Schema};
use schemas::solution::{Element, NONE};

fn provenance() -> Provenance {
    Provenance::in_memory("test")
}

fn image(width: usize, height: usize, rgb: Vec<[f32; 3]>, coverage: Vec<f32>) -> HdrImage {
    HdrImage { header: HdrImage::header(provenance()), width, height, rgb, coverage }
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
    assert_eq!(result.counters()["coverage_mismatch_pixels"], 1.0);
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

#[test]
fn difference_picture_diverges_from_white() {
    assert_eq!(images::diverging(0.0), [255, 255, 255]);
    assert_eq!(images::diverging(-1.0), [0, 0, 255]);
    assert_eq!(images::diverging(1.0), [255, 0, 0]);
    assert_eq!(images::diverging(7.0), [255, 0, 0]);
    assert_eq!(images::diverging(-0.5), [128, 128, 255]);
    // Mean reference luminance 1, τ_max 0.5: ΔL = -0.25 is half-way to blue,
    // +0.75 saturates red, equal is white, uncovered is grey.
    let b = image(4, 1, vec![[1.0; 3]; 4], vec![1.0, 1.0, 1.0, 0.0]);
    let a = image(4, 1, vec![[0.75; 3], [1.75; 3], [1.0; 3], [9.0; 3]], vec![1.0; 4]);
    let picture = images::difference_picture(&a, &b, 1.0, 0.5);
    assert_eq!(picture[0], [128, 128, 255]);
    assert_eq!(picture[1], [255, 0, 0]);
    assert_eq!(picture[2], [255, 255, 255]);
    assert_eq!(picture[3], images::UNCOVERED_GREY);
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
    Solution { header: Solution::header(provenance()), elements, clusters: vec![], links: vec![] }
}

fn flat(t0: [f32; 3], t1: [f32; 3]) -> Solution {
    let elements = vec![element(0, NONE, NONE, 0, 4.0, t0), element(1, NONE, NONE, 0, 2.0, t1)];
    Solution { header: Solution::header(provenance()), elements, clusters: vec![], links: vec![] }
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
    // Mean L_b = (4 · 1.8504 + 2 · 3) / 6 = 2.2336; 0.05 τ → 0.11168 < 0.19555 < 0.22336 (τ = 0.1).
    assert!(close(m.mean_reference_luminance, (4.0 * 1.8504 + 6.0) / 6.0));
    assert_eq!(m.percent_over_tau[1].0, 0.05);
    assert!(close(m.percent_over_tau[1].1, 100.0 * 4.0 / 6.0));
    assert_eq!(m.percent_over_tau[2], (0.1, 0.0));
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
    let mut cyclic = hierarchical();
    cyclic.elements[6].first_child = 2; // 6 -> 2..5 -> 6 ...
    let err = solutions::triangle_means(&cyclic.elements, Which::B).unwrap_err();
    assert!(err.to_string().contains("revisits"), "{err}");
}

#[test]
fn parameters_validate_and_parse_strictly() {
    assert!(Params::default().validate().is_ok());
    assert!(Params { tau: vec![], ..Params::default() }.validate().is_err());
    assert!(Params { tau: vec![0.0], ..Params::default() }.validate().is_err());
    assert!(Params { max_rmse: Some(-1.0), ..Params::default() }.validate().is_err());
    let params: Params = ron::from_str("(max_rel_rmse: Some(0.02))").unwrap();
    assert_eq!(params.tau, vec![0.01, 0.05, 0.1]);
    assert_eq!(params.max_rel_rmse, Some(0.02));
    assert!(ron::from_str::<Params>("(max_relrmse: Some(0.02))").is_err());
    assert_eq!(Params::default().tau_max(), 0.1);
}

//! The model against closed forms and the published TVI curve.

use crate::model::{band_frequency_cpd, contrast_sensitivity, tvi};
use crate::{srgb_decode, Params};
use schemas::header::{Provenance, Schema};
use schemas::threshold::ThresholdImage;

/// The model's threshold image of a `width` x `height` image of display
/// luminances `luminance` under `params`.
fn thresholds(params: &Params, width: usize, height: usize, luminance: &[f64]) -> schemas::Result<ThresholdImage> {
    crate::thresholds(params, ThresholdImage::header(Provenance::in_memory("mask tests")), width, height, luminance).map(|t| t.image)
}

#[test]
fn tvi_matches_ferwerda_1996_at_three_points_one_per_branch() {
    // Cone branch, hand-evaluated: La = 1e-3 (log -3 <= -2.6): 10^-0.72;
    // La = 1 (log 0): 10^(0.65^2.7 - 0.72) = 10^-0.40752; La = 100
    // (log 2 >= 1.9): 10^(2 - 1.255).
    let table = [(1e-3, 0.190_546), (1.0, 0.391_297), (100.0, 5.559_043)];
    for (la, dl) in table {
        let got = tvi(la);
        assert!((got / dl - 1.0).abs() < 1e-4, "TVI({la}) = {got}, published curve {dl}");
    }
    // The threshold grows with the adaptation luminance, linearly (Weber)
    // at the top: a decade up in La is a decade up in dL.
    let mut previous = 0.0;
    for k in -40..=40 {
        let t = tvi(10f64.powf(f64::from(k) / 10.0));
        assert!(t >= previous, "TVI decreases at 10^{}", f64::from(k) / 10.0);
        previous = t;
    }
    assert!((tvi(1e4) / tvi(1e3) - 10.0).abs() < 1e-9);
}

#[test]
fn csf_peaks_near_four_cycles_per_degree() {
    let peak = (1..200).map(|k| f64::from(k) * 0.05).max_by(|a, b| contrast_sensitivity(*a).total_cmp(&contrast_sensitivity(*b))).unwrap();
    assert!((peak - 4.0).abs() < 0.051, "{peak}");
    assert!((contrast_sensitivity(4.0) - 75.0 * 4f64.powf(0.8) * (-0.8f64).exp()).abs() < 1e-12);
}

#[test]
fn a_uniform_field_gives_elevation_one_and_the_tvi_threshold() {
    let params = Params::default();
    let (w, h) = (40, 30);
    let t = thresholds(&params, w, h, &vec![50.0; w * h]).unwrap();
    for i in 0..w * h {
        assert!((f64::from(t.elevation[i]) - 1.0).abs() < 1e-6, "elevation {}", t.elevation[i]);
        assert!((f64::from(t.threshold[i]) / tvi(50.0) - 1.0).abs() < 1e-6);
        assert!((f64::from(t.contrast[i]) - tvi(50.0) / 50.0).abs() < 1e-6);
    }
}

#[test]
fn a_high_contrast_grating_at_the_peak_frequency_masks() {
    let params = Params::default();
    // Band 1 is the band nearest the CSF peak at 32 pixels per degree.
    let f_cpd = band_frequency_cpd(1, params.pixels_per_degree);
    assert!((f_cpd - 4.0).abs() < 0.5, "{f_cpd}");
    let f_px = f_cpd / params.pixels_per_degree;
    let (w, h) = (96, 64);
    let grating = |contrast: f64| -> Vec<f64> {
        (0..w * h).map(|i| 50.0 * (1.0 + contrast * (2.0 * std::f64::consts::PI * f_px * (i % w) as f64).sin())).collect()
    };
    let centre = (h / 2) * w + w / 2;
    let strong = thresholds(&params, w, h, &grating(0.9)).unwrap();
    assert!(strong.elevation[centre] > 2.0, "elevation {}", strong.elevation[centre]);
    // A grating below threshold (contrast 0.1% x S < 1 in every band) does
    // not mask, and masking grows with contrast.
    let faint = thresholds(&params, w, h, &grating(0.001)).unwrap();
    assert!((f64::from(faint.elevation[centre]) - 1.0).abs() < 1e-6, "{}", faint.elevation[centre]);
    let medium = thresholds(&params, w, h, &grating(0.2)).unwrap();
    assert!(medium.elevation[centre] > 1.0 && medium.elevation[centre] < strong.elevation[centre]);
}

#[test]
fn srgb_decoding_inverts_the_standard_encoding() {
    assert_eq!(srgb_decode(0.0), 0.0);
    assert!((srgb_decode(1.0) - 1.0).abs() < 1e-12);
    // 0.735356983052449 is sRGB(0.5).
    assert!((srgb_decode(0.735_356_983_052_449) - 0.5).abs() < 1e-12);
    assert!((srgb_decode(0.04) - 0.04 / 12.92).abs() < 1e-15);
}

#[test]
fn params_round_trip_and_refuse_typos() {
    let p = Params { pixels_per_degree: 40.0, ..Params::default() };
    let text = ron::to_string(&p).unwrap();
    assert_eq!(ron::from_str::<Params>(&text).unwrap(), p);
    assert!(ron::from_str::<Params>("(pixels_per_degre: 3.0)").is_err());
    use stage_kit::knobs::Knobs;
    let refused = |p: Params| p.check("").unwrap_err().to_string();
    assert_eq!(refused(Params { levels: 0, ..Params::default() }), "parameters: levels must be in 1..=12, not 0");
    assert_eq!(refused(Params { display_black: 1.0, ..Params::default() }), "parameters: display_black must be in (0, 1), not 1");
    assert_eq!(refused(Params { display_max_cd_m2: f64::INFINITY, ..Params::default() }), "parameters: display_max_cd_m2 must be a positive number, not inf");
    assert_eq!(refused(Params { masking_slope: 1.5, ..Params::default() }), "parameters: masking_slope must be in (0, 1], not 1.5");
    assert!(Params { masking_slope: 1.0, ..Params::default() }.check("").is_ok(), "(0, 1] holds 1");
}

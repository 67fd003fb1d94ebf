//! The binary's contract: exit 0 / 1 / 2, report to a file or stdout, the
//! difference picture, kind detection, and no output on error.

use schemas::header::{Provenance, Schema};
use schemas::image::HdrImage;
use schemas::report::Report;
use schemas::solution::{Element, Solution};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn provenance() -> Provenance {
    Provenance::in_memory("test")
}

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compare-cli-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_image(path: &Path, width: usize, rgb: Vec<[f32; 3]>) {
    let height = rgb.len() / width;
    let coverage = vec![1.0; rgb.len()];
    HdrImage { header: HdrImage::header(provenance()), width, height, rgb, coverage, surfaces: None }.write(path).unwrap();
}

fn write_solution(path: &Path, radiosity: [f32; 3]) {
    let e = Element::root(0, 0.5, radiosity);
    Solution { header: Solution::header(provenance()), elements: vec![e], clusters: vec![], links: vec![], slopes: vec![] }.write(path).unwrap();
}

fn compare(args: &[&Path], flags: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_compare")).args(args).args(flags).output().unwrap()
}

#[test]
fn images_match_differ_and_report() {
    let dir = scratch("images");
    let (a, b, report, diff) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("r.ron"), dir.join("d.png"));
    write_image(&b, 2, vec![[1.0; 3]; 4]);
    write_image(&a, 2, vec![[1.5; 3], [1.0; 3], [1.5; 3], [1.0; 3]]);
    // Same file twice: exit 0 even at zero tolerance; report on stdout.
    let out = compare(&[&b, &b], &["--max-rmse", "0"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let printed: Report = ron::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!(printed.counters["rmse"], 0.0);
    // Relative RMSE sqrt(1/8) = 0.354 > 0.3: exit 1, report and diff written.
    let flags = ["--max-rel-rmse", "0.3", "-o", report.to_str().unwrap(), "--diff", diff.to_str().unwrap()];
    let out = compare(&[&a, &b], &flags);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("compare: differ: relative_rmse 0.353553 > 0.3"), "{stderr}");
    let report = schemas::ron_io::read_ron::<Report>(&report).unwrap().value;
    assert!((report.counters["relative_rmse"] - 0.125f64.sqrt()).abs() < 1e-12);
    assert_eq!(report.counters["percent_over_tau_0.05"], 50.0);
    assert!(report.notes.contains(&"mode: images".to_string()));
    assert_eq!(&std::fs::read(&diff).unwrap()[1..4], b"PNG");
    let out = compare(&[&a, &b], &["--max-rel-rmse", "0.4"]);
    assert_eq!(out.status.code(), Some(0));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn size_mismatch_is_error_without_output() {
    let dir = scratch("size");
    let (a, b, report, diff) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("r.ron"), dir.join("d.png"));
    write_image(&a, 2, vec![[1.0; 3]; 4]);
    write_image(&b, 4, vec![[1.0; 3]; 4]);
    let out = compare(&[&a, &b], &["-o", report.to_str().unwrap(), "--diff", diff.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end(), format!("compare: error: {}: is 2x2 pixels but the reference is 4x1", a.display()));
    assert!(!report.exists() && !diff.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn solutions_are_detected_and_mixed_kinds_refused() {
    let dir = scratch("solutions");
    let (a, b, image) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("i.exr"));
    write_solution(&a, [1.0, 2.0, 3.0]);
    write_solution(&b, [1.0, 2.0, 3.0]);
    write_image(&image, 1, vec![[1.0; 3]]);
    let out = compare(&[&a, &b], &["--max-rmse", "0"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let printed: Report = ron::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert!(printed.notes.contains(&"mode: solution leaves".to_string()));
    assert_eq!(printed.counters["total_weight"], 0.5);
    let out = compare(&[&a, &b], &["--diff", dir.join("d.png").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let out = compare(&[&a, &image], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is a 'image' artifact, expected 'solution'"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Writes `rgb` as a plain float RGB EXR with the `exr` crate, with no
/// custom attribute: what another renderer writes.
fn write_foreign(path: &Path, width: usize, rgb: &[[f32; 3]]) {
    use exr::prelude::*;
    let height = rgb.len() / width;
    let pixel = |p: Vec2<usize>| {
        let v = rgb[p.y() * width + p.x()];
        (v[0], v[1], v[2])
    };
    let layer = Layer::new((width, height), LayerAttributes::default(), Encoding::SMALL_LOSSLESS, SpecificChannels::rgb(pixel));
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn foreign_reference_gives_the_same_metrics_with_one_note() {
    let dir = scratch("foreign");
    let (a, pipeline_b, foreign_b) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("mitsuba.exr"));
    let b_rgb: Vec<[f32; 3]> = (0..12).map(|i| [0.1 + 0.05 * i as f32, 0.3, 0.02 * i as f32]).collect();
    let a_rgb: Vec<[f32; 3]> = b_rgb.iter().enumerate().map(|(i, p)| p.map(|v| v * (1.0 + 0.03 * (i % 5) as f32 - 0.05))).collect();
    write_image(&a, 4, a_rgb);
    write_image(&pipeline_b, 4, b_rgb.clone());
    write_foreign(&foreign_b, 4, &b_rgb);
    let (ours, theirs) = (dir.join("ours.ron"), dir.join("theirs.ron"));
    let out = compare(&[&a, &pipeline_b], &["-o", ours.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let out = compare(&[&a, &foreign_b], &["-o", theirs.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches("foreign EXR (no provenance").count(), 1, "{stderr}");
    let (ours, theirs) =
        (schemas::ron_io::read_ron::<Report>(&ours).unwrap().value, schemas::ron_io::read_ron::<Report>(&theirs).unwrap().value);
    assert_eq!(ours.counters.keys().collect::<Vec<_>>(), theirs.counters.keys().collect::<Vec<_>>());
    for (name, value) in &ours.counters {
        assert!((value - theirs.counters[name]).abs() <= 1e-12 * value.abs().max(1.0), "{name}: {value} vs {}", theirs.counters[name]);
    }
    assert!(ours.counters["relative_rmse"] > 0.01);
    // The report names the foreign input with its hash and no provenance.
    let input = &theirs.header.provenance.inputs[1];
    assert!(input.made_by.is_none() && input.sha256 == schemas::header::sha256_hex(&std::fs::read(&foreign_b).unwrap()));
    assert!(theirs.notes.iter().any(|n| n.contains("foreign EXR")));
    // Sizes must match; exclusions need a surface layer.
    write_foreign(&foreign_b, 3, &b_rgb);
    let out = compare(&[&a, &foreign_b], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is 4x3 pixels but the reference is 3x4"));
    let out = compare(&[&a, &pipeline_b], &["--exclude-emitters"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs a surface layer"));
    std::fs::remove_dir_all(&dir).unwrap();
}

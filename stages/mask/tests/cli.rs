//! The binary end to end: PNG in, threshold image out, one-line errors
//! with no partial output, --print-params round trip.

use schemas::threshold::ThresholdImage;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mask-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn mask(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mask")).current_dir(dir).args(args).output().unwrap()
}

/// A 16 x 8 grey PNG (sRGB 128).
fn write_png(dir: &Path) {
    image::RgbImage::from_pixel(16, 8, image::Rgb([128, 128, 128])).save(dir.join("preview.png")).unwrap();
}

#[test]
fn writes_a_threshold_image_with_provenance_and_reruns_byte_identical() {
    let dir = workdir("ok");
    write_png(&dir);
    let out = mask(&dir, &["preview.png", "-o", "t.exr", "--report", "r.ron"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stdout.is_empty());
    let (t, _) = ThresholdImage::read(&dir.join("t.exr")).unwrap();
    assert_eq!((t.width, t.height), (16, 8));
    assert_eq!(t.header.provenance.stage, "mask");
    // A uniform field: no masking, contrast = TVI(L) / L.
    assert!(t.elevation.iter().all(|&e| (e - 1.0).abs() < 1e-6));
    let l = 100.0 * mask::srgb_decode(128.0 / 255.0);
    assert!((f64::from(t.luminance[0]) / l - 1.0).abs() < 1e-5);
    assert!((f64::from(t.contrast[0]) - mask::model::tvi(l) / l).abs() < 1e-5);
    let first = std::fs::read(dir.join("t.exr")).unwrap();
    assert!(mask(&dir, &["preview.png", "-o", "t.exr", "--report", "r.ron"]).status.success());
    assert!(first == std::fs::read(dir.join("t.exr")).unwrap(), "reruns are byte-identical");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_are_one_line_naming_the_file_and_leave_no_output() {
    let dir = workdir("err");
    std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
    let out = mask(&dir, &["bad.png", "-o", "t.exr"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.lines().count() == 1 && stderr.contains("bad.png"), "{stderr}");
    assert!(!dir.join("t.exr").exists());
    let out = mask(&dir, &["missing.png", "-o", "t.exr"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.png"));
    // An unwritable report is found before anything is written.
    write_png(&dir);
    let out = mask(&dir, &["preview.png", "-o", "t.exr", "--report", "no/such/dir/r.ron"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
    assert!(!dir.join("t.exr").exists(), "no partial output");
    let out = mask(&dir, &["preview.png", "-o", "t.exr", "--levels", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("levels"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn print_params_reads_back_through_params() {
    let dir = workdir("params");
    let out = mask(&dir, &["--print-params", "--pixels-per-degree", "40", "--masking-slope", "0.5"]);
    assert!(out.status.success());
    std::fs::write(dir.join("p.ron"), &out.stdout).unwrap();
    let again = mask(&dir, &["--params", "p.ron", "--print-params"]);
    assert_eq!(out.stdout, again.stdout);
    let p: mask::Params = ron::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!(p, mask::Params { pixels_per_degree: 40.0, masking_slope: 0.5, ..mask::Params::default() });
    std::fs::write(dir.join("typo.ron"), "(level: 3)").unwrap();
    let out = mask(&dir, &["--params", "typo.ron", "--print-params"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("typo.ron"));
    std::fs::remove_dir_all(&dir).unwrap();
}

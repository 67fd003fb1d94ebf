//! The binary's contract: files in, PNG and report out, exit codes, one-line
//! errors and no partial output.

use schemas::header::{Provenance, Schema};
use schemas::image::HdrImage;
use schemas::report::Report;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tonemap-cli-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_image(path: &Path, rgb: Vec<[f32; 3]>, width: usize) {
    let provenance = Provenance::in_memory("test");
    let height = rgb.len() / width;
    let coverage = vec![1.0; rgb.len()];
    HdrImage { header: HdrImage::header(provenance), width, height, rgb, coverage, surfaces: None }.write(path).unwrap();
}

fn tonemap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tonemap")).args(args).output().unwrap()
}

#[test]
fn writes_png_and_report() {
    let dir = scratch("ok");
    let (input, png, report) = (dir.join("in.exr"), dir.join("out.png"), dir.join("r.ron"));
    write_image(&input, vec![[1.0; 3], [0.25; 3], [4.0; 3], [0.0; 3]], 2);
    let out = tonemap(&[input.to_str().unwrap(), "-o", png.to_str().unwrap(), "--report", report.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stdout.is_empty(), "stdout is data or nothing");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let report = schemas::ron_io::read_ron::<Report>(&report).unwrap().value;
    assert_eq!(report.counters["pixels"], 4.0);
    assert!(report.counters.contains_key("key") && report.counters.contains_key("white_luminance"));
    assert_eq!(report.header.provenance.inputs.len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn non_finite_input_is_one_line_error_and_no_output() {
    let dir = scratch("nan");
    let (input, png) = (dir.join("in.exr"), dir.join("out.png"));
    write_image(&input, vec![[1.0; 3], [1.0; 3], [1.0; 3], [1.0, f32::NAN, 1.0]], 2);
    let out = tonemap(&[input.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("tonemap: error: ") && stderr.contains("in.exr") && stderr.contains("(x 1, y 1)"),
        "{stderr}"
    );
    assert!(!png.exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "a temporary file was left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn printed_params_read_back_and_flags_override() {
    let dir = scratch("params");
    let out = tonemap(&["--print-params", "--operator", "exposure", "--exposure", "0.5"]);
    assert_eq!(out.status.code(), Some(0));
    let file = dir.join("p.ron");
    std::fs::write(&file, &out.stdout).unwrap();
    let out = tonemap(&["--print-params", "--params", file.to_str().unwrap(), "--exposure", "auto"]);
    let params: tonemap::Params = ron::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!(params.operator, tonemap::Operator::Exposure);
    assert_eq!(params.exposure, tonemap::Setting::Auto);
    std::fs::write(&file, "(operater: Exposure)").unwrap();
    let out = tonemap(&["--print-params", "--params", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn foreign_exr_is_tonemapped_with_a_note() {
    use exr::prelude::*;
    let dir = scratch("foreign");
    let (ours, theirs) = (dir.join("ours.exr"), dir.join("theirs.exr"));
    let rgb = vec![[1.0; 3], [0.25; 3], [4.0; 3], [0.5; 3]];
    write_image(&ours, rgb.clone(), 2);
    let pixel = |p: Vec2<usize>| {
        let v = rgb[p.y() * 2 + p.x()];
        (v[0], v[1], v[2])
    };
    let layer = Layer::new((2, 2), LayerAttributes::default(), Encoding::FAST_LOSSLESS, SpecificChannels::rgb(pixel));
    Image::from_layer(layer).write().to_file(&theirs).unwrap();
    let (a, b) = (dir.join("ours.png"), dir.join("theirs.png"));
    let out = tonemap(&[ours.to_str().unwrap(), "-o", a.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty());
    let out = tonemap(&[theirs.to_str().unwrap(), "-o", b.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("tonemap: note: ") && stderr.contains("foreign EXR (no provenance") && stderr.lines().count() == 1, "{stderr}");
    // Same pixels, same picture (an alpha-less EXR counts as fully covered).
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

//! Same inputs and parameters give byte-identical artifacts, whatever the
//! thread count; only the reports' wall time differs between runs.

use end_to_end::{run_ok, s, scratch};
use std::path::Path;
use std::process::Command;

/// The whole hierarchical pipeline on the built-in Cornell box into `dir`,
/// with `threads` worker threads.
fn pipeline(dir: &Path, threads: &str) {
    let p = |name: &str| dir.join(name);
    let with_threads = |stage: &str, args: &[&str]| {
        let out = Command::new(end_to_end::bin(stage)).args(args).env("RAYON_NUM_THREADS", threads).output().unwrap();
        assert!(out.status.success(), "{stage}: {}", String::from_utf8_lossy(&out.stderr));
    };
    run_ok("mesh-prep", &["--builtin", "cornell-box", "--mesh", s(&p("mesh.exr")), "--manifest", s(&p("manifest.ron"))]);
    with_threads(
        "hierarchical-solve",
        &["--mesh", s(&p("mesh.exr")), "--manifest", s(&p("manifest.ron")), "-o", s(&p("solution.exr")), "--report", s(&p("solve.report.ron"))],
    );
    with_threads(
        "grid-gather",
        &["--mesh", s(&p("mesh.exr")), "--manifest", s(&p("manifest.ron")), "--solution", s(&p("solution.exr")), "-o", s(&p("image.exr")), "--width", "64", "--height", "64"],
    );
    run_ok("tonemap", &[s(&p("image.exr")), "-o", s(&p("image.png"))]);
}

#[test]
fn reruns_are_byte_identical_for_any_thread_count() {
    // The runs happen in the same directory, so their command lines (part
    // of the provenance) are the same too.
    let dir = scratch("determinism");
    pipeline(&dir, "2");
    let first: Vec<(String, Vec<u8>)> = ["mesh.exr", "manifest.ron", "solution.exr", "image.exr", "image.png"]
        .iter()
        .map(|name| (name.to_string(), std::fs::read(dir.join(name)).unwrap()))
        .collect();
    let report = std::fs::read_to_string(dir.join("solve.report.ron")).unwrap();
    pipeline(&dir, "1");
    for (name, bytes) in &first {
        assert!(std::fs::read(dir.join(name)).unwrap() == *bytes, "{name} differs between runs");
    }
    // Reports: identical but for the volatile wall time and timings.
    let strip = |text: &str| -> Vec<String> {
        text.lines().filter(|l| !l.contains("seconds") && !l.contains("wall_time_s") && !l.contains("per_second")).map(String::from).collect()
    };
    assert_eq!(strip(&report), strip(&std::fs::read_to_string(dir.join("solve.report.ron")).unwrap()));
}

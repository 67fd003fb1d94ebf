//! The photon-trace binary's contract: `--print-params` round trips
//! through `--params`, a misspelt parameter file and a missing input are
//! one line with exit 2 and no output. (Cargo builds the binary for these
//! tests, so the end-to-end tests in `tests/` find it after `cargo test`.)

use std::path::PathBuf;
use std::process::{Command, Output};

fn photon_trace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_photon-trace")).args(args).output().expect("photon-trace runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("photon-trace-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn print_params_round_trips_through_a_params_file() {
    let dir = scratch("params");
    let out = photon_trace(&["--print-params", "--target-error", "0.0125", "--max-photons", "777", "--time-budget-s", "3", "--seed", "9"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("target_error: 0.0125") && text.contains("max_photons: 777") && text.contains("time_budget_s: Some(3.0)"), "{text}");
    let file = dir.join("p.ron");
    std::fs::write(&file, &text).unwrap();
    let again = photon_trace(&["--print-params", "--params", file.to_str().unwrap()]);
    assert!(again.status.success());
    assert_eq!(String::from_utf8(again.stdout).unwrap(), text);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_gives_one_line_exit_2_and_no_output() {
    let dir = scratch("bad");
    let (params, output) = (dir.join("p.ron"), dir.join("solution.exr"));
    std::fs::write(&params, "(target_eror: 0.1)").unwrap();
    let p = |p: &PathBuf| p.to_str().unwrap().to_string();
    let missing = dir.join("missing.exr");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--print-params".into(), "--params".into(), p(&params)], "target_eror"),
        (vec!["--mesh".into(), p(&missing), "--manifest".into(), p(&missing), "-o".into(), p(&output)], "missing.exr"),
        (vec!["--print-params".into(), "--batches-per-round".into(), "1".into()], "batches_per_round must be at least 2"),
    ];
    for (args, needle) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = photon_trace(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!output.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

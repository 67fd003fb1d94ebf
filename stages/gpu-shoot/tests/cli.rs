//! The gpu-shoot binary's contract: `--print-params` round trips, and bad
//! input gives one line naming the problem, exit 2, and no output files.
//! None of these needs a GPU (errors are found before the device).

use std::path::PathBuf;
use std::process::{Command, Output};

fn gpu_shoot(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gpu-shoot")).args(args).output().expect("gpu-shoot runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gpu-shoot-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn print_params_round_trips_through_a_params_file() {
    let dir = scratch("params");
    let out = gpu_shoot(&["--print-params", "--texels", "1234", "--visibility", "stereographic", "--no-overshoot", "--resolution", "64", "--convergence-target", "0.95"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("1234") && text.contains("stereographic") && text.contains("overshoot: false"), "{text}");
    let file = dir.join("p.ron");
    std::fs::write(&file, &text).unwrap();
    let again = gpu_shoot(&["--print-params", "--params", file.to_str().unwrap()]);
    assert!(again.status.success());
    assert_eq!(String::from_utf8(again.stdout).unwrap(), text);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_gives_one_line_exit_2_and_no_output() {
    let dir = scratch("bad");
    let (mesh, manifest, output, lightmap) = (dir.join("missing.exr"), dir.join("manifest.ron"), dir.join("solution.exr"), dir.join("lightmap.exr"));
    std::fs::write(&manifest, "not ron").unwrap();
    let p = |p: &PathBuf| p.to_str().unwrap().to_string();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--mesh".into(), p(&mesh), "--manifest".into(), p(&manifest), "-o".into(), p(&output), "--lightmap".into(), p(&lightmap)], "missing.exr"),
        (vec!["--mesh".into(), p(&mesh), "--manifest".into(), p(&manifest), "-o".into(), p(&output), "--resolution".into(), "4".into()], "resolution"),
        (vec!["--print-params".into(), "--params".into(), p(&manifest)], "manifest.ron"),
    ];
    for (args, names) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = gpu_shoot(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: not one line: {stderr}");
        assert!(stderr.contains(names), "{args:?}: {stderr} does not name {names}");
        assert!(out.stdout.is_empty());
        assert!(!output.exists() && !lightmap.exists(), "{args:?} left partial output");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

//! The command line every stage shares: one name per knob across
//! `--print-params` and the flags, one-line usage errors, outputs that never
//! overwrite inputs, bounded image sizes.

use end_to_end::stages::stages;
use end_to_end::{assert_refused, run, run_ok, s, scratch};

/// The top-level fields of `--print-params` output (`  name: value,`).
fn params(stage: &str, flags: &[&str]) -> Option<Vec<(String, String)>> {
    let mut args = vec!["--print-params"];
    args.extend_from_slice(flags);
    let out = run(stage, &args);
    out.status.success().then(|| {
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("  ").filter(|l| !l.starts_with(' ')))
            .filter_map(|l| l.split_once(": "))
            .map(|(k, v)| (k.to_string(), v.trim_end_matches(',').to_string()))
            .collect()
    })
}

/// The long flags `--help` lists.
fn flags(stage: &str) -> Vec<String> {
    let help = String::from_utf8(run_ok(stage, &["--help"]).stdout).unwrap();
    help.lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with('-'))
        .filter_map(|l| l.find("--").map(|at| &l[at + 2..]))
        .map(|l| l.split([' ', '=']).next().unwrap().to_string())
        .collect()
}

/// Values to try for a knob whose default prints as `value`: a different
/// number of the same kind (the stage's range check decides which is
/// legal), or `None` for knobs that are not numbers.
fn other_values(value: &str) -> Vec<String> {
    if value == "None" {
        return vec!["7".into(), "0.25".into()];
    }
    match value.parse::<f64>() {
        Ok(v) if !value.contains(['.', 'e']) => [1, 2, -1].into_iter().map(|d| v as i64 + d).filter(|x| *x >= 0).map(|x| x.to_string()).collect(),
        Ok(v) => vec![format!("{}", v / 2.0), format!("{}", v * 2.0)],
        Err(_) => Vec::new(),
    }
}

/// One name per knob: every parameter `--print-params` shows has a flag of
/// the same name (`snake_case` as `--kebab-case`), and that flag sets that
/// parameter: a changed number (or the boolean's `--no-` form) shows up in
/// `--print-params` under the same name. A flag that sets another knob, or
/// a knob with no flag, fails here.
#[test]
fn every_parameter_has_a_flag_of_its_name_that_sets_it() {
    for stage in &stages() {
        let defaults = params(stage, &[]).unwrap_or_else(|| panic!("{stage} --print-params fails"));
        let flags = flags(stage);
        for (name, value) in &defaults {
            let flag = name.replace('_', "-");
            assert!(flags.contains(&flag), "{stage}: parameter {name} has no flag --{flag} (flags: {flags:?})");
            let changed = match value.as_str() {
                "true" | "false" => {
                    let (toggle, want) = if value == "true" { (format!("--no-{flag}"), "false") } else { (format!("--{flag}"), "true") };
                    if !flags.contains(&toggle[2..].to_string()) {
                        panic!("{stage}: boolean {name} has no {toggle}");
                    }
                    params(stage, &[&toggle]).map(|p| (p, want.to_string()))
                }
                _ => other_values(value).into_iter().find_map(|v| params(stage, &[&format!("--{flag}"), &v]).map(|p| (p, v))),
            };
            let Some((after, want)) = changed else {
                assert!(other_values(value).is_empty() || value == "None", "{stage}: --{flag} accepts none of {:?}", other_values(value));
                continue;
            };
            let got = &after.iter().find(|(k, _)| k == name).unwrap().1;
            let same = match (got.trim_start_matches("Some(").trim_end_matches(')').parse::<f64>(), want.parse::<f64>()) {
                (Ok(a), Ok(b)) => a == b,
                _ => got == &want,
            };
            assert!(same, "{stage}: --{flag} {want} gave {name}: {got}");
        }
    }
}

/// Runs `stage` and expects exit 2 with one stderr line containing every
/// needle.
fn refused(stage: &str, args: &[&str], needles: &[&str]) {
    assert_refused(stage, args, needles, &[]);
}

#[test]
fn bad_flags_get_one_line_errors() {
    for stage in &stages() {
        refused(stage, &["--no-such-flag"], &[stage.as_str(), "--no-such-flag"]);
    }
    refused("hierarchical-solve", &["--print-params", "--eps", "-1"], &["eps", "-1"]);
    refused("hierarchical-solve", &["--print-params", "--eps", "x"], &["--eps", "'x'"]);
    refused("hierarchical-solve", &["--eps", "1e-3"], &["--mesh", "--manifest"]);
    refused("grid-gather", &["--print-params", "--width", "100000"], &["width", "16384"]);
}

#[test]
fn an_output_never_overwrites_an_input() {
    let dir = scratch("output_is_input");
    let (mesh, manifest, solution, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("solution.exr"), dir.join("image.exr"));
    run_ok("mesh-prep", &["--builtin", "cornell-box", "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    run_ok("hierarchical-solve", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--eps", "1e-2"]);
    let before = std::fs::read(&solution).unwrap();
    let link = dir.join("link.exr");
    std::os::unix::fs::symlink(&solution, &link).unwrap();
    for output in [&solution, &link] {
        refused("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(output)], &["refusing to overwrite"]);
    }
    assert_eq!(std::fs::read(&solution).unwrap(), before, "the input was changed");
    run_ok("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--width", "8", "--height", "8"]);
    refused("tonemap", &[s(&image), "-o", s(&image)], &["image.exr", "refusing to overwrite"]);
    refused("compare", &[s(&image), s(&image), "--diff", s(&image)], &["refusing to overwrite"]);
    refused("grid-gather", &["--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(&solution), "-o", s(&image), "--report", s(&image)], &["named twice"]);
}

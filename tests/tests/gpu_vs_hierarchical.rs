//! gpu-shoot against hierarchical-solve on the built-in Cornell box: two
//! solvers of the same radiosity equation, previewed by grid-gather the
//! same way, agree within 3% relative RMSE when gpu-shoot has shot 99% of
//! the emitted power (issue 5). gpu-shoot needs a Vulkan adapter (Mesa's
//! lavapipe is enough): without one the test skips loudly, but fails when
//! the environment variable CI is set.

use end_to_end::{run, run_ok, s, scratch, skipped_without_gpu};

#[test]
fn gpu_shoot_and_hierarchical_solve_previews_agree_on_the_cornell_box() {
    let dir = scratch("gpu_vs_hierarchical");
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &["--builtin", "cornell-box", "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let gpu_solution = dir.join("gpu.exr");
    let convergence = dir.join("convergence.ron");
    let gpu = run(
        "gpu-shoot",
        &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&gpu_solution), "--convergence-log", s(&convergence), "--texels", "8000", "--convergence-target", "0.99"],
    );
    if skipped_without_gpu(&gpu, "gpu_vs_hierarchical") {
        return;
    }
    let text = std::fs::read_to_string(&convergence).unwrap();
    let last = text.rfind("unshot_fraction:").expect("shots in convergence.ron");
    let unshot: f64 = text[last + "unshot_fraction:".len()..].trim_start().split(|c: char| c == ',' || c.is_whitespace()).next().unwrap().parse().unwrap();
    assert!(unshot <= 0.01, "gpu-shoot stopped at unshot fraction {unshot}");

    let hierarchical = dir.join("hierarchical.exr");
    run_ok("hierarchical-solve", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&hierarchical), "--eps", "1e-3"]);
    let mut previews = Vec::new();
    for (name, solution) in [("gpu", &gpu_solution), ("hierarchical", &hierarchical)] {
        let preview = dir.join(format!("preview-{name}.exr"));
        run_ok(
            "grid-gather",
            &["--mode", "preview", "--mesh", s(&mesh), "--manifest", s(&manifest), "--solution", s(solution), "-o", s(&preview), "--width", "64", "--height", "64"],
        );
        previews.push(preview);
    }
    let report = dir.join("compare.ron");
    let out = run("compare", &[s(&previews[0]), s(&previews[1]), "-o", s(&report), "--max-rel-rmse", "0.03"]);
    let text = std::fs::read_to_string(&report).unwrap();
    eprintln!("gpu-shoot vs hierarchical-solve at unshot {unshot:.4}:\n{text}");
    assert_eq!(out.status.code(), Some(0), "relative RMSE of the previews over 3%: {text}");
}

/// Power (W, channel 0) leaving `object`: its leaves' area times radiosity.
fn flux(mesh: &std::path::Path, manifest: &std::path::Path, solution: &std::path::Path, object: &str) -> f64 {
    let (mesh, _) = schemas::mesh::Mesh::read(mesh).unwrap();
    let manifest = schemas::ron_io::read_ron::<schemas::mesh::Manifest>(manifest).unwrap().value;
    let (solution, _) = schemas::solution::Solution::read(solution).unwrap();
    solution
        .elements
        .iter()
        .filter(|e| e.is_leaf() && manifest.objects[mesh.triangles[e.triangle as usize].object as usize] == object)
        .map(|e| f64::from(e.area) * f64::from(e.radiosity[0]))
        .sum()
}

/// Issue 10, item 7: gpu-shoot's ambient term (004 Eq. 2.4) spreads the
/// unshot power over the scene as if it were closed; in an open scene it
/// adds light that is not there. On paper 002's one-bounce configuration
/// (open: everything leaves past the edges of A), receiver B's power from
/// gpu-shoot at 99% shot (default atlas) must match hierarchical-solve's
/// (which its own test holds within 1.1% per leaf of a quadrature
/// reference) within 2% by default, and the ambient term, asked for, must
/// add over 1% to it, or this test no longer tells the two apart. Measured:
/// -0.44% by default, +1.25% with `--ambient` (+1.3% and +3.0% before the
/// solution's lookup read the atlas at its texel centres and the receiver
/// pass took near groups by reciprocity; the issue measured +6.3% at its
/// settings). The receiver powers of `gpu_shoot_elements` hold open scenes
/// to 0.5% of closed forms.
#[test]
fn gpu_shoot_adds_no_ambient_light_to_an_open_scene_by_default() {
    let dir = scratch("gpu_open_scene");
    let scene = test_support::scenes::one_bounce(0.5, 0.05, 1.0).write(&dir);
    let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    run_ok("mesh-prep", &[s(&scene), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    let hierarchical = dir.join("hierarchical.exr");
    run_ok("hierarchical-solve", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&hierarchical)]);
    let reference = flux(&mesh, &manifest, &hierarchical, "B");
    let mut relative = Vec::new();
    for extra in [None, Some("--ambient")] {
        let solution = dir.join(format!("gpu{}.exr", extra.unwrap_or("")));
        let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--convergence-target", "0.99"];
        args.extend(extra);
        if skipped_without_gpu(&run("gpu-shoot", &args), "gpu_open_scene") {
            return;
        }
        relative.push(flux(&mesh, &manifest, &solution, "B") / reference - 1.0);
    }
    eprintln!("B's power, gpu-shoot vs hierarchical-solve: default {:+.2}%, --ambient {:+.2}%", 100.0 * relative[0], 100.0 * relative[1]);
    assert!(relative[0].abs() <= 0.02, "gpu-shoot's B is {:+.2}% off hierarchical-solve's", 100.0 * relative[0]);
    assert!(relative[1] - relative[0] > 0.01, "the ambient term no longer shows its bias ({:+.2}% against {:+.2}%)", 100.0 * relative[1], 100.0 * relative[0]);
}

//! The `bench-structured` binary end to end on paper 002's simple
//! environment at a small image size: the table holds structured
//! sampling's run and hierarchical-solve's, its per-surface figures add up
//! to the image's, and bad options are one-line errors. No timing is
//! asserted beyond its being measured.
//!
//! The benchmark drives the release stage binaries beside it in
//! `target/release`, which `make test` builds before the tests.

use bench::structured::table::{Bench, Role};
use bench::sweep::knobs::Solver;
use schemas::ron_io::read_ron;
use std::process::Output;

mod common;
use common::scratch;

fn bench_structured(args: &[&str]) -> Output {
    let stages = ["mesh-prep", "cluster", "hierarchical-solve", "grid-gather", "compare", "exact", "structured-sample"];
    common::run_driver(env!("CARGO_BIN_EXE_bench-structured"), &stages, args)
}

/// At 100 x 100 pixels (the exact image takes about 5 s), EPS 8e-3 to
/// 4e-3 brackets structured sampling's figure on B: measured, structured
/// sampling 0.00% of B over 10% with 155 samples, EPS 8e-3 0.31% with 47
/// element vertices, EPS 6e-3 0.00% with 71. The preview's mean-preserving
/// vertex values (grid-gather's `mean_passes`) reversed paper 002's Table
/// 2 here: with plain area-weighted vertex means, the display paper 002
/// compares with, the bracket was EPS 4e-3 (1.9%) to 2e-3 (0.00% with 208
/// vertices), more than structured sampling's 155 samples. (Before
/// hierarchical-solve's relative criterion took the absolute threshold as
/// a cap, `RELATIVE_AT`, that bracket was EPS 0.1 to 0.05: 3.1%, and 0.00%
/// with 225 vertices at 0.07.)
#[test]
fn the_simple_environment_table_has_both_solvers_its_surfaces_add_up_and_b_takes_fewer_vertices_than_samples() {
    let out = scratch("bench_structured");
    let run = bench_structured(&["--scene", "simple-environment", "--eps", "0.008,0.006,0.004", "--width", "100", "--height", "100", "--quality-tau", "0.05,0.1", "-o", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "bench-structured failed:\n{stderr}");
    let bench: Bench = read_ron(&out.join("bench.ron")).unwrap().value;
    assert!(bench.reference.contains("exact image"), "{}", bench.reference);
    let solvers: Vec<(Solver, &str)> = bench.runs.iter().map(|r| (r.solver, r.setting.as_str())).collect();
    assert_eq!(solvers, [(Solver::Structured, "STRUCTURED_LEVELS=8"), (Solver::Hierarchical, "EPS=0.008"), (Solver::Hierarchical, "EPS=0.006"), (Solver::Hierarchical, "EPS=0.004")]);
    for r in &bench.runs {
        let names: Vec<&str> = r.surfaces.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["A", "B"], "every non-emitting object, each its own surface");
        assert!(r.surfaces.iter().all(|s| s.samples > 0 && s.pixels > 0), "{r:?}");
        assert_eq!(r.surfaces.iter().all(|s| s.vertices.is_some()), r.solver == Solver::Hierarchical, "element vertices for hierarchical-solve only");
        // Emitters are left out, so A's and B's pixels are the image's and
        // their pixel-weighted shares over each tau make up the image's.
        for tau in &bench.taus {
            let image = r.over(*tau).expect("measured");
            let pixels: usize = r.surfaces.iter().map(|s| s.pixels).sum();
            let weighted: f64 = r.surfaces.iter().map(|s| s.pixels as f64 * s.over(*tau).unwrap()).sum::<f64>() / pixels as f64;
            assert!((weighted - image).abs() < 1e-9, "{} at tau {tau}: surfaces {weighted} image {image}", r.setting);
        }
        assert!(r.total_s > 0.0);
        assert_eq!(r.light_to_a_s.is_some(), r.solver == Solver::Structured, "only structured-sample's report splits the transfers");
        if let (Some(a), Some(b)) = (r.light_to_a_s, r.a_to_b_s) {
            assert!(a + b <= r.total_s, "the split is part of the stage's time: {a} + {b} > {}", r.total_s);
        }
    }
    assert_eq!(bench.comparisons.len(), 2);
    for c in &bench.comparisons {
        let roles: Vec<&Role> = c.rows.iter().map(|r| &r.role).collect();
        assert_eq!(roles, [&Role::Structured, &Role::SameSpeed, &Role::SameQuality, &Role::FewestOn("A".into()), &Role::FewestOn("B".into())]);
        assert_eq!(c.findings.len(), 4, "{:?}", c.findings);
    }
    // Paper 002's Table 2 (issue 16), measured: structured sampling has
    // under 2% of A's and 1% of B's pixels over 10%; the hierarchical-solve
    // run with the fewest element vertices on B that does as well has fewer
    // of them than structured sampling has samples there (paper 002: more),
    // and the coarsest run swept does worse.
    let structured = &bench.runs[0];
    let (a, b) = (structured.surface("A").unwrap(), structured.surface("B").unwrap());
    assert!(a.over(0.1).unwrap() < 2.0 && b.over(0.1).unwrap() < 1.0, "A {:?} B {:?}", a.over(0.1), b.over(0.1));
    let at_10 = bench.comparisons.iter().find(|c| c.quality_tau == 0.1).unwrap();
    let fewest = at_10.rows.iter().find(|r| r.role == Role::FewestOn("B".into())).and_then(|r| r.run).expect("a hierarchical run does as well on B");
    let theirs = bench.runs[fewest].surface("B").unwrap();
    eprintln!("B: structured {} samples at {:?}%; {} {} vertices", b.samples, b.over(0.1), bench.runs[fewest].setting, theirs.display_points());
    assert!(theirs.display_points() < b.samples, "structured {} samples, hierarchical {} vertices", b.samples, theirs.display_points());
    assert!(bench.runs[1].surface("B").unwrap().over(0.1).unwrap() > b.over(0.1).unwrap(), "EPS 8e-3 does worse on B: the bracket is not vacuous");
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    let text = std::fs::read_to_string(out.join("bench.txt")).unwrap();
    assert!(text.contains("quality compared at tau = 5%:") && text.contains("quality compared at tau = 10%:"), "{text}");
}

#[test]
fn bad_options_are_one_line_errors_naming_them() {
    let out = scratch("bench_structured_bad");
    let o = out.to_str().unwrap();
    for (args, expected) in [
        (vec!["--tau", "0.1", "--quality-tau", "0.15", "-o", o], "--quality-tau 0.15"),
        (vec!["--eps", "-1", "-o", o], "positive numbers"),
        (vec!["--surface", "walls", "-o", o], "--surface walls"),
        (vec!["--surface", "floor=floor", "-o", o], "no object \"floor\""),
    ] {
        let run = bench_structured(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {stderr}");
        // Progress lines may come first; the error is one line, the last.
        let errors: Vec<&str> = stderr.lines().filter(|l| l.contains("error")).collect();
        assert_eq!(errors.len(), 1, "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().last(), Some(errors[0]), "{args:?}: {stderr}");
        assert!(errors[0].contains(expected), "{args:?}: {stderr}");
    }
}

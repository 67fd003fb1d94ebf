//! Artifacts that belong together (issue 11, items 5, 6 and 9): a stage
//! refuses a malformed hierarchy instead of hanging or panicking, refuses
//! inputs of different runs naming both files, a killed mesh-prep leaves
//! its old pair, its new pair or a pair the next stage refuses, and a write
//! over a file-size limit leaves no temporary file.

use end_to_end::{bin, refused, run_ok, s, scratch};
use schemas::cluster::Clusters;
use stage_kit::run::PAUSE_AFTER_COMMITS;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The mesh-prep command writing `mesh.exr`, `manifest.ron` and a report
/// into `dir` from built-in scene `builtin`, with `extra` arguments.
fn mesh_prep(dir: &Path, builtin: &str, extra: &[&str]) -> Command {
    let mut command = Command::new(bin("mesh-prep"));
    let (mesh, manifest, report) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("prep.report.ron"));
    command.args(["--builtin", builtin, "--mesh", s(&mesh), "--manifest", s(&manifest), "--report", s(&report)]).args(extra);
    command
}

/// Runs mesh-prep as [`mesh_prep`] and expects success.
fn prepare(dir: &Path, builtin: &str, extra: &[&str]) {
    let out = mesh_prep(dir, builtin, extra).output().expect("mesh-prep runs");
    assert!(out.status.success(), "mesh-prep failed: {}", String::from_utf8_lossy(&out.stderr));
}

/// `--mesh` and `--manifest` of the pair in `dir`, then `-o dir/output`.
fn stage_args(dir: &Path, output: &str) -> Vec<String> {
    let p = |name: &str| s(&dir.join(name)).to_string();
    vec!["--mesh".into(), p("mesh.exr"), "--manifest".into(), p("manifest.ron"), "-o".into(), p(output)]
}

/// `cluster` over the pair in `dir`, into `dir/clusters.exr`.
fn cluster_args(dir: &Path) -> Vec<String> {
    stage_args(dir, "clusters.exr")
}

fn as_strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

/// Every file of `dir`, temporaries included.
fn everything(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// Rewrites the clusters of `dir` through the schemas writer after `edit`
/// (the provenance stays that of the real run), and returns what
/// hierarchical-solve says of them.
fn solve_with_edited_clusters(dir: &Path, edit: impl FnOnce(&mut Clusters)) -> String {
    let path = dir.join("clusters.exr");
    let triangles = schemas::mesh::Mesh::read(&dir.join("mesh.exr")).unwrap().0.triangles.len();
    let (mut clusters, _) = Clusters::read(&path, triangles).unwrap();
    edit(&mut clusters);
    clusters.write(&path).unwrap();
    let mut args = stage_args(dir, "solution.exr");
    args.extend(["--clusters".into(), s(&path).into()]);
    let message = refused("hierarchical-solve", &as_strs(&args));
    assert!(!dir.join("solution.exr").exists(), "no solution may be written");
    message
}

#[test]
fn the_solver_refuses_a_cyclic_or_empty_hierarchy_in_one_line() {
    let dir = scratch("artifacts_hierarchy");
    prepare(&dir, "cornell-box", &[]);
    run_ok("cluster", &as_strs(&cluster_args(&dir)));
    let clusters = dir.join("clusters.exr");
    // The last inner cluster points back at the root: walked naively, the
    // solver would descend forever.
    let message = solve_with_edited_clusters(&dir, |c| {
        let inner = c.nodes.iter().rposition(|n| !n.is_leaf()).unwrap();
        c.nodes[inner].first_child = 0;
        c.nodes[inner].child_count = 1;
    });
    assert!(message.starts_with(&format!("hierarchical-solve: error: {}: cluster 0: reached twice from the root", s(&clusters))), "{message}");
    run_ok("cluster", &as_strs(&cluster_args(&dir)));
    // A leaf that holds no triangle: the solver once sliced 17..16 of it.
    let message = solve_with_edited_clusters(&dir, |c| {
        let leaf = c.nodes.iter().position(|n| n.is_leaf()).unwrap();
        c.nodes[leaf].triangle_count = 0;
    });
    assert!(message.ends_with("holds no triangle (field triangle_count)") && message.contains(s(&clusters)), "{message}");
}

#[test]
fn artifacts_of_different_runs_are_refused_naming_both_files() {
    let (a, b) = (scratch("artifacts_runs_a"), scratch("artifacts_runs_b"));
    prepare(&a, "cornell-box", &[]);
    // The same geometry from another run: every index fits, only the
    // provenance tells the files apart.
    prepare(&b, "cornell-box", &["--weld-tolerance", "1e-7"]);
    run_ok("cluster", &as_strs(&cluster_args(&a)));
    let (mesh_a, manifest_b) = (a.join("mesh.exr"), b.join("manifest.ron"));
    let mut mixed = cluster_args(&a);
    mixed[3] = s(&manifest_b).into();
    let message = refused("cluster", &as_strs(&mixed));
    assert_eq!(
        message,
        format!("cluster: error: {}: does not belong with {}: they come from different mesh-prep runs (their provenance differs); rerun it to write both", s(&mesh_a), s(&manifest_b))
    );
    let other_mesh = stage_args(&b, "solution.exr");
    let mut args = as_strs(&other_mesh);
    let clusters_a = a.join("clusters.exr");
    args.extend(["--clusters", s(&clusters_a)]);
    let message = refused("hierarchical-solve", &args);
    let prefix = format!("hierarchical-solve: error: {}: does not belong with {} (SHA-256 ", s(&clusters_a), s(&b.join("mesh.exr")));
    assert!(message.starts_with(&prefix) && message.contains(&format!("it was made from {} (SHA-256", s(&mesh_a))), "{message}");
    // A solution of the first pair, gathered over the second.
    let coarse = ["--criterion", "absolute", "--eps", "1", "--min-area", "0.1", "--visibility-rays", "1", "--max-passes", "1"];
    let mut solve = stage_args(&a, "solution.exr");
    solve.extend(coarse.map(String::from));
    run_ok("hierarchical-solve", &as_strs(&solve));
    let mut gather = stage_args(&b, "image.exr");
    let solution_a = a.join("solution.exr");
    gather.extend(["--solution".into(), s(&solution_a).into()]);
    let message = refused("grid-gather", &as_strs(&gather));
    let prefix = format!("grid-gather: error: {}: does not belong with {} (SHA-256 ", s(&solution_a), s(&b.join("mesh.exr")));
    assert!(message.starts_with(&prefix), "{message}");
    assert!(!b.join("image.exr").exists());
}

/// Which run each of the pair in a killed run's directory comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pair {
    Old,
    New,
    /// The new mesh beside the old manifest (or the reverse).
    Mixed,
}

/// The two runs of a kill test: the old pair is in place, the new run
/// overwrites it and is stopped somewhere.
struct KillTest {
    dir: PathBuf,
    old: [Vec<u8>; 2],
    new: [Vec<u8>; 2],
}

impl KillTest {
    const PAIR: [&'static str; 2] = ["mesh.exr", "manifest.ron"];

    /// Records the pairs `old_scene` and `new_scene` give in `test`'s dir.
    fn new(test: &str, old_scene: &str, new_scene: &str) -> Self {
        let dir = scratch(test);
        let read = |dir: &Path| Self::PAIR.map(|n| std::fs::read(dir.join(n)).unwrap());
        prepare(&dir, new_scene, &[]);
        let new = read(&dir);
        prepare(&dir, old_scene, &[]);
        let old = read(&dir);
        KillTest { dir, old, new }
    }

    /// Puts the old pair back and removes what a killed run left.
    fn restore(&self) {
        for name in everything(&self.dir) {
            std::fs::remove_file(self.dir.join(name)).unwrap();
        }
        for (name, bytes) in Self::PAIR.iter().zip(&self.old) {
            std::fs::write(self.dir.join(name), bytes).unwrap();
        }
    }

    /// Classifies the pair now on disk; a mixed pair must be refused by
    /// `cluster` with exit 2, naming both files.
    fn pair(&self) -> Pair {
        let now = Self::PAIR.map(|n| std::fs::read(self.dir.join(n)).unwrap());
        let from = |k: usize| match (now[k] == self.old[k], now[k] == self.new[k]) {
            (true, _) => Pair::Old,
            (_, true) => Pair::New,
            _ => panic!("{} is neither the old nor the new one", Self::PAIR[k]),
        };
        match (from(0), from(1)) {
            (a, b) if a == b => a,
            _ => {
                let message = refused("cluster", &as_strs(&cluster_args(&self.dir)));
                assert!(message.contains(s(&self.dir.join("mesh.exr"))) && message.contains(s(&self.dir.join("manifest.ron"))), "{message}");
                assert!(message.contains("different mesh-prep runs"), "{message}");
                Pair::Mixed
            }
        }
    }
}

impl KillTest {
    /// Runs the new mesh-prep over the old pair, waits until the test hook
    /// has it pause after `renames` renames, sends it `signal` (`KILL`,
    /// `INT`, `TERM`) and returns its exit code (`None` when killed).
    fn stop_after(&self, scene: &str, renames: usize, signal: &str) -> Option<i32> {
        self.restore();
        let mut child = mesh_prep(&self.dir, scene, &[])
            .env(PAUSE_AFTER_COMMITS, renames.to_string())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
        let mut line = String::new();
        while !line.contains("paused after") {
            line.clear();
            assert!(stderr.read_line(&mut line).unwrap() > 0, "mesh-prep ended without pausing after {renames} renames");
        }
        // bash's own kill: a minimal machine may have no kill binary.
        let sent = Command::new("bash").arg("-c").arg(format!("kill -{signal} {}", child.id())).status().unwrap();
        assert!(sent.success());
        child.wait().unwrap().code()
    }
}

#[test]
fn a_kill_between_the_renames_leaves_a_pair_the_next_stage_can_trust() {
    let test = KillTest::new("artifacts_kill_hook", "cornell-box", "cornell-box-2k");
    // The outputs are renamed in the order written: mesh, manifest, report.
    for (renames, expected) in [(0, Pair::Old), (1, Pair::Mixed), (2, Pair::New)] {
        assert_eq!(test.stop_after("cornell-box-2k", renames, "KILL"), None);
        assert_eq!(test.pair(), expected, "after {renames} renames");
        let clustered = Command::new(bin("cluster")).args(cluster_args(&test.dir)).output().unwrap();
        assert_eq!(clustered.status.success(), expected != Pair::Mixed, "cluster on the pair left after {renames} renames");
    }
}

#[test]
fn an_interrupt_between_the_renames_removes_every_temporary_file() {
    let test = KillTest::new("artifacts_interrupt", "cornell-box", "cornell-box-2k");
    // Before the first rename all three outputs are staged; after the first,
    // two. Exit code 128 + the signal, as the shell reports one.
    for (renames, signal, code, expected) in [(0, "INT", 130, Pair::Old), (1, "TERM", 143, Pair::Mixed)] {
        assert_eq!(test.stop_after("cornell-box-2k", renames, signal), Some(code), "SIG{signal} after {renames} renames");
        assert_eq!(everything(&test.dir), ["manifest.ron", "mesh.exr"], "no temporary file left");
        assert_eq!(test.pair(), expected);
    }
}

#[test]
fn sigkill_at_any_moment_leaves_the_old_pair_the_new_pair_or_a_refused_one() {
    let test = KillTest::new("artifacts_sigkill", "cornell-box", "plants-100k");
    let mut seen = Vec::new();
    for delay_ms in [20, 300, 600, 800, 1000, 1300, 3000] {
        test.restore();
        let mut child = mesh_prep(&test.dir, "plants-100k", &[]).stderr(std::process::Stdio::null()).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        child.wait().unwrap();
        seen.push((delay_ms, test.pair()));
    }
    // The pair was checked at every kill; the spread of delays is meant to
    // catch the run before, during and after its writes.
    assert!(seen.iter().any(|(_, p)| *p == Pair::Old), "{seen:?}");
}

#[test]
fn a_write_over_the_file_size_limit_fails_in_one_line_and_leaves_no_temporary_file() {
    let dir = scratch("artifacts_ulimit");
    // 64 KiB: plants-10k's mesh.exr is about 300 KB. Without the SIGXFSZ
    // handler the kernel would kill mesh-prep mid-write, leaving its
    // temporary file.
    let script = "ulimit -f 64; exec \"$0\" \"$@\"";
    let mesh = mesh_prep(&dir, "plants-10k", &[]);
    let out = Command::new("bash").arg("-c").arg(script).arg(mesh.get_program()).args(mesh.get_args()).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].starts_with(&format!("mesh-prep: error: {}: ", s(&dir.join("mesh.exr")))) && errors[0].ends_with("File too large (os error 27)"), "{stderr}");
    assert_eq!(everything(&dir), Vec::<String>::new(), "nothing may be left behind");
}

//! The layers of ARCHITECTURE.md, read from the manifests: no stage names
//! another stage in any of its dependency tables (normal, dev, build), the
//! shared libraries depend only on the libraries below them, and no
//! library or stage needs test-support outside its dev-dependencies.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The workspace root (this crate is `tests/`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

/// One crate's manifest: its package name and the names in each of its
/// dependency tables (`dependencies`, `dev-dependencies`,
/// `build-dependencies`, target-specific ones under the same names).
struct Manifest {
    name: String,
    tables: BTreeMap<String, Vec<String>>,
}

/// Reads the manifest of the crate in `dir`: a line parser for the forms
/// the workspace writes (`name = ...`, `name.workspace = true`, `[table]`).
fn manifest(dir: &Path) -> Manifest {
    let path = dir.join("Cargo.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (mut name, mut table, mut tables) = (String::new(), String::new(), BTreeMap::<String, Vec<String>>::new());
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        if let Some(header) = line.strip_prefix('[') {
            table = header.trim_end_matches(']').rsplit('.').next().unwrap_or_default().to_string();
            continue;
        }
        let key = line.split(['=', '.']).next().unwrap_or_default().trim().to_string();
        if table == "package" && key == "name" {
            name = line.split('"').nth(1).expect("a quoted package name").to_string();
        } else if table.ends_with("dependencies") {
            tables.entry(table.clone()).or_default().push(key);
        }
    }
    assert!(!name.is_empty(), "{}: no package name", path.display());
    Manifest { name, tables }
}

/// The manifests of the crates in the folders of `folder`.
fn crates_in(folder: &str) -> Vec<Manifest> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root().join(folder)).unwrap().map(|e| e.unwrap().path()).filter(|p| p.join("Cargo.toml").exists()).collect();
    dirs.sort();
    dirs.iter().map(|d| manifest(d)).collect()
}

#[test]
fn no_stage_depends_on_another_stage() {
    let stages = crates_in("stages");
    assert!(stages.len() >= 12, "the stages are found: {}", stages.len());
    let names: Vec<&str> = stages.iter().map(|m| m.name.as_str()).collect();
    let mut broken = Vec::new();
    for stage in &stages {
        for (table, deps) in &stage.tables {
            broken.extend(deps.iter().filter(|d| names.contains(&d.as_str()) || d.as_str() == "end-to-end").map(|d| format!("{} [{table}] {d}", stage.name)));
        }
    }
    assert!(broken.is_empty(), "a stage depends on another (move the test that joins them to tests/tests/): {broken:?}");
}

#[test]
fn the_libraries_depend_only_on_the_layers_below_them() {
    let libs = crates_in("libs");
    let workspace: Vec<String> = libs.iter().map(|m| m.name.clone()).chain(crates_in("stages").into_iter().map(|m| m.name)).collect();
    // Normal dependencies within the workspace each library may name.
    let allowed = BTreeMap::from([
        ("schemas", vec![]),
        ("radiometry", vec![]),
        ("stage-kit", vec!["schemas", "radiometry"]),
        ("test-support", vec!["schemas"]),
    ]);
    assert_eq!(libs.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), allowed.keys().copied().collect::<Vec<_>>(), "every library has its row here and in ARCHITECTURE.md");
    for lib in &libs {
        let named: Vec<&String> = lib.tables.get("dependencies").into_iter().flatten().filter(|d| workspace.contains(d)).collect();
        let may = &allowed[lib.name.as_str()];
        assert!(named.iter().all(|d| may.contains(&d.as_str())), "{} depends on {named:?}; it may depend on {may:?}", lib.name);
    }
}

#[test]
fn test_support_is_only_a_dev_dependency_of_libraries_and_stages() {
    for m in crates_in("libs").into_iter().chain(crates_in("stages")) {
        for (table, deps) in &m.tables {
            assert!(table == "dev-dependencies" || !deps.iter().any(|d| d == "test-support"), "{} names test-support in [{table}]", m.name);
        }
    }
}

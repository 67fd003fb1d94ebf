//! The workspace's stages, read from its folders: a test that runs every
//! stage takes them from here, so a new stage cannot be left out of it.

use std::path::Path;

/// The binaries of the stages: the `[[bin]]` names in the manifest of
/// every folder of `stages/` (each stage is a binary; a folder there
/// without one fails here, as a stage the tests could not run).
pub fn stages() -> Vec<String> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../stages");
    let mut manifests: Vec<_> = std::fs::read_dir(&folder).expect("the stages folder").map(|e| e.expect("a stage folder").path().join("Cargo.toml")).filter(|m| m.exists()).collect();
    manifests.sort();
    let mut binaries = Vec::new();
    for manifest in manifests {
        let text = std::fs::read_to_string(&manifest).unwrap_or_else(|e| panic!("{}: {e}", manifest.display()));
        let found = bin_names(&text);
        assert!(!found.is_empty(), "{}: no [[bin]] with a name", manifest.display());
        binaries.extend(found);
    }
    binaries
}

/// The `name = "..."` of each `[[bin]]` table of a manifest's `text`.
fn bin_names(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut in_bin = false;
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            in_bin = line == "[[bin]]";
        } else if let Some(value) = line.strip_prefix("name").map(str::trim_start).and_then(|l| l.strip_prefix('=')).filter(|_| in_bin) {
            names.push(value.trim().trim_matches('"').to_string());
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bin_names_are_read_from_bin_tables_only() {
        let manifest = "[package]\nname = \"pkg\"\n\n[lib]\nname = \"lib\"\n\n[[bin]]\nname = \"one\"\npath = \"src/main.rs\"\n\n[[bin]]\npath = \"src/b.rs\"\nname=\"two\"\n\n[dependencies]\nname = \"x\"\n";
        assert_eq!(bin_names(manifest), ["one", "two"]);
    }

    #[test]
    fn every_stage_folder_is_found() {
        let found = stages();
        assert!(found.len() >= 12 && ["mesh-prep", "compare", "exact", "structured-sample"].iter().all(|s| found.iter().any(|f| f == s)), "{found:?}");
    }
}

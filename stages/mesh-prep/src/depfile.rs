//! The dependency file mesh-prep writes for `make` (`--depfile`): its
//! outputs depend on every file the run read, in make's syntax, so that
//! the Makefile can `-include` it and rerun mesh-prep when any of them
//! changes, wherever it lies.

use std::collections::BTreeSet;

/// A make rule saying that `targets` depend on `prerequisites` (duplicates
/// dropped, first order kept), and an empty rule for each prerequisite, as
/// `gcc -MP` writes: a deleted input then makes `make` rerun mesh-prep,
/// which names it, instead of stopping with "no rule to make target".
pub fn rule(targets: &[&str], prerequisites: &[&str]) -> String {
    let mut seen = BTreeSet::new();
    let prerequisites: Vec<String> = prerequisites.iter().filter(|p| seen.insert(**p)).map(|p| escape(p)).collect();
    let targets: Vec<String> = targets.iter().map(|t| escape(t)).collect();
    let mut text = format!("# Written by mesh-prep: the files its outputs were made from.\n{}:", targets.join(" "));
    for p in &prerequisites {
        text += &format!(" \\\n  {p}");
    }
    text += "\n";
    for p in &prerequisites {
        text += &format!("\n{p}:\n");
    }
    text
}

/// `path` as one word of a make rule: space, tab, `#` and `:` escaped with
/// a backslash, `$` doubled.
pub fn escape(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for c in path.chars() {
        match c {
            ' ' | '\t' | '#' | ':' => {
                out.push('\\');
                out.push(c);
            }
            '$' => out.push_str("$$"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_escaped_for_make() {
        assert_eq!(escape("my scene/a#1:b$c.obj"), "my\\ scene/a\\#1\\:b$$c.obj");
    }

    #[test]
    fn the_rule_lists_each_file_once_and_an_empty_rule_for_it() {
        let text = rule(&["o/mesh.exr", "o/manifest.ron"], &["s/scene.ron", "s/a b.obj", "s/m.mtl", "s/a b.obj"]);
        assert_eq!(
            text,
            "# Written by mesh-prep: the files its outputs were made from.\no/mesh.exr o/manifest.ron: \\\n  s/scene.ron \\\n  s/a\\ b.obj \\\n  s/m.mtl\n\ns/scene.ron:\n\ns/a\\ b.obj:\n\ns/m.mtl:\n"
        );
        assert_eq!(rule(&["m.exr"], &[]), "# Written by mesh-prep: the files its outputs were made from.\nm.exr:\n");
    }
}

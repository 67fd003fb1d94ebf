//! The README's knob tables are the stages' declarations: each stage's
//! `--print-knobs` (the table its `knobs!` declaration makes) must equal
//! the README's table between `<!-- knobs: STAGE -->` and `<!-- /knobs -->`,
//! so a knob added, renamed, re-ranged or re-defaulted without its README
//! row fails here.

use end_to_end::run_ok;
use end_to_end::stages::stages;

/// The README's table for `stage`: the lines between its two markers.
fn readme_table(readme: &str, stage: &str) -> Option<String> {
    let open = format!("<!-- knobs: {stage} -->\n");
    let start = readme.find(&open)? + open.len();
    let end = start + readme[start..].find("<!-- /knobs -->")?;
    Some(readme[start..end].to_string())
}

#[test]
fn every_readme_knob_table_is_its_stage_declaration() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md");
    let readme = std::fs::read_to_string(path).unwrap();
    for stage in &stages() {
        let declared = String::from_utf8(run_ok(stage, &["--print-knobs"]).stdout).unwrap();
        assert!(declared.lines().count() >= 3, "{stage} --print-knobs printed no knob:\n{declared}");
        let documented = readme_table(&readme, stage).unwrap_or_else(|| panic!("README.md has no table between <!-- knobs: {stage} --> and <!-- /knobs -->"));
        assert_eq!(documented, declared, "README.md's knob table of {stage} differs from its declaration; paste `{stage} --print-knobs` between its markers");
    }
}

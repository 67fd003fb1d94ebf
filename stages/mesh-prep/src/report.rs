//! What a run of mesh-prep tells: its warnings and a one-line summary on
//! stderr, the report's counters (the mesh's statistics) and notes (the
//! warnings), and the files it read, for make's dependency file.

use crate::prepare::Prepared;
use schemas::header::Provenance;
use stage_kit::stage::Done;
use std::path::Path;

/// The files a run with `provenance` read from disk, and the dependency
/// file ([`crate::depfile::rule`]) that makes `targets` (those given)
/// depend on them. Every file the scene named (OBJ, MTL, textures,
/// photometry) is one; a built-in scene's files are inside the binary,
/// which the Makefile already lists, so none are.
pub fn files_read<'a>(provenance: &'a Provenance, builtin: bool, targets: &[Option<&Path>]) -> (Vec<&'a Path>, String) {
    let read: Vec<&str> = if builtin { Vec::new() } else { provenance.inputs.iter().map(|i| i.path.as_str()).collect() };
    let targets: Vec<String> = targets.iter().flatten().map(|p| p.display().to_string()).collect();
    let depfile = crate::depfile::rule(&targets.iter().map(String::as_str).collect::<Vec<_>>(), &read);
    (read.into_iter().map(Path::new).collect(), depfile)
}

/// Prints `prepared`'s warnings and its summary on stderr, and returns
/// what the report holds.
pub fn summarise(prepared: &Prepared) -> Done {
    let s = &prepared.statistics;
    for warning in &prepared.warnings {
        eprintln!("mesh-prep: warning: {warning}");
    }
    let twins = match s.two_sided_twins {
        0 => String::new(),
        n => format!(", {n} of them two-sided twins"),
    };
    eprintln!(
        "mesh-prep: {} triangles{twins}, {} vertices ({} degenerate and {} duplicate triangles dropped, {} vertices welded)",
        s.triangles, s.vertices, s.degenerate_dropped, s.duplicates_dropped, s.vertices_welded
    );
    let mut done = Done::counted([
        ("input_triangles", s.input_triangles as f64),
        ("triangles", s.triangles as f64),
        ("vertices", s.vertices as f64),
        ("degenerate_dropped", s.degenerate_dropped as f64),
        ("duplicates_dropped", s.duplicates_dropped as f64),
        ("two_sided_twins", s.two_sided_twins as f64),
        ("vertices_welded", s.vertices_welded as f64),
    ]);
    done.notes = prepared.warnings.clone();
    done
}

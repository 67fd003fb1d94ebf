//! What a run of mesh-prep tells: its warnings and a one-line summary on
//! stderr, and the report's counters (the mesh's statistics) and notes
//! (the warnings).

use crate::prepare::Prepared;
use stage_kit::stage::Done;

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

//! The table of `make bench-mirror`: paper 004 Table 4.1's columns for
//! scenes with mirrors (triangles `n_t`, elements or texels, shots `n_s`,
//! the solver's time `t_r`) and the part of it spent on the specular
//! paths, `t_spec`, for both solvers that simulate mirrors:
//!
//! - *gpu-shoot*, run to 90% convergence (`--convergence-target 0.9`, the
//!   paper's measure): `shots`, `texels`, `shoot_seconds` as `t_r`,
//!   `reflection_seconds` as `t_spec` (building and rendering the
//!   reflection trees, Sec. 4.3.2), and the trees' size
//!   (`reflection_nodes`, `reflection_depth`);
//! - *hierarchical-solve*, run to its own tolerance (it has no 90% point:
//!   it refines and solves in passes): `passes` in the shots column,
//!   `leaves`, the stage's wall time as `t_r`, `specular_seconds` (building
//!   the couplings through the mirrors' windows, hierarchical-solve's `mirrors.rs`) as
//!   `t_spec`, and `specular_couplings` and `specular_rays` for its size.
//!
//! Counters are read from the stages' reports by name; one a report does
//! not hold (an older stage, a scene without mirrors) prints as `-`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

/// One solver's run on one scene, as its report gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct MirrorRun {
    /// The scene's name.
    pub scene: String,
    /// Input triangles of the prepared scene.
    pub triangles: usize,
    /// `gpu-shoot` or `hierarchical-solve`.
    pub solver: &'static str,
    /// The report's wall time, seconds.
    pub wall_s: f64,
    /// The report's counters.
    pub counters: BTreeMap<String, f64>,
}

/// The counters each column reads, per solver: elements, shots, `t_r`,
/// `t_spec`, tree nodes, tree depth, specular couplings, specular rays
/// (`None`: no such counter for that solver; `"wall"`: the wall time).
fn columns(solver: &str) -> [Option<&'static str>; 8] {
    match solver {
        "gpu-shoot" => [Some("texels"), Some("shots"), Some("shoot_seconds"), Some("reflection_seconds"), Some("reflection_nodes"), Some("reflection_depth"), None, None],
        _ => [Some("leaves"), Some("passes"), Some("wall"), Some("specular_seconds"), None, None, Some("specular_couplings"), Some("specular_rays")],
    }
}

impl MirrorRun {
    /// The value of counter `name` (`"wall"`: the wall time), if reported.
    fn value(&self, name: Option<&str>) -> Option<f64> {
        match name? {
            "wall" => Some(self.wall_s),
            name => self.counters.get(name).copied(),
        }
    }
}

/// A count as an integer with thousands apart, `-` when absent.
fn count(x: Option<f64>) -> String {
    let Some(x) = x else { return "-".into() };
    let digits = format!("{:.0}", x.round());
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Seconds to 3 decimals under 10 s, 2 under 100 s, else whole; `-` when
/// absent.
fn seconds(x: Option<f64>) -> String {
    match x {
        None => "-".into(),
        Some(s) if s < 10.0 => format!("{s:.3}"),
        Some(s) if s < 100.0 => format!("{s:.2}"),
        Some(s) => format!("{s:.0}"),
    }
}

/// The markdown table of `runs`, one row each, in order.
pub fn table(runs: &[MirrorRun]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "| scene | triangles | solver | elements / texels | shots (gpu) / passes | t_r (s) | t_spec (s) | t_spec / t_r | tree nodes | tree depth | specular couplings | specular rays |");
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for run in runs {
        let [elements, shots, t_r, t_spec, nodes, depth, couplings, rays] = columns(run.solver).map(|c| run.value(c));
        let share = match (t_spec, t_r) {
            (Some(s), Some(r)) if r > 0.0 => format!("{:.0}%", 100.0 * s / r),
            _ => "-".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            run.scene,
            run.triangles,
            run.solver,
            count(elements),
            count(shots),
            seconds(t_r),
            seconds(t_spec),
            share,
            count(nodes),
            count(depth),
            count(couplings),
            count(rays)
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(solver: &'static str, wall_s: f64, counters: &[(&str, f64)]) -> MirrorRun {
        MirrorRun { scene: "box".into(), triangles: 32, solver, wall_s, counters: counters.iter().map(|&(k, v)| (k.to_string(), v)).collect() }
    }

    #[test]
    fn each_solver_fills_its_columns_by_counter_name_and_dashes_the_rest() {
        let gpu = run("gpu-shoot", 9.0, &[("texels", 8244.0), ("shots", 17.0), ("shoot_seconds", 2.034), ("reflection_seconds", 1.953), ("reflection_nodes", 63.0), ("reflection_depth", 1.0)]);
        let solve = run("hierarchical-solve", 80.29, &[("leaves", 35510.0), ("passes", 8.0), ("specular_seconds", 44.34), ("specular_couplings", 1302193.0), ("specular_rays", 130323415.0)]);
        // A gpu-shoot from before the reflection tree: no tree counters.
        let older = run("gpu-shoot", 3.0, &[("texels", 8244.0), ("shots", 20.0), ("shoot_seconds", 1.5)]);
        let table = table(&[gpu, solve, older]);
        let rows: Vec<Vec<&str>> = table.lines().skip(2).map(|l| l.trim_matches('|').split('|').map(str::trim).collect()).collect();
        assert_eq!(rows[0], ["box", "32", "gpu-shoot", "8,244", "17", "2.034", "1.953", "96%", "63", "1", "-", "-"]);
        assert_eq!(rows[1], ["box", "32", "hierarchical-solve", "35,510", "8", "80.29", "44.34", "55%", "-", "-", "1,302,193", "130,323,415"]);
        assert_eq!(rows[2], ["box", "32", "gpu-shoot", "8,244", "20", "1.500", "-", "-", "-", "-", "-", "-"]);
    }
}

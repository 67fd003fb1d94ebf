//! The knobs a sweep varies: their Makefile names, the stage flag each one
//! sets, which way is "stricter", and the grid of their values.
//!
//! A knob is named as in the Makefile (`EPS`, `SPP`, `GPU_TEXELS`, ...),
//! so `make sweep SWEEP_KNOB=EPS` reads like `make EPS=...`. Each is
//! declared once, in [`KNOBS`]: the stage it goes to, its flag, the
//! solvers it applies to, and how the strictest-run reference tightens it
//! beyond the strictest value swept.

use std::fmt;

/// A radiosity solver the sweep can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
pub enum Solver {
    /// `cluster` (unless `--no-clusters`) then `hierarchical-solve`.
    Hierarchical,
    /// `gpu-shoot` (progressive radiosity, wgpu).
    Gpu,
    /// `photon-trace` (paper 001: photons, kd-tree filter, exact direct
    /// light on a perceptually split mesh).
    Photon,
    /// `structured-sample` (paper 002: samples along isolux contours,
    /// shot and displayed by its own conical filter, no grid-gather).
    Structured,
}

impl Solver {
    /// Every solver, in the order the table lists them.
    pub const ALL: [Solver; 4] = [Solver::Hierarchical, Solver::Gpu, Solver::Photon, Solver::Structured];

    /// The name on the command line and in the table.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Hierarchical => "hierarchical",
            Solver::Gpu => "gpu",
            Solver::Photon => "photon",
            Solver::Structured => "structured",
        }
    }

    /// The solver of a command-line name.
    pub fn parse(name: &str) -> Option<Solver> {
        Solver::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The stage binary that solves.
    pub fn stage(self) -> &'static str {
        match self {
            Solver::Hierarchical => "hierarchical-solve",
            Solver::Gpu => "gpu-shoot",
            Solver::Photon => "photon-trace",
            Solver::Structured => "structured-sample",
        }
    }

    /// Gather modes that apply to this solver's solutions: the full gather
    /// resamples links, which gpu-shoot's and photon-trace's solutions do
    /// not have; structured-sample displays its samples itself.
    pub fn gathers(self) -> &'static [Gather] {
        match self {
            Solver::Hierarchical => &[Gather::Preview, Gather::Full],
            Solver::Gpu | Solver::Photon => &[Gather::Preview],
            Solver::Structured => &[Gather::Own],
        }
    }

    /// Whether the solver writes a per-element solution (which a closed
    /// form per element can measure).
    pub fn has_solution(self) -> bool {
        self != Solver::Structured
    }

    /// The grid a sweep of this solver runs when no knob of it is given:
    /// chosen so that a default `make sweep` of the Cornell box (hierarchical,
    /// preview and full gathers, 3 reps) takes a few minutes on 2 cores.
    /// EPS runs in half-decades from 1e-3 (about 2% relative RMSE on the
    /// Cornell box with the full gather) to 1e-5, just past the Makefile's
    /// default (1.5e-5); MIN_AREA stays at its default (1e-4). GPU_CONVERGENCE
    /// spans 80% to 99.9% of the power shot at the Makefile's 32768 texels.
    /// PHOTON_TARGET_ERROR halves the photon estimate's relative error per
    /// step (four times the photons); STRUCTURED_LEVELS doubles the isolux
    /// bands (and so the samples along them) per step.
    pub fn default_knobs(self) -> Vec<(&'static Knob, Vec<f64>)> {
        let named = |name: &str| knob(name).unwrap_or_else(|| panic!("{name} is a knob"));
        match self {
            Solver::Hierarchical => vec![(named("EPS"), vec![1e-3, 3e-4, 1e-4, 3e-5, 1e-5])],
            Solver::Gpu => vec![(named("GPU_CONVERGENCE"), vec![0.8, 0.9, 0.99, 0.999])],
            Solver::Photon => vec![(named("PHOTON_TARGET_ERROR"), vec![0.2, 0.1, 0.05, 0.025])],
            Solver::Structured => vec![(named("STRUCTURED_LEVELS"), vec![2.0, 4.0, 8.0, 16.0])],
        }
    }
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A mode of `grid-gather`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
pub enum Gather {
    /// `--mode preview`: interpolates the solution.
    Preview,
    /// `--mode full`: paper 000's final gather over the solution's links.
    Full,
    /// No grid-gather: the solver's own display (structured-sample's
    /// conical filter), timed with the solve.
    Own,
}

impl Gather {
    /// Every mode.
    pub const ALL: [Gather; 3] = [Gather::Preview, Gather::Full, Gather::Own];

    /// The name on the command line, in the table, and grid-gather's `--mode`.
    pub fn name(self) -> &'static str {
        match self {
            Gather::Preview => "preview",
            Gather::Full => "full",
            Gather::Own => "own",
        }
    }

    /// The mode of a command-line name.
    pub fn parse(name: &str) -> Option<Gather> {
        Gather::ALL.into_iter().find(|g| g.name() == name)
    }
}

impl fmt::Display for Gather {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The stage a knob is a flag of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// The solver's own stage (hierarchical-solve or gpu-shoot).
    Solve,
    /// grid-gather, whatever the solver.
    Gather,
}

/// How the strictest-run reference goes beyond the strictest swept value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tighten {
    /// Smaller is stricter; the reference divides by this factor.
    Divide(f64),
    /// Larger is stricter; the reference multiplies by this factor.
    Multiply(f64),
    /// A fraction that is stricter nearer 1 (a convergence target): the
    /// reference divides what is left, `1 - v`, by this factor.
    Remaining(f64),
    /// Smaller is stricter, an integer >= 0: the reference takes one less.
    Decrement,
}

/// One knob: a Makefile variable that is a stage flag.
#[derive(Debug)]
pub struct Knob {
    /// The Makefile's name, e.g. `EPS`.
    pub name: &'static str,
    /// Which stage takes it.
    pub target: Target,
    /// The stage's flag, e.g. `--eps`.
    pub flag: &'static str,
    /// The solvers it applies to (gather knobs apply to every solver).
    pub solvers: &'static [Solver],
    /// Whether the stage takes an integer.
    pub integer: bool,
    /// Which way is stricter, and by how much the reference goes further.
    pub tighten: Tighten,
    /// What it means, for `--help` and the errors.
    pub meaning: &'static str,
}

/// Every knob a sweep can vary, each declared once.
pub const KNOBS: &[Knob] = &[
    Knob { name: "EPS", target: Target::Solve, flag: "--eps", solvers: &[Solver::Hierarchical], integer: false, tighten: Tighten::Divide(4.0), meaning: "refinement threshold" },
    Knob { name: "MIN_AREA", target: Target::Solve, flag: "--min-area", solvers: &[Solver::Hierarchical], integer: false, tighten: Tighten::Divide(4.0), meaning: "smallest element, fraction of the total area" },
    Knob { name: "VISIBILITY_RAYS", target: Target::Solve, flag: "--visibility-rays", solvers: &[Solver::Hierarchical], integer: true, tighten: Tighten::Multiply(4.0), meaning: "visibility rays per link" },
    Knob { name: "TOLERANCE", target: Target::Solve, flag: "--tolerance", solvers: &[Solver::Hierarchical], integer: false, tighten: Tighten::Divide(10.0), meaning: "gathering stops below this change" },
    Knob { name: "GPU_TEXELS", target: Target::Solve, flag: "--texels", solvers: &[Solver::Gpu], integer: false, tighten: Tighten::Multiply(4.0), meaning: "lightmap atlas size, texels" },
    Knob { name: "GPU_CONVERGENCE", target: Target::Solve, flag: "--convergence-target", solvers: &[Solver::Gpu], integer: false, tighten: Tighten::Remaining(10.0), meaning: "fraction of the power shot" },
    Knob { name: "GPU_RESOLUTION", target: Target::Solve, flag: "--resolution", solvers: &[Solver::Gpu], integer: true, tighten: Tighten::Multiply(2.0), meaning: "visibility map side, pixels" },
    Knob { name: "GPU_SHOOT_LEVEL", target: Target::Solve, flag: "--shoot-level", solvers: &[Solver::Gpu], integer: true, tighten: Tighten::Decrement, meaning: "shoot from 2^level x 2^level texels" },
    Knob { name: "PHOTON_TARGET_ERROR", target: Target::Solve, flag: "--target-error", solvers: &[Solver::Photon], integer: false, tighten: Tighten::Divide(2.0), meaning: "photons until every vertex's relative error is under this" },
    Knob { name: "STRUCTURED_LEVELS", target: Target::Solve, flag: "--levels", solvers: &[Solver::Structured], integer: true, tighten: Tighten::Multiply(2.0), meaning: "isolux bands per surface" },
    Knob { name: "SPP", target: Target::Gather, flag: "--spp", solvers: &[Solver::Hierarchical, Solver::Gpu, Solver::Photon], integer: true, tighten: Tighten::Multiply(4.0), meaning: "camera rays per pixel" },
    Knob { name: "LATTICE_SPACING", target: Target::Gather, flag: "--lattice-spacing", solvers: &[Solver::Hierarchical], integer: false, tighten: Tighten::Divide(2.0), meaning: "pixels between the full gather's lattice points" },
];

/// grid-gather's camera rays per pixel where SPP is not swept: the
/// Makefile's default, which the strictest-run reference multiplies by 4.
pub const DEFAULT_SPP: f64 = 4.0;

/// The knob named `name`.
pub fn knob(name: &str) -> Option<&'static Knob> {
    KNOBS.iter().find(|k| k.name == name)
}

impl Knob {
    /// Whether the knob applies to `solver`.
    pub fn applies_to(&self, solver: Solver) -> bool {
        self.solvers.contains(&solver)
    }

    /// The strictest of `values`.
    pub fn strictest(&self, values: &[f64]) -> f64 {
        let larger = matches!(self.tighten, Tighten::Multiply(_) | Tighten::Remaining(_));
        let fold = if larger { f64::max } else { f64::min };
        values.iter().copied().reduce(fold).expect("a knob has at least one value")
    }

    /// The reference's value: beyond the strictest of `values`.
    pub fn beyond(&self, values: &[f64]) -> f64 {
        let v = self.strictest(values);
        let beyond = match self.tighten {
            Tighten::Divide(k) => v / k,
            Tighten::Multiply(k) => v * k,
            Tighten::Remaining(k) => 1.0 - (1.0 - v) / k,
            Tighten::Decrement => (v - 1.0).max(0.0),
        };
        if self.integer {
            beyond.round()
        } else {
            beyond
        }
    }

    /// The value as the stage flag takes it: `--eps=0.001` (the `=` form,
    /// so a negative value reaches the stage's own check instead of being
    /// read as a flag).
    pub fn arg(&self, value: f64) -> String {
        format!("{}={}", self.flag, format_value(value, self.integer))
    }

    /// Parses one value: a finite number, an integer where the stage wants
    /// one. Ranges are left to the stage, which checks them itself.
    pub fn parse_value(&self, text: &str) -> Result<f64, String> {
        let value: f64 = text.trim().parse().map_err(|_| format!("{}: {text:?} is not a number", self.name))?;
        if !value.is_finite() {
            return Err(format!("{}: {text:?} is not finite", self.name));
        }
        if self.integer && value.fract() != 0.0 {
            return Err(format!("{}: {text:?} is not an integer", self.name));
        }
        Ok(value)
    }
}

/// A value as text: integers without a fraction, others as Rust's shortest
/// round-trip form (`0.001`, `1e-5`).
pub fn format_value(value: f64, integer: bool) -> String {
    if integer {
        format!("{}", value as i64)
    } else {
        format!("{value}")
    }
}

/// One point of a knob grid: a value for each swept knob, in the order
/// they were given.
pub type Setting = Vec<(&'static Knob, f64)>;

/// The cartesian product of the knobs' values, the first knob varying
/// slowest, values in the order given.
pub fn grid(knobs: &[(&'static Knob, Vec<f64>)]) -> Vec<Setting> {
    let mut settings: Vec<Setting> = vec![Vec::new()];
    for (knob, values) in knobs {
        settings = settings
            .into_iter()
            .flat_map(|s| {
                values.iter().map(move |&v| {
                    let mut s = s.clone();
                    s.push((*knob, v));
                    s
                })
            })
            .collect();
    }
    settings
}

/// A setting as a label: `EPS=0.001 SPP=16` (empty for no knob).
pub fn label(setting: &Setting) -> String {
    setting.iter().map(|(k, v)| format!("{}={}", k.name, format_value(*v, k.integer))).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_is_the_cartesian_product_first_knob_slowest() {
        let (eps, spp) = (knob("EPS").unwrap(), knob("SPP").unwrap());
        let g = grid(&[(eps, vec![1e-2, 1e-3]), (spp, vec![4.0, 16.0, 64.0])]);
        assert_eq!(g.len(), 6);
        assert_eq!(label(&g[0]), "EPS=0.01 SPP=4");
        assert_eq!(label(&g[2]), "EPS=0.01 SPP=64");
        assert_eq!(label(&g[5]), "EPS=0.001 SPP=64");
        assert_eq!(grid(&[]).len(), 1);
        assert!(grid(&[])[0].is_empty());
    }

    #[test]
    fn the_reference_goes_beyond_the_strictest_value() {
        let beyond = |name: &str, values: &[f64]| knob(name).unwrap().beyond(values);
        assert_eq!(beyond("EPS", &[1e-2, 1e-3]), 2.5e-4);
        assert_eq!(beyond("SPP", &[16.0, 4.0]), 64.0);
        assert!((beyond("GPU_CONVERGENCE", &[0.9, 0.99]) - 0.999).abs() < 1e-12);
        assert_eq!(beyond("GPU_SHOOT_LEVEL", &[3.0, 2.0]), 1.0);
        assert_eq!(beyond("GPU_SHOOT_LEVEL", &[0.0]), 0.0);
    }

    #[test]
    fn values_are_numbers_and_integers_where_the_stage_wants_them() {
        let (eps, spp) = (knob("EPS").unwrap(), knob("SPP").unwrap());
        assert_eq!(eps.parse_value("3e-4"), Ok(3e-4));
        assert!(eps.parse_value("fast").is_err());
        assert!(eps.parse_value("inf").is_err());
        assert!(spp.parse_value("4.5").is_err());
        assert_eq!(spp.arg(16.0), "--spp=16");
        assert_eq!(eps.arg(-1.0), "--eps=-1");
    }
}

//! The benchmark of paper 002's structured sampling against
//! hierarchical-solve (`make bench-structured`, the `bench-structured`
//! binary): its Tables 2 and 3 in shape.
//!
//! For one scene, it prepares the scene (mesh-prep), renders the reference,
//! runs `structured-sample` at its defaults (isolux levels
//! `--levels`) and the hierarchical pipeline (`cluster`,
//! `hierarchical-solve`, `grid-gather --mode preview`: the Gouraud display
//! paper 002 compares with) at each EPS of a grid, then measures every
//! image with `compare`: the percentage of measured pixels whose luminance
//! is more than tau off the reference's (paper 002 Sec. 4.1), for the
//! whole image and per surface, emitters and edge pixels left out. The
//! table ([`table`]) sets beside structured sampling the hierarchical runs
//! at the same speed, at the same quality, and per surface the one needing
//! the fewest element vertices for structured sampling's figure there
//! (paper 002's "fewer samples on B").
//!
//! The reference is, as in the sweep ([`crate::sweep`]): the `exact`
//! stage's image where it can render the scene (the simple environment);
//! else the `--reference` EXR (e.g. `make bench-peer`'s Mitsuba image);
//! else a converged hierarchical run: hierarchical-solve at a quarter of
//! the smallest EPS swept and grid-gather's full gather at 4x the SPP,
//! which the table names as not an independent truth.
//!
//! Times are each stage's reported `wall_time_s`, one run per setting.
//! structured-sample's report times its phases, so the light's transfer
//! from the sources (exact direct light at every sample: "LS -> A") and
//! between surfaces (shooting the secondary emitters and gathering their
//! light at the display samples of surfaces lit only by reflection: "A ->
//! B") are separate; hierarchical-solve refines, tests and gathers every
//! link in the same passes, so its times have no such split and the table
//! says "not split".

pub mod figures;
pub mod table;

use crate::sweep::knobs::{knob, Gather, Solver};
use crate::sweep::stages::Stages;
use crate::sweep::table::ReferenceKind;
use crate::sweep::{self, Measure};
use figures::SurfaceGroup;
use schemas::samples::Samples;
use schemas::solution::Solution;
use schemas::header::Schema;
use stage_kit::run::{bad_parameter, Run};
use schemas::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};
use table::{Bench, RunFigures, SurfaceFigures};

/// What the benchmark runs.
#[derive(Clone, Debug, Serialize)]
pub struct Config {
    /// The scene: `cornell`, a built-in scene name, or a `scene.ron` path.
    pub scene: String,
    /// The surfaces reported on, as (name, object names); empty: every
    /// object with a non-emitting triangle, each its own surface.
    pub surfaces: Vec<(String, Vec<String>)>,
    /// hierarchical-solve's EPS values.
    pub eps: Vec<f64>,
    /// structured-sample's isolux levels.
    pub levels: usize,
    /// A foreign EXR reference.
    pub reference: Option<PathBuf>,
    /// The tolerances measured.
    pub taus: Vec<f64>,
    /// The tolerances quality is compared at (each one of `taus`).
    pub quality_taus: Vec<f64>,
    /// Whether the hierarchical solver runs with the cluster hierarchy.
    pub clusters: bool,
    /// Image width (default: the scene camera's).
    pub width: Option<u32>,
    /// Image height.
    pub height: Option<u32>,
    /// Output directory.
    pub out: PathBuf,
}

impl Config {
    /// The sweep's configuration for the same runs: structured-sample at
    /// its levels and the hierarchical solver over the EPS grid, preview
    /// gather, one repetition.
    fn sweep(&self) -> sweep::Config {
        let named = |name: &str| knob(name).unwrap_or_else(|| panic!("{name} is a knob"));
        sweep::Config {
            scene: self.scene.clone(),
            solvers: vec![Solver::Structured, Solver::Hierarchical],
            gathers: Some(vec![Gather::Preview]),
            knobs: vec![(named("STRUCTURED_LEVELS"), vec![self.levels as f64]), (named("EPS"), self.eps.clone())],
            reps: 1,
            reference: self.reference.clone(),
            clusters: self.clusters,
            width: self.width,
            height: self.height,
            out: self.out.clone(),
        }
    }
}

/// Runs the benchmark; `progress` gets one line per run.
pub fn run(config: &Config, stages: &Stages, progress: &mut dyn FnMut(&str)) -> Result<Bench> {
    if let Some(tau) = config.quality_taus.iter().find(|t| !config.taus.contains(t)) {
        return Err(bad_parameter(format!("--quality-tau {tau}: not one of the --tau values")));
    }
    if config.eps.is_empty() || config.quality_taus.is_empty() {
        return Err(bad_parameter(if config.eps.is_empty() { "--eps: no value" } else { "--quality-tau: no value" }));
    }
    let sweep_config = config.sweep();
    let plans = sweep::plan(&sweep_config)?;
    sweep::check_flags(stages, &sweep_config, &plans)?;
    if let Some(reference) = &config.reference {
        if !reference.is_file() {
            return Err(bad_parameter(format!("--reference {}: no such file", reference.display())));
        }
    }
    let out = &config.out;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let mut record = Run::start("bench-structured", env!("CARGO_PKG_VERSION"));
    let (prepared, mesh, manifest, _) = sweep::prepare(stages, &sweep_config, &mut record, progress)?;
    let groups = figures::surface_groups(&mesh, &manifest, &config.surfaces).map_err(bad_parameter)?;

    let mut notes = Vec::new();
    let reference_dir = out.join("reference");
    std::fs::create_dir_all(&reference_dir).map_err(|e| Error::io(&reference_dir, e))?;
    // The converged run of the last resort is hierarchical-solve's full
    // gather, which the runs themselves do not sweep.
    let hierarchical = plans.iter().find(|p| p.solver == Solver::Hierarchical).expect("the plan has the hierarchical solver");
    let converged = sweep::Plan { gathers: vec![Gather::Preview, Gather::Full], ..hierarchical.clone() };
    let (mut reference, measure) = sweep::image_reference(stages, &sweep_config, &converged, &prepared, &reference_dir, &mut record, &mut notes, progress)?;
    if let (ReferenceKind::StrictestRun, Some(run)) = (reference.kind, &reference.run) {
        let knobs: Vec<String> = run.knobs.iter().map(|k| format!("{}={}", k.name, k.value)).collect();
        reference.label = format!("reference: hierarchical-solve converged run, {} gather, {} (no --reference EXR given; not an independent truth)", run.gather, knobs.join(" "));
    }
    let Measure::Image(reference_image, flags) = &measure else {
        return Err(bad_parameter(format!("--scene {}: its reference is a closed form per element, and structured-sample writes images", config.scene)));
    };
    progress(&reference.label);

    let taus = config.taus.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
    let mut runs = Vec::new();
    let total: usize = plans.iter().map(|p| p.settings.len()).sum();
    for plan in &plans {
        for setting in &plan.settings {
            let dir = out.join("runs").join(plan.solver.name()).join(sweep::setting_dir(setting));
            let output = sweep::run_pipeline(stages, &sweep_config, &prepared, plan.solver, setting, &plan.gathers, (1, 0), &dir)?;
            let (gather, gather_s, image) = &output.gathers[0];
            let mut args: Vec<String> = vec![image.display().to_string(), reference_image.display().to_string()];
            args.extend(flags.iter().map(|f| f.to_string()));
            args.extend(["--tau".into(), taus.clone(), "--manifest".into(), prepared.manifest.display().to_string()]);
            let compared = stages.run("compare", &args, &dir.join("compare.ron"))?;
            let counts = counts(plan.solver, &output.solution, &mesh, &groups)?;
            let surfaces = groups
                .iter()
                .zip(counts)
                .map(|(g, (samples, vertices, emitters))| {
                    let (pixels, over_tau) = figures::surface_over_tau(&compared.counters, &manifest.objects, g, &config.taus);
                    SurfaceFigures { name: g.name.clone(), pixels, over_tau, samples, vertices, emitters }
                })
                .collect();
            let mut stage_times = output.solve_stages.clone();
            if *gather != Gather::Own {
                stage_times.push(("grid-gather".into(), *gather_s));
            }
            let (phases, light_to_a_s, a_to_b_s) = figures::time_split(plan.solver, &stage_times, &output.solve_report);
            let figures = RunFigures {
                solver: plan.solver,
                setting: crate::sweep::knobs::label(setting),
                image: figures::image_over_tau(&compared.counters, &config.taus),
                surfaces,
                phases,
                light_to_a_s,
                a_to_b_s,
                total_s: stage_times.iter().map(|(_, t)| t).sum(),
                dir: dir.display().to_string(),
            };
            let over: Vec<String> = figures.image.iter().map(|o| format!("{:.2}% > {}", o.percent, table::percent_label(o.tau))).collect();
            progress(&format!("[{}/{total}] {} {}: {:.3} s, {}", runs.len() + 1, plan.solver, figures.setting, figures.total_s, over.join(", ")));
            runs.push(figures);
        }
    }
    notes.push("one run per setting; times are each stage's reported wall time on this machine, cluster and grid-gather included for hierarchical-solve".into());
    Ok(Bench {
        header: Bench::header(record.provenance(config)),
        scene: config.scene.clone(),
        reference: reference.label,
        taus: config.taus.clone(),
        comparisons: config.quality_taus.iter().map(|&tau| table::select(&runs, tau)).collect(),
        runs,
        notes,
    })
}

/// A surface's samples (or leaf elements), element vertices and secondary
/// emitters.
type Counts = (usize, Option<usize>, Option<usize>);

/// Per surface, its [`Counts`] from the solver's output file.
fn counts(solver: Solver, output: &Path, mesh: &schemas::mesh::Mesh, groups: &[SurfaceGroup]) -> Result<Vec<Counts>> {
    Ok(match solver {
        Solver::Structured => {
            let (samples, _) = Samples::read(output)?;
            figures::structured_counts(&samples, groups).into_iter().map(|(n, e)| (n, None, Some(e))).collect()
        }
        _ => {
            let (solution, _) = Solution::read(output)?;
            figures::hierarchical_counts(&solution, mesh, groups).into_iter().map(|(n, v)| (n, Some(v), None)).collect()
        }
    })
}

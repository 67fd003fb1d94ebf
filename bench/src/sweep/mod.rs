//! The sweep: error against time over a grid of knob values (`make
//! sweep`, the `sweep` binary).
//!
//! For one scene and one or more solvers, the sweep prepares the scene
//! once (mesh-prep), then for every point of the knob grid (the cartesian
//! product of the values given per knob) and every repetition runs the
//! release stage binaries as `make` would: `cluster` (unless
//! `--no-clusters`) and `hierarchical-solve`, or `gpu-shoot`; then
//! `grid-gather` in each gather mode; then `compare` against the
//! reference. Each stage's time is the `wall_time_s` of its report; a
//! point's total is the sum of its cluster, solve and gather times
//! (mesh-prep is shared by all points and listed once; compare is the
//! measurement, not part of the cost). Every figure of a point is the
//! median over its repetitions, with the range beside it.
//!
//! Repetition k seeds the solver's visibility rays with `1 + k` and the
//! gather's camera rays with `k` (rep 0 is the Makefile's defaults), so
//! the error range shows the Monte Carlo spread as well as the time range
//! showing the machine's noise.
//!
//! The reference is, in this order ([`table::ReferenceKind`]):
//! 1. the closed form, where the scene has one per element (the
//!    integrating sphere, recognised by its geometry: [`closed_form`]);
//!    errors are then the solutions' per input triangle, so both gather
//!    modes of a setting share the solve's error (the gather is run and
//!    timed all the same: it is part of the cost of a picture). compare
//!    cannot leave emitters out of a solution comparison, so the lamp's
//!    radiosity dominates the denominator; the table's notes give the
//!    factor by which the other triangles' own relative RMSE can exceed
//!    the figure (7.6x on sphere-300). A `--reference` given
//!    too is not used, and the notes say so;
//! 2. the exact image, where the `exact` stage can render the scene (no
//!    occluders, planar diffuse surfaces: paper 002's simple environment)
//!    with [`EXACT_BOUNCES`] bounces, every pixel within its stated bound
//!    of the truth; images are compared leaving out emitters and the
//!    pixels within 1 pixel of an edge (`exact` samples each pixel at its
//!    centre, the gathers average over it). Where `exact` refuses the
//!    scene, its one-line reason is in the notes. A `--reference` given too
//!    is not used;
//! 3. a foreign EXR given with `--reference`: each point's image is
//!    compared with it leaving out emitters and pixels within 2 pixels of
//!    an edge (`compare --exclude-emitters --exclude-edges 2`: another
//!    renderer's pixel filter and light sources differ there);
//! 4. otherwise a run at settings stricter than every point's (every
//!    swept knob beyond its strictest value, see [`knobs::Tighten`], and
//!    SPP 4x), with the most accurate gather swept (full where swept) and
//!    seeds no point uses: "reference: strictest run (not converged
//!    truth)". Images are then compared leaving out emitters and the
//!    pixels that mix surfaces (`compare --exclude-emitters
//!    --exclude-edges 0`): the emitters' exact, much brighter pixels
//!    would dominate the reference's RMS, and the pixels half on an
//!    emitter differ by tens of percent with where the camera rays fell
//!    (measured on the Cornell box at 64 x 64 pixels, EPS 1e-3, full
//!    gather: 0.68 relative RMSE with them, 0.06 without).
//!
//! The error is `compare`'s `relative_rmse`:
//! `sqrt(Σ w (a − b)² / Σ w b²)` over pixels (or triangles, weighted by
//! area) and channels. Against an image each point also has its worst
//! surface, the largest `|mean signed error|` of compare's objects (each
//! object's mean luminance against the reference's), summarised over the
//! runs like the error.

pub mod closed_form;
pub mod knobs;
pub mod pareto;
pub mod plot;
pub mod stages;
pub mod table;

use knobs::{Gather, Knob, Setting, Solver, Target};
use pareto::Spread;
use schemas::header::{Input, Schema};
use schemas::mesh::{Manifest, Mesh};
use schemas::report::Report;
use schemas::ron_io::read_bytes;
use stage_kit::run::{bad_parameter, read_prepared, Run};
use schemas::{Error, Result};
use serde::Serialize;
use stages::Stages;
use std::path::{Path, PathBuf};
use table::{KnobValue, Point, Reference, ReferenceKind, ReferenceRun, StageTime, Sweep};

/// Seeds of the strictest-run reference: offset far from every
/// repetition's, so its noise is independent of theirs.
pub const REFERENCE_SEED: u64 = 1_000_000;

/// What a sweep runs.
#[derive(Clone, Debug)]
pub struct Config {
    /// The scene: `cornell` (the Makefile's name for the built-in Cornell
    /// box), a built-in scene name, or a `scene.ron` path.
    pub scene: String,
    /// The solvers, each swept over its own grid.
    pub solvers: Vec<Solver>,
    /// Gather modes; `None`: every mode that applies to each solver.
    pub gathers: Option<Vec<Gather>>,
    /// The knobs given and their values; a solver none of them applies to
    /// sweeps its [`Solver::default_knobs`].
    pub knobs: Vec<(&'static Knob, Vec<f64>)>,
    /// Runs per point.
    pub reps: usize,
    /// A foreign EXR reference.
    pub reference: Option<PathBuf>,
    /// Whether the hierarchical solver runs with the cluster hierarchy.
    pub clusters: bool,
    /// Image size for grid-gather (default: the scene camera's).
    pub width: Option<u32>,
    /// Image height.
    pub height: Option<u32>,
    /// Output directory.
    pub out: PathBuf,
}

/// The configuration as the table's provenance records it.
#[derive(Serialize)]
struct Parameters {
    scene: String,
    solvers: Vec<String>,
    gathers: Option<Vec<String>>,
    knobs: Vec<(String, Vec<f64>)>,
    reps: usize,
    reference: Option<String>,
    clusters: bool,
    width: Option<u32>,
    height: Option<u32>,
}

impl Config {
    fn parameters(&self) -> Parameters {
        Parameters {
            scene: self.scene.clone(),
            solvers: self.solvers.iter().map(|s| s.name().to_string()).collect(),
            gathers: self.gathers.as_ref().map(|g| g.iter().map(|g| g.name().to_string()).collect()),
            knobs: self.knobs.iter().map(|(k, v)| (k.name.to_string(), v.clone())).collect(),
            reps: self.reps,
            reference: self.reference.as_ref().map(|p| p.display().to_string()),
            clusters: self.clusters,
            width: self.width,
            height: self.height,
        }
    }

    /// mesh-prep's arguments for the scene, as the Makefile maps `SCENE`.
    pub fn scene_args(&self) -> Vec<String> {
        if self.scene == "cornell" {
            vec!["--builtin".into(), "cornell-box".into()]
        } else if Path::new(&self.scene).exists() {
            vec![self.scene.clone()]
        } else {
            vec!["--builtin".into(), self.scene.clone()]
        }
    }
}

/// One solver's part of a sweep.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The solver.
    pub solver: Solver,
    /// Its gather modes.
    pub gathers: Vec<Gather>,
    /// Its knobs and their values.
    pub knobs: Vec<(&'static Knob, Vec<f64>)>,
    /// Its grid.
    pub settings: Vec<Setting>,
}

/// Each solver's knobs, grid and gathers; a one-line error naming the
/// option for a knob no solver has, or a gather a solver cannot do.
pub fn plan(config: &Config) -> Result<Vec<Plan>> {
    if config.solvers.is_empty() {
        return Err(bad_parameter("--solver: no solver given"));
    }
    if config.reps == 0 {
        return Err(bad_parameter("--reps: at least 1"));
    }
    for (knob, _) in &config.knobs {
        if !config.solvers.iter().any(|s| knob.applies_to(*s)) {
            let names: Vec<&str> = config.solvers.iter().map(|s| s.name()).collect();
            return Err(bad_parameter(format!("--knob {}: not a knob of {}", knob.name, names.join(" or "))));
        }
    }
    for (i, (knob, _)) in config.knobs.iter().enumerate() {
        if config.knobs[..i].iter().any(|(k, _)| k.name == knob.name) {
            return Err(bad_parameter(format!("--knob {}: given twice", knob.name)));
        }
    }
    let mut plans = Vec::new();
    for &solver in &config.solvers {
        let gathers = match &config.gathers {
            // structured-sample displays its own samples: no grid-gather mode applies.
            None | Some(_) if solver == Solver::Structured => solver.gathers().to_vec(),
            None => solver.gathers().to_vec(),
            Some(gathers) => {
                if let Some(g) = gathers.iter().find(|g| !solver.gathers().contains(g)) {
                    return Err(bad_parameter(format!("--gather {g}: {} writes no links for the full gather to resample; use preview", solver.stage())));
                }
                gathers.clone()
            }
        };
        if gathers.is_empty() {
            return Err(bad_parameter("--gather: no gather mode given"));
        }
        let given: Vec<_> = config.knobs.iter().filter(|(k, _)| k.applies_to(solver)).cloned().collect();
        let knobs = if given.is_empty() { solver.default_knobs() } else { given };
        let settings = knobs::grid(&knobs);
        plans.push(Plan { solver, gathers, knobs, settings });
    }
    Ok(plans)
}

/// The arguments a setting gives the solver's stage (the knob flags and,
/// for every solver that draws random rays, their seed; gpu-shoot draws
/// none).
fn solve_flags(solver: Solver, setting: &Setting, seed: u64) -> Vec<String> {
    let mut args: Vec<String> = setting.iter().filter(|(k, _)| k.target == Target::Solve).map(|(k, v)| k.arg(*v)).collect();
    if solver != Solver::Gpu {
        args.push(format!("--seed={seed}"));
    }
    args
}

/// The arguments a setting gives grid-gather: mode, SPP (the setting's,
/// else [`knobs::DEFAULT_SPP`]), seed, image size.
fn gather_flags(config: &Config, gather: Gather, setting: &Setting, seed: u64) -> Vec<String> {
    let mut args = vec![format!("--mode={}", gather.name())];
    args.extend(setting.iter().filter(|(k, _)| k.target == Target::Gather).map(|(k, v)| k.arg(*v)));
    if !setting.iter().any(|(k, _)| k.name == "SPP") {
        args.push(knobs::knob("SPP").expect("SPP is a knob").arg(knobs::DEFAULT_SPP));
    }
    args.push(format!("--seed={seed}"));
    args.extend(config.width.map(|w| format!("--width={w}")));
    args.extend(config.height.map(|h| format!("--height={h}")));
    args
}

fn s(path: &Path) -> String {
    path.display().to_string()
}

/// The prepared scene every run reads.
pub struct Prepared {
    /// mesh-prep's mesh.exr.
    pub mesh: PathBuf,
    /// mesh-prep's manifest.ron.
    pub manifest: PathBuf,
}

/// One run of a solver and its gathers: times per stage and the files.
pub struct RunOutput {
    /// (stage, seconds), pipeline order, gathers excluded.
    pub solve_stages: Vec<(String, f64)>,
    /// The solver's output (solution.exr, or structured-sample's samples.exr).
    pub solution: PathBuf,
    /// Per gather mode: seconds and image.
    pub gathers: Vec<(Gather, f64, PathBuf)>,
    /// The solver stage's report.
    pub solve_report: Report,
}

/// Runs the solver at `setting` and then each gather, in `dir`.
#[allow(clippy::too_many_arguments)]
pub fn run_pipeline(stages: &Stages, config: &Config, prepared: &Prepared, solver: Solver, setting: &Setting, gathers: &[Gather], seeds: (u64, u64), dir: &Path) -> Result<RunOutput> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let scene = ["--mesh".to_string(), s(&prepared.mesh), "--manifest".to_string(), s(&prepared.manifest)];
    let mut solve_stages = Vec::new();
    let clusters = (solver == Solver::Hierarchical && config.clusters).then(|| dir.join("clusters.exr"));
    if let Some(clusters) = &clusters {
        let mut args = scene.to_vec();
        args.extend(["-o".into(), s(clusters)]);
        let report = stages.run("cluster", &args, &dir.join("cluster.report.ron"))?;
        solve_stages.push(("cluster".to_string(), report.wall_time_s));
    }
    // structured-sample writes samples and its own image, not a solution.
    let solution = dir.join(if solver.has_solution() { "solution.exr" } else { "samples.exr" });
    let mut args = scene.to_vec();
    args.extend(["-o".into(), s(&solution)]);
    if let Some(clusters) = &clusters {
        args.extend(["--clusters".into(), s(clusters)]);
    }
    let own = dir.join(format!("{}.exr", Gather::Own.name()));
    if gathers.contains(&Gather::Own) {
        args.extend(["--image".into(), s(&own)]);
        args.extend(config.width.map(|w| format!("--width={w}")));
        args.extend(config.height.map(|h| format!("--height={h}")));
    }
    // gpu-shoot's lightmap, which its preview shows (README, gpu-shoot).
    let lightmap = (solver == Solver::Gpu).then(|| dir.join("lightmap.exr"));
    if let Some(lightmap) = &lightmap {
        args.extend(["--lightmap".into(), s(lightmap)]);
    }
    args.extend(solve_flags(solver, setting, seeds.0));
    let solve_report = stages.run(solver.stage(), &args, &dir.join("solve.report.ron"))?;
    solve_stages.push((solver.stage().to_string(), solve_report.wall_time_s));
    let mut images = Vec::new();
    for &gather in gathers {
        if gather == Gather::Own {
            // Displayed within the solve, whose time includes it.
            images.push((gather, 0.0, own.clone()));
            continue;
        }
        let image = dir.join(format!("{}.exr", gather.name()));
        let mut args = scene.to_vec();
        args.extend(["--solution".into(), s(&solution), "-o".into(), s(&image)]);
        if let Some(clusters) = &clusters {
            args.extend(["--clusters".into(), s(clusters)]);
        }
        if let Some(lightmap) = lightmap.as_ref().filter(|_| gather == Gather::Preview) {
            args.extend(["--lightmap".into(), s(lightmap)]);
        }
        args.extend(gather_flags(config, gather, setting, seeds.1));
        let report = stages.run("grid-gather", &args, &dir.join(format!("{}.report.ron", gather.name())))?;
        images.push((gather, report.wall_time_s, image));
    }
    Ok(RunOutput { solve_stages, solution, gathers: images, solve_report })
}

/// compare's `relative_rmse` of `a` against `b` and its worst surface
/// ([`worst_surface`]), its report in `report`.
fn error(stages: &Stages, a: &Path, b: &Path, flags: &[&str], report: &Path) -> Result<Errors> {
    let mut args = vec![s(a), s(b)];
    args.extend(flags.iter().map(|f| f.to_string()));
    let report_value = stages.run("compare", &args, report)?;
    let relative_rmse = report_value.counters.get("relative_rmse").copied().ok_or_else(|| Error::invalid(report, None, "no relative_rmse counter"))?;
    Ok(Errors { relative_rmse, worst_surface: worst_surface(&report_value) })
}

/// What a run's gather measured against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Errors {
    /// compare's `relative_rmse`.
    relative_rmse: f64,
    /// [`worst_surface`] of the same comparison.
    worst_surface: Option<f64>,
}

/// The largest `|object[..].mean_signed_error|` of a compare report: the
/// worst surface's mean luminance off the reference's, relative (the
/// issue's "every surface within 1%"). `None` where compare reports no
/// objects (solutions, and images without a surface layer).
fn worst_surface(report: &Report) -> Option<f64> {
    report
        .counters
        .iter()
        .filter(|(k, _)| k.starts_with("object[") && k.ends_with("].mean_signed_error"))
        .map(|(_, v)| v.abs())
        .reduce(f64::max)
}

/// How points are compared with the reference.
pub enum Measure {
    /// Solutions against the closed-form solution.
    Solution(PathBuf),
    /// Images against a reference image, with compare's flags.
    Image(PathBuf, Vec<&'static str>),
}

impl Measure {
    /// The errors of each gather of a run.
    fn errors(&self, stages: &Stages, run: &RunOutput, dir: &Path) -> Result<Vec<Errors>> {
        match self {
            Measure::Solution(reference) => {
                let e = error(stages, &run.solution, reference, &[], &dir.join("compare.ron"))?;
                Ok(vec![e; run.gathers.len()])
            }
            Measure::Image(reference, flags) => run
                .gathers
                .iter()
                .map(|(g, _, image)| error(stages, image, reference, flags, &dir.join(format!("compare-{}.ron", g.name()))))
                .collect(),
        }
    }
}

/// A setting's knob values as the table records them.
pub fn knob_values(setting: &Setting) -> Vec<KnobValue> {
    setting.iter().map(|(k, v)| KnobValue { name: k.name.to_string(), value: *v }).collect()
}

/// The directory name of a setting.
pub fn setting_dir(setting: &Setting) -> String {
    let label = knobs::label(setting);
    if label.is_empty() {
        "default".to_string()
    } else {
        label.replace(' ', "_")
    }
}

/// Checks every point's flags with the stages themselves before running.
pub fn check_flags(stages: &Stages, config: &Config, plans: &[Plan]) -> Result<()> {
    for plan in plans {
        for setting in &plan.settings {
            let named = |e: Error| bad_parameter(format!("--knob {}: {e}", knobs::label(setting)));
            stages.check(plan.solver.stage(), &solve_flags(plan.solver, setting, 1)).map_err(named)?;
            for &gather in plan.gathers.iter().filter(|g| **g != Gather::Own) {
                stages.check("grid-gather", &gather_flags(config, gather, setting, 0)).map_err(named)?;
            }
        }
    }
    Ok(())
}

/// Prepares the scene into the output directory (mesh-prep) and reads it
/// back as an input of `record`; returns the files, their content and
/// mesh-prep's report.
pub fn prepare(stages: &Stages, config: &Config, record: &mut Run, progress: &mut dyn FnMut(&str)) -> Result<(Prepared, Mesh, Manifest, Report)> {
    let out = &config.out;
    let prepared = Prepared { mesh: out.join("mesh.exr"), manifest: out.join("manifest.ron") };
    let mut args = config.scene_args();
    args.extend(["--mesh".into(), s(&prepared.mesh), "--manifest".into(), s(&prepared.manifest)]);
    let mesh_prep = stages.run("mesh-prep", &args, &out.join("mesh-prep.report.ron"))?;
    let (mesh, manifest) = read_prepared(record, &prepared.mesh, &prepared.manifest)?;
    progress(&format!("mesh-prep: {} triangles, {:.2} s", mesh.triangles.len(), mesh_prep.wall_time_s));
    Ok((prepared, mesh, manifest, mesh_prep))
}

/// Runs the sweep of `plans` (from [`plan`]); `progress` gets one line per run.
pub fn run(config: &Config, plans: &[Plan], stages: &Stages, progress: &mut dyn FnMut(&str)) -> Result<Sweep> {
    check_flags(stages, config, plans)?;
    if let Some(reference) = &config.reference {
        if !reference.is_file() {
            return Err(bad_parameter(format!("--reference {}: no such file", reference.display())));
        }
    }
    let out = &config.out;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let mut notes = Vec::new();
    let mut record = Run::start("sweep", env!("CARGO_PKG_VERSION"));

    // The scene, once.
    let (prepared, mesh, manifest, mesh_prep) = prepare(stages, config, &mut record, progress)?;

    // The reference.
    let reference_dir = out.join("reference");
    std::fs::create_dir_all(&reference_dir).map_err(|e| Error::io(&reference_dir, e))?;
    let (reference, measure) = match closed_form::integrating_sphere(&mesh, &manifest) {
        Ok(radiosity) => {
            let path = reference_dir.join("closed_form.exr");
            closed_form::solution(&mesh, &radiosity, record.provenance(&"closed form: integrating sphere")).write(&path)?;
            if let Some(given) = &config.reference {
                notes.push(format!("--reference {} not used: the scene has a closed form, which comes first", given.display()));
            }
            let label = "reference: closed form (integrating sphere, exact up to faceting)".to_string();
            notes.extend(emitter_share_note(&mesh, &manifest, &radiosity));
            (Reference { kind: ReferenceKind::ClosedForm, label, file: s(&path), run: None }, Measure::Solution(path))
        }
        Err(why) => {
            notes.push(format!("no closed form per element: {why}"));
            image_reference(stages, config, &plans[0], &prepared, &reference_dir, &mut record, &mut notes, progress)?
        }
    };
    if let (Measure::Solution(_), Some(plan)) = (&measure, plans.iter().find(|p| !p.solver.has_solution())) {
        return Err(bad_parameter(format!("--solver {}: the scene's closed form is per element, and {} writes images, not a solution", plan.solver, plan.solver.stage())));
    }
    match &reference.run {
        Some(run) => progress(&format!("{} in {:.2} s", reference.label, run.stages.iter().map(|s| s.seconds.median).sum::<f64>())),
        None => progress(&reference.label),
    }

    // The points, in a `runs` folder of this sweep's alone: a point left
    // there by an earlier sweep of other knobs would be read as one of
    // this sweep's (`make bench-peer` reads the best point's surfaces from
    // it).
    let runs = out.join("runs");
    if runs.exists() {
        std::fs::remove_dir_all(&runs).map_err(|e| Error::io(&runs, e))?;
    }
    let runs_total: usize = plans.iter().map(|p| p.settings.len() * config.reps).sum();
    let mut done = 0;
    let mut points = Vec::new();
    for plan in plans {
        for setting in &plan.settings {
            let point_dir = runs.join(plan.solver.name()).join(setting_dir(setting));
            let mut reps: Vec<RepFigures> = Vec::new();
            for rep in 0..config.reps {
                let dir = point_dir.join(format!("rep{rep}"));
                let seeds = (1 + rep as u64, rep as u64);
                let run = run_pipeline(stages, config, &prepared, plan.solver, setting, &plan.gathers, seeds, &dir)?;
                let errors = measure.errors(stages, &run, &dir)?;
                done += 1;
                let times: Vec<String> = run.solve_stages.iter().map(|(st, t)| format!("{st} {t:.3} s")).chain(run.gathers.iter().map(|(g, t, _)| format!("{g} {t:.3} s"))).collect();
                let errs: Vec<String> = plan
                    .gathers
                    .iter()
                    .zip(&errors)
                    .map(|(g, e)| match e.worst_surface {
                        Some(w) => format!("{g} {:.3e} (worst surface {:.2}%)", e.relative_rmse, 100.0 * w),
                        None => format!("{g} {:.3e}", e.relative_rmse),
                    })
                    .collect();
                progress(&format!(
                    "[{done}/{runs_total}] {} {} rep {}/{}: {}; error {}",
                    plan.solver,
                    knobs::label(setting),
                    rep + 1,
                    config.reps,
                    times.join(", "),
                    errs.join(", ")
                ));
                let gathers = run.gathers.iter().zip(&errors).map(|((_, t, _), e)| (*t, *e)).collect();
                reps.push(RepFigures { solve_stages: run.solve_stages, gathers });
            }
            points.extend(plan.gathers.iter().enumerate().map(|(g, &gather)| point(plan.solver, gather, g, setting, &reps, &point_dir)));
        }
    }
    let front = pareto::front(&points.iter().map(|p| (p.total_s.median, p.error.median)).collect::<Vec<_>>());
    for (p, on) in points.iter_mut().zip(front) {
        p.pareto = on;
    }

    let error_metric = match reference.kind {
        ReferenceKind::ClosedForm => "relative RMSE of the solution per input triangle, area-weighted (compare's relative_rmse; the closed form is per element, so the gather's own error is not in it)",
        ReferenceKind::Exact => "relative RMSE of the image (compare's relative_rmse, emitters and pixels within 1 of an edge left out)",
        ReferenceKind::ForeignExr => "relative RMSE of the image (compare's relative_rmse, emitters and pixels within 2 of an edge left out)",
        ReferenceKind::StrictestRun => "relative RMSE of the image (compare's relative_rmse, emitters and pixels that mix surfaces left out)",
    };
    Ok(Sweep {
        header: Sweep::header(record.provenance(&config.parameters())),
        scene: config.scene.clone(),
        triangles: mesh.triangles.len(),
        reference,
        error_metric: error_metric.to_string(),
        reps: config.reps,
        shared: vec![StageTime { stage: "mesh-prep".into(), seconds: Spread::of(&[mesh_prep.wall_time_s]) }],
        points,
        notes,
    })
}

/// A note when emitting triangles hold most of the closed form's
/// `Σ A B²`, the denominator of the relative RMSE of solutions (compare
/// has no emitter exclusion for solutions): the other triangles' own
/// relative RMSE is then up to `sqrt(1 / (1 - share))` times the figure
/// (equal to it where the emitters' error is nil).
fn emitter_share_note(mesh: &Mesh, manifest: &Manifest, radiosity: &[[f64; 3]]) -> Option<String> {
    let (mut emitting, mut all) = (0.0, 0.0);
    for (t, b) in mesh.triangles.iter().zip(radiosity) {
        let energy = f64::from(t.area) * b.iter().map(|x| x * x).sum::<f64>();
        all += energy;
        if manifest.materials[t.material as usize].emission.iter().any(|&e| e > 0.0) {
            emitting += energy;
        }
    }
    let share = emitting / all;
    (share > 0.5).then(|| {
        format!(
            "emitting triangles hold {:.1}% of the closed form's sum of A B^2, the relative RMSE's denominator: the other triangles' own relative RMSE is up to {:.1}x the figures (that much where the emitters' error is nil)",
            100.0 * share,
            (1.0 / (1.0 - share)).sqrt()
        )
    })
}

/// What one run of a setting measured.
struct RepFigures {
    /// (stage, seconds) of cluster and solve, in pipeline order.
    solve_stages: Vec<(String, f64)>,
    /// Per gather mode: its seconds and errors.
    gathers: Vec<(f64, Errors)>,
}

/// The point of gather mode `gather` (index `g`) of a setting, from its
/// runs: each stage's median and range, the total per run (cluster +
/// solve + gather) and the error, summarised the same way.
fn point(solver: Solver, gather: Gather, g: usize, setting: &Setting, reps: &[RepFigures], dir: &Path) -> Point {
    let spread = |f: &dyn Fn(&RepFigures) -> f64| Spread::of(&reps.iter().map(f).collect::<Vec<_>>());
    let mut stages: Vec<StageTime> = reps[0]
        .solve_stages
        .iter()
        .enumerate()
        .map(|(i, (name, _))| StageTime { stage: name.clone(), seconds: spread(&|r| r.solve_stages[i].1) })
        .collect();
    if gather != Gather::Own {
        stages.push(StageTime { stage: "grid-gather".into(), seconds: spread(&|r| r.gathers[g].0) });
    }
    // Rounded to the nanosecond the reports resolve, so sums print
    // without float noise.
    let total = |r: &RepFigures| ((r.solve_stages.iter().map(|(_, t)| t).sum::<f64>() + r.gathers[g].0) * 1e9).round() / 1e9;
    Point {
        solver,
        gather,
        knobs: knob_values(setting),
        stages,
        total_s: spread(&total),
        error: spread(&|r| r.gathers[g].1.relative_rmse),
        worst_surface: reps.iter().map(|r| r.gathers[g].1.worst_surface).collect::<Option<Vec<f64>>>().map(|w| Spread::of(&w)),
        pareto: false,
        runs: s(dir),
    }
}

/// Bounces `exact` renders for a sweep's reference: far more than a
/// closed two-plane system needs for the further bounces to fall under its
/// tolerance at reflectances up to 0.8 (0.8^20 = 1e-2 of the first).
pub const EXACT_BOUNCES: u32 = 20;

/// The exact image as the reference, if the `exact` stage renders the
/// scene; else its refusal, one line.
fn exact_reference(stages: &Stages, config: &Config, prepared: &Prepared, dir: &Path) -> std::result::Result<(Reference, Measure), String> {
    let image = dir.join("exact.exr");
    let mut args = vec!["--mesh".to_string(), s(&prepared.mesh), "--manifest".into(), s(&prepared.manifest), "-o".into(), s(&image)];
    args.push(format!("--bounces={EXACT_BOUNCES}"));
    args.extend(config.width.map(|w| format!("--width={w}")));
    args.extend(config.height.map(|h| format!("--height={h}")));
    stages.run("exact", &args, &dir.join("exact.report.ron")).map_err(|e| e.to_string())?;
    let label = format!("reference: exact image (paper 002, {EXACT_BOUNCES} bounces, within its stated bound)");
    Ok((Reference { kind: ReferenceKind::Exact, label, file: s(&image), run: None }, Measure::Image(image, vec!["--exclude-emitters", "--exclude-edges", "1"])))
}

/// The reference image of a scene without a closed form: the exact image
/// where the `exact` stage renders the scene, else [`other_reference`]
/// (with `plan`'s strictest run as the last resort). `notes` get why the
/// exact image is missing, or that a `--reference` given is not used.
#[allow(clippy::too_many_arguments)]
pub fn image_reference(
    stages: &Stages,
    config: &Config,
    plan: &Plan,
    prepared: &Prepared,
    dir: &Path,
    record: &mut Run,
    notes: &mut Vec<String>,
    progress: &mut dyn FnMut(&str),
) -> Result<(Reference, Measure)> {
    match exact_reference(stages, config, prepared, dir) {
        Ok(found) => {
            if let Some(given) = &config.reference {
                notes.push(format!("--reference {} not used: the scene has an exact image, which comes first", given.display()));
            }
            Ok(found)
        }
        Err(refused) => {
            notes.push(format!("no exact image: {refused}"));
            other_reference(stages, config, plan, prepared, dir, record, progress)
        }
    }
}

/// The reference of a scene with neither a closed form nor an exact image:
/// the `--reference` EXR, else the strictest run of `plan`.
#[allow(clippy::too_many_arguments)]
fn other_reference(
    stages: &Stages,
    config: &Config,
    plan: &Plan,
    prepared: &Prepared,
    dir: &Path,
    record: &mut Run,
    progress: &mut dyn FnMut(&str),
) -> Result<(Reference, Measure)> {
    Ok(match &config.reference {
        Some(path) => {
            record.input(Input::new(path, &read_bytes(path)?, None))?;
            let name = path.file_name().map_or_else(|| s(path), |n| n.to_string_lossy().into_owned());
            let label = format!("reference: {name} (foreign EXR)");
            let flags = vec!["--exclude-emitters", "--exclude-edges", "2"];
            (Reference { kind: ReferenceKind::ForeignExr, label, file: s(path), run: None }, Measure::Image(path.clone(), flags))
        }
        None => {
            let (reference, image) = strictest_run(stages, config, plan, prepared, dir, progress)?;
            (reference, Measure::Image(image, vec!["--exclude-emitters", "--exclude-edges", "0"]))
        }
    })
}

/// The strictest-run reference: the first solver's plan with every swept
/// knob beyond its strictest value and SPP 4x, in the most accurate
/// gather swept, with seeds no point uses. Returns the reference and its
/// image.
fn strictest_run(stages: &Stages, config: &Config, plan: &Plan, prepared: &Prepared, dir: &Path, progress: &mut dyn FnMut(&str)) -> Result<(Reference, PathBuf)> {
    let mut setting: Setting = plan.knobs.iter().map(|(k, values)| (*k, k.beyond(values))).collect();
    if !setting.iter().any(|(k, _)| k.name == "SPP") {
        let spp = knobs::knob("SPP").expect("SPP is a knob");
        setting.push((spp, spp.beyond(&[knobs::DEFAULT_SPP])));
    }
    let gather = if plan.gathers.contains(&Gather::Full) { Gather::Full } else { plan.gathers[0] };
    progress(&format!("reference: strictest run, {} {} {gather} ...", plan.solver, knobs::label(&setting)));
    let run = run_pipeline(stages, config, prepared, plan.solver, &setting, &[gather], (1 + REFERENCE_SEED, REFERENCE_SEED), dir)?;
    let mut times: Vec<StageTime> = run.solve_stages.iter().map(|(st, t)| StageTime { stage: st.clone(), seconds: Spread::of(&[*t]) }).collect();
    times.push(StageTime { stage: "grid-gather".into(), seconds: Spread::of(&[run.gathers[0].1]) });
    let image = run.gathers[0].2.clone();
    let reference = Reference {
        kind: ReferenceKind::StrictestRun,
        label: "reference: strictest run (not converged truth)".into(),
        file: s(&image),
        run: Some(ReferenceRun { solver: plan.solver, gather, knobs: knob_values(&setting), stages: times }),
    };
    Ok((reference, image))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worst surface is the largest per-object mean signed error in
    /// magnitude, whatever its sign; materials and the whole image do not
    /// count, and a report without objects has none.
    #[test]
    fn the_worst_surface_is_the_largest_object_mean_error_in_magnitude() {
        let report = |counters: &[(&str, f64)]| Report {
            header: Report::header(schemas::header::Provenance::in_memory("test")),
            wall_time_s: 0.0,
            counters: counters.iter().map(|&(k, v)| (k.to_string(), v)).collect(),
            skipped: Vec::new(),
            notes: Vec::new(),
        };
        let image = report(&[
            ("relative_rmse", 0.02),
            ("mean_signed_error", -0.05),
            ("material[white].mean_signed_error", 0.04),
            ("object[floor].mean_signed_error", 0.003),
            ("object[short_block].mean_signed_error", -0.0125),
            ("object[#7].mean_signed_error", 0.01),
            ("object[short_block].relative_rmse", 0.5),
        ]);
        assert_eq!(worst_surface(&image), Some(0.0125));
        assert_eq!(worst_surface(&report(&[("relative_rmse", 0.02), ("mean_signed_error", 0.01)])), None);
    }

    fn config(solvers: &[Solver], knobs: &[(&str, &[f64])], gathers: Option<Vec<Gather>>) -> Config {
        Config {
            scene: "cornell".into(),
            solvers: solvers.to_vec(),
            gathers,
            knobs: knobs.iter().map(|(n, v)| (knobs::knob(n).unwrap(), v.to_vec())).collect(),
            reps: 1,
            reference: None,
            clusters: true,
            width: None,
            height: None,
            out: PathBuf::from("out"),
        }
    }

    #[test]
    fn each_solver_sweeps_the_knobs_given_for_it_or_else_its_defaults() {
        let both = [Solver::Hierarchical, Solver::Gpu];
        let plans = plan(&config(&both, &[("EPS", &[1e-2, 1e-3]), ("SPP", &[4.0, 16.0])], None)).unwrap();
        assert_eq!(plans[0].settings.len(), 4, "EPS x SPP");
        assert_eq!(plans[0].gathers, [Gather::Preview, Gather::Full]);
        assert_eq!(plans[1].settings.len(), 2, "gpu: SPP only");
        assert_eq!(plans[1].gathers, [Gather::Preview], "gpu-shoot's solution has no links");
        let defaults = plan(&config(&both, &[], None)).unwrap();
        assert_eq!(knobs::label(&defaults[0].settings[0]), "EPS=0.001");
        assert_eq!(knobs::label(&defaults[1].settings[0]), "GPU_CONVERGENCE=0.8");
    }

    #[test]
    fn a_knob_or_gather_no_solver_can_take_is_refused_naming_the_option() {
        let message = |c: Config| plan(&c).unwrap_err().to_string();
        assert!(message(config(&[Solver::Hierarchical], &[("GPU_TEXELS", &[1e3])], None)).contains("--knob GPU_TEXELS"));
        assert!(message(config(&[Solver::Gpu], &[], Some(vec![Gather::Full]))).contains("--gather full"));
        assert!(message(config(&[Solver::Hierarchical], &[("EPS", &[1e-2]), ("EPS", &[1e-3])], None)).contains("given twice"));
    }

    #[test]
    fn the_strictest_settings_go_beyond_every_point() {
        let c = config(&[Solver::Hierarchical], &[("EPS", &[1e-2, 1e-3])], None);
        let setting: Setting = plan(&c).unwrap()[0].knobs.iter().map(|(k, v)| (*k, k.beyond(v))).collect();
        assert_eq!(knobs::label(&setting), "EPS=0.00025");
        assert_eq!(gather_flags(&c, Gather::Full, &setting, 7), ["--mode=full", "--spp=4", "--seed=7"]);
        assert_eq!(solve_flags(Solver::Hierarchical, &setting, 2), ["--eps=0.00025", "--seed=2"]);
    }
}

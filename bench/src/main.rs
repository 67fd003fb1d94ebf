//! # bench-solve: what hierarchical-solve costs, and how close its ray casting gets to the BVH's raw rate
//!
//! Prepares the built-in Cornell box in memory (no files), then runs
//! `hierarchical_solve::solve` `--runs` times at a fixed refinement of about
//! 10k leaf elements ([`EPS`], [`MIN_AREA`]). Right after each solve, in the
//! same run, it measures obvhs's raw traversal rate on the same triangles:
//! a `SceneRays` over the mesh, and `first_blocker` (the query the solver's
//! visibility uses) over random segments between points on random pairs of
//! triangles that face each other, as many as the solver cast (at least
//! `--min-raw-rays`). The segments come from a deterministic `Stream` and
//! are drawn once into a pool of at most [`POOL`] segments that the timed
//! loop cycles through, so their generation is not timed and their memory
//! stays bounded.
//!
//! How to read the table (stderr) and the RON report (stdout or `-o`):
//!
//! - `solve`, `refine`, `visibility`, `gather`: median seconds over the runs.
//!   `solve` is the wall time of the whole call (hierarchy, BVH build,
//!   refinement, visibility, gather, output tables); the three phases are the
//!   solver's own `Work` timers, so they need not add up to `solve`.
//! - `links`, `leaves`, `elements`, `rays`, `iterations`, ...: the work done.
//!   The solver is deterministic, so these are the same in every run (the
//!   bench says so if they are not).
//! - `solver visibility rays/s` = rays / visibility seconds. It includes what
//!   the solver does around each ray (stratified points, per-link streams,
//!   link bookkeeping), which is the point: it is compared with
//! - `raw first_blocker rays/s`, all threads (rayon, like the solver) and one
//!   thread. `solver / raw` is computed per run from the two rates measured
//!   in that run, then the median is taken; near 1 means visibility is bound
//!   by traversal, well below 1 means overhead around the rays dominates.
//!   The raw segments join uniformly random points of whole triangles, so
//!   they are longer and less coherent than the solver's element-to-element
//!   rays; a ratio somewhat above 1 is therefore possible.
//! - `peak memory`: VmHWM of the process (Linux) at the end, and right after
//!   the first solve, before the raw measurement allocated its pool; the
//!   latter is the solver's own peak (plus the prepared scene).
//!
//! Reproduce with `cargo build --release -p bench && target/release/bench-solve`
//! (the bench prints its exact command line). Timings are volatile; the work
//! counters are not.

use bench::{median, peak_memory_mib};
use clap::Parser;
use glam::DVec3;
use hierarchical_solve::{solve, Params, Work};
use radiometry::geometry::TriangleGeometry;
use stage_kit::scene::mesh_triangles;
use radiometry::rays::SceneRays;
use radiometry::sampling::{stratified_point, Stream};
use rayon::prelude::*;
use schemas::mesh::{Manifest, Mesh};
use stage_kit::run::{bad_parameter, check_writable, exit_code};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// BF threshold of the benchmark solve (fraction of the largest emitted
/// radiosity). With [`MIN_AREA`] it gives 10651 leaf elements (14186
/// elements, 53141 links) on the built-in Cornell box: "the Cornell box at
/// about 10k leaf elements". Chosen once by this search of leaf counts
/// (`bench-solve --runs 1 --eps E --min-area M`, 16 rays per link):
///
/// | eps \ min_area | 1e-4 | 3e-5 | 1e-5 | 3e-6 |
/// |---|---|---|---|---|
/// | 1e-3 | 2065 | 3082 | 4495 | 6262 |
/// | 3e-4 | 3934 | **10651** | 22549 | 39433 |
/// | 1e-4 | 4174 | 14119 | 45769 | 116518 |
///
/// Retune (and update this table) if the solver's oracle changes the
/// leaf count far from 10k; the bench reports the count it got.
pub const EPS: f64 = 3e-4;
/// Smallest element area of the benchmark solve (fraction of the scene's
/// total area); see [`EPS`].
pub const MIN_AREA: f64 = 3e-5;
/// Most distinct segments drawn for the raw traversal measurement (56 bytes
/// each); the timed loop cycles through them.
pub const POOL: usize = 1 << 20;
/// Seed of the raw measurement's segments.
const RAW_SEED: u64 = 0x5eed;

/// The built-in scene the bench solves.
const CORNELL: &str = "cornell-box";

/// Times hierarchical-solve on the built-in Cornell box at about 10k leaf
/// elements and compares its visibility ray rate with obvhs's raw traversal
/// rate on the same scene. Table on stderr, RON report on stdout (or -o).
#[derive(Parser, Debug)]
#[command(name = "bench-solve", version)]
struct Args {
    /// Solves to run; the report gives medians over them.
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Output: the RON report (default: stdout).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// BF threshold (overrides the bench's fixed value, for retuning).
    #[arg(long, default_value_t = EPS)]
    eps: f64,
    /// Smallest element area, fraction of the total (overrides the bench's fixed value).
    #[arg(long, default_value_t = MIN_AREA)]
    min_area: f64,
    /// Visibility rays per link.
    #[arg(long, default_value_t = Params::default().visibility_rays)]
    visibility_rays: usize,
    /// Raw traversal: at least this many segments per run (else as many as the solver cast).
    #[arg(long, default_value_t = 1_000_000)]
    min_raw_rays: u64,
}

/// The work of one solve (deterministic).
#[derive(Serialize, Clone, Debug, PartialEq)]
struct WorkCounts {
    passes: usize,
    links: usize,
    elements: usize,
    leaves: usize,
    form_factors: u64,
    rays: u64,
    iterations: usize,
}

impl From<&Work> for WorkCounts {
    fn from(w: &Work) -> Self {
        WorkCounts {
            passes: w.passes,
            links: w.links,
            elements: w.elements,
            leaves: w.leaves,
            form_factors: w.form_factors,
            rays: w.rays,
            iterations: w.iterations,
        }
    }
}

/// Timings of one run: the solve, then the raw traversal right after it.
#[derive(Serialize, Clone, Debug, Default)]
struct RunTimes {
    solve_seconds: f64,
    refine_seconds: f64,
    visibility_seconds: f64,
    gather_seconds: f64,
    solver_rays_per_second: f64,
    raw_rays_per_second: f64,
    raw_single_thread_rays_per_second: f64,
    solver_over_raw: f64,
}

/// The raw traversal measurement's setup.
#[derive(Serialize, Debug)]
struct RawSetup {
    /// Segments traced per run with all threads.
    segments: u64,
    /// Distinct segments (the pool cycled through).
    distinct_segments: usize,
    /// Segments traced per run on one thread (the pool once).
    single_thread_segments: usize,
    /// Fraction of the segments that are blocked.
    blocked_fraction: f64,
}

/// The bench's RON report.
#[derive(Serialize, Debug)]
struct BenchReport {
    bench: String,
    version: String,
    command_line: Vec<String>,
    scene: String,
    triangles: usize,
    params: Params,
    threads: usize,
    runs: usize,
    work: WorkCounts,
    /// Whether every run did the same work.
    deterministic: bool,
    median: RunTimes,
    raw: RawSetup,
    peak_memory_mib: Option<f64>,
    peak_memory_after_first_solve_mib: Option<f64>,
    per_run: Vec<RunTimes>,
}

/// A segment for the raw measurement: end points and their triangles.
#[derive(Clone, Copy)]
struct Segment {
    from: DVec3,
    to: DVec3,
    skip: [u32; 2],
}

/// The Cornell box as mesh-prep would write it, in memory.
fn cornell_box() -> schemas::Result<(Mesh, Manifest)> {
    mesh_prep::prepare_builtin(CORNELL, "bench")
}

/// `count` segments between uniform random points of two distinct
/// triangles in front of each other (as the solver's links are), from a
/// deterministic stream per segment.
fn segments(triangles: &[TriangleGeometry], count: usize) -> Vec<Segment> {
    let n = triangles.len() as u64;
    (0..count as u64)
        .into_par_iter()
        .map(|i| {
            let mut stream = Stream::new(RAW_SEED, i, 0);
            let pick = |s: &mut Stream| -> Segment {
                let a = ((s.next_f64() * n as f64) as u64).min(n - 1);
                let b = (a + 1 + ((s.next_f64() * (n - 1) as f64) as u64).min(n - 2)) % n;
                let (ta, tb) = (&triangles[a as usize], &triangles[b as usize]);
                let from = stratified_point(&ta.corners, 0, 1, s);
                let to = stratified_point(&tb.corners, 0, 1, s);
                Segment { from, to, skip: [a as u32, b as u32] }
            };
            let facing = |seg: &Segment| {
                let d = seg.to - seg.from;
                triangles[seg.skip[0] as usize].normal.dot(d) > 0.0 && triangles[seg.skip[1] as usize].normal.dot(-d) > 0.0
            };
            let mut seg = pick(&mut stream);
            for _ in 0..64 {
                if facing(&seg) {
                    break;
                }
                seg = pick(&mut stream);
            }
            seg
        })
        .collect()
}

/// Rays per second of `first_blocker` over `count` segments cycled from
/// `pool`, on all threads; and the number blocked.
fn raw_parallel(scene: &SceneRays, pool: &[Segment], count: u64) -> (f64, u64) {
    let started = Instant::now();
    let blocked = (0..count)
        .into_par_iter()
        .filter(|&i| {
            let s = &pool[(i % pool.len() as u64) as usize];
            scene.first_blocker(s.from, s.to, s.skip).is_some()
        })
        .count() as u64;
    (count as f64 / started.elapsed().as_secs_f64(), blocked)
}

/// Rays per second of `first_blocker` over `pool` on this thread.
fn raw_single(scene: &SceneRays, pool: &[Segment]) -> f64 {
    let started = Instant::now();
    let blocked = pool.iter().filter(|s| scene.first_blocker(s.from, s.to, s.skip).is_some()).count();
    std::hint::black_box(blocked);
    pool.len() as f64 / started.elapsed().as_secs_f64()
}


fn median_times(runs: &[RunTimes]) -> RunTimes {
    let m = |f: fn(&RunTimes) -> f64| median(runs.iter().map(f).collect());
    RunTimes {
        solve_seconds: m(|r| r.solve_seconds),
        refine_seconds: m(|r| r.refine_seconds),
        visibility_seconds: m(|r| r.visibility_seconds),
        gather_seconds: m(|r| r.gather_seconds),
        solver_rays_per_second: m(|r| r.solver_rays_per_second),
        raw_rays_per_second: m(|r| r.raw_rays_per_second),
        raw_single_thread_rays_per_second: m(|r| r.raw_single_thread_rays_per_second),
        solver_over_raw: m(|r| r.solver_over_raw),
    }
}

fn table(r: &BenchReport) -> String {
    let w = &r.work;
    let m = &r.median;
    let mib = |x: Option<f64>| x.map_or("n/a".to_string(), |x| format!("{x:.1} MiB"));
    let mut t = String::new();
    let mut row = |name: &str, value: String| t.push_str(&format!("  {name:<34} {value}\n"));
    row("scene", format!("{} ({} triangles)", r.scene, r.triangles));
    row("params", format!("eps {:e}, min_area {:e}, {} rays/link", r.params.eps, r.params.min_area, r.params.visibility_rays));
    row("threads / runs", format!("{} / {}", r.threads, r.runs));
    row("leaves / elements", format!("{} / {}", w.leaves, w.elements));
    row("links", w.links.to_string());
    row("visibility rays cast", w.rays.to_string());
    row("form factors", w.form_factors.to_string());
    row("passes / Jacobi iterations", format!("{} / {}", w.passes, w.iterations));
    row("deterministic across runs", r.deterministic.to_string());
    row("solve (median)", format!("{:.3} s", m.solve_seconds));
    row("  refine", format!("{:.3} s", m.refine_seconds));
    row("  visibility", format!("{:.3} s", m.visibility_seconds));
    row("  gather", format!("{:.3} s", m.gather_seconds));
    row("solver visibility rays/s", format!("{:.3} M", m.solver_rays_per_second * 1e-6));
    row("raw first_blocker rays/s, all thr.", format!("{:.3} M ({} segments)", m.raw_rays_per_second * 1e-6, r.raw.segments));
    row("raw first_blocker rays/s, 1 thread", format!("{:.3} M ({} segments)", m.raw_single_thread_rays_per_second * 1e-6, r.raw.single_thread_segments));
    row("solver / raw (all threads)", format!("{:.3}", m.solver_over_raw));
    row("raw segments blocked", format!("{:.1} %", 100.0 * r.raw.blocked_fraction));
    row("peak memory (VmHWM), end", mib(r.peak_memory_mib));
    row("peak memory after first solve", mib(r.peak_memory_after_first_solve_mib));
    t
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    if args.runs == 0 {
        return Err(bad_parameter("--runs must be at least 1"));
    }
    let params = Params { eps: args.eps, min_area: args.min_area, visibility_rays: args.visibility_rays, ..Params::default() };
    if let Some(problem) = params.problem() {
        return Err(bad_parameter(problem));
    }
    if let Some(path) = &args.output {
        check_writable(path)?;
    }
    let (mesh, manifest) = cornell_box()?;
    let triangles = mesh_triangles(&mesh);
    let scene_name = format!("builtin:{CORNELL}");
    let threads = rayon::current_num_threads();
    eprintln!("bench-solve: {} triangles, {threads} threads, {} runs", triangles.len(), args.runs);

    let scene = SceneRays::new(&triangles.iter().map(|t| t.corners).collect::<Vec<_>>());
    let mut pool: Vec<Segment> = Vec::new();
    let mut works: Vec<WorkCounts> = Vec::new();
    let mut times: Vec<RunTimes> = Vec::new();
    let mut peak_after_first_solve = None;
    let mut blocked_fraction = 0.0;
    let mut raw_count = 0;
    for k in 1..=args.runs {
        let started = Instant::now();
        let solved = solve(&mesh, &manifest, None, &params, &|_| {})
            .map_err(|message| schemas::Error::invalid(Path::new(&scene_name), None, message))?;
        let solve_seconds = started.elapsed().as_secs_f64();
        let w = solved.work;
        drop((solved.elements, solved.links));
        if k == 1 {
            peak_after_first_solve = peak_memory_mib();
            raw_count = w.rays.max(args.min_raw_rays);
            pool = segments(&triangles, (raw_count as usize).min(POOL));
        }
        let (raw, blocked) = raw_parallel(&scene, &pool, raw_count);
        blocked_fraction = blocked as f64 / raw_count as f64;
        let single = raw_single(&scene, &pool);
        let solver_rate = w.rays as f64 / w.visibility_seconds.max(1e-9);
        let t = RunTimes {
            solve_seconds,
            refine_seconds: w.refine_seconds,
            visibility_seconds: w.visibility_seconds,
            gather_seconds: w.gather_seconds,
            solver_rays_per_second: solver_rate,
            raw_rays_per_second: raw,
            raw_single_thread_rays_per_second: single,
            solver_over_raw: solver_rate / raw,
        };
        eprintln!(
            "  run {k}: solve {:.3} s (refine {:.3}, visibility {:.3}, gather {:.3}), {} leaves, solver {:.2} M rays/s, raw {:.2} M rays/s ({:.2} M on 1 thread), ratio {:.3}",
            t.solve_seconds,
            t.refine_seconds,
            t.visibility_seconds,
            t.gather_seconds,
            w.leaves,
            t.solver_rays_per_second * 1e-6,
            t.raw_rays_per_second * 1e-6,
            t.raw_single_thread_rays_per_second * 1e-6,
            t.solver_over_raw
        );
        works.push(WorkCounts::from(&w));
        times.push(t);
    }
    let deterministic = works.windows(2).all(|p| p[0] == p[1]);
    if !deterministic {
        eprintln!("bench-solve: warning: the runs did different work; the solver is meant to be deterministic");
    }
    let report = BenchReport {
        bench: "bench-solve".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        command_line: std::env::args().collect(),
        scene: scene_name,
        triangles: triangles.len(),
        params,
        threads,
        runs: args.runs,
        work: works[0].clone(),
        deterministic,
        median: median_times(&times),
        raw: RawSetup { segments: raw_count, distinct_segments: pool.len(), single_thread_segments: pool.len(), blocked_fraction },
        peak_memory_mib: peak_memory_mib(),
        peak_memory_after_first_solve_mib: peak_after_first_solve,
        per_run: times,
    };
    eprintln!("bench-solve (medians over {} runs):\n{}", report.runs, table(&report));
    eprintln!("reproduce: cargo build --release -p bench && {}", report.command_line.join(" "));
    match &args.output {
        Some(path) => schemas::ron_io::write_ron(path, &report)?,
        None => println!("{}", schemas::ron_io::to_ron_text(&report)),
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    exit_code("bench-solve", run(Args::parse()))
}

//! # photon-trace: paper 001's progressive hybrid solver
//!
//! "A progressive global illumination solution considering perceptual
//! factors" (paper 001, `shared/papers/001_*.txt`) in three stages, each
//! leaving a displayable solution:
//!
//! 1. **Stochastic** ([`tracing`]): photons from every emitter, bucketed
//!    into the vertices of the *photon mesh* ([`mesh`]: the input
//!    triangles split 1:4 to `initial_area`), every hit deposited, the
//!    estimates filtered over a kd-tree of the vertices with a radius that
//!    shrinks as each vertex's variance falls ([`filter`]), until
//!    `preview_photons`.
//! 2. **Deterministic direct light** ([`direct`]): Lambert's formula with
//!    ray-cast visibility for area lights, `I cos / r²` for goniometric
//!    ones, at every vertex of a *display mesh* that starts as the photon
//!    mesh and is split where linear interpolation misses the perceived
//!    brightness (Stevens' power law over direct plus the stage-1 indirect
//!    estimate, [`perceptual`]).
//! 3. **Stochastic indirect**: photons again, their first hits no longer
//!    deposited (the direct light is exact now), added to stage 1's
//!    indirect tally ([`tally`]: the deposits of photons that had bounced
//!    at least once), until every photon-mesh vertex's estimated relative
//!    error is under `target_error`, or `max_photons`, or `time_budget_s`.
//!
//! Indirect light stays on the photon mesh; the display mesh's vertices
//! get it by linear interpolation over the photon-mesh leaf they lie in.
//! This is the premise of the hybrid: the sharp features (shadow edges)
//! are in the direct light, which is exact at every display vertex, and
//! the indirect light is smooth, so the photons need not resolve them, and
//! each photon-mesh vertex keeps a hat area large enough to converge. It
//! also keeps every photon: stage 3 continues stage 1's indirect sums
//! (the paper "replaces the finished direct computations with additional
//! stochastic particle tracing"); a split would have changed the hat
//! functions those sums project onto.
//!
//! Radiosity at a vertex is `B = M + rho (E_direct + E_indirect)` (stage 1:
//! `M + rho E`), per channel; a leaf's radiosity in `solution.exr` is its
//! mean over its part open to the scene ([`exposure`]): the direct light's
//! by its edge midpoints (`mean_points`), the indirect light's the mean
//! of its linear interpolant, so grid-gather renders it as any solution.
//!
//! Reproducible: photons come in rounds of `batches_per_round` batches of
//! `batch_photons`; batch `i` of stage `s` draws from its own stream
//! `(seed, s, i)`; batches are traced in parallel and added in index
//! order; every stop test runs between rounds. So a run gives the same
//! bits at any thread count, unless it stops on `time_budget_s`.
//!
//! The binary writes the solutions of the way there ([`snapshot`]) and
//! reports the work and the error against time ([`report`]).

pub mod direct;
pub mod exposure;
pub mod filter;
pub mod mesh;
pub mod perceptual;
pub mod projection;
pub mod report;
pub mod snapshot;
pub mod tally;
pub mod tracing;

use direct::{AreaLight, DirectScene, Query};
use exposure::Exposure;
use filter::{Estimates, VertexTree};
use glam::DVec3;
use mesh::{Elements, PointKey, Vertices};
use projection::MassMatrix;
use radiometry::bounds::Aabb;
use radiometry::color::luminance;
use radiometry::geometry::TriangleGeometry;
use stage_kit::scene::{luminaires, mesh_triangles};
use radiometry::photometry::{DirectLight, Luminaire};
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;
use radiometry::subdivision::to_triangle_uv;
use rayon::prelude::*;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Element;
use std::collections::HashMap;
use std::time::Instant;
use tally::Tally;
use tracing::{Deposit, Emitters, Scene};

stage_kit::knobs! {
    /// The solver's parameters (the stage's `--params` file).
    pub struct Params {
        /// Seed of every photon and shadow ray.
        seed: u64 = 1, "", value;
        /// Photons per batch (the unit of the variance estimate).
        batch_photons: usize = 4096, "photons", value(at_least(1));
        /// Batches per round (traced in parallel; stop tests between rounds); the variance needs two.
        batches_per_round: usize = 16, "batches", value(at_least(2));
        /// Photons of stage 1 (every hit deposited), a whole number of rounds (rounded up).
        preview_photons: u64 = 65_536, "photons", value(at_least(1));
        /// Stage 3 stops once every vertex's estimated relative standard error of radiosity is under this (see `relative_floor`).
        target_error: f64 = 0.005, "", value(positive());
        /// Stage 3 stops once the indirect estimate holds this many photons (stage 1's included), whatever the error.
        max_photons: u64 = 1 << 26, "photons", value(at_least(1));
        /// Stage 3 stops after this many seconds of the whole run (makes the result depend on the machine).
        time_budget_s: Option<f64> = None, "s", optional(positive());
        /// A vertex's error is relative to its radiosity, or to this fraction of the scene's area-mean radiosity where that is larger (dark corners would otherwise never converge).
        relative_floor: f64 = 0.1, "fraction of mean radiosity", value(positive());
        /// Corners (and filter neighbours) whose normals differ by more than this are not one vertex (do not filter into each other).
        crease_angle_deg: f64 = 45.0, "degrees", value(0.0..=180.0);
        /// Largest filter radius; 0 turns filtering off.
        filter_radius: f64 = 0.2, "fraction of diagonal", value(at_least(0.0));
        /// Shadow rays per vertex and emitting triangle in the direct pass.
        visibility_rays: usize = 16, "rays", value(at_least(1));
        /// Split a leaf when the Stevens brightness at an edge midpoint departs from the mean of its edge's ends by more than this (brightness 1 = the adaptation luminance).
        brightness_threshold: f64 = 0.02, "brightness", value(positive());
        /// Exponent of Stevens' power law.
        stevens_exponent: f64 = 1.0 / 3.0, "", value(positive());
        /// Splitting passes at most (each splits every leaf over the threshold once).
        max_splits: u32 = 6, "passes", value;
        /// Smallest element area.
        min_area: f64 = 1e-4, "fraction of total area", value(positive());
        /// Before stage 1, elements are split 1:4 until none is larger than this, so photons have vertices to land on and the splitting criterion samples every surface.
        initial_area: f64 = 1e-2, "fraction of total area", value(positive());
        /// Bounces after which a photon is dropped.
        max_bounces: u32 = 1000, "bounces", value(at_least(1));
    }
}

/// The stage a solution comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Stage 1: photons, every hit.
    Stochastic,
    /// Stage 2 done: exact direct light plus the stage-1 indirect estimate.
    Direct,
    /// Stage 3: exact direct light plus photons' indirect light.
    Indirect,
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stage::Stochastic => "stochastic",
            Stage::Direct => "direct",
            Stage::Indirect => "indirect",
        })
    }
}

/// A displayable state of the solution.
pub struct Snapshot {
    /// Its stage.
    pub stage: Stage,
    /// Photons in the estimate (as [`Progress::photons`]).
    pub photons: u64,
    /// Seconds since the solve started (volatile).
    pub seconds: f64,
    /// Largest estimated relative error of a vertex's radiosity.
    pub max_error: f64,
    /// The elements with their radiosity.
    pub elements: Vec<Element>,
}

/// One point of the error-against-time curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Stage.
    pub stage: Stage,
    /// Photons in the estimate: of stage 1, or, in stage 3, of the
    /// indirect estimate (stage 1's included).
    pub photons: u64,
    /// Seconds since the solve started (volatile).
    pub seconds: f64,
    /// Largest estimated relative error of a vertex's radiosity.
    pub max_error: f64,
    /// Area-weighted mean over vertices of that error.
    pub mean_error: f64,
}

/// Work done.
#[derive(Clone, Debug, Default)]
pub struct Work {
    /// Photons of stage 1.
    pub stage1_photons: u64,
    /// Photons of stage 3.
    pub stage3_photons: u64,
    /// Photon rays cast.
    pub photon_rays: u64,
    /// Shadow rays of the direct pass.
    pub direct_rays: u64,
    /// Rays that tested the leaves' points for burial ([`exposure`]).
    pub exposure_rays: u64,
    /// Photons dropped at the bounce limit.
    pub capped_photons: u64,
    /// Leaves split by the perceptual criterion.
    pub splits: u64,
    /// Elements, leaves and vertices of the final mesh.
    pub elements: usize,
    /// Leaves.
    pub leaves: usize,
    /// Vertices.
    pub vertices: usize,
    /// Seconds to the end of stage 1's first round (first displayable
    /// solution), of stage 1, of stage 2, of stage 3 (volatile).
    pub first_image_s: f64,
    /// End of stage 1.
    pub stage1_s: f64,
    /// End of stage 2.
    pub direct_s: f64,
    /// End of stage 3.
    pub final_s: f64,
    /// Whether stage 3 reached the target error.
    pub converged: bool,
    /// Why stage 3 stopped.
    pub stopped_by: &'static str,
    /// The error against time, a point per round (power-of-two round
    /// numbers, and the last of each stage).
    pub curve: Vec<Progress>,
}

/// The result: the leaf mesh's radiosity as elements, and the work done.
pub struct Solved {
    /// Elements with radiosity.
    pub elements: Vec<Element>,
    /// Work done.
    pub work: Work,
}

/// What the caller hears while the solve runs.
pub struct Observer<'a> {
    /// Called after every round and at each stage's end.
    pub progress: &'a mut dyn FnMut(&Progress),
    /// Snapshot every this many photons of a stochastic stage (0: none),
    /// rounded to whole rounds.
    pub snapshot_every: u64,
    /// Called with each snapshot: at every `snapshot_every` photons, at the
    /// end of stage 1 and of stage 2. An error ends the solve.
    pub snapshot: &'a mut dyn FnMut(&Snapshot) -> Result<(), String>,
}

/// The scene, read-only, with what every stage derives from it.
struct Setup<'a> {
    mesh: &'a Mesh,
    manifest: &'a Manifest,
    geometry: Vec<TriangleGeometry>,
    rays: SceneRays,
    luminaires: Vec<Luminaire>,
    emitters: Emitters,
    area_lights: Vec<AreaLight>,
    total_area: f64,
    diagonal: f64,
}

impl Setup<'_> {
    /// Where rays start: past the rounding of their f32 origins.
    fn t_min(&self) -> f32 {
        (1e-6 * self.diagonal) as f32
    }
}

/// The leaf mesh in its current state, with everything per vertex.
struct State {
    elements: Elements,
    exposure: Exposure,
    vertices: Vertices,
    tree: VertexTree,
}

impl State {
    /// The state of `elements`, whose leaves created since `exposure` was
    /// measured are measured now.
    fn new(setup: &Setup, elements: Elements, mut exposure: Exposure, params: &Params, work: &mut Work) -> Self {
        work.exposure_rays += exposure.extend(&setup.geometry, &setup.rays, &elements, setup.t_min(), params.seed);
        let vertices = Vertices::new(setup.mesh, &setup.geometry, &elements, &exposure.open, params.crease_angle_deg.to_radians().cos());
        let tree = VertexTree::new(&vertices.position);
        State { elements, exposure, vertices, tree }
    }

    fn material<'a>(&self, setup: &Setup<'a>, v: usize) -> &'a schemas::mesh::Material {
        &setup.manifest.materials[self.vertices.material[v] as usize]
    }
}

/// Radiosity `M + rho E` per channel.
fn radiosity(m: &schemas::mesh::Material, e: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|c| m.emission[c] + m.diffuse[c] * e[c])
}

/// Solves the scene (module documentation). Errors are messages about the
/// scene (no emitter) or from the snapshot writer.
pub fn solve(mesh: &Mesh, manifest: &Manifest, params: &Params, observer: &mut Observer) -> Result<Solved, String> {
    let started = Instant::now();
    let geometry = mesh_triangles(mesh);
    let luminaires = luminaires(&manifest.goniometric_lights)?;
    let Some(emitters) = Emitters::new(mesh, manifest, &geometry, &luminaires) else {
        return Err("the scene has no emitter: no material emits and no goniometric light has flux; nothing to trace".into());
    };
    let corners: Vec<[DVec3; 3]> = geometry.iter().map(|g| g.corners).collect();
    let area_lights = mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|(t, tri)| geometry[*t].area > 0.0 && manifest.materials[tri.material as usize].emission.iter().any(|&m| m > 0.0))
        .map(|(t, tri)| AreaLight { triangle: t as u32, exitance: manifest.materials[tri.material as usize].emission })
        .collect();
    let scene = Aabb::around(corners.iter().flatten().copied());
    let setup = Setup {
        mesh,
        manifest,
        total_area: geometry.iter().map(|g| g.area).sum(),
        diagonal: (scene.max - scene.min).length(),
        rays: SceneRays::new(&corners),
        geometry,
        luminaires,
        emitters,
        area_lights,
    };
    let mut work = Work::default();
    let clock = || started.elapsed().as_secs_f64();

    // The photon mesh: the input triangles split to initial_area.
    let mut elements = Elements::new(mesh);
    let coarsest = params.initial_area * setup.total_area;
    let mut e = 0;
    while e < elements.elements.len() {
        if f64::from(elements.elements[e].area) > coarsest {
            elements.split(e);
        }
        e += 1;
    }
    let coarse = State::new(&setup, elements, Exposure::default(), params, &mut work);
    let mass = MassMatrix::new(&setup.geometry, &coarse.elements, &coarse.vertices, &coarse.exposure.open);

    // Stage 1: every hit.
    let mut all = Tally::new(&coarse.vertices.hat_area, params.batch_photons);
    let mut indirect = Tally::new(&coarse.vertices.hat_area, params.batch_photons);
    let no_direct = vec![[0.0; 3]; coarse.vertices.len()];
    let mut round = 0u64;
    loop {
        let batch = trace_round(&setup, &coarse, params, 1, round, Deposit::All, &mut work);
        for b in &batch {
            all.add(b, true, &mass);
            indirect.add(b, false, &mass);
        }
        round += 1;
        if round == 1 {
            work.first_image_s = clock();
        }
        let done = all.photons() >= params.preview_photons;
        let (mean, errors) = estimate(&setup, &coarse, &no_direct, &all, params);
        let p = progress(Stage::Stochastic, all.photons(), clock(), &coarse, &errors);
        report_round(&mut work, observer, &p, round, done);
        if snapshot_due(observer, params, round, done) || done {
            let e = interpolate(&coarse, &coarse, &filtered(&setup, &coarse, &mass, &mean, &errors, params));
            let elements = element_radiosity(&setup, &coarse, &vec![[0.0; 3]; e.len()], &e);
            (observer.snapshot)(&Snapshot { stage: Stage::Stochastic, photons: all.photons(), seconds: clock(), max_error: p.max_error, elements })?;
        }
        if done {
            break;
        }
    }
    work.stage1_photons = all.photons();
    work.stage1_s = clock();

    // Stage 2: direct light on a perceptually split mesh; the stage-1
    // indirect estimate (filtered) sets the adaptation.
    let direct_scene = DirectScene {
        geometry: &setup.geometry,
        rays: &setup.rays,
        area_lights: &setup.area_lights,
        luminaires: DirectLight { lights: &setup.luminaires, rays: &setup.rays },
        visibility_rays: params.visibility_rays,
        seed: params.seed,
    };
    let mut cache: HashMap<DirectKey, [f64; 3]> = HashMap::new();
    let coarse_direct = direct_at_vertices(&direct_scene, &coarse.vertices, &mut cache, &mut work);
    let (mean, errors) = estimate(&setup, &coarse, &coarse_direct, &indirect, params);
    let coarse_indirect = filtered(&setup, &coarse, &mass, &mean, &errors, params);
    let mut fine = State::new(&setup, coarse.elements.clone(), coarse.exposure.clone(), params, &mut work);
    let smallest = params.min_area * setup.total_area;
    for _ in 0..params.max_splits {
        let direct = direct_at_vertices(&direct_scene, &fine.vertices, &mut cache, &mut work);
        let corner_indirect = interpolate(&coarse, &fine, &coarse_indirect);
        let vertex_indirect = vertex_values(&fine, &corner_indirect);
        let luminance_of = |v: usize, e: [f64; 3], i: [f64; 3]| {
            perceptual::surface_luminance(radiosity(fine.material(&setup, v), [0, 1, 2].map(|c| e[c] + i[c])))
        };
        let luminance_at: Vec<f64> = (0..fine.vertices.len()).map(|v| luminance_of(v, direct[v], vertex_indirect[v])).collect();
        let adaptation = area_mean(&fine.vertices.hat_area, &luminance_at);
        let candidates: Vec<usize> =
            (0..fine.elements.elements.len()).filter(|&e| fine.elements.elements[e].is_leaf() && f64::from(fine.elements.elements[e].area) / 4.0 >= smallest).collect();
        // The direct light at the edge midpoints, the vertices a split
        // would make: a leaf is judged on how far their brightness departs
        // from its corners' interpolation ([`perceptual`]).
        cache_direct(&direct_scene, candidates.iter().flat_map(|&e| midpoints(&setup, &fine.elements, e)), &mut cache, &mut work);
        let to_split: Vec<usize> = candidates
            .into_iter()
            .filter(|&e| {
                let corners = fine.vertices.of_element[e].map(|v| v as usize);
                let ci = corner_indirect[e];
                let mid = |a: usize, b: usize| [0, 1, 2].map(|c| 0.5 * (ci[a][c] + ci[b][c]));
                let indirect_mid = [mid(0, 1), mid(1, 2), mid(2, 0)];
                let keys = midpoints(&setup, &fine.elements, e).map(|(key, _)| key);
                let l = corners.map(|v| luminance_at[v]);
                let mids = [0, 1, 2].map(|k| luminance_of(corners[0], cache[&keys[k]], indirect_mid[k]));
                perceptual::should_split(l, mids, adaptation, params.stevens_exponent, params.brightness_threshold)
            })
            .collect();
        if to_split.is_empty() {
            break;
        }
        let mut elements = fine.elements;
        for &e in &to_split {
            elements.split(e);
        }
        work.splits += to_split.len() as u64;
        fine = State::new(&setup, elements, fine.exposure, params, &mut work);
    }
    let leaf_direct = direct_means(&direct_scene, &setup, &fine, &mut cache, &mut work);
    let fine_radiosity = |indirect: &[[f64; 3]]| element_radiosity(&setup, &fine, &leaf_direct, &interpolate(&coarse, &fine, indirect));
    work.direct_s = clock();
    (observer.progress)(&Progress { stage: Stage::Direct, photons: 0, seconds: work.direct_s, max_error: f64::NAN, mean_error: f64::NAN });
    let elements = fine_radiosity(&coarse_indirect);
    (observer.snapshot)(&Snapshot { stage: Stage::Direct, photons: 0, seconds: work.direct_s, max_error: f64::NAN, elements })?;

    // Stage 3: indirect light only, added to the stage-1 indirect tally on
    // the photon mesh.
    let mut round = 0u64;
    let (mean, errors) = loop {
        let batch = trace_round(&setup, &coarse, params, 3, round, Deposit::Indirect, &mut work);
        for b in &batch {
            indirect.add(b, false, &mass);
        }
        round += 1;
        let (mean, errors) = estimate(&setup, &coarse, &coarse_direct, &indirect, params);
        let p = progress(Stage::Indirect, indirect.photons(), clock(), &coarse, &errors);
        let stop = if p.max_error <= params.target_error {
            Some("target_error")
        } else if indirect.photons() >= params.max_photons {
            Some("max_photons")
        } else if params.time_budget_s.is_some_and(|t| clock() >= t) {
            Some("time_budget_s")
        } else {
            None
        };
        report_round(&mut work, observer, &p, round, stop.is_some());
        if let Some(why) = stop {
            work.converged = why == "target_error";
            work.stopped_by = why;
            break (mean, errors);
        }
        if snapshot_due(observer, params, round, false) {
            let elements = fine_radiosity(&filtered(&setup, &coarse, &mass, &mean, &errors, params));
            (observer.snapshot)(&Snapshot { stage: Stage::Indirect, photons: indirect.photons(), seconds: clock(), max_error: p.max_error, elements })?;
        }
    };
    work.stage3_photons = indirect.photons() - work.stage1_photons;
    work.final_s = clock();
    let smoothed = filtered(&setup, &coarse, &mass, &mean, &errors, params);
    let elements = fine_radiosity(&smoothed);
    work.elements = elements.len();
    work.leaves = elements.iter().filter(|e| e.is_leaf()).count();
    work.vertices = fine.vertices.len();
    Ok(Solved { elements, work })
}

/// Per leaf of `fine` (whose elements extend `coarse`'s), the values at
/// its corners, interpolated linearly from `values` at the vertices of its
/// ancestor among `coarse`'s leaves (inner elements get zeros).
fn interpolate(coarse: &State, fine: &State, values: &[[f64; 3]]) -> Vec<[[f64; 3]; 3]> {
    let n = coarse.elements.elements.len();
    let els = &fine.elements.elements;
    (0..els.len())
        .map(|e| {
            if !els[e].is_leaf() {
                return [[0.0; 3]; 3];
            }
            let mut a = e;
            while a >= n {
                a = els[a].parent as usize;
            }
            let ca = coarse.elements.corners[a];
            let corner_values = coarse.vertices.of_element[a].map(|v| values[v as usize]);
            let (e1, e2) = ([ca[1][0] - ca[0][0], ca[1][1] - ca[0][1]], [ca[2][0] - ca[0][0], ca[2][1] - ca[0][1]]);
            let det = e1[0] * e2[1] - e1[1] * e2[0];
            fine.elements.corners[e].map(|uv| {
                let d = [uv[0] - ca[0][0], uv[1] - ca[0][1]];
                let (l1, l2) = ((d[0] * e2[1] - d[1] * e2[0]) / det, (e1[0] * d[1] - e1[1] * d[0]) / det);
                let l = [1.0 - l1 - l2, l1, l2];
                [0, 1, 2].map(|c| (0..3).map(|k| l[k] * corner_values[k][c]).sum())
            })
        })
        .collect()
}

/// Traces one round of `params.batches_per_round` batches of stage
/// `stage`, in parallel, returned in batch order.
fn trace_round(setup: &Setup, state: &State, params: &Params, stage: u64, round: u64, deposit: Deposit, work: &mut Work) -> Vec<tracing::Batch> {
    let scene = Scene {
        mesh: setup.mesh,
        manifest: setup.manifest,
        geometry: &setup.geometry,
        rays: &setup.rays,
        luminaires: &setup.luminaires,
        emitters: &setup.emitters,
        elements: &state.elements,
        vertices: &state.vertices,
        max_bounces: params.max_bounces,
        t_min: setup.t_min(),
    };
    let n = params.batches_per_round as u64;
    let batches: Vec<tracing::Batch> = (0..n)
        .into_par_iter()
        .map(|i| scene.trace(params.batch_photons, deposit, &mut Stream::new(params.seed, stage, round * n + i)))
        .collect();
    for b in &batches {
        work.photon_rays += b.rays;
        work.capped_photons += b.capped;
    }
    batches
}

/// Per vertex: the mean irradiance of `tally`, and the estimated relative
/// standard error of the radiosity it gives with `direct` added: the
/// irradiance's standard error times the reflectance the estimate's colour
/// sees, over the radiosity or `relative_floor` times the area-mean
/// radiosity, whichever is larger.
fn estimate(setup: &Setup, state: &State, direct: &[[f64; 3]], tally: &Tally, params: &Params) -> (Vec<[f64; 3]>, Vec<f64>) {
    let v = &state.vertices;
    let n = v.len();
    let mean: Vec<[f64; 3]> = (0..n).map(|i| tally.mean(i)).collect();
    let b: Vec<f64> = (0..n).map(|i| luminance(radiosity(state.material(setup, i), [0, 1, 2].map(|c| direct[i][c] + mean[i][c])))).collect();
    let floor = params.relative_floor * area_mean(&v.hat_area, &b);
    let errors = (0..n)
        .map(|i| {
            let rho = state.material(setup, i).diffuse;
            let e = luminance(mean[i]);
            let seen = if e > 0.0 { luminance([0, 1, 2].map(|c| rho[c] * mean[i][c])) / e } else { luminance(rho) };
            if seen <= 0.0 || v.hat_area[i] <= 0.0 {
                return 0.0;
            }
            seen * tally.standard_error(i) / b[i].max(floor).max(f64::MIN_POSITIVE)
        })
        .collect();
    (mean, errors)
}

/// The irradiance `mean` filtered with each vertex's radius from its error
/// ([`filter`]), then projected onto the hat functions of mass matrix
/// `mass` ([`projection`]).
fn filtered(setup: &Setup, state: &State, mass: &MassMatrix, mean: &[[f64; 3]], errors: &[f64], params: &Params) -> Vec<[f64; 3]> {
    let v = &state.vertices;
    let max_radius = params.filter_radius * setup.diagonal;
    let radius: Vec<f64> = (0..v.len()).map(|i| filter::radius(v.hat_area[i], errors[i], params.target_error, max_radius)).collect();
    let estimates = Estimates { position: &v.position, normal: &v.normal, hat_area: &v.hat_area, irradiance: mean, radius: &radius };
    mass.project(&filter::filter(&state.tree, &estimates, params.crease_angle_deg.to_radians().cos()))
}

/// The direct irradiance of every vertex, from `cache` where known.
fn direct_at_vertices(scene: &DirectScene, vertices: &Vertices, cache: &mut HashMap<DirectKey, [f64; 3]>, work: &mut Work) -> Vec<[f64; 3]> {
    let all: Vec<Query> = (0..vertices.len())
        .map(|v| Query { point: vertices.inside[v], normal: vertices.mean_normal[v], triangle: vertices.triangle[v], key: vertices.key[v] })
        .collect();
    let queries: Vec<Query> = all.iter().filter(|q| !cache.contains_key(&direct_key(q))).copied().collect();
    let (values, rays) = scene.at(&queries);
    work.direct_rays += rays;
    for (q, value) in queries.iter().zip(values) {
        cache.insert(direct_key(q), value);
    }
    all.iter().map(|q| cache[&direct_key(q)]).collect()
}

/// What a direct-light value is cached under: the point's identity and
/// the normal it was computed with (a vertex's mean normal changes when a
/// neighbouring leaf splits, and its value with it).
type DirectKey = ((PointKey, u32), [u64; 3]);

fn direct_key(q: &Query) -> DirectKey {
    (q.key, q.normal.to_array().map(f64::to_bits))
}

/// The midpoints of leaf `e`'s edges (01, 12, 20) as direct-light queries
/// with their identities: each moved a ten-thousandth of the way towards
/// the leaf's centroid, as vertices are ([`mesh::Vertices::inside`]).
fn midpoints(setup: &Setup, elements: &Elements, e: usize) -> [(DirectKey, Query); 3] {
    let t = elements.elements[e].triangle as usize;
    let g = &setup.geometry[t];
    let c = elements.corners[e];
    let centroid = g.point([(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0]);
    [(0, 1), (1, 2), (2, 0)].map(|(a, b)| query(setup, t, [0.5 * (c[a][0] + c[b][0]), 0.5 * (c[a][1] + c[b][1])], Some(centroid)))
}

/// The direct-light query at the point `uv` of mesh triangle `t`, with its
/// identity, moved a ten-thousandth of the way towards `towards` if given.
fn query(setup: &Setup, t: usize, uv: [f64; 2], towards: Option<DVec3>) -> (DirectKey, Query) {
    let g = &setup.geometry[t];
    let key = (mesh::point_key(setup.mesh, t, uv), t as u32);
    let p = g.point(uv);
    let query = Query { point: towards.map_or(p, |c| p + 1e-4 * (c - p)), normal: g.normal, triangle: t as u32, key };
    (direct_key(&query), query)
}

/// Caches the direct irradiance at `points` (those not cached yet).
fn cache_direct(scene: &DirectScene, points: impl Iterator<Item = (DirectKey, Query)>, cache: &mut HashMap<DirectKey, [f64; 3]>, work: &mut Work) {
    let mut queries = Vec::new();
    let mut queued = std::collections::HashSet::new();
    for (key, query) in points {
        if !cache.contains_key(&key) && queued.insert(key) {
            queries.push(query);
        }
    }
    let (values, rays) = scene.at(&queries);
    work.direct_rays += rays;
    for (q, value) in queries.iter().zip(values) {
        cache.insert(direct_key(q), value);
    }
}

/// Where a leaf's mean direct irradiance is taken: the edge midpoints of
/// a leaf open all over, the rule exact for a quadratic over a triangle;
/// the open burial points of one partly buried ([`exposure`]); none for
/// an inner or a wholly buried element. The mean of the corners is exact
/// for a linear function only, and direct light is not linear over a leaf
/// the brightness criterion kept whole: `1/r²` and the cosines bend it,
/// so on the Cornell box's tall block, whose faces the lamp lights at a
/// slant, the mean of the corners made the block 4% too bright against a
/// path-traced reference.
fn mean_points(setup: &Setup, state: &State, e: usize) -> Vec<(DirectKey, Query)> {
    let open = state.exposure.open[e];
    if !state.elements.elements[e].is_leaf() {
        Vec::new()
    } else if open == exposure::ALL_OPEN {
        midpoints(setup, &state.elements, e).to_vec()
    } else {
        let t = state.elements.elements[e].triangle as usize;
        exposure::open_points(open).map(|local| query(setup, t, to_triangle_uv(&state.elements.corners[e], local), None)).collect()
    }
}

/// Per element: a leaf's mean direct irradiance over its open part, the
/// mean at its [`mean_points`]; zeros for the others.
fn direct_means(scene: &DirectScene, setup: &Setup, state: &State, cache: &mut HashMap<DirectKey, [f64; 3]>, work: &mut Work) -> Vec<[f64; 3]> {
    let points: Vec<Vec<(DirectKey, Query)>> = (0..state.elements.elements.len()).map(|e| mean_points(setup, state, e)).collect();
    cache_direct(scene, points.iter().flatten().copied(), cache, work);
    points
        .iter()
        .map(|p| match p.len() {
            0 => [0.0; 3],
            n => [0, 1, 2].map(|c| p.iter().map(|(key, _)| cache[key][c]).sum::<f64>() / n as f64),
        })
        .collect()
}

/// Per vertex, the mean of the values its leaves' corners hold.
fn vertex_values(state: &State, per_corner: &[[[f64; 3]; 3]]) -> Vec<[f64; 3]> {
    let mut sum = vec![[0.0; 3]; state.vertices.len()];
    let mut count = vec![0u32; state.vertices.len()];
    for (e, corners) in state.vertices.of_element.iter().enumerate() {
        for k in 0..3 {
            if corners[k] != u32::MAX {
                let v = corners[k] as usize;
                for c in 0..3 {
                    sum[v][c] += per_corner[e][k][c];
                }
                count[v] += 1;
            }
        }
    }
    sum.into_iter().zip(count).map(|(s, n)| if n > 0 { s.map(|x| x / f64::from(n)) } else { s }).collect()
}

/// `sum A_v x_v / sum A_v`.
fn area_mean(area: &[f64], x: &[f64]) -> f64 {
    let total: f64 = area.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    area.iter().zip(x).map(|(a, x)| a * x).sum::<f64>() / total
}

fn progress(stage: Stage, photons: u64, seconds: f64, state: &State, errors: &[f64]) -> Progress {
    let max_error = errors.iter().copied().fold(0.0, f64::max);
    Progress { stage, photons, seconds, max_error, mean_error: area_mean(&state.vertices.hat_area, errors) }
}

fn report_round(work: &mut Work, observer: &mut Observer, p: &Progress, round: u64, last: bool) {
    (observer.progress)(p);
    if round.is_power_of_two() || last {
        work.curve.push(*p);
    }
}

fn snapshot_due(observer: &Observer, params: &Params, round: u64, last: bool) -> bool {
    if observer.snapshot_every == 0 || last {
        return false;
    }
    let per_round = (params.batches_per_round * params.batch_photons) as u64;
    let every = observer.snapshot_every.div_ceil(per_round).max(1);
    round.is_multiple_of(every)
}

/// The elements with radiosity and area of their open part
/// ([`exposure`]): a leaf's radiosity is `M + rho E` with `E` its mean
/// direct irradiance `direct` plus the mean of the indirect irradiance's
/// linear interpolant from `indirect` at its corners over its open burial
/// points (all open: the mean of the corners), an inner element's the
/// open-area-weighted mean of its children's.
fn element_radiosity(setup: &Setup, state: &State, direct: &[[f64; 3]], indirect: &[[[f64; 3]; 3]]) -> Vec<Element> {
    let mut elements = state.elements.elements.clone();
    let mut value = vec![[0.0f64; 3]; elements.len()];
    let mut area = vec![0.0f64; elements.len()];
    for (e, el) in elements.iter().enumerate() {
        let open = state.exposure.open[e];
        if el.is_leaf() && open != 0 {
            let m = &setup.manifest.materials[setup.mesh.triangles[el.triangle as usize].material as usize];
            let open_points: Vec<[f64; 3]> = exposure::open_points(open).collect();
            let interpolated = |c: usize| open_points.iter().map(|l| (0..3).map(|k| l[k] * indirect[e][k][c]).sum::<f64>()).sum::<f64>() / open_points.len() as f64;
            value[e] = radiosity(m, [0, 1, 2].map(|c| direct[e][c] + interpolated(c)));
            area[e] = state.elements.area(&setup.geometry, e) * exposure::fraction(open);
        }
    }
    for e in (0..elements.len()).rev() {
        if !elements[e].is_leaf() {
            let first = elements[e].first_child as usize;
            area[e] = (first..first + 4).map(|k| area[k]).sum();
            if area[e] > 0.0 {
                value[e] = [0, 1, 2].map(|c| (first..first + 4).map(|k| area[k] * value[k][c]).sum::<f64>() / area[e]);
            }
        }
    }
    for (el, (v, a)) in elements.iter_mut().zip(value.into_iter().zip(area)) {
        el.radiosity = v.map(|x| x as f32);
        el.area = a as f32;
    }
    elements
}

//! `hierarchical-solve`: see the library's documentation and `--help`.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use hierarchical_solve::transmission::Transmission;
use hierarchical_solve::{solve_with_surface, Criterion, Params, Phase};
use schemas::cluster::Clusters;
use schemas::header::Schema;
use schemas::mesh::Effects;
use schemas::solution::Solution;
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, read_surface, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

/// Hierarchical radiosity (Hanrahan, Salzman, Aupperle 1991) on a prepared
/// mesh: refinement of each link whose estimated error exceeds a fraction of
/// its receiver's radiosity (or, `--criterion absolute`, of the largest
/// emission), down to a minimum element area,
/// Lambert's closed-form form factors, ray-cast visibility per link, Jacobi
/// gather with push-pull. Writes solution.exr: the element hierarchy with
/// radiosity, and every link (form factor, visibility, unoccluded
/// irradiance, nearest occluder distance).
#[derive(Parser, Debug)]
#[command(name = "hierarchical-solve", version)]
struct Args {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Input: clusters.exr from cluster; without it every pair of input
    /// triangles starts linked (no clustering).
    #[arg(long)]
    clusters: Option<PathBuf>,
    /// Input: surface.exr from mesh-prep --surface: elements transport with
    /// their texture-averaged reflectance, and alpha masks cut surfaces.
    #[arg(long)]
    surface: Option<PathBuf>,
    /// Output: the solution (EXR tables of elements and links).
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// What a link's estimated error is compared with: `relative` (a fraction
    /// of its receiver's radiosity) or `absolute` (a fraction of the largest
    /// emitted radiosity).
    #[arg(long, value_enum)]
    criterion: Option<Criterion>,
    /// BF refinement threshold, as a fraction of the largest emitted radiosity
    /// (absolute criterion; the relative one's first pass).
    #[arg(long)]
    eps: Option<f64>,
    /// Relative criterion: a link's error as a fraction of its receiver's radiosity (default: eps x largest emission / (3 x mean reflected radiosity)).
    #[arg(long)]
    eps_relative: Option<f64>,
    /// Relative criterion: least receiver radiosity, as a fraction of the scene's area-mean reflected radiosity.
    #[arg(long)]
    relative_floor: Option<f64>,
    /// Relative criterion: least share of its receiver's radiosity a link's allowed error is computed from [default: 1/16].
    #[arg(long)]
    share_floor: Option<f64>,
    /// Smallest element area, as a fraction of the scene's total area.
    #[arg(long)]
    min_area: Option<f64>,
    /// How many 1:4 levels below min_area a shadow edge across a link between elements may split [default: 2].
    #[arg(long)]
    shadow_levels: Option<u32>,
    /// Visibility rays per link between two elements.
    #[arg(long)]
    visibility_rays: Option<usize>,
    /// Point pairs (and rays) per link with a cluster at an end.
    #[arg(long)]
    cluster_samples: Option<usize>,
    /// Deepest split of the adaptive receiver quadrature between touching elements.
    #[arg(long)]
    quadrature_depth: Option<u32>,
    /// Stop gathering when a bound of every leaf's remaining error is under this fraction of the largest radiosity.
    #[arg(long)]
    tolerance: Option<f64>,
    /// Jacobi iterations per solve, at most.
    #[arg(long)]
    max_iterations: Option<usize>,
    /// Refine-and-solve passes, at most.
    #[arg(long)]
    max_passes: Option<usize>,
    /// Seed of the visibility rays.
    #[arg(long)]
    seed: Option<u64>,
    /// Rays per coupling through a mirror or pane [default: 16].
    #[arg(long)]
    specular_rays: Option<usize>,
    /// Couplings through a mirror or pane whose rho_s F or tau_s F is under this are dropped [default: 1e-6].
    #[arg(long)]
    specular_min_factor: Option<f64>,
    /// Levels below each input triangle the senders through mirrors and panes are taken at [default: 2].
    #[arg(long)]
    specular_sender_level: Option<u32>,
    /// Most mirrors and panes along a path of light [default: 2].
    #[arg(long)]
    specular_depth: Option<u32>,
}

fn params_of(args: &Args) -> schemas::Result<Params> {
    let mut p: Params = load_params(args.stage.params.as_deref())?;
    p.criterion = args.criterion.unwrap_or(p.criterion);
    p.eps = args.eps.unwrap_or(p.eps);
    p.eps_relative = args.eps_relative.or(p.eps_relative);
    p.relative_floor = args.relative_floor.unwrap_or(p.relative_floor);
    p.share_floor = args.share_floor.unwrap_or(p.share_floor);
    p.min_area = args.min_area.unwrap_or(p.min_area);
    p.shadow_levels = args.shadow_levels.unwrap_or(p.shadow_levels);
    p.visibility_rays = args.visibility_rays.unwrap_or(p.visibility_rays);
    p.cluster_samples = args.cluster_samples.unwrap_or(p.cluster_samples);
    p.quadrature_depth = args.quadrature_depth.unwrap_or(p.quadrature_depth);
    p.tolerance = args.tolerance.unwrap_or(p.tolerance);
    p.max_iterations = args.max_iterations.unwrap_or(p.max_iterations);
    p.max_passes = args.max_passes.unwrap_or(p.max_passes);
    p.seed = args.seed.unwrap_or(p.seed);
    p.specular_rays = args.specular_rays.unwrap_or(p.specular_rays);
    p.specular_min_factor = args.specular_min_factor.unwrap_or(p.specular_min_factor);
    p.specular_sender_level = args.specular_sender_level.unwrap_or(p.specular_sender_level);
    p.specular_depth = args.specular_depth.unwrap_or(p.specular_depth);
    match p.problem() {
        Some(problem) => Err(bad_parameter(problem)),
        None => Ok(p),
    }
}

/// What this stage does not simulate, for the effects the scene has;
/// `surface`: whether surface.exr was given (textures, alpha masks and
/// normal maps are simulated from it); `one_sided`: triangles of
/// translucent materials that are not two-sided (they cannot transmit).
fn skipped(effects: &Effects, surface: bool, one_sided: usize) -> Vec<String> {
    let transmits = format!("diffuse transmission: {one_sided} triangles of translucent materials that are not two-sided transmit nothing (their back face has no elements; make the material two_sided)");
    Effects::skipped(&[
        (!effects.diffuse_interreflection, "interreflection passes: no surface both receives light and reflects it; direct light only"),
        (effects.specular_reflection, "specular reflection: planar mirrors by virtual senders, up to --specular-depth mirrors and panes per path (light meeting one more stops there), senders at their elements' mean radiosity --specular-sender-level levels down; no glossy reflection (a curved mirror is its facets), goniometric lights not mirrored"),
        (effects.specular_transmission, "specular transmission: thin panes by transmitted senders, in the chains of up to --specular-depth mirrors and panes per path; no refraction bending by thick glass (a pane is a thin plate: light goes straight through)"),
        (effects.diffuse_transmission && one_sided > 0, &transmits),
        (effects.textures && !surface, "textures: no --surface given; radiosity uses each material's diffuse reflectance"),
        (effects.alpha_masks && !surface, "alpha masks: no --surface given; surfaces are treated as opaque"),
        (effects.normal_maps && !surface, "normal maps: no --surface given; radiosity uses geometric normals"),
    ])
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let params = params_of(&args)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output)) = (&args.mesh, &args.manifest, &args.output) else {
        unreachable!("clap requires the inputs and output without --print-params")
    };
    check_outputs(&[args.mesh.as_deref(), args.manifest.as_deref(), args.clusters.as_deref(), args.surface.as_deref()], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start("hierarchical-solve", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    stage_kit::scene::luminaires(&manifest.goniometric_lights).map_err(|m| schemas::Error::invalid(manifest_path, None, m))?;
    let clusters = match &args.clusters {
        Some(path) => {
            let (clusters, input) = Clusters::read(path, mesh.triangles.len())?;
            run.input(input)?;
            Some(clusters)
        }
        None => None,
    };
    let surface = match &args.surface {
        Some(path) => {
            let (surface, input) = read_surface(path, mesh_path, &mesh, &manifest)?;
            run.input(input)?;
            Some(surface)
        }
        None => None,
    };
    let with_surface = surface.is_some();
    let clustered = clusters.is_some();
    let bar = progress(params.max_passes as u64, "passes");
    // Ticking, so a long phase shows it is alive.
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    let solved = solve_with_surface(&mesh, &manifest, clusters, surface, &params, &|p| {
        bar.set_position(p.pass as u64 - u64::from(p.phase != Phase::Done));
        bar.set_message(format!("pass {}: {} ({} links, {} elements)", p.pass, p.phase, p.links, p.elements));
    })
    .map_err(|message| schemas::Error::invalid(mesh_path, None, message))?;
    bar.finish_and_clear();
    let w = &solved.work;
    eprintln!(
        "hierarchical-solve: {} passes, {} links, {} elements ({} leaves), {} rays, {} iterations",
        w.passes, w.links, w.elements, w.leaves, w.rays, w.iterations
    );
    let mut notes = Vec::new();
    if !w.converged {
        let note = format!(
            "tolerance not reached: the last pass stopped at max_iterations = {} with a remaining-error bound of {:.3e} of the largest radiosity (tolerance {:.1e}, contraction {:.6}); raise --max-iterations",
            params.max_iterations, w.error_bound, params.tolerance, w.contraction
        );
        eprintln!("hierarchical-solve: warning: {note}");
        notes.push(note);
    }
    let solution = Solution {
        header: Solution::header(run.provenance(&params)),
        elements: solved.elements,
        clusters: solved.clusters,
        links: solved.links,
    };
    let mut outputs = Outputs::new();
    outputs.write(output, |p| solution.write(p))?;
    let one_sided = Transmission::new(&mesh, &manifest).map_or(0, |t| t.one_sided);
    let mut skipped = skipped(&manifest.effects, with_surface, one_sided);
    if !clustered && manifest.effects.fine_clustered_geometry {
        skipped.push("clustering: no --clusters given; every pair of input triangles starts linked".to_string());
    }
    for note in &skipped {
        eprintln!("hierarchical-solve: skipped: {note}");
    }
    if let Some(report) = &args.stage.report {
        let mut counters = BTreeMap::from([
            ("passes".to_string(), w.passes as f64),
            ("links".to_string(), w.links as f64),
            ("resolved_links".to_string(), w.resolved_links as f64),
            ("cluster_links".to_string(), w.cluster_links as f64),
            ("elements".to_string(), w.elements as f64),
            ("leaves".to_string(), w.leaves as f64),
            ("form_factors".to_string(), w.form_factors as f64),
            ("rays".to_string(), w.rays as f64),
            ("iterations".to_string(), w.iterations as f64),
            ("relative_change".to_string(), w.relative_change),
            ("converged".to_string(), f64::from(u8::from(w.converged))),
            ("capped_passes".to_string(), w.capped_passes as f64),
            ("extrapolations".to_string(), w.extrapolations as f64),
            ("refine_seconds".to_string(), w.refine_seconds),
            ("visibility_seconds".to_string(), w.visibility_seconds),
            ("gather_seconds".to_string(), w.gather_seconds),
            ("luminaires".to_string(), manifest.goniometric_lights.len() as f64),
            ("luminaire_rays".to_string(), w.luminaire_rays as f64),
            ("luminaire_seconds".to_string(), w.luminaire_seconds),
            ("visibility_rays_per_second".to_string(), w.rays as f64 / w.visibility_seconds.max(1e-9)),
        ]);
        // Only where the scene has mirrors or panes; the bound where finite.
        if manifest.effects.specular_reflection || manifest.effects.specular_transmission {
            counters.insert("specular_couplings".to_string(), w.specular_couplings as f64);
            counters.insert("specular_rays".to_string(), w.specular_rays as f64);
            counters.insert("specular_seconds".to_string(), w.specular_seconds);
            if w.specular_truncation.is_finite() {
                counters.insert("specular_truncation_bound".to_string(), w.specular_truncation);
            }
        }
        // Left out where unknown (no contraction below 1 was known).
        for (name, value) in [("error_bound", w.error_bound), ("contraction", w.contraction)] {
            if value.is_finite() {
                counters.insert(name.to_string(), value);
            }
        }
        outputs.write(report, |p| run.write_report(p, &params, counters, skipped, notes.clone()))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("hierarchical-solve", run)
}

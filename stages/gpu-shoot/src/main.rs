//! `gpu-shoot`: see the library's documentation and `--help`.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use gpu_shoot::{gpu, output, solve, Adaptive, Params, Visibility};
use schemas::header::Schema;
use schemas::lightmap::{Convergence, Lightmap};
use schemas::mesh::Effects;
use schemas::ron_io::write_ron;
use schemas::solution::Solution;
use stage_kit::run::{bad_parameter, load_params, print_params, progress, read_prepared, read_surface, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Progressive radiosity on the GPU (paper 004): per-triangle float
/// lightmaps, shooter selection by GPU reduction, hemicube or stereographic
/// visibility, disc-approximation form factors, ambient overshooting,
/// goniometric lights (the manifest's tables, from .ldt/.ies files). Writes the lightmap atlas (EXR), a
/// solution.exr that grid-gather previews, and a convergence record.
/// Runs on any Vulkan adapter, Mesa's lavapipe included.
#[derive(Parser, Debug)]
#[command(name = "gpu-shoot", version)]
struct Args {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Input: surface.exr from mesh-prep --surface (textures, alpha masks,
    /// normal maps), read only when the manifest says the scene has one of
    /// them; without it those effects are skipped.
    #[arg(long)]
    surface: Option<PathBuf>,
    /// Output: the solution (elements averaging the atlas; no links).
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Output: the lightmap atlas and its region table (EXR).
    #[arg(long)]
    lightmap: Option<PathBuf>,
    /// Output: the convergence log, shot by shot: unshot fraction and time (RON; timings are volatile).
    #[arg(long)]
    convergence_log: Option<PathBuf>,
    /// Output: a plot of the unshot fraction against time (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// Covered texels to aim for over the scene.
    #[arg(long)]
    texels: Option<f64>,
    /// Smallest side of a triangle's lightmap region, texels.
    #[arg(long)]
    min_size: Option<u32>,
    /// Largest side of a triangle's lightmap region, texels.
    #[arg(long)]
    max_size: Option<u32>,
    /// Substructuring: shoot from groups of 2^level x 2^level texels.
    #[arg(long)]
    shoot_level: Option<u32>,
    /// Visibility: hemicube or stereographic.
    #[arg(long, value_enum)]
    visibility: Option<Visibility>,
    /// Visibility map side, pixels.
    #[arg(long)]
    resolution: Option<u32>,
    /// Relative depth tolerance of the visibility test.
    #[arg(long)]
    tolerance: Option<f64>,
    /// Ambient overshooting (004 Eq. 4.9).
    #[arg(long, overrides_with = "no_overshoot")]
    overshoot: bool,
    /// No ambient overshooting.
    #[arg(long)]
    no_overshoot: bool,
    /// Stop when this fraction of the emitted power has been shot.
    #[arg(long)]
    convergence_target: Option<f64>,
    /// Stop after this many shots.
    #[arg(long)]
    max_shots: Option<usize>,
    /// Add rho x ambient to the solution: a display aid for an unconverged solution [default: off].
    #[arg(long, overrides_with = "no_ambient")]
    ambient: bool,
    /// Leave the ambient term out of the solution.
    #[arg(long)]
    no_ambient: bool,
    /// Texels per solution leaf, about.
    #[arg(long)]
    texels_per_leaf: Option<f64>,
    /// Adaptive subdivision at shadow boundaries (004 Sec. 2.4); not with --lightmap.
    /// Most mirrors and panes on a light path of the reflection tree (004
    /// Sec. 4.3.2).
    #[arg(long)]
    reflection_depth: Option<u32>,
    /// Cut a reflection-tree node whose power bound (Eq. 4.6) is under
    /// this fraction of the emitted power.
    #[arg(long)]
    reflection_threshold: Option<f64>,
    #[arg(long)]
    adaptive: bool,
    /// Adaptive subdivision: split a receiver whose visible fraction is at least this (b_l) [default: 0.05].
    #[arg(long)]
    adaptive_lower: Option<f64>,
    /// Adaptive subdivision: ... and at most this (b_u) [default: 0.95].
    #[arg(long)]
    adaptive_upper: Option<f64>,
    /// Adaptive subdivision: most 1:4 splits of an input triangle [default: 3].
    #[arg(long)]
    adaptive_levels: Option<u32>,
}

fn params_of(args: &Args) -> schemas::Result<Params> {
    let mut p: Params = load_params(args.stage.params.as_deref())?;
    p.texels = args.texels.unwrap_or(p.texels);
    p.shoot_level = args.shoot_level.unwrap_or(p.shoot_level);
    p.visibility = args.visibility.unwrap_or(p.visibility);
    p.resolution = args.resolution.unwrap_or(p.resolution);
    p.tolerance = args.tolerance.unwrap_or(p.tolerance);
    if args.overshoot {
        p.overshoot = true;
    }
    if args.no_overshoot {
        p.overshoot = false;
    }
    p.convergence_target = args.convergence_target.unwrap_or(p.convergence_target);
    p.max_shots = args.max_shots.unwrap_or(p.max_shots);
    p.min_size = args.min_size.unwrap_or(p.min_size);
    p.max_size = args.max_size.unwrap_or(p.max_size);
    if args.ambient {
        p.ambient = true;
    }
    if args.no_ambient {
        p.ambient = false;
    }
    p.texels_per_leaf = args.texels_per_leaf.unwrap_or(p.texels_per_leaf);
    p.reflection_depth = args.reflection_depth.unwrap_or(p.reflection_depth);
    p.reflection_threshold = args.reflection_threshold.unwrap_or(p.reflection_threshold);
    if args.adaptive || args.adaptive_lower.is_some() || args.adaptive_upper.is_some() || args.adaptive_levels.is_some() {
        let a = p.adaptive.get_or_insert_with(Adaptive::default);
        a.lower = args.adaptive_lower.unwrap_or(a.lower);
        a.upper = args.adaptive_upper.unwrap_or(a.upper);
        a.levels = args.adaptive_levels.unwrap_or(a.levels);
    }
    if p.adaptive.is_some() && args.lightmap.is_some() {
        return Err(bad_parameter("--lightmap is not written with adaptive subdivision: its regions would be the subdivided tiles', not the mesh's triangles"));
    }
    match p.problem() {
        Some(problem) => Err(bad_parameter(problem)),
        None => Ok(p),
    }
}

/// The effects of the scene gpu-shoot does not simulate; textures, alpha
/// masks and normal maps are simulated when `surface` (the artifact that
/// holds them) was given, diffuse transmission where its material is
/// two-sided (`one_sided` triangles are not).
fn skipped(effects: &Effects, surface: bool, one_sided: u64) -> Vec<String> {
    let without = !surface;
    let transmits = format!("diffuse transmission: {one_sided} triangles of translucent materials that are not two-sided transmit nothing (their back face has no texels; make the material two_sided)");
    Effects::skipped(&[
        (one_sided > 0, transmits.as_str()),
        (effects.specular_reflection, "specular reflection: planar mirrors by the reflection tree (004 Sec. 4.3.2), up to --reflection-depth windows per path, nodes under --reflection-threshold cut (their bound in reflection_truncated_fraction); no glossy reflection (a curved mirror is its facets), alpha masks opaque in the frustum maps"),
        (effects.specular_transmission, "specular transmission: thin panes in the reflection tree (004 Sec. 4.3.3); no refraction bending by thick glass"),
        (effects.alpha_masks && without, "alpha masks: surfaces are treated as opaque (no --surface given)"),
        (effects.normal_maps && without, "normal maps: texels use the geometric normal (no --surface given)"),
        (effects.textures && without, "textures: radiosity uses each material's diffuse reflectance (no --surface given)"),
        (effects.fine_clustered_geometry, "fine geometry: gpu-shoot does not cluster; every triangle keeps its own region (--adaptive splits receivers only at shadow boundaries)"),
    ])
}

/// An SVG plot of the unshot magnitude fraction (log scale) against time.
fn plot_svg(convergence: &Convergence) -> String {
    let (w, h, m) = (640.0, 400.0, 50.0);
    let t_max = convergence.shots.last().map(|s| s.seconds).unwrap_or(1.0).max(1e-9);
    let floor = convergence.shots.iter().map(|s| s.unshot_magnitude_fraction).fold(1.0f64, f64::min).max(1e-6);
    let decades = (-floor.log10()).ceil().max(1.0);
    let x = |t: f64| m + (w - 2.0 * m) * t / t_max;
    let y = |f: f64| m + (h - 2.0 * m) * (-f.max(1e-12).log10() / decades).min(1.0);
    let mut points = format!("{:.1},{:.1}", x(0.0), y(convergence.initial_unshot_fraction));
    for s in &convergence.shots {
        points += &format!(" {:.1},{:.1}", x(s.seconds), y(s.unshot_magnitude_fraction));
    }
    let mut svg = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n");
    svg += &format!("<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n");
    svg += &format!("<polyline fill=\"none\" stroke=\"black\" points=\"{m},{m} {m},{} {},{}\"/>\n", h - m, w - m, h - m);
    for d in 0..=decades as i32 {
        let yy = y(10f64.powi(-d));
        svg += &format!("<text x=\"4\" y=\"{:.1}\">1e-{d}</text><line x1=\"{m}\" x2=\"{}\" y1=\"{yy:.1}\" y2=\"{yy:.1}\" stroke=\"#ddd\"/>\n", yy + 4.0, w - m);
    }
    svg += &format!("<text x=\"{}\" y=\"{}\">{t_max:.3} s</text>\n", w - m - 30.0, h - m + 16.0);
    svg += &format!("<text x=\"{m}\" y=\"20\">unshot fraction (sum |dB| A / emitted) vs time, {} shots ({})</text>\n", convergence.shots.len(), convergence.adapter);
    svg += &format!("<polyline fill=\"none\" stroke=\"#c33\" stroke-width=\"1.5\" points=\"{points}\"/>\n</svg>\n");
    svg
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
    check_outputs(
        &[args.mesh.as_deref(), args.manifest.as_deref(), args.surface.as_deref()],
        &[Some(output), args.lightmap.as_deref(), args.convergence_log.as_deref(), args.plot.as_deref(), args.stage.report.as_deref()],
    )?;
    let mut run = Run::start("gpu-shoot", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let surface = match args.surface.as_ref().filter(|_| manifest.effects.surface_detail()) {
        Some(path) => {
            let (surface, input) = read_surface(path, mesh_path, &mesh, &manifest)?;
            run.input(input)?;
            Some(surface)
        }
        None => None,
    };
    let lights = stage_kit::scene::luminaires(&manifest.goniometric_lights).map_err(|m| schemas::Error::invalid(manifest_path, None, m))?;
    let (device, queue, info) = gpu::acquire().map_err(|m| schemas::Error::invalid(Path::new("gpu"), None, m))?;
    let adapter = gpu::describe(&info);
    let bar = progress(1000, "converged");
    let mut fired = 0usize;
    let solved = solve(&device, &queue, &mesh, &manifest, surface.as_ref(), &lights, &params, &mut |shot| {
        fired += 1;
        bar.set_position(((1.0 - shot.unshot_magnitude_fraction).clamp(0.0, 1.0) * 1000.0) as u64);
        bar.set_message(format!("{fired} shots"));
    })
    .map_err(|m| schemas::Error::invalid(mesh_path, None, m))?;
    bar.finish_and_clear();
    let final_unshot = solved.shots.last().map(|s| s.unshot_magnitude_fraction).unwrap_or(solved.initial_unshot);
    let final_net = solved.shots.last().map_or(solved.initial_unshot, |s| s.unshot_fraction);
    eprintln!(
        "gpu-shoot: {} shots, {} texels, unshot {:.4}, {:.3} s shooting on {adapter}",
        solved.work.shots,
        solved.atlas.texels.len(),
        final_unshot,
        solved.work.shoot_seconds
    );
    let provenance = run.provenance(&params);
    let lightmap = output::lightmap(&solved, &solved.tile_mesh(&mesh), Lightmap::header(provenance.clone()));
    let ambient = params.ambient.then_some(solved.ambient);
    let solution = output::solution(&lightmap, &mesh, &manifest, &solved.tiles, ambient, params.texels_per_leaf, Solution::header(provenance.clone()));
    let convergence = Convergence {
        header: Convergence::header(provenance),
        adapter: adapter.clone(),
        initial_unshot_fraction: solved.initial_unshot,
        setup_seconds: solved.work.setup_seconds,
        shots: solved.shots.clone(),
    };
    let mut outputs = Outputs::new();
    outputs.write(output, |p| solution.write(p))?;
    if let Some(path) = &args.lightmap {
        outputs.write(path, |p| lightmap.write(p))?;
    }
    if let Some(path) = &args.convergence_log {
        outputs.write(path, |p| write_ron(p, &convergence))?;
    }
    if let Some(path) = &args.plot {
        let svg = plot_svg(&convergence);
        outputs.write(path, |p| schemas::atomic::write_atomically(p, |w| std::io::Write::write_all(w, svg.as_bytes()).map_err(|e| schemas::Error::io(p, e))))?;
    }
    if let Some(report) = &args.stage.report {
        let w = &solved.work;
        let mut counters = BTreeMap::from([
            ("shots".to_string(), w.shots as f64),
            ("samples".to_string(), w.samples as f64),
            ("visibility_layers".to_string(), w.layers as f64),
            ("receiver_evaluations".to_string(), w.receiver_evaluations as f64),
            ("texels".to_string(), solved.atlas.texels.len() as f64),
            ("mask_texels".to_string(), w.mask_texels as f64),
            ("subdivision_texels_added".to_string(), w.elements_added as f64),
            ("subdivision_tiles_added".to_string(), w.tiles_added as f64),
            ("subdivision_seconds".to_string(), w.subdivision_seconds),
            ("unshot_fraction".to_string(), final_net),
            ("unshot_magnitude_fraction".to_string(), final_unshot),
            ("setup_seconds".to_string(), w.setup_seconds),
            ("shoot_seconds".to_string(), w.shoot_seconds),
            ("seconds_per_shot".to_string(), w.shoot_seconds / (w.shots.max(1) as f64)),
        ]);
        if manifest.effects.specular_reflection || manifest.effects.specular_transmission {
            let r = &w.reflection;
            let emitted: f64 = solved.emitted_power.iter().sum();
            counters.extend([
                ("reflection_nodes".to_string(), r.nodes as f64),
                ("reflection_depth".to_string(), r.depth as f64),
                ("reflection_layers".to_string(), r.layers as f64),
                ("reflection_bound_fraction".to_string(), r.bound / emitted),
                ("reflection_truncated_fraction".to_string(), r.truncated / emitted),
                ("reflection_seconds".to_string(), r.seconds),
            ]);
        }
        let mut notes = vec![format!("adapter: {adapter}")];
        if args.surface.is_some() && !manifest.effects.surface_detail() {
            notes.push("surface.exr not read: the scene has no texture, alpha mask or normal map".into());
        }
        outputs.write(report, |p| run.write_report(p, &params, counters, skipped(&manifest.effects, surface.is_some(), w.one_sided_translucent), notes))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    gpu::quiet_device_select_layer();
    main_of("gpu-shoot", run)
}

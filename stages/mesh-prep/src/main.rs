//! `mesh-prep`: see the library's documentation and `mesh-prep --help`.

use clap::Parser;
use mesh_prep::builtin::Builtin;
use mesh_prep::obj::Files;
use mesh_prep::{prepare, read_scene, Params, Recording};
use stage_kit::cli::{check_outputs, main_of};
use stage_kit::run::{load_params, print_params, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Prepare a scene for the radiosity pipeline: read scene.ron (OBJ/MTL
/// files, camera, lights, material overrides), or a built-in scene; weld,
/// clean and recentre the mesh; write mesh.exr and manifest.ron (materials,
/// camera, and the effects the scene calls for).
#[derive(Parser, Debug)]
#[command(name = "mesh-prep", version)]
struct Args {
    /// Scene file (scene.ron); omit it and give --builtin for a built-in scene.
    #[arg(required_unless_present_any = ["builtin", "print_params"])]
    scene: Option<PathBuf>,
    /// Use a built-in scene instead of a file: cornell-box, or sized
    /// (n like 10k, 100k, 1m): cornell-box-<n> (tessellated), plants-<n>,
    /// sphere-<n> (integrating sphere), box-<n> (closed box, rho 0.8);
    /// simple-environment (paper 002's one-bounce scene).
    #[arg(long, conflicts_with = "scene")]
    builtin: Option<Builtin>,
    /// Output: the mesh (EXR tables of vertices and triangles).
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Output: the manifest (RON: camera, materials, effects, statistics).
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output: the surface detail (EXR: corner texture coordinates and
    /// shading normals, tangents, the materials' textures decoded), for
    /// the stages that simulate textures, alpha masks and normal maps.
    #[arg(long, value_name = "SURFACE.exr")]
    surface: Option<PathBuf>,
    /// Output: a dependency file in make syntax: the mesh and manifest
    /// depend on every file this run read (scene, OBJ, MTL, textures,
    /// photometric files), for the Makefile to include.
    #[arg(long, value_name = "MESH.d")]
    depfile: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// Weld vertices closer than this times the scene's diagonal.
    #[arg(long)]
    weld_tolerance: Option<f64>,
    /// Drop triangles smaller than this times the squared diagonal.
    #[arg(long)]
    degenerate_area: Option<f64>,
    /// Flag the geometry as fine (for clustering) above this many triangles.
    #[arg(long)]
    fine_geometry_triangles: Option<usize>,
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let mut params: Params = load_params(args.stage.params.as_deref())?;
    params.weld_tolerance = args.weld_tolerance.unwrap_or(params.weld_tolerance);
    params.degenerate_area = args.degenerate_area.unwrap_or(params.degenerate_area);
    params.fine_geometry_triangles = args.fine_geometry_triangles.unwrap_or(params.fine_geometry_triangles);
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path)) = (args.mesh, args.manifest) else {
        unreachable!("clap requires --mesh and --manifest without --print-params")
    };
    let outputs = [Some(mesh_path.as_path()), Some(manifest_path.as_path()), args.surface.as_deref(), args.stage.report.as_deref(), args.depfile.as_deref()];
    check_outputs(&[args.scene.as_deref()], &outputs)?;
    let mut run = Run::start("mesh-prep", env!("CARGO_PKG_VERSION"));
    let (source, scene_path): (&dyn mesh_prep::obj::TextSource, PathBuf) = match (&args.builtin, &args.scene) {
        (Some(b), _) => (b, b.scene_path()),
        (None, Some(path)) => (&Files, path.clone()),
        (None, None) => unreachable!("clap requires a scene or --builtin"),
    };
    let recording = Recording::new(source);
    let scene = read_scene(&recording, &scene_path)?;
    let prepared = prepare(&scene, &scene_path, &recording, &params)?;
    for input in recording.into_inputs() {
        run.input(input)?;
    }
    let statistics = prepared.statistics.clone();
    let warnings = prepared.warnings.clone();
    let provenance = run.provenance(&params);
    // A built-in scene's files are inside the binary, which the Makefile
    // already lists.
    let read: Vec<&str> = if args.builtin.is_some() { Vec::new() } else { provenance.inputs.iter().map(|i| i.path.as_str()).collect() };
    // Every file the scene named (OBJ, MTL, textures, photometry) is an
    // input too: none may be overwritten.
    check_outputs(&read.iter().map(|p| Some(Path::new(*p))).collect::<Vec<_>>(), &outputs)?;
    let mut targets = vec![mesh_path.display().to_string(), manifest_path.display().to_string()];
    targets.extend(args.surface.as_ref().map(|p| p.display().to_string()));
    let depfile_text = mesh_prep::depfile::rule(&targets.iter().map(String::as_str).collect::<Vec<_>>(), &read);
    let surface = args.surface.as_ref().map(|_| prepared.surface_artifact(provenance.clone()));
    let (mesh, manifest) = prepared.into_artifacts(provenance);
    for warning in &warnings {
        eprintln!("mesh-prep: warning: {warning}");
    }
    let twins = match statistics.two_sided_twins {
        0 => String::new(),
        n => format!(", {n} of them two-sided twins"),
    };
    eprintln!(
        "mesh-prep: {} triangles{twins}, {} vertices ({} degenerate and {} duplicate triangles dropped, {} vertices welded)",
        statistics.triangles, statistics.vertices, statistics.degenerate_dropped, statistics.duplicates_dropped, statistics.vertices_welded
    );
    let mut outputs = Outputs::new();
    outputs.write(&mesh_path, |p| mesh.write(p))?;
    outputs.write(&manifest_path, |p| schemas::ron_io::write_ron(p, &manifest))?;
    if let (Some(path), Some(surface)) = (&args.surface, &surface) {
        outputs.write(path, |p| surface.write(p))?;
    }
    if let Some(report) = &args.stage.report {
        let counters = BTreeMap::from([
            ("input_triangles".to_string(), statistics.input_triangles as f64),
            ("triangles".to_string(), statistics.triangles as f64),
            ("vertices".to_string(), statistics.vertices as f64),
            ("degenerate_dropped".to_string(), statistics.degenerate_dropped as f64),
            ("duplicates_dropped".to_string(), statistics.duplicates_dropped as f64),
            ("two_sided_twins".to_string(), statistics.two_sided_twins as f64),
            ("vertices_welded".to_string(), statistics.vertices_welded as f64),
        ]);
        outputs.write(report, |p| run.write_report(p, &params, counters, vec![], warnings))?;
    }
    if let Some(path) = &args.depfile {
        outputs.write(path, |p| std::fs::write(p, &depfile_text).map_err(|e| schemas::Error::io(path, e)))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("mesh-prep", run)
}

//! `cluster`: see the library's documentation and `cluster --help`.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use cluster::{build, Params};
use schemas::cluster::Clusters;
use schemas::header::Schema;
use stage_kit::run::{bad_parameter, load_params, print_params, read_prepared, Outputs, Run, StageArgs};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Build the cluster hierarchy over a prepared mesh (median splits along
/// the longest axis), with per-cluster bounds, area, reflectance-weighted
/// area and normal cone. Writes clusters.exr for hierarchical-solve
/// --clusters and the final gather.
#[derive(Parser, Debug)]
#[command(name = "cluster", version)]
struct Args {
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep (materials).
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output: the cluster hierarchy.
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// Most triangles in a leaf cluster (1..=255).
    #[arg(long)]
    leaf_size: Option<u32>,
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let mut params: Params = load_params(args.stage.params.as_deref())?;
    params.leaf_size = args.leaf_size.unwrap_or(params.leaf_size);
    if !(1..=255).contains(&params.leaf_size) {
        return Err(bad_parameter(format!("leaf_size must be in 1..=255, not {}", params.leaf_size)));
    }
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output)) = (&args.mesh, &args.manifest, &args.output) else {
        unreachable!("clap requires the inputs and output without --print-params")
    };
    check_outputs(&[args.mesh.as_deref(), args.manifest.as_deref()], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start("cluster", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let started = Instant::now();
    let triangles = stage_kit::scene::mesh_triangles(&mesh);
    let reflectance: Vec<[f64; 3]> = mesh.triangles.iter().map(|t| manifest.materials[t.material as usize].diffuse).collect();
    let hierarchy = build(&triangles, &reflectance, &params);
    let seconds = started.elapsed().as_secs_f64();
    let leaves = hierarchy.nodes.iter().filter(|n| n.is_leaf()).count();
    let isotropic = hierarchy.nodes.iter().filter(|n| n.normal_cos <= -1.0).count();
    eprintln!("cluster: {} clusters ({leaves} leaves, {isotropic} isotropic) over {} triangles", hierarchy.nodes.len(), triangles.len());
    let clusters = Clusters { header: Clusters::header(run.provenance(&params)), nodes: hierarchy.nodes, order: hierarchy.order };
    let mut outputs = Outputs::new();
    outputs.write(output, |p| clusters.write(p))?;
    if let Some(report) = &args.stage.report {
        let counters = BTreeMap::from([
            ("clusters".to_string(), clusters.nodes.len() as f64),
            ("leaf_clusters".to_string(), leaves as f64),
            ("isotropic_clusters".to_string(), isotropic as f64),
            ("triangles".to_string(), clusters.order.len() as f64),
            ("build_seconds".to_string(), seconds),
        ]);
        let mut notes = Vec::new();
        if !manifest.effects.fine_clustered_geometry {
            notes.push("the manifest does not flag fine geometry: clustering may not pay on this scene".to_string());
        }
        outputs.write(report, |p| run.write_report(p, &params, counters, vec![], notes))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("cluster", run)
}

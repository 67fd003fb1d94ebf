//! `cluster`: see the library's documentation and `cluster --help`.

use clap::Parser;
use cluster::{build, Params};
use schemas::cluster::Clusters;
use schemas::header::Schema;
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Build the cluster hierarchy over a prepared mesh (median splits along
/// the longest axis), with per-cluster bounds, area, reflectance-weighted
/// area and normal cone. Writes clusters.exr for hierarchical-solve
/// --clusters and the final gather.
#[derive(Parser, Debug)]
#[command(name = "cluster", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output: the cluster hierarchy.
    #[arg(short = 'o', long = "output", value_name = "CLUSTERS.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (self.scene.paths().to_vec(), vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh, manifest) = self.scene.read(run)?;
        let started = Instant::now();
        let triangles = stage_kit::scene::mesh_triangles(&mesh);
        let reflectance: Vec<[f64; 3]> = mesh.triangles.iter().map(|t| manifest.materials[t.material as usize].diffuse).collect();
        let hierarchy = build(&triangles, &reflectance, params);
        let seconds = started.elapsed().as_secs_f64();
        let leaves = hierarchy.nodes.iter().filter(|n| n.is_leaf()).count();
        let isotropic = hierarchy.nodes.iter().filter(|n| n.normal_cos <= -1.0).count();
        eprintln!("cluster: {} clusters ({leaves} leaves, {isotropic} isotropic) over {} triangles", hierarchy.nodes.len(), triangles.len());
        let clusters = Clusters { header: Clusters::header(run.provenance(params)), nodes: hierarchy.nodes, order: hierarchy.order };
        outputs.write(required(&self.output, "-o")?, |p| clusters.write(p))?;
        let mut done = Done::counted([
            ("clusters", clusters.nodes.len() as f64),
            ("leaf_clusters", leaves as f64),
            ("isotropic_clusters", isotropic as f64),
            ("triangles", clusters.order.len() as f64),
            ("build_seconds", seconds),
        ]);
        if !manifest.effects.fine_clustered_geometry {
            done.notes.push("the manifest does not flag fine geometry: clustering may not pay on this scene".to_string());
        }
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

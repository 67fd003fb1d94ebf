//! `mesh-prep`: see the library's documentation and `mesh-prep --help`.

use clap::Parser;
use mesh_prep::builtin::Builtin;
use mesh_prep::obj::{Files, TextSource};
use mesh_prep::report::files_read;
use mesh_prep::{prepare, read_scene, Params, Recording};
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, Stage};
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
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (vec![self.scene.as_deref()], vec![self.mesh.as_deref(), self.manifest.as_deref(), self.surface.as_deref(), self.depfile.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (mesh_path, manifest_path) = (required(&self.mesh, "--mesh")?, required(&self.manifest, "--manifest")?);
        let (source, scene_path): (&dyn TextSource, PathBuf) = match &self.builtin {
            Some(b) => (b, b.scene_path()),
            None => (&Files, required(&self.scene, "SCENE")?.to_path_buf()),
        };
        let recording = Recording::new(source);
        let prepared = prepare(&read_scene(&recording, &scene_path)?, &scene_path, &recording, params)?;
        recording.into_inputs().into_iter().try_for_each(|input| run.input(input))?;
        let provenance = run.provenance(params);
        // The files the scene named are inputs too: none may be overwritten.
        let (read, depfile) = files_read(&provenance, self.builtin.is_some(), &[Some(mesh_path), Some(manifest_path), self.surface.as_deref()]);
        run.check_outputs_against(&read)?;
        let done = mesh_prep::report::summarise(&prepared);
        let surface = self.surface.as_ref().map(|_| prepared.surface_artifact(provenance.clone()));
        let (mesh, manifest) = prepared.into_artifacts(provenance);
        outputs.write(mesh_path, |p| mesh.write(p))?;
        outputs.write(manifest_path, |p| schemas::ron_io::write_ron(p, &manifest))?;
        if let (Some(path), Some(surface)) = (&self.surface, &surface) {
            outputs.write(path, |p| surface.write(p))?;
        }
        if let Some(path) = &self.depfile {
            outputs.write(path, |p| std::fs::write(p, &depfile).map_err(|e| schemas::Error::io(path, e)))?;
        }
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

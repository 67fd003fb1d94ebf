//! `export-mitsuba`: see the library's documentation and `export-mitsuba --help`.

use clap::Parser;
use export_mitsuba::{export, files, Params};
use schemas::Error;
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, SceneArgs, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Write the prepared scene as a Mitsuba 3 XML scene: one binary PLY per
/// material (face normals) in a folder named after the XML beside it
/// (scene.xml -> scene/), diffuse reflectances, area emitters with radiance
/// = exitance / pi, the manifest camera (perspective, fov_axis y, lookat),
/// hdrfilm with a box filter, the path integrator. What has no exact Mitsuba
/// equivalent (goniometric lights, transmission, textures) is listed in the
/// report's `skipped` and on stderr. Render with
/// `mitsuba -Dspp=256 scene.xml` or `mi.load_file("scene.xml", spp=256)`.
#[derive(Parser, Debug)]
#[command(name = "export-mitsuba", version)]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output: the Mitsuba 3 XML scene; its PLY meshes go into the folder
    /// of the same name without the extension.
    #[arg(short = 'o', long = "output", value_name = "SCENE.xml", required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (self.scene.paths().to_vec(), vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let output = required(&self.output, "-o")?;
        let (folder, folder_name) = files::mesh_folder(output)?;
        let (mesh, manifest) = self.scene.read(run)?;
        let (width, height) = (params.width.unwrap_or(manifest.camera.width), params.height.unwrap_or(manifest.camera.height));
        if stage_kit::scene::pinhole(&manifest.camera, width, height).is_none() {
            let problem = "camera: the view direction is zero or parallel to up, the field of view is not in (0, 180) degrees, or the image is empty";
            return Err(Error::invalid(required(&self.scene.manifest, "--manifest")?, None, problem));
        }
        if mesh.triangles.is_empty() {
            return Err(Error::invalid(required(&self.scene.mesh, "--mesh")?, None, "the mesh has no triangles: nothing to export"));
        }
        let provenance = schemas::ron_io::to_ron_text(&run.provenance(params));
        let exported = export(&mesh, &manifest, params, &folder_name, &provenance);
        files::write(&exported, &folder, output, outputs)?;
        let (triangles, (w, h)) = (mesh.triangles.len(), exported.film);
        eprintln!("export-mitsuba: {triangles} triangles in {} PLY meshes, {} area emitters, film {w}x{h}", exported.meshes.len(), exported.emitters);
        let mut done = Done::counted([
            ("triangles", triangles as f64),
            ("meshes", exported.meshes.len() as f64),
            ("vertices", exported.meshes.iter().map(|m| m.vertices).sum::<usize>() as f64),
            ("emitters", exported.emitters as f64),
            ("skipped", exported.skipped.len() as f64),
        ]);
        done.skipped = exported.skipped;
        done.notes = vec![
            "Mitsuba's world frame is the mesh frame: positions and camera written as they are, no transform".to_string(),
            format!("PLY meshes in {}", folder.display()),
        ];
        Ok(done)
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

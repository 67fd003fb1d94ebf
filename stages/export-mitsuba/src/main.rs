//! `export-mitsuba`: see the library's documentation and `export-mitsuba --help`.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use export_mitsuba::{export, Params};
use schemas::atomic::write_bytes_atomically;
use stage_kit::run::{bad_parameter, load_params, print_params, read_prepared, Outputs, Run, StageArgs};
use schemas::Error;
use std::collections::BTreeMap;
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
    /// Input: mesh.exr from mesh-prep.
    #[arg(long, required_unless_present = "print_params")]
    mesh: Option<PathBuf>,
    /// Input: manifest.ron from mesh-prep (materials, camera, lights).
    #[arg(long, required_unless_present = "print_params")]
    manifest: Option<PathBuf>,
    /// Output: the Mitsuba 3 XML scene; its PLY meshes go into the folder
    /// of the same name without the extension.
    #[arg(short = 'o', long = "output", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    #[command(flatten)]
    stage: StageArgs,
    /// Samples per pixel (the scene's `spp` default; `-Dspp=N` overrides it).
    #[arg(long)]
    spp: Option<u32>,
    /// Longest path of the path integrator; -1: unbounded.
    #[arg(long, allow_hyphen_values = true)]
    max_depth: Option<i32>,
    /// Mitsuba sampler: independent, stratified, multijitter, orthogonal, ldsampler.
    #[arg(long)]
    sampler: Option<String>,
    /// The sampler's seed.
    #[arg(long)]
    seed: Option<u32>,
    /// Film width in pixels (default: the manifest camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Film height in pixels (default: the manifest camera's).
    #[arg(long)]
    height: Option<u32>,
}

/// The PLY folder of `xml`: `dir/scene.xml` -> `dir/scene`, and its name as
/// the XML refers to it.
fn mesh_folder(xml: &Path) -> schemas::Result<(PathBuf, String)> {
    let stem = xml.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if stem.is_empty() || xml.extension().is_none() {
        return Err(Error::invalid(xml, None, "the output needs a name with an extension (e.g. scene.xml): its meshes go into the folder named after it"));
    }
    Ok((xml.with_file_name(&stem), stem))
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let mut params: Params = load_params(args.stage.params.as_deref())?;
    params.spp = args.spp.unwrap_or(params.spp);
    params.max_depth = args.max_depth.unwrap_or(params.max_depth);
    params.sampler = args.sampler.clone().unwrap_or(params.sampler);
    params.seed = args.seed.unwrap_or(params.seed);
    params.width = args.width.or(params.width);
    params.height = args.height.or(params.height);
    params.check().map_err(bad_parameter)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(mesh_path), Some(manifest_path), Some(output)) = (&args.mesh, &args.manifest, &args.output) else {
        unreachable!("clap requires the inputs and output without --print-params")
    };
    let (folder, folder_name) = mesh_folder(output)?;
    check_outputs(&[args.mesh.as_deref(), args.manifest.as_deref()], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start("export-mitsuba", env!("CARGO_PKG_VERSION"));
    let (mesh, manifest) = read_prepared(&mut run, mesh_path, manifest_path)?;
    let (width, height) = (params.width.unwrap_or(manifest.camera.width), params.height.unwrap_or(manifest.camera.height));
    if stage_kit::scene::pinhole(&manifest.camera, width, height).is_none() {
        return Err(Error::invalid(
            manifest_path,
            None,
            "camera: the view direction is zero or parallel to up, the field of view is not in (0, 180) degrees, or the image is empty",
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(Error::invalid(mesh_path, None, "the mesh has no triangles: nothing to export"));
    }
    let provenance = schemas::ron_io::to_ron_text(&run.provenance(&params));
    let exported = export(&mesh, &manifest, &params, &folder_name, &provenance);

    let created_folder = !folder.is_dir();
    std::fs::create_dir_all(&folder).map_err(|e| Error::io(&folder, e))?;
    let outcome = (|| {
        let mut outputs = Outputs::new();
        // The meshes first, the XML that names them last.
        for ply in &exported.meshes {
            outputs.write(&folder.join(&ply.file_name), |p| write_bytes_atomically(p, &ply.bytes))?;
        }
        outputs.write(output, |p| write_bytes_atomically(p, exported.xml.as_bytes()))?;
        for line in &exported.skipped {
            eprintln!("export-mitsuba: not exported: {line}");
        }
        eprintln!(
            "export-mitsuba: {} triangles in {} PLY meshes, {} area emitters, film {}x{}",
            mesh.triangles.len(),
            exported.meshes.len(),
            exported.emitters,
            exported.film.0,
            exported.film.1
        );
        if let Some(report) = &args.stage.report {
            let counters = BTreeMap::from([
                ("triangles".to_string(), mesh.triangles.len() as f64),
                ("meshes".to_string(), exported.meshes.len() as f64),
                ("vertices".to_string(), exported.meshes.iter().map(|m| m.vertices).sum::<usize>() as f64),
                ("emitters".to_string(), exported.emitters as f64),
                ("skipped".to_string(), exported.skipped.len() as f64),
            ]);
            let notes = vec![
                "Mitsuba's world frame is the mesh frame: positions and camera written as they are, no transform".to_string(),
                format!("PLY meshes in {}", folder.display()),
            ];
            outputs.write(report, |p| run.write_report(p, &params, counters, exported.skipped.clone(), notes))?;
        }
        outputs.keep()?;
        Ok(())
    })();
    if outcome.is_err() && created_folder {
        let _ = std::fs::remove_dir(&folder);
    }
    outcome.map(|()| ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("export-mitsuba", run)
}

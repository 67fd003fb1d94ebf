//! `bench-surfaces`: each surface's mean radiosity in solutions of one
//! scene against a reference solve (see [`bench::surfaces`]), a Markdown
//! table: what `make bench-renderpark` measures RenderPark's accuracy and
//! hierarchical-solve's with.
//!
//! Reproduce: `make bench-renderpark` (figures in README, RenderPark).

use bench::SceneFiles;
use bench::surfaces::{table, vrml_faces, Surfaces, Unit};
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use schemas::header::{Input, Schema};
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use schemas::{Error, Result};
use stage_kit::cli::main_of;
use stage_kit::run::{bad_parameter, check_writable, Run};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Tabulates each surface's mean radiosity in solutions (hierarchical-solve's, or RenderPark VRML models) against a reference solution.
#[derive(Parser, Debug)]
#[command(name = "bench-surfaces", version)]
struct Args {
    #[command(flatten)]
    scene: SceneFiles,
    /// The reference: a hierarchical-solve solution of the scene at a fine EPS.
    #[arg(long, value_name = "SOLUTION.exr")]
    reference: PathBuf,
    /// What a surface is: an object of the manifest, or an input triangle (a block's face is two).
    #[arg(long, value_enum, default_value_t = Unit::Object)]
    by: Unit,
    /// Output: the table (also printed on stdout).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Also write each RenderPark model as a solution on the mesh, DIR/LABEL.exr (LABEL's characters other than letters, digits, '.' and '-' as '-'), for grid-gather's preview to render.
    #[arg(long, value_name = "DIR")]
    solutions: Option<PathBuf>,
    /// The series, LABEL=FILE: a solution (EXR) of the same mesh, or a RenderPark model (.wrl) whose colours are radiance.
    #[arg(required = true, value_name = "LABEL=FILE")]
    series: Vec<String>,
}

fn run(args: Args) -> Result<ExitCode> {
    check_writable(&args.output)?;
    if let Some(dir) = &args.solutions {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    // The run records its inputs for the solutions it writes, refusing a
    // reference made from another mesh-prep run than the mesh.
    let mut run = Run::start("bench-surfaces", env!("CARGO_PKG_VERSION"));
    let (mesh, mesh_input) = Mesh::read(&args.scene.mesh)?;
    run.input(mesh_input)?;
    let manifest = read_ron::<Manifest>(&args.scene.manifest)?;
    run.input(manifest.input)?;
    let manifest = manifest.value;
    let (reference, reference_input) = Solution::read(&args.reference)?;
    run.input(reference_input)?;
    let invalid = |path: &Path, message: String| Error::invalid(path, None, message);
    let surfaces = Surfaces::new(&mesh, &manifest, &reference, args.by).map_err(|m| invalid(&args.reference, m))?;
    let mut series = Vec::new();
    for s in &args.series {
        let (label, file) = s.split_once('=').ok_or_else(|| bad_parameter(format!("series '{s}' is not LABEL=FILE")))?;
        let path = Path::new(file);
        let means = if path.extension().is_some_and(|e| e == "wrl") {
            let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
            let faces = vrml_faces(&String::from_utf8_lossy(&bytes)).map_err(|m| invalid(path, m))?;
            run.input(Input::new(path, &bytes, None))?;
            if let Some(dir) = &args.solutions {
                let name: String = label.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '-' }).collect();
                let solution = surfaces.solution_of_faces(&faces, Solution::header(run.provenance(&()))).map_err(|m| invalid(path, m))?;
                solution.write(&dir.join(format!("{name}.exr")))?;
            }
            surfaces.of_faces(&faces)
        } else {
            surfaces.of_solution(&Solution::read(path)?.0)
        };
        series.push((label.to_string(), means.map_err(|m| invalid(path, m))?));
    }
    let reference = surfaces.of_solution(&reference).map_err(|m| invalid(&args.reference, m))?;
    let text = table(&surfaces.names(), &reference, &series);
    write_bytes_atomically(&args.output, text.as_bytes())?;
    print!("{text}");
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-surfaces", run)
}

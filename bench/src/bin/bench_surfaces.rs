//! `bench-surfaces`: each surface's mean radiosity in solutions of one
//! scene against a reference solve (see [`bench::surfaces`]), a Markdown
//! table: what `make bench-renderpark` measures RenderPark's accuracy and
//! hierarchical-solve's with.
//!
//! Reproduce: `make bench-renderpark` (figures in README, RenderPark).

use bench::surfaces::{table, vrml_faces, Surfaces};
use clap::Parser;
use schemas::atomic::write_bytes_atomically;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use schemas::{Error, Result};
use stage_kit::cli::main_of;
use stage_kit::run::{bad_parameter, check_writable};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Tabulates each surface's mean radiosity in solutions (hierarchical-solve's, or RenderPark VRML models) against a reference solution.
#[derive(Parser, Debug)]
#[command(name = "bench-surfaces", version)]
struct Args {
    /// The scene's mesh (mesh-prep).
    #[arg(long)]
    mesh: PathBuf,
    /// The scene's manifest (mesh-prep): names the surfaces, marks the emitters.
    #[arg(long)]
    manifest: PathBuf,
    /// The reference: a hierarchical-solve solution of the scene at a fine EPS.
    #[arg(long, value_name = "SOLUTION.exr")]
    reference: PathBuf,
    /// Output: the table (also printed on stdout).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// The series, LABEL=FILE: a solution (EXR) of the same mesh, or a RenderPark model (.wrl) whose colours are radiance.
    #[arg(required = true, value_name = "LABEL=FILE")]
    series: Vec<String>,
}

fn run(args: Args) -> Result<ExitCode> {
    check_writable(&args.output)?;
    let (mesh, _) = Mesh::read(&args.mesh)?;
    let manifest: Manifest = read_ron(&args.manifest)?.value;
    let (reference, _) = Solution::read(&args.reference)?;
    let invalid = |path: &Path, message: String| Error::invalid(path, None, message);
    let surfaces = Surfaces::new(&mesh, &manifest, &reference).map_err(|m| invalid(&args.reference, m))?;
    let mut series = Vec::new();
    for s in &args.series {
        let (label, file) = s.split_once('=').ok_or_else(|| bad_parameter(format!("series '{s}' is not LABEL=FILE")))?;
        let path = Path::new(file);
        let means = if path.extension().is_some_and(|e| e == "wrl") {
            let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
            vrml_faces(&text).and_then(|faces| surfaces.of_faces(&faces))
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

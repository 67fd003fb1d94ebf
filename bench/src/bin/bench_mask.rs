//! `bench-mask`: paper 000 Table 1's masking experiment on a textured
//! floor (see [`bench::mask`]). `bench-mask scene --dir D` writes the
//! room with its checkerboard floor (`D/scene.ron` and the files it
//! names); `bench-mask summary --dir D unmasked masked` tabulates the full
//! gathers `D/NAME.exr` (with `D/NAME.report.ron`) against
//! `D/reference.exr`, on the floor by `D/manifest.ron`'s `floor` material,
//! and against the mask's thresholds `D/threshold.exr`.
//!
//! Reproduce: `make bench-mask` (figures in README, Performance).

use bench::gather::GatherRun;
use bench::mask::{scene, table};
use clap::{Parser, Subcommand};
use schemas::atomic::write_bytes_atomically;
use stage_kit::cli::main_of;
use schemas::image::HdrImage;
use schemas::mesh::Manifest;
use schemas::report::Report;
use schemas::ron_io::read_ron;
use stage_kit::run::{bad_parameter, check_writable};
use schemas::threshold::ThresholdImage;
use schemas::{Error, Result};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The textured-floor scene of the masking benchmark, and its table.
#[derive(Parser, Debug)]
#[command(name = "bench-mask", version)]
struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Writes the room with the checkerboard floor into DIR.
    Scene {
        /// Output directory (created).
        #[arg(long)]
        dir: PathBuf,
        /// Checks per side of the floor.
        #[arg(long, default_value_t = 32)]
        checks: usize,
        /// Image width, pixels.
        #[arg(long, default_value_t = 128)]
        width: u32,
        /// Image height, pixels.
        #[arg(long, default_value_t = 128)]
        height: u32,
    },
    /// Tabulates the runs (unmasked first, masked last) against DIR/reference.exr.
    Summary {
        /// The directory holding reference.exr, threshold.exr, manifest.ron and each run's NAME.exr and NAME.report.ron.
        #[arg(long)]
        dir: PathBuf,
        /// The floor's material name in the manifest.
        #[arg(long, default_value = "floor")]
        floor: String,
        /// The runs, in table order.
        #[arg(required = true, value_name = "RUN")]
        runs: Vec<String>,
        /// Output: the table (also printed on stdout).
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
    },
}

/// Reads image `path` and checks it has `size` pixels.
fn image_of(path: &Path, size: Option<(usize, usize)>) -> Result<HdrImage> {
    let image = HdrImage::read(path)?.0;
    match size {
        Some((w, h)) if (image.width, image.height) != (w, h) => Err(Error::invalid(path, None, format!("{} x {} pixels, the reference has {w} x {h}", image.width, image.height))),
        _ => Ok(image),
    }
}

fn summary(dir: &Path, floor: &str, names: &[String], output: &Path) -> Result<()> {
    check_writable(output)?;
    let reference = image_of(&dir.join("reference.exr"), None)?;
    let size = Some((reference.width, reference.height));
    let manifest_path = dir.join("manifest.ron");
    let manifest = read_ron::<Manifest>(&manifest_path)?.value;
    let index = manifest.materials.iter().position(|m| m.name == floor).ok_or_else(|| Error::invalid(&manifest_path, None, format!("no material named '{floor}'")))?;
    let floor_pixels = table::floor_pixels(&reference, index as u32);
    let threshold_path = dir.join("threshold.exr");
    let threshold = ThresholdImage::read(&threshold_path)?.0;
    if (threshold.width, threshold.height) != (reference.width, reference.height) {
        return Err(Error::invalid(&threshold_path, None, format!("{} x {} pixels, the reference has {} x {}", threshold.width, threshold.height, reference.width, reference.height)));
    }
    let mut runs = Vec::new();
    for name in names {
        let report: Report = read_ron(&dir.join(format!("{name}.report.ron")))?.value;
        let image = image_of(&dir.join(format!("{name}.exr")), size)?;
        runs.push((GatherRun::of(name, &report, 0.0), table::errors(&image, &reference, &floor_pixels, &threshold.contrast)));
    }
    let floor_mean = |values: &[f32]| table::mean_over(values, &floor_pixels);
    let text = format!(
        "{} floor pixels of {}; the mask on the floor: mean threshold contrast {:.3}, mean elevation {:.2}\n{}",
        floor_pixels.iter().filter(|&&f| f).count(),
        floor_pixels.len(),
        floor_mean(&threshold.contrast),
        floor_mean(&threshold.elevation),
        table::summary(&runs)
    );
    write_bytes_atomically(output, text.as_bytes())?;
    print!("{text}");
    Ok(())
}

fn run(args: Args) -> Result<ExitCode> {
    match args.command {
        Command::Scene { dir, checks, width, height } => {
            let files = scene::files(checks, width, height).map_err(bad_parameter)?;
            std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
            for (name, bytes) in files {
                write_bytes_atomically(&dir.join(name), &bytes)?;
            }
        }
        Command::Summary { dir, floor, runs, output } => summary(&dir, &floor, &runs, &output)?,
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of("bench-mask", run)
}

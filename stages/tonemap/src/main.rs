//! `tonemap IMAGE.exr -o OUT.png`: linear HDR image to 8-bit sRGB PNG.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use schemas::image::HdrImage;
use stage_kit::run::{load_params, print_params, Run, StageArgs};
use schemas::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tonemap::{Curve, Operator, Params, Setting};

/// Maps a linear HDR image (radiance, with coverage) to an 8-bit sRGB PNG.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Input HDR image (`image` artifact of this pipeline, or any RGB(A) EXR).
    #[arg(required_unless_present = "print_params")]
    image: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Tone curve: reinhard | exposure.
    #[arg(long)]
    operator: Option<Operator>,
    /// Reinhard key a (middle grey), or 'auto'.
    #[arg(long)]
    key: Option<Setting>,
    /// Exposure k in 1/(W/(m^2 sr)) for the exposure operator, or 'auto' (1 / log-average luminance).
    #[arg(long)]
    exposure: Option<Setting>,
    #[command(flatten)]
    stage: StageArgs,
}

fn params(args: &Args) -> schemas::Result<Params> {
    let mut params: Params = load_params(args.stage.params.as_deref())?;
    if let Some(operator) = args.operator {
        params.operator = operator;
    }
    if let Some(key) = args.key {
        params.key = key;
    }
    if let Some(exposure) = args.exposure {
        params.exposure = exposure;
    }
    params.validate()?;
    Ok(params)
}

fn run(args: Args) -> schemas::Result<ExitCode> {
    let params = params(&args)?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(input), Some(output)) = (args.image.as_deref(), args.output.as_deref()) else {
        unreachable!("clap requires IMAGE and -o without --print-params")
    };
    check_outputs(&[Some(input)], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start("tonemap", env!("CARGO_PKG_VERSION"));
    let (image, record, origin) = HdrImage::read_any(input)?;
    if let Some(note) = origin.foreign_note(input, &record) {
        eprintln!("tonemap: note: {note}");
    }
    run.input(record)?;
    let mapped = tonemap::tonemap(&image, &params).map_err(|e| Error::invalid(input, None, e.to_string()))?;
    let png = stage_kit::png::encode_png(mapped.width, mapped.height, &mapped.pixels)
        .map_err(|e| Error::invalid(output, None, e))?;
    schemas::atomic::write_bytes_atomically(output, &png)?;
    if let Some(report) = args.stage.report.as_deref() {
        write_report(&run, report, &params, &mapped.stats)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn write_report(run: &Run, path: &Path, params: &Params, stats: &tonemap::Stats) -> schemas::Result<()> {
    let mut notes = vec![match stats.curve {
        Curve::Reinhard { key, white } => format!(
            "Reinhard 2002 global operator, key {key:.4} ({}), white point {white:.4} (largest scaled luminance)",
            if params.key == Setting::Auto { "automatic" } else { "given" }
        ),
        Curve::Exposure { k } => format!(
            "exposure operator 1 - exp(-k x), k {k:.6} ({})",
            if params.exposure == Setting::Auto { "1 / log-average luminance" } else { "given" }
        ),
    }];
    if stats.covered_pixels == 0 {
        notes.push("no pixel has coverage > 0: the picture is black".to_string());
    }
    if stats.negative_values_clamped > 0 {
        notes.push(format!("{} negative radiance values clamped to 0", stats.negative_values_clamped));
    }
    run.write_report(path, params, stats.counters(), Vec::new(), notes)
}

fn main() -> ExitCode {
    main_of("tonemap", run)
}

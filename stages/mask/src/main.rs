//! `mask PREVIEW.png -o threshold.exr`: per-pixel visibility thresholds of
//! a tone-mapped preview (TVI x masking elevation). See the library docs.

use clap::Parser;
use stage_kit::cli::{check_outputs, main_of};
use mask::{display_luminance, thresholds, Params};
use schemas::header::{Input, Schema};
use schemas::ron_io::read_bytes;
use schemas::threshold::ThresholdImage;
use stage_kit::run::{load_params, print_params, Outputs, Run, StageArgs};
use schemas::{Error, Result};
use std::path::PathBuf;
use std::process::ExitCode;

const STAGE: &str = "mask";

/// Visibility threshold per pixel of a tone-mapped image: threshold versus
/// intensity (Ferwerda et al. 1996) times the masking threshold elevation
/// (Ramasubramanian, Pattanaik, Greenberg 1999).
#[derive(Parser, Debug)]
#[command(name = STAGE, version)]
struct Args {
    /// Tone-mapped preview (8-bit sRGB PNG from tonemap).
    #[arg(value_name = "IMAGE.png", required_unless_present = "print_params")]
    image: Option<PathBuf>,
    /// Output threshold image (EXR: L, La, elevation, threshold, contrast).
    #[arg(short = 'o', long = "output", value_name = "THRESHOLD.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
    /// Luminance of display white, cd/m^2 [default: 100].
    #[arg(long, value_name = "CD_M2")]
    display_max_cd_m2: Option<f64>,
    /// Darkest displayed luminance, fraction of white [default: 0.005].
    #[arg(long, value_name = "FRACTION")]
    display_black: Option<f64>,
    /// Image pixels per degree of visual angle [default: 32].
    #[arg(long, value_name = "PIXELS")]
    pixels_per_degree: Option<f64>,
    /// Band-pass levels of the contrast pyramid [default: 6].
    #[arg(long, value_name = "N")]
    levels: Option<u32>,
    /// Exponent s of the masking function max(1, C^s) [default: 0.7].
    #[arg(long, value_name = "S")]
    masking_slope: Option<f64>,
    #[command(flatten)]
    stage: StageArgs,
}

impl Args {
    fn params(&self) -> Result<Params> {
        let mut p: Params = load_params(self.stage.params.as_deref())?;
        if let Some(v) = self.display_max_cd_m2 {
            p.display_max_cd_m2 = v;
        }
        if let Some(v) = self.display_black {
            p.display_black = v;
        }
        if let Some(v) = self.pixels_per_degree {
            p.pixels_per_degree = v;
        }
        if let Some(v) = self.levels {
            p.levels = v;
        }
        if let Some(v) = self.masking_slope {
            p.masking_slope = v;
        }
        p.validate()?;
        Ok(p)
    }
}

fn run(args: &Args) -> Result<ExitCode> {
    let params = args.params()?;
    if args.stage.print_params {
        print_params(&params);
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(input), Some(output)) = (&args.image, &args.output) else {
        return Err(stage_kit::run::bad_parameter("IMAGE and -o are required"));
    };
    check_outputs(&[Some(input)], &[Some(output), args.stage.report.as_deref()])?;
    let mut run = Run::start(STAGE, env!("CARGO_PKG_VERSION"));
    let bytes = read_bytes(input)?;
    run.input(Input::new(input, &bytes, None))?;
    let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| Error::parse(input, None, format!("not a readable PNG: {e}")))?
        .to_rgb8();
    let (width, height) = (decoded.width() as usize, decoded.height() as usize);
    let pixels: Vec<[u8; 3]> = decoded.pixels().map(|p| p.0).collect();
    let luminance = display_luminance(&pixels, params.display_max_cd_m2);
    let t = thresholds(&params, width, height, &luminance).map_err(|e| Error::invalid(input, None, e.to_string()))?;
    let counters = t.counters.clone();
    let artifact = t.into_artifact(ThresholdImage::header(run.provenance(&params)));
    let mut outputs = Outputs::new();
    outputs.write(output, |p| artifact.write(p))?;
    if let Some(report) = &args.stage.report {
        outputs.write(report, |p| run.write_report(p, &params, counters, Vec::new(), Vec::new()))?;
    }
    outputs.keep()?;
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    main_of(STAGE, |args: Args| run(&args))
}

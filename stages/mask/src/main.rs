//! `mask PREVIEW.png -o threshold.exr`: per-pixel visibility thresholds of
//! a tone-mapped preview (TVI x masking elevation). See the library docs.

use clap::Parser;
use mask::{display_luminance, thresholds, Params};
use schemas::header::{Input, Schema};
use schemas::ron_io::read_bytes;
use schemas::threshold::ThresholdImage;
use schemas::{Error, Result};
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Visibility threshold per pixel of a tone-mapped image: threshold versus
/// intensity (Ferwerda et al. 1996) times the masking threshold elevation
/// (Ramasubramanian, Pattanaik, Greenberg 1999).
#[derive(Parser, Debug)]
#[command(name = "mask", version)]
struct Args {
    /// Tone-mapped preview (8-bit sRGB PNG from tonemap).
    #[arg(value_name = "IMAGE.png", required_unless_present = "print_params")]
    image: Option<PathBuf>,
    /// Output threshold image (EXR: L, La, elevation, threshold, contrast).
    #[arg(short = 'o', long = "output", value_name = "THRESHOLD.exr", required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (vec![self.image.as_deref()], vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> Result<Done> {
        let input = required(&self.image, "IMAGE")?;
        let bytes = read_bytes(input)?;
        run.input(Input::new(input, &bytes, None))?;
        let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .map_err(|e| Error::parse(input, None, format!("not a readable PNG: {e}")))?
            .to_rgb8();
        let (width, height) = (decoded.width() as usize, decoded.height() as usize);
        let pixels: Vec<[u8; 3]> = decoded.pixels().map(|p| p.0).collect();
        let luminance = display_luminance(&pixels, params.display_max_cd_m2);
        let t = thresholds(params, ThresholdImage::header(run.provenance(params)), width, height, &luminance).map_err(|e| Error::invalid(input, None, e.to_string()))?;
        outputs.write(required(&self.output, "-o")?, |p| t.image.write(p))?;
        Ok(Done { counters: t.counters, ..Done::default() })
    }
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

//! `tonemap IMAGE.exr -o OUT.png`: linear HDR image to 8-bit sRGB PNG.

use clap::Parser;
use schemas::image::HdrImage;
use schemas::Error;
use stage_kit::run::{Outputs, Run};
use stage_kit::stage::{required, Done, Stage};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tonemap::{Curve, Params, Setting};

/// Maps a linear HDR image (radiance, with coverage) to an 8-bit sRGB PNG.
#[derive(Parser, Debug)]
#[command(name = "tonemap", version, about)]
struct Args {
    /// Input HDR image (`image` artifact of this pipeline, or any RGB(A) EXR).
    #[arg(required_unless_present = "print_params")]
    image: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, required_unless_present = "print_params")]
    output: Option<PathBuf>,
}

impl Stage for Args {
    type Params = Params;

    fn files(&self) -> (Vec<Option<&Path>>, Vec<Option<&Path>>) {
        (vec![self.image.as_deref()], vec![self.output.as_deref()])
    }

    fn run(self, params: &Params, run: &mut Run, outputs: &mut Outputs) -> schemas::Result<Done> {
        let (input, output) = (required(&self.image, "IMAGE")?, required(&self.output, "-o")?);
        let (image, record, origin) = HdrImage::read_any(input)?;
        if let Some(note) = origin.foreign_note(input, &record) {
            eprintln!("tonemap: note: {note}");
        }
        run.input(record)?;
        let mapped = tonemap::tonemap(&image, params).map_err(|e| Error::invalid(input, None, e.to_string()))?;
        let png = stage_kit::png::encode_png(mapped.width, mapped.height, &mapped.pixels).map_err(|e| Error::invalid(output, None, e))?;
        outputs.write_bytes(output, &png)?;
        Ok(Done { counters: mapped.stats.counters(), notes: notes(params, &mapped.stats), ..Done::default() })
    }
}

/// The report's notes: the curve and its constants, and what was clamped.
fn notes(params: &Params, stats: &tonemap::Stats) -> Vec<String> {
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
    notes
}

fn main() -> ExitCode {
    stage_kit::stage::main::<Args>()
}

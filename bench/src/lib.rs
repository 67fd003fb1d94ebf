//! Measuring helpers the benchmark binaries share, the sweep of error
//! against time ([`sweep`], the `sweep` binary), and paper 002's
//! benchmark of structured sampling ([`structured`], `bench-structured`),
//! the summary of `make bench-gather` ([`gather`], `bench-gather`), and the
//! table of `make bench-mirror` ([`mirror`], `bench-mirror`).

pub mod gather;
pub mod mask;
pub mod mirror;
pub mod residual;
pub mod structured;
pub mod surfaces;
pub mod sweep;

use std::path::PathBuf;

/// The options of the drivers that run the pipeline on a scene (sweep,
/// bench-structured): the reference, the solver's clustering, the image
/// size and the output directory.
#[derive(clap::Args, Debug)]
pub struct PipelineArgs {
    /// A reference image (EXR, e.g. another renderer's, such as make bench-peer's Mitsuba image) for scenes with neither a closed form nor an exact image.
    #[arg(long, value_name = "REFERENCE.exr")]
    pub reference: Option<PathBuf>,
    /// Solve without the cluster hierarchy (the Makefile's CLUSTERS=0).
    #[arg(long)]
    pub no_clusters: bool,
    /// Image width, pixels [default: the scene camera's].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height, pixels [default: the scene camera's].
    #[arg(long)]
    pub height: Option<u32>,
    /// Output directory.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    pub output: PathBuf,
}

/// The scene files a measuring binary reads (bench-surfaces,
/// bench-residual): mesh-prep's mesh and manifest.
#[derive(clap::Args, Debug)]
pub struct SceneFiles {
    /// The scene's mesh (mesh-prep).
    #[arg(long)]
    pub mesh: PathBuf,
    /// The scene's manifest (mesh-prep): its materials and emitters, its surfaces' names.
    #[arg(long)]
    pub manifest: PathBuf,
}

/// The process's peak resident memory (VmHWM), MiB; `None` off Linux.
pub fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib / 1024.0)
}

/// Resets the peak resident memory to the current one (Linux: writing 5 to
/// `/proc/self/clear_refs`), so the next [`peak_memory_mib`] measures only
/// what follows. Returns whether the kernel took it.
pub fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The median (the mean of the two middle values for an even count).
pub fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let m = xs.len() / 2;
    if xs.len() % 2 == 1 {
        xs[m]
    } else {
        0.5 * (xs[m - 1] + xs[m])
    }
}

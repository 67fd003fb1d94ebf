//! Measuring helpers the benchmark binaries share, the sweep of error
//! against time ([`sweep`], the `sweep` binary), and paper 002's
//! benchmark of structured sampling ([`structured`], `bench-structured`),
//! and the summary of `make bench-gather` ([`gather`], `bench-gather`).

pub mod gather;
pub mod structured;
pub mod sweep;

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

//! The solutions of the way there (`--snapshot-dir`): `stochastic.exr`
//! at the end of stage 1, `direct.exr` at the end of stage 2, and, with
//! `--snapshot-every N`, `<stage>-<photons>.exr` about every `N` photons
//! of stages 1 and 3 (paper 001's Figure 1 sequence).

use crate::{Snapshot, Stage};
use schemas::header::Header;
use schemas::solution::Solution;
use stage_kit::run::Outputs;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The snapshot of the end of stage 2, which every run with a snapshot
/// directory writes.
const DIRECT: &str = "direct.exr";

/// An existing directory for the snapshots (the `--snapshot-dir` flag's
/// value), with the path of the snapshot every run writes there, which the
/// command line checks as an output before the run.
#[derive(Clone, Debug)]
pub struct SnapshotDir {
    dir: PathBuf,
    direct: PathBuf,
}

impl From<OsString> for SnapshotDir {
    fn from(dir: OsString) -> Self {
        let dir = PathBuf::from(dir);
        SnapshotDir { direct: dir.join(DIRECT), dir }
    }
}

impl SnapshotDir {
    /// Where the end of stage 2 goes.
    pub fn direct(&self) -> &Path {
        &self.direct
    }

    /// Writes `snapshot` as a solution with `header`, put in place at once;
    /// a stage-1 snapshot of `preview_photons` or more is the end of stage
    /// 1. Returns the report's note on it.
    pub fn write(&self, snapshot: &Snapshot, preview_photons: u64, header: &Header) -> Result<String, String> {
        let name = match snapshot.stage {
            Stage::Direct => DIRECT.to_string(),
            Stage::Stochastic if snapshot.photons >= preview_photons => "stochastic.exr".to_string(),
            stage => format!("{stage}-{:012}.exr", snapshot.photons),
        };
        let solution = Solution { header: header.clone(), elements: snapshot.elements.clone(), clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() };
        let mut outputs = Outputs::new();
        outputs.write(&self.dir.join(&name), |p| solution.write(p)).and_then(|()| outputs.keep()).map_err(|e| e.to_string())?;
        let error = if snapshot.max_error.is_finite() { format!(", largest vertex error {:.3e}", snapshot.max_error) } else { String::new() };
        Ok(format!("snapshot {name}: {} stage, {} photons, {:.3} s{error}", snapshot.stage, snapshot.photons, snapshot.seconds))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::{Provenance, Schema};

    /// The Figure 1 names: a stage-1 snapshot before `preview_photons` is
    /// numbered, the one at it is `stochastic.exr`, stage 2's is
    /// `direct.exr` (the path the command line checks), stage 3's are
    /// numbered; each note names the file, its stage, photons and error.
    #[test]
    fn snapshots_are_named_by_stage_and_photons() {
        let dir = std::env::temp_dir().join(format!("photon-trace-snapshots-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let snapshots = SnapshotDir::from(dir.clone().into_os_string());
        assert_eq!(snapshots.direct(), dir.join("direct.exr"));
        let header = Solution::header(Provenance::in_memory("test"));
        let shot = |stage, photons, max_error| Snapshot { stage, photons, seconds: 0.25, max_error, elements: Vec::new() };
        let notes: Vec<String> = [shot(Stage::Stochastic, 4096, 0.5), shot(Stage::Stochastic, 8192, 0.25), shot(Stage::Direct, 0, f64::NAN), shot(Stage::Indirect, 16384, 0.125)]
            .iter()
            .map(|s| snapshots.write(s, 8192, &header).unwrap())
            .collect();
        assert_eq!(
            notes,
            [
                "snapshot stochastic-000000004096.exr: stochastic stage, 4096 photons, 0.250 s, largest vertex error 5.000e-1",
                "snapshot stochastic.exr: stochastic stage, 8192 photons, 0.250 s, largest vertex error 2.500e-1",
                "snapshot direct.exr: direct stage, 0 photons, 0.250 s",
                "snapshot indirect-000000016384.exr: indirect stage, 16384 photons, 0.250 s, largest vertex error 1.250e-1",
            ]
        );
        for name in ["stochastic-000000004096.exr", "stochastic.exr", "direct.exr", "indirect-000000016384.exr"] {
            assert!(dir.join(name).is_file(), "{name}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

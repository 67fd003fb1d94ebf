//! Atomic file writes: write beside the target, flush, then rename, so a
//! killed stage never leaves a half-written file that `make` would trust.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The temporary path beside `target`: same directory (so the rename stays on
/// one file system), hidden, and tagged with the process id so two runs never
/// share it.
fn temporary_beside(target: &Path) -> PathBuf {
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    target.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `target` atomically: `fill` writes the whole content into a
/// temporary file beside it, which is renamed over `target` only when `fill`
/// and the flush succeeded. On any error the temporary file is removed and
/// `target` is left as it was.
pub fn write_atomically<F>(target: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let temporary = temporary_beside(target);
    let outcome = (|| {
        let file = File::create(&temporary).map_err(|e| Error::io(target, e))?;
        let mut writer = BufWriter::new(file);
        fill(&mut writer)?;
        let file = writer.into_inner().map_err(|e| Error::io(target, e.into_error()))?;
        file.sync_all().map_err(|e| Error::io(target, e))?;
        std::fs::rename(&temporary, target).map_err(|e| Error::io(target, e))
    })();
    if outcome.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    outcome
}

/// Writes `bytes` to `target` atomically.
pub fn write_bytes_atomically(target: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(target, |w| w.write_all(bytes).map_err(|e| Error::io(target, e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_fill_leaves_no_file_and_keeps_the_old_one() {
        let dir = std::env::temp_dir().join(format!("atomic-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.txt");
        write_bytes_atomically(&target, b"old").unwrap();
        let failed = write_atomically(&target, |w| {
            w.write_all(b"half").unwrap();
            Err(Error::invalid(&target, None, "stopped halfway"))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "temporary file left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

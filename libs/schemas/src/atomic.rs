//! Atomic file writes: write beside the target, flush, then rename, so a
//! killed stage never leaves a half-written file that `make` would trust.
//!
//! [`Staged`] is the first half alone: a complete file beside its target,
//! put in place by [`Staged::commit`]. A stage with several outputs stages
//! them all and commits them together (see `stage_kit::run::Outputs`).
//!
//! Every temporary file is removed on every path that can be caught: an
//! error or a panic (by [`Staged`]'s `Drop`), and an interrupt (SIGINT,
//! SIGTERM, SIGHUP: by [`remove_temporaries_on_interrupt`]'s handler).
//! Only SIGKILL, or a machine's crash, can leave one, hidden
//! (`.NAME.PID.tmp`) beside its target.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The temporary files of this process not yet committed or removed: what
/// the interrupt handler removes.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// [`PENDING`], usable even after a panic while it was held (a list of
/// paths cannot be left inconsistent).
fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// From now on, SIGINT, SIGTERM and SIGHUP remove this process's
/// temporary files, then end it with exit code 128 + the signal's number,
/// as the default action would have (the shell's convention), so that an
/// interrupted `make` leaves nothing hidden behind. Should the handler not
/// install, the default actions stay.
pub fn remove_temporaries_on_interrupt() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else { return };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Held until the exit: no temporary file is created or renamed
            // after these are removed (creations and renames take the list).
            let mut listed = pending();
            for path in listed.drain(..) {
                let _ = std::fs::remove_file(path);
            }
            std::process::exit(128 + signal);
        }
    });
}

/// The temporary path beside `target`: same directory (so the rename stays on
/// one file system), hidden, and tagged with the process id so two runs never
/// share it.
fn temporary_beside(target: &Path) -> PathBuf {
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    target.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// A file written completely beside its target, not yet in place. Dropped
/// without [`Staged::commit`] (an error, a panic), it removes its temporary
/// file, so every error path that unwinds leaves nothing behind.
#[derive(Debug)]
pub struct Staged {
    temporary: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl Staged {
    /// Writes the whole content of `target` into a temporary file beside it
    /// through `fill`, flushed and synced; `target` itself is untouched. On
    /// any error (a full disk, a file-size limit, `fill` failing) the
    /// temporary file is removed again.
    pub fn write<F>(target: &Path, fill: F) -> Result<Staged>
    where
        F: FnOnce(&mut BufWriter<File>) -> Result<()>,
    {
        let staged = Staged::beside(target);
        let file = {
            let _listed = pending();
            File::create(&staged.temporary)
        };
        let file = file.map_err(|e| Error::io(target, e))?;
        let mut writer = BufWriter::new(file);
        fill(&mut writer)?;
        let file = writer.into_inner().map_err(|e| Error::io(target, e.into_error()))?;
        file.sync_all().map_err(|e| Error::io(target, e))?;
        Ok(staged)
    }

    /// Stages `target` through `write`, which writes a complete file at the
    /// path it is given (the temporary one; writers such as
    /// [`crate::exr_io::write_exr`] write there atomically themselves). An
    /// error names `target`, not the temporary file, and removes the
    /// temporary file.
    pub fn written_by(target: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<Staged> {
        let staged = Staged::beside(target);
        write(&staged.temporary).map_err(|e| renamed(e, &staged.temporary, target))?;
        Ok(staged)
    }

    /// A temporary file for `target`, not yet created, registered for
    /// removal on interrupt.
    fn beside(target: &Path) -> Staged {
        let temporary = temporary_beside(target);
        pending().push(temporary.clone());
        Staged { temporary, target: target.to_path_buf(), committed: false }
    }

    /// The file's final path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Puts the file in place: renames it over its target (atomic on one
    /// file system). On failure the temporary file is removed.
    pub fn commit(mut self) -> Result<()> {
        // The list is held across the rename, so that an interrupt removes
        // the temporary file before it or nothing after it, never a file
        // just renamed.
        let renamed = {
            let mut pending = pending();
            let renamed = std::fs::rename(&self.temporary, &self.target);
            if renamed.is_ok() {
                pending.retain(|p| *p != self.temporary);
            }
            renamed
        };
        renamed.map_err(|e| Error::io(&self.target, e))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temporary);
            pending().retain(|p| *p != self.temporary);
        }
    }
}

/// `error` with the path `from` it names replaced by `to`.
fn renamed(error: Error, from: &Path, to: &Path) -> Error {
    let swap = |path: PathBuf| if path == from { to.to_path_buf() } else { path };
    match error {
        Error::Io { path, source } => Error::Io { path: swap(path), source },
        Error::Parse { path, line, message } => Error::Parse { path: swap(path), line, message },
        Error::Schema { path, what } => Error::Schema { path: swap(path), what },
        Error::Invalid { path, line, message } => Error::Invalid { path: swap(path), line, message },
    }
}

/// Writes `target` atomically: `fill` writes the whole content into a
/// temporary file beside it, which is renamed over `target` only when `fill`
/// and the flush succeeded. On any error the temporary file is removed and
/// `target` is left as it was.
pub fn write_atomically<F>(target: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    Staged::write(target, fill)?.commit()
}

/// Writes `bytes` to `target` atomically.
pub fn write_bytes_atomically(target: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(target, |w| w.write_all(bytes).map_err(|e| Error::io(target, e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("atomic-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn failed_fill_leaves_no_file_and_keeps_the_old_one() {
        let dir = scratch("fill");
        let target = dir.join("out.txt");
        write_bytes_atomically(&target, b"old").unwrap();
        let failed = write_atomically(&target, |w| {
            w.write_all(b"half").unwrap();
            Err(Error::invalid(&target, None, "stopped halfway"))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(names(&dir), ["out.txt"], "temporary file left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_staged_file_is_invisible_until_committed_and_gone_if_dropped() {
        let dir = scratch("staged");
        let target = dir.join("out.txt");
        write_bytes_atomically(&target, b"old").unwrap();
        let staged = Staged::write(&target, |w| w.write_all(b"new").map_err(|e| Error::io(&target, e))).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(names(&dir).len(), 2);
        drop(staged);
        assert_eq!(names(&dir), ["out.txt"]);
        Staged::write(&target, |w| w.write_all(b"new").map_err(|e| Error::io(&target, e))).unwrap().commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(names(&dir), ["out.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

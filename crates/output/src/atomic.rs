//! Atomic, no-clobber file writes: every output is written under a temporary name in its
//! directory and renamed into place; an existing file is replaced only with `--force`.
//!
//! The temporary files of writes in progress are registered, so that a process stopped by a
//! signal removes them ([`remove_temporaries`]) instead of leaving `.tmp-*` files behind.

use shpb_input::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The temporary files of the writes in progress in this process.
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes the temporary file of every write in progress and returns a guard that keeps any
/// write from being renamed into place (or a new one from starting) while it is held: what a
/// process stopped by SIGINT/SIGTERM calls just before it exits, so that it leaves neither a
/// temporary file nor a half-finished output.
pub fn remove_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    let mut held = temporaries();
    for tmp in held.drain(..) {
        let _ = std::fs::remove_file(tmp);
    }
    held
}

/// Refuses to overwrite `path` unless `force`.
pub fn check_output(path: &Path, force: bool) -> Result<()> {
    if path.exists() && !force {
        return Err(Error::OutputExists(path.to_path_buf()));
    }
    Ok(())
}

/// Writes a file through `write` to a temporary name beside `path`, then renames it into place;
/// on failure the temporary file is removed, so no half-written output is left.
pub fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    check_output(path, force)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    // The temporary name keeps the extension (plotters picks the image format from it).
    let tmp: PathBuf = dir.join(format!(".tmp-{}-{name}", std::process::id()));
    temporaries().push(tmp.clone());
    let result = write(&tmp).and_then(|_| {
        // Renamed under the lock: a signal handler's `remove_temporaries` comes before or after.
        let mut held = temporaries();
        held.retain(|t| t != &tmp);
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    });
    if result.is_err() {
        temporaries().retain(|t| t != &tmp);
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `text` to `path` atomically (refusing to overwrite without `force`).
pub fn write_text_atomically(path: &Path, force: bool, text: &str) -> Result<()> {
    write_atomically(path, force, |tmp| {
        std::fs::write(tmp, text).map_err(|e| Error::io(path, e))
    })
}

//! Atomic, no-clobber file writes: every output is written under a temporary name in its
//! directory and renamed into place; an existing file is replaced only with `--force`.

use shpb_input::{Error, Result};
use std::path::{Path, PathBuf};

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
    let result =
        write(&tmp).and_then(|_| std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e)));
    if result.is_err() {
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

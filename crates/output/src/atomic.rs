//! Atomic, no-clobber file writes: every output is written under a temporary name in its
//! directory and moved into place; an existing file is replaced only with `--force`. Without
//! `--force` the move is a hard link (which fails if the name exists, so of two runs writing
//! the same file at once exactly one succeeds) followed by removing the temporary name.
//!
//! The temporary files of writes in progress are registered, so that a process stopped by a
//! signal removes them ([`remove_temporaries`]) instead of leaving `.tmp-*` files behind.

use shpb_input::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The temporary files of the writes in progress in this process.
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes the temporary file of every write in progress and returns a guard that keeps any
/// write from being moved into place (or a new one from starting) while it is held: what a
/// process stopped by SIGINT/SIGTERM calls just before it exits, so that it leaves neither a
/// temporary file nor a half-finished output.
pub fn remove_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    let mut held = temporaries();
    for tmp in held.drain(..) {
        let _ = std::fs::remove_file(tmp);
    }
    held
}

/// The directory a file is written in (`.` for a bare name).
fn directory_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// An input error about the output path given by `flag` (exit code 2).
fn bad_output(flag: &str, problem: String, allowed: &str) -> Error {
    Error::Input {
        file: "command line".into(),
        key: flag.into(),
        problem,
        allowed: allowed.into(),
    }
}

/// Refuses an output that cannot be written before anything is computed: `path` is a
/// directory, its directory does not exist or is not writable, or it exists and not `force`.
pub fn check_output(path: &Path, force: bool) -> Result<()> {
    check_output_flag(path, force, "output")
}

/// Bytes free for an unprivileged user on the file system of `dir` (`statvfs`).
pub fn free_space(dir: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: `c` is a valid NUL-terminated path and `s` a valid out-pointer.
    let mut s: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c.as_ptr(), &mut s) } != 0 {
        return None;
    }
    Some((s.f_bavail as u64).saturating_mul(s.f_frsize as u64))
}

/// Whether `path` is `-`: the output goes to standard output.
pub fn is_stdout(path: &Path) -> bool {
    path == Path::new("-")
}

/// [`check_output`], naming the command-line `flag` that gave the path in its errors.
pub fn check_output_flag(path: &Path, force: bool, flag: &str) -> Result<()> {
    if is_stdout(path) {
        return Ok(());
    }
    let allowed = "a file name in an existing, writable directory";
    if path.is_dir() {
        return Err(bad_output(
            flag,
            format!("{} is a directory", path.display()),
            allowed,
        ));
    }
    let dir = directory_of(path);
    if !dir.is_dir() {
        return Err(bad_output(
            flag,
            format!("directory {} does not exist", dir.display()),
            allowed,
        ));
    }
    if path.exists() && !force {
        return Err(Error::OutputExists(path.to_path_buf()));
    }
    // Writable? Create and remove a probe file (permission bits do not tell for root or ACLs).
    let probe = dir.join(format!(".shpb-probe-{}-{}", std::process::id(), unique()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(bad_output(
            flag,
            format!("cannot write in directory {}: {e}", dir.display()),
            allowed,
        )),
    }
}

/// [`check_output_flag`] and then [`check_extension`]: every check of an output path given by
/// `flag` that needs no knowledge of the run's inputs.
pub fn check_output_path(path: &Path, force: bool, flag: &str, extensions: &[&str]) -> Result<()> {
    check_output_flag(path, force, flag)?;
    check_extension(path, flag, extensions)
}

/// Refuses an output whose extension is not one of `extensions` (lower case, without dot).
pub fn check_extension(path: &Path, flag: &str, extensions: &[&str]) -> Result<()> {
    if is_stdout(path) {
        return Ok(());
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if extensions.contains(&ext.as_str()) {
        return Ok(());
    }
    Err(bad_output(
        flag,
        format!("{}: unknown extension `{ext}`", path.display()),
        &format!(
            "a file name ending in {}",
            extensions
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    ))
}

/// Refuses an output that is one of the run's inputs (the same file, by any name), even with
/// `--force`: an output may never replace what it was computed from.
pub fn check_not_input(path: &Path, flag: &str, inputs: &[PathBuf]) -> Result<()> {
    if is_stdout(path) {
        return Ok(());
    }
    let Some(out) = canonical_target(path) else {
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            return Err(bad_output(
                flag,
                format!(
                    "{} is an input of this run ({})",
                    path.display(),
                    input.display()
                ),
                "an output path that is not one of the inputs",
            ));
        }
    }
    Ok(())
}

/// The canonical path `path` would have once written (its directory resolved), if it has one.
fn canonical_target(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    let dir = std::fs::canonicalize(directory_of(path)).ok()?;
    Some(dir.join(path.file_name()?))
}

/// A number unique within this process, for temporary names.
fn unique() -> usize {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Writes a file through `write` to a temporary name beside `path`, then renames it into place;
/// on failure the temporary file is removed, so no half-written output is left.
pub fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if is_stdout(path) {
        return write_to_stdout(write);
    }
    check_output(path, force)?;
    let dir = directory_of(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    // The temporary name keeps the extension (plotters picks the image format from it).
    let tmp: PathBuf = dir.join(format!(".tmp-{}-{}-{name}", std::process::id(), unique()));
    temporaries().push(tmp.clone());
    let result = write(&tmp).and_then(|_| {
        // Moved under the lock: a signal handler's `remove_temporaries` comes before or after.
        let mut held = temporaries();
        held.retain(|t| t != &tmp);
        move_into_place(&tmp, path, force)
    });
    temporaries().retain(|t| t != &tmp);
    let _ = std::fs::remove_file(&tmp);
    result
}

/// Writes through `write` to a temporary file, then copies it to standard output (a closed
/// pipe is not an error).
fn write_to_stdout(write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    use std::io::Write;
    // The `.png` ending lets plotters choose its format; HDF5 and CSV writers ignore it.
    let tmp = std::env::temp_dir().join(format!(
        ".shpb-stdout-{}-{}.png",
        std::process::id(),
        unique()
    ));
    temporaries().push(tmp.clone());
    let result = write(&tmp).and_then(|_| {
        let bytes = std::fs::read(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut out = std::io::stdout().lock();
        match out.write_all(&bytes).and_then(|_| out.flush()) {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                Err(Error::io(Path::new("stdout"), e))
            }
            _ => Ok(()),
        }
    });
    temporaries().retain(|t| t != &tmp);
    let _ = std::fs::remove_file(&tmp);
    result
}

/// Moves the finished temporary file to `path`: a rename with `force`; otherwise a hard link,
/// which fails if `path` exists (another writer got there first), then the temporary name is
/// removed by the caller. On a file system without hard links, an existence check and a rename.
fn move_into_place(tmp: &Path, path: &Path, force: bool) -> Result<()> {
    if force {
        return std::fs::rename(tmp, path).map_err(|e| Error::io(path, e));
    }
    match std::fs::hard_link(tmp, path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            Err(Error::OutputExists(path.to_path_buf()))
        }
        Err(_) if !path.exists() => std::fs::rename(tmp, path).map_err(|e| Error::io(path, e)),
        Err(_) => Err(Error::OutputExists(path.to_path_buf())),
    }
}

/// Writes `text` to `path` atomically (refusing to overwrite without `force`).
pub fn write_text_atomically(path: &Path, force: bool, text: &str) -> Result<()> {
    write_atomically(path, force, |tmp| {
        std::fs::write(tmp, text).map_err(|e| Error::io(path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("shpb-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn of_concurrent_writers_without_force_exactly_one_wins() {
        let dir = temp_dir("race");
        for trial in 0..20 {
            let path = dir.join(format!("out-{trial}.txt"));
            let wins: usize = std::thread::scope(|s| {
                let handles: Vec<_> = (0..4)
                    .map(|k| {
                        let path = path.clone();
                        s.spawn(move || {
                            write_atomically(&path, false, |tmp| {
                                // Slow writers: all of them pass the early existence check.
                                std::thread::sleep(std::time::Duration::from_millis(5));
                                std::fs::write(tmp, format!("writer {k}"))
                                    .map_err(|e| Error::io(tmp, e))
                            })
                            .is_ok() as usize
                        })
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).sum()
            });
            assert_eq!(wins, 1, "trial {trial}: {wins} writers reported success");
        }
        // No temporary file is left behind.
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn output_paths_are_checked_before_anything_is_computed() {
        let dir = temp_dir("paths");
        let msg = |r: Result<()>| r.unwrap_err().to_string();
        assert!(msg(check_output_flag(&dir, true, "-o")).contains("is a directory"));
        let nowhere = dir.join("no/such/dir/out.h5");
        assert!(msg(check_output_flag(&nowhere, false, "-o")).contains("does not exist"));
        assert!(check_output_flag(&dir.join("out.h5"), false, "-o").is_ok());
        let e = msg(check_extension(&dir.join("out.hdf"), "-o", &["h5", "hdf5"]));
        assert!(e.contains(".h5 or .hdf5"), "{e}");
        assert!(check_extension(&dir.join("OUT.H5"), "-o", &["h5"]).is_ok());
        // An output may not be an input, whatever it is called.
        let scene = dir.join("scene.toml");
        std::fs::write(&scene, "kind = \"collision\"\n").unwrap();
        let other_name = dir.join("sub/../scene.toml");
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let e = msg(check_not_input(
            &other_name,
            "-o",
            std::slice::from_ref(&scene),
        ));
        assert!(e.contains("is an input of this run"), "{e}");
        assert!(check_not_input(&dir.join("run.h5"), "-o", &[scene]).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

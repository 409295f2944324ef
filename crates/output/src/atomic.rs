//! Atomic, no-clobber file writes: every output is written under a temporary name in its
//! directory and moved into place; an existing file is replaced only with `--force`. Without
//! `--force` the move is a hard link (which fails if the name exists, so of two runs writing
//! the same file at once exactly one succeeds) followed by removing the temporary name.
//!
//! The temporary files of writes in progress (`.shpb-tmp-<pid>-…`, created with `O_EXCL`) are
//! registered, so that a process stopped by a signal removes them ([`remove_temporaries`])
//! instead of leaving them behind. Inside an output plan ([`crate::plan`]) the moves wait until
//! every output of the command is complete and are then made together (`commit`).

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
/// temporary file nor a half-finished output. The guard still lists the names removed: a writer
/// on another thread (the HDF5 library's create, say) may make its file again after the
/// removal, so the caller removes them once more just before it exits.
pub fn remove_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    let held = temporaries();
    for tmp in held.iter() {
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
    let name = path.file_name().unwrap_or_default();
    let name_max = name_max(dir);
    if name.len() > name_max {
        return Err(bad_output(
            flag,
            format!(
                "the file name {} is {} bytes long; the file system of {} allows {name_max}",
                path.display(),
                name.len(),
                dir.display()
            ),
            &format!("a file name of at most {name_max} bytes"),
        ));
    }
    if name
        .as_encoded_bytes()
        .starts_with(TEMPORARY_PREFIX.as_bytes())
        || name.as_encoded_bytes().starts_with(b".shpb-probe-")
    {
        return Err(bad_output(
            flag,
            format!(
                "{} has the form of shpb's temporary files, which another shpb removes",
                path.display()
            ),
            &format!("a file name not beginning with {TEMPORARY_PREFIX} or .shpb-probe-"),
        ));
    }
    // A symbolic link whose target does not exist: writing through it is not what was meant
    // and replacing it would lose the link.
    if let Ok(m) = std::fs::symlink_metadata(path)
        && m.file_type().is_symlink()
        && !path.exists()
    {
        return Err(bad_output(
            flag,
            format!(
                "{} is a symbolic link to a file that does not exist ({})",
                path.display(),
                std::fs::read_link(path)
                    .map(|t| t.display().to_string())
                    .unwrap_or_default()
            ),
            "a file name, or a link to an existing file (with --force)",
        ));
    }
    if std::fs::symlink_metadata(path).is_ok() && !force {
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

/// The longest file name the file system of `dir` takes (`pathconf(_PC_NAME_MAX)`, else 255).
fn name_max(dir: &Path) -> usize {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) else {
        return 255;
    };
    // SAFETY: `c` is a valid NUL-terminated path.
    let n = unsafe { libc::pathconf(c.as_ptr(), libc::_PC_NAME_MAX) };
    if n > 0 { n as usize } else { 255 }
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

/// How the name of every temporary file of shpb begins: `.shpb-tmp-<pid>-…`. An output may not
/// have such a name (another process would remove it as its own temporary).
pub const TEMPORARY_PREFIX: &str = ".shpb-tmp-";

/// A fresh temporary file beside `path`, created empty with `O_EXCL` (so a temporary name is
/// never a file this process did not create) and registered for removal on a signal. The name
/// keeps the output's extension (plotters picks the image format from it) but not its stem,
/// so a long output name does not make a longer temporary one.
fn new_temporary(dir: &Path, path: &Path) -> Result<PathBuf> {
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .filter(|e| e.len() <= 16)
        .unwrap_or_default();
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    loop {
        let tmp = dir.join(format!(
            "{TEMPORARY_PREFIX}{}-{}-{nanos:x}{ext}",
            std::process::id(),
            unique()
        ));
        let mut held = temporaries();
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(_) => {
                held.push(tmp.clone());
                return Ok(tmp);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(Error::io(path, e)),
        }
    }
}

/// Forgets and removes a temporary file of this process.
fn drop_temporary(tmp: &Path) {
    temporaries().retain(|t| t != tmp);
    let _ = std::fs::remove_file(tmp);
}

/// A finished temporary file waiting to be moved to its final name (`-`: standard output).
#[derive(Debug)]
pub(crate) struct Pending {
    pub(crate) tmp: PathBuf,
    pub(crate) path: PathBuf,
    pub(crate) force: bool,
}

thread_local! {
    /// The finished temporaries of the output plan open on this thread ([`crate::plan`]):
    /// while it is `Some`, [`write_atomically`] leaves its file under the temporary name.
    pub(crate) static DEFERRED: std::cell::RefCell<Option<Vec<Pending>>> =
        const { std::cell::RefCell::new(None) };
}

/// Writes a file through `write` to a temporary name beside `path`, then moves it into place;
/// on failure the temporary file is removed, so no half-written output is left. Inside an
/// output plan ([`crate::plan::OutputPlan::write`]) the move waits for the plan's other outputs.
pub fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    let deferred = DEFERRED.with(|d| d.borrow().is_some());
    let tmp = if is_stdout(path) {
        // The `.png` ending lets plotters choose its format; HDF5 and CSV writers ignore it.
        new_temporary(&std::env::temp_dir(), Path::new("stdout.png"))?
    } else {
        check_output(path, force)?;
        new_temporary(directory_of(path), path)?
    };
    test_pause(&format!("write:{}", path.display()));
    if let Err(e) = write(&tmp) {
        drop_temporary(&tmp);
        return Err(e);
    }
    let pending = Pending {
        tmp,
        path: path.to_path_buf(),
        force,
    };
    if deferred {
        DEFERRED.with(|d| d.borrow_mut().as_mut().map(|v| v.push(pending)));
        return Ok(());
    }
    commit(vec![pending], &mut |_| {})
}

/// Moves every finished temporary file to its final name, all or none: under the lock of the
/// temporaries, so a SIGINT/SIGTERM comes before the first move (and removes them all) or after
/// the last; an existing file replaced with `force` is kept under a temporary name until every
/// move has succeeded and put back if one fails. `wrote` is called for each output once all are
/// in place, still under the lock, so a stop cannot lose the report of a file written. Outputs
/// to standard output are copied last.
pub(crate) fn commit(pending: Vec<Pending>, wrote: &mut dyn FnMut(&Path)) -> Result<()> {
    let mut held = temporaries();
    let mut done: Vec<(&Pending, Option<PathBuf>)> = Vec::new();
    let mut result = Ok(());
    let files: Vec<&Pending> = pending.iter().filter(|p| !is_stdout(&p.path)).collect();
    // Several files: what the moves are is written down first, so that a process killed by
    // SIGKILL among them has its moves completed by the next plan writing there.
    let journal = (files.len() > 1).then(|| write_journal(&files)).transpose();
    let journal = match journal {
        Ok(j) => j,
        Err(e) => {
            drop(held);
            discard(pending);
            return Err(e);
        }
    };
    for (k, p) in files.iter().enumerate() {
        // A file replaced with --force is first kept under a temporary name.
        let backup = (p.force && std::fs::symlink_metadata(&p.path).is_ok())
            .then(|| p.tmp.with_extension("old"))
            .filter(|b| std::fs::hard_link(&p.path, b).is_ok());
        if let Some(b) = &backup {
            held.push(b.clone());
        }
        if let Err(e) = move_into_place(&p.tmp, &p.path, p.force) {
            if let Some(b) = &backup {
                let _ = std::fs::remove_file(b);
            }
            result = Err(e);
            break;
        }
        done.push((p, backup));
        test_pause(&format!("commit:{}", k + 1));
    }
    if result.is_err() {
        // Undo the moves made: the old file back, or the new name removed.
        for (p, backup) in done.drain(..).rev() {
            match backup {
                Some(b) => {
                    let _ = std::fs::rename(&b, &p.path);
                }
                None => {
                    let _ = std::fs::remove_file(&p.path);
                }
            }
        }
    }
    if result.is_ok() {
        for p in pending.iter().filter(|p| is_stdout(&p.path)) {
            if let Err(e) = copy_to_stdout(&p.tmp) {
                result = Err(e);
                break;
            }
        }
    }
    if result.is_ok() {
        for p in &pending {
            wrote(&p.path);
        }
    }
    for (_, backup) in &done {
        if let Some(b) = backup {
            let _ = std::fs::remove_file(b);
        }
    }
    for p in &pending {
        let _ = std::fs::remove_file(&p.tmp);
    }
    if let Some(j) = &journal {
        let _ = std::fs::remove_file(j);
    }
    held.retain(|t| {
        !pending.iter().any(|p| &p.tmp == t) && !done.iter().any(|(_, b)| b.as_ref() == Some(t))
    });
    result
}

/// The journal of a commit of several files: beside the first, named as a temporary of this
/// process with the ending `.journal`, one line per file: `force` (0 or 1), the temporary and
/// the final name, absolute, their bytes in hex.
fn write_journal(files: &[&Pending]) -> Result<PathBuf> {
    let first = files[0];
    let journal = first.tmp.with_extension("journal");
    let hex = |p: &Path| -> String {
        let absolute = std::fs::canonicalize(directory_of(p))
            .map(|d| d.join(p.file_name().unwrap_or_default()))
            .unwrap_or_else(|_| p.to_path_buf());
        absolute
            .as_os_str()
            .as_encoded_bytes()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    };
    let text: String = files
        .iter()
        .map(|p| format!("{} {} {}\n", p.force as u8, hex(&p.tmp), hex(&p.path)))
        .collect();
    let written = std::fs::File::create_new(&journal).and_then(|mut f| {
        use std::io::Write;
        f.write_all(text.as_bytes())?;
        f.sync_all()
    });
    if let Err(e) = written {
        let _ = std::fs::remove_file(&journal);
        return Err(Error::io(&first.path, e));
    }
    Ok(journal)
}

/// Completes the commit whose `journal` a process killed among its moves left: every
/// temporary still there is moved to its final name (replacing it where the commit had
/// `--force`), then the journal is removed.
pub(crate) fn roll_forward(journal: &Path) {
    use std::os::unix::ffi::OsStringExt;
    let Ok(text) = std::fs::read_to_string(journal) else {
        return;
    };
    let path = |h: &str| -> Option<PathBuf> {
        let bytes: Option<Vec<u8>> = (0..h.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(h.get(i..i + 2)?, 16).ok())
            .collect();
        Some(PathBuf::from(std::ffi::OsString::from_vec(bytes?)))
    };
    for line in text.lines() {
        let mut f = line.split(' ');
        let (Some(force), Some(tmp), Some(path)) =
            (f.next(), f.next().and_then(path), f.next().and_then(path))
        else {
            continue;
        };
        if std::fs::symlink_metadata(&tmp).is_ok() {
            let _ = move_into_place(&tmp, &path, force == "1");
            let _ = std::fs::remove_file(&tmp);
        }
    }
    let _ = std::fs::remove_file(journal);
}

/// Removes finished temporaries that will not be committed (a plan that failed).
pub(crate) fn discard(pending: Vec<Pending>) {
    for p in pending {
        drop_temporary(&p.tmp);
    }
}

/// Copies a finished temporary file to standard output (a closed pipe is not an error).
fn copy_to_stdout(tmp: &Path) -> Result<()> {
    use std::io::Write;
    let bytes = std::fs::read(tmp).map_err(|e| Error::io(tmp, e))?;
    let mut out = std::io::stdout().lock();
    match out.write_all(&bytes).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

/// Tests only (feature `test-hooks`): stops for `SHPB_TEST_PAUSE_S` seconds (default 30) at
/// the output step named by `SHPB_TEST_PAUSE_AT` (`write:PATH` before an output's temporary is
/// written, `commit:K` after the K-th move into place), announced on stderr as
/// `shpb-test: paused at STEP`, so a test can stop the process there.
#[cfg(feature = "test-hooks")]
pub fn test_pause(step: &str) {
    if std::env::var_os("SHPB_TEST_PAUSE_AT").is_some_and(|s| s == step) {
        let seconds = std::env::var("SHPB_TEST_PAUSE_S")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(30.0);
        eprintln!("shpb-test: paused at {step}");
        std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
    }
}

/// Without the feature `test-hooks`: nothing.
#[cfg(not(feature = "test-hooks"))]
#[inline(always)]
pub fn test_pause(_step: &str) {}

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
        Err(_) if std::fs::symlink_metadata(path).is_err() => {
            std::fs::rename(tmp, path).map_err(|e| Error::io(path, e))
        }
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

//! The output plan of a command: every file a command writes, checked together before anything
//! is computed and written together, all or none.
//!
//! Before the run ([`OutputPlan::new`], [`OutputPlan::not_inputs`], [`OutputPlan::check_space`]):
//! each path is checked ([`crate::atomic::check_output_path`]: directory, extension, an existing
//! file without `--force`, a dangling symbolic link, a name too long for its file system, the
//! form of shpb's temporary names), no file is given twice, at most one output is `-`, no output
//! is one of the inputs (even with `--force`) and the outputs together fit in the space free on
//! each file system. After the run ([`OutputPlan::write`]): every output is written under a
//! temporary name of its own (created with `O_EXCL`), and only when all are complete are they
//! moved into place together, under the lock a SIGINT/SIGTERM takes first
//! ([`crate::atomic::remove_temporaries`]); a failure (a full disk, an error, a name taken by a
//! concurrent writer) removes every temporary file and restores what was replaced, so no final
//! name is touched. Temporary files left by a process killed with SIGKILL (`.shpb-tmp-<pid>-…`
//! of a process that no longer runs) are removed by the next plan writing in that directory; a
//! process killed among the moves of its commit (after every file was complete) left a journal
//! of them, and that next plan completes the moves first ([`crate::atomic`]'s `roll_forward`).

use crate::atomic::{self, Pending, TEMPORARY_PREFIX, is_stdout};
use shpb_input::{Error, Result};
use std::path::{Path, PathBuf};

/// One output of a plan: its path and the command-line flag that named it.
#[derive(Debug, Clone)]
pub struct Planned {
    /// Where it goes (`-`: standard output).
    pub path: PathBuf,
    /// The flag that gave it (`--output`, `--csv`, …), named in errors.
    pub flag: String,
}

/// Every output of one command ([module documentation](self)).
#[derive(Debug, Clone)]
pub struct OutputPlan {
    force: bool,
    outputs: Vec<Planned>,
}

/// An input error about the command line (exit code 2).
fn bad(flag: &str, problem: String, allowed: &str) -> Error {
    Error::Input {
        file: "command line".into(),
        key: flag.into(),
        problem,
        allowed: allowed.into(),
    }
}

impl OutputPlan {
    /// Checks every output given (`(path, flag, extensions)`; an empty `extensions` takes any)
    /// and that no two are the same file or both standard output.
    pub fn new(force: bool, outputs: &[(Option<&Path>, &str, &[&str])]) -> Result<OutputPlan> {
        let mut planned: Vec<Planned> = Vec::new();
        for &(path, flag, extensions) in outputs {
            let Some(path) = path else { continue };
            atomic::check_output_flag(path, force, flag)?;
            if !extensions.is_empty() {
                atomic::check_extension(path, flag, extensions)?;
            }
            for other in &planned {
                let same = if is_stdout(path) || is_stdout(&other.path) {
                    is_stdout(path) && is_stdout(&other.path)
                } else {
                    target(path) == target(&other.path)
                };
                if same && is_stdout(path) {
                    return Err(bad(
                        "-",
                        format!(
                            "standard output can take only one of: --json, one output `-` \
                             ({} and {} are both `-`)",
                            other.flag, flag
                        ),
                        "at most one output `-`, and not with --json",
                    ));
                }
                if same {
                    return Err(bad(
                        flag,
                        format!(
                            "{} is also the output of {}: one file cannot hold both",
                            path.display(),
                            other.flag
                        ),
                        "a different file for each output",
                    ));
                }
            }
            planned.push(Planned {
                path: path.to_path_buf(),
                flag: flag.to_string(),
            });
        }
        let plan = OutputPlan {
            force,
            outputs: planned,
        };
        for dir in plan.directories() {
            remove_stale_temporaries(&dir);
        }
        Ok(plan)
    }

    /// The outputs of the plan.
    pub fn outputs(&self) -> &[Planned] {
        &self.outputs
    }

    /// Whether one output goes to standard output (then nothing else may be printed there).
    pub fn to_stdout(&self) -> bool {
        self.outputs.iter().any(|o| is_stdout(&o.path))
    }

    /// Refuses an output `-` when `other` (e.g. `--json`) also prints on standard output.
    pub fn refuse_stdout_with(&self, other: Option<&str>) -> Result<()> {
        match (other, self.outputs.iter().find(|o| is_stdout(&o.path))) {
            (Some(other), Some(o)) => Err(bad(
                "-",
                format!(
                    "standard output can take only one of: --json, one output `-` ({} is `-` \
                     and {other} prints there)",
                    o.flag
                ),
                "at most one output `-`, and not with --json",
            )),
            _ => Ok(()),
        }
    }

    /// Refuses an output that is one of `inputs` (the same file by any name), even with force.
    pub fn not_inputs(&self, inputs: &[PathBuf]) -> Result<()> {
        for o in &self.outputs {
            atomic::check_not_input(&o.path, &o.flag, inputs)?;
        }
        Ok(())
    }

    /// Refuses outputs that will not fit: `bytes[i]` is the estimated size of the i-th output
    /// given to [`OutputPlan::new`] that is present (`None`: unknown, not counted); the sizes of
    /// all outputs on one file system are added and compared with the space free there.
    pub fn check_space(&self, bytes: &[Option<f64>]) -> Result<()> {
        use shpb_core::error::format_si;
        // (device, directory, total bytes, the outputs' names)
        let mut by_device: Vec<(u64, PathBuf, f64, Vec<String>)> = Vec::new();
        for (o, b) in self.outputs.iter().zip(bytes) {
            let Some(b) = b.filter(|b| *b > 0.0) else {
                continue;
            };
            if is_stdout(&o.path) {
                continue;
            }
            let dir = directory_of(&o.path);
            let Ok(m) = std::fs::metadata(&dir) else {
                continue;
            };
            let dev = std::os::unix::fs::MetadataExt::dev(&m);
            match by_device.iter_mut().find(|d| d.0 == dev) {
                Some(d) => {
                    d.2 += b;
                    d.3.push(o.path.display().to_string());
                }
                None => by_device.push((dev, dir, b, vec![o.path.display().to_string()])),
            }
        }
        for (_, dir, total, names) in by_device {
            if let Some(free) = atomic::free_space(&dir)
                && total > free as f64
            {
                return Err(bad(
                    &self
                        .outputs
                        .iter()
                        .find(|o| names.contains(&o.path.display().to_string()))
                        .map_or("output".into(), |o| o.flag.clone()),
                    format!(
                        "the outputs {} together need about {} but only {} are free there",
                        names.join(", "),
                        format_si(total, "B"),
                        format_si(free as f64, "B")
                    ),
                    "outputs on a file system with room for all of them, or a smaller run",
                ));
            }
        }
        Ok(())
    }

    /// Runs `write`, which writes the plan's outputs through the atomic writers of this crate
    /// (on this thread), then moves them into place together; `wrote` is called for each file
    /// in place (the command's `wrote PATH` line). On an error nothing is moved into place and
    /// every temporary file is removed.
    pub fn write(
        &self,
        write: impl FnOnce() -> Result<()>,
        mut wrote: impl FnMut(&Path),
    ) -> Result<()> {
        let outer = atomic::DEFERRED.with(|d| d.borrow_mut().replace(Vec::new()));
        let result = write();
        let pending: Vec<Pending> = atomic::DEFERRED
            .with(|d| std::mem::replace(&mut *d.borrow_mut(), outer))
            .unwrap_or_default();
        match result {
            Ok(()) => atomic::commit(pending, &mut wrote),
            Err(e) => {
                atomic::discard(pending);
                Err(e)
            }
        }
    }

    /// Whether `--force` was given.
    pub fn force(&self) -> bool {
        self.force
    }

    /// The directories the outputs go to (each once).
    fn directories(&self) -> Vec<PathBuf> {
        let mut dirs: Vec<PathBuf> = Vec::new();
        for o in self.outputs.iter().filter(|o| !is_stdout(&o.path)) {
            let d = directory_of(&o.path);
            if !dirs.contains(&d) {
                dirs.push(d);
            }
        }
        dirs
    }
}

/// The directory a file is written in (`.` for a bare name).
fn directory_of(path: &Path) -> PathBuf {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf()
}

/// Whether two paths name the same file once written (their directories resolved).
pub fn same_file(a: &Path, b: &Path) -> bool {
    !is_stdout(a) && !is_stdout(b) && target(a) == target(b)
}

/// The path a file will have: its directory resolved, the name kept.
fn target(path: &Path) -> PathBuf {
    std::fs::canonicalize(directory_of(path))
        .ok()
        .zip(path.file_name())
        .map_or_else(|| path.to_path_buf(), |(d, n)| d.join(n))
}

/// Removes the temporary files in `dir` of shpb processes that no longer run (killed by
/// SIGKILL while writing): `.shpb-tmp-<pid>-…` whose `<pid>` is not a process.
fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut stale: Vec<PathBuf> = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(TEMPORARY_PREFIX)) else {
            continue;
        };
        let Some(pid) = rest
            .split('-')
            .next()
            .and_then(|p| p.parse::<libc::pid_t>().ok())
        else {
            continue;
        };
        // SAFETY: kill with signal 0 only asks whether the process exists.
        let gone = unsafe { libc::kill(pid, 0) } != 0
            && std::io::Error::last_os_error().raw_os_error() == Some(libc::ESRCH);
        if gone {
            stale.push(e.path());
        }
    }
    // A commit killed among its moves is completed first, then what is left is removed.
    for journal in stale
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "journal"))
    {
        atomic::roll_forward(journal);
    }
    for p in &stale {
        let _ = std::fs::remove_file(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_of_a_plan_are_moved_into_place_together_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        let plan = OutputPlan::new(
            true,
            &[(Some(&a), "--csv", &["csv"]), (Some(&b), "--summary", &[])],
        )
        .unwrap();
        // The second output fails: the first, already complete, is not moved into place.
        let e = plan.write(
            || {
                atomic::write_text_atomically(&a, true, "new a")?;
                Err(Error::io(&b, std::io::Error::other("disk full")))
            },
            |_| panic!("nothing was written"),
        );
        assert!(e.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        let names = |d: &Path| {
            let mut v: Vec<String> = std::fs::read_dir(d)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        assert_eq!(names(dir.path()), ["a.csv", "b.csv"]);
        // Both succeed: both replaced, both reported.
        let mut reported = Vec::new();
        plan.write(
            || {
                atomic::write_text_atomically(&a, true, "new a")?;
                atomic::write_text_atomically(&b, true, "new b")
            },
            |p| reported.push(p.to_path_buf()),
        )
        .unwrap();
        assert_eq!(reported, [a.clone(), b.clone()]);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert_eq!(names(dir.path()), ["a.csv", "b.csv"]);
    }

    #[test]
    fn a_name_taken_during_the_run_undoes_the_moves_already_made() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
        let plan =
            OutputPlan::new(false, &[(Some(&a), "-o", &[]), (Some(&b), "--csv", &[])]).unwrap();
        let e = plan
            .write(
                || {
                    atomic::write_text_atomically(&a, false, "mine")?;
                    atomic::write_text_atomically(&b, false, "mine")?;
                    // A concurrent writer takes b before the commit.
                    std::fs::write(&b, "theirs").unwrap();
                    Ok(())
                },
                |_| {},
            )
            .unwrap_err();
        assert!(matches!(e, Error::OutputExists(_)), "{e}");
        assert!(!a.exists(), "a was moved into place although b failed");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "theirs");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_plan_refuses_a_file_twice_stdout_twice_and_names_of_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        let same = dir.path().join("sub/../a.csv");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = OutputPlan::new(
            false,
            &[(Some(&a), "--csv", &[]), (Some(&same), "--summary", &[])],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("also the output of --csv"), "{e}");
        let dash = Path::new("-");
        let e = OutputPlan::new(
            false,
            &[(Some(dash), "--csv", &[]), (Some(dash), "-o", &[])],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("standard output can take only one"), "{e}");
        let plan = OutputPlan::new(false, &[(Some(dash), "--csv", &[])]).unwrap();
        assert!(plan.to_stdout());
        assert!(plan.refuse_stdout_with(Some("--json")).is_err());
        let tmp = dir.path().join(".shpb-tmp-1-2-3.h5");
        let e = OutputPlan::new(false, &[(Some(&tmp), "-o", &[])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("temporary files"), "{e}");
        let long = dir.path().join(format!("{}.csv", "x".repeat(300)));
        let e = OutputPlan::new(false, &[(Some(&long), "--csv", &[])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("bytes long"), "{e}");
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(dir.path().join("nowhere/x.csv"), &link).unwrap();
        let e = OutputPlan::new(true, &[(Some(&link), "--csv", &[])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("symbolic link"), "{e}");
    }

    #[test]
    fn temporaries_of_a_process_that_no_longer_runs_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        // A pid above the kernel's maximum (4194304) is never a process.
        let stale = dir
            .path()
            .join(format!("{TEMPORARY_PREFIX}999999999-0-1.h5"));
        let ours = dir
            .path()
            .join(format!("{TEMPORARY_PREFIX}{}-0-1.h5", std::process::id()));
        std::fs::write(&stale, "").unwrap();
        std::fs::write(&ours, "").unwrap();
        OutputPlan::new(false, &[(Some(&dir.path().join("x.h5")), "-o", &[])]).unwrap();
        assert!(!stale.exists());
        assert!(ours.exists());
    }
}

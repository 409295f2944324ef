//! The outputs of one command are all-or-nothing (issue 42, category 2): a run's HDF5, CSV and
//! PNG are replaced together or not at all when the process is stopped by SIGINT, SIGTERM or
//! SIGKILL at any output step, or when the file system fills up between them; and a `wrote`
//! line is printed for every file in place, also under SIGTERM.
//!
//! The binary is stopped at each step through the pause points of `shpb_output::atomic::
//! test_pause` (`SHPB_TEST_PAUSE_AT=write:PATH` before an output's temporary file is written,
//! `commit:K` after the K-th of the final moves), compiled in by the feature `test-hooks` this
//! crate's dev-dependency turns on. Defects covered: 3 signals × 5 steps (the HDF5 beside the old
//! CSV, a missing `wrote` line, temporaries left), the full disk (the new HDF5 beside the old
//! CSV; the free space checked per file), and the SIGKILL among the moves (completed by the
//! next command writing there).

mod common;

use common::{repo_path, shpb, stderr};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use tempfile::TempDir;

/// The three outputs of one run, in the order the command writes them.
const NAMES: [&str; 3] = ["run.h5", "run.csv", "run.png"];

/// The old files, each holding the text `old`.
fn old_outputs(dir: &Path) {
    for n in NAMES {
        std::fs::write(dir.join(n), "old").unwrap();
    }
}

/// How many of the three outputs are still the old files.
fn old_count(dir: &Path) -> usize {
    NAMES
        .iter()
        .filter(|n| std::fs::read(dir.join(n)).is_ok_and(|b| b == b"old"))
        .count()
}

/// Names in `dir` other than the three outputs (temporary files left behind).
fn others(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !NAMES.contains(&n.as_str()) && n != "other.csv")
        .collect()
}

/// `shpb run` of a fast collision writing the three outputs over the old ones, stopped with
/// `signal` when paused at `step`; returns its exit status code (None: killed) and stderr.
fn stopped_run(dir: &Path, step: &str, signal: libc::c_int) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args([
            "run",
            &repo_path("scenes/collision-ss440c-5ms.toml"),
            "-o",
            "run.h5",
            "--csv",
            "run.csv",
            "--plot",
            "run.png",
            "--force",
        ])
        .env("SHPB_TEST_PAUSE_AT", step)
        .env("SHPB_TEST_PAUSE_S", "3")
        .env_remove("SHPB_MEMORY_LIMIT")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut text = String::new();
    let mut line = String::new();
    let mut paused = false;
    while err.read_line(&mut line).unwrap() > 0 {
        text.push_str(&line);
        if line.starts_with("shpb-test: paused at") {
            paused = true;
            // SAFETY: a signal to our own child process.
            unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        }
        line.clear();
    }
    let status = child.wait().unwrap();
    assert!(paused, "step {step} never reached:\n{text}");
    (status.code(), text)
}

#[test]
fn a_signal_at_any_output_step_leaves_the_old_outputs_or_all_the_new_ones() {
    let steps = [
        "write:run.h5",
        "write:run.csv",
        "write:run.png",
        "commit:1",
        "commit:2",
    ];
    for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGKILL] {
        for step in steps {
            let dir = TempDir::new().unwrap();
            old_outputs(dir.path());
            let (code, err) = stopped_run(dir.path(), step, signal);
            let old = old_count(dir.path());
            let what = format!("signal {signal} at {step}: exit {code:?}, stderr:\n{err}");
            if step.starts_with("write:") {
                // Stopped before the moves: every old file is still there, nothing else.
                assert_eq!(old, 3, "{what}");
                if signal != libc::SIGKILL {
                    assert_eq!(code, Some(128 + signal), "{what}");
                    assert!(
                        others(dir.path()).is_empty(),
                        "{:?} {what}",
                        others(dir.path())
                    );
                }
            } else if signal == libc::SIGKILL {
                // Killed among the moves: the next command writing there completes them.
                let next = shpb(
                    dir.path(),
                    &[
                        "run",
                        &repo_path("scenes/collision-ss440c-5ms.toml"),
                        "--csv",
                        "other.csv",
                    ],
                );
                assert!(next.status.success(), "{}", stderr(&next));
                assert_eq!(old_count(dir.path()), 0, "{what}");
            } else {
                // A stop during the moves waits for them: all new, every `wrote` line printed
                // (and the command may have finished before the stop is handled).
                assert_eq!(old, 0, "{what}");
                assert!(code == Some(128 + signal) || code == Some(0), "{what}");
                for n in NAMES {
                    assert!(err.contains(&format!("wrote {n}")), "{n}: {what}");
                }
            }
            // The stopped process's temporaries are gone (after a SIGKILL, removed by the next
            // command writing in the directory).
            if signal == libc::SIGKILL && step.starts_with("write:") {
                let next = shpb(
                    dir.path(),
                    &[
                        "run",
                        &repo_path("scenes/collision-ss440c-5ms.toml"),
                        "--csv",
                        "other.csv",
                    ],
                );
                assert!(next.status.success(), "{}", stderr(&next));
                assert_eq!(old_count(dir.path()), 3, "{what}");
            }
            assert!(
                others(dir.path()).is_empty(),
                "{:?} {what}",
                others(dir.path())
            );
        }
    }
}

/// Runs `script` (sh) as root of a new user and mount namespace, or None where the kernel does
/// not allow one.
fn in_namespace(script: &str) -> Option<std::process::Output> {
    let probe = Command::new("unshare")
        .args(["--user", "--map-root-user", "--mount", "true"])
        .output()
        .ok()?;
    if !probe.status.success() {
        return None;
    }
    Command::new("unshare")
        .args(["--user", "--map-root-user", "--mount", "sh", "-c", script])
        .output()
        .ok()
}

#[test]
fn a_file_system_that_fills_up_between_the_outputs_keeps_the_old_ones() {
    let dir = TempDir::new().unwrap();
    let mnt: PathBuf = dir.path().join("small");
    std::fs::create_dir(&mnt).unwrap();
    let bin = env!("CARGO_BIN_EXE_shpb");
    let scene = repo_path("scenes/collision-ss440c-5ms.toml");
    // A 64 MB file system (room for the run's estimated outputs) with the old outputs; the run passes the free-space check, writes
    // its HDF5 file, and the disk is filled while it is paused before the CSV.
    let script = format!(
        "set -e; mount -t tmpfs -o size=64m none '{m}'; cd '{m}'; \
         for n in run.h5 run.csv run.png; do printf old > $n; done; \
         SHPB_TEST_PAUSE_AT=write:run.csv SHPB_TEST_PAUSE_S=2 {bin} run '{scene}' -o run.h5 \
           --csv run.csv --plot run.png --force > /dev/null 2> ../err.txt & pid=$!; \
         while kill -0 $pid 2>/dev/null && ! grep -q 'paused at' ../err.txt; do sleep 0.05; done; \
         grep -q 'paused at' ../err.txt; \
         dd if=/dev/zero of=filler bs=64k 2>/dev/null || true; \
         set +e; wait $pid; echo \"exit=$?\"; rm filler; ls -a; \
         for n in run.h5 run.csv run.png; do printf \"%s=\" $n; head -c 3 $n; echo; done",
        m = mnt.display(),
    );
    let Some(out) = in_namespace(&script) else {
        println!(
            "skipped: this kernel does not let an unprivileged test mount a tmpfs (unshare \
             --user --map-root-user --mount failed)"
        );
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let err = std::fs::read_to_string(dir.path().join("err.txt")).unwrap_or_default();
    let what = format!(
        "stdout:\n{text}\nstderr:\n{}\nshpb's stderr:\n{err}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("exit=1"), "the CSV cannot be written: {what}");
    assert!(err.contains("No space left"), "{what}");
    for n in NAMES {
        assert!(text.contains(&format!("{n}=old")), "{n}: {what}");
    }
    assert!(!text.contains(".shpb-tmp-"), "a temporary was left: {what}");
    assert!(!err.contains("wrote "), "{what}");
}

#[test]
fn outputs_too_large_for_their_file_system_together_are_refused_before_the_run() {
    let dir = TempDir::new().unwrap();
    let mnt: PathBuf = dir.path().join("small");
    std::fs::create_dir(&mnt).unwrap();
    let bin = env!("CARGO_BIN_EXE_shpb");
    let scene = repo_path("scenes/collision-ss440c-5ms.toml");
    // The run's HDF5 file is about 95 kB and its CSV 170 kB: a 128 kB file system takes
    // neither with the other, and the refusal names both with their total.
    let script = format!(
        "set -e; mount -t tmpfs -o size=128k none '{m}'; cd '{m}'; set +e; \
         {bin} run '{scene}' -o run.h5 --csv run.csv; echo \"exit=$?\"; ls -a",
        m = mnt.display(),
    );
    let Some(out) = in_namespace(&script) else {
        println!("skipped: no unprivileged tmpfs mount on this kernel");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let what = format!("stdout:\n{text}\nstderr:\n{err}");
    assert!(text.contains("exit=2"), "{what}");
    assert!(
        err.contains("the outputs run.h5, run.csv together need about"),
        "{what}"
    );
    // Refused before the run: no summary, no file.
    assert!(
        !text.contains("restitution") && !text.contains("run.h5"),
        "{what}"
    );
    assert!(!text.contains(".shpb-tmp-"), "{what}");
}

#[test]
fn an_unwritable_directory_is_refused_before_the_run_even_for_root() {
    let dir = TempDir::new().unwrap();
    let mnt: PathBuf = dir.path().join("ro");
    std::fs::create_dir(&mnt).unwrap();
    let bin = env!("CARGO_BIN_EXE_shpb");
    let scene = repo_path("scenes/collision-ss440c-5ms.toml");
    // Root writes in a directory of mode 555; a read-only file system stops everyone.
    let script = format!(
        "set -e; mount -t tmpfs -o ro,size=1m none '{m}'; set +e; \
         {bin} run '{scene}' --csv '{m}/x.csv'; echo \"exit=$?\"",
        m = mnt.display(),
    );
    let Some(out) = in_namespace(&script) else {
        println!("skipped: no unprivileged tmpfs mount on this kernel");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(text.contains("exit=2"), "{text}\n{err}");
    assert!(err.contains("cannot write in directory"), "{err}");
    // Refused before the run: no summary was printed.
    assert!(!text.contains("restitution"), "{text}");
}

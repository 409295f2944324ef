//! Issue 15, the sweep items: a checkpoint and a study file record what they belong to and
//! `--resume` refuses anything else (item 1); `--resume` of a finished sweep says so and touches
//! nothing (item 2); a sweep that cannot finish on the machine is refused before anything is
//! allocated (item 6); `merge` refuses a missing or repeated shard (item 11); a `--set` key given
//! twice is an error (item 12); inputs are stored as SI numbers with units (item 15); a stopped
//! sweep removes its temporary files and says how to resume (item 20).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// A directory holding `scenes/x.toml` (the paper's SS440c test, which reads
/// `../bars/authors.toml` and its gauge file) and the scenes that name only built-ins.
fn workdir() -> tempfile::TempDir {
    let dir = tempfile::TempDir::new().unwrap();
    for sub in ["scenes", "bars"] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
    }
    std::fs::copy(
        repo().join("scenes/shpb-ss440c-10psi.toml"),
        dir.path().join("scenes/x.toml"),
    )
    .unwrap();
    for f in ["authors.toml", "gauges-authors.toml"] {
        std::fs::copy(repo().join("bars").join(f), dir.path().join("bars").join(f)).unwrap();
    }
    for f in ["quasistatic-fig2.toml", "collision-ss440c-5ms.toml"] {
        std::fs::copy(
            repo().join("scenes").join(f),
            dir.path().join("scenes").join(f),
        )
        .unwrap();
    }
    dir
}

fn shpb(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// The finished runs in a checkpoint (its lines after the `#` header).
fn checkpoint_rows(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .map(|t| t.lines().filter(|l| !l.starts_with('#')).count())
        .unwrap_or(0)
}

/// Starts `shpb args` in `dir`, waits until `ready()` holds, sends `signal` (SIGKILL, SIGINT,
/// SIGTERM) and returns what the process printed.
fn stopped(dir: &Path, args: &[&str], signal: i32, ready: impl Fn() -> bool) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "never ready: {args:?}"
        );
        std::thread::sleep(Duration::from_micros(500));
    }
    // SAFETY: a plain kill(2) of our own child.
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
    child.wait_with_output().unwrap()
}

/// The rows of a sweep file.
fn rows(path: &Path) -> Vec<shpb::sweep::RunSummary> {
    shpb::study_file::read_sweep_hdf5(path).unwrap().rows
}

/// Item 1: a checkpoint records the scene's content, the set-up files it resolves, the `--set`
/// values and the version; `--resume` after any of them changed is refused (exit 2) with what
/// differs, and leaves the checkpoint as it was.
#[test]
fn resume_refuses_a_checkpoint_of_another_scene_set_up_or_set() {
    let dir = workdir();
    let d = dir.path();
    let set = ["--set", "fidelity=fast", "--set", "pressure=7psi:22psi:150"];
    let args = |extra: &[&'static str]| {
        let mut a = vec!["sweep", "scenes/x.toml"];
        a.extend(set);
        a.extend(extra);
        a
    };
    let checkpoint = d.join("k.h5.partial.csv");
    let killed = stopped(d, &args(&["-o", "k.h5", "-j", "1"]), libc::SIGKILL, || {
        checkpoint_rows(&checkpoint) >= 2
    });
    assert_eq!(killed.status.code(), None, "killed before it finished");
    let kept = std::fs::read(&checkpoint).unwrap();
    let header = String::from_utf8_lossy(&kept).into_owned();
    for line in [
        "# scene_file: ",
        "# input_file: ",
        "bars/authors.toml",
        "# set: pressure=",
    ] {
        assert!(header.contains(line), "{line}: {header}");
    }

    let resume = args(&["-o", "k.h5", "--resume"]);
    let scene = d.join("scenes/x.toml");
    let original = std::fs::read_to_string(&scene).unwrap();
    // Another material in the scene.
    std::fs::write(&scene, original.replace("\"ss440c\"", "\"ss302\"")).unwrap();
    let o = shpb(d, &resume);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the content of the scene scenes/x.toml"),
        "{}",
        stderr(&o)
    );
    std::fs::write(&scene, &original).unwrap();
    // A set-up file the scene reads.
    let bars = d.join("bars/authors.toml");
    let setup = std::fs::read_to_string(&bars).unwrap();
    std::fs::write(&bars, setup.replace("length_m = 0.10", "length_m = 0.11")).unwrap();
    let o = shpb(d, &resume);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("bars/authors.toml"), "{}", stderr(&o));
    std::fs::write(&bars, &setup).unwrap();
    // Other swept values.
    let mut other = vec!["sweep", "scenes/x.toml", "--set", "fidelity=fast"];
    other.extend(["--set", "pressure=7psi:22psi:151", "-o", "k.h5", "--resume"]);
    let o = shpb(d, &other);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pressure=7psi:22psi:151"),
        "{}",
        stderr(&o)
    );
    // Refusals change nothing; the same sweep resumes and its file says what it belongs to.
    assert_eq!(std::fs::read(&checkpoint).unwrap(), kept);
    assert!(!d.join("k.h5").exists());
    let o = shpb(d, &resume);
    ok(&o);
    assert!(stderr(&o).contains("resuming"), "{}", stderr(&o));
    let file = shpb::study_file::read_sweep_hdf5(&d.join("k.h5")).unwrap();
    let id = file.identity.unwrap();
    assert_eq!(
        id.scene.sha256,
        shpb::provenance::sha256_hex(original.as_bytes())
    );
    assert!(
        id.inputs
            .iter()
            .any(|f| f.sha256 == shpb::provenance::sha256_hex(setup.as_bytes()))
    );
    assert_eq!((id.shard, id.runs_total), ((1, 1), 150));
    assert_eq!(file.rows.len(), 150);
}

/// Item 2: `--resume` of a finished sweep neither runs nor rewrites anything without `--force`;
/// it says the sweep is complete (from the HDF5 file, or a CSV alone).
#[test]
fn resume_of_a_finished_sweep_says_it_is_complete_and_keeps_its_files() {
    let dir = workdir();
    let d = dir.path();
    let base = [
        "sweep",
        "scenes/x.toml",
        "--set",
        "fidelity=fast",
        "--set",
        "pressure=7psi:22psi:4",
    ];
    let with = |extra: &[&'static str]| {
        let mut a = base.to_vec();
        a.extend(extra);
        a
    };
    ok(&shpb(d, &with(&["-o", "d.h5", "--csv", "d.csv"])));
    ok(&shpb(d, &with(&["--csv", "c.csv"])));
    let snapshot = |names: &[&str]| -> Vec<(Vec<u8>, std::time::SystemTime, u64)> {
        use std::os::unix::fs::MetadataExt;
        names
            .iter()
            .map(|n| {
                let m = std::fs::metadata(d.join(n)).unwrap();
                (
                    std::fs::read(d.join(n)).unwrap(),
                    m.modified().unwrap(),
                    m.ino(),
                )
            })
            .collect()
    };
    let before = snapshot(&["d.h5", "d.csv", "c.csv"]);
    std::thread::sleep(Duration::from_millis(20));
    for extra in [&["-o", "d.h5", "--csv", "d.csv"][..], &["--csv", "c.csv"]] {
        let mut a = with(extra);
        a.push("--resume");
        let o = shpb(d, &a);
        ok(&o);
        assert!(
            stderr(&o).contains("the sweep is complete"),
            "{}",
            stderr(&o)
        );
        assert!(!stderr(&o).contains("resuming"), "{}", stderr(&o));
        assert!(!stderr(&o).contains("wrote"), "{}", stderr(&o));
    }
    assert!(
        snapshot(&["d.h5", "d.csv", "c.csv"]) == before,
        "files untouched"
    );
    // A finished file of another sweep is not taken for this one.
    let o = shpb(
        d,
        &[
            "sweep",
            "scenes/x.toml",
            "--set",
            "fidelity=fast",
            "--set",
            "pressure=7psi:22psi:5",
            "-o",
            "d.h5",
            "--resume",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("another sweep"), "{}", stderr(&o));
    assert!(snapshot(&["d.h5"])[0] == before[0]);
    // With --force it runs again.
    let o = shpb(d, &with(&["-o", "d.h5", "--resume", "--force"]));
    ok(&o);
    assert!(stderr(&o).contains("wrote d.h5"), "{}", stderr(&o));
}

/// Item 6: a sweep of 10¹⁰ runs is refused before anything is allocated (under a 2 GB address
/// space limit, where the old code aborted), with the estimate and the limits.
#[test]
fn a_sweep_of_ten_billion_runs_is_refused_before_allocating() {
    let dir = workdir();
    let start = Instant::now();
    let o = Command::new("bash")
        .current_dir(dir.path())
        .args([
            "-c",
            "ulimit -v 2000000; exec \"$0\" sweep scenes/x.toml \
             --set pressure=7psi:22psi:100000 --set shaper.thickness=0.3mm:0.6mm:100000 -o big.h5",
            env!("CARGO_BIN_EXE_shpb"),
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(start.elapsed() < Duration::from_secs(10));
    let e = stderr(&o);
    for part in [
        "10000000000 runs",
        "of memory",
        "HDF5",
        "at most",
        "B per run",
        "free space in",
        "fewer values",
    ] {
        assert!(e.contains(part), "{part}: {e}");
    }
    assert!(e.contains("MemAvailable") || e.contains("cgroup"), "{e}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no file written"
    );
}

/// Item 11: merging one of two shards, or one shard twice, or shards of two sweeps fails with a
/// clear message; the two shards merge to the whole sweep.
#[test]
fn merge_refuses_a_missing_or_repeated_shard_and_another_sweep() {
    let dir = workdir();
    let d = dir.path();
    let sweep = |set: &'static str, extra: &[&'static str]| {
        let mut a = vec![
            "sweep",
            "scenes/x.toml",
            "--set",
            "fidelity=fast",
            "--set",
            set,
        ];
        a.extend(extra);
        shpb(d, &a)
    };
    let set = "pressure=7psi:22psi:5";
    ok(&sweep(set, &["-o", "whole.h5"]));
    ok(&sweep(set, &["--shard", "1/2", "-o", "s1.h5"]));
    ok(&sweep(set, &["--shard", "2/2", "-o", "s2.h5"]));
    ok(&sweep(
        "pressure=7psi:22psi:6",
        &["--shard", "2/2", "-o", "other2.h5"],
    ));
    for (inputs, problem) in [
        (&["s1.h5"][..], "shard 2/2 missing (2 of its 5 runs)"),
        (&["s2.h5"], "shard 1/2 missing (3 of its 5 runs)"),
        (&["s1.h5", "s1.h5"], "shard 1/2 is given twice"),
        (&["s1.h5", "s2.h5", "s2.h5"], "shard 2/2 is given twice"),
        (&["s1.h5", "other2.h5"], "not a shard of the same sweep"),
        (&["whole.h5", "s1.h5"], "split into 1"),
    ] {
        let mut args = vec!["merge"];
        args.extend(inputs);
        args.extend(["-o", "m.h5"]);
        let o = shpb(d, &args);
        assert_eq!(o.status.code(), Some(2), "{inputs:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(problem), "{inputs:?}: {}", stderr(&o));
        assert!(!d.join("m.h5").exists());
    }
    ok(&shpb(d, &["merge", "s2.h5", "s1.h5", "-o", "m.h5"]));
    assert_eq!(rows(&d.join("m.h5")), rows(&d.join("whole.h5")));
    let merged = shpb::study_file::read_sweep_hdf5(&d.join("m.h5")).unwrap();
    let whole = shpb::study_file::read_sweep_hdf5(&d.join("whole.h5")).unwrap();
    assert_eq!(merged.identity, whole.identity);
}

/// Item 12: a `--set` key given twice (also through an alias) is an error naming the key.
#[test]
fn a_set_key_given_twice_is_an_error_naming_it() {
    let dir = workdir();
    for set in [
        ["pressure=7psi,8psi", "pressure=9psi"],
        ["striker.pressure=7psi,8psi", "pressure=9psi"],
    ] {
        let o = shpb(
            dir.path(),
            &[
                "sweep",
                "scenes/x.toml",
                "--set",
                set[0],
                "--set",
                set[1],
                "-o",
                "p.h5",
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("`pressure` is set twice"), "{e}");
        assert!(e.contains(set[0]) && e.contains(set[1]), "{e}");
        assert!(!dir.path().join("p.h5").exists());
    }
}

/// Item 15: swept inputs are SI numbers with units in the HDF5 file (`units` attribute) and the
/// CSV (units in the column name); the values as written are kept beside them.
#[test]
fn sweep_inputs_are_stored_as_si_numbers_with_units() {
    let dir = workdir();
    let d = dir.path();
    ok(&shpb(
        d,
        &[
            "sweep",
            "scenes/x.toml",
            "--set",
            "pressure=7psi,10psi",
            "--set",
            "shaper.thickness=0.3mm",
            "--set",
            "fidelity=fast",
            "-o",
            "si.h5",
            "--csv",
            "si.csv",
        ],
    ));
    let psi = shpb::units::PSI_PA;
    let f = hdf5::File::open(d.join("si.h5")).unwrap();
    let units = |ds: &hdf5::Dataset| {
        ds.attr("units")
            .unwrap()
            .read_scalar::<hdf5::types::VarLenUnicode>()
            .unwrap()
            .as_str()
            .to_string()
    };
    let pressure = f.dataset("summary/inputs/pressure").unwrap();
    assert_eq!(pressure.read_raw::<f64>().unwrap(), [7.0 * psi, 10.0 * psi]);
    assert_eq!(units(&pressure), "Pa");
    let thickness = f.dataset("summary/inputs/shaper.thickness_m").unwrap();
    assert_eq!(thickness.read_raw::<f64>().unwrap(), [0.3e-3, 0.3e-3]);
    assert_eq!(units(&thickness), "m");
    let written = f
        .dataset("summary/inputs_as_written/pressure")
        .unwrap()
        .read_raw::<hdf5::types::VarLenUnicode>()
        .unwrap();
    assert_eq!(written[0].as_str(), "7psi");
    let run: f64 = f
        .attr_in("runs/1", "pressure")
        .unwrap_or_else(|| panic!("runs/1 pressure"));
    assert_eq!(run, 10.0 * psi);

    let csv = std::fs::read_to_string(d.join("si.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &head[..4],
        ["run", "pressure_Pa", "shaper.thickness_m", "fidelity"]
    );
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(first[1].parse::<f64>().unwrap(), 7.0 * psi);
    assert_eq!(first[2].parse::<f64>().unwrap(), 0.3e-3);
    assert_eq!(first[3], "fast");
}

/// A scalar attribute of a group, read as f64.
trait AttrIn {
    fn attr_in(&self, group: &str, name: &str) -> Option<f64>;
}

impl AttrIn for hdf5::File {
    fn attr_in(&self, group: &str, name: &str) -> Option<f64> {
        self.group(group).ok()?.attr(name).ok()?.read_scalar().ok()
    }
}

/// Item 20: SIGINT in the middle of the runs stops the sweep (exit 130) with the number of runs
/// kept and the exact command that resumes it, which does; SIGTERM while the output is being
/// written (from the first run on, issue 45) removes its temporary file (exit 143), and the sweep
/// resumes from there.
#[test]
fn a_stopped_sweep_removes_its_temporary_files_and_says_how_to_resume() {
    let dir = workdir();
    let d = dir.path();
    let args = [
        "sweep",
        "scenes/x.toml",
        "--set",
        "fidelity=fast",
        "--set",
        "pressure=7psi:22psi:150",
        "-o",
        "k.h5",
    ];
    let checkpoint = d.join("k.h5.partial.csv");
    let o = stopped(d, &args, libc::SIGINT, || checkpoint_rows(&checkpoint) >= 2);
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("shpb: stopped by SIGINT"), "{e}");
    assert!(
        e.contains("of 150 runs are done and kept in k.h5.partial.csv"),
        "{e}"
    );
    let command = format!("{} {} --resume", env!("CARGO_BIN_EXE_shpb"), args.join(" "));
    assert!(
        e.lines().any(|l| l.trim() == command),
        "resume command `{command}` in: {e}"
    );
    assert!(checkpoint_rows(&checkpoint) >= 2);
    let resumed = Command::new("sh")
        .current_dir(d)
        .args(["-c", &command])
        .output()
        .unwrap();
    ok(&resumed);
    assert!(
        stderr(&resumed).contains("resuming"),
        "{}",
        stderr(&resumed)
    );
    assert_eq!(rows(&d.join("k.h5")).len(), 150);

    // SIGTERM while the HDF5 file of 2000 quick runs is being written.
    let args = [
        "sweep",
        "scenes/quasistatic-fig2.toml",
        "--set",
        "max_displacement_m=100um:250um:2000",
        "--set",
        "points=11",
        "-j",
        "2",
        "-o",
        "q.h5",
    ];
    let temporary = || {
        std::fs::read_dir(d).unwrap().any(|e| {
            e.unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(".shpb-tmp-")
        })
    };
    // Since issue 45 the study file's run groups are written as the runs finish: the temporary
    // file is there from the first run on, and the runs done when it is stopped are those the
    // message names, all kept in the checkpoint, and no more are run on resuming.
    let o = stopped(d, &args, libc::SIGTERM, temporary);
    assert_eq!(o.status.code(), Some(143), "{}", stderr(&o));
    let e = stderr(&o);
    let done: usize = e
        .split(" of 2000 runs are done")
        .next()
        .and_then(|head| head.rsplit(|c: char| !c.is_ascii_digit()).next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("runs done in: {e}"));
    assert!(!temporary(), "the temporary file is removed");
    assert!(!d.join("q.h5").exists(), "no half-written output");
    assert_eq!(checkpoint_rows(&d.join("q.h5.partial.csv")), done);
    let mut again = args.to_vec();
    again.push("--resume");
    let o = shpb(d, &again);
    ok(&o);
    assert!(
        stderr(&o).contains(&format!(
            "resuming: {done} runs done, {} to go",
            2000 - done
        )),
        "{}",
        stderr(&o)
    );
    assert_eq!(rows(&d.join("q.h5")).len(), 2000);
    assert!(!temporary());
}

//! The run file is trustworthy (issue 15): outputs never clobber each other or an input, output
//! paths are checked before anything runs, a run file carries its provenance (scene, set-up and
//! every input read, command line, version) and its set-up, every value carries its unit, and
//! the file alone reruns the test with identical results.

mod common;

use common::{repo, shpb, stderr};
use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

/// A fast full test (`shpb` kind) on the authors' set-up with 12.7 mm bars instead of 19.05 mm.
fn small_bar_test(dir: &Path) -> PathBuf {
    let setup = std::fs::read_to_string(repo().join("bars/authors.toml"))
        .unwrap()
        .replace("diameter_m = 0.01905", "diameter_m = 0.0127");
    std::fs::write(dir.join("small.toml"), setup).unwrap();
    std::fs::copy(
        repo().join("bars/gauges-authors.toml"),
        dir.join("gauges-authors.toml"),
    )
    .unwrap();
    let scene = dir.join("test.toml");
    std::fs::write(
        &scene,
        "kind = \"shpb\"\nbars = \"small.toml\"\npressure = \"10psi\"\nfidelity = \"fast\"\n\
         [specimen]\npair = \"ss440c\"\n",
    )
    .unwrap();
    scene
}

/// `/summary` of a run file: (key, value, unit) from the per-value datasets (the group
/// `/summary/bands` holds the values' 90 % bands, docs/physics.md §10.6).
fn summary(path: &Path) -> Vec<(String, f64, String)> {
    let f = hdf5::File::open(path).unwrap();
    let s = f.group("summary").unwrap();
    let mut out = Vec::new();
    for name in s.member_names().unwrap() {
        if name == "bands" {
            continue;
        }
        let ds = s.dataset(&name).unwrap();
        let unit = ds
            .attr("units")
            .unwrap()
            .read_scalar::<VarLenUnicode>()
            .unwrap();
        out.push((name, ds.read_scalar::<f64>().unwrap(), unit.to_string()));
    }
    out
}

fn text_attr(loc: &hdf5::Location, name: &str) -> String {
    loc.attr(name)
        .unwrap()
        .read_scalar::<VarLenUnicode>()
        .unwrap()
        .to_string()
}

#[test]
fn reduce_of_a_run_file_uses_the_set_up_it_was_simulated_with() {
    let dir = TempDir::new().unwrap();
    small_bar_test(dir.path());
    let run = shpb(dir.path(), &["run", "test.toml", "-o", "run.h5"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let true_peak = summary(&dir.path().join("run.h5"))
        .into_iter()
        .find(|(k, _, _)| k == "peak_contact_force")
        .expect("peak_contact_force")
        .1;
    // Without --bars: the run's own 12.7 mm bars. The simulated bars do not disperse, so the
    // reduction recovers the true contact force within the 2 % of the round-trip test.
    let out = shpb(dir.path(), &["reduce", "run.h5", "-o", "red.h5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let f = hdf5::File::open(dir.path().join("red.h5")).unwrap();
    let back: Vec<f64> = f
        .dataset("reduction/force_back")
        .unwrap()
        .read_raw()
        .unwrap();
    let reduced = back.iter().cloned().fold(0.0, f64::max);
    assert!(
        (reduced - true_peak).abs() < 0.02 * true_peak,
        "reduced {reduced} N against true {true_peak} N"
    );
    // A different set-up is refused, naming both.
    let out = shpb(dir.path(), &["reduce", "run.h5", "--bars", "authors"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.contains("12.7") && e.contains("19.05") && e.contains("--bars"),
        "{e}"
    );
    // The same set-up named explicitly is accepted.
    let out = shpb(dir.path(), &["reduce", "run.h5", "--bars", "small.toml"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_run_file_alone_reruns_the_test_with_identical_results() {
    let dir = TempDir::new().unwrap();
    small_bar_test(dir.path());
    let run = shpb(
        dir.path(),
        &["run", "test.toml", "-o", "run.h5", "--fidelity", "fast"],
    );
    assert!(run.status.success(), "{}", stderr(&run));
    // Only the run file travels: no scene, no set-up, no gauge file.
    let elsewhere = TempDir::new().unwrap();
    std::fs::copy(dir.path().join("run.h5"), elsewhere.path().join("run.h5")).unwrap();
    drop(dir);
    let again = shpb(elsewhere.path(), &["run", "run.h5", "-o", "again.h5"]);
    assert!(again.status.success(), "{}", stderr(&again));
    let (a, b) = (
        summary(&elsewhere.path().join("run.h5")),
        summary(&elsewhere.path().join("again.h5")),
    );
    assert!(a.len() > 10);
    assert_eq!(a, b, "the rerun's summary differs");
    // The provenance names what was read and how.
    let f = hdf5::File::open(elsewhere.path().join("run.h5")).unwrap();
    let p = f.group("provenance").unwrap();
    assert_eq!(text_attr(&p, "scene_file"), "test.toml");
    assert_eq!(text_attr(&p, "fidelity_override"), "fast");
    assert!(text_attr(&p, "command_line").contains("run test.toml -o run.h5"));
    assert_eq!(text_attr(&p, "shpb_version"), env!("CARGO_PKG_VERSION"));
    let names: Vec<VarLenUnicode> = p.dataset("input_names").unwrap().read_raw().unwrap();
    let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    for expected in [
        "test.toml",
        "small.toml",
        "gauges-authors.toml",
        "built-in:specimens/ss440c.toml",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not in {names:?}"
        );
    }
    // Every time axis states its origin and its offset from /time.
    for axis in ["time", "contact/time", "reduction/time"] {
        let ds = f.dataset(axis).unwrap();
        assert!(!text_attr(&ds, "origin").is_empty(), "{axis}");
        let offset: f64 = ds
            .attr("offset_from_time_s")
            .unwrap()
            .read_scalar()
            .unwrap();
        assert!(offset.is_finite() && offset >= 0.0, "{axis}: {offset}");
    }
    // Each summary value carries its own unit.
    let units: std::collections::HashMap<String, String> =
        b.into_iter().map(|(k, _, u)| (k, u)).collect();
    assert_eq!(units["peak_contact_force"], "N");
    assert_eq!(units["pressure"], "Pa");
    assert_eq!(units["time_step"], "s");
}

#[test]
fn an_output_is_never_one_of_the_inputs() {
    let dir = TempDir::new().unwrap();
    // A TOML scene under an .h5 name, and the force CSV a force-driven scene reads.
    let fd = std::fs::read_to_string(repo().join("scenes/force-driven-ss440c-10psi.toml")).unwrap();
    let csv_key = fd
        .lines()
        .find(|l| l.starts_with("force_csv"))
        .expect("force_csv key")
        .to_string();
    let csv_rel = csv_key.split('"').nth(1).unwrap();
    std::fs::copy(
        repo().join("scenes").join(csv_rel),
        dir.path().join("force.csv"),
    )
    .unwrap();
    let scene = fd.replace(&csv_key, "force_csv = \"force.csv\"");
    std::fs::write(dir.path().join("scene.h5"), &scene).unwrap();
    let before = std::fs::read(dir.path().join("force.csv")).unwrap();
    for args in [
        &["run", "scene.h5", "-o", "scene.h5", "--force"][..],
        &["run", "scene.h5", "--csv", "force.csv", "--force"][..],
        &["run", "scene.h5", "--csv", "./sub/../force.csv", "--force"][..],
    ] {
        std::fs::create_dir_all(dir.path().join("sub")).unwrap();
        let out = shpb(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("is an input of this run"),
            "{}",
            stderr(&out)
        );
    }
    assert_eq!(
        std::fs::read_to_string(dir.path().join("scene.h5")).unwrap(),
        scene
    );
    assert_eq!(std::fs::read(dir.path().join("force.csv")).unwrap(), before);
}

#[test]
fn output_paths_are_refused_before_the_run_with_plain_messages() {
    let dir = TempDir::new().unwrap();
    let scene = repo().join("scenes/collision-ss440c-5ms.toml");
    let scene = scene.to_str().unwrap();
    std::fs::create_dir(dir.path().join("adir")).unwrap();
    for (args, needle) in [
        (vec!["run", scene, "-o", "adir"], "is a directory"),
        (
            vec!["run", scene, "-o", "no/such/dir/run.h5"],
            "does not exist",
        ),
        (vec!["run", scene, "-o", "run.hdf"], "unknown extension"),
        (vec!["run", scene, "--plot", "run.jpg"], ".png"),
        (vec!["run", scene, "--csv", "adir/../run.txt"], ".csv"),
    ] {
        let out = shpb(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let e = stderr(&out);
        assert!(e.contains(needle), "{args:?}: {e}");
        // Plain words, not library internals, and nothing ran (no summary on stdout).
        assert!(!e.contains("o_flags") && !e.contains("H5"), "{e}");
        assert!(out.stdout.is_empty(), "{args:?} ran");
    }
}

/// Every HDF5 file shpb writes (run, rerun, reduction, strain) reads with the HDF5 project's
/// own h5dump (Debian `hdf5-tools`, installed by `make deps`), as a user's tools would.
#[test]
fn h5dump_reads_every_output() {
    let dir = TempDir::new().unwrap();
    small_bar_test(dir.path());
    let record = repo().join("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let record = record.to_str().unwrap();
    for args in [
        &["run", "test.toml", "-o", "run.h5"][..],
        &["run", "run.h5", "-o", "again.h5"][..],
        &["reduce", "run.h5", "-o", "reduced-run.h5"][..],
        &["reduce", record, "-o", "reduced-record.h5"][..],
        &["strain", record, "-o", "strain.h5"][..],
    ] {
        let out = shpb(dir.path(), args);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    }
    for file in [
        "run.h5",
        "again.h5",
        "reduced-run.h5",
        "reduced-record.h5",
        "strain.h5",
    ] {
        let dump = Command::new("h5dump")
            .current_dir(dir.path())
            .args(["-H", file])
            .output()
            .expect("h5dump (Debian hdf5-tools; `make deps` installs it)");
        assert!(dump.status.success(), "h5dump {file}: {}", stderr(&dump));
        assert!(String::from_utf8_lossy(&dump.stdout).contains("GROUP \"/\""));
    }
}

//! Issue 45: the bars' x–t snapshots only when an output holds them (`shpb run -o`, `--plot`),
//! and the summary-only run mode (`shpb::run::Outputs::Summary`) of sweeps, studies, fits and
//! designs. The snapshots are written by a recorder that only reads the bars, so a run without
//! them must give every other series, the summary, the reduction and the warnings bit for bit.

mod common;
use common::{repo, repo_path, shpb, stderr, stdout};
use shpb::prelude::*;
use shpb::run::{Outputs, RunOutput};
use shpb::scene::Params;

/// Everything of a run output but its x–t snapshots must be equal (not close: the same
/// arithmetic runs with or without the snapshot recorder).
fn assert_same_but_snapshots(full: &RunOutput, summary: &RunOutput) {
    assert_eq!(full.summary, summary.summary);
    assert_eq!(full.reduction, summary.reduction);
    assert_eq!(full.warnings, summary.warnings);
    assert_eq!(full.gauges, summary.gauges);
    assert_eq!(full.energy, summary.energy);
    assert_eq!(full.contact, summary.contact);
    assert_eq!(full.time_s, summary.time_s);
    assert_eq!(full.specimen, summary.specimen);
    assert_eq!(full.cylinder_reduction, summary.cylinder_reduction);
    assert_eq!(full.chain, summary.chain);
    assert_eq!(full.drive, summary.drive);
}

/// `shpb run` without a run file or a figure records no x–t snapshots (`-q`, the summary table,
/// `--json`, `--csv`), with `-o` or `--plot` it does; the run without them gives the same
/// summary, reduction, series and warnings — on a sphere pair and on a cylinder at `fast`.
#[test]
fn run_without_outputs_records_no_snapshots() {
    for scene in [
        "scenes/shpb-ss440c-10psi.toml",
        "scenes/shpb-cylinder-copper.toml",
    ] {
        let path = repo().join(scene);
        let fast = Some(shpb::fidelity::Fidelity::Fast);
        let load = |run_file, figure| {
            shpb::cmd::run::load_for_outputs(&path, fast, &[], run_file, figure)
                .unwrap()
                .0
        };
        let summary_only = load(false, false);
        assert!(!summary_only.records_snapshots(), "{scene}");
        assert!(load(true, false).records_snapshots(), "{scene}: -o");
        assert!(load(false, true).records_snapshots(), "{scene}: --plot");
        let full = load(true, true);
        let (a, b) = (full.run().unwrap(), summary_only.run().unwrap());
        assert!(
            !a.bars.is_empty() && a.bars.iter().all(|b| !b.stress_pa.is_empty()),
            "{scene}: a run file holds the snapshots"
        );
        assert!(b.bars.is_empty(), "{scene}: {} fields", b.bars.len());
        assert_same_but_snapshots(&a, &b);
    }
}

/// The summary-only mode of the study runs (`Params::summary_only`) drops the snapshots of a
/// scene that asks for them and nothing else; `Outputs::Full` keeps the scene's.
#[test]
fn summary_only_runs_keep_everything_a_summary_reads() {
    let params = Params::from_file_overridden(
        &repo().join("scenes/shpb-ss440c-10psi.toml"),
        &[("fidelity".into(), shpb::scene::Value::String("fast".into()))],
    )
    .unwrap();
    assert!(params.records_snapshots());
    assert_eq!(params.clone().with_outputs(Outputs::Full), params);
    let summary = params.clone().summary_only();
    assert!(!summary.records_snapshots());
    assert_eq!(Outputs::for_files(false, false), Outputs::Summary);
    let (a, b) = (params.run().unwrap(), summary.run().unwrap());
    assert!(b.bars.is_empty() && !a.bars.is_empty());
    assert_same_but_snapshots(&a, &b);
}

/// On the command line: the summary `shpb run --json` prints without any file (no snapshots
/// recorded) is the one it prints while writing a run file, bands included; `-q` without any
/// output prints nothing and succeeds; the run file still holds every bar's snapshots.
#[test]
fn the_printed_summary_is_the_same_with_and_without_a_run_file() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = repo_path("scenes/shpb-ss440c-10psi.toml");
    let args = ["--json", "run", &scene, "--fidelity", "fast"];
    let bare = shpb(tmp.path(), &args);
    assert!(bare.status.success(), "{}", stderr(&bare));
    let with_file = shpb(tmp.path(), &[&args[..], &["-o", "r.h5"]].concat());
    assert!(with_file.status.success(), "{}", stderr(&with_file));
    let json = |o: &std::process::Output| -> serde_json::Value {
        serde_json::from_str(&stdout(o)).unwrap_or_else(|e| panic!("{e}: {}", stdout(o)))
    };
    let (a, b) = (json(&bare), json(&with_file));
    assert_eq!(a, b);
    assert!(
        a["summary"]["incident_peak_stress"]["band_90"].is_array(),
        "the bands are computed when shown: {a}"
    );
    let quiet = shpb(tmp.path(), &["-q", "run", &scene, "--fidelity", "fast"]);
    assert!(quiet.status.success(), "{}", stderr(&quiet));
    assert_eq!(stdout(&quiet), "");
    let run = shpb_output::run_file::read_run_file(&tmp.path().join("r.h5")).unwrap();
    for bar in ["striker", "incident", "transmission"] {
        let d = run
            .datasets
            .iter()
            .find(|d| d.path == format!("bars/{bar}/snapshots"))
            .unwrap_or_else(|| panic!("no bars/{bar}/snapshots"));
        assert!(
            d.shape.len() == 2 && d.data.iter().any(|&s| s != 0.0),
            "{bar}"
        );
    }
}

//! Issue 41 item 4: `shpb sweep` and `shpb design` keep every warning of their runs — the same
//! warnings `shpb run` prints for the same scene and values (a gun pressure outside the pressures
//! the gun and the shaper were calibrated at, bars/authors.toml: 10–15 psi) — in their tables
//! (CSV `warnings` column, JSON `warnings` per run) and files (the study file's
//! `/summary/warnings` and `/runs/<index>` attribute).

mod common;
use common::{repo_path, shpb, stderr, stdout};

const SCENE: &str = "scenes/shpb-ss440c-10psi.toml";

fn json(out: &std::process::Output) -> serde_json::Value {
    assert_eq!(out.status.code(), Some(0), "{}", stderr(out));
    serde_json::from_str(&stdout(out)).unwrap_or_else(|e| panic!("{e}: {}", stdout(out)))
}

fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .unwrap_or_else(|| panic!("not a list: {v}"))
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

/// The warnings `shpb run` gives the scene at `pressure` and `fidelity`.
fn run_warnings(dir: &std::path::Path, pressure: &str, fidelity: &str) -> Vec<String> {
    let set = format!("pressure={pressure}");
    let out = shpb(
        dir,
        &[
            "--json",
            "run",
            &repo_path(SCENE),
            "--set",
            &set,
            "--fidelity",
            fidelity,
            "--no-bands",
        ],
    );
    strings(&json(&out)["warnings"])
}

#[test]
fn a_sweep_keeps_its_runs_warnings_in_its_table_and_files() {
    let dir = tempfile::TempDir::new().unwrap();
    let outside = run_warnings(dir.path(), "8psi", "fast");
    let inside = run_warnings(dir.path(), "10psi", "fast");
    assert!(
        outside
            .iter()
            .any(|w| w.contains("gun pressure 8 psi is outside")),
        "{outside:?}"
    );
    assert!(inside.is_empty(), "{inside:?}");
    let out = shpb(
        dir.path(),
        &[
            "--json",
            "sweep",
            &repo_path(SCENE),
            "--set",
            "pressure=8psi,10psi",
            "--set",
            "fidelity=fast",
            "-o",
            "s.h5",
            "--csv",
            "s.csv",
        ],
    );
    let j = json(&out);
    assert_eq!(strings(&j["runs"][0]["warnings"]), outside);
    assert_eq!(strings(&j["runs"][1]["warnings"]), inside);
    // The CSV: a last `warnings` column, the run's warnings joined by " | ", quoted (they hold
    // commas).
    let csv = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].ends_with(",warnings"), "{}", lines[0]);
    let cells = shpb::sweep::split_csv_line(lines[1]);
    assert_eq!(cells.last().unwrap(), &outside.join(" | "));
    assert!(
        lines[2].ends_with(','),
        "no warning: an empty cell: {}",
        lines[2]
    );
    // The study file, and a merge of it, keep them one per line.
    let table = shpb_output::study::read_study_hdf5(&dir.path().join("s.h5")).unwrap();
    assert_eq!(table.warnings, [outside.join("\n"), String::new()]);
    let file = shpb::study_file::read_sweep_hdf5(&dir.path().join("s.h5")).unwrap();
    assert_eq!(file.rows[0].warnings, outside);
}

#[test]
fn a_design_keeps_its_runs_warnings() {
    let dir = tempfile::TempDir::new().unwrap();
    let out = shpb(
        dir.path(),
        &[
            "--json",
            "design",
            &repo_path(SCENE),
            "--target",
            "peak_force=8kN",
            "--vary",
            "pressure=7psi:11psi",
        ],
    );
    let j = json(&out);
    let runs = j["runs"].as_array().unwrap();
    let mut outside = 0;
    for r in runs {
        let psi = r["inputs"]["pressure"]["value"].as_f64().unwrap();
        let preset = r["preset"].as_str().unwrap();
        let expected = run_warnings(dir.path(), &format!("{psi}psi"), preset);
        assert_eq!(strings(&r["warnings"]), expected, "{psi} psi, {preset}");
        outside += usize::from(!expected.is_empty());
    }
    assert!(outside > 0, "no run below 10 psi: {j}");
    // The table: a `warnings` column, its cells the runs' warnings.
    let out = shpb(
        dir.path(),
        &[
            "design",
            &repo_path(SCENE),
            "--target",
            "peak_force=8kN",
            "--vary",
            "pressure=7psi:11psi",
        ],
    );
    let text = stdout(&out);
    let header = text
        .lines()
        .find(|l| l.starts_with("run,"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(header.ends_with(",warnings"), "{header}");
    assert!(
        text.lines()
            .any(|l| !l.starts_with('#') && l.contains("gun pressure 7 psi is outside")),
        "{text}"
    );
}

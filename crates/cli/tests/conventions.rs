//! One output convention for every command (issue 15, item 18): results on stdout (a table, or
//! one JSON object with `--json`), messages, warnings and `wrote PATH` on stderr, `-` for an
//! output on stdout, `--quiet` for silence.

mod common;

use common::{repo_path as path, shpb, stderr as err, stdout as out};
use std::process::Command;
use tempfile::TempDir;

#[test]
fn json_results_parse_and_carry_units() {
    let dir = TempDir::new().unwrap();
    let scene = path("scenes/shpb-ss440c-10psi.toml");
    let o = shpb(dir.path(), &["run", &scene, "--fidelity", "fast", "--json"]);
    assert!(o.status.success(), "{}", err(&o));
    let v: serde_json::Value = serde_json::from_str(&out(&o)).expect("one JSON object");
    assert_eq!(v["kind"], "shpb");
    assert_eq!(v["summary"]["peak_contact_force"]["unit"], "N");
    let f = v["summary"]["peak_contact_force"]["value"]
        .as_f64()
        .unwrap();
    assert!(f > 1e3, "{f}");
    assert!(v["result"]["reduced_peak_back_force_N"].as_f64().unwrap() > 1e3);

    let record = path("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let o = shpb(dir.path(), &["reduce", &record, "--json"]);
    assert!(o.status.success(), "{}", err(&o));
    let v: serde_json::Value = serde_json::from_str(&out(&o)).expect("one JSON object");
    assert!(v["peak_back_force_N"].as_f64().unwrap() > 1e3);
    // Warnings are messages: on stderr, never mixed into the data on stdout.
    assert!(!out(&o).contains("warning:"));

    let force = path("validation/fig4-force-driven/data/ss440c_10psi_force10.csv");
    let o = shpb(
        dir.path(),
        &["incident", &force, "--pressure", "10psi", "--json"],
    );
    assert!(o.status.success(), "{}", err(&o));
    let v: serde_json::Value = serde_json::from_str(&out(&o)).expect("one JSON object");
    assert!(v["energy_J"].as_f64().unwrap() > 0.0);
    assert!(v["set_up_striker"]["possible"].is_boolean());

    let collision = path("scenes/collision-ss440c-5ms.toml");
    let o = shpb(
        dir.path(),
        &["sweep", &collision, "--set", "velocity1_m_s=1,2", "--json"],
    );
    assert!(o.status.success(), "{}", err(&o));
    let v: serde_json::Value = serde_json::from_str(&out(&o)).expect("one JSON object");
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[1]["inputs"]["velocity1_m_s"]["value"], 2.0);
    assert_eq!(runs[1]["inputs"]["velocity1_m_s"]["unit"], "m/s");
    assert_eq!(runs[1]["results"]["peak_force"]["unit"], "N");
}

#[test]
fn every_file_written_is_reported_on_stderr_and_quiet_silences_them() {
    let dir = TempDir::new().unwrap();
    let scene = path("scenes/collision-ss440c-5ms.toml");
    let o = shpb(
        dir.path(),
        &[
            "run", &scene, "-o", "a.h5", "--csv", "a.csv", "--plot", "a.png",
        ],
    );
    assert!(o.status.success(), "{}", err(&o));
    for f in ["a.h5", "a.csv", "a.png"] {
        assert!(err(&o).contains(&format!("wrote {f}")), "{}", err(&o));
        assert!(!out(&o).contains("wrote"), "messages belong on stderr");
    }
    let o = shpb(dir.path(), &["run", &scene, "-o", "b.h5", "--quiet"]);
    assert!(o.status.success(), "{}", err(&o));
    assert!(out(&o).is_empty(), "{}", out(&o));
    assert!(err(&o).is_empty(), "{}", err(&o));
    assert!(dir.path().join("b.h5").is_file());
}

#[test]
fn dash_writes_an_output_to_stdout_alone() {
    let dir = TempDir::new().unwrap();
    let scene = path("scenes/collision-ss440c-5ms.toml");
    let o = shpb(dir.path(), &["run", &scene, "--csv", "-"]);
    assert!(o.status.success(), "{}", err(&o));
    let text = out(&o);
    let mut lines = text.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("time_s,displacement_m,force_N")
    );
    assert!(lines.count() > 10, "CSV rows on stdout");
    assert!(!text.contains("scene:"), "no table mixed into the CSV");
    // A file named `-` is not created.
    assert!(!dir.path().join("-").exists());
    // Two things on stdout at once are refused before anything runs.
    let o = shpb(dir.path(), &["run", &scene, "--csv", "-", "--json"]);
    assert_eq!(o.status.code(), Some(2), "{}", err(&o));
    assert!(out(&o).is_empty());
}

#[test]
fn a_run_shows_its_progress_with_an_eta() {
    // On a terminal the line appears after two seconds; SHPB_PROGRESS=always prints it at once.
    let dir = TempDir::new().unwrap();
    let scene = path("scenes/shpb-ss440c-10psi.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir.path())
        .args(["run", &scene, "--fidelity", "fast"])
        .env("SHPB_PROGRESS", "always")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", err(&o));
    let e = err(&o);
    assert!(e.contains("ETA") && e.contains("100 % done"), "{e}");
    assert!(!out(&o).contains("ETA"), "progress belongs on stderr");
}

/// `study` and `design` follow the same convention: one JSON object on stdout with `--json`,
/// progress and messages on stderr.
#[test]
fn study_and_design_json_results_parse() {
    let dir = TempDir::new().unwrap();
    let scene = dir.path().join("uncertain.toml");
    std::fs::write(
        &scene,
        "kind = \"collision\"\nvelocity1_m_s = { min = 1.0, max = 2.0 }\n[specimen]\npair = \"ss440c\"\n",
    )
    .unwrap();
    let o = shpb(
        dir.path(),
        &["study", scene.to_str().unwrap(), "--samples", "4", "--json"],
    );
    assert!(o.status.success(), "{}", err(&o));
    let v: serde_json::Value = serde_json::from_str(&out(&o)).expect("one JSON object");
    let q = v["quantities"].as_array().unwrap();
    assert!(
        q.iter()
            .any(|x| x["quantity"] == "peak_force" && x["unit"] == "N")
    );

    let o = shpb(
        dir.path(),
        &[
            "design",
            &path("scenes/collision-ss440c-5ms.toml"),
            "--target",
            "peak_force=0.5kN",
            "--vary",
            "velocity1_m_s=0.5:10",
            "--json",
        ],
    );
    assert!(o.status.success(), "{}", err(&o));
    serde_json::from_str::<serde_json::Value>(&out(&o)).expect("one JSON object");
    assert!(!out(&o).contains("shpb:"), "messages belong on stderr");
}

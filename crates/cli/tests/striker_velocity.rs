//! `striker_velocity_m_s` (the striker's impact velocity given instead of the gun's pressure) and
//! `shpb run --set KEY=VALUE` (issue 41).

mod common;

use common::{repo, shpb, stderr, stdout};
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use std::path::Path;

/// The 10 psi test's scene text at `fast`, with its `pressure` line replaced by `drive`.
fn ss440c(drive: &str) -> String {
    let text = std::fs::read_to_string(repo().join("scenes/shpb-ss440c-10psi.toml")).unwrap();
    assert!(text.contains("pressure = \"10psi\"\n"));
    format!(
        "fidelity = \"fast\"\n{}",
        text.replace("pressure = \"10psi\"\n", drive)
    )
}

fn parse(text: &str) -> shpb::Result<Params> {
    Params::from_toml(text, "velocity-test.toml", &repo().join("scenes"))
}

fn velocity(p: &Params) -> f64 {
    match &p.params {
        SceneParams::Pulse { options, .. } => options.striker_velocity_m_s,
        _ => unreachable!(),
    }
}

#[test]
fn the_gun_velocity_at_10_psi_gives_the_10_psi_test_bit_for_bit() {
    let gun = parse(&ss440c("pressure = \"10psi\"\n")).unwrap();
    let v = velocity(&gun);
    // `{v:?}` is the shortest text that reads back as the same f64.
    let given = parse(&ss440c(&format!("striker_velocity_m_s = {v:?}\n"))).unwrap();
    assert_eq!(velocity(&given).to_bits(), v.to_bits());
    let (a, b) = (gun.run().unwrap(), given.run().unwrap());
    assert_eq!(a.gauges.len(), b.gauges.len());
    for (ga, gb) in a.gauges.iter().zip(&b.gauges) {
        assert!(!ga.strain.is_empty());
        let bits = |s: &[f64]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&ga.strain), bits(&gb.strain), "gauge {}", ga.name);
    }
    // No gun: no pressure in the summary (no NaN), and no gun-calibration warning.
    assert!(a.summary.iter().any(|i| i.key == "pressure"));
    assert!(!b.summary.iter().any(|i| i.key == "pressure"));
    assert!(
        b.summary.iter().all(|i| !i.value.is_nan()),
        "{:?}",
        b.summary
    );
    assert!(
        b.warnings.iter().all(|w| !w.contains("gun")),
        "{:?}",
        b.warnings
    );
}

#[test]
fn a_pulse_scene_takes_a_striker_velocity() {
    let text = "kind = \"pulse\"\nbars = \"authors\"\nstriker_velocity_m_s = 4.5\n";
    let p = Params::from_toml(text, "pulse.toml", Path::new(".")).unwrap();
    assert_eq!(velocity(&p), 4.5);
    // An integer reads as a velocity too.
    let text = "kind = \"pulse\"\nbars = \"authors\"\nstriker_velocity_m_s = 6\n";
    let p = Params::from_toml(text, "pulse.toml", Path::new(".")).unwrap();
    assert_eq!(velocity(&p), 6.0);
}

#[test]
fn exactly_one_incident_wave_source_is_taken() {
    let both = parse(&ss440c(
        "pressure = \"10psi\"\nstriker_velocity_m_s = 5.0\n",
    ))
    .unwrap_err()
    .to_string();
    assert!(
        both.contains("striker_velocity_m_s") && both.contains("given with pressure"),
        "{both}"
    );
    assert!(both.contains("[incident_record]"), "{both}");
    let none = parse(&ss440c("")).unwrap_err().to_string();
    assert!(
        none.contains("`pressure`: missing") && none.contains("striker_velocity_m_s"),
        "{none}"
    );
    let record = parse(&format!(
        "{}\n[incident_record]\nfile = \"x.csv\"\n",
        ss440c("striker_velocity_m_s = 5.0\n")
    ))
    .unwrap_err()
    .to_string();
    assert!(
        record.contains("`incident_record`: given with striker_velocity_m_s"),
        "{record}"
    );
    for bad in ["0.0", "-3.0", "101.0", "nan"] {
        let e = parse(&ss440c(&format!("striker_velocity_m_s = {bad}\n")))
            .unwrap_err()
            .to_string();
        assert!(e.contains("striker_velocity_m_s"), "{bad}: {e}");
    }
}

/// `shpb run ARGS --json` in the repository root: the parsed summary.
fn run_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["run"];
    all.extend(args);
    all.extend(["--fidelity", "fast", "--json"]);
    let out = shpb(&repo(), &all);
    assert!(out.status.success(), "{:?}: {}", all, stderr(&out));
    serde_json::from_str(&stdout(&out)).unwrap()
}

#[test]
fn run_set_equals_the_scene_with_that_value() {
    let dir = tempfile::tempdir_in(repo().join("scenes")).unwrap();
    let file = dir.path().join("ss440c-12.5psi.toml");
    let text = std::fs::read_to_string(repo().join("scenes/shpb-ss440c-10psi.toml"))
        .unwrap()
        .replace("pressure = \"10psi\"", "pressure = \"12.5psi\"")
        .replace("\"../bars/", "\"../../bars/");
    std::fs::write(&file, text).unwrap();
    let from_file = run_json(&[file.to_str().unwrap()]);
    let h5 = dir.path().join("set.h5");
    let set = run_json(&[
        "scenes/shpb-ss440c-10psi.toml",
        "--set",
        "pressure=12.5psi",
        "-o",
        h5.to_str().unwrap(),
    ]);
    assert_eq!(set["summary"], from_file["summary"]);
    assert_eq!(set["result"], from_file["result"]);
    assert_eq!(set["summary"]["pressure"]["value"], 12.5 * 6894.757293168);
    // The run file stores the scene with the value set: rerunning it reruns 12.5 psi.
    let rerun = run_json(&[h5.to_str().unwrap()]);
    assert_eq!(rerun["summary"], set["summary"]);
}

#[test]
fn run_set_velocity_replaces_the_pressure() {
    let json = run_json(&[
        "scenes/shpb-ss440c-10psi.toml",
        "--set",
        "striker_velocity_m_s=6",
    ]);
    assert_eq!(json["summary"]["striker_velocity"]["value"], 6.0);
    assert!(json["summary"].get("pressure").is_none(), "{json}");
}

#[test]
fn run_set_refuses_what_the_scene_does_not_take() {
    let refused = |args: &[&str], names: &str| {
        let mut all = vec!["run", "scenes/shpb-ss440c-10psi.toml"];
        all.extend(args);
        let out = shpb(&repo(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(names), "{args:?}: {}", stderr(&out));
    };
    refused(&["--set", "no_such_key=1"], "no_such_key");
    refused(&["--set", "pressure=10psi,12psi"], "one value");
    refused(
        &["--set", "pressure=10psi", "--set", "pressure=12psi"],
        "set twice",
    );
    refused(
        &["--set", "pressure=10psi", "--set", "striker_velocity_m_s=6"],
        "striker_velocity_m_s",
    );
    refused(
        &["--set", "striker_velocity_m_s=500"],
        "striker_velocity_m_s",
    );
}

//! `shpb calibrate`: errors that name the file and key, no clobbering, and the set-up it writes
//! (the base's text with the calibrated keys replaced and the `[uncertainty]` table). The
//! regeneration of the authors' set-up from its eight shots (slow) is validation/pulse/REPORT.md.

mod common;

use common::{repo_path, shpb, stderr, stdout};
use std::path::Path;

/// A manifest of four gun shots with measured velocities on the line v² = k (p − p_loss),
/// k = 8e-4 m²/s²/Pa, p_loss = 20 kPa (±1 % about it), each on a 2013-05-22 record.
fn gun_manifest(dir: &Path) -> std::path::PathBuf {
    let record = repo_path("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let mut t = String::from("fitted_on = \"four gun shots\"\ncalibrate = [\"gun\"]\n");
    for (psi, wobble) in [(8.0_f64, 1.01), (10.0, 0.99), (12.0, 1.0), (14.0, 1.005)] {
        let v = (8e-4 * (psi * 6894.757 - 2e4_f64)).sqrt() * wobble;
        t.push_str(&format!(
            "[[shot]]\nfile = \"{record}\"\npressure = \"{psi}psi\"\nstriker_velocity_m_s = {v}\n"
        ));
    }
    let p = dir.join("shots.toml");
    std::fs::write(&p, t).unwrap();
    p
}

#[test]
fn the_gun_line_is_written_into_the_base_set_up_with_its_uncertainty() {
    let d = tempfile::tempdir().unwrap();
    gun_manifest(d.path());
    let out = shpb(
        d.path(),
        &[
            "calibrate",
            "shots.toml",
            "--bars",
            "authors",
            "-o",
            "lab.toml",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("gun.k_m2_per_s2_per_pa"), "{text}");
    assert!(text.contains("covariance"), "{text}");
    let setup = std::fs::read_to_string(d.path().join("lab.toml")).unwrap();
    // The base's comments stay; each replaced value says what it was fitted on.
    assert!(
        setup.contains("# Gas gun (docs/physics.md §6.4)"),
        "{setup}"
    );
    assert!(setup.contains("# shpb calibrate:"), "{setup}");
    // Until the [uncertainty] table is parsed by `--bars` (BANDS), check the TOML itself.
    let t: toml::Table = toml::from_str(&setup).unwrap();
    let k = t["gun"]["k_m2_per_s2_per_pa"].as_float().unwrap();
    let loss = t["gun"]["loss_pressure_pa"].as_float().unwrap();
    // Four points within ±1 % of the line: k and p_loss close to it.
    assert!((k / 8e-4 - 1.0).abs() < 0.05, "k {k}");
    assert!((loss - 2e4).abs() < 3e3, "p_loss {loss}");
    let u = &t["uncertainty"];
    assert_eq!(u["shots"].as_integer(), Some(4));
    assert_eq!(u["fitted_on"].as_str(), Some("four gun shots"));
    assert!(
        u["relative_sd"]["gun.k_m2_per_s2_per_pa"]
            .as_float()
            .unwrap()
            > 0.0
    );
    assert!(u["sd"]["gun.loss_pressure_pa"].as_float().unwrap() > 0.0);
    // The shaper is the base's, untouched; the gauge file is beside the set-up.
    assert_eq!(t["shaper"]["diameter_m"].as_float(), Some(3.982e-3));
    assert_eq!(t["gauges"].as_str(), Some("lab-gauges.toml"));
    assert!(d.path().join("lab-gauges.toml").is_file());
    // Without the [uncertainty] table the written set-up loads as a set-up with the new line.
    let bare = setup[..setup.find("\n# What the calibrated constants").unwrap()].to_string();
    std::fs::write(d.path().join("bare.toml"), bare).unwrap();
    let gun = shpb(
        d.path(),
        &["gun", "--pressure", "12psi", "--bars", "bare.toml"],
    );
    assert!(gun.status.success(), "{}", stderr(&gun));

    // No clobbering without --force; --json gives the constants.
    let again = shpb(
        d.path(),
        &[
            "calibrate",
            "shots.toml",
            "--bars",
            "authors",
            "-o",
            "lab.toml",
        ],
    );
    assert_eq!(again.status.code(), Some(2), "{}", stderr(&again));
    assert!(stderr(&again).contains("lab.toml"), "{}", stderr(&again));
    let json = shpb(
        d.path(),
        &[
            "--json",
            "calibrate",
            "shots.toml",
            "--bars",
            "authors",
            "-o",
            "lab.toml",
            "--force",
        ],
    );
    assert!(json.status.success(), "{}", stderr(&json));
    let v: serde_json::Value = serde_json::from_str(&stdout(&json)).unwrap();
    let keys: Vec<&str> = v["constants"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["key"].as_str().unwrap())
        .collect();
    assert!(keys.contains(&"gun.loss_pressure_pa"), "{keys:?}");
}

#[test]
fn errors_name_the_file_and_the_key() {
    let d = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let o = shpb(d.path(), args);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        stderr(&o)
    };
    let e = run(&["calibrate", "missing.toml", "-o", "x.toml"]);
    assert!(e.contains("SHOTS") && e.contains("missing.toml"), "{e}");
    std::fs::write(d.path().join("m.toml"), "[[shot]]\nfile = \"nope.csv\"\n").unwrap();
    let e = run(&["calibrate", "m.toml", "-o", "x.toml"]);
    assert!(e.contains("m.toml") && e.contains("shot[1].file"), "{e}");
    let e = run(&["calibrate", "m.toml", "-o", "x.h5"]);
    assert!(e.contains("-o"), "{e}");
    let e = run(&[
        "calibrate",
        "m.toml",
        "--bars",
        "no-such.toml",
        "-o",
        "x.toml",
    ]);
    assert!(e.contains("--bars"), "{e}");
    // Shots that carry no calibration's data: each calibration says why.
    let record = repo_path("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    std::fs::write(
        d.path().join("one.toml"),
        format!("calibrate = [\"gun\"]\n[[shot]]\nfile = \"{record}\"\npressure = \"10psi\"\n"),
    )
    .unwrap();
    let e = run(&["calibrate", "one.toml", "-o", "x.toml"]);
    assert!(e.contains("gun:") && e.contains("fewer than three"), "{e}");
    assert!(!d.path().join("x.toml").exists());
}

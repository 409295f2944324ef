//! `shpb setup new` (issue 41): a complete, commented set-up file from the numbers a lab states,
//! which `--bars FILE` loads directly (gauge channels inline, a linear or Wheatstone channel, no
//! gun or shaper), and every flag checked with an error naming it (exit 2).

mod common;
use common::{repo_path, shpb, stderr};
use shpb::gauge::BridgeKind;
use shpb::prelude::*;
use shpb::striker::Gun;
use std::path::Path;

/// The required flags: Yao et al.'s 945-steel bars (experiment_details_en-US.txt).
const STATED: [&str; 14] = [
    "--diameter",
    "0.02",
    "--modulus",
    "210e9",
    "--density",
    "7800",
    "--incident-length",
    "2.1",
    "--transmission-length",
    "1.8",
    "--incident-gauge",
    "1.02",
    "--transmission-gauge",
    "0.77",
];

fn setup_new(dir: &Path, file: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["setup", "new", "-o", file];
    args.extend(STATED);
    args.extend(extra);
    shpb(dir, &args)
}

#[test]
fn the_file_loads_as_a_set_up_with_the_stated_numbers_and_says_what_each_key_is() {
    let tmp = tempfile::tempdir().unwrap();
    let out = setup_new(tmp.path(), "bars.toml", &["--poisson", "0.29"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let path = tmp.path().join("bars.toml");
    let a = shpb::apparatus::Apparatus::from_file(&path).unwrap();
    assert_eq!(a.material.youngs_modulus_pa, 210e9);
    assert_eq!(a.material.density_kg_m3, 7800.0);
    assert_eq!(a.material.poisson_ratio, 0.29);
    assert_eq!((a.incident.length_m, a.transmission.length_m), (2.1, 1.8));
    assert_eq!(
        (a.incident.diameter_m, a.transmission.diameter_m),
        (0.02, 0.02)
    );
    assert_eq!(a.gun, Gun::None);
    assert!(a.shaper.is_none());
    let inc = a.gauges.channel("incident").unwrap();
    let tra = a.gauges.channel("transmission").unwrap();
    assert_eq!(inc.distance_from_specimen_m, 1.02);
    assert_eq!(tra.distance_from_specimen_m, 0.77);
    // No factor stated: a linear channel whose factor is "not stated".
    assert_eq!(inc.bridge.kind, BridgeKind::Linear);
    assert!(inc.bridge.strain_per_volt.is_nan());
    // Every key line carries its explanation, and every flag is named where it went.
    let text = std::fs::read_to_string(&path).unwrap();
    for flag in STATED.iter().step_by(2).chain(&["--poisson"]) {
        assert!(
            text.contains(&format!("# {flag}")),
            "{flag} not named:\n{text}"
        );
    }
    for line in text.lines() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') || l.starts_with('[') {
            continue;
        }
        let key = l.split('=').next().unwrap().trim();
        let explained = l.contains('#')
            || ["description", "name", "bar", "adc_bits", "adc_range_v"].contains(&key);
        assert!(explained, "`{l}` has no comment");
    }
    // No clobbering without --force.
    let again = setup_new(tmp.path(), "bars.toml", &[]);
    assert!(!again.status.success());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    let forced = setup_new(tmp.path(), "bars.toml", &["--force"]);
    assert!(forced.status.success(), "{}", stderr(&forced));
}

#[test]
fn a_volt_record_needs_the_factor_a_strain_record_does_not() {
    let tmp = tempfile::tempdir().unwrap();
    let volts = repo_path("tests/data/labs/yao-2026/steel_945/sample_02/raw_voltage.xlsx");
    let strains = repo_path("tests/data/labs/yao-2026/steel_945/sample_02/raw_microstrain.xlsx");
    assert!(setup_new(tmp.path(), "plain.toml", &[]).status.success());
    let out = shpb(tmp.path(), &["reduce", &volts, "--bars", "plain.toml"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.contains("`strain_per_volt`") && e.contains("--strain-per-volt"),
        "{e}"
    );
    let out = shpb(
        tmp.path(),
        &["-q", "reduce", &strains, "--bars", "plain.toml"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // With the factor (the lab's 496 µε/V) the volt record reduces.
    let out = setup_new(tmp.path(), "linear.toml", &["--strain-per-volt", "4.96e-4"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = shpb::apparatus::Apparatus::from_file(&tmp.path().join("linear.toml")).unwrap();
    assert_eq!(a.gauges.channels[0].bridge.strain_per_volt, 4.96e-4);
    let out = shpb(
        tmp.path(),
        &["-q", "reduce", &volts, "--bars", "linear.toml"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_wheatstone_bridge_from_its_flags() {
    let tmp = tempfile::tempdir().unwrap();
    let out = setup_new(
        tmp.path(),
        "bridge.toml",
        &[
            "--bridge",
            "half-poisson",
            "--gauge-factor",
            "2.1",
            "--excitation",
            "10",
            "--gain",
            "100",
            "--sample-rate",
            "31.25e6",
            "--striker-length",
            "0.3",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let a = shpb::apparatus::Apparatus::from_file(&tmp.path().join("bridge.toml")).unwrap();
    let c = a.gauges.channel("transmission").unwrap();
    assert_eq!(c.bridge.kind, BridgeKind::HalfPoisson);
    assert_eq!(
        (
            c.bridge.gauge_factor,
            c.bridge.excitation_v,
            c.amplifier_gain
        ),
        (2.1, 10.0, 100.0)
    );
    assert_eq!(c.digitiser.sample_rate_hz, 31.25e6);
    assert_eq!(a.striker.length_m, 0.3);
}

#[test]
fn every_flag_is_checked_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let refused = |replace: (&str, &str), extra: &[&str], flag: &str| {
        let mut args = vec!["setup", "new", "-o", "x.toml"];
        for pair in STATED.chunks(2) {
            args.push(pair[0]);
            args.push(if pair[0] == replace.0 {
                replace.1
            } else {
                pair[1]
            });
        }
        args.extend(extra);
        let out = shpb(tmp.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let e = stderr(&out);
        assert!(e.contains(&format!("`{flag}`")), "{args:?}: {e}");
        assert!(!tmp.path().join("x.toml").exists());
    };
    refused(("--diameter", "-0.02"), &[], "--diameter");
    refused(("--modulus", "nan"), &[], "--modulus");
    refused(("--density", "inf"), &[], "--density");
    refused(("--incident-length", "0"), &[], "--incident-length");
    refused(("--incident-gauge", "2.5"), &[], "--incident-gauge");
    refused(("--transmission-gauge", "1.8"), &[], "--transmission-gauge");
    refused(("", ""), &["--poisson", "0.6"], "--poisson");
    refused(("", ""), &["--striker-length", "-1"], "--striker-length");
    refused(("", ""), &["--sample-rate", "0"], "--sample-rate");
    refused(("", ""), &["--gauge-factor", "2.1"], "--bridge");
    refused(
        ("", ""),
        &["--bridge", "half-poisson", "--gauge-factor", "2.1"],
        "--excitation",
    );
    refused(("", ""), &["--bridge", "octopus"], "--bridge");
    refused(
        ("", ""),
        &["--strain-per-volt", "4.96e-4", "--gauge-factor", "2"],
        "--gauge-factor",
    );
    refused(("", ""), &["--strain-per-volt", "-1"], "--strain-per-volt");
}

#[test]
fn a_virtual_test_runs_on_the_set_up_at_a_striker_velocity() {
    let tmp = tempfile::tempdir().unwrap();
    let out = setup_new(tmp.path(), "bars.toml", &["--striker-length", "0.2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::write(
        tmp.path().join("pulse.toml"),
        "kind = \"pulse\"\nbars = \"bars.toml\"\nstriker_velocity_m_s = 5.0\nfidelity = \"fast\"\n",
    )
    .unwrap();
    let out = shpb(tmp.path(), &["-q", "run", "pulse.toml", "-o", "pulse.h5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    // A cylinder test on it reduces its own records (the channels state no factor: their
    // strains), without a warning that the reduction failed.
    std::fs::write(
        tmp.path().join("cylinder.toml"),
        "kind = \"shpb\"\nbars = \"bars.toml\"\nstriker_velocity_m_s = 10.0\nfidelity = \"fast\"\n\
         [specimen]\nshape = \"cylinder\"\nlength_m = 4e-3\ndiameter_m = 8e-3\nmaterial = \"steel4340\"\n",
    )
    .unwrap();
    let out = shpb(tmp.path(), &["run", "cylinder.toml", "-o", "cylinder.h5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("failed"), "{}", stderr(&out));
    assert!(
        common::stdout(&out).contains("reduced_peak_back_force"),
        "{}",
        common::stdout(&out)
    );
    // A pressure needs a gun, which this set-up has not.
    std::fs::write(
        tmp.path().join("gun.toml"),
        "kind = \"pulse\"\nbars = \"bars.toml\"\npressure = \"10psi\"\n",
    )
    .unwrap();
    let out = shpb(tmp.path(), &["run", "gun.toml", "-o", "gun.h5"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("no [gun]"), "{}", stderr(&out));
}

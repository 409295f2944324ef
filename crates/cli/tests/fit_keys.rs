//! The material constants `shpb run --set` (and `shpb fit --free`, issue 44) reaches: a sphere
//! pair's `specimen.yield_stress_pa`, `specimen.jc_c` and `specimen.jc_reference_rate_per_s`
//! (σy, C and ε̇0 of the paper's Eq. 2, for every sphere), and a cylinder's Johnson–Cook constants
//! one by one (`specimen.johnson_cook.b_pa`, …, merged over the material's table;
//! docs/physics.md §6.12).

mod common;

use common::{repo_path, shpb, stderr, stdout};
use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use shpb_core::numeric::resample;

const FORCE_DRIVEN: &str = "scenes/force-driven-ss440c-10psi.toml";

/// `shpb run SCENE --json` with `--set` for each of `set`: the summary's values by key, and the
/// contact history `--csv` wrote.
fn run_json(scene: &str, set: &[&str]) -> (serde_json::Map<String, serde_json::Value>, String) {
    let tmp = tempfile::tempdir().unwrap();
    let scene = repo_path(scene);
    let mut args = vec!["run", &scene, "--json", "--no-bands", "--csv", "c.csv"];
    for s in set {
        args.extend(["--set", s]);
    }
    let out = shpb(tmp.path(), &args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    let json: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let summary = json["summary"].as_object().unwrap().clone();
    let csv = std::fs::read_to_string(tmp.path().join("c.csv")).unwrap();
    (summary, csv)
}

fn value(summary: &serde_json::Map<String, serde_json::Value>, key: &str) -> f64 {
    summary[key]["value"]
        .as_f64()
        .unwrap_or_else(|| panic!("no {key}"))
}

#[test]
fn the_materials_own_constants_set_on_the_command_line_change_nothing() {
    // specimens/ss440c.toml: σy = 1900 MPa, C = 0.035, ε̇0 = 1e-3 1/s (paper Table I, Fig. 4).
    let plain = run_json(FORCE_DRIVEN, &[]);
    let own = run_json(
        FORCE_DRIVEN,
        &[
            "specimen.yield_stress_pa=1900e6",
            "specimen.jc_c=0.035",
            "specimen.jc_reference_rate_per_s=1e-3",
        ],
    );
    assert_eq!(plain.0, own.0, "summary");
    assert_eq!(plain.1, own.1, "contact history");
}

#[test]
fn a_lower_yield_stress_gives_a_larger_approach_under_the_same_force() {
    // The force history is the measured one (a force-driven scene), so the same force presses
    // a softer contact: Eq. 2 scales the plastic contact's resistance with σy (and with the
    // rate factor 1 + C ln(ε̇/ε̇0) ≥ 1), so a lower σy, or C = 0, gives a larger approach and a
    // lower secant stiffness F/δ at the peak force.
    let (own, _) = run_json(FORCE_DRIVEN, &[]);
    for set in ["specimen.yield_stress_pa=1700e6", "specimen.jc_c=0"] {
        let (soft, _) = run_json(FORCE_DRIVEN, &[set]);
        // The same drive: the measured peak force is the file's.
        assert_eq!(
            value(&soft, "measured_peak_force"),
            value(&own, "measured_peak_force")
        );
        for key in ["displacement_at_peak_force", "max_displacement"] {
            assert!(
                value(&soft, key) > value(&own, key),
                "{set}: {key} {} not above {}",
                value(&soft, key),
                value(&own, key)
            );
        }
        let stiffness = |s: &serde_json::Map<_, _>| {
            value(s, "peak_force") / value(s, "displacement_at_peak_force")
        };
        assert!(stiffness(&soft) < stiffness(&own), "{set}");
        // Softer contact, more plastic work done by the same force.
        assert!(
            value(&soft, "contact_work") > value(&own, "contact_work"),
            "{set}"
        );
    }
}

/// A repository cylinder scene read with `--set` overrides, run.
fn run_cylinder(scene: &str, set: &[(&str, f64)]) -> RunOutput {
    let overrides: Vec<(String, toml::Value)> = set
        .iter()
        .map(|(k, x)| (k.to_string(), toml::Value::Float(*x)))
        .collect();
    Params::from_file_overridden(&common::repo().join(scene), &overrides)
        .unwrap()
        .run()
        .unwrap()
}

#[test]
fn a_larger_johnson_cook_b_raises_the_copper_cylinders_flow_stress_as_jc_says() {
    // σ_f = (A + B ε̄pⁿ)(1 + C ln(ε̇/ε̇0))(1 − T*ᵐ) (docs/physics.md §6.12), copper A = 90 MPa,
    // B = 292 MPa, n = 0.31, C = 0.025, ε̇0 = 1/s (specimens/ofhc-copper.toml). While the
    // specimen flows, its stress at the same plastic strain in a run with B' = 400 MPa is the
    // first run's times (A + B' ε̄pⁿ)/(A + B ε̄pⁿ) and the ratio of the rate factors at the two
    // runs' strain rates (the thermal factors differ by < 0.01 %: both stay within 3 K of room
    // temperature, T* < 0.003).
    let (a, b, b2, n, c) = (90e6, 292e6, 400e6, 0.31, 0.025);
    for (scene, sense) in [
        ("scenes/shpb-cylinder-copper.toml", "compression"),
        ("scenes/shtb-cylinder-copper.toml", "tension"),
    ] {
        let own = run_cylinder(scene, &[]);
        let stiff = run_cylinder(scene, &[("specimen.johnson_cook.b_pa", b2)]);
        let (s1, s2) = (own.specimen.unwrap(), stiff.specimen.unwrap());
        let peak_rate = |s: &[f64]| s.iter().cloned().fold(0.0, f64::max);
        let (fast1, fast2) = (
            0.5 * peak_rate(&s1.true_strain_rate_per_s),
            0.5 * peak_rate(&s2.true_strain_rate_per_s),
        );
        // The first run's loading branch, where its plastic strain grows (a function of it).
        let last1 = shpb_core::numeric::argmax(&s1.plastic_strain);
        let at =
            |x: &[f64], ep: f64| resample(&s1.plastic_strain[..=last1], &x[..=last1], &[ep])[0];
        let mut checked = 0;
        let mut worst: f64 = 0.0;
        for k in 1..s2.time_s.len() {
            let ep = s2.plastic_strain[k];
            let rate2 = s2.true_strain_rate_per_s[k];
            // Flowing in both runs (past the first yield, at more than half the peak rate),
            // within the plastic strain the first run reached.
            if ep < 5e-3 || ep > s1.plastic_strain[last1] || ep <= s2.plastic_strain[k - 1] {
                continue;
            }
            let rate1 = at(&s1.true_strain_rate_per_s, ep);
            if rate2 < fast2 || rate1 < fast1 {
                continue;
            }
            let ratio = s2.element_stress_pa[k] / at(&s1.element_stress_pa, ep);
            let expected = (a + b2 * ep.powf(n)) / (a + b * ep.powf(n)) * (1.0 + c * rate2.ln())
                / (1.0 + c * rate1.ln());
            assert!(ratio > 1.0, "{sense}: ε̄p {ep}: ratio {ratio}");
            worst = worst.max((ratio / expected - 1.0).abs());
            checked += 1;
        }
        // 0.2 %: the series are means over the specimen's elements (the stress of the mean
        // plastic strain is not the mean stress), and the total strain rate stands for the
        // plastic rate.
        assert!(worst < 2e-3, "{sense}: ratio off Johnson–Cook's by {worst}");
        assert!(checked > 100, "{sense}: only {checked} samples flowing");
        eprintln!("{sense}: {checked} samples, ratio within {worst:.2e} of Johnson–Cook's");
    }
}

#[test]
fn the_command_line_reaches_the_cylinders_constants() {
    for scene in [
        "scenes/shpb-cylinder-copper.toml",
        "scenes/shtb-cylinder-copper.toml",
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let peak = |set: &[&str]| {
            let scene = repo_path(scene);
            let mut args = vec!["run", &scene, "--json", "--no-bands"];
            for s in set {
                args.extend(["--set", s]);
            }
            let out = shpb(tmp.path(), &args);
            assert!(out.status.success(), "{args:?}: {}", stderr(&out));
            let json: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
            json["summary"]["true_peak_stress"]["value"]
                .as_f64()
                .unwrap()
        };
        let own = peak(&[]);
        assert_eq!(peak(&["specimen.johnson_cook.b_pa=292e6"]), own, "{scene}");
        assert!(peak(&["specimen.johnson_cook.b_pa=300e6"]) > own, "{scene}");
        assert!(peak(&["specimen.johnson_cook.a_pa=60e6"]) < own, "{scene}");
        // A sphere's constant is refused for a cylinder, naming the key and the cylinder's own.
        let scene_path = repo_path(scene);
        let out = shpb(
            tmp.path(),
            &[
                "run",
                &scene_path,
                "--set",
                "specimen.yield_stress_pa=100e6",
            ],
        );
        assert_eq!(out.status.code(), Some(2));
        let e = stderr(&out);
        assert!(
            e.contains("`specimen.yield_stress_pa`") && e.contains("specimen.johnson_cook.a_pa"),
            "{e}"
        );
    }
}

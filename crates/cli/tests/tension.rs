//! Tension (split Hopkinson tension bar; issue 43, docs/physics.md §6.13, §7.8.1): the
//! elastoplastic cylinder of issue 40 loaded in tension as its virtual test, and the lab's
//! reduction in tension.
//!
//! * Round trip: a 6 × 6 mm annealed OFHC copper specimen (Johnson–Cook constants of
//!   `specimens/ofhc-copper.toml`, the issue-40 acceptance specimen) threaded to the authors'
//!   bars and pulled by the 20 cm striker without a shaper: the lab's 1-wave reduction of the
//!   simulated gauges recovers the specimen's own true flow stress within 3 % from 2 % true
//!   strain to the end of loading (the acceptance), every stress and strain tension
//!   positive; the energy ledger closes in tension to 1e-9 of the striker's energy.
//! * `shpb reduce` of the run file reads its loading from the stored scene and gives the run's
//!   own reduction; `--tension` on a compression record, spheres in tension and a tension
//!   reduction without a cylinder are refused (exit 2).

mod common;

use common::{repo, shpb, stderr, stdout};
use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use shpb_core::numeric::resample;

/// The copper specimen at `pressure` in `loading`, its length given as `length_key`.
fn scene(pressure: &str, loading: &str, length_key: &str) -> String {
    format!(
        "kind = \"shpb\"\nbars = \"authors-20cm-striker\"\npressure = \"{pressure}\"\n\
         loading = \"{loading}\"\n[specimen]\nshape = \"cylinder\"\nmaterial = \"ofhc-copper\"\n\
         {length_key} = 6e-3\ndiameter_m = 6e-3\n"
    )
}

fn run(text: &str) -> RunOutput {
    Params::from_toml(text, "copper.toml", &repo())
        .unwrap()
        .run()
        .unwrap()
}

fn summary(out: &RunOutput, key: &str) -> f64 {
    out.summary_value(key)
        .unwrap_or_else(|| panic!("no {key} in the summary"))
}

/// The acceptance (issue 43, "Tension round trip on a simulated elastoplastic tension specimen:
/// flow stress within 3 %"), checked as issue 40's compression acceptance is
/// (`plastic_cylinder.rs`): the 1-wave true stress against the specimen's own face stress at the
/// same true strain on its loading branch, from 2 % true strain to the end of loading, recomputed
/// here from the two series and equal to the summary's `reduced_true_stress_max_relative_error`.
/// The specimen lengthens (true strain > 4 %) and both curves are tension positive; the ledger
/// (striker = bars + specimen + joints + plastic work) closes to 1e-9 (the issue-40 bound).
/// As in `plastic_cylinder.rs`, the error is the largest over a weak transmitted pulse, set by
/// the noise the filter leaves, so the run keeps the 2 µs moving average (`smooth_s`) the 3 %
/// bound was set with (measured at 12.5 psi: 2.1 % with it, 3.7 % with the default Butterworth
/// at 0.4 c0/a; docs/physics.md §7.12).
#[test]
fn the_reduction_of_a_tension_test_recovers_its_true_flow_stress() {
    for pressure in ["12.5psi", "15psi"] {
        let text = scene(pressure, "tension", "gauge_length_m")
            .replace("[specimen]", "smooth_s = 2e-6\n[specimen]");
        let out = run(&text);
        let error = summary(&out, "reduced_true_stress_max_relative_error");
        let s = out.specimen.as_ref().expect("a cylinder run has /specimen");
        let peak = shpb_core::numeric::argmax(&s.face_stress_pa);
        let (mut strain, mut stress, mut rate) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..=peak {
            if strain.last().is_none_or(|&e| s.true_strain[k] > e) {
                strain.push(s.true_strain[k]);
                stress.push(s.face_stress_pa[k]);
                rate.push(s.true_strain_rate_per_s[k]);
            }
        }
        let end = *strain.last().unwrap();
        assert!(end > 0.04, "{pressure}: the copper lengthens to {end}");
        assert!(s.face_stress_pa[peak] > 100e6, "tension positive");
        let one = &out.cylinder_reduction.as_ref().unwrap().one_wave;
        let reduced_peak = shpb_core::numeric::argmax(&one.true_stress_pa);
        assert!(one.true_stress_pa[reduced_peak] > 100e6 && one.strain[reduced_peak] > 0.04);
        let window: Vec<usize> = (0..=reduced_peak)
            .filter(|&k| (0.02..=end).contains(&one.true_strain[k]))
            .collect();
        assert!(window.len() > 100, "{pressure}: {} samples", window.len());
        let at: Vec<f64> = window.iter().map(|&k| one.true_strain[k]).collect();
        let truth = resample(&strain, &stress, &at);
        let worst = window
            .iter()
            .zip(&truth)
            .map(|(&k, t)| (one.true_stress_pa[k] / t - 1.0).abs())
            .fold(0.0, f64::max);
        assert_eq!(worst, error, "{pressure}");
        let rates = resample(&strain, &rate, &at);
        let (lo, hi) = rates
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
        let ledger = summary(&out, "energy_balance_max_relative_error");
        println!(
            "{pressure} tension: error {error:.4}, strain 0.02–{end:.4}, true rate {lo:.0}–{hi:.0} 1/s, \
             peak {:.1} MPa, ledger {ledger:.1e}",
            s.face_stress_pa[peak] / 1e6
        );
        assert!(
            error < 0.03,
            "{pressure}: 1-wave flow stress off by {error}"
        );
        assert!(lo > 0.0, "{pressure}: the specimen lengthens throughout");
        assert!(ledger < 1e-9, "{pressure}: ledger {ledger:e}");
        assert!(summary(&out, "plastic_work") > 0.0);
        // The incident gauge reads the tensile pulse, as a stress in the loading's sense.
        assert!(summary(&out, "incident_peak_stress") > 0.0);
    }
}

/// `length_m` and `gauge_length_m` name the same length: the two scenes run alike.
#[test]
fn gauge_length_is_the_cylinders_length() {
    let a = run(&scene("12.5psi", "tension", "gauge_length_m"));
    let b = run(&scene("12.5psi", "tension", "length_m"));
    assert_eq!(a.summary, b.summary);
}

/// The shipped scene's run file reduced by `shpb reduce` (its own set-up and specimen, the
/// loading read from the stored scene; the run's correction, none for elementary bars) gives
/// the run's own reduction; `--tension` says the same. The same record read as a compression
/// test is refused (its incident pulse is tensile), and a compression run file with `--tension`
/// too.
#[test]
fn shpb_reduce_reads_a_tension_run_in_tension() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = common::repo_path("scenes/shtb-cylinder-copper.toml");
    let out = shpb(tmp.path(), &["run", &scene, "-o", "t.h5", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let run: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let run_peak = run["summary"]["reduced_peak_stress"]["value"]
        .as_f64()
        .unwrap();
    assert!(run_peak > 100e6, "{run_peak}");
    for extra in [&[][..], &["--tension"][..]] {
        let mut args = vec!["reduce", "t.h5", "--dispersion", "none", "--json"];
        args.extend(extra);
        let out = shpb(tmp.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let red: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
        assert_eq!(red["loading"], "tension");
        assert_eq!(
            red["cylinder"]["peak_stress_Pa"].as_f64().unwrap(),
            run_peak
        );
        assert!(red["peak_back_force_N"].as_f64().unwrap() > 0.0);
    }
    // A compression run file read with --tension: its incident pulse is compressive.
    let compression = common::repo_path("scenes/shpb-cylinder-copper.toml");
    let out = shpb(tmp.path(), &["run", &compression, "-o", "c.h5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = shpb(tmp.path(), &["reduce", "c.h5", "--tension"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("incident"), "{}", stderr(&out));
}

/// Spheres carry no tension: a tension scene of spheres and a tension reduction for spheres are
/// refused with the key and what is allowed (exit 2).
#[test]
fn spheres_refuse_tension() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\nloading = \"tension\"\n\
               [specimen]\npair = \"ss440c\"\n";
    std::fs::write(tmp.path().join("s.toml"), bad).unwrap();
    let out = shpb(tmp.path(), &["run", "s.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(
        e.contains("loading") && e.contains("spheres in contact carry no tension"),
        "{e}"
    );
    let record = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/2013-05-22_sample1_ss440c.csv"
    );
    let out = shpb(tmp.path(), &["reduce", record, "--tension"]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(
        e.contains("--tension") && e.contains("carry no tension"),
        "{e}"
    );
}

/// `shpb run --plot` of the shipped tension scene draws the cylinder test's figure (as
/// `plastic_cylinder.rs` checks for compression): the specimen's own curves (solid orange) and
/// the 1-wave reduction (dashed dark red) in both specimen panels, labelled tension positive.
#[test]
fn a_tension_run_plots_its_true_and_reduced_stress_strain_and_rate() {
    common::assert_cylinder_figure("scenes/shtb-cylinder-copper.toml");
}

/// With the authors' copper shaper on the flange (`bars = "authors"`) the tension bar's incident
/// wave is the pressure bar's with its sign turned, bit for bit, until the specimen's reflection
/// reaches the incident gauge (the flange is the shaped striker mirrored, docs/physics.md §6.13);
/// the ledger closes in tension to 1e-9 with the shaper's work in it.
#[test]
fn a_shaped_tension_pulse_is_the_shaped_compression_pulse_turned() {
    let text = |loading: &str| {
        scene("12.5psi", loading, "length_m").replace("authors-20cm-striker", "authors")
    };
    let params = Params::from_toml(&text("tension"), "copper.toml", &repo()).unwrap();
    let shpb::scene::SceneParams::Pulse {
        apparatus, options, ..
    } = &params.params
    else {
        panic!("a bar scene")
    };
    assert!(options.shaper.is_some(), "the authors' set-up has a shaper");
    let d = apparatus
        .gauges
        .channel("incident")
        .unwrap()
        .distance_from_specimen_m;
    let c0 = apparatus.material.wave_speed_m_s();
    let pulled = params.run().unwrap();
    let pushed = run(&text("compression"));
    let trace = |out: &RunOutput| {
        out.gauges
            .iter()
            .find(|g| g.name == "incident")
            .unwrap()
            .strain
            .clone()
    };
    let (t, p, q) = (
        pulled.time_s.clone().unwrap(),
        trace(&pulled),
        trace(&pushed),
    );
    let foot = p.iter().position(|&e| e > 1e-6).unwrap();
    let before = t
        .iter()
        .position(|&x| x >= t[foot] + 2.0 * d / c0 - 5e-6)
        .unwrap();
    let turned: Vec<f64> = q[..before].iter().map(|e| -e).collect();
    assert_eq!(p[..before], turned[..]);
    let ledger = summary(&pulled, "energy_balance_max_relative_error");
    println!("shaped tension: ledger {ledger:.1e}, compared {before} samples");
    assert!(ledger < 1e-9, "{ledger:e}");
    assert!(summary(&pulled, "reduced_peak_stress") > 0.0);
}

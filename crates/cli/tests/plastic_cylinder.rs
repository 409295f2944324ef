//! Elastoplastic cylinders in a whole virtual test (issue 40; docs/physics.md §6.12): a 6 × 6 mm
//! annealed OFHC copper cylinder (Johnson–Cook constants of `specimens/ofhc-copper.toml`)
//! between the authors' bars, struck by the 20 cm striker without a shaper (a flat incident
//! pulse: once the copper flows, its strain rate is near constant).
//!
//! * The lab's 1-wave reduction of the simulated gauges recovers the specimen's own true flow
//!   stress within 3 % from 2 % true strain to the end of loading (the summary's
//!   `reduced_true_stress_max_relative_error`, checked here against the series themselves).
//! * What end friction and radial inertia contribute, as the run reports them (the `/specimen`
//!   series `friction_stress` and `inertia_stress`), is what switching each off takes away.

mod common;

use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use shpb_core::numeric::resample;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The copper test at `pressure` with `extra` keys in its `[specimen]` table.
fn run(pressure: &str, extra: &str) -> RunOutput {
    let text = format!(
        "kind = \"shpb\"\nbars = \"authors-20cm-striker\"\npressure = \"{pressure}\"\n\
         [specimen]\nshape = \"cylinder\"\nmaterial = \"ofhc-copper\"\nlength_m = 6e-3\n\
         diameter_m = 6e-3\n{extra}"
    );
    Params::from_toml(&text, "copper.toml", &root())
        .unwrap()
        .run()
        .unwrap()
}

/// [`run`] with `top` keys (e.g. `smooth_s`) before the `[specimen]` table.
fn run_smoothed(pressure: &str, top: &str) -> RunOutput {
    let text = format!(
        "kind = \"shpb\"\nbars = \"authors-20cm-striker\"\npressure = \"{pressure}\"\n{top}\
         [specimen]\nshape = \"cylinder\"\nmaterial = \"ofhc-copper\"\nlength_m = 6e-3\n\
         diameter_m = 6e-3\n"
    );
    Params::from_toml(&text, "copper.toml", &root())
        .unwrap()
        .run()
        .unwrap()
}

fn summary(out: &RunOutput, key: &str) -> f64 {
    out.summary_value(key)
        .unwrap_or_else(|| panic!("no {key} in the summary"))
}

/// The specimen's loading branch (up to its peak true stress, strain increasing): (true strain,
/// series values at those samples) for each of `series`.
fn loading_branch(out: &RunOutput, series: &[&[f64]]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let s = out.specimen.as_ref().expect("a cylinder run has /specimen");
    let peak = shpb_core::numeric::argmax(&s.face_stress_pa);
    let mut strain = Vec::new();
    let mut values = vec![Vec::new(); series.len()];
    for k in 0..=peak {
        if strain.last().is_none_or(|&e| s.true_strain[k] > e) {
            strain.push(s.true_strain[k]);
            for (v, x) in values.iter_mut().zip(series) {
                v.push(x[k]);
            }
        }
    }
    (strain, values)
}

/// 1-wave reduction against the true flow stress (docs/physics.md §6.12): the summary's error is
/// below 3 % and equals the largest error recomputed here from the two series; the rate over the
/// compared window is near constant. The error is the largest over 100+ samples of a weak
/// transmitted pulse (≈ 140 µε against 3.8 µε of digitiser noise), so it is set by the noise the
/// filter leaves: the run keeps the 2 µs moving average (`smooth_s`) this bound was set with
/// (with no filter 11.5 % at 15 psi, with the default Butterworth at 0.4 c0/a 3.1 %, with the
/// 2 µs box 1.9 %; docs/physics.md §7.12).
#[test]
fn the_reduction_of_a_copper_test_recovers_its_true_flow_stress() {
    for pressure in ["12.5psi", "15psi"] {
        let out = run_smoothed(pressure, "smooth_s = 2e-6\n");
        let error = summary(&out, "reduced_true_stress_max_relative_error");
        let s = out.specimen.as_ref().unwrap();
        let (strain, v) = loading_branch(&out, &[&s.face_stress_pa, &s.true_strain_rate_per_s]);
        let end = *strain.last().unwrap();
        assert!(end > 0.04, "{pressure}: the copper flows to {end}");
        let one = &out.cylinder_reduction.as_ref().unwrap().one_wave;
        let peak = shpb_core::numeric::argmax(&one.true_stress_pa);
        let window: Vec<usize> = (0..=peak)
            .filter(|&k| (0.02..=end).contains(&one.true_strain[k]))
            .collect();
        assert!(window.len() > 100, "{pressure}: {} samples", window.len());
        let at: Vec<f64> = window.iter().map(|&k| one.true_strain[k]).collect();
        let truth = resample(&strain, &v[0], &at);
        let worst = window
            .iter()
            .zip(&truth)
            .map(|(&k, t)| (one.true_stress_pa[k] / t - 1.0).abs())
            .fold(0.0, f64::max);
        assert_eq!(worst, error, "{pressure}");
        assert!(
            error < 0.03,
            "{pressure}: 1-wave flow stress off by {error}"
        );
        // Near-constant rate: the true strain rate over the compared strains.
        let rate = resample(&strain, &v[1], &at);
        let (lo, hi) = rate
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
        println!(
            "{pressure}: error {error:.4}, strain 0.02–{end:.4}, true rate {lo:.0}–{hi:.0} 1/s"
        );
    }
}

/// Friction (μ = 0.2, Avitzur) and radial inertia on together; each switched off in turn. The
/// face stress the other run loses at equal true strain is what the reported series says that
/// mechanism added. The runs differ in more than the switched term — a stress 7 % lower lets the
/// copper flow at another rate and heat differently (Johnson–Cook C = 0.025: a 10 % change of
/// rate moves the flow stress by 0.24 %) — so the two agree to that sensitivity, not to rounding:
/// measured within 1.8 % of the friction stress. Radial inertia at this near-constant rate adds
/// almost nothing (Davies–Hunter's ρ(h²/6 − ν²d²/8) ε̈ with ε̈ ≈ 0 once the copper flows: the
/// reported peak is 45 kPa, 2e-4 of the stress), and switching it off moves the stress by that
/// much within the same rate-path effect (measured 1.8e-4 of the stress); the case where it
/// dominates is the core's Davies–Hunter test (`solver/cylinder/tests.rs`).
#[test]
fn the_run_reports_what_friction_and_inertia_contribute() {
    let both = run(
        "15psi",
        "radial_inertia = true\nfriction_coefficient = 0.2\n",
    );
    let no_friction = run("15psi", "radial_inertia = true\n");
    let no_inertia = run("15psi", "friction_coefficient = 0.2\n");
    let s = both.specimen.as_ref().unwrap();
    let (strain, v) = loading_branch(
        &both,
        &[
            &s.face_stress_pa,
            &s.friction_stress_pa,
            &s.inertia_stress_pa,
        ],
    );
    let at: Vec<f64> = strain
        .iter()
        .copied()
        .filter(|&e| e >= 0.02 && e <= 0.95 * strain.last().unwrap())
        .collect();
    assert!(at.len() > 50);
    let on = resample(&strain, &v[0], &at);
    let friction = resample(&strain, &v[1], &at);
    let inertia = resample(&strain, &v[2], &at);
    let face_of = |out: &RunOutput| {
        let s = out.specimen.as_ref().unwrap();
        let (e, v) = loading_branch(out, &[&s.face_stress_pa]);
        resample(&e, &v[0], &at)
    };
    let without_friction = face_of(&no_friction);
    let without_inertia = face_of(&no_inertia);
    let mut worst_friction = 0.0f64;
    let mut worst_inertia = 0.0f64;
    for k in 0..at.len() {
        let measured = on[k] - without_friction[k];
        worst_friction = worst_friction.max((measured / friction[k] - 1.0).abs());
        let measured = on[k] - without_inertia[k];
        worst_inertia = worst_inertia.max((measured - inertia[k]).abs() / on[k]);
    }
    let peak_friction = summary(&both, "friction_peak_stress");
    let peak_inertia = summary(&both, "inertia_peak_stress");
    println!(
        "friction: reported peak {peak_friction:.3e} Pa, switched off within {worst_friction:.4} of it; \
         inertia: reported peak {peak_inertia:.3e} Pa, switched off within {worst_inertia:.2e} of the stress"
    );
    let peak = summary(&both, "true_peak_stress");
    assert!(peak_friction > 0.03 * peak, "friction {peak_friction} Pa");
    assert!(worst_friction < 0.03, "friction {worst_friction}");
    assert!(peak_inertia < 1e-3 * peak, "inertia {peak_inertia} Pa");
    assert!(worst_inertia < 1e-3, "inertia {worst_inertia}");
}

/// `shpb run --plot` of the shipped copper scene draws the cylinder test's figure: three panels
/// of 800 × 620 pixels across (gauge signals; true stress against true strain; true strain rate
/// against true strain) above the bars' x–t diagram, 2400 × 1300 in all. The specimen's own
/// curves (solid orange) and the 1-wave reduction (dashed dark red) are in both specimen panels.
#[test]
fn a_cylinder_run_plots_its_true_and_reduced_stress_strain_and_rate() {
    common::assert_cylinder_figure("scenes/shpb-cylinder-copper.toml");
}

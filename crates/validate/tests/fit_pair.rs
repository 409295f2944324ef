//! A sphere pair fit (`shpb fit`'s engine, docs/physics.md §11) of a simulated force-driven
//! record whose noise is known: white Gaussian noise of SD 2 µm on the model's approach at the
//! published SS440c constants (σy = 1900 MPa, C = 0.035) driven by the Fig. 4 SS440c 10 psi force.
//! The full coverage measurement (50 records, AR(1) noise) is `validation/fit-pair/REPORT.md`.

use shpb_study::fit::observe::Quantity;
use shpb_study::fit::{Problem, Settings, fit};
use shpb_validate::fit_pair::{pair_free, simulated};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

#[test]
fn a_simulated_record_with_white_noise_gives_back_its_truth_and_noise() {
    let scene = root().join("scenes/force-driven-ss440c-10psi.toml");
    let base = Problem::new(&scene, pair_free(1.2e9, 2.6e9).unwrap(), vec![], None, &[]).unwrap();
    assert_eq!(base.series.len(), 1);
    assert_eq!(base.series[0].quantity, Quantity::ApproachTime);
    let truth = [1.9e9, 0.035];
    let sd = 2e-6;
    // White noise: the AR(1) of τ = 1 (φ = 0), seeded.
    let noise = shpb_validate::fit_pair::ar1_noise(base.series[0].y.len(), sd, 1.0, 11);
    let problem = simulated(&base, &truth, &noise).unwrap();
    let settings = Settings {
        walkers: 8,
        steps: 48,
        burn_in: Some(16),
        seed: 3,
        jobs: 2,
        predictive_draws: 1,
        max_least_squares_runs: 0,
        noise_draws: 64,
    };
    let r = fit(&problem, &settings, "test", &mut |_, _, _| {}, &|| true).unwrap();
    // The noise SD from the best fit's residuals: with N = 3844 points its standard error is
    // sd/√(2N) = 1.1 %; 5 % allows for that (4 standard errors) and for a best fit a little off
    // the optimum (which only adds a smooth misfit).
    let rec = &r.records[0];
    assert!(
        (rec.noise_sd / sd - 1.0).abs() < 0.05,
        "noise SD {}",
        rec.noise_sd
    );
    // White residuals: their correlation time is near one point (a misfit would lengthen it).
    assert!(rec.noise_correlation < 1.5, "τ {}", rec.noise_correlation);
    // The truth inside each 90 % interval (seeded: a correct posterior puts it there with
    // probability 0.9 a key; the 50-record rate is the report's).
    for (p, t) in r.parameters.iter().zip(truth) {
        assert!(
            t >= p.band_90[0] && t <= p.band_90[1],
            "{}: {t} outside {:?}",
            p.key,
            p.band_90
        );
    }
}

#[test]
fn a_scene_record_is_counted_from_its_first_sample() {
    // The Fig. 4 Al2017 15 psi record starts at δ(0) = 58.2 µm under 0.2 N (its CSV's first row);
    // the model starts at 0: the fit's record is δ − δ(0).
    let scene = root().join("validation/fig4-force-driven/al2017-15psi.toml");
    let p = Problem::new(&scene, pair_free(1e8, 6e8).unwrap(), vec![], None, &[]).unwrap();
    let y = &p.series[0].y;
    assert_eq!(y[0], 0.0);
    assert!(
        (y[1] - (5.857992e-05 - 5.82111404e-05)).abs() < 1e-15,
        "{}",
        y[1]
    );
}

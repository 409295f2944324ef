//! The fast check of `validation/fit-yao/` (issue 44): Yao et al.'s 945-steel record reduces
//! through its scene's set-up, the scene driven by the record's incident wave runs, and a short
//! `shpb fit` of A, B, n and C returns finite intervals holding its best fit (A and B free, seconds). The full fit is the
//! report generator's (`cargo run --release -p shpb-validate --bin fit_yao`).

use shpb_study::fit::{Settings, fit};
use shpb_validate::fit_yao;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The lab's own largest 2-wave (transmitted) stress and strain on the loading branch.
fn lab_peaks(sample: &str) -> (f64, f64) {
    let (e, s) = fit_yao::lab_loading(&root(), sample).unwrap();
    let peak = s.iter().cloned().fold(f64::MIN, f64::max);
    (peak, *e.last().unwrap())
}

#[test]
fn each_record_reduces_through_its_scene_like_the_labs_and_the_scene_runs() {
    for (sample, _) in fit_yao::SAMPLES {
        let p = fit_yao::problem(&root(), &[sample]).unwrap();
        assert_eq!(p.series.len(), 1, "{sample}: one stress-strain series");
        // Driven by its own record (the scene's [incident_record] replaced by the record).
        assert_eq!(
            p.drives,
            vec![Some(fit_yao::record(&root(), sample))],
            "{sample}"
        );
        let s = &p.series[0];
        let peak = s.y.iter().cloned().fold(f64::MIN, f64::max);
        let strain = s.x.iter().cloned().fold(f64::MIN, f64::max);
        let (lab_peak, lab_strain) = lab_peaks(sample);
        eprintln!(
            "{sample}: {} loading points, peak 1-wave stress {:.0} MPa (lab {:.0}), largest strain {strain:.4} (lab {lab_strain:.4})",
            s.y.len(),
            peak / 1e6,
            lab_peak / 1e6
        );
        // The same transmitted stress with the default filter instead of none, the stated
        // diameter (8 mm) instead of the measured (8.04–8.05 mm, 1.2 % less area): within 3 %,
        // as crates/cli/tests/lab_records.rs holds the 3-wave peak with the lab's windows.
        assert!(
            (peak / lab_peak - 1.0).abs() < 0.03,
            "{sample}: {peak} Pa against the lab's {lab_peak} Pa"
        );
        // The largest strain integrates the reflected wave to where the windows end (automatic
        // here, hand-cut by the lab; 32 ns samples of a ≈ 100 µs pulse): within 5 % of the lab's.
        assert!(
            (strain / lab_strain - 1.0).abs() < 0.05,
            "{sample}: {strain} against the lab's {lab_strain}"
        );
    }
}

#[test]
fn a_short_fit_returns_finite_intervals_holding_its_best_fit() {
    // A and B only (the fewest runs: a 9-point start design, 4 walkers × 4 steps).
    let free = fit_yao::free().unwrap()[..2].to_vec();
    let p = fit_yao::problem_with(&root(), &["sample_01"], free).unwrap();
    let settings = Settings {
        walkers: 4,
        steps: 4,
        burn_in: Some(1),
        seed: 3,
        jobs: 2,
        predictive_draws: 2,
        max_least_squares_runs: 4,
        noise_draws: 64,
    };
    let r = fit(&p, &settings, "test", &mut |_, _, _| {}, &|| true).unwrap();
    for q in &r.parameters {
        let [lo, hi] = q.band_90;
        assert!(lo.is_finite() && hi.is_finite(), "{}: {lo} {hi}", q.key);
        assert!(
            q.min <= lo && lo <= q.best && q.best <= hi && hi <= q.max,
            "{}: best {} outside {lo} – {hi}",
            q.key,
            q.best
        );
    }
    let rec = &r.records[0];
    assert!(rec.noise_sd.is_finite() && rec.noise_sd > 0.0);
    assert_eq!(rec.band_low.len(), rec.y.len());
    assert!((0.0..=1.0).contains(&rec.inside_band));
}

//! Coverage of the intervals of a sphere pair fit and the cross-prediction of the authors' Fig. 4
//! records (issue 44; docs/physics.md §12.8 "Coverage of the intervals (sphere pair)"): simulated
//! records (the model's approach at known constants plus Gaussian AR(1) noise, [`ar1_noise`])
//! fitted by `shpb fit`'s engine ([`shpb_study::fit`]), and a fit's posterior draws run on the
//! same material's other records ([`predict`]).

use shpb_input::Result;
use shpb_output::fit::FitReport;
use shpb_study::fit::noise::Noise;
use shpb_study::fit::observe::{Observables, series_of};
use shpb_study::fit::spec::{Free, parse_free};
use shpb_study::fit::{Problem, Settings, fit};
use shpb_study::uq::{Rng, normal_quantile};
use std::path::Path;

/// The free keys of a pair fit: yield stress σy in [lo, hi] Pa and Johnson–Cook C in [0, 0.1].
pub fn pair_free(yield_lo_pa: f64, yield_hi_pa: f64) -> Result<Vec<Free>> {
    Ok(vec![
        parse_free(&format!(
            "specimen.yield_stress_pa={yield_lo_pa}:{yield_hi_pa}"
        ))?,
        parse_free("specimen.jc_c=0:0.1")?,
    ])
}

/// The lag-one coefficient φ of the AR(1) process with integrated autocorrelation time `tau`
/// points: τ = 1 + 2 Σ φᵏ = (1 + φ)/(1 − φ), so φ = (τ − 1)/(τ + 1).
pub fn ar1_phi(tau: f64) -> f64 {
    let tau = tau.max(1.0);
    (tau - 1.0) / (tau + 1.0)
}

/// `n` points of stationary Gaussian AR(1) noise, x₀ ~ N(0, sd²), x_{t+1} = φ x_t + √(1 − φ²) sd e_t
/// (marginal SD `sd`, integrated autocorrelation time `tau` points, [`ar1_phi`]), seeded.
pub fn ar1_noise(n: usize, sd: f64, tau: f64, seed: u64) -> Vec<f64> {
    let phi = ar1_phi(tau);
    let innovation = sd * (1.0 - phi * phi).sqrt();
    let mut rng = Rng::new(seed);
    let mut x = Vec::with_capacity(n);
    let mut v = sd * normal_quantile(rng.uniform());
    for _ in 0..n {
        x.push(v);
        v = phi * v + innovation * normal_quantile(rng.uniform());
    }
    x
}

/// The question of a simulated record: `base`'s scene, free keys and residual, its record the
/// model's series at `truth` plus `noise` (one value a point of `base`'s series, in order),
/// built through the engine's own [`series_of`] from the noisy observables. None when the run at
/// `truth` fails.
pub fn simulated(base: &Problem, truth: &[f64], noise: &[f64]) -> Option<Problem> {
    let model = base.model(truth)?;
    let s = base.series.first()?;
    let y: Vec<f64> = model[0].iter().zip(noise).map(|(m, e)| m + e).collect();
    let o = Observables {
        time_s: s.x.clone(),
        approach_m: Some(y),
        force_is_drive: base.force_driven,
        ..Observables::default()
    };
    let series = series_of("simulated", &o, base.residual, base.force_driven).ok()?;
    Some(Problem {
        series,
        ..base.clone()
    })
}

/// One simulated record's fit against its truth.
#[derive(Debug, Clone)]
pub struct Coverage {
    /// The true values, in the order of the free keys.
    pub truth: Vec<f64>,
    /// Posterior medians.
    pub median: Vec<f64>,
    /// 90 % intervals (5 % and 95 % quantiles).
    pub band_90: Vec<[f64; 2]>,
    /// The truth lies inside each interval.
    pub inside: Vec<bool>,
    /// The fit's noise model: SD of a point, m.
    pub noise_sd: f64,
    /// The fit's noise model: integrated autocorrelation time, points.
    pub noise_tau_points: f64,
    /// Largest autocorrelation time of the chain over the keys, steps.
    pub chain_tau_steps: f64,
    /// Smallest effective sample size over the keys.
    pub ess: f64,
    /// Acceptance fraction.
    pub acceptance: f64,
    /// Steps kept after burn-in.
    pub kept_steps: usize,
    /// The fit's warnings.
    pub warnings: Vec<String>,
}

impl Coverage {
    /// Reads the outcome off a fit report of a record simulated at `truth`.
    pub fn of(report: &FitReport, truth: &[f64]) -> Coverage {
        let p = &report.parameters;
        let band_90: Vec<[f64; 2]> = p.iter().map(|q| q.band_90).collect();
        Coverage {
            truth: truth.to_vec(),
            median: p.iter().map(|q| q.median).collect(),
            inside: band_90
                .iter()
                .zip(truth)
                .map(|(b, &t)| t >= b[0] && t <= b[1])
                .collect(),
            band_90,
            noise_sd: report.records[0].noise_sd,
            noise_tau_points: report.records[0].noise_correlation,
            chain_tau_steps: p.iter().map(|q| q.tau_steps).fold(0.0, f64::max),
            ess: p.iter().map(|q| q.ess).fold(f64::INFINITY, f64::min),
            acceptance: report.acceptance,
            kept_steps: report.steps - report.burn_in,
            warnings: report.warnings.clone(),
        }
    }
}

/// Fits one record simulated from `base` at `truth` with AR(1) noise (`sd`, `tau` points,
/// `seed`) and reads its coverage.
pub fn fit_simulated(
    base: &Problem,
    truth: &[f64],
    sd: f64,
    tau: f64,
    seed: u64,
    settings: &Settings,
) -> Result<Coverage> {
    let n = base.series.first().map_or(0, |s| s.y.len());
    let noise = ar1_noise(n, sd, tau, seed);
    let problem = simulated(base, truth, &noise).ok_or_else(|| shpb_input::Error::Input {
        file: base.scene.display().to_string(),
        key: "--free".into(),
        problem: format!("the run at the truth {truth:?} failed"),
        allowed: "truths within which the scene runs".into(),
    })?;
    let report = fit(&problem, settings, "fit_pair", &mut |_, _, _| {}, &|| true)?;
    Ok(Coverage::of(&report, truth))
}

/// `k` posterior draws of a fit report, evenly spaced over its samples after burn-in.
pub fn draws(report: &FitReport, k: usize) -> Vec<Vec<f64>> {
    let p = report.parameters.len();
    let rows: Vec<&[f64]> = report.samples().chunks(p).collect();
    if rows.is_empty() {
        return Vec::new();
    }
    let k = k.clamp(1, rows.len());
    (0..k).map(|i| rows[i * rows.len() / k].to_vec()).collect()
}

/// A fit's constants run on another record of the same material.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// The other record's times, s.
    pub time_s: Vec<f64>,
    /// Its measured approach (from its first sample), m.
    pub measured_m: Vec<f64>,
    /// The model's approach at the fit's best constants, m.
    pub best_m: Vec<f64>,
    /// 90 % posterior-predictive band: the runs at the draws plus the fit's noise, m.
    pub band_low_m: Vec<f64>,
    /// Its upper edge, m.
    pub band_high_m: Vec<f64>,
    /// RMS of measured − best over the record, over the record's peak approach.
    pub rms_relative: f64,
    /// Fraction of the record's points inside the band.
    pub inside_band: f64,
}

/// Runs the scene `other` (a force-driven scene whose CSV carries its approach) at the best
/// constants and at `draws` of a fit of `free`, with that fit's noise SD `noise_sd` for the
/// predictive band (Noise::predictive_band, seeded by `seed`). None when a run fails.
pub fn predict(
    other: &Path,
    free: &[Free],
    best: &[f64],
    draws: &[Vec<f64>],
    noise_sd: f64,
    seed: u64,
) -> Result<Option<Prediction>> {
    let problem = Problem::new(other, free.to_vec(), Vec::new(), None, &[])?;
    let s = &problem.series[0];
    let Some(best_m) = problem.model(best).map(|mut m| m.swap_remove(0)) else {
        return Ok(None);
    };
    let models: Vec<Vec<f64>> = {
        use rayon::prelude::*;
        draws
            .par_iter()
            .filter_map(|d| problem.model(d).map(|mut m| m.swap_remove(0)))
            .collect()
    };
    let noise = Noise {
        sd: noise_sd,
        correlation_points: 1.0,
        calibration: 1.0,
    };
    let (low, high) = noise.predictive_band(models.iter().map(Vec::as_slice), s.y.len(), seed);
    let peak = s.y.iter().cloned().fold(0.0, f64::max);
    let n = s.y.len() as f64;
    let rms =
        (s.y.iter()
            .zip(&best_m)
            .map(|(y, m)| (y - m).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
    let inside = shpb_study::fit::noise::inside_fraction(&s.y, &low, &high);
    Ok(Some(Prediction {
        time_s: s.x.clone(),
        measured_m: s.y.clone(),
        best_m,
        band_low_m: low,
        band_high_m: high,
        rms_relative: rms / peak,
        inside_band: inside,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ar1_noise_has_its_sd_and_correlation_time() {
        // 200 000 points of τ = 9 (φ = 0.8): the estimator's own test tolerance (10 %) for τ; the
        // SD's standard error is ≈ sd √(τ/(2n)) = 0.5 %, so 3 % is six of them.
        let x = ar1_noise(200_000, 2.0, 9.0, 5);
        assert!((ar1_phi(9.0) - 0.8).abs() < 1e-12);
        let sd = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        assert!((sd - 2.0).abs() < 0.06, "{sd}");
        let tau = shpb_study::fit::noise::autocorrelation_time(&x);
        assert!((tau - 9.0).abs() < 0.9, "{tau}");
    }
}

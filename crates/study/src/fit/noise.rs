//! The noise model of a fit (docs/physics.md §12.3), estimated from the records: each series'
//! residual at the least-squares best fit gives the standard deviation of one point and the
//! noise's correlation length (its integrated autocorrelation time in points, Sokal's automatic
//! window), so that N correlated points weigh as N/τ independent ones in the Gaussian likelihood.
//! What the model cannot reproduce (its own error) is counted as noise: the intervals include it.
//!
//! A record reduced from gauges is noisy on both axes (a stress–strain record's strain is
//! integrated from a noisy wave), which σ and τ of the stress residual alone under-count along
//! the directions the model moves in. Such fits calibrate the noise on simulated records: the
//! scene at the best fit run with the set-up's digitiser noise, reduced like the records, and
//! their residuals projected on the model's directions ([`calibration`], docs/physics.md §12.3).

use crate::uq::{Rng, normal_quantile, percentile};

/// The noise of one series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Standard deviation of one point, in the series' units.
    pub sd: f64,
    /// Integrated autocorrelation time of the residual, points (1 for white noise).
    pub correlation_points: f64,
    /// Factor on the likelihood's variance σ²τ from simulated records ([`calibration`]; 1:
    /// none).
    pub calibration: f64,
}

/// A simulated record for [`calibration`]: its residual at the truth and the model's directions
/// at its points.
pub type SimulatedRecord = (Vec<f64>, Vec<Vec<f64>>);

/// The noise model's calibration from simulated records: for each record k its residual at the
/// truth r_k and the model's directions v_i at its points (the change of the model for a step of
/// each free value), the mean of (v_i·r_k)²/|v_i|² (the noise's variance along v_i) over the
/// mean σ²τ of the r_k ([`Noise::of_residuals`]): how much more (> 1) or less the noise varies
/// along the directions that decide the fit than the stationary model says. None without
/// records or directions.
pub fn calibration(records: &[SimulatedRecord], free: usize) -> Option<f64> {
    let mut along = Vec::new();
    let mut model = Vec::new();
    for (r, dirs) in records {
        let n = Noise::of_residuals(r, free, 1);
        model.push(n.sd * n.sd * n.correlation_points);
        for v in dirs {
            let vv: f64 = v.iter().map(|a| a * a).sum();
            if vv > 0.0 && v.len() == r.len() {
                along.push(v.iter().zip(r).map(|(a, b)| a * b).sum::<f64>().powi(2) / vv);
            }
        }
    }
    if along.is_empty() || model.is_empty() {
        return None;
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let c = mean(&along) / mean(&model);
    c.is_finite().then_some(c)
}

/// Integrated autocorrelation time of a series, in samples: τ = 1 + 2 Σ_{k=1}^{M} ρ(k) with
/// Sokal's automatic window (the sampler's estimator, [`super::mcmc::windowed_time`]); at least
/// 1 (anticorrelated residuals are not counted as more than independent).
pub fn autocorrelation_time(x: &[f64]) -> f64 {
    if x.len() < 4 {
        return 1.0;
    }
    super::mcmc::windowed_time(&super::mcmc::autocorrelation(x)).max(1.0)
}

/// The fraction of a record's points `y` inside a band [`low`, `high`] (NaN without a band):
/// `inside_band` of a fit's records.
pub fn inside_fraction(y: &[f64], low: &[f64], high: &[f64]) -> f64 {
    if low.is_empty() || y.is_empty() {
        return f64::NAN;
    }
    y.iter()
        .zip(low.iter().zip(high))
        .filter(|(y, (l, h))| *y >= *l && *y <= *h)
        .count() as f64
        / y.len() as f64
}

impl Noise {
    /// The noise of residuals `r` (record − best model) of one of `series` series of a fit with
    /// `free` free values: SD with the free values' degrees of freedom shared among the series,
    /// √(Σ r² / (N − free/series)), and the residuals' correlation time.
    pub fn of_residuals(r: &[f64], free: usize, series: usize) -> Noise {
        let n = r.len() as f64;
        let dof = (n - free as f64 / series.max(1) as f64).max(1.0);
        let sd = (r.iter().map(|v| v * v).sum::<f64>() / dof).sqrt();
        Noise {
            sd: if sd > 0.0 { sd } else { f64::MIN_POSITIVE },
            correlation_points: autocorrelation_time(r),
            calibration: 1.0,
        }
    }

    /// ln L of record `y` given model `m` under this noise, up to a constant:
    /// −Σ (y − m)² / (2 c σ² τ), c the calibration.
    pub fn log_likelihood(&self, y: &[f64], m: &[f64]) -> f64 {
        let ss: f64 = y.iter().zip(m).map(|(y, m)| (y - m).powi(2)).sum();
        -ss / (2.0 * self.calibration * self.sd * self.sd * self.correlation_points)
    }

    /// The 90 % posterior-predictive band (5 % and 95 % quantiles, point by point) of `models`
    /// (the model at posterior draws) plus this noise: 16 normal noise draws per model, seeded.
    /// Empty when no model is given.
    pub fn predictive_band<'a>(
        &self,
        models: impl Iterator<Item = &'a [f64]>,
        points: usize,
        seed: u64,
    ) -> (Vec<f64>, Vec<f64>) {
        const PER_MODEL: usize = 16;
        let models: Vec<&[f64]> = models.collect();
        if models.is_empty() {
            return (Vec::new(), Vec::new());
        }
        let mut rng = Rng::new(seed);
        let mut low = Vec::with_capacity(points);
        let mut high = Vec::with_capacity(points);
        let mut values = Vec::with_capacity(models.len() * PER_MODEL);
        for i in 0..points {
            values.clear();
            for m in &models {
                for _ in 0..PER_MODEL {
                    values.push(m[i] + self.sd * normal_quantile(rng.uniform()));
                }
            }
            values.sort_by(f64::total_cmp);
            low.push(percentile(&values, 0.05));
            high.push(percentile(&values, 0.95));
        }
        (low, high)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_ar1_series_has_its_known_correlation_time() {
        // x_{t+1} = φ x_t + e: τ = (1 + φ)/(1 − φ) = 9 for φ = 0.8.
        let mut rng = Rng::new(7);
        let mut x = vec![0.0; 200_000];
        for t in 1..x.len() {
            x[t] = 0.8 * x[t - 1] + normal_quantile(rng.uniform());
        }
        let tau = autocorrelation_time(&x);
        assert!((tau - 9.0).abs() < 0.1 * 9.0, "{tau}");
        let white: Vec<f64> = (0..100_000)
            .map(|_| normal_quantile(rng.uniform()))
            .collect();
        assert!((autocorrelation_time(&white) - 1.0).abs() < 0.1);
    }

    #[test]
    fn the_band_of_one_exact_model_is_its_noise_band() {
        // 40 draws of a model 0 everywhere, noise SD 2: 640 values a point, whose 5 % quantile
        // has a standard error of √(0.05 × 0.95 / 640) / φ(1.645) = 0.084 SD; the mean over 2000
        // points is within 0.01 SD of ±1.645 × 2 = ±3.29.
        let n = Noise {
            sd: 2.0,
            correlation_points: 1.0,
            calibration: 1.0,
        };
        let m = vec![0.0; 2000];
        let (lo, hi) = n.predictive_band((0..40).map(|_| m.as_slice()), 2000, 3);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        assert!((mean(&hi) - 3.29).abs() < 0.03, "{}", mean(&hi));
        assert!((mean(&lo) + 3.29).abs() < 0.03, "{}", mean(&lo));
    }

    #[test]
    fn correlated_points_weigh_as_fewer_independent_ones() {
        let a = Noise {
            sd: 1.0,
            correlation_points: 1.0,
            calibration: 1.0,
        };
        let b = Noise {
            sd: 1.0,
            correlation_points: 4.0,
            calibration: 1.0,
        };
        let y = [1.0, 2.0];
        let m = [0.0, 0.0];
        assert_eq!(a.log_likelihood(&y, &m), -2.5);
        assert_eq!(b.log_likelihood(&y, &m), -2.5 / 4.0);
    }

    #[test]
    fn the_calibration_finds_noise_the_stationary_model_misses() {
        // Records of white noise (SD 1) plus a random offset of SD 0.1 over 400 points: along the
        // constant direction the noise's variance is 1 + 400 × 0.01 = 5 where the stationary model
        // (σ² ≈ 1.01, τ ≈ 1) says ≈ 1; along a direction orthogonal to constants (a ±1 square
        // wave) the offset is invisible and the ratio is 1. Mean of 400 records: within 20 %
        // (the projections are χ²₁: relative SD √2/√400 = 7 %).
        let mut rng = Rng::new(5);
        let n = 400;
        let records = |dir: &[f64], rng: &mut Rng| -> Vec<SimulatedRecord> {
            (0..400)
                .map(|_| {
                    let o = 0.1 * normal_quantile(rng.uniform());
                    let r: Vec<f64> = (0..n).map(|_| o + normal_quantile(rng.uniform())).collect();
                    (r, vec![dir.to_vec()])
                })
                .collect()
        };
        let flat = vec![1.0; n];
        let c = calibration(&records(&flat, &mut rng), 0).unwrap();
        assert!((c - 5.0).abs() < 1.0, "{c}");
        let square: Vec<f64> = (0..n)
            .map(|i| if (i / 20) % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let c = calibration(&records(&square, &mut rng), 0).unwrap();
        assert!((c - 1.0).abs() < 0.2, "{c}");
    }
}

//! The authors' eight records (2013-05-22) reduced twice, with the Bancroft fit and with the
//! exact Pochhammer–Chree first mode (docs/physics.md §7.9), and the difference set against each
//! record's noise: the report `validation/dispersion/REPORT.md` (`src/bin/dispersion_report.rs`)
//! and the test `tests/dispersion_records.rs` read the same numbers from [`compare_records`].

use crate::gauge_records::{SAMPLES, Sample};
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::RawRecord;
use shpb_core::numeric::spectral_filter;
use shpb_core::reduce::{
    BANCROFT_FIT, DispersionCorrection, Reduction, ReductionOptions, ReductionSetup,
    quality::baseline_rms, record_strains, reduce_named,
};
use shpb_input::Result;
use shpb_input::prelude::*;
use std::path::Path;

/// One record reduced both ways.
#[derive(Debug, Clone)]
pub struct RecordComparison {
    /// The record.
    pub sample: Sample,
    /// Reduction with the Bancroft fit (the default).
    pub bancroft: Reduction,
    /// Reduction with the exact first mode.
    pub exact: Reduction,
    /// Reduction with the exact first mode and the Tyas–Pope amplitude factors.
    pub exact_tyas_pope: Reduction,
    /// RMS of the transmission gauge's pre-trigger strain (baseline removed) times E A, N: the
    /// noise of one sample of the back force.
    pub back_noise_n: f64,
    /// RMS of the incident gauge's pre-trigger strain times E A √2, N: the noise of one sample of
    /// the front force (the sum of two independent samples of that channel).
    pub front_noise_n: f64,
    /// [`Self::back_noise_n`] in the pulses' band ([`low_pass`]), N.
    pub back_noise_band_n: f64,
    /// [`Self::front_noise_n`] in the pulses' band ([`low_pass`]), N.
    pub front_noise_band_n: f64,
    /// Sample step, s.
    pub dt_s: f64,
    /// What the fit's long-wave offset alone changes in the front force, N: the fit's c → (A + B)
    /// c0 moves the incident and reflected waves by τ0 = d_I/c0 (1 − 1/(A + B)) each way, so
    /// |ΔF_front| ≤ E A τ0 (max|ε̇_I| + max|ε̇_R|) (in-band strain rates of the Bancroft reduction).
    pub front_offset_bound_n: f64,
    /// The same for the back force: E A τ0_T max|ε̇_T|, τ0_T = d_T/c0 (1 − 1/(A + B)), N.
    pub back_offset_bound_n: f64,
}

/// Largest |dv/dt| of `v` (step `dt_s`) by central differences.
fn max_rate(v: &[f64], dt_s: f64) -> f64 {
    v.windows(3)
        .fold(0.0f64, |m, w| m.max(((w[2] - w[0]) / (2.0 * dt_s)).abs()))
}

/// Upper edge of the pulses' band, Hz: the records' pulses rise in 40–60 µs, and the report
/// states the share of each force's energy above this edge (f a/c0 = 0.098 on the authors' bars).
pub const BAND_EDGE_HZ: f64 = 50e3;

/// `v` (step `dt_s`) with every Fourier component above [`BAND_EDGE_HZ`] removed (zero phase).
///
/// The series is extended by its mirror image at both ends (…, v1, v0 | v0, v1, …, vn-1 |
/// vn-1, …) before the filter, so that no single end sample is held over the filter's padding:
/// [`spectral_filter`] alone joins the last sample to the first through its padding, which puts
/// that one sample's noise, at nearly full amplitude, into the band at the series' ends.
pub fn low_pass(v: &[f64], dt_s: f64) -> Vec<f64> {
    let n = v.len();
    let mirrored: Vec<f64> = v
        .iter()
        .rev()
        .chain(v)
        .chain(v.iter().rev())
        .copied()
        .collect();
    let filtered = spectral_filter(&mirrored, dt_s, |b| {
        (
            0.0,
            if b.frequency_hz <= BAND_EDGE_HZ {
                1.0
            } else {
                0.0
            },
        )
    });
    filtered[n..2 * n].to_vec()
}

/// Share of the energy Σv² of `v` that lies above [`BAND_EDGE_HZ`].
pub fn energy_above_band(v: &[f64], dt_s: f64) -> f64 {
    let low = low_pass(v, dt_s);
    let total: f64 = v.iter().map(|x| x * x).sum();
    let high: f64 = v.iter().zip(&low).map(|(x, l)| (x - l) * (x - l)).sum();
    high / total.max(f64::MIN_POSITIVE)
}

/// Largest |a − b| over two series of equal length.
pub fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// RMS of a − b over two series of equal length.
pub fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / n as f64).sqrt()
}

impl RecordComparison {
    /// Largest |ΔF_back| between the two reductions, N.
    pub fn max_back_difference_n(&self) -> f64 {
        max_abs_difference(&self.exact.force_back_n, &self.bancroft.force_back_n)
    }

    /// Largest |ΔF_front| between the two reductions, N.
    pub fn max_front_difference_n(&self) -> f64 {
        max_abs_difference(&self.exact.force_front_n, &self.bancroft.force_front_n)
    }

    /// RMS of ΔF_back over the window, N.
    pub fn rms_back_difference_n(&self) -> f64 {
        rms_difference(&self.exact.force_back_n, &self.bancroft.force_back_n)
    }

    /// RMS of ΔF_front over the window, N.
    pub fn rms_front_difference_n(&self) -> f64 {
        rms_difference(&self.exact.force_front_n, &self.bancroft.force_front_n)
    }

    /// Largest |ΔF_back| in the pulses' band (both series through [`low_pass`]), N.
    pub fn max_back_difference_band_n(&self) -> f64 {
        max_abs_difference(
            &low_pass(&self.exact.force_back_n, self.dt_s),
            &low_pass(&self.bancroft.force_back_n, self.dt_s),
        )
    }

    /// |Δ| of the peak back force in the pulses' band (both series through [`low_pass`]), N.
    pub fn peak_back_difference_band_n(&self) -> f64 {
        let peak = |v: &[f64]| {
            low_pass(v, self.dt_s)
                .into_iter()
                .fold(f64::NEG_INFINITY, f64::max)
        };
        (peak(&self.exact.force_back_n) - peak(&self.bancroft.force_back_n)).abs()
    }

    /// Largest |ΔF_front| in the pulses' band (both series through [`low_pass`]), N.
    pub fn max_front_difference_band_n(&self) -> f64 {
        self.largest_front_difference_band().1
    }

    /// Where in the window (sample index) the largest |ΔF_front| in the pulses' band lies, and
    /// its size, N.
    pub fn largest_front_difference_band(&self) -> (usize, f64) {
        low_pass(&self.exact.force_front_n, self.dt_s)
            .iter()
            .zip(low_pass(&self.bancroft.force_front_n, self.dt_s))
            .map(|(x, y)| (x - y).abs())
            .enumerate()
            .fold((0, 0.0f64), |b, (i, m)| if m > b.1 { (i, m) } else { b })
    }
}

/// Reduces each of the eight records (`validation/gauge-records/data` below `root`) with the
/// authors' set-up (`bars/authors.toml`), once with the Bancroft fit and once with the exact
/// first mode, on the raw samples (no smoothing: the comparison is with the records' own noise),
/// all other options at their defaults.
pub fn compare_records(root: &Path) -> Result<Vec<RecordComparison>> {
    let app = Apparatus::from_file(&root.join("bars/authors.toml"))?;
    let setup = ReductionSetup::from_apparatus(&app)?;
    let bancroft = ReductionOptions {
        smoothing_window_s: 0.0,
        filter: shpb_core::reduce::Filter::None,
        ..ReductionOptions::default()
    };
    let exact = ReductionOptions {
        dispersion: DispersionCorrection::PochhammerChree,
        ..bancroft
    };
    let mut rows = Vec::new();
    for sample in SAMPLES {
        let path = sample.record_path(root);
        let name = path.display().to_string();
        let rec = RawRecord::read(&path)?;
        let input = record_strains(&rec, &app, bancroft.baseline_samples)?;
        let b = reduce_named(&input, &setup, &bancroft, &name)?;
        let e = reduce_named(&input, &setup, &exact, &name)?;
        let tp = reduce_named(
            &input,
            &setup,
            &ReductionOptions {
                tyas_pope: true,
                ..exact
            },
            &name,
        )?;
        let nb = b.windows.baseline_samples;
        let dt_s = rec.sample_interval_s();
        let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
        let (ea_i, ea_t) = (
            bi.youngs_modulus_pa * bi.area_m2,
            bt.youngs_modulus_pa * bt.area_m2,
        );
        let (inc, tra) = (
            &input.incident_strain[..nb],
            &input.transmission_strain[..nb],
        );
        let offset = 1.0 - 1.0 / (BANCROFT_FIT[0] + BANCROFT_FIT[1]);
        let tau_i = setup.incident_gauge_m / bi.wave_speed_m_s * offset;
        let tau_t = setup.transmission_gauge_m / bt.wave_speed_m_s * offset;
        let front_offset_bound_n = ea_i
            * tau_i
            * (max_rate(&low_pass(&b.incident_strain, dt_s), dt_s)
                + max_rate(&low_pass(&b.reflected_strain, dt_s), dt_s));
        let back_offset_bound_n =
            ea_t * tau_t * max_rate(&low_pass(&b.transmitted_strain, dt_s), dt_s);
        rows.push(RecordComparison {
            sample,
            bancroft: b,
            exact: e,
            exact_tyas_pope: tp,
            back_noise_n: ea_t * baseline_rms(tra, nb),
            front_noise_n: ea_i * baseline_rms(inc, nb) * std::f64::consts::SQRT_2,
            back_noise_band_n: ea_t * baseline_rms(&low_pass(tra, dt_s), nb),
            front_noise_band_n: ea_i
                * baseline_rms(&low_pass(inc, dt_s), nb)
                * std::f64::consts::SQRT_2,
            dt_s,
            front_offset_bound_n,
            back_offset_bound_n,
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The records' step, s (10 MHz).
    const DT_S: f64 = 1e-7;

    #[test]
    fn one_noisy_end_sample_stays_out_of_the_band() {
        // A single sample at the series' end carries 2 f_c Δt = 1 % of its amplitude into the
        // band (twice that once mirrored); held over the padding it would carry about half.
        let mut v = vec![0.0; 2325];
        v[0] = 1.0;
        let low = low_pass(&v, DT_S);
        assert!(low[0].abs() < 0.03, "{}", low[0]);
        let n = v.len();
        v[0] = 0.0;
        v[n - 1] = 1.0;
        let low = low_pass(&v, DT_S);
        assert!(low[n - 1].abs() < 0.03, "{}", low[n - 1]);
    }

    #[test]
    fn a_pulse_inside_the_band_passes_unchanged() {
        // A Gaussian pulse, σ = 15 µs (its spectrum exp(−(2π f σ)²/2) is 1.5e-5 of its peak at
        // 50 kHz), in the window's middle: the filter returns it to that order, ends included.
        let n = 2325;
        let sigma_s = 15e-6;
        let v: Vec<f64> = (0..n)
            .map(|i| {
                let t = (i as f64 - 1100.0) * DT_S / sigma_s;
                (-0.5 * t * t).exp()
            })
            .collect();
        let low = low_pass(&v, DT_S);
        let err = max_abs_difference(&low, &v);
        assert!(err < 1e-4, "{err}");
    }
}

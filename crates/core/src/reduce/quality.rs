//! Quality checks of a reduction, with their numbers (docs/physics.md §7.7): equilibrium over the
//! loading with a verdict, whether the incident and reflected pulses overlap at the incident
//! gauge, and each channel's noise floor against its signal.

/// Largest front/back imbalance over the loading for a specimen to be called in equilibrium:
/// R = |F_front − F_back| / F_mean ≤ 0.05 (Ravichandran & Subhash 1994, J. Am. Ceram. Soc. 77:263).
pub const EQUILIBRIUM_TOLERANCE: f64 = 0.05;

/// Smallest peak-to-baseline-RMS ratio of a channel before a warning: 20 (26 dB), below which
/// the noise moves the 2 % foot of a pulse by more than its own rise fraction.
pub const MINIMUM_SIGNAL_TO_NOISE: f64 = 20.0;

/// Whether the specimen was in force equilibrium over the loading (docs/physics.md §7.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EquilibriumVerdict {
    /// R ≤ 0.05 at every sample of the loading span.
    Equilibrium,
    /// R ≤ 0.05 on average over the loading span, but not at every sample.
    Marginal,
    /// R > 0.05 on average over the loading span.
    NotInEquilibrium,
}

impl EquilibriumVerdict {
    /// The name written to files and printed (`equilibrium`, `marginal`, `not in equilibrium`).
    pub fn name(self) -> &'static str {
        match self {
            EquilibriumVerdict::Equilibrium => "equilibrium",
            EquilibriumVerdict::Marginal => "marginal",
            EquilibriumVerdict::NotInEquilibrium => "not in equilibrium",
        }
    }
}

/// The quality checks of one reduction (docs/physics.md §7.7).
#[derive(Debug, Clone, PartialEq)]
pub struct Quality {
    /// Loading span of the 3-wave force, (start, end) on the reduction's time axis, s: from its
    /// first sample at 25 % of its peak to the peak.
    pub loading_span_s: (f64, f64),
    /// Mean of the equilibrium ratio over the loading span.
    pub equilibrium_mean: f64,
    /// Largest equilibrium ratio over the loading span.
    pub equilibrium_max: f64,
    /// Verdict from the two against [`EQUILIBRIUM_TOLERANCE`].
    pub verdict: EquilibriumVerdict,
    /// Duration of the incident pulse at the incident gauge, foot to its fall below the foot
    /// level, s (the record's end if it never falls).
    pub incident_duration_s: f64,
    /// How much the incident pulse outlasts the reflected delay (0: the two are separate at the
    /// incident gauge), s.
    pub pulse_overlap_s: f64,
    /// Baseline RMS strain of the incident and transmission channels.
    pub noise_strain: (f64, f64),
    /// Largest |strain| over each channel's window divided by its baseline RMS.
    pub signal_to_noise: (f64, f64),
}

/// The rise of `y` to its peak: (first sample at `fraction` of the peak, peak), sample indices.
pub(crate) fn rising_span(y: &[f64], fraction: f64) -> (usize, usize) {
    let k_peak = crate::numeric::argmax(y);
    let level = fraction * y[k_peak];
    let k_start = (0..=k_peak).find(|&k| y[k] >= level).unwrap_or(k_peak);
    (k_start, k_peak)
}

/// RMS of the first `n` samples (0 when n is 0): a record's pre-trigger noise.
pub fn baseline_rms(v: &[f64], n: usize) -> f64 {
    let n = n.min(v.len());
    if n == 0 {
        return 0.0;
    }
    (v[..n].iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt()
}

/// Mean and maximum of the equilibrium ratio over the loading span of `force_3wave` (first sample
/// at 25 % of its peak to the peak), the span's sample indices, and the verdict.
pub(crate) fn equilibrium_over_loading(
    force_3wave_n: &[f64],
    equilibrium_ratio: &[f64],
) -> ((usize, usize), f64, f64, EquilibriumVerdict) {
    let (k_start, k_peak) = rising_span(force_3wave_n, 0.25);
    let span = &equilibrium_ratio[k_start..=k_peak];
    let mean = span.iter().sum::<f64>() / span.len() as f64;
    let max = span.iter().copied().fold(0.0, f64::max);
    let verdict = if max <= EQUILIBRIUM_TOLERANCE {
        EquilibriumVerdict::Equilibrium
    } else if mean <= EQUILIBRIUM_TOLERANCE {
        EquilibriumVerdict::Marginal
    } else {
        EquilibriumVerdict::NotInEquilibrium
    };
    ((k_start, k_peak), mean, max, verdict)
}

/// Duration of the incident pulse at its gauge: from the foot (sample `k_foot`) to the first
/// sample after the peak `k_peak` where the compression `−ε` falls below `level`, s.
pub(crate) fn incident_duration_s(
    eps_i: &[f64],
    dt: f64,
    k_foot: usize,
    k_peak: usize,
    level: f64,
) -> f64 {
    let end = (k_peak..eps_i.len())
        .find(|&k| -eps_i[k] < level)
        .unwrap_or(eps_i.len() - 1);
    (end.saturating_sub(k_foot)) as f64 * dt
}

/// Metrics of one wave at a specimen face (peak, rise, duration, energy): what a lab reads off
/// its pulses (docs/physics.md §7.7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveMetrics {
    /// Peak stress E·|ε|, in the wave's own sense (compression for the incident and transmitted
    /// waves, tension for the reflected one), Pa.
    pub peak_stress_pa: f64,
    /// Time from the 10 % to the 90 % crossing of the rise, s.
    pub rise_10_90_s: f64,
    /// Time between the rising and falling 10 % crossings, s (NaN if the window ends first).
    pub duration_10_s: f64,
    /// Energy the wave carries over the window, E A c0 ∫ε² dt, J.
    pub energy_j: f64,
}

/// [`WaveMetrics`] of a strain window (`compressive`: the wave is compressive, ε < 0) on a bar,
/// with crossings interpolated between samples: the rise needs the 10 % and 90 % crossings
/// before the peak, the duration also the falling 10 % one (NaN when the window ends first, as
/// a reflected or transmitted pulse longer than the window does). None if the window holds no
/// pulse of that sense or its rise is cut off.
pub fn wave_metrics(
    time_s: &[f64],
    strain: &[f64],
    bar: &super::BarProperties,
    compressive: bool,
) -> Option<WaveMetrics> {
    let sign = if compressive { -1.0 } else { 1.0 };
    let e = crate::gauge::pulse_edges(time_s, strain, sign)?;
    let dt = time_s[1] - time_s[0];
    let e_a_c = bar.youngs_modulus_pa * bar.area_m2 * bar.wave_speed_m_s;
    Some(WaveMetrics {
        peak_stress_pa: bar.youngs_modulus_pa * e.peak,
        rise_10_90_s: e.rise_90_s - e.start_10_s,
        duration_10_s: e.fall_10_s.map_or(f64::NAN, |end| end - e.start_10_s),
        energy_j: e_a_c * strain.iter().map(|e| e * e).sum::<f64>() * dt,
    })
}

/// The fourth stage's checks (docs/physics.md §7.7): equilibrium over the loading, the incident
/// pulse's length against the reflected delay, each channel's signal against its noise;
/// `warnings` gets an overlap and a weak channel.
pub(crate) fn assess(
    options: &super::ReductionOptions,
    strains: &super::baseline::Conditioned,
    placed: &super::windows::Placed,
    waves: &super::waves::FaceWaves,
    warnings: &mut Vec<String>,
) -> Quality {
    let dt = strains.dt;
    let f = &waves.faces;
    let samples = placed.windows.samples;
    let reflected_delay_s = placed.windows.reflected_delay_s;
    let ((ka, kb), equilibrium_mean, equilibrium_max, verdict) =
        equilibrium_over_loading(&f.force_3wave_n, &f.equilibrium_ratio);
    let manual_start = options.window.is_some_and(|w| w.incident_start_s.is_some());
    let incident_duration_s = match strains.incident_foot {
        Some((k_foot, k_peak)) if !manual_start => incident_duration_s(
            &strains.incident,
            dt,
            k_foot,
            k_peak,
            options.start_fraction * strains.incident_peak,
        ),
        _ => f64::NAN,
    };
    let pulse_overlap_s = (incident_duration_s - reflected_delay_s).max(0.0);
    if pulse_overlap_s > 0.0 {
        warnings.push(format!(
            "the incident pulse lasts {:.1} µs at its gauge but the reflected one arrives {:.1} µs \
             after its foot: they overlap there, and the windows ({:.1} µs) miss the last {:.1} µs \
             of the incident pulse",
            incident_duration_s * 1e6,
            reflected_delay_s * 1e6,
            (samples - 1) as f64 * dt * 1e6,
            (incident_duration_s - (samples - 1) as f64 * dt).max(0.0) * 1e6
        ));
    }
    let noise_strain = (
        baseline_rms(&strains.incident, strains.baseline_samples),
        strains.transmission_noise,
    );
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let snr = |peak: f64, noise: f64| {
        if noise > 0.0 {
            peak / noise
        } else {
            f64::INFINITY
        }
    };
    let signal_to_noise = (
        snr(largest(&waves.incident), noise_strain.0),
        snr(largest(&waves.transmitted), noise_strain.1),
    );
    for (name, s) in [
        ("incident", signal_to_noise.0),
        ("transmission", signal_to_noise.1),
    ] {
        if s < MINIMUM_SIGNAL_TO_NOISE {
            warnings.push(format!(
                "the {name} channel's pulse is only {s:.1} times its baseline noise (RMS): feet \
                 and peaks are uncertain (smooth with --smooth, or check the gauge)"
            ));
        }
    }
    Quality {
        loading_span_s: (ka as f64 * dt, kb as f64 * dt),
        equilibrium_mean,
        equilibrium_max,
        verdict,
        incident_duration_s,
        pulse_overlap_s,
        noise_strain,
        signal_to_noise,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_verdict_follows_the_ratio_over_the_loading_span() {
        let force: Vec<f64> = (0..=100).map(|k| k as f64).collect();
        let good = vec![0.01; 101];
        let ((a, b), mean, max, v) = equilibrium_over_loading(&force, &good);
        assert_eq!((a, b), (25, 100));
        assert!((mean - 0.01).abs() < 1e-15 && (max - 0.01).abs() < 1e-15);
        assert_eq!(v, EquilibriumVerdict::Equilibrium);
        // A spike before the span does not count; one inside makes it marginal.
        let mut spiky = good.clone();
        spiky[10] = 1.0;
        assert_eq!(
            equilibrium_over_loading(&force, &spiky).3,
            EquilibriumVerdict::Equilibrium
        );
        spiky[50] = 0.5;
        assert_eq!(
            equilibrium_over_loading(&force, &spiky).3,
            EquilibriumVerdict::Marginal
        );
        let bad = vec![0.2; 101];
        assert_eq!(
            equilibrium_over_loading(&force, &bad).3,
            EquilibriumVerdict::NotInEquilibrium
        );
    }

    /// A square strain pulse of amplitude ε and length T carries E A c0 ε² T.
    #[test]
    fn wave_energy_is_the_flux_integral() {
        let bar = crate::reduce::BarProperties {
            youngs_modulus_pa: 200e9,
            wave_speed_m_s: 5000.0,
            area_m2: 1e-4,
            radius_m: 5.6e-3,
            poisson_ratio: 0.3,
            length_m: None,
        };
        let dt = 1e-7;
        let time_s: Vec<f64> = (0..1000).map(|k| k as f64 * dt).collect();
        let strain: Vec<f64> = (0..1000)
            .map(|k| if (300..700).contains(&k) { -1e-3 } else { 0.0 })
            .collect();
        let m = wave_metrics(&time_s, &strain, &bar, true).unwrap();
        let expected = 200e9 * 1e-4 * 5000.0 * 1e-6 * 400.0 * dt;
        assert!((m.energy_j - expected).abs() < 1e-12 * expected);
        assert!((m.peak_stress_pa - 200e6).abs() < 1e-3);
        // Crossings interpolated linearly: 10 % of the step at 299.1 and 699.9 samples.
        assert!((m.duration_10_s - 400.8 * dt).abs() < 1e-15);
        assert!(wave_metrics(&time_s, &strain, &bar, false).is_none());
        // A pulse still up at the window's end has a rise but no duration.
        let cut: Vec<f64> = strain[..500].to_vec();
        let m = wave_metrics(&time_s[..500], &cut, &bar, true).unwrap();
        assert!(m.duration_10_s.is_nan() && m.rise_10_90_s > 0.0);
    }

    #[test]
    fn incident_duration_runs_from_foot_to_fall() {
        let mut eps = vec![0.0; 100];
        for e in &mut eps[20..60] {
            *e = -1.0;
        }
        assert!((incident_duration_s(&eps, 1e-7, 19, 30, 0.02) - 41e-7).abs() < 1e-15);
    }
}

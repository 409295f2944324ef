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
                 and peaks are uncertain (filter with a lower --filter-cutoff, or check the gauge)"
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

/// How the equilibrium ratio behaved over the loading span of a reduction: the numbers
/// [`verdict_reason`] states beside the verdict (docs/physics.md §7.7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumDetail {
    /// Largest equilibrium ratio over the loading span and its time on the faces' axis, s.
    pub max_at_s: f64,
    /// Share of the loading span's samples whose ratio exceeds [`EQUILIBRIUM_TOLERANCE`].
    pub share_above: f64,
    /// Time from which the ratio stays within the tolerance up to the peak, s (None when the
    /// last sample of the span is above it).
    pub settled_from_s: Option<f64>,
    /// F_front / F_back at the peak back force.
    pub front_over_back_at_peak: f64,
    /// Mean ratio over the first and the second half of the loading span (by time).
    pub half_means: (f64, f64),
}

/// [`EquilibriumDetail`] of a reduction: where over its loading span (the span of
/// [`Quality::loading_span_s`]) the ratio |F_front − F_back| / F_3wave exceeds the tolerance.
pub fn equilibrium_detail(r: &super::Reduction) -> EquilibriumDetail {
    let (ka, kb) = rising_span(&r.force_3wave_n, 0.25);
    let span = &r.equilibrium_ratio[ka..=kb];
    let k_max = ka + crate::numeric::argmax(span);
    let above = span.iter().filter(|&&v| v > EQUILIBRIUM_TOLERANCE).count();
    let settled_from = (ka..=kb)
        .rev()
        .take_while(|&k| r.equilibrium_ratio[k] <= EQUILIBRIUM_TOLERANCE)
        .last();
    let mid = (span.len() / 2).max(1).min(span.len());
    let mean = |v: &[f64]| {
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    EquilibriumDetail {
        half_means: (mean(&span[..mid]), mean(&span[mid..])),
        max_at_s: r.time_s[k_max],
        share_above: above as f64 / span.len() as f64,
        settled_from_s: settled_from.map(|k| r.time_s[k]),
        front_over_back_at_peak: r.force_front_n[r.peak_index] / r.force_back_n[r.peak_index],
    }
}

/// One sentence saying which alignment placed a reduction's windows and why its equilibrium
/// verdict follows (docs/physics.md §7.6–§7.7): the strategy and its delays against the gauge
/// distances' (with the balance search's bound), then the criterion (R = |F_front − F_back| /
/// F_3wave over the loading span, 25 % of the 3-wave peak to the peak, against 0.05, Ravichandran
/// & Subhash 1994), the measured mean and maximum, where R exceeds 0.05, and F_front/F_back at
/// the peak back force.
pub fn verdict_reason(r: &super::Reduction) -> String {
    let a = &r.alignment;
    let w = &r.windows;
    let us = |s: f64| format!("{:.1} µs", s * 1e6);
    let moved = |name: &str, shift_s: f64| {
        if shift_s.abs() < 0.05e-6 {
            format!("the {name} window on the geometric delay")
        } else {
            format!(
                "the {name} window {} {} than the geometric delay",
                us(shift_s.abs()),
                if shift_s < 0.0 { "earlier" } else { "later" }
            )
        }
    };
    let dr = w.reflected_delay_s - a.geometric_reflected_delay_s;
    let dt = w.transmitted_delay_s - a.geometric_transmitted_delay_s;
    let strategy_r = match (a.strategy, a.balance_shift_s) {
        (super::Alignment::Balance, Some((sr, _))) => sr,
        (super::Alignment::Foot, _) => a
            .measured_reflected_delay_s
            .map_or(dr, |m| m - a.geometric_reflected_delay_s),
        _ => 0.0,
    };
    let strategy_t = match (a.strategy, a.balance_shift_s) {
        (super::Alignment::Balance, Some((_, st))) => st,
        (super::Alignment::Foot, _) => a
            .measured_transmitted_delay_s
            .map_or(dt, |m| m - a.geometric_transmitted_delay_s),
        _ => 0.0,
    };
    // A delay given by hand differs from the strategy's by more than rounding (1 ns).
    let by_hand = (dr - strategy_r).abs() > 1e-9 || (dt - strategy_t).abs() > 1e-9;
    let alignment = match a.strategy {
        super::Alignment::Geometric => format!(
            "geometric alignment placed the windows by the stated gauge distances (reflected +{}, \
             transmitted +{} after the incident foot)",
            us(w.reflected_delay_s),
            us(w.transmitted_delay_s)
        ),
        super::Alignment::Foot => format!(
            "foot alignment put {} and {} (on the record's pulse feet)",
            moved("reflected", dr),
            moved("transmitted", dt)
        ),
        super::Alignment::Balance => format!(
            "balance alignment moved {} and {} (bound ±{}{}), where F_front and F_back over the \
             incident pulse agree best",
            moved("reflected", dr),
            moved("transmitted", dt),
            us(a.balance_bound_s),
            if a.at_bound {
                "; a shift stopped at the bound, so the balance may lie beyond it"
            } else {
                ""
            }
        ),
    };
    let alignment = if by_hand {
        format!(
            "the windows were set by hand, reflected +{} and transmitted +{} after the incident \
             foot ({} alignment would give +{} and +{})",
            us(w.reflected_delay_s),
            us(w.transmitted_delay_s),
            a.strategy.name(),
            us(a.geometric_reflected_delay_s + strategy_r),
            us(a.geometric_transmitted_delay_s + strategy_t)
        )
    } else {
        alignment
    };
    let q = &r.quality;
    let d = equilibrium_detail(r);
    let tol = EQUILIBRIUM_TOLERANCE;
    let where_above = if d.share_above == 0.0 {
        "never above it".to_string()
    } else {
        format!(
            "above it on {:.0} % of the span{}",
            100.0 * d.share_above,
            match d.settled_from_s {
                Some(t) if t > q.loading_span_s.0 => format!(", within it for good from {}", us(t)),
                Some(_) => String::new(),
                None => " and still above it at the peak".to_string(),
            }
        )
    };
    let conclusion = match q.verdict {
        EquilibriumVerdict::Equilibrium => {
            format!("every sample is within {tol}, so the specimen is in equilibrium")
        }
        EquilibriumVerdict::Marginal => {
            format!("the mean is within {tol} but not every sample, so the verdict is marginal")
        }
        EquilibriumVerdict::NotInEquilibrium => {
            format!("the mean exceeds {tol}, so the specimen is not in equilibrium")
        }
    };
    format!(
        "{alignment}; over the loading ({}–{}, 25 % of the 3-wave peak to the peak) R = \
         |F_front − F_back|/F_3wave averages {:.3} ({:.3} over the span's first half, {:.3} over \
         its second) and reaches {:.3} at {} against the {tol} criterion, {where_above}, and \
         F_front/F_back at the peak back force is {:.3}: {conclusion}.",
        us(q.loading_span_s.0),
        us(q.loading_span_s.1),
        q.equilibrium_mean,
        d.half_means.0,
        d.half_means.1,
        q.equilibrium_max,
        us(d.max_at_s),
        d.front_over_back_at_peak,
    )
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

    /// A balanced test on the authors' bars (no dispersion): an incident sin² pulse −4e-4,
    /// its reflection +3e-4 and a transmitted pulse −1e-4 (so F_front = F_back at every instant),
    /// the transmitted one arriving `late_s` after the gauge distances' delay (a clock offset).
    fn balanced_record(
        late_s: f64,
    ) -> (crate::reduce::ReductionInput, crate::reduce::ReductionSetup) {
        crate::reduce::synthetic_record(3e-4, late_s, 0.0)
    }

    fn reduce_with(late_s: f64, alignment: crate::reduce::Alignment) -> crate::reduce::Reduction {
        let (input, setup) = balanced_record(late_s);
        let options = crate::reduce::ReductionOptions {
            dispersion: crate::reduce::DispersionCorrection::None,
            smoothing_window_s: 0.0,
            alignment,
            ..crate::reduce::ReductionOptions::default()
        };
        crate::reduce::reduce(&input, &setup, &options).unwrap()
    }

    /// The sentence names the alignment and the shift it made, and the criterion, the measured
    /// mean and maximum and the verdict it reads from them: on a balanced test the geometric
    /// windows give equilibrium; with the transmitted pulse 10 µs late they do not, and the
    /// balance search moves the transmitted window 10.0 µs later (its exact shift, in samples
    /// of 0.1 µs) and finds the balance again.
    #[test]
    fn the_verdict_reason_names_the_alignment_the_criterion_and_the_numbers() {
        let r = reduce_with(0.0, crate::reduce::Alignment::Geometric);
        assert_eq!(r.quality.verdict, EquilibriumVerdict::Equilibrium);
        let s = verdict_reason(&r);
        assert!(
            s.starts_with("geometric alignment placed the windows by the stated gauge distances"),
            "{s}"
        );
        assert!(
            s.contains("against the 0.05 criterion, never above it"),
            "{s}"
        );
        assert!(s.contains("so the specimen is in equilibrium."), "{s}");
        let d = equilibrium_detail(&r);
        assert!((d.front_over_back_at_peak - 1.0).abs() < 1e-3, "{d:?}");

        let late = reduce_with(10e-6, crate::reduce::Alignment::Geometric);
        assert_eq!(late.quality.verdict, EquilibriumVerdict::NotInEquilibrium);
        let s = verdict_reason(&late);
        assert!(
            s.contains(&format!("averages {:.3}", late.quality.equilibrium_mean)),
            "{s}"
        );
        assert!(
            s.contains("the mean exceeds 0.05, so the specimen is not in equilibrium."),
            "{s}"
        );
        // Two sin² pulses of 120 µs, the back one 10 µs behind the front one: over the span
        // from 25 % of their mean's peak to the peak, R averages 0.349, exceeds 0.05 on 91 % of
        // it and stays within 0.05 only over the last 3.7 µs before the peak (computed from the
        // two sin² pulses directly; the 2 % foot and the sampling move these by < 1 %).
        let d = equilibrium_detail(&late);
        assert!(
            (late.quality.equilibrium_mean / 0.349 - 1.0).abs() < 0.02,
            "{d:?}"
        );
        assert!((d.share_above - 0.91).abs() < 0.01, "{d:?}");
        let settled = d.settled_from_s.unwrap();
        assert!(
            (late.quality.loading_span_s.1 - settled - 3.7e-6).abs() < 0.3e-6,
            "{d:?}"
        );
        assert!(
            s.contains(&format!(
                "above it on {:.0} % of the span, within it for good from",
                100.0 * d.share_above
            )),
            "{s}"
        );

        let balanced = reduce_with(10e-6, crate::reduce::Alignment::Balance);
        let s = verdict_reason(&balanced);
        assert!(
            s.starts_with(
                "balance alignment moved the reflected window on the geometric delay and the \
                 transmitted window 10.0 µs later than the geometric delay (bound ±60.0 µs)"
            ),
            "{s}"
        );
        assert!(s.contains("so the specimen is in equilibrium."), "{s}");
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

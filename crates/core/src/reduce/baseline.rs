//! The first stage of the reduction (docs/physics.md §7.3, "Windows" 1–3): the records checked,
//! smoothed, their baselines removed, each channel's polarity judged, and the incident foot
//! found; and a raw record's voltages read as bar strains.

use super::{ReductionInput, ReductionOptions, channel, input_err, quality};
use crate::apparatus::Apparatus;
use crate::error::Result;
use crate::gauge::{GaugeChannel, RawRecord};

/// How a record's baseline is removed (`--baseline`; docs/physics.md §7.12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Baseline {
    /// The mean of the pre-trigger samples (the first `baseline_samples`), as the authors do.
    #[default]
    StartMean,
    /// A straight line fitted by least squares to the pre-trigger samples and to as many samples
    /// of the record's quiet tail, for a gauge whose zero drifts during the record.
    LinearDrift,
}

impl Baseline {
    /// The name of `--baseline` (`start-mean`, `linear-drift`).
    pub fn name(&self) -> &'static str {
        match self {
            Baseline::StartMean => "start-mean",
            Baseline::LinearDrift => "linear-drift",
        }
    }
}

/// How many times the pre-trigger noise the tail's scatter about the fitted line may be for the
/// tail to count as quiet (docs/physics.md §7.12): 3, above the ±√2 scatter of two RMS
/// estimates of one white noise over hundreds of samples and well below a pulse or its echoes.
pub const QUIET_TAIL_FACTOR: f64 = 3.0;

/// `v` less its baseline taken from its first `n` samples (`mode`; docs/physics.md §7.12): their
/// mean, or the least-squares line through them and the last `n` samples, refused (an error
/// naming `channel` of `file`) when that tail scatters about the line by more than
/// [`QUIET_TAIL_FACTOR`] times the first samples' RMS: a pulse or its echoes are still there.
pub fn remove_baseline(
    v: &[f64],
    n: usize,
    mode: Baseline,
    channel: &str,
    file: &str,
) -> Result<Vec<f64>> {
    let len = v.len();
    if mode == Baseline::StartMean || n < 2 || 2 * n > len {
        return Ok(debias(v, n));
    }
    let idx: Vec<f64> = (0..n).chain(len - n..len).map(|k| k as f64).collect();
    let ones = vec![1.0; idx.len()];
    let y: Vec<f64> = (0..n).chain(len - n..len).map(|k| v[k]).collect();
    let p = crate::numeric::least_squares(&[&ones, &idx], &y).ok_or_else(|| {
        input_err(
            file,
            &format!("{channel}_strain"),
            "the baseline line could not be fitted",
            "finite samples",
        )
    })?;
    let line = |k: usize| p[0] + p[1] * k as f64;
    let rms = |r: std::ops::Range<usize>| {
        let m = r.len() as f64;
        (r.map(|k| (v[k] - line(k)).powi(2)).sum::<f64>() / m).sqrt()
    };
    let (head, tail) = (rms(0..n), rms(len - n..len));
    if tail > QUIET_TAIL_FACTOR * head {
        return Err(input_err(
            file,
            "baseline",
            format!(
                "linear-drift: the {channel} record's last {n} samples are not quiet (their scatter about the fitted line is {:.1} times the pre-trigger noise): a pulse or its echoes are still there",
                tail / head.max(f64::MIN_POSITIVE)
            ),
            format!(
                "a record whose last {n} samples are as quiet as its first (within {QUIET_TAIL_FACTOR} times their noise), or --baseline start-mean"
            ),
        ));
    }
    Ok((0..len).map(|k| v[k] - line(k)).collect())
}

/// Checks the input series: equal lengths, enough samples, finite, uniform time axis; returns dt.
pub(crate) fn check_input(input: &ReductionInput, file: &str) -> Result<f64> {
    let n = input.time_s.len();
    if input.incident_strain.len() != n || input.transmission_strain.len() != n {
        return Err(input_err(
            file,
            "incident_strain/transmission_strain",
            format!(
                "{} times but {} incident and {} transmission samples",
                n,
                input.incident_strain.len(),
                input.transmission_strain.len()
            ),
            "one strain sample per time on both channels",
        ));
    }
    if n < 16 {
        return Err(input_err(
            file,
            "time_s",
            format!("{n} samples"),
            "at least 16 samples",
        ));
    }
    for (key, v) in [
        ("time_s", &input.time_s),
        ("incident_strain", &input.incident_strain),
        ("transmission_strain", &input.transmission_strain),
    ] {
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(input_err(
                file,
                key,
                format!("sample {k} is {}", v[k]),
                "finite numbers",
            ));
        }
    }
    let t = &input.time_s;
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    if dt.is_nan() || dt <= 0.0 {
        return Err(input_err(
            file,
            "time_s",
            "times do not increase",
            "a uniform increasing time axis",
        ));
    }
    if let Some(k) = t
        .windows(2)
        .position(|w| ((w[1] - w[0]) - dt).abs() > 0.01 * dt)
    {
        return Err(input_err(
            file,
            "time_s",
            format!(
                "step {:e} s between samples {k} and {} differs from the mean step {dt:e} s by more than 1 %",
                t[k + 1] - t[k],
                k + 1
            ),
            "a uniform time axis (steps within 1 % of their mean)",
        ));
    }
    Ok(dt)
}

/// Subtracts the mean of the first `n` samples (none if `n` is 0).
pub(crate) fn debias(v: &[f64], n: usize) -> Vec<f64> {
    crate::gauge::remove_baseline(v, n)
}

/// Index of the foot of the first pulse of `y` (positive pulse) and its peak index, by the rule
/// of docs/physics.md §7.3, "Windows" 3 (`gauge::pulse_foot`); None if `y` has no positive value.
fn pulse_foot(y: &[f64], fraction: f64) -> Option<(usize, usize)> {
    crate::gauge::pulse_foot(y, fraction).map(|f| (f.index, f.peak_index))
}

/// How many times the RMS of its baseline a channel's largest |ε| must be for its polarity to be
/// judged (docs/physics.md §7.3, "Polarity").
const POLARITY_SIGNAL_TO_NOISE: f64 = 10.0;

/// The first sample of `eps` (baseline removed) whose |ε| reaches half the largest |ε|, as
/// (index, value), when that largest |ε| stands out of the noise of the first `baseline`
/// samples (docs/physics.md §7.3, "Polarity"); None for a channel without a clear pulse.
fn first_pulse(eps: &[f64], baseline: usize) -> Option<(usize, f64)> {
    let largest = eps.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let noise = quality::baseline_rms(eps, baseline);
    if !(largest > 0.0 && largest > POLARITY_SIGNAL_TO_NOISE * noise) {
        return None;
    }
    eps.iter()
        .position(|e| e.abs() >= 0.5 * largest)
        .map(|k| (k, eps[k]))
}

/// Refuses a channel whose first pulse is tensile: its polarity is inverted (docs/physics.md §7.3,
/// "Polarity"). `channel` is `incident` or `transmission`.
pub(crate) fn check_polarity(
    eps: &[f64],
    baseline: usize,
    time_s: &[f64],
    channel: &str,
    file: &str,
) -> Result<()> {
    match first_pulse(eps, baseline) {
        Some((k, e)) if e > 0.0 => Err(input_err(
            file,
            &format!("{channel}_strain"),
            format!(
                "the first pulse on the {channel} gauge is tensile (strain +{} at {}), but the \
                 {} pulse, compressive, comes first there: the channel's polarity is inverted (a \
                 compressive pulse recorded as tension)",
                crate::error::format_si(e, ""),
                crate::error::format_si(time_s[k], "s"),
                if channel == "incident" {
                    "incident"
                } else {
                    "transmitted"
                }
            ),
            format!(
                "a record whose first {channel} pulse is compressive (strain < 0): flip the sign \
                 of `polarity` of the {channel} channel in the gauge set-up (bars/gauges-*.toml) \
                 that reads this record, or correct the record"
            ),
        )),
        _ => Ok(()),
    }
}

/// Bar strains of a raw record (the authors' CSV) read through the set-up's `incident` and
/// `transmission` channels (bridge, gain, polarity), after removing each channel's voltage
/// baseline (the mean of its first `baseline_samples` samples, as the authors do).
pub fn record_strains(
    record: &RawRecord,
    apparatus: &Apparatus,
    baseline_samples: usize,
) -> Result<ReductionInput> {
    let n = baseline_samples.min(record.time_s.len() / 2);
    let inc = channel(apparatus, "incident")?;
    let tra = channel(apparatus, "transmission")?;
    for c in [inc, tra] {
        if c.bridge.kind == crate::gauge::BridgeKind::Linear && c.bridge.strain_per_volt.is_nan() {
            return Err(crate::error::Named::new(apparatus.source.clone()).error(
                "strain_per_volt",
                format!(
                    "the `{}` channel states no strain per volt (nan), and the record is in volts",
                    c.name
                ),
                "the channel's factor (`shpb setup new --strain-per-volt K`, or `shpb calibrate` \
                 from paired volt and strain files), or a record in strain or microstrain",
            ));
        }
    }
    for (c, v) in [(inc, &record.incident_v), (tra, &record.transmission_v)] {
        beyond_digitiser_range(c, v, &apparatus.source)?;
    }
    Ok(ReductionInput {
        time_s: record.time_s.clone(),
        incident_strain: inc.strains_from_voltages(&debias(&record.incident_v, n)),
        transmission_strain: tra.strains_from_voltages(&debias(&record.transmission_v, n)),
    })
}

/// Refuses a recorded voltage beyond the full scale ±`range_v` of the channel's digitiser (one
/// quantisation step of margin): no sample of that digitiser can read it, so the record is not
/// in this channel's volts (millivolts, another set-up's gauges, a strain file read as volts).
pub fn beyond_digitiser_range(c: &GaugeChannel, v: &[f64], source: &str) -> Result<()> {
    let d = &c.digitiser;
    let limit = d.range_v + d.quantisation_step_v();
    let Some((k, &x)) = v
        .iter()
        .enumerate()
        .filter(|(_, x)| x.is_finite())
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
    else {
        return Ok(());
    };
    if x.abs() <= limit {
        return Ok(());
    }
    Err(crate::error::Named::new(source.to_string()).error(
        "adc_range_v",
        format!(
            "the {} record reaches {x} V (sample {k}), beyond the ±{} V full scale of the \
             channel's digitiser: no sample of it can read that, so the record is not in this \
             channel's volts",
            c.name, d.range_v
        ),
        "a record in volts within the channel's digitiser range (`adc_range_v`): check the \
         record's unit (mV is 1000 times V), that the set-up's gauges are the ones it was \
         taken with, and the gauge file's `adc_range_v`",
    ))
}

/// The two strain records after the first stage: smoothed, baselines removed, polarity checked
/// (docs/physics.md §7.3, "Windows" 1–3).
pub(crate) struct Conditioned {
    /// Sample step, s.
    pub dt: f64,
    /// Incident-gauge strain, smoothed and debiased.
    pub incident: Vec<f64>,
    /// Transmission-gauge strain, smoothed and debiased.
    pub transmission: Vec<f64>,
    /// Baseline samples actually averaged (cut short before an early pulse).
    pub baseline_samples: usize,
    /// The incident pulse's (foot, peak) sample indices, if it has one.
    pub incident_foot: Option<(usize, usize)>,
    /// Largest compressive incident strain of the first pulse (0 without one).
    pub incident_peak: f64,
    /// RMS of the transmission channel's baseline.
    pub transmission_noise: f64,
}

/// Checks, filters and debiases the two records, judges their polarity and finds the incident
/// foot; the baseline is re-taken before the pulse if the pulse starts within it. The options'
/// filter must be resolved ([`ReductionOptions::resolved_for`]). With a linear-drift baseline the
/// foot is found on the start-mean record and the line then removed from both.
pub(crate) fn condition(
    input: &ReductionInput,
    options: &ReductionOptions,
    file: &str,
) -> Result<Conditioned> {
    let dt = check_input(input, file)?;
    let n = input.time_s.len();

    // 0. The zero-phase filter (options resolved for the set-up, docs/physics.md §7.12).
    let incident_strain = options.filter.apply(&input.incident_strain, dt, file)?;
    let transmission_strain = options.filter.apply(&input.transmission_strain, dt, file)?;

    // 1–3. Baseline, polarity, then the incident foot; the baseline must end before the pulse.
    let mut nb = options.baseline_samples.min(n / 2);
    let mut eps_i = debias(&incident_strain, nb);
    check_polarity(&eps_i, nb, &input.time_s, "incident", file)?;
    check_polarity(
        &debias(&transmission_strain, nb),
        nb,
        &input.time_s,
        "transmission",
        file,
    )?;
    let foot = |e: &[f64]| {
        let y: Vec<f64> = e.iter().map(|v| -v).collect();
        pulse_foot(&y, options.start_fraction)
    };
    let mut detected = foot(&eps_i);
    if let Some((k_foot, _)) = detected
        && k_foot < nb
    {
        nb = k_foot;
        eps_i = debias(&incident_strain, nb);
        detected = foot(&eps_i);
    }
    if options.baseline != Baseline::StartMean {
        eps_i = remove_baseline(&incident_strain, nb, options.baseline, "incident", file)?;
    }
    let eps_t = remove_baseline(
        &transmission_strain,
        nb,
        options.baseline,
        "transmission",
        file,
    )?;
    let incident_peak = detected.map(|(_, k)| -eps_i[k]).unwrap_or(0.0);
    let transmission_noise = quality::baseline_rms(&eps_t, nb);
    Ok(Conditioned {
        dt,
        incident: eps_i,
        transmission: eps_t,
        baseline_samples: nb,
        incident_foot: detected,
        incident_peak,
        transmission_noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_drift_is_removed_and_a_busy_tail_refused() {
        // A pulse on a gauge whose zero drifts linearly (1e-5 over the record), a little noise,
        // quiet at both ends: the line through the first and last 500 samples takes the drift
        // away, leaving the pulse to within the noise's share of the fit (≪ 1e-6).
        let n = 4000;
        let noise = |k: usize| 2e-7 * ((k * 7919 % 101) as f64 / 50.0 - 1.0);
        let pulse = |k: usize| {
            let x = (k as f64 - 1500.0) / 1000.0;
            if (0.0..=1.0).contains(&x) {
                -1e-4 * (std::f64::consts::PI * x).sin().powi(2)
            } else {
                0.0
            }
        };
        let drift = |k: usize| 3e-6 + 1e-5 * k as f64 / n as f64;
        let v: Vec<f64> = (0..n).map(|k| pulse(k) + drift(k) + noise(k)).collect();
        let clean = remove_baseline(&v, 500, Baseline::LinearDrift, "incident", "r").unwrap();
        let worst = (0..n)
            .map(|k| (clean[k] - pulse(k) - noise(k)).abs())
            .fold(0.0, f64::max);
        assert!(worst < 5e-8, "{worst}");
        // The start mean leaves the drift: 1e-5 × 3500/4000 at the end less its start share.
        let start = remove_baseline(&v, 500, Baseline::StartMean, "incident", "r").unwrap();
        assert!((start[n - 1] - noise(n - 1)).abs() > 8e-6);
        // A pulse still in the tail is refused, naming the baseline.
        let echo = |k: usize| if k >= 2100 { pulse(k - 2100) } else { 0.0 };
        let busy: Vec<f64> = (0..n).map(|k| pulse(k) + echo(k) + noise(k)).collect();
        match remove_baseline(&busy, 500, Baseline::LinearDrift, "incident", "r") {
            Err(crate::Error::Invalid { quantity, .. }) => assert_eq!(quantity, "baseline"),
            other => panic!("a busy tail accepted: {:?}", other.map(|v| v.len())),
        }
    }

    #[test]
    fn polarity_is_not_judged_on_noise() {
        // A channel that is all noise has no first pulse to judge.
        let noise: Vec<f64> = (0..2000)
            .map(|k| 1e-7 * ((k * 7919 % 101) as f64 - 50.0))
            .collect();
        assert_eq!(first_pulse(&noise, 900), None);
        let mut pulse = noise.clone();
        pulse[1500] = 1e-3;
        assert_eq!(first_pulse(&pulse, 900), Some((1500, 1e-3)));
    }

    #[test]
    fn volts_beyond_the_digitiser_full_scale_are_refused() {
        use crate::gauge::{Bridge, BridgeKind, Digitiser};
        // The authors' channel: 12 bits over ±0.11166 V.
        let c = GaugeChannel {
            name: "incident".into(),
            bar: "incident".into(),
            distance_from_specimen_m: 0.644525,
            bridge: Bridge {
                kind: BridgeKind::FullPoisson,
                gauge_factor: 2.12,
                excitation_v: 15.0,
                poisson_ratio: 0.31,
                strain_per_volt: 0.0,
            },
            amplifier_gain: 2.0,
            polarity: 1.0,
            digitiser: Digitiser {
                sample_rate_hz: 10e6,
                bits: 12,
                range_v: 0.11166,
                noise_rms_v: 1.57e-4,
                seed: 1,
            },
        };
        // A sample at the last code of full scale is a reading; a pulse in mV under a volts
        // header (19.6 V for 19.6 mV) is not.
        let q = c.digitiser.quantisation_step_v();
        assert!(beyond_digitiser_range(&c, &[0.0, -0.11166, 0.11166 - q], "s.toml").is_ok());
        let e = beyond_digitiser_range(&c, &[0.0, 19.63, f64::NAN], "s.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("19.63") && e.contains("±0.11166 V") && e.contains("adc_range_v"),
            "{e}"
        );
    }
}

//! Records checked for plausibility before they are reduced or used (docs/physics.md §7.10): a
//! record in mV under V headers, an ADC range that clips the pulse, a dead channel, times in µs
//! under a seconds header, an inverted incident channel, an approach larger than the specimen.
//! Each check is one registration in [`CHECKS`]; every entry point that reads a record runs them
//! all through [`check_channels`] (the record's channels, as bar strain) and
//! [`check_reduction`] (what a reduction made of them), and refuses the record with a message
//! naming what it is, not a consequence of it.

use super::{Reduction, input_err};
use crate::error::{Result, format_si};
use crate::numeric::moving_average;

/// One gauge channel of a record as the checks see it: bar strain, tension positive, as read
/// (before smoothing or baseline removal).
#[derive(Debug, Clone, Copy)]
pub struct Channel<'a> {
    /// `incident` or `transmission`.
    pub name: &'a str,
    /// Sample times, s.
    pub time_s: &'a [f64],
    /// Bar strain, tension positive; or the bridge's volts when `volts` (a paired calibration's
    /// record, read before any set-up converts it).
    pub strain: &'a [f64],
    /// Whether `strain` holds volts (only the checks of a raw signal run: time span, dead,
    /// clipped).
    pub volts: bool,
    /// Young's modulus of the channel's bar, Pa (None: unknown, the loosest limit).
    pub youngs_modulus_pa: Option<f64>,
    /// Samples at the start whose mean is the baseline (the reduction's `baseline_samples`).
    pub baseline_samples: usize,
    /// Width of the moving average the reduction applies, s (the polarity is judged on it).
    pub smoothing_window_s: f64,
    /// When the last pulse a reduction reads on this channel reaches its gauge, on the record's
    /// clock, s, and its name (`reflected`, `transmitted`): the incident foot plus the set-up's
    /// delay ([`check_input`]); None when unknown.
    pub pulse_due_s: Option<(f64, &'static str)>,
}

impl Channel<'_> {
    /// A value of the channel for messages: `strain -1.2e-4` or `-15.9 mV`.
    fn value(&self, x: f64) -> String {
        if self.volts {
            format_si(x, "V")
        } else {
            format!("strain {}", format_si(x, ""))
        }
    }
}

/// What a reduction's specimen measures, for [`check_reduction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpecimenSize {
    /// Two spheres of radii r1 + r2 (m): their approach cannot exceed it.
    Spheres {
        /// r1 + r2, m.
        radii_sum_m: f64,
    },
    /// A cylinder of length L (m): its shortening cannot exceed it.
    Cylinder {
        /// Length, m.
        length_m: f64,
    },
}

/// What one check looks at.
#[derive(Debug, Clone, Copy)]
pub enum Stage {
    /// A record's channel, before the reduction (`file` names the record).
    Channel(fn(&Channel<'_>, &str) -> Result<()>),
    /// A reduction's result with its specimen's size.
    Reduced(fn(&Reduction, SpecimenSize, &str) -> Result<()>),
}

/// One plausibility check: its name, what it refuses, and the function.
#[derive(Debug, Clone, Copy)]
pub struct Check {
    /// Short name (`clipped`, `dead-channel`, …).
    pub name: &'static str,
    /// What it refuses, for documentation.
    pub refuses: &'static str,
    /// The check.
    pub stage: Stage,
}

/// Every plausibility check, in the order they run (a dead channel is named as dead before its
/// noise could be judged clipped or inverted).
pub const CHECKS: &[Check] = &[
    Check {
        name: "time-span",
        refuses: "times spanning more than 1 s (µs or ms under a seconds header)",
        stage: Stage::Channel(time_span),
    },
    Check {
        name: "truncated",
        refuses: "a record that ends before a pulse the reduction reads reaches its gauge",
        stage: Stage::Channel(truncated),
    },
    Check {
        name: "dead-channel",
        refuses: "a channel that is constant or holds only noise (a disconnected gauge or amplifier)",
        stage: Stage::Channel(dead_channel),
    },
    Check {
        name: "clipped",
        refuses: "a pulse flat-topped at the channel's extreme value (the digitiser's range clipped it)",
        stage: Stage::Channel(clipped),
    },
    Check {
        name: "elastic-limit",
        refuses: "a bar strain beyond what any bar of its modulus carries elastically (a record in mV under V headers, a wrong gain)",
        stage: Stage::Channel(elastic_limit),
    },
    Check {
        name: "polarity",
        refuses: "a channel whose first pulse is tensile (an inverted record)",
        stage: Stage::Channel(polarity),
    },
    Check {
        name: "approach",
        refuses: "an approach (spheres) or shortening (cylinder) larger than the specimen",
        stage: Stage::Reduced(approach),
    },
];

/// Runs every channel check of [`CHECKS`] on each channel, in order; the first refusal is the
/// error (an [`crate::Error::Invalid`] naming `file` and the channel).
pub fn check_channels(channels: &[Channel<'_>], file: &str) -> Result<()> {
    for check in CHECKS {
        if let Stage::Channel(f) = check.stage {
            for c in channels {
                f(c, file)?;
            }
        }
    }
    Ok(())
}

/// Runs the channel checks of [`CHECKS`] called `names` only, in the registry's order: what a
/// command that converts a record without reducing it needs (`shpb strain`: the record's time
/// unit and scale, a clipped pulse; a short or pulse-less record converts as well as any).
pub fn check_channels_named(channels: &[Channel<'_>], file: &str, names: &[&str]) -> Result<()> {
    for check in CHECKS.iter().filter(|c| names.contains(&c.name)) {
        if let Stage::Channel(f) = check.stage {
            for c in channels {
                f(c, file)?;
            }
        }
    }
    Ok(())
}

/// Runs every reduction check of [`CHECKS`] on a reduction of `file` whose specimen is `size`.
pub fn check_reduction(reduction: &Reduction, size: SpecimenSize, file: &str) -> Result<()> {
    for check in CHECKS {
        if let Stage::Reduced(f) = check.stage {
            f(reduction, size, file)?;
        }
    }
    Ok(())
}

/// Runs [`check_channels`] on both channels of a reduction's input, read with `setup`'s bars and
/// `options`' baseline and smoothing: what every command that reduces or uses a record calls.
pub fn check_input(
    input: &super::ReductionInput,
    setup: &super::ReductionSetup,
    options: &super::ReductionOptions,
    file: &str,
) -> Result<()> {
    // A tension test's records are checked in its loading's sense, as they are reduced (§7.10).
    let input = &*input.in_loading_sense(options.tension);
    // A moving average that spans a large part of the record flattens every pulse in it: the
    // record must hold at least ten of its windows.
    let n = input.time_s.len();
    let span = if n >= 2 {
        input.time_s[n - 1] - input.time_s[0]
    } else {
        0.0
    };
    if span > 0.0 && options.smoothing_window_s > 0.1 * span {
        return Err(input_err(
            file,
            "smoothing_window_s",
            format!(
                "a moving average {} wide over a record {} long flattens every pulse in it",
                format_si(options.smoothing_window_s, "s"),
                format_si(span, "s")
            ),
            format!(
                "0 (off) or a width of at most a tenth of the record, {} (the default is 2 µs)",
                format_si(0.1 * span, "s")
            ),
        ));
    }
    // The incident foot (the reduction's rule, on the smoothed and debiased channel) and the
    // set-up's delays say when the reflected and transmitted pulses reach their gauges.
    let foot_s = (n >= 2)
        .then(|| {
            let dt = (input.time_s[n - 1] - input.time_s[0]) / (n - 1) as f64;
            let half = if dt > 0.0 {
                (options.smoothing_window_s / dt / 2.0).round() as usize
            } else {
                0
            };
            let nb = options.baseline_samples.min(n / 2);
            let eps =
                crate::gauge::remove_baseline(&moving_average(&input.incident_strain, half), nb);
            let compression: Vec<f64> = eps.iter().map(|e| -e).collect();
            crate::gauge::pulse_foot(&compression, options.start_fraction)
                .map(|f| f.time_s(&input.time_s))
        })
        .flatten();
    let (ci, ct) = (
        setup.incident_bar.wave_speed_m_s,
        setup.transmission_bar.wave_speed_m_s,
    );
    let due = |delay_s: f64, pulse| foot_s.map(|f| (f + delay_s, pulse));
    let channel = |name, strain, bar: &super::BarProperties, pulse_due_s| Channel {
        name,
        time_s: &input.time_s,
        strain,
        volts: false,
        youngs_modulus_pa: Some(bar.youngs_modulus_pa),
        baseline_samples: options.baseline_samples,
        smoothing_window_s: options.smoothing_window_s,
        pulse_due_s,
    };
    check_channels(
        &[
            channel(
                "incident",
                &input.incident_strain,
                &setup.incident_bar,
                due(2.0 * setup.incident_gauge_m / ci, "reflected"),
            ),
            channel(
                "transmission",
                &input.transmission_strain,
                &setup.transmission_bar,
                due(
                    setup.incident_gauge_m / ci
                        + setup.transmission_gauge_m / ct
                        + options.specimen_transit_s,
                    "transmitted",
                ),
            ),
        ],
        file,
    )
}

impl SpecimenSize {
    /// The size of a reduction's specimen: r1 + r2 of spheres, a cylinder's length.
    pub fn of(specimen: &super::ReducedSpecimen) -> SpecimenSize {
        match specimen {
            super::ReducedSpecimen::Spheres { radii_m } => SpecimenSize::Spheres {
                radii_sum_m: radii_m.0 + radii_m.1,
            },
            super::ReducedSpecimen::Cylinder(g) => SpecimenSize::Cylinder {
                length_m: g.length_m,
            },
        }
    }
}

/// The longest time a record of one test may span, s: an SHPB test is over within milliseconds
/// (the authors' records span 1 ms) and a scene runs at most 1 s.
pub const MAX_RECORD_SPAN_S: f64 = 1.0;

/// Noise of a channel, robustly: the median absolute first difference over 0.6745 √2 (white
/// noise of RMS σ has differences of RMS √2 σ; the median ignores the pulse's fronts). A
/// quantised channel whose differences are mostly 0 falls back to the RMS difference over √2.
pub fn noise_rms(v: &[f64]) -> f64 {
    let mut d: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    let median = *median;
    if median > 0.0 {
        median / (0.6745 * std::f64::consts::SQRT_2)
    } else {
        (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt() / std::f64::consts::SQRT_2
    }
}

/// The median of `v` (0 for none).
fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    let mid = s.len() / 2;
    *s.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// How many times its noise a channel's largest excursion from its median must be for it to hold
/// a pulse: Gaussian noise of n = 10⁶ samples exceeds 5.3 σ about once, so 6 σ is noise-free.
pub const DEAD_CHANNEL_SIGNAL_TO_NOISE: f64 = 6.0;

fn time_span(c: &Channel<'_>, file: &str) -> Result<()> {
    let (Some(first), Some(last)) = (c.time_s.first(), c.time_s.last()) else {
        return Ok(());
    };
    let span = last - first;
    if span > MAX_RECORD_SPAN_S {
        return Err(input_err(
            file,
            "time_s",
            format!(
                "the record's times span {} ({first:e} to {last:e}): a test is over within \
                 milliseconds, so these are µs or ms under a seconds header",
                format_si(span, "s")
            ),
            format!(
                "times in seconds spanning at most {MAX_RECORD_SPAN_S} s (write the time unit in \
                 the header, `Time/us`, or in a layout's time_unit)"
            ),
        ));
    }
    Ok(())
}

fn truncated(c: &Channel<'_>, file: &str) -> Result<()> {
    let (Some((due_s, pulse)), Some(&end_s)) = (c.pulse_due_s, c.time_s.last()) else {
        return Ok(());
    };
    if end_s < due_s {
        return Err(input_err(
            file,
            "time_s",
            format!(
                "the record is truncated: it ends at {}, before the {pulse} pulse reaches the {} \
                 gauge (at {}: the incident foot plus the set-up's gauge delays)",
                format_si(end_s, "s"),
                c.name,
                format_si(due_s, "s")
            ),
            "a record that lasts until the reflected and transmitted pulses are over",
        ));
    }
    Ok(())
}

fn dead_channel(c: &Channel<'_>, file: &str) -> Result<()> {
    let v = c.strain;
    if v.len() < 2 {
        return Ok(());
    }
    let key = format!("{}_strain", c.name);
    if v.iter().all(|&x| x == v[0]) {
        return Err(input_err(
            file,
            &key,
            format!(
                "the {} channel is dead: all {} samples are the same value ({}), not even the \
                 digitiser's noise",
                c.name,
                v.len(),
                c.value(v[0])
            ),
            format!(
                "a record whose {} channel holds its gauge's pulse: check the gauge, its bridge \
                 and amplifier, and the digitiser channel the record was taken from",
                c.name
            ),
        ));
    }
    let m = median(v);
    let largest = v.iter().fold(0.0f64, |a, x| a.max((x - m).abs()));
    let noise = noise_rms(v);
    if noise > 0.0 && largest < DEAD_CHANNEL_SIGNAL_TO_NOISE * noise {
        return Err(input_err(
            file,
            &key,
            format!(
                "the {} channel is dead: it holds only noise (its largest excursion, {}, is \
                 {:.1} times its noise RMS, {}; a pulse stands out at least \
                 {DEAD_CHANNEL_SIGNAL_TO_NOISE} times)",
                c.name,
                c.value(largest),
                largest / noise,
                c.value(noise)
            ),
            format!(
                "a record whose {} channel holds its gauge's pulse: check the gauge, its bridge \
                 and amplifier, and the digitiser channel the record was taken from",
                c.name
            ),
        ));
    }
    Ok(())
}

/// Fewest consecutive samples at the channel's extreme value that make a flat top.
pub const CLIP_MIN_RUN: usize = 5;

/// How many times the samples at the level next to the extreme the run at the extreme must be:
/// a smooth peak quantised by the digitiser holds its top level at most ~2.4 times as long as the
/// next (a parabola's top band is √q wide, the next (√2 − 1)√q), a clipped one far longer.
pub const CLIP_RUN_OVER_NEXT_LEVEL: usize = 4;

fn clipped(c: &Channel<'_>, file: &str) -> Result<()> {
    let v = c.strain;
    if v.len() < CLIP_MIN_RUN {
        return Ok(());
    }
    let m = median(v);
    let noise = noise_rms(v);
    for sign in [1.0, -1.0] {
        let rail = v
            .iter()
            .copied()
            .max_by(|a, b| (sign * a).total_cmp(&(sign * b)))
            .expect("not empty");
        if (rail - m).abs() < 10.0 * noise || rail == m {
            continue;
        }
        // The longest run at exactly the rail, and how many samples sit at the next level.
        let (mut run, mut longest, mut start, mut longest_start) = (0, 0, 0, 0);
        for (k, &x) in v.iter().enumerate() {
            if x == rail {
                if run == 0 {
                    start = k;
                }
                run += 1;
                if run > longest {
                    longest = run;
                    longest_start = start;
                }
            } else {
                run = 0;
            }
        }
        let next = v
            .iter()
            .copied()
            .filter(|&x| sign * x < sign * rail)
            .max_by(|a, b| (sign * a).total_cmp(&(sign * b)));
        let at_next = next.map_or(0, |n| v.iter().filter(|&&x| x == n).count());
        if longest >= CLIP_MIN_RUN && longest >= CLIP_RUN_OVER_NEXT_LEVEL * at_next.max(1) {
            let t = |k: usize| c.time_s.get(k).copied().unwrap_or(f64::NAN);
            return Err(input_err(
                file,
                &format!("{}_strain", c.name),
                format!(
                    "the {} channel is clipped: {longest} consecutive samples ({} to {}) sit at \
                     exactly its extreme value ({}), a flat top the digitiser's range cut off; \
                     the pulse's peak, and every force and approach from it, are lost",
                    c.name,
                    format_si(t(longest_start), "s"),
                    format_si(t(longest_start + longest - 1), "s"),
                    c.value(rail)
                ),
                "a record taken with a digitiser range above the pulse's peak (a larger range \
                 or a lower amplifier gain)",
            ));
        }
    }
    Ok(())
}

/// Largest elastic bar strain of a bar of Young's modulus E ≥ 40 GPa (metals and ceramics:
/// maraging steel 2.4 GPa / 190 GPa = 1.3 %, Ti-6Al-4V 1.1 GPa / 114 GPa = 1 %, 7075 aluminium
/// 0.7 %, tungsten carbide ≈ 1 %), with a margin: 1.5 %.
pub const METAL_BAR_STRAIN_LIMIT: f64 = 0.015;

/// Largest elastic bar strain of a softer (polymer) bar: PMMA and polycarbonate yield at 2–4 %;
/// with a margin, 5 %.
pub const POLYMER_BAR_STRAIN_LIMIT: f64 = 0.05;

/// The elastic strain limit of a bar of Young's modulus `e_pa` and its class, for messages.
pub fn bar_strain_limit(e_pa: f64) -> (f64, &'static str) {
    if e_pa >= 40e9 {
        (
            METAL_BAR_STRAIN_LIMIT,
            "a metal or ceramic bar (E ≥ 40 GPa)",
        )
    } else {
        (POLYMER_BAR_STRAIN_LIMIT, "a polymer bar (E < 40 GPa)")
    }
}

fn elastic_limit(c: &Channel<'_>, file: &str) -> Result<()> {
    if c.volts {
        return Ok(());
    }
    let v = c.strain;
    let nb = c.baseline_samples.min(v.len() / 2);
    let eps = crate::gauge::remove_baseline(v, nb);
    let Some((k, peak)) = eps
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
    else {
        return Ok(());
    };
    let (limit, class) = match c.youngs_modulus_pa {
        Some(e) => bar_strain_limit(e),
        None => (POLYMER_BAR_STRAIN_LIMIT, "any bar"),
    };
    if peak.abs() > limit {
        let times = peak.abs() / limit;
        let hint = format!(
            " ({times:.0} times the limit: values in mV under a `V` header read 1000 times too \
             large, µε under a strain header 10⁶ times)"
        );
        return Err(input_err(
            file,
            &format!("{}_strain", c.name),
            format!(
                "the {} channel reads a bar strain of {:.3} % at {}{}, beyond what {class} \
                 carries elastically, {} %: the record's scale is wrong{hint}",
                c.name,
                peak * 100.0,
                format_si(c.time_s.get(k).copied().unwrap_or(f64::NAN), "s"),
                c.youngs_modulus_pa.map_or(String::new(), |e| format!(
                    " (a stress of {} at E = {})",
                    format_si(peak.abs() * e, "Pa"),
                    format_si(e, "Pa")
                )),
                limit * 100.0
            ),
            "a record whose units are those its header or layout states (V, mV, strain, µε), \
             read through the set-up's gauge factor, excitation and gain",
        ));
    }
    Ok(())
}

fn polarity(c: &Channel<'_>, file: &str) -> Result<()> {
    if c.volts {
        return Ok(());
    }
    let v = c.strain;
    let n = v.len();
    if n < 2 {
        return Ok(());
    }
    let dt = (c.time_s[n - 1] - c.time_s[0]) / (n - 1) as f64;
    let half = if dt > 0.0 {
        (c.smoothing_window_s / dt / 2.0).round() as usize
    } else {
        0
    };
    let smoothed = moving_average(v, half);
    let mut nb = c.baseline_samples.min(n / 2);
    let mut eps = crate::gauge::remove_baseline(&smoothed, nb);
    // A baseline that reaches into the pulse (a short pre-trigger) is cut to half the samples
    // before the pulse's first half-peak crossing, as the reduction re-takes it before the foot.
    let largest = eps.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    if let Some(k) = eps.iter().position(|e| e.abs() >= 0.5 * largest)
        && k < nb
        && k >= 4
    {
        nb = k / 2;
        eps = crate::gauge::remove_baseline(&smoothed, nb);
    }
    super::baseline::check_polarity(&eps, nb, c.time_s, c.name, file)
}

fn approach(r: &Reduction, size: SpecimenSize, file: &str) -> Result<()> {
    let (limit, what, allowed) = match size {
        SpecimenSize::Spheres { radii_sum_m } => (
            radii_sum_m,
            format!(
                "the two spheres' radii together, {}",
                format_si(radii_sum_m, "m")
            ),
            "an approach smaller than the spheres (a record in its stated units, reduced with \
             the set-up and specimen it was taken with)",
        ),
        SpecimenSize::Cylinder { length_m } => (
            length_m,
            format!("the cylinder's length, {}", format_si(length_m, "m")),
            "a shortening smaller than the specimen (a record in its stated units, reduced with \
             the set-up and specimen it was taken with)",
        ),
    };
    if limit.is_nan() || limit <= 0.0 {
        return Ok(());
    }
    let (k, largest) = r
        .displacement_m
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap_or((0, 0.0));
    if largest.abs() > limit {
        return Err(input_err(
            file,
            "displacement_m",
            format!(
                "the reduced approach reaches {} at {} (peak force {}), more than {what}: no \
                 specimen shortens by more than its size, so the record's scale, the set-up or the \
                 specimen is not the test's",
                format_si(largest, "m"),
                format_si(r.time_s.get(k).copied().unwrap_or(f64::NAN), "s"),
                format_si(r.peak_back_force_n, "N")
            ),
            allowed,
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of n samples at 10 MHz: a half-sine pulse of `peak` strain from sample 2000 to
    /// 4000 plus deterministic white noise of RMS `noise` (uniform in ±√3 noise).
    fn record(n: usize, peak: f64, noise: f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-7).collect();
        let v = (0..n)
            .map(|k| {
                // splitmix64 of k: independent uniform samples in ±0.5.
                let mut x = (k as u64)
                    .wrapping_add(1)
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15);
                x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                x ^= x >> 31;
                let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let pulse = if (2000..4000).contains(&k) {
                    -peak * (std::f64::consts::PI * (k - 2000) as f64 / 2000.0).sin()
                } else {
                    0.0
                };
                pulse + noise * 12f64.sqrt() * u
            })
            .collect();
        (t, v)
    }

    fn channel<'a>(t: &'a [f64], v: &'a [f64]) -> Channel<'a> {
        Channel {
            name: "incident",
            time_s: t,
            strain: v,
            volts: false,
            youngs_modulus_pa: Some(192e9),
            baseline_samples: 900,
            smoothing_window_s: 2e-6,
            pulse_due_s: None,
        }
    }

    fn refusal(t: &[f64], v: &[f64]) -> Option<String> {
        check_channels(&[channel(t, v)], "r.csv")
            .err()
            .map(|e| e.to_string())
    }

    #[test]
    fn a_clean_pulse_passes_every_check() {
        let (t, v) = record(10_000, 4e-4, 2e-6);
        assert_eq!(refusal(&t, &v), None);
        // Quantised without noise (a digitiser of step 1e-6 strain): the smooth peak holds its
        // top level for many samples, but not 4 times the next level's.
        let q: Vec<f64> = record(10_000, 4e-4, 0.0)
            .1
            .iter()
            .map(|x| (x / 1e-6).round() * 1e-6)
            .collect();
        assert_eq!(refusal(&t, &q), None);
    }

    #[test]
    fn a_clipped_pulse_is_named_clipped() {
        let (t, v) = record(10_000, 4e-4, 2e-6);
        let c: Vec<f64> = v.iter().map(|x| x.max(-2.5e-4)).collect();
        let e = refusal(&t, &c).unwrap();
        assert!(e.contains("clipped"), "{e}");
        assert!(!e.contains("inverted"), "{e}");
    }

    #[test]
    fn a_dead_channel_is_named_dead() {
        let t: Vec<f64> = (0..5000).map(|k| k as f64 * 1e-7).collect();
        let flat = vec![3e-5; 5000];
        let e = refusal(&t, &flat).unwrap();
        assert!(e.contains("dead") && e.contains("same value"), "{e}");
        let (_, noise) = record(5000, 0.0, 2e-6);
        let e = refusal(&t, &noise).unwrap();
        assert!(e.contains("dead") && e.contains("only noise"), "{e}");
    }

    #[test]
    fn a_record_a_thousand_times_too_large_is_refused_as_such() {
        // 4e-4 strain read as mV under a V header: 0.4 strain, 27× the metal bar's 1.5 %.
        let (t, v) = record(10_000, 0.4, 2e-3);
        let e = refusal(&t, &v).unwrap();
        assert!(
            e.contains("elastically") && e.contains("mV under a `V` header"),
            "{e}"
        );
        // A polymer bar (E = 3 GPa) carries 5 %: 4 % passes, as 4e-4 does on steel.
        let (t, v) = record(10_000, 0.04, 2e-4);
        let mut c = channel(&t, &v);
        c.youngs_modulus_pa = Some(3e9);
        assert!(check_channels(&[c], "r.csv").is_ok());
    }

    #[test]
    fn times_in_microseconds_are_named() {
        let (t, v) = record(10_000, 4e-4, 2e-6);
        let us: Vec<f64> = t.iter().map(|x| x * 1e6).collect();
        let e = refusal(&us, &v).unwrap();
        assert!(e.contains("µs or ms under a seconds header"), "{e}");
    }

    #[test]
    fn an_inverted_channel_is_named_inverted() {
        let (t, v) = record(10_000, 4e-4, 2e-6);
        let inv: Vec<f64> = v.iter().map(|x| -x).collect();
        let e = refusal(&t, &inv).unwrap();
        assert!(e.contains("inverted"), "{e}");
    }

    #[test]
    fn noise_is_estimated_from_differences() {
        // White noise of RMS 1 (the hash is uniform): the estimate is within 20 %.
        let (_, v) = record(10_000, 0.0, 1.0);
        let n = noise_rms(&v);
        assert!((n - 1.0).abs() < 0.2, "{n}");
    }
}

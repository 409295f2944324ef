//! Where the incident, reflected and transmitted windows start and how long they last
//! (docs/physics.md §7.3, "Windows" 3–6, and §7.6): the incident foot or its override, the
//! delays of the alignment strategy ([`super::align`]) or the overrides, and the longest clean
//! window the record holds.

use super::baseline::Conditioned;
use super::correction::{FaceCorrections, WaveCorrection, cut};
use super::{Alignment, AlignmentReport, ReductionInput, ReductionOptions, ReductionSetup};
use super::{align, input_err};
use crate::error::Result;

/// Manual window settings; each `None` keeps the automatic rule (docs/physics.md §7.3, "Windows").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WindowOverride {
    /// Incident window start at the incident gauge, record clock, s (may fall between samples).
    pub incident_start_s: Option<f64>,
    /// Reflected window start minus incident start, s (default 2 d_I/c0).
    pub reflected_delay_s: Option<f64>,
    /// Transmitted window start minus incident start, s (default (d_I + d_T)/c0 + transit).
    pub transmitted_delay_s: Option<f64>,
    /// Window length, s (default: the longest clean window that fits the record).
    pub duration_s: Option<f64>,
}

/// The windows a reduction used (record clock).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Windows {
    /// Incident window start at the incident gauge, s.
    pub incident_start_s: f64,
    /// Reflected window start minus incident start, s.
    pub reflected_delay_s: f64,
    /// Transmitted window start minus incident start, s.
    pub transmitted_delay_s: f64,
    /// Window length, s.
    pub duration_s: f64,
    /// Samples per window.
    pub samples: usize,
    /// Baseline samples actually averaged.
    pub baseline_samples: usize,
}

/// The windows the second stage placed, in samples of the record and as [`Windows`].
pub(crate) struct Placed {
    /// The windows (record clock).
    pub windows: Windows,
    /// Incident, reflected and transmitted window starts, fractional sample indices.
    pub starts: (f64, f64, f64),
    /// What the alignment chose and measured.
    pub alignment: AlignmentReport,
}

/// The incident window's start on the record clock, s: the override or the detected foot
/// (an error names the record when it has no compressive incident pulse).
pub(crate) fn incident_start_s(
    input: &ReductionInput,
    strains: &Conditioned,
    options: &ReductionOptions,
    file: &str,
) -> Result<f64> {
    match options.window.unwrap_or_default().incident_start_s {
        Some(s) => Ok(s),
        None => {
            let (k_foot, _) = strains.incident_foot.ok_or_else(|| {
                input_err(
                    file,
                    "incident_strain",
                    "no compressive (negative) incident pulse",
                    "an incident record with a compressive pulse",
                )
            })?;
            Ok(input.time_s[k_foot])
        }
    }
}

/// Places the reflected and transmitted windows after the incident start `incident_start_s`
/// (geometric delays, the record's feet, or the balance search; overrides win) and the window
/// length; `warnings` gets the balance search's stop at its bound. Errors name the record when
/// the windows do not fit in it or the feet `--align foot` needs are missing.
#[allow(clippy::too_many_arguments)]
pub(crate) fn place(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
    strains: &Conditioned,
    incident_start_s: f64,
    corrections: &FaceCorrections,
    file: &str,
    warnings: &mut Vec<String>,
) -> Result<Placed> {
    let dt = strains.dt;
    let n = input.time_s.len();
    let t0 = input.time_s[0];
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let (d_i, d_t) = (setup.incident_gauge_m, setup.transmission_gauge_m);
    let ov = options.window.unwrap_or_default();
    let (eps_i, eps_t) = (&strains.incident, &strains.transmission);
    let incident_peak = strains.incident_peak;

    // 4. Delays: the gauge distances', the record's feet, and the strategy's choice.
    let c_i = bi.wave_speed_m_s;
    let c_t = bt.wave_speed_m_s;
    let geometric_r = 2.0 * d_i / c_i;
    let geometric_t = d_i / c_i + d_t / c_t + options.specimen_transit_s;
    let s_i = (incident_start_s - t0) / dt;
    // The reflected pulse: the first tensile one, at least 10 % of the incident peak (a
    // specimen that reflects almost nothing has no foot to measure).
    let measured_reflected_delay_s = (incident_peak > 0.0)
        .then(|| {
            align::foot_delay_s(
                eps_i,
                1.0,
                dt,
                s_i,
                geometric_r,
                0.1 * incident_peak,
                options.start_fraction,
            )
        })
        .flatten();
    // The transmitted pulse: the first compressive one, above 10 times the gauge's noise.
    let measured_transmitted_delay_s = align::foot_delay_s(
        eps_t,
        -1.0,
        dt,
        s_i,
        geometric_t,
        10.0 * strains.transmission_noise,
        options.start_fraction,
    );
    let (ea_i, ea_t) = (
        bi.youngs_modulus_pa * bi.area_m2,
        bt.youngs_modulus_pa * bt.area_m2,
    );
    let longest_clean = {
        let mut d = geometric_r;
        if let Some(l) = bi.length_m {
            d = d.min(2.0 * (l - d_i) / c_i);
        }
        if !setup.transmission_absorbing
            && let Some(l) = bt.length_m
        {
            d = d.min(2.0 * (l - d_t) / c_t);
        }
        d
    };
    let mut balance_shift_s = None;
    let mut at_bound = false;
    let (auto_r, auto_t) = match options.alignment {
        Alignment::Geometric => (geometric_r, geometric_t),
        Alignment::Foot => {
            let missing = |which: &str| {
                input_err(
                    file,
                    "align",
                    format!(
                        "`foot` alignment: no {which} pulse foot found in the record (a pulse \
                         of at least 10 % of the incident peak, or 10 times the noise, between \
                         half and twice its geometric delay)"
                    ),
                    "a record with clear reflected and transmitted pulses, or --align geometric|balance",
                )
            };
            (
                measured_reflected_delay_s.ok_or_else(|| missing("reflected"))?,
                measured_transmitted_delay_s.ok_or_else(|| missing("transmitted"))?,
            )
        }
        Alignment::Balance => {
            let margin = (options.balance_bound_s / dt).round() as usize;
            let window = ((longest_clean.min(ov.duration_s.unwrap_or(f64::INFINITY))) / dt)
                .floor()
                .max(8.0) as usize;
            let e_in = cut(eps_i, dt, s_i, window, corrections.incident(d_i).as_ref());
            let ext = |x: &[f64], start: f64, d: Option<WaveCorrection>| {
                cut(
                    x,
                    dt,
                    start - margin as f64,
                    window + 2 * margin,
                    d.as_ref(),
                )
            };
            let reflected = ext(eps_i, s_i + geometric_r / dt, corrections.incident(-d_i));
            let transmitted = ext(
                eps_t,
                s_i + geometric_t / dt,
                corrections.transmission(-d_t),
            );
            let problem = align::BalanceProblem {
                incident: &e_in,
                reflected: &reflected,
                transmitted: &transmitted,
                margin,
                ea_incident_n: ea_i,
                ea_transmission_n: ea_t,
            };
            let ((jr, jt), bound) = problem.solve();
            at_bound = bound;
            let shift = (jr as f64 * dt, jt as f64 * dt);
            balance_shift_s = Some(shift);
            (geometric_r + shift.0, geometric_t + shift.1)
        }
    };
    let reflected_delay_s = ov.reflected_delay_s.unwrap_or(auto_r);
    let transmitted_delay_s = ov.transmitted_delay_s.unwrap_or(auto_t);

    // 5. Window length.
    let record_end = input.time_s[n - 1];
    let duration_s = match ov.duration_s {
        Some(d) => d,
        None => longest_clean
            .min(reflected_delay_s)
            .min(record_end - (incident_start_s + reflected_delay_s))
            .min(record_end - (incident_start_s + transmitted_delay_s)),
    };
    let samples = (duration_s / dt * (1.0 + 1e-12)).floor() as usize + 1;
    let s_r = s_i + reflected_delay_s / dt;
    let s_t = s_i + transmitted_delay_s / dt;
    // The record's end cut the window short: refused as truncated when a pulse is still on at
    // the end (docs/physics.md §7.10), not reduced over the part of it the record holds.
    let clean_s = longest_clean.min(reflected_delay_s);
    if ov.duration_s.is_none() && duration_s < clean_s - dt && duration_s > 0.0 {
        let tail = ((1e-6 / dt).round() as usize).clamp(1, n);
        let at_end = |e: &[f64]| e[n - tail..].iter().sum::<f64>() / tail as f64;
        let transmitted_peak = eps_t.iter().fold(0.0f64, |m, e| m.max(-e));
        for (channel, pulse, end, peak) in [
            ("incident", "reflected", at_end(eps_i), incident_peak),
            (
                "transmission",
                "transmitted",
                at_end(eps_t),
                transmitted_peak,
            ),
        ] {
            if peak > 0.0 && end.abs() > 0.1 * peak {
                return Err(input_err(
                    file,
                    "time_s",
                    format!(
                        "the record is truncated: it ends at {:.1} µs while the {pulse} pulse is \
                         still on ({channel} strain {:.0} % of its pulse's peak over the last \
                         µs), so its window would hold {:.1} µs of the {:.1} µs the bars give",
                        record_end * 1e6,
                        100.0 * end.abs() / peak,
                        duration_s * 1e6,
                        clean_s * 1e6
                    ),
                    format!(
                        "a record that lasts until the pulses are over (here until at least \
                         {:.1} µs), or --duration to reduce a shorter window on purpose",
                        (incident_start_s + reflected_delay_s.max(transmitted_delay_s) + clean_s)
                            * 1e6
                    ),
                ));
            }
        }
    }
    let last = (n - 1) as f64 + 1e-6;
    if samples < 8
        || s_i < -1e-6
        || s_r + (samples - 1) as f64 > last
        || s_t + (samples - 1) as f64 > last
    {
        return Err(input_err(
            file,
            "time_s",
            format!(
                "the record ({:.1} µs to {:.1} µs) does not hold the windows: incident from {:.1} µs, \
                 reflected from {:.1} µs, transmitted from {:.1} µs, {:.1} µs long",
                t0 * 1e6,
                record_end * 1e6,
                incident_start_s * 1e6,
                (incident_start_s + reflected_delay_s) * 1e6,
                (incident_start_s + transmitted_delay_s) * 1e6,
                duration_s.max(0.0) * 1e6
            ) + &if record_end < incident_start_s + reflected_delay_s.max(transmitted_delay_s) {
                format!(
                    " (the record is truncated: it ends before the {} pulse arrives)",
                    if reflected_delay_s >= transmitted_delay_s {
                        "reflected"
                    } else {
                        "transmitted"
                    }
                )
            } else {
                String::new()
            },
            "a record long enough for the incident, reflected and transmitted windows (at least 8 samples each)",
        ));
    }
    if at_bound {
        warnings.push(format!(
            "the balance search stopped at its bound (±{:.1} µs): the best shift may lie beyond \
             it; check the gauge distances, or widen the bound (--balance-bound)",
            options.balance_bound_s * 1e6
        ));
    }

    Ok(Placed {
        windows: Windows {
            incident_start_s,
            reflected_delay_s,
            transmitted_delay_s,
            duration_s: (samples - 1) as f64 * dt,
            samples,
            baseline_samples: strains.baseline_samples,
        },
        starts: (s_i, s_r, s_t),
        alignment: AlignmentReport {
            strategy: options.alignment,
            geometric_reflected_delay_s: geometric_r,
            geometric_transmitted_delay_s: geometric_t,
            measured_reflected_delay_s,
            measured_transmitted_delay_s,
            balance_shift_s,
            balance_paths_m: balance_shift_s
                .map(|(sr, st)| (d_i + c_i * sr / 2.0, d_t + c_t * (st - sr / 2.0))),
            balance_bound_s: options.balance_bound_s,
            at_bound,
        },
    })
}

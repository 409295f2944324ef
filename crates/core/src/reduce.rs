//! The laboratory's data reduction (docs/physics.md §7; shared/reference/README.md,
//! "Reduction"): from the strains recorded at the incident and transmission gauges to the forces
//! on the two specimen faces, the approach δ(t), its rate and what the specimen makes of them.
//! It works on simulated records (`shpb run` HDF5) and on real ones (the authors' raw CSV).
//! Signs, windows and the dispersion correction are written out in docs/physics.md §7.2–§7.3.
//!
//! [`reduce_named`] runs the stages in order, each in its own module:
//!
//! 1. [`baseline`]: the records checked, smoothed, debiased, their polarity judged, the
//!    incident foot found (§7.3, "Windows" 1–3);
//! 2. [`windows`]: where the incident, reflected and transmitted windows start and how long
//!    they last ([`align`]: geometric, feet, balance; §7.3 "Windows" 3–6, §7.6), each wave moved
//!    to its face by [`correction`] (Bancroft, exact first mode, Tyas–Pope; §7.2, §7.9);
//! 3. [`waves`]: the 1/2/3-wave forces, face velocities and displacements, the approach, the
//!    equilibrium ratio (§7.3), and the incident pulse a history implies (§7.4);
//! 4. [`quality`]: equilibrium over the loading, pulse overlap, noise (§7.7);
//! 5. [`specimen`]: spheres' strain rate δ̇/Σrᵢ, a cylinder's 1/2/3-wave stress and strain
//!    (§7.8).
//!
//! The options are checked once, by [`ReductionOptions::validate`].

use crate::apparatus::Apparatus;
use crate::error::{Error, Result};
use crate::gauge::GaugeChannel;

pub mod align;
pub mod baseline;
pub mod correction;
pub use crate::filter;
pub mod options;
pub mod plausibility;
pub mod quality;
pub mod separation;
pub mod specimen;
pub mod waves;
pub mod windows;

pub use align::{Alignment, AlignmentReport};
pub use baseline::{Baseline, beyond_digitiser_range, record_strains};
pub use correction::{
    BANCROFT_FIT, BANCROFT_FIT_POISSON_RATIO, DispersionCorrection, TYAS_POPE_CUTOFF_FA_OVER_C0,
    bancroft_phase_velocity_m_s, bancroft_velocity_ratio, dispersion_delay_s, dispersion_shift,
    dispersion_shift_exact,
};
pub use filter::Filter;
pub use options::{DEFAULT_BALANCE_BOUND_S, MAX_BALANCE_BOUND_S, ReductionOptions};
pub use quality::{EquilibriumDetail, equilibrium_detail, verdict_reason};
pub use quality::{EquilibriumVerdict, Quality, WaveMetrics, wave_metrics};
pub use separation::{SECOND_GAUGE_CHANNELS, SecondGauges, Separation, WaveSeparation};
pub use specimen::{PAPER_SPHERE_RADII_M, ReducedSpecimen};
pub use waves::{ImpliedIncident, implied_incident};
pub use windows::{WindowOverride, Windows};

pub use crate::gauge::DEFAULT_SMOOTHING_S;

/// One bar as the reduction sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarProperties {
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: f64,
    /// Bar-wave speed c0, m/s.
    pub wave_speed_m_s: f64,
    /// Cross-section A, m².
    pub area_m2: f64,
    /// Radius a, m (dispersion correction).
    pub radius_m: f64,
    /// Poisson's ratio ν (checked against the Bancroft fit's 0.31).
    pub poisson_ratio: f64,
    /// Length, m (None: unknown, no limit on the window from its far end).
    pub length_m: Option<f64>,
}

/// Bars and gauge positions of a reduction.
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionSetup {
    /// Incident bar.
    pub incident_bar: BarProperties,
    /// Transmission bar.
    pub transmission_bar: BarProperties,
    /// Distance of the incident gauge from the specimen face, m.
    pub incident_gauge_m: f64,
    /// Distance of the transmission gauge from the specimen face, m.
    pub transmission_gauge_m: f64,
    /// Whether the transmission bar's far end absorbs (no reflection from it limits the window).
    pub transmission_absorbing: bool,
}

impl ReductionSetup {
    /// Bars and gauge distances of a set-up file (its `incident` and `transmission` channels);
    /// an insert adds its transit as bar length L_ins c0/c_ins (docs/physics.md §6.8).
    pub fn from_apparatus(a: &Apparatus) -> Result<ReductionSetup> {
        let m = &a.material;
        let bar = |g: &crate::apparatus::BarGeometry| BarProperties {
            youngs_modulus_pa: m.youngs_modulus_pa,
            wave_speed_m_s: m.wave_speed_m_s(),
            area_m2: g.area_m2(),
            radius_m: g.diameter_m / 2.0,
            poisson_ratio: m.poisson_ratio,
            length_m: Some(g.length_m),
        };
        let (ins_i, ins_t) = a.inserts.equivalent_bar_lengths_m(m.wave_speed_m_s());
        Ok(ReductionSetup {
            incident_bar: bar(&a.incident),
            transmission_bar: bar(&a.transmission),
            incident_gauge_m: channel(a, "incident")?.distance_from_specimen_m + ins_i,
            transmission_gauge_m: channel(a, "transmission")?.distance_from_specimen_m + ins_t,
            transmission_absorbing: a.transmission_absorbing,
        })
    }
}

/// The gauge channel called `name` of a set-up, or an input error naming the set-up file.
fn channel<'a>(a: &'a Apparatus, name: &str) -> Result<&'a GaugeChannel> {
    a.gauges.channel(name).ok_or_else(|| {
        crate::error::Named::new(a.source.clone()).error(
            "gauges",
            format!("no `{name}` channel in the gauge set-up"),
            "channels named incident and transmission",
        )
    })
}

/// The two gauge strain histories to reduce (strain positive in tension).
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionInput {
    /// Sample times, s (uniform).
    pub time_s: Vec<f64>,
    /// Incident-gauge strain (incident and reflected waves).
    pub incident_strain: Vec<f64>,
    /// Transmission-gauge strain.
    pub transmission_strain: Vec<f64>,
}

impl ReductionInput {
    /// The records in the loading's sense in which the compression stages read them
    /// (docs/physics.md §7.8.1): a tension test's strains turned, s ε with s = −1; a compression
    /// test's unchanged (borrowed).
    pub fn in_loading_sense(&self, tension: bool) -> std::borrow::Cow<'_, ReductionInput> {
        if !tension {
            return std::borrow::Cow::Borrowed(self);
        }
        let turn = |v: &[f64]| v.iter().map(|x| -x).collect();
        std::borrow::Cow::Owned(ReductionInput {
            time_s: self.time_s.clone(),
            incident_strain: turn(&self.incident_strain),
            transmission_strain: turn(&self.transmission_strain),
        })
    }
}

/// Result of a reduction, on the common time axis of the specimen faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Reduction {
    /// Time since the incident pulse's foot reached the specimen face, s (starts at 0).
    pub time_s: Vec<f64>,
    /// Record-clock time of `time_s = 0`: incident start + d_I/c0, s.
    pub face_time_offset_s: f64,
    /// Incident strain at the incident-bar face (tension positive).
    pub incident_strain: Vec<f64>,
    /// Reflected strain at the incident-bar face.
    pub reflected_strain: Vec<f64>,
    /// Transmitted strain at the transmission-bar face.
    pub transmitted_strain: Vec<f64>,
    /// 2-wave force on the incident-bar face, −E A (εI + εR), N (compression positive).
    pub force_front_n: Vec<f64>,
    /// 1-wave force on the transmission-bar face, −E A εT, N (compression positive).
    pub force_back_n: Vec<f64>,
    /// 3-wave force, mean of front and back, N.
    pub force_3wave_n: Vec<f64>,
    /// Incident-bar face displacement along +x, m.
    pub front_displacement_m: Vec<f64>,
    /// Transmission-bar face displacement along +x, m.
    pub back_displacement_m: Vec<f64>,
    /// Sphere approach δ = u_front − u_back, m (compression positive).
    pub displacement_m: Vec<f64>,
    /// Approach velocity δ̇ = v_front − v_back, m/s.
    pub approach_velocity_m_s: Vec<f64>,
    /// Global strain rate δ̇/(r1 + r2), 1/s (when the radii were given).
    pub strain_rate_per_s: Option<Vec<f64>>,
    /// |F_front − F_back| / max(|F_3wave|, 0.05 max|F_3wave|).
    pub equilibrium_ratio: Vec<f64>,
    /// Largest back (transmitted) force, N.
    pub peak_back_force_n: f64,
    /// Time of the peak back force, s.
    pub peak_back_force_time_s: f64,
    /// Index of the peak back force in the series.
    pub peak_index: usize,
    /// δ at the peak back force, m.
    pub displacement_at_peak_force_m: f64,
    /// Equilibrium ratio at the peak back force.
    pub equilibrium_ratio_at_peak: f64,
    /// Largest front force, N.
    pub peak_front_force_n: f64,
    /// Largest δ, m.
    pub max_displacement_m: f64,
    /// The windows used.
    pub windows: Windows,
    /// Start of the reflected pulse measured in the incident record (same foot rule as the
    /// incident, on its largest tensile excursion), minus the incident start, s; None if no
    /// tensile pulse of at least 10 % of the incident peak is found.
    pub measured_reflected_delay_s: Option<f64>,
    /// What the window alignment chose and measured (docs/physics.md §7.6).
    pub alignment: AlignmentReport,
    /// Quality checks: equilibrium over the loading, pulse overlap, noise (docs/physics.md §7.7).
    pub quality: Quality,
    /// Whether the dispersion correction was applied.
    pub dispersion_corrected: bool,
    /// Which dispersion correction was applied.
    pub dispersion: DispersionCorrection,
    /// Whether the Tyas–Pope amplitude factors were applied.
    pub tyas_pope: bool,
    /// Things the user should know (Poisson's ratio off the fit, reflected delay off nominal, …).
    pub warnings: Vec<String>,
    /// The filter applied to both records, its parameters fixed (docs/physics.md §7.12).
    pub filter: Filter,
    /// How the baselines were removed (docs/physics.md §7.12).
    pub baseline: Baseline,
    /// The wave separation applied, if any (docs/physics.md §7.11).
    pub separation: Option<Separation>,
    /// A tension reduction (docs/physics.md §7.8.1): every series is in the loading's sense, the
    /// face strains −ε of the gauges', forces, δ (the elongation) and stresses tension positive.
    pub tension: bool,
    /// The two gauge records the windows were cut from, conditioned (smoothed, debiased) on the
    /// record's clock: what `--plot` places the windows on.
    pub record: RecordTrace,
}

/// The gauge strains a reduction cut its windows from, on the record's clock (docs/physics.md
/// §7.3, "Windows" 1–3: smoothed and debiased as the first stage leaves them).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecordTrace {
    /// Sample times, s (the record's clock).
    pub time_s: Vec<f64>,
    /// Incident-gauge strain (incident and reflected pulses), tension positive.
    pub incident_strain: Vec<f64>,
    /// Transmission-gauge strain, tension positive.
    pub transmission_strain: Vec<f64>,
}

impl RecordTrace {
    /// The conditioned records of the first stage on the record's clock.
    fn of(input: &ReductionInput, strains: &baseline::Conditioned) -> RecordTrace {
        RecordTrace {
            time_s: input.time_s.clone(),
            incident_strain: strains.incident.clone(),
            transmission_strain: strains.transmission.clone(),
        }
    }
}

/// The arrivals of a record's pulses by the rule of the reduction's measured delays
/// (docs/physics.md §7.6, `--align foot`): every delay is a foot (2 % of the pulse's own peak,
/// [`crate::gauge::pulse_foot`]) minus the incident foot, on the record's clock; what
/// `shpb calibrate` fits the wave speed and the gauge distances to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrivals {
    /// Sample step of the record, s.
    pub dt_s: f64,
    /// Foot of the incident pulse on the record's clock, s.
    pub incident_foot_s: f64,
    /// Largest compressive strain of the incident pulse (0 without one).
    pub incident_peak_strain: f64,
    /// Foot of the reflected (first tensile) pulse after the incident foot, s; None without one
    /// of at least 10 % of the incident peak.
    pub reflected_delay_s: Option<f64>,
    /// Foot of the transmitted pulse after the incident foot, s; None without one above 10 times
    /// the transmission gauge's noise.
    pub transmitted_delay_s: Option<f64>,
    /// Arrival of the incident bar's far-end reflection (the reflected pulse come back from the
    /// impact end as compression, ideally 2 L_I/c0 after the incident foot) after the incident
    /// foot, s: the reflected foot's delay plus the time from the reflected pulse's half-peak
    /// rising crossing to the echo's; None without a reflected pulse or when the record does not
    /// show an echo of at least 10 % of the incident peak within (L_I − d_I)/c0 of 2 L_I/c0.
    pub incident_echo_delay_s: Option<f64>,
}

/// The pulse arrivals of a record ([`Arrivals`]): conditioned as [`reduce_named`] conditions it
/// (smoothing, baseline, polarity, incident foot) and the feet searched from half to twice the
/// delays `setup` predicts (2 d_I/c0, d_I/c0 + d_T/c0 + the options' specimen transit, and
/// 2 L_I/c0 for the far-end reflection), as `--align foot` measures them.
pub fn measured_arrivals(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
    file: &str,
) -> Result<Arrivals> {
    options.validate()?;
    let options = &options.resolved_for(setup);
    let strains = baseline::condition(input, options, file)?;
    let incident_start_s = windows::incident_start_s(input, &strains, options, file)?;
    let dt = strains.dt;
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let (c_i, c_t) = (bi.wave_speed_m_s, bt.wave_speed_m_s);
    let s_i = (incident_start_s - input.time_s[0]) / dt;
    let peak = strains.incident_peak;
    let foot = |eps: &[f64], sign: f64, geometric_s: f64, least: f64| {
        align::foot_delay_s(
            eps,
            sign,
            dt,
            s_i,
            geometric_s,
            least,
            options.start_fraction,
        )
    };
    let geometric_r = 2.0 * setup.incident_gauge_m / c_i;
    let geometric_t = setup.incident_gauge_m / c_i
        + setup.transmission_gauge_m / c_t
        + options.specimen_transit_s;
    let reflected = (peak > 0.0)
        .then(|| foot(&strains.incident, 1.0, geometric_r, 0.1 * peak))
        .flatten();
    Ok(Arrivals {
        dt_s: dt,
        incident_foot_s: incident_start_s,
        incident_peak_strain: peak,
        reflected_delay_s: reflected,
        transmitted_delay_s: foot(
            &strains.transmission,
            -1.0,
            geometric_t,
            10.0 * strains.transmission_noise,
        ),
        // The echo rides on the tail of the reflected pulse, whose 2 % level it may not leave:
        // it is timed against the reflected pulse, itself inverted, by their half-peak rising
        // crossings, and the reflected foot's delay added. It is searched within half the
        // reflected pulse's path to the impact end, 2 (L_I − d_I)/c0, around where the set-up
        // puts it (so within ±25 % of the set-up's c0).
        incident_echo_delay_s: match (bi.length_m, reflected) {
            (Some(l), Some(r)) => {
                let geometric_e = 2.0 * l / c_i;
                let w = 0.5 * (geometric_e - geometric_r).max(0.0);
                let half = |sign: f64, within_s: (f64, f64)| {
                    align::foot_delay_between_s(
                        &strains.incident,
                        sign,
                        dt,
                        s_i,
                        within_s,
                        0.1 * peak,
                        0.5,
                    )
                };
                let r50 = half(1.0, (0.5 * geometric_r, 2.0 * geometric_r));
                let e50 = half(-1.0, (geometric_e - w, geometric_e + w));
                match (r50, e50) {
                    (Some(r50), Some(e50)) if e50 > r50 => Some(r + e50 - r50),
                    _ => None,
                }
            }
            _ => None,
        },
    })
}

/// An input error of the reduction (`file` names the record or "reduction options").
fn input_err(
    file: &str,
    key: &str,
    problem: impl Into<String>,
    allowed: impl Into<String>,
) -> Error {
    Error::Invalid {
        object: file.to_string(),
        quantity: key.to_string(),
        problem: problem.into(),
        allowed: allowed.into(),
    }
}

/// Reduces two gauge strain histories to face forces, approach, its rate and the strain rate
/// (docs/physics.md §7.3 gives every rule and sign). Errors name `"reduction input"`/`"reduction
/// options"` and the key at fault.
pub fn reduce(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
) -> Result<Reduction> {
    reduce_named(input, setup, options, "reduction input")
}

/// [`reduce`] with the record's name for error messages (`<name>: <series>`): the stages of the
/// module docs in order.
pub fn reduce_named(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
    file: &str,
) -> Result<Reduction> {
    reduce_separated(input, None, setup, options, file)
}

/// [`reduce_named`] with the records of a second gauge on each bar, which the two-gauge wave
/// separation needs (`options.wave_separation`, docs/physics.md §7.11): with a separation the
/// windows are cut from the separated face waves ([`separation`]) instead of the gauge records.
pub fn reduce_separated(
    input: &ReductionInput,
    second: Option<&SecondGauges>,
    setup: &ReductionSetup,
    options: &ReductionOptions,
    file: &str,
) -> Result<Reduction> {
    options.validate()?;
    let options = &options.resolved_for(setup);
    // A tension test is reduced in its loading's sense: its records turned (§7.8.1).
    let input = &*input.in_loading_sense(options.tension);
    let strains = baseline::condition(input, options, file)?;
    let incident_start_s = windows::incident_start_s(input, &strains, options, file)?;
    // Stage 2, the windows and the waves at the faces: cut from the gauge records, or from the
    // separated face waves (§7.11).
    let mut warnings = Vec::new();
    let (placed, waves, separation) = if options.wave_separation != WaveSeparation::None {
        let (placed, waves, separation) = separation::stage(
            input,
            second,
            setup,
            options,
            &strains,
            incident_start_s,
            file,
        )?;
        (placed, waves, Some(separation))
    } else {
        let corrections = correction::FaceCorrections::new(setup, options)?;
        let placed = windows::place(
            input,
            setup,
            options,
            &strains,
            incident_start_s,
            &corrections,
            file,
            &mut warnings,
        )?;
        warnings.extend(corrections.warnings());
        let waves = waves::at_faces(setup, &strains, &placed, &corrections);
        warnings.extend(waves::reflected_delay_warning(
            setup,
            options,
            &strains,
            &placed,
            &corrections,
            &waves,
        ));
        (placed, waves, None)
    };
    let quality = quality::assess(options, &strains, &placed, &waves, &mut warnings);
    if separation.is_some() {
        // The windows of separated waves are not cut short by the overlap at the gauge.
        warnings.retain(|w| !w.starts_with("the incident pulse lasts"));
    }
    let strain_rate_per_s = options
        .specimen_radii_m
        .map(|radii| specimen::sphere_strain_rate(&waves.faces.approach_velocity_m_s, radii));
    let record = RecordTrace::of(input, &strains);
    let reduction = Reduction::assemble(
        strains.dt,
        setup,
        options,
        placed,
        waves,
        quality,
        strain_rate_per_s,
        warnings,
    );
    Ok(Reduction {
        record,
        separation,
        ..reduction
    })
}

impl Reduction {
    /// The result of the stages on the faces' time axis: the peak of the back force and what
    /// goes with it.
    #[allow(clippy::too_many_arguments)]
    fn assemble(
        dt: f64,
        setup: &ReductionSetup,
        options: &ReductionOptions,
        placed: windows::Placed,
        waves: waves::FaceWaves,
        quality: Quality,
        strain_rate_per_s: Option<Vec<f64>>,
        warnings: Vec<String>,
    ) -> Reduction {
        let w = placed.windows;
        let time_s: Vec<f64> = (0..w.samples).map(|k| k as f64 * dt).collect();
        let f = waves.faces;
        let peak_index = f.peak_index;
        Reduction {
            face_time_offset_s: w.incident_start_s
                + setup.incident_gauge_m / setup.incident_bar.wave_speed_m_s,
            peak_back_force_n: f.force_back_n[peak_index],
            peak_back_force_time_s: time_s[peak_index],
            peak_index,
            displacement_at_peak_force_m: f.displacement_m[peak_index],
            equilibrium_ratio_at_peak: f.equilibrium_ratio[peak_index],
            peak_front_force_n: f
                .force_front_n
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max),
            max_displacement_m: f
                .displacement_m
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max),
            windows: w,
            measured_reflected_delay_s: placed.alignment.measured_reflected_delay_s,
            alignment: placed.alignment,
            quality,
            dispersion_corrected: options.dispersion != DispersionCorrection::None,
            dispersion: options.dispersion,
            tyas_pope: options.tyas_pope,
            warnings,
            tension: options.tension,
            separation: None,
            filter: options.filter,
            baseline: options.baseline,
            time_s,
            incident_strain: waves.incident,
            reflected_strain: waves.reflected,
            transmitted_strain: waves.transmitted,
            force_front_n: f.force_front_n,
            force_back_n: f.force_back_n,
            force_3wave_n: f.force_3wave_n,
            front_displacement_m: f.front_displacement_m,
            back_displacement_m: f.back_displacement_m,
            displacement_m: f.displacement_m,
            approach_velocity_m_s: f.approach_velocity_m_s,
            strain_rate_per_s,
            equilibrium_ratio: f.equilibrium_ratio,
            record: RecordTrace::default(),
        }
    }
}

/// The authors' bars as the reduction sees them (192 GPa, c0 4865.5 m/s, 19.05 mm, ν 0.31), for
/// the unit tests of the reduction and of its cylinder analysis.
#[cfg(test)]
pub(crate) fn authors_bar() -> BarProperties {
    BarProperties {
        youngs_modulus_pa: 192e9,
        wave_speed_m_s: 4865.5,
        area_m2: std::f64::consts::PI * 9.525e-3 * 9.525e-3,
        radius_m: 9.525e-3,
        poisson_ratio: 0.31,
        length_m: None,
    }
}

/// A synthetic record of the authors' bars (no dispersion), for the unit tests: a compressive
/// incident sin² pulse of 4e-4 and 120 µs whose foot passes the incident gauge at 100 µs, its
/// tensile reflection of `reflected` 2 d_I/c0 later, a compressive transmitted pulse of 1e-4
/// (d_I + d_T)/c0 + `late_s` later, sampled at 10 MHz with a deterministic noise of amplitude
/// `noise` (absorbing transmission bar).
#[cfg(test)]
pub(crate) fn synthetic_record(
    reflected: f64,
    late_s: f64,
    noise: f64,
) -> (ReductionInput, ReductionSetup) {
    let bar = authors_bar();
    let setup = ReductionSetup {
        incident_bar: bar,
        transmission_bar: bar,
        incident_gauge_m: 0.644525,
        transmission_gauge_m: 0.3683,
        transmission_absorbing: true,
    };
    let c0 = bar.wave_speed_m_s;
    let pulse = |t: f64| {
        let x = t / 120e-6;
        if (0.0..=1.0).contains(&x) {
            (std::f64::consts::PI * x).sin().powi(2)
        } else {
            0.0
        }
    };
    let (t_i, d_r, d_t) = (100e-6, 2.0 * 0.644525 / c0, (0.644525 + 0.3683) / c0);
    let time_s: Vec<f64> = (0..8000).map(|k| k as f64 * 1e-7).collect();
    let noise = |k: usize| noise * ((k * 7919 % 101) as f64 / 50.0 - 1.0);
    let incident_strain = time_s
        .iter()
        .enumerate()
        .map(|(k, &t)| -4e-4 * pulse(t - t_i) + reflected * pulse(t - t_i - d_r) + noise(k))
        .collect();
    let transmission_strain = time_s
        .iter()
        .enumerate()
        .map(|(k, &t)| -1e-4 * pulse(t - t_i - d_t - late_s) + noise(k + 3))
        .collect();
    (
        ReductionInput {
            time_s,
            incident_strain,
            transmission_strain,
        },
        setup,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of the authors' bars (no dispersion): a compressive incident sin² pulse whose
    /// foot passes the incident gauge at 100 µs, its reflection (tensile, 60 % of it) 2 d_I/c0
    /// later, and a compressive transmitted pulse, sampled at 10 MHz with a little noise.
    fn record() -> (ReductionInput, ReductionSetup) {
        synthetic_record(2.4e-4, 0.0, 1e-7)
    }

    /// No dispersion and no smoothing: the record's own samples.
    fn options() -> ReductionOptions {
        ReductionOptions {
            dispersion: DispersionCorrection::None,
            smoothing_window_s: 0.0,
            filter: Filter::None,
            ..ReductionOptions::default()
        }
    }

    /// Issue 15, item 9: a record with inverted polarity was reduced with the reflected pulse
    /// taken as the incident one; the first pulse on each gauge must be compressive.
    #[test]
    fn a_record_with_inverted_polarity_is_refused_naming_the_channel() {
        let (input, setup) = record();
        let r = reduce_named(&input, &setup, &options(), "rec.csv").unwrap();
        // The foot (2 % of the peak) of the pulse starting at 100 µs.
        assert!((100e-6..110e-6).contains(&r.windows.incident_start_s));

        let mut inverted = input.clone();
        for e in inverted
            .incident_strain
            .iter_mut()
            .chain(inverted.transmission_strain.iter_mut())
        {
            *e = -*e;
        }
        let e = reduce_named(&inverted, &setup, &options(), "rec.csv").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with(
                "rec.csv: `incident_strain`: the first pulse on the incident gauge is tensile \
                 (strain +2.01e-4 at 130.1 µs)"
            ),
            "{msg}"
        );
        assert!(msg.contains("the channel's polarity is inverted"), "{msg}");
        assert!(
            msg.contains("flip the sign of `polarity` of the incident channel"),
            "{msg}"
        );

        // The transmission channel alone inverted.
        let mut inverted = input.clone();
        for e in inverted.transmission_strain.iter_mut() {
            *e = -*e;
        }
        let msg = reduce_named(&inverted, &setup, &options(), "rec.csv")
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("rec.csv: `transmission_strain`: the first pulse on the transmission gauge is tensile"),
            "{msg}"
        );
    }

    /// The Poisson's-ratio warning belongs to the Bancroft fit (made for ν = 0.31); the exact
    /// mode takes the bar's own ν. The Tyas–Pope factors need a phase correction.
    #[test]
    fn exact_correction_takes_the_bars_poisson_ratio_and_tyas_pope_needs_a_correction() {
        let (input, mut setup) = record();
        setup.incident_bar.poisson_ratio = 0.29;
        setup.transmission_bar.poisson_ratio = 0.29;
        let with = |dispersion, tyas_pope| ReductionOptions {
            dispersion,
            tyas_pope,
            ..ReductionOptions::default()
        };
        let fit = reduce(&input, &setup, &with(DispersionCorrection::Bancroft, false)).unwrap();
        assert_eq!(fit.dispersion, DispersionCorrection::Bancroft);
        assert!(
            fit.warnings.iter().any(|w| w.contains("0.29")),
            "{:?}",
            fit.warnings
        );
        let exact = reduce(
            &input,
            &setup,
            &with(DispersionCorrection::PochhammerChree, false),
        )
        .unwrap();
        assert_eq!(exact.dispersion, DispersionCorrection::PochhammerChree);
        assert!(exact.dispersion_corrected && !exact.tyas_pope);
        assert!(
            !exact.warnings.iter().any(|w| w.contains("Poisson")),
            "{:?}",
            exact.warnings
        );
        let e = reduce(&input, &setup, &with(DispersionCorrection::None, true)).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("tyas_pope") && msg.contains("pochhammer-chree"),
            "{msg}"
        );
        // On a 120 µs sin² pulse (nearly all its energy below 20 kHz, where M1·M2 − 1 < 0.2 %)
        // the amplitude factors change the peak back force by less than 0.5 %, but do change it.
        let tp = reduce(
            &input,
            &setup,
            &with(DispersionCorrection::PochhammerChree, true),
        )
        .unwrap();
        assert!(tp.tyas_pope);
        let rel = tp.peak_back_force_n / exact.peak_back_force_n - 1.0;
        assert!(rel.abs() < 5e-3 && rel != 0.0, "{rel}");
    }
}

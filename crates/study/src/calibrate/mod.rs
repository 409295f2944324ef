//! `shpb calibrate`: the constants of a set-up fitted to a lab's own shots, each with its 1-sigma
//! and what it was fitted on (docs/physics.md §6.4 and §7.6; validation/pulse/REPORT.md).
//!
//! One module per calibration, registered once in [`CALIBRATIONS`]; each runs when the shots
//! carry its data:
//! - [`arrivals`]: wave speed and effective gauge distances from the pulses' feet;
//! - [`velocity_factor`]: the incident gauge's strain factor from measured striker velocities
//!   (a set-up without a shaper: incident strain = v/(2c0) for a striker of the bar's section);
//! - [`gun`]: the gun line v² = k (p − p_loss) from measured velocities against pressure
//!   (weighted least squares);
//! - [`shaper`]: the Frew shaper's diameter, thickness and effective modulus from incident
//!   pulses at several pressures (tied to the gun line) or measured velocities (argmin's
//!   Nelder–Mead);
//! - [`specimen_arrivals`]: the transmission gauge's effective distance from specimen shots'
//!   virtual tests (shots naming their `scene`).
//!
//! [`model_scatter`] then states the shots' scatter about the calibrated model when shots name
//! their virtual tests.
//!
//! The strain factor from paired volt and strain files (`--paired VOLTS STRAINS`) is
//! `crate::strain_factor` (helper RECORDS); the command is the place it is wired in.

pub mod arrivals;
pub mod gun;
pub mod model_scatter;
pub mod optimise;
pub mod setup_file;
pub mod shaper;
pub mod specimen_arrivals;
pub mod velocity_factor;

use shpb_core::apparatus::Apparatus;
use shpb_core::reduce::{Arrivals, ReductionInput, ReductionOptions, ReductionSetup};
pub use shpb_core::uncertainty::Correlation;
use shpb_input::shots::{Shot, ShotManifest};
use shpb_input::{Error, Result};

/// Where a constant's 1-sigma comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdFrom {
    /// The shot-to-shot scatter of the per-shot values (standard error of their mean).
    Scatter,
    /// The least-squares covariance: the residuals' scatter through the fit's Jacobian.
    Covariance,
    /// The record's sampling: one sample step over √12 per arrival (a single shot).
    Resolution,
}

impl SdFrom {
    /// The name printed beside the value (`scatter`, `covariance`, `resolution`).
    pub fn name(self) -> &'static str {
        match self {
            SdFrom::Scatter => "scatter",
            SdFrom::Covariance => "covariance",
            SdFrom::Resolution => "resolution",
        }
    }
}

/// One calibrated constant.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    /// The dotted key it replaces: a set-up key (`gun.k_m2_per_s2_per_pa`) or a gauge channel's
    /// (`gauges.incident.distance_from_specimen_m`, written to the gauge file).
    pub key: String,
    /// Value, SI.
    pub value: f64,
    /// SI unit (`1` for numbers).
    pub unit: &'static str,
    /// 1-sigma in the key's unit; None when the shots cannot give one.
    pub sd: Option<f64>,
    /// Where the 1-sigma comes from.
    pub sd_from: SdFrom,
    /// What it was fitted on (the calibration and its data), one line.
    pub fitted_on: String,
    /// Whether it goes into `[uncertainty]` (a derived bookkeeping key such as the calibration
    /// striker's length does not).
    pub uncertain: bool,
}

impl Fitted {
    /// The 1-sigma as a fraction of the value.
    pub fn relative_sd(&self) -> Option<f64> {
        self.sd.map(|s| s / self.value.abs())
    }
}

/// One shot as the calibrations see it: the manifest's entry, the record's strains read through
/// the base set-up, and its pulses' arrivals.
#[derive(Debug, Clone)]
pub struct ShotData {
    /// The manifest's entry.
    pub shot: Shot,
    /// The record's gauge strains (the one record entry point, [`crate::api::record_input`]).
    pub input: ReductionInput,
    /// Its pulses' feet (`shpb reduce`'s measured delays).
    pub arrivals: Arrivals,
}

impl ShotData {
    /// The shot's group for the shot-to-shot scatter: its pressure, else its velocity.
    fn group(&self) -> Option<u64> {
        self.shot
            .pressure_pa
            .or(self.shot.velocity_m_s)
            .map(|x| (x * 1e3).round() as u64)
    }
}

/// What every calibration gets: the base set-up and the shots.
pub struct Data {
    /// The shots manifest, as named (messages name it).
    pub source: String,
    /// The base set-up (`--bars`).
    pub base: Apparatus,
    /// The manifest's `fitted_on`.
    pub fitted_on: String,
    /// The shots.
    pub shots: Vec<ShotData>,
    /// Which calibrations to run (None: every one whose data is given).
    pub only: Option<Vec<String>>,
    /// The base set-up's texts ([`setup_file::read_base`]), for the shots' virtual tests on a
    /// calibrated set-up ([`model_scatter`]); None when its file cannot be read again.
    pub base_texts: Option<model_scatter::BaseTexts>,
}

impl Data {
    /// Reads every shot of `manifest` through the base set-up (records through
    /// [`crate::api::record_input`], arrivals through [`shpb_core::reduce::measured_arrivals`]).
    pub fn read(base: Apparatus, manifest: &ShotManifest) -> Result<Data> {
        let options = ReductionOptions::default();
        let setup = ReductionSetup::from_apparatus(&base)?;
        let mut shots = Vec::with_capacity(manifest.shots.len());
        for s in &manifest.shots {
            let input = crate::api::record_input(
                &s.file,
                &base,
                s.layout.as_ref(),
                true,
                options.baseline_samples,
            )?;
            let name = s.file.display().to_string();
            // Each shot's record checked for plausibility, as `shpb reduce` checks it.
            shpb_core::reduce::plausibility::check_input(&input, &setup, &options, &name)?;
            let arrivals = shpb_core::reduce::measured_arrivals(&input, &setup, &options, &name)?;
            shots.push(ShotData {
                shot: s.clone(),
                input,
                arrivals,
            });
        }
        // A built-in set-up is read again by its name, a file by its path.
        let source =
            shpb_input::uncertainty::builtin_setup_name(&base.source).unwrap_or(&base.source);
        let base_texts = setup_file::read_base(std::path::Path::new(source)).ok();
        Ok(Data {
            source: manifest.source.clone(),
            base,
            fitted_on: manifest.fitted_on.clone(),
            shots,
            only: manifest.only.clone(),
            base_texts,
        })
    }

    /// What `shots` are, for `fitted_on`: the manifest's `fitted_on` when they are all the
    /// shots, else their labels, comma-separated.
    pub fn on<'a>(&self, shots: impl IntoIterator<Item = &'a ShotData>) -> String {
        let labels: Vec<&str> = shots.into_iter().map(|s| s.shot.label.as_str()).collect();
        if labels.len() == self.shots.len() {
            self.fitted_on.clone()
        } else {
            labels.join(", ")
        }
    }
}

/// What one calibration fitted: its constants and the correlations of those one fit gave
/// together (from the fit's covariance matrix).
#[derive(Debug, Clone, Default)]
pub struct Fit {
    /// The constants.
    pub constants: Vec<Fitted>,
    /// Correlations of pairs of uncertain constants (a pair not listed: independent).
    pub correlations: Vec<Correlation>,
}

impl From<Vec<Fitted>> for Fit {
    fn from(constants: Vec<Fitted>) -> Self {
        Fit {
            constants,
            correlations: Vec::new(),
        }
    }
}

/// A calibration: a named fit that runs when the shots carry its data.
pub trait Calibrator: Sync {
    /// Its name (`arrivals`, `strain-factor`, `gun`, `shaper`).
    fn name(&self) -> &'static str;
    /// None when it can run on `data`, else why not (printed when skipped).
    fn skip_reason(&self, data: &Data, earlier: &[Fitted]) -> Option<String>;
    /// Fits its constants; `earlier` holds what the calibrations before it fitted, `progress`
    /// gets one line per stage of a long fit.
    fn fit(&self, data: &Data, earlier: &[Fitted], progress: &mut dyn FnMut(&str)) -> Result<Fit>;
}

/// Every calibration, in the order they run (the registration).
pub const CALIBRATIONS: [&dyn Calibrator; 5] = [
    &arrivals::ArrivalFit,
    &velocity_factor::VelocityFactor,
    &gun::GunLine,
    &shaper::ShaperFit,
    &specimen_arrivals::SpecimenArrivals,
];

/// The names of [`CALIBRATIONS`], for messages.
pub fn calibration_names() -> String {
    CALIBRATIONS
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// What `shpb calibrate` found.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// What the shots are.
    pub fitted_on: String,
    /// Number of shots.
    pub shots: usize,
    /// The calibrated constants, in the order fitted.
    pub constants: Vec<Fitted>,
    /// Correlations of pairs of the constants (`[uncertainty.correlation]`).
    pub correlations: Vec<Correlation>,
    /// Shot-to-shot scatter beyond the model (`[uncertainty.scatter]` keys and 1-sigma).
    pub scatter: Vec<(&'static str, f64)>,
    /// The calibrations that ran and those skipped, with why.
    pub ran: Vec<(&'static str, Option<String>)>,
}

/// Runs every registered calibration whose data `data` carries (or those `data.only` names).
pub fn calibrate(data: &Data, progress: &mut dyn FnMut(&str)) -> Result<Calibration> {
    if let Some(only) = &data.only
        && let Some(bad) = only
            .iter()
            .find(|n| !CALIBRATIONS.iter().any(|c| c.name() == n.as_str()))
    {
        return Err(Error::Input {
            file: data.source.clone(),
            key: "calibrate".into(),
            problem: format!("unknown calibration `{bad}`"),
            allowed: calibration_names(),
        });
    }
    let mut constants: Vec<Fitted> = Vec::new();
    let mut correlations: Vec<Correlation> = Vec::new();
    let mut ran = Vec::new();
    for c in CALIBRATIONS {
        if data
            .only
            .as_ref()
            .is_some_and(|o| !o.iter().any(|n| n == c.name()))
        {
            ran.push((
                c.name(),
                Some("not asked for (`calibrate` in the manifest)".into()),
            ));
            continue;
        }
        if let Some(why) = c.skip_reason(data, &constants) {
            ran.push((c.name(), Some(why)));
            continue;
        }
        let fitted = c.fit(data, &constants, progress)?;
        // A later fit of a key replaces the earlier value and its correlations.
        for f in &fitted.constants {
            correlations.retain(|r| r.a != f.key && r.b != f.key);
        }
        constants.extend(fitted.constants);
        correlations.extend(fitted.correlations);
        ran.push((c.name(), None));
    }
    if constants.is_empty() {
        return Err(Error::Input {
            file: data.source.clone(),
            key: "shot".into(),
            problem: format!(
                "no calibration can run on these shots: {}",
                ran.iter()
                    .filter_map(|(n, w)| w.as_ref().map(|w| format!("{n}: {w}")))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
            allowed: "shots with pulse arrivals, measured striker velocities or gun pressures"
                .into(),
        });
    }
    Ok(Calibration {
        fitted_on: data.fitted_on.clone(),
        shots: data.shots.len(),
        constants,
        correlations,
        scatter: scatter(data),
        ran,
    })
}

/// Mean of `x` (NaN when empty).
pub fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// Sample standard deviation of `x` (n − 1 degrees of freedom); None for fewer than two values.
pub fn sample_sd(x: &[f64]) -> Option<f64> {
    (x.len() >= 2).then(|| {
        let m = mean(x);
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64).sqrt()
    })
}

/// Pooled within-group standard deviation of `values` grouped by `groups` (Σ over groups of the
/// squared deviations from the group's mean over Σ (n_g − 1)), relative to each group's mean when
/// `relative`; None without a group of two.
pub fn pooled_sd(values: &[(Option<u64>, f64)], relative: bool) -> Option<f64> {
    let mut keys: Vec<u64> = values.iter().filter_map(|v| v.0).collect();
    keys.sort_unstable();
    keys.dedup();
    let (mut ss, mut df) = (0.0, 0usize);
    for k in keys {
        let g: Vec<f64> = values
            .iter()
            .filter(|v| v.0 == Some(k))
            .map(|v| v.1)
            .collect();
        if g.len() < 2 {
            continue;
        }
        let m = mean(&g);
        let scale = if relative { m.abs() } else { 1.0 };
        ss += g.iter().map(|v| ((v - m) / scale).powi(2)).sum::<f64>();
        df += g.len() - 1;
    }
    (df > 0).then(|| (ss / df as f64).sqrt())
}

/// Energy a stress pulse carries past a gauge in one direction, A/(ρ c0) ∫σ² dt, J
/// (docs/physics.md §6.4), on samples evenly spaced by their mean step (0 for fewer than two).
pub fn pulse_energy_j(a: &Apparatus, time_s: &[f64], stress_pa: &[f64]) -> f64 {
    let n = time_s.len();
    if n < 2 {
        return 0.0;
    }
    let z = a.material.density_kg_m3 * a.material.wave_speed_m_s();
    let dt = (time_s[n - 1] - time_s[0]) / (n - 1) as f64;
    a.incident.area_m2() / z * stress_pa.iter().map(|s| s * s).sum::<f64>() * dt
}

/// A shot's incident pulse as the calibrations read it: compressive stress −E ε at the incident
/// gauge from 10 µs before its foot to 10 µs before the reflected pulse can arrive (2 d_I/c0
/// after the foot); returns (times, stress).
pub fn incident_pulse(a: &Apparatus, s: &ShotData) -> (Vec<f64>, Vec<f64>) {
    let c0 = a.material.wave_speed_m_s();
    let d = a
        .gauges
        .channel("incident")
        .map_or(0.0, |c| c.distance_from_specimen_m);
    let t0 = s.arrivals.incident_foot_s - 10e-6;
    let t1 = s.arrivals.incident_foot_s + 2.0 * d / c0 - 10e-6;
    let e = a.material.youngs_modulus_pa;
    s.input
        .time_s
        .iter()
        .zip(&s.input.incident_strain)
        .filter(|(t, _)| (t0..=t1).contains(*t))
        .map(|(&t, &eps)| (t, -e * eps))
        .unzip()
}

/// The shot-to-shot scatter the shots show (`[uncertainty.scatter]`): the pooled within-pressure
/// (else within-velocity) relative sd of the incident peak and energy, and the pooled sd of the
/// reflected and transmitted delays.
fn scatter(data: &Data) -> Vec<(&'static str, f64)> {
    let a = &data.base;
    let mut peaks = Vec::new();
    let mut energies = Vec::new();
    let mut reflected = Vec::new();
    let mut transmitted = Vec::new();
    for s in &data.shots {
        let g = s.group();
        let (t, y) = incident_pulse(a, s);
        if let Some(p) = y.iter().copied().reduce(f64::max) {
            peaks.push((g, p));
            energies.push((g, pulse_energy_j(a, &t, &y)));
        }
        if let Some(r) = s.arrivals.reflected_delay_s {
            reflected.push((g, r));
        }
        if let Some(r) = s.arrivals.transmitted_delay_s {
            transmitted.push((g, r));
        }
    }
    [
        ("incident_peak_stress", pooled_sd(&peaks, true)),
        ("incident_energy", pooled_sd(&energies, true)),
        ("reflected_delay_s", pooled_sd(&reflected, false)),
        ("transmitted_delay_s", pooled_sd(&transmitted, false)),
    ]
    .into_iter()
    .filter_map(|(k, v)| v.map(|v| (k, v)))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooled_sd_is_the_within_group_scatter() {
        // Groups {1, 3} and {10, 12, 14}: squared deviations 2 + 8 over 1 + 2 degrees of freedom.
        let v = [
            (Some(1), 1.0),
            (Some(1), 3.0),
            (Some(2), 10.0),
            (Some(2), 12.0),
            (Some(2), 14.0),
            (Some(3), 99.0),
            (None, 5.0),
        ];
        assert!((pooled_sd(&v, false).unwrap() - (10.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(pooled_sd(&v[5..], false), None);
        assert!((sample_sd(&[1.0, 3.0]).unwrap() - 2f64.sqrt()).abs() < 1e-12);
    }
}

//! The choices of a reduction and their one check (docs/physics.md §7.3, §7.6): what the
//! library, `shpb reduce`, `shpb run` and the Python package all pass, refused here when out of
//! range with the quantity at fault.

use super::{
    Alignment, Baseline, DEFAULT_SMOOTHING_S, DispersionCorrection, Filter, ReductionSetup,
    WindowOverride, input_err,
};
use crate::error::Result;

/// Default bound of the balance search on each window shift, s: 60 µs (docs/physics.md §7.6).
pub const DEFAULT_BALANCE_BOUND_S: f64 = 60e-6;

/// Largest bound of the balance search on each window shift, s: 200 µs, most of the authors'
/// 232 µs window; a shift beyond would leave little of the pulses to compare (docs/physics.md
/// §7.6).
pub const MAX_BALANCE_BOUND_S: f64 = 200e-6;

/// Options of a reduction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReductionOptions {
    /// Samples at the start of each record whose mean is the baseline (default 900: 90 µs at
    /// 10 MHz, the pre-trigger part of the authors' records).
    pub baseline_samples: usize,
    /// Dispersion correction of the waves between gauges and faces (default Bancroft).
    pub dispersion: DispersionCorrection,
    /// Apply the Tyas–Pope amplitude factors M1·M2 (exact first mode; needs a dispersion
    /// correction; default false).
    pub tyas_pope: bool,
    /// Manual windows (default None: the automatic rule).
    pub window: Option<WindowOverride>,
    /// Fraction of the incident peak that marks its foot (default 0.02).
    pub start_fraction: f64,
    /// Transit time through the specimen added to the transmitted delay, s (default 0).
    pub specimen_transit_s: f64,
    /// Sphere radii (r1, r2), m, for the global strain rate δ̇/(r1 + r2) (default None).
    pub specimen_radii_m: Option<(f64, f64)>,
    /// Width of a centred moving average applied to both strain records before the reduction,
    /// s (default [`DEFAULT_SMOOTHING_S`]; 0: off). A box of width w attenuates noise by √(w/Δt) and changes a pulse of
    /// rise time τ by about w²/(24 τ²) of its peak.
    pub smoothing_window_s: f64,
    /// How the reflected and transmitted windows are placed (default geometric); a window
    /// override of a delay wins over the strategy for that delay.
    pub alignment: Alignment,
    /// Bound of the balance search on each shift, s (default [`DEFAULT_BALANCE_BOUND_S`]).
    pub balance_bound_s: f64,
    /// A tension test (split Hopkinson tension bar; default false): the records are read in the
    /// loading's sense, every force, stress and strain tension positive (docs/physics.md §7.8.1).
    pub tension: bool,
    /// Wave separation of overlapping pulses (default none; docs/physics.md §7.11).
    pub wave_separation: super::WaveSeparation,
    /// The zero-phase filter of both strain records before the reduction (default
    /// [`Filter::DEFAULT`]: 4th-order Butterworth at the bars' dispersion band, forward and
    /// backward; docs/physics.md §7.12). A moving average without its own width takes
    /// `smoothing_window_s`.
    pub filter: Filter,
    /// How each record's baseline is removed (default [`Baseline::StartMean`]; docs/physics.md
    /// §7.12).
    pub baseline: Baseline,
}

impl Default for ReductionOptions {
    fn default() -> Self {
        ReductionOptions {
            baseline_samples: 900,
            dispersion: DispersionCorrection::Bancroft,
            tyas_pope: false,
            window: None,
            start_fraction: 0.02,
            specimen_transit_s: 0.0,
            specimen_radii_m: None,
            smoothing_window_s: DEFAULT_SMOOTHING_S,
            alignment: Alignment::Geometric,
            balance_bound_s: DEFAULT_BALANCE_BOUND_S,
            tension: false,
            wave_separation: super::WaveSeparation::None,
            filter: Filter::DEFAULT,
            baseline: Baseline::StartMean,
        }
    }
}

impl ReductionOptions {
    /// These options with the filter's parameters fixed for `setup` (docs/physics.md §7.12): a
    /// moving average's width from `smoothing_window_s`, a Butterworth cut-off not given from
    /// the bars' dispersion band (the lower of the two bars'
    /// [`super::filter::band_cutoff_hz`]).
    pub fn resolved_for(&self, setup: &ReductionSetup) -> ReductionOptions {
        let band =
            |b: &super::BarProperties| super::filter::band_cutoff_hz(b.radius_m, b.wave_speed_m_s);
        let band_hz = band(&setup.incident_bar).min(band(&setup.transmission_bar));
        ReductionOptions {
            filter: self.filter.resolved(self.smoothing_window_s, band_hz),
            ..*self
        }
    }

    /// Checks every choice once (docs/physics.md §7.3, §7.6): an [`crate::Error::Invalid`] of
    /// object `"reduction options"` whose quantity is the field at fault (`smoothing_window_s`,
    /// `balance_bound_s`, `window.reflected_delay_s`, …) and whose `allowed` gives the range.
    pub fn validate(&self) -> Result<()> {
        let o = self;
        let file = "reduction options";
        super::separation::validate(o)?;
        if o.tyas_pope && o.dispersion == DispersionCorrection::None {
            return Err(input_err(
                file,
                "tyas_pope",
                "the Tyas–Pope amplitude factors were asked for without a dispersion correction",
                "tyas_pope with dispersion bancroft or pochhammer-chree",
            ));
        }
        if !(o.start_fraction > 0.0 && o.start_fraction < 0.5) {
            return Err(input_err(
                file,
                "start_fraction",
                format!("{} is out of range", o.start_fraction),
                "greater than 0 and less than 0.5",
            ));
        }
        if !(o.specimen_transit_s.is_finite() && o.specimen_transit_s >= 0.0) {
            return Err(input_err(
                file,
                "specimen_transit_s",
                format!("{} s is out of range", o.specimen_transit_s),
                "0 or more seconds",
            ));
        }
        if !(o.smoothing_window_s.is_finite() && o.smoothing_window_s >= 0.0) {
            return Err(input_err(
                file,
                "smoothing_window_s",
                format!("{} s is out of range", o.smoothing_window_s),
                "0 (off) or a positive width in seconds, e.g. 2e-6",
            ));
        }
        if !(o.balance_bound_s.is_finite()
            && o.balance_bound_s > 0.0
            && o.balance_bound_s <= MAX_BALANCE_BOUND_S)
        {
            return Err(input_err(
                file,
                "balance_bound_s",
                format!("{} s is out of range", o.balance_bound_s),
                "a positive bound in seconds up to 2e-4 (200 µs), e.g. 6e-5",
            ));
        }
        o.filter.validate(file)?;
        if let Some((r1, r2)) = o.specimen_radii_m
            && !(r1 > 0.0 && r2 > 0.0 && r1.is_finite() && r2.is_finite())
        {
            return Err(input_err(
                file,
                "specimen_radii_m",
                format!("({r1}, {r2}) m"),
                "two positive radii",
            ));
        }
        if o.tension && o.specimen_radii_m.is_some() {
            return Err(input_err(
                file,
                "tension",
                "a tension reduction of spheres: spheres in contact carry no tension",
                "tension with a cylinder specimen (or none), or spheres in compression",
            ));
        }
        if let Some(w) = o.window {
            for (key, v) in [
                ("window.reflected_delay_s", w.reflected_delay_s),
                ("window.transmitted_delay_s", w.transmitted_delay_s),
                ("window.duration_s", w.duration_s),
            ] {
                if let Some(v) = v
                    && !(v.is_finite() && v > 0.0)
                {
                    return Err(input_err(
                        file,
                        key,
                        format!("{v} s is out of range"),
                        "a positive number of seconds",
                    ));
                }
            }
            if let Some(v) = w.incident_start_s
                && !v.is_finite()
            {
                return Err(input_err(
                    file,
                    "window.incident_start_s",
                    format!("{v} s"),
                    "a finite time on the record clock, s",
                ));
            }
        }
        Ok(())
    }
}

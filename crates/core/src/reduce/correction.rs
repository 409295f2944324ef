//! Dispersion correction of a wave between its gauge and the specimen face (docs/physics.md
//! §7.2, §7.9): the Bancroft fit of the authors' `disp_corr.m`, the exact Pochhammer–Chree first
//! mode, the Tyas–Pope amplitude factors, and the cut of a window at a fractional start.

use super::{BarProperties, ReductionOptions, ReductionSetup};
use crate::dispersion::PochhammerChree;
use crate::error::Result;
use crate::numeric::{bisect, spectral_filter};

/// Bancroft first-mode fit for ν = 0.31 (docs/physics.md §7): A, B, C, D, E, F of
/// `c/c0 = A + B/(C y⁴ + D y³ + E y² + F y^1.5 + 1)`, `y = a/Λ`.
pub const BANCROFT_FIT: [f64; 6] = [0.57344, 0.42790, 18.668, 19.664, -6.6213, 2.3118];

/// Poisson's ratio the Bancroft fit was made for.
pub const BANCROFT_FIT_POISSON_RATIO: f64 = 0.31;

/// `c/c0` of the Bancroft fit at `y = a/Λ` (radius over wavelength).
pub fn bancroft_velocity_ratio(radius_over_wavelength: f64) -> f64 {
    let [a, b, c, d, e, f] = BANCROFT_FIT;
    let y = radius_over_wavelength.max(0.0);
    a + b / (c * y.powi(4) + d * y.powi(3) + e * y * y + f * y.powf(1.5) + 1.0)
}

/// Phase velocity of the first longitudinal mode at frequency `frequency_hz` on a bar of radius
/// `radius_m` and bar-wave speed `c0_m_s`, m/s: the root of `c/c0 = g(a f/c)` (Bancroft fit `g`).
/// `c/c0 − g(a f/c)` increases monotonically with c and changes sign on
/// `[A c0 (1 − 1e-9), (A + B) c0 (1 + 1e-9)]`, so bisection always converges.
pub fn bancroft_phase_velocity_m_s(frequency_hz: f64, radius_m: f64, c0_m_s: f64) -> f64 {
    let f = frequency_hz.abs();
    if f == 0.0 {
        return c0_m_s * (BANCROFT_FIT[0] + BANCROFT_FIT[1]);
    }
    let h = |c: f64| c / c0_m_s - bancroft_velocity_ratio(radius_m * f / c);
    let (lo, hi) = bisect(
        BANCROFT_FIT[0] * c0_m_s * (1.0 - 1e-9),
        (BANCROFT_FIT[0] + BANCROFT_FIT[1]) * c0_m_s * (1.0 + 1e-9),
        100,
        |lo, hi| hi - lo <= 1e-13 * c0_m_s,
        |c| h(c) <= 0.0,
    );
    0.5 * (lo + hi)
}

/// Extra travel time of the component at `frequency_hz` over `distance_m` beyond `distance/c0`,
/// `Δx (1/c(f) − 1/c0)`, s (negative distance: moved back against the propagation).
pub fn dispersion_delay_s(frequency_hz: f64, distance_m: f64, radius_m: f64, c0_m_s: f64) -> f64 {
    let c = bancroft_phase_velocity_m_s(frequency_hz, radius_m, c0_m_s);
    distance_m * (1.0 / c - 1.0 / c0_m_s)
}

/// How the reduction corrects each wave for geometric dispersion between its gauge and the
/// specimen face (docs/physics.md §7.2, §7.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DispersionCorrection {
    /// No correction: every component travels at c0.
    None,
    /// The six-parameter Bancroft fit for ν = 0.31 of the authors' `disp_corr.m` (§7.2).
    #[default]
    Bancroft,
    /// The exact Pochhammer–Chree first mode for the bar's own Poisson's ratio (§7.9).
    PochhammerChree,
}

impl DispersionCorrection {
    /// Every correction, in the order the command line lists them.
    pub const ALL: [DispersionCorrection; 3] = [
        DispersionCorrection::None,
        DispersionCorrection::Bancroft,
        DispersionCorrection::PochhammerChree,
    ];

    /// The correction called `name` (`none`, `bancroft`, `pochhammer-chree`), if any.
    pub fn from_name(name: &str) -> Option<DispersionCorrection> {
        Self::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The name the command line and the outputs use: `none`, `bancroft`, `pochhammer-chree`.
    pub fn name(self) -> &'static str {
        match self {
            DispersionCorrection::None => "none",
            DispersionCorrection::Bancroft => "bancroft",
            DispersionCorrection::PochhammerChree => "pochhammer-chree",
        }
    }
}

/// Highest normalised frequency f a/c0 the Tyas–Pope factors are applied to; components above
/// it are removed (docs/physics.md §7.9: M1 has a pole near f a/c0 ≈ 0.3 for ν = 0.29–0.31, at
/// 0.2 M1·M2 ≈ 1.1 for ν = 0.31).
pub const TYAS_POPE_CUTOFF_FA_OVER_C0: f64 = 0.2;

/// The correction of one wave between its gauge and the face: Bancroft fit (`exact` None) or
/// the exact first mode, and optionally the Tyas–Pope amplitude factors.
pub(crate) struct WaveCorrection<'a> {
    /// Distance the wave is moved, m (negative: back against its propagation).
    distance_m: f64,
    /// Bar radius, m.
    radius_m: f64,
    /// Bar-wave speed c0, m/s.
    c0_m_s: f64,
    /// The exact first mode, if it gives the phase (else the Bancroft fit).
    exact: Option<&'a PochhammerChree>,
    /// The exact first mode, if the Tyas–Pope factors apply.
    tyas_pope: Option<&'a PochhammerChree>,
}

/// The correction of a wave moved by `distance_m` along bar `b` under `options` (None: no
/// dispersion correction).
fn wave_correction<'a>(
    options: &ReductionOptions,
    distance_m: f64,
    b: &BarProperties,
    pc: Option<&'a PochhammerChree>,
) -> Option<WaveCorrection<'a>> {
    (options.dispersion != DispersionCorrection::None).then_some(WaveCorrection {
        distance_m,
        radius_m: b.radius_m,
        c0_m_s: b.wave_speed_m_s,
        exact: if options.dispersion == DispersionCorrection::PochhammerChree {
            pc
        } else {
            None
        },
        tyas_pope: if options.tyas_pope { pc } else { None },
    })
}

impl WaveCorrection<'_> {
    /// Smallest phase velocity over c0 any component can have (margin of [`cut`]).
    fn slowest_ratio(&self) -> f64 {
        match self.exact {
            // The first mode dips below cR before rising back to it (docs/physics.md §7.9);
            // 0.95 cR bounds the dip for every 0 < ν < 0.5.
            Some(pc) => 0.95 * pc.rayleigh_ratio(),
            None => BANCROFT_FIT[0],
        }
    }
}

/// Cuts `n` samples starting at fractional index `start` out of `x` (uniform step `dt`), after
/// delaying every Fourier component by its dispersion delay `Δx (1/c(f) − 1/c0)` (and scaling it
/// by the Tyas–Pope factor) when a correction is given. Exact copy when the start is on a sample
/// and there is no correction; otherwise a Fourier filter (see `spectral_filter`) of the window
/// extended by margins on both sides that cover the largest dispersion delay, so that what the
/// shift moves into the window comes from the record, not from the wrap-around. Samples outside
/// the record read as 0 (the caller keeps the window itself inside the record).
pub(crate) fn cut(
    x: &[f64],
    dt: f64,
    start: f64,
    n: usize,
    correction: Option<&WaveCorrection>,
) -> Vec<f64> {
    let i = start.floor();
    let mut frac = start - i;
    let mut i = i as isize;
    if frac > 1.0 - 1e-9 {
        i += 1;
        frac = 0.0;
    } else if frac < 1e-9 {
        frac = 0.0;
    }
    if frac == 0.0 && correction.is_none() {
        return (0..n)
            .map(|k| {
                let j = i + k as isize;
                if j >= 0 && (j as usize) < x.len() {
                    x[j as usize]
                } else {
                    0.0
                }
            })
            .collect();
    }
    // Margin: the largest dispersion delay (the slowest components) plus slack.
    let max_delay = correction
        .map(|w| w.distance_m.abs() / w.c0_m_s * (1.0 / w.slowest_ratio() - 1.0))
        .unwrap_or(0.0);
    let margin = (max_delay / dt).ceil() as isize + 64;
    let lo = (i - margin).max(0);
    let hi = (i + n as isize + margin).min(x.len() as isize);
    let seg = &x[lo as usize..hi as usize];
    let shifted = spectral_filter(seg, dt, |bin| {
        // Advance by `frac` samples (y(t) = x(t + frac·dt)), then the dispersion delay.
        let Some(w) = correction else {
            return (-frac * dt, 1.0);
        };
        let disp = match w.exact {
            Some(pc) => pc.delay_for_bin_s(bin.index, bin.length, dt, w.distance_m),
            None => dispersion_delay_s(bin.frequency_hz, w.distance_m, w.radius_m, w.c0_m_s),
        };
        let gain = match w.tyas_pope {
            Some(pc) => {
                if bin.frequency_hz * w.radius_m / w.c0_m_s <= TYAS_POPE_CUTOFF_FA_OVER_C0 {
                    pc.tyas_pope_factor_for_bin(bin.index, bin.length, dt)
                } else {
                    0.0
                }
            }
            None => 1.0,
        };
        (disp - frac * dt, gain)
    });
    let off = i - lo;
    (0..n)
        .map(|k| {
            let j = off + k as isize;
            if j >= 0 && (j as usize) < shifted.len() {
                shifted[j as usize]
            } else {
                0.0
            }
        })
        .collect()
}

/// Moves a whole uniformly sampled signal by `distance_m` along a dispersive bar beyond the plain
/// transit `distance/c0`: each Fourier component is delayed by `distance (1/c(f) − 1/c0)`
/// (Bancroft first mode). Positive distance propagates forward (the incident wave from its gauge
/// to the face); negative moves back (reflected and transmitted waves from their gauges to the
/// faces). The same operation the reduction applies to each window.
pub fn dispersion_shift(
    signal: &[f64],
    dt_s: f64,
    distance_m: f64,
    bar: &BarProperties,
) -> Vec<f64> {
    shift_whole(signal, dt_s, distance_m, bar, None)
}

/// The whole of `signal` moved `distance_m` along `bar` by the Bancroft fit (`exact` = None) or
/// the exact first mode: what [`dispersion_shift`] and [`dispersion_shift_exact`] share.
fn shift_whole(
    signal: &[f64],
    dt_s: f64,
    distance_m: f64,
    bar: &BarProperties,
    exact: Option<&PochhammerChree>,
) -> Vec<f64> {
    cut(
        signal,
        dt_s,
        0.0,
        signal.len(),
        Some(&WaveCorrection {
            distance_m,
            radius_m: bar.radius_m,
            c0_m_s: bar.wave_speed_m_s,
            exact,
            tyas_pope: None,
        }),
    )
}

/// [`dispersion_shift`] along the exact Pochhammer–Chree first mode of `bar` (its own Poisson's
/// ratio; docs/physics.md §7.9) instead of the Bancroft fit. Errors name the bar property out of
/// range.
pub fn dispersion_shift_exact(
    signal: &[f64],
    dt_s: f64,
    distance_m: f64,
    bar: &BarProperties,
) -> Result<Vec<f64>> {
    let pc = PochhammerChree::new(bar.poisson_ratio, bar.radius_m, bar.wave_speed_m_s)?;
    Ok(shift_whole(signal, dt_s, distance_m, bar, Some(&pc)))
}

/// The corrections of the three waves of one reduction: one exact first mode per bar (its roots
/// shared by all its windows) when the exact mode or the Tyas–Pope factors are asked for.
pub(crate) struct FaceCorrections<'a> {
    options: &'a ReductionOptions,
    setup: &'a ReductionSetup,
    exact_incident: Option<PochhammerChree>,
    exact_transmission: Option<PochhammerChree>,
}

impl<'a> FaceCorrections<'a> {
    /// The corrections `options` ask for on the bars of `setup`; errors name the bar property
    /// the exact first mode refuses.
    pub(crate) fn new(
        setup: &'a ReductionSetup,
        options: &'a ReductionOptions,
    ) -> Result<FaceCorrections<'a>> {
        let exact = |b: &BarProperties| -> Result<Option<PochhammerChree>> {
            if options.dispersion == DispersionCorrection::PochhammerChree || options.tyas_pope {
                PochhammerChree::new(b.poisson_ratio, b.radius_m, b.wave_speed_m_s).map(Some)
            } else {
                Ok(None)
            }
        };
        Ok(FaceCorrections {
            options,
            setup,
            exact_incident: exact(&setup.incident_bar)?,
            exact_transmission: exact(&setup.transmission_bar)?,
        })
    }

    /// The correction of a wave moved `distance_m` along the incident bar (None: no correction).
    pub(crate) fn incident(&self, distance_m: f64) -> Option<WaveCorrection<'_>> {
        wave_correction(
            self.options,
            distance_m,
            &self.setup.incident_bar,
            self.exact_incident.as_ref(),
        )
    }

    /// The correction of a wave moved `distance_m` along the transmission bar.
    pub(crate) fn transmission(&self, distance_m: f64) -> Option<WaveCorrection<'_>> {
        wave_correction(
            self.options,
            distance_m,
            &self.setup.transmission_bar,
            self.exact_transmission.as_ref(),
        )
    }

    /// Warnings of the Bancroft fit (made for ν = 0.31) on bars of another Poisson's ratio.
    pub(crate) fn warnings(&self) -> Vec<String> {
        let mut warnings = Vec::new();
        if self.options.dispersion == DispersionCorrection::Bancroft {
            for (name, b) in [
                ("incident", &self.setup.incident_bar),
                ("transmission", &self.setup.transmission_bar),
            ] {
                if (b.poisson_ratio - BANCROFT_FIT_POISSON_RATIO).abs() > 0.02 {
                    warnings.push(format!(
                        "the {name} bar's Poisson's ratio {} differs from the Bancroft fit's 0.31",
                        b.poisson_ratio
                    ));
                }
            }
        }
        warnings
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact correction undoes its own propagation, and on a smooth pulse it differs from
    /// the Bancroft fit by no more than the fit's long-wave offset explains: c → (A + B) c0 moves
    /// every long component by τ0 = d/c0 (1 − 1/(A + B)), so |Δε| ≲ τ0 max|ε̇| (10 % allowance
    /// for the fit's residual higher up, ±0.3 % of c). In the pulse's band the residual is of
    /// the other sign (−0.1 % at 20 kHz) and takes back part of the offset, so the difference
    /// is smaller; it is not zero (at least a fifth of τ0 max|ε̇|).
    #[test]
    fn exact_dispersion_inverts_itself_and_differs_from_the_fit_by_its_offset() {
        let bar = super::super::authors_bar();
        let dt = 1e-7;
        let t_rise = 60e-6;
        let pulse: Vec<f64> = (0..6000)
            .map(|k| {
                let x = (k as f64 * dt - 150e-6) / (2.0 * t_rise);
                if (0.0..=1.0).contains(&x) {
                    -1e-3 * (std::f64::consts::PI * x).sin().powi(2)
                } else {
                    0.0
                }
            })
            .collect();
        let d = 0.644525;
        let there = dispersion_shift_exact(&pulse, dt, d, &bar).unwrap();
        let back = dispersion_shift_exact(&there, dt, -d, &bar).unwrap();
        let err = pulse
            .iter()
            .zip(&back)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-9, "round trip error {err}");
        let fit = dispersion_shift(&pulse, dt, d, &bar);
        let diff = fit
            .iter()
            .zip(&there)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let tau0 = d / bar.wave_speed_m_s * (1.0 - 1.0 / (BANCROFT_FIT[0] + BANCROFT_FIT[1]));
        let max_rate = 1e-3 * std::f64::consts::PI / (2.0 * t_rise);
        assert!(
            diff > 0.2 * tau0 * max_rate,
            "{diff} vs {}",
            tau0 * max_rate
        );
        assert!(
            diff < 1.1 * tau0 * max_rate,
            "{diff} vs {}",
            tau0 * max_rate
        );
    }
}

//! Wave separation (docs/physics.md §7.11): the waves travelling toward and away from the
//! specimen at each bar's face, for records whose pulses overlap at the gauges (short bars,
//! gauges near the specimen), so that the reduction's windows are no longer bounded by
//! 2 d/c0 and 2 (L − d)/c0.
//!
//! Two methods, both on the record's whole length and in the frequency domain, each wave moved
//! between a gauge and the face along the exact first Pochhammer–Chree mode (or at c0 without a
//! dispersion correction):
//!
//! - **two gauges per bar** (Lundberg & Henchoz 1977; Park & Zhou 1999): gauges at s₁ < s₂
//!   from the face, Q the propagation over Δ = s₂ − s₁, P₁ over s₁; the toward-face wave at the
//!   face A = P₁ (Q E₂ − Q² E₁)/(1 − Q²) and the away wave B = P₁⁻¹ (E₁ − Q E₂)/(1 − Q²).
//!   1/(1 − Q²) is singular where Δ is a multiple of half a wavelength (and at 0 Hz); it is
//!   replaced by its geometric series Σ_{n<N} Q^{2n} truncated at the record's length
//!   (2 N Δ/c0 > T): in the time domain exactly the Lundberg–Henchoz recursion started from
//!   the quiet record, so the waves are exact within the record, and at the singular
//!   frequencies the gain grows as N (noise grows with time like a random walk).
//! - **one gauge per bar**, with the bar's far end (at a = L − s beyond the gauge) reflecting
//!   with coefficient r (−1 free, 0 absorbing): on the transmission bar ε = (1 + r P_{2a}) T,
//!   T = ε Σ_{n<N} (−r P_{2a})ⁿ, unrolled in steps of the round trip 2 (L − s)/c0. On the
//!   incident bar the far end is the impact end: the wave it generates is taken as the record
//!   before the first reflection can arrive (the incident foot + 2 s/c0), which must be over
//!   by then (else the pulses overlap at the gauge and only two gauges separate them).

use super::ReductionOptions;
use super::input_err;
use crate::dispersion::PochhammerChree;
use crate::error::Result;
use crate::numeric::{fast_fft_length, fft_plan};
use rustfft::num_complex::Complex;

/// Which wave separation the reduction applies (`--wave-separation`, docs/physics.md §7.11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WaveSeparation {
    /// None: each wave is cut from its gauge record in its own window (§7.3).
    #[default]
    None,
    /// One gauge per bar and each bar's far-end reflection (free or absorbing).
    OneGauge,
    /// Two gauges per bar (channels `incident_2`, `transmission_2` of the set-up).
    TwoGauge,
}

impl WaveSeparation {
    /// Every method, in the order the command line lists them.
    pub const ALL: [WaveSeparation; 3] = [
        WaveSeparation::None,
        WaveSeparation::OneGauge,
        WaveSeparation::TwoGauge,
    ];

    /// The method called `name` (`none`, `one-gauge`, `two-gauge`), if any.
    pub fn from_name(name: &str) -> Option<WaveSeparation> {
        Self::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The name the command line and the outputs use.
    pub fn name(self) -> &'static str {
        match self {
            WaveSeparation::None => "none",
            WaveSeparation::OneGauge => "one-gauge",
            WaveSeparation::TwoGauge => "two-gauge",
        }
    }
}

/// Names of the second gauge channels of a set-up, one per bar (two-gauge separation): a
/// channel of this name on bar `incident` / `transmission`, farther from the specimen than the
/// first.
pub const SECOND_GAUGE_CHANNELS: [&str; 2] = ["incident_2", "transmission_2"];

/// The records of the second gauge on each bar (two-gauge separation), on the first gauges'
/// time axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SecondGauges {
    /// Distance of the incident bar's second gauge from the specimen face, m.
    pub incident_gauge_m: f64,
    /// Distance of the transmission bar's second gauge from the specimen face, m.
    pub transmission_gauge_m: f64,
    /// Strain at the incident bar's second gauge (tension positive).
    pub incident_strain: Vec<f64>,
    /// Strain at the transmission bar's second gauge.
    pub transmission_strain: Vec<f64>,
}

/// How a wave travels along one bar: at c0, or along the exact first Pochhammer–Chree mode
/// (docs/physics.md §7.9).
#[derive(Debug, Clone, Copy)]
pub struct Propagation<'a> {
    /// Bar-wave speed c0, m/s.
    pub c0_m_s: f64,
    /// The exact first mode, if the bar disperses.
    pub exact: Option<&'a PochhammerChree>,
}

impl Propagation<'_> {
    /// Spectrum factor of travel over `distance_m` at bin `bin` of an `m`-point FFT at step
    /// `dt`: exp(−2πi f d/c(f)) (a delay of d/c(f); negative distance: an advance).
    fn factor(&self, bin: usize, m: usize, dt: f64, distance_m: f64) -> Complex<f64> {
        let f = bin as f64 / (m as f64 * dt);
        let ratio = match self.exact {
            Some(pc) => pc.velocity_ratio_for_bin(bin, m, dt),
            None => 1.0,
        };
        let phase = -2.0 * std::f64::consts::PI * f * distance_m / (self.c0_m_s * ratio);
        Complex::from_polar(1.0, phase)
    }

    /// Smallest phase velocity over c0 (the first mode dips below cR before rising back to
    /// it; 0.95 cR bounds the dip for every 0 < ν < 0.5, as in `correction::cut`).
    fn slowest_ratio(&self) -> f64 {
        self.exact.map_or(1.0, |pc| 0.95 * pc.rayleigh_ratio())
    }
}

/// The two waves of one bar at its specimen face, on the record's clock (tension positive).
#[derive(Debug, Clone, PartialEq)]
pub struct SeparatedWaves {
    /// The wave travelling toward the specimen (incident bar: the incident wave; transmission
    /// bar: the far end's echo).
    pub toward: Vec<f64>,
    /// The wave travelling away from the specimen (reflected; transmitted).
    pub away: Vec<f64>,
}

/// Σ_{n<N} zⁿ (the truncated geometric series that replaces 1/(1 − z), docs/physics.md §7.11):
/// for |z| = 1, z = e^{−iθ}, e^{−i(N−1)θ/2} sin(Nθ/2)/sin(θ/2), N where sin(θ/2) = 0; else
/// (1 − z^N)/(1 − z) (an absorbing far end, z = 0, gives 1).
fn truncated_series(z: Complex<f64>, n_terms: usize) -> Complex<f64> {
    if (z.norm() - 1.0).abs() > 1e-9 {
        return (Complex::new(1.0, 0.0) - z.powu(n_terms as u32)) / (Complex::new(1.0, 0.0) - z);
    }
    let theta = -z.arg();
    let n = n_terms as f64;
    let half = 0.5 * theta;
    let s = half.sin();
    if s.abs() < 1e-12 {
        // θ = 2πk: every term is 1 (to rounding).
        return Complex::new(n, 0.0);
    }
    Complex::from_polar((n * half).sin() / s, -(n - 1.0) * half)
}

/// Forward FFTs of `signals`, zero-padded to `m`.
fn spectra(signals: &[&[f64]], m: usize) -> Vec<Vec<Complex<f64>>> {
    let plan = fft_plan(m, false);
    signals
        .iter()
        .map(|x| {
            let mut buf: Vec<Complex<f64>> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
            buf.resize(m, Complex::new(0.0, 0.0));
            plan.process(&mut buf);
            buf
        })
        .collect()
}

/// The first `n` samples of the inverse FFT of the half spectrum `half` (bins 0..=m/2; the
/// negative frequencies are its conjugates, so the signal is real).
fn inverse(half: &[Complex<f64>], m: usize, n: usize) -> Vec<f64> {
    let mut buf = vec![Complex::new(0.0, 0.0); m];
    for (k, z) in half.iter().enumerate() {
        buf[k] = *z;
        if k > 0 && k < m - k {
            buf[m - k] = z.conj();
        }
    }
    if m.is_multiple_of(2) {
        buf[m / 2] = Complex::new(buf[m / 2].re, 0.0);
    }
    fft_plan(m, true).process(&mut buf);
    buf.iter().take(n).map(|z| z.re / m as f64).collect()
}

/// Terms of a truncated series whose steps each delay by at least `step_s`: enough that the
/// first term left out lies beyond a record of `n` samples of step `dt`.
fn series_terms(n: usize, dt: f64, step_s: f64) -> usize {
    (n as f64 * dt / step_s).ceil() as usize + 2
}

/// FFT length for `n` samples whose waves are moved by up to `longest_m` of travel (at the
/// slowest phase velocity) and advanced by up to `advance_m`: no wrap-around into the record.
fn fft_length(n: usize, dt: f64, prop: &Propagation, longest_m: f64, advance_m: f64) -> usize {
    let slow = prop.c0_m_s * prop.slowest_ratio();
    let extra = ((longest_m + advance_m) / slow / dt).ceil() as usize + 64;
    fast_fft_length(n + extra)
}

/// Two-gauge separation on one bar (module docs; docs/physics.md §7.11): `near`, `far` are the
/// strains at `near_m` < `far_m` from the face, on one uniform time axis of step `dt` (quiet at
/// its start). Returns the face waves on the same clock.
#[allow(clippy::needless_range_loop)] // bin k indexes the spectra and the factors
pub fn two_gauge(
    near: &[f64],
    far: &[f64],
    near_m: f64,
    far_m: f64,
    dt: f64,
    prop: &Propagation,
) -> SeparatedWaves {
    let n = near.len().min(far.len());
    let gap = far_m - near_m;
    let terms = series_terms(n, dt, 2.0 * gap / prop.c0_m_s);
    let m = fft_length(n, dt, prop, near_m + gap * (2 * terms + 1) as f64, near_m);
    let s = spectra(&[&near[..n], &far[..n]], m);
    let half = m / 2;
    let (mut toward, mut away) = (Vec::with_capacity(half + 1), Vec::with_capacity(half + 1));
    for k in 0..=half {
        let q = prop.factor(k, m, dt, gap);
        let p1 = prop.factor(k, m, dt, near_m);
        let g = truncated_series(q * q, terms);
        let (e1, e2) = (s[0][k], s[1][k]);
        toward.push(p1 * (q * e2 - q * q * e1) * g);
        away.push(p1.conj() * (e1 - q * e2) * g);
    }
    SeparatedWaves {
        toward: inverse(&toward, m, n),
        away: inverse(&away, m, n),
    }
}

/// One-gauge separation on the transmission bar (module docs): strain `e` at `gauge_m` from the
/// face, the far end `beyond_m` beyond the gauge reflecting with `reflection` (−1 free, 0
/// absorbing).
#[allow(clippy::needless_range_loop)] // bin k indexes the spectra and the factors
pub fn one_gauge_transmission(
    e: &[f64],
    gauge_m: f64,
    beyond_m: f64,
    reflection: f64,
    dt: f64,
    prop: &Propagation,
) -> SeparatedWaves {
    let n = e.len();
    let terms = series_terms(n, dt, 2.0 * beyond_m / prop.c0_m_s);
    let m = fft_length(
        n,
        dt,
        prop,
        gauge_m + 2.0 * beyond_m * terms as f64,
        gauge_m,
    );
    let s = spectra(&[e], m);
    let (mut toward, mut away) = (Vec::new(), Vec::new());
    for k in 0..=m / 2 {
        let p = prop.factor(k, m, dt, gauge_m);
        let echo = prop.factor(k, m, dt, 2.0 * beyond_m) * reflection;
        let t = s[0][k] * truncated_series(-echo, terms);
        away.push(p.conj() * t);
        toward.push(p * (s[0][k] - t));
    }
    SeparatedWaves {
        toward: inverse(&toward, m, n),
        away: inverse(&away, m, n),
    }
}

/// One-gauge separation on the incident bar (module docs): strain `e` at `gauge_m` from the
/// face; the impact end `beyond_m` beyond the gauge is free (reflection −1) once the samples
/// before `generated_until` (the incident foot + 2 s/c0) have given the wave it generated.
#[allow(clippy::needless_range_loop)] // bin k indexes the spectra and the factors
pub fn one_gauge_incident(
    e: &[f64],
    generated_until: usize,
    gauge_m: f64,
    beyond_m: f64,
    dt: f64,
    prop: &Propagation,
) -> SeparatedWaves {
    let n = e.len();
    let cut = generated_until.min(n);
    let rest: Vec<f64> = (0..n).map(|k| if k < cut { 0.0 } else { e[k] }).collect();
    let terms = series_terms(n, dt, 2.0 * beyond_m / prop.c0_m_s);
    let m = fft_length(
        n,
        dt,
        prop,
        gauge_m + 2.0 * beyond_m * terms as f64,
        gauge_m,
    );
    let s = spectra(&[e, &rest], m);
    let (mut toward, mut away) = (Vec::new(), Vec::new());
    for k in 0..=m / 2 {
        let p = prop.factor(k, m, dt, gauge_m);
        // Free end: the away wave comes back inverted, −P_{2a} R; R (1 − P_{2a}) = ε − G.
        let echo = -prop.factor(k, m, dt, 2.0 * beyond_m);
        let r = s[1][k] * truncated_series(-echo, terms);
        away.push(p.conj() * r);
        toward.push(p * (s[0][k] - r));
    }
    SeparatedWaves {
        toward: inverse(&toward, m, n),
        away: inverse(&away, m, n),
    }
}

/// The propagation a reduction's options ask for on a bar: the exact first mode unless the
/// dispersion correction is off (the separation has no Bancroft variant).
pub(crate) fn propagation<'a>(
    options: &ReductionOptions,
    c0_m_s: f64,
    exact: Option<&'a PochhammerChree>,
) -> Propagation<'a> {
    Propagation {
        c0_m_s,
        exact: if options.dispersion == super::DispersionCorrection::None {
            None
        } else {
            exact
        },
    }
}

/// Checks the separation's options: no Tyas–Pope factors and geometric windows only.
pub(crate) fn validate(o: &ReductionOptions) -> Result<()> {
    if o.wave_separation == WaveSeparation::None {
        return Ok(());
    }
    if o.tyas_pope {
        return Err(input_err(
            "reduction options",
            "wave_separation",
            "the Tyas–Pope amplitude factors are not applied to separated waves",
            "wave_separation without tyas_pope",
        ));
    }
    if o.alignment != super::Alignment::Geometric {
        return Err(input_err(
            "reduction options",
            "wave_separation",
            format!(
                "separated waves are placed at the faces by the set-up's distances, not by \
                 `{}` alignment",
                o.alignment.name()
            ),
            "wave_separation with the geometric alignment (window overrides are kept)",
        ));
    }
    Ok(())
}

/// What a separation did, for the reduction's outputs (`--json`, `/summary` of the HDF5 file),
/// and the one separated wave the three series of a reduction do not hold.
#[derive(Debug, Clone, PartialEq)]
pub struct Separation {
    /// The method.
    pub method: WaveSeparation,
    /// Gauge distances from the face used on the incident bar (second: two-gauge only), m.
    pub incident_gauges_m: (f64, Option<f64>),
    /// Gauge distances from the face used on the transmission bar, m.
    pub transmission_gauges_m: (f64, Option<f64>),
    /// Whether the waves were moved along the exact first mode (else at c0).
    pub exact_mode: bool,
    /// Largest number of terms of the truncated series (the noise gain at a singular
    /// frequency), over the bars.
    pub series_terms: usize,
    /// The wave coming back to the transmission-bar face from its far end, in the reduction's
    /// window (tension positive; the back force and velocity include it).
    pub returned_strain: Vec<f64>,
}

/// The separated waves at the faces cut into the reduction's windows: the second stage of a
/// reduction with wave separation, in place of `windows::place` and `waves::at_faces`
/// (docs/physics.md §7.11). The windows all start at the incident foot's arrival at the face
/// (the transmitted one the specimen transit later; delay overrides move them as usual); their
/// default length is 1.5 times the separated incident pulse (foot to its return below the start
/// fraction of its peak), within the record.
#[allow(clippy::too_many_arguments)]
pub(crate) fn stage(
    input: &super::ReductionInput,
    second: Option<&SecondGauges>,
    setup: &super::ReductionSetup,
    options: &ReductionOptions,
    strains: &super::baseline::Conditioned,
    incident_start_s: f64,
    file: &str,
) -> Result<(super::windows::Placed, super::waves::FaceWaves, Separation)> {
    let dt = strains.dt;
    let n = input.time_s.len();
    let t0 = input.time_s[0];
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let (c_i, c_t) = (bi.wave_speed_m_s, bt.wave_speed_m_s);
    let (d_i, d_t) = (setup.incident_gauge_m, setup.transmission_gauge_m);
    let exact = |b: &super::BarProperties| -> Result<Option<PochhammerChree>> {
        if options.dispersion == super::DispersionCorrection::None {
            Ok(None)
        } else {
            PochhammerChree::new(b.poisson_ratio, b.radius_m, b.wave_speed_m_s).map(Some)
        }
    };
    let (pc_i, pc_t) = (exact(bi)?, exact(bt)?);
    let prop_i = propagation(options, c_i, pc_i.as_ref());
    let prop_t = propagation(options, c_t, pc_t.as_ref());
    let s_i = (incident_start_s - t0) / dt;
    let missing = |what: String, allowed: &str| input_err(file, "wave_separation", what, allowed);
    let (inc, tra, report) = match options.wave_separation {
        WaveSeparation::None => unreachable!("the stage runs with a separation only"),
        WaveSeparation::TwoGauge => {
            let Some(g) = second else {
                return Err(missing(
                    "two-gauge separation needs a second gauge on each bar, and the record has \
                     none"
                        .into(),
                    "a set-up with channels `incident_2` and `transmission_2` (bar incident and \
                     transmission, farther from the specimen than the first) and a record of \
                     them (a run file of that set-up), or --wave-separation one-gauge",
                ));
            };
            for (name, d2, d1) in [
                ("incident_2", g.incident_gauge_m, d_i),
                ("transmission_2", g.transmission_gauge_m, d_t),
            ] {
                if !d2.is_finite() || d2 - d1 <= 2.0 * c_i.max(c_t) * dt {
                    return Err(missing(
                        format!(
                            "the `{name}` gauge is {:.1} mm from the specimen, the first {:.1} mm: \
                             not farther by more than two samples of travel",
                            d2 * 1e3,
                            d1 * 1e3
                        ),
                        "a second gauge farther from the specimen than the first",
                    ));
                }
            }
            // Filtered as the first gauges (and turned in a tension test, as they are, §7.8.1);
            // the baseline ends before the pulse reaches the gauge: on the incident bar the
            // second gauge sees it (d₂ − d₁)/c0 earlier.
            let sign = if options.tension { -1.0 } else { 1.0 };
            let condition = |e: &[f64], earlier_s: f64| -> Result<Vec<f64>> {
                let nb = strains
                    .baseline_samples
                    .saturating_sub((earlier_s / dt).ceil() as usize);
                let turned: Vec<f64> = e.iter().map(|x| sign * x).collect();
                Ok(super::baseline::debias(
                    &options.filter.apply(&turned, dt, file)?,
                    nb,
                ))
            };
            if g.incident_strain.len() != n || g.transmission_strain.len() != n {
                return Err(missing(
                    format!(
                        "the second gauges have {} and {} samples, the record {n}",
                        g.incident_strain.len(),
                        g.transmission_strain.len()
                    ),
                    "second-gauge records on the record's time axis",
                ));
            }
            let inc = two_gauge(
                &strains.incident,
                &condition(&g.incident_strain, (g.incident_gauge_m - d_i) / c_i)?,
                d_i,
                g.incident_gauge_m,
                dt,
                &prop_i,
            );
            let tra = two_gauge(
                &strains.transmission,
                &condition(&g.transmission_strain, 0.0)?,
                d_t,
                g.transmission_gauge_m,
                dt,
                &prop_t,
            );
            let terms = series_terms(n, dt, 2.0 * (g.incident_gauge_m - d_i) / c_i).max(
                series_terms(n, dt, 2.0 * (g.transmission_gauge_m - d_t) / c_t),
            );
            let report = Separation {
                method: WaveSeparation::TwoGauge,
                incident_gauges_m: (d_i, Some(g.incident_gauge_m)),
                transmission_gauges_m: (d_t, Some(g.transmission_gauge_m)),
                exact_mode: prop_i.exact.is_some(),
                series_terms: terms,
                returned_strain: Vec::new(),
            };
            (inc, tra, report)
        }
        WaveSeparation::OneGauge => {
            let length = |b: &super::BarProperties, name: &str| {
                b.length_m.ok_or_else(|| {
                    missing(
                        format!("one-gauge separation needs the {name} bar's length, not known"),
                        "a set-up that gives the bars' lengths",
                    )
                })
            };
            let beyond_i = length(bi, "incident")? - d_i;
            // The impact end's generated wave: the record before the reflection can arrive.
            let until = (s_i + 2.0 * d_i / c_i / dt).floor();
            let peak = strains.incident_peak;
            let k_until = until.max(0.0) as usize;
            let last_us = ((1e-6 / dt).round() as usize).max(1);
            let at_cut = strains.incident
                [k_until.saturating_sub(last_us).min(n - 1)..k_until.min(n)]
                .iter()
                .fold(0.0f64, |m, e| m.max(e.abs()));
            if peak > 0.0 && at_cut > 0.05 * peak {
                return Err(missing(
                    format!(
                        "the incident pulse is still on ({:.0} % of its peak) when its reflection \
                         reaches the incident gauge, 2 d_I/c0 = {:.1} µs after its foot: the \
                         pulses overlap there, and one gauge cannot tell them apart",
                        100.0 * at_cut / peak,
                        2.0 * d_i / c_i * 1e6
                    ),
                    "--wave-separation two-gauge (channels `incident_2`, `transmission_2`), or \
                     an incident gauge farther from the specimen than half the pulse's length",
                ));
            }
            let inc = one_gauge_incident(&strains.incident, k_until, d_i, beyond_i, dt, &prop_i);
            let (tra, beyond_t) = if setup.transmission_absorbing {
                (
                    one_gauge_transmission(&strains.transmission, d_t, 1.0, 0.0, dt, &prop_t),
                    None,
                )
            } else {
                let beyond_t = length(bt, "transmission")? - d_t;
                (
                    one_gauge_transmission(&strains.transmission, d_t, beyond_t, -1.0, dt, &prop_t),
                    Some(beyond_t),
                )
            };
            let mut terms = series_terms(n, dt, 2.0 * beyond_i / c_i);
            if let Some(b) = beyond_t {
                terms = terms.max(series_terms(n, dt, 2.0 * b / c_t));
            }
            let report = Separation {
                method: WaveSeparation::OneGauge,
                incident_gauges_m: (d_i, None),
                transmission_gauges_m: (d_t, None),
                exact_mode: prop_i.exact.is_some(),
                series_terms: terms,
                returned_strain: Vec::new(),
            };
            (inc, tra, report)
        }
    };

    // Windows on the face clock: the geometric delays (or the overrides) less the transits.
    let ov = options.window.unwrap_or_default();
    let geometric_r = 2.0 * d_i / c_i;
    let geometric_t = d_i / c_i + d_t / c_t + options.specimen_transit_s;
    let reflected_delay_s = ov.reflected_delay_s.unwrap_or(geometric_r);
    let transmitted_delay_s = ov.transmitted_delay_s.unwrap_or(geometric_t);
    let f_i = s_i + d_i / c_i / dt;
    let f_r = s_i + (reflected_delay_s - d_i / c_i) / dt;
    let f_t = s_i + (transmitted_delay_s - d_t / c_t) / dt;
    // The last samples are spoilt by the record's end moved back to the faces (the away waves
    // are advanced by the gauge distances): the windows end before.
    let far = report
        .incident_gauges_m
        .1
        .unwrap_or(d_i)
        .max(report.transmission_gauges_m.1.unwrap_or(d_t));
    let slow = prop_i.slowest_ratio().min(prop_t.slowest_ratio()) * c_i.min(c_t);
    let last = (n - 1) as f64 - (far / slow / dt).ceil();
    let duration_s = match ov.duration_s {
        Some(d) => d,
        None => {
            let k0 = f_i.max(0.0).ceil() as usize;
            let pulse: Vec<f64> = inc.toward[k0.min(n)..].iter().map(|e| -e).collect();
            let k_peak = crate::numeric::argmax(&pulse);
            let level = options.start_fraction * pulse.get(k_peak).copied().unwrap_or(0.0);
            let end = (k_peak..pulse.len())
                .find(|&k| pulse[k] < level)
                .unwrap_or(pulse.len());
            (1.5 * end as f64 * dt).min((last - f_i.max(f_r).max(f_t)) * dt)
        }
    };
    let samples = (duration_s / dt * (1.0 + 1e-12)).floor() as usize + 1;
    if samples < 8 || f_i < 0.0 || f_i.max(f_r).max(f_t) + (samples - 1) as f64 > last + 1e-6 {
        return Err(input_err(
            file,
            "time_s",
            format!(
                "the record ({:.1} µs to {:.1} µs) does not hold the separated waves' windows: \
                 from {:.1} µs at the faces, {:.1} µs long, and the last {:.1} µs of the \
                 record are lost to the gauges' distances",
                t0 * 1e6,
                input.time_s[n - 1] * 1e6,
                (t0 + f_i * dt) * 1e6,
                duration_s.max(0.0) * 1e6,
                ((n - 1) as f64 - last) * dt * 1e6
            ),
            "a record long enough for the windows (at least 8 samples), or a shorter --duration",
        ));
    }
    let cut = |x: &[f64], start: f64| super::correction::cut(x, dt, start, samples, None);
    let e_in = cut(&inc.toward, f_i);
    let e_re = cut(&inc.away, f_r);
    let e_tr = cut(&tra.away, f_t);
    let e_ret = cut(&tra.toward, f_t);
    let faces = super::waves::faces_with_return(&e_in, &e_re, &e_tr, Some(&e_ret), dt, bi, bt);
    let placed = super::windows::Placed {
        windows: super::Windows {
            incident_start_s,
            reflected_delay_s,
            transmitted_delay_s,
            duration_s: (samples - 1) as f64 * dt,
            samples,
            baseline_samples: strains.baseline_samples,
        },
        starts: (
            s_i,
            s_i + reflected_delay_s / dt,
            s_i + transmitted_delay_s / dt,
        ),
        alignment: super::AlignmentReport {
            strategy: super::Alignment::Geometric,
            geometric_reflected_delay_s: geometric_r,
            geometric_transmitted_delay_s: geometric_t,
            measured_reflected_delay_s: None,
            measured_transmitted_delay_s: None,
            balance_shift_s: None,
            balance_paths_m: None,
            balance_bound_s: options.balance_bound_s,
            at_bound: false,
        },
    };
    Ok((
        placed,
        super::waves::FaceWaves {
            incident: e_in,
            reflected: e_re,
            transmitted: e_tr,
            faces,
        },
        Separation {
            returned_strain: e_ret,
            ..report
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth compressive pulse of duration `width_s` starting at `t0_s`.
    fn pulse(t: f64, t0_s: f64, width_s: f64, amplitude: f64) -> f64 {
        let x = (t - t0_s) / width_s;
        if (0.0..=1.0).contains(&x) {
            amplitude * (std::f64::consts::PI * x).sin().powi(2)
        } else {
            0.0
        }
    }

    fn rms(a: &[f64], b: &[f64]) -> f64 {
        let n = a.len() as f64;
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / n).sqrt()
    }

    fn peak(a: &[f64]) -> f64 {
        a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
    }

    /// Non-dispersive bar, overlapping pulses (a 150 µs incident pulse, its reflection 2 s/c0 =
    /// 103 µs later at the gauge, and a second, later reflection), exact on samples: every
    /// delay is a whole number of samples, so the two-gauge series recovers the face waves to
    /// rounding (1e-12 of their peak), singular frequencies and all.
    #[test]
    fn two_gauges_recover_overlapping_waves_on_a_non_dispersive_bar() {
        let c0 = 5000.0;
        let dt = 1e-7;
        let (s1, s2) = (0.25, 0.40); // 500 and 800 samples of travel
        let n = 6000;
        let inc = |t: f64| pulse(t, 100e-6, 150e-6, -1e-3);
        let refl = |t: f64| pulse(t, 100e-6, 120e-6, 6e-4) + pulse(t, 260e-6, 80e-6, -2e-4);
        // Face waves: incident I(t) at the face, reflected R(t) leaving it.
        let strain_at = |s: f64, t: f64| inc(t + s / c0) + refl(t - s / c0);
        let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let e1: Vec<f64> = time.iter().map(|&t| strain_at(s1, t)).collect();
        let e2: Vec<f64> = time.iter().map(|&t| strain_at(s2, t)).collect();
        // The pulses do overlap at the near gauge.
        assert!(
            e1.iter()
                .zip(&time)
                .any(|(_, &t)| inc(t + s1 / c0).abs() > 1e-4 && refl(t - s1 / c0).abs() > 1e-4)
        );
        let prop = Propagation {
            c0_m_s: c0,
            exact: None,
        };
        let w = two_gauge(&e1, &e2, s1, s2, dt, &prop);
        let want_i: Vec<f64> = time.iter().map(|&t| inc(t)).collect();
        let want_r: Vec<f64> = time.iter().map(|&t| refl(t)).collect();
        // The advance of the away wave by s1/c0 reads the padding over the last 500 samples.
        let k = n - 600;
        let (ei, er) = (
            rms(&w.toward[..k], &want_i[..k]),
            rms(&w.away[..k], &want_r[..k]),
        );
        assert!(ei < 1e-12 * peak(&want_i), "incident {ei}");
        assert!(er < 1e-12 * peak(&want_r), "reflected {er}");
    }

    /// The same with the exact first mode: the synthetic strains are made by moving the face
    /// waves along the mode (an independent path, `dispersion_shift_exact`, docs/physics.md
    /// §7.9, whose FFT closes each 800 µs signal periodically by its own bridge), and the
    /// separation gives them back within 1e-4 of their peak RMS (measured 3e-5: the two FFT
    /// paths' different lengths and closures are the limit), a hundredth of the 1 % the
    /// simulated test is held to.
    #[test]
    fn two_gauges_recover_overlapping_waves_along_the_exact_mode() {
        let bar = super::super::authors_bar();
        let c0 = bar.wave_speed_m_s;
        let dt = 1e-7;
        let (s1, s2) = (0.25, 0.40);
        let n = 8000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let inc: Vec<f64> = time
            .iter()
            .map(|&t| pulse(t, 150e-6, 150e-6, -1e-3))
            .collect();
        let refl: Vec<f64> = time
            .iter()
            .map(|&t| pulse(t, 150e-6, 120e-6, 6e-4))
            .collect();
        // At distance s: the incident wave before it reached the face (moved back by s along
        // the mode, −s), the reflected after (forward by s), each with its plain transit s/c0.
        let at = |s: f64| -> Vec<f64> {
            let i = super::super::dispersion_shift_exact(&inc, dt, -s, &bar).unwrap();
            let r = super::super::dispersion_shift_exact(&refl, dt, s, &bar).unwrap();
            let k = (s / c0 / dt).round() as usize;
            assert!((k as f64 * dt * c0 - s).abs() < 1e-9, "whole samples");
            (0..n)
                .map(|j| {
                    let a = if j + k < n { i[j + k] } else { 0.0 };
                    let b = if j >= k { r[j - k] } else { 0.0 };
                    a + b
                })
                .collect()
        };
        // Gauge distances on whole samples of c0 dt.
        let s1 = (s1 / (c0 * dt)).round() * c0 * dt;
        let s2 = (s2 / (c0 * dt)).round() * c0 * dt;
        let (e1, e2) = (at(s1), at(s2));
        let pc = PochhammerChree::new(bar.poisson_ratio, bar.radius_m, c0).unwrap();
        let prop = Propagation {
            c0_m_s: c0,
            exact: Some(&pc),
        };
        let w = two_gauge(&e1, &e2, s1, s2, dt, &prop);
        let k = n - 1200;
        let (ei, er) = (
            rms(&w.toward[..k], &inc[..k]),
            rms(&w.away[..k], &refl[..k]),
        );
        assert!(ei < 1e-4 * peak(&inc), "incident {ei}");
        assert!(er < 1e-4 * peak(&refl), "reflected {er}");
    }

    /// One gauge on a transmission bar with a free far end: the transmitted pulse and its
    /// echo (inverted, 2 a/c0 later) overlap at the gauge; unrolled by the round trip they
    /// come back to rounding. On the incident bar, a pulse over before its reflection arrives
    /// (2 s/c0) and a reflection overlapping the impact end's echo of itself.
    #[test]
    fn one_gauge_unrolls_the_far_end_echoes() {
        let c0 = 5000.0;
        let dt = 1e-7;
        let (s, a) = (0.25, 0.30); // gauge 500 samples from the face, far end 600 beyond
        let n = 8000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let prop = Propagation {
            c0_m_s: c0,
            exact: None,
        };
        // Transmission bar: away wave T at the face, toward wave B = −T delayed 2(s + a)/c0.
        let tr = |t: f64| pulse(t, 100e-6, 180e-6, -5e-4);
        let back = |t: f64| -tr(t - 2.0 * (s + a) / c0);
        let e: Vec<f64> = time
            .iter()
            .map(|&t| tr(t - s / c0) + back(t + s / c0))
            .collect();
        let w = one_gauge_transmission(&e, s, a, -1.0, dt, &prop);
        let k = n - 600;
        let want_t: Vec<f64> = time.iter().map(|&t| tr(t)).collect();
        let want_b: Vec<f64> = time.iter().map(|&t| back(t)).collect();
        assert!(rms(&w.away[..k], &want_t[..k]) < 1e-12 * peak(&want_t));
        assert!(rms(&w.toward[..k], &want_b[..k]) < 1e-12 * peak(&want_t));
        // An absorbing far end: no echo, the gauge's record is the transmitted wave.
        let e: Vec<f64> = time.iter().map(|&t| tr(t - s / c0)).collect();
        let w = one_gauge_transmission(&e, s, a, 0.0, dt, &prop);
        assert!(rms(&w.away[..k], &want_t[..k]) < 1e-12 * peak(&want_t));
        assert!(peak(&w.toward[..k]) < 1e-12 * peak(&want_t));

        // Incident bar: incident 90 µs (over before 2 s/c0 = 100 µs), reflection 150 µs long
        // overlapping its own echo from the impact end (2 a/c0 = 120 µs).
        let inc = |t: f64| pulse(t, 100e-6, 90e-6, -1e-3);
        let refl = |t: f64| pulse(t, 100e-6, 150e-6, 5e-4);
        // Toward wave at the face: incident plus the reflection's echo (−R, 2(s + a)/c0 later).
        let toward = |t: f64| inc(t) - refl(t - 2.0 * (s + a) / c0);
        let e: Vec<f64> = time
            .iter()
            .map(|&t| toward(t + s / c0) + refl(t - s / c0))
            .collect();
        let foot = ((100e-6 - s / c0) / dt).round() as usize;
        let w = one_gauge_incident(&e, foot + (2.0 * s / c0 / dt) as usize, s, a, dt, &prop);
        let want_i: Vec<f64> = time.iter().map(|&t| toward(t)).collect();
        let want_r: Vec<f64> = time.iter().map(|&t| refl(t)).collect();
        assert!(rms(&w.toward[..k], &want_i[..k]) < 1e-12 * peak(&want_i));
        assert!(rms(&w.away[..k], &want_r[..k]) < 1e-12 * peak(&want_r));
    }

    /// The truncated series is the sum it stands for, at and away from its singular points, and
    /// off the unit circle (an absorbing end's z = 0 sums to 1).
    #[test]
    fn truncated_series_sums_its_terms() {
        assert_eq!(
            truncated_series(Complex::new(0.0, 0.0), 17),
            Complex::new(1.0, 0.0)
        );
        let z = Complex::from_polar(0.5, 0.7);
        let direct: Complex<f64> = (0..17).map(|k| z.powu(k)).sum();
        assert!((truncated_series(z, 17) - direct).norm() < 1e-12);
        for theta in [
            0.0,
            1e-9,
            0.3,
            std::f64::consts::PI,
            2.0 * std::f64::consts::PI,
            4.0,
        ] {
            let z = Complex::from_polar(1.0, -theta);
            let direct: Complex<f64> = (0..17).map(|k| z.powu(k)).sum();
            let got = truncated_series(z, 17);
            assert!(
                (got - direct).norm() < 1e-9,
                "θ = {theta}: {got} vs {direct}"
            );
        }
    }
}

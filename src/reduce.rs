//! The laboratory's data reduction (physics.md §7; shared/reference/README.md, "Reduction"):
//! from the strains recorded at the incident and transmission gauges to the forces on the two
//! specimen faces, the sphere approach δ(t), its rate and the global strain rate. It works on
//! simulated records (`shpb run` HDF5) and on real ones (the authors' raw CSV).
//!
//! # Sign conventions
//!
//! Bar strain ε is positive in tension (physics.md). The incident bar lies at x < 0 with its
//! specimen face at x = 0⁻, the transmission bar at x > 0; displacements u and velocities v are
//! positive along +x (from the incident towards the transmission bar). For a wave running towards
//! +x, v = −c0 ε; towards −x, v = +c0 ε. Hence, with εI, εR, εT the incident, reflected and
//! transmitted strains *at the specimen faces*:
//!
//! * `v_front = −c0 (εI − εR)`, `u_front = ∫ v_front dt` (incident-bar face, positive when it
//!   moves towards the specimen);
//! * `v_back = −c0 εT`, `u_back = ∫ v_back dt` (transmission-bar face, positive when it is pushed
//!   away);
//! * sphere approach `δ = u_front − u_back = −c0 ∫ (εI − εR − εT) dt`, positive in compression
//!   (physics.md §7 writes the same with the bar-axis signs left to the reader), and
//!   `δ̇ = v_front − v_back`;
//! * contact forces, positive in compression: `F_front = −E A (εI + εR)` (2-wave),
//!   `F_back = −E A εT` (1-wave), `F_3wave = (F_front + F_back)/2`;
//! * equilibrium ratio `|F_front − F_back| / max(|F_3wave|, 0.05·max|F_3wave|)` (the floor keeps
//!   it finite before loading and after unloading), reported as a series and at the peak of
//!   `F_back`;
//! * global strain rate `δ̇/(r1 + r2)` (paper Eq. 3) when the sphere radii are given.
//!
//! Displacements are integrated with the trapezoidal rule from the first sample of the window
//! (δ(0) = 0).
//!
//! # Windows (how each wave is cut from the records)
//!
//! 1. Baseline: the mean of the first `baseline_samples` samples of each channel is subtracted
//!    (the authors use the pre-trigger part; if the incident pulse starts earlier than that, the
//!    baseline is re-taken over the samples before the pulse start).
//! 2. Incident start `t_I` (at the incident gauge, record clock): with `y = −εI` (compression),
//!    `y_max` its largest value in the record, the first pulse is the first run of samples with
//!    `y ≥ y_max/2`; its peak `y_p` is the largest `y` in that run; `t_I` is the time of the last
//!    sample before the peak with `y < start_fraction·y_p` (default 2 %). `t_I` is therefore on
//!    the sample grid, at the foot of the pulse. It can be overridden (`WindowOverride`).
//! 3. Reflected window at the incident gauge: starts at `t_I + Δ_R`, `Δ_R = 2 d_I/c0`.
//!    Transmitted window at the transmission gauge: starts at `t_I + Δ_T`,
//!    `Δ_T = d_I/c0 + d_T/c0 + specimen_transit_s`; the transit through the specimen (two
//!    6.35 mm spheres, ≈ 2.5 µs at the spheres' bar-wave speed, but really set by the contact
//!    compliance) is neglected by default (0). Both delays can be overridden. Fractional-sample
//!    delays are applied exactly for band-limited signals (Fourier phase shift), not rounded.
//! 4. Window length `D`: the longest clean window, `min(Δ_R` (the incident gauge sees only the
//!    incident wave until the reflected one arrives), `2 (L_I − d_I)/c0` (the reflected wave
//!    comes back from the impact end after that), `2 (L_T − d_T)/c0` if the transmission bar's
//!    far end is not absorbing`)`, then shortened so that both the reflected and the transmitted
//!    windows lie inside the record. It can be overridden.
//! 5. Time axis: `t = 0` is the arrival of the incident pulse's foot at the specimen face,
//!    `t_I + d_I/c0` on the record clock (`Reduction::face_time_offset_s`); the three waves,
//!    time-shifted to the faces, share it.
//!
//! # Dispersion correction
//!
//! Optional (on by default), as in the authors' `disp_corr.m`: every Fourier component of a
//! wave is shifted in time by `τ(f) = Δx (1/c(f) − 1/c0)` (a spectrum factor `exp(−iωτ)`, i.e. a
//! *delay* for τ > 0), where `c(f)` is the first-mode phase velocity of the Bancroft fit of
//! physics.md §7, `c/c0 = A + B/(C y⁴ + D y³ + E y² + F y^1.5 + 1)`, `y = a/Λ`, solved for the
//! wavelength `Λ = c/f` at each frequency (a scalar monotone equation, bisection). The plain
//! transit `Δx/c0` is the window offset of step 3; the correction adds only what dispersion
//! changes. Signs: the incident wave is moved *forward* to the face (`Δx = +d_I`: its slow,
//! high-frequency components arrive later at the face than at the gauge, so they are delayed);
//! the reflected and transmitted waves are moved *back* from their gauges to the faces
//! (`Δx = −d_I`, `−d_T`: their slow components left the face earlier than they reached the gauge,
//! so they are advanced). The fit is the ν = 0.31 one the authors used; a warning is given for
//! bars with another Poisson's ratio. As f → 0 the fit gives c → (A + B) c0 = 1.0013 c0, so the
//! longest waves are shifted by −0.13 % of the transit (−0.18 µs over 0.64 m), as in the
//! authors' code.

use crate::apparatus::Apparatus;
use crate::error::{Error, Result};
use crate::gauge::{GaugeChannel, RawRecord};
use crate::io::{h5err, string_attr};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;
use std::io::Write;
use std::path::Path;

/// Bancroft first-mode fit for ν = 0.31 (physics.md §7): A, B, C, D, E, F of
/// `c/c0 = A + B/(C y⁴ + D y³ + E y² + F y^1.5 + 1)`, `y = a/Λ`.
pub const BANCROFT_FIT: [f64; 6] = [0.57344, 0.42790, 18.668, 19.664, -6.6213, 2.3118];

/// Poisson's ratio the Bancroft fit was made for.
pub const BANCROFT_FIT_POISSON_RATIO: f64 = 0.31;

/// Radii of the paper's specimen, two 6.35 mm spheres, m (used by `shpb reduce` for the strain
/// rate; the authors' `analysis.m` divides by 0.0254/4 m = r1 + r2 too).
pub const PAPER_SPHERE_RADII_M: (f64, f64) = (3.175e-3, 3.175e-3);

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
    let mut lo = BANCROFT_FIT[0] * c0_m_s * (1.0 - 1e-9);
    let mut hi = (BANCROFT_FIT[0] + BANCROFT_FIT[1]) * c0_m_s * (1.0 + 1e-9);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if h(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
        if hi - lo <= 1e-13 * c0_m_s {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Extra travel time of the component at `frequency_hz` over `distance_m` beyond `distance/c0`,
/// `Δx (1/c(f) − 1/c0)`, s (negative distance: moved back against the propagation).
pub fn dispersion_delay_s(frequency_hz: f64, distance_m: f64, radius_m: f64, c0_m_s: f64) -> f64 {
    let c = bancroft_phase_velocity_m_s(frequency_hz, radius_m, c0_m_s);
    distance_m * (1.0 / c - 1.0 / c0_m_s)
}

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
    /// Bars and gauge distances of a set-up file (its `incident` and `transmission` channels).
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
        Ok(ReductionSetup {
            incident_bar: bar(&a.incident),
            transmission_bar: bar(&a.transmission),
            incident_gauge_m: channel(a, "incident")?.distance_from_specimen_m,
            transmission_gauge_m: channel(a, "transmission")?.distance_from_specimen_m,
            transmission_absorbing: a.transmission_absorbing,
        })
    }
}

/// The gauge channel called `name` of a set-up, or an input error naming the set-up file.
fn channel<'a>(a: &'a Apparatus, name: &str) -> Result<&'a GaugeChannel> {
    a.gauges.channel(name).ok_or_else(|| Error::Input {
        file: a.source.clone(),
        key: "gauges".into(),
        problem: format!("no `{name}` channel in the gauge set-up"),
        allowed: "channels named incident and transmission".into(),
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
    /// The noise-free gauge strains of a simulated test (`/gauges/{incident,transmission}/strain`
    /// of `shpb run`), if it recorded both channels.
    pub fn from_noise_free_gauges(out: &crate::io::RunOutput) -> Option<ReductionInput> {
        let strain = |name: &str| {
            out.gauges
                .iter()
                .find(|g| g.name == name)
                .map(|g| g.strain.clone())
        };
        Some(ReductionInput {
            time_s: out.time_s.clone()?,
            incident_strain: strain("incident")?,
            transmission_strain: strain("transmission")?,
        })
    }
}

/// Manual window settings; each `None` keeps the automatic rule (module docs, "Windows").
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

/// Options of a reduction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReductionOptions {
    /// Samples at the start of each record whose mean is the baseline (default 900: 90 µs at
    /// 10 MHz, the pre-trigger part of the authors' records).
    pub baseline_samples: usize,
    /// Correct the waves for Bancroft dispersion between gauges and faces (default true).
    pub dispersion_correction: bool,
    /// Manual windows (default None: the automatic rule).
    pub window: Option<WindowOverride>,
    /// Fraction of the incident peak that marks its foot (default 0.02).
    pub start_fraction: f64,
    /// Transit time through the specimen added to the transmitted delay, s (default 0).
    pub specimen_transit_s: f64,
    /// Sphere radii (r1, r2), m, for the global strain rate δ̇/(r1 + r2) (default None).
    pub specimen_radii_m: Option<(f64, f64)>,
    /// Width of a centred moving average applied to both strain records before the reduction,
    /// s (default 0: off). A box of width w attenuates noise by √(w/Δt) and changes a pulse of
    /// rise time τ by about w²/(24 τ²) of its peak.
    pub smoothing_window_s: f64,
}

impl Default for ReductionOptions {
    fn default() -> Self {
        ReductionOptions {
            baseline_samples: 900,
            dispersion_correction: true,
            window: None,
            start_fraction: 0.02,
            specimen_transit_s: 0.0,
            specimen_radii_m: None,
            smoothing_window_s: 0.0,
        }
    }
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
    /// Whether the dispersion correction was applied.
    pub dispersion_corrected: bool,
    /// Things the user should know (Poisson's ratio off the fit, reflected delay off nominal, …).
    pub warnings: Vec<String>,
}

/// An input error of the reduction (`file` names the record or "reduction options").
fn input_err(
    file: &str,
    key: &str,
    problem: impl Into<String>,
    allowed: impl Into<String>,
) -> Error {
    Error::Input {
        file: file.to_string(),
        key: key.to_string(),
        problem: problem.into(),
        allowed: allowed.into(),
    }
}

/// Centred moving average over 2 `half` + 1 samples (fewer at the ends); `half` = 0 copies.
fn moving_average(v: &[f64], half: usize) -> Vec<f64> {
    if half == 0 {
        return v.to_vec();
    }
    let mut prefix = Vec::with_capacity(v.len() + 1);
    prefix.push(0.0);
    for x in v {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + x);
    }
    (0..v.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(v.len()));
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

/// The incident pulse a measured specimen history implies (what the incident gauge saw, moved to
/// the specimen face), from force F(t) and sphere approach δ(t) alone: see [`implied_incident`].
#[derive(Debug, Clone, PartialEq)]
pub struct ImpliedIncident {
    /// Incident stress at the face at the history's sample times, compression positive, Pa.
    pub stress_pa: Vec<f64>,
    /// Largest incident stress, Pa.
    pub peak_pa: f64,
    /// Time of the largest incident stress, s.
    pub peak_time_s: f64,
    /// Full width of the pulse at half its peak, s (for an unshaped pulse: 2 L_striker / c0).
    pub duration_half_s: f64,
    /// Mean stress over that width, Pa (the plateau of an unshaped pulse, which its peak is not:
    /// the spheres' inertia adds a spike at the start).
    pub mean_over_half_pa: f64,
    /// Impulse A ∫σ dt over the pulse (above 5 % of peak), N s: a stopped striker's momentum.
    pub impulse_n_s: f64,
    /// Energy the pulse carries, A c0 / E ∫σ² dt over the pulse (above 5 % of peak), J.
    pub energy_j: f64,
}

/// Incident stress at the specimen face implied by force F and approach δ (physics.md §7 run
/// backwards): with the front force equal to the back force F (equilibrium), the transmission
/// face moving at F/(ρ c0 A) and the incident face at that plus δ̇, the one-wave relations
/// F = A(σI + σR), v = (σI − σR)/(ρ c0) give σI = F/A + ρ c0 δ̇ / 2. δ̇ is a central difference over
/// `smoothing_s` and F is averaged over the same span (the records are noisy). None if the
/// history has fewer than 3 samples or no compressive pulse.
pub fn implied_incident(
    time_s: &[f64],
    displacement_m: &[f64],
    force_n: &[f64],
    bar: &BarProperties,
    smoothing_s: f64,
) -> Option<ImpliedIncident> {
    let n = time_s.len();
    if n < 3 || displacement_m.len() != n || force_n.len() != n {
        return None;
    }
    let dt = (time_s[n - 1] - time_s[0]) / (n - 1) as f64;
    let half = ((smoothing_s / (2.0 * dt)).round() as usize).max(1);
    let rho_c = bar.youngs_modulus_pa / bar.wave_speed_m_s;
    let force = moving_average(force_n, half);
    let stress_pa: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half).min(n - 1));
            let rate = (displacement_m[b] - displacement_m[a]) / (time_s[b] - time_s[a]);
            force[i] / bar.area_m2 + 0.5 * rho_c * rate
        })
        .collect();
    let (k, &peak_pa) = stress_pa
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if peak_pa <= 0.0 {
        return None;
    }
    let half_peak = index_interval_above(&stress_pa, k, 0.5 * peak_pa);
    let (h0, h1) = crossing_times(time_s, &stress_pa, half_peak, 0.5 * peak_pa);
    let (lo, hi) = index_interval_above(&stress_pa, k, 0.05 * peak_pa);
    let integral = |f: &dyn Fn(f64) -> f64| -> f64 {
        (lo..hi)
            .map(|i| 0.5 * (f(stress_pa[i]) + f(stress_pa[i + 1])) * (time_s[i + 1] - time_s[i]))
            .sum()
    };
    let impulse_n_s = bar.area_m2 * integral(&|s| s);
    let (m0, m1) = half_peak;
    let mean_over_half_pa = stress_pa[m0..=m1].iter().sum::<f64>() / (m1 - m0 + 1) as f64;
    let energy_j = bar.area_m2 / rho_c * integral(&|s| s * s);
    Some(ImpliedIncident {
        peak_time_s: time_s[k],
        duration_half_s: h1 - h0,
        mean_over_half_pa,
        impulse_n_s,
        energy_j,
        peak_pa,
        stress_pa,
    })
}

/// Sample indices (first, last) of the contiguous run around `k` where `y` ≥ `level`.
fn index_interval_above(y: &[f64], k: usize, level: f64) -> (usize, usize) {
    let lo = (0..k).rev().find(|&i| y[i] < level).map_or(0, |i| i + 1);
    let hi = (k + 1..y.len())
        .find(|&j| y[j] < level)
        .map_or(y.len() - 1, |j| j - 1);
    (lo, hi)
}

/// Times where `y` crosses `level` just outside the run of samples `(lo, hi)` at or above it
/// (linear between samples; the record's ends if it never drops below).
fn crossing_times(t: &[f64], y: &[f64], (lo, hi): (usize, usize), level: f64) -> (f64, f64) {
    let cross = |i: usize| t[i] + (level - y[i]) * (t[i + 1] - t[i]) / (y[i + 1] - y[i]);
    let start = if lo > 0 { cross(lo - 1) } else { t[0] };
    let end = if hi + 1 < y.len() {
        cross(hi)
    } else {
        t[y.len() - 1]
    };
    (start, end)
}

/// Subtracts the mean of the first `n` samples (none if `n` is 0).
fn debias(v: &[f64], n: usize) -> Vec<f64> {
    crate::gauge::remove_baseline(v, n)
}

/// Index of the foot of the first pulse of `y` (positive pulse) and its peak index, by the rule
/// of the module docs; None if `y` has no positive value.
fn pulse_foot(y: &[f64], fraction: f64) -> Option<(usize, usize)> {
    let y_max = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if y_max.is_nan() || y_max <= 0.0 {
        return None;
    }
    let half = 0.5 * y_max;
    let k_half = y.iter().position(|&v| v >= half)?;
    let k_end = (k_half..y.len()).find(|&k| y[k] < half).unwrap_or(y.len());
    let mut k_peak = k_half;
    for k in k_half..k_end {
        if y[k] > y[k_peak] {
            k_peak = k;
        }
    }
    let level = fraction * y[k_peak];
    let foot = (0..=k_peak).rev().find(|&k| y[k] < level).unwrap_or(0);
    Some((foot, k_peak))
}

/// Cuts `n` samples starting at fractional index `start` out of `x` (uniform step `dt`), after
/// delaying every Fourier component by `dispersion_delay_s(f, distance)` when `dispersion` is
/// given as (distance, radius, c0). Exact copy when the start is on a sample and there is no
/// dispersion; otherwise a Fourier phase shift (see `phase_shift`) of the window extended by
/// margins on both sides that cover the largest dispersion delay, so that what the shift moves
/// into the window comes from the record, not from the wrap-around. Samples outside the record
/// read as 0 (the caller keeps the window itself inside the record).
fn cut(x: &[f64], dt: f64, start: f64, n: usize, dispersion: Option<(f64, f64, f64)>) -> Vec<f64> {
    let i = start.floor();
    let mut frac = start - i;
    let mut i = i as isize;
    if frac > 1.0 - 1e-9 {
        i += 1;
        frac = 0.0;
    } else if frac < 1e-9 {
        frac = 0.0;
    }
    if frac == 0.0 && dispersion.is_none() {
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
    // Margin: the largest dispersion delay (slowest components travel at A·c0) plus slack.
    let max_delay = dispersion
        .map(|(d, _, c0)| d.abs() / c0 * (1.0 / BANCROFT_FIT[0] - 1.0))
        .unwrap_or(0.0);
    let margin = (max_delay / dt).ceil() as isize + 64;
    let lo = (i - margin).max(0);
    let hi = (i + n as isize + margin).min(x.len() as isize);
    let seg = &x[lo as usize..hi as usize];
    let shifted = phase_shift(seg, dt, |f| {
        // Advance by `frac` samples (y(t) = x(t + frac·dt)), then the dispersion delay.
        let disp = dispersion
            .map(|(d, a, c0)| dispersion_delay_s(f, d, a, c0))
            .unwrap_or(0.0);
        disp - frac * dt
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

/// Delays every Fourier component of `x` (step `dt`) at frequency f by `delay(f)` seconds
/// (spectrum factor exp(−2πi f delay(|f|))). The segment is closed into a smooth periodic signal
/// by a raised-cosine bridge from its last value back to its first over a padding at least as
/// long as the segment (power-of-two FFT length), so no jump is created at the wrap.
fn phase_shift(x: &[f64], dt: f64, delay: impl Fn(f64) -> f64) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let m = (2 * n).next_power_of_two().max(64);
    let (first, last) = (x[0], x[n - 1]);
    let pad = m - n;
    let mut buf: Vec<Complex<f64>> = Vec::with_capacity(m);
    buf.extend(x.iter().map(|&v| Complex::new(v, 0.0)));
    for k in 0..pad {
        let s = (k as f64 + 1.0) / (pad as f64 + 1.0);
        let w = 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
        buf.push(Complex::new(last + (first - last) * w, 0.0));
    }
    let mut planner = FftPlanner::<f64>::new();
    planner.plan_fft_forward(m).process(&mut buf);
    let df = 1.0 / (m as f64 * dt);
    for (k, z) in buf.iter_mut().enumerate() {
        let kk = if k <= m / 2 {
            k as f64
        } else {
            k as f64 - m as f64
        };
        let f = kk * df;
        let phase = -2.0 * std::f64::consts::PI * f * delay(f.abs());
        let factor = if 2 * k == m {
            // Nyquist bin: keep the signal real.
            Complex::new(phase.cos(), 0.0)
        } else {
            Complex::from_polar(1.0, phase)
        };
        *z *= factor;
    }
    planner.plan_fft_inverse(m).process(&mut buf);
    buf.iter().take(n).map(|z| z.re / m as f64).collect()
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
    cut(
        signal,
        dt_s,
        0.0,
        signal.len(),
        Some((distance_m, bar.radius_m, bar.wave_speed_m_s)),
    )
}

/// Cumulative trapezoidal integral with zero first value.
fn cumulative_trapezoid(v: &[f64], dt: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    let mut acc = 0.0;
    for (k, &x) in v.iter().enumerate() {
        if k > 0 {
            acc += 0.5 * dt * (x + v[k - 1]);
        }
        out.push(acc);
    }
    out
}

/// Checks the input series: equal lengths, enough samples, finite, uniform time axis; returns dt.
fn check_input(input: &ReductionInput, file: &str) -> Result<f64> {
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

fn check_options(o: &ReductionOptions) -> Result<()> {
    let file = "reduction options";
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
            format!("{} is out of range", o.specimen_transit_s),
            "0 or more seconds",
        ));
    }
    if !(o.smoothing_window_s.is_finite() && o.smoothing_window_s >= 0.0) {
        return Err(input_err(
            file,
            "smoothing_window_s",
            format!("{} is out of range", o.smoothing_window_s),
            "0 (off) or more seconds",
        ));
    }
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
                    format!("{v} s"),
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
                format!("{v}"),
                "a finite time on the record clock",
            ));
        }
    }
    Ok(())
}

/// Reduces two gauge strain histories to face forces, approach, its rate and the strain rate
/// (module docs give every rule and sign). Errors name `"reduction input"`/`"reduction options"`
/// and the key at fault.
pub fn reduce(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
) -> Result<Reduction> {
    reduce_named(input, setup, options, "reduction input")
}

/// [`reduce`] with the record's name for error messages.
fn reduce_named(
    input: &ReductionInput,
    setup: &ReductionSetup,
    options: &ReductionOptions,
    file: &str,
) -> Result<Reduction> {
    check_options(options)?;
    let dt = check_input(input, file)?;
    let n = input.time_s.len();
    let t0 = input.time_s[0];
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let (d_i, d_t) = (setup.incident_gauge_m, setup.transmission_gauge_m);
    let ov = options.window.unwrap_or_default();
    let mut warnings = Vec::new();

    // 0. Optional smoothing (a centred moving average over an odd number of samples).
    let half = (options.smoothing_window_s / dt / 2.0).round() as usize;
    let incident_strain = moving_average(&input.incident_strain, half);
    let transmission_strain = moving_average(&input.transmission_strain, half);

    // 1–2. Baseline, then the incident foot; the baseline must end before the pulse.
    let mut nb = options.baseline_samples.min(n / 2);
    let mut eps_i = debias(&incident_strain, nb);
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
    let eps_t = debias(&transmission_strain, nb);
    let incident_start_s = match ov.incident_start_s {
        Some(s) => s,
        None => {
            let (k_foot, _) = detected.ok_or_else(|| {
                input_err(
                    file,
                    "incident_strain",
                    "no compressive (negative) incident pulse",
                    "an incident record with a compressive pulse",
                )
            })?;
            input.time_s[k_foot]
        }
    };
    let incident_peak = detected.map(|(_, k)| -eps_i[k]).unwrap_or(0.0);

    // 3. Delays.
    let c_i = bi.wave_speed_m_s;
    let c_t = bt.wave_speed_m_s;
    let nominal_r = 2.0 * d_i / c_i;
    let reflected_delay_s = ov.reflected_delay_s.unwrap_or(nominal_r);
    let transmitted_delay_s = ov
        .transmitted_delay_s
        .unwrap_or(d_i / c_i + d_t / c_t + options.specimen_transit_s);

    // 4. Window length.
    let record_end = input.time_s[n - 1];
    let duration_s = match ov.duration_s {
        Some(d) => d,
        None => {
            let mut d = reflected_delay_s;
            if let Some(l) = bi.length_m {
                d = d.min(2.0 * (l - d_i) / c_i);
            }
            if !setup.transmission_absorbing
                && let Some(l) = bt.length_m
            {
                d = d.min(2.0 * (l - d_t) / c_t);
            }
            d.min(record_end - (incident_start_s + reflected_delay_s))
                .min(record_end - (incident_start_s + transmitted_delay_s))
        }
    };
    let samples = (duration_s / dt * (1.0 + 1e-12)).floor() as usize + 1;
    let s_i = (incident_start_s - t0) / dt;
    let s_r = s_i + reflected_delay_s / dt;
    let s_t = s_i + transmitted_delay_s / dt;
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
            ),
            "a record long enough for the incident, reflected and transmitted windows (at least 8 samples each)",
        ));
    }

    // Reflected start measured in the record (a check of the gauge distance and c0).
    let measured_reflected_delay_s = {
        let from = (s_i + 0.5 * reflected_delay_s / dt).max(0.0) as usize;
        let to = ((s_r + samples as f64) as usize).min(n);
        if from + 2 < to {
            let y = &eps_i[from..to];
            pulse_foot(y, options.start_fraction)
                .filter(|&(_, kp)| y[kp] >= 0.1 * incident_peak && incident_peak > 0.0)
                .map(|(kf, _)| input.time_s[from + kf] - incident_start_s)
        } else {
            None
        }
    };
    if let Some(m) = measured_reflected_delay_s
        && (m - reflected_delay_s).abs() > 0.02 * reflected_delay_s
    {
        warnings.push(format!(
            "the reflected pulse starts {:.1} µs after the incident one in the record, the window \
             uses {:.1} µs (2 d_I/c0 = {:.1} µs): check the gauge distance and c0",
            m * 1e6,
            reflected_delay_s * 1e6,
            nominal_r * 1e6
        ));
    }
    if options.dispersion_correction {
        for (name, b) in [("incident", bi), ("transmission", bt)] {
            if (b.poisson_ratio - BANCROFT_FIT_POISSON_RATIO).abs() > 0.02 {
                warnings.push(format!(
                    "the {name} bar's Poisson's ratio {} differs from the Bancroft fit's 0.31",
                    b.poisson_ratio
                ));
            }
        }
    }

    // Waves at the faces.
    let disp = |d: f64, b: &BarProperties| {
        options
            .dispersion_correction
            .then_some((d, b.radius_m, b.wave_speed_m_s))
    };
    let e_in = cut(&eps_i, dt, s_i, samples, disp(d_i, bi));
    let e_re = cut(&eps_i, dt, s_r, samples, disp(-d_i, bi));
    let e_tr = cut(&eps_t, dt, s_t, samples, disp(-d_t, bt));

    // Quantities.
    let (ea_i, ea_t) = (
        bi.youngs_modulus_pa * bi.area_m2,
        bt.youngs_modulus_pa * bt.area_m2,
    );
    let force_front_n: Vec<f64> = (0..samples).map(|k| -ea_i * (e_in[k] + e_re[k])).collect();
    let force_back_n: Vec<f64> = e_tr.iter().map(|e| -ea_t * e).collect();
    let force_3wave_n: Vec<f64> = (0..samples)
        .map(|k| 0.5 * (force_front_n[k] + force_back_n[k]))
        .collect();
    let v_front: Vec<f64> = (0..samples).map(|k| -c_i * (e_in[k] - e_re[k])).collect();
    let v_back: Vec<f64> = e_tr.iter().map(|e| -c_t * e).collect();
    let front_displacement_m = cumulative_trapezoid(&v_front, dt);
    let back_displacement_m = cumulative_trapezoid(&v_back, dt);
    let displacement_m: Vec<f64> = (0..samples)
        .map(|k| front_displacement_m[k] - back_displacement_m[k])
        .collect();
    let approach_velocity_m_s: Vec<f64> = (0..samples).map(|k| v_front[k] - v_back[k]).collect();
    let strain_rate_per_s = options.specimen_radii_m.map(|(r1, r2)| {
        approach_velocity_m_s
            .iter()
            .map(|v| v / (r1 + r2))
            .collect()
    });
    let f3_max = force_3wave_n.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let floor = (0.05 * f3_max).max(f64::MIN_POSITIVE);
    let equilibrium_ratio: Vec<f64> = (0..samples)
        .map(|k| (force_front_n[k] - force_back_n[k]).abs() / force_3wave_n[k].abs().max(floor))
        .collect();
    let peak_index = (0..samples)
        .max_by(|&a, &b| force_back_n[a].total_cmp(&force_back_n[b]))
        .unwrap_or(0);
    let time_s: Vec<f64> = (0..samples).map(|k| k as f64 * dt).collect();
    Ok(Reduction {
        face_time_offset_s: incident_start_s + d_i / c_i,
        peak_back_force_n: force_back_n[peak_index],
        peak_back_force_time_s: time_s[peak_index],
        peak_index,
        displacement_at_peak_force_m: displacement_m[peak_index],
        equilibrium_ratio_at_peak: equilibrium_ratio[peak_index],
        peak_front_force_n: force_front_n
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        max_displacement_m: displacement_m
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        windows: Windows {
            incident_start_s,
            reflected_delay_s,
            transmitted_delay_s,
            duration_s: (samples - 1) as f64 * dt,
            samples,
            baseline_samples: nb,
        },
        measured_reflected_delay_s,
        dispersion_corrected: options.dispersion_correction,
        warnings,
        time_s,
        incident_strain: e_in,
        reflected_strain: e_re,
        transmitted_strain: e_tr,
        force_front_n,
        force_back_n,
        force_3wave_n,
        front_displacement_m,
        back_displacement_m,
        displacement_m,
        approach_velocity_m_s,
        strain_rate_per_s,
        equilibrium_ratio,
    })
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
    Ok(ReductionInput {
        time_s: record.time_s.clone(),
        incident_strain: inc.strains_from_voltages(&debias(&record.incident_v, n)),
        transmission_strain: tra.strains_from_voltages(&debias(&record.transmission_v, n)),
    })
}

/// Reduces a raw gauge record in the authors' CSV format (`time_s,incident_V,transmission_V`)
/// with the bars and gauge channels of `apparatus`.
pub fn reduce_record_file(
    record: &Path,
    apparatus: &Apparatus,
    options: &ReductionOptions,
) -> Result<Reduction> {
    let rec = RawRecord::read(record)?;
    let input = record_strains(&rec, apparatus, options.baseline_samples)?;
    reduce_named(
        &input,
        &ReductionSetup::from_apparatus(apparatus)?,
        options,
        &record.display().to_string(),
    )
}

/// Reads `/time` and `/gauges/{incident,transmission}/strain` of an HDF5 file written by
/// `shpb run`.
pub fn read_hdf5_strains(path: &Path) -> Result<ReductionInput> {
    let f = hdf5::File::open(path).map_err(h5err(path))?;
    let read = |name: &str| -> Result<Vec<f64>> {
        let ds = f.dataset(name).map_err(|e| {
            input_err(
                &path.display().to_string(),
                name,
                format!("cannot read it ({e})"),
                "an HDF5 file written by `shpb run` of a bar scene (/time, /gauges/incident/strain, /gauges/transmission/strain)",
            )
        })?;
        ds.read_raw::<f64>().map_err(h5err(path))
    };
    Ok(ReductionInput {
        time_s: read("time")?,
        incident_strain: read("gauges/incident/strain")?,
        transmission_strain: read("gauges/transmission/strain")?,
    })
}

/// Whether `path` starts with the HDF5 signature.
fn is_hdf5(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut sig = [0u8; 8];
    let n = f.read(&mut sig).map_err(|e| Error::io(path, e))?;
    Ok(n == 8 && sig == *b"\x89HDF\r\n\x1a\n")
}

/// The `/reduction` datasets: (name, data, units, CSV column).
pub fn reduction_columns(r: &Reduction) -> Vec<(&'static str, &[f64], &'static str, &'static str)> {
    let mut cols = vec![
        ("time", r.time_s.as_slice(), "s", "time_s"),
        (
            "displacement",
            r.displacement_m.as_slice(),
            "m",
            "displacement_m",
        ),
        (
            "force_front",
            r.force_front_n.as_slice(),
            "N",
            "force_front_N",
        ),
        ("force_back", r.force_back_n.as_slice(), "N", "force_back_N"),
        (
            "force_3wave",
            r.force_3wave_n.as_slice(),
            "N",
            "force_3wave_N",
        ),
        (
            "approach_velocity",
            r.approach_velocity_m_s.as_slice(),
            "m/s",
            "approach_velocity_m_s",
        ),
    ];
    if let Some(s) = &r.strain_rate_per_s {
        cols.push(("strain_rate", s.as_slice(), "1/s", "strain_rate_per_s"));
    }
    cols.push((
        "equilibrium_ratio",
        r.equilibrium_ratio.as_slice(),
        "1",
        "equilibrium_ratio",
    ));
    cols
}

/// Scalar results: (key, value, unit).
fn summary_items(r: &Reduction) -> Vec<(&'static str, f64, &'static str)> {
    let mut v = vec![
        ("peak_back_force", r.peak_back_force_n, "N"),
        ("peak_back_force_time", r.peak_back_force_time_s, "s"),
        (
            "displacement_at_peak_force",
            r.displacement_at_peak_force_m,
            "m",
        ),
        (
            "equilibrium_ratio_at_peak",
            r.equilibrium_ratio_at_peak,
            "1",
        ),
        ("peak_front_force", r.peak_front_force_n, "N"),
        ("max_displacement", r.max_displacement_m, "m"),
        ("face_time_offset", r.face_time_offset_s, "s"),
        ("incident_start", r.windows.incident_start_s, "s"),
        ("reflected_delay", r.windows.reflected_delay_s, "s"),
        ("transmitted_delay", r.windows.transmitted_delay_s, "s"),
        ("window_duration", r.windows.duration_s, "s"),
        (
            "dispersion_corrected",
            if r.dispersion_corrected { 1.0 } else { 0.0 },
            "1",
        ),
    ];
    if let Some(m) = r.measured_reflected_delay_s {
        v.push(("measured_reflected_delay", m, "s"));
    }
    v
}

/// Writes a reduction to HDF5 atomically: root attributes `shpb_version` and `scene` (the
/// command line), `/reduction/<series>` with `units` attributes, `/summary` scalar attributes
/// with a `units` list.
pub fn write_reduction_hdf5(path: &Path, force: bool, scene: &str, r: &Reduction) -> Result<()> {
    crate::io::write_atomically(path, force, |tmp| {
        let f = hdf5::File::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        string_attr(&f, "scene", scene, path)?;
        let g = f.create_group("reduction").map_err(h5err(path))?;
        for (name, data, units, _) in reduction_columns(r) {
            crate::io::write_dataset(&g, name, data, units, path)?;
        }
        let s = f.create_group("summary").map_err(h5err(path))?;
        let items = summary_items(r);
        for (key, value, _) in &items {
            s.new_attr::<f64>()
                .shape(())
                .create(*key)
                .and_then(|a| a.write_scalar(value))
                .map_err(h5err(path))?;
        }
        let units = items
            .iter()
            .map(|(k, _, u)| format!("{k}={u}"))
            .collect::<Vec<_>>()
            .join(", ");
        string_attr(&s, "units", &units, path)?;
        string_attr(&s, "warnings", &r.warnings.join("\n"), path)?;
        f.close().map_err(h5err(path))
    })
}

/// Writes the reduction series as CSV (one header line, units in the column names).
pub fn write_reduction_csv(path: &Path, force: bool, r: &Reduction) -> Result<()> {
    let cols = reduction_columns(r);
    let mut text = cols.iter().map(|c| c.3).collect::<Vec<_>>().join(",");
    text.push('\n');
    for i in 0..r.time_s.len() {
        let row: Vec<String> = cols.iter().map(|c| format!("{:e}", c.1[i])).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    crate::io::write_text_atomically(path, force, &text)
}

/// Prints a line on stdout; a closed pipe is not an error.
fn say(line: &str) -> Result<()> {
    let stdout = std::io::stdout();
    let mut w = stdout.lock();
    match writeln!(w, "{line}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

/// `shpb reduce RECORD --bars BARS [-o OUT.h5] [--csv OUT.csv] [--no-dispersion] [--force]`:
/// reduces a raw record (the authors' CSV) or an HDF5 file of `shpb run` (recognised by its
/// signature) with the set-up's bars and gauges, writes `/reduction/*` (HDF5) and/or CSV, and
/// prints a summary. The strain rate uses the paper's spheres (r1 + r2 = 6.35 mm).
pub fn reduce_command(
    record: &Path,
    bars: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
    no_dispersion: bool,
) -> Result<()> {
    for p in [output, csv].into_iter().flatten() {
        crate::io::check_output(p, force)?;
    }
    if !bars.is_file() {
        return Err(input_err(
            "command line",
            "--bars",
            format!("cannot read {}: no such file", bars.display()),
            "a bar set-up .toml file such as bars/authors.toml",
        ));
    }
    if !record.is_file() {
        return Err(input_err(
            "command line",
            "RECORD",
            format!("cannot read {}: no such file", record.display()),
            "a raw gauge record (.csv: time_s,incident_V,transmission_V) or an HDF5 file of `shpb run`",
        ));
    }
    let apparatus = Apparatus::from_file(bars)?;
    let options = ReductionOptions {
        dispersion_correction: !no_dispersion,
        specimen_radii_m: Some(PAPER_SPHERE_RADII_M),
        ..ReductionOptions::default()
    };
    let hdf5_input = is_hdf5(record)?;
    let r = if hdf5_input {
        let input = read_hdf5_strains(record)?;
        reduce_named(
            &input,
            &ReductionSetup::from_apparatus(&apparatus)?,
            &options,
            &record.display().to_string(),
        )?
    } else {
        reduce_record_file(record, &apparatus, &options)?
    };
    let mut scene = format!("shpb reduce {} --bars {}", record.display(), bars.display());
    if let Some(o) = output {
        scene.push_str(&format!(" -o {}", o.display()));
    }
    if let Some(c) = csv {
        scene.push_str(&format!(" --csv {}", c.display()));
    }
    if no_dispersion {
        scene.push_str(" --no-dispersion");
    }
    if force {
        scene.push_str(" --force");
    }
    if let Some(o) = output {
        write_reduction_hdf5(o, force, &scene, &r)?;
    }
    if let Some(c) = csv {
        write_reduction_csv(c, force, &r)?;
    }
    let bridges: Vec<String> = ["incident", "transmission"]
        .iter()
        .filter_map(|n| apparatus.gauges.channel(n))
        .map(|c| {
            format!(
                "{} {} gain {}",
                c.name,
                c.bridge.kind.name(),
                c.amplifier_gain
            )
        })
        .collect();
    say(&format!(
        "record: {} ({}); bridges: {}",
        record.display(),
        if hdf5_input {
            "HDF5 gauge strains"
        } else {
            "raw gauge voltages"
        },
        bridges.join(", ")
    ))?;
    say(&format!(
        "windows: incident from {:.2} µs, reflected +{:.2} µs, transmitted +{:.2} µs, {:.1} µs long; dispersion correction {}",
        r.windows.incident_start_s * 1e6,
        r.windows.reflected_delay_s * 1e6,
        r.windows.transmitted_delay_s * 1e6,
        r.windows.duration_s * 1e6,
        if r.dispersion_corrected { "on" } else { "off" }
    ))?;
    say(&format!(
        "peak back force {:.1} N at t = {:.2} µs; displacement at peak force {:.2} µm; equilibrium ratio at peak {:.3}",
        r.peak_back_force_n,
        r.peak_back_force_time_s * 1e6,
        r.displacement_at_peak_force_m * 1e6,
        r.equilibrium_ratio_at_peak
    ))?;
    for w in &r.warnings {
        say(&format!("warning: {w}"))?;
    }
    Ok(())
}

//! The laboratory's data reduction (docs/physics.md §7; shared/reference/README.md, "Reduction"):
//! from the strains recorded at the incident and transmission gauges to the forces on the two
//! specimen faces, the sphere approach δ(t), its rate and the global strain rate. It works on
//! simulated records (`shpb run` HDF5) and on real ones (the authors' raw CSV).
//!
//! # Sign conventions
//!
//! Bar strain ε is positive in tension (docs/physics.md). The incident bar lies at x < 0 with its
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
//!   (docs/physics.md §7 writes the same with the bar-axis signs left to the reader), and
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
//! 2. Polarity: on the incident gauge the incident pulse, compressive (ε < 0), comes first; the
//!    reflected one, tensile for a specimen softer than the bars, only 2 d_I/c0 later. So the
//!    first sample whose |ε| reaches half the record's largest |ε| must be negative; if it is
//!    positive the channel's polarity is inverted (a compressive pulse recorded as tension) and
//!    the reduction is refused, naming the channel, rather than taking the reflected pulse for
//!    the incident one. The transmitted pulse is compressive too (the spheres can only push), so
//!    the same rule holds on the transmission gauge. A channel is judged only when its largest
//!    |ε| stands out of the noise (10 times the RMS of its baseline samples).
//! 3. Incident start `t_I` (at the incident gauge, record clock): with `y = −εI` (compression),
//!    `y_max` its largest value in the record, the first pulse is the first run of samples with
//!    `y ≥ y_max/2`; its peak `y_p` is the largest `y` in that run; `t_I` is the time of the last
//!    sample before the peak with `y < start_fraction·y_p` (default 2 %). `t_I` is therefore on
//!    the sample grid, at the foot of the pulse. It can be overridden (`WindowOverride`).
//! 4. Reflected window at the incident gauge: starts at `t_I + Δ_R`, `Δ_R = 2 d_I/c0`.
//!    Transmitted window at the transmission gauge: starts at `t_I + Δ_T`,
//!    `Δ_T = d_I/c0 + d_T/c0 + specimen_transit_s`; the transit through the specimen (two
//!    6.35 mm spheres, ≈ 2.5 µs at the spheres' bar-wave speed, but really set by the contact
//!    compliance) is neglected by default (0). Both delays can be overridden. Fractional-sample
//!    delays are applied exactly for band-limited signals (Fourier phase shift), not rounded.
//! 5. Window length `D`: the longest clean window, `min(Δ_R` (the incident gauge sees only the
//!    incident wave until the reflected one arrives), `2 (L_I − d_I)/c0` (the reflected wave
//!    comes back from the impact end after that), `2 (L_T − d_T)/c0` if the transmission bar's
//!    far end is not absorbing`)`, then shortened so that both the reflected and the transmitted
//!    windows lie inside the record. It can be overridden.
//! 6. Time axis: `t = 0` is the arrival of the incident pulse's foot at the specimen face,
//!    `t_I + d_I/c0` on the record clock (`Reduction::face_time_offset_s`); the three waves,
//!    time-shifted to the faces, share it.
//!
//! # Dispersion correction
//!
//! Optional (on by default), as in the authors' `disp_corr.m`: every Fourier component of a
//! wave is shifted in time by `τ(f) = Δx (1/c(f) − 1/c0)` (a spectrum factor `exp(−iωτ)`, i.e. a
//! *delay* for τ > 0), where `c(f)` is the first-mode phase velocity of the Bancroft fit of
//! docs/physics.md §7, `c/c0 = A + B/(C y⁴ + D y³ + E y² + F y^1.5 + 1)`, `y = a/Λ`, solved for the
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
//!
//! `DispersionCorrection::PochhammerChree` takes `c(f)` instead from the exact first mode for
//! the bar's own Poisson's ratio (`crate::dispersion`, docs/physics.md §7.9), solved once per FFT
//! bin. With `tyas_pope` each component is also multiplied by the Tyas–Pope factor M1·M2 (mean
//! axial stress over E times the surface strain the gauge reads), up to the cut-off
//! `f a/c0 = TYAS_POPE_CUTOFF_FA_OVER_C0`; components above it are removed. The three strain
//! series of such a reduction are then σ̄/E at the faces (forces exact for the first mode); the
//! face velocities keep the 1-D relation v = ∓c0 ε with them.

use crate::apparatus::Apparatus;
use crate::dispersion::PochhammerChree;
use crate::error::{Error, Result};
use crate::gauge::{GaugeChannel, RawRecord};
use crate::numeric::{bisect, cumulative_trapezoid, moving_average, spectral_filter};

pub mod align;
pub mod quality;

pub use align::{Alignment, AlignmentReport};
pub use quality::{EquilibriumVerdict, Quality, WaveMetrics, wave_metrics};

pub use crate::gauge::DEFAULT_SMOOTHING_S;

/// Default bound of the balance search on each window shift, s: 60 µs (docs/physics.md §7.6).
pub const DEFAULT_BALANCE_BOUND_S: f64 = 60e-6;

/// Bancroft first-mode fit for ν = 0.31 (docs/physics.md §7): A, B, C, D, E, F of
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

/// How the reduction corrects each wave for geometric dispersion between its gauge and the
/// specimen face (module docs, "Dispersion correction"; docs/physics.md §7.2, §7.9).
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

/// Incident stress at the specimen face implied by force F and approach δ (docs/physics.md §7 run
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
/// of the module docs (`gauge::pulse_foot`); None if `y` has no positive value.
fn pulse_foot(y: &[f64], fraction: f64) -> Option<(usize, usize)> {
    crate::gauge::pulse_foot(y, fraction).map(|f| (f.index, f.peak_index))
}

/// How many times the RMS of its baseline a channel's largest |ε| must be for its polarity to be
/// judged (module docs, "Windows" 2).
const POLARITY_SIGNAL_TO_NOISE: f64 = 10.0;

/// The first sample of `eps` (baseline removed) whose |ε| reaches half the largest |ε|, as
/// (index, value), when that largest |ε| stands out of the noise of the first `baseline`
/// samples (module docs, "Windows" 2); None for a channel without a clear pulse.
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

/// Refuses a channel whose first pulse is tensile: its polarity is inverted (module docs,
/// "Windows" 2). `channel` is `incident` or `transmission`.
fn check_polarity(
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

/// The correction of one wave between its gauge and the face: Bancroft fit (`exact` None) or
/// the exact first mode, and optionally the Tyas–Pope amplitude factors.
struct WaveCorrection<'a> {
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
fn cut(x: &[f64], dt: f64, start: f64, n: usize, correction: Option<&WaveCorrection>) -> Vec<f64> {
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
    if !(o.balance_bound_s.is_finite() && o.balance_bound_s > 0.0) {
        return Err(input_err(
            file,
            "balance_bound_s",
            format!("{} is out of range", o.balance_bound_s),
            "a positive number of seconds",
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

/// [`reduce`] with the record's name for error messages (`<name>: <series>`).
pub fn reduce_named(
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
                &eps_i,
                1.0,
                dt,
                s_i,
                geometric_r,
                0.1 * incident_peak,
                options.start_fraction,
            )
        })
        .flatten();
    let noise_t = quality::baseline_rms(&eps_t, nb);
    // The transmitted pulse: the first compressive one, above 10 times the gauge's noise.
    let measured_transmitted_delay_s = align::foot_delay_s(
        &eps_t,
        -1.0,
        dt,
        s_i,
        geometric_t,
        10.0 * noise_t,
        options.start_fraction,
    );
    // One exact first mode per bar, its roots shared by all its windows.
    let exact = |b: &BarProperties| -> Result<Option<PochhammerChree>> {
        if options.dispersion == DispersionCorrection::PochhammerChree || options.tyas_pope {
            PochhammerChree::new(b.poisson_ratio, b.radius_m, b.wave_speed_m_s).map(Some)
        } else {
            Ok(None)
        }
    };
    let (pc_i, pc_t) = (exact(bi)?, exact(bt)?);
    let disp = |d: f64, b: &BarProperties, pc| wave_correction(options, d, b, pc);
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
            let e_in = cut(
                &eps_i,
                dt,
                s_i,
                window,
                disp(d_i, bi, pc_i.as_ref()).as_ref(),
            );
            let ext = |x: &[f64], start: f64, d: Option<WaveCorrection>| {
                cut(
                    x,
                    dt,
                    start - margin as f64,
                    window + 2 * margin,
                    d.as_ref(),
                )
            };
            let reflected = ext(
                &eps_i,
                s_i + geometric_r / dt,
                disp(-d_i, bi, pc_i.as_ref()),
            );
            let transmitted = ext(
                &eps_t,
                s_i + geometric_t / dt,
                disp(-d_t, bt, pc_t.as_ref()),
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
    if at_bound {
        warnings.push(format!(
            "the balance search stopped at its bound (±{:.1} µs): the best shift may lie beyond \
             it; check the gauge distances, or widen the bound (--balance-bound)",
            options.balance_bound_s * 1e6
        ));
    }
    if options.dispersion == DispersionCorrection::Bancroft {
        for (name, b) in [("incident", bi), ("transmission", bt)] {
            if (b.poisson_ratio - BANCROFT_FIT_POISSON_RATIO).abs() > 0.02 {
                warnings.push(format!(
                    "the {name} bar's Poisson's ratio {} differs from the Bancroft fit's 0.31",
                    b.poisson_ratio
                ));
            }
        }
    }

    // Waves at the faces, and the quantities.
    let e_in = cut(
        &eps_i,
        dt,
        s_i,
        samples,
        disp(d_i, bi, pc_i.as_ref()).as_ref(),
    );
    let e_re = cut(
        &eps_i,
        dt,
        s_r,
        samples,
        disp(-d_i, bi, pc_i.as_ref()).as_ref(),
    );
    let e_tr = cut(
        &eps_t,
        dt,
        s_t,
        samples,
        disp(-d_t, bt, pc_t.as_ref()).as_ref(),
    );
    let f = faces(&e_in, &e_re, &e_tr, dt, bi, bt);

    // The reflected delay against the record: worth a word only when the record's own foot
    // is off the window by more than its detection uncertainty (2 % of the delay, 5 samples)
    // and moving the window there changes δ at peak by more than 5 % or the equilibrium ratio
    // at peak by more than 0.05.
    if let Some(m) = measured_reflected_delay_s
        && options.alignment == Alignment::Geometric
        && ov.reflected_delay_s.is_none()
        && (m - reflected_delay_s).abs() > (0.02 * reflected_delay_s).max(5.0 * dt)
    {
        let e_re_m = cut(
            &eps_i,
            dt,
            s_i + m / dt,
            samples,
            disp(-d_i, bi, pc_i.as_ref()).as_ref(),
        );
        let g = faces(&e_in, &e_re_m, &e_tr, dt, bi, bt);
        let (d0, d1) = (
            f.displacement_m[f.peak_index],
            g.displacement_m[g.peak_index],
        );
        let (q0, q1) = (
            f.equilibrium_ratio[f.peak_index],
            g.equilibrium_ratio[g.peak_index],
        );
        if (d1 - d0).abs() > 0.05 * d0.abs() || (q1 - q0).abs() > 0.05 {
            warnings.push(format!(
                "the reflected pulse starts {:.1} µs after the incident one in the record, the \
                 window uses {:.1} µs (2 d_I/c0 = {:.1} µs); on the record's own delay δ at peak \
                 would be {:.1} µm (not {:.1}) and the equilibrium ratio at peak {:.3} (not \
                 {:.3}): check the gauge distance and c0, or use --align foot|balance",
                m * 1e6,
                reflected_delay_s * 1e6,
                geometric_r * 1e6,
                d1 * 1e6,
                d0 * 1e6,
                q1,
                q0
            ));
        }
    }

    // Quality checks.
    let ((ka, kb), equilibrium_mean, equilibrium_max, verdict) =
        quality::equilibrium_over_loading(&f.force_3wave_n, &f.equilibrium_ratio);
    let incident_duration_s = match detected {
        Some((k_foot, k_peak)) if ov.incident_start_s.is_none() => quality::incident_duration_s(
            &eps_i,
            dt,
            k_foot,
            k_peak,
            options.start_fraction * incident_peak,
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
    let noise_strain = (quality::baseline_rms(&eps_i, nb), noise_t);
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let snr = |peak: f64, noise: f64| {
        if noise > 0.0 {
            peak / noise
        } else {
            f64::INFINITY
        }
    };
    let signal_to_noise = (
        snr(largest(&e_in), noise_strain.0),
        snr(largest(&e_tr), noise_strain.1),
    );
    for (name, s) in [
        ("incident", signal_to_noise.0),
        ("transmission", signal_to_noise.1),
    ] {
        if s < quality::MINIMUM_SIGNAL_TO_NOISE {
            warnings.push(format!(
                "the {name} channel's pulse is only {s:.1} times its baseline noise (RMS): feet \
                 and peaks are uncertain (smooth with --smooth, or check the gauge)"
            ));
        }
    }
    let time_s: Vec<f64> = (0..samples).map(|k| k as f64 * dt).collect();
    let quality = Quality {
        loading_span_s: (time_s[ka], time_s[kb]),
        equilibrium_mean,
        equilibrium_max,
        verdict,
        incident_duration_s,
        pulse_overlap_s,
        noise_strain,
        signal_to_noise,
    };
    let strain_rate_per_s = options.specimen_radii_m.map(|(r1, r2)| {
        f.approach_velocity_m_s
            .iter()
            .map(|v| v / (r1 + r2))
            .collect()
    });
    let peak_index = f.peak_index;
    Ok(Reduction {
        face_time_offset_s: incident_start_s + d_i / c_i,
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
        windows: Windows {
            incident_start_s,
            reflected_delay_s,
            transmitted_delay_s,
            duration_s: (samples - 1) as f64 * dt,
            samples,
            baseline_samples: nb,
        },
        measured_reflected_delay_s,
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
        quality,
        dispersion_corrected: options.dispersion != DispersionCorrection::None,
        dispersion: options.dispersion,
        tyas_pope: options.tyas_pope,
        warnings,
        time_s,
        incident_strain: e_in,
        reflected_strain: e_re,
        transmitted_strain: e_tr,
        force_front_n: f.force_front_n,
        force_back_n: f.force_back_n,
        force_3wave_n: f.force_3wave_n,
        front_displacement_m: f.front_displacement_m,
        back_displacement_m: f.back_displacement_m,
        displacement_m: f.displacement_m,
        approach_velocity_m_s: f.approach_velocity_m_s,
        strain_rate_per_s,
        equilibrium_ratio: f.equilibrium_ratio,
    })
}

/// Forces, displacements and the equilibrium ratio of the three waves at the faces (module docs,
/// "Sign conventions").
struct Faces {
    force_front_n: Vec<f64>,
    force_back_n: Vec<f64>,
    force_3wave_n: Vec<f64>,
    front_displacement_m: Vec<f64>,
    back_displacement_m: Vec<f64>,
    displacement_m: Vec<f64>,
    approach_velocity_m_s: Vec<f64>,
    equilibrium_ratio: Vec<f64>,
    /// Index of the largest back force.
    peak_index: usize,
}

/// [`Faces`] of incident, reflected and transmitted strains at the faces (equal lengths).
fn faces(
    e_in: &[f64],
    e_re: &[f64],
    e_tr: &[f64],
    dt: f64,
    bi: &BarProperties,
    bt: &BarProperties,
) -> Faces {
    let samples = e_in.len();
    let (ea_i, ea_t) = (
        bi.youngs_modulus_pa * bi.area_m2,
        bt.youngs_modulus_pa * bt.area_m2,
    );
    let (c_i, c_t) = (bi.wave_speed_m_s, bt.wave_speed_m_s);
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
    let f3_max = force_3wave_n.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let floor = (0.05 * f3_max).max(f64::MIN_POSITIVE);
    let equilibrium_ratio: Vec<f64> = (0..samples)
        .map(|k| (force_front_n[k] - force_back_n[k]).abs() / force_3wave_n[k].abs().max(floor))
        .collect();
    let peak_index = (0..samples)
        .max_by(|&a, &b| force_back_n[a].total_cmp(&force_back_n[b]))
        .unwrap_or(0);
    Faces {
        force_front_n,
        force_back_n,
        force_3wave_n,
        front_displacement_m,
        back_displacement_m,
        displacement_m,
        approach_velocity_m_s,
        equilibrium_ratio,
        peak_index,
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
    Ok(ReductionInput {
        time_s: record.time_s.clone(),
        incident_strain: inc.strains_from_voltages(&debias(&record.incident_v, n)),
        transmission_strain: tra.strains_from_voltages(&debias(&record.transmission_v, n)),
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of the authors' bars (no dispersion): a compressive incident sin² pulse whose
    /// foot passes the incident gauge at 100 µs, its reflection (tensile, 60 % of it) 2 d_I/c0
    /// later, and a compressive transmitted pulse, sampled at 10 MHz with a little noise.
    fn record() -> (ReductionInput, ReductionSetup) {
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
        let noise = |k: usize| 1e-7 * ((k * 7919 % 101) as f64 / 50.0 - 1.0);
        let incident_strain = time_s
            .iter()
            .enumerate()
            .map(|(k, &t)| -4e-4 * pulse(t - t_i) + 2.4e-4 * pulse(t - t_i - d_r) + noise(k))
            .collect();
        let transmission_strain = time_s
            .iter()
            .enumerate()
            .map(|(k, &t)| -1e-4 * pulse(t - t_i - d_t) + noise(k + 3))
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

    /// No dispersion and no smoothing: the record's own samples.
    fn options() -> ReductionOptions {
        ReductionOptions {
            dispersion: DispersionCorrection::None,
            smoothing_window_s: 0.0,
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

    /// The exact correction undoes its own propagation, and on a smooth pulse it differs from
    /// the Bancroft fit by no more than the fit's long-wave offset explains: c → (A + B) c0 moves
    /// every long component by τ0 = d/c0 (1 − 1/(A + B)), so |Δε| ≲ τ0 max|ε̇| (10 % allowance
    /// for the fit's residual higher up, ±0.3 % of c). In the pulse's band the residual is of
    /// the other sign (−0.1 % at 20 kHz) and takes back part of the offset, so the difference
    /// is smaller; it is not zero (at least a fifth of τ0 max|ε̇|).
    #[test]
    fn exact_dispersion_inverts_itself_and_differs_from_the_fit_by_its_offset() {
        let (_, setup) = record();
        let bar = setup.incident_bar;
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
}

//! Strain gauges on a bar → Wheatstone bridge → amplifier → digitiser, and back from recorded
//! voltages to bar strain (docs/physics.md §7; the authors' `analysis.m`, shared/reference/README.md).
//!
//! Sign conventions: bar strain ε is positive in tension (compression is negative). A bridge's
//! output is taken with the sign that makes it rise with the axial gauge's resistance, so it is
//! positive in tension; the channel's `polarity` (±1) is the wiring/amplifier sign after that.
//! In the authors' 2013-05-22 records the first (incident, compressive) pulse and the
//! transmitted (compressive) pulse are *negative* volts and the reflected (tensile) pulse is
//! positive, so their channels have polarity +1 here.
//!
//! Bridge outputs from first principles. A Wheatstone bridge excited by Vex has arms R1–R2 in one
//! divider and R4–R3 in the other; its output is `V = Vex·(R1/(R1+R2) − R4/(R3+R4))`. An axial
//! gauge has `R(1 + GF·ε)`, a transverse (Poisson) gauge `R(1 − GF·ν·ε)`, a completion resistor
//! `R`. Writing x = GF·ε:
//!
//! * quarter bridge, one axial gauge (R1) and three completion resistors:
//!   `V = Vex·x / (2(2 + x))`, inverse `ε = 4V / (GF·(Vex − 2V))`;
//! * half bridge, axial (R1) and Poisson (R2) gauges in adjacent arms, R3 = R4 = R:
//!   `V = Vex·x(1+ν) / (2(2 + x(1−ν)))`, inverse `ε = 4V / (Vex·GF·((1+ν) + 2V(ν−1)/Vex))`;
//! * half bridge, two axial gauges in opposite arms (R1 and R3, e.g. on opposite faces of the
//!   bar, so bending cancels), R2 = R4 = R: `V = Vex·x / (2 + x)`, inverse
//!   `ε = 2V / (GF·(Vex − V))`; to first order `ε = 2V/(GF·Vex)`, the conversion of LANL's
//!   HopPyBar (`2/GF` over gain·excitation);
//! * full bridge, axial gauges in R1 and R3, Poisson gauges in R2 and R4:
//!   `V = Vex·x(1+ν) / (2 + x(1−ν))` (exactly twice the half bridge),
//!   inverse `ε = 2V / (Vex·GF·((1+ν) + V(ν−1)/Vex))`.
//!
//! The authors' conversion `σ = −E·2V/(Vex·GF·((1+ν) + V(ν−1)/Vex))` is *exactly* the full-bridge
//! inverse with `σ = −E·ε`, i.e. it is the full Poisson bridge (or the half bridge behind a gain
//! of 2) and its σ is compression-positive for the records' polarity. Read with the opposite
//! polarity (compression → positive V, tension-positive σ) its second-order term would have the
//! wrong sign for any Wheatstone bridge, which confirms the records' polarity.

/// Which gauges the Wheatstone bridge has (module docs give each output formula).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BridgeKind {
    /// One axial gauge and three completion resistors: `V = Vex·x/(2(2+x))`, x = GF·ε.
    QuarterAxial,
    /// Axial + Poisson gauge in adjacent arms: `V = Vex·x(1+ν)/(2(2+x(1−ν)))`.
    HalfPoisson,
    /// Two axial gauges in opposite arms: `V = Vex·x/(2+x)` (HopPyBar's 2/GF to first order).
    HalfAxial,
    /// Two axial + two Poisson gauges: `V = Vex·x(1+ν)/(2+x(1−ν))`; the authors' formula exactly.
    FullPoisson,
    /// A calibrated linear channel, no bridge model: `ε = k·V` with k = [`Bridge::strain_per_volt`]
    /// (a lab's stated or fitted factor; gauge factor, excitation and ν unused).
    Linear,
}

impl BridgeKind {
    /// Every kind with its name in a gauge file (`bridge = "half-poisson"`).
    pub const ALL: [(BridgeKind, &'static str); 5] = [
        (BridgeKind::QuarterAxial, "quarter-axial"),
        (BridgeKind::HalfPoisson, "half-poisson"),
        (BridgeKind::HalfAxial, "half-axial"),
        (BridgeKind::FullPoisson, "full-poisson"),
        (BridgeKind::Linear, "linear"),
    ];

    /// The kind called `name` in a gauge file, if any.
    pub fn from_name(name: &str) -> Option<BridgeKind> {
        BridgeKind::ALL
            .iter()
            .find(|(_, n)| *n == name)
            .map(|(k, _)| *k)
    }

    /// Its name in a gauge file.
    pub fn name(self) -> &'static str {
        BridgeKind::ALL
            .iter()
            .find(|(k, _)| *k == self)
            .map(|(_, n)| *n)
            .unwrap_or("?")
    }
}

/// A strain-gauge Wheatstone bridge (module docs: arm resistances and output formulas).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bridge {
    /// Gauge arrangement.
    pub kind: BridgeKind,
    /// Gauge factor GF = (ΔR/R)/ε of every gauge.
    pub gauge_factor: f64,
    /// Bridge excitation Vex, V.
    pub excitation_v: f64,
    /// Poisson's ratio ν of the bar (the transverse gauges see −ν·ε).
    pub poisson_ratio: f64,
    /// Strain per volt of bridge output, tension positive: the factor of a
    /// [`BridgeKind::Linear`] channel (0 and unused for the Wheatstone kinds).
    pub strain_per_volt: f64,
}

impl Bridge {
    /// Bridge output for bar strain `strain` (tension positive), V; exact Wheatstone closed form
    /// (module docs), positive in tension. Physical for GF·ε > −1 (and GF·ν·ε < 1).
    pub fn output_v(&self, strain: f64) -> f64 {
        let x = self.gauge_factor * strain;
        let (vex, nu) = (self.excitation_v, self.poisson_ratio);
        match self.kind {
            BridgeKind::QuarterAxial => vex * x / (2.0 * (2.0 + x)),
            BridgeKind::HalfPoisson => vex * x * (1.0 + nu) / (2.0 * (2.0 + x * (1.0 - nu))),
            BridgeKind::HalfAxial => vex * x / (2.0 + x),
            BridgeKind::FullPoisson => vex * x * (1.0 + nu) / (2.0 + x * (1.0 - nu)),
            BridgeKind::Linear => strain / self.strain_per_volt,
        }
    }

    /// Bar strain from bridge output `v` (V): the exact closed-form inverse of [`Bridge::output_v`]
    /// (module docs); for full-poisson `−E·strain_from_output(V)` is the authors' formula.
    pub fn strain_from_output(&self, v: f64) -> f64 {
        let (vex, nu, gf) = (self.excitation_v, self.poisson_ratio, self.gauge_factor);
        match self.kind {
            BridgeKind::QuarterAxial => 4.0 * v / (gf * (vex - 2.0 * v)),
            BridgeKind::HalfPoisson => {
                4.0 * v / (vex * gf * ((1.0 + nu) + 2.0 * v * (nu - 1.0) / vex))
            }
            BridgeKind::HalfAxial => 2.0 * v / (gf * (vex - v)),
            BridgeKind::FullPoisson => 2.0 * v / (vex * gf * ((1.0 + nu) + v * (nu - 1.0) / vex)),
            BridgeKind::Linear => self.strain_per_volt * v,
        }
    }

    /// Small-strain sensitivity dV/dε at ε = 0, V: Vex·GF/4, Vex·GF(1+ν)/4, Vex·GF/2,
    /// Vex·GF(1+ν)/2, 1/k.
    pub fn sensitivity_v(&self) -> f64 {
        let base = self.excitation_v * self.gauge_factor / 4.0;
        match self.kind {
            BridgeKind::QuarterAxial => base,
            BridgeKind::HalfPoisson => base * (1.0 + self.poisson_ratio),
            BridgeKind::HalfAxial => 2.0 * base,
            BridgeKind::FullPoisson => 2.0 * base * (1.0 + self.poisson_ratio),
            BridgeKind::Linear => 1.0 / self.strain_per_volt,
        }
    }
}

/// The authors' conversion of bridge voltage to bar stress, literally (`analysis.m`):
/// `σ = −E·2V/(Vex·GF·((1+ν) + V(ν−1)/Vex))`, Pa; compression-positive for the records' polarity.
pub fn authors_stress_from_voltage(v: f64, e_pa: f64, nu: f64, vex: f64, gf: f64) -> f64 {
    -e_pa * 2.0 * v / (vex * gf * ((1.0 + nu) + v * (nu - 1.0) / vex))
}

/// A small deterministic pseudo-random generator (SplitMix64, Steele, Lea & Flood, OOPSLA 2014).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits (SplitMix64 output function).
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform number in (0, 1] with 53 random bits (never 0, so its logarithm is finite).
    pub fn next_unit(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) * (1.0 / (1u64 << 53) as f64)
    }
}

/// Standard normal deviates by the Box–Muller transform (Box & Muller, Ann. Math. Stat. 29, 610
/// (1958)) of SplitMix64 uniforms; deterministic for a given seed.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianNoise {
    rng: SplitMix64,
    spare: Option<f64>,
}

impl GaussianNoise {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        GaussianNoise {
            rng: SplitMix64::new(seed),
            spare: None,
        }
    }

    /// The next N(0, 1) deviate: `√(−2 ln u1)·cos(2π u2)`, then the matching sine value.
    pub fn next_standard(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let r = (-2.0 * self.rng.next_unit().ln()).sqrt();
        let theta = std::f64::consts::TAU * self.rng.next_unit();
        self.spare = Some(r * theta.sin());
        r * theta.cos()
    }
}

/// An analogue-to-digital converter with additive Gaussian input noise.
#[derive(Debug, Clone, PartialEq)]
pub struct Digitiser {
    /// Sampling rate, Hz.
    pub sample_rate_hz: f64,
    /// Resolution, bits (1–32).
    pub bits: u32,
    /// Full scale ±range_v, V.
    pub range_v: f64,
    /// RMS of the white Gaussian noise added before quantisation, V.
    pub noise_rms_v: f64,
    /// Seed of the noise generator (the same seed gives the same record).
    pub seed: u64,
}

impl Digitiser {
    /// Quantisation step q = 2·range/2^bits, V.
    pub fn quantisation_step_v(&self) -> f64 {
        2.0 * self.range_v / 2f64.powi(self.bits as i32)
    }

    /// Sampling interval 1/fs, s.
    pub fn sample_interval_s(&self) -> f64 {
        1.0 / self.sample_rate_hz
    }

    /// Quantises `v` (mid-tread: codes k·q, k = −2^(bits−1) … 2^(bits−1)−1), clipping at full
    /// scale: the output lies in [−range, range − q]; non-finite input clips to the nearer end.
    pub fn quantise(&self, v: f64) -> f64 {
        let q = self.quantisation_step_v();
        let half = 2f64.powi(self.bits as i32 - 1);
        let code = if v.is_nan() { 0.0 } else { (v / q).round() };
        code.clamp(-half, half - 1.0) * q
    }
}

/// One strain-gauge channel: gauges on a bar, bridge, amplifier and digitiser.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeChannel {
    /// Channel name (`incident`, `transmission`).
    pub name: String,
    /// Name of the bar the gauges are bonded to.
    pub bar: String,
    /// Distance of the gauges from the bar's specimen face, m.
    pub distance_from_specimen_m: f64,
    /// The bridge.
    pub bridge: Bridge,
    /// Voltage gain of the amplifier between bridge and digitiser.
    pub amplifier_gain: f64,
    /// Sign (+1 or −1) between bridge output and recorded voltage.
    pub polarity: f64,
    /// The digitiser.
    pub digitiser: Digitiser,
}

impl GaugeChannel {
    /// Recorded voltage for bar strain `strain` without noise or quantisation:
    /// `polarity · gain · V_bridge(ε)`, V.
    pub fn voltage_from_strain(&self, strain: f64) -> f64 {
        self.polarity * self.amplifier_gain * self.bridge.output_v(strain)
    }

    /// Bar strain (tension positive) from a recorded voltage: exact inverse of
    /// [`GaugeChannel::voltage_from_strain`].
    pub fn strain_from_voltage(&self, v: f64) -> f64 {
        self.bridge
            .strain_from_output(v / (self.polarity * self.amplifier_gain))
    }

    /// Bar strains of a whole voltage record (see [`GaugeChannel::strain_from_voltage`]).
    pub fn strains_from_voltages(&self, v: &[f64]) -> Vec<f64> {
        v.iter().map(|&x| self.strain_from_voltage(x)).collect()
    }

    /// Samples a strain history (`time_s`, `strain`, linear interpolation, end values held
    /// outside it) at the digitiser rate from `t0_s` for `n` samples, adds Gaussian noise
    /// (restarted from the digitiser's seed on every call) and quantises with clipping; returns
    /// (time_s, voltage_v). Panics if the history is empty or its two slices differ in length.
    pub fn record(
        &self,
        time_s: &[f64],
        strain: &[f64],
        t0_s: f64,
        n: usize,
    ) -> (Vec<f64>, Vec<f64>) {
        assert_eq!(
            time_s.len(),
            strain.len(),
            "gauge channel `{}`: time and strain histories differ in length",
            self.name
        );
        assert!(
            !time_s.is_empty(),
            "gauge channel `{}`: empty strain history",
            self.name
        );
        let d = &self.digitiser;
        let dt = d.sample_interval_s();
        let mut noise = GaussianNoise::new(d.seed);
        let mut times = Vec::with_capacity(n);
        let mut volts = Vec::with_capacity(n);
        let mut j = 0usize; // time_s[j] <= t < time_s[j + 1] once inside the history
        for k in 0..n {
            let t = t0_s + k as f64 * dt;
            let eps = if t <= time_s[0] {
                strain[0]
            } else if t >= time_s[time_s.len() - 1] {
                strain[strain.len() - 1]
            } else {
                while time_s[j + 1] <= t {
                    j += 1;
                }
                let w = (t - time_s[j]) / (time_s[j + 1] - time_s[j]);
                strain[j] + w * (strain[j + 1] - strain[j])
            };
            let v = self.voltage_from_strain(eps) + d.noise_rms_v * noise.next_standard();
            times.push(t);
            volts.push(d.quantise(v));
        }
        (times, volts)
    }
}

/// The gauge channels of a set-up, as read from a gauge file (`bars/gauges-*.toml`).
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeSetup {
    /// The channels, in file order.
    pub channels: Vec<GaugeChannel>,
}

impl GaugeSetup {
    /// The channel called `name`, if any.
    pub fn channel(&self, name: &str) -> Option<&GaugeChannel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// The fastest channel's sample rate, Hz (0 without channels): what sets how many samples
    /// a run records.
    pub fn max_sample_rate_hz(&self) -> f64 {
        self.channels
            .iter()
            .map(|c| c.digitiser.sample_rate_hz)
            .fold(0.0, f64::max)
    }
}

/// A raw two-channel gauge record in the authors' CSV format (`# ` comments, header
/// `time_s,incident_V,transmission_V`; shared/reference/README.md).
#[derive(Debug, Clone, PartialEq)]
pub struct RawRecord {
    /// Sample times, s (strictly increasing).
    pub time_s: Vec<f64>,
    /// Incident-bar gauge voltage, V.
    pub incident_v: Vec<f64>,
    /// Transmission-bar gauge voltage, V.
    pub transmission_v: Vec<f64>,
}

impl RawRecord {
    /// Mean sampling interval, s.
    pub fn sample_interval_s(&self) -> f64 {
        (self.time_s[self.time_s.len() - 1] - self.time_s[0]) / (self.time_s.len() - 1) as f64
    }
}

/// Removes the baseline: subtracts the mean of the first `n_first` samples (the pre-trigger part;
/// the authors use those before 93 µs of a record that starts 100 µs before the trigger).
pub fn remove_baseline(v: &[f64], n_first: usize) -> Vec<f64> {
    let n = n_first.min(v.len());
    if n == 0 {
        return v.to_vec();
    }
    let mean = v[..n].iter().sum::<f64>() / n as f64;
    v.iter().map(|x| x - mean).collect()
}

/// Shape of the pulse containing a signal's largest excursion of one sign.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseMetrics {
    /// Peak value, signed as in the signal (negative for a compressive-negative pulse).
    pub peak: f64,
    /// Time of the peak sample, s.
    pub peak_time_s: f64,
    /// Time from the 10 % to the 90 % crossing of the rising edge before the peak, s.
    pub rise_10_90_s: f64,
    /// Time from the rising to the falling 10 % crossing around the peak, s.
    pub duration_10_s: f64,
    /// Time of the rising 10 % crossing, s.
    pub start_10_s: f64,
}

/// Default width of the moving average applied to a gauge record before its reduction, s: 2 µs
/// (20 samples at 10 MHz) cuts the digitiser noise √20-fold and changes a pulse rising in ≥ 40 µs
/// by < 0.02 % of its peak. `shpb run` applies it to simulated records, `shpb reduce` to any
/// record, so that the two read alike.
pub const DEFAULT_SMOOTHING_S: f64 = 2e-6;

/// Metrics of the largest-magnitude pulse of the requested sign (negative if
/// `compressive_negative`) in a baseline-free signal; crossings are interpolated linearly between
/// samples. None if there is no such pulse or it is cut off by the record's ends.
pub fn pulse_metrics(
    time_s: &[f64],
    signal: &[f64],
    compressive_negative: bool,
) -> Option<PulseMetrics> {
    let sign = if compressive_negative { -1.0 } else { 1.0 };
    let e = pulse_edges(time_s, signal, sign)?;
    Some(PulseMetrics {
        peak: sign * e.peak,
        peak_time_s: time_s[e.peak_index],
        rise_10_90_s: e.rise_90_s - e.start_10_s,
        duration_10_s: e.fall_10_s? - e.start_10_s,
        start_10_s: e.start_10_s,
    })
}

/// The crossings of a pulse around its peak (see [`pulse_edges`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseEdges {
    /// Index of the peak (the last sample of the largest finite value of `sign · signal`).
    pub peak_index: usize,
    /// The peak of `sign · signal` (> 0).
    pub peak: f64,
    /// Time of the rising 10 % crossing, s.
    pub start_10_s: f64,
    /// Time of the rising 90 % crossing, s.
    pub rise_90_s: f64,
    /// Time of the falling 10 % crossing, s; None when the signal ends before it.
    pub fall_10_s: Option<f64>,
}

/// Peak and 10 %/90 % crossings (interpolated linearly between samples) of the largest pulse of
/// `sign · signal` (`sign` +1 or −1); None if there is no positive value or the rise is cut off
/// by the start of the signal. [`pulse_metrics`] and the reduction's wave metrics share it.
pub fn pulse_edges(time_s: &[f64], signal: &[f64], sign: f64) -> Option<PulseEdges> {
    if time_s.len() != signal.len() || signal.len() < 3 {
        return None;
    }
    let y: Vec<f64> = signal.iter().map(|s| sign * s).collect();
    let (k, &p) = y
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if p <= 0.0 {
        return None;
    }
    let fall_10_s = (k + 1..y.len())
        .find(|&j| y[j] < 0.1 * p)
        .map(|j| crossing_s(time_s, &y, j - 1, 0.1 * p));
    Some(PulseEdges {
        peak_index: k,
        peak: p,
        start_10_s: rising_crossing_s(time_s, &y, k, 0.1 * p)?,
        rise_90_s: rising_crossing_s(time_s, &y, k, 0.9 * p)?,
        fall_10_s,
    })
}

/// Time where `y` crosses `level` between samples i and i + 1 (linear interpolation), s.
fn crossing_s(time_s: &[f64], y: &[f64], i: usize, level: f64) -> f64 {
    time_s[i] + (level - y[i]) * (time_s[i + 1] - time_s[i]) / (y[i + 1] - y[i])
}

/// The last crossing of `level` by `y` rising to its peak at index `k`, s; None if `y` is above
/// it from the start.
fn rising_crossing_s(time_s: &[f64], y: &[f64], k: usize, level: f64) -> Option<f64> {
    (0..k)
        .rev()
        .find(|&i| y[i] < level)
        .map(|i| crossing_s(time_s, y, i, level))
}

impl PulseEdges {
    /// The rising crossing of `fraction` of the peak of `sign · signal` (the signal these edges
    /// were found on), by the rule of the 10 % and 90 % crossings, s; None if the signal is above
    /// that level from its start to the peak.
    pub fn rising_s(
        &self,
        time_s: &[f64],
        signal: &[f64],
        sign: f64,
        fraction: f64,
    ) -> Option<f64> {
        let y: Vec<f64> = signal[..=self.peak_index]
            .iter()
            .map(|s| sign * s)
            .collect();
        rising_crossing_s(time_s, &y, self.peak_index, fraction * self.peak)
    }
}

/// Foot of the first pulse of a signal (positive pulse), the arrival feature of the reduction's
/// windows and of the records' timing (docs/physics.md §7.5; reduce.rs module docs, "Windows").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseFoot {
    /// Last sample before the peak below `fraction` of it (0 if none is).
    pub index: usize,
    /// Index of the pulse's peak: the largest sample of the first excursion above half the
    /// signal's largest value.
    pub peak_index: usize,
    /// Where the signal rises through `fraction` of the peak, in (fractional) samples from the
    /// start, interpolated linearly between `index` and `index + 1`.
    pub crossing_samples: f64,
}

impl PulseFoot {
    /// Time of the crossing on the sample times `time_s` (uniform or not), s.
    pub fn time_s(&self, time_s: &[f64]) -> f64 {
        let k = self.index;
        let w = self.crossing_samples - k as f64;
        if k + 1 < time_s.len() {
            time_s[k] + w * (time_s[k + 1] - time_s[k])
        } else {
            time_s[k]
        }
    }
}

/// Fraction of each pulse's own peak that marks its foot, the arrival feature of records and
/// simulations alike (docs/physics.md §7.5; the reduction's incident-start rule, reduce.rs).
pub const FOOT_FRACTION: f64 = 0.02;

/// Width of the centred moving average applied to records and simulated strains before their
/// feet are measured, s (docs/physics.md §7.5: 2 µs cuts the records' 0.16 mV noise, which
/// would otherwise cross 2 % of a pulse early; it moves the foot of a pulse rising in ≥ 40 µs by
/// well under 1 µs, the same on both).
pub const FOOT_SMOOTHING_S: f64 = 2e-6;

/// A strain series (tension positive, sample step `dt_s`) as pulse feet are read on it
/// (docs/physics.md §7.5): compression positive, on a centred moving average over
/// [`FOOT_SMOOTHING_S`].
pub fn foot_signal(strain: &[f64], dt_s: f64) -> Vec<f64> {
    let half = (0.5 * FOOT_SMOOTHING_S / dt_s).round() as usize;
    crate::numeric::moving_average(strain, half)
        .iter()
        .map(|e| -e)
        .collect()
}

/// The foot of the first pulse of `y` at `fraction` of its peak (see [`PulseFoot`];
/// docs/physics.md §7.5); None if `y` has no positive value.
pub fn pulse_foot(y: &[f64], fraction: f64) -> Option<PulseFoot> {
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
    let below = (0..=k_peak).rev().find(|&k| y[k] < level);
    let (index, crossing_samples) = match below {
        Some(k) => (k, k as f64 + (level - y[k]) / (y[k + 1] - y[k])),
        None => (0, 0.0),
    };
    Some(PulseFoot {
        index,
        peak_index: k_peak,
        crossing_samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn baseline_removal_subtracts_the_mean_of_the_first_samples() {
        let v = [1.0, 3.0, 10.0, 12.0];
        assert_eq!(remove_baseline(&v, 2), vec![-1.0, 1.0, 8.0, 10.0]);
        assert_eq!(remove_baseline(&v, 0), v.to_vec());
        assert_eq!(remove_baseline(&v, 99).iter().sum::<f64>(), 0.0);
    }

    #[test]
    fn pulse_metrics_of_a_trapezoid_are_its_analytic_crossings() {
        // Trapezoid, compressive negative: 0 until 10 µs, ramp to −1 at 20 µs, flat to 50 µs,
        // back to 0 at 60 µs; 10 % crossings at 11 and 59 µs, 90 % at 19 µs.
        let dt = 0.1e-6;
        let t: Vec<f64> = (0..800).map(|k| k as f64 * dt).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&s| {
                let us = s * 1e6;
                -if us < 10.0 {
                    0.0
                } else if us < 20.0 {
                    (us - 10.0) / 10.0
                } else if us < 50.0 {
                    1.0
                } else if us < 60.0 {
                    (60.0 - us) / 10.0
                } else {
                    0.0
                }
            })
            .collect();
        let m = pulse_metrics(&t, &y, true).unwrap();
        assert_relative_eq!(m.peak, -1.0);
        assert_relative_eq!(m.start_10_s, 11e-6, max_relative = 1e-9);
        assert_relative_eq!(m.rise_10_90_s, 8e-6, max_relative = 1e-9);
        assert_relative_eq!(m.duration_10_s, 48e-6, max_relative = 1e-9);
        // Any level of the rise by the same rule: 30 % at 13 µs, 70 % at 17 µs.
        let e = pulse_edges(&t, &y, -1.0).unwrap();
        assert_relative_eq!(
            e.rising_s(&t, &y, -1.0, 0.3).unwrap(),
            13e-6,
            max_relative = 1e-9
        );
        assert_relative_eq!(
            e.rising_s(&t, &y, -1.0, 0.7).unwrap(),
            17e-6,
            max_relative = 1e-9
        );
        // No tensile pulse in it; a pulse cut off by the record's end has no metrics.
        assert!(pulse_metrics(&t, &y, false).is_none());
        assert!(pulse_metrics(&t[..300], &y[..300], true).is_none());
    }

    #[test]
    fn pulse_foot_of_a_ramp_is_its_analytic_crossing_and_skips_a_smaller_earlier_bump() {
        // A bump of 0.3 at 5–7 µs (below half the largest value, so not "the pulse"), then a ramp
        // from 0 at 10 µs to 2 at 30 µs (0.1 per µs), flat to 60 µs, on a 0.1 µs grid. Levels
        // between samples: 2.35 % of the peak (0.047) at 10.47 µs, 1.3 % (0.026) at 10.26 µs.
        // Exact up to rounding (1e-9 sample).
        let dt = 0.1e-6;
        let t: Vec<f64> = (0..800).map(|k| 1e-3 + k as f64 * dt).collect();
        let y: Vec<f64> = (0..800)
            .map(|k| {
                let us = k as f64 * 0.1;
                if (5.0..7.0).contains(&us) {
                    0.3
                } else if (10.0..30.0).contains(&us) {
                    (us - 10.0) / 10.0
                } else if (30.0..60.0).contains(&us) {
                    2.0
                } else {
                    0.0
                }
            })
            .collect();
        let f = pulse_foot(&y, 0.0235).unwrap();
        assert_eq!(f.index, 104);
        assert_eq!(f.peak_index, 300);
        assert_relative_eq!(f.crossing_samples, 104.7, epsilon = 1e-9);
        let g = pulse_foot(&y, 0.013).unwrap();
        assert_eq!(g.index, 102);
        assert_relative_eq!(g.time_s(&t), 1e-3 + 10.26e-6, epsilon = 1e-15);
        // The same pulse shifted by 3.7 samples: the foot moves by 0.37 µs.
        let shift = |s: f64| -> Vec<f64> {
            (0..800)
                .map(|k| {
                    let us = (k as f64 - s) * 0.1;
                    if (10.0..30.0).contains(&us) {
                        (us - 10.0) / 10.0
                    } else if (30.0..60.0).contains(&us) {
                        2.0
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let (a, b) = (shift(0.0), shift(3.7));
        let d = pulse_foot(&b, 0.02).unwrap().time_s(&t) - pulse_foot(&a, 0.02).unwrap().time_s(&t);
        assert_relative_eq!(d, 0.37e-6, epsilon = 1e-15);
        assert!(pulse_foot(&[0.0, -1.0], 0.02).is_none());
    }

    #[test]
    fn a_linear_channel_is_its_factor() {
        let b = Bridge {
            kind: BridgeKind::Linear,
            gauge_factor: 0.0,
            excitation_v: 0.0,
            poisson_ratio: 0.0,
            strain_per_volt: 4.96e-4,
        };
        // Yao et al.'s 945-steel shot: -0.0145833 V is -7.23333 µε in their paired files.
        assert_relative_eq!(
            b.strain_from_output(-0.0145833),
            -7.2333e-6,
            max_relative = 1e-4
        );
        assert_relative_eq!(b.sensitivity_v(), 1.0 / 4.96e-4);
    }

    #[test]
    fn bridges_invert_exactly() {
        for (kind, _) in BridgeKind::ALL {
            let b = Bridge {
                kind,
                gauge_factor: 2.1,
                excitation_v: 10.0,
                poisson_ratio: 0.3,
                strain_per_volt: 4.96e-4,
            };
            for strain in [-2e-3, -1e-5, 0.0, 4e-4] {
                assert_relative_eq!(
                    b.strain_from_output(b.output_v(strain)),
                    strain,
                    epsilon = 1e-15,
                    max_relative = 1e-12
                );
            }
        }
    }
}

//! Zero-phase filters of the gauge records before their reduction (docs/physics.md §7.12):
//! none, a centred moving average, a Butterworth low-pass run forward and backward, and a
//! Savitzky–Golay smoother. Every one is symmetric in time, so a pulse's peak stays where it is.
//!
//! The routines are written here (a few dozen lines) rather than taken from a crate: the Rust
//! crates found (`butterworth` 0.0.3, `savgol-rs` 0.1.0) are single releases left unmaintained,
//! and `biquad` designs one second-order section without the forward–backward pass.

use crate::error::{Error, Result};

/// Butterworth order per pass of the default filter (docs/physics.md §7.12): 4, so the
/// forward–backward gain 1/(1 + (f/f_c)^8) is flat to 0.4 % up to half the cut-off.
pub const DEFAULT_BUTTERWORTH_ORDER: usize = 4;

/// Highest Butterworth order per pass accepted (second-order sections stay well conditioned).
pub const MAX_BUTTERWORTH_ORDER: usize = 12;

/// The Butterworth cut-off tied to a bar's dispersion band, as f a/c0 (docs/physics.md §7.12):
/// 0.4, where the exact first mode's phase velocity has fallen to 0.63 c0 (ν = 0.29–0.31),
/// within 11 % of its Rayleigh-wave limit: the mode is a surface wave there, and what a surface
/// gauge reads no longer stands for the force on the section, so the one-dimensional reduction
/// has nothing to read above it (204 kHz on the authors' 19.05 mm steel bars).
pub const BAND_CUTOFF_FA_OVER_C0: f64 = 0.4;

/// Default Savitzky–Golay window, s (docs/physics.md §7.12): 5 µs, 51 samples at 10 MHz.
pub const DEFAULT_SAVGOL_WINDOW_S: f64 = 5e-6;

/// Default Savitzky–Golay polynomial order (docs/physics.md §7.12): 3, exact on cubics.
pub const DEFAULT_SAVGOL_ORDER: usize = 3;

/// Largest Savitzky–Golay polynomial order accepted.
pub const MAX_SAVGOL_ORDER: usize = 8;

/// A zero-phase filter of the records (docs/physics.md §7.12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Filter {
    /// The records as recorded.
    None,
    /// A centred moving average of `width_s` (None: the options' `smoothing_window_s`,
    /// `--smooth`), rounded to an odd number of samples.
    MovingAverage {
        /// Width of the box, s.
        width_s: Option<f64>,
    },
    /// A Butterworth low-pass of `order` per pass, run forward then backward (gain
    /// 1/(1 + (tan(π f Δt)/tan(π f_c Δt))^(2N)), no phase).
    Butterworth {
        /// Order N per pass (1 to [`MAX_BUTTERWORTH_ORDER`]).
        order: usize,
        /// Cut-off f_c, Hz, where one pass has gain 1/√2 (None: [`band_cutoff_hz`] of the
        /// incident bar).
        cutoff_hz: Option<f64>,
    },
    /// A Savitzky–Golay smoother: the least-squares polynomial of `order` over a centred window
    /// of `window_s` (rounded to an odd number of samples), evaluated at its centre; at the ends
    /// the first and last windows' polynomials.
    SavitzkyGolay {
        /// Window, s.
        window_s: f64,
        /// Polynomial order (0 to [`MAX_SAVGOL_ORDER`], less than the window's samples).
        order: usize,
    },
}

impl Filter {
    /// The default filter of a reduction (docs/physics.md §7.12): a 4th-order Butterworth at the
    /// bars' dispersion band, forward and backward.
    pub const DEFAULT: Filter = Filter::Butterworth {
        order: DEFAULT_BUTTERWORTH_ORDER,
        cutoff_hz: None,
    };

    /// The name of `--filter` (`none`, `moving-average`, `butterworth`, `savitzky-golay`).
    pub fn name(&self) -> &'static str {
        match self {
            Filter::None => "none",
            Filter::MovingAverage { .. } => "moving-average",
            Filter::Butterworth { .. } => "butterworth",
            Filter::SavitzkyGolay { .. } => "savitzky-golay",
        }
    }

    /// The filter with every parameter fixed: a moving average's width from `smoothing_window_s`,
    /// a Butterworth cut-off from `band_cutoff_hz` when not given; a zero-width moving average is
    /// no filter.
    pub fn resolved(&self, smoothing_window_s: f64, band_cutoff_hz: f64) -> Filter {
        match *self {
            Filter::MovingAverage { width_s } => {
                let w = width_s.unwrap_or(smoothing_window_s);
                if w > 0.0 {
                    Filter::MovingAverage { width_s: Some(w) }
                } else {
                    Filter::None
                }
            }
            Filter::Butterworth { order, cutoff_hz } => Filter::Butterworth {
                order,
                cutoff_hz: Some(cutoff_hz.unwrap_or(band_cutoff_hz)),
            },
            other => other,
        }
    }

    /// One line naming the filter and its parameters (provenance of a reduction), e.g.
    /// `butterworth order 4, cut-off 2.04e5 Hz, forward-backward`.
    pub fn describe(&self) -> String {
        match *self {
            Filter::None => "none".into(),
            Filter::MovingAverage { width_s } => match width_s {
                Some(w) => format!("moving-average {w:e} s"),
                None => "moving-average (the --smooth width)".into(),
            },
            Filter::Butterworth { order, cutoff_hz } => match cutoff_hz {
                Some(f) => {
                    format!("butterworth order {order}, cut-off {f:.4e} Hz, forward-backward")
                }
                None => format!("butterworth order {order}, cut-off at the bars' band"),
            },
            Filter::SavitzkyGolay { window_s, order } => {
                format!("savitzky-golay window {window_s:e} s, order {order}")
            }
        }
    }

    /// Checks the parameters that need no sample step: an [`Error::Invalid`] of `object` whose
    /// quantity is `filter.<parameter>`.
    pub fn validate(&self, object: &str) -> Result<()> {
        let err = |q: &str, problem: String, allowed: &str| Error::Invalid {
            object: object.into(),
            quantity: q.into(),
            problem,
            allowed: allowed.into(),
        };
        match *self {
            Filter::None => Ok(()),
            Filter::MovingAverage { width_s } => match width_s {
                Some(w) if !(w.is_finite() && w >= 0.0) => Err(err(
                    "filter.width_s",
                    format!("{w} s is out of range"),
                    "0 (off) or a positive width in seconds, e.g. 2e-6",
                )),
                _ => Ok(()),
            },
            Filter::Butterworth { order, cutoff_hz } => {
                if !(1..=MAX_BUTTERWORTH_ORDER).contains(&order) {
                    return Err(err(
                        "filter.order",
                        format!("order {order} is out of range"),
                        "a Butterworth order from 1 to 12 per pass",
                    ));
                }
                match cutoff_hz {
                    Some(f) if !(f.is_finite() && f > 0.0) => Err(err(
                        "filter.cutoff_hz",
                        format!("{f} Hz is out of range"),
                        "a positive cut-off in Hz below half the sample rate, e.g. 2e5",
                    )),
                    _ => Ok(()),
                }
            }
            Filter::SavitzkyGolay { window_s, order } => {
                if !(window_s.is_finite() && window_s > 0.0) {
                    return Err(err(
                        "filter.window_s",
                        format!("{window_s} s is out of range"),
                        "a positive window in seconds, e.g. 5e-6",
                    ));
                }
                if order > MAX_SAVGOL_ORDER {
                    return Err(err(
                        "filter.order",
                        format!("order {order} is out of range"),
                        "a Savitzky–Golay order from 0 to 8",
                    ));
                }
                Ok(())
            }
        }
    }

    /// The series `v` (sample step `dt_s`) filtered, same length; the filter must be
    /// [`Filter::resolved`]. Errors (object `object`) for a parameter the sample step makes
    /// impossible: a cut-off at or above the Nyquist frequency, a Savitzky–Golay window of fewer
    /// samples than its order needs or longer than the series.
    pub fn apply(&self, v: &[f64], dt_s: f64, object: &str) -> Result<Vec<f64>> {
        let err = |q: &str, problem: String, allowed: String| Error::Invalid {
            object: object.into(),
            quantity: q.into(),
            problem,
            allowed,
        };
        match *self {
            Filter::None => Ok(v.to_vec()),
            Filter::MovingAverage { width_s } => {
                let half = (width_s.unwrap_or(0.0) / dt_s / 2.0).round() as usize;
                Ok(crate::numeric::moving_average(v, half))
            }
            Filter::Butterworth { order, cutoff_hz } => {
                let fc = cutoff_hz.unwrap_or(f64::NAN);
                let nyquist = 0.5 / dt_s;
                if !(fc > 0.0 && fc < nyquist) {
                    return Err(err(
                        "filter.cutoff_hz",
                        format!(
                            "{fc:e} Hz is not below the record's Nyquist frequency {}",
                            crate::error::format_si(nyquist, "Hz")
                        ),
                        format!(
                            "a cut-off above 0 and below {} (half the sample rate)",
                            crate::error::format_si(nyquist, "Hz")
                        ),
                    ));
                }
                Ok(butterworth_zero_phase(v, order, fc * dt_s))
            }
            Filter::SavitzkyGolay { window_s, order } => {
                let half = (window_s / dt_s / 2.0).round() as usize;
                let m = 2 * half + 1;
                if m <= order || m > v.len() {
                    return Err(err(
                        "filter.window_s",
                        format!(
                            "{window_s:e} s spans {m} of this record's samples (step {}), for \
                             order {order} on {} samples",
                            crate::error::format_si(dt_s, "s"),
                            v.len()
                        ),
                        format!(
                            "a window of more than {order} samples (order + 1) and at most the \
                             record's {} samples",
                            v.len()
                        ),
                    ));
                }
                Ok(savitzky_golay(v, half, order))
            }
        }
    }
}

/// The Butterworth cut-off tied to a bar's dispersion band, Hz: [`BAND_CUTOFF_FA_OVER_C0`]
/// c0/a for bar radius a and bar-wave speed c0 (docs/physics.md §7.12).
pub fn band_cutoff_hz(radius_m: f64, wave_speed_m_s: f64) -> f64 {
    BAND_CUTOFF_FA_OVER_C0 * wave_speed_m_s / radius_m
}

/// One second-order (or first-order, `b2 = a2 = 0`) section y = (b0 + b1 z⁻¹ + b2 z⁻²) /
/// (1 + a1 z⁻¹ + a2 z⁻²) x, unit gain at DC.
#[derive(Debug, Clone, Copy)]
struct Section {
    b: [f64; 3],
    a: [f64; 2],
}

/// The sections of a digital Butterworth low-pass of order `order` and cut-off `fc_dt` (cut-off
/// over sample rate) by the bilinear transform with the cut-off prewarped, K = tan(π f_c Δt):
/// each pole pair of the analogue prototype at angle ψ_k = π(N − 1 − 2k)/(2N) from the
/// negative real axis gives b = K²(1, 2, 1)/D, a = (2(K² − 1), 1 − 2K cos ψ_k + K²)/D with
/// D = 1 + 2K cos ψ_k + K², and an odd order adds b = K(1, 1)/(1 + K), a1 = (K − 1)/(K + 1)
/// (Oppenheim & Schafer, Discrete-Time Signal Processing, §7.1).
fn butterworth_sections(order: usize, fc_dt: f64) -> Vec<Section> {
    use std::f64::consts::PI;
    let k = (PI * fc_dt).tan();
    let mut sections: Vec<Section> = (0..order / 2)
        .map(|j| {
            let c = (PI * (order - 1 - 2 * j) as f64 / (2 * order) as f64).cos();
            let d = 1.0 + 2.0 * k * c + k * k;
            let b0 = k * k / d;
            Section {
                b: [b0, 2.0 * b0, b0],
                a: [2.0 * (k * k - 1.0) / d, (1.0 - 2.0 * k * c + k * k) / d],
            }
        })
        .collect();
    if order % 2 == 1 {
        let b0 = k / (1.0 + k);
        sections.push(Section {
            b: [b0, b0, 0.0],
            a: [(k - 1.0) / (k + 1.0), 0.0],
        });
    }
    sections
}

/// One pass of the sections over `x` (transposed direct form II), each section's state started
/// at its steady state for the constant input `x[0]`, so a record that starts at rest starts
/// without a transient.
fn run_sections(sections: &[Section], x: &mut [f64]) {
    for s in sections {
        let [b0, b1, b2] = s.b;
        let [a1, a2] = s.a;
        let u = x.first().copied().unwrap_or(0.0);
        // Steady state for input u (output u at unit DC gain).
        let mut z2 = (b2 - a2) * u;
        let mut z1 = (b1 - a1) * u + z2;
        for v in x.iter_mut() {
            let xin = *v;
            let y = b0 * xin + z1;
            z1 = b1 * xin - a1 * y + z2;
            z2 = b2 * xin - a2 * y;
            *v = y;
        }
    }
}

/// The Butterworth low-pass of `order` and cut-off `fc_dt` (over the sample rate) run forward
/// then backward (zero phase, gain |H|²), on `v` extended at both ends by its odd reflection
/// (2 v₀ − v_k) over ten time constants of its least damped pole pair, 1/(2π f_c sin(π/2N))
/// samples each, which are cut off again: the filter's start-up (e^−10 of its size) stays out of
/// the record.
pub fn butterworth_zero_phase(v: &[f64], order: usize, fc_dt: f64) -> Vec<f64> {
    let n = v.len();
    if n < 2 {
        return v.to_vec();
    }
    let sections = butterworth_sections(order, fc_dt);
    use std::f64::consts::PI;
    let damping = (PI / (2 * order) as f64).sin();
    let settle = (10.0 / (2.0 * PI * fc_dt * damping)).ceil() as usize;
    let pad = (3 * (order + 1) + settle).min(n - 1);
    let mut x = Vec::with_capacity(n + 2 * pad);
    x.extend((1..=pad).rev().map(|k| 2.0 * v[0] - v[k]));
    x.extend_from_slice(v);
    x.extend((1..=pad).map(|k| 2.0 * v[n - 1] - v[n - 1 - k]));
    run_sections(&sections, &mut x);
    x.reverse();
    run_sections(&sections, &mut x);
    x.reverse();
    x[pad..pad + n].to_vec()
}

/// The Savitzky–Golay smoother of half-window `half` and polynomial `order` (Savitzky & Golay,
/// Anal. Chem. 36, 1627, 1964): the hat matrix H = A (AᵀA)⁻¹ Aᵀ of the window's Vandermonde
/// matrix A (rows (j − half)^p) maps a window's samples to its fitted polynomial's values; its
/// centre row is the convolution applied inside the series, its first and last rows give the
/// first and last `half` samples from the end windows' fits. Needs 2 half + 1 ≤ v.len() and
/// order < 2 half + 1.
pub fn savitzky_golay(v: &[f64], half: usize, order: usize) -> Vec<f64> {
    let m = 2 * half + 1;
    let n = v.len();
    if half == 0 || n < m {
        return v.to_vec();
    }
    let a = nalgebra::DMatrix::from_fn(m, order + 1, |i, p| {
        ((i as f64 - half as f64) / half as f64).powi(p as i32)
    });
    let hat = &a
        * (a.transpose() * &a)
            .try_inverse()
            .expect("a Vandermonde matrix of distinct points has full column rank")
        * a.transpose();
    let row = |i: usize, start: usize| (0..m).map(|j| hat[(i, j)] * v[start + j]).sum::<f64>();
    (0..n)
        .map(|k| {
            if k < half {
                row(k, 0)
            } else if k + half >= n {
                row(m - (n - k), n - m)
            } else {
                row(half, k - half)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Amplitude of the tone of `f_dt` cycles a sample in `y` over samples `range`, by least
    /// squares on its cosine and sine.
    fn tone_amplitude(y: &[f64], f_dt: f64, range: std::ops::Range<usize>) -> f64 {
        let c: Vec<f64> = range
            .clone()
            .map(|k| (2.0 * PI * f_dt * k as f64).cos())
            .collect();
        let s: Vec<f64> = range
            .clone()
            .map(|k| (2.0 * PI * f_dt * k as f64).sin())
            .collect();
        let yy: Vec<f64> = y[range].to_vec();
        let p = crate::numeric::least_squares(&[&c, &s], &yy).unwrap();
        p[0].hypot(p[1])
    }

    fn tone(f_dt: f64, n: usize) -> Vec<f64> {
        (0..n).map(|k| (2.0 * PI * f_dt * k as f64).sin()).collect()
    }

    #[test]
    fn butterworth_gain_at_the_cut_off_is_a_half_forward_backward() {
        // One pass has |H(f_c)| = 1/√2 exactly (the cut-off is prewarped), so forward and back
        // give 1/2, for every order; read in the middle of a long tone.
        let fc_dt = 0.01; // 100 kHz at 10 MHz
        let n = 20_000;
        for order in [1, 2, 3, 4, 6] {
            let y = butterworth_zero_phase(&tone(fc_dt, n), order, fc_dt);
            let g = tone_amplitude(&y, fc_dt, 5000..15_000);
            assert!((g - 0.5).abs() < 1e-4, "order {order}: gain {g}");
        }
    }

    #[test]
    fn a_tone_below_the_cut_off_passes_within_the_butterworth_ripple() {
        // Forward-backward gain 1/(1 + r^(2N)), r = tan(π f Δt)/tan(π f_c Δt): the ripple a tone
        // at f ≤ f_c/2 sees is at most r^(2N) ≤ 0.4 % for N = 4; the measured gain is that
        // within 1e-4.
        let (fc_dt, order, n) = (0.02, 4, 20_000);
        for f_dt in [0.002, 0.005, 0.01] {
            let y = butterworth_zero_phase(&tone(f_dt, n), order, fc_dt);
            let r = (PI * f_dt).tan() / (PI * fc_dt).tan();
            let expected = 1.0 / (1.0 + r.powi(2 * order as i32));
            let g = tone_amplitude(&y, f_dt, 5000..15_000);
            assert!(
                (g - expected).abs() < 1e-4,
                "f {f_dt}: gain {g} vs {expected}"
            );
            assert!(g > 1.0 - 0.0040, "f {f_dt}: ripple {}", 1.0 - g);
        }
    }

    #[test]
    fn a_tone_above_the_cut_off_is_stopped() {
        // At 4 f_c the forward-backward gain of order 4 is below 4^-8 ≈ 1.5e-5 (the bilinear
        // transform only lowers it further).
        let y = butterworth_zero_phase(&tone(0.04, 20_000), 4, 0.01);
        assert!(tone_amplitude(&y, 0.04, 5000..15_000) < 2e-5);
    }

    /// A sin² pulse of `width` samples centred on sample `centre`.
    fn pulse(n: usize, centre: f64, width: f64) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let x = (k as f64 - centre) / width + 0.5;
                if (0.0..=1.0).contains(&x) {
                    (PI * x).sin().powi(2)
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// Time of the peak of `y` in samples, the vertex of the parabola through its largest
    /// sample and its neighbours.
    fn peak_time(y: &[f64]) -> f64 {
        let k = crate::numeric::argmax(y);
        let (a, b, c) = (y[k - 1], y[k], y[k + 1]);
        k as f64 + 0.5 * (a - c) / (a - 2.0 * b + c)
    }

    #[test]
    fn every_filter_keeps_a_symmetric_pulse_peak_where_it_is() {
        // Zero phase: a symmetric pulse stays symmetric about its centre (the forward-backward
        // IIR, the symmetric FIRs), so its peak time is unmoved to rounding.
        let centre = 2000.3;
        let x = pulse(4000, centre, 300.0);
        for f in [
            Filter::MovingAverage {
                width_s: Some(21e-7),
            },
            Filter::Butterworth {
                order: 4,
                cutoff_hz: Some(1e5),
            },
            Filter::Butterworth {
                order: 3,
                cutoff_hz: Some(3e4),
            },
            Filter::SavitzkyGolay {
                window_s: 5e-6,
                order: 3,
            },
        ] {
            let y = f.apply(&x, 1e-7, "test").unwrap();
            let t = peak_time(&y);
            assert!((t - centre).abs() < 1e-3, "{f:?}: peak at {t}");
        }
    }

    #[test]
    fn savitzky_golay_keeps_polynomials_up_to_its_order_exactly() {
        // The least-squares polynomial of a polynomial of degree ≤ order is itself, at the
        // centre and at the ends alike.
        for order in 0..=5 {
            for degree in 0..=order {
                let v: Vec<f64> = (0..300)
                    .map(|k| {
                        let x = k as f64 / 100.0 - 1.2;
                        (0..=degree)
                            .map(|p| (p as f64 + 1.0) * x.powi(p as i32))
                            .sum()
                    })
                    .collect();
                let y = savitzky_golay(&v, 12, order);
                let worst = v
                    .iter()
                    .zip(&y)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-9, "order {order}, degree {degree}: {worst}");
            }
        }
        // A degree above the order is not kept (the test above is not vacuous).
        let v: Vec<f64> = (0..300).map(|k| (k as f64 / 100.0).powi(4)).collect();
        let y = savitzky_golay(&v, 12, 3);
        assert!(v.iter().zip(&y).any(|(a, b)| (a - b).abs() > 1e-7));
    }

    #[test]
    fn savitzky_golay_centre_weights_are_the_published_ones() {
        // Savitzky & Golay (1964), Table I: 5-point quadratic smoothing (−3, 12, 17, 12, −3)/35.
        let mut v = vec![0.0; 11];
        v[5] = 1.0;
        let y = savitzky_golay(&v, 2, 2);
        let table = [-3.0, 12.0, 17.0, 12.0, -3.0];
        for (j, w) in table.iter().enumerate() {
            assert!((y[3 + j] - w / 35.0).abs() < 1e-12, "{j}: {}", y[3 + j]);
        }
    }

    #[test]
    fn a_constant_and_a_ramp_pass_the_butterworth_unchanged() {
        // Unit DC gain: a constant passes to rounding. |H|² is even with unit value at DC, so a
        // ramp passes exactly in steady state; at the ends, the start-up on the odd reflection
        // (of size ≈ slope × group delay ≈ 1e-3 × 40 samples) has decayed by e^−10 within the
        // padding: 2e-6 at most.
        for order in [2, 3, 4] {
            let c = butterworth_zero_phase(&[2.5; 3000], order, 0.01);
            assert!(c.iter().all(|y| (y - 2.5).abs() < 1e-12), "order {order}");
            let v: Vec<f64> = (0..3000).map(|k| 1.0 + 1e-3 * k as f64).collect();
            let y = butterworth_zero_phase(&v, order, 0.01);
            let worst = v
                .iter()
                .zip(&y)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < 2e-6, "order {order}: {worst}");
        }
    }

    #[test]
    fn parameters_out_of_range_are_named() {
        let bad = [
            (
                Filter::Butterworth {
                    order: 0,
                    cutoff_hz: None,
                },
                "filter.order",
            ),
            (
                Filter::Butterworth {
                    order: 4,
                    cutoff_hz: Some(-1.0),
                },
                "filter.cutoff_hz",
            ),
            (
                Filter::SavitzkyGolay {
                    window_s: 0.0,
                    order: 3,
                },
                "filter.window_s",
            ),
        ];
        for (f, q) in bad {
            match f.validate("options") {
                Err(Error::Invalid { quantity, .. }) => assert_eq!(quantity, q),
                other => panic!("{f:?}: {other:?}"),
            }
        }
        // A cut-off at the Nyquist frequency, a window shorter than its order: known only with
        // the sample step.
        let v = vec![0.0; 100];
        let f = Filter::Butterworth {
            order: 4,
            cutoff_hz: Some(5e6),
        };
        assert!(f.apply(&v, 1e-7, "r").is_err());
        let f = Filter::SavitzkyGolay {
            window_s: 2e-7,
            order: 3,
        };
        assert!(f.apply(&v, 1e-7, "r").is_err());
    }

    #[test]
    fn the_band_cut_off_is_where_the_first_mode_has_become_a_surface_wave() {
        // The exact first mode at f a/c0 = 0.4 (docs/physics.md §7.9): 0.63 c0, within 11 % of
        // the Rayleigh velocity, for the bars' ν = 0.29–0.31; at half of it, still 0.94 c0 or
        // more (the dispersion correction's band).
        for nu in [0.29, 0.31] {
            let at = |fa| crate::dispersion::velocity_ratio_at_normalised_frequency(nu, fa);
            let rayleigh = crate::dispersion::rayleigh_velocity_ratio(nu);
            let c = at(BAND_CUTOFF_FA_OVER_C0);
            assert!((0.62..0.65).contains(&c), "ν {nu}: {c}");
            assert!(c < 1.11 * rayleigh, "ν {nu}: {c} vs c_R/c0 {rayleigh}");
            assert!(at(0.5 * BAND_CUTOFF_FA_OVER_C0) > 0.94, "ν {nu}");
        }
        // 204 kHz on the authors' bars (a = 9.525 mm, c0 = 4865.5 m/s).
        assert!((band_cutoff_hz(9.525e-3, 4865.5) - 2.043e5).abs() < 100.0);
    }
}

//! The numeric helpers every part of shpb shares, one copy each: argmax, linear resampling,
//! moving average, cumulative trapezoid, bisection, Illinois root bracketing, linear least squares
//! (nalgebra's SVD), the FFT phase shift (docs/physics.md §7 for where the reduction uses them),
//! the process's FFT plans and fast FFT lengths.

use nalgebra::{DMatrix, DVector, SVD};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// Index of the largest element (first one on ties; 0 for an empty slice).
pub fn argmax(values: &[f64]) -> usize {
    let mut best = 0;
    for (i, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = i;
        }
    }
    best
}

/// Smallest and largest of the values, (min, max); (+∞, −∞) when there are none.
pub fn min_max(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// Linear interpolation of (t, y) at the times `at` (end values held outside); `t` increasing.
pub fn resample(t: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let mut j = 0usize;
    at.iter()
        .map(|&x| {
            if x <= t[0] {
                return y[0];
            }
            if x >= t[t.len() - 1] {
                return y[y.len() - 1];
            }
            while t[j + 1] <= x {
                j += 1;
            }
            let w = (x - t[j]) / (t[j + 1] - t[j]);
            y[j] + w * (y[j + 1] - y[j])
        })
        .collect()
}

/// Centred moving average over 2 `half` + 1 samples (fewer at the ends); `half` = 0 copies.
pub fn moving_average(v: &[f64], half: usize) -> Vec<f64> {
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

/// Cumulative trapezoidal integral of samples `v` at step `dt`, with zero first value.
pub fn cumulative_trapezoid(v: &[f64], dt: f64) -> Vec<f64> {
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

/// The forward (or `inverse`) FFT of length `len` from one planner per process: rustfft's
/// planner keeps every plan it made, with its twiddle factors, so a length is planned once per
/// process instead of at every call (the same plan, so the same results bit for bit).
pub fn fft_plan(len: usize, inverse: bool) -> std::sync::Arc<dyn rustfft::Fft<f64>> {
    static PLANNER: std::sync::OnceLock<std::sync::Mutex<FftPlanner<f64>>> =
        std::sync::OnceLock::new();
    let mut planner = PLANNER
        .get_or_init(|| std::sync::Mutex::new(FftPlanner::new()))
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if inverse {
        planner.plan_fft_inverse(len)
    } else {
        planner.plan_fft_forward(len)
    }
}

/// Smallest length ≥ `min` (at least 1) whose only prime factors are 2, 3 and 5: a length
/// rustfft transforms with its fast radix kernels, for zero-padded transforms that need no power
/// of two (at most 1.25× `min` above 1000, against up to 2× for the next power of two).
pub fn fast_fft_length(min: usize) -> usize {
    let min = min.max(1);
    let mut best = min.next_power_of_two();
    let mut p5 = 1;
    while p5 < best {
        let mut p35 = p5;
        while p35 < best {
            // The smallest power-of-two multiple of p35 that reaches min.
            let mut n = p35;
            while n < min {
                n *= 2;
            }
            best = best.min(n);
            p35 *= 3;
        }
        p5 *= 5;
    }
    best
}

/// Bisection on `[lo, hi]`: halves the bracket at most `max_iter` times, keeping the upper half
/// when `root_above(mid)` and the lower one otherwise, and stops once `converged(lo, hi)`.
/// Returns the final bracket (lo, hi).
pub fn bisect(
    mut lo: f64,
    mut hi: f64,
    max_iter: usize,
    converged: impl Fn(f64, f64) -> bool,
    root_above: impl Fn(f64) -> bool,
) -> (f64, f64) {
    for _ in 0..max_iter {
        let mid = 0.5 * (lo + hi);
        if root_above(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
        if converged(lo, hi) {
            break;
        }
    }
    (lo, hi)
}

/// Root of g on `[lo, hi]` (g(lo) = `g_lo` and g(hi) = `g_hi` of opposite signs) by the plain
/// Illinois method (Dowell & Jarratt, BIT 11, 168 (1971)): the iterate u = (lo g_hi − hi g_lo)/
/// (g_hi − g_lo) replaces the end whose g has its sign, and the kept end's g is halved when the
/// same end moves twice in a row. Returns u as soon as g(u) = 0 or
/// `stop(u, previous u, lo, hi)` holds (judged on the bracket before u enters it), else the
/// bracket's midpoint after `max_iter` evaluations. Unlike [`illinois`] it has no bisection
/// safeguard, so a stop on the iterate's own motion ends the superlinear run without waiting
/// for the far side of the bracket.
pub fn illinois_until(
    mut lo: f64,
    mut hi: f64,
    mut g_lo: f64,
    mut g_hi: f64,
    max_iter: usize,
    stop: impl Fn(f64, f64, f64, f64) -> bool,
    g: impl Fn(f64) -> f64,
) -> f64 {
    let (mut side, mut previous) = (0, f64::NAN);
    for _ in 0..max_iter {
        let u = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        let gu = g(u);
        if gu == 0.0 || stop(u, previous, lo, hi) {
            return u;
        }
        previous = u;
        if gu.signum() == g_lo.signum() {
            lo = u;
            g_lo = gu;
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        } else {
            hi = u;
            g_hi = gu;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (lo + hi)
}

/// Root of g on `[lo, hi]` with g(lo) = `g_lo` > 0 ≥ g(hi) = `g_hi` by the Illinois method
/// (regula falsi that halves the kept end's value when the same end moves twice in a row;
/// Dowell & Jarratt, BIT 11, 168 (1971)), safeguarded by a bisection step whenever the bracket has
/// not halved over three steps. Stops once `converged(lo, hi)`, at an exact zero (then lo = hi),
/// or after `max_iter` evaluations of g. Returns the final bracket (lo, hi).
pub fn illinois(
    mut lo: f64,
    mut hi: f64,
    mut g_lo: f64,
    mut g_hi: f64,
    max_iter: usize,
    converged: impl Fn(f64, f64) -> bool,
    g: impl Fn(f64) -> f64,
) -> (f64, f64) {
    // Which end the last step moved (−1 lo, +1 hi, 0 none), and the width three steps ago.
    let mut last_side = 0;
    let mut widths = [hi - lo; 3];
    for k in 0..max_iter {
        let width = hi - lo;
        let bisecting = width > 0.5 * widths[k % 3];
        widths[k % 3] = width;
        let mut x = if bisecting {
            0.5 * (lo + hi)
        } else {
            lo + width * (g_lo / (g_lo - g_hi))
        };
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let gx = g(x);
        if gx > 0.0 {
            lo = x;
            g_lo = gx;
            if last_side == -1 {
                g_hi *= 0.5;
            }
            last_side = -1;
        } else if gx < 0.0 {
            hi = x;
            g_hi = gx;
            if last_side == 1 {
                g_lo *= 0.5;
            }
            last_side = 1;
        } else {
            return (x, x);
        }
        if converged(lo, hi) {
            break;
        }
    }
    (lo, hi)
}

/// Root of g on `[lo, hi]` where g(lo) = `g_lo` > 0 ≥ g(hi) = `g_hi` and g crosses zero once, by
/// the secant method kept inside the bracket (a step that would leave it, or a bracket that has
/// not halved over three evaluations, bisects instead): stops at an exact zero, once the
/// bracket is within `rel` of its larger end's magnitude (its midpoint), or once a secant step
/// is within `rel`/4 of the iterate's magnitude (the step's end: the superlinear iteration is
/// then well inside `rel`), or after `max_iter` evaluations (the bracket's midpoint). For a
/// nearly linear g (the implicit contact solve, docs/physics.md §6.6) the first secant,
/// the regula falsi point of the bracket, is already close, and two or three evaluations do.
pub fn secant_in_bracket(
    lo: f64,
    hi: f64,
    g_lo: f64,
    g_hi: f64,
    max_iter: usize,
    rel: f64,
    g: impl Fn(f64) -> f64,
) -> f64 {
    let (mut a, mut b) = (lo, hi);
    // The two latest points, newest last (the bracket's ends to start: regula falsi).
    let (mut x0, mut g0, mut x1, mut g1) = (lo, g_lo, hi, g_hi);
    let mut widths = [b - a; 3];
    for k in 0..max_iter {
        let width = b - a;
        let slow = k >= 3 && width > 0.5 * widths[k % 3];
        widths[k % 3] = width;
        let secant = x1 - g1 * (x1 - x0) / (g1 - g0);
        let x = if !slow && secant > a && secant < b {
            if (secant - x1).abs() <= 0.25 * rel * secant.abs().max(x1.abs()) {
                return secant;
            }
            secant
        } else {
            0.5 * (a + b)
        };
        let gx = g(x);
        if gx > 0.0 {
            a = x;
        } else if gx < 0.0 {
            b = x;
        } else {
            return x;
        }
        if b - a <= rel * a.abs().max(b.abs()) {
            break;
        }
        (x0, g0, x1, g1) = (x1, g1, x, gx);
    }
    0.5 * (a + b)
}

/// Linear least squares by SVD: the β minimising ‖Σⱼ βⱼ `columns[j]` − `y`‖₂, or None when the
/// columns are rank-deficient (or any input is not finite).
///
/// Each column is a regressor sampled at the points of `y` (a column of ones gives an intercept)
/// and must have `y`'s length. The columns are scaled to unit norm before the decomposition, so
/// the rank test — a singular value at most max(rows, columns) · ε times the largest, NumPy's
/// `matrix_rank` rule — does not depend on their units; fewer rows than columns is
/// rank-deficient.
pub fn least_squares(columns: &[&[f64]], y: &[f64]) -> Option<Vec<f64>> {
    let (n, p) = (y.len(), columns.len());
    assert!(
        columns.iter().all(|c| c.len() == n),
        "least_squares: every column needs y's length {n}"
    );
    if p == 0
        || n < p
        || !y
            .iter()
            .chain(columns.iter().copied().flatten())
            .all(|v| v.is_finite())
    {
        return None;
    }
    let norms: Vec<f64> = columns
        .iter()
        .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt())
        .collect();
    if norms.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return None;
    }
    let a = DMatrix::from_fn(n, p, |i, j| columns[j][i] / norms[j]);
    // Finite input converges in a few sweeps per singular value; the cap only guards the loop.
    let svd = SVD::try_new_unordered(a, true, true, 5.0 * f64::EPSILON, 100 * p)?;
    let s = &svd.singular_values;
    let tol = n.max(p) as f64 * f64::EPSILON * s.max();
    if s.iter().any(|&v| v <= tol) {
        return None;
    }
    let beta = svd.solve(&DVector::from_column_slice(y), tol).ok()?;
    Some(beta.iter().zip(&norms).map(|(b, s)| b / s).collect())
}

/// Delays every Fourier component of `x` (step `dt`) at frequency f by `delay(f)` seconds
/// (spectrum factor exp(−2πi f delay(|f|))). The segment is closed into a smooth periodic signal
/// by a raised-cosine bridge from its last value back to its first over a padding at least as
/// long as the segment (power-of-two FFT length), so no jump is created at the wrap.
pub fn phase_shift(x: &[f64], dt: f64, delay: impl Fn(f64) -> f64) -> Vec<f64> {
    spectral_filter(x, dt, |bin| (delay(bin.frequency_hz), 1.0))
}

/// One bin of the FFT [`spectral_filter`] applies its factor to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FftBin {
    /// |k|, from 0 to m/2 (negative frequencies share their positive twin's bin).
    pub index: usize,
    /// FFT length m.
    pub length: usize,
    /// |f| = |k|/(m dt), Hz.
    pub frequency_hz: f64,
}

/// [`phase_shift`] with a real gain as well: the component of bin b is multiplied by
/// `gain · exp(−2πi f delay)` where `(delay, gain) = factor(b)` (docs/physics.md §7.9, the
/// Tyas–Pope amplitude factors). With gain 1 it is exactly [`phase_shift`].
pub fn spectral_filter(
    x: &[f64],
    dt: f64,
    mut factor: impl FnMut(FftBin) -> (f64, f64),
) -> Vec<f64> {
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
    fft_plan(m, false).process(&mut buf);
    let df = 1.0 / (m as f64 * dt);
    // The factors of the bins k = 0..=m/2; a negative frequency −k takes its twin's conjugate
    // (the same (delay, gain) and the phase negated: the same numbers a direct evaluation gives).
    let half = m / 2;
    let factors: Vec<Complex<f64>> = (0..=half)
        .map(|k| {
            let f = k as f64 * df;
            let (delay, gain) = factor(FftBin {
                index: k,
                length: m,
                frequency_hz: f,
            });
            let phase = -2.0 * std::f64::consts::PI * f * delay;
            if k == half {
                // Nyquist bin: keep the signal real.
                Complex::new(gain * phase.cos(), 0.0)
            } else {
                Complex::from_polar(gain, phase)
            }
        })
        .collect();
    for (k, z) in buf.iter_mut().enumerate() {
        *z *= if k <= half {
            factors[k]
        } else {
            factors[m - k].conj()
        };
    }
    fft_plan(m, true).process(&mut buf);
    buf.iter().take(n).map(|z| z.re / m as f64).collect()
}

/// A factorised symmetric tridiagonal matrix (Thomas algorithm): the Love rod's mass operator
/// (docs/physics.md §6.3) and a cylinder's radial-inertia mass (§6.12).
#[derive(Debug, Clone, Default)]
pub(crate) struct Tridiagonal {
    /// Off-diagonal A_{i,i+1}.
    off: Vec<f64>,
    /// Modified upper coefficients c'_i = A_{i,i+1}/den_i.
    cprime: Vec<f64>,
    /// 1/den_i of the forward sweep.
    inv_den: Vec<f64>,
}

impl Tridiagonal {
    /// Factorises the matrix with diagonal `diag` and off-diagonal `off` (diagonally dominant here).
    pub(crate) fn factor(diag: &[f64], off: Vec<f64>) -> Tridiagonal {
        let n = diag.len();
        let mut cprime = vec![0.0; n.saturating_sub(1)];
        let mut inv_den = vec![0.0; n];
        let mut prev_c = 0.0;
        for i in 0..n {
            let den = if i == 0 {
                diag[0]
            } else {
                diag[i] - off[i - 1] * prev_c
            };
            inv_den[i] = 1.0 / den;
            if i + 1 < n {
                prev_c = off[i] * inv_den[i];
                cprime[i] = prev_c;
            }
        }
        Tridiagonal {
            off,
            cprime,
            inv_den,
        }
    }

    /// Solves A x = b in place (b in, x out).
    pub(crate) fn solve(&self, x: &mut [f64]) {
        let n = x.len();
        x[0] *= self.inv_den[0];
        for i in 1..n {
            x[i] = (x[i] - self.off[i - 1] * x[i - 1]) * self.inv_den[i];
        }
        for i in (0..n - 1).rev() {
            x[i] -= self.cprime[i] * x[i + 1];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Illinois converges on smooth, kinked and discontinuous decreasing functions to the same
    /// bracket tolerance as bisection, in far fewer evaluations on the smooth ones.
    #[test]
    fn illinois_brackets_the_root_like_bisection_in_fewer_steps() {
        let cases: [(&dyn Fn(f64) -> f64, f64); 4] = [
            (
                &|f: f64| 10.0 * (1.0 - f / 7.0).powf(1.5).max(0.0) - f,
                10.0,
            ),
            (&|f: f64| 5.0 - f * f * f, 5.0),
            (&|f: f64| if f < 2.0 { 4.0 - f } else { 3.0 - 1.4 * f }, 4.0),
            (&|f: f64| if f < 1.5 { 3.0 - f } else { 0.5 - f }, 3.0),
        ];
        for (law, hi) in cases {
            let calls = std::cell::Cell::new(0);
            let counted = |f: f64| {
                calls.set(calls.get() + 1);
                law(f)
            };
            let tol = |lo: f64, hi: f64| hi - lo <= 1e-12 * hi;
            let (a, b) = illinois(0.0, hi, law(0.0), law(hi), 100, tol, counted);
            assert!(tol(a, b) && law(a) >= 0.0 && law(b) <= 0.0, "{a} {b}");
            let (c, d) = bisect(0.0, hi, 100, tol, |f| law(f) > 0.0);
            assert!((0.5 * (a + b) - 0.5 * (c + d)).abs() <= 1e-12 * d);
            assert!(calls.get() <= 25, "{} evaluations", calls.get());
        }
    }

    /// The bracketed secant finds the one crossing of smooth, kinked and discontinuous decreasing
    /// functions to the tolerance bisection reaches, and a nearly linear one (the contact solve's
    /// g, slope ≈ −1) in at most three evaluations.
    #[test]
    fn the_bracketed_secant_finds_the_crossing_bisection_finds() {
        type Law<'a> = &'a dyn Fn(f64) -> f64;
        let cases: [(Law, f64, usize); 5] = [
            (
                &|f: f64| 10.0 * (1.0 - f / 7.0).powf(1.5).max(0.0) - f,
                10.0,
                12,
            ),
            (&|f: f64| 5.0 - f * f * f, 5.0, 20),
            (
                &|f: f64| if f < 2.0 { 4.0 - f } else { 3.0 - 1.4 * f },
                4.0,
                20,
            ),
            (&|f: f64| if f < 1.5 { 3.0 - f } else { 0.5 - f }, 3.0, 60),
            (
                &|f: f64| 1e4 * (1.0 - f / 3e5).max(0.0).powf(1.5) - f,
                1e4,
                3,
            ),
        ];
        for (g, hi, most) in cases {
            let calls = std::cell::Cell::new(0);
            let counted = |f: f64| {
                calls.set(calls.get() + 1);
                g(f)
            };
            let x = secant_in_bracket(0.0, hi, g(0.0), g(hi), 100, 1e-12, counted);
            let (c, d) = bisect(0.0, hi, 200, |lo, hi| hi - lo <= 1e-13 * hi, |f| g(f) > 0.0);
            assert!((x - 0.5 * (c + d)).abs() <= 1e-12 * d, "{x} against {c}");
            assert!(calls.get() <= most, "{} evaluations", calls.get());
        }
    }

    #[test]
    fn min_max_is_the_extent_and_empty_is_inverted() {
        assert_eq!(min_max([3.0, -1.5, 2.0]), (-1.5, 3.0));
        assert_eq!(min_max([4.0]), (4.0, 4.0));
        assert_eq!(
            min_max(std::iter::empty()),
            (f64::INFINITY, f64::NEG_INFINITY)
        );
    }

    #[test]
    fn argmax_takes_the_first_of_ties_and_zero_for_empty() {
        assert_eq!(argmax(&[1.0, 3.0, 2.0, 3.0]), 1);
        assert_eq!(argmax(&[]), 0);
        assert_eq!(argmax(&[-2.0, -1.0]), 1);
    }

    #[test]
    fn resample_is_exact_on_a_line_and_holds_the_ends() {
        let t = [0.0, 1.0, 3.0];
        let y = [1.0, 3.0, 7.0]; // y = 2t + 1
        let r = resample(&t, &y, &[-1.0, 0.5, 2.0, 3.0, 9.0]);
        assert_eq!(r, vec![1.0, 2.0, 5.0, 7.0, 7.0]);
    }

    #[test]
    fn moving_average_keeps_a_line_inside_and_averages_fewer_samples_at_the_ends() {
        let v: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let m = moving_average(&v, 2);
        for k in 2..8 {
            assert_relative_eq!(m[k], v[k], epsilon = 1e-12);
        }
        assert_relative_eq!(m[0], 1.0); // (0 + 1 + 2) / 3
        assert_eq!(moving_average(&v, 0), v);
    }

    #[test]
    fn trapezoid_integrates_a_line_exactly() {
        let dt = 0.1;
        let v: Vec<f64> = (0..11).map(|k| 3.0 * k as f64 * dt).collect(); // 3t
        let i = cumulative_trapezoid(&v, dt);
        assert_eq!(i[0], 0.0);
        assert_relative_eq!(i[10], 1.5, epsilon = 1e-12); // ∫0^1 3t dt
    }

    #[test]
    fn fast_fft_lengths_are_the_smallest_5_smooth_ones() {
        let smooth = |mut n: usize| {
            for p in [2, 3, 5] {
                while n.is_multiple_of(p) {
                    n /= p;
                }
            }
            n == 1
        };
        for min in (0..3000).chain([7313, 65537, 1 << 20]) {
            let n = fast_fft_length(min);
            assert!(n >= min.max(1) && smooth(n), "{min}: {n}");
            assert!(
                (min.max(1)..n).all(|m| !smooth(m)),
                "{min}: {n} is not the smallest"
            );
        }
        assert_eq!(fast_fft_length(7313), 7500);
    }

    #[test]
    fn bisection_finds_sqrt2_to_the_tolerance() {
        let (lo, hi) = bisect(0.0, 2.0, 200, |lo, hi| hi - lo <= 1e-14, |x| x * x < 2.0);
        assert!(hi - lo <= 1e-14);
        assert_relative_eq!(0.5 * (lo + hi), 2f64.sqrt(), epsilon = 1e-13);
    }

    #[test]
    fn least_squares_recovers_an_exact_linear_model() {
        // y = 2 − 3 x + 0.5 x² sampled without noise: the fit returns the coefficients.
        let x: Vec<f64> = (0..12).map(|k| 0.25 * k as f64 - 1.0).collect();
        let ones = vec![1.0; x.len()];
        let x2: Vec<f64> = x.iter().map(|v| v * v).collect();
        let y: Vec<f64> = x.iter().map(|v| 2.0 - 3.0 * v + 0.5 * v * v).collect();
        let beta = least_squares(&[&ones, &x, &x2], &y).expect("full rank");
        for (b, want) in beta.iter().zip([2.0, -3.0, 0.5]) {
            assert_relative_eq!(*b, want, epsilon = 1e-13);
        }
        // Square and exactly determined: the solution of the system (columns in Pa-sized units).
        let p = [68_947.6, 103_421.4];
        let beta = least_squares(&[&p, &[1.0, 1.0]], &[20.0, 45.0]).expect("full rank");
        assert_relative_eq!(beta[0] * p[0] + beta[1], 20.0, max_relative = 1e-13);
        assert_relative_eq!(beta[0] * p[1] + beta[1], 45.0, max_relative = 1e-13);
    }

    #[test]
    fn least_squares_refuses_rank_deficient_columns() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let y = [1.0, 0.0, 2.0, 5.0];
        let twice: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        assert_eq!(least_squares(&[&x, &twice], &y), None); // collinear
        assert_eq!(least_squares(&[&x, &[0.0; 4]], &y), None); // a zero column
        assert_eq!(least_squares(&[&x[..1], &[1.0]], &y[..1]), None); // fewer rows than columns
        assert_eq!(least_squares(&[], &y), None);
        assert_eq!(least_squares(&[&x], &[1.0, f64::NAN, 0.0, 0.0]), None);
        // Independent columns of very different sizes are not rank-deficient.
        assert!(least_squares(&[&[1e5, 2e5, 3e5, 4e5], &[1e-9, 1e-9, 1e-9, 1.1e-9]], &y).is_some());
    }

    #[test]
    fn least_squares_matches_the_normal_equations_on_noisy_data() {
        // 40 points of a quadratic in x ∈ [1, 3] plus deterministic ±0.05 noise.
        let x: Vec<f64> = (0..40).map(|k| 1.0 + 0.05 * k as f64).collect();
        let ones = vec![1.0; x.len()];
        let x2: Vec<f64> = x.iter().map(|v| v * v).collect();
        let y: Vec<f64> = (0..40)
            .map(|k| {
                let noise = 0.05 * ((k * 37 % 17) as f64 / 8.0 - 1.0);
                1.5 + 0.7 * x[k] - 0.2 * x2[k] + noise
            })
            .collect();
        let cols: [&[f64]; 3] = [&ones, &x, &x2];
        let beta = least_squares(&cols, &y).expect("full rank");
        // Normal equations (AᵀA) β = Aᵀy, by Cholesky.
        let a = DMatrix::from_fn(40, 3, |i, j| cols[j][i]);
        let ata = a.transpose() * &a;
        let aty = a.transpose() * DVector::from_column_slice(&y);
        let normal = ata.cholesky().expect("SPD").solve(&aty);
        // Forming AᵀA squares the condition number: the normal equations' relative error is of
        // order κ(A)² ε (Golub & Van Loan §5.3), the SVD's κ(A) ε, so they agree to a few κ² ε.
        let sv = a.singular_values();
        let kappa = sv.max() / sv.min();
        let tol = 10.0 * kappa * kappa * f64::EPSILON;
        assert!(
            tol < 1e-8,
            "κ = {kappa}: the test case is well enough conditioned"
        );
        let diff = (DVector::from_vec(beta.clone()) - &normal).norm() / normal.norm();
        assert!(diff <= tol, "relative difference {diff:e} > {tol:e}");
        // And it is the minimum: the residual is orthogonal to every column.
        let r: Vec<f64> = (0..40)
            .map(|i| y[i] - (0..3).map(|j| beta[j] * cols[j][i]).sum::<f64>())
            .collect();
        for c in cols {
            let dot: f64 = c.iter().zip(&r).map(|(a, b)| a * b).sum();
            let scale = c.iter().map(|v| v * v).sum::<f64>().sqrt()
                * y.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!(dot.abs() <= 1e-12 * scale, "Aᵀr = {dot:e}");
        }
    }

    #[test]
    fn a_constant_delay_moves_a_smooth_pulse_by_that_delay() {
        // A Gaussian delayed by 20 samples through the FFT equals the Gaussian 20 samples later.
        let dt = 1e-6;
        let g = |k: f64| (-((k - 100.0) / 12.0).powi(2)).exp();
        let x: Vec<f64> = (0..400).map(|k| g(k as f64)).collect();
        let y = phase_shift(&x, dt, |_| 20.0 * dt);
        for (k, &yk) in y.iter().enumerate().take(300) {
            assert!((yk - g(k as f64 - 20.0)).abs() < 1e-9, "sample {k}");
        }
        assert!(phase_shift(&[], dt, |_| 0.0).is_empty());
    }
}

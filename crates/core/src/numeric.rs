//! The numeric helpers every part of shpb shares, one copy each: argmax, linear resampling,
//! moving average, cumulative trapezoid, bisection and the FFT phase shift (docs/physics.md §7
//! for where the reduction uses them).

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

/// Delays every Fourier component of `x` (step `dt`) at frequency f by `delay(f)` seconds
/// (spectrum factor exp(−2πi f delay(|f|))). The segment is closed into a smooth periodic signal
/// by a raised-cosine bridge from its last value back to its first over a padding at least as
/// long as the segment (power-of-two FFT length), so no jump is created at the wrap.
pub fn phase_shift(x: &[f64], dt: f64, delay: impl Fn(f64) -> f64) -> Vec<f64> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

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
    fn bisection_finds_sqrt2_to_the_tolerance() {
        let (lo, hi) = bisect(0.0, 2.0, 200, |lo, hi| hi - lo <= 1e-14, |x| x * x < 2.0);
        assert!(hi - lo <= 1e-14);
        assert_relative_eq!(0.5 * (lo + hi), 2f64.sqrt(), epsilon = 1e-13);
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

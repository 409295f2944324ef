//! The exact first longitudinal mode of a solid elastic cylinder (Pochhammer 1876, Chree 1889;
//! docs/physics.md §7.9): its phase velocity c(f) for any Poisson's ratio 0 < ν < 0.5, the
//! Tyas–Pope amplitude factors M1 and M2, and the mode tabulated once per ν ([`ModeTable`]) for
//! the reduction's FFT bins and the dispersive delay lines.
//!
//! # The frequency equation
//!
//! For axisymmetric waves `exp(i(kz − ωt))` in a free cylinder of radius a (in the form of
//! K. F. Graff, *Wave Motion in Elastic Solids* (1975), §8.2), with
//! `α² = ω²/cL² − k²` and `β² = ω²/cT² − k²`:
//!
//! ```text
//! (2α/a)(β² + k²) J1(αa) J1(βa) − (β² − k²)² J0(αa) J1(βa) − 4k²αβ J1(αa) J0(βa) = 0
//! ```
//!
//! On the first branch c < c0 < cL, so α² < 0 always, and β² changes sign where c crosses cT.
//! The code writes the equation with the two even entire functions
//! `C0(s) = J0(√s)` and `C1(s) = J1(√s)/√s` (for s < 0: `I0(√−s)` and `I1(√−s)/√−s`, DLMF
//! 10.27.6), which are real for either sign of `s = α²a²` or `β²a²`. Dividing by βa:
//!
//! ```text
//! F = 2X(Y + K²) C1(X) C1(Y) − (Y − K²)² C0(X) C1(Y) − 4K² X C1(X) C0(Y),
//! X = α²a², Y = β²a², K = ka
//! ```
//!
//! Each term holds one function of X and one of Y, so the modified Bessel functions can be
//! scaled by `exp(−√−s)` (no overflow at any frequency) without changing the sign of F. At
//! k → 0 F's leading term vanishes at c = c0 = √(E/ρ); at k → ∞ it becomes the Rayleigh
//! equation, c → cR.
//!
//! # The root
//!
//! At a fixed wavenumber (or a fixed frequency) the first mode is the slowest root c > 0: the
//! first branch lies below every other. The solver scans c/c0 upwards from 0.9 cR/c0 in steps of
//! 0.005 (the next root, on the second branch, is never closer than cT − cR ≥ 0.025 c0 for
//! 0 < ν < 0.5) and bisects the first sign change to 1e-14.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

use crate::error::{Error, Result};

/// Switch from the power series to Hankel's expansion for J0, J1 (DLMF 10.2.2 / 10.17.3).
const J_SERIES_LIMIT: f64 = 12.0;
/// Switch from the power series to the large-argument expansion for I0, I1 (DLMF 10.25.2 /
/// 10.40.1).
const I_SERIES_LIMIT: f64 = 25.0;

/// `Σ_k (sign·x²/4)^k / (k! (k+n)!)` (the series of DLMF 10.2.2, 10.25.2 without `(x/2)^n`).
fn bessel_series(x: f64, n: u32, sign: f64) -> f64 {
    let q = sign * x * x / 4.0;
    let mut term = 1.0 / (1..=n).map(f64::from).product::<f64>();
    let mut sum = term;
    for k in 1..200 {
        term *= q / (k as f64 * (k + n) as f64);
        sum += term;
        if term.abs() <= 1e-17 * sum.abs() {
            break;
        }
    }
    sum
}

/// Hankel's coefficients summed: `(P, Q)` of DLMF 10.17.3 for order n at x (x ≥ 12).
fn hankel_pq(x: f64, n: u32) -> (f64, f64) {
    let mu = 4.0 * f64::from(n * n);
    let (mut p, mut q) = (1.0, 0.0);
    let mut a = 1.0; // a_k(n) / x^k
    let mut last = f64::INFINITY;
    for k in 1..60 {
        let odd = (2 * k - 1) as f64;
        a *= (mu - odd * odd) / (k as f64 * 8.0 * x);
        if a.abs() >= last || a == 0.0 {
            break;
        }
        last = a.abs();
        // k odd → Q with sign (−1)^((k−1)/2); k even → P with sign (−1)^(k/2).
        if k % 2 == 1 {
            q += if (k / 2) % 2 == 0 { a } else { -a };
        } else {
            p += if (k / 2) % 2 == 0 { a } else { -a };
        }
        if a.abs() < 1e-17 {
            break;
        }
    }
    (p, q)
}

/// Bessel function J0(x) (power series DLMF 10.2.2 for |x| ≤ 12, Hankel's expansion DLMF
/// 10.17.3 beyond).
pub fn bessel_j0(x: f64) -> f64 {
    let x = x.abs();
    if x <= J_SERIES_LIMIT {
        return bessel_series(x, 0, -1.0);
    }
    let (p, q) = hankel_pq(x, 0);
    let w = x - PI / 4.0;
    (2.0 / (PI * x)).sqrt() * (p * w.cos() - q * w.sin())
}

/// Bessel function J1(x) (DLMF 10.2.2 for |x| ≤ 12, Hankel's expansion DLMF 10.17.3 beyond).
pub fn bessel_j1(x: f64) -> f64 {
    let s = x.signum();
    let x = x.abs();
    if x <= J_SERIES_LIMIT {
        return s * 0.5 * x * bessel_series(x, 1, -1.0);
    }
    let (p, q) = hankel_pq(x, 1);
    let w = x - 3.0 * PI / 4.0;
    s * (2.0 / (PI * x)).sqrt() * (p * w.cos() - q * w.sin())
}

/// Large-argument sum `Σ (−1)^k a_k(n)/x^k` of DLMF 10.40.1 (x ≥ 25).
fn modified_asymptotic(x: f64, n: u32) -> f64 {
    let mu = 4.0 * f64::from(n * n);
    let (mut sum, mut a, mut last) = (1.0, 1.0, f64::INFINITY);
    for k in 1..60 {
        let odd = (2 * k - 1) as f64;
        a *= -(mu - odd * odd) / (k as f64 * 8.0 * x);
        if a.abs() >= last || a == 0.0 {
            break;
        }
        last = a.abs();
        sum += a;
        if a.abs() < 1e-17 {
            break;
        }
    }
    sum / (2.0 * PI * x).sqrt()
}

/// Scaled modified Bessel function e^−|x| I0(x) (DLMF 10.25.2 for |x| ≤ 25, DLMF 10.40.1
/// beyond).
pub fn bessel_i0_scaled(x: f64) -> f64 {
    let x = x.abs();
    if x <= I_SERIES_LIMIT {
        return (-x).exp() * bessel_series(x, 0, 1.0);
    }
    modified_asymptotic(x, 0)
}

/// Scaled modified Bessel function e^−|x| I1(x) (DLMF 10.25.2 for |x| ≤ 25, DLMF 10.40.1
/// beyond).
pub fn bessel_i1_scaled(x: f64) -> f64 {
    let s = x.signum();
    let x = x.abs();
    if x <= I_SERIES_LIMIT {
        return s * (-x).exp() * 0.5 * x * bessel_series(x, 1, 1.0);
    }
    s * modified_asymptotic(x, 1)
}

/// `(C0(s), C1(s))` of the module docs: `J0(√s)`, `J1(√s)/√s` for s ≥ 0, and
/// `I0(√−s)`, `I1(√−s)/√−s` scaled by `e^−√−s` for s < 0 (DLMF 10.27.6).
fn even_bessel(s: f64) -> (f64, f64) {
    if s >= 0.0 {
        let z = s.sqrt();
        if z <= J_SERIES_LIMIT {
            (bessel_series(z, 0, -1.0), 0.5 * bessel_series(z, 1, -1.0))
        } else {
            (bessel_j0(z), bessel_j1(z) / z)
        }
    } else {
        let z = (-s).sqrt();
        if z <= I_SERIES_LIMIT {
            let e = (-z).exp();
            (
                e * bessel_series(z, 0, 1.0),
                e * 0.5 * bessel_series(z, 1, 1.0),
            )
        } else {
            (bessel_i0_scaled(z), bessel_i1_scaled(z) / z)
        }
    }
}

/// Squared wave-speed ratios of an isotropic solid: `(c0²/cL², c0²/cT²)` =
/// `((1 + ν)(1 − 2ν)/(1 − ν), 2(1 + ν))`.
fn speed_ratios_squared(poisson_ratio: f64) -> (f64, f64) {
    let nu = poisson_ratio;
    ((1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu), 2.0 * (1.0 + nu))
}

/// The Pochhammer frequency function F of the module docs, divided by K⁴, at normalised
/// wavenumber `ka` and velocity ratio `x = c/c0` (Graff 1975, §8.2).
pub fn frequency_function(poisson_ratio: f64, ka: f64, velocity_ratio: f64) -> f64 {
    let (l2, t2) = speed_ratios_squared(poisson_ratio);
    let x2 = velocity_ratio * velocity_ratio;
    let k2 = ka * ka;
    let (a2, b2) = (k2 * (x2 * l2 - 1.0), k2 * (x2 * t2 - 1.0));
    let (c0x, c1x) = even_bessel(a2);
    let (c0y, c1y) = even_bessel(b2);
    (2.0 * a2 * (b2 + k2) * c1x * c1y
        - (b2 - k2) * (b2 - k2) * c0x * c1y
        - 4.0 * k2 * a2 * c1x * c0y)
        / (k2 * k2)
}

/// Rayleigh surface-wave speed over c0, the first mode's limit at high frequency: the root
/// ξ = c/cT in (0.5, 1) of `(2 − ξ²)² = 4 √(1 − ξ² cT²/cL²) √(1 − ξ²)` (Lord Rayleigh,
/// *Proc. Lond. Math. Soc.* 17, 4 (1885)).
pub fn rayleigh_velocity_ratio(poisson_ratio: f64) -> f64 {
    let (l2, t2) = speed_ratios_squared(poisson_ratio);
    let r = l2 / t2; // cT²/cL²
    let f = |xi: f64| {
        let x2 = xi * xi;
        (2.0 - x2).powi(2) - 4.0 * (1.0 - r * x2).sqrt() * (1.0 - x2).sqrt()
    };
    let (mut lo, mut hi) = (0.5, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-16 {
            break;
        }
    }
    0.5 * (lo + hi) / t2.sqrt()
}

/// The first sign change of `g` scanning upwards from `lo` to 1 (steps ≤ 0.005), bisected to
/// 1e-14; 1 if there is none (the long-wave limit within rounding).
fn first_root(lo: f64, g: impl Fn(f64) -> f64) -> f64 {
    let steps = ((1.0 - lo) / 0.005).ceil().max(1.0) as usize;
    let h = (1.0 - lo) / steps as f64;
    let mut a = lo;
    let mut ga = g(a);
    for i in 1..=steps {
        let b = if i == steps { 1.0 } else { lo + i as f64 * h };
        let gb = g(b);
        if ga == 0.0 {
            return a;
        }
        if ga.signum() != gb.signum() {
            let (mut a, mut b, ga0) = (a, b, ga);
            while b - a > 1e-14 {
                let m = 0.5 * (a + b);
                if g(m).signum() == ga0.signum() {
                    a = m;
                } else {
                    b = m;
                }
            }
            return 0.5 * (a + b);
        }
        a = b;
        ga = gb;
    }
    1.0
}

/// Below this a/Λ (or f a/c0) the solver uses Rayleigh's long-wave limit
/// `c/c0 = 1 − ν²π²(a/Λ)²` (the Rayleigh–Love rod, docs/physics.md §6.3), whose error is
/// O((a/Λ)⁴) < 1e-16.
const LONG_WAVE_LIMIT: f64 = 1e-4;

/// First-mode phase velocity over c0 at radius over wavelength `a/Λ` (exact Pochhammer–Chree
/// root, module docs).
pub fn velocity_ratio_at_radius_over_wavelength(poisson_ratio: f64, a_over_lambda: f64) -> f64 {
    let y = a_over_lambda.abs();
    if y < LONG_WAVE_LIMIT {
        return 1.0 - (poisson_ratio * PI * y).powi(2);
    }
    let ka = 2.0 * PI * y;
    let lo = 0.9 * rayleigh_velocity_ratio(poisson_ratio);
    first_root(lo, |x| frequency_function(poisson_ratio, ka, x))
}

/// First-mode phase velocity over c0 at normalised frequency `f a / c0` (exact Pochhammer–Chree
/// root at fixed frequency: ka = 2π (f a/c0) / (c/c0)).
pub fn velocity_ratio_at_normalised_frequency(poisson_ratio: f64, fa_over_c0: f64) -> f64 {
    let w = fa_over_c0.abs();
    if w < LONG_WAVE_LIMIT {
        return 1.0 - (poisson_ratio * PI * w).powi(2);
    }
    let lo = 0.9 * rayleigh_velocity_ratio(poisson_ratio);
    first_root(lo, |x| {
        frequency_function(poisson_ratio, 2.0 * PI * w / x, x)
    })
}

/// Tyas–Pope factor M1 (A. Tyas & A. M. Pope, *Meas. Sci. Technol.* 16, 642 (2005), after
/// R. M. Davies 1948): the mean axial strain over the cross-section over the axial strain at the
/// surface, for the first mode at `a/Λ` with velocity ratio `c/c0`. From the Pochhammer–Chree
/// displacement field with the shear-free surface:
/// `M1 = 2 C1(X) C1(Y) (K² − Y + 2X) / ((K² − Y) C1(Y) C0(X) + 2X C1(X) C0(Y))`.
pub fn tyas_pope_m1(poisson_ratio: f64, a_over_lambda: f64, velocity_ratio: f64) -> f64 {
    let y = a_over_lambda.abs();
    if y < LONG_WAVE_LIMIT {
        return 1.0;
    }
    let (l2, t2) = speed_ratios_squared(poisson_ratio);
    let k2 = (2.0 * PI * y).powi(2);
    let x2 = velocity_ratio * velocity_ratio;
    let (a2, b2) = (k2 * (x2 * l2 - 1.0), k2 * (x2 * t2 - 1.0));
    let (c0x, c1x) = even_bessel(a2);
    let (c0y, c1y) = even_bessel(b2);
    2.0 * c1x * c1y * (k2 - b2 + 2.0 * a2) / ((k2 - b2) * c1y * c0x + 2.0 * a2 * c1x * c0y)
}

/// Tyas–Pope factor M2 (Tyas & Pope 2005): the dynamic over the static Young's modulus, mean
/// axial stress over E times mean axial strain. The section-averaged axial momentum balance of a
/// mode `exp(i(kz − ωt))` with a traction-free surface gives σ̄ = ρc²ε̄, so `M2 = (c/c0)²`.
pub fn tyas_pope_m2(velocity_ratio: f64) -> f64 {
    velocity_ratio * velocity_ratio
}

/// The first Pochhammer–Chree mode tabulated: in y = f a/c0, 0.002 apart, up to y = 2 (where
/// the curve bends), and in u = 1/y, 0.0025 apart, beyond (where it flattens toward the
/// Rayleigh speed, reached at u = 0).
#[derive(Debug)]
pub struct ModeTable {
    fine: Vec<f64>,
    coarse: Vec<f64>,
}

const FINE_STEP: f64 = 0.003;
const FINE_END: f64 = 2.0;
const COARSE_STEP: f64 = 0.0025;

impl ModeTable {
    /// Roots by continuation: each from the previous one (c/c0 falls with frequency), scanning
    /// down for the first sign change and refining it by the Illinois method to rounding.
    fn new(poisson_ratio: f64) -> ModeTable {
        let rayleigh = rayleigh_velocity_ratio(poisson_ratio);
        let (mut previous, mut change) = (1.0, 0.0);
        let mut root = |y: f64, restart: bool| -> f64 {
            let x = if y < 1e-3 || restart {
                // The exact solver (the long-wave branch, or the start of a sequence).
                velocity_ratio_at_normalised_frequency(poisson_ratio, y)
            } else {
                continue_root(poisson_ratio, y, previous, change, rayleigh)
            };
            change = if restart { 0.0 } else { x - previous };
            previous = x;
            x
        };
        let fine_n = (FINE_END / FINE_STEP).round() as usize + LAGRANGE_POINTS;
        let fine: Vec<f64> = (0..=fine_n)
            .map(|i| root(i as f64 * FINE_STEP, false))
            .collect();
        let coarse_n = ((1.0 / FINE_END) / COARSE_STEP).round() as usize + LAGRANGE_POINTS;
        let mut coarse: Vec<f64> = (1..=coarse_n)
            .rev()
            .map(|i| root(1.0 / (i as f64 * COARSE_STEP), i == coarse_n))
            .collect();
        coarse.push(rayleigh);
        coarse.reverse();
        ModeTable { fine, coarse }
    }

    /// c/c0 at y by 8-point Lagrange interpolation.
    pub fn ratio(&self, y: f64) -> f64 {
        if y <= FINE_END {
            lagrange(&self.fine, y / FINE_STEP)
        } else {
            lagrange(&self.coarse, 1.0 / (y * COARSE_STEP))
        }
    }
}

/// The root of `g` between `a` and `b` (g(a), g(b) of opposite signs) by the Illinois method,
/// stopped when an iterate moves by less than 1e-15 of itself (superlinear: about six
/// evaluations from a narrow bracket, where a stop on the bracket's width would wait for its
/// far side).
fn illinois_to_rounding(a: f64, b: f64, ga: f64, gb: f64, g: impl Fn(f64) -> f64) -> f64 {
    crate::numeric::illinois_until(
        a,
        b,
        ga,
        gb,
        200,
        |u, previous, _, _| (u - previous).abs() <= 1e-15 * u.abs(),
        g,
    )
}

/// The first-mode root at f a/c0 = `y` next to `previous` (the root at the previous y of a
/// sequence; `change` is the last step's change): a bracket around the linear extrapolation,
/// twice the last change wide each side, doubled (to 0.002) until g changes sign, refined by
/// the Illinois method to rounding. The root falls with y to a minimum just below cR and rises
/// to it beyond; every other branch is faster than c0 there, so the bracket holds only this
/// one. Without a sign change, the exact solver's scan decides.
fn continue_root(poisson_ratio: f64, y: f64, previous: f64, change: f64, rayleigh: f64) -> f64 {
    let g = |x: f64| frequency_function(poisson_ratio, 2.0 * PI * y / x, x);
    let centre = previous + change;
    let mut step = (2.0 * change.abs()).max(1e-9);
    loop {
        let (lo, hi) = (
            (centre - step).max(0.9 * rayleigh),
            (centre + step).min(1.0),
        );
        let (g_lo, g_hi) = (g(lo), g(hi));
        if g_lo == 0.0 {
            return lo;
        }
        if g_lo.signum() != g_hi.signum() {
            return illinois_to_rounding(lo, hi, g_lo, g_hi, g);
        }
        if step >= 0.002 {
            return velocity_ratio_at_normalised_frequency(poisson_ratio, y);
        }
        step = (2.0 * step).min(0.002);
    }
}

/// Points of the interpolating polynomial ([`lagrange`]): 8, so that the error (order h⁸) and
/// the jumps of the derivatives between intervals stay far below the transit filters' 1e-8.
const LAGRANGE_POINTS: usize = 8;

/// 1/Π_{m≠j}(j − m) for the nodes 0..[`LAGRANGE_POINTS`]: the constant denominators of the
/// Lagrange weights on equispaced nodes, (−1)^{P−1−j}/(j! (P−1−j)!).
const LAGRANGE_INVERSE_DENOMINATORS: [f64; LAGRANGE_POINTS] = {
    let mut out = [0.0; LAGRANGE_POINTS];
    let mut j = 0;
    while j < LAGRANGE_POINTS {
        let mut d = 1.0;
        let mut m = 0;
        while m < LAGRANGE_POINTS {
            if m != j {
                d *= j as f64 - m as f64;
            }
            m += 1;
        }
        out[j] = 1.0 / d;
        j += 1;
    }
    out
};

/// Value at fractional index t of samples `v` by the Lagrange polynomial through the
/// [`LAGRANGE_POINTS`] samples around t: weight_j = Π_{m≠j}(s − m) / Π_{m≠j}(j − m), the
/// numerators from prefix and suffix products (no division; exact at the nodes).
fn lagrange(v: &[f64], t: f64) -> f64 {
    let half = LAGRANGE_POINTS / 2;
    let i = (t.floor() as usize).clamp(half - 1, v.len() - half - 1);
    let first = i + 1 - half;
    let s = t - first as f64;
    let mut prefix = [1.0; LAGRANGE_POINTS];
    for j in 1..LAGRANGE_POINTS {
        prefix[j] = prefix[j - 1] * (s - (j - 1) as f64);
    }
    let mut suffix = 1.0;
    let mut sum = 0.0;
    for j in (0..LAGRANGE_POINTS).rev() {
        sum += prefix[j] * suffix * LAGRANGE_INVERSE_DENOMINATORS[j] * v[first + j];
        suffix *= s - j as f64;
    }
    sum
}

/// Process-wide tables of the first mode, by ν's bits.
pub fn mode_table(poisson_ratio: f64) -> Arc<ModeTable> {
    static TABLES: OnceLock<Mutex<HashMap<u64, Arc<ModeTable>>>> = OnceLock::new();
    let key = poisson_ratio.to_bits();
    let tables = TABLES.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(t) = tables.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Arc::clone(t);
    }
    let table = Arc::new(ModeTable::new(poisson_ratio));
    tables
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, Arc::clone(&table));
    table
}

/// The first Pochhammer–Chree mode of one bar; the reduction's FFT bins read its phase velocity
/// from the process-wide table ([`mode_table`]; docs/physics.md §7.9).
#[derive(Debug, Clone)]
pub struct PochhammerChree {
    poisson_ratio: f64,
    radius_m: f64,
    c0_m_s: f64,
    rayleigh_ratio: f64,
    /// The mode tabulated (within 4.6e-11 of the exact root).
    table: Arc<ModeTable>,
}

impl PochhammerChree {
    /// The first mode of a bar of Poisson's ratio `poisson_ratio` (0 < ν < 0.5), radius
    /// `radius_m` (> 0) and bar-wave speed `c0_m_s` (> 0); errors name the quantity and its range.
    pub fn new(poisson_ratio: f64, radius_m: f64, c0_m_s: f64) -> Result<PochhammerChree> {
        let bad = |quantity: &str, value: f64, allowed: &str| Error::Invalid {
            object: "Pochhammer–Chree dispersion".to_string(),
            quantity: quantity.to_string(),
            problem: format!("{value} is out of range"),
            allowed: allowed.to_string(),
        };
        if !(poisson_ratio > 0.0 && poisson_ratio < 0.5) {
            return Err(bad(
                "poisson_ratio",
                poisson_ratio,
                "greater than 0 and less than 0.5",
            ));
        }
        if !(radius_m > 0.0 && radius_m.is_finite()) {
            return Err(bad("radius_m", radius_m, "a positive radius in metres"));
        }
        if !(c0_m_s > 0.0 && c0_m_s.is_finite()) {
            return Err(bad("wave_speed_m_s", c0_m_s, "a positive speed in m/s"));
        }
        Ok(PochhammerChree {
            poisson_ratio,
            radius_m,
            c0_m_s,
            rayleigh_ratio: rayleigh_velocity_ratio(poisson_ratio),
            table: mode_table(poisson_ratio),
        })
    }

    /// Poisson's ratio ν.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// cR/c0, the high-frequency limit of the first mode's phase velocity.
    pub fn rayleigh_ratio(&self) -> f64 {
        self.rayleigh_ratio
    }

    /// c/c0 at `frequency_hz` (solved, not cached).
    pub fn velocity_ratio(&self, frequency_hz: f64) -> f64 {
        velocity_ratio_at_normalised_frequency(
            self.poisson_ratio,
            frequency_hz.abs() * self.radius_m / self.c0_m_s,
        )
    }

    /// Phase velocity c(f), m/s.
    pub fn phase_velocity_m_s(&self, frequency_hz: f64) -> f64 {
        self.c0_m_s * self.velocity_ratio(frequency_hz)
    }

    /// c/c0 for bin `bin` (|k|, 0..=n/2) of an `n`-point FFT at step `dt_s`, f = bin/(n dt),
    /// from the table (within 4.6e-11 of the exact root; the values the dispersive delay lines
    /// use).
    pub fn velocity_ratio_for_bin(&self, bin: usize, n: usize, dt_s: f64) -> f64 {
        self.table
            .ratio(bin as f64 / (n as f64 * dt_s) * self.radius_m / self.c0_m_s)
    }

    /// Extra travel time over `distance_m` beyond `distance/c0` for bin `bin` of an `n`-point FFT
    /// at step `dt_s`: `Δx (1/c(f) − 1/c0)`, s (tabulated mode).
    pub fn delay_for_bin_s(&self, bin: usize, n: usize, dt_s: f64, distance_m: f64) -> f64 {
        let x = self.velocity_ratio_for_bin(bin, n, dt_s);
        distance_m / self.c0_m_s * (1.0 / x - 1.0)
    }

    /// Tyas–Pope amplitude factor M1·M2 (mean axial stress over E times the surface strain) for
    /// bin `bin` of an `n`-point FFT at step `dt_s` (tabulated mode).
    pub fn tyas_pope_factor_for_bin(&self, bin: usize, n: usize, dt_s: f64) -> f64 {
        let x = self.velocity_ratio_for_bin(bin, n, dt_s);
        let f = bin as f64 / (n as f64 * dt_s);
        let a_over_lambda = self.radius_m * f / (x * self.c0_m_s);
        tyas_pope_m1(self.poisson_ratio, a_over_lambda, x) * tyas_pope_m2(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lagrange_reproduces_a_degree_seven_polynomial_and_the_nodes() {
        // Eight points determine a degree-7 polynomial: interpolation is exact up to rounding,
        // anywhere in the table (interior, and the clamped first and last intervals).
        let p = |x: f64| 0.3 + x * (-1.2 + x * (0.5 + x * (0.01 - 2e-3 * x * x * x * x)));
        let v: Vec<f64> = (0..20).map(|i| p(i as f64 / 10.0)).collect();
        for k in 0..=190 {
            let t = k as f64 / 10.0 + 0.003;
            let want = p(t / 10.0);
            let got = lagrange(&v, t);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs().max(1.0),
                "t = {t}: {got} vs {want}"
            );
        }
        // At a node the value is the sample itself.
        for (i, &x) in v.iter().enumerate() {
            assert_eq!(lagrange(&v, i as f64), x);
        }
    }

    #[test]
    fn the_mode_table_interpolates_the_exact_root_within_1e10() {
        let table = ModeTable::new(0.31);
        // The continuation finds the exact solver's roots at the nodes.
        for (i, &x) in table.fine.iter().enumerate().step_by(37) {
            let exact = velocity_ratio_at_normalised_frequency(0.31, i as f64 * FINE_STEP);
            assert!((x - exact).abs() < 1e-12, "node {i}: {x} vs {exact}");
        }
        let mut worst: f64 = 0.0;
        for i in 0..1200 {
            let y = 0.0037 + i as f64 * 0.0397;
            let exact = velocity_ratio_at_normalised_frequency(0.31, y);
            worst = worst.max((table.ratio(y) - exact).abs());
        }
        for i in 0..2000 {
            let y = 0.1003 + i as f64 * 0.000349;
            let exact = velocity_ratio_at_normalised_frequency(0.31, y);
            worst = worst.max((table.ratio(y) - exact).abs());
        }
        println!("worst {worst:e}");
        // 1e-10 in c/c0 is a phase error below 1e-7 rad over the 1210 cells of the authors'
        // incident bar at 1 mm (Ω d δc/c² at the steepest point, y ≈ 0.27).
        assert!(worst < 1e-10, "{worst:e}");
    }

    /// Reference values computed with mpmath 1.3.0 (`besselj`, `besseli`, 30 digits).
    #[test]
    fn bessel_functions_match_reference_values_on_both_sides_of_each_switch() {
        let j = [
            (0.5, 0.9384698072408129, 0.2422684576748739),
            (1.0, 0.7651976865579666, 0.4400505857449335),
            (5.0, -0.1775967713143383, -0.32757913759146523),
            (10.0, -0.24593576445134835, 0.04347274616886144),
            (11.9, 0.025049441699589645, -0.22898324966192407),
            (12.1, 0.06966677360680731, -0.2157489733769248),
            (20.0, 0.16702466434058316, 0.06683312417585005),
            (40.0, 0.00736689058423729, 0.126038318037585),
        ];
        for (x, j0, j1) in j {
            // Absolute 1e-12: the series at x = 12 loses ~4 of 16 digits to cancellation.
            assert!((bessel_j0(x) - j0).abs() < 1e-12, "J0({x})");
            assert!((bessel_j1(x) - j1).abs() < 1e-12, "J1({x})");
        }
        let i = [
            (0.5, 0.6450352704491501, 0.1564208031848717),
            (1.0, 0.46575960759364043, 0.20791041534970844),
            (5.0, 0.18354081260932836, 0.16397226694454237),
            (10.0, 0.12783333716342862, 0.12126268138445552),
            (24.0, 0.08186828833403062, 0.08014413927653474),
            (26.0, 0.07862365204001373, 0.07709652456966624),
            (40.0, 0.06327827987523534, 0.062482229074442064),
            (100.0, 0.03994437929909668, 0.039744153025130256),
        ];
        for (x, i0, i1) in i {
            // Relative 1e-13: all terms positive, no cancellation.
            assert!((bessel_i0_scaled(x) / i0 - 1.0).abs() < 1e-13, "I0({x})");
            assert!((bessel_i1_scaled(x) / i1 - 1.0).abs() < 1e-13, "I1({x})");
        }
        // First zeros (Abramowitz & Stegun Table 9.5): j0,1 = 2.404825557695773,
        // j1,1 = 3.831705970207512.
        assert!(bessel_j0(2.404825557695773).abs() < 1e-14);
        assert!(bessel_j1(3.831705970207512).abs() < 1e-14);
        // Odd and even symmetry.
        assert_eq!(bessel_j1(-3.0), -bessel_j1(3.0));
        assert_eq!(bessel_j0(-3.0), bessel_j0(3.0));
    }

    #[test]
    fn rayleigh_speed_matches_its_equation_and_viktorovs_approximation() {
        for nu in [0.1, 0.25, 0.29, 0.31, 0.45] {
            let x = rayleigh_velocity_ratio(nu);
            // Viktorov's approximation cR/cT ≈ (0.87 + 1.12ν)/(1 + ν) is good to ~0.5 %.
            let ct_over_c0 = 1.0 / (2.0 * (1.0 + nu)).sqrt();
            let approx = (0.87 + 1.12 * nu) / (1.0 + nu) * ct_over_c0;
            assert!((x / approx - 1.0).abs() < 5e-3, "ν = {nu}: {x} vs {approx}");
        }
        // ν = 0.25: cR/cT = √(2 − 2/√3) exactly (Rayleigh 1885).
        let exact = (2.0 - 2.0 / 3f64.sqrt()).sqrt() / 2.5f64.sqrt();
        assert!((rayleigh_velocity_ratio(0.25) - exact).abs() < 1e-12);
    }

    #[test]
    fn first_mode_runs_from_c0_down_to_the_rayleigh_speed() {
        for nu in [0.05, 0.2, 0.29, 0.31, 0.45] {
            // Long waves: Rayleigh's correction 1 − ν²π²(a/Λ)² to O((a/Λ)⁴).
            let y = 0.01;
            let x = velocity_ratio_at_radius_over_wavelength(nu, y);
            let rayleigh = 1.0 - (nu * PI * y).powi(2);
            assert!((x - rayleigh).abs() < 1e-6, "ν = {nu}: {x} vs {rayleigh}");
            // Continuity at the long-wave switch: the root just above it is Rayleigh's limit.
            let y = 1.01 * LONG_WAVE_LIMIT;
            let above = velocity_ratio_at_radius_over_wavelength(nu, y);
            let limit = 1.0 - (nu * PI * y).powi(2);
            assert!(
                (above - limit).abs() < 1e-12,
                "ν = {nu}: {above} vs {limit}"
            );
            // Short waves: the Rayleigh speed, approached from below as 1/(ka) (the branch
            // dips 0.2–1.5 % under cR near a/Λ ≈ 2 before rising back to it).
            let cr = rayleigh_velocity_ratio(nu);
            let x = velocity_ratio_at_radius_over_wavelength(nu, 20.0);
            assert!((x / cr - 1.0).abs() < 2e-3, "ν = {nu}: {x} vs cR {cr}");
            // Monotone while the wave is longer than the radius, never below 0.95 cR.
            let mut last = 1.0;
            for i in 1..=200 {
                let y = i as f64 * 0.01;
                let x = velocity_ratio_at_radius_over_wavelength(nu, y);
                assert!(x > 0.95 * cr, "ν = {nu}, a/Λ = {y}");
                if y <= 1.0 {
                    assert!(x < last, "ν = {nu}, a/Λ = {y}");
                }
                last = x;
            }
        }
    }

    #[test]
    fn fixed_frequency_and_fixed_wavelength_roots_agree() {
        for nu in [0.29, 0.31] {
            for y in [0.05, 0.2, 0.5, 1.0] {
                let x = velocity_ratio_at_radius_over_wavelength(nu, y);
                let back = velocity_ratio_at_normalised_frequency(nu, y * x);
                assert!((back - x).abs() < 1e-12, "ν = {nu}, a/Λ = {y}");
            }
        }
    }

    #[test]
    fn tyas_pope_m1_is_the_mean_of_the_modal_strain_profile() {
        for nu in [0.29, 0.31] {
            let x = velocity_ratio_at_radius_over_wavelength(nu, 1e-3);
            assert!((tyas_pope_m1(nu, 1e-3, x) - 1.0).abs() < 1e-5);
            assert!((tyas_pope_m2(x) - 1.0).abs() < 1e-5);
            for y in [0.05, 0.1, 0.2, 0.3] {
                // The axial strain of the mode across the section, up to a constant
                // (docs/physics.md §7.9): (K² − Y) C1(Y) C0(X r²/a²) + 2X C1(X) C0(Y r²/a²);
                // its area mean by Simpson's rule over r/a in [0, 1], over its surface value.
                let x = velocity_ratio_at_radius_over_wavelength(nu, y);
                let (l2, t2) = speed_ratios_squared(nu);
                let k2 = (2.0 * PI * y).powi(2);
                let (a2, b2) = (k2 * (x * x * l2 - 1.0), k2 * (x * x * t2 - 1.0));
                let (_, c1x) = even_bessel(a2);
                let (_, c1y) = even_bessel(b2);
                // C0 unscaled at r/a = ρ, relative to the scale at the surface.
                let c0 = |s: f64, rho: f64| {
                    let scale = if s < 0.0 {
                        ((-s).sqrt() * (rho - 1.0)).exp()
                    } else {
                        1.0
                    };
                    even_bessel(s * rho * rho).0 * scale
                };
                let strain =
                    |rho: f64| (k2 - b2) * c1y * c0(a2, rho) + 2.0 * a2 * c1x * c0(b2, rho);
                let n = 2000;
                let h = 1.0 / n as f64;
                let mean = 2.0 * h / 3.0
                    * (0..=n)
                        .map(|i| {
                            let rho = i as f64 * h;
                            let w = if i == 0 || i == n {
                                1.0
                            } else if i % 2 == 1 {
                                4.0
                            } else {
                                2.0
                            };
                            w * rho * strain(rho)
                        })
                        .sum::<f64>();
                let m1 = tyas_pope_m1(nu, y, x);
                assert!(
                    (mean / strain(1.0) / m1 - 1.0).abs() < 1e-9,
                    "ν = {nu}, a/Λ = {y}: {mean} {} {m1}",
                    strain(1.0)
                );
                // The surface strain lags the mean as the wave shortens (Davies 1948): M1 > 1.
                assert!(m1 > 1.0, "ν = {nu}, a/Λ = {y}: M1 = {m1}");
            }
        }
    }

    #[test]
    fn bin_delays_are_the_exact_modes() {
        let pc = PochhammerChree::new(0.31, 9.525e-3, 4865.5).unwrap();
        let (n, dt) = (1024, 1e-7);
        let delays: Vec<f64> = (0..=n / 2)
            .map(|k| pc.delay_for_bin_s(k, n, dt, 0.64))
            .collect();
        assert_eq!(delays[0], 0.0);
        // The table's values are the exact roots to 1e-10 (the test above), so the delays over
        // 0.64 m are the exact ones to (0.64 m / c0)·1e-10/(c/c0)² ≤ 3e-14 s (c ≥ 0.57 c0).
        for k in (1..=n / 2).step_by(7) {
            let exact = 0.64 / 4865.5 * (1.0 / pc.velocity_ratio(k as f64 / (n as f64 * dt)) - 1.0);
            assert!(
                (delays[k] - exact).abs() < 3e-14,
                "bin {k}: {} vs {exact}",
                delays[k]
            );
        }
        // Every delay lies between 0 and the one of the slowest component (≥ 0.95 cR).
        let slowest = 0.64 / 4865.5 * (1.0 / (0.95 * pc.rayleigh_ratio()) - 1.0);
        assert!(delays.iter().all(|&d| (0.0..slowest).contains(&d)));
        let e = PochhammerChree::new(0.5, 9.525e-3, 4865.5).unwrap_err();
        assert!(e.to_string().contains("poisson_ratio"), "{e}");
        assert!(e.to_string().contains("less than 0.5"), "{e}");
    }
}

//! The striker and its gas gun: reservoir pressure → striker velocity by adiabatic expansion of
//! the reservoir gas behind the striker over the barrel (Rohrbach et al., Am. J. Phys. 80, 24
//! (2012); docs/physics.md §6.4). The gas does the same work on any striker, so a heavier striker
//! leaves slower: ½ m v² = W(p), independent of m.

use crate::error::{Error, Result, format_range, format_si};

/// The quantity named in errors about the gun pressure.
const PRESSURE: &str = "gun pressure";

/// Standard atmospheric pressure, Pa.
pub const ATMOSPHERE_PA: f64 = 101_325.0;
/// One pound per square inch, Pa.
pub const PSI_PA: f64 = 6_894.757_293_168;

/// A gas gun: reservoir of volume V0 at gauge pressure p, barrel of length Lb and bore A, friction Ff.
///
/// Work–energy (Rohrbach et al. 2012): ½ m v² = ∫₀^Lb [p_abs (V0/(V0 + A x))^γ − p_atm] A dx − Ff Lb
/// = p_abs V0/(γ−1) · (1 − (V0/(V0 + A Lb))^{γ−1}) − p_atm A Lb − Ff Lb. It is linear in p, so it
/// is the `v² = k (p − p_loss)` curve with k and p_loss given by the geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasGun {
    /// Reservoir volume V0, m³.
    pub reservoir_volume_m3: f64,
    /// Barrel length Lb over which the gas pushes the striker, m.
    pub barrel_length_m: f64,
    /// Sliding friction on the striker, N.
    pub friction_n: f64,
    /// Adiabatic exponent γ of the gas (1.4 for air).
    pub gamma: f64,
    /// Atmospheric (back) pressure, Pa.
    pub atmospheric_pa: f64,
    /// Smallest gauge pressure the gun is used at, Pa.
    pub min_pressure_pa: f64,
    /// Largest gauge pressure the gun is rated for, Pa.
    pub max_pressure_pa: f64,
}

impl GasGun {
    /// Kinetic energy given to a striker of bore area `area_m2` at gauge pressure `p_gauge_pa`, J (may be ≤ 0: it does not move).
    pub fn kinetic_energy_j(&self, p_gauge_pa: f64, area_m2: f64) -> f64 {
        let p_abs = p_gauge_pa + self.atmospheric_pa;
        let ratio =
            self.reservoir_volume_m3 / (self.reservoir_volume_m3 + area_m2 * self.barrel_length_m);
        let expansion = p_abs * self.reservoir_volume_m3 / (self.gamma - 1.0)
            * (1.0 - ratio.powf(self.gamma - 1.0));
        expansion
            - self.atmospheric_pa * area_m2 * self.barrel_length_m
            - self.friction_n * self.barrel_length_m
    }

    /// Striker velocity at gauge pressure `p_gauge_pa` for a striker of mass `mass_kg` and bore
    /// `area_m2`; an error names the allowed pressure range if p is outside it or too low to fire.
    pub fn velocity_m_s(&self, p_gauge_pa: f64, mass_kg: f64, area_m2: f64) -> Result<f64> {
        let allowed = check_range(p_gauge_pa, self.min_pressure_pa, self.max_pressure_pa)?;
        let ke = self.kinetic_energy_j(p_gauge_pa, area_m2);
        if ke <= 0.0 {
            return Err(Error::invalid(
                PRESSURE,
                format!(
                    "{} is too low to overcome friction and back-pressure",
                    format_si(p_gauge_pa / PSI_PA, "psi")
                ),
                allowed,
            ));
        }
        Ok((2.0 * ke / mass_kg).sqrt())
    }
}

/// Checks a gauge pressure against the gun's range; returns the range text for later errors.
fn check_range(p_gauge_pa: f64, min_pa: f64, max_pa: f64) -> Result<String> {
    let allowed = format!(
        "{} ({} gauge)",
        format_range(min_pa / PSI_PA, max_pa / PSI_PA, "psi"),
        format_range(min_pa, max_pa, "Pa")
    );
    if !p_gauge_pa.is_finite() || p_gauge_pa < min_pa || p_gauge_pa > max_pa {
        return Err(Error::invalid(
            PRESSURE,
            format!(
                "{} is outside the gun's range",
                format_si(p_gauge_pa / PSI_PA, "psi")
            ),
            allowed,
        ));
    }
    Ok(allowed)
}

/// Most energy a striker of mass `mass_kg` arriving at `velocity_m_s` can put into the bar while
/// giving it impulse `impulse_n_s`: it leaves at v − I/m and keeps that kinetic energy, so the
/// pulse carries at most m (v² − (v − I/m)²)/2, whatever a pulse shaper does (momentum and
/// energy conservation), J.
pub fn most_pulse_energy_j(mass_kg: f64, velocity_m_s: f64, impulse_n_s: f64) -> f64 {
    let after = velocity_m_s - impulse_n_s / mass_kg;
    0.5 * mass_kg * (velocity_m_s * velocity_m_s - after * after)
}

/// The gun's calibration line v² = k (p − p_loss), measured with a striker of mass m_ref
/// (docs/physics.md §6.4): the adiabatic model's work W(p) = ½ m_ref k (p − p_loss), shared by
/// any striker, so v² = k (m_ref/m)(p − p_loss) for a striker of mass m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearGun {
    /// k, m²/s² per Pa of gauge pressure, for the calibration striker.
    pub k_m2_per_s2_per_pa: f64,
    /// Pressure lost to back-pressure, reservoir expansion and friction, Pa.
    pub loss_pressure_pa: f64,
    /// Mass m_ref of the striker the line was measured with, kg.
    pub calibration_mass_kg: f64,
    /// Smallest usable gauge pressure, Pa.
    pub min_pressure_pa: f64,
    /// Largest rated gauge pressure, Pa.
    pub max_pressure_pa: f64,
}

impl LinearGun {
    /// Work the gas does on any striker at gauge pressure `p_gauge_pa`, ½ m_ref k (p − p_loss), J
    /// (≤ 0: it does not move).
    pub fn kinetic_energy_j(&self, p_gauge_pa: f64) -> f64 {
        0.5 * self.calibration_mass_kg
            * self.k_m2_per_s2_per_pa
            * (p_gauge_pa - self.loss_pressure_pa)
    }

    /// The frictionless adiabatic gun (γ = `gamma`, bore `area_m2`, back-pressure `atmospheric_pa`)
    /// with the same work line: dW/dp = V0/(γ−1)·[1 − (V0/(V0 + A Lb))^{γ−1}] = ½ m_ref k and
    /// W(p_loss) = 0, i.e. A Lb = ½ m_ref k (1 + p_loss/p_atm) (docs/physics.md §6.4). None if no
    /// reservoir volume fits.
    pub fn equivalent_adiabatic(
        &self,
        area_m2: f64,
        gamma: f64,
        atmospheric_pa: f64,
    ) -> Option<GasGun> {
        let slope_m3 = 0.5 * self.calibration_mass_kg * self.k_m2_per_s2_per_pa;
        let swept_m3 = slope_m3 * (1.0 + self.loss_pressure_pa / atmospheric_pa);
        let target = slope_m3 / swept_m3;
        // f(x) = x/(γ−1)·[1 − (x/(x+1))^{γ−1}] rises from 0 to 1 as x = V0/(A Lb) grows.
        let f = |x: f64| x / (gamma - 1.0) * (1.0 - (x / (x + 1.0)).powf(gamma - 1.0));
        let (mut lo, mut hi) = (1e-9_f64, 1e9_f64);
        if !target.is_finite() || f(lo) >= target || f(hi) <= target {
            return None;
        }
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if f(mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(GasGun {
            reservoir_volume_m3: (lo * hi).sqrt() * swept_m3,
            barrel_length_m: swept_m3 / area_m2,
            friction_n: 0.0,
            gamma,
            atmospheric_pa,
            min_pressure_pa: self.min_pressure_pa,
            max_pressure_pa: self.max_pressure_pa,
        })
    }
}

/// A gas gun model: the linear curve or the adiabatic expansion model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gun {
    /// v² = k (m_ref/m)(p − p_loss): the calibration line, work shared by any striker.
    Linear(LinearGun),
    /// Adiabatic reservoir expansion over the barrel (Rohrbach et al. 2012).
    Adiabatic(GasGun),
    /// No gun: a set-up without `[gun]`, whose scenes give the striker's velocity
    /// (`striker_velocity_m_s`); any pressure is refused.
    None,
}

impl Gun {
    /// The allowed gauge-pressure range (min, max), Pa (NaN, NaN without a gun).
    pub fn range_pa(&self) -> (f64, f64) {
        match self {
            Gun::Linear(g) => (g.min_pressure_pa, g.max_pressure_pa),
            Gun::Adiabatic(g) => (g.min_pressure_pa, g.max_pressure_pa),
            Gun::None => (f64::NAN, f64::NAN),
        }
    }

    /// Work the gas does on a striker of bore `area_m2` at gauge pressure `p_gauge_pa`, whatever
    /// its mass (½ m v² = W(p), docs/physics.md §6.4), J (NaN without a gun).
    pub fn kinetic_energy_j(&self, p_gauge_pa: f64, area_m2: f64) -> f64 {
        match self {
            Gun::Linear(g) => g.kinetic_energy_j(p_gauge_pa),
            Gun::Adiabatic(g) => g.kinetic_energy_j(p_gauge_pa, area_m2),
            Gun::None => f64::NAN,
        }
    }

    /// Striker velocity at gauge pressure `p_gauge_pa` for a striker of mass `mass_kg` and bore
    /// `area_m2`, v = √(2 W(p)/m);
    /// an out-of-range pressure is an [`Error::Invalid`] naming the range.
    pub fn striker_velocity_m_s(&self, p_gauge_pa: f64, mass_kg: f64, area_m2: f64) -> Result<f64> {
        match self {
            Gun::Adiabatic(g) => g.velocity_m_s(p_gauge_pa, mass_kg, area_m2),
            Gun::None => Err(Error::invalid(
                PRESSURE,
                "given, but the set-up has no [gun]",
                "the striker's velocity (striker_velocity_m_s) instead of a pressure, or a set-up \
                 with a [gun] table",
            )),
            Gun::Linear(g) => {
                let allowed = check_range(p_gauge_pa, g.min_pressure_pa, g.max_pressure_pa)?;
                let v2 = 2.0 * g.kinetic_energy_j(p_gauge_pa) / mass_kg;
                if v2 <= 0.0 {
                    return Err(Error::invalid(
                        PRESSURE,
                        "too low to overcome the pressure loss",
                        allowed,
                    ));
                }
                Ok(v2.sqrt())
            }
        }
    }
}

/// The shape of an incident pulse that tells a copper-shaped striker from an unshaped one,
/// whatever its amplitude (gauge reading) or the gun (docs/physics.md §6.4, "Which striker").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseShape {
    /// Rise from 10 % to 90 % of the peak on the leading edge, s.
    pub rise_s: f64,
    /// Full width at half the peak, s (2 L/c0 for an unshaped striker).
    pub width_half_s: f64,
    /// Full width between the 10 % crossings, s.
    pub width_10_s: f64,
    /// Stress at the first sample over the peak: above 0.1 the record starts after the pulse's
    /// foot, and its rise (and, above 0.5, its width) cannot be measured.
    pub start_fraction: f64,
    /// Effective duration (∫σ dt)² / ∫σ² dt over the pulse (above 5 % of peak), s: 2 L/c0 for a
    /// rectangle, and so the length c0 T/2 of the one striker that gives both the pulse's impulse
    /// and energy, m = I²/(2E) (momentum and energy of a striker that stops).
    pub effective_duration_s: f64,
}

impl PulseShape {
    /// Rise over width at half peak: ≈ 0.1 for an unshaped striker (dispersion and contact round
    /// the corners), ≈ 0.4–0.7 for a copper shaper's ramp.
    pub fn rise_fraction(&self) -> f64 {
        self.rise_s / self.width_half_s
    }

    /// Effective duration over width at half peak: 1 for a rectangle, 1.5 for a triangle.
    pub fn squareness(&self) -> f64 {
        self.effective_duration_s / self.width_half_s
    }
}

/// Largest rise fraction (10–90 % rise over width at half peak) called unshaped: above the
/// simulated unshaped 20 cm striker's 0.13 (dispersive bars, spheres) with room for noise.
pub const UNSHAPED_MAX_RISE_FRACTION: f64 = 0.2;
/// Smallest rise fraction called shaped: below the 0.42–0.66 of the eight shaped 2013-05-22
/// records and the simulated shaped 10 cm striker's 0.56.
pub const SHAPED_MIN_RISE_FRACTION: f64 = 0.3;

/// Which striker a pulse's shape points to (docs/physics.md §6.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrikerVerdict {
    /// A steep rise and a plateau: a striker hitting the bar directly, L ≈ c0 × width / 2.
    Unshaped,
    /// A ramped rise over a large part of the pulse: a copper pulse shaper.
    Shaped,
    /// Between the two thresholds: the shape does not decide.
    Inconclusive,
    /// The record starts above 10 % of the peak: the leading edge is missing, the shape cannot
    /// decide (the Fig. 4 force–approach records start at the start of loading).
    EdgeMissing,
}

impl StrikerVerdict {
    /// The verdict from the rise fraction and the two thresholds above (none if the edge is
    /// missing).
    pub fn from_shape(shape: &PulseShape) -> StrikerVerdict {
        let f = shape.rise_fraction();
        if shape.start_fraction > 0.1 {
            StrikerVerdict::EdgeMissing
        } else if f < UNSHAPED_MAX_RISE_FRACTION {
            StrikerVerdict::Unshaped
        } else if f > SHAPED_MIN_RISE_FRACTION {
            StrikerVerdict::Shaped
        } else {
            StrikerVerdict::Inconclusive
        }
    }

    /// The verdict as a word (`unshaped`, `shaped`, `inconclusive`).
    pub fn name(&self) -> &'static str {
        match self {
            StrikerVerdict::Unshaped => "unshaped",
            StrikerVerdict::Shaped => "shaped",
            StrikerVerdict::Inconclusive => "inconclusive",
            StrikerVerdict::EdgeMissing => "edge missing",
        }
    }
}

/// Smallest pulse energy over the gas's work W(p), E/W, called unshaped: a striker of the bar's
/// impedance that stops gives the bar all of W (the simulated unshaped 20 cm striker: 0.98); the
/// margin is twice the gun's 1σ of 4.5 % in k (bars/authors.toml).
pub const UNSHAPED_MIN_ENERGY_FRACTION: f64 = 0.91;
/// Largest E/W called shaped: the copper disc dissipates 20-34 % of W in the eight shaped
/// 2013-05-22 records (E/W 0.66-0.80).
pub const SHAPED_MAX_ENERGY_FRACTION: f64 = 0.85;

impl StrikerVerdict {
    /// The verdict from the pulse's energy over the gun's work E/W (needs the test's pressure and
    /// the gun's calibration; amplitude-dependent, unlike [`StrikerVerdict::from_shape`]).
    pub fn from_energy_fraction(fraction: f64) -> StrikerVerdict {
        if fraction > UNSHAPED_MIN_ENERGY_FRACTION {
            StrikerVerdict::Unshaped
        } else if fraction < SHAPED_MAX_ENERGY_FRACTION {
            StrikerVerdict::Shaped
        } else {
            StrikerVerdict::Inconclusive
        }
    }
}

/// The [`PulseShape`] of the largest compressive pulse in `stress_pa` (compression positive) at
/// `time_s`; None if the series is shorter than 3 samples or has no positive peak.
pub fn pulse_shape(time_s: &[f64], stress_pa: &[f64]) -> Option<PulseShape> {
    let n = time_s.len();
    if n < 3 || stress_pa.len() != n {
        return None;
    }
    let (k, &peak) = stress_pa
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if peak.is_nan() || peak <= 0.0 {
        return None;
    }
    let y = stress_pa;
    // Contiguous run around the peak at or above `level`, and its two crossing times.
    let run = |level: f64| {
        let lo = (0..k).rev().find(|&i| y[i] < level).map_or(0, |i| i + 1);
        let hi = (k + 1..n).find(|&j| y[j] < level).map_or(n - 1, |j| j - 1);
        (lo, hi)
    };
    let cross = |i: usize, level: f64| {
        time_s[i] + (level - y[i]) * (time_s[i + 1] - time_s[i]) / (y[i + 1] - y[i])
    };
    let edges = |level: f64| {
        let (lo, hi) = run(level);
        let up = if lo > 0 {
            cross(lo - 1, level)
        } else {
            time_s[0]
        };
        let down = if hi + 1 < n {
            cross(hi, level)
        } else {
            time_s[n - 1]
        };
        (up, down)
    };
    let (up10, down10) = edges(0.1 * peak);
    let (up50, down50) = edges(0.5 * peak);
    let (up90, _) = edges(0.9 * peak);
    let (lo, hi) = run(0.05 * peak);
    let (mut first, mut second) = (0.0, 0.0);
    for i in lo..hi {
        let dt = time_s[i + 1] - time_s[i];
        first += 0.5 * (y[i] + y[i + 1]) * dt;
        second += 0.5 * (y[i] * y[i] + y[i + 1] * y[i + 1]) * dt;
    }
    Some(PulseShape {
        rise_s: up90 - up10,
        width_half_s: down50 - up50,
        width_10_s: down10 - up10,
        start_fraction: y[0] / peak,
        effective_duration_s: first * first / second,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The authors' calibration line (bars/authors.toml): k, p_loss, 10 cm maraging striker.
    fn authors_line() -> LinearGun {
        let area_m2 = std::f64::consts::PI / 4.0 * 0.01905_f64.powi(2);
        LinearGun {
            k_m2_per_s2_per_pa: 7.163e-4,
            loss_pressure_pa: 21.76e3,
            calibration_mass_kg: 8110.0 * area_m2 * 0.10,
            min_pressure_pa: 44.8e3,
            max_pressure_pa: 206.8e3,
        }
    }

    fn area_m2() -> f64 {
        std::f64::consts::PI / 4.0 * 0.01905_f64.powi(2)
    }

    #[test]
    fn the_calibration_striker_gets_the_calibration_line() {
        let g = authors_line();
        let gun = Gun::Linear(g);
        for psi in [10.0, 12.5, 15.0] {
            let p = psi * PSI_PA;
            let v = gun
                .striker_velocity_m_s(p, g.calibration_mass_kg, area_m2())
                .unwrap();
            // Same formula rearranged: only rounding separates them.
            assert!(
                (v * v / (g.k_m2_per_s2_per_pa * (p - g.loss_pressure_pa)) - 1.0).abs() < 1e-12
            );
        }
    }

    #[test]
    fn a_striker_twice_as_long_gets_the_same_energy_and_v_over_root_two() {
        // ½ m v² = W(p) with W independent of m: doubling m keeps the energy and divides v by √2,
        // so the momentum grows by √2 (and the unshaped pulse, 2 L/c0, doubles in length).
        let g = authors_line();
        let gun = Gun::Linear(g);
        let m = g.calibration_mass_kg;
        let p = 10.0 * PSI_PA;
        let v1 = gun.striker_velocity_m_s(p, m, area_m2()).unwrap();
        let v2 = gun.striker_velocity_m_s(p, 2.0 * m, area_m2()).unwrap();
        assert!((v1 / v2 - 2f64.sqrt()).abs() < 1e-12);
        assert!((0.5 * 2.0 * m * v2 * v2 / (0.5 * m * v1 * v1) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_equivalent_adiabatic_gun_reproduces_the_line_for_any_striker() {
        // The adiabatic work is linear in p (docs/physics.md §6.4), so the frictionless gun that
        // matches slope and zero of the line matches it at every pressure and mass.
        let g = authors_line();
        let a = g
            .equivalent_adiabatic(area_m2(), 1.4, ATMOSPHERE_PA)
            .unwrap();
        // Fitted geometry: A Lb = ½ m_ref k (1 + p_loss/p_atm), 0.353 m of 19.05 mm bore.
        assert!((a.barrel_length_m - 0.3528).abs() < 1e-3, "{a:?}");
        for psi in [7.0, 10.0, 12.5, 15.0, 29.0] {
            for factor in [0.5, 1.0, 2.0] {
                let m = factor * g.calibration_mass_kg;
                let p = psi * PSI_PA;
                let lin = Gun::Linear(g)
                    .striker_velocity_m_s(p, m, area_m2())
                    .unwrap();
                let adi = Gun::Adiabatic(a)
                    .striker_velocity_m_s(p, m, area_m2())
                    .unwrap();
                // The reservoir volume is bisected to ~1e-15 relative; 1e-9 leaves room.
                assert!(
                    (lin / adi - 1.0).abs() < 1e-9,
                    "{psi} psi ×{factor}: {lin} vs {adi}"
                );
            }
        }
    }

    #[test]
    fn a_pressure_outside_the_range_is_refused_with_the_range() {
        let gun = Gun::Linear(authors_line());
        let e = gun
            .striker_velocity_m_s(40.0 * PSI_PA, 0.23, area_m2())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("outside the gun's range") && e.contains("6.5"),
            "{e}"
        );
    }

    /// A trapezoid of plateau `plateau_s` and linear ramps `ramp_s`, sampled every 0.1 µs.
    fn trapezoid(plateau_s: f64, ramp_s: f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..4000).map(|i| i as f64 * 1e-7).collect();
        let t0 = 20e-6;
        let y = t
            .iter()
            .map(|&t| {
                let x = t - t0;
                let up = (x / ramp_s).clamp(0.0, 1.0);
                let down = ((plateau_s + 2.0 * ramp_s - x) / ramp_s).clamp(0.0, 1.0);
                1e8 * up.min(down)
            })
            .collect();
        (t, y)
    }

    #[test]
    fn a_rectangle_and_a_ramp_are_told_apart_by_their_shape() {
        // Trapezoid, ramps r, plateau T: rise 0.8 r, width at half T + r, effective duration
        // (T + r)²/(T + 2r/3). 41 µs plateau with 5 µs ramps (an unshaped 10 cm striker after
        // dispersion): rise fraction 4/46.
        let (t, y) = trapezoid(41e-6, 5e-6);
        let s = pulse_shape(&t, &y).unwrap();
        assert!((s.rise_s - 4e-6).abs() < 1e-9, "{s:?}");
        assert!((s.width_half_s - 46e-6).abs() < 1e-9, "{s:?}");
        assert!((s.width_10_s - 50e-6).abs() < 1e-9, "{s:?}");
        let te = 46e-6_f64.powi(2) / (41e-6 + 2.0 * 5e-6 / 3.0);
        // The 5 % cut-off and the 0.1 µs trapezoid rule: 1e-3 relative.
        assert!((s.effective_duration_s / te - 1.0).abs() < 1e-3, "{s:?}");
        assert_eq!(StrikerVerdict::from_shape(&s), StrikerVerdict::Unshaped);
        // A triangle-like ramp over most of the pulse (a shaper): rise fraction 0.8 × 60/(20+60).
        let (t, y) = trapezoid(20e-6, 60e-6);
        let s = pulse_shape(&t, &y).unwrap();
        assert!((s.rise_fraction() - 0.6).abs() < 1e-6, "{s:?}");
        assert_eq!(StrikerVerdict::from_shape(&s), StrikerVerdict::Shaped);
        assert!(pulse_shape(&t, &vec![0.0; t.len()]).is_none());
        // Cut before 10 % of the peak has been reached: the edge is missing, no verdict.
        let k = t.iter().position(|&x| x > 20e-6 + 12e-6).unwrap();
        let s = pulse_shape(&t[k..], &y[k..]).unwrap();
        assert!((s.start_fraction - 0.2).abs() < 0.01, "{s:?}");
        assert_eq!(StrikerVerdict::from_shape(&s), StrikerVerdict::EdgeMissing);
    }
}

//! The striker and its gas gun: reservoir pressure → striker velocity by adiabatic expansion of
//! the reservoir gas behind the striker over the barrel (Rohrbach et al., Am. J. Phys. 80, 24
//! (2012); docs/physics.md §6).

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

/// The simple gun curve v² = k (p − p_loss) (docs/physics.md §6), equivalent to [`GasGun`] for fixed geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearGun {
    /// k, m²/s² per Pa of gauge pressure.
    pub k_m2_per_s2_per_pa: f64,
    /// Pressure lost to friction and back-pressure, Pa.
    pub loss_pressure_pa: f64,
    /// Smallest usable gauge pressure, Pa.
    pub min_pressure_pa: f64,
    /// Largest rated gauge pressure, Pa.
    pub max_pressure_pa: f64,
}

/// A gas gun model: the linear curve or the adiabatic expansion model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gun {
    /// v² = k (p − p_loss).
    Linear(LinearGun),
    /// Adiabatic reservoir expansion over the barrel (Rohrbach et al. 2012).
    Adiabatic(GasGun),
}

impl Gun {
    /// The allowed gauge-pressure range (min, max), Pa.
    pub fn range_pa(&self) -> (f64, f64) {
        match self {
            Gun::Linear(g) => (g.min_pressure_pa, g.max_pressure_pa),
            Gun::Adiabatic(g) => (g.min_pressure_pa, g.max_pressure_pa),
        }
    }

    /// Striker velocity at gauge pressure `p_gauge_pa` (striker mass and bore for the adiabatic model);
    /// an out-of-range pressure is an [`Error::Invalid`] naming the range.
    pub fn striker_velocity_m_s(&self, p_gauge_pa: f64, mass_kg: f64, area_m2: f64) -> Result<f64> {
        match self {
            Gun::Adiabatic(g) => g.velocity_m_s(p_gauge_pa, mass_kg, area_m2),
            Gun::Linear(g) => {
                let allowed = check_range(p_gauge_pa, g.min_pressure_pa, g.max_pressure_pa)?;
                let v2 = g.k_m2_per_s2_per_pa * (p_gauge_pa - g.loss_pressure_pa);
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

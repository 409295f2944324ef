//! Sphere materials (paper Table I) with Johnson–Cook rate hardening (paper Eq. 2, plus sign).

/// Johnson–Cook rate hardening of the yield stress, `σy* = σy (1 + C ln(ε̇/ε̇0))` (paper Eq. 2 with
/// the sign corrected as in the authors' code, docs/physics.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JohnsonCook {
    /// Dimensionless rate sensitivity C.
    pub c: f64,
    /// Reference (quasi-static) strain rate ε̇0 at which σy was measured, 1/s.
    pub reference_rate_per_s: f64,
}

/// Largest global strain rate (paper Eq. 3) at which the Johnson–Cook constants were fitted or
/// used, 1/s: the paper chose C (Fig. 4 values, docs/physics.md §2) to match its bar tests,
/// whose global rates δ̇/(r1 + r2) reach 1.1e3–5.2e3 1/s (the Fig. 4 records, δ̇ over 2 µs), and
/// ran its FEM with Johnson–Cook at 1e-3, 10 and 1e4 1/s (Fig. 3). Beyond it the rate hardening
/// is an extrapolation and a run says so (a warning, not an error).
pub const JOHNSON_COOK_RATE_LIMIT_PER_S: f64 = 1e4;

impl JohnsonCook {
    /// No rate dependence (C = 0).
    pub const NONE: JohnsonCook = JohnsonCook {
        c: 0.0,
        reference_rate_per_s: 1e-3,
    };

    /// Dynamic yield stress at strain rate `rate_per_s`; equals `sigma_y_pa` for ε̇ ≤ ε̇0 (docs/physics.md §2).
    pub fn dynamic_yield_stress(&self, sigma_y_pa: f64, rate_per_s: f64) -> f64 {
        if rate_per_s > self.reference_rate_per_s && self.c != 0.0 {
            sigma_y_pa * (1.0 + self.c * (rate_per_s / self.reference_rate_per_s).ln())
        } else {
            sigma_y_pa
        }
    }
}

/// An isotropic elastic–perfectly-plastic sphere material with rate hardening (paper Table I).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Short name, e.g. `ss440c`.
    pub name: String,
    /// Mass density, kg/m³.
    pub density_kg_m3: f64,
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio (not given in the paper; docs/physics.md §4 defaults).
    pub poisson_ratio: f64,
    /// Quasi-static yield stress σy, Pa.
    pub yield_stress_pa: f64,
    /// Johnson–Cook rate hardening (paper Eq. 2).
    pub rate: JohnsonCook,
}

impl Material {
    /// Plane-strain modulus E/(1−ν²), Pa (one sphere's share of E*, docs/physics.md §1).
    pub fn plane_strain_modulus_pa(&self) -> f64 {
        self.youngs_modulus_pa / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }

    /// Bar wave speed c0 = √(E/ρ), m/s.
    pub fn wave_speed_m_s(&self) -> f64 {
        (self.youngs_modulus_pa / self.density_kg_m3).sqrt()
    }
}

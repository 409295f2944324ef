//! The copper pulse shaper between striker and incident bar (Frew, Forrestal & Chen,
//! Exp. Mech. 42, 93 (2002); docs/physics.md §6): a thin disc flattened plastically.

/// Frew–Forrestal–Chen pulse shaper: true stress σ = σ0 εⁿ/(1 − εᵐ) at engineering strain ε,
/// area A = A0/(1 − ε) (volume conserved), force F = σ A; elastic (modulus E) below the plastic
/// curve and on unloading, which keeps the plastic strain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseShaper {
    /// Initial diameter, m.
    pub diameter_m: f64,
    /// Initial thickness h0, m.
    pub thickness_m: f64,
    /// Strength coefficient σ0, Pa (Frew et al.: ≈ 0.75 GPa for annealed C11000).
    pub sigma0_pa: f64,
    /// Hardening exponent n (≈ 0.37).
    pub n: f64,
    /// Locking exponent m (≈ 4.25).
    pub m: f64,
    /// Young's modulus of the disc (elastic loading and unloading), Pa.
    pub youngs_modulus_pa: f64,
}

/// The shaper's memory: the largest compressive strain reached and its flow stress.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ShaperState {
    /// Largest engineering strain reached.
    pub max_strain: f64,
    /// True stress at that strain, Pa.
    pub max_stress_pa: f64,
    /// Plastic work dissipated so far, J (∫F dh minus the recoverable elastic part).
    pub work_j: f64,
    /// Last strain seen (for the work increment).
    pub last_strain: f64,
    /// Last force (for the work increment), N.
    pub last_force_n: f64,
}

impl PulseShaper {
    /// Initial area A0, m².
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI * 0.25 * self.diameter_m * self.diameter_m
    }

    /// Flow (true) stress on the plastic curve at strain ε, Pa (Frew et al. 2002).
    pub fn flow_stress_pa(&self, strain: f64) -> f64 {
        if strain <= 0.0 {
            return 0.0;
        }
        let e = strain.min(0.999);
        self.sigma0_pa * e.powf(self.n) / (1.0 - e.powf(self.m))
    }

    /// Compressive force for a closure (approach of its faces) `closure_m`, updating `state`.
    pub fn force_n(&self, state: &mut ShaperState, closure_m: f64) -> f64 {
        let strain = (closure_m / self.thickness_m).min(0.99);
        let stress = if strain >= state.max_strain {
            // Loading: elastic until it meets the plastic curve.
            let s = (self.youngs_modulus_pa * strain)
                .min(self.flow_stress_pa(strain))
                .max(0.0);
            state.max_strain = strain;
            state.max_stress_pa = s;
            s
        } else {
            (state.max_stress_pa - self.youngs_modulus_pa * (state.max_strain - strain)).max(0.0)
        };
        let force = if strain > 0.0 {
            stress * self.area_m2() / (1.0 - strain)
        } else {
            0.0
        };
        let dh = (strain - state.last_strain) * self.thickness_m;
        state.work_j += 0.5 * (force + state.last_force_n) * dh;
        state.last_strain = strain;
        state.last_force_n = force;
        force
    }

    /// Stiffness bound dF/dclosure ≤ E A/(h0 (1−ε)²) used for the explicit stability limit, N/m.
    pub fn max_stiffness_n_per_m(&self, strain: f64) -> f64 {
        let e = strain.clamp(0.0, 0.99);
        self.youngs_modulus_pa * self.area_m2() / (self.thickness_m * (1.0 - e) * (1.0 - e))
    }
}

//! The bar's energy ledger (docs/physics.md §6.6): the energy E^{n−1/2} carried from step to step
//! by the end work less the absorbed energy, O(1) a step, rebased on and checked against a full
//! recomputation (the theory's kinetic plus strain energy), or on a dispersive delay line the
//! transit's passivity (§6.2.1); the finiteness checks that name a node.

use super::Bar;
use super::dispersive::Transit;
use crate::error::{Error, Result};

/// Largest accepted difference between a bar's energy ledger and its full recomputation, relative
/// to the energy that has passed through the ledger or, if larger, the energy in play around the
/// bar (e.g. the whole chain's: [`Bar::check_energy_ledger`]). The two agree to rounding: each step
/// adds a few ulp of the turnover, so 10⁶ steps stay near 1e-10; 1e-9 is the output tolerance of
/// the results ("results unchanged", `validation/perf/REPORT.md`).
pub const ENERGY_LEDGER_TOLERANCE: f64 = 1e-9;

/// The energy ledger of a bar and the end work and absorbed energy it books (docs/physics.md §6.6).
#[derive(Debug, Clone, Default)]
pub(super) struct Ledger {
    /// Energy that left through absorbing ends, J.
    pub(super) absorbed_j: f64,
    /// Work of the external end forces, J.
    pub(super) work_j: f64,
    /// Kinetic + strain energy at n − 1/2 carried by the ledger: the last full recomputation plus
    /// the end work and minus the absorbed energy of every step since, J.
    pub(super) energy_j: f64,
    /// The energy that has passed through the ledger (|energy| at the last full recomputation plus
    /// every step's |work| and absorbed energy since): the scale of its rounding error, J.
    pub(super) turnover_j: f64,
}

impl Ledger {
    /// Books one step at both ends: end forces `f`, end velocities v^{n−1/2} `v_before` and
    /// v^{n+1/2} `v_after`, dashpots `impedance`, time step `dt`.
    pub(super) fn book(
        &mut self,
        impedance: [f64; 2],
        f: [f64; 2],
        v_before: [f64; 2],
        v_after: [f64; 2],
        dt: f64,
    ) {
        for end in 0..2 {
            let mean = 0.5 * (v_before[end] + v_after[end]);
            let work = f[end] * mean * dt;
            let absorbed = impedance[end] * mean * mean * dt;
            self.work_j += work;
            self.absorbed_j += absorbed;
            // The scheme's energy identity: E^{n+1/2} − E^{n−1/2} = Σ_ends (F − Z v̄) v̄ Δt.
            self.energy_j += work - absorbed;
            self.turnover_j += work.abs() + absorbed;
        }
    }
}

impl Bar {
    /// Restarts the energy ledger from a full recomputation (after the masses or the velocities
    /// were set outside a step).
    pub(super) fn rebase_energy_ledger(&mut self) {
        self.ledger.energy_j = self.recomputed_energy_j();
        self.ledger.turnover_j = self.ledger.energy_j.abs();
        self.interior.get_mut().rebase(&self.nodes);
    }

    /// Momentum Σ m v of the nodes at level n, kg·m/s: the sum over the nodes of
    /// [`Bar::velocity_m_s`]; for a dispersive delay line (whose interior reads cost a
    /// convolution each) the same quantity from its impulse ledger: Σ m v^{n−1/2} carried by the
    /// end velocities' changes and the end springs' forces, plus half the coming step's.
    pub fn momentum_kg_m_s(&self) -> f64 {
        self.interior.get().momentum(&self.nodes)
    }

    /// Kinetic energy ½ v^{n−1/2}ᵀ M v^{n−1/2} at the half level n − 1/2 (with the Love lateral part), J.
    pub fn kinetic_energy_j(&self) -> f64 {
        self.interior.get().kinetic_energy(&self.nodes)
    }

    /// Strain energy ½ u^{n−1}ᵀ K u^n at the half level n − 1/2: with the kinetic energy, the scheme's exactly conserved energy, J.
    pub fn strain_energy_j(&self) -> f64 {
        self.interior.get().strain_energy(&self.nodes)
    }

    /// Kinetic plus strain energy at the half level n − 1/2 from the energy ledger: the last full
    /// recomputation plus the end work less the absorbed energy of each step since, O(1), J. Equal
    /// to [`Bar::recomputed_energy_j`] to rounding ([`Bar::check_energy_ledger`]).
    pub fn energy_j(&self) -> f64 {
        self.ledger.energy_j
    }

    /// The energy that has passed through the ledger since its last rebase (|energy| then, plus
    /// every step's |work| and absorbed energy), J: the scale of the ledger's rounding.
    pub fn energy_turnover_j(&self) -> f64 {
        self.ledger.turnover_j
    }

    /// Kinetic plus strain energy at the half level n − 1/2 summed over every node and element
    /// (a whole-bar pass), J.
    pub fn recomputed_energy_j(&self) -> f64 {
        self.kinetic_energy_j() + self.strain_energy_j()
    }

    /// Compares the energy ledger with a full recomputation: Error::Unstable (naming step, time,
    /// bar and the difference) if they differ by more than [`ENERGY_LEDGER_TOLERANCE`] of the
    /// larger of the energy that has passed through the ledger and `scale_j` (the energy in play
    /// around the bar, J: a bar reached only by a tiny precursor has a turnover of 1e-315 J, whose
    /// rounding is judged against the energy of the test), or if the ledger is not finite.
    pub fn check_energy_ledger(&self, scale_j: f64) -> Result<()> {
        if let Some(t) = self.transit().filter(|t| t.step > 0) {
            return self.check_transit_passivity(t, scale_j);
        }
        let full = self.recomputed_energy_j();
        let difference = self.ledger.energy_j - full;
        let scale = self.ledger.turnover_j.max(scale_j);
        if difference.is_finite() && difference.abs() <= ENERGY_LEDGER_TOLERANCE * scale {
            return Ok(());
        }
        Err(Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity: format!(
                "bar {}: energy ledger {:e} J minus its recomputation {full:e} J (allowed: {ENERGY_LEDGER_TOLERANCE:e} of {scale:e} J)",
                self.name, self.ledger.energy_j
            ),
            value: difference,
        })
    }

    /// The dispersive delay line's energy check (docs/physics.md §6.2.1): the
    /// transit delivers no more wave energy than was injected into it (k Σ D̃² ≤ k Σ D², the
    /// filters being passive), and the ledger is finite and not below zero, each within
    /// [`ENERGY_LEDGER_TOLERANCE`] of the energy in play.
    fn check_transit_passivity(&self, t: &Transit, scale_j: f64) -> Result<()> {
        let k = self.nodes.k[0];
        let scale = self.ledger.turnover_j.max(scale_j);
        // A truncated filter's gain may exceed one by its truncation error: allow that share
        // of the wave energy delivered, on top of the rounding of the energy in play.
        let excess = k * (t.delivered_sq - t.injected_sq);
        let allowed = ENERGY_LEDGER_TOLERANCE * scale + k * t.delivered_sq * t.ends_gain_excess;
        let (quantity, value) = if excess.is_nan() || excess > allowed {
            (
                format!(
                    "bar {}: the dispersive transit delivered {excess:e} J more wave energy than it was given \
                     (allowed: {allowed:e} J)",
                    self.name
                ),
                excess,
            )
        } else if self.ledger.energy_j.is_nan() || self.ledger.energy_j < -allowed {
            (
                format!(
                    "bar {}: energy ledger {:e} J (allowed: ≥ {:e} J)",
                    self.name, self.ledger.energy_j, -allowed
                ),
                self.ledger.energy_j,
            )
        } else {
            return Ok(());
        };
        Err(Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity,
            value,
        })
    }

    /// O(1) check of one step: the energy ledger is finite (it takes the end velocities every
    /// step, so a non-finite value at an end, where the joints read the bar, shows at once); if it
    /// is not, the whole-bar [`Bar::check_finite`] names the node.
    pub fn check_step(&self) -> Result<()> {
        if self.ledger.energy_j.is_finite() {
            return Ok(());
        }
        self.check_finite()?;
        self.check_energy_ledger(0.0)
    }

    /// Energy that left through absorbing ends so far, Σ Z Δt ((v^{n+1/2} + v^{n−1/2})/2)², J.
    pub fn absorbed_energy_j(&self) -> f64 {
        self.ledger.absorbed_j
    }

    /// Work done by the external end forces so far, Σ F^n Δt (v^{n+1/2} + v^{n−1/2})/2, J.
    pub fn work_done_j(&self) -> f64 {
        self.ledger.work_j
    }

    /// Test hook: sets v_i^{n−1/2} of node i and shifts the energy ledger by `ledger_offset_j`
    /// without rebasing it (a state corrupted behind the ledger's back).
    #[cfg(test)]
    pub(crate) fn corrupt_for_test(&mut self, i: usize, v_m_s: f64, ledger_offset_j: f64) {
        self.interior
            .get_mut()
            .set_half_step_velocity(&mut self.nodes, i, v_m_s);
        self.ledger.energy_j += ledger_offset_j;
    }

    /// Checks that displacements and velocities are finite (Error::Unstable naming step, time, node).
    pub fn check_finite(&self) -> Result<()> {
        for (what, values) in [
            ("displacement", &self.nodes.u),
            ("half-step velocity", &self.nodes.v),
        ] {
            if let Some((i, &value)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(self.unstable_node(what, i, value));
            }
        }
        if let Some((what, i, value)) = self.interior.get().first_non_finite(&self.nodes) {
            return Err(self.unstable_node(what, i, value));
        }
        Ok(())
    }

    /// Error::Unstable naming step, time, bar, the quantity `what` of node i and its value.
    fn unstable_node(&self, what: &str, i: usize, value: f64) -> Error {
        Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity: format!(
                "bar {}: {what} of node {i} (x = {} m)",
                self.name, self.x[i]
            ),
            value,
        }
    }
}

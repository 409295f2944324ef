//! The end nodes of a bar, shared by every theory (docs/physics.md §6.2, "Absorbing end"; §6.6):
//! the end conditions, the absorbing dashpots Z = ρ c0 A taken at the mid-step velocity, the end
//! forces of a step, added masses, and what a joint reads of an end (free velocity, mobility,
//! end-element force), with the rigid butt contact between two bars.

use super::{Bar, BarSpec, EndCondition, Segment};

/// The two ends of a bar: conditions, dashpots and the forces of the last step.
#[derive(Debug, Clone)]
pub(super) struct Ends {
    /// Condition at [x = 0, x = L].
    pub(super) condition: [EndCondition; 2],
    /// Dashpot coefficient Z at each end (0 unless absorbing), kg/s.
    pub(super) impedance: [f64; 2],
    /// The end forces of the last step, N.
    pub(super) last_force: [f64; 2],
}

impl Ends {
    /// The ends of `spec`: a dashpot ρ c0 A of the end segment at an absorbing end.
    pub(super) fn new(spec: &BarSpec) -> Ends {
        let z = |s: &Segment, end: EndCondition| {
            if end == EndCondition::Absorbing {
                s.impedance_kg_s()
            } else {
                0.0
            }
        };
        let (first, last) = (&spec.segments[0], &spec.segments[spec.segments.len() - 1]);
        Ends {
            condition: [spec.left_end, spec.right_end],
            impedance: [z(first, spec.left_end), z(last, spec.right_end)],
            last_force: [0.0; 2],
        }
    }

    /// Whether each end is clamped.
    pub(super) fn fixed(&self) -> [bool; 2] {
        [
            self.condition[0] == EndCondition::Fixed,
            self.condition[1] == EndCondition::Fixed,
        ]
    }

    /// The dashpot coefficient D_i of each of `nodes` nodes (Z at an absorbing end, else 0), kg/s.
    pub(super) fn damping(&self, nodes: usize) -> Vec<f64> {
        let mut damping = vec![0.0; nodes];
        damping[0] += self.impedance[0];
        damping[nodes - 1] += self.impedance[1];
        damping
    }

    /// The external forces a step applies: `left` and `right`, none at a fixed end, N.
    pub(super) fn forces(&self, left_force_n: f64, right_force_n: f64) -> [f64; 2] {
        [
            if self.condition[0] == EndCondition::Fixed {
                0.0
            } else {
                left_force_n
            },
            if self.condition[1] == EndCondition::Fixed {
                0.0
            } else {
                right_force_n
            },
        ]
    }

    /// Internal force on each end node less its dashpot: [T_0 − Z v_0, −T_{N−1} − Z v_N] from the
    /// end elements' tensions `tension` and the end nodes' v^{n−1/2} `v`, N.
    pub(super) fn rhs(&self, tension: [f64; 2], v: [f64; 2]) -> [f64; 2] {
        [
            tension[0] - self.impedance[0] * v[0],
            -tension[1] - self.impedance[1] * v[1],
        ]
    }
}

/// Change of node i's v^{n+1/2} per unit time from end forces `f` on a lumped chain of nodes
/// 0..=`last`: f/(m + Δt Z/2) at the end node it acts on, `inv` = [1/(m + Δt Z/2) of each end]
/// (0 at a fixed end), m/s².
pub(super) fn lumped_response(inv: [f64; 2], i: usize, last: usize, f: [f64; 2]) -> f64 {
    let mut r = 0.0;
    if i == 0 {
        r += inv[0] * f[0];
    }
    if i == last {
        r += inv[1] * f[1];
    }
    r
}

/// Adds a lumped chain's response to end forces `f` to the free rate `w` (`inv` as in
/// [`lumped_response`]).
pub(super) fn add_lumped_forces(inv: [f64; 2], w: &mut [f64], f: [f64; 2]) {
    let last = w.len() - 1;
    w[0] += inv[0] * f[0];
    w[last] += inv[1] * f[1];
}

impl Bar {
    /// v^{n+1/2} that an end node gets from the coming step if no external force acts, m/s (for contacts).
    pub fn free_end_velocity_m_s(&self, right: bool) -> f64 {
        let c = &self.nodes;
        let i = if right { c.u.len() - 1 } else { 0 };
        c.v[i] + c.dt_s * c.w[i]
    }

    /// ∂v^{n+1/2}/∂F of the end node `velocity_at_right` per newton on end `force_at_right`: Δt (A⁻¹)_{ij}, s/kg.
    pub fn end_mobility_s_per_kg(&self, velocity_at_right: bool, force_at_right: bool) -> f64 {
        let i = if velocity_at_right {
            self.nodes.u.len() - 1
        } else {
            0
        };
        let f = if force_at_right {
            [0.0, 1.0]
        } else {
            [1.0, 0.0]
        };
        self.nodes.dt_s * self.interior.get().force_response(&self.nodes, i, f)
    }

    /// Adds a lumped mass to node i (e.g. a sphere joining the end node), kg; best before stepping.
    ///
    /// Only raises the stability limit. The energy ledger uses the current masses, so a mass added
    /// to a moving node changes the reported kinetic energy. An interior node mass turns a delay
    /// line into the leapfrog on every node (docs/physics.md §6.2, "Delay lines").
    ///
    /// # Panics
    /// If `i` is out of range or `mass_kg` is negative or not finite (a programming error: validate
    /// input first), or if `i` is an interior node of a dispersive delay line.
    pub fn add_node_mass(&mut self, i: usize, mass_kg: f64) {
        assert!(
            mass_kg.is_finite() && mass_kg >= 0.0,
            "bar {}: added node mass must be finite and ≥ 0, got {mass_kg}",
            self.name
        );
        if i > 0
            && i + 1 < self.nodes.u.len()
            && let Some(leapfrog) = self.interior.get().materialise(&mut self.nodes, &self.name)
        {
            self.interior = super::Theory::Leapfrog(leapfrog);
        }
        self.nodes.mass[i] += mass_kg;
        self.refresh_operators();
    }

    /// Lumped (diagonal) mass of node i, kg: half of each neighbouring cell plus added masses (no Love term).
    pub fn node_mass_kg(&self, i: usize) -> f64 {
        self.nodes.mass[i]
    }

    /// Axial force (tension positive) in the end element, k (u_1 − u_0) or k (u_N − u_{N−1}), N.
    pub fn end_force_n(&self, right: bool) -> f64 {
        let e = if right { self.nodes.k.len() - 1 } else { 0 };
        self.nodes.k[e] * self.interior.get().stretch(&self.nodes, e)
    }
}

/// Compression-only rigid contact between the right end of `left` and the left end of `right`
/// (same Δt): the force (N, ≥ 0, compressive) that closes the gap exactly at the end of the
/// coming step if it would otherwise close, else 0; apply it as `left.step(.., −F)`, `right.step(F, ..)`.
///
/// The gap at the current level is `initial_gap_m + u_right(0) − u_left(N)`. While closed, the two
/// half-mass end nodes move as one full node, so two equal bars at Courant 1 behave exactly as one
/// continuous bar (the impact of a striker is exact); the very first step of an impact merges two
/// half-mass nodes of different velocities, the discrete counterpart of the velocity jump
/// (docs/physics.md §6.6). Forces applied by the caller at the far ends are not included (their
/// cross-mobility is zero for a lumped chain and decays geometrically along a Love rod).
pub fn rigid_contact_force_n(left: &Bar, right: &Bar, initial_gap_m: f64) -> f64 {
    let dt = left.dt_s();
    debug_assert!(
        (right.dt_s() - dt).abs() <= 1e-12 * dt,
        "contact between bars with different time steps"
    );
    let gap = initial_gap_m + right.displacement_m(0) - left.displacement_m(left.node_count() - 1);
    let closing =
        gap + dt * (right.free_end_velocity_m_s(false) - left.free_end_velocity_m_s(true));
    let mobility =
        left.end_mobility_s_per_kg(true, true) + right.end_mobility_s_per_kg(false, false);
    if closing < 0.0 && mobility > 0.0 {
        -closing / (dt * mobility)
    } else {
        0.0
    }
}

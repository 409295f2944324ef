//! The bodies of a chain (docs/physics.md §5–§6): bar segments discretised on the common time
//! step, and rigid masses (a sphere between two contacts). Both advance by the same leapfrog
//! (v^{n+1/2} = v^{n−1/2} + Δt F/m, u^{n+1} = u^n + Δt v^{n+1/2}) and expose the same end
//! data to the joints: current displacement, last half-step velocity, the velocity the coming
//! step would give the end without the joint's force, and the end's mobility ∂v/∂F.

use super::cylinder::PlasticCylinder;
use crate::bar::{Bar, BarSpec};
use crate::error::{Error, Result};
use crate::specimen::CylinderSpecimen;

/// What a chain is built from, left to right.
#[derive(Debug, Clone, PartialEq)]
pub enum BodySpec {
    /// An elastic bar (striker, incident, transmission, an insert).
    Bar(BarSpec),
    /// A rigid mass, e.g. a sphere of a chain between two contacts.
    Mass(MassSpec),
    /// An elastoplastic cylindrical specimen (docs/physics.md §6.12).
    Cylinder(CylinderSpecimen),
}

impl From<BarSpec> for BodySpec {
    fn from(spec: BarSpec) -> BodySpec {
        BodySpec::Bar(spec)
    }
}

/// A rigid body moving along the bar axis.
#[derive(Debug, Clone, PartialEq)]
pub struct MassSpec {
    /// Name (e.g. `sphere 2`).
    pub name: String,
    /// Mass, kg.
    pub mass_kg: f64,
}

/// A rigid mass on the chain's time step (same leapfrog as a bar node).
#[derive(Debug, Clone, PartialEq)]
pub struct PointMass {
    name: String,
    mass_kg: f64,
    dt_s: f64,
    /// Displacement from the initial position at level n, m.
    displacement_m: f64,
    /// Velocity at level n − 1/2, m/s.
    velocity_m_s: f64,
    step_index: usize,
}

impl PointMass {
    /// A mass at rest on time step `dt_s`; errors on a mass that is not finite and positive.
    pub fn new(spec: &MassSpec, dt_s: f64) -> Result<PointMass> {
        if !(spec.mass_kg.is_finite() && spec.mass_kg > 0.0) {
            return Err(Error::Invalid {
                object: spec.name.clone(),
                quantity: "mass_kg".into(),
                problem: format!("{} is not a finite positive mass", spec.mass_kg),
                allowed: "> 0 kg".into(),
            });
        }
        Ok(PointMass {
            name: spec.name.clone(),
            mass_kg: spec.mass_kg,
            dt_s,
            displacement_m: 0.0,
            velocity_m_s: 0.0,
            step_index: 0,
        })
    }
}

/// A body of a chain, in its time-stepping state.
#[derive(Debug, Clone)]
pub enum Body {
    /// An elastic bar (boxed: a bar is large, a mass is small).
    Bar(Box<Bar>),
    /// A rigid mass.
    Mass(PointMass),
    /// An elastoplastic cylinder (boxed, as a bar).
    Cylinder(Box<PlasticCylinder>),
}

impl Body {
    /// Builds the body on time step `dt_s` (bars check their stability limit).
    pub fn new(spec: &BodySpec, dt_s: f64) -> Result<Body> {
        Ok(match spec {
            BodySpec::Bar(s) => Body::Bar(Box::new(Bar::new(s, dt_s)?)),
            BodySpec::Mass(m) => Body::Mass(PointMass::new(m, dt_s)?),
            BodySpec::Cylinder(c) => Body::Cylinder(Box::new(PlasticCylinder::new(c, dt_s)?)),
        })
    }

    /// The body's name.
    pub fn name(&self) -> &str {
        match self {
            Body::Bar(b) => b.name(),
            Body::Mass(m) => &m.name,
            Body::Cylinder(c) => c.name(),
        }
    }

    /// The bar, if the body is one.
    pub fn as_bar(&self) -> Option<&Bar> {
        match self {
            Body::Bar(b) => Some(b),
            _ => None,
        }
    }

    /// The elastoplastic cylinder, if the body is one.
    pub fn as_cylinder(&self) -> Option<&PlasticCylinder> {
        match self {
            Body::Cylinder(c) => Some(c),
            _ => None,
        }
    }

    /// Displacement u^n of an end (right end if `right`), m.
    pub fn end_displacement_m(&self, right: bool) -> f64 {
        match self {
            Body::Bar(b) => b.displacement_m(if right { b.node_count() - 1 } else { 0 }),
            Body::Mass(m) => m.displacement_m,
            Body::Cylinder(c) => c.displacement_m(if right { c.node_count() - 1 } else { 0 }),
        }
    }

    /// Velocity v^{n−1/2} of an end, m/s.
    pub fn end_half_step_velocity_m_s(&self, right: bool) -> f64 {
        match self {
            Body::Bar(b) => b.half_step_velocity_m_s(if right { b.node_count() - 1 } else { 0 }),
            Body::Mass(m) => m.velocity_m_s,
            Body::Cylinder(c) => {
                c.half_step_velocity_m_s(if right { c.node_count() - 1 } else { 0 })
            }
        }
    }

    /// v^{n+1/2} of an end if the joint at that end carried no force, given the force (N, toward
    /// +x) applied at the other end this step: a bar's ends are one step apart, so a bar ignores
    /// it; a rigid mass moves as a whole.
    pub fn free_end_velocity_m_s(&self, right: bool, other_end_force_n: f64) -> f64 {
        match self {
            Body::Bar(b) => b.free_end_velocity_m_s(right),
            Body::Mass(m) => m.velocity_m_s + m.dt_s * other_end_force_n / m.mass_kg,
            Body::Cylinder(c) => c.free_end_velocity_m_s(right, other_end_force_n),
        }
    }

    /// ∂v^{n+1/2}/∂F of an end per newton applied at that same end, s/kg.
    pub fn end_mobility_s_per_kg(&self, right: bool) -> f64 {
        match self {
            Body::Bar(b) => b.end_mobility_s_per_kg(right, right),
            Body::Mass(m) => m.dt_s / m.mass_kg,
            Body::Cylinder(c) => c.end_mobility_s_per_kg(right),
        }
    }

    /// Whether the force at one end moves the other end within the same step (a rigid mass, a
    /// cylinder with radial inertia).
    pub fn is_rigid(&self) -> bool {
        match self {
            Body::Mass(_) => true,
            Body::Cylinder(c) => c.couples_ends(),
            Body::Bar(_) => false,
        }
    }

    /// Advances one step with forces (N, toward +x) at the left and right ends.
    pub fn step(&mut self, left_force_n: f64, right_force_n: f64) {
        match self {
            Body::Bar(b) => b.step(left_force_n, right_force_n),
            Body::Mass(m) => {
                m.velocity_m_s += m.dt_s * (left_force_n + right_force_n) / m.mass_kg;
                m.displacement_m += m.dt_s * m.velocity_m_s;
                m.step_index += 1;
            }
            Body::Cylinder(c) => c.step(left_force_n, right_force_n),
        }
    }

    /// Sets the body moving rigidly at `v_m_s` (the striker, or the first sphere of a collision).
    pub fn set_initial_velocity(&mut self, v_m_s: f64) {
        match self {
            Body::Bar(b) => b.set_initial_velocity(v_m_s),
            Body::Mass(m) => m.velocity_m_s = v_m_s,
            Body::Cylinder(c) => c.set_initial_velocity(v_m_s),
        }
    }

    /// Total mass, kg.
    pub fn mass_kg(&self) -> f64 {
        match self {
            Body::Bar(b) => (0..b.node_count()).map(|i| b.node_mass_kg(i)).sum(),
            Body::Mass(m) => m.mass_kg,
            Body::Cylinder(c) => (0..c.node_count()).map(|i| c.node_mass_kg(i)).sum(),
        }
    }

    /// Momentum Σ m v, kg·m/s (a bar's nodes at level n, a mass at its last half level).
    pub fn momentum_kg_m_s(&self) -> f64 {
        match self {
            Body::Bar(b) => b.momentum_kg_m_s(),
            Body::Mass(m) => m.mass_kg * m.velocity_m_s,
            Body::Cylinder(c) => c.momentum_kg_m_s(),
        }
    }

    /// Kinetic plus strain energy at the half level n − 1/2 (the scheme's conserved energy), J: a
    /// bar's from its energy ledger ([`Bar::energy_j`], O(1)), a mass's from its velocity, a
    /// cylinder's kinetic plus elastic energy from its ledger ([`PlasticCylinder::energy_j`]).
    pub fn energy_j(&self) -> f64 {
        match self {
            Body::Bar(b) => b.energy_j(),
            Body::Mass(m) => 0.5 * m.mass_kg * m.velocity_m_s * m.velocity_m_s,
            Body::Cylinder(c) => c.energy_j(),
        }
    }

    /// Plastic work done in the body so far (a cylinder's; 0 otherwise), J.
    pub fn plastic_work_j(&self) -> f64 {
        self.as_cylinder()
            .map_or(0.0, PlasticCylinder::plastic_work_j)
    }

    /// Friction work at the body's faces so far (a cylinder's; 0 otherwise), J.
    pub fn friction_work_j(&self) -> f64 {
        self.as_cylinder()
            .map_or(0.0, PlasticCylinder::friction_work_j)
    }

    /// Kinetic energy given to the body by its changing radial-inertia mass (a cylinder's;
    /// 0 otherwise), J.
    pub fn inertia_exchange_j(&self) -> f64 {
        self.as_cylinder()
            .map_or(0.0, PlasticCylinder::inertia_exchange_j)
    }

    /// The energy that has passed through the body: a bar's ledger turnover
    /// ([`Bar::energy_turnover_j`]), a mass's kinetic energy, J.
    pub fn energy_turnover_j(&self) -> f64 {
        match self {
            Body::Bar(b) => b.energy_turnover_j(),
            Body::Mass(_) => self.energy_j(),
            Body::Cylinder(c) => c.energy_turnover_j(),
        }
    }

    /// [`Body::energy_j`] recomputed over the whole body (a bar: every node and element), J.
    pub fn recomputed_energy_j(&self) -> f64 {
        match self {
            Body::Bar(b) => b.recomputed_energy_j(),
            Body::Mass(_) => self.energy_j(),
            Body::Cylinder(c) => c.recomputed_energy_j(),
        }
    }

    /// Energy that left through absorbing ends so far, J (0 for a mass).
    pub fn absorbed_energy_j(&self) -> f64 {
        match self {
            Body::Bar(b) => b.absorbed_energy_j(),
            Body::Mass(_) | Body::Cylinder(_) => 0.0,
        }
    }

    /// The O(1) check of every step: a bar's energy ledger is finite ([`Bar::check_step`]), a
    /// mass's state is finite (Error::Unstable naming step, time and quantity).
    pub fn check_step(&self) -> Result<()> {
        match self {
            Body::Bar(b) => b.check_step(),
            Body::Mass(_) => self.check_finite(),
            Body::Cylinder(c) => c.check_step(),
        }
    }

    /// The full check of the interval: every value is finite, then a bar's energy ledger agrees
    /// with its recomputation ([`Bar::check_energy_ledger`] with the energy in play `scale_j`, J).
    pub fn check_full(&self, scale_j: f64) -> Result<()> {
        self.check_finite()?;
        match self {
            Body::Bar(b) => b.check_energy_ledger(scale_j),
            Body::Mass(_) => Ok(()),
            Body::Cylinder(c) => c.check_energy_ledger(scale_j),
        }
    }

    /// Checks that the state is finite (Error::Unstable naming step, time and quantity).
    pub fn check_finite(&self) -> Result<()> {
        match self {
            Body::Bar(b) => b.check_finite(),
            Body::Mass(m) => {
                for (what, value) in [
                    ("displacement", m.displacement_m),
                    ("velocity", m.velocity_m_s),
                ] {
                    if !value.is_finite() {
                        return Err(Error::Unstable {
                            step: m.step_index,
                            time_s: m.step_index as f64 * m.dt_s,
                            quantity: format!("mass {}: {what}", m.name),
                            value,
                        });
                    }
                }
                Ok(())
            }
            Body::Cylinder(c) => c.check_finite(),
        }
    }
}

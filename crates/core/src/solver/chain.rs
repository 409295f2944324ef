//! The apparatus in time as a chain of bodies joined end to end (docs/physics.md §6):
//! striker → (pulse shaper) → incident bar → specimen → transmission bar, or any other chain of
//! bars and rigid masses (a chain of spheres) joined by butt joints, shapers and contacts, all
//! on one time step (Courant number 1 in the bars).
//!
//! Each step predicts every joint from its two bodies' free end velocities and mobilities
//! ([`JointPrediction`]) and solves its force ([`JointState::trial_force_n`]). A bar's two ends
//! are a step apart, so joints between bars are independent and one pass is exact. A rigid mass
//! between two joints couples them within the step; the joint forces are then found by
//! nonlinear Gauss–Seidel sweeps (each joint's force given its neighbours') until no force
//! changes by more than 1e-12 of the largest, which converges because the coupled system is
//! monotone (each force falls as its neighbour's rises less than it rises with its own closure).
//! Every joint then commits its memory once, and every body steps with its end forces.

use super::body::{Body, BodySpec};
use super::joint::{Joint, JointPrediction, JointState};
use super::record::{
    BarSnapshots, ContactRecorder, EnergyRecorder, GaugeProbe, GaugeRecorder, Recorder,
    SnapshotRecorder,
};
use crate::error::{Error, Result};

/// Inputs of a chain run: bodies joined end to end, the first moving at the striker speed.
#[derive(Debug, Clone)]
pub struct ChainSetup {
    /// The bodies, left to right (striker first).
    pub bodies: Vec<BodySpec>,
    /// The joints between consecutive bodies.
    pub joints: Vec<Joint>,
    /// Initial velocity of the first body, m/s.
    pub striker_velocity_m_s: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Gauges to record.
    pub gauges: Vec<GaugeProbe>,
    /// Record every n-th step.
    pub record_every: usize,
    /// Lumped masses added to bar ends before the run: (body index, right end?, kg) — spheres at bar ends.
    pub end_masses: Vec<(usize, bool, f64)>,
    /// Record the stress field of every bar every this many steps (None: no snapshots).
    pub snapshot_every: Option<usize>,
    /// Spacing of the snapshot points along the bars, m.
    pub snapshot_spacing_m: f64,
}

/// A chain in its time-stepping state.
pub struct Chain {
    /// The bodies, left to right.
    pub bodies: Vec<Body>,
    /// The joints between consecutive bodies.
    pub joints: Vec<JointState>,
    dt_s: f64,
    step_index: usize,
    forces: Vec<f64>,
    coupled: bool,
}

impl Chain {
    /// Builds the bodies (with end masses and the first body's velocity) and fresh joints.
    pub fn new(setup: &ChainSetup) -> Result<Chain> {
        if setup.joints.len() + 1 != setup.bodies.len() {
            return Err(Error::invalid(
                "joints",
                format!(
                    "{} joints for {} bodies",
                    setup.joints.len(),
                    setup.bodies.len()
                ),
                "one joint between each two consecutive bodies",
            ));
        }
        let mut bodies = setup
            .bodies
            .iter()
            .map(|s| Body::new(s, setup.dt_s))
            .collect::<Result<Vec<_>>>()?;
        for &(k, right, mass_kg) in &setup.end_masses {
            match &mut bodies[k] {
                Body::Bar(bar) => {
                    let node = if right { bar.node_count() - 1 } else { 0 };
                    bar.add_node_mass(node, mass_kg);
                }
                Body::Mass(_) => {
                    return Err(Error::invalid(
                        "end_masses",
                        format!("body {k} is a rigid mass"),
                        "masses are added to bar ends",
                    ));
                }
            }
        }
        for g in &setup.gauges {
            if bodies.get(g.bar).and_then(Body::as_bar).is_none() {
                return Err(Error::Invalid {
                    object: format!("gauge {}", g.name),
                    quantity: "bar".into(),
                    problem: format!("body {} is not a bar of the chain", g.bar),
                    allowed: "the index of a bar".into(),
                });
            }
        }
        bodies[0].set_initial_velocity(setup.striker_velocity_m_s);
        let n = bodies.len();
        let coupled = (1..n.saturating_sub(1)).any(|k| bodies[k].is_rigid());
        Ok(Chain {
            bodies,
            joints: setup.joints.iter().map(|&j| JointState::new(j)).collect(),
            dt_s: setup.dt_s,
            step_index: 0,
            forces: vec![0.0; setup.joints.len()],
            coupled,
        })
    }

    /// Time of the current level, s.
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.dt_s
    }

    /// Steps taken.
    pub fn step_index(&self) -> usize {
        self.step_index
    }

    /// Prediction of joint `k` given the current estimates of the other joints' forces.
    fn predict(&self, k: usize) -> JointPrediction {
        // Forces toward +x on the far ends of the joint's two bodies.
        let left_other = if k > 0 { self.forces[k - 1] } else { 0.0 };
        let right_other = if k + 1 < self.forces.len() {
            -self.forces[k + 1]
        } else {
            0.0
        };
        JointPrediction::new(
            &self.bodies[k],
            &self.bodies[k + 1],
            left_other,
            right_other,
            self.dt_s,
        )
    }

    /// Advances one step (module docs).
    pub fn step(&mut self) -> Result<()> {
        let dt = self.dt_s;
        if self.coupled {
            self.forces.fill(0.0);
            for sweep in 0.. {
                let mut change = 0.0f64;
                for k in 0..self.joints.len() {
                    let f = self.joints[k].trial_force_n(&self.predict(k), dt);
                    change = change.max((f - self.forces[k]).abs());
                    self.forces[k] = f;
                }
                let scale = self.forces.iter().fold(0.0f64, |a, &f| a.max(f));
                if change <= 1e-12 * scale || sweep == 1000 {
                    break;
                }
            }
            for k in 0..self.joints.len() {
                let p = self.predict(k);
                self.joints[k].commit(&p, self.forces[k], dt);
            }
        } else {
            for k in 0..self.joints.len() {
                let p = self.predict(k);
                let f = self.joints[k].trial_force_n(&p, dt);
                self.joints[k].commit(&p, f, dt);
                self.forces[k] = f;
            }
        }
        let n = self.bodies.len();
        for (k, body) in self.bodies.iter_mut().enumerate() {
            let left = if k > 0 { self.forces[k - 1] } else { 0.0 };
            let right = if k + 1 < n { -self.forces[k] } else { 0.0 };
            body.step(left, right);
            body.check_finite()?;
        }
        self.step_index += 1;
        Ok(())
    }

    /// Runs `steps` steps, calling every recorder before the first and after each step; stops
    /// with [`Error::Cancelled`] when a recorder asks to ([`Recorder::stop`]).
    pub fn run(&mut self, steps: usize, recorders: &mut [&mut dyn Recorder]) -> Result<()> {
        for r in recorders.iter_mut() {
            r.record(self.step_index, self.time_s(), &self.bodies, &self.joints);
        }
        for _ in 0..steps {
            self.step()?;
            for r in recorders.iter_mut() {
                r.record(self.step_index, self.time_s(), &self.bodies, &self.joints);
            }
            if recorders.iter().any(|r| r.stop()) {
                return Err(Error::Cancelled {
                    step: self.step_index,
                    time_s: self.time_s(),
                });
            }
        }
        Ok(())
    }
}

/// What a pulse run yields: gauge strains and the energy ledger over time.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainResult {
    /// Recording times, s.
    pub time_s: Vec<f64>,
    /// Strain per gauge (positive in tension), in the order of the setup.
    pub strain: Vec<Vec<f64>>,
    /// Kinetic + strain energy in all bodies at each recording time, J.
    pub bar_energy_j: Vec<f64>,
    /// Energy absorbed by non-reflecting ends so far, J.
    pub absorbed_energy_j: Vec<f64>,
    /// Work taken by the pulse shaper and butt joints so far, J.
    pub shaper_energy_j: Vec<f64>,
    /// Work taken by the sphere contacts so far (dissipated plus elastic energy held), J.
    pub contact_energy_j: Vec<f64>,
    /// The first sphere contact's history (approach, force, σy*, strain rate), if the chain has one.
    pub contact: Option<crate::solver::ContactSeries>,
    /// Stress fields of the bars over time, if requested.
    pub snapshots: Vec<BarSnapshots>,
    /// Initial kinetic energy of the striker, J.
    pub striker_energy_j: f64,
    /// Velocity of the striker's centre of mass at the end, m/s.
    pub striker_final_velocity_m_s: f64,
    /// Steps taken.
    pub steps: usize,
}

/// Runs a chain (striker → shaper → incident → specimen → transmission …) and records its gauges.
pub fn simulate_chain(setup: &ChainSetup) -> Result<ChainResult> {
    simulate_chain_with(setup, &mut [])
}

/// [`simulate_chain`] with extra recorders of the caller's (e.g. a sphere's velocity in a chain).
pub fn simulate_chain_with(
    setup: &ChainSetup,
    extra: &mut [&mut dyn Recorder],
) -> Result<ChainResult> {
    let mut chain = Chain::new(setup)?;
    let striker_energy_j = chain.bodies[0].energy_j();
    let steps = (setup.end_time_s / setup.dt_s).ceil() as usize;
    let cap = steps / setup.record_every + 2;
    let mut gauges = GaugeRecorder::new(setup.gauges.clone(), setup.record_every, cap);
    let mut energy = EnergyRecorder {
        every: setup.record_every,
        ..Default::default()
    };
    let mut contact = chain
        .joints
        .iter()
        .position(|j| j.law.is_some())
        .map(|k| ContactRecorder::new(k, setup.record_every, cap));
    let mut snapshots = setup
        .snapshot_every
        .map(|k| SnapshotRecorder::new(&chain.bodies, k, setup.snapshot_spacing_m));
    {
        let mut recorders: Vec<&mut dyn Recorder> = vec![&mut gauges, &mut energy];
        if let Some(c) = contact.as_mut() {
            recorders.push(c);
        }
        if let Some(s) = snapshots.as_mut() {
            recorders.push(s);
        }
        recorders.extend(extra.iter_mut().map(|r| &mut **r as &mut dyn Recorder));
        chain.run(steps, &mut recorders)?;
    }
    let striker = &chain.bodies[0];
    Ok(ChainResult {
        time_s: gauges.time_s,
        strain: gauges.strain,
        bar_energy_j: energy.body_energy_j,
        absorbed_energy_j: energy.absorbed_energy_j,
        shaper_energy_j: energy.shaper_energy_j,
        contact_energy_j: energy.contact_energy_j,
        contact: contact.map(|c| c.series),
        snapshots: snapshots.map(|s| s.snapshots).unwrap_or_default(),
        striker_energy_j,
        striker_final_velocity_m_s: striker.momentum_kg_m_s() / striker.mass_kg(),
        steps,
    })
}

#[cfg(test)]
mod tests {
    //! Chains of rigid spheres through the general chain solver, against Hertz impact theory
    //! (Johnson, Contact Mechanics §11.4) and the conservation of momentum and energy.
    use super::*;
    use crate::contact::{LawKind, Region2Form, Unloading};
    use crate::solver::body::MassSpec;
    use crate::solver::{hertz_impact_duration, record::Recorder};

    /// Velocities of every rigid mass and forces of every joint, each step.
    #[derive(Default)]
    struct Trace {
        velocity: Vec<Vec<f64>>,
        force: Vec<Vec<f64>>,
        work_j: Vec<f64>,
    }

    impl Recorder for Trace {
        fn record(&mut self, _step: usize, _t: f64, bodies: &[Body], joints: &[JointState]) {
            self.velocity.push(
                bodies
                    .iter()
                    .map(|b| b.momentum_kg_m_s() / b.mass_kg())
                    .collect(),
            );
            self.force.push(joints.iter().map(|j| j.force_n).collect());
            self.work_j
                .push(joints.iter().map(JointState::dissipated_j).sum());
        }
    }

    /// `n` equal SS440c spheres in a row, just touching, the first moving at `speed` (Hertz contacts).
    fn sphere_row(n: usize, speed: f64, steps_per_contact: f64) -> (ChainSetup, f64, f64) {
        let pair = crate::fixtures::ss440c_pair();
        let p = pair.contact_properties();
        let tc = hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed);
        let dt = tc / steps_per_contact;
        let setup = ChainSetup {
            bodies: (0..n)
                .map(|k| {
                    BodySpec::Mass(MassSpec {
                        name: format!("sphere {}", k + 1),
                        mass_kg: pair.sphere1.mass_kg,
                    })
                })
                .collect(),
            joints: vec![
                Joint::Spheres {
                    props: p,
                    law: LawKind::Hertz,
                    region2: Region2Form::Smooth,
                    unloading: Unloading::Static,
                };
                n - 1
            ],
            striker_velocity_m_s: speed,
            dt_s: dt,
            end_time_s: 4.0 * n as f64 * tc,
            gauges: vec![],
            record_every: 1,
            end_masses: vec![],
            snapshot_every: None,
            snapshot_spacing_m: 1e-3,
        };
        (setup, tc, pair.sphere1.mass_kg)
    }

    #[test]
    fn two_rigid_spheres_bounce_as_hertz_predicts() {
        let speed = 1.0;
        let (setup, tc, _) = sphere_row(2, speed, 2000.0);
        let mut trace = Trace::default();
        simulate_chain_with(&setup, &mut [&mut trace]).unwrap();
        // Equal masses, elastic: the velocities exchange (restitution 1).
        let last = trace.velocity.last().unwrap();
        assert!(last[0].abs() < 1e-6 * speed, "v1' = {}", last[0]);
        assert!((last[1] - speed).abs() < 1e-6 * speed, "v2' = {}", last[1]);
        // Contact time within O(Δt) of Hertz theory: the force is positive for t_c/Δt steps ± 1.
        let loaded = trace.force.iter().filter(|f| f[0] > 0.0).count() as f64;
        let hertz = tc / setup.dt_s;
        assert!(
            (loaded - hertz).abs() <= 2.0,
            "{loaded} steps in contact, Hertz: {hertz}"
        );
    }

    #[test]
    fn a_row_of_spheres_conserves_momentum_and_energy() {
        // Three spheres: the middle one couples both contacts within a step (Gauss–Seidel solve).
        let speed = 2.0;
        let (setup, _, m) = sphere_row(3, speed, 1000.0);
        let mut trace = Trace::default();
        simulate_chain_with(&setup, &mut [&mut trace]).unwrap();
        let e0 = 0.5 * m * speed * speed;
        for (v, w) in trace.velocity.iter().zip(&trace.work_j) {
            let p: f64 = v.iter().map(|v| m * v).sum();
            // Momentum: each joint force acts equally and oppositely, so only rounding remains.
            assert!((p - m * speed).abs() < 1e-12 * m * speed, "momentum {p}");
            // Energy: kinetic at the half level plus the contacts' discrete work is conserved to
            // O(Δt²) of the Newmark-average contact (here ~1e-6 of the impact energy).
            let e: f64 = v.iter().map(|v| 0.5 * m * v * v).sum::<f64>() + w;
            assert!((e - e0).abs() < 1e-4 * e0, "energy {e} vs {e0}");
        }
        // At the end the spheres fly apart (no contact left) and the last one carries the blow.
        let last = trace.velocity.last().unwrap();
        assert!(trace.force.last().unwrap().iter().all(|&f| f == 0.0));
        assert!(last[0] <= last[1] && last[1] <= last[2], "{last:?}");
        assert!(last[2] > 0.5 * speed, "{last:?}");
    }
}

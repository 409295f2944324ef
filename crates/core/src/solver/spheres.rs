//! A free chain of N ≥ 2 rigid spheres in a line (docs/physics.md §8): the first sphere (or a
//! striker mass) strikes the others, optionally against a wall at the far end.
//!
//! Scheme: the two-sphere stepper's ([`super::PairStepper`]) generalised to N bodies: explicit
//! velocity-Verlet half steps and drifts for every body, then the forces at the end of the step.
//! A rate-independent contact's force follows from its new approach alone; a rate-dependent one
//! that is loading takes the end-of-step approach speed u_k = A_k − B_k F_k(u_k), where A_k
//! holds the forces of its two neighbours at the end of the step: the contacts are coupled
//! through the spheres they share, and solved by Gauss–Seidel sweeps (each contact's scalar
//! equation by [`super::solve_approach_speed`], given its neighbours' latest forces) until no
//! force changes by more than 1e-13 of the largest. For two spheres this is exactly one
//! solve of the pair stepper, in the same arithmetic, so a chain of two reproduces the
//! `collision` scene bit for bit. Each contact keeps its own law and memory
//! (`LawSpec::build`) and commits it once a step.
//!
//! A striker is a rigid mass with a flat face (rigid, or of a material) against sphere 1; a
//! wall is a flat of infinite mass (rigid, or elastic with a material) after sphere N; their
//! contacts are sphere-on-flat ([`Sphere::against_flat`]).
//!
//! Energy ledger: kinetic energy of all bodies plus the work ∫F dδ taken by every contact
//! (trapezoidal in δ, as for pairs) equals the initial kinetic energy up to velocity Verlet's
//! O(Δt²) error; momentum Σ m v is conserved to rounding without a wall (equal and opposite
//! contact forces). Stability: a run whose contacts return more than
//! [`super::PASSIVITY_TOLERANCE`] of the initial kinetic energy stops as unstable.

use super::{ContactSeries, PASSIVITY_TOLERANCE, contact_period, hertz_impact_duration};
use super::{hertz_max_approach, solve_approach_speed};
use crate::contact::{Contact, ContactEval, LawSpec, hertz_force};
use crate::error::{Error, Result};
use crate::material::Material;
use crate::specimen::{ContactProperties, SphereChain, reduced_mass_kg};

/// A rigid striker mass with a flat face that hits sphere 1 (docs/physics.md §8).
#[derive(Debug, Clone, PartialEq)]
pub struct StrikerMass {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Initial velocity toward the chain, m/s.
    pub velocity_m_s: f64,
    /// Material of its face (None: rigid).
    pub material: Option<Material>,
}

/// A fixed wall after the last sphere (docs/physics.md §8).
#[derive(Debug, Clone, PartialEq)]
pub enum Wall {
    /// A rigid flat: the sphere alone deforms.
    Rigid,
    /// An elastic(–plastic) flat of a material: E* and yield stress as for two bodies.
    Elastic(Material),
}

/// Inputs of a free chain run.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeChainSetup {
    /// The spheres, sphere 1 first.
    pub chain: SphereChain,
    /// The contact law of every contact.
    pub law: LawSpec,
    /// Initial velocity of sphere 1, m/s (the others rest); 0 with a striker.
    pub velocity1_m_s: f64,
    /// A striker hitting sphere 1 instead (None: sphere 1 moves).
    pub striker: Option<StrikerMass>,
    /// A wall after the last sphere (None: free end).
    pub wall: Option<Wall>,
    /// Time step, s.
    pub dt_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Keep every n-th step in the output series.
    pub output_every: usize,
    /// True when the scene did not set `output_every` and it was chosen by
    /// [`FreeChainSetup::output_every_within`] for [`CHAIN_OUTPUT_BUDGET_NUMBERS`]; the run
    /// then says so in its warnings.
    pub output_every_by_budget: bool,
}

/// Numbers a chain run keeps in its series (`/chain`, `/contact`) when its scene does not set
/// `output_every`: 2e7, 8 bytes each, so at most 160 MB held during the run and written to
/// its HDF5 file (README, `chain` scenes; issue 45: a 10 000-sphere chain kept every step,
/// 5.75 GB).
pub const CHAIN_OUTPUT_BUDGET_NUMBERS: f64 = 2e7;

/// The bodies and contacts of a setup: masses (infinite for the wall), the contact properties
/// and the centre distance at touch of each contact, in order along the line.
struct Layout {
    masses_kg: Vec<f64>,
    contacts: Vec<ContactProperties>,
    touch_distance_m: Vec<f64>,
}

impl FreeChainSetup {
    /// Time steps of the run, ⌈end_time_s/Δt⌉.
    pub fn steps(&self) -> usize {
        (self.end_time_s / self.dt_s).ceil() as usize
    }

    /// Numbers recorded per sample, an upper count: the time, N − 1 contact forces and
    /// approaches, N velocities, the first contact's 5 series and the striker's and wall's 3.
    pub fn numbers_per_sample(&self) -> usize {
        3 * self.chain.len() + 7
    }

    /// Samples a run keeps at `output_every = every`: the start, every `every`-th step and the
    /// last step, at most ⌊steps/every⌋ + 2.
    pub fn samples_kept(&self, every: usize) -> usize {
        self.steps() / every.max(1) + 2
    }

    /// The smallest `output_every` whose samples ([`FreeChainSetup::samples_kept`]) times
    /// [`FreeChainSetup::numbers_per_sample`] stay within `budget_numbers`; when even the start
    /// and the end alone exceed it, every step but the last is skipped (`steps`).
    pub fn output_every_within(&self, budget_numbers: f64) -> usize {
        let steps = self.steps().max(1);
        let samples = (budget_numbers / self.numbers_per_sample() as f64).floor();
        if samples < 3.0 {
            return steps;
        }
        // ⌊steps/n⌋ + 2 ≤ S  ⇔  steps/n < S − 1  ⇔  n > steps/(S − 1).
        let s = samples as usize;
        (steps / (s - 1) + 1).min(steps)
    }

    /// Index of sphere 1 among the bodies (1 with a striker).
    pub fn first_sphere(&self) -> usize {
        usize::from(self.striker.is_some())
    }

    /// The striking speed: the striker's or sphere 1's initial velocity, m/s.
    pub fn impact_speed_m_s(&self) -> f64 {
        self.striker
            .as_ref()
            .map_or(self.velocity1_m_s, |s| s.velocity_m_s)
    }

    fn layout(&self) -> Layout {
        let spheres = &self.chain.spheres;
        let mut l = Layout {
            masses_kg: Vec::new(),
            contacts: Vec::new(),
            touch_distance_m: Vec::new(),
        };
        if let Some(s) = &self.striker {
            l.masses_kg.push(s.mass_kg);
            l.contacts
                .push(spheres[0].against_flat(s.material.as_ref()));
            l.touch_distance_m.push(spheres[0].radius_m);
        }
        for (k, s) in spheres.iter().enumerate() {
            l.masses_kg.push(s.mass_kg);
            if k + 1 < spheres.len() {
                let p = self.chain.contact_properties(k);
                l.touch_distance_m.push(p.sum_of_radii_m);
                l.contacts.push(p);
            }
        }
        if let Some(w) = &self.wall {
            let last = spheres.last().expect("a chain has spheres");
            l.masses_kg.push(f64::INFINITY);
            l.contacts.push(last.against_flat(match w {
                Wall::Rigid => None,
                Wall::Elastic(m) => Some(m),
            }));
            l.touch_distance_m.push(last.radius_m);
        }
        l
    }

    /// Hertz impact duration of every contact at the striking speed (with the reduced mass of
    /// its two bodies), s: the default step is the shortest over `steps_per_contact`.
    pub fn hertz_contact_times_s(&self) -> Vec<f64> {
        let l = self.layout();
        let v = self.impact_speed_m_s();
        l.contacts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let m = reduced_mass_kg(l.masses_kg[k], l.masses_kg[k + 1]);
                hertz_impact_duration(m, p.e_star_pa, p.radius_m, v)
            })
            .collect()
    }

    /// Refuses a striking speed outside [`super::impact_speed_range`] of the first contact
    /// (striker–sphere 1 or sphere 1–sphere 2), the positions' scale being the chain's length.
    pub fn check_impact_speed(&self) -> Result<()> {
        let l = self.layout();
        let spheres = &self.chain.spheres;
        let smallest = match &self.striker {
            Some(_) => spheres[0].radius_m,
            None => spheres
                .iter()
                .take(2)
                .map(|s| s.radius_m)
                .fold(f64::INFINITY, f64::min),
        };
        let p = &l.contacts[0];
        super::check_impact_speed(
            reduced_mass_kg(l.masses_kg[0], l.masses_kg[1]),
            p.e_star_pa,
            p.radius_m,
            smallest,
            l.touch_distance_m.iter().sum(),
            self.impact_speed_m_s(),
        )
    }

    /// Default time step: the stiffest contact's Hertz contact time over `steps_per_contact`
    /// (for two spheres exactly the `collision` scene's step).
    pub fn default_time_step(&self, steps_per_contact: f64) -> f64 {
        self.hertz_contact_times_s()
            .into_iter()
            .fold(f64::INFINITY, f64::min)
            / steps_per_contact
    }

    /// Largest Hertz peak force of any contact struck at the striking speed, N (the force the
    /// stability limit is taken at).
    pub fn expected_peak_force_n(&self) -> f64 {
        let l = self.layout();
        let v = self.impact_speed_m_s();
        l.contacts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let m = reduced_mass_kg(l.masses_kg[k], l.masses_kg[k + 1]);
                let d = hertz_max_approach(m, p.e_star_pa, p.radius_m, v);
                hertz_force(p.e_star_pa, p.radius_m, d)
            })
            .fold(0.0, f64::max)
    }

    /// Stability limit 1/ω of the stiffest contact linearised at the expected peak force, s
    /// (`solver::stability_limit` over the contacts; for two spheres the pair's).
    pub fn stability_limit(&self) -> f64 {
        let l = self.layout();
        let f = self.expected_peak_force_n().max(1e-6);
        l.contacts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let m = reduced_mass_kg(l.masses_kg[k], l.masses_kg[k + 1]);
                contact_period(m, p.e_star_pa, p.radius_m, f) / (2.0 * std::f64::consts::PI)
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// What a free chain run yields (series every `output_every` steps and at the end).
#[derive(Debug, Clone, PartialEq)]
pub struct FreeChainResult {
    /// Recording times, s.
    pub time_s: Vec<f64>,
    /// Force of each sphere–sphere contact (contact 1 between spheres 1 and 2), N.
    pub contact_force_n: Vec<Vec<f64>>,
    /// Approach δ of each sphere–sphere contact, m.
    pub contact_approach_m: Vec<Vec<f64>>,
    /// Velocity of each sphere, m/s.
    pub velocity_m_s: Vec<Vec<f64>>,
    /// Striker velocity, m/s (with a striker).
    pub striker_velocity_m_s: Option<Vec<f64>>,
    /// Force of the striker–sphere 1 contact, N (with a striker).
    pub striker_force_n: Option<Vec<f64>>,
    /// Force of the sphere N–wall contact, N (with a wall).
    pub wall_force_n: Option<Vec<f64>>,
    /// The first contact (striker–sphere 1 or sphere 1–sphere 2) with σy* and strain rate.
    pub first_contact: ContactSeries,
    /// Initial velocity of every body (striker, spheres), m/s.
    pub initial_velocity_m_s: Vec<f64>,
    /// Final velocity of every body (striker, spheres), m/s.
    pub final_velocity_m_s: Vec<f64>,
    /// Largest force of each contact over every step (striker, spheres, wall), N.
    pub peak_force_n: Vec<f64>,
    /// Largest approach of each contact over every step, m.
    pub max_approach_m: Vec<f64>,
    /// Work ∫F dδ taken by each contact at the end (dissipated plus elastic energy held), J.
    pub contact_work_j: Vec<f64>,
    /// Kinetic energy of all bodies at the start, J.
    pub kinetic_energy_before_j: f64,
    /// Kinetic energy of all bodies at the end, J.
    pub kinetic_energy_after_j: f64,
    /// Largest |kinetic + contact work − initial kinetic| over the run, relative to the initial.
    pub energy_balance_max_relative_error: f64,
    /// Momentum of the moving bodies at the start, kg·m/s.
    pub momentum_before_kg_m_s: f64,
    /// Largest |Σ m v − initial| over the run (no wall), relative to the initial momentum.
    pub momentum_max_relative_drift: f64,
    /// Steps taken.
    pub steps: usize,
}

/// The chain in its time-stepping state.
struct Stepper {
    laws: Vec<Box<dyn Contact>>,
    masses_kg: Vec<f64>,
    position_m: Vec<f64>,
    velocity_m_s: Vec<f64>,
    touch_distance_m: Vec<f64>,
    evals: Vec<ContactEval>,
    work_j: Vec<f64>,
    dt_s: f64,
    step_index: usize,
    speeds: Vec<f64>,
    forces: Vec<f64>,
}

impl Stepper {
    fn new(setup: &FreeChainSetup) -> Stepper {
        let l = setup.layout();
        let laws: Vec<Box<dyn Contact>> = l.contacts.iter().map(|&p| setup.law.build(p)).collect();
        let mut position_m = vec![0.0];
        for d in &l.touch_distance_m {
            let last = *position_m.last().expect("one body at least");
            position_m.push(last + d);
        }
        let mut velocity_m_s = vec![0.0; l.masses_kg.len()];
        match &setup.striker {
            Some(s) => velocity_m_s[0] = s.velocity_m_s,
            None => velocity_m_s[0] = setup.velocity1_m_s,
        }
        let n = laws.len();
        Stepper {
            evals: laws.iter().map(|c| c.fresh().trial(0.0, 0.0)).collect(),
            laws,
            masses_kg: l.masses_kg,
            position_m,
            velocity_m_s,
            touch_distance_m: l.touch_distance_m,
            work_j: vec![0.0; n],
            dt_s: setup.dt_s,
            step_index: 0,
            speeds: vec![0.0; n],
            forces: vec![0.0; n],
        }
    }

    /// Approach of contact `k`, δ = touch distance − (x_{k+1} − x_k), m.
    fn approach_m(&self, k: usize) -> f64 {
        self.touch_distance_m[k] - (self.position_m[k + 1] - self.position_m[k])
    }

    fn kinetic_energy_j(&self) -> f64 {
        self.masses_kg
            .iter()
            .zip(&self.velocity_m_s)
            .filter(|(m, _)| m.is_finite())
            .map(|(m, v)| 0.5 * m * v.powi(2))
            .sum()
    }

    fn momentum_kg_m_s(&self) -> f64 {
        self.masses_kg
            .iter()
            .zip(&self.velocity_m_s)
            .filter(|(m, _)| m.is_finite())
            .map(|(m, v)| m * v)
            .sum()
    }

    /// One step (module docs).
    fn step(&mut self) {
        let dt = self.dt_s;
        let nc = self.laws.len();
        let nb = self.masses_kg.len();
        let delta_now: Vec<f64> = (0..nc).map(|k| self.approach_m(k)).collect();
        let f_now: Vec<f64> = self.evals.iter().map(|e| e.force_n).collect();
        let mut vh = vec![0.0; nb];
        for i in 0..nb {
            let left = if i > 0 { f_now[i - 1] } else { 0.0 };
            let right = if i < nc { f_now[i] } else { 0.0 };
            vh[i] = self.velocity_m_s[i] + 0.5 * dt * (left - right) / self.masses_kg[i];
            self.position_m[i] += dt * vh[i];
        }
        let delta_next: Vec<f64> = (0..nc).map(|k| self.approach_m(k)).collect();
        let implicit: Vec<bool> = (0..nc)
            .map(|k| self.laws[k].is_rate_dependent() && self.laws[k].is_loading(delta_next[k]))
            .collect();
        for k in 0..nc {
            self.speeds[k] = (delta_next[k] - delta_now[k]) / dt;
            self.forces[k] = if implicit[k] {
                f_now[k]
            } else {
                self.laws[k].trial_force(delta_next[k], self.speeds[k])
            };
        }
        if implicit.iter().any(|&i| i) {
            for _sweep in 0..500 {
                let mut change = 0.0f64;
                for k in (0..nc).filter(|&k| implicit[k]) {
                    let (m_l, m_r) = (self.masses_kg[k], self.masses_kg[k + 1]);
                    let f_left = if k > 0 { self.forces[k - 1] } else { 0.0 };
                    let f_right = if k + 1 < nc { self.forces[k + 1] } else { 0.0 };
                    let a =
                        (vh[k] + 0.5 * dt * f_left / m_l) - (vh[k + 1] - 0.5 * dt * f_right / m_r);
                    let b = 0.5 * dt / m_l + 0.5 * dt / m_r;
                    let u = solve_approach_speed(self.laws[k].as_ref(), delta_next[k], a, b);
                    let f = self.laws[k].trial_force(delta_next[k], u);
                    change = change.max((f - self.forces[k]).abs());
                    self.speeds[k] = u;
                    self.forces[k] = f;
                }
                let scale = self.forces.iter().fold(0.0f64, |a, &f| a.max(f));
                if change <= 1e-13 * scale {
                    break;
                }
            }
        }
        for k in 0..nc {
            self.evals[k] = self.laws[k].evaluate(delta_next[k], self.speeds[k]);
            self.forces[k] = self.evals[k].force_n;
            self.work_j[k] += 0.5 * (f_now[k] + self.forces[k]) * (delta_next[k] - delta_now[k]);
        }
        for (i, v) in vh.iter().enumerate() {
            let left = if i > 0 { self.forces[i - 1] } else { 0.0 };
            let right = if i < nc { self.forces[i] } else { 0.0 };
            self.velocity_m_s[i] = v + 0.5 * dt * (left - right) / self.masses_kg[i];
        }
        self.step_index += 1;
    }

    fn time_s(&self) -> f64 {
        self.step_index as f64 * self.dt_s
    }

    /// Stops a run that produced a non-finite value or whose contacts returned more energy
    /// than [`PASSIVITY_TOLERANCE`] of the initial kinetic energy (module docs).
    fn check(&self, initial_kinetic_energy_j: f64) -> Result<()> {
        for (i, v) in self.velocity_m_s.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::Unstable {
                    step: self.step_index,
                    time_s: self.time_s(),
                    quantity: format!("velocity of body {} (m/s)", i + 1),
                    value: *v,
                });
            }
        }
        for (k, e) in self.evals.iter().enumerate() {
            if !e.force_n.is_finite() {
                return Err(Error::Unstable {
                    step: self.step_index,
                    time_s: self.time_s(),
                    quantity: format!("force of contact {} (N)", k + 1),
                    value: e.force_n,
                });
            }
        }
        let work: f64 = self.work_j.iter().sum();
        if work < 0.0 && -work > PASSIVITY_TOLERANCE * initial_kinetic_energy_j {
            return Err(Error::Unstable {
                step: self.step_index,
                time_s: self.time_s(),
                quantity: format!(
                    "contact work ∫F dδ (J): the contacts returned more than {:.0} % of the \
                     {initial_kinetic_energy_j:e} J put in beyond what they received (time step \
                     {:e} s too large; stability limit 1/ω of the stiffest contact)",
                    100.0 * PASSIVITY_TOLERANCE,
                    self.dt_s
                ),
                value: work,
            });
        }
        Ok(())
    }
}

/// Series of many rows (one per contact or sphere) recorded time-major: each sample appends
/// one contiguous line of every row's value, so recording writes memory in order; turned into
/// one `Vec` per row once, at the end ([`TimeMajor::into_rows`]).
struct TimeMajor {
    width: usize,
    data: Vec<f64>,
}

impl TimeMajor {
    /// Room for `samples` lines of `width` values, allocated once.
    fn new(width: usize, samples: usize) -> TimeMajor {
        TimeMajor {
            width,
            data: Vec::with_capacity(width * samples),
        }
    }

    /// Appends one sample: the value of every row, in row order.
    fn push(&mut self, line: impl Iterator<Item = f64>) {
        self.data.extend(line);
    }

    /// One `Vec` per row (columns: the samples), transposed by blocks of rows so that reads
    /// and writes both stay in cache; the time-major copy is freed on return.
    fn into_rows(self) -> Vec<Vec<f64>> {
        const BLOCK: usize = 64;
        let w = self.width;
        let samples = self.data.len().checked_div(w).unwrap_or(0);
        let mut rows: Vec<Vec<f64>> = (0..w).map(|_| Vec::with_capacity(samples)).collect();
        for start in (0..w).step_by(BLOCK) {
            let end = (start + BLOCK).min(w);
            for line in self.data.chunks_exact(w) {
                for (row, &x) in rows[start..end].iter_mut().zip(&line[start..end]) {
                    row.push(x);
                }
            }
        }
        rows
    }
}

/// Runs a free chain of spheres struck by its first sphere or a striker (module docs).
pub fn free_chain(setup: &FreeChainSetup) -> Result<FreeChainResult> {
    free_chain_with_progress(setup, &mut |_| true)
}

/// [`free_chain`], calling `progress` with the fraction done every 1 % of the steps; `progress`
/// returning false stops the run with [`Error::Cancelled`].
pub fn free_chain_with_progress(
    setup: &FreeChainSetup,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<FreeChainResult> {
    let mut st = Stepper::new(setup);
    let first = setup.first_sphere();
    let n_spheres = setup.chain.len();
    let nc = st.laws.len();
    let sphere_contacts = first..first + n_spheres - 1;
    let wall = setup.wall.as_ref().map(|_| nc - 1);
    let steps = setup.steps();
    let cap = setup.samples_kept(setup.output_every);
    let ke0 = st.kinetic_energy_j();
    let p0 = st.momentum_kg_m_s();
    let initial_velocity_m_s = st.velocity_m_s.clone();
    let mut r = FreeChainResult {
        time_s: Vec::with_capacity(cap),
        contact_force_n: Vec::new(),
        contact_approach_m: Vec::new(),
        velocity_m_s: Vec::new(),
        striker_velocity_m_s: setup.striker.as_ref().map(|_| Vec::with_capacity(cap)),
        striker_force_n: setup.striker.as_ref().map(|_| Vec::with_capacity(cap)),
        wall_force_n: wall.map(|_| Vec::with_capacity(cap)),
        first_contact: ContactSeries {
            time_s: Some(Vec::with_capacity(cap)),
            yield_stress_pa: st.laws[0]
                .has_yield_stress()
                .then(|| Vec::with_capacity(cap)),
            strain_rate_per_s: Some(Vec::with_capacity(cap)),
            ..Default::default()
        },
        initial_velocity_m_s,
        final_velocity_m_s: Vec::new(),
        peak_force_n: vec![0.0; nc],
        max_approach_m: vec![0.0; nc],
        contact_work_j: Vec::new(),
        kinetic_energy_before_j: ke0,
        kinetic_energy_after_j: 0.0,
        energy_balance_max_relative_error: 0.0,
        momentum_before_kg_m_s: p0,
        momentum_max_relative_drift: 0.0,
        steps,
    };
    // Issue 45: the many-row series are kept time-major while recording (each sample one
    // contiguous row), every `output_every`-th step only, and turned into rows at the end.
    let mut force = TimeMajor::new(n_spheres - 1, cap);
    let mut approach = TimeMajor::new(n_spheres - 1, cap);
    let mut velocity = TimeMajor::new(n_spheres, cap);
    let mut record = |st: &Stepper, r: &mut FreeChainResult| {
        r.time_s.push(st.time_s());
        force.push(st.evals[sphere_contacts.clone()].iter().map(|e| e.force_n));
        approach.push(sphere_contacts.clone().map(|k| st.approach_m(k)));
        velocity.push(st.velocity_m_s[first..first + n_spheres].iter().copied());
        if let Some(v) = r.striker_velocity_m_s.as_mut() {
            v.push(st.velocity_m_s[0]);
        }
        if let Some(f) = r.striker_force_n.as_mut() {
            f.push(st.evals[0].force_n);
        }
        if let (Some(f), Some(k)) = (r.wall_force_n.as_mut(), wall) {
            f.push(st.evals[k].force_n);
        }
        r.first_contact
            .push(st.time_s(), st.approach_m(0), &st.evals[0]);
    };
    record(&st, &mut r);
    let every = (steps / 100).max(1);
    for n in 1..=steps {
        st.step();
        st.check(ke0)?;
        for k in 0..nc {
            r.peak_force_n[k] = r.peak_force_n[k].max(st.evals[k].force_n);
            r.max_approach_m[k] = r.max_approach_m[k].max(st.approach_m(k));
        }
        let ledger = st.kinetic_energy_j() + st.work_j.iter().sum::<f64>() - ke0;
        r.energy_balance_max_relative_error =
            r.energy_balance_max_relative_error.max(ledger.abs() / ke0);
        if wall.is_none() {
            let drift = (st.momentum_kg_m_s() - p0).abs() / p0.abs();
            r.momentum_max_relative_drift = r.momentum_max_relative_drift.max(drift);
        }
        if n % setup.output_every == 0 || n == steps {
            record(&st, &mut r);
        }
        if (n % every == 0 || n == steps) && !progress(n as f64 / steps as f64) {
            return Err(Error::Cancelled {
                step: n,
                time_s: st.time_s(),
            });
        }
    }
    r.contact_force_n = force.into_rows();
    r.contact_approach_m = approach.into_rows();
    r.velocity_m_s = velocity.into_rows();
    r.final_velocity_m_s = st
        .velocity_m_s
        .iter()
        .zip(&st.masses_kg)
        .filter(|(_, m)| m.is_finite())
        .map(|(v, _)| *v)
        .collect();
    r.contact_work_j = st.work_j.clone();
    r.kinetic_energy_after_j = st.kinetic_energy_j();
    Ok(r)
}

impl FreeChainResult {
    /// Restitution of the first contact (striker–sphere 1, or spheres 1–2): separation speed
    /// at the end over the approach speed at the start, −(v_a' − v_b')/(v_a − v_b).
    pub fn first_restitution(&self) -> f64 {
        let (v, v0) = (&self.final_velocity_m_s, &self.initial_velocity_m_s);
        -(v[0] - v[1]) / (v0[0] - v0[1])
    }

    /// Kinetic energy after over before: the chain's energetic restitution (its square root is
    /// the restitution for a pair of equal spheres).
    pub fn kinetic_energy_ratio(&self) -> f64 {
        self.kinetic_energy_after_j / self.kinetic_energy_before_j
    }
}

#[cfg(test)]
mod tests {
    //! The chain against the two-sphere `collision` stepper (N = 2, identical arithmetic), and
    //! the conservation of momentum and energy of longer chains (module docs).
    use super::*;
    use crate::contact::{LawKind, Region2Form};
    use crate::material::JohnsonCook;
    use crate::solver::{CollisionSetup, collision};
    use crate::specimen::{Sphere, SpherePair};

    fn al2017() -> Material {
        Material {
            name: "al2017".into(),
            density_kg_m3: 2790.0,
            youngs_modulus_pa: 72e9,
            poisson_ratio: 0.33,
            yield_stress_pa: 275e6,
            rate: JohnsonCook {
                c: 0.003,
                reference_rate_per_s: 1e-3,
            },
        }
    }

    fn setup(chain: SphereChain, law: LawKind, speed: f64, end_time_s: f64) -> FreeChainSetup {
        let mut s = FreeChainSetup {
            chain,
            law: LawSpec::of(law),
            velocity1_m_s: speed,
            striker: None,
            wall: None,
            dt_s: 0.0,
            end_time_s,
            output_every: 1,
            output_every_by_budget: false,
        };
        s.dt_s = s.default_time_step(2000.0);
        s
    }

    fn relative(a: f64, b: f64) -> f64 {
        if a == b { 0.0 } else { (a - b).abs() / b.abs() }
    }

    /// Largest relative difference between a chain of two and the collision scene's stepper,
    /// over restitution, peak force, max approach and the force series (relative to the peak).
    fn chain_vs_collision(pair: &SpherePair, law: LawKind, speed: f64) -> f64 {
        let contact = law.build_with(pair.contact_properties(), Region2Form::Smooth);
        let p = pair.contact_properties();
        let tc = hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed);
        let c = collision(
            contact.as_ref(),
            pair,
            &CollisionSetup {
                velocity1_m_s: speed,
                velocity2_m_s: 0.0,
                dt_s: tc / 2000.0,
                max_time_s: 100.0 * tc,
                output_every: 1,
            },
        )
        .unwrap();
        let t_end = *c.series.time_s.as_ref().unwrap().last().unwrap();
        let s = setup(
            SphereChain::from_pair(pair),
            law,
            speed,
            t_end + 50.0 * tc / 2000.0,
        );
        assert_eq!(s.dt_s, tc / 2000.0, "the same time step");
        assert_eq!(
            s.stability_limit(),
            crate::solver::stability_limit(pair, crate::solver::hertz_peak_force(pair, speed))
        );
        let r = free_chain(&s).unwrap();
        let peak = c.peak_force_n;
        let mut worst = [
            relative(r.first_restitution(), c.restitution),
            relative(r.peak_force_n[0], peak),
            relative(r.max_approach_m[0], c.max_approach_m),
            relative(r.contact_work_j[0], c.dissipated_j),
            relative(r.kinetic_energy_after_j, c.kinetic_energy_after_j),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        let n = c.series.force_n.len();
        for i in 0..n {
            worst = worst.max((r.contact_force_n[0][i] - c.series.force_n[i]).abs() / peak);
            worst = worst.max(
                (r.contact_approach_m[0][i] - c.series.displacement_m[i]).abs() / c.max_approach_m,
            );
        }
        // After the collision scene stops the spheres are apart: no force.
        assert!(r.contact_force_n[0][n..].iter().all(|&f| f == 0.0));
        worst
    }

    /// Acceptance: a chain of two reproduces the collision scene to 1e-12 relative (it takes
    /// the same arithmetic, so the difference is exactly 0) for every law and a few speeds,
    /// equal and dissimilar spheres.
    #[test]
    fn a_chain_of_two_is_the_collision_scene() {
        let equal = crate::fixtures::ss440c_pair();
        let dissimilar = SpherePair {
            sphere1: Sphere::full(crate::fixtures::ss440c(), 3.175e-3),
            sphere2: Sphere::full(al2017(), 2.5e-3),
        };
        for pair in [&equal, &dissimilar] {
            for (_, law) in LawKind::ALL {
                for speed in [0.5, 5.0, 20.0] {
                    let d = chain_vs_collision(pair, law, speed);
                    println!("{law:?} {speed} m/s: max relative difference {d:e}");
                    assert!(d <= 1e-12, "{law:?} at {speed} m/s: {d:e}");
                }
            }
        }
    }

    fn ten_ss440c(law: LawKind, steps_per_contact: f64) -> FreeChainSetup {
        let chain = SphereChain {
            spheres: vec![crate::fixtures::ss440c_pair().sphere1; 10],
        };
        let mut s = setup(chain, law, 5.0, 75e-6);
        s.dt_s = s.default_time_step(steps_per_contact);
        s
    }

    /// Acceptance: momentum of a free chain of ten is conserved to 1e-12 relative (equal and
    /// opposite contact forces: only rounding changes Σ m v), for every law.
    #[test]
    fn a_chain_of_ten_conserves_momentum() {
        for (_, law) in LawKind::ALL {
            let r = free_chain(&ten_ss440c(law, 2000.0)).unwrap();
            println!(
                "{law:?}: momentum drift {:e}",
                r.momentum_max_relative_drift
            );
            assert!(r.momentum_max_relative_drift <= 1e-12, "{law:?}");
            // The wave reached the far end: the last sphere moves away.
            assert!(*r.final_velocity_m_s.last().unwrap() > 0.0);
        }
    }

    /// Acceptance: energy ledger, kinetic + work taken by the contacts = initial kinetic energy.
    /// Velocity Verlet with the trapezoidal contact work closes it to O(Δt²): the tolerance is
    /// the measured error at 2000 steps per contact being below 1e-5 and falling at least 3.5
    /// times (4 for an exact second-order error) when the step is halved, so it is the scheme's
    /// discretisation error, not a leak. Elastic Hertz chains return all of it: a kinetic
    /// energy ratio of 1 within the same error; plastic laws dissipate (ratio < 1).
    #[test]
    fn a_chain_of_ten_closes_its_energy_ledger() {
        for (_, law) in LawKind::ALL {
            let coarse = free_chain(&ten_ss440c(law, 2000.0)).unwrap();
            let fine = free_chain(&ten_ss440c(law, 4000.0)).unwrap();
            let (e1, e2) = (
                coarse.energy_balance_max_relative_error,
                fine.energy_balance_max_relative_error,
            );
            println!(
                "{law:?}: ledger error {e1:e} then {e2:e} (ratio {:.2}), KE ratio {}",
                e1 / e2,
                coarse.kinetic_energy_ratio()
            );
            assert!(e1 < 1e-5, "{law:?}: {e1:e}");
            assert!(e1 / e2 > 3.5, "{law:?}: {e1:e} then {e2:e}");
            let work: f64 = coarse.contact_work_j.iter().sum();
            assert!(
                work >= -1e-5 * coarse.kinetic_energy_before_j,
                "passive: {work:e}"
            );
            if law == LawKind::Hertz {
                assert!((coarse.kinetic_energy_ratio() - 1.0).abs() < 1e-4);
            } else {
                assert!(coarse.kinetic_energy_ratio() < 1.0);
            }
        }
    }

    /// A striker and a wall: a 3-sphere SS440c chain struck by a flat-faced striker of one
    /// sphere's mass, against a rigid wall and against an elastic Al2017 wall. Elastic Hertz
    /// contacts return every joule (kinetic energy after = before within the scheme's O(Δt²)
    /// ledger error, < 1e-4 at 2000 steps per contact, as for free chains above) and the wall
    /// turns the momentum round (Σ m v after < 0: everything leaves away from the wall); the
    /// plastic law dissipates (after < before) with the ledger still closed. A wall does no net
    /// work on rigid spheres once all contacts have opened.
    #[test]
    fn a_striker_and_a_wall_keep_the_ledger_and_reverse_the_momentum() {
        let sphere = crate::fixtures::ss440c_pair().sphere1;
        for wall in [Wall::Rigid, Wall::Elastic(al2017())] {
            for (_, law) in LawKind::ALL {
                let mut s = setup(
                    SphereChain {
                        spheres: vec![sphere.clone(); 3],
                    },
                    law,
                    0.0,
                    0.0,
                );
                s.striker = Some(StrikerMass {
                    mass_kg: sphere.mass_kg,
                    velocity_m_s: 2.0,
                    material: None,
                });
                s.wall = Some(wall.clone());
                s.dt_s = s.default_time_step(2000.0);
                // Long enough for every contact to open for good (a few tens of contact times).
                s.end_time_s = 300.0
                    * s.hertz_contact_times_s()
                        .iter()
                        .copied()
                        .fold(0.0, f64::max);
                let r = free_chain(&s).unwrap();
                let what = format!("{law:?}, {wall:?}");
                assert!(
                    r.energy_balance_max_relative_error < 1e-4,
                    "{what}: ledger {:e}",
                    r.energy_balance_max_relative_error
                );
                let masses: Vec<f64> = std::iter::repeat_n(sphere.mass_kg, 4).collect();
                let momentum: f64 = masses
                    .iter()
                    .zip(&r.final_velocity_m_s)
                    .map(|(m, v)| m * v)
                    .sum();
                assert!(momentum < 0.0, "{what}: momentum after {momentum:e}");
                let ratio = r.kinetic_energy_ratio();
                if law == LawKind::Hertz {
                    assert!((ratio - 1.0).abs() < 1e-4, "{what}: KE ratio {ratio}");
                } else {
                    assert!(ratio < 1.0, "{what}: KE ratio {ratio}");
                }
                let last_force = r.wall_force_n.as_ref().unwrap().last().copied().unwrap();
                assert_eq!(last_force, 0.0, "{what}: still pressing on the wall");
            }
        }
    }

    /// Issue 45: the `output_every` a scene without one gets is the smallest that keeps the
    /// series within the budget: at it the samples kept (start, every n-th step, end) times the
    /// numbers per sample are within the budget, one step less frequent they are not; a chain
    /// that fits keeps every step; a budget below three samples keeps the start and the end.
    #[test]
    fn the_output_budget_rule() {
        let chain = |n: usize, end_time_s: f64| {
            let spheres = vec![crate::fixtures::ss440c_pair().sphere1; n];
            setup(SphereChain { spheres }, LawKind::Hertz, 20.0, end_time_s)
        };
        for (s, budget) in [
            (chain(10_000, 75e-6), CHAIN_OUTPUT_BUDGET_NUMBERS),
            (chain(2_000, 75e-6), CHAIN_OUTPUT_BUDGET_NUMBERS),
            (chain(10, 75e-6), 1e4),
            (chain(10, 75e-6), 37.0 * 3.0),
        ] {
            let every = s.output_every_within(budget);
            let numbers = |n: usize| (s.samples_kept(n) * s.numbers_per_sample()) as f64;
            println!(
                "{} spheres, {} steps, budget {budget:e}: output_every {every}, {} numbers",
                s.chain.len(),
                s.steps(),
                numbers(every)
            );
            assert!(numbers(every) <= budget, "{every}: {}", numbers(every));
            assert!(
                every == 1 || numbers(every - 1) > budget,
                "{every} not the smallest"
            );
        }
        let fits = chain(10, 75e-6);
        assert_eq!(fits.output_every_within(CHAIN_OUTPUT_BUDGET_NUMBERS), 1);
        let tiny = chain(10, 75e-6);
        assert_eq!(tiny.output_every_within(100.0), tiny.steps());
        // 10 000 spheres at 20 m/s for 75 µs: 3 × 10⁴ numbers a sample, 666 samples in 2e7.
        let big = chain(10_000, 75e-6);
        let every = big.output_every_within(CHAIN_OUTPUT_BUDGET_NUMBERS);
        assert_eq!(every, big.steps() / 665 + 1);
    }

    /// The time-major recording turns into the rows the samples were pushed as, for widths
    /// below, at and across the transpose's block of 64 rows.
    #[test]
    fn time_major_lines_become_rows() {
        for (width, samples) in [(0, 3), (1, 4), (9, 5), (64, 2), (130, 7)] {
            let mut tm = TimeMajor::new(width, samples);
            for t in 0..samples {
                tm.push((0..width).map(|k| (1000 * k + t) as f64));
            }
            let rows = tm.into_rows();
            assert_eq!(rows.len(), width);
            for (k, row) in rows.iter().enumerate() {
                let expected: Vec<f64> = (0..samples).map(|t| (1000 * k + t) as f64).collect();
                assert_eq!(row, &expected, "row {k} of {width}");
            }
        }
    }

    /// Issue 45: the series are decimated as they are recorded, and what is kept is exactly
    /// the every-step run's samples at the steps kept (the start, every n-th step, the last).
    #[test]
    fn a_decimated_run_keeps_the_every_step_run_s_samples() {
        let mut s = ten_ss440c(LawKind::BurgoyneDaraio, 200.0);
        let all = free_chain(&s).unwrap();
        for every in [7, 50] {
            s.output_every = every;
            let some = free_chain(&s).unwrap();
            let steps = s.steps();
            let kept: Vec<usize> = (0..=steps)
                .filter(|&n| n % every == 0 || n == steps)
                .collect();
            assert_eq!(some.time_s.len(), kept.len());
            assert!(some.time_s.len() <= s.samples_kept(every));
            assert!(some.time_s.capacity() <= s.samples_kept(every));
            let pick = |v: &[f64]| kept.iter().map(|&n| v[n]).collect::<Vec<f64>>();
            assert_eq!(some.time_s, pick(&all.time_s));
            for k in 0..9 {
                assert_eq!(some.contact_force_n[k], pick(&all.contact_force_n[k]));
                assert_eq!(some.contact_approach_m[k], pick(&all.contact_approach_m[k]));
            }
            for j in 0..10 {
                assert_eq!(some.velocity_m_s[j], pick(&all.velocity_m_s[j]));
            }
            assert_eq!(some.final_velocity_m_s, all.final_velocity_m_s);
            assert_eq!(some.peak_force_n, all.peak_force_n);
            assert_eq!(
                some.energy_balance_max_relative_error,
                all.energy_balance_max_relative_error
            );
        }
    }
}

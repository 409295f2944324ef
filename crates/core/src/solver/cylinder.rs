//! An elastoplastic cylindrical specimen as a body of the chain (docs/physics.md §6.12): the
//! lumped leapfrog of a bar segment on the chain's time step, whose elements carry a plastic
//! (stress-free) length at constant plastic volume, return-mapped onto a flow stress
//! ([`crate::flow::FlowModel`]) raised by end friction, with optional radial inertia (the
//! Love-rod lateral kinetic energy with an effective Poisson ratio, solved implicitly). With no
//! yield, no friction and no radial inertia it is today's elastic cylinder step for step.

use super::body::Body;
use super::joint::JointState;
use super::record::Recorder;
use crate::bar::ENERGY_LEDGER_TOLERANCE;
use crate::error::{Error, Named, Result};
use crate::flow::FlowModel;
use crate::numeric::Tridiagonal;
use crate::specimen::CylinderSpecimen;
use std::f64::consts::PI;

/// One sample of the specimen at a time level (compression positive, as docs/physics.md §7.8).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpecimenSample {
    /// Mean of the two face forces over the current area A₀L₀/Σl_p, Pa.
    pub face_stress_pa: f64,
    /// Mean true stress of the elements F/A_p, Pa.
    pub element_stress_pa: f64,
    /// The friction part of the element stress, (φ − 1)/φ of the flowing elements' stress, Pa.
    pub friction_stress_pa: f64,
    /// Face stress minus element stress: what the specimen's inertia adds, Pa.
    pub inertia_stress_pa: f64,
    /// True strain −ln(h/L₀), h the current length.
    pub true_strain: f64,
    /// True strain rate −(v_back − v_front)/h, 1/s.
    pub true_strain_rate_per_s: f64,
    /// Mean equivalent plastic strain of the elements.
    pub plastic_strain: f64,
    /// Mean temperature of the elements, K.
    pub temperature_k: f64,
    /// Plastic work so far, J.
    pub plastic_work_j: f64,
    /// Friction work so far, J.
    pub friction_work_j: f64,
}

/// The specimen in its time-stepping state (docs/physics.md §6.12).
#[derive(Debug, Clone)]
pub struct PlasticCylinder {
    spec: CylinderSpecimen,
    dt_s: f64,
    step_index: usize,
    /// Initial cell Δx₀, m.
    dx0_m: f64,
    /// Initial area A₀, m².
    area0_m2: f64,
    /// u^n, m.
    u: Vec<f64>,
    /// v^{n−1/2}, m/s.
    v: Vec<f64>,
    /// Free rate: v^{n+1/2} = v^{n−1/2} + Δt (w + response to end forces).
    w: Vec<f64>,
    /// Lumped node masses, kg.
    mass: Vec<f64>,
    /// 1/m_i (lumped, without radial inertia).
    inv_a: Vec<f64>,
    /// Element stiffness E A_p/l_p, N/m.
    k: Vec<f64>,
    /// Plastic elongation l_p − Δx₀ per element, m.
    slack: Vec<f64>,
    /// Plastic length l_p per element, m.
    lp: Vec<f64>,
    /// Equivalent plastic strain per element.
    eqps: Vec<f64>,
    /// Temperature per element, K.
    temperature_k: Vec<f64>,
    /// Whether the element flowed in the last return map.
    flowing: Vec<bool>,
    /// Element forces (tension) at the current level, N.
    force: Vec<f64>,
    /// Radial-inertia coefficients ρν_eff²J/l_p per element (empty without radial inertia).
    beta: Vec<f64>,
    /// Factorised M + B(β) with radial inertia.
    matrix: Tridiagonal,
    /// A⁻¹e₀ and A⁻¹e_N with radial inertia.
    response: [Vec<f64>; 2],
    /// The friction factor φ of the last return map.
    friction_factor: f64,
    last_force: [f64; 2],
    work_j: f64,
    plastic_j: f64,
    friction_j: f64,
    exchange_j: f64,
    ledger_j: f64,
    turnover_j: f64,
    unstable: Option<(String, f64)>,
    /// The specimen at the level of the last step's forces.
    sample: SpecimenSample,
}

/// Largest Gershgorin bound Δt² 2(k_l + k_r)/m accepted before the specimen reports itself
/// unstable (4 is the lumped chain's limit; the slack covers rounding at Courant 1).
const STABILITY_BOUND: f64 = 4.0 * (1.0 + 1e-9);

impl PlasticCylinder {
    /// Builds the specimen on time step `dt_s` (cells [`CylinderSpecimen::cells_at`]); refuses a
    /// step above the stability limit of one cell (Error::Invalid naming `time_step_s`).
    pub fn new(spec: &CylinderSpecimen, dt_s: f64) -> Result<PlasticCylinder> {
        spec.validate()?;
        let val = Named::new(CylinderSpecimen::NAME);
        val.positive("time_step_s", dt_s, 1.0, "s")?;
        let n = spec.cells_at(dt_s);
        let seg = spec.segment();
        let dx = seg.length_m / n as f64;
        let area = seg.area_m2();
        let half_cell_mass = 0.5 * seg.material.density_kg_m3 * area * dx;
        let stiffness = seg.material.youngs_modulus_pa * area / dx;
        if dt_s * dt_s * 4.0 * stiffness / (2.0 * half_cell_mass) > STABILITY_BOUND
            && n == 1
            && !spec.radial_inertia
        {
            return Err(val.error(
                "time_step_s",
                format!(
                    "{dt_s:e} s exceeds the stability limit of the specimen's single cell ({} m shorter than c·Δt = {:e} m)",
                    spec.length_m,
                    seg.material.wave_speed_m_s() * dt_s
                ),
                format!(
                    "at most {:e} s",
                    spec.length_m / seg.material.wave_speed_m_s()
                ),
            ));
        }
        let mut mass = vec![0.0; n + 1];
        for e in 0..n {
            mass[e] += half_cell_mass;
            mass[e + 1] += half_cell_mass;
        }
        let beta = if spec.radial_inertia {
            let nu = spec.material.poisson_ratio;
            vec![spec.material.density_kg_m3 * nu * nu * seg.polar_moment_m4() / dx; n]
        } else {
            Vec::new()
        };
        let mut body = PlasticCylinder {
            dt_s,
            step_index: 0,
            dx0_m: dx,
            area0_m2: area,
            u: vec![0.0; n + 1],
            v: vec![0.0; n + 1],
            w: vec![0.0; n + 1],
            inv_a: mass.iter().map(|&m| 1.0 / m).collect(),
            mass,
            k: vec![stiffness; n],
            slack: vec![0.0; n],
            lp: vec![dx; n],
            eqps: vec![0.0; n],
            temperature_k: vec![spec.initial_temperature_k; n],
            flowing: vec![false; n],
            force: vec![0.0; n],
            beta,
            matrix: Tridiagonal::default(),
            response: [Vec::new(), Vec::new()],
            friction_factor: 1.0,
            last_force: [0.0; 2],
            work_j: 0.0,
            plastic_j: 0.0,
            friction_j: 0.0,
            exchange_j: 0.0,
            ledger_j: 0.0,
            turnover_j: 0.0,
            unstable: None,
            sample: SpecimenSample {
                temperature_k: spec.initial_temperature_k,
                ..Default::default()
            },
            spec: spec.clone(),
        };
        body.refactor();
        body.update_free_rate();
        body.rebase_energy_ledger();
        Ok(body)
    }

    /// The specimen's name.
    pub fn name(&self) -> &str {
        CylinderSpecimen::NAME
    }

    /// Its specification.
    pub fn spec(&self) -> &CylinderSpecimen {
        &self.spec
    }

    /// Number of nodes N + 1.
    pub fn node_count(&self) -> usize {
        self.u.len()
    }

    /// Number of elements N.
    pub fn element_count(&self) -> usize {
        self.k.len()
    }

    /// Displacement u_i^n of node i, m.
    pub fn displacement_m(&self, i: usize) -> f64 {
        self.u[i]
    }

    /// Velocity v_i^{n−1/2} of node i, m/s.
    pub fn half_step_velocity_m_s(&self, i: usize) -> f64 {
        self.v[i]
    }

    /// Lumped mass of node i, kg.
    pub fn node_mass_kg(&self, i: usize) -> f64 {
        self.mass[i]
    }

    /// Equivalent plastic strain of element e.
    pub fn plastic_strain(&self, e: usize) -> f64 {
        self.eqps[e]
    }

    /// Temperature of element e, K.
    pub fn temperature_k(&self, e: usize) -> f64 {
        self.temperature_k[e]
    }

    /// True stress F/A_p of element e at the current level (tension positive), Pa.
    pub fn element_stress_pa(&self, e: usize) -> f64 {
        self.force[e] * self.lp[e] / (self.area0_m2 * self.dx0_m)
    }

    /// Initial length L₀, m (the x–t snapshots' axis).
    pub fn initial_length_m(&self) -> f64 {
        self.dx0_m * self.element_count() as f64
    }

    /// Elastic strain (l − l_p)/l_p = (Δu − s)/l_p of element e (tension positive): with no
    /// plastic slack exactly a bar element's Δu/Δx₀.
    fn elastic_strain(&self, e: usize) -> f64 {
        (self.u[e + 1] - self.u[e] - self.slack[e]) / self.lp[e]
    }

    /// True stress E ε_e at x along the initial length (tension positive), Pa: linear between
    /// element centres, constant from the outermost centres to the ends, as
    /// [`crate::bar::Bar::stress_at`] reads a bar.
    pub fn stress_at(&self, x_m: f64) -> f64 {
        let n = self.element_count();
        let e_mod = self.spec.material.youngs_modulus_pa;
        if n == 1 {
            return e_mod * self.elastic_strain(0);
        }
        let xi = (x_m / self.dx0_m - 0.5).clamp(0.0, (n - 1) as f64);
        let j = (xi as usize).min(n - 2);
        let t = xi - j as f64;
        let strain = if t == 0.0 {
            self.elastic_strain(j)
        } else {
            (1.0 - t) * self.elastic_strain(j) + t * self.elastic_strain(j + 1)
        };
        e_mod * strain
    }

    /// [`PlasticCylinder::stress_at`] at each of `x_m` found once (element and weight), for
    /// [`PlasticCylinder::sample_stress`] to read the specimen at the same points step after step (the
    /// x–t snapshots).
    pub fn stress_sampler(&self, x_m: &[f64]) -> Vec<(usize, f64)> {
        let n = self.element_count();
        x_m.iter()
            .map(|&x| {
                if n == 1 {
                    return (0, 0.0);
                }
                let xi = (x / self.dx0_m - 0.5).clamp(0.0, (n - 1) as f64);
                let j = (xi as usize).min(n - 2);
                (j, xi - j as f64)
            })
            .collect()
    }

    /// The stresses [`PlasticCylinder::stress_at`] gives at the points of `sampler` (made by
    /// [`PlasticCylinder::stress_sampler`] for this specimen), the same formula on the same operands:
    /// E·((1 − t) ε_j + t ε_{j+1}), ε_j alone where t = 0, Pa.
    pub fn sample_stress(&self, sampler: &[(usize, f64)]) -> Vec<f64> {
        let e_mod = self.spec.material.youngs_modulus_pa;
        sampler
            .iter()
            .map(|&(j, t)| {
                let strain = if t == 0.0 {
                    self.elastic_strain(j)
                } else {
                    (1.0 - t) * self.elastic_strain(j) + t * self.elastic_strain(j + 1)
                };
                e_mod * strain
            })
            .collect()
    }

    /// The sample taken by the last step (the level of its end forces).
    pub fn sample(&self) -> &SpecimenSample {
        &self.sample
    }

    /// Plastic work so far (the return maps' release of elastic energy less the friction part), J.
    pub fn plastic_work_j(&self) -> f64 {
        self.plastic_j
    }

    /// Friction work so far, J.
    pub fn friction_work_j(&self) -> f64 {
        self.friction_j
    }

    /// Kinetic energy the radial-inertia mass gave the specimen as it changed (ν_eff and J), J.
    pub fn inertia_exchange_j(&self) -> f64 {
        self.exchange_j
    }

    /// Work done by the end forces so far, J.
    pub fn work_done_j(&self) -> f64 {
        self.work_j
    }

    /// Whether a force at one end moves the other within the step (radial inertia couples them).
    pub fn couples_ends(&self) -> bool {
        !self.beta.is_empty()
    }

    /// The current plastic height Σl_p and diameter d₀√(L₀/Σl_p), m.
    fn plastic_geometry(&self) -> (f64, f64) {
        let h: f64 = self.lp.iter().sum();
        (h, self.spec.diameter_m * (self.spec.length_m / h).sqrt())
    }

    /// Refactorises M + B(β) and the end responses (radial inertia only).
    fn refactor(&mut self) {
        if self.beta.is_empty() {
            return;
        }
        let n = self.mass.len();
        let b = &self.beta;
        let diag: Vec<f64> = (0..n)
            .map(|i| {
                let bl = if i > 0 { b[i - 1] } else { 0.0 };
                let br = if i + 1 < n { b[i] } else { 0.0 };
                self.mass[i] + bl + br
            })
            .collect();
        let off: Vec<f64> = b.iter().map(|&x| -x).collect();
        self.matrix = Tridiagonal::factor(&diag, off);
        for (end, node) in [(0usize, 0usize), (1, n - 1)] {
            let mut r = vec![0.0; n];
            r[node] = 1.0;
            self.matrix.solve(&mut r);
            self.response[end] = r;
        }
    }

    /// Change of node i's v^{n+1/2} per unit time from end forces `f` = [left, right], m/s².
    fn force_response(&self, i: usize, f: [f64; 2]) -> f64 {
        if self.beta.is_empty() {
            let last = self.u.len() - 1;
            let mut r = 0.0;
            if i == 0 {
                r += self.inv_a[0] * f[0];
            }
            if i == last {
                r += self.inv_a[last] * f[1];
            }
            r
        } else {
            f[0] * self.response[0][i] + f[1] * self.response[1][i]
        }
    }

    /// Element forces at u^n and w = A⁻¹ f_int(u^n): the bar's operations for one free segment.
    fn update_free_rate(&mut self) {
        let last = self.u.len() - 1;
        for e in 0..self.k.len() {
            self.force[e] = self.k[e] * ((self.u[e + 1] - self.u[e]) - self.slack[e]);
        }
        let t = &self.force;
        if self.beta.is_empty() {
            for i in 1..last {
                self.w[i] = self.inv_a[i] * (t[i] - t[i - 1]);
            }
            self.w[0] = self.inv_a[0] * t[0];
            self.w[last] = self.inv_a[last] * -t[last - 1];
        } else {
            for i in 1..last {
                self.w[i] = t[i] - t[i - 1];
            }
            self.w[0] = t[0];
            self.w[last] = -t[last - 1];
            self.matrix.solve(&mut self.w);
        }
    }

    /// Restarts the energy ledger from a full recomputation.
    fn rebase_energy_ledger(&mut self) {
        self.ledger_j = self.recomputed_energy_j();
        self.turnover_j = self.ledger_j.abs();
    }

    /// v^{n+1/2} of an end if no force acted on it, given the force `other_end_force_n` on the
    /// other end this step (it moves this end only with radial inertia), m/s.
    pub fn free_end_velocity_m_s(&self, right: bool, other_end_force_n: f64) -> f64 {
        let i = if right { self.u.len() - 1 } else { 0 };
        if self.beta.is_empty() {
            return self.v[i] + self.dt_s * self.w[i];
        }
        let other = &self.response[usize::from(!right)];
        self.v[i] + self.dt_s * (self.w[i] + other[i] * other_end_force_n)
    }

    /// ∂v^{n+1/2}/∂F of an end per newton on that end, s/kg.
    pub fn end_mobility_s_per_kg(&self, right: bool) -> f64 {
        let i = if right { self.u.len() - 1 } else { 0 };
        let f = if right { [0.0, 1.0] } else { [1.0, 0.0] };
        self.dt_s * self.force_response(i, f)
    }

    /// Sets the specimen moving rigidly at `v_m_s`.
    pub fn set_initial_velocity(&mut self, v_m_s: f64) {
        self.v.fill(v_m_s);
        self.update_free_rate();
        self.rebase_energy_ledger();
    }

    /// Advances one step with axial forces (N, toward +x) on the two end nodes (the bar's
    /// leapfrog and energy rule, [`crate::bar::Bar::step`]), then return-maps every element at
    /// the new level (§6.12).
    pub fn step(&mut self, left_force_n: f64, right_force_n: f64) {
        let dt = self.dt_s;
        let last = self.u.len() - 1;
        let f = [left_force_n, right_force_n];
        let v_before = [self.v[0], self.v[last]];
        let height_before = self.spec.length_m + (self.u[last] - self.u[0]);
        if self.beta.is_empty() {
            self.w[0] += self.inv_a[0] * f[0];
            self.w[last] += self.inv_a[last] * f[1];
        } else {
            for (end, &fe) in f.iter().enumerate() {
                if fe != 0.0 {
                    for (wi, &g) in self.w.iter_mut().zip(&self.response[end]) {
                        *wi += fe * g;
                    }
                }
            }
        }
        for ((ui, vi), &wi) in self.u.iter_mut().zip(self.v.iter_mut()).zip(&self.w) {
            *vi += dt * wi;
            *ui += dt * *vi;
        }
        for (end, &node) in [0, last].iter().enumerate() {
            let mean = 0.5 * (v_before[end] + self.v[node]);
            let work = f[end] * mean * dt;
            let absorbed = 0.0;
            self.work_j += work;
            self.ledger_j += work - absorbed;
            self.turnover_j += work.abs() + absorbed;
        }
        self.take_sample(f, v_before, height_before);
        self.last_force = f;
        self.step_index += 1;
        self.settle();
        self.update_free_rate();
    }

    /// Advances one step with the end velocities v^{n+1/2} prescribed (e.g. a quasi-static test
    /// between platens) and returns the end forces (N, toward +x) that give them.
    pub fn step_with_end_velocities(&mut self, left_m_s: f64, right_m_s: f64) -> [f64; 2] {
        let last = self.u.len() - 1;
        let dt = self.dt_s;
        let rhs = [
            (left_m_s - self.v[0]) / dt - self.w[0],
            (right_m_s - self.v[last]) / dt - self.w[last],
        ];
        let a = [
            [
                self.force_response(0, [1.0, 0.0]),
                self.force_response(0, [0.0, 1.0]),
            ],
            [
                self.force_response(last, [1.0, 0.0]),
                self.force_response(last, [0.0, 1.0]),
            ],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let f = [
            (rhs[0] * a[1][1] - a[0][1] * rhs[1]) / det,
            (a[0][0] * rhs[1] - a[1][0] * rhs[0]) / det,
        ];
        self.step(f[0], f[1]);
        f
    }

    /// The sample of the level the forces `f` act at (before the step moved the nodes).
    fn take_sample(&mut self, f: [f64; 2], v_before: [f64; 2], height_m: f64) {
        let last = self.u.len() - 1;
        let n = self.k.len() as f64;
        let (h_p, _) = self.plastic_geometry();
        let area = self.area0_m2 * self.spec.length_m / h_p;
        let face = 0.5 * (f[0] - f[1]) / area;
        let phi = self.friction_factor;
        let mut element = 0.0;
        let mut friction = 0.0;
        for e in 0..self.k.len() {
            let s = -self.element_stress_pa(e);
            element += s;
            if self.flowing[e] {
                friction += s * (phi - 1.0) / phi;
            }
        }
        element /= n;
        friction /= n;
        let v_front = 0.5 * (v_before[0] + self.v[0]);
        let v_back = 0.5 * (v_before[1] + self.v[last]);
        self.sample = SpecimenSample {
            face_stress_pa: face,
            element_stress_pa: element,
            friction_stress_pa: friction,
            inertia_stress_pa: face - element,
            true_strain: -(height_m / self.spec.length_m).ln(),
            true_strain_rate_per_s: -(v_back - v_front) / height_m,
            plastic_strain: self.eqps.iter().sum::<f64>() / n,
            temperature_k: self.temperature_k.iter().sum::<f64>() / n,
            plastic_work_j: self.plastic_j,
            friction_work_j: self.friction_j,
        };
    }

    /// The return map of every element at the new level u^{n+1} (§6.12), then the radial-inertia
    /// mass of the new state; books the plastic and friction work and the inertia exchange.
    fn settle(&mut self) {
        if matches!(self.spec.flow, FlowModel::Elastic) && self.beta.is_empty() {
            return;
        }
        let dt = self.dt_s;
        let (h_p, d_p) = self.plastic_geometry();
        let phi = self
            .spec
            .friction
            .map_or(1.0, |f| f.factor(d_p, h_p).max(1.0));
        self.friction_factor = phi;
        let e_mod = self.spec.material.youngs_modulus_pa;
        let rho = self.spec.material.density_kg_m3;
        let volume_term = self.area0_m2 * self.dx0_m;
        let mut stiffened = false;
        for e in 0..self.k.len() {
            self.flowing[e] = false;
            if matches!(self.spec.flow, FlowModel::Elastic) {
                continue;
            }
            let stretch = self.u[e + 1] - self.u[e];
            let elastic = stretch - self.slack[e];
            let trial = e_mod * elastic / self.lp[e];
            let (eqps, temp) = (self.eqps[e], self.temperature_k[e]);
            let static_flow = phi * self.spec.flow.flow_stress_pa(eqps, 0.0, temp);
            if trial.abs() <= static_flow || trial.is_nan() {
                continue;
            }
            let sign = trial.signum();
            let lp = self.lp[e];
            let slack = self.slack[e];
            // |σ(Δ)| − φσ_f(ε̄p + Δ, Δ/Δt, T), falling in Δ, from > 0 at Δ = 0 to ≤ 0 where
            // l_p reaches l (σ = 0).
            let flow = &self.spec.flow;
            let g = |delta: f64| {
                let growth = lp * (sign * delta).exp_m1();
                let stress = e_mod * (elastic - growth) / (lp + growth);
                sign * stress - phi * flow.flow_stress_pa(eqps + delta, delta / dt, temp)
            };
            let hi = ((self.dx0_m + stretch) / lp).ln().abs();
            let g_lo = trial.abs() - static_flow;
            let g_hi = g(hi);
            let delta = if g_hi >= 0.0 {
                hi
            } else {
                let (a, b) = crate::numeric::illinois(
                    0.0,
                    hi,
                    g_lo,
                    g_hi,
                    200,
                    |a, b| b - a <= 1e-15 * b,
                    g,
                );
                0.5 * (a + b)
            };
            let growth = lp * (sign * delta).exp_m1();
            let new_lp = lp + growth;
            let new_slack = slack + growth;
            let new_k = e_mod * volume_term / (new_lp * new_lp);
            // The bilinear energy ½k(Δu^n − s)(Δu^{n+1} − s) before and after, at fixed
            // displacements: its release is the work the flow took (§6.12).
            let previous = stretch - dt * (self.v[e + 1] - self.v[e]);
            let before = self.k[e] * (previous - slack) * (stretch - slack);
            let after = new_k * (previous - new_slack) * (stretch - new_slack);
            let released = 0.5 * (before - after);
            self.plastic_j += released / phi;
            self.friction_j += released * (phi - 1.0) / phi;
            self.ledger_j -= released;
            self.turnover_j += released.abs();
            let flow_stress = flow.flow_stress_pa(eqps + delta, delta / dt, temp);
            if let Some(t) = flow.thermal() {
                self.temperature_k[e] +=
                    t.taylor_quinney * flow_stress * delta / (rho * t.specific_heat_j_kg_k);
            }
            self.eqps[e] = eqps + delta;
            self.lp[e] = new_lp;
            self.slack[e] = new_slack;
            stiffened |= new_k > self.k[e];
            self.k[e] = new_k;
            self.flowing[e] = true;
        }
        if !self.beta.is_empty() {
            let nu = self.spec.material.poisson_ratio;
            let mut exchange = 0.0;
            for e in 0..self.beta.len() {
                let nu_eff = if self.flowing[e] { 0.5 } else { nu };
                let area = volume_term / self.lp[e];
                let beta = rho * nu_eff * nu_eff * area * area / (2.0 * PI * self.lp[e]);
                let dv = self.v[e + 1] - self.v[e];
                exchange += 0.5 * (beta - self.beta[e]) * dv * dv;
                self.beta[e] = beta;
            }
            self.exchange_j += exchange;
            self.ledger_j += exchange;
            self.turnover_j += exchange.abs();
            self.refactor();
        }
        if stiffened && self.unstable.is_none() {
            let n = self.mass.len();
            for i in 0..n {
                let kl = if i > 0 { self.k[i - 1] } else { 0.0 };
                let kr = if i + 1 < n { self.k[i] } else { 0.0 };
                let bl = if i > 0 && !self.beta.is_empty() {
                    self.beta[i - 1]
                } else {
                    0.0
                };
                let br = if i + 1 < n && !self.beta.is_empty() {
                    self.beta[i]
                } else {
                    0.0
                };
                let bound = dt * dt * 2.0 * (kl + kr) / (self.mass[i] + 2.0 * (bl + br));
                if bound > STABILITY_BOUND {
                    let strain = (self.spec.length_m / self.lp.iter().sum::<f64>()).ln();
                    self.unstable = Some((
                        format!(
                            "specimen {}: compressed to a true strain {strain:.3}, node {i} is past the \
                             grid's stability limit (design_true_strain = {} sets the cells for it)",
                            CylinderSpecimen::NAME,
                            self.spec.design_true_strain
                        ),
                        bound,
                    ));
                    break;
                }
            }
        }
    }

    /// Momentum Σ m v at level n (v^{n−1/2} plus half the coming step's change), kg·m/s.
    pub fn momentum_kg_m_s(&self) -> f64 {
        (0..self.mass.len())
            .map(|i| {
                self.mass[i]
                    * (self.v[i]
                        + 0.5 * self.dt_s * (self.w[i] + self.force_response(i, self.last_force)))
            })
            .sum()
    }

    /// Kinetic energy ½vᵀ(M + B(β))v at n − 1/2, J.
    pub fn kinetic_energy_j(&self) -> f64 {
        let lumped: f64 = self.mass.iter().zip(&self.v).map(|(m, v)| m * v * v).sum();
        let lateral: f64 = self
            .beta
            .iter()
            .zip(self.v.windows(2))
            .map(|(b, vv)| b * (vv[1] - vv[0]).powi(2))
            .sum();
        0.5 * (lumped + lateral)
    }

    /// Elastic energy ½Σk(Δu^{n−1} − s)(Δu^n − s) at n − 1/2 (the bar's, about the plastic
    /// lengths), J.
    pub fn strain_energy_j(&self) -> f64 {
        let dt = self.dt_s;
        0.5 * self
            .k
            .iter()
            .zip(&self.slack)
            .zip(self.u.windows(2).zip(self.v.windows(2)))
            .map(|((k, s), (uu, vv))| {
                let du = (uu[1] - uu[0]) - s;
                k * du * (du - dt * (vv[1] - vv[0]))
            })
            .sum::<f64>()
    }

    /// Kinetic plus elastic energy from the ledger (end work, less plastic and friction work,
    /// plus the inertia exchange, since the last recomputation), J.
    pub fn energy_j(&self) -> f64 {
        self.ledger_j
    }

    /// The energy that has passed through the ledger, J.
    pub fn energy_turnover_j(&self) -> f64 {
        self.turnover_j
    }

    /// Kinetic plus elastic energy over every node and element, J.
    pub fn recomputed_energy_j(&self) -> f64 {
        self.kinetic_energy_j() + self.strain_energy_j()
    }

    /// Time of the current level, s.
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.dt_s
    }

    /// The O(1) check of a step: the ledger is finite and the grid still stable.
    pub fn check_step(&self) -> Result<()> {
        if let Some((what, value)) = &self.unstable {
            return Err(Error::Unstable {
                step: self.step_index,
                time_s: self.time_s(),
                quantity: what.clone(),
                value: *value,
            });
        }
        if self.ledger_j.is_finite() {
            return Ok(());
        }
        self.check_finite()?;
        self.check_energy_ledger(0.0)
    }

    /// Ledger against recomputation within [`ENERGY_LEDGER_TOLERANCE`] of the larger of the
    /// turnover and `scale_j`.
    pub fn check_energy_ledger(&self, scale_j: f64) -> Result<()> {
        let full = self.recomputed_energy_j();
        let difference = self.ledger_j - full;
        let scale = self.turnover_j.max(scale_j);
        if difference.is_finite() && difference.abs() <= ENERGY_LEDGER_TOLERANCE * scale {
            return Ok(());
        }
        Err(Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity: format!(
                "specimen {}: energy ledger {:e} J minus its recomputation {full:e} J (allowed: {ENERGY_LEDGER_TOLERANCE:e} of {scale:e} J)",
                CylinderSpecimen::NAME,
                self.ledger_j
            ),
            value: difference,
        })
    }

    /// Every displacement, velocity and plastic length is finite.
    pub fn check_finite(&self) -> Result<()> {
        for (what, values) in [
            ("displacement", &self.u),
            ("half-step velocity", &self.v),
            ("plastic length", &self.lp),
        ] {
            if let Some((i, &value)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(Error::Unstable {
                    step: self.step_index,
                    time_s: self.time_s(),
                    quantity: format!(
                        "specimen {}: {what} of node or element {i}",
                        CylinderSpecimen::NAME
                    ),
                    value,
                });
            }
        }
        Ok(())
    }
}

/// The specimen's series (compression positive; docs/physics.md §6.12), on the times of the
/// levels of the forces that loaded it (as the contact's, `record::ContactRecorder`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpecimenSeries {
    /// Times, s.
    pub time_s: Vec<f64>,
    /// Mean of the two face forces over the current area, Pa.
    pub face_stress_pa: Vec<f64>,
    /// Mean element true stress, Pa.
    pub element_stress_pa: Vec<f64>,
    /// Friction part of the element stress, Pa.
    pub friction_stress_pa: Vec<f64>,
    /// Inertia part: face minus element stress, Pa.
    pub inertia_stress_pa: Vec<f64>,
    /// True strain −ln(h/L₀).
    pub true_strain: Vec<f64>,
    /// True strain rate, 1/s.
    pub true_strain_rate_per_s: Vec<f64>,
    /// Mean equivalent plastic strain.
    pub plastic_strain: Vec<f64>,
    /// Mean temperature, K.
    pub temperature_k: Vec<f64>,
    /// Plastic work so far, J.
    pub plastic_work_j: Vec<f64>,
    /// Friction work so far, J.
    pub friction_work_j: Vec<f64>,
}

impl SpecimenSeries {
    /// The series in the loading's sense (docs/physics.md §6.13): in tension the stresses, the
    /// true strain and its rate turned (tension positive: σ = F/A with A = A₀L₀/L, ε = ln(L/L₀));
    /// in compression unchanged. Plastic strain, temperature and work carry no sign.
    pub fn in_loading_sense(mut self, loading: crate::loading::Loading) -> SpecimenSeries {
        if loading.is_tension() {
            for v in [
                &mut self.face_stress_pa,
                &mut self.element_stress_pa,
                &mut self.friction_stress_pa,
                &mut self.inertia_stress_pa,
                &mut self.true_strain,
                &mut self.true_strain_rate_per_s,
            ] {
                v.iter_mut().for_each(|x| *x = -*x);
            }
        }
        self
    }

    /// Appends one sample at `time_s`.
    pub fn push(&mut self, time_s: f64, s: &SpecimenSample) {
        self.time_s.push(time_s);
        self.face_stress_pa.push(s.face_stress_pa);
        self.element_stress_pa.push(s.element_stress_pa);
        self.friction_stress_pa.push(s.friction_stress_pa);
        self.inertia_stress_pa.push(s.inertia_stress_pa);
        self.true_strain.push(s.true_strain);
        self.true_strain_rate_per_s.push(s.true_strain_rate_per_s);
        self.plastic_strain.push(s.plastic_strain);
        self.temperature_k.push(s.temperature_k);
        self.plastic_work_j.push(s.plastic_work_j);
        self.friction_work_j.push(s.friction_work_j);
    }
}

/// Records the cylinder body `body` every `every` levels: after step k its sample holds level
/// k − 1, stamped (k − 1)Δt.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecimenRecorder {
    /// Index of the cylinder in the chain.
    pub body: usize,
    /// Sampling interval in steps.
    pub every: usize,
    /// Time step, s.
    pub dt_s: f64,
    /// The series.
    pub series: SpecimenSeries,
}

impl Recorder for SpecimenRecorder {
    fn record(&mut self, step: usize, _time_s: f64, bodies: &[Body], _joints: &[JointState]) {
        let Some(level) = step.checked_sub(1) else {
            return;
        };
        if !level.is_multiple_of(self.every) {
            return;
        }
        if let Body::Cylinder(c) = &bodies[self.body] {
            self.series.push(level as f64 * self.dt_s, c.sample());
        }
    }
}

#[cfg(test)]
mod tests;

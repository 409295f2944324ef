//! Time integration of the two-sphere DEM scenes (paper Sec. III, DEM; docs/physics.md §5).
//!
//! Scheme: velocity Verlet for the contact force, with linear dashpots (the bar media) treated by
//! the trapezoidal rule so that they are unconditionally stable. The per-contact history is
//! committed exactly once per step. The strain rate of paper Eq. 3 makes the force depend on the
//! approach speed like a (log-)viscous damper whose coefficient ∝ 1/δ̇ becomes unbounded as the
//! spheres stop; an explicit rate would be unstable there, so a rate-dependent law is evaluated
//! with the end-of-step approach speed u_{n+1}, solving the scalar monotone equation
//! u = A − B F(δ_{n+1}, u) of the velocity update by bracketed secant iteration (implicit in the rate,
//! second-order and stable). Rate-independent laws need one evaluation per step.
//!
//! Time-step rule: Δt = min(T/`steps_per_period`, m/(2Z)), where T = 2π√(m_red/k) is the period of
//! the linearised contact with k the Hertz tangent stiffness at the largest force expected, and
//! m/Z the relaxation time of a sphere on a dashpot.
//!
//! **Stability limit** ([`stability_limit`]): Δt ≤ 1/ω = T/(2π), half the linear bound 2/ω of
//! velocity Verlet. The linear bound is not a bound for a one-sided Hertz impact: at 0.99 · 2/ω an
//! impact takes two steps, overshoots to 1.7 times the Hertz peak force (where ω is 10 % higher,
//! so the step is past the bound after all) and returns 2.8 times the kinetic energy it received
//! (restitution 2.1), finite and silent. Measured on elastic Hertz impacts, whose discrete
//! result depends on Δt/t_c only (ω at the Hertz peak force; t_c ≈ 4/ω): for ωΔt ≤ 0.2 (≥ 20
//! steps per contact) the energy error is below 5e-4, for ωΔt ≤ 1 (≥ 4 steps) below 2 % — an
//! O(Δt²) error of a stable run; at ωΔt = 1.4 it reaches +6 %, at 1.8 +59 %, at 1.98 +180 %.
//! The smallest step counts a scene accepts (20 per contact, 10 per period) lie inside the limit.
//! At the limit a run is stable and passive, not accurate (restitution off by up to 56 % for
//! plastic impacts): the default steps are 500 times smaller.
//!
//! **Instability.** Every step checks that the state is finite, and that the contact has not
//! returned more energy than it received: ∫F dδ ≥ −[`PASSIVITY_TOLERANCE`] × (initial kinetic
//! energy + ∫|F_ext v1| dt). The laws are passive (Hertz conserves, the elastoplastic law
//! dissipates; the paper's published region II creates up to 2.8 % of the impact energy just
//! past yield), so a larger deficit is the scheme's doing: the run stops with
//! [`Error::Unstable`] naming the step, time and quantity instead of reporting a restitution > 1.

pub mod body;
pub mod chain;
pub mod cylinder;
pub mod joint;
pub mod record;
pub mod solitary;
pub mod spheres;

pub use body::{Body, BodySpec, MassSpec};
pub use chain::{Chain, ChainResult, ChainSetup, simulate_chain, simulate_chain_with};
pub use cylinder::{PlasticCylinder, SpecimenRecorder, SpecimenSeries};
pub use joint::Joint;
pub use record::{BarSnapshots, GaugeProbe, Recorder};
pub use spheres::{FreeChainResult, FreeChainSetup, StrikerMass, Wall, free_chain};

use crate::contact::{Contact, ContactEval, hertz_force};
use crate::error::{Error, Result};
use crate::specimen::SpherePair;

/// Hertz impact-duration constant 2∫₀¹(1−x^{5/2})^{-1/2}dx = (4/5)B(2/5,1/2) (Johnson, Contact Mechanics §11.4).
pub const HERTZ_DURATION_CONSTANT: f64 = 2.943_275_184_324_705;

/// Hertz maximum approach of an elastic impact, δ* = (15 m v² / (16 E* √r))^{2/5} (Johnson §11.4).
pub fn hertz_max_approach(
    reduced_mass_kg: f64,
    e_star_pa: f64,
    radius_m: f64,
    speed_m_s: f64,
) -> f64 {
    (15.0 * reduced_mass_kg * speed_m_s * speed_m_s / (16.0 * e_star_pa * radius_m.sqrt()))
        .powf(0.4)
}

/// Analytic duration of an elastic Hertz impact, t_c = 2.9432 δ*/v (Johnson §11.4).
pub fn hertz_impact_duration(
    reduced_mass_kg: f64,
    e_star_pa: f64,
    radius_m: f64,
    speed_m_s: f64,
) -> f64 {
    HERTZ_DURATION_CONSTANT * hertz_max_approach(reduced_mass_kg, e_star_pa, radius_m, speed_m_s)
        / speed_m_s
}

/// Smallest largest-approach a stepped impact may have, as a fraction of the scale of the
/// bodies' positions (r1 + r2 for two spheres): double-precision positions resolve the approach
/// δ = r1 + r2 − (x2 − x1) to about 2.2e-16 of that scale, so at 1e-6 of it δ* carries 10
/// significant digits. Below, the round-off of δ feeds the force and the energy: a 1e-12 m/s
/// collision of 6.35 mm spheres (δ* = 1.7 fm, 2000 ulps of 6.35 mm) came out with restitution
/// 1.0046 (issue 42).
pub const APPROACH_RESOLUTION_OF_POSITIONS: f64 = 1e-6;

/// Closing speed at which the elastic Hertz impact reaches largest approach `approach_m`, the
/// inverse of [`hertz_max_approach`]: v = √(16 E* √r δ*^{5/2} / (15 m)) (Johnson §11.4), m/s.
pub fn hertz_speed_for_approach(
    reduced_mass_kg: f64,
    e_star_pa: f64,
    radius_m: f64,
    approach_m: f64,
) -> f64 {
    (16.0 * e_star_pa * radius_m.sqrt() * approach_m.powf(2.5) / (15.0 * reduced_mass_kg)).sqrt()
}

/// The closing speeds an impact may be stepped at (m/s, low and high): from the speed whose
/// elastic Hertz approach is [`APPROACH_RESOLUTION_OF_POSITIONS`] of `position_scale_m` (below,
/// round-off decides the restitution) to the speed whose Hertz approach reaches the smaller
/// body radius `smallest_radius_m` (beyond, the spheres overlap by more than a radius: no
/// contact law describes them; the approach of a yielding law is larger still, Hertz is its
/// lower bound). `radius_m` and `e_star_pa` are the contact's effective radius and modulus.
pub fn impact_speed_range(
    reduced_mass_kg: f64,
    e_star_pa: f64,
    radius_m: f64,
    smallest_radius_m: f64,
    position_scale_m: f64,
) -> (f64, f64) {
    let v = |d: f64| hertz_speed_for_approach(reduced_mass_kg, e_star_pa, radius_m, d);
    (
        v(APPROACH_RESOLUTION_OF_POSITIONS * position_scale_m),
        v(smallest_radius_m),
    )
}

/// Refuses a closing speed outside [`impact_speed_range`] with an [`Error::Invalid`] of the
/// quantity `closing speed` naming the range and why.
pub fn check_impact_speed(
    reduced_mass_kg: f64,
    e_star_pa: f64,
    radius_m: f64,
    smallest_radius_m: f64,
    position_scale_m: f64,
    speed_m_s: f64,
) -> Result<()> {
    let (lo, hi) = impact_speed_range(
        reduced_mass_kg,
        e_star_pa,
        radius_m,
        smallest_radius_m,
        position_scale_m,
    );
    let delta = hertz_max_approach(reduced_mass_kg, e_star_pa, radius_m, speed_m_s);
    let allowed = || {
        format!(
            "a closing speed of {} for these spheres (their elastic Hertz approach from {:e} \
             of the position scale {} up to the smaller radius {})",
            crate::error::format_range(lo, hi, "m/s"),
            APPROACH_RESOLUTION_OF_POSITIONS,
            crate::error::format_si(position_scale_m, "m"),
            crate::error::format_si(smallest_radius_m, "m"),
        )
    };
    if speed_m_s < lo {
        return Err(Error::invalid(
            "closing speed",
            format!(
                "{}: its largest approach ({} by Hertz) is too small for double-precision \
                 positions to resolve, so round-off would decide the restitution and energies",
                crate::error::format_si(speed_m_s, "m/s"),
                crate::error::format_si(delta, "m"),
            ),
            allowed(),
        ));
    }
    if speed_m_s > hi {
        return Err(Error::invalid(
            "closing speed",
            format!(
                "{}: the spheres would overlap by more than the smaller radius ({} by elastic \
                 Hertz, more with yielding), where no contact law holds",
                crate::error::format_si(speed_m_s, "m/s"),
                crate::error::format_si(delta, "m"),
            ),
            allowed(),
        ));
    }
    Ok(())
}

/// Period 2π√(m/k) of the contact linearised at the Hertz tangent stiffness at force `force_n`, s.
pub fn contact_period(reduced_mass_kg: f64, e_star_pa: f64, radius_m: f64, force_n: f64) -> f64 {
    let delta = (3.0 * force_n / (4.0 * e_star_pa * radius_m.sqrt())).powf(2.0 / 3.0);
    let k = 2.0 * e_star_pa * (radius_m * delta).sqrt();
    2.0 * std::f64::consts::PI * (reduced_mass_kg / k).sqrt()
}

/// One rigid sphere moving along the bar axis, optionally held by a dashpot (a 1D elastic medium).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DashpotSphere {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Dashpot coefficient: impedance Z = ρ c0 A of the medium it presses on, kg/s (0 for none).
    pub damping_kg_s: f64,
    /// Position of the centre along the axis, m.
    pub position_m: f64,
    /// Velocity, m/s (positive toward the transmission side).
    pub velocity_m_s: f64,
}

/// Energies accumulated by the stepper, J (for the energy audit of a run).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyLedger {
    /// ∫F dδ of the contact (trapezoidal in δ): stored elastic energy plus plastic dissipation.
    pub contact_work_j: f64,
    /// Work done by the external force on sphere 1.
    pub external_work_j: f64,
    /// Energy radiated into the dashpot media.
    pub radiated_j: f64,
}

/// Largest share of the energy put into a pair (initial kinetic energy plus absolute external
/// work) that its contact may return beyond what it received before a run is stopped as unstable
/// (module docs, "Instability").
pub const PASSIVITY_TOLERANCE: f64 = 0.1;

/// State of the two-sphere system advanced by [`PairStepper::step`].
pub struct PairStepper {
    /// The contact law with its memory.
    law: Box<dyn Contact>,
    /// Incident-side sphere.
    pub sphere1: DashpotSphere,
    /// Transmission-side sphere.
    pub sphere2: DashpotSphere,
    /// r1 + r2: δ = r1 + r2 − (x2 − x1), m.
    pub sum_of_radii_m: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// Current time, s.
    pub time_s: f64,
    /// Steps taken.
    pub step_index: usize,
    /// Last contact evaluation.
    pub contact: ContactEval,
    /// External force on sphere 1 at the current time, N.
    pub external_force_n: f64,
    /// Energy bookkeeping.
    pub energy: EnergyLedger,
    /// Kinetic energy at the first step (set then, so velocities may be assigned after `new`), J.
    initial_kinetic_energy_j: Option<f64>,
    /// ∫|F_ext v1| dt: the external work counted without cancellation, J.
    external_work_abs_j: f64,
}

impl PairStepper {
    /// A stepper for `pair` under a fresh copy of `law`, with the spheres just touching (δ = 0) at t = 0.
    pub fn new(law: &dyn Contact, pair: &SpherePair, dt_s: f64) -> PairStepper {
        let sum = pair.sphere1.radius_m + pair.sphere2.radius_m;
        PairStepper {
            law: law.fresh(),
            sphere1: DashpotSphere {
                mass_kg: pair.sphere1.mass_kg,
                damping_kg_s: 0.0,
                position_m: 0.0,
                velocity_m_s: 0.0,
            },
            sphere2: DashpotSphere {
                mass_kg: pair.sphere2.mass_kg,
                damping_kg_s: 0.0,
                position_m: sum,
                velocity_m_s: 0.0,
            },
            sum_of_radii_m: sum,
            dt_s,
            time_s: 0.0,
            step_index: 0,
            // What the law reports before contact (the static σy for Burgoyne–Daraio).
            contact: law.fresh().trial(0.0, 0.0),
            external_force_n: 0.0,
            energy: EnergyLedger::default(),
            initial_kinetic_energy_j: None,
            external_work_abs_j: 0.0,
        }
    }

    /// Approach below which the contact carries no force now (the residual approach δr), m.
    pub fn zero_force_approach_m(&self) -> f64 {
        self.law.zero_force_approach()
    }

    /// Approach δ of the sphere centres (positive in compression), m.
    pub fn approach_m(&self) -> f64 {
        self.sum_of_radii_m - (self.sphere2.position_m - self.sphere1.position_m)
    }

    /// Approach speed δ̇ = v1 − v2, m/s.
    pub fn approach_speed_m_s(&self) -> f64 {
        self.sphere1.velocity_m_s - self.sphere2.velocity_m_s
    }

    /// Total kinetic energy of the spheres, J.
    pub fn kinetic_energy_j(&self) -> f64 {
        0.5 * self.sphere1.mass_kg * self.sphere1.velocity_m_s.powi(2)
            + 0.5 * self.sphere2.mass_kg * self.sphere2.velocity_m_s.powi(2)
    }

    /// Advances one step; `external_force_next_n` is the force on sphere 1 at the end of the step.
    pub fn step(&mut self, external_force_next_n: f64) -> Result<()> {
        let dt = self.dt_s;
        if self.initial_kinetic_energy_j.is_none() {
            self.initial_kinetic_energy_j = Some(self.kinetic_energy_j());
        }
        let (f_now, fext_now) = (self.contact.force_n, self.external_force_n);
        let delta_now = self.approach_m();
        let (v1_now, v2_now) = (self.sphere1.velocity_m_s, self.sphere2.velocity_m_s);
        let b1 = &mut self.sphere1;
        let v1h = b1.velocity_m_s
            + 0.5 * dt * (fext_now - f_now - b1.damping_kg_s * b1.velocity_m_s) / b1.mass_kg;
        b1.position_m += dt * v1h;
        let b2 = &mut self.sphere2;
        let v2h =
            b2.velocity_m_s + 0.5 * dt * (f_now - b2.damping_kg_s * b2.velocity_m_s) / b2.mass_kg;
        b2.position_m += dt * v2h;
        let delta_next = self.approach_m();
        let speed = if self.law.is_rate_dependent() && self.law.is_loading(delta_next) {
            self.implicit_approach_speed(v1h, v2h, external_force_next_n, delta_next)
        } else {
            (delta_next - delta_now) / dt
        };
        let eval = self.law.evaluate(delta_next, speed);
        let f_next = eval.force_n;
        let b1 = &mut self.sphere1;
        b1.velocity_m_s = (v1h + 0.5 * dt * (external_force_next_n - f_next) / b1.mass_kg)
            / (1.0 + 0.5 * dt * b1.damping_kg_s / b1.mass_kg);
        let b2 = &mut self.sphere2;
        b2.velocity_m_s = (v2h + 0.5 * dt * f_next / b2.mass_kg)
            / (1.0 + 0.5 * dt * b2.damping_kg_s / b2.mass_kg);
        let (v1m, v2m) = (
            0.5 * (v1_now + self.sphere1.velocity_m_s),
            0.5 * (v2_now + self.sphere2.velocity_m_s),
        );
        self.energy.contact_work_j += 0.5 * (f_now + f_next) * (delta_next - delta_now);
        let external_work = 0.5 * (fext_now + external_force_next_n) * v1m * dt;
        self.energy.external_work_j += external_work;
        self.external_work_abs_j += external_work.abs();
        self.energy.radiated_j +=
            (self.sphere1.damping_kg_s * v1m * v1m + self.sphere2.damping_kg_s * v2m * v2m) * dt;
        self.contact = eval;
        self.external_force_n = external_force_next_n;
        self.step_index += 1;
        self.time_s = self.step_index as f64 * dt;
        self.check_finite()?;
        self.check_passive()
    }

    /// Solves u = A − B F(δ, u) for the end-of-step approach speed u (module docs).
    fn implicit_approach_speed(&self, v1h: f64, v2h: f64, fext_next: f64, delta: f64) -> f64 {
        let dt = self.dt_s;
        let (b1, b2) = (&self.sphere1, &self.sphere2);
        let k1 = 1.0 + 0.5 * dt * b1.damping_kg_s / b1.mass_kg;
        let k2 = 1.0 + 0.5 * dt * b2.damping_kg_s / b2.mass_kg;
        let a = (v1h + 0.5 * dt * fext_next / b1.mass_kg) / k1 - v2h / k2;
        let b = 0.5 * dt / (b1.mass_kg * k1) + 0.5 * dt / (b2.mass_kg * k2);
        solve_approach_speed(self.law.as_ref(), delta, a, b)
    }

    /// Stops a run whose contact returned more energy than it received (module docs, "Instability").
    fn check_passive(&self) -> Result<()> {
        let input = self.initial_kinetic_energy_j.unwrap_or(0.0) + self.external_work_abs_j;
        let work = self.energy.contact_work_j;
        if work < 0.0 && -work > PASSIVITY_TOLERANCE * input {
            return Err(Error::Unstable {
                step: self.step_index,
                time_s: self.time_s,
                quantity: format!(
                    "contact work ∫F dδ (J): the contact returned more than {:.0} % of the {input:e} J \
                     put in beyond what it received (time step {:e} s too large for this contact; \
                     stability limit 1/ω at the peak force, solver::stability_limit)",
                    100.0 * PASSIVITY_TOLERANCE,
                    self.dt_s
                ),
                value: work,
            });
        }
        Ok(())
    }

    /// Stops a run that produced a non-finite value, naming step, time and quantity.
    fn check_finite(&self) -> Result<()> {
        let checks = [
            ("approach delta (m)", self.approach_m()),
            ("contact force (N)", self.contact.force_n),
            ("sphere 1 velocity (m/s)", self.sphere1.velocity_m_s),
            ("sphere 2 velocity (m/s)", self.sphere2.velocity_m_s),
        ];
        for (name, value) in checks {
            if !value.is_finite() {
                return Err(Error::Unstable {
                    step: self.step_index,
                    time_s: self.time_s,
                    quantity: name.to_string(),
                    value,
                });
            }
        }
        Ok(())
    }
}

/// The end-of-step approach speed u of a rate-dependent contact at approach `delta`: the root of
/// u = A − B F(δ, u) (velocity update of velocity Verlet with the force at the end of the step,
/// module docs), by bracketed Illinois iteration to 1e-13 relative. Shared by the pair and the
/// chain steppers, so both take exactly the same arithmetic.
pub fn solve_approach_speed(law: &dyn Contact, delta: f64, a: f64, b: f64) -> f64 {
    let force = |u: f64| law.trial_force(delta, u);
    // g(u) = u − A + B F(u) is increasing in u (F does not fall with the rate): bracket its root.
    let g = |u: f64| u - a + b * force(u);
    let u_hi = a - b * force(0.0);
    let f_hi = force(u_hi.max(0.0));
    let u_lo = a - b * f_hi;
    let (lo, hi) = (u_lo.min(u_hi), u_lo.max(u_hi));
    // F(u_hi) is known already when u_hi ≥ 0 (the usual case: F does not fall with the rate, so
    // u_lo ≤ u_hi): the same number, one law evaluation fewer a step.
    let g_at = |u: f64| {
        if u == u_hi && u_hi >= 0.0 {
            u - a + b * f_hi
        } else {
            g(u)
        }
    };
    let (glo, ghi) = (g_at(lo), g_at(hi));
    if glo >= 0.0 {
        return lo;
    }
    if ghi <= 0.0 {
        return hi;
    }
    // Illinois (modified regula falsi): superlinear, never leaves the bracket.
    crate::numeric::illinois_until(
        lo,
        hi,
        glo,
        ghi,
        100,
        |_, _, lo, hi| (hi - lo) <= 1e-13 * (hi.abs() + lo.abs()) + 1e-18,
        g,
    )
}

/// Time series of the contact, as written to `/contact` (datasets a scene lacks are `None`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactSeries {
    /// Time, s.
    pub time_s: Option<Vec<f64>>,
    /// Sphere approach δ, m.
    pub displacement_m: Vec<f64>,
    /// Contact force F, N.
    pub force_n: Vec<f64>,
    /// Yield stress in effect σy*, Pa.
    pub yield_stress_pa: Option<Vec<f64>>,
    /// Global strain rate of paper Eq. 3, 1/s.
    pub strain_rate_per_s: Option<Vec<f64>>,
}

impl ContactSeries {
    /// An empty series with time, yield-stress and strain-rate columns.
    fn dynamic(capacity: usize) -> ContactSeries {
        ContactSeries {
            time_s: Some(Vec::with_capacity(capacity)),
            displacement_m: Vec::with_capacity(capacity),
            force_n: Vec::with_capacity(capacity),
            yield_stress_pa: Some(Vec::with_capacity(capacity)),
            strain_rate_per_s: Some(Vec::with_capacity(capacity)),
        }
    }

    /// Appends one sample.
    pub fn push(&mut self, t: f64, delta: f64, eval: &ContactEval) {
        if let Some(v) = self.time_s.as_mut() {
            v.push(t);
        }
        self.displacement_m.push(delta);
        self.force_n.push(eval.force_n);
        if let Some(v) = self.yield_stress_pa.as_mut() {
            v.push(eval.yield_stress_pa);
        }
        if let Some(v) = self.strain_rate_per_s.as_mut() {
            v.push(eval.strain_rate_per_s);
        }
    }

    /// Index of the largest force.
    pub fn peak_index(&self) -> usize {
        argmax(&self.force_n)
    }
}

pub use crate::numeric::argmax;

/// Quasi-static loading curve F(δ) on `points` equally spaced approaches up to `max_m` (Fig. 2).
pub fn loading_curve(
    law: &dyn Contact,
    max_m: f64,
    points: usize,
    strain_rate_per_s: f64,
) -> ContactSeries {
    let mut s = ContactSeries::default();
    for i in 0..points {
        let d = max_m * i as f64 / (points - 1) as f64;
        s.displacement_m.push(d);
        s.force_n.push(law.loading_force(d, strain_rate_per_s));
    }
    s
}

/// Spheres pressed together at constant approach speed (Fig. 3): δ = v t up to `max_m`.
pub fn constant_rate(
    law: &dyn Contact,
    pair: &SpherePair,
    strain_rate_per_s: f64,
    max_m: f64,
    points: usize,
) -> ContactSeries {
    let speed = strain_rate_per_s * (pair.sphere1.radius_m + pair.sphere2.radius_m);
    let mut contact = law.fresh();
    let mut s = ContactSeries::dynamic(points);
    if !law.has_yield_stress() {
        s.yield_stress_pa = None;
    }
    for i in 0..points {
        let d = max_m * i as f64 / (points - 1) as f64;
        let eval = contact.evaluate(d, speed);
        s.push(d / speed, d, &eval);
    }
    s
}

/// Time limit of a collision scene in Hertz contact times t_c (`max_time_s = 100 t_c`): the
/// solver gives up (exit 3) when the contact has not ended by then. Measured over the built-in
/// materials, all three laws and closing speeds of 1 mm/s to 10 km/s, contacts last at most
/// 3 t_c; a yield stress 275 times lower than Al 2017's (1 MPa) stretches them to 13 t_c at
/// δ ≈ 2 R and 32 t_c at δ ≈ 200 R, far outside the model's range. The run's size is
/// estimated from this limit (`shpb_core::estimate`).
pub const COLLISION_TIME_LIMIT_CONTACT_TIMES: f64 = 100.0;

/// Inputs of a free two-sphere collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionSetup {
    /// Initial velocity of sphere 1, m/s.
    pub velocity1_m_s: f64,
    /// Initial velocity of sphere 2, m/s (v1 > v2 so that they approach).
    pub velocity2_m_s: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// Give up (no separation) after this time, s.
    pub max_time_s: f64,
    /// Keep every n-th step in the output series.
    pub output_every: usize,
}

/// What a collision yields.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionResult {
    /// Contact history over the impact.
    pub series: ContactSeries,
    /// Coefficient of restitution (v2' − v1')/(v1 − v2).
    pub restitution: f64,
    /// Duration of non-zero contact force, s (crossings interpolated linearly).
    pub contact_time_s: f64,
    /// Peak contact force, N.
    pub peak_force_n: f64,
    /// Largest approach, m.
    pub max_approach_m: f64,
    /// Kinetic energy before, J.
    pub kinetic_energy_before_j: f64,
    /// Kinetic energy after separation, J.
    pub kinetic_energy_after_j: f64,
    /// Energy dissipated in the contact ∮F dδ, J.
    pub dissipated_j: f64,
    /// Residual approach δr after unloading (permanent flattening), m.
    pub residual_approach_m: f64,
}

/// Two free spheres collide, starting in touch (δ = 0) with the given velocities.
pub fn collision(
    law: &dyn Contact,
    pair: &SpherePair,
    setup: &CollisionSetup,
) -> Result<CollisionResult> {
    let mut st = PairStepper::new(law, pair, setup.dt_s);
    st.sphere1.velocity_m_s = setup.velocity1_m_s;
    st.sphere2.velocity_m_s = setup.velocity2_m_s;
    let ke0 = st.kinetic_energy_j();
    let approach0 = setup.velocity1_m_s - setup.velocity2_m_s;
    let mut series = ContactSeries::dynamic(1024);
    if !law.has_yield_stress() {
        series.yield_stress_pa = None;
    }
    series.push(0.0, 0.0, &st.contact);
    let mut contact_end = None;
    let mut peak = 0.0f64;
    let mut max_approach = 0.0f64;
    while st.time_s < setup.max_time_s {
        let (t_prev, d_prev) = (st.time_s, st.approach_m());
        st.step(0.0)?;
        let d = st.approach_m();
        peak = peak.max(st.contact.force_n);
        max_approach = max_approach.max(d);
        if st.step_index.is_multiple_of(setup.output_every) {
            series.push(st.time_s, d, &st.contact);
        }
        if st.contact.force_n == 0.0 && peak > 0.0 && st.approach_speed_m_s() < 0.0 {
            // Force returned to zero: interpolate the crossing of δ through δr.
            let d0 = st.zero_force_approach_m();
            let frac = if d_prev != d {
                (d_prev - d0) / (d_prev - d)
            } else {
                1.0
            };
            contact_end = Some(t_prev + frac.clamp(0.0, 1.0) * setup.dt_s);
            if !st.step_index.is_multiple_of(setup.output_every) {
                series.push(st.time_s, d, &st.contact);
            }
            break;
        }
    }
    let contact_end = contact_end.ok_or_else(|| Error::Unstable {
        step: st.step_index,
        time_s: st.time_s,
        quantity: "contact did not end before the time limit; approach (m)".into(),
        value: st.approach_m(),
    })?;
    let ke1 = st.kinetic_energy_j();
    Ok(CollisionResult {
        series,
        restitution: -st.approach_speed_m_s() / approach0,
        contact_time_s: contact_end,
        peak_force_n: peak,
        max_approach_m: max_approach,
        kinetic_energy_before_j: ke0,
        kinetic_energy_after_j: ke1,
        dissipated_j: st.energy.contact_work_j,
        residual_approach_m: st.zero_force_approach_m(),
    })
}

/// A force history sampled at increasing times, linearly interpolated, zero outside its span.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceHistory {
    /// Sample times, s (strictly increasing).
    pub time_s: Vec<f64>,
    /// Force at each time, N.
    pub force_n: Vec<f64>,
}

impl ForceHistory {
    /// Force at time `t_s` (linear interpolation; 0 before the first and after the last sample).
    pub fn at(&self, t_s: f64) -> f64 {
        let t = &self.time_s;
        if t.is_empty() || t_s < t[0] || t_s > t[t.len() - 1] {
            return 0.0;
        }
        let i = t.partition_point(|&x| x <= t_s).clamp(1, t.len() - 1);
        let (t0, t1) = (t[i - 1], t[i]);
        let w = (t_s - t0) / (t1 - t0);
        self.force_n[i - 1] * (1.0 - w) + self.force_n[i] * w
    }

    /// Largest force, N.
    pub fn peak_n(&self) -> f64 {
        self.force_n.iter().cloned().fold(0.0, f64::max)
    }
}

/// Inputs of the force-driven Fig. 4 DEM (docs/physics.md §5).
#[derive(Debug, Clone, PartialEq)]
pub struct ForceDrivenSetup {
    /// Force applied to sphere 1.
    pub drive: ForceHistory,
    /// Impedance of the medium holding sphere 2, Z = ρ c0 A, kg/s.
    pub medium_impedance_kg_s: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Keep every n-th step in the output series.
    pub output_every: usize,
}

/// What a force-driven run yields.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceDrivenResult {
    /// Contact history.
    pub series: ContactSeries,
    /// Energy bookkeeping at the end.
    pub energy: EnergyLedger,
    /// Kinetic energy of the spheres at the end, J.
    pub kinetic_energy_j: f64,
}

/// Sphere 1 driven by a force history, sphere 2 on a linear medium of impedance Z (paper Fig. 4 DEM).
pub fn force_driven(
    law: &dyn Contact,
    pair: &SpherePair,
    setup: &ForceDrivenSetup,
) -> Result<ForceDrivenResult> {
    let mut st = PairStepper::new(law, pair, setup.dt_s);
    st.sphere2.damping_kg_s = setup.medium_impedance_kg_s;
    st.external_force_n = setup.drive.at(0.0);
    let steps = (setup.end_time_s / setup.dt_s).ceil() as usize;
    let mut series = ContactSeries::dynamic(steps / setup.output_every + 2);
    if !law.has_yield_stress() {
        series.yield_stress_pa = None;
    }
    series.push(0.0, 0.0, &st.contact);
    for n in 1..=steps {
        st.step(setup.drive.at(n as f64 * setup.dt_s))?;
        if n % setup.output_every == 0 || n == steps {
            series.push(st.time_s, st.approach_m(), &st.contact);
        }
    }
    Ok(ForceDrivenResult {
        series,
        energy: st.energy,
        kinetic_energy_j: st.kinetic_energy_j(),
    })
}

/// The default time step of a pair: min(T/steps_per_period, m2/(2Z)) (module docs).
pub fn default_time_step(
    pair: &SpherePair,
    expected_peak_force_n: f64,
    medium_impedance_kg_s: f64,
    steps_per_period: f64,
) -> f64 {
    let p = pair.contact_properties();
    let t = contact_period(
        pair.reduced_mass_kg(),
        p.e_star_pa,
        p.radius_m,
        expected_peak_force_n.max(1e-6),
    );
    let mut dt = t / steps_per_period;
    if medium_impedance_kg_s > 0.0 {
        dt = dt.min(pair.sphere2.mass_kg / (2.0 * medium_impedance_kg_s));
    }
    dt
}

/// Stability limit 1/ω = T/(2π) of the contact linearised at force `expected_peak_force_n`, s:
/// half velocity Verlet's linear bound 2/ω, which a one-sided impact violates at its own
/// overshoot (module docs, "Stability limit").
pub fn stability_limit(pair: &SpherePair, expected_peak_force_n: f64) -> f64 {
    let p = pair.contact_properties();
    contact_period(
        pair.reduced_mass_kg(),
        p.e_star_pa,
        p.radius_m,
        expected_peak_force_n.max(1e-6),
    ) / (2.0 * std::f64::consts::PI)
}

/// Hertz force on the Hertz curve at the elastic maximum approach (for sizing steps of collisions).
pub fn hertz_peak_force(pair: &SpherePair, speed_m_s: f64) -> f64 {
    let p = pair.contact_properties();
    let d = hertz_max_approach(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed_m_s);
    hertz_force(p.e_star_pa, p.radius_m, d)
}

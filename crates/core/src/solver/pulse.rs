//! The bar apparatus in time: striker → (pulse shaper) → incident bar (→ transmission bar),
//! all bars on one time step at Courant number 1 (docs/physics.md §6).
//!
//! Couplings between bar ends are solved implicitly for the step's end velocities, so they add
//! no stiffness to the explicit limit of the bars (which sit exactly at it at Courant 1):
//! * a **butt joint** (striker on bar without shaper, bar pressed on bar) carries compression
//!   only: while closed, the two half-mass end nodes move as one full node, exactly as a
//!   continuous bar would; it opens when holding it would need tension;
//! * a **pulse shaper** is a massless nonlinear spring F(closure): its force at level n is
//!   evaluated at the Newmark average closure (c^{n+1}(F) + 2c^n + c^{n−1})/4 (the β = 1/4
//!   "average acceleration" rule: unconditionally stable and, for an elastic spring, energy
//!   conserving) and solved by bisection (F_shaper does not fall with closure). The work it takes
//!   from the bars is F^n (c^{n+1} − c^{n−1})/2, the same discrete work the bars' ledgers count.

use crate::bar::Bar;
use crate::contact::{ContactEval, ContactHistory, ContactLaw, LawKind, Region2Form};
use crate::error::Result;
use crate::shaper::{PulseShaper, ShaperState};
use crate::specimen::ContactProperties;

/// How two bar ends touch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Joint {
    /// Compression-only butt contact.
    Butt,
    /// A copper pulse shaper between the ends.
    Shaper(PulseShaper),
    /// The two-sphere specimen: each sphere's mass sits on its bar's end node (added by the
    /// caller) and the spheres touch through a contact law (paper Eq. 1–3).
    Spheres {
        /// Effective contact properties of the pair.
        props: ContactProperties,
        /// The contact law.
        law: LawKind,
        /// Form of region II.
        region2: Region2Form,
    },
}

/// State of a joint between the right end of one bar and the left end of the next.
pub struct JointState {
    /// The joint's law.
    pub joint: Joint,
    /// Shaper memory (unused for other joints).
    pub shaper: ShaperState,
    /// The contact law of a `Spheres` joint.
    pub law: Option<Box<dyn ContactLaw>>,
    /// Contact memory of a `Spheres` joint.
    pub history: ContactHistory,
    /// Last contact evaluation of a `Spheres` joint.
    pub contact: ContactEval,
    /// Sphere approach δ at which the last force was evaluated, m.
    pub approach_m: f64,
    /// Compressive force carried in the last step, N.
    pub force_n: f64,
    /// Work the joint has taken from the bars, J (dissipation plus elastic energy held).
    pub work_j: f64,
}

impl JointState {
    /// A joint with no history.
    pub fn new(joint: Joint) -> JointState {
        let law = match joint {
            Joint::Spheres {
                props,
                law,
                region2,
            } => Some(law.build_with(props, region2)),
            _ => None,
        };
        let contact = match &law {
            Some(l) => l.evaluate(&mut ContactHistory::default(), 0.0, 0.0),
            None => ContactEval {
                force_n: 0.0,
                yield_stress_pa: 0.0,
                strain_rate_per_s: 0.0,
            },
        };
        JointState {
            joint,
            shaper: ShaperState::default(),
            law,
            history: ContactHistory::default(),
            contact,
            approach_m: 0.0,
            force_n: 0.0,
            work_j: 0.0,
        }
    }

    /// Plastic work dissipated in the shaper so far, J.
    pub fn dissipated_j(&self) -> f64 {
        self.work_j
    }
}

/// End-node data needed to solve a joint: current closure, predicted closure rate without the
/// joint force, and how the closure rate responds to it.
#[derive(Debug, Clone, Copy)]
pub struct JointPrediction {
    /// Closure: displacement of the left bar's end minus that of the right bar's end (> 0 compresses), m.
    pub closure_m: f64,
    /// Closure at the previous level c^{n−1}, m.
    pub previous_closure_m: f64,
    /// Closure rate at the half step if the joint carried no force, m/s.
    pub free_rate_m_s: f64,
    /// Drop of the closure rate per newton of joint force (Δt/m_left + Δt/m_right for lumped ends), m/(s·N).
    pub compliance: f64,
}

/// Root of F = law(F) for a law that does not grow with F (more force, less closure), in
/// [0, law(0)], by bisection to 1e-12 relative.
fn solve_force(law: impl Fn(f64) -> f64) -> f64 {
    let f_hi = law(0.0);
    if f_hi <= 0.0 {
        return 0.0;
    }
    let (lo, hi) = crate::numeric::bisect(
        0.0,
        f_hi,
        100,
        |lo, hi| hi - lo <= 1e-12 * hi,
        |f| law(f) > f,
    );
    0.5 * (lo + hi)
}

/// Solves the joint force for one step (≥ 0, compressive), updating the joint's memory.
pub fn solve_joint(state: &mut JointState, p: JointPrediction, dt_s: f64) -> f64 {
    let c_next = |f: f64| p.closure_m + dt_s * (p.free_rate_m_s - p.compliance * f);
    // Newmark-average closure and centred closure rate at level n for a force f.
    let c_avg = |f: f64| 0.25 * (c_next(f) + 2.0 * p.closure_m + p.previous_closure_m);
    let rate = |f: f64| (c_next(f) - p.previous_closure_m) / (2.0 * dt_s);
    let f = match state.joint {
        Joint::Butt => {
            // Closed joint: force that makes both ends move together (closure rate 0), if compressive.
            // (0 when the joint stays open, i.e. the ends would not meet within the step).
            ((p.closure_m + dt_s * p.free_rate_m_s) / (dt_s * p.compliance)).max(0.0)
        }
        Joint::Shaper(s) => {
            let shaper = state.shaper;
            solve_force(|f| s.force_n(&mut shaper.clone(), c_avg(f)))
        }
        Joint::Spheres { .. } => {
            let law = state.law.as_ref().expect("sphere joints carry their law");
            let h = state.history;
            solve_force(|f| law.evaluate(&mut h.clone(), c_avg(f), rate(f)).force_n)
        }
    };
    match state.joint {
        Joint::Shaper(s) => {
            s.force_n(&mut state.shaper, c_avg(f));
        }
        Joint::Spheres { .. } => {
            let law = state.law.as_ref().expect("sphere joints carry their law");
            state.approach_m = c_avg(f);
            state.contact = law.evaluate(&mut state.history, state.approach_m, rate(f));
        }
        Joint::Butt => {}
    }
    state.work_j += f * 0.5 * (c_next(f) - p.previous_closure_m);
    state.force_n = f;
    f
}

/// Predicts a joint between the right end of `left` and the left end of `right` (exact for
/// lumped and Love-rod bars: uses the bars' own free end velocities and end mobilities).
pub fn predict_joint(left: &Bar, right: &Bar) -> JointPrediction {
    let il = left.node_count() - 1;
    let closure = left.displacement_m(il) - right.displacement_m(0);
    let last_rate = left.half_step_velocity_m_s(il) - right.half_step_velocity_m_s(0);
    JointPrediction {
        closure_m: closure,
        previous_closure_m: closure - left.dt_s() * last_rate,
        free_rate_m_s: left.free_end_velocity_m_s(true) - right.free_end_velocity_m_s(false),
        compliance: left.end_mobility_s_per_kg(true, true)
            + right.end_mobility_s_per_kg(false, false),
    }
}

/// Advances a chain of bars joined end to end by one step; returns the joint forces used.
pub fn step_chain(bars: &mut [Bar], joints: &mut [JointState]) -> Result<()> {
    debug_assert_eq!(joints.len() + 1, bars.len());
    let dt = bars[0].dt_s();
    let mut forces = vec![0.0; joints.len()];
    for (k, j) in joints.iter_mut().enumerate() {
        let p = predict_joint(&bars[k], &bars[k + 1]);
        forces[k] = solve_joint(j, p, dt);
    }
    let n = bars.len();
    for (k, bar) in bars.iter_mut().enumerate() {
        let left = if k > 0 { forces[k - 1] } else { 0.0 };
        let right = if k + 1 < n { -forces[k] } else { 0.0 };
        bar.step(left, right);
        bar.check_finite()?;
    }
    Ok(())
}

/// Which bar of the chain a gauge sits on, and where.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeProbe {
    /// Channel name.
    pub name: String,
    /// Index of the bar in the chain (0 = striker).
    pub bar: usize,
    /// Position along that bar from its left end, m.
    pub x_m: f64,
    /// Gauge grid length over which the strain is averaged, m (0: a point).
    pub length_m: f64,
}

/// Inputs of a pulse run: a chain of bars joined end to end, the first moving at the striker speed.
#[derive(Debug, Clone)]
pub struct ChainSetup {
    /// The bars, left to right (striker first).
    pub bars: Vec<crate::bar::BarSpec>,
    /// The joints between consecutive bars.
    pub joints: Vec<Joint>,
    /// Initial velocity of the first bar, m/s.
    pub striker_velocity_m_s: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Gauges to record.
    pub gauges: Vec<GaugeProbe>,
    /// Record every n-th step.
    pub record_every: usize,
    /// Lumped masses added to bar ends before the run: (bar index, right end?, kg) — the spheres.
    pub end_masses: Vec<(usize, bool, f64)>,
    /// Record the stress field of every bar every this many steps (None: no snapshots).
    pub snapshot_every: Option<usize>,
    /// Spacing of the snapshot points along the bars, m.
    pub snapshot_spacing_m: f64,
}

/// The decimated x–t stress field of one bar (for Lagrange diagrams).
#[derive(Debug, Clone, PartialEq)]
pub struct BarSnapshots {
    /// Bar name.
    pub name: String,
    /// Positions along the bar, m.
    pub x_m: Vec<f64>,
    /// Snapshot times, s.
    pub time_s: Vec<f64>,
    /// Axial stress (tension positive), one row per time, Pa.
    pub stress_pa: Vec<Vec<f64>>,
}

/// What a pulse run yields: gauge strains and the energy ledger over time.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainResult {
    /// Recording times, s.
    pub time_s: Vec<f64>,
    /// Strain per gauge (positive in tension), in the order of the setup.
    pub strain: Vec<Vec<f64>>,
    /// Kinetic + strain energy in all bars at each recording time, J.
    pub bar_energy_j: Vec<f64>,
    /// Energy absorbed by non-reflecting ends so far, J.
    pub absorbed_energy_j: Vec<f64>,
    /// Work taken by the pulse shaper and butt joints so far, J.
    pub shaper_energy_j: Vec<f64>,
    /// Work taken by the sphere contact so far (dissipated plus elastic energy held), J.
    pub contact_energy_j: Vec<f64>,
    /// The sphere contact's history (approach, force, σy*, strain rate), if the chain has one.
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

/// Axial displacement at position `x_m` along a bar (linear between nodes), m.
fn displacement_at(bar: &Bar, x_m: f64) -> f64 {
    let n = bar.node_count();
    let (mut lo, mut hi) = (0, n - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if bar.node_position_m(mid) <= x_m {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (x0, x1) = (bar.node_position_m(lo), bar.node_position_m(hi));
    let w = ((x_m - x0) / (x1 - x0)).clamp(0.0, 1.0);
    bar.displacement_m(lo) * (1.0 - w) + bar.displacement_m(hi) * w
}

/// Strain a gauge reads: the mean bar strain over its grid, (u(x+L/2) − u(x−L/2))/L, exactly what a
/// bonded foil gauge of length L averages (and, over an even number of cells, free of the grid's
/// two-cell zigzag); a point value for L = 0.
fn gauge_strain(bar: &Bar, g: &GaugeProbe) -> f64 {
    if g.length_m <= 0.0 {
        return bar.strain_at(g.x_m);
    }
    (displacement_at(bar, g.x_m + 0.5 * g.length_m)
        - displacement_at(bar, g.x_m - 0.5 * g.length_m))
        / g.length_m
}

/// Runs a chain of bars (striker → shaper → incident → transmission …) and records its gauges.
pub fn simulate_chain(setup: &ChainSetup) -> Result<ChainResult> {
    let mut bars = setup
        .bars
        .iter()
        .map(|s| Bar::new(s, setup.dt_s))
        .collect::<Result<Vec<_>>>()?;
    // Each sphere's mass joins its bar's end node (the paper's DEM).
    for &(k, right, mass_kg) in &setup.end_masses {
        let node = if right { bars[k].node_count() - 1 } else { 0 };
        bars[k].add_node_mass(node, mass_kg);
    }
    bars[0].set_initial_velocity(setup.striker_velocity_m_s);
    let striker_energy_j = bars[0].kinetic_energy_j();
    let mut joints: Vec<JointState> = setup.joints.iter().map(|&j| JointState::new(j)).collect();
    let steps = (setup.end_time_s / setup.dt_s).ceil() as usize;
    let cap = steps / setup.record_every + 2;
    let mut out = ChainResult {
        time_s: Vec::with_capacity(cap),
        strain: vec![Vec::with_capacity(cap); setup.gauges.len()],
        bar_energy_j: Vec::with_capacity(cap),
        absorbed_energy_j: Vec::with_capacity(cap),
        shaper_energy_j: Vec::with_capacity(cap),
        contact_energy_j: Vec::with_capacity(cap),
        contact: joints
            .iter()
            .any(|j| j.law.is_some())
            .then(|| crate::solver::ContactSeries {
                time_s: Some(Vec::with_capacity(cap)),
                yield_stress_pa: Some(Vec::with_capacity(cap)),
                strain_rate_per_s: Some(Vec::with_capacity(cap)),
                ..Default::default()
            }),
        snapshots: match setup.snapshot_every {
            Some(_) => bars
                .iter()
                .map(|b| {
                    let len = b.node_position_m(b.node_count() - 1);
                    let n = ((len / setup.snapshot_spacing_m).round() as usize).max(1);
                    BarSnapshots {
                        name: b.name().to_string(),
                        x_m: (0..=n).map(|k| len * k as f64 / n as f64).collect(),
                        time_s: Vec::new(),
                        stress_pa: Vec::new(),
                    }
                })
                .collect(),
            None => Vec::new(),
        },
        striker_energy_j,
        striker_final_velocity_m_s: 0.0,
        steps,
    };
    let mut record = |bars: &[Bar], joints: &[JointState], t: f64| {
        out.time_s.push(t);
        for (k, g) in setup.gauges.iter().enumerate() {
            out.strain[k].push(gauge_strain(&bars[g.bar], g));
        }
        out.bar_energy_j.push(
            bars.iter()
                .map(|b| b.kinetic_energy_j() + b.strain_energy_j())
                .sum(),
        );
        out.absorbed_energy_j
            .push(bars.iter().map(|b| b.absorbed_energy_j()).sum());
        out.shaper_energy_j.push(
            joints
                .iter()
                .filter(|j| j.law.is_none())
                .map(|j| j.dissipated_j())
                .sum(),
        );
        out.contact_energy_j.push(
            joints
                .iter()
                .filter(|j| j.law.is_some())
                .map(|j| j.dissipated_j())
                .sum(),
        );
        if let (Some(c), Some(j)) = (
            out.contact.as_mut(),
            joints.iter().find(|j| j.law.is_some()),
        ) {
            c.push(t, j.approach_m, &j.contact);
        }
    };
    record(&bars, &joints, 0.0);
    let snapshot = |bars: &[Bar], snaps: &mut [BarSnapshots], t: f64| {
        for (b, s) in bars.iter().zip(snaps.iter_mut()) {
            s.time_s.push(t);
            s.stress_pa
                .push(s.x_m.iter().map(|&x| b.stress_at(x)).collect());
        }
    };
    for n in 1..=steps {
        step_chain(&mut bars, &mut joints)?;
        if let Some(k) = setup.snapshot_every
            && n % k == 0
        {
            snapshot(&bars, &mut out.snapshots, n as f64 * setup.dt_s);
        }
        if n % setup.record_every == 0 {
            record(&bars, &joints, n as f64 * setup.dt_s);
        }
    }
    let s = &bars[0];
    let m: f64 = (0..s.node_count()).map(|i| s.node_mass_kg(i)).sum();
    out.striker_final_velocity_m_s = (0..s.node_count())
        .map(|i| s.node_mass_kg(i) * s.velocity_m_s(i))
        .sum::<f64>()
        / m;
    Ok(out)
}

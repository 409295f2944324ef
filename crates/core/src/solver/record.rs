//! What a chain run keeps: recorders sample the bodies and joints while it runs (gauges,
//! energies, the sphere contact, x–t stress snapshots, every sphere of a chain, the progress
//! line). On dispersive delay-line bars the gauges and snapshots are evaluated after the run from
//! the bars' whole histories through the transit filters (`finish`; docs/physics.md §6.2.1). A
//! new output is a new [`Recorder`], not a new field in the solver.

use super::body::Body;
use super::joint::JointState;
use crate::bar::Bar;
use crate::contact::ContactEval;
use crate::solver::ContactSeries;

/// Something that samples a chain while it runs.
pub trait Recorder {
    /// Called before the first step (`step` 0) and after every step `step` = 1, 2, …, at time `time_s`.
    fn record(&mut self, step: usize, time_s: f64, bodies: &[Body], joints: &[JointState]);

    /// Whether the run should stop now (checked after every record; the run then ends with
    /// [`crate::Error::Cancelled`]).
    fn stop(&self) -> bool {
        false
    }
}

/// Which bar of the chain a gauge sits on, and where.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeProbe {
    /// Channel name.
    pub name: String,
    /// Index of the body in the chain (0 = striker); it must be a bar.
    pub bar: usize,
    /// Position along that bar from its left end, m.
    pub x_m: f64,
    /// Gauge grid length over which the strain is averaged, m (0: a point).
    pub length_m: f64,
}

/// Strain a gauge reads: the mean bar strain over its grid, (u(x+L/2) − u(x−L/2))/L, exactly what a
/// bonded foil gauge of length L averages (and, over an even number of cells, free of the grid's
/// two-cell zigzag); a point value for L = 0.
pub fn gauge_strain(bar: &Bar, g: &GaugeProbe) -> f64 {
    if g.length_m <= 0.0 {
        return bar.strain_at(g.x_m);
    }
    bar.stretch_between_m(g.x_m - 0.5 * g.length_m, g.x_m + 0.5 * g.length_m) / g.length_m
}

/// [`gauge_strain`] over the past `steps` of a dispersive delay line, from its histories
/// ([`Bar::stress_history`]); `None` for any other bar.
pub fn gauge_strain_history(bar: &Bar, g: &GaugeProbe, steps: &[usize]) -> Option<Vec<f64>> {
    if g.length_m <= 0.0 {
        return bar.strain_history(g.x_m, steps);
    }
    let stretch =
        bar.stretch_between_history(g.x_m - 0.5 * g.length_m, g.x_m + 0.5 * g.length_m, steps)?;
    Some(stretch.into_iter().map(|s| s / g.length_m).collect())
}

/// Gauge strains every `every` steps, on a common time axis. Gauges on dispersive delay lines
/// are computed after the run ([`GaugeRecorder::finish`]): with each wave's whole precursor, and
/// without a convolution per step.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeRecorder {
    /// The gauges.
    pub gauges: Vec<GaugeProbe>,
    /// Sampling interval in steps.
    pub every: usize,
    /// Recording times, s.
    pub time_s: Vec<f64>,
    /// Strain per gauge (positive in tension), in the order of `gauges`.
    pub strain: Vec<Vec<f64>>,
    /// Steps recorded.
    steps: Vec<usize>,
}

impl GaugeRecorder {
    /// A recorder of `gauges` every `every` steps, with room for `capacity` samples.
    pub fn new(gauges: Vec<GaugeProbe>, every: usize, capacity: usize) -> GaugeRecorder {
        GaugeRecorder {
            strain: vec![Vec::with_capacity(capacity); gauges.len()],
            gauges,
            every,
            time_s: Vec::with_capacity(capacity),
            steps: Vec::with_capacity(capacity),
        }
    }

    /// Fills the series of the gauges on dispersive delay lines among `bodies` (the same chain,
    /// after the run), held at zero while it ran.
    pub fn finish(&mut self, bodies: &[Body]) {
        for (g, s) in self.gauges.iter().zip(self.strain.iter_mut()) {
            let bar = bodies[g.bar].as_bar().expect("gauges sit on bars");
            if let Some(series) = gauge_strain_history(bar, g, &self.steps) {
                *s = series;
            }
        }
    }
}

impl Recorder for GaugeRecorder {
    fn record(&mut self, step: usize, time_s: f64, bodies: &[Body], _joints: &[JointState]) {
        if !step.is_multiple_of(self.every) {
            return;
        }
        self.time_s.push(time_s);
        self.steps.push(step);
        for (g, s) in self.gauges.iter().zip(self.strain.iter_mut()) {
            let bar = bodies[g.bar].as_bar().expect("gauges sit on bars");
            s.push(if bar.transit_model().is_some() {
                0.0
            } else {
                gauge_strain(bar, g)
            });
        }
    }
}

/// The energy ledger every `every` steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EnergyRecorder {
    /// Sampling interval in steps.
    pub every: usize,
    /// Kinetic + strain energy in all bodies, J.
    pub body_energy_j: Vec<f64>,
    /// Energy absorbed by non-reflecting ends so far, J.
    pub absorbed_energy_j: Vec<f64>,
    /// Work taken by pulse shapers and butt joints so far, J.
    pub shaper_energy_j: Vec<f64>,
    /// Work taken by sphere contacts so far (dissipated plus elastic energy held), J.
    pub contact_energy_j: Vec<f64>,
    /// Plastic work in elastoplastic specimens so far, J (docs/physics.md §6.12).
    pub plastic_work_j: Vec<f64>,
    /// Friction work at the specimens' faces so far, J (§6.12).
    pub friction_work_j: Vec<f64>,
    /// Kinetic energy given to the specimens by their changing radial-inertia mass, J (§6.12).
    pub inertia_exchange_j: Vec<f64>,
}

impl Recorder for EnergyRecorder {
    fn record(&mut self, step: usize, _time_s: f64, bodies: &[Body], joints: &[JointState]) {
        if !step.is_multiple_of(self.every) {
            return;
        }
        self.body_energy_j
            .push(bodies.iter().map(Body::energy_j).sum());
        self.absorbed_energy_j
            .push(bodies.iter().map(Body::absorbed_energy_j).sum());
        let work = |contact: bool| {
            joints
                .iter()
                .filter(|j| j.law.is_some() == contact)
                .map(JointState::dissipated_j)
                .sum()
        };
        self.shaper_energy_j.push(work(false));
        self.contact_energy_j.push(work(true));
        self.plastic_work_j
            .push(bodies.iter().map(Body::plastic_work_j).sum());
        self.friction_work_j
            .push(bodies.iter().map(Body::friction_work_j).sum());
        self.inertia_exchange_j
            .push(bodies.iter().map(Body::inertia_exchange_j).sum());
    }
}

/// The history of one sphere contact (approach, force, σy*, strain rate) every `every` steps,
/// each sample at the time of the level it belongs to: the step from level n to n + 1 solves the
/// joint at level n (Newmark-average closure and centred rate, [`super::joint`]), so the joint
/// read after that step is stamped t_n, not t_{n+1} (the gauges, read from the bodies, are at
/// t_{n+1}).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRecorder {
    /// Index of the joint recorded.
    pub joint: usize,
    /// Sampling interval in steps.
    pub every: usize,
    /// Time step, s.
    pub dt_s: f64,
    /// The series.
    pub series: ContactSeries,
}

impl ContactRecorder {
    /// A recorder of joint `joint` every `every` steps of `dt_s`, with room for `capacity` samples.
    pub fn new(joint: usize, every: usize, dt_s: f64, capacity: usize) -> ContactRecorder {
        ContactRecorder {
            joint,
            every,
            dt_s,
            series: ContactSeries {
                time_s: Some(Vec::with_capacity(capacity)),
                yield_stress_pa: Some(Vec::with_capacity(capacity)),
                strain_rate_per_s: Some(Vec::with_capacity(capacity)),
                ..Default::default()
            },
        }
    }
}

/// The time of the level whose joint solves the chain holds after step `step`, if a sample of
/// every `every` levels is due: the step from level n to n + 1 solves the joints at level n, so
/// after step k they hold level k − 1, at t = (k − 1) Δt (`None` before the first step).
fn joint_level_time(step: usize, every: usize, dt_s: f64) -> Option<f64> {
    let level = step.checked_sub(1)?;
    level.is_multiple_of(every).then_some(level as f64 * dt_s)
}

impl Recorder for ContactRecorder {
    fn record(&mut self, step: usize, _time_s: f64, _bodies: &[Body], joints: &[JointState]) {
        // The force is the one the joint applied to the bodies (what the gauges see), plus a
        // preload's static force (the contact's whole force; docs/physics.md §6.11): it equals
        // the law's value at the committed approach to the solve's 1e-12, except where the solve
        // stops on the law's jump at a turning point (the `dynamic` unloading starts from the
        // largest force reached, so at δ = δmax the law holds any force between the loading and
        // that one; joint.rs), where the law's value alone would read the largest force again.
        if let Some(t) = joint_level_time(step, self.every, self.dt_s) {
            let j = &joints[self.joint];
            let applied = ContactEval {
                force_n: j.contact_force_n(),
                ..j.contact
            };
            self.series.push(t, j.approach_m, &applied);
        }
    }
}

/// The series of a chain of spheres, as written to `/chain` (docs/physics.md §8): contact k
/// (1-based) is between spheres k and k + 1.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChainSeries {
    /// Recording times, s.
    pub time_s: Vec<f64>,
    /// Force of each contact (rows: contact, columns: time), N.
    pub contact_force_n: Vec<Vec<f64>>,
    /// Approach δ of each contact (rows: contact, columns: time), m.
    pub contact_approach_m: Vec<Vec<f64>>,
    /// Velocity of each sphere (rows: sphere, columns: time), m/s.
    pub velocity_m_s: Vec<Vec<f64>>,
    /// Velocity of each sphere at the end, m/s.
    pub final_velocity_m_s: Vec<f64>,
    /// Further 1-D series on the same time axis: (name, data, units), e.g. `wall_force`.
    pub extra: Vec<(String, Vec<f64>, &'static str)>,
}

/// Every sphere contact and every sphere of a chain specimen between the bars, every `every`
/// steps: the `/chain` series of an SHPB test (docs/physics.md §8). Sphere 1 and sphere N are
/// the end nodes of the incident and transmission bars; the spheres between are rigid masses.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereChainRecorder {
    /// Sampling interval in steps.
    pub every: usize,
    /// Time step, s.
    pub dt_s: f64,
    /// Indices of the sphere-contact joints, in order along the chain.
    pub joints: Vec<usize>,
    /// Each sphere as (body index, end of that body it sits at: `Some(right)` for a bar's end
    /// node, `None` for a rigid mass).
    pub spheres: Vec<(usize, Option<bool>)>,
    /// The series, on the times of the levels the contacts were solved at, as
    /// [`ContactRecorder`]'s (velocities at those levels: the mean of the two half-step ones
    /// around each, (v^{n−1/2} + v^{n+1/2})/2; the final velocities are filled in by
    /// [`SphereChainRecorder::into_series`]).
    pub series: ChainSeries,
    /// Each sphere's half-step velocity after the previous step, m/s.
    half_step_m_s: Vec<f64>,
}

impl SphereChainRecorder {
    /// A recorder of the sphere contacts of `joints` (the chain's joints), every `every` steps
    /// of `dt_s`.
    pub fn new(joints: &[super::joint::Joint], every: usize, dt_s: f64) -> SphereChainRecorder {
        let contacts: Vec<usize> = joints
            .iter()
            .enumerate()
            .filter(|(_, j)| matches!(j, super::joint::Joint::Spheres { .. }))
            .map(|(k, _)| k)
            .collect();
        let mut spheres = Vec::new();
        if let (Some(&first), Some(&last)) = (contacts.first(), contacts.last()) {
            // Joint k joins bodies k and k + 1.
            spheres.push((first, Some(true)));
            spheres.extend((first + 1..=last).map(|b| (b, None)));
            spheres.push((last + 1, Some(false)));
        }
        SphereChainRecorder {
            every,
            dt_s,
            series: ChainSeries {
                time_s: Vec::new(),
                contact_force_n: vec![Vec::new(); contacts.len()],
                contact_approach_m: vec![Vec::new(); contacts.len()],
                velocity_m_s: vec![Vec::new(); spheres.len()],
                final_velocity_m_s: Vec::new(),
                extra: Vec::new(),
            },
            half_step_m_s: vec![0.0; spheres.len()],
            joints: contacts,
            spheres,
        }
    }
}

impl SphereChainRecorder {
    /// The recorded series, with each sphere's final velocity (its last sample).
    pub fn into_series(self) -> ChainSeries {
        let mut series = self.series;
        series.final_velocity_m_s = series
            .velocity_m_s
            .iter()
            .map(|v| v.last().copied().unwrap_or(0.0))
            .collect();
        series
    }
}

impl Recorder for SphereChainRecorder {
    fn record(&mut self, step: usize, _time_s: f64, bodies: &[Body], joints: &[JointState]) {
        // After step k the bodies hold v^{k−1/2}, the half step after the level k − 1 the joints
        // were solved at; with v^{k−3/2}, kept from the step before (at step 0 the initial
        // v^{−1/2}), their mean is the velocity at that level, on the forces' time: a sphere's
        // velocity is then its initial one plus the trapezoidal integral of the recorded net
        // force over its mass.
        let due = joint_level_time(step, self.every, self.dt_s);
        if let Some(t) = due {
            self.series.time_s.push(t);
            for (k, &j) in self.joints.iter().enumerate() {
                // The force applied to the bodies, as `ContactRecorder` records it.
                self.series.contact_force_n[k].push(joints[j].contact_force_n());
                self.series.contact_approach_m[k].push(joints[j].approach_m);
            }
        }
        for (k, &(b, end)) in self.spheres.iter().enumerate() {
            let v = bodies[b].end_half_step_velocity_m_s(end.unwrap_or(true));
            if due.is_some() {
                self.series.velocity_m_s[k].push(0.5 * (self.half_step_m_s[k] + v));
            }
            self.half_step_m_s[k] = v;
        }
    }
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

/// Stress fields of every bar every `every` steps (not at step 0), at `spacing_m` along each bar.
/// A dispersive delay line's fields are computed after the run from its histories
/// ([`SnapshotRecorder::finish`], [`Bar::stress_history`]): reading them step by step would cost
/// a convolution per point and snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotRecorder {
    /// Sampling interval in steps.
    pub every: usize,
    /// One field per bar of the chain, in chain order.
    pub snapshots: Vec<BarSnapshots>,
    /// Steps recorded.
    steps: Vec<usize>,
    /// Each field's points with their elements and weights, found once (None: a dispersive
    /// delay line, filled by [`SnapshotRecorder::finish`]).
    samplers: Vec<Option<FieldSampler>>,
}

/// Where a snapshot reads one body, found once ([`Bar::stress_sampler`],
/// [`super::cylinder::PlasticCylinder::stress_sampler`]).
#[derive(Debug, Clone, PartialEq)]
enum FieldSampler {
    /// A bar stepped node by node or a plain delay line.
    Bar(crate::bar::StressSampler),
    /// A cylindrical specimen: (element, weight) per point.
    Cylinder(Vec<(usize, f64)>),
}

impl SnapshotRecorder {
    /// A recorder of the bars among `bodies` every `every` steps with points `spacing_m` apart.
    pub fn new(bodies: &[Body], every: usize, spacing_m: f64) -> SnapshotRecorder {
        let snapshots = bodies
            .iter()
            .filter_map(|b| {
                match b {
                    Body::Bar(bar) => Some(bar.node_position_m(bar.node_count() - 1)),
                    Body::Cylinder(c) => Some(c.initial_length_m()),
                    Body::Mass(_) => None,
                }
                .map(|len| (b.name(), len))
            })
            .map(|(name, len)| {
                let n = ((len / spacing_m).round() as usize).max(1);
                BarSnapshots {
                    name: name.to_string(),
                    x_m: (0..=n).map(|k| len * k as f64 / n as f64).collect(),
                    time_s: Vec::new(),
                    stress_pa: Vec::new(),
                }
            })
            .collect::<Vec<BarSnapshots>>();
        let samplers = bodies
            .iter()
            .filter(|b| !matches!(b, Body::Mass(_)))
            .zip(&snapshots)
            .map(|(b, s)| match b {
                Body::Bar(b) if b.transit_model().is_none() => {
                    Some(FieldSampler::Bar(b.stress_sampler(&s.x_m)))
                }
                Body::Cylinder(c) => Some(FieldSampler::Cylinder(c.stress_sampler(&s.x_m))),
                _ => None,
            })
            .collect();
        SnapshotRecorder {
            every,
            snapshots,
            steps: Vec::new(),
            samplers,
        }
    }

    /// Fills the fields of the dispersive delay lines among `bodies` (the same chain, after the
    /// run), left empty while it ran.
    pub fn finish(&mut self, bodies: &[Body]) {
        for (b, s) in bodies
            .iter()
            .filter(|b| !matches!(b, Body::Mass(_)))
            .zip(self.snapshots.iter_mut())
        {
            if let Some(rows) = b
                .as_bar()
                .and_then(|b| b.stress_history(&s.x_m, &self.steps))
            {
                s.stress_pa = rows;
            }
        }
    }
}

impl Recorder for SnapshotRecorder {
    fn record(&mut self, step: usize, time_s: f64, bodies: &[Body], _joints: &[JointState]) {
        if step == 0 || !step.is_multiple_of(self.every) {
            return;
        }
        self.steps.push(step);
        for ((b, s), sampler) in bodies
            .iter()
            .filter(|b| !matches!(b, Body::Mass(_)))
            .zip(self.snapshots.iter_mut())
            .zip(&self.samplers)
        {
            s.time_s.push(time_s);
            // The points' elements and weights were found once (`new`): the same values as
            // `stress_at` at each x.
            match (b, sampler) {
                (Body::Bar(b), Some(FieldSampler::Bar(p))) => s.stress_pa.push(b.sample_stress(p)),
                (Body::Cylinder(c), Some(FieldSampler::Cylinder(p))) => {
                    s.stress_pa.push(c.sample_stress(p))
                }
                _ => {}
            }
        }
    }
}

/// Reports the fraction of the run done to a callback, every 1 % of the steps; the callback
/// returns whether to go on (false stops the run: [`crate::Error::Cancelled`]).
pub struct Progress<'a> {
    steps: usize,
    every: usize,
    callback: &'a mut dyn FnMut(f64) -> bool,
    stop: bool,
}

impl<'a> Progress<'a> {
    /// Progress of a run of `steps` steps, reported to `callback`.
    pub fn new(steps: usize, callback: &'a mut dyn FnMut(f64) -> bool) -> Progress<'a> {
        Progress {
            steps: steps.max(1),
            every: (steps / 100).max(1),
            callback,
            stop: false,
        }
    }
}

impl Recorder for Progress<'_> {
    fn record(&mut self, step: usize, _time_s: f64, _bodies: &[Body], _joints: &[JointState]) {
        if step.is_multiple_of(self.every) || step == self.steps {
            self.stop = !(self.callback)(step as f64 / self.steps as f64);
        }
    }

    fn stop(&self) -> bool {
        self.stop
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_reports_rising_fractions_up_to_one() {
        let mut seen = Vec::new();
        let mut callback = |f: f64| {
            seen.push(f);
            true
        };
        let mut p = Progress::new(1000, &mut callback);
        for step in 0..=1000 {
            p.record(step, 0.0, &[], &[]);
        }
        assert_eq!(seen.len(), 101, "every 1 %");
        assert!(seen.windows(2).all(|w| w[1] > w[0]));
        assert_eq!((seen[0], *seen.last().unwrap()), (0.0, 1.0));
    }
}

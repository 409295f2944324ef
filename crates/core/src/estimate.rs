//! What a run will cost before it starts ([`RunEstimate`], [`Params::estimate`]): time steps,
//! the degrees of freedom advanced each step, the samples kept, the memory its data takes and the
//! size of its HDF5 output. Nothing is allocated to find out: the numbers come from the
//! validated scene alone. The input layer compares them with the machine's limits and refuses a
//! run that cannot finish (`shpb_input::resources`); a sweep can add them up over its points.
//!
//! The estimate is an *upper* one, by kind (8 bytes per stored number):
//!
//! * `quasistatic`, `constant-rate`: `points` samples of the contact series (2 or 5 columns).
//! * `collision`: the solver stops at the end of contact, which for the built-in materials,
//!   all three laws and every closing speed a scene accepts comes within
//!   [`COLLISION_ESTIMATE_CONTACT_TIMES`] (3) Hertz contact times t_c (measured: 0.95–1.5 t_c,
//!   `crates/cli/tests/estimate.rs`); the estimate takes 3 t_c (never more than the solver's
//!   time limit `max_time_s` = 100 t_c, [`crate::solver::COLLISION_TIME_LIMIT_CONTACT_TIMES`],
//!   after which it gives up with exit 3), `3 t_c/Δt` steps, every `output_every`-th kept in 5
//!   columns that grow by doubling (memory counted three times the data: capacity and the copy
//!   while a vector grows). Until issue 42 it took the time limit itself, 85–270 times the
//!   steps a run takes, and refused runs that fit.
//! * `force-driven`: `⌈end_time_s/Δt⌉` steps, every `output_every`-th kept (5 columns,
//!   allocated once).
//! * `chain`: `⌈end_time_s/Δt⌉` steps, every `output_every`-th kept: N − 1 contact forces and
//!   approaches, N velocities, the time, the first contact's 5 series and 3 end series.
//! * `pulse`, `shpb`: `⌈end_time_s/Δt⌉` steps of Δt = Δx/c0 over every node of the bars (the
//!   state of a node, with the Love rod's tridiagonal factors, is counted as 256 bytes); gauges,
//!   energies and the contact recorded at 10 MHz; x–t snapshots every `snapshot_interval_s` at
//!   5 mm spacing; the records digitised at the channels' rate and the reduction (counted as
//!   40 series of digitised length); the output adds the HDF5 file's metadata (256 kB). Against
//!   the files the shipped scenes write, the output estimate is 1.0–1.5 times their size
//!   (`results_trust::a_bar_run_s_output_estimate_bounds_its_file`).

use crate::apparatus::{Apparatus, PulseOptions};
use crate::scene::{Params, SceneParams};
use crate::solver::BodySpec;
use crate::specimen::Specimen;

/// Hertz contact times a `collision` run is estimated to last (module docs): an upper bound of
/// the measured durations (at most 1.5 t_c within the accepted closing speeds), with margin
/// for softer user materials.
pub const COLLISION_ESTIMATE_CONTACT_TIMES: f64 = 3.0;

/// Bytes of one stored number.
const F64: f64 = 8.0;

/// Bytes of the state of one bar node (u, v, free rate, tension, stiffness, mass, x and the
/// inverse diagonal: 8 numbers; the Love rod's factors and responses about as many again),
/// rounded up.
const BAR_NODE_BYTES: f64 = 256.0;

/// Memory of a series that grows by doubling, per byte of data: the spare capacity plus the
/// old buffer while it is copied.
const GROWTH: f64 = 3.0;

/// Series of digitised length the post-processing of a bar run holds at once (per-gauge time,
/// voltage and strain; the energy ledger resampled; the reduction's waves, forces and
/// displacements and its Fourier buffers), an upper count.
const DIGITISED_SERIES: f64 = 40.0;

/// Bytes of an HDF5 run file beyond its datasets' numbers (the file's metadata, ~100 groups and
/// datasets with their attributes, the provenance texts): measured ≈ 100 kB on the shipped
/// `shpb-cylinder-copper` scene, taken as 256 kB.
const HDF5_OVERHEAD_BYTES: f64 = 256e3;

/// The cost of one run, from its validated parameters alone (module docs). All counts are
/// `f64` so that absurd inputs (a time step of 1e-300 s) give a number instead of an overflow.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunEstimate {
    /// Time steps (grid points for `quasistatic` and `constant-rate`).
    pub steps: f64,
    /// Degrees of freedom advanced each step: bar nodes and rigid bodies (2 for the two-sphere
    /// scenes, 1 per point for the curve kinds).
    pub degrees_of_freedom: f64,
    /// Time samples kept of the longest series.
    pub samples_stored: f64,
    /// Peak memory of the run's data (solver state, recorded series, post-processing), bytes.
    pub memory_bytes: f64,
    /// Size of the datasets of its HDF5 output (`shpb run -o`), bytes.
    pub output_bytes: f64,
}

impl RunEstimate {
    /// Node updates of the whole run: steps × degrees of freedom (what the run time scales with).
    pub fn updates(&self) -> f64 {
        self.steps * self.degrees_of_freedom
    }
}

impl Params {
    /// What this run will cost (module docs); allocates nothing.
    pub fn estimate(&self) -> RunEstimate {
        match &self.params {
            SceneParams::Quasistatic { points, .. } => {
                let n = *points as f64;
                RunEstimate {
                    steps: n,
                    degrees_of_freedom: 1.0,
                    samples_stored: n,
                    memory_bytes: 2.0 * n * F64 * GROWTH,
                    output_bytes: 2.0 * n * F64,
                }
            }
            SceneParams::ConstantRate { points, .. } => {
                let n = *points as f64;
                RunEstimate {
                    steps: n,
                    degrees_of_freedom: 1.0,
                    samples_stored: n,
                    memory_bytes: 5.0 * n * F64,
                    output_bytes: 5.0 * n * F64,
                }
            }
            SceneParams::Collision(setup) => {
                let tc = setup.max_time_s / crate::solver::COLLISION_TIME_LIMIT_CONTACT_TIMES;
                let duration = (COLLISION_ESTIMATE_CONTACT_TIMES * tc).min(setup.max_time_s);
                let steps = (duration / setup.dt_s).ceil();
                let samples = (steps / setup.output_every as f64).floor() + 2.0;
                RunEstimate {
                    steps,
                    degrees_of_freedom: 2.0,
                    samples_stored: samples,
                    memory_bytes: 5.0 * samples * F64 * GROWTH,
                    output_bytes: 5.0 * samples * F64,
                }
            }
            SceneParams::ForceDriven {
                setup,
                measured_displacement_m,
            } => {
                let steps = (setup.end_time_s / setup.dt_s).ceil();
                let samples = (steps / setup.output_every as f64).floor() + 2.0;
                let drive = (2 * setup.drive.time_s.len()
                    + measured_displacement_m.as_ref().map_or(0, Vec::len))
                    as f64
                    * F64;
                RunEstimate {
                    steps,
                    degrees_of_freedom: 2.0,
                    samples_stored: samples,
                    memory_bytes: 5.0 * samples * F64 + drive,
                    output_bytes: 5.0 * samples * F64,
                }
            }
            SceneParams::Pulse {
                apparatus, options, ..
            } => bar_run(apparatus, options, self.specimen.as_ref()),
            SceneParams::Chain(setup) => {
                // Every output_every-th step of N − 1 forces and approaches, N velocities, the
                // time, the first contact's 5 series and 3 end series, allocated once.
                let steps = (setup.end_time_s / setup.dt_s).ceil();
                let samples = (steps / setup.output_every as f64).floor() + 2.0;
                let n = setup.chain.len() as f64;
                let columns = setup.numbers_per_sample() as f64;
                let bodies = n + 2.0;
                RunEstimate {
                    steps,
                    degrees_of_freedom: bodies,
                    samples_stored: samples,
                    memory_bytes: samples * F64 * columns + bodies * 64.0,
                    output_bytes: samples * F64 * columns,
                }
            }
        }
    }
}

/// The estimate of a `pulse` or `shpb` run of `apparatus` with `options` and `specimen` (module
/// docs), before its bars are built.
pub fn bar_run(
    apparatus: &Apparatus,
    options: &PulseOptions,
    specimen: Option<&Specimen>,
) -> RunEstimate {
    let chain = apparatus.pulse_chain(options, specimen);
    let dt = chain.dt_s;
    let steps = (options.end_time_s / dt).ceil();
    let mut nodes = 0.0;
    let mut snapshot_points = 0.0;
    let mut bars = 0.0;
    for body in &chain.bodies {
        match body {
            BodySpec::Bar(spec) => {
                let cells: usize = spec
                    .cells_for_time_step(dt)
                    .iter()
                    .fold(0usize, |a, &c| a.saturating_add(c));
                nodes += cells as f64 + 1.0;
                snapshot_points += (spec.length_m() / chain.snapshot_spacing_m)
                    .round()
                    .max(1.0)
                    + 1.0;
                bars += 1.0;
            }
            BodySpec::Mass(_) => nodes += 1.0,
            BodySpec::Cylinder(c) => nodes += c.cells_at(dt) as f64 + 1.0,
        }
    }
    // Recorders at every `record_every`-th step: gauges and time (allocated once), the energy
    // ledger (4 series, growing), the contact (5 series, allocated once).
    let recorded = (steps / chain.record_every as f64).floor() + 2.0;
    let gauges = chain.gauges.len() as f64;
    let spheres = specimen.is_some_and(|s| s.spheres().is_some());
    let contact = if spheres { 5.0 } else { 0.0 };
    let recorders = recorded * F64 * ((gauges + 1.0) + 4.0 * GROWTH + contact);
    // x–t snapshots: one row per bar per snapshot.
    let snapshots = chain
        .snapshot_every
        .map_or(0.0, |k| (steps / k as f64).floor());
    let snapshot_bytes = snapshots * (snapshot_points * F64 + bars * 32.0 + F64) * 1.25;
    // The records digitised at the channels' rate, their post-processing and the reduction.
    let rate = apparatus.gauges.max_sample_rate_hz();
    let digitised = (options.end_time_s * rate).floor();
    let post = digitised * F64 * (DIGITISED_SERIES + 3.0 * gauges);
    let reduction = if specimen.is_some() {
        // /reduction: 15 series at most of the window's length (shorter than the record).
        15.0 * digitised
    } else {
        0.0
    };
    let output = F64
        * (digitised * (1.0 + 2.0 * gauges + 6.0)
            + contact * recorded
            + snapshots * (snapshot_points + 1.0)
            + reduction)
        + HDF5_OVERHEAD_BYTES;
    RunEstimate {
        steps,
        degrees_of_freedom: nodes,
        samples_stored: recorded.max(digitised),
        memory_bytes: nodes * BAR_NODE_BYTES + recorders + snapshot_bytes + post,
        output_bytes: output,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{LawKind, LawSpec};
    use crate::fidelity::Fidelity;
    use crate::solver::{CollisionSetup, ForceDrivenSetup, ForceHistory};

    fn params(p: SceneParams) -> Params {
        Params {
            source: "test.toml".into(),
            text: String::new(),
            kind: "test".into(),
            specimen: Some(Specimen::Spheres(crate::specimen::SphereSpecimen::pair(
                &crate::fixtures::ss440c_pair(),
                LawSpec::of(LawKind::BurgoyneDaraio),
            ))),
            fidelity: Fidelity::Standard,
            params: p,
        }
    }

    #[test]
    fn a_collision_is_sized_by_three_contact_times() {
        let setup = CollisionSetup {
            velocity1_m_s: 5.0,
            velocity2_m_s: 0.0,
            dt_s: 1e-15,
            max_time_s: 2e-3,
            output_every: 1,
        };
        // max_time_s = 100 t_c: t_c = 20 µs, 3 t_c = 60 µs of 1 fs steps.
        let e = params(SceneParams::Collision(setup)).estimate();
        assert!((e.steps - 6e10).abs() <= 1.0);
        assert_eq!(e.samples_stored, e.steps + 2.0);
        assert_eq!(e.output_bytes, 40.0 * (e.steps + 2.0));
        assert_eq!(e.memory_bytes, 3.0 * e.output_bytes);
        assert_eq!(e.updates(), 2.0 * e.steps);
        // Keeping every 1000th step keeps a thousandth of the samples.
        let e = params(SceneParams::Collision(CollisionSetup {
            output_every: 1000,
            ..setup
        }))
        .estimate();
        assert_eq!(e.samples_stored, (e.steps / 1000.0).floor() + 2.0);
    }

    #[test]
    fn a_force_driven_run_is_sized_by_its_end_time() {
        let drive = ForceHistory {
            time_s: vec![0.0, 1e-4],
            force_n: vec![0.0, 1e3],
        };
        let e = params(SceneParams::ForceDriven {
            setup: ForceDrivenSetup {
                drive,
                medium_impedance_kg_s: 1e4,
                dt_s: 1e-9,
                end_time_s: 1e-4,
                output_every: 10,
            },
            measured_displacement_m: None,
        })
        .estimate();
        assert_eq!(e.steps, 1e5);
        assert_eq!(e.samples_stored, 1e4 + 2.0);
        assert_eq!(e.output_bytes, 40.0 * (1e4 + 2.0));
    }

    #[test]
    fn absurd_time_steps_give_numbers_not_overflows() {
        let e = params(SceneParams::Collision(CollisionSetup {
            velocity1_m_s: 5.0,
            velocity2_m_s: 0.0,
            dt_s: 1e-300,
            max_time_s: 1e-3,
            output_every: 1,
        }))
        .estimate();
        assert!(e.steps > 1e290 && e.memory_bytes.is_finite());
    }
}

//! `shpb fit` (issue 44; docs/physics.md §12): the constants a record implies, with their
//! uncertainty. The free scene keys ([`spec::Free`]) are fitted by least squares (argmin's
//! Nelder–Mead, [`crate::calibrate::optimise`]) to the records' series ([`observe`]); a noise
//! model is then estimated from the best fit's residuals (each series' standard deviation and
//! correlation length, [`noise`]), and the posterior is sampled by the affine-invariant ensemble
//! sampler ([`mcmc`]) with the forward runs of each step in parallel. Every forward run is a whole
//! run of the scene with the values set, without the outputs nobody reads (the bars' x–t
//! snapshots).

pub mod mcmc;
pub mod noise;
pub mod observe;
pub mod spec;

use crate::api::input_err;
use observe::{Observables, Series};
use rayon::prelude::*;
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use shpb_output::fit::{FitParameter, FitRecord, FitReport};
use spec::{Free, Prior, Reach, Residual};
use std::path::{Path, PathBuf};

/// A fit's question: the scene, its free keys and priors, and the series of its records.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The scene file.
    pub scene: PathBuf,
    /// The free keys, in order.
    pub free: Vec<Free>,
    /// Normal priors on some of them.
    pub priors: Vec<Prior>,
    /// What the residual compares.
    pub residual: Residual,
    /// The records' series.
    pub series: Vec<Series>,
    /// The scene is force-driven (its force is the drive, not a result).
    pub force_driven: bool,
    /// How the gauge records were reduced: the model's virtual gauges are reduced alike
    /// (None: no gauge record; the run's own reduction or contact series is compared).
    pub reducer: Option<Reducer>,
    /// For each series, the gauge record whose incident wave drives its model run (a scene with
    /// `[incident_record]` fitted to raw gauge records: each record's model is driven by that
    /// record's own incident wave, docs/physics.md §6.10); None: the scene's own drive. Series
    /// of the same drive share one run.
    pub drives: Vec<Option<PathBuf>>,
}

/// The reduction a fit's gauge records went through, applied alike to each run's virtual
/// gauges: the same options, bars and specimen (like is compared with like).
#[derive(Debug, Clone)]
pub struct Reducer {
    /// The reduction's options (`shpb reduce`'s defaults with the record's specimen).
    pub options: shpb_core::reduce::ReductionOptions,
    /// The bars and gauges.
    pub setup: shpb_core::reduce::ReductionSetup,
    /// The specimen reduced for.
    pub specimen: shpb_core::reduce::ReducedSpecimen,
}

impl Reducer {
    /// The reduction of a run's virtual gauges (their digitised voltages through the bridges).
    pub fn reduce(
        &self,
        out: &RunOutput,
        apparatus: &shpb_core::apparatus::Apparatus,
    ) -> Option<Observables> {
        let input = crate::api::run_input(out, apparatus)?;
        let r =
            shpb_core::reduce::reduce_separated(&input, None, &self.setup, &self.options, "model")
                .ok()?;
        let cylinder = self.specimen.reduce(&r, &self.setup).ok()?;
        Some(Observables::of_reduction(&r, cylinder.as_ref()))
    }
}

/// The residual a scene is fitted on unless `--residual` says: a force-driven or contact scene's
/// force–approach, a cylinder's stress–strain, a sphere bar test's force–time.
pub fn default_residual(params: &Params) -> Residual {
    let cylinder = params
        .specimen
        .as_ref()
        .and_then(shpb_core::specimen::Specimen::cylinder)
        .is_some();
    match &params.params {
        SceneParams::Pulse { .. } if cylinder => Residual::StressStrain,
        SceneParams::Pulse { .. } => Residual::ForceTime,
        _ => Residual::ForceApproach,
    }
}

/// The scene's own record: a force-driven scene whose CSV carries the measured approach, counted
/// from its first sample (the model's approach starts at 0 under the drive's zero force; the
/// Fig. 4 records start at an offset δ(0) of 5–58 µm, removed alike by `fig4-force-driven`,
/// docs/physics.md §5).
pub fn scene_record(params: &Params) -> Option<Observables> {
    match &params.params {
        SceneParams::ForceDriven {
            setup,
            measured_displacement_m: Some(d),
        } => Some(Observables {
            time_s: setup.drive.time_s.clone(),
            force_n: Some(setup.drive.force_n.clone()),
            approach_m: Some(d.iter().map(|v| v - d[0]).collect()),
            force_is_drive: true,
            ..Observables::default()
        }),
        _ => None,
    }
}

/// The set-up file or name a bar scene's `bars` key gives, resolved against the scene's folder.
fn scene_bars(scene: &Path) -> Result<PathBuf> {
    let text = shpb_input::csv::read_text(scene)?;
    let table: toml::Table = text.parse().map_err(|e| {
        input_err(
            "SCENE",
            format!("{}: {e}", scene.display()),
            "a scene .toml",
        )
    })?;
    let Some(bars) = table.get("bars").and_then(toml::Value::as_str) else {
        return Err(input_err(
            "--record",
            format!(
                "{} names no `bars`: a gauge record needs the scene's set-up to be reduced",
                scene.display()
            ),
            "a bar-test scene (kind = \"shpb\" with bars = …), or a reduced curve as CSV",
        ));
    };
    let file = scene.parent().unwrap_or(Path::new(".")).join(bars);
    Ok(if file.is_file() {
        file
    } else {
        PathBuf::from(bars)
    })
}

/// Whether a scene file has an `[incident_record]` table (a measured incident wave drives it).
fn scene_has_incident_record(scene: &Path) -> Result<bool> {
    let text = shpb_input::csv::read_text(scene)?;
    Ok(text
        .parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("incident_record")))
}

/// Reads one `--record`: a CSV with `time_s` and reduced quantities (a reduced curve), else a raw
/// gauge record or run file reduced through the scene's set-up (`shpb reduce`'s defaults, the
/// scene's cylinder as specimen).
pub fn read_record(
    scene: &Path,
    params: &Params,
    record: &Path,
) -> Result<(Observables, Option<Reducer>)> {
    let is_csv = record
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if is_csv {
        let table = shpb_input::csv::CsvTable::read(record)?;
        let o = Observables::of_csv(&table);
        let any = o.force_n.is_some()
            || o.approach_m.is_some()
            || o.stress_pa.is_some()
            || o.reflected_strain.is_some();
        if !o.time_s.is_empty() && any {
            return Ok((o, None));
        }
    }
    let cylinder = params
        .specimen
        .as_ref()
        .and_then(shpb_core::specimen::Specimen::cylinder)
        .map(|c| shpb_core::reduce_cylinder::CylinderGeometry {
            length_m: c.length_m,
            diameter_m: c.diameter_m,
        });
    let bars = scene_bars(scene)?;
    // Like is compared with like: the model's gauges are reduced as the record is, so the
    // dispersion correction follows the model's bars. Elementary bars (the fast and standard
    // presets) carry no dispersion, which a correction would wrongly take out of the model;
    // the record is then reduced without it too, and what dispersion a real record has is the
    // model's misfit (counted in the noise, §12.3). Dispersive bars: `shpb reduce`'s default.
    let dispersive = match &params.params {
        SceneParams::Pulse { options, .. } => {
            options.dispersion != shpb_core::bar::Dispersion::None
        }
        _ => true,
    };
    let choices = crate::api::RecordOptions {
        cylinder,
        dispersion: if dispersive {
            shpb_core::reduce::DispersionCorrection::default()
        } else {
            shpb_core::reduce::DispersionCorrection::None
        },
        ..crate::api::RecordOptions::default()
    };
    // A run file carries its own set-up: given no --bars, as `shpb reduce` reads it.
    let is_run_file = shpb_output::reduction::is_hdf5(record)?;
    let reduced =
        crate::api::reduce_record_with(record, (!is_run_file).then_some(bars.as_path()), &choices)?;
    let mut options = crate::api::reduction_options(&choices)?;
    options.specimen_radii_m = reduced.specimen.radii_m();
    options.tension = reduced.cylinder.as_ref().is_some_and(|c| c.tension);
    let reducer = Reducer {
        options,
        setup: shpb_core::reduce::ReductionSetup::from_apparatus(&reduced.apparatus)?,
        specimen: reduced.specimen,
    };
    Ok((
        Observables::of_reduction(&reduced.reduction, reduced.cylinder.as_ref()),
        Some(reducer),
    ))
}

impl Problem {
    /// Builds the question: reads the scene, checks that every free key reaches it at both
    /// bounds, reads the records (none: the scene's own) into the series of `residual` (None: the
    /// scene's [`default_residual`]).
    pub fn new(
        scene: &Path,
        free: Vec<Free>,
        priors: Vec<Prior>,
        residual: Option<Residual>,
        records: &[PathBuf],
    ) -> Result<Problem> {
        crate::sweep::require_scene(scene)?;
        if free.is_empty() {
            return Err(input_err(
                "--free",
                "no free key",
                "one --free KEY=MIN:MAX or more",
            ));
        }
        for (i, f) in free.iter().enumerate() {
            if free[..i].iter().any(|g| g.key == f.key) {
                return Err(input_err(
                    "--free",
                    format!("`{}` is given twice", f.key),
                    "each key once",
                ));
            }
        }
        let params = Params::from_file(scene)?;
        // Each bound is a valid scene (the scene's own checks name the key and its range).
        for f in &free {
            for x in [f.min, f.max] {
                if let Some(o) = f.value(x) {
                    Params::from_file_overridden(scene, &[o]).map_err(|e| match e {
                        Error::Input {
                            file,
                            problem,
                            allowed,
                            ..
                        } => input_err(
                            &format!("--free {}", f.key),
                            format!(
                                "{} refuses the bound {x}{}: {problem}",
                                file,
                                if f.unit == "1" {
                                    String::new()
                                } else {
                                    format!(" {}", f.unit)
                                }
                            ),
                            allowed,
                        ),
                        other => other,
                    })?;
                }
            }
        }
        let residual = residual.unwrap_or_else(|| default_residual(&params));
        let force_driven = matches!(params.params, SceneParams::ForceDriven { .. });
        let mut series = Vec::new();
        if records.is_empty() {
            let own = scene_record(&params).ok_or_else(|| {
                input_err(
                    "--record",
                    format!("{} carries no record of its own", scene.display()),
                    "one --record FILE or more (a raw gauge record, a run file, a reduced curve as CSV), or a force-driven scene whose CSV has displacement_m",
                )
            })?;
            series.extend(observe::series_of(
                "the scene's own record",
                &own,
                residual,
                force_driven,
            )?);
        }
        let mut drives = vec![None; series.len()];
        let mut reducer = None;
        let record_driven = scene_has_incident_record(scene)?;
        for r in records {
            let (o, red) = read_record(scene, &params, r)?;
            // A raw gauge record (not a reduced CSV, not a run file) drives its own model.
            let drive = (record_driven && red.is_some() && !shpb_output::reduction::is_hdf5(r)?)
                .then(|| std::path::absolute(r).unwrap_or_else(|_| r.clone()));
            reducer = reducer.or(red);
            let name = r.display().to_string();
            let s = observe::series_of(&name, &o, residual, force_driven)?;
            drives.extend(std::iter::repeat_n(drive, s.len()));
            series.extend(s);
        }
        Ok(Problem {
            scene: scene.to_path_buf(),
            free,
            priors,
            residual,
            series,
            force_driven,
            reducer,
            drives,
        })
    }

    /// The scene with the values of `theta` set, and the time shift of the model against the
    /// records (None when the scene refuses the values).
    pub fn params_at(&self, theta: &[f64]) -> Option<(Params, f64)> {
        let overrides: Vec<_> = self
            .free
            .iter()
            .zip(theta)
            .filter_map(|(f, &x)| f.value(x))
            .collect();
        let shift = self
            .free
            .iter()
            .zip(theta)
            .find(|(f, _)| f.reach == Reach::TimeShift)
            .map_or(0.0, |(_, &x)| x);
        let params = Params::from_file_overridden(&self.scene, &overrides).ok()?;
        Some((params, shift))
    }

    /// The run at `theta` as a fit makes it (with the set-up it ran with): without the bars' x–t snapshots (nobody reads them)
    /// and, with `noise_seed` None, without the digitisers' noise and quantisation (the model is
    /// the record's expectation; the noise model is the fit's own, [`noise`]); with `Some(seed)` every channel's noise drawn from that seed (a
    /// simulated record). Also the time shift.
    pub fn run_at(
        &self,
        theta: &[f64],
        noise_seed: Option<u64>,
    ) -> Option<(RunOutput, Params, f64)> {
        self.run_driven(theta, noise_seed, None)
    }

    /// [`Problem::run_at`] with the scene's `[incident_record]` file replaced by `drive` (a
    /// gauge record, [`Problem::drives`]; None: the scene's own).
    pub fn run_driven(
        &self,
        theta: &[f64],
        noise_seed: Option<u64>,
        drive: Option<&Path>,
    ) -> Option<(RunOutput, Params, f64)> {
        let (mut params, shift) = match drive {
            None => self.params_at(theta)?,
            Some(file) => {
                let (_, shift) = self.params_at(theta)?;
                let mut overrides: Vec<_> = self
                    .free
                    .iter()
                    .zip(theta)
                    .filter_map(|(f, &x)| f.value(x))
                    .collect();
                overrides.push((
                    "incident_record.file".to_string(),
                    toml::Value::String(file.display().to_string()),
                ));
                (
                    Params::from_file_overridden(&self.scene, &overrides).ok()?,
                    shift,
                )
            }
        };
        if let SceneParams::Pulse { apparatus, .. } = &mut params.params {
            for (i, ch) in apparatus.gauges.channels.iter_mut().enumerate() {
                match noise_seed {
                    // The model of a record is its expectation: no noise, and no quantisation
                    // (the noise dithers a record's codes; a quantised model would be a
                    // staircase in θ, rough at the code step, docs/physics.md §12.3).
                    None => {
                        ch.digitiser.noise_rms_v = 0.0;
                        ch.digitiser.bits = 32;
                    }
                    Some(seed) => ch.digitiser.seed = seed.wrapping_mul(31).wrapping_add(i as u64),
                }
            }
        }
        let params = params.summary_only();
        Some((params.run().ok()?, params, shift))
    }

    /// What the records are compared with in a run: its virtual gauges reduced as the records
    /// were ([`Reducer`]), else its own reduction or contact series.
    pub fn observe(&self, out: &RunOutput, params: &Params) -> Option<Observables> {
        match (&self.reducer, &params.params) {
            (Some(r), SceneParams::Pulse { apparatus, .. }) => r.reduce(out, apparatus),
            _ => Some(Observables::of_run(out, self.force_driven)),
        }
    }

    /// The model's values on every series at `theta` ([`Problem::run_at`] without noise; None
    /// when the scene refuses the values or the run fails: outside the posterior's support).
    pub fn model(&self, theta: &[f64]) -> Option<Vec<Vec<f64>>> {
        self.model_with(theta, None)
    }

    /// [`Problem::model`] with the digitisers' noise drawn from `noise_seed` (None: without it).
    pub fn model_with(&self, theta: &[f64], noise_seed: Option<u64>) -> Option<Vec<Vec<f64>>> {
        let mut values: Vec<Option<Vec<f64>>> = vec![None; self.series.len()];
        for i in 0..self.series.len() {
            if values[i].is_some() {
                continue;
            }
            let drive = self.drive_of(i);
            let (m, shift) = self.observed(theta, noise_seed, drive.as_deref())?;
            for (j, s) in self.series.iter().enumerate() {
                if self.drive_of(j) == drive {
                    values[j] = Some(s.model(&m, shift)?);
                }
            }
        }
        values.into_iter().collect()
    }

    /// The drive of series `j` ([`Problem::drives`]; None, also without an entry: the scene's own).
    pub fn drive_of(&self, j: usize) -> Option<PathBuf> {
        self.drives.get(j).cloned().flatten()
    }

    /// The run at `theta` with `noise_seed` and `drive` ([`Problem::run_driven`]) as the records
    /// are compared with it ([`Problem::observe`]), with its time shift.
    pub fn observed(
        &self,
        theta: &[f64],
        noise_seed: Option<u64>,
        drive: Option<&Path>,
    ) -> Option<(Observables, f64)> {
        let (out, params, shift) = self.run_driven(theta, noise_seed, drive)?;
        Some((self.observe(&out, &params)?, shift))
    }

    /// Whether `theta` lies inside every bound.
    pub fn inside(&self, theta: &[f64]) -> bool {
        self.free
            .iter()
            .zip(theta)
            .all(|(f, &x)| x >= f.min && x <= f.max)
    }

    /// ln of the priors at `theta` (uniform within the bounds, times the normal priors; −∞
    /// outside), up to a constant.
    pub fn log_prior(&self, theta: &[f64]) -> f64 {
        if !self.inside(theta) {
            return f64::NEG_INFINITY;
        }
        self.priors
            .iter()
            .map(|p| {
                let i = self
                    .free
                    .iter()
                    .position(|f| f.key == p.key)
                    .expect("a prior names a free key");
                -0.5 * ((theta[i] - p.mean) / p.sd).powi(2)
            })
            .sum()
    }
}

/// The sampler's and the fit's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Walkers of the ensemble (even, at least twice the free keys; 0: the default
    /// max(16, 4 × keys)).
    pub walkers: usize,
    /// Sampler steps.
    pub steps: usize,
    /// Steps dropped as burn-in (None: a quarter of the steps).
    pub burn_in: Option<usize>,
    /// Seed of the sampler and of the predictive band's noise draws.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Posterior samples run again for the posterior-predictive band.
    pub predictive_draws: usize,
    /// Most forward runs of the least-squares search.
    pub max_least_squares_runs: usize,
    /// Draws of the set-up's digitiser noise propagated through the reduction at the best fit
    /// (gauge records only; 0: none), for the noise's whole-record modes ([`noise`]).
    pub noise_draws: usize,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            walkers: 0,
            steps: 200,
            burn_in: None,
            seed: 1,
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            predictive_draws: 48,
            max_least_squares_runs: 0,
            noise_draws: 64,
        }
    }
}

/// Where a fit is, for a progress line: stage name, done, total.
pub type Progress<'a> = &'a mut dyn FnMut(&str, usize, usize);

/// The model values at many points, in parallel on `pool`.
fn models(
    problem: &Problem,
    pool: &rayon::ThreadPool,
    points: &[Vec<f64>],
) -> Vec<Option<Vec<Vec<f64>>>> {
    pool.install(|| points.par_iter().map(|p| problem.model(p)).collect())
}

/// Relative step of each free value (of its range) for the model's directions of the noise's
/// calibration: large enough that the reduced model's roughness in θ (its sample-grid steps)
/// does not dominate the change.
const CALIBRATION_STEP: f64 = 0.05;

/// The noise model's calibration for gauge records ([`noise::calibration`], docs/physics.md
/// §12.3): `settings.noise_draws` simulated records at the best fit `best` (the set-up's
/// digitiser noise, seeds from the fit's seed apart from any record's, reduced and cut like the
/// records), each one's residual against the noise-free model at its own points, and the
/// model's directions there (a step of [`CALIBRATION_STEP`] of each free value's range). One
/// factor per series (None: no gauge records, no digitiser noise in the set-up, or a run
/// failed), and the runs made.
fn calibrate_noise(
    problem: &Problem,
    settings: &Settings,
    pool: &rayon::ThreadPool,
    best: &[f64],
    progress: Progress,
) -> (Vec<Option<f64>>, usize) {
    let none = (vec![None; problem.series.len()], 0);
    if problem.reducer.is_none() || settings.noise_draws == 0 {
        return none;
    }
    let noisy = problem
        .params_at(best)
        .is_some_and(|(p, _)| match &p.params {
            SceneParams::Pulse { apparatus, .. } => apparatus
                .gauges
                .channels
                .iter()
                .any(|c| c.digitiser.noise_rms_v > 0.0),
            _ => false,
        });
    if !noisy {
        return none;
    }
    progress("noise model", 0, settings.noise_draws);
    // The points the model's directions are taken at: the best fit and one step of each value.
    let mut points = vec![best.to_vec()];
    for (i, f) in problem.free.iter().enumerate() {
        let step = CALIBRATION_STEP * (f.max - f.min);
        let mut p = best.to_vec();
        p[i] = if p[i] + step <= f.max {
            p[i] + step
        } else {
            p[i] - step
        };
        points.push(p);
    }
    let mut drives: Vec<Option<PathBuf>> = Vec::new();
    for j in 0..problem.series.len() {
        if !drives.contains(&problem.drive_of(j)) {
            drives.push(problem.drive_of(j));
        }
    }
    let base = settings.seed ^ 0x6e6f_6973_6521_0000;
    let mut factors = vec![None; problem.series.len()];
    let mut runs = 0;
    for drive in &drives {
        let clean: Vec<Option<(Observables, f64)>> = pool.install(|| {
            points
                .par_iter()
                .map(|p| problem.observed(p, None, drive.as_deref()))
                .collect()
        });
        let simulated: Vec<Option<(Observables, f64)>> = pool.install(|| {
            (0..settings.noise_draws as u64)
                .into_par_iter()
                .map(|k| problem.observed(best, Some(base.wrapping_add(k)), drive.as_deref()))
                .collect()
        });
        runs += points.len() + simulated.len();
        let Some(clean) = clean.into_iter().collect::<Option<Vec<_>>>() else {
            continue;
        };
        for (j, s) in problem.series.iter().enumerate() {
            if problem.drive_of(j) != *drive {
                continue;
            }
            let records: Option<Vec<noise::SimulatedRecord>> = simulated
                .iter()
                .map(|o| {
                    let (obs, _) = o.as_ref()?;
                    let sim =
                        observe::series_of(&s.record, obs, problem.residual, problem.force_driven)
                            .ok()?
                            .into_iter()
                            .find(|x| x.quantity == s.quantity)?;
                    let at: Vec<Vec<f64>> = clean
                        .iter()
                        .map(|(o, shift)| sim.model(o, *shift))
                        .collect::<Option<_>>()?;
                    let r = sim.y.iter().zip(&at[0]).map(|(y, m)| y - m).collect();
                    let dirs = at[1..]
                        .iter()
                        .map(|m| m.iter().zip(&at[0]).map(|(a, b)| a - b).collect())
                        .collect();
                    Some((r, dirs))
                })
                .collect();
            factors[j] = records.and_then(|r| noise::calibration(&r, problem.free.len()));
        }
    }
    (factors, runs)
}

/// The least-squares cost of model values `m` against the series, each series weighted by
/// 1/(its scale² × its points) so that series of different units and lengths weigh alike.
fn cost(problem: &Problem, scales: &[f64], m: &Option<Vec<Vec<f64>>>) -> f64 {
    let Some(m) = m else { return f64::INFINITY };
    problem
        .series
        .iter()
        .zip(m)
        .zip(scales)
        .map(|((s, v), sc)| {
            s.y.iter()
                .zip(v)
                .map(|(y, v)| ((y - v) / sc).powi(2))
                .sum::<f64>()
                / s.y.len() as f64
        })
        .sum()
}

/// Runs the whole fit: least squares, noise model, posterior samples, posterior-predictive
/// bands. `keep_going` is asked between steps (Ctrl-C): once false the sampler stops and the
/// report holds the steps done (with a warning).
pub fn fit(
    problem: &Problem,
    settings: &Settings,
    command_line: &str,
    progress: Progress,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<FitReport> {
    fit_resumable(
        problem,
        settings,
        command_line,
        progress,
        keep_going,
        None,
        &mut |_| Ok(()),
    )
}

/// The checkpoint of a fit writing `output`: `<output>.partial.h5` (a fit file of the steps so
/// far, without the predictive bands).
pub fn checkpoint_path(output: &Path) -> PathBuf {
    let mut name = output.as_os_str().to_owned();
    name.push(".partial.h5");
    PathBuf::from(name)
}

/// Checks a checkpoint against this fit (the same scene, residual, keys, bounds, priors,
/// walkers and records): a resumed chain continues only the fit it was made for.
pub fn check_resume(
    problem: &Problem,
    settings: &Settings,
    r: &FitReport,
    file: &Path,
) -> Result<()> {
    let walkers = resolved_walkers(problem, settings);
    let same = r.scene == problem.scene.display().to_string()
        && r.residual == problem.residual.name()
        && r.walkers == walkers
        && r.parameters.len() == problem.free.len()
        && r.parameters.iter().zip(&problem.free).all(|(p, f)| {
            p.key == f.key
                && p.min == f.min
                && p.max == f.max
                && p.prior_normal
                    == problem
                        .priors
                        .iter()
                        .find(|q| q.key == f.key)
                        .map(|q| (q.mean, q.sd))
        })
        && r.records.len() == problem.series.len()
        && r.records
            .iter()
            .zip(&problem.series)
            .all(|(a, b)| a.name == b.record && a.y == b.y);
    if same && r.steps <= settings.steps {
        return Ok(());
    }
    Err(Error::Input {
        file: file.display().to_string(),
        key: "--resume".into(),
        problem: format!(
            "the checkpoint is of another fit (scene {}, residual {}, {} walkers, keys {}, {} steps done)",
            r.scene,
            r.residual,
            r.walkers,
            r.parameters.iter().map(|p| p.key.as_str()).collect::<Vec<_>>().join(", "),
            r.steps
        ),
        allowed: "the command line that wrote it, with --steps at least the steps done (or remove the checkpoint)".into(),
    })
}

fn resolved_walkers(problem: &Problem, settings: &Settings) -> usize {
    match settings.walkers {
        0 => (4 * problem.free.len()).max(16),
        w => w,
    }
}

/// The sampler's chain stored in a fit report (the accepted moves counted as the steps where a
/// walker moved: a rejected move keeps its position exactly).
fn chain_of(r: &FitReport) -> mcmc::Chain {
    let (dim, walkers) = (r.parameters.len(), r.walkers);
    let accepted = chain_moves(&r.chain, dim, walkers, r.steps);
    mcmc::Chain {
        dim,
        walkers,
        positions: r.chain.clone(),
        log_prob: r.log_prob.clone(),
        accepted,
        steps_done: r.steps,
    }
}

/// The fraction of accepted moves, counted as the steps where a walker moved from step 1 on (a
/// rejected move keeps its position exactly; the move into step 0 is not stored), so that a
/// resumed chain reports what the uninterrupted one does.
fn moved_fraction(chain: &mcmc::Chain) -> f64 {
    let moves: u64 = chain_moves(&chain.positions, chain.dim, chain.walkers, chain.steps_done)
        .iter()
        .sum();
    moves as f64 / (chain.walkers * chain.steps_done.saturating_sub(1)).max(1) as f64
}

/// Per walker, the steps (from step 1 on) at which it moved.
fn chain_moves(positions: &[f64], dim: usize, walkers: usize, steps: usize) -> Vec<u64> {
    let mut accepted = vec![0u64; walkers];
    for step in 1..steps {
        for (w, a) in accepted.iter_mut().enumerate() {
            let at = |s: usize| &positions[(s * walkers + w) * dim..(s * walkers + w + 1) * dim];
            if at(step) != at(step - 1) {
                *a += 1;
            }
        }
    }
    accepted
}

/// The residual vector whose squared norm is [`cost`]: each series' (y − m)/(scale √N).
fn weighted_residuals(problem: &Problem, scales: &[f64], m: &[Vec<f64>]) -> Vec<f64> {
    problem
        .series
        .iter()
        .zip(m)
        .zip(scales)
        .flat_map(|((s, v), sc)| {
            let w = 1.0 / (sc * (s.y.len() as f64).sqrt());
            s.y.iter().zip(v).map(move |(y, v)| (y - v) * w)
        })
        .collect()
}

/// Levenberg–Marquardt (Marquardt 1963, SIAM J. Appl. Math. 11, 431: the damped Gauss–Newton
/// step (JᵀJ + λ diag JᵀJ) δ = −Jᵀr, λ divided by 3 on success and multiplied by 4 on
/// failure) on the unit cube, the Jacobian by forward differences of 10⁻³ (away from the
/// nearer bound), its d runs in parallel on `pool`; at most `iterations` Jacobians. Returns the
/// best point, its cost |r|² and the runs made. A failed run counts as an infinite cost.
fn levenberg_marquardt(
    residuals: &(dyn Fn(&[f64]) -> Option<Vec<f64>> + Sync),
    pool: &rayon::ThreadPool,
    u0: &[f64],
    c0: f64,
    iterations: usize,
    progress: &mut dyn FnMut(usize),
) -> (Vec<f64>, f64, usize) {
    let d = u0.len();
    let norm2 = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut runs = 1;
    let Some(mut r) = residuals(u0) else {
        return (u0.to_vec(), f64::INFINITY, runs);
    };
    let (mut u, mut c) = (u0.to_vec(), norm2(&r).min(c0));
    let mut lambda = 1e-3;
    const H: f64 = 1e-3;
    for _ in 0..iterations {
        progress(runs);
        let columns: Vec<Option<(f64, Vec<f64>)>> = pool.install(|| {
            (0..d)
                .into_par_iter()
                .map(|k| {
                    let h = if u[k] + H <= 1.0 { H } else { -H };
                    let mut v = u.clone();
                    v[k] += h;
                    residuals(&v).map(|rk| (h, rk))
                })
                .collect()
        });
        runs += d;
        let Some(columns) = columns.into_iter().collect::<Option<Vec<_>>>() else {
            break;
        };
        let n = r.len();
        let j = nalgebra::DMatrix::from_fn(n, d, |i, k| (columns[k].1[i] - r[i]) / columns[k].0);
        let rv = nalgebra::DVector::from_column_slice(&r);
        let a = j.transpose() * &j;
        let g = j.transpose() * rv;
        let mut improved = false;
        for _ in 0..8 {
            let mut m = a.clone();
            for k in 0..d {
                m[(k, k)] += lambda * a[(k, k)].max(1e-12);
            }
            let Some(step) = m.lu().solve(&(-&g)) else {
                lambda *= 4.0;
                continue;
            };
            let trial: Vec<f64> = u
                .iter()
                .zip(step.iter())
                .map(|(x, s)| (x + s).clamp(0.0, 1.0))
                .collect();
            runs += 1;
            match residuals(&trial) {
                Some(rt) if norm2(&rt) < c => {
                    let gain = c - norm2(&rt);
                    (u, r, c) = (trial, rt.clone(), norm2(&rt));
                    lambda = (lambda / 3.0).max(1e-9);
                    improved = gain > 1e-10 * c;
                    break;
                }
                _ => lambda *= 4.0,
            }
        }
        if !improved {
            break;
        }
    }
    (u, c, runs)
}

/// The least-squares best fit: the point, its cost, the model's series there, the runs made.
type BestFit = (Vec<f64>, f64, Vec<Vec<f64>>, usize);

/// The least-squares best fit on the unit cube of the bounds: the best of a start design (the
/// centre and 4d points of a seeded Latin hypercube), then argmin's Nelder–Mead from it.
/// Returns the best point, its cost, the model there and the runs made.
fn least_squares(
    problem: &Problem,
    settings: &Settings,
    pool: &rayon::ThreadPool,
    scales: &[f64],
    progress: Progress,
) -> Result<BestFit> {
    let d = problem.free.len();
    let to_x = |u: &[f64]| -> Vec<f64> {
        problem
            .free
            .iter()
            .zip(u)
            .map(|(f, &u)| f.min + u.clamp(0.0, 1.0) * (f.max - f.min))
            .collect()
    };
    let mut starts = vec![vec![0.5; d]];
    starts.extend(crate::uq::latin_hypercube(
        4 * d,
        d,
        &mut crate::uq::Rng::new(settings.seed),
    ));
    let start_x: Vec<Vec<f64>> = starts.iter().map(|u| to_x(u)).collect();
    progress("least squares", 0, starts.len());
    let start_costs: Vec<f64> = models(problem, pool, &start_x)
        .iter()
        .map(|m| cost(problem, scales, m))
        .collect();
    let mut runs = starts.len();
    let (i0, c0) =
        start_costs.iter().enumerate().fold(
            (0, f64::INFINITY),
            |b, (i, &c)| if c < b.1 { (i, c) } else { b },
        );
    let failed = |what: &str| Error::Input {
        file: problem.scene.display().to_string(),
        key: "--free".into(),
        problem: what.into(),
        allowed: "bounds within which the scene runs".into(),
    };
    if !c0.is_finite() {
        return Err(failed("no run of the start design succeeded"));
    }
    let budget = match settings.max_least_squares_runs {
        0 => 100 * d + 60,
        n => n,
    };
    // Levenberg–Marquardt on the weighted residuals from the best start (it follows the long
    // curved valleys correlated constants make, A, B and n of Johnson–Cook, where a simplex
    // stalls), then Nelder–Mead restarted from its result with a fresh simplex (half the steps
    // each time) while a restart still lowers the cost by more than 1e-6 of it.
    let residuals = |u: &[f64]| -> Option<Vec<f64>> {
        let m = problem.model(&to_x(u))?;
        Some(weighted_residuals(problem, scales, &m))
    };
    let (lm_u, lm_cost, lm_runs) =
        levenberg_marquardt(&residuals, pool, &starts[i0], c0, 25, &mut |k| {
            progress("least squares", k, budget)
        });
    runs += lm_runs;
    let evals = std::cell::Cell::new(0usize);
    let mut objective = |u: &[f64]| {
        evals.set(evals.get() + 1);
        progress("least squares", evals.get(), budget);
        let outside: f64 = u.iter().map(|v| (v.clamp(0.0, 1.0) - v).abs()).sum();
        let m = problem.model(&to_x(u));
        cost(problem, scales, &m) + 1e3 * outside
    };
    let (mut u_best, mut best_cost) = if lm_cost < c0 {
        (lm_u, lm_cost)
    } else {
        (starts[i0].clone(), c0)
    };
    let mut step = 0.1;
    for _ in 0..4 {
        let left = budget.saturating_sub(evals.get());
        if left <= d + 1 {
            break;
        }
        let (u, c, used) = crate::calibrate::optimise::nelder_mead(
            &mut objective,
            &u_best,
            &vec![step; d],
            left,
            1e-10 * c0.max(1e-300),
        );
        runs += used;
        let gained = best_cost - c;
        if c < best_cost {
            (u_best, best_cost) = (u, c);
        }
        if gained <= 1e-6 * best_cost {
            break;
        }
        step *= 0.5;
    }
    runs += 1;
    let best = to_x(&u_best);
    let best_model = problem
        .model(&best)
        .ok_or_else(|| failed("the best fit's run failed"))?;
    Ok((best, best_cost, best_model, runs))
}

/// [`fit`] that continues the chain of `resume` (a checkpoint, [`check_resume`]: its best fit and
/// noise model are kept, the sampler continues from its last step bit for bit) and hands a
/// report of the steps so far to `checkpoint` every twentieth of the steps.
pub fn fit_resumable(
    problem: &Problem,
    settings: &Settings,
    command_line: &str,
    progress: Progress,
    keep_going: &(dyn Fn() -> bool + Sync),
    resume: Option<&FitReport>,
    checkpoint: &mut dyn FnMut(&FitReport) -> Result<()>,
) -> Result<FitReport> {
    let d = problem.free.len();
    let pool = crate::sweep::thread_pool(settings.jobs)?;
    let walkers = resolved_walkers(problem, settings);
    if !walkers.is_multiple_of(2) || walkers < 2 * d {
        return Err(input_err(
            "--walkers",
            format!("{walkers} walkers for {d} free keys"),
            format!("an even number, at least {}", 2 * d),
        ));
    }
    if settings.steps < 4 {
        return Err(input_err(
            "--steps",
            format!("{}", settings.steps),
            "at least 4 sampler steps",
        ));
    }
    let burn = settings.burn_in.unwrap_or(settings.steps / 4);
    if burn >= settings.steps {
        return Err(input_err(
            "--burn-in",
            format!("{burn} of {} steps", settings.steps),
            "fewer steps than --steps",
        ));
    }
    let scales: Vec<f64> = problem
        .series
        .iter()
        .map(|s| {
            let rms = (s.y.iter().map(|v| v * v).sum::<f64>() / s.y.len() as f64).sqrt();
            if rms > 0.0 { rms } else { 1.0 }
        })
        .collect();

    // 1. The least-squares best fit, and 2. the noise model of each series from its residuals
    // (a resumed fit keeps its checkpoint's).
    let (best, best_cost, best_model, mut runs, noise) = match resume {
        Some(r) => {
            let best: Vec<f64> = r.parameters.iter().map(|p| p.best).collect();
            let best_model: Vec<Vec<f64>> = r.records.iter().map(|rec| rec.best.clone()).collect();
            let noise = r
                .records
                .iter()
                .map(|rec| noise::Noise {
                    sd: rec.noise_sd,
                    correlation_points: rec.noise_correlation,
                    calibration: rec.noise_calibration,
                })
                .collect();
            (best, r.best_cost, best_model, r.evaluations, noise)
        }
        None => {
            let (best, best_cost, best_model, runs) =
                least_squares(problem, settings, &pool, &scales, progress)?;
            let (calibration, draws) = calibrate_noise(problem, settings, &pool, &best, progress);
            let noise: Vec<noise::Noise> = problem
                .series
                .iter()
                .zip(&best_model)
                .zip(&calibration)
                .map(|((s, m), c)| {
                    let r: Vec<f64> = s.y.iter().zip(m).map(|(y, m)| y - m).collect();
                    noise::Noise {
                        calibration: c.unwrap_or(1.0),
                        ..noise::Noise::of_residuals(&r, d, problem.series.len())
                    }
                })
                .collect();
            (best, best_cost, best_model, runs + draws, noise)
        }
    };
    let log_prob = |theta: &[f64], m: &Option<Vec<Vec<f64>>>| -> f64 {
        let lp = problem.log_prior(theta);
        if !lp.is_finite() {
            return f64::NEG_INFINITY;
        }
        let Some(m) = m else { return f64::NEG_INFINITY };
        lp + problem
            .series
            .iter()
            .zip(m)
            .zip(&noise)
            .map(|((s, v), n)| n.log_likelihood(&s.y, v))
            .sum::<f64>()
    };

    // A report of the chain so far (the bands left empty until the end).
    let assemble = |chain: &mcmc::Chain,
                    runs: usize,
                    warnings: Vec<String>,
                    bands: Option<&[(Vec<f64>, Vec<f64>)]>|
     -> FitReport {
        let burn = burn.min(chain.steps_done.saturating_sub(1));
        let samples = chain.flat_after(burn);
        let tau = mcmc::integrated_autocorr_time(chain, burn);
        let ess = mcmc::effective_sample_size(chain, burn);
        let records = problem
            .series
            .iter()
            .enumerate()
            .map(|(j, s)| {
                let (xl, xu, yl, yu) = s.quantity.labels();
                let (low, high) = bands.map_or((Vec::new(), Vec::new()), |b| b[j].clone());
                let inside = noise::inside_fraction(&s.y, &low, &high);
                FitRecord {
                    name: s.record.clone(),
                    x_label: xl.into(),
                    x_unit: xu.into(),
                    y_label: yl.into(),
                    y_unit: yu.into(),
                    x: s.x.clone(),
                    y: s.y.clone(),
                    best: best_model[j].clone(),
                    band_low: low,
                    band_high: high,
                    noise_sd: noise[j].sd,
                    noise_correlation: noise[j].correlation_points,
                    noise_calibration: noise[j].calibration,
                    inside_band: inside,
                }
            })
            .collect();
        let parameters = problem
            .free
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let values: Vec<f64> = samples.iter().map(|s| s[i]).collect();
                FitParameter {
                    key: f.key.clone(),
                    unit: f.unit.to_string(),
                    min: f.min,
                    max: f.max,
                    prior_normal: problem
                        .priors
                        .iter()
                        .find(|p| p.key == f.key)
                        .map(|p| (p.mean, p.sd)),
                    best: best[i],
                    median: mcmc::quantile(&values, 0.5),
                    band_90: mcmc::band_90(&values),
                    tau_steps: tau[i],
                    ess: ess[i],
                }
            })
            .collect();
        FitReport {
            scene: problem.scene.display().to_string(),
            residual: problem.residual.name().to_string(),
            command_line: command_line.to_string(),
            parameters,
            walkers,
            steps: chain.steps_done,
            burn_in: burn,
            chain: chain.positions.clone(),
            log_prob: chain.log_prob.clone(),
            correlations: mcmc::correlations(&samples),
            acceptance: moved_fraction(chain),
            evaluations: runs,
            best_cost,
            records,
            warnings,
        }
    };

    // 3. The posterior: an ensemble started in a small ball around the best fit.
    let scale: Vec<f64> = problem
        .free
        .iter()
        .map(|f| 1e-3 * (f.max - f.min))
        .collect();
    let start = match resume {
        Some(_) => Vec::new(),
        None => mcmc::initial_ball(&best, &scale, walkers, settings.seed, &|x| {
            problem.inside(x)
        }),
    };
    let sampler = mcmc::Settings {
        walkers,
        steps: settings.steps,
        stretch_a: 2.0,
        seed: settings.seed,
    };
    let evaluated = std::sync::atomic::AtomicUsize::new(0);
    let batch = |points: &[Vec<f64>]| -> Vec<f64> {
        evaluated.fetch_add(points.len(), std::sync::atomic::Ordering::Relaxed);
        let ms = models(problem, &pool, points);
        points
            .iter()
            .zip(&ms)
            .map(|(p, m)| log_prob(p, m))
            .collect()
    };
    let mut stopped = false;
    let mut saved: Result<()> = Ok(());
    let every = (settings.steps / 20).max(1);
    let chain = mcmc::sample(&sampler, &start, resume.map(chain_of), &batch, &mut |c| {
        progress("posterior", c.steps_done, settings.steps);
        if c.steps_done.is_multiple_of(every) && c.steps_done < settings.steps && saved.is_ok() {
            let so_far = runs + evaluated.load(std::sync::atomic::Ordering::Relaxed);
            saved = checkpoint(&assemble(c, so_far, Vec::new(), None));
        }
        let go = keep_going() && saved.is_ok();
        stopped = !go;
        go
    });
    saved?;
    runs += evaluated.into_inner();
    let steps_done = chain.steps_done;
    let kept_burn = burn.min(steps_done.saturating_sub(1));
    let samples = chain.flat_after(kept_burn);
    let tau = mcmc::integrated_autocorr_time(&chain, kept_burn);
    let mut warnings = Vec::new();
    if stopped {
        warnings.push(format!(
            "interrupted after {steps_done} of {} sampler steps: the posterior is from those",
            settings.steps
        ));
    }
    let kept = steps_done - kept_burn;
    if let Some(t) = tau
        .iter()
        .cloned()
        .filter(|t| t.is_finite())
        .reduce(f64::max)
        && (kept as f64) < 10.0 * t
    {
        warnings.push(format!(
            "the chain kept {kept} steps after burn-in, fewer than 10 autocorrelation times ({t:.1} steps): run more --steps for trustworthy intervals"
        ));
    }

    // 4. The posterior-predictive band: runs at draws of the posterior, plus the noise model.
    let draws: Vec<Vec<f64>> = if samples.is_empty() {
        Vec::new()
    } else {
        let k = settings.predictive_draws.min(samples.len()).max(1);
        (0..k)
            .map(|i| samples[i * samples.len() / k].clone())
            .collect()
    };
    progress("predictive band", 0, draws.len());
    let predicted: Vec<Vec<Vec<f64>>> = models(problem, &pool, &draws)
        .into_iter()
        .flatten()
        .collect();
    runs += draws.len();
    let bands: Vec<(Vec<f64>, Vec<f64>)> = problem
        .series
        .iter()
        .enumerate()
        .map(|(j, s)| {
            noise[j].predictive_band(
                predicted.iter().map(|m| m[j].as_slice()),
                s.y.len(),
                settings.seed.wrapping_add(j as u64),
            )
        })
        .collect();
    Ok(assemble(&chain, runs, warnings, Some(&bands)))
}

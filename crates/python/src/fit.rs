//! `shpb._shpb.fit`: the binding of `shpb fit` (issue 44; docs/physics.md §12). The same steps as
//! `crates/cli/src/cmd/fit.rs`: the `--free`/`--prior`/`--residual` texts parsed by
//! `shpb_study::fit::spec`, the outputs checked before the fit (`shpb_output::plan`), the
//! `shpb_study::fit::Problem` and `shpb_study::fit::fit`, the outputs written by `shpb_output::fit`;
//! `FitData` hands the `shpb_output::fit::FitReport` to Python (`shpb.Fit` wraps it).

use super::{input_error, interruptible, require_scene};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use shpb_input::{Error, Result};
use shpb_output::atomic::{check_not_input, is_stdout};
use shpb_output::fit::{FitReport, write_fit_outputs};
use shpb_study::fit::spec::parse_flags;
use shpb_study::fit::{Problem, Settings};
use std::path::{Path, PathBuf};

/// What a fit found (`shpb_output::fit::FitReport`) and how long it took; `shpb.Fit` wraps it.
#[pyclass(module = "shpb._shpb", name = "FitData", frozen)]
pub struct FitData {
    report: FitReport,
    seconds: f64,
}

#[pymethods]
impl FitData {
    /// The `--json` object of `shpb fit` (`shpb_output::fit::fit_json` with `seconds`), as text.
    fn json(&self) -> String {
        let mut j = shpb_output::fit::fit_json(&self.report);
        j["seconds"] = self.seconds.into();
        j.to_string()
    }

    /// The free keys, in the order of the chain's last axis.
    fn keys(&self) -> Vec<String> {
        self.report
            .parameters
            .iter()
            .map(|p| p.key.clone())
            .collect()
    }

    /// (steps, walkers, parameters): the shape of [`FitData::chain`].
    fn shape(&self) -> (usize, usize, usize) {
        let r = &self.report;
        (r.steps, r.walkers, r.parameters.len())
    }

    /// Steps dropped as burn-in.
    #[getter]
    fn burn_in(&self) -> usize {
        self.report.burn_in
    }

    /// Every walker's position at every step, flat (steps × walkers × parameters, row-major).
    fn chain<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.report.chain)
    }

    /// The chain after the burn-in, flat (n × parameters, row-major).
    fn samples<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.report.samples())
    }

    /// The log posterior of each position, flat (steps × walkers).
    fn log_prob<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.report.log_prob)
    }

    /// The posterior Pearson correlations (parameters × parameters).
    fn correlations(&self) -> Vec<Vec<f64>> {
        self.report.correlations.clone()
    }

    /// Each record as a dict: `name`, the axes' `x_label`, `x_unit`, `y_label`, `y_unit`, the
    /// numpy arrays `x`, `y`, `best`, `band_low`, `band_high` and the noise model's `noise_sd`,
    /// `noise_correlation`, `noise_calibration` with `inside_band` (`shpb_output::fit::FitRecord`).
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.report
            .records
            .iter()
            .map(|r| {
                let d = PyDict::new(py);
                d.set_item("name", &r.name)?;
                d.set_item("x_label", &r.x_label)?;
                d.set_item("x_unit", &r.x_unit)?;
                d.set_item("y_label", &r.y_label)?;
                d.set_item("y_unit", &r.y_unit)?;
                for (k, v) in [
                    ("x", &r.x),
                    ("y", &r.y),
                    ("best", &r.best),
                    ("band_low", &r.band_low),
                    ("band_high", &r.band_high),
                ] {
                    d.set_item(k, PyArray1::from_slice(py, v))?;
                }
                d.set_item("noise_sd", r.noise_sd)?;
                d.set_item("noise_correlation", r.noise_correlation)?;
                d.set_item("noise_calibration", r.noise_calibration)?;
                d.set_item("inside_band", r.inside_band)?;
                Ok(d)
            })
            .collect()
    }

    /// What the fit warned about (as `shpb fit` prints them).
    fn warnings(&self) -> Vec<String> {
        self.report.warnings.clone()
    }

    /// Writes the fit file of `shpb fit -o` (`shpb_output::fit::write_fit_hdf5`): refused if it
    /// exists unless `force`.
    #[pyo3(signature = (path, force = false))]
    fn save(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        super::detached(py, || {
            refuse_stdout(&path, "path")?;
            let plan = shpb_output::plan::OutputPlan::new(
                force,
                &[(Some(&path), "path", &["h5", "hdf5"])],
            )?;
            let inputs = self.inputs();
            check_not_input(&path, "path", &inputs)?;
            plan.write(
                || shpb_output::fit::write_fit_hdf5(&path, force, &self.report, None),
                |_| {},
            )
        })
    }
}

impl FitData {
    /// The files the fit read: its scene and the records (never overwritten by an output).
    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![PathBuf::from(&self.report.scene)];
        v.extend(
            self.report
                .records
                .iter()
                .filter(|r| r.name != "scene")
                .map(|r| PathBuf::from(&r.name)),
        );
        v
    }
}

/// An input error for `-` as an output: standard output is the command line's, not a file here.
fn refuse_stdout(path: &Path, argument: &str) -> Result<()> {
    if is_stdout(path) {
        return Err(Error::Input {
            file: "python".into(),
            key: argument.into(),
            problem: "`-` (standard output on the command line) is not a file name here".into(),
            allowed: "a file path".into(),
        });
    }
    Ok(())
}

/// Fits the free keys of `scene` to the records as `shpb fit` does: `free` are `--free
/// KEY=MIN:MAX` texts, `prior` `--prior KEY=normal:MEAN:SD`, `record` the `--record` files,
/// `residual` `--residual`; `walkers` 0 is the default max(16, 4 × keys), `burn_in` None a
/// quarter of the steps, `jobs` None one thread per core; `output`, `plot` and `corner` are the
/// files of `-o`, `--plot` and `--corner`, checked before the fit and written after it (refused
/// if they exist, unless `force`). The GIL is released; a Ctrl-C stops the sampler between steps
/// and raises KeyboardInterrupt with the fit of the steps done as its `fit` attribute (`FitData`;
/// no output written).
#[pyfunction]
#[pyo3(signature = (scene, free, prior = vec![], record = vec![], residual = None, walkers = 0, steps = 200, burn_in = None, seed = 1, jobs = None, output = None, plot = None, corner = None, force = false, command_line = String::new()))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with its default
pub fn fit(
    py: Python<'_>,
    scene: PathBuf,
    free: Vec<String>,
    prior: Vec<String>,
    record: Vec<PathBuf>,
    residual: Option<String>,
    walkers: usize,
    steps: usize,
    burn_in: Option<usize>,
    seed: u64,
    jobs: Option<usize>,
    output: Option<PathBuf>,
    plot: Option<PathBuf>,
    corner: Option<PathBuf>,
    force: bool,
    command_line: String,
) -> PyResult<FitData> {
    require_scene(&scene)?;
    if free.is_empty() {
        return Err(input_error(
            "free",
            "no free key",
            "one free key or more: {KEY: (MIN, MAX)} or [\"KEY=MIN:MAX\"]",
        ));
    }
    let settings = Settings {
        walkers,
        steps,
        burn_in,
        seed,
        jobs: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        ..Settings::default()
    };
    let ((report, seconds, outputs), signal) = interruptible(py, |keep_going| {
        let (free, priors, residual) = parse_flags(&free, &prior, residual.as_deref())?;
        let named = [
            (output.as_deref(), "output", &["h5", "hdf5"][..]),
            (plot.as_deref(), "plot", &["png"][..]),
            (corner.as_deref(), "corner", &["png"][..]),
        ];
        for (path, argument, _) in &named {
            if let Some(p) = path {
                refuse_stdout(p, argument)?;
            }
        }
        let outputs = shpb_output::plan::OutputPlan::new(force, &named)?;
        let mut inputs = vec![scene.clone()];
        inputs.extend(record.iter().cloned());
        for (path, argument, _) in &named {
            if let Some(p) = path {
                check_not_input(p, argument, &inputs)?;
            }
        }
        let problem = Problem::new(&scene, free, priors, residual, &record)?;
        let started = std::time::Instant::now();
        let report = shpb_study::fit::fit(
            &problem,
            &settings,
            &command_line,
            &mut |_, _, _| {},
            keep_going,
        )?;
        Ok((report, started.elapsed().as_secs_f64(), outputs))
    })?;
    let data = FitData { report, seconds };
    if let Some(signal) = signal {
        // Interrupted: the fit of the steps done rides on the exception; nothing is written.
        let value = signal.value(py);
        if let Ok(d) = Bound::new(py, data) {
            let _ = value.setattr("fit", d);
        }
        return Err(signal);
    }
    super::detached(py, || {
        let r = &data.report;
        outputs.write(
            || {
                write_fit_outputs(
                    r,
                    output.as_deref(),
                    plot.as_deref(),
                    corner.as_deref(),
                    force,
                )
            },
            |_| {},
        )
    })?;
    Ok(data)
}

//! `shpb._shpb`: the Python extension module of shpb (PyO3, stable ABI for CPython ≥ 3.9).
//!
//! A thin binding of the library calls the `shpb` command line makes (`shpb_study::api`, the
//! writers of `shpb-output`): no physics here. The pure-Python package `shpb`
//! (`python/shpb/__init__.py`) wraps these functions into `Run`, `Table` and `Study` objects
//! with numpy arrays. Every error is a Python exception with the command line's message:
//! exit-code-2 errors raise `InputError` (a `ValueError`), an unstable run `InstabilityError` (a
//! `RuntimeError`), I/O and HDF5 failures `OSError`; a panic is caught and raised as
//! `RuntimeError`.

use numpy::PyArray1;
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyError, PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use shpb_core::contact::LawKind;
use shpb_core::fidelity::Fidelity;
use shpb_core::reduce::{DispersionCorrection, Reduction};
use shpb_core::run::RunOutput;
use shpb_core::scene::Params;
use shpb_input::Error;
use shpb_input::files::Provenance;
use shpb_output::Writer;
use shpb_output::run_file::{Dataset, RunFile};
use shpb_study::api::{self, Scene};
use std::borrow::Cow;
use std::path::{Path, PathBuf};

mod fit;

create_exception!(
    shpb,
    InputError,
    PyValueError,
    "Bad input (exit code 2 of the `shpb` command): a scene, set-up or record with a missing, \
     malformed or out-of-range value, a run too large for the machine, or an existing output."
);
create_exception!(
    shpb,
    InstabilityError,
    PyRuntimeError,
    "A run that became numerically unstable (exit code 3 of the `shpb` command)."
);

/// The Python exception of a shpb error, with the command line's message.
fn py_err(e: Error) -> PyErr {
    let message = e.to_string();
    match &e {
        Error::Io { source, .. } => match source.raw_os_error() {
            Some(errno) => PyOSError::new_err((errno, message)),
            None => PyOSError::new_err(message),
        },
        Error::Hdf5 { .. } => PyOSError::new_err(message),
        Error::Unstable { .. } => InstabilityError::new_err(message),
        Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        _ => InputError::new_err(message),
    }
}

fn input_error(key: &str, problem: impl Into<String>, allowed: impl Into<String>) -> PyErr {
    py_err(Error::Input {
        file: "python".into(),
        key: key.into(),
        problem: problem.into(),
        allowed: allowed.into(),
    })
}

/// Runs `f` without the GIL, catching a panic (raised as `RuntimeError`) and converting a shpb
/// error into its Python exception.
fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> shpb_input::Result<T> + Send,
) -> PyResult<T> {
    let result = py.allow_threads(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match result {
        Ok(r) => r.map_err(py_err),
        Err(panic) => Err(internal_error(panic)),
    }
}

/// How often a sweep or a study run by [`interruptible`] looks for a pending Ctrl-C.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// Runs `f` on a thread of its own, handing it a `keep_going` flag, while this thread waits
/// without the GIL and takes it back every [`SIGNAL_POLL`] to run Python's signal handlers
/// (`Python::check_signals`; only the main thread's handlers run, so a sweep's worker threads
/// cannot see Ctrl-C themselves). The first signal's exception (KeyboardInterrupt for SIGINT)
/// clears the flag: `f` starts no more runs, stops those running at their next 1 % and returns
/// what it finished; that exception comes back beside `f`'s result. A panic is raised as
/// `RuntimeError`, a shpb error as its Python exception (as [`detached`] does).
fn interruptible<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&(dyn Fn() -> bool + Sync)) -> shpb_input::Result<T> + Send,
) -> PyResult<(T, Option<PyErr>)> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let stop = AtomicBool::new(false);
    let keep_going = || !stop.load(Ordering::Relaxed);
    let mut signal = None;
    let joined = std::thread::scope(|s| {
        let worker =
            s.spawn(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&keep_going))));
        while !worker.is_finished() {
            py.allow_threads(|| std::thread::sleep(SIGNAL_POLL));
            if signal.is_none()
                && let Err(e) = py.check_signals()
            {
                signal = Some(e);
                stop.store(true, Ordering::Relaxed);
            }
        }
        worker.join()
    });
    match joined.and_then(|r| r) {
        Ok(r) => Ok((r.map_err(py_err)?, signal)),
        Err(panic) => Err(internal_error(panic)),
    }
}

/// The exception `signal` with the rows finished before it: attribute `table` holds them as
/// the columns [`sweep_table`] gives (the Python package wraps them into a `Table`), `finished`
/// their count.
fn with_finished_rows(
    py: Python<'_>,
    signal: PyErr,
    keys: &[String],
    rows: &[shpb_study::sweep::RunSummary],
) -> PyErr {
    let mut rows = rows.to_vec();
    rows.sort_by_key(|r| r.index);
    let value = signal.value(py);
    let table = table_columns(keys, &rows);
    if let Ok(t) = table.into_pyobject(py) {
        let _ = value.setattr("table", t);
    }
    let _ = value.setattr("finished", rows.len());
    signal
}

/// A panic caught in a run as a Python RuntimeError naming it (never a crash of the interpreter).
fn internal_error(panic: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "unknown panic".into());
    PyRuntimeError::new_err(format!("shpb: internal error (please report it): {what}"))
}

/// FileNotFoundError (errno ENOENT) for a scene that is not a file, IsADirectoryError (EISDIR) for
/// a directory, with the message of `shpb sweep` (python/README: a missing scene file is a
/// `FileNotFoundError`).
fn require_scene(scene: &Path) -> PyResult<()> {
    match shpb_study::sweep::require_scene(scene) {
        Ok(()) => Ok(()),
        // A directory is an IsADirectoryError (errno EISDIR), as `shpb.run` raises it.
        Err(e) if scene.is_dir() => Err(pyo3::exceptions::PyIsADirectoryError::new_err((
            21,
            e.to_string(),
            scene.display().to_string(),
        ))),
        Err(e) => Err(pyo3::exceptions::PyFileNotFoundError::new_err((
            2,
            e.to_string(),
            scene.display().to_string(),
        ))),
    }
}

fn fidelity(name: Option<&str>) -> PyResult<Option<Fidelity>> {
    name.map(|n| {
        Fidelity::parse(n).ok_or_else(|| {
            input_error(
                "fidelity",
                format!("unknown preset `{n}`"),
                "fast, standard, reference",
            )
        })
    })
    .transpose()
}

/// A Python value of a scene dict as a TOML value.
fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.downcast::<PyDict>() {
        return Ok(toml::Value::Table(to_table(d, key)?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .map(|item| to_toml(&item?, key))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(input_error(
        key,
        format!(
            "a value of type {} cannot be written to a scene",
            v.get_type().name()?
        ),
        "str, int, float, bool, dict and list values",
    ))
}

fn to_table(d: &Bound<'_, PyDict>, prefix: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let k: String = k
            .extract()
            .map_err(|_| input_error(prefix, "a key is not a string", "string keys"))?;
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        t.insert(k, to_toml(&v, &key)?);
    }
    Ok(t)
}

/// The `set=` overrides of one run: a string is read as `shpb sweep --set KEY=VALUE` reads it
/// (units such as `12psi`, `0.5mm`), a number or bool as it is.
fn overrides(set: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, toml::Value)>> {
    let Some(set) = set else { return Ok(vec![]) };
    let mut out = Vec::new();
    for (k, v) in set.iter() {
        let key: String = k
            .extract()
            .map_err(|_| input_error("set", "a key is not a string", "dotted scene keys"))?;
        if v.is_instance_of::<PyString>() {
            let text: String = v.extract()?;
            let axis = shpb_study::sweep::parse_axis(&format!("{key}={text}")).map_err(py_err)?;
            if axis.values.len() != 1 {
                return Err(input_error(
                    &format!("set {key}"),
                    format!("`{text}` is {} values", axis.values.len()),
                    "one value per key (shpb.sweep takes several)",
                ));
            }
            out.push((axis.key, axis.values[0].clone()));
        } else {
            let key = shpb_study::sweep::parse_axis(&format!("{key}=0"))
                .map(|a| a.key)
                .unwrap_or(key);
            let value = to_toml(&v, &key)?;
            out.push((key, value));
        }
    }
    Ok(out)
}

enum Source {
    /// A run of a scene, as `shpb run` makes it.
    Simulated {
        params: Box<Params>,
        out: Box<RunOutput>,
        provenance: Provenance,
    },
    /// A reduction of `shpb reduce`, with the command line it stands for.
    Reduced {
        scene: String,
        reduction: Box<Reduction>,
        /// A cylinder's 1/2/3-wave curves, when its geometry was given.
        cylinder: Option<Box<shpb_core::reduce_cylinder::CylinderReduction>>,
    },
    /// A run or reduction file read back.
    Loaded { path: PathBuf, file: Box<RunFile> },
}

/// The data of one run (a simulation, a reduction or a file read back); `shpb.Run` wraps it.
#[pyclass(module = "shpb._shpb", name = "RunData", frozen)]
struct RunData {
    source: Source,
}

impl RunData {
    fn datasets(&self) -> Vec<Dataset<'_>> {
        let mut v = match &self.source {
            Source::Simulated { out, .. } => shpb_output::run_file::run_datasets(out),
            Source::Reduced {
                reduction,
                cylinder,
                ..
            } => {
                let mut v = shpb_output::run_file::reduction_datasets(reduction);
                if let Some(c) = cylinder {
                    v.extend(shpb_output::run_file::cylinder_datasets(c));
                }
                v
            }
            Source::Loaded { file, .. } => file
                .datasets
                .iter()
                .map(|d| Dataset {
                    path: d.path.clone(),
                    shape: d.shape.clone(),
                    data: Cow::Borrowed(&d.data),
                    units: Cow::Borrowed(&d.units),
                })
                .collect(),
        };
        v.sort_by(|a, b| a.path.cmp(&b.path));
        v
    }
}

#[pymethods]
impl RunData {
    /// `"run"`, `"reduction"` or `"file"`.
    #[getter]
    fn origin(&self) -> &'static str {
        match self.source {
            Source::Simulated { .. } => "run",
            Source::Reduced { .. } => "reduction",
            Source::Loaded { .. } => "file",
        }
    }

    /// The summary: (key, value, units) in the order `shpb run` prints it.
    fn summary(&self) -> Vec<(String, f64, String)> {
        match &self.source {
            Source::Simulated { out, .. } => out
                .summary
                .iter()
                .map(|i| (i.key.clone(), i.value, i.unit.to_string()))
                .collect(),
            Source::Reduced {
                reduction,
                cylinder,
                ..
            } => shpb_output::reduction::summary_items(reduction)
                .into_iter()
                .chain(
                    cylinder
                        .iter()
                        .flat_map(|c| shpb_output::reduction::cylinder_summary_items(c)),
                )
                .map(|(k, v, u)| (k.to_string(), v, u.to_string()))
                .collect(),
            Source::Loaded { file, .. } => file.summary.clone(),
        }
    }

    /// The 90 % bands of the summary (docs/physics.md §10.6): (key, value, units, low, high) in
    /// the order of the summary; a loaded file's from its `summary/bands/<key>`.
    fn bands(&self) -> Vec<(String, f64, String, f64, f64)> {
        match &self.source {
            Source::Simulated { out, .. } => out
                .summary
                .iter()
                .filter_map(|i| {
                    i.band_90
                        .map(|[lo, hi]| (i.key.clone(), i.value, i.unit.to_string(), lo, hi))
                })
                .collect(),
            Source::Reduced { .. } => Vec::new(),
            Source::Loaded { file, .. } => file
                .summary
                .iter()
                .filter_map(|(k, v, u)| {
                    let band = file
                        .datasets
                        .iter()
                        .find(|d| d.path == format!("summary/bands/{k}"))?;
                    match band.data.as_ref() {
                        [lo, hi] => Some((k.clone(), *v, u.clone(), *lo, *hi)),
                        _ => None,
                    }
                })
                .collect(),
        }
    }

    /// Every numeric dataset: (path, shape, units), in path order.
    fn dataset_info(&self) -> Vec<(String, Vec<usize>, String)> {
        self.datasets()
            .into_iter()
            .map(|d| (d.path, d.shape, d.units.into_owned()))
            .collect()
    }

    /// The values of the dataset `path`, flat (row-major; `dataset_info` gives the shape).
    fn array<'py>(&self, py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let path = path.trim_start_matches('/');
        let found = match &self.source {
            Source::Loaded { file, .. } => file
                .datasets
                .iter()
                .find(|d| d.path == path)
                .map(|d| PyArray1::from_slice(py, &d.data)),
            _ => self
                .datasets()
                .into_iter()
                .find(|d| d.path == path)
                .map(|d| PyArray1::from_slice(py, &d.data)),
        };
        found.ok_or_else(|| PyKeyError::new_err(path.to_string()))
    }

    /// The equilibrium verdict of the reduction and the sentence saying why it follows
    /// (`shpb_core::reduce::verdict_reason`); None for a run without a reduction or a file.
    fn verdict(&self) -> Option<(String, String)> {
        let r = match &self.source {
            Source::Simulated { out, .. } => out.reduction.as_ref()?,
            Source::Reduced { reduction, .. } => reduction,
            Source::Loaded { .. } => return None,
        };
        Some((
            r.quality.verdict.name().to_string(),
            shpb_core::reduce::verdict_reason(r),
        ))
    }

    /// The warnings of the run (one string each).
    fn warnings(&self) -> Vec<String> {
        match &self.source {
            Source::Simulated { out, .. } => out.warnings.clone(),
            Source::Reduced { reduction, .. } => reduction.warnings.clone(),
            Source::Loaded { file, .. } => file.warnings.clone(),
        }
    }

    /// The scene text (root attribute `scene` of the file).
    fn scene(&self) -> String {
        match &self.source {
            Source::Simulated { params, .. } => params.text.clone(),
            Source::Reduced { scene, .. } => scene.clone(),
            Source::Loaded { file, .. } => file.scene.clone(),
        }
    }

    /// The provenance, if any: (scene_file, fidelity_override, command_line, [(name, text)]).
    #[allow(clippy::type_complexity)]
    fn provenance(&self) -> Option<(String, Option<String>, String, Vec<(String, String)>)> {
        let p = match &self.source {
            Source::Simulated { provenance, .. } => provenance,
            Source::Loaded { file, .. } => file.provenance.as_ref()?,
            Source::Reduced { .. } => return None,
        };
        Some((
            p.scene_file.clone(),
            p.fidelity_override.clone(),
            p.command_line.clone(),
            p.inputs
                .iter()
                .map(|i| (i.name.clone(), i.text.clone()))
                .collect(),
        ))
    }

    /// Writes the file `shpb run -o` (or `shpb reduce -o`) writes; a file read back is copied.
    #[pyo3(signature = (path, force = false))]
    fn save(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        use shpb_output::atomic::{check_not_input, is_stdout};
        detached(py, || {
            if is_stdout(&path) {
                return Err(Error::Input {
                    file: "save".into(),
                    key: "path".into(),
                    problem: "`-` (standard output on the command line) is not a file name here"
                        .into(),
                    allowed: "a .h5 or .hdf5 file path".into(),
                });
            }
            let plan = shpb_output::plan::OutputPlan::new(
                force,
                &[(Some(path.as_path()), "path", &["h5", "hdf5"])],
            )?;
            plan.write(
                || match &self.source {
                    Source::Simulated {
                        params,
                        out,
                        provenance,
                    } => {
                        let inputs: Vec<PathBuf> = provenance
                            .inputs
                            .iter()
                            .filter(|f| !f.name.starts_with("built-in:"))
                            .map(|f| PathBuf::from(&f.name))
                            .collect();
                        check_not_input(&path, "path", &inputs)?;
                        shpb_output::Hdf5 {
                            provenance: Some(provenance.clone()),
                        }
                        .write_run(&path, force, params, out)
                    }
                    Source::Reduced {
                        scene,
                        reduction,
                        cylinder,
                    } => shpb_output::reduction::write_reduction_hdf5_with(
                        &path,
                        force,
                        scene,
                        reduction,
                        cylinder.as_deref(),
                    ),
                    Source::Loaded { path: source, .. } => {
                        check_not_input(&path, "path", std::slice::from_ref(source))?;
                        shpb_output::atomic::write_atomically(&path, force, |tmp| {
                            std::fs::copy(source, tmp)
                                .map(|_| ())
                                .map_err(|e| Error::io(source, e))
                        })
                    }
                },
                |_| {},
            )
        })
    }
}

/// Runs a scene (a scene file, a run file to rerun, or a dict) as `shpb run` does.
#[pyfunction]
#[pyo3(signature = (scene, fidelity = None, set = None, command_line = String::new(), bands = true))]
fn run(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    fidelity: Option<&str>,
    set: Option<&Bound<'_, PyDict>>,
    command_line: String,
    bands: bool,
) -> PyResult<RunData> {
    let fidelity = self::fidelity(fidelity)?;
    let overrides = overrides(set)?;
    let (path, text) = match scene.downcast::<PyDict>() {
        Ok(d) => {
            let table = to_table(d, "")?;
            let text = toml::to_string(&table)
                .map_err(|e| input_error("scene", e.to_string(), "a TOML-like dict"))?;
            (None, Some(text))
        }
        Err(_) => (Some(scene.extract::<PathBuf>()?), None),
    };
    let (params, out, provenance) = detached(py, || {
        let scene = match (&path, &text) {
            (Some(p), _) => Scene::File(p),
            (None, Some(t)) => Scene::Text {
                name: "<dict>",
                text: t,
            },
            (None, None) => unreachable!("a path or a text"),
        };
        let (params, provenance) = api::load_scene(scene, fidelity, &overrides, command_line)?;
        // Every 1 % of a long run: a pending Ctrl-C (SIGINT) stops it with KeyboardInterrupt.
        // The summary's 90 % bands unless `bands=False` (docs/physics.md §10.6).
        let out = api::run_scene_with_bands(&params, &provenance, bands, &mut |_| {
            Python::with_gil(|py| py.check_signals().is_ok())
        })?;
        Ok((params, out, provenance))
    })?;
    Ok(RunData {
        source: Source::Simulated {
            params: Box::new(params),
            out: Box::new(out),
            provenance,
        },
    })
}

/// Reads a run file (`shpb run -o`, `Run.save`) or reduction file (`shpb reduce -o`).
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<RunData> {
    let file = detached(py, || {
        if !path.is_file() || !shpb_output::reduction::is_hdf5(&path)? {
            return Err(Error::Input {
                file: path.display().to_string(),
                key: "path".into(),
                problem: "not an HDF5 file".into(),
                allowed: "a run file written by `shpb run -o` or `Run.save`, or a reduction file \
                          of `shpb reduce -o`"
                    .into(),
            });
        }
        shpb_output::run_file::read_run_file(&path)
    })?;
    Ok(RunData {
        source: Source::Loaded {
            path,
            file: Box::new(file),
        },
    })
}

/// The striker velocity (m/s) the set-up's gas gun gives at `pressure` (`shpb gun`).
#[pyfunction]
#[pyo3(signature = (pressure, bars = api::DEFAULT_BARS.into()))]
fn gun(py: Python<'_>, pressure: String, bars: PathBuf) -> PyResult<f64> {
    detached(py, || {
        let apparatus = api::load_apparatus(&bars)?;
        Ok(api::gun_shot(&apparatus, &pressure)?.1)
    })
}

/// Two numpy arrays.
type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// The loading curve F(δ) of a specimen (`shpb curve`): (displacement m, force N).
#[pyfunction]
#[pyo3(signature = (pair = "ss440c".into(), rate = 0.0, to = 250e-6, points = 101, law = "burgoyne-daraio".into()))]
fn curve<'py>(
    py: Python<'py>,
    pair: String,
    rate: f64,
    to: f64,
    points: i64,
    law: String,
) -> PyResult<ArrayPair<'py>> {
    let Some(&(_, law)) = LawKind::ALL.iter().find(|(n, _)| *n == law) else {
        return Err(input_error(
            "law",
            format!("unknown contact law `{law}`"),
            LawKind::ALL
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", "),
        ));
    };
    let s = detached(py, || api::loading_curve(&pair, rate, to, points, law))?;
    Ok((
        PyArray1::from_vec(py, s.displacement_m),
        PyArray1::from_vec(py, s.force_n),
    ))
}

/// The lab's reduction of a raw record or run file (`shpb reduce`): `dispersion` is `none`,
/// `bancroft` or `pochhammer-chree` (`--dispersion`), `tyas_pope` adds the Tyas–Pope factors,
/// `align` is `geometric`, `foot` or `balance` (`--align`), `smooth` the moving-average width in
/// s (`--smooth`), `filter` `none`, `butterworth`, `savitzky-golay` or `moving-average`
/// (`--filter`, with `filter_cutoff` Hz, `filter_order`, `filter_window` s; docs/physics.md
/// §7.12), `baseline` `start-mean` or `linear-drift` (`--baseline`), `layout` a record layout file (`--layout`), `balance_bound_s` the bound of the
/// balance search (`--balance-bound`); with a cylinder's length and diameter (m, both or
/// neither) also its 1/2/3-wave curves; `specimen` a specimen file (`--specimen`: spheres of any
/// diameter, a chain, or a cylinder); `tension` a tension test (`--tension`, §7.8.1);
/// `wave_separation` `none`, `one-gauge` or `two-gauge` (`--wave-separation`)
/// (docs/physics.md §7.3, §7.6–7.11).
#[pyfunction]
#[pyo3(signature = (record, bars = None, dispersion = "bancroft".into(), tyas_pope = false, align = "geometric".into(), smooth = None, specimen_length_m = None, specimen_diameter_m = None, layout = None, balance_bound_s = shpb_core::reduce::DEFAULT_BALANCE_BOUND_S, specimen = None, tension = false, wave_separation = "none".into(), filter = None, filter_cutoff = None, filter_order = None, filter_window = None, baseline = "start-mean".into()))]
#[allow(clippy::too_many_arguments)]
fn reduce(
    py: Python<'_>,
    record: PathBuf,
    bars: Option<PathBuf>,
    dispersion: String,
    tyas_pope: bool,
    align: String,
    smooth: Option<f64>,
    specimen_length_m: Option<f64>,
    specimen_diameter_m: Option<f64>,
    layout: Option<PathBuf>,
    balance_bound_s: f64,
    specimen: Option<PathBuf>,
    tension: bool,
    wave_separation: String,
    filter: Option<String>,
    filter_cutoff: Option<f64>,
    filter_order: Option<usize>,
    filter_window: Option<f64>,
    baseline: String,
) -> PyResult<RunData> {
    let Some(separation) = shpb_core::reduce::WaveSeparation::from_name(&wave_separation) else {
        return Err(input_error(
            "wave_separation",
            format!("unknown wave separation `{wave_separation}`"),
            shpb_core::reduce::WaveSeparation::ALL
                .iter()
                .map(|a| a.name())
                .collect::<Vec<_>>()
                .join(", "),
        ));
    };
    let Some(correction) = DispersionCorrection::from_name(&dispersion) else {
        return Err(input_error(
            "dispersion",
            format!("unknown dispersion correction `{dispersion}`"),
            DispersionCorrection::ALL
                .iter()
                .map(|d| d.name())
                .collect::<Vec<_>>()
                .join(", "),
        ));
    };
    let Some(alignment) = shpb_core::reduce::Alignment::from_name(&align) else {
        return Err(input_error(
            "align",
            format!("unknown alignment `{align}`"),
            shpb_core::reduce::Alignment::ALL
                .iter()
                .map(|a| a.name())
                .collect::<Vec<_>>()
                .join(", "),
        ));
    };
    let (reduced, scene) = detached(py, || {
        let geometry = api::cylinder_geometry(
            specimen_length_m,
            specimen_diameter_m,
            ("specimen_length_m", "specimen_diameter_m"),
        )?;
        let (reduction_filter, smoothing_s) = api::filter_choice(
            filter.as_deref(),
            smooth,
            filter_cutoff,
            filter_order,
            filter_window,
            [
                "filter",
                "filter_cutoff",
                "filter_order",
                "filter_window",
                "smooth",
            ],
        )?;
        let choices = api::RecordOptions {
            dispersion: correction,
            tyas_pope,
            alignment,
            smoothing_s,
            balance_bound_s,
            window: None,
            cylinder: geometry,
            layout: layout
                .as_deref()
                .map(shpb_input::layout::RecordLayout::from_file)
                .transpose()?,
            specimen: specimen
                .as_deref()
                .map(shpb_input::specimen_file::SpecimenFile::read)
                .transpose()?,
            channels: None,
            tension,
            wave_separation: separation,
            filter: reduction_filter,
            baseline: api::baseline_choice(&baseline, "baseline")?,
        };
        let r = api::reduce_record_with(&record, bars.as_deref(), &choices)?;
        let mut scene = format!(
            "shpb reduce {} --bars {}",
            record.display(),
            bars.as_deref()
                .map_or(r.apparatus.source.clone(), |b| b.display().to_string())
        );
        scene.push_str(&choices.command_flags());
        Ok((r, scene))
    })?;
    Ok(RunData {
        source: Source::Reduced {
            scene,
            reduction: Box::new(reduced.reduction),
            cylinder: reduced.cylinder.map(Box::new),
        },
    })
}

/// A sweep's table: the swept keys, each row's values as written, the SI value and units of each
/// input column (None when not numeric), the summary columns (name, units, values) and each
/// row's warnings.
type SweepTable = (
    Vec<String>,
    Vec<Vec<String>>,
    Vec<Option<(String, Vec<f64>)>>,
    Vec<(String, String, Vec<f64>)>,
    Vec<Vec<String>>,
);

/// The rows of a table as Python takes them ([`SweepTable`]).
fn table_columns(keys: &[String], rows: &[shpb_study::sweep::RunSummary]) -> SweepTable {
    let labels: Vec<Vec<String>> = rows.iter().map(|r| r.inputs.clone()).collect();
    let inputs = keys
        .iter()
        .enumerate()
        .map(|(i, k)| {
            let values: Option<Vec<(f64, &str)>> = rows
                .iter()
                .map(|r| shpb_study::sweep::input_si(k, &r.inputs[i]))
                .collect();
            let values = values?;
            let unit = values.first().map_or("1", |v| v.1);
            values
                .iter()
                .all(|v| v.1 == unit)
                .then(|| (unit.to_string(), values.iter().map(|v| v.0).collect()))
        })
        .collect();
    let columns = shpb_study::sweep::SUMMARY_COLUMNS
        .iter()
        .enumerate()
        .map(|(j, (name, unit))| {
            (
                name.to_string(),
                unit.to_string(),
                rows.iter().map(|r| r.values()[j]).collect(),
            )
        })
        .collect();
    let warnings = rows.iter().map(|r| r.warnings.clone()).collect();
    (keys.to_vec(), labels, inputs, columns, warnings)
}

/// Runs `scene` over the product of the `--set` specifications `set` on `jobs` threads
/// (`shpb sweep`, without checkpoint or files); `shard = (k, n)` runs only shard k of n
/// (`shpb sweep --shard k/n`). Returns the swept keys and the rows, for [`sweep_table`].
#[pyfunction]
#[pyo3(signature = (scene, set, jobs = 1, shard = (1, 1)))]
fn sweep_runs(
    py: Python<'_>,
    scene: PathBuf,
    set: Vec<String>,
    jobs: usize,
    shard: (usize, usize),
) -> PyResult<(Vec<String>, StudyRows)> {
    require_scene(&scene)?;
    let ((axes, finished), signal) = interruptible(py, |keep_going| {
        api::sweep_shard_rows_until(&scene, &set, shard, jobs, keep_going)
    })?;
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    if let Some(signal) = signal {
        return Err(with_finished_rows(py, signal, &keys, &finished.rows));
    }
    Ok((keys, travelling(&finished.rows)))
}

/// The table of a sweep over `keys` from the rows of all its shards (`sweep_runs`), in sweep
/// order; an input error unless they hold every run exactly once (`partial`: the rows of the
/// shards that finished before a Ctrl-C, each run at most once).
#[pyfunction]
#[pyo3(signature = (keys, rows, partial = false))]
fn sweep_table(keys: Vec<String>, rows: StudyRows, partial: bool) -> PyResult<SweepTable> {
    let mut rows = arrived(rows);
    rows.sort_by_key(|r| r.index);
    let exactly_once = rows.iter().enumerate().all(|(i, r)| r.index == i);
    let at_most_once = rows.windows(2).all(|w| w[0].index < w[1].index);
    if !(if partial { at_most_once } else { exactly_once }) {
        return Err(input_error(
            "shards",
            format!(
                "{} rows do not hold each run of the sweep exactly once",
                rows.len()
            ),
            "the rows of every shard k/n of one sweep, k = 1..n",
        ));
    }
    Ok(table_columns(&keys, &rows))
}

/// Rows as they travel between processes ([`StudyRows`]).
fn travelling(rows: &[shpb_study::sweep::RunSummary]) -> StudyRows {
    rows.iter()
        .map(|r| (r.index, r.inputs.clone(), r.values(), r.warnings.clone()))
        .collect()
}

/// Rows back from their travelling form.
fn arrived(rows: StudyRows) -> Vec<shpb_study::sweep::RunSummary> {
    rows.into_iter()
        .map(|(index, inputs, v, warnings)| {
            let mut row = shpb_study::sweep::RunSummary::from_values(index, inputs, v);
            row.warnings = warnings;
            row
        })
        .collect()
}

/// Runs of a sweep or a study as they travel between processes: (index, inputs as written, the
/// summary values in the order of `SUMMARY_COLUMNS`, the run's warnings).
type StudyRows = Vec<(usize, Vec<String>, [f64; 5], Vec<String>)>;

/// The plan of a study (`shpb study --samples --seed [--no-gun-scatter] [--fidelity]`).
fn study_plan(
    samples: usize,
    seed: u64,
    gun_scatter: bool,
    fidelity: Option<&str>,
) -> PyResult<shpb_study::uq::StudyPlan> {
    Ok(shpb_study::uq::StudyPlan {
        samples,
        seed,
        gun_scatter,
        fidelity: self::fidelity(fidelity)?,
    })
}

/// Runs shard `k` of `n` (`shard`) of the study of `scene` (`shpb study`: `samples` Latin-
/// hypercube samples drawn with `seed`, the gun scatter with `gun_scatter`, every run at
/// `fidelity` if given) on `jobs` threads.
#[pyfunction]
#[pyo3(signature = (scene, samples, seed = 1, jobs = 1, gun_scatter = true, shard = (1, 1), fidelity = None))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with its default
fn study_runs(
    py: Python<'_>,
    scene: PathBuf,
    samples: usize,
    seed: u64,
    jobs: usize,
    gun_scatter: bool,
    shard: (usize, usize),
    fidelity: Option<&str>,
) -> PyResult<StudyRows> {
    let plan = study_plan(samples, seed, gun_scatter, fidelity)?;
    require_scene(&scene)?;
    let ((study, _), signal) = interruptible(py, |keep_going| {
        shpb_study::uq::study_shard_rows_until(
            &scene,
            &plan,
            jobs,
            false,
            shard,
            |_| {},
            keep_going,
        )
    })?;
    if let Some(signal) = signal {
        return Err(with_finished_rows(py, signal, &study.keys(), &study.rows));
    }
    Ok(travelling(&study.rows))
}

/// One statistic row of a study: quantity, units, finite values counted, mean, sd, the 5/50/95 %
/// percentiles and the first-order index to each input (empty for an input's own row).
type StudyStat = (String, String, usize, f64, f64, [f64; 3], Vec<f64>);

/// The study of `scene` from the rows of all its shards (`study_runs`): its table (as `sweep`
/// returns one), its statistics (`shpb study --summary`) and the description of its inputs.
#[pyfunction]
#[pyo3(signature = (scene, samples, seed, gun_scatter, rows, fidelity = None))]
fn study_table(
    py: Python<'_>,
    scene: PathBuf,
    samples: usize,
    seed: u64,
    gun_scatter: bool,
    rows: StudyRows,
    fidelity: Option<&str>,
) -> PyResult<(SweepTable, Vec<StudyStat>, Vec<String>)> {
    let rows = arrived(rows);
    let plan = study_plan(samples, seed, gun_scatter, fidelity)?;
    let study = detached(py, || shpb_study::uq::Study::from_rows(&scene, &plan, rows))?;
    let stats = study
        .statistics()
        .into_iter()
        .map(|s| {
            (
                s.name,
                s.unit,
                s.count,
                s.mean,
                s.sd,
                s.p5_p50_p95,
                s.first_order,
            )
        })
        .collect();
    Ok((
        table_columns(&study.keys(), &study.rows),
        stats,
        study.specification(),
    ))
}

/// The version of shpb this module was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// Whether a path names a run file that `shpb.run` would rerun (an HDF5 file).
#[pyfunction]
fn is_hdf5(path: PathBuf) -> bool {
    path.is_file() && shpb_output::reduction::is_hdf5(Path::new(&path)).unwrap_or(false)
}

#[pymodule]
fn _shpb(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("InstabilityError", m.py().get_type::<InstabilityError>())?;
    m.add_class::<RunData>()?;
    m.add_class::<fit::FitData>()?;
    for f in [
        wrap_pyfunction!(run, m)?,
        wrap_pyfunction!(study_runs, m)?,
        wrap_pyfunction!(study_table, m)?,
        wrap_pyfunction!(load, m)?,
        wrap_pyfunction!(gun, m)?,
        wrap_pyfunction!(curve, m)?,
        wrap_pyfunction!(reduce, m)?,
        wrap_pyfunction!(sweep_runs, m)?,
        wrap_pyfunction!(sweep_table, m)?,
        wrap_pyfunction!(version, m)?,
        wrap_pyfunction!(is_hdf5, m)?,
        wrap_pyfunction!(fit::fit, m)?,
    ] {
        m.add_function(f)?;
    }
    Ok(())
}

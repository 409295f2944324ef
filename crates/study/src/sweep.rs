//! Design studies: a scene run over the Cartesian product of swept parameters, in parallel
//! (rayon), with a summary row per run (peak force, displacement at peak, peak strain rate,
//! equilibrium ratio, time to equilibrium) and deterministic shards.

use crate::identity::Stamp;
use rayon::prelude::*;
use shpb_core::run::RunOutput;
use shpb_core::scene::Params;
use shpb_input::prelude::*;
use shpb_input::provenance::InputFile;
use shpb_input::{Error, Result};
use std::path::Path;

/// One swept parameter: the scene key and its values (TOML values as the scene takes them).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Scene key path (`pressure`, `shaper.thickness_m`).
    pub key: String,
    /// Values, in sweep order.
    pub values: Vec<shpb_input::scene::Value>,
    /// The values as written (for tables), e.g. `5psi`, `0.5mm`.
    pub labels: Vec<String>,
}

/// Names users write on the command line for the scene's keys.
const ALIASES: &[(&str, &str)] = &[
    ("striker.pressure", "pressure"),
    ("gun.pressure", "pressure"),
    ("shaper.thickness", "shaper.thickness_m"),
    ("shaper.diameter", "shaper.diameter_m"),
];

/// Length units accepted for keys ending in `_m`, with their factor to metres.
const LENGTH_UNITS: &[(&str, f64)] = &[("mm", 1e-3), ("um", 1e-6), ("µm", 1e-6), ("m", 1.0)];

fn bad_set(spec: &str, problem: impl Into<String>) -> Error {
    Error::Input {
        file: "command line".into(),
        key: format!("--set {spec}"),
        problem: problem.into(),
        allowed: "KEY=V1,V2,… or KEY=START:STOP:COUNT (e.g. pressure=5psi:20psi:16, \
                  shaper.thickness_m=0.5mm,1mm)"
            .into(),
    }
}

pub use shpb_input::units::number_and_unit;

/// The TOML value of one text value of `key`: lengths in m for `_m` keys, numbers as floats,
/// anything else (a pressure with unit, a law name) as a string the scene validates.
fn value_of(key: &str, text: &str, spec: &str) -> Result<shpb_input::scene::Value> {
    // `nan`, `inf`, `infinity` (any case, signed) are numbers to Rust but words to
    // `number_and_unit`: refused here rather than passed on as text the scene calls a string.
    if text.trim().parse::<f64>().is_ok_and(|v| !v.is_finite()) {
        return Err(bad_set(spec, format!("{text}: not finite")));
    }
    match number_and_unit(text) {
        Some((v, _)) if !v.is_finite() => Err(bad_set(spec, format!("{text}: not finite"))),
        // A whole number stays an integer (a count such as `points` takes no float; a float key
        // takes an integer too).
        Some((_, unit)) if unit.is_empty() && text.trim().parse::<i64>().is_ok() => Ok(
            shpb_input::scene::Value::Integer(text.trim().parse().expect("checked")),
        ),
        Some((v, unit)) if unit.is_empty() => Ok(shpb_input::scene::Value::Float(v)),
        Some((v, unit)) if key.ends_with("_m") => LENGTH_UNITS
            .iter()
            .find(|(u, _)| *u == unit)
            .map(|(_, f)| shpb_input::scene::Value::Float(v * f))
            .ok_or_else(|| bad_set(spec, format!("unknown length unit `{unit}` (mm, um, m)"))),
        _ => Ok(shpb_input::scene::Value::String(text.trim().to_string())),
    }
}

/// Parses one `--set KEY=…` specification.
pub fn parse_axis(spec: &str) -> Result<Axis> {
    let (key, values) = spec
        .split_once('=')
        .ok_or_else(|| bad_set(spec, "no `=`"))?;
    let key = key.trim();
    if key.is_empty() {
        return Err(bad_set(spec, "empty key"));
    }
    let key = ALIASES
        .iter()
        .find(|(a, _)| *a == key)
        .map(|(_, k)| k.to_string())
        .unwrap_or_else(|| key.to_string());
    let labels: Vec<String> = if values.contains(':') {
        let parts: Vec<&str> = values.split(':').collect();
        let [start, stop, count] = parts[..] else {
            return Err(bad_set(spec, "a range needs START:STOP:COUNT"));
        };
        let count: usize = count
            .trim()
            .parse()
            .map_err(|_| bad_set(spec, format!("count `{count}` is not a whole number")))?;
        let (a, ua) = number_and_unit(start)
            .ok_or_else(|| bad_set(spec, format!("`{start}` is not a number")))?;
        let (b, ub) = number_and_unit(stop)
            .ok_or_else(|| bad_set(spec, format!("`{stop}` is not a number")))?;
        if ua != ub {
            return Err(bad_set(spec, format!("units differ: `{ua}` and `{ub}`")));
        }
        if !(2..=100_000).contains(&count) || !a.is_finite() || !b.is_finite() {
            return Err(bad_set(spec, "finite ends and 2 to 100000 values"));
        }
        (0..count)
            .map(|i| {
                let v = a + (b - a) * i as f64 / (count - 1) as f64;
                format!("{}{ua}", (v * 1e9).round() / 1e9)
            })
            .collect()
    } else {
        values.split(',').map(|v| v.trim().to_string()).collect()
    };
    if labels.iter().any(String::is_empty) {
        return Err(bad_set(spec, "an empty value"));
    }
    let values = labels
        .iter()
        .map(|l| value_of(&key, l, spec))
        .collect::<Result<Vec<_>>>()?;
    Ok(Axis {
        key,
        values,
        labels,
    })
}

/// Parses every `--set` specification of a sweep; a key set twice (also through an alias, such as
/// `striker.pressure` and `pressure`) is an error naming it: the second would silently win in
/// every run while the rows were labelled with the first one's values.
pub fn parse_axes(specs: &[String]) -> Result<Vec<Axis>> {
    let mut axes: Vec<(Axis, &str)> = Vec::new();
    for spec in specs {
        let axis = parse_axis(spec)?;
        if let Some((_, first)) = axes.iter().find(|(a, _)| a.key == axis.key) {
            return Err(Error::Input {
                file: "command line".into(),
                key: format!("--set {}", axis.key),
                problem: format!(
                    "`{}` is set twice (`--set {first}` and `--set {spec}`)",
                    axis.key
                ),
                allowed: format!(
                    "each key once; give all its values in one --set, e.g. {}=V1,V2,V3",
                    axis.key
                ),
            });
        }
        axes.push((axis, spec));
    }
    Ok(axes.into_iter().map(|(a, _)| a).collect())
}

/// The number of runs of the whole sweep (the product of the axes' lengths), `None` beyond
/// `u128` (computed without allocating, so a sweep too large to run can be refused).
pub fn run_count(axes: &[Axis]) -> Option<u128> {
    axes.iter()
        .try_fold(1u128, |n, a| n.checked_mul(a.values.len() as u128))
}

/// The number of runs of shard `k` of `n` of a sweep of `total` runs (every n-th from k − 1).
pub fn shard_run_count(total: u128, k: usize, n: usize) -> u128 {
    let (k, n) = (k as u128, n as u128);
    if total < k { 0 } else { (total - k) / n + 1 }
}

/// The point of run `index` of the product (last axis fastest).
pub fn point_at(axes: &[Axis], index: usize) -> Point {
    let mut rest = index;
    let mut coords = vec![0; axes.len()];
    for (k, a) in axes.iter().enumerate().rev() {
        coords[k] = rest % a.values.len();
        rest /= a.values.len();
    }
    Point { index, coords }
}

/// The points of shard `k` of `n` (1-based `k`; `1/1` is the whole sweep), built one by one
/// without the whole product (call it once [`Estimate::check`] has passed).
pub fn shard_points(axes: &[Axis], k: usize, n: usize) -> Vec<Point> {
    let total = run_count(axes).map_or(usize::MAX, |t| t.min(usize::MAX as u128) as usize);
    (k - 1..total)
        .step_by(n)
        .map(|i| point_at(axes, i))
        .collect()
}

/// SHA-256 of the swept keys and values ([`crate::identity::set_sha256`]).
pub fn axes_sha256(axes: &[Axis]) -> String {
    crate::identity::set_sha256(axes.iter().map(|a| (a.key.as_str(), a.labels.as_slice())))
}

/// One run of a sweep: its index in the full product and its coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Index in the Cartesian product (last axis fastest).
    pub index: usize,
    /// Index along each axis.
    pub coords: Vec<usize>,
}

/// The Cartesian product of the axes, last axis fastest (the whole sweep: [`shard_points`] with
/// 1/1).
pub fn product(axes: &[Axis]) -> Vec<Point> {
    shard_points(axes, 1, 1)
}

/// The runs of shard `k` of `n` (1-based `k`): every n-th run starting at k − 1, so shards are
/// balanced across the product and their union is the whole sweep.
pub fn shard(points: Vec<Point>, k: usize, n: usize) -> Vec<Point> {
    points
        .into_iter()
        .filter(|p| p.index % n == k - 1)
        .collect()
}

/// Parses `--shard k/n` ([`check_shard`]).
pub fn parse_shard(text: &str) -> Result<(usize, usize)> {
    let (k, n) = text.split_once('/').ok_or_else(|| shard_error(text))?;
    match (k.trim().parse(), n.trim().parse()) {
        (Ok(k), Ok(n)) => check_shard(k, n).map_err(|_| shard_error(text)),
        _ => Err(shard_error(text)),
    }
}

/// Checks a shard `k` of `n` given as numbers (Python, Dask): 1 ≤ k ≤ n, else the error
/// `--shard k/n` gets.
pub fn check_shard(k: usize, n: usize) -> Result<(usize, usize)> {
    if k == 0 || n == 0 || k > n {
        return Err(shard_error(&format!("{k}/{n}")));
    }
    Ok((k, n))
}

/// The error of a shard outside 1 ≤ k ≤ n, quoting it as written.
fn shard_error(text: &str) -> Error {
    Error::Input {
        file: "command line".into(),
        key: "--shard".into(),
        problem: format!("`{text}`"),
        allowed: "k/n with 1 ≤ k ≤ n, e.g. 2/4".into(),
    }
}

/// The summary of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Index in the full product.
    pub index: usize,
    /// The swept values as written.
    pub inputs: Vec<String>,
    /// Peak true contact force, N.
    pub peak_force_n: f64,
    /// True approach at peak force, m.
    pub displacement_at_peak_m: f64,
    /// Largest reduced global strain rate, 1/s (NaN without a reduction).
    pub peak_strain_rate_per_s: f64,
    /// Reduced equilibrium ratio at the peak back force (NaN without a reduction).
    pub equilibrium_ratio_at_peak: f64,
    /// First reduced time at which the equilibrium ratio is ≤ 0.05 with the back force ≥ 10 % of
    /// its peak, s (NaN if never).
    pub time_to_equilibrium_s: f64,
    /// The run's warnings, the scene's first, as `shpb run` prints them (a gun pressure outside
    /// its calibration, a shaper extrapolated, …).
    pub warnings: Vec<String>,
}

/// The separator of a row's warnings in one CSV cell (`shpb sweep --csv`, `shpb design`).
pub const WARNINGS_SEPARATOR: &str = " | ";

/// A row's warnings as one CSV cell: joined by [`WARNINGS_SEPARATOR`], double-quoted (RFC 4180,
/// quotes doubled) when it holds a comma or a quote; empty for none.
pub fn warnings_cell(warnings: &[String]) -> String {
    let text = warnings
        .iter()
        .map(|w| w.replace(['\n', '\r'], " "))
        .collect::<Vec<_>>()
        .join(WARNINGS_SEPARATOR);
    if text.contains([',', '"']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text
    }
}

/// The cells of one CSV line, a double-quoted cell (RFC 4180, `""` for a quote) read as one.
pub fn split_csv_line(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        let cell = cells.last_mut().expect("one cell at least");
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            ('"', true) => quoted = false,
            ('"', false) if cell.is_empty() => quoted = true,
            (',', false) => cells.push(String::new()),
            (c, _) => cell.push(c),
        }
    }
    cells
}

/// The warnings of a CSV cell written by [`warnings_cell`] (after [`split_csv_line`]).
pub fn warnings_of_cell(cell: &str) -> Vec<String> {
    if cell.is_empty() {
        return Vec::new();
    }
    cell.split(WARNINGS_SEPARATOR).map(str::to_string).collect()
}

/// Summary columns with units.
pub const SUMMARY_COLUMNS: [(&str, &str); 5] = [
    ("peak_force", "N"),
    ("displacement_at_peak", "m"),
    ("peak_strain_rate", "1/s"),
    ("equilibrium_ratio_at_peak", "1"),
    ("time_to_equilibrium", "s"),
];

/// Worker threads `-j` may ask for per core of the machine: a run is CPU-bound, so more
/// threads than cores only share them; 4 per core leaves room for runs that wait on their
/// output, and refuses `-j 100000` (issue 42: it spawned hundreds of threads without a word).
pub const MAX_JOBS_PER_CORE: usize = 4;

/// The most worker threads `-j` may ask for on this machine: [`MAX_JOBS_PER_CORE`] × its
/// cores (`std::thread::available_parallelism`, 1 where unknown).
pub fn max_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get()) * MAX_JOBS_PER_CORE
}

/// `jobs` as a thread count (0 counts as 1), or an input error naming `-j` and the range when
/// it is more than [`max_jobs`].
pub fn check_jobs(jobs: usize) -> Result<usize> {
    let most = max_jobs();
    if jobs > most {
        return Err(Error::Input {
            file: "command line".into(),
            key: "-j".into(),
            problem: format!(
                "{jobs} worker threads is more than {MAX_JOBS_PER_CORE} per core of this \
                 machine's {} cores",
                most / MAX_JOBS_PER_CORE
            ),
            allowed: format!("1 to {most} (0 counts as 1)"),
        });
    }
    Ok(jobs.max(1))
}

/// A pool of `jobs` worker threads (`-j`; 0 counts as 1, at most [`max_jobs`]) for the runs of
/// a sweep or a study.
pub fn thread_pool(jobs: usize) -> Result<rayon::ThreadPool> {
    let jobs = check_jobs(jobs)?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| Error::Input {
            file: "command line".into(),
            key: "-j".into(),
            problem: e.to_string(),
            allowed: "a thread count from 1 up".into(),
        })
}

/// An input error unless `scene` names a readable file (before any run is planned).
pub fn require_scene(scene: &Path) -> Result<()> {
    if scene.is_file() {
        return Ok(());
    }
    Err(Error::Input {
        file: "command line".into(),
        key: "SCENE".into(),
        problem: format!(
            "cannot read {}: {}",
            scene.display(),
            shpb_input::files::not_a_file(scene)
        ),
        allowed: "a scene .toml file".into(),
    })
}

impl RunSummary {
    /// A row from its index, inputs as written and numeric columns in the order of
    /// [`SUMMARY_COLUMNS`] (the inverse of [`RunSummary::values`]).
    pub fn from_values(index: usize, inputs: Vec<String>, v: [f64; 5]) -> RunSummary {
        RunSummary {
            index,
            inputs,
            peak_force_n: v[0],
            displacement_at_peak_m: v[1],
            peak_strain_rate_per_s: v[2],
            equilibrium_ratio_at_peak: v[3],
            time_to_equilibrium_s: v[4],
            warnings: Vec::new(),
        }
    }

    /// The numeric columns in the order of [`SUMMARY_COLUMNS`].
    pub fn values(&self) -> [f64; 5] {
        [
            self.peak_force_n,
            self.displacement_at_peak_m,
            self.peak_strain_rate_per_s,
            self.equilibrium_ratio_at_peak,
            self.time_to_equilibrium_s,
        ]
    }
}

/// The summary of a run's output.
pub fn summarise(index: usize, inputs: Vec<String>, out: &RunOutput) -> RunSummary {
    let (peak_force_n, displacement_at_peak_m) = match &out.contact {
        Some(c) => {
            let k = c.peak_index();
            (c.force_n[k], c.displacement_m[k])
        }
        None => (f64::NAN, f64::NAN),
    };
    let (rate, eq, t_eq) = match &out.reduction {
        Some(r) => {
            let rate = r
                .strain_rate_per_s
                .as_ref()
                .map(|s| s.iter().copied().fold(f64::NEG_INFINITY, f64::max))
                .unwrap_or(f64::NAN);
            let t_eq = (0..r.time_s.len())
                .find(|&i| {
                    r.equilibrium_ratio[i] <= 0.05 && r.force_back_n[i] >= 0.1 * r.peak_back_force_n
                })
                .map(|i| r.time_s[i])
                .unwrap_or(f64::NAN);
            (rate, r.equilibrium_ratio_at_peak, t_eq)
        }
        None => (f64::NAN, f64::NAN, f64::NAN),
    };
    // Issue 42: a column a full test cannot give is NaN with the reason in the row's warnings
    // (a kind without a reduction has none of the reduction's columns, documented in README).
    let mut warnings = out.warnings.clone();
    if out.reduction.is_some() {
        for (value, column, why) in [
            (
                rate,
                "peak_strain_rate",
                "the reduction gave no strain rate (no specimen length)",
            ),
            (
                eq,
                "equilibrium_ratio_at_peak",
                "the reduction found no peak back force",
            ),
            (
                t_eq,
                "time_to_equilibrium",
                "the front and back forces never came within 5 % while the back force was \
                 above 10 % of its peak",
            ),
        ] {
            let named = format!("`{column}`");
            if !value.is_finite() && !warnings.iter().any(|w| w.contains(&named)) {
                warnings.push(format!("{named} is not available (NaN): {why}"));
            }
        }
    }
    RunSummary {
        index,
        inputs,
        peak_force_n,
        displacement_at_peak_m,
        peak_strain_rate_per_s: rate,
        equilibrium_ratio_at_peak: eq,
        time_to_equilibrium_s: t_eq,
        warnings,
    }
}

/// Validates every point's scene before any run (bad values fail fast, naming the value) and
/// returns the files the scene resolved for them, each once with its SHA-256 (the scene file
/// first): what the sweep's checkpoint and study file record it belongs to. The first run of the
/// whole sweep is validated too, so a shard without runs still names its files. Serial
/// ([`check_points_on`] on one thread).
pub fn check_points(scene: &Path, axes: &[Axis], points: &[Point]) -> Result<Vec<InputFile>> {
    check_points_on(&thread_pool(1)?, scene, axes, points)
}

/// [`check_points`] in parallel on `pool` (the pool of the runs, issue 45: a serial validation
/// capped a 64-core sweep near 23× by Amdahl's law). The outcome is the serial one: the error of
/// the first invalid point in order (the sweep's first run, then `points`; the points after an
/// invalid one are skipped), else the files in the order the serial loop first read them (by
/// point, then by the order within the point), each with the text first read.
pub fn check_points_on(
    pool: &rayon::ThreadPool,
    scene: &Path,
    axes: &[Axis],
    points: &[Point],
) -> Result<Vec<InputFile>> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    // Item 0 is the sweep's first run, item i ≥ 1 is points[i − 1].
    let first_bad = AtomicUsize::new(usize::MAX);
    let checked = pool.install(|| {
        (0..=points.len())
            .into_par_iter()
            .map(|i| {
                if i > first_bad.load(Ordering::Relaxed) {
                    return Checked::default();
                }
                let first;
                let p = match i {
                    0 => {
                        first = point_at(axes, 0);
                        &first
                    }
                    _ => &points[i - 1],
                };
                let (parsed, read) = shpb_input::files::capture(|| {
                    Params::from_file_overridden(scene, &overrides(axes, p)).map(drop)
                });
                match parsed {
                    Ok(()) => Checked {
                        error: None,
                        files: read
                            .into_iter()
                            .enumerate()
                            .map(|(k, f)| ((i, k), f))
                            .collect(),
                    },
                    Err(e) => {
                        first_bad.fetch_min(i, Ordering::Relaxed);
                        Checked {
                            error: Some((i, e)),
                            files: Vec::new(),
                        }
                    }
                }
            })
            .reduce(Checked::default, Checked::merge)
    });
    if let Some((_, e)) = checked.error {
        return Err(e);
    }
    let mut files = checked.files;
    files.sort_by_key(|(at, _)| *at);
    Ok(files
        .into_iter()
        .filter(|(_, f)| !f.name.starts_with("built-in:"))
        .map(|(_, f)| InputFile {
            path: f.name.into(),
            sha256: shpb_input::provenance::sha256_hex(f.text.as_bytes()),
        })
        .collect())
}

/// What the validation of some points found ([`check_points_on`]): the first error by item and
/// each file read with the first (item, read) that read it.
#[derive(Default)]
struct Checked {
    error: Option<(usize, Error)>,
    files: Vec<((usize, usize), shpb_input::files::InputFile)>,
}

impl Checked {
    /// The union of two validations: the earlier error; each file once, from its earliest read.
    fn merge(mut self, other: Checked) -> Checked {
        if let Some((j, e)) = other.error
            && self.error.as_ref().is_none_or(|(i, _)| j < *i)
        {
            self.error = Some((j, e));
        }
        for (at, f) in other.files {
            match self.files.iter_mut().find(|(_, g)| g.name == f.name) {
                Some(kept) if at < kept.0 => *kept = (at, f),
                Some(_) => {}
                None => self.files.push((at, f)),
            }
        }
        self
    }
}

/// The scene overrides of one point.
pub fn overrides(axes: &[Axis], p: &Point) -> Vec<(String, shpb_input::scene::Value)> {
    axes.iter()
        .zip(&p.coords)
        .map(|(a, &c)| (a.key.clone(), a.values[c].clone()))
        .collect()
}

/// Runs `points` of the sweep on `threads` threads (rayon), calling `done` with each finished
/// run's summary (from the worker thread); the summaries come back in point order whatever the
/// order of completion.
pub fn run_points(
    scene: &Path,
    axes: &[Axis],
    points: &[Point],
    threads: usize,
    done: impl Fn(&RunSummary) + Sync,
) -> Result<Vec<RunSummary>> {
    run_points_on(&thread_pool(threads)?, scene, axes, points, done, &|| true).map(|p| p.rows)
}

/// The rows of many runs that a caller may stop: those finished, in order, and whether the
/// caller stopped the rest (`interrupted`: runs not started and runs stopped mid-way are
/// missing from `rows`).
#[derive(Debug, Clone, PartialEq)]
pub struct Finished<T> {
    /// The finished rows, in order.
    pub rows: Vec<T>,
    /// True when `keep_going` returned false before every run finished.
    pub interrupted: bool,
}

/// Runs `items` on `pool`, `run` giving each one's row; `keep_going` is asked before each run
/// and passed to it (a run asks it every 1 % of its steps, `Params::run_with_progress`): once it
/// returns false no run starts, the running ones stop with `Error::Cancelled`, and the rows
/// finished so far come back with `interrupted` set. Any other error of a run is returned.
pub fn run_until<I: Sync, T: Send>(
    pool: &rayon::ThreadPool,
    items: &[I],
    keep_going: &(dyn Fn() -> bool + Sync),
    run: impl Fn(&I, &mut dyn FnMut(f64) -> bool) -> Result<T> + Sync,
) -> Result<Finished<T>> {
    let results: Vec<Option<T>> = pool.install(|| {
        items
            .par_iter()
            .map(|item| {
                if !keep_going() {
                    return Ok(None);
                }
                match run(item, &mut |_| keep_going()) {
                    Ok(row) => Ok(Some(row)),
                    Err(Error::Interrupted { .. }) if !keep_going() => Ok(None),
                    Err(e) => Err(e),
                }
            })
            .collect::<Result<Vec<_>>>()
    })?;
    let interrupted = results.iter().any(Option::is_none);
    Ok(Finished {
        rows: results.into_iter().flatten().collect(),
        interrupted,
    })
}

/// [`run_points`] that `keep_going` may stop ([`run_until`]): the finished rows and whether it
/// stopped the sweep (how `shpb.sweep` keeps its rows on Ctrl-C).
pub fn run_points_until(
    scene: &Path,
    axes: &[Axis],
    points: &[Point],
    threads: usize,
    done: impl Fn(&RunSummary) + Sync,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<Finished<RunSummary>> {
    run_points_on(
        &thread_pool(threads)?,
        scene,
        axes,
        points,
        done,
        keep_going,
    )
}

/// [`run_points_until`] on a given `pool` (the one [`check_points_on`] validated the points on).
pub fn run_points_on(
    pool: &rayon::ThreadPool,
    scene: &Path,
    axes: &[Axis],
    points: &[Point],
    done: impl Fn(&RunSummary) + Sync,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<Finished<RunSummary>> {
    run_until(pool, points, keep_going, |p, progress| {
        let params = Params::from_file_overridden(scene, &overrides(axes, p))?.summary_only();
        // The scene's warnings first, as `shpb run` prints them (api::run_scene).
        let mut out = params.run_with_progress(progress)?;
        out.warnings.splice(0..0, params.warnings());
        let inputs = axes
            .iter()
            .zip(&p.coords)
            .map(|(a, &c)| a.labels[c].clone())
            .collect();
        let row = summarise(p.index, inputs, &out);
        done(&row);
        Ok(row)
    })
}

/// SI units of a number given without unit for `key`, from the suffix of its name (the scene
/// files' convention: `_m`, `_s`, `_m_s`, `_per_s`, `_pa`, …); `1` for counts and ratios.
pub fn key_units(key: &str) -> &'static str {
    const SUFFIXES: &[(&str, &str)] = &[
        ("_m2_per_s2_per_pa", "m^2/(s^2 Pa)"),
        ("_kg_s", "kg/s"),
        ("_m_s", "m/s"),
        ("_per_s", "1/s"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_m", "m"),
        ("_s", "s"),
        ("_n", "N"),
        ("_j", "J"),
        ("_v", "V"),
    ];
    let k = key.to_ascii_lowercase();
    SUFFIXES
        .iter()
        .find(|(suffix, _)| k.ends_with(suffix))
        .map_or("1", |(_, units)| units)
}

/// One swept value as written (`7psi`, `0.3mm`, `5`) in SI units, with the units: lengths of
/// `_m` keys in m, pressures in Pa (the scene's parser), plain numbers in the units of their key
/// ([`key_units`]); `None` for a name (`hertz`, `fast`, a set-up).
pub fn input_si(key: &str, text: &str) -> Option<(f64, &'static str)> {
    let (v, unit) = number_and_unit(text)?;
    if !v.is_finite() {
        return None;
    }
    if unit.is_empty() {
        return Some((v, key_units(key)));
    }
    if key.ends_with("_m") {
        return LENGTH_UNITS
            .iter()
            .find(|(u, _)| *u == unit)
            .map(|(_, f)| (v * f, "m"));
    }
    shpb_input::units::parse_pressure(text)
        .ok()
        .map(|p| (p, "Pa"))
}

/// The input columns of a study: for each key, its values as written and, when every value is a
/// number of the same units ([`input_si`]), in SI units.
pub fn input_columns(keys: &[String], rows: &[RunSummary]) -> Vec<shpb_output::study::InputColumn> {
    keys.iter()
        .enumerate()
        .map(|(k, key)| {
            let values: Vec<String> = rows
                .iter()
                .filter_map(|r| r.inputs.get(k).cloned())
                .collect();
            let si: Option<Vec<(f64, &str)>> = values.iter().map(|v| input_si(key, v)).collect();
            let si = si.and_then(|si| {
                let units = si.first().map_or(key_units(key), |(_, u)| *u);
                si.iter()
                    .all(|(_, u)| *u == units)
                    .then(|| (si.iter().map(|(v, _)| *v).collect(), units.to_string()))
            });
            shpb_output::study::InputColumn {
                key: key.clone(),
                values,
                si,
            }
        })
        .collect()
}

/// The CSV name of an input column: the key with its units appended (`pressure_Pa`) unless the
/// key already ends with them (`shaper.thickness_m`) or it has none (a count, a name).
pub fn csv_input_name(key: &str, units: &str) -> String {
    let suffix = match units {
        "1" | "" => return key.to_string(),
        "1/s" => "per_s".to_string(),
        "m/s" => "m_s".to_string(),
        "kg/s" => "kg_s".to_string(),
        "m^2/(s^2 Pa)" => "m2_per_s2_per_pa".to_string(),
        u => u.to_string(),
    };
    if key
        .to_ascii_lowercase()
        .ends_with(&format!("_{}", suffix.to_ascii_lowercase()))
    {
        key.to_string()
    } else {
        format!("{key}_{suffix}")
    }
}

/// The summary table as CSV: `run`, one column per swept key (SI numbers with the units in the
/// column name, `pressure_Pa`; names as written), then the summary columns with units; one row
/// per run.
pub fn summary_csv_keys(keys: &[String], rows: &[RunSummary]) -> String {
    let columns = input_columns(keys, rows);
    let mut head = vec!["run".to_string()];
    head.extend(columns.iter().map(|c| match &c.si {
        Some((_, units)) => csv_input_name(&c.key, units),
        None => c.key.clone(),
    }));
    head.extend(
        SUMMARY_COLUMNS
            .iter()
            .map(|(n, u)| shpb_output::io::csv_name(n, u)),
    );
    head.push("warnings".into());
    let mut text = head.join(",");
    text.push('\n');
    for (i, r) in rows.iter().enumerate() {
        let mut cells = vec![r.index.to_string()];
        cells.extend(columns.iter().map(|c| match &c.si {
            Some((si, _)) => format!("{:e}", si[i]),
            None => c.values[i].clone(),
        }));
        cells.extend(r.values().iter().map(|v| format!("{v:e}")));
        cells.push(warnings_cell(&r.warnings));
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    text
}

/// The outputs a sweep writes, for its [`Estimate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Outputs {
    /// An HDF5 study file (`-o`).
    pub hdf5: bool,
    /// A CSV summary (`--csv`).
    pub csv: bool,
    /// A checkpoint (`<output>.partial.csv`, with `-o` or `--csv`).
    pub checkpoint: bool,
}

/// Memory a sweep holds per run until it has written its outputs, bytes (fixed, per swept key):
/// the point, its summary row, its line of the CSV table, its row of the study table and the HDF5
/// library's share while writing `/runs/<index>` (peak RSS of 100 000-run sweeps: ≈ 1.0 kB per
/// run with one or two keys, 1.4 kB with five; rounded up).
pub const MEMORY_PER_RUN: (u128, u128) = (1024, 192);
/// HDF5 bytes per run (fixed, per swept key): its `/summary` row and its `/runs/<index>` group
/// (100 000-run files: ≈ 1.1 kB + 190 B per key), plus a fixed 64 kB.
pub const HDF5_PER_RUN: (u128, u128) = (1600, 256);
/// CSV bytes per row (fixed, per swept key), summary table or checkpoint (≈ 75 B + 20 B per key
/// with values as written, up to 24 B per key in SI numbers).
pub const CSV_PER_RUN: (u128, u128) = (100, 32);
/// The largest number of runs of one sweep: run indices are stored as float64 in
/// `/summary/run`, exact up to 2^53.
pub const MAX_RUNS: u128 = 1 << 53;

/// What a sweep will need, computed from the axes alone before anything is allocated.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Runs of the whole sweep (`None`: beyond `u128`).
    pub runs_total: Option<u128>,
    /// Runs of this shard (all of them without `--shard`).
    pub runs: u128,
    /// Memory held until the outputs are written, bytes (the runs' own working memory aside).
    pub memory_bytes: u128,
    /// Bytes written: (name, size) per output.
    pub outputs: Vec<(&'static str, u128)>,
}

/// What the machine allows a sweep, with where each limit comes from (for the message).
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Memory a sweep may hold, bytes.
    pub memory_bytes: u64,
    /// Where the memory limit comes from (`half of MemAvailable in /proc/meminfo`).
    pub memory_basis: String,
    /// Disk space the outputs may take, bytes (`None`: unknown, not checked).
    pub disk_bytes: Option<u64>,
    /// Where the disk limit comes from (`free space in DIR`).
    pub disk_basis: String,
}

impl Limits {
    /// What the machine allows a sweep: half the memory available (MemAvailable in /proc/meminfo,
    /// or what the cgroup still allows if less; the runs themselves need the rest) and the free disk
    /// space where the outputs go.
    pub fn of_machine(outputs: &[&std::path::Path]) -> Limits {
        let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
            t.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
                .map(|kb| kb * 1024)
        });
        let read =
            |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
        let cgroup = read("/sys/fs/cgroup/memory.max")
            .zip(read("/sys/fs/cgroup/memory.current"))
            .or_else(|| {
                read("/sys/fs/cgroup/memory/memory.limit_in_bytes")
                    .zip(read("/sys/fs/cgroup/memory/memory.usage_in_bytes"))
            })
            .map(|(max, used)| max.saturating_sub(used));
        let (available, basis) = match (meminfo, cgroup) {
            (Some(m), Some(c)) if c < m => (c, "half of what the memory cgroup still allows"),
            (Some(m), _) => (m, "half of MemAvailable in /proc/meminfo"),
            (None, Some(c)) => (c, "half of what the memory cgroup still allows"),
            (None, None) => (8 << 30, "half of an assumed 8 GiB (no /proc/meminfo)"),
        };
        let mut disk: Option<(u64, String)> = None;
        for p in outputs {
            let dir = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(std::path::Path::new("."));
            if let Some(free) = shpb_output::atomic::free_space(dir)
                && disk.as_ref().is_none_or(|(d, _)| free < *d)
            {
                disk = Some((free, format!("free space in {}", dir.display())));
            }
        }
        Limits {
            memory_bytes: available / 2,
            memory_basis: basis.to_string(),
            disk_bytes: disk.as_ref().map(|(d, _)| *d),
            disk_basis: disk.map(|(_, b)| b).unwrap_or_default(),
        }
    }
}

/// Estimates a sweep of `axes`, shard `k` of `n`, writing `outputs`.
pub fn estimate(axes: &[Axis], (k, n): (usize, usize), outputs: Outputs) -> Estimate {
    let runs_total = run_count(axes);
    let runs = shard_run_count(runs_total.unwrap_or(u128::MAX), k, n);
    let per = |(fixed, per_key): (u128, u128)| fixed + per_key * axes.len() as u128;
    let times = |bytes: u128| runs.saturating_mul(bytes);
    let mut out = Vec::new();
    if outputs.hdf5 {
        out.push(("HDF5", times(per(HDF5_PER_RUN)).saturating_add(65_536)));
    }
    if outputs.csv {
        out.push(("CSV", times(per(CSV_PER_RUN))));
    }
    if outputs.checkpoint {
        out.push(("checkpoint", times(per(CSV_PER_RUN))));
    }
    Estimate {
        runs_total,
        runs,
        memory_bytes: times(per(MEMORY_PER_RUN)),
        outputs: out,
    }
}

/// A number of bytes as a person reads it: `512 B`, `3.2 MB`, `320 GB` (powers of 1000).
pub fn human_bytes(b: u128) -> String {
    const UNITS: [&str; 7] = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1000.0 && u < UNITS.len() - 1 {
        v /= 1000.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else if v >= 1000.0 {
        format!("{:.1e} B", b as f64)
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

impl Estimate {
    /// Bytes written by all outputs.
    pub fn output_bytes(&self) -> u128 {
        self.outputs
            .iter()
            .map(|(_, b)| *b)
            .fold(0, u128::saturating_add)
    }

    /// Refuses (an input error, exit 2) a sweep that cannot finish within `limits`: more runs
    /// than [`MAX_RUNS`], more memory than the limit, more output than the free disk space. The
    /// message gives the estimate, the limits, where they come from and the number of shards
    /// that would fit.
    pub fn check(&self, limits: &Limits) -> Result<()> {
        let memory_ok = self.memory_bytes <= limits.memory_bytes as u128;
        let disk_ok = limits
            .disk_bytes
            .is_none_or(|d| self.output_bytes() <= d as u128);
        let runs_ok = self.runs_total.is_some_and(|t| t <= MAX_RUNS);
        if memory_ok && disk_ok && runs_ok {
            return Ok(());
        }
        let total = match self.runs_total {
            Some(t) => format!("{t}"),
            None => format!("more than {}", u128::MAX),
        };
        let outputs = if self.outputs.is_empty() {
            "no output file".to_string()
        } else {
            format!(
                "{} of output ({})",
                human_bytes(self.output_bytes()),
                self.outputs
                    .iter()
                    .map(|(n, b)| format!("{n} {}", human_bytes(*b)))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        // Shards needed for one to fit in memory and on disk.
        let need = |used: u128, limit: u128| used.div_ceil(limit.max(1));
        let mut shards = need(self.memory_bytes, limits.memory_bytes as u128);
        if let Some(d) = limits.disk_bytes {
            shards = shards.max(need(self.output_bytes(), d as u128));
        }
        let disk = match limits.disk_bytes {
            _ if self.outputs.is_empty() => String::new(),
            Some(d) => format!(
                ", at most {} of output ({})",
                human_bytes(d as u128),
                limits.disk_basis
            ),
            None => ", output size not checked (free space unknown)".to_string(),
        };
        Err(Error::Input {
            file: "command line".into(),
            key: "--set".into(),
            problem: format!(
                "the sweep cannot finish on this machine: {total} runs{}, estimated {} of memory \
                 and {outputs}",
                if self.runs_total == Some(self.runs) {
                    String::new()
                } else {
                    format!(" ({} in this shard)", self.runs)
                },
                human_bytes(self.memory_bytes),
            ),
            allowed: format!(
                "at most {} of memory ({}; about {} B per run){disk}, at most 2^53 runs \
                 (run indices are float64); fewer values{}",
                human_bytes(limits.memory_bytes as u128),
                limits.memory_basis,
                self.memory_bytes / self.runs.max(1),
                if runs_ok && shards > 1 {
                    format!(", or --shard k/{shards} (each shard on its own)")
                } else {
                    String::new()
                }
            ),
        })
    }
}

/// The checkpoint of a sweep: finished runs, one CSV line each, appended and flushed as they
/// finish, so an interrupted sweep (Ctrl-C, a killed job) loses only the runs in flight.
/// Its header is the sweep's [`Stamp`] (scene and input files by SHA-256, `--set`, shard, shpb
/// version); `--resume` refuses a checkpoint of another sweep and names what differs. The file
/// is locked while a sweep writes it, so a second sweep on the same output is refused instead of
/// duplicating runs. Values are written in Rust's shortest round-trip form, so a resumed sweep
/// reproduces the uninterrupted one bit for bit; a line without its end (a torn write) is
/// dropped.
pub struct Checkpoint {
    /// The checkpoint file.
    pub path: std::path::PathBuf,
    file: std::sync::Mutex<std::fs::File>,
}

/// The checkpoint path of a sweep writing `output`: `<output>.partial.csv`.
pub fn checkpoint_path(output: &Path) -> std::path::PathBuf {
    let mut name = output.as_os_str().to_owned();
    name.push(".partial.csv");
    std::path::PathBuf::from(name)
}

fn row_line(r: &RunSummary) -> String {
    let mut cells = vec![r.index.to_string()];
    cells.extend(r.inputs.iter().cloned());
    cells.extend(r.values().iter().map(|v| format!("{v:e}")));
    cells.push(warnings_cell(&r.warnings));
    cells.join(",") + "\n"
}

fn parse_row(line: &str, n_inputs: usize) -> Option<RunSummary> {
    let cells = split_csv_line(line);
    if cells.len() != 2 + n_inputs + SUMMARY_COLUMNS.len() {
        return None;
    }
    let (cells, warnings) = cells.split_at(cells.len() - 1);
    let index = cells[0].parse().ok()?;
    let inputs = cells[1..=n_inputs].iter().map(|c| c.to_string()).collect();
    let v: Vec<f64> = cells[1 + n_inputs..]
        .iter()
        .map(|c| c.parse().ok())
        .collect::<Option<_>>()?;
    let mut row = RunSummary::from_values(index, inputs, [v[0], v[1], v[2], v[3], v[4]]);
    row.warnings = warnings_of_cell(&warnings[0]);
    Some(row)
}

/// Whether run `index` belongs to the shard of `stamp`.
fn in_shard(stamp: &Stamp, index: usize) -> bool {
    let (k, n) = stamp.identity.shard;
    (index as u64) < stamp.identity.runs_total && index as u64 % n == k - 1
}

/// The finished runs of a checkpoint's text after its header: complete lines (ending with a
/// line end) of runs of the shard, each run once.
fn checkpoint_rows(text: &str, stamp: &Stamp, n_inputs: usize) -> Vec<RunSummary> {
    let mut seen = std::collections::HashSet::new();
    text.split_inclusive('\n')
        .filter(|l| l.ends_with('\n') && !l.starts_with('#'))
        .filter_map(|l| parse_row(l.trim_end_matches(['\n', '\r']), n_inputs))
        .filter(|r| in_shard(stamp, r.index) && seen.insert(r.index))
        .collect()
}

/// Opens `path` for reading and writing (creating it) and locks it exclusively; refuses when
/// another process holds the lock.
fn open_locked(path: &Path) -> Result<std::fs::File> {
    use std::os::unix::fs::MetadataExt;
    for _ in 0..10 {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(Error::Input {
                    file: path.display().to_string(),
                    key: "output".into(),
                    problem: "another `shpb sweep` is writing this checkpoint (it is locked)"
                        .into(),
                    allowed: "one sweep per output at a time: wait for it to finish (then \
                              --resume says whether it is complete), or give another -o/--csv"
                        .into(),
                });
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(Error::io(path, e)),
        }
        // The sweep that held the lock may have finished and removed the file meanwhile: the
        // lock must be on the file that is at `path` now.
        let held = file.metadata().map_err(|e| Error::io(path, e))?;
        match std::fs::metadata(path) {
            Ok(now) if now.dev() == held.dev() && now.ino() == held.ino() => return Ok(file),
            _ => continue,
        }
    }
    Err(Error::io(
        path,
        std::io::Error::other("the checkpoint kept being replaced while it was opened"),
    ))
}

impl Checkpoint {
    /// Opens and locks the checkpoint of `output` for the sweep stamped `stamp`. With `resume`,
    /// an existing checkpoint must be of the same sweep and shard (else an input error naming
    /// what differs) and its finished runs are returned (`Some`). Without, an existing checkpoint
    /// is refused unless `force` (then the sweep starts afresh). `None`: no checkpoint was taken
    /// over.
    pub fn open(
        output: &Path,
        stamp: &Stamp,
        n_inputs: usize,
        resume: bool,
        force: bool,
    ) -> Result<(Checkpoint, Option<Vec<RunSummary>>)> {
        use std::io::{Read, Seek, Write};
        let path = checkpoint_path(output);
        let mut file = open_locked(&path)?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)
            .map_err(|e| Error::io(&path, e))?;
        let text = String::from_utf8_lossy(&bytes);
        let mut finished = None;
        if !text.is_empty() {
            if resume {
                let header = text.lines().take_while(|l| l.starts_with('#'));
                let Some(then) = Stamp::from_checkpoint_header(header) else {
                    return Err(Error::Input {
                        file: path.display().to_string(),
                        key: "--resume".into(),
                        problem: "the checkpoint does not say which sweep it belongs to \
                                  (written by an older shpb, or damaged)"
                            .into(),
                        allowed: "a checkpoint of this shpb; or start afresh with --force \
                                  (without --resume)"
                            .into(),
                    });
                };
                let differences = then.differences(stamp);
                if !differences.is_empty() {
                    return Err(Error::Input {
                        file: path.display().to_string(),
                        key: "--resume".into(),
                        problem: format!(
                            "the checkpoint belongs to another sweep; what differs: {}",
                            differences.join("; ")
                        ),
                        allowed: "the same scene, set-up files, --set, --shard and shpb version \
                                  as the interrupted sweep; or start afresh with --force (without \
                                  --resume)"
                            .into(),
                    });
                }
                finished = Some(checkpoint_rows(&text, stamp, n_inputs));
            } else if !force {
                return Err(Error::Input {
                    file: path.display().to_string(),
                    key: "output".into(),
                    problem: "an interrupted sweep left this checkpoint".into(),
                    allowed: "--resume to continue it, or --force to start afresh".into(),
                });
            }
        }
        let written = if finished.is_some() {
            // Resumed: the runs stay where they are (a stop now loses none of them); only a torn
            // last line is cut off, and new runs are appended.
            let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            file.set_len(complete as u64)
                .and_then(|_| file.seek(std::io::SeekFrom::End(0)).map(|_| ()))
        } else {
            // A fresh start: the header of this sweep.
            file.set_len(0)
                .and_then(|_| file.rewind())
                .and_then(|_| file.write_all(stamp.checkpoint_header().as_bytes()))
                .and_then(|_| file.flush())
        };
        written.map_err(|e| Error::io(&path, e))?;
        Ok((
            Checkpoint {
                path,
                file: std::sync::Mutex::new(file),
            },
            finished,
        ))
    }

    /// Appends one finished run (one write of a whole line, then flush).
    pub fn record(&self, r: &RunSummary) -> Result<()> {
        use std::io::Write;
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.write_all(row_line(r).as_bytes())
            .and_then(|_| f.flush())
            .map_err(|e| Error::io(&self.path, e))
    }

    /// Removes the checkpoint once the outputs are written (still holding its lock, so no other
    /// sweep takes it over in between).
    pub fn finish(self) -> Result<()> {
        let removed = std::fs::remove_file(&self.path).map_err(|e| Error::io(&self.path, e));
        drop(self.file);
        removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specs(s: &[&str]) -> Vec<String> {
        s.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_row_s_warnings_survive_the_checkpoint_line() {
        // Warnings hold commas and quotes: one quoted cell (RFC 4180), read back as written.
        let mut r = RunSummary::from_values(3, vec!["7psi".into()], [1.0, 2.0, 3.0, 4.0, 5.0]);
        r.warnings = vec![
            "gun pressure 7 psi is outside 10 to 15 psi, the pressures".into(),
            "a \"quoted\" word".into(),
        ];
        let line = row_line(&r);
        let back = parse_row(line.trim_end(), 1).unwrap();
        assert_eq!(back, r);
        let none = RunSummary::from_values(4, vec!["8psi".into()], [1.0; 5]);
        assert!(row_line(&none).ends_with(",\n"));
        assert_eq!(parse_row(row_line(&none).trim_end(), 1).unwrap(), none);
        assert_eq!(split_csv_line("a,\"b, c\",\"\""), ["a", "b, c", ""]);
    }

    fn shipped_scene(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes")
            .join(name)
    }

    /// The validation before issue 45, one point after the other on this thread: the
    /// definition the parallel one must reproduce.
    fn serial_check(scene: &Path, axes: &[Axis], points: &[Point]) -> Result<Vec<InputFile>> {
        let (checked, files) = shpb_input::provenance::recording(|| -> Result<()> {
            Params::from_file_overridden(scene, &overrides(axes, &point_at(axes, 0)))?;
            for p in points {
                Params::from_file_overridden(scene, &overrides(axes, p))?;
            }
            Ok(())
        });
        checked.map(|()| files)
    }

    #[test]
    fn points_validated_in_parallel_give_the_serial_files_and_first_error() {
        let scene = shipped_scene("shpb-ss440c-10psi.toml");
        let pools = [thread_pool(1).unwrap(), thread_pool(2).unwrap()];
        // Valid points: the same files (scene first, then the set-up and gauge files as first
        // read, the second set-up from the second point on), with the same SHA-256, on one
        // thread or two.
        let good = parse_axes(&specs(&[
            "pressure=8psi:12psi:5",
            "bars=../bars/authors.toml,../bars/authors-20cm-striker.toml",
        ]))
        .unwrap();
        let points = product(&good);
        let want = serial_check(&scene, &good, &points).unwrap();
        assert!(want.len() >= 3, "{want:?}");
        assert_eq!(want[0].path, scene);
        assert!(
            want[want.len() - 1]
                .path
                .ends_with("bars/authors-20cm-striker.toml")
        );
        for pool in &pools {
            assert_eq!(check_points_on(pool, &scene, &good, &points).unwrap(), want);
        }
        assert_eq!(check_points(&scene, &good, &points).unwrap(), want);
        // A shard without runs still names the files of the sweep's first run.
        let none = shard_points(&good, 25, 30);
        assert!(none.is_empty());
        assert_eq!(
            check_points_on(&pools[1], &scene, &good, &none).unwrap(),
            serial_check(&scene, &good, &none).unwrap()
        );
        // Several invalid points, the first late in the product: the error of the first one in
        // order, exactly (text and exit code), whichever thread met which point first.
        let bad = parse_axes(&specs(&[
            "shaper.thickness=0.5mm,0.4mm,0.3mm,-1mm,0.2mm,-2mm,-3mm",
        ]))
        .unwrap();
        let points = product(&bad);
        let want = serial_check(&scene, &bad, &points).unwrap_err();
        assert!(want.to_string().contains("-1 mm is out of range"), "{want}");
        for pool in &pools {
            for _ in 0..3 {
                let e = check_points_on(pool, &scene, &bad, &points).unwrap_err();
                assert_eq!(
                    (e.to_string(), e.exit_code()),
                    (want.to_string(), want.exit_code())
                );
            }
        }
        // An invalid first run of the sweep is reported for any shard, as before.
        let shard = shard_points(&bad, 2, 3);
        let e = check_points_on(&pools[1], &scene, &bad, &shard);
        let want = serial_check(&scene, &bad, &shard);
        assert_eq!(
            e.map_err(|e| e.to_string()),
            want.map_err(|e| e.to_string())
        );
    }

    #[test]
    fn a_key_set_twice_is_an_error_naming_it() {
        for set in [
            &["pressure=7psi,8psi", "pressure=9psi"][..],
            &["striker.pressure=7psi,8psi", "pressure=9psi"],
            &[
                "shaper.thickness=1mm",
                "fidelity=fast",
                "shaper.thickness_m=2mm",
            ],
        ] {
            let e = parse_axes(&specs(set)).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            let text = e.to_string();
            assert!(text.contains("set twice"), "{text}");
            assert!(text.contains(set[set.len() - 1]), "{text}");
        }
        assert_eq!(
            parse_axes(&specs(&["pressure=7psi", "fidelity=fast"]))
                .unwrap()
                .len(),
            2
        );
    }

    #[test]
    fn swept_values_convert_to_si_units() {
        let (pa, units) = input_si("pressure", "7psi").unwrap();
        assert_eq!(units, "Pa");
        assert!((pa - 7.0 * shpb_input::units::PSI_PA).abs() < 1e-3, "{pa}");
        assert_eq!(input_si("shaper.thickness_m", "0.3mm"), Some((0.3e-3, "m")));
        assert_eq!(input_si("shaper.thickness_m", "3e-4"), Some((3e-4, "m")));
        assert_eq!(input_si("velocity1_m_s", "5"), Some((5.0, "m/s")));
        assert_eq!(input_si("strain_rate_per_s", "1e4"), Some((1e4, "1/s")));
        assert_eq!(input_si("shaper.sigma0_pa", "2e8"), Some((2e8, "Pa")));
        assert_eq!(input_si("points", "11"), Some((11.0, "1")));
        assert_eq!(input_si("law", "hertz"), None);
        assert_eq!(input_si("fidelity", "fast"), None);
        assert_eq!(input_si("bars", "../bars/authors.toml"), None);
        assert_eq!(csv_input_name("pressure", "Pa"), "pressure_Pa");
        assert_eq!(
            csv_input_name("shaper.thickness_m", "m"),
            "shaper.thickness_m"
        );
        assert_eq!(csv_input_name("shaper.sigma0_pa", "Pa"), "shaper.sigma0_pa");
        assert_eq!(csv_input_name("velocity1_m_s", "m/s"), "velocity1_m_s");
        assert_eq!(csv_input_name("points", "1"), "points");
        // A whole number is a TOML integer (a count takes no float).
        let p = parse_axis("points=11,21").unwrap();
        assert_eq!(p.values[0], shpb_input::scene::Value::Integer(11));
    }

    #[test]
    fn the_summary_csv_has_si_inputs_with_units_in_the_header() {
        let row = |index, inputs: &[&str]| RunSummary {
            index,
            inputs: inputs.iter().map(|s| s.to_string()).collect(),
            peak_force_n: 1.0,
            displacement_at_peak_m: 2.0,
            peak_strain_rate_per_s: 3.0,
            equilibrium_ratio_at_peak: 4.0,
            time_to_equilibrium_s: 5.0,
            warnings: Vec::new(),
        };
        let keys = specs(&["pressure", "shaper.thickness_m", "law"]);
        let text = summary_csv_keys(
            &keys,
            &[
                row(0, &["7psi", "0.3mm", "hertz"]),
                row(1, &["10psi", "0.5mm", "hertz"]),
            ],
        );
        let mut lines = text.lines();
        assert_eq!(
            lines.next().unwrap(),
            "run,pressure_Pa,shaper.thickness_m,law,peak_force_N,displacement_at_peak_m,\
             peak_strain_rate_per_s,equilibrium_ratio_at_peak_1,time_to_equilibrium_s,warnings"
        );
        let cells: Vec<&str> = lines.next().unwrap().split(',').collect();
        let pa: f64 = cells[1].parse().unwrap();
        assert!((pa - 7.0 * shpb_input::units::PSI_PA).abs() < 1e-3);
        assert_eq!(cells[2].parse::<f64>().unwrap(), 3e-4);
        assert_eq!(cells[3], "hertz");
    }

    #[test]
    fn shards_are_built_without_the_whole_product() {
        let axes: Vec<Axis> = ["a=1:2:7", "b=1,2,3"]
            .iter()
            .map(|s| parse_axis(s).unwrap())
            .collect();
        assert_eq!(run_count(&axes), Some(21));
        let all = product(&axes);
        for (k, n) in [(1, 1), (1, 4), (3, 4), (4, 4), (5, 30)] {
            let s = shard_points(&axes, k, n);
            assert_eq!(s, shard(all.clone(), k, n));
            assert_eq!(s.len() as u128, shard_run_count(21, k, n));
        }
        let huge: Vec<Axis> = (0..9)
            .map(|i| parse_axis(&format!("k{i}=1:2:100000")).unwrap())
            .collect();
        assert_eq!(run_count(&huge), None, "10^45 runs overflow u128");
    }

    fn limits(memory: u64, disk: Option<u64>) -> Limits {
        Limits {
            memory_bytes: memory,
            memory_basis: "half of MemAvailable in /proc/meminfo".into(),
            disk_bytes: disk,
            disk_basis: "free space in .".into(),
        }
    }

    #[test]
    fn a_sweep_that_cannot_finish_is_refused_with_the_estimate_and_the_limit() {
        let axes: Vec<Axis> = [
            "pressure=7psi:22psi:100000",
            "shaper.thickness=0.3mm:0.6mm:100000",
        ]
        .iter()
        .map(|s| parse_axis(s).unwrap())
        .collect();
        let outputs = Outputs {
            hdf5: true,
            csv: false,
            checkpoint: true,
        };
        let e = estimate(&axes, (1, 1), outputs);
        assert_eq!(e.runs_total, Some(10_000_000_000));
        let err = e.check(&limits(8 << 30, Some(100 << 30))).unwrap_err();
        assert_eq!(err.exit_code(), 2);
        let text = err.to_string();
        for part in [
            "10000000000 runs",
            "TB of memory",
            "HDF5",
            "at most 8.6 GB of memory",
            "MemAvailable",
            "107.4 GB of output",
            "--shard",
        ] {
            assert!(text.contains(part), "{part}: {text}");
        }
        // A study of 64 runs passes; so does a shard of the large one that fits.
        let small: Vec<Axis> = ["pressure=7psi:22psi:16", "shaper.thickness=0.3mm:0.6mm:4"]
            .iter()
            .map(|s| parse_axis(s).unwrap())
            .collect();
        estimate(&small, (1, 1), outputs)
            .check(&limits(8 << 30, Some(100 << 30)))
            .unwrap();
        let shard = estimate(&axes, (1, 100_000), outputs);
        assert_eq!(shard.runs, 100_000);
        shard.check(&limits(8 << 30, Some(100 << 30))).unwrap();
        // Disk alone, and a count beyond u128.
        let disk = estimate(&small, (1, 1), outputs).check(&limits(8 << 30, Some(1000)));
        assert!(disk.unwrap_err().to_string().contains("free space in ."));
        let huge: Vec<Axis> = (0..9)
            .map(|i| parse_axis(&format!("k{i}=1:2:100000")).unwrap())
            .collect();
        let text = estimate(&huge, (1, 1), Outputs::default())
            .check(&limits(8 << 30, None))
            .unwrap_err()
            .to_string();
        assert!(text.contains("more than"), "{text}");
    }

    fn stamp(scene: &str, shard: (usize, usize)) -> Stamp {
        let set = specs(&["velocity1_m_s=1,2,3,4"]);
        let axes = parse_axes(&set).unwrap();
        let file = InputFile {
            path: "s.toml".into(),
            sha256: shpb_input::provenance::sha256_hex(scene.as_bytes()),
        };
        Stamp::new(
            Path::new("s.toml"),
            &[file],
            &set,
            axes_sha256(&axes),
            shard,
            4,
        )
    }

    fn row(index: usize) -> RunSummary {
        RunSummary {
            index,
            inputs: vec![format!("{}", index + 1)],
            peak_force_n: 1e3 + index as f64,
            displacement_at_peak_m: 1e-4,
            peak_strain_rate_per_s: f64::NAN,
            equilibrium_ratio_at_peak: f64::NAN,
            time_to_equilibrium_s: f64::NAN,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn a_checkpoint_is_resumed_only_by_its_own_sweep_and_by_one_process() {
        let dir = std::env::temp_dir().join(format!("shpb-checkpoint-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("out.h5");
        let a = stamp("kind = 1", (1, 1));
        let (c, resumed) = Checkpoint::open(&out, &a, 1, false, false).unwrap();
        assert_eq!(resumed, None);
        // A second sweep on the same output is refused while the first holds it.
        let e = Checkpoint::open(&out, &a, 1, true, false).err().unwrap();
        assert!(e.to_string().contains("locked"), "{e}");
        c.record(&row(0)).unwrap();
        c.record(&row(2)).unwrap();
        drop(c);
        // A torn last line and a duplicated line are dropped.
        let path = checkpoint_path(&out);
        let mut text = std::fs::read_to_string(&path).unwrap();
        text.push_str(&row_line(&row(0)));
        text.push_str("3,4,1.5e3");
        std::fs::write(&path, text).unwrap();
        // Another scene: refused, naming it; the checkpoint is kept.
        let e = Checkpoint::open(&out, &stamp("kind = 2", (1, 1)), 1, true, false)
            .err()
            .unwrap();
        assert_eq!(e.exit_code(), 2);
        assert!(
            e.to_string().contains("the content of the scene s.toml"),
            "{e}"
        );
        // Another shard of the same sweep: refused too.
        let e = Checkpoint::open(&out, &stamp("kind = 1", (1, 2)), 1, true, false)
            .err()
            .unwrap();
        assert!(
            e.to_string().contains("the shard (1/1 then, 1/2 now)"),
            "{e}"
        );
        // Without --resume or --force: refused.
        assert!(Checkpoint::open(&out, &a, 1, false, false).is_err());
        let (c, resumed) = Checkpoint::open(&out, &a, 1, true, false).unwrap();
        let resumed = resumed.unwrap();
        assert_eq!(resumed.iter().map(|r| r.index).collect::<Vec<_>>(), [0, 2]);
        assert_eq!(resumed[1].peak_force_n, 1002.0);
        c.finish().unwrap();
        assert!(!path.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

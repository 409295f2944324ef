//! Design studies: a scene run over the Cartesian product of swept parameters, in parallel
//! (rayon), with a summary row per run (peak force, displacement at peak, peak strain rate,
//! equilibrium ratio, time to equilibrium) and deterministic shards.

use rayon::prelude::*;
use shpb_core::run::RunOutput;
use shpb_core::scene::Params;
use shpb_input::prelude::*;
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

/// Splits `12.5psi` into (12.5, "psi"); None when it does not start with a number.
pub fn number_and_unit(text: &str) -> Option<(f64, String)> {
    let t = text.trim();
    let split = t
        .char_indices()
        .find(|(_, c)| !(c.is_ascii_digit() || "+-.eE".contains(*c)))
        .map(|(i, _)| i)
        .unwrap_or(t.len());
    // A trailing `e`/`E` belongs to the unit when no exponent digits follow.
    let (mut num, mut unit) = t.split_at(split);
    while num.ends_with(['e', 'E', '+', '-']) {
        let k = num.len() - 1;
        unit = &t[k..];
        num = &t[..k];
    }
    let value: f64 = num.parse().ok()?;
    Some((value, unit.trim().to_string()))
}

/// The TOML value of one text value of `key`: lengths in m for `_m` keys, numbers as floats,
/// anything else (a pressure with unit, a law name) as a string the scene validates.
fn value_of(key: &str, text: &str, spec: &str) -> Result<shpb_input::scene::Value> {
    match number_and_unit(text) {
        Some((v, _)) if !v.is_finite() => Err(bad_set(spec, format!("{text}: not finite"))),
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

/// One run of a sweep: its index in the full product and its coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Index in the Cartesian product (last axis fastest).
    pub index: usize,
    /// Index along each axis.
    pub coords: Vec<usize>,
}

/// The Cartesian product of the axes, last axis fastest.
pub fn product(axes: &[Axis]) -> Vec<Point> {
    let total: usize = axes.iter().map(|a| a.values.len()).product();
    (0..total)
        .map(|index| {
            let mut rest = index;
            let mut coords = vec![0; axes.len()];
            for (k, a) in axes.iter().enumerate().rev() {
                coords[k] = rest % a.values.len();
                rest /= a.values.len();
            }
            Point { index, coords }
        })
        .collect()
}

/// The runs of shard `k` of `n` (1-based `k`): every n-th run starting at k − 1, so shards are
/// balanced across the product and their union is the whole sweep.
pub fn shard(points: Vec<Point>, k: usize, n: usize) -> Vec<Point> {
    points
        .into_iter()
        .filter(|p| p.index % n == k - 1)
        .collect()
}

/// Parses `--shard k/n`.
pub fn parse_shard(text: &str) -> Result<(usize, usize)> {
    let err = || Error::Input {
        file: "command line".into(),
        key: "--shard".into(),
        problem: format!("`{text}`"),
        allowed: "k/n with 1 ≤ k ≤ n, e.g. 2/4".into(),
    };
    let (k, n) = text.split_once('/').ok_or_else(err)?;
    let (k, n): (usize, usize) = (
        k.trim().parse().map_err(|_| err())?,
        n.trim().parse().map_err(|_| err())?,
    );
    if k == 0 || n == 0 || k > n {
        return Err(err());
    }
    Ok((k, n))
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
}

/// Summary columns with units.
pub const SUMMARY_COLUMNS: [(&str, &str); 5] = [
    ("peak_force", "N"),
    ("displacement_at_peak", "m"),
    ("peak_strain_rate", "1/s"),
    ("equilibrium_ratio_at_peak", "1"),
    ("time_to_equilibrium", "s"),
];

impl RunSummary {
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
    RunSummary {
        index,
        inputs,
        peak_force_n,
        displacement_at_peak_m,
        peak_strain_rate_per_s: rate,
        equilibrium_ratio_at_peak: eq,
        time_to_equilibrium_s: t_eq,
    }
}

/// Validates every point's scene before any run (bad values fail fast, naming the value).
pub fn check_points(scene: &Path, axes: &[Axis], points: &[Point]) -> Result<()> {
    for p in points {
        Params::from_file_overridden(scene, &overrides(axes, p))?;
    }
    Ok(())
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| Error::Input {
            file: "command line".into(),
            key: "-j".into(),
            problem: e.to_string(),
            allowed: "a thread count from 1 up".into(),
        })?;
    pool.install(|| {
        points
            .par_iter()
            .map(|p| {
                let params = Params::from_file_overridden(scene, &overrides(axes, p))?;
                let out = params.run()?;
                let inputs = axes
                    .iter()
                    .zip(&p.coords)
                    .map(|(a, &c)| a.labels[c].clone())
                    .collect();
                let row = summarise(p.index, inputs, &out);
                done(&row);
                Ok(row)
            })
            .collect::<Result<Vec<_>>>()
    })
}

/// The summary table as CSV: `run`, one column per swept key, then the summary columns with
/// units; one row per run.
pub fn summary_csv_keys(keys: &[String], rows: &[RunSummary]) -> String {
    let mut head = vec!["run".to_string()];
    head.extend(keys.iter().cloned());
    head.extend(
        SUMMARY_COLUMNS
            .iter()
            .map(|(n, u)| shpb_output::io::csv_name(n, u)),
    );
    let mut text = head.join(",");
    text.push('\n');
    for r in rows {
        text.push_str(&row_line(r));
    }
    text
}

/// The checkpoint of a sweep: finished runs, one CSV line each, appended and flushed as they
/// finish, so an interrupted sweep (Ctrl-C, a killed job) loses only the runs in flight.
/// Its first line identifies the sweep (scene and `--set` specifications); `--resume` refuses a
/// checkpoint of another sweep. Values are written in Rust's shortest round-trip form, so a
/// resumed sweep reproduces the uninterrupted one bit for bit.
pub struct Checkpoint {
    /// The checkpoint file.
    pub path: std::path::PathBuf,
    file: std::sync::Mutex<std::fs::File>,
}

/// The identifying first line of a checkpoint.
fn checkpoint_header(scene: &Path, set: &[String]) -> String {
    format!(
        "# shpb sweep checkpoint; scene={}; set={}",
        scene.display(),
        set.join(" ; ")
    )
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
    cells.join(",") + "\n"
}

fn parse_row(line: &str, n_inputs: usize) -> Option<RunSummary> {
    let cells: Vec<&str> = line.split(',').collect();
    if cells.len() != 1 + n_inputs + SUMMARY_COLUMNS.len() {
        return None;
    }
    let index = cells[0].parse().ok()?;
    let inputs = cells[1..=n_inputs].iter().map(|c| c.to_string()).collect();
    let v: Vec<f64> = cells[1 + n_inputs..]
        .iter()
        .map(|c| c.parse().ok())
        .collect::<Option<_>>()?;
    Some(RunSummary {
        index,
        inputs,
        peak_force_n: v[0],
        displacement_at_peak_m: v[1],
        peak_strain_rate_per_s: v[2],
        equilibrium_ratio_at_peak: v[3],
        time_to_equilibrium_s: v[4],
    })
}

impl Checkpoint {
    /// Opens the checkpoint of `output`: with `resume`, reads the finished runs of an existing
    /// one (it must belong to the same sweep; a torn last line is dropped); without, refuses an
    /// existing one unless `force` (then starts afresh).
    pub fn open(
        output: &Path,
        scene: &Path,
        set: &[String],
        n_inputs: usize,
        resume: bool,
        force: bool,
    ) -> Result<(Checkpoint, Vec<RunSummary>)> {
        use std::io::Write;
        let path = checkpoint_path(output);
        let header = checkpoint_header(scene, set);
        let mut finished = Vec::new();
        let exists = path.is_file();
        if exists && resume {
            let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
            let mut lines = text.lines();
            if lines.next() != Some(header.as_str()) {
                return Err(Error::Input {
                    file: path.display().to_string(),
                    key: "--resume".into(),
                    problem: "the checkpoint belongs to another sweep (scene or --set differ)".into(),
                    allowed: "the same scene and --set values as the interrupted sweep, or --force to start afresh".into(),
                });
            }
            finished = lines.filter_map(|l| parse_row(l, n_inputs)).collect();
        } else if exists && !force {
            return Err(Error::Input {
                file: path.display().to_string(),
                key: "output".into(),
                problem: "an interrupted sweep left this checkpoint".into(),
                allowed: "--resume to continue it, or --force to start afresh".into(),
            });
        }
        // Rewrite the checkpoint with the header and the complete rows (drops a torn line).
        let mut text = header + "\n";
        for r in &finished {
            text.push_str(&row_line(r));
        }
        std::fs::write(&path, &text).map_err(|e| Error::io(&path, e))?;
        let mut file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| Error::io(&path, e))?;
        file.flush().map_err(|e| Error::io(&path, e))?;
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

    /// Removes the checkpoint once the outputs are written.
    pub fn finish(self) -> Result<()> {
        drop(self.file);
        std::fs::remove_file(&self.path).map_err(|e| Error::io(&self.path, e))
    }
}

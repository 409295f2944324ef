//! Input and output: CSV tables in, HDF5 and CSV results out, written atomically
//! (temporary name, then rename; never overwriting without `--force`).

use crate::error::{Error, Result};
use crate::solver::ContactSeries;
use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A numeric CSV table: `#` comment lines, one header line, then rows of numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// The file it came from (for error messages).
    pub file: String,
    /// Column names from the header line.
    pub names: Vec<String>,
    /// Column data, one vector per name.
    pub columns: Vec<Vec<f64>>,
}

impl CsvTable {
    /// Parses CSV text; `file` names the source in errors.
    pub fn parse(text: &str, file: &str) -> Result<CsvTable> {
        let input = |line: usize, key: &str, problem: String, allowed: &str| Error::Input {
            file: format!("{file}:{line}"),
            key: key.to_string(),
            problem,
            allowed: allowed.to_string(),
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (hline, header) = lines.next().ok_or_else(|| {
            input(
                1,
                "header",
                "the file has no header line".into(),
                "a header line naming the columns, then numeric rows",
            )
        })?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        if names.iter().any(|n| n.is_empty()) {
            return Err(input(
                hline,
                "header",
                "empty column name".into(),
                "comma-separated column names",
            ));
        }
        let mut columns = vec![Vec::new(); names.len()];
        for (line, row) in lines {
            let cells: Vec<&str> = row.split(',').collect();
            if cells.len() != names.len() {
                return Err(input(
                    line,
                    "row",
                    format!(
                        "{} values where the header has {}",
                        cells.len(),
                        names.len()
                    ),
                    "one value per header column",
                ));
            }
            for (k, cell) in cells.iter().enumerate() {
                let v = f64::from_str(cell.trim()).map_err(|_| {
                    input(
                        line,
                        &names[k],
                        format!("`{}` is not a number", cell.trim()),
                        "a finite decimal number",
                    )
                })?;
                if !v.is_finite() {
                    return Err(input(
                        line,
                        &names[k],
                        format!("{v} is not finite"),
                        "a finite decimal number",
                    ));
                }
                columns[k].push(v);
            }
        }
        if columns[0].is_empty() {
            return Err(input(
                hline,
                "rows",
                "the file has no data rows".into(),
                "at least two rows",
            ));
        }
        Ok(CsvTable {
            file: file.to_string(),
            names,
            columns,
        })
    }

    /// Reads and parses a CSV file.
    pub fn read(path: &Path) -> Result<CsvTable> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        CsvTable::parse(&text, &path.display().to_string())
    }

    /// The column called `name`, or an error listing the columns there are.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
            .ok_or_else(|| Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: "column missing".into(),
                allowed: format!("a header with `{name}` (found: {})", self.names.join(", ")),
            })
    }

    /// The column called `name` if present.
    pub fn optional_column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }

    /// The column `name`, checked to be strictly increasing (a time axis).
    pub fn time_column(&self, name: &str) -> Result<&[f64]> {
        let t = self.column(name)?;
        if t.len() < 2 {
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: "fewer than two samples".into(),
                allowed: "at least two strictly increasing times".into(),
            });
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: format!(
                    "not strictly increasing at data row {} ({:e} after {:e})",
                    i + 2,
                    t[i + 1],
                    t[i]
                ),
                allowed: "strictly increasing times".into(),
            });
        }
        Ok(t)
    }
}

/// Refuses to overwrite `path` unless `force`.
pub fn check_output(path: &Path, force: bool) -> Result<()> {
    if path.exists() && !force {
        return Err(Error::OutputExists(path.to_path_buf()));
    }
    Ok(())
}

/// Writes a file through `write` to a temporary name beside `path`, then renames it into place;
/// on failure the temporary file is removed, so no half-written output is left.
pub fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    check_output(path, force)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    // The temporary name keeps the extension (plotters picks the image format from it).
    let tmp: PathBuf = dir.join(format!(".tmp-{}-{name}", std::process::id()));
    let result =
        write(&tmp).and_then(|_| std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A scalar result of a run (peak force, restitution, …) with its unit.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryItem {
    /// Name, snake_case (used as HDF5 attribute name).
    pub key: String,
    /// Value in SI units.
    pub value: f64,
    /// Unit (`N`, `m`, `1`, …).
    pub unit: &'static str,
}

/// Shorthand constructor of a [`SummaryItem`].
pub fn item(key: &str, value: f64, unit: &'static str) -> SummaryItem {
    SummaryItem {
        key: key.to_string(),
        value,
        unit,
    }
}

/// The output of one scene run, ready to be written.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// The `/contact` time series (absent for scenes without spheres).
    pub contact: Option<ContactSeries>,
    /// The `/time` axis of the gauge and energy series, s.
    pub time_s: Option<Vec<f64>>,
    /// `/gauges/<name>/{strain,voltage}`.
    pub gauges: Vec<GaugeTrace>,
    /// `/energy/<name>`, J, on the `/time` axis.
    pub energy: Vec<(String, Vec<f64>)>,
    /// `/bars/<name>/{snapshots,x,time}`: decimated x–t stress fields.
    pub bars: Vec<crate::solver::pulse::BarSnapshots>,
    /// Scalar results (attributes of `/summary`).
    pub summary: Vec<SummaryItem>,
    /// The lab's reduction of the simulated gauge records (`/reduction/*`), full SHPB tests only.
    pub reduction: Option<crate::reduce::Reduction>,
    /// Things the user should know about the run (`/summary` attribute `warnings`, one per line).
    pub warnings: Vec<String>,
}

/// One recorded gauge channel: bar strain and the digitised voltage on the `/time` axis.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeTrace {
    /// Channel name.
    pub name: String,
    /// Bar strain at the gauge (positive in tension), noise-free.
    pub strain: Vec<f64>,
    /// Recorded voltage: bridge, amplifier, noise and quantisation, V.
    pub voltage_v: Vec<f64>,
}

impl RunOutput {
    /// An output with only a contact series and a summary.
    pub fn contact_only(contact: ContactSeries, summary: Vec<SummaryItem>) -> RunOutput {
        RunOutput {
            contact: Some(contact),
            time_s: None,
            gauges: Vec::new(),
            energy: Vec::new(),
            bars: Vec::new(),
            summary,
            reduction: None,
            warnings: Vec::new(),
        }
    }
}

/// Converts an HDF5 error into the crate's error naming `file`.
pub(crate) fn h5err(file: &Path) -> impl Fn(hdf5::Error) -> Error + '_ {
    move |e| Error::Hdf5 {
        file: file.display().to_string(),
        message: e.to_string(),
    }
}

fn vlu(s: &str) -> VarLenUnicode {
    VarLenUnicode::from_str(s)
        .unwrap_or_else(|_| VarLenUnicode::from_str("").expect("empty string is valid"))
}

/// Writes a string attribute.
pub(crate) fn string_attr(
    loc: &hdf5::Location,
    name: &str,
    value: &str,
    file: &Path,
) -> Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .shape(())
        .create(name)
        .and_then(|a| a.write_scalar(&vlu(value)))
        .map_err(h5err(file))
}

/// Writes a 1-D f64 dataset with a `units` attribute.
pub fn write_dataset(
    group: &hdf5::Group,
    name: &str,
    data: &[f64],
    units: &str,
    file: &Path,
) -> Result<()> {
    let ds = group
        .new_dataset_builder()
        .with_data(data)
        .create(name)
        .map_err(h5err(file))?;
    string_attr(&ds, "units", units, file)
}

/// The `/contact` datasets of a series: (name, data, units), absent ones skipped.
pub fn contact_columns(s: &ContactSeries) -> Vec<(&'static str, &[f64], &'static str)> {
    let mut cols = Vec::new();
    if let Some(t) = &s.time_s {
        cols.push(("time", t.as_slice(), "s"));
    }
    cols.push(("displacement", s.displacement_m.as_slice(), "m"));
    cols.push(("force", s.force_n.as_slice(), "N"));
    if let Some(v) = &s.yield_stress_pa {
        cols.push(("yield_stress", v.as_slice(), "Pa"));
    }
    if let Some(v) = &s.strain_rate_per_s {
        cols.push(("strain_rate", v.as_slice(), "1/s"));
    }
    cols
}

/// Writes a run to HDF5: `/contact/*` with units, `/summary` attributes, root `shpb_version` and `scene`.
pub fn write_hdf5(path: &Path, force: bool, scene_text: &str, out: &RunOutput) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let f = hdf5::File::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        string_attr(&f, "scene", scene_text, path)?;
        if let Some(contact) = &out.contact {
            let g = f.create_group("contact").map_err(h5err(path))?;
            for (name, data, units) in contact_columns(contact) {
                write_dataset(&g, name, data, units, path)?;
            }
        }
        if let Some(t) = &out.time_s {
            let root = f.group("/").map_err(h5err(path))?;
            write_dataset(&root, "time", t, "s", path)?;
        }
        if !out.gauges.is_empty() {
            let g = f.create_group("gauges").map_err(h5err(path))?;
            for tr in &out.gauges {
                let c = g.create_group(&tr.name).map_err(h5err(path))?;
                write_dataset(&c, "strain", &tr.strain, "1", path)?;
                write_dataset(&c, "voltage", &tr.voltage_v, "V", path)?;
            }
        }
        if !out.bars.is_empty() {
            let g = f.create_group("bars").map_err(h5err(path))?;
            for b in &out.bars {
                let c = g.create_group(&b.name).map_err(h5err(path))?;
                write_dataset(&c, "x", &b.x_m, "m", path)?;
                write_dataset(&c, "time", &b.time_s, "s", path)?;
                let flat: Vec<f64> = b.stress_pa.iter().flatten().copied().collect();
                let field = ndarray::Array2::from_shape_vec((b.time_s.len(), b.x_m.len()), flat)
                    .map_err(|e| Error::Hdf5 {
                        file: path.display().to_string(),
                        message: e.to_string(),
                    })?;
                let ds = c
                    .new_dataset_builder()
                    .with_data(&field)
                    .create("snapshots")
                    .map_err(h5err(path))?;
                string_attr(&ds, "units", "Pa", path)?;
                string_attr(
                    &ds,
                    "description",
                    "axial stress (tension positive), rows: time, columns: x",
                    path,
                )?;
            }
        }
        if let Some(r) = &out.reduction {
            let g = f.create_group("reduction").map_err(h5err(path))?;
            for (name, data, units, _) in crate::reduce::reduction_columns(r) {
                write_dataset(&g, name, data, units, path)?;
            }
        }
        if !out.energy.is_empty() {
            let g = f.create_group("energy").map_err(h5err(path))?;
            for (name, data) in &out.energy {
                write_dataset(&g, name, data, "J", path)?;
            }
        }
        let s = f.create_group("summary").map_err(h5err(path))?;
        for it in &out.summary {
            let a = s
                .new_attr::<f64>()
                .shape(())
                .create(it.key.as_str())
                .map_err(h5err(path))?;
            a.write_scalar(&it.value).map_err(h5err(path))?;
        }
        string_attr(
            &s,
            "units",
            &out.summary
                .iter()
                .map(|i| format!("{}={}", i.key, i.unit))
                .collect::<Vec<_>>()
                .join(", "),
            path,
        )?;
        string_attr(&s, "warnings", &out.warnings.join("\n"), path)?;
        f.close().map_err(h5err(path))
    })
}

/// Writes `text` to `path` atomically (refusing to overwrite without `force`).
pub fn write_text_atomically(path: &Path, force: bool, text: &str) -> Result<()> {
    write_atomically(path, force, |tmp| {
        std::fs::write(tmp, text).map_err(|e| Error::io(path, e))
    })
}

/// Writes a run as CSV with one header line (units in the column names): the contact series,
/// or for bar scenes the time axis with each gauge's strain and voltage.
pub fn write_csv(path: &Path, force: bool, out: &RunOutput) -> Result<()> {
    let mut cols: Vec<(String, &[f64])> = Vec::new();
    if let Some(c) = &out.contact {
        for (n, d, u) in contact_columns(c) {
            cols.push((csv_name(n, u), d));
        }
    } else if let Some(t) = &out.time_s {
        cols.push(("time_s".into(), t));
        for g in &out.gauges {
            cols.push((format!("{}_strain", g.name), &g.strain));
            cols.push((format!("{}_voltage_V", g.name), &g.voltage_v));
        }
    }
    let rows = cols.iter().map(|(_, d)| d.len()).min().unwrap_or(0);
    let mut text = cols
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for i in 0..rows {
        let row: Vec<String> = cols.iter().map(|(_, d)| format!("{:e}", d[i])).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    write_text_atomically(path, force, &text)
}

/// CSV column name with unit, e.g. `force_N`, `strain_rate_per_s`.
pub fn csv_name(name: &str, unit: &str) -> String {
    let u = match unit {
        "1/s" => "per_s",
        u => u,
    };
    format!("{name}_{u}")
}

/// Writes a sweep: root attributes `shpb_version`, `scene` (the scene text) and `sweep` (the
/// `--set` specifications, one per line); `/summary/run` and `/summary/<column>` (with `units`)
/// with one row per run, `/summary/inputs/<key>` (the swept values as written); and
/// `/runs/<index>` groups whose attributes are that run's inputs and results.
pub fn write_sweep_hdf5(
    path: &Path,
    force: bool,
    scene_text: &str,
    sweep: &[String],
    keys: &[String],
    rows: &[crate::sweep::RunSummary],
) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let f = hdf5::File::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        string_attr(&f, "scene", scene_text, path)?;
        string_attr(&f, "sweep", &sweep.join("\n"), path)?;
        let s = f.create_group("summary").map_err(h5err(path))?;
        let run: Vec<f64> = rows.iter().map(|r| r.index as f64).collect();
        write_dataset(&s, "run", &run, "1", path)?;
        for (k, (name, units)) in crate::sweep::SUMMARY_COLUMNS.iter().enumerate() {
            let col: Vec<f64> = rows.iter().map(|r| r.values()[k]).collect();
            write_dataset(&s, name, &col, units, path)?;
        }
        let inputs = s.create_group("inputs").map_err(h5err(path))?;
        for (k, key) in keys.iter().enumerate() {
            let col: Vec<VarLenUnicode> = rows.iter().map(|r| vlu(&r.inputs[k])).collect();
            inputs
                .new_dataset_builder()
                .with_data(&col)
                .create(key.as_str())
                .map_err(h5err(path))?;
        }
        string_attr(&inputs, "order", &keys.join("\n"), path)?;
        let runs = f.create_group("runs").map_err(h5err(path))?;
        for r in rows {
            let g = runs
                .create_group(&r.index.to_string())
                .map_err(h5err(path))?;
            for (key, v) in keys.iter().zip(&r.inputs) {
                string_attr(&g, key, v, path)?;
            }
            for ((name, _), v) in crate::sweep::SUMMARY_COLUMNS.iter().zip(r.values()) {
                g.new_attr::<f64>()
                    .shape(())
                    .create(*name)
                    .and_then(|at| at.write_scalar(&v))
                    .map_err(h5err(path))?;
            }
        }
        f.close().map_err(h5err(path))
    })
}

/// A sweep file read back (for `shpb merge`).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepFile {
    /// The scene text.
    pub scene: String,
    /// The `--set` specifications (and a `shard k/n` line for a shard).
    pub sweep: Vec<String>,
    /// The swept keys, in order.
    pub keys: Vec<String>,
    /// The runs.
    pub rows: Vec<crate::sweep::RunSummary>,
}

impl SweepFile {
    /// The specifications without the shard line: what shards of one sweep share.
    pub fn sweep_without_shard(&self) -> Vec<String> {
        self.sweep
            .iter()
            .filter(|s| !s.starts_with("shard "))
            .cloned()
            .collect()
    }
}

/// Reads a file written by [`write_sweep_hdf5`].
pub fn read_sweep_hdf5(path: &Path) -> Result<SweepFile> {
    let bad = |what: &str, e: String| Error::Input {
        file: path.display().to_string(),
        key: what.to_string(),
        problem: e,
        allowed: "an HDF5 file written by `shpb sweep -o`".into(),
    };
    let f = hdf5::File::open(path).map_err(|e| bad("file", e.to_string()))?;
    let text = |loc: &hdf5::Location, name: &str| -> Result<String> {
        loc.attr(name)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .map(|v| v.as_str().to_string())
            .map_err(|e| bad(name, e.to_string()))
    };
    let lines = |t: String| -> Vec<String> {
        t.lines()
            .filter(|l| !l.is_empty())
            .map(str::to_string)
            .collect()
    };
    let scene = text(&f, "scene")?;
    let sweep = lines(text(&f, "sweep")?);
    let s = f
        .group("summary")
        .map_err(|e| bad("summary", e.to_string()))?;
    let inputs = s
        .group("inputs")
        .map_err(|e| bad("summary/inputs", e.to_string()))?;
    let keys = lines(text(&inputs, "order")?);
    let col = |name: &str| -> Result<Vec<f64>> {
        s.dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map_err(|e| bad(&format!("summary/{name}"), e.to_string()))
    };
    let run = col("run")?;
    let cols = crate::sweep::SUMMARY_COLUMNS
        .iter()
        .map(|(n, _)| col(n))
        .collect::<Result<Vec<_>>>()?;
    let labels = keys
        .iter()
        .map(|k| {
            inputs
                .dataset(k)
                .and_then(|d| d.read_raw::<VarLenUnicode>())
                .map(|v| v.iter().map(|x| x.as_str().to_string()).collect::<Vec<_>>())
                .map_err(|e| bad(&format!("summary/inputs/{k}"), e.to_string()))
        })
        .collect::<Result<Vec<_>>>()?;
    if cols.iter().any(|c| c.len() != run.len()) || labels.iter().any(|c| c.len() != run.len()) {
        return Err(bad("summary", "columns of different lengths".into()));
    }
    let rows = (0..run.len())
        .map(|i| crate::sweep::RunSummary {
            index: run[i] as usize,
            inputs: labels.iter().map(|c| c[i].clone()).collect(),
            peak_force_n: cols[0][i],
            displacement_at_peak_m: cols[1][i],
            peak_strain_rate_per_s: cols[2][i],
            equilibrium_ratio_at_peak: cols[3][i],
            time_to_equilibrium_s: cols[4][i],
        })
        .collect();
    Ok(SweepFile {
        scene,
        sweep,
        keys,
        rows,
    })
}

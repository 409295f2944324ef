//! The study file: the table of a study (one row per run: its swept inputs and its results) in
//! HDF5, written by `shpb sweep -o` and `shpb merge`, read back by `merge` and `sweep --resume`.
//!
//! Layout: root attributes `shpb_version`, `scene` (the scene text) and `sweep` (the
//! specifications, one per line) and, naming what the study belongs to ([`Identity`]),
//! `sweep_id`, `scene_file`, `input_files`, `set_sha256`, `shard` and `runs_total`;
//! `/summary/run` (the run indices) and `/summary/<column>` (with `units`), one row per run;
//! `/summary/inputs/<key>` (the input values in SI units, float64 with `units`, or strings for
//! inputs that are names) with the attribute `order` (the keys, one per line);
//! `/summary/inputs_as_written/<key>` (the values as the user wrote them, `7psi`, `0.3mm`); and
//! `/runs/<index>` groups whose attributes are that run's inputs (SI numbers, or strings) and
//! results (numbers); `/summary/warnings` (strings, one per run: its warnings, one per line,
//! empty for none) and the same as each `/runs/<index>` attribute `warnings`.

use crate::atomic::write_atomically;
use crate::h5::{h5err, string_attr, vlu, write_dataset};
use hdf5::types::VarLenUnicode;
use shpb_input::provenance::InputFile;
use shpb_input::{Error, Result};
use std::path::Path;

/// One input of a study: its key and its value in each row, as written (`5psi`, `0.5mm`) and,
/// for a numeric input, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct InputColumn {
    /// The key (`pressure`, `shaper.thickness_m`).
    pub key: String,
    /// The value of each row as written.
    pub values: Vec<String>,
    /// The value of each row in SI units with the units (`Pa`, `m`, `1` for a count); `None`
    /// for an input that is a name (a law, a preset, a set-up).
    pub si: Option<(Vec<f64>, String)>,
}

/// What a study file belongs to: the scene and the files it resolves (by content), the swept
/// values, the shard and the version, so that `shpb sweep --resume` and `shpb merge` can refuse
/// the files of another sweep.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// SHA-256 (hex) over the shpb version, the contents of the scene and of the files it
    /// resolves and the swept keys and values: the same for every shard of one sweep.
    pub sweep_id: String,
    /// The scene file and the SHA-256 of its content.
    pub scene: InputFile,
    /// The other files the scene resolves (set-up, gauges, materials, records), by content.
    pub inputs: Vec<InputFile>,
    /// SHA-256 (hex) of the swept keys and their values, in order.
    pub set_sha256: String,
    /// The shard this file holds, k of n (1/1: the whole sweep).
    pub shard: (u64, u64),
    /// The number of runs of the whole sweep (all shards).
    pub runs_total: u64,
}

/// A file and its SHA-256 as `sha256sum` prints them: `<sha256>  <path>`.
pub fn sha256sum_line(f: &InputFile) -> String {
    format!("{}  {}", f.sha256, f.path.display())
}

/// Reads a [`sha256sum_line`].
pub fn parse_sha256sum_line(line: &str) -> Option<InputFile> {
    let (sha, path) = line.split_once("  ")?;
    (sha.len() == 64 && sha.bytes().all(|b| b.is_ascii_hexdigit())).then(|| InputFile {
        sha256: sha.to_string(),
        path: path.into(),
    })
}

/// One result of a study: its name, its units and its value in each row.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultColumn {
    /// The name (`peak_force`).
    pub name: String,
    /// The units (`N`, `1` for a ratio).
    pub units: String,
    /// The value of each row.
    pub values: Vec<f64>,
}

/// The table of a study: what the study was (version, scene, specifications) and one row per
/// run (its index, its inputs, its results), stored by column.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyTable {
    /// The version of shpb that ran the study (empty when a file read back has none).
    pub shpb_version: String,
    /// The scene text.
    pub scene: String,
    /// The specifications of the study (`--set` values, a `shard k/n` line), one per entry.
    pub sweep: Vec<String>,
    /// What the study belongs to (`None` in a file written before shpb recorded it).
    pub identity: Option<Identity>,
    /// The run index of each row.
    pub run: Vec<usize>,
    /// The inputs, in order.
    pub inputs: Vec<InputColumn>,
    /// The results, in order.
    pub results: Vec<ResultColumn>,
    /// Each run's warnings (out of the model's calibrated range, …), one per line; empty for
    /// none. An empty vector: none recorded (a file of an older shpb).
    pub warnings: Vec<String>,
}

impl StudyTable {
    /// The number of rows.
    pub fn len(&self) -> usize {
        self.run.len()
    }

    /// Whether the table has no row.
    pub fn is_empty(&self) -> bool {
        self.run.is_empty()
    }

    /// The input keys, in order.
    pub fn keys(&self) -> Vec<String> {
        self.inputs.iter().map(|c| c.key.clone()).collect()
    }

    /// The result column named `name`.
    pub fn result(&self, name: &str) -> Option<&ResultColumn> {
        self.results.iter().find(|c| c.name == name)
    }

    /// The first column whose length differs from the number of rows, if any.
    fn ragged_column(&self) -> Option<&str> {
        let n = self.len();
        self.inputs
            .iter()
            .find(|c| c.values.len() != n || c.si.as_ref().is_some_and(|(v, _)| v.len() != n))
            .map(|c| c.key.as_str())
            .or_else(|| {
                self.results
                    .iter()
                    .find(|c| c.values.len() != n)
                    .map(|c| c.name.as_str())
            })
            .or_else(|| {
                (!self.warnings.is_empty() && self.warnings.len() != n).then_some("warnings")
            })
    }

    /// The warnings of row `row` (none when the table records none).
    pub fn warnings_of(&self, row: usize) -> &str {
        self.warnings.get(row).map_or("", String::as_str)
    }
}

/// Writes `table` to `path` in the layout of this module, atomically (refusing to replace an
/// existing file unless `force`). Every column must have one value per run.
pub fn write_study_hdf5(path: &Path, force: bool, table: &StudyTable) -> Result<()> {
    ragged(table, path)?;
    write_atomically(path, force, |tmp| {
        let f = crate::h5::create(tmp).map_err(h5err(path))?;
        write_header_and_summary(&f, table, path)?;
        let runs = f.create_group("runs").map_err(h5err(path))?;
        for row in 0..table.len() {
            write_run_group(&runs, table, row, path)?;
        }
        f.close().map_err(h5err(path))
    })
}

/// [`write_study_hdf5`] with the `/runs/<index>` groups written while the runs go on (issue 45:
/// the file's per-run work, HDF5's cost per group and attribute, leaves the serial end of a
/// sweep). `produce` gets a sink that writes the groups of the rows of a table it is given (one
/// finished run, its inputs in the form, SI number or text, of the whole table's columns) and
/// returns the whole table, whose root attributes and `/summary` are then written. The file is
/// written under a temporary name and appears only complete, as [`write_study_hdf5`]'s; the
/// same layout, read back the same (groups and attributes are listed by name).
pub fn write_study_hdf5_streamed<T>(
    path: &Path,
    force: bool,
    produce: impl FnOnce(&mut dyn FnMut(&StudyTable) -> Result<()>) -> Result<(StudyTable, T)>,
) -> Result<T> {
    let mut produced = None;
    write_atomically(path, force, |tmp| {
        let f = crate::h5::create(tmp).map_err(h5err(path))?;
        let runs = f.create_group("runs").map_err(h5err(path))?;
        let mut written = 0usize;
        let (table, value) = produce(&mut |rows: &StudyTable| {
            ragged(rows, path)?;
            for row in 0..rows.len() {
                write_run_group(&runs, rows, row, path)?;
            }
            written += rows.len();
            Ok(())
        })?;
        ragged(&table, path)?;
        if written != table.len() {
            return Err(Error::Hdf5 {
                file: path.display().to_string(),
                message: format!("{written} run groups written for {} runs", table.len()),
            });
        }
        write_header_and_summary(&f, &table, path)?;
        f.close().map_err(h5err(path))?;
        produced = Some(value);
        Ok(())
    })?;
    Ok(produced.expect("set once the file is written"))
}

/// An error naming the first column of `table` without one value per run.
fn ragged(table: &StudyTable, path: &Path) -> Result<()> {
    match table.ragged_column() {
        Some(column) => Err(Error::Hdf5 {
            file: path.display().to_string(),
            message: format!(
                "study column `{column}` does not have one value per run ({} runs)",
                table.len()
            ),
        }),
        None => Ok(()),
    }
}

/// The root attributes and `/summary` of a study file.
fn write_header_and_summary(f: &hdf5::File, table: &StudyTable, path: &Path) -> Result<()> {
    string_attr(f, "shpb_version", &table.shpb_version, path)?;
    string_attr(f, "scene", &table.scene, path)?;
    string_attr(f, "sweep", &table.sweep.join("\n"), path)?;
    if let Some(id) = &table.identity {
        write_identity(f, id, path)?;
    }
    let s = f.create_group("summary").map_err(h5err(path))?;
    let run: Vec<f64> = table.run.iter().map(|&i| i as f64).collect();
    write_dataset(&s, "run", &run, "1", path)?;
    for c in &table.results {
        write_dataset(&s, &c.name, &c.values, &c.units, path)?;
    }
    let inputs = s.create_group("inputs").map_err(h5err(path))?;
    let written = s.create_group("inputs_as_written").map_err(h5err(path))?;
    for c in &table.inputs {
        let text: Vec<VarLenUnicode> = c.values.iter().map(|v| vlu(v)).collect();
        written
            .new_dataset_builder()
            .with_data(&text)
            .create(c.key.as_str())
            .map_err(h5err(path))?;
        match &c.si {
            Some((values, units)) => write_dataset(&inputs, &c.key, values, units, path)?,
            None => {
                inputs
                    .new_dataset_builder()
                    .with_data(&text)
                    .create(c.key.as_str())
                    .map_err(h5err(path))?;
            }
        }
    }
    let warnings: Vec<VarLenUnicode> = (0..table.len())
        .map(|i| vlu(table.warnings_of(i)))
        .collect();
    s.new_dataset_builder()
        .with_data(&warnings)
        .create("warnings")
        .map_err(h5err(path))?;
    string_attr(&inputs, "order", &table.keys().join("\n"), path)?;
    string_attr(&written, "order", &table.keys().join("\n"), path)
}

/// The group `/runs/<index>` of row `row` of `table`: its inputs (SI numbers, or text) and
/// results as attributes, and its warnings.
fn write_run_group(runs: &hdf5::Group, table: &StudyTable, row: usize, path: &Path) -> Result<()> {
    let g = runs
        .create_group(&table.run[row].to_string())
        .map_err(h5err(path))?;
    for c in &table.inputs {
        match &c.si {
            Some((values, _)) => g
                .new_attr::<f64>()
                .shape(())
                .create(c.key.as_str())
                .and_then(|at| at.write_scalar(&values[row]))
                .map_err(h5err(path))?,
            None => string_attr(&g, &c.key, &c.values[row], path)?,
        }
    }
    for c in &table.results {
        g.new_attr::<f64>()
            .shape(())
            .create(c.name.as_str())
            .and_then(|at| at.write_scalar(&c.values[row]))
            .map_err(h5err(path))?;
    }
    string_attr(&g, "warnings", table.warnings_of(row), path)
}

/// The root attributes of an [`Identity`].
fn write_identity(f: &hdf5::File, id: &Identity, path: &Path) -> Result<()> {
    string_attr(f, "sweep_id", &id.sweep_id, path)?;
    string_attr(f, "scene_file", &sha256sum_line(&id.scene), path)?;
    let inputs: Vec<String> = id.inputs.iter().map(sha256sum_line).collect();
    string_attr(f, "input_files", &inputs.join("\n"), path)?;
    string_attr(f, "set_sha256", &id.set_sha256, path)?;
    string_attr(f, "shard", &format!("{}/{}", id.shard.0, id.shard.1), path)?;
    f.new_attr::<u64>()
        .shape(())
        .create("runs_total")
        .and_then(|a| a.write_scalar(&id.runs_total))
        .map_err(h5err(path))
}

/// Reads a file written by [`write_study_hdf5`] from its `/summary` datasets: the results come
/// back in the file's order of names (find one with [`StudyTable::result`]), the inputs in the
/// order of the `order` attribute.
pub fn read_study_hdf5(path: &Path) -> Result<StudyTable> {
    let bad = |what: &str, e: String| Error::Input {
        file: path.display().to_string(),
        key: what.to_string(),
        problem: e,
        allowed: "an HDF5 file written by `shpb sweep -o`".into(),
    };
    let f = crate::h5::open(path).map_err(|e| bad("file", e.to_string()))?;
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
    let shpb_version = text(&f, "shpb_version").unwrap_or_default();
    let scene = text(&f, "scene")?;
    let sweep = lines(text(&f, "sweep")?);
    let identity = if f.attr("sweep_id").is_ok() {
        let file_line = |line: &str, name: &str| {
            parse_sha256sum_line(line)
                .ok_or_else(|| bad(name, format!("`{line}` is not `<sha256>  <path>`")))
        };
        let shard = text(&f, "shard")?;
        let parsed_shard = shard
            .split_once('/')
            .and_then(|(k, n)| Some((k.parse().ok()?, n.parse().ok()?)))
            .ok_or_else(|| bad("shard", format!("`{shard}` is not k/n")))?;
        Some(Identity {
            sweep_id: text(&f, "sweep_id")?,
            scene: file_line(&text(&f, "scene_file")?, "scene_file")?,
            inputs: lines(text(&f, "input_files")?)
                .iter()
                .map(|l| file_line(l, "input_files"))
                .collect::<Result<Vec<_>>>()?,
            set_sha256: text(&f, "set_sha256")?,
            shard: parsed_shard,
            runs_total: f
                .attr("runs_total")
                .and_then(|a| a.read_scalar::<u64>())
                .map_err(|e| bad("runs_total", e.to_string()))?,
        })
    } else {
        None
    };
    let s = f
        .group("summary")
        .map_err(|e| bad("summary", e.to_string()))?;
    let inputs_group = s
        .group("inputs")
        .map_err(|e| bad("summary/inputs", e.to_string()))?;
    let keys = lines(text(&inputs_group, "order")?);
    let col = |name: &str| -> Result<Vec<f64>> {
        s.dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map_err(|e| bad(&format!("summary/{name}"), e.to_string()))
    };
    let run: Vec<usize> = col("run")?.into_iter().map(|i| i as usize).collect();
    let names = s
        .member_names()
        .map_err(|e| bad("summary", e.to_string()))?;
    let results = names
        .iter()
        .filter(|n| !["run", "inputs", "inputs_as_written", "warnings"].contains(&n.as_str()))
        .map(|name| {
            let units = s
                .dataset(name)
                .map_err(|e| e.to_string())
                .and_then(|d| text(&d, "units").map_err(|e| e.to_string()))
                .map_err(|e| bad(&format!("summary/{name}/units"), e))?;
            Ok(ResultColumn {
                name: name.clone(),
                units,
                values: col(name)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    // Files written before the inputs were stored in SI units have only `inputs` (as written).
    let written_group = s.group("inputs_as_written").ok();
    let strings = |g: &hdf5::Group, key: &str, group: &str| -> Result<Vec<String>> {
        g.dataset(key)
            .and_then(|d| d.read_raw::<VarLenUnicode>())
            .map(|v| v.iter().map(|x| x.as_str().to_string()).collect())
            .map_err(|e| bad(&format!("summary/{group}/{key}"), e.to_string()))
    };
    let inputs = keys
        .into_iter()
        .map(|key| {
            let ds = inputs_group
                .dataset(&key)
                .map_err(|e| bad(&format!("summary/inputs/{key}"), e.to_string()))?;
            let numeric = ds.dtype().is_ok_and(|t| t.is::<f64>());
            let si = if numeric {
                let values = ds
                    .read_raw::<f64>()
                    .map_err(|e| bad(&format!("summary/inputs/{key}"), e.to_string()))?;
                Some((values, text(&ds, "units")?))
            } else {
                None
            };
            let values = match &written_group {
                Some(g) => strings(g, &key, "inputs_as_written")?,
                None => strings(&inputs_group, &key, "inputs")?,
            };
            Ok(InputColumn { key, values, si })
        })
        .collect::<Result<Vec<_>>>()?;
    // Files written before the warnings were kept have none.
    let warnings = match s.dataset("warnings") {
        Ok(d) => d
            .read_raw::<VarLenUnicode>()
            .map(|v| v.iter().map(|x| x.as_str().to_string()).collect())
            .map_err(|e| bad("summary/warnings", e.to_string()))?,
        Err(_) => Vec::new(),
    };
    let table = StudyTable {
        shpb_version,
        scene,
        sweep,
        identity,
        run,
        inputs,
        results,
        warnings,
    };
    if table.ragged_column().is_some() {
        return Err(bad("summary", "columns of different lengths".into()));
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> StudyTable {
        StudyTable {
            shpb_version: "9.9.9".into(),
            scene: "kind = \"collision\"\n".into(),
            sweep: vec!["pressure=5psi,10psi".into(), "shard 1/2".into()],
            identity: Some(Identity {
                sweep_id: "ab".repeat(32),
                scene: InputFile {
                    path: "scenes/x.toml".into(),
                    sha256: "01".repeat(32),
                },
                inputs: vec![InputFile {
                    path: "bars/authors.toml".into(),
                    sha256: "23".repeat(32),
                }],
                set_sha256: "45".repeat(32),
                shard: (1, 2),
                runs_total: 4,
            }),
            run: vec![0, 2],
            inputs: vec![
                InputColumn {
                    key: "pressure".into(),
                    values: vec!["5psi".into(), "10psi".into()],
                    si: Some((vec![5.0 * 6894.757, 10.0 * 6894.757], "Pa".into())),
                },
                InputColumn {
                    key: "shaper.thickness_m".into(),
                    values: vec!["0.5mm".into(), "0.5mm".into()],
                    si: Some((vec![5e-4, 5e-4], "m".into())),
                },
                InputColumn {
                    key: "law".into(),
                    values: vec!["hertz".into(), "hertz".into()],
                    si: None,
                },
            ],
            results: vec![
                ResultColumn {
                    name: "peak_force".into(),
                    units: "N".into(),
                    values: vec![1.0e3, 2.5e3],
                },
                ResultColumn {
                    name: "equilibrium_ratio_at_peak".into(),
                    units: "1".into(),
                    values: vec![0.1, f64::NAN],
                },
            ],
            warnings: vec![
                String::new(),
                "gun pressure 17.5 psi is outside 10-15 psi\nsecond".into(),
            ],
        }
    }

    #[test]
    fn a_study_table_round_trips_through_its_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("study.h5");
        let t = table();
        write_study_hdf5(&path, false, &t).unwrap();
        let back = read_study_hdf5(&path).unwrap();
        assert_eq!(
            (&back.shpb_version, &back.scene, &back.sweep, &back.run),
            (&t.shpb_version, &t.scene, &t.sweep, &t.run)
        );
        assert_eq!(back.identity, t.identity);
        assert_eq!(back.inputs, t.inputs);
        assert_eq!(back.keys(), ["pressure", "shaper.thickness_m", "law"]);
        for c in &t.results {
            let b = back.result(&c.name).unwrap();
            assert_eq!(b.units, c.units);
            assert_eq!(b.values[0].to_bits(), c.values[0].to_bits());
            assert_eq!(b.values[1].is_nan(), c.values[1].is_nan());
        }
        assert_eq!(back.results.len(), t.results.len());
        assert_eq!(back.warnings, t.warnings, "each run's warnings kept");
        // No clobbering without `force`.
        assert!(write_study_hdf5(&path, false, &t).is_err());
        write_study_hdf5(&path, true, &t).unwrap();
    }

    #[test]
    fn the_file_has_the_layout_scripts_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("study.h5");
        write_study_hdf5(&path, false, &table()).unwrap();
        let f = hdf5::File::open(&path).unwrap();
        let attr = |loc: &hdf5::Location, name: &str| {
            loc.attr(name)
                .unwrap()
                .read_scalar::<VarLenUnicode>()
                .unwrap()
                .as_str()
                .to_string()
        };
        assert_eq!(attr(&f, "shpb_version"), "9.9.9");
        assert_eq!(attr(&f, "sweep"), "pressure=5psi,10psi\nshard 1/2");
        assert_eq!(attr(&f, "sweep_id"), "ab".repeat(32));
        assert_eq!(
            attr(&f, "scene_file"),
            format!("{}  scenes/x.toml", "01".repeat(32))
        );
        assert_eq!(
            attr(&f, "input_files"),
            format!("{}  bars/authors.toml", "23".repeat(32))
        );
        assert_eq!(attr(&f, "shard"), "1/2");
        let runs_total: u64 = f.attr("runs_total").unwrap().read_scalar().unwrap();
        assert_eq!(runs_total, 4);
        let s = f.group("summary").unwrap();
        assert_eq!(
            s.dataset("run").unwrap().read_raw::<f64>().unwrap(),
            [0.0, 2.0]
        );
        assert_eq!(attr(&s.dataset("run").unwrap(), "units"), "1");
        assert_eq!(attr(&s.dataset("peak_force").unwrap(), "units"), "N");
        let inputs = s.group("inputs").unwrap();
        assert_eq!(attr(&inputs, "order"), "pressure\nshaper.thickness_m\nlaw");
        // Numeric inputs in SI units with their units; names as strings.
        let pressure = inputs.dataset("pressure").unwrap();
        assert_eq!(attr(&pressure, "units"), "Pa");
        assert_eq!(
            pressure.read_raw::<f64>().unwrap(),
            [5.0 * 6894.757, 10.0 * 6894.757]
        );
        let thickness = inputs.dataset("shaper.thickness_m").unwrap();
        assert_eq!(attr(&thickness, "units"), "m");
        assert_eq!(thickness.read_raw::<f64>().unwrap(), [5e-4, 5e-4]);
        let law = inputs.dataset("law").unwrap();
        assert_eq!(
            law.read_raw::<VarLenUnicode>().unwrap()[0].as_str(),
            "hertz"
        );
        // The values as written.
        let written = s.group("inputs_as_written").unwrap();
        let as_written = written
            .dataset("pressure")
            .unwrap()
            .read_raw::<VarLenUnicode>()
            .unwrap();
        assert_eq!(as_written[1].as_str(), "10psi");
        let g = f.group("runs/2").unwrap();
        let p: f64 = g.attr("pressure").unwrap().read_scalar().unwrap();
        assert_eq!(p, 10.0 * 6894.757);
        assert_eq!(attr(&g, "law"), "hertz");
        let force: f64 = g.attr("peak_force").unwrap().read_scalar().unwrap();
        assert_eq!(force, 2.5e3);
    }

    #[test]
    fn a_file_of_the_older_layout_reads_without_identity_and_with_text_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("old.h5");
        {
            let f = hdf5::File::create(&path).unwrap();
            for (name, value) in [
                ("shpb_version", "0.1.0"),
                ("scene", "kind = 1"),
                ("sweep", "p"),
            ] {
                string_attr(&f, name, value, &path).unwrap();
            }
            let s = f.create_group("summary").unwrap();
            write_dataset(&s, "run", &[0.0, 1.0], "1", &path).unwrap();
            write_dataset(&s, "peak_force", &[1.0, 2.0], "N", &path).unwrap();
            let inputs = s.create_group("inputs").unwrap();
            let col = [vlu("5psi"), vlu("10psi")];
            inputs
                .new_dataset_builder()
                .with_data(&col)
                .create("pressure")
                .unwrap();
            string_attr(&inputs, "order", "pressure", &path).unwrap();
        }
        let t = read_study_hdf5(&path).unwrap();
        assert_eq!(t.identity, None);
        assert_eq!(t.inputs[0].values, ["5psi", "10psi"]);
        assert_eq!(t.inputs[0].si, None);
        assert_eq!(t.result("peak_force").unwrap().values, [1.0, 2.0]);
    }

    /// The rows of `t` one at a time, as a sweep's sink gets them.
    fn row_of(t: &StudyTable, i: usize) -> StudyTable {
        let mut one = t.clone();
        one.run = vec![t.run[i]];
        for c in &mut one.inputs {
            c.values = vec![c.values[i].clone()];
            if let Some((v, _)) = &mut c.si {
                *v = vec![v[i]];
            }
        }
        for c in &mut one.results {
            c.values = vec![c.values[i]];
        }
        one.warnings = vec![t.warnings[i].clone()];
        one
    }

    #[test]
    fn a_file_streamed_run_by_run_reads_as_the_file_written_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let (whole, streamed) = (dir.path().join("whole.h5"), dir.path().join("streamed.h5"));
        let t = table();
        write_study_hdf5(&whole, false, &t).unwrap();
        // The runs finish in the other order; no file until the table is complete.
        let n = write_study_hdf5_streamed(&streamed, false, |sink| {
            for i in (0..t.len()).rev() {
                sink(&row_of(&t, i))?;
                assert!(!streamed.exists(), "no half-written file");
            }
            Ok((t.clone(), t.len()))
        })
        .unwrap();
        assert_eq!(n, 2);
        let dump = |p: &Path| {
            let o = std::process::Command::new("h5dump")
                .arg(p)
                .output()
                .unwrap();
            assert!(o.status.success());
            String::from_utf8(o.stdout)
                .unwrap()
                .replace(&p.display().to_string(), "FILE")
        };
        assert_eq!(dump(&streamed), dump(&whole));
        // A run that fails, or a table that is not the runs written: no file, no temporary.
        let failed = dir.path().join("failed.h5");
        let e = write_study_hdf5_streamed::<()>(&failed, false, |sink| {
            sink(&row_of(&t, 0))?;
            Err(Error::Input {
                file: "x".into(),
                key: "k".into(),
                problem: "a run failed".into(),
                allowed: "".into(),
            })
        });
        assert!(e.unwrap_err().to_string().contains("a run failed"));
        let e = write_study_hdf5_streamed(&failed, false, |sink| {
            sink(&row_of(&t, 0))?;
            Ok((t.clone(), ()))
        });
        assert!(
            e.unwrap_err()
                .to_string()
                .contains("1 run groups written for 2 runs")
        );
        assert!(!failed.exists());
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }

    #[test]
    fn a_ragged_table_is_refused_and_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("study.h5");
        let mut t = table();
        t.results[0].values.pop();
        let e = write_study_hdf5(&path, false, &t).unwrap_err().to_string();
        assert!(e.contains("peak_force"), "{e}");
        assert!(!path.exists());
    }
}

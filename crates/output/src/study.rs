//! The study file: the table of a study (one row per run: its swept inputs and its results) in
//! HDF5, written by `shpb sweep -o` and `shpb merge`, read back by `merge`.
//!
//! Layout: root attributes `shpb_version`, `scene` (the scene text) and `sweep` (the
//! specifications, one per line); `/summary/run` (the run indices) and `/summary/<column>` (with
//! `units`), one row per run; `/summary/inputs/<key>` (the input values as written) with the
//! attribute `order` (the keys, one per line); and `/runs/<index>` groups whose attributes are
//! that run's inputs (strings) and results (numbers).

use crate::atomic::write_atomically;
use crate::h5::{h5err, string_attr, vlu, write_dataset};
use hdf5::types::VarLenUnicode;
use shpb_input::{Error, Result};
use std::path::Path;

/// One input of a study: its key and its value in each row, as written (`5psi`, `0.5mm`).
#[derive(Debug, Clone, PartialEq)]
pub struct InputColumn {
    /// The key (`pressure`, `shaper.thickness_m`).
    pub key: String,
    /// The value of each row.
    pub values: Vec<String>,
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
    /// The run index of each row.
    pub run: Vec<usize>,
    /// The inputs, in order.
    pub inputs: Vec<InputColumn>,
    /// The results, in order.
    pub results: Vec<ResultColumn>,
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
            .find(|c| c.values.len() != n)
            .map(|c| c.key.as_str())
            .or_else(|| {
                self.results
                    .iter()
                    .find(|c| c.values.len() != n)
                    .map(|c| c.name.as_str())
            })
    }
}

/// Writes `table` to `path` in the layout of this module, atomically (refusing to replace an
/// existing file unless `force`). Every column must have one value per run.
pub fn write_study_hdf5(path: &Path, force: bool, table: &StudyTable) -> Result<()> {
    if let Some(column) = table.ragged_column() {
        return Err(Error::Hdf5 {
            file: path.display().to_string(),
            message: format!(
                "study column `{column}` does not have one value per run ({} runs)",
                table.len()
            ),
        });
    }
    write_atomically(path, force, |tmp| {
        let f = hdf5::File::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", &table.shpb_version, path)?;
        string_attr(&f, "scene", &table.scene, path)?;
        string_attr(&f, "sweep", &table.sweep.join("\n"), path)?;
        let s = f.create_group("summary").map_err(h5err(path))?;
        let run: Vec<f64> = table.run.iter().map(|&i| i as f64).collect();
        write_dataset(&s, "run", &run, "1", path)?;
        for c in &table.results {
            write_dataset(&s, &c.name, &c.values, &c.units, path)?;
        }
        let inputs = s.create_group("inputs").map_err(h5err(path))?;
        for c in &table.inputs {
            let col: Vec<VarLenUnicode> = c.values.iter().map(|v| vlu(v)).collect();
            inputs
                .new_dataset_builder()
                .with_data(&col)
                .create(c.key.as_str())
                .map_err(h5err(path))?;
        }
        string_attr(&inputs, "order", &table.keys().join("\n"), path)?;
        let runs = f.create_group("runs").map_err(h5err(path))?;
        for (row, index) in table.run.iter().enumerate() {
            let g = runs.create_group(&index.to_string()).map_err(h5err(path))?;
            for c in &table.inputs {
                string_attr(&g, &c.key, &c.values[row], path)?;
            }
            for c in &table.results {
                g.new_attr::<f64>()
                    .shape(())
                    .create(c.name.as_str())
                    .and_then(|at| at.write_scalar(&c.values[row]))
                    .map_err(h5err(path))?;
            }
        }
        f.close().map_err(h5err(path))
    })
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
    let shpb_version = text(&f, "shpb_version").unwrap_or_default();
    let scene = text(&f, "scene")?;
    let sweep = lines(text(&f, "sweep")?);
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
        .filter(|n| !["run", "inputs"].contains(&n.as_str()))
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
    let inputs = keys
        .into_iter()
        .map(|key| {
            inputs_group
                .dataset(&key)
                .and_then(|d| d.read_raw::<VarLenUnicode>())
                .map(|v| v.iter().map(|x| x.as_str().to_string()).collect())
                .map_err(|e| bad(&format!("summary/inputs/{key}"), e.to_string()))
                .map(|values| InputColumn { key, values })
        })
        .collect::<Result<Vec<_>>>()?;
    let table = StudyTable {
        shpb_version,
        scene,
        sweep,
        run,
        inputs,
        results,
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
            run: vec![0, 2],
            inputs: vec![
                InputColumn {
                    key: "pressure".into(),
                    values: vec!["5psi".into(), "10psi".into()],
                },
                InputColumn {
                    key: "shaper.thickness_m".into(),
                    values: vec!["0.5mm".into(), "0.5mm".into()],
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
        assert_eq!(back.inputs, t.inputs);
        assert_eq!(back.keys(), ["pressure", "shaper.thickness_m"]);
        for c in &t.results {
            let b = back.result(&c.name).unwrap();
            assert_eq!(b.units, c.units);
            assert_eq!(b.values[0].to_bits(), c.values[0].to_bits());
            assert_eq!(b.values[1].is_nan(), c.values[1].is_nan());
        }
        assert_eq!(back.results.len(), t.results.len());
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
        let s = f.group("summary").unwrap();
        assert_eq!(
            s.dataset("run").unwrap().read_raw::<f64>().unwrap(),
            [0.0, 2.0]
        );
        assert_eq!(attr(&s.dataset("run").unwrap(), "units"), "1");
        assert_eq!(attr(&s.dataset("peak_force").unwrap(), "units"), "N");
        let inputs = s.group("inputs").unwrap();
        assert_eq!(attr(&inputs, "order"), "pressure\nshaper.thickness_m");
        let g = f.group("runs/2").unwrap();
        assert_eq!(attr(&g, "pressure"), "10psi");
        let force: f64 = g.attr("peak_force").unwrap().read_scalar().unwrap();
        assert_eq!(force, 2.5e3);
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

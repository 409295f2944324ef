//! The study file of a sweep: its [`RunSummary`] rows as a [`StudyTable`] of the output layer,
//! which writes and reads the HDF5 (`shpb sweep -o`, `shpb merge`).

use crate::sweep::{RunSummary, SUMMARY_COLUMNS};
use shpb_input::{Error, Result};
use shpb_output::study::{
    InputColumn, ResultColumn, StudyTable, read_study_hdf5, write_study_hdf5,
};
use std::path::Path;

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
    pub rows: Vec<RunSummary>,
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

    /// The study table of the sweep ([`sweep_table`]).
    pub fn to_table(&self) -> StudyTable {
        sweep_table(&self.scene, &self.sweep, &self.keys, &self.rows)
    }

    /// The sweep of a study table read from `path`: every [`SUMMARY_COLUMNS`] column must be
    /// there (other results are ignored).
    pub fn from_table(table: StudyTable, path: &Path) -> Result<SweepFile> {
        let cols = SUMMARY_COLUMNS
            .iter()
            .map(|(name, _)| {
                table
                    .result(name)
                    .map(|c| c.values.as_slice())
                    .ok_or_else(|| Error::Input {
                        file: path.display().to_string(),
                        key: format!("summary/{name}"),
                        problem: "missing".into(),
                        allowed: "an HDF5 file written by `shpb sweep -o`".into(),
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        let rows = (0..table.len())
            .map(|i| RunSummary {
                index: table.run[i],
                inputs: table.inputs.iter().map(|c| c.values[i].clone()).collect(),
                peak_force_n: cols[0][i],
                displacement_at_peak_m: cols[1][i],
                peak_strain_rate_per_s: cols[2][i],
                equilibrium_ratio_at_peak: cols[3][i],
                time_to_equilibrium_s: cols[4][i],
            })
            .collect();
        Ok(SweepFile {
            keys: table.keys(),
            scene: table.scene,
            sweep: table.sweep,
            rows,
        })
    }
}

/// The study table of a sweep: one row per run, the swept values (`keys`, in order) as inputs
/// and the [`SUMMARY_COLUMNS`] as results, stamped with this version of shpb. A row without a
/// value for every key makes a ragged table, which [`write_study_hdf5`] refuses.
pub fn sweep_table(
    scene_text: &str,
    sweep: &[String],
    keys: &[String],
    rows: &[RunSummary],
) -> StudyTable {
    StudyTable {
        shpb_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: scene_text.to_string(),
        sweep: sweep.to_vec(),
        run: rows.iter().map(|r| r.index).collect(),
        inputs: keys
            .iter()
            .enumerate()
            .map(|(k, key)| InputColumn {
                key: key.clone(),
                values: rows
                    .iter()
                    .filter_map(|r| r.inputs.get(k).cloned())
                    .collect(),
            })
            .collect(),
        results: SUMMARY_COLUMNS
            .iter()
            .enumerate()
            .map(|(k, (name, units))| ResultColumn {
                name: name.to_string(),
                units: units.to_string(),
                values: rows.iter().map(|r| r.values()[k]).collect(),
            })
            .collect(),
    }
}

/// Writes a sweep's study file (layout in [`shpb_output::study`]): the scene text, the `--set`
/// specifications, the swept `keys` and one row per run.
pub fn write_sweep_hdf5(
    path: &Path,
    force: bool,
    scene_text: &str,
    sweep: &[String],
    keys: &[String],
    rows: &[RunSummary],
) -> Result<()> {
    write_study_hdf5(path, force, &sweep_table(scene_text, sweep, keys, rows))
}

/// Reads a file written by [`write_sweep_hdf5`].
pub fn read_sweep_hdf5(path: &Path) -> Result<SweepFile> {
    SweepFile::from_table(read_study_hdf5(path)?, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(index: usize, inputs: &[&str], force: f64) -> RunSummary {
        RunSummary {
            index,
            inputs: inputs.iter().map(|s| s.to_string()).collect(),
            peak_force_n: force,
            displacement_at_peak_m: 2e-4,
            peak_strain_rate_per_s: 500.0,
            equilibrium_ratio_at_peak: f64::NAN,
            time_to_equilibrium_s: 3.5e-5,
        }
    }

    #[test]
    fn sweep_rows_become_a_study_table_and_back() {
        let keys = ["pressure".to_string(), "shaper.thickness_m".to_string()];
        let rows = [
            row(0, &["5psi", "0.5mm"], 1e3),
            row(3, &["10psi", "1mm"], 2e3),
        ];
        let sweep = ["pressure=5psi,10psi".to_string(), "shard 1/2".to_string()];
        let table = sweep_table("scene", &sweep, &keys, &rows);
        assert_eq!(table.run, [0, 3]);
        assert_eq!(table.keys(), keys);
        assert_eq!(table.inputs[1].values, ["0.5mm", "1mm"]);
        assert_eq!(table.result("peak_force").unwrap().units, "N");
        assert_eq!(table.results.len(), SUMMARY_COLUMNS.len());
        let back = SweepFile::from_table(table, Path::new("t.h5")).unwrap();
        assert_eq!(back.sweep_without_shard(), ["pressure=5psi,10psi"]);
        assert_eq!(
            (back.keys.as_slice(), back.scene.as_str()),
            (&keys[..], "scene")
        );
        assert_eq!(back.rows.len(), 2);
        assert_eq!(back.rows[1].index, 3);
        assert_eq!(back.rows[1].inputs, rows[1].inputs);
        assert_eq!(back.rows[1].peak_force_n, 2e3);
        assert!(back.rows[0].equilibrium_ratio_at_peak.is_nan());
    }

    #[test]
    fn a_table_without_a_summary_column_is_refused() {
        let mut table = sweep_table("scene", &[], &[], &[row(0, &[], 1.0)]);
        table.results.retain(|c| c.name != "peak_strain_rate");
        let e = SweepFile::from_table(table, Path::new("t.h5"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("summary/peak_strain_rate"), "{e}");
    }
}

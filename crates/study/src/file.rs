//! The study file: a sweep's HDF5 (one row per run, inputs and results), read back by `merge`
//! and `--resume`.

use hdf5::types::VarLenUnicode;
use shpb_input::{Error, Result};
use shpb_output::io::{h5err, string_attr, vlu, write_atomically, write_dataset};
use std::path::Path;
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

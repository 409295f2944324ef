//! The study file of a sweep: its [`RunSummary`] rows as a [`StudyTable`] of the output layer,
//! which writes and reads the HDF5 (`shpb sweep -o`, `shpb merge`).

use crate::identity::{Identity, Stamp};
use crate::sweep::{RunSummary, SUMMARY_COLUMNS, input_columns};
use shpb_input::{Error, Result};
use shpb_output::study::{ResultColumn, StudyTable, read_study_hdf5, write_study_hdf5};
use std::path::{Path, PathBuf};

/// A sweep file read back (for `shpb merge`).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepFile {
    /// The version of shpb that wrote it.
    pub shpb_version: String,
    /// The scene text.
    pub scene: String,
    /// The `--set` specifications (and a `shard k/n` line for a shard).
    pub sweep: Vec<String>,
    /// What the sweep belongs to (`None` in a file written before shpb recorded it).
    pub identity: Option<Identity>,
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
        let mut t = sweep_table(
            &self.scene,
            &self.sweep,
            &self.keys,
            &self.rows,
            self.identity.as_ref(),
        );
        t.shpb_version = self.shpb_version.clone();
        t
    }

    /// The stamp of the file (`None` without an identity).
    pub fn stamp(&self) -> Option<Stamp> {
        Stamp::of_file(&self.shpb_version, &self.sweep, self.identity.as_ref())
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
                warnings: table.warnings_of(i).lines().map(str::to_string).collect(),
            })
            .collect();
        Ok(SweepFile {
            keys: table.keys(),
            shpb_version: table.shpb_version,
            scene: table.scene,
            sweep: table.sweep,
            identity: table.identity,
            rows,
        })
    }
}

/// The study table of a sweep: one row per run, the swept values (`keys`, in order) as inputs
/// (in SI units where they are numbers, [`input_columns`]) and the [`SUMMARY_COLUMNS`] as
/// results, stamped with this version of shpb and the sweep's `identity`. A row without a value
/// for every key makes a ragged table, which [`write_study_hdf5`] refuses.
pub fn sweep_table(
    scene_text: &str,
    sweep: &[String],
    keys: &[String],
    rows: &[RunSummary],
    identity: Option<&Identity>,
) -> StudyTable {
    StudyTable {
        shpb_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: scene_text.to_string(),
        sweep: sweep.to_vec(),
        identity: identity.cloned(),
        run: rows.iter().map(|r| r.index).collect(),
        inputs: input_columns(keys, rows),
        results: SUMMARY_COLUMNS
            .iter()
            .enumerate()
            .map(|(k, (name, units))| ResultColumn {
                name: name.to_string(),
                units: units.to_string(),
                values: rows.iter().map(|r| r.values()[k]).collect(),
            })
            .collect(),
        warnings: rows.iter().map(|r| r.warnings.join("\n")).collect(),
    }
}

/// Writes a sweep's study file (layout in [`shpb_output::study`]): the scene text, the `--set`
/// specifications, the sweep's identity, the swept `keys` and one row per run.
pub fn write_sweep_hdf5(
    path: &Path,
    force: bool,
    scene_text: &str,
    sweep: &[String],
    identity: Option<&Identity>,
    keys: &[String],
    rows: &[RunSummary],
) -> Result<()> {
    write_study_hdf5(
        path,
        force,
        &sweep_table(scene_text, sweep, keys, rows, identity),
    )
}

/// Reads a file written by [`write_sweep_hdf5`].
pub fn read_sweep_hdf5(path: &Path) -> Result<SweepFile> {
    SweepFile::from_table(read_study_hdf5(path)?, path)
}

/// The runs of shard `k/n` of a sweep of `total` runs, in order.
fn shard_runs((k, n): (u64, u64), total: u64) -> impl Iterator<Item = usize> {
    (k.saturating_sub(1)..total)
        .step_by(n.max(1) as usize)
        .map(|i| i as usize)
}

/// Joins the shard files of one sweep (`shpb merge`): every file must record the same sweep
/// (identity), each shard k/n must be there exactly once and hold exactly its runs, so the result
/// is the whole sweep with each run once, or an input error naming the file and what is wrong.
pub fn merge_shards(parts: Vec<(PathBuf, SweepFile)>) -> Result<SweepFile> {
    let err = |file: &Path, key: &str, problem: String, allowed: &str| Error::Input {
        file: file.display().to_string(),
        key: key.to_string(),
        problem,
        allowed: allowed.to_string(),
    };
    const SHARDS: &str = "the shard files of one `shpb sweep --shard k/n -o …` (same scene, \
                          set-up files, --set and shpb version), every k from 1 to n once";
    let mut stamps = Vec::new();
    for (p, f) in &parts {
        let stamp = f.stamp().ok_or_else(|| {
            err(
                p,
                "sweep_id",
                "the file records no sweep identity (written by an older shpb), so it cannot \
                 be checked to be a shard of the same sweep"
                    .into(),
                "shard files written by this shpb: run the shards again",
            )
        })?;
        stamps.push(stamp);
    }
    let (first_path, first) = (&parts[0].0, &stamps[0]);
    let n = first.identity.shard.1;
    let total = first.identity.runs_total;
    let mut taken: Vec<Option<&Path>> = vec![None; n as usize];
    for ((p, f), stamp) in parts.iter().zip(&stamps) {
        if !first.same_sweep(stamp) || f.keys != parts[0].1.keys {
            return Err(err(
                p,
                "sweep_id",
                format!(
                    "not a shard of the same sweep as {}; what differs: {}",
                    first_path.display(),
                    first.differences(stamp).join("; ")
                ),
                SHARDS,
            ));
        }
        let (k, m) = stamp.identity.shard;
        if m != n {
            return Err(err(
                p,
                "shard",
                format!(
                    "shard {k}/{m}, but {} is a shard of a split into {n}",
                    first_path.display()
                ),
                SHARDS,
            ));
        }
        if let Some(other) = taken[(k - 1) as usize] {
            return Err(err(
                p,
                "shard",
                format!(
                    "shard {k}/{n} is given twice ({} and {})",
                    other.display(),
                    p.display()
                ),
                SHARDS,
            ));
        }
        taken[(k - 1) as usize] = Some(p);
        let expected: Vec<usize> = shard_runs((k, n), total).collect();
        let mut found: Vec<usize> = f.rows.iter().map(|r| r.index).collect();
        found.sort_unstable();
        if found != expected {
            return Err(err(
                p,
                "summary/run",
                format!(
                    "holds {} runs, not the {} runs of shard {k}/{n} of {total}",
                    found.len(),
                    expected.len()
                ),
                SHARDS,
            ));
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| taken[(*k - 1) as usize].is_none())
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        let runs: usize = (1..=n)
            .filter(|k| taken[(*k - 1) as usize].is_none())
            .map(|k| shard_runs((k, n), total).count())
            .sum();
        return Err(err(
            Path::new("command line"),
            "INPUTS",
            format!(
                "the sweep is incomplete: shard{} {} missing ({runs} of its {total} runs)",
                if missing.len() > 1 { "s" } else { "" },
                missing.join(", ")
            ),
            SHARDS,
        ));
    }
    let mut parts = parts.into_iter().map(|(_, f)| f);
    let mut merged = parts.next().expect("at least one shard");
    for f in parts {
        merged.rows.extend(f.rows);
    }
    merged.rows.sort_by_key(|r| r.index);
    merged.sweep = merged.sweep_without_shard();
    if let Some(id) = &mut merged.identity {
        id.shard = (1, 1);
    }
    Ok(merged)
}

/// The study file of a sweep ([`write_sweep_hdf5`]) with each run's
/// `/runs/<index>` group written as `run` hands over its finished row, on this thread, while the
/// other runs go on (issue 45: that work leaves the serial end of the sweep). `points` are all
/// the sweep's rows-to-be (this shard's points, finished or not): their labels fix before any
/// run which input columns are SI numbers, as [`crate::sweep::input_columns`] of the finished table decides.
/// `run` gets the sink and returns the rows; they come back in index order. The file appears
/// only complete (written under a temporary name, [`shpb_output::study::write_study_hdf5_streamed`]).
#[allow(clippy::too_many_arguments)]
pub fn write_sweep_hdf5_streamed(
    path: &Path,
    force: bool,
    scene_text: &str,
    spec: &[String],
    identity: Option<&shpb_output::study::Identity>,
    (axes, points): (&[crate::sweep::Axis], &[crate::sweep::Point]),
    run: impl FnOnce(&mut dyn FnMut(&RunSummary) -> Result<()>) -> Result<Vec<RunSummary>>,
) -> Result<Vec<RunSummary>> {
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    let numeric: Vec<bool> = {
        let labelled: Vec<RunSummary> = points
            .iter()
            .map(|p| {
                let inputs = axes
                    .iter()
                    .zip(&p.coords)
                    .map(|(a, &c)| a.labels[c].clone())
                    .collect();
                RunSummary::from_values(p.index, inputs, [f64::NAN; 5])
            })
            .collect();
        input_columns(&keys, &labelled)
            .iter()
            .map(|c| c.si.is_some())
            .collect()
    };
    shpb_output::study::write_study_hdf5_streamed(path, force, |sink| {
        let mut rows = run(&mut |row: &RunSummary| {
            let mut one = sweep_table(scene_text, spec, &keys, std::slice::from_ref(row), identity);
            for (c, &si) in one.inputs.iter_mut().zip(&numeric) {
                if !si {
                    c.si = None;
                }
            }
            sink(&one)
        })?;
        rows.sort_by_key(|r| r.index);
        let table = sweep_table(scene_text, spec, &keys, &rows, identity);
        let same_columns = table
            .inputs
            .iter()
            .zip(&numeric)
            .all(|(c, &si)| c.si.is_some() == si);
        if !same_columns {
            return Err(Error::Hdf5 {
                file: path.display().to_string(),
                message: "the runs finished are not the points of the sweep".into(),
            });
        }
        Ok((table, rows))
    })
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
            warnings: Vec::new(),
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
        let table = sweep_table("scene", &sweep, &keys, &rows, None);
        assert_eq!(table.run, [0, 3]);
        assert_eq!(table.keys(), keys);
        assert_eq!(table.inputs[1].values, ["0.5mm", "1mm"]);
        // Inputs in SI units: `0.5mm` in a column of metres, `5psi` in pascals.
        assert_eq!(
            table.inputs[1].si,
            Some((vec![0.5e-3, 1e-3], "m".to_string()))
        );
        let (pa, units) = table.inputs[0].si.clone().unwrap();
        assert_eq!(units, "Pa");
        assert_eq!(pa[1], 10.0 * shpb_input::units::PSI_PA);
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
        let mut table = sweep_table("scene", &[], &[], &[row(0, &[], 1.0)], None);
        table.results.retain(|c| c.name != "peak_strain_rate");
        let e = SweepFile::from_table(table, Path::new("t.h5"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("summary/peak_strain_rate"), "{e}");
    }
}

#[cfg(test)]
mod merge_tests {
    use super::*;
    use crate::sweep::{axes_sha256, parse_axes};
    use shpb_input::provenance::InputFile;

    fn shard(scene: &str, k: usize, n: usize) -> (PathBuf, SweepFile) {
        let set = vec!["velocity1_m_s=1,2,3,4,5".to_string()];
        let axes = parse_axes(&set).unwrap();
        let file = InputFile {
            path: "s.toml".into(),
            sha256: shpb_input::provenance::sha256_hex(scene.as_bytes()),
        };
        let stamp = Stamp::new(
            Path::new("s.toml"),
            &[file],
            &set,
            axes_sha256(&axes),
            (k, n),
            5,
        );
        let rows = (k - 1..5)
            .step_by(n)
            .map(|i| RunSummary {
                index: i,
                inputs: vec![format!("{}", i + 1)],
                peak_force_n: i as f64,
                displacement_at_peak_m: 0.0,
                peak_strain_rate_per_s: f64::NAN,
                equilibrium_ratio_at_peak: f64::NAN,
                time_to_equilibrium_s: f64::NAN,
                warnings: Vec::new(),
            })
            .collect();
        let mut sweep = set.clone();
        sweep.push(format!("shard {k}/{n}"));
        (
            PathBuf::from(format!("part{k}.h5")),
            SweepFile {
                shpb_version: stamp.shpb_version.clone(),
                scene: scene.into(),
                sweep,
                identity: Some(stamp.identity),
                keys: vec!["velocity1_m_s".into()],
                rows,
            },
        )
    }

    fn problem(parts: Vec<(PathBuf, SweepFile)>) -> String {
        let e = merge_shards(parts).expect_err("refused");
        assert_eq!(e.exit_code(), 2);
        e.to_string()
    }

    #[test]
    fn shards_merge_only_when_each_is_there_once_and_of_one_sweep() {
        let m = merge_shards(vec![shard("a", 2, 2), shard("a", 1, 2)]).unwrap();
        assert_eq!(
            m.rows.iter().map(|r| r.index).collect::<Vec<_>>(),
            [0, 1, 2, 3, 4]
        );
        assert_eq!(m.identity.as_ref().unwrap().shard, (1, 1));
        assert_eq!(m.sweep, ["velocity1_m_s=1,2,3,4,5"]);
        let whole = merge_shards(vec![shard("a", 1, 1)]).unwrap();
        assert_eq!(whole.rows.len(), 5);

        let e = problem(vec![shard("a", 1, 2)]);
        assert!(
            e.contains("incomplete: shard 2/2 missing (2 of its 5 runs)"),
            "{e}"
        );
        let e = problem(vec![shard("a", 1, 2), shard("a", 1, 2)]);
        assert!(e.contains("shard 1/2 is given twice"), "{e}");
        let e = problem(vec![shard("a", 1, 2), shard("b", 2, 2)]);
        assert!(
            e.contains("not a shard of the same sweep") && e.contains("scene"),
            "{e}"
        );
        let e = problem(vec![shard("a", 1, 2), shard("a", 2, 3)]);
        assert!(e.contains("split into 2"), "{e}");
        let mut short = shard("a", 2, 2);
        short.1.rows.pop();
        let e = problem(vec![shard("a", 1, 2), short]);
        assert!(e.contains("part2.h5") && e.contains("summary/run"), "{e}");
        let mut old = shard("a", 2, 2);
        old.1.identity = None;
        let e = problem(vec![shard("a", 1, 2), old]);
        assert!(e.contains("no sweep identity"), "{e}");
    }
}

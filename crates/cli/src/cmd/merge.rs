//! `shpb merge`: the shard files of one sweep joined into one file.

use super::common::write_study;
use shpb_input::{Error, Result};
use shpb_output::io::check_output;
use std::path::{Path, PathBuf};

/// `shpb merge`: joins shard files of one sweep (same scene and `--set`), sorted by run index.
pub fn merge(inputs: &[PathBuf], output: &Path, csv: Option<&Path>, force: bool) -> Result<()> {
    for p in [Some(output), csv].into_iter().flatten() {
        check_output(p, force)?;
    }
    let mut merged: Option<shpb_study::file::SweepFile> = None;
    for p in inputs {
        let part = shpb_study::file::read_sweep_hdf5(p)?;
        merged = Some(match merged {
            None => part,
            Some(mut m) => {
                if m.scene != part.scene
                    || m.sweep_without_shard() != part.sweep_without_shard()
                    || m.keys != part.keys
                {
                    return Err(Error::Input {
                        file: p.display().to_string(),
                        key: "sweep".into(),
                        problem: "not a shard of the same sweep as the first file (scene or --set differ)".into(),
                        allowed: "shards of one `shpb sweep` (same scene and --set, different --shard)".into(),
                    });
                }
                m.rows.extend(part.rows);
                m
            }
        });
    }
    let mut m = merged.expect("clap requires at least one input");
    m.rows.sort_by_key(|r| r.index);
    m.rows.dedup_by_key(|r| r.index);
    let table = shpb_study::sweep::summary_csv_keys(&m.keys, &m.rows);
    let spec = m.sweep_without_shard();
    write_study(
        &m.scene,
        &spec,
        &m.keys,
        &m.rows,
        &table,
        (Some(output), csv),
    )?;
    eprintln!("merged {} runs", m.rows.len());
    Ok(())
}

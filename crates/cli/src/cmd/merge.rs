//! `shpb merge`: the shard files of one sweep joined into one file.

use super::common::{plan, write_all, write_study};
use shpb_input::Result;
use std::path::{Path, PathBuf};

/// `shpb merge`: joins the shard files of one sweep, sorted by run index. Every file must record
/// the same sweep (scene and set-up files by content, `--set`, shpb version) and every shard k/n
/// must be there exactly once ([`shpb_study::file::merge_shards`]): one of two shards, or a shard
/// given twice, is an input error (exit 2) naming the file and what is wrong. An output may not
/// be one of the shards, even with `--force`.
pub fn merge(inputs: &[PathBuf], output: &Path, csv: Option<&Path>, force: bool) -> Result<()> {
    let outputs = plan(
        force,
        &[
            (Some(output), "--output", &["h5", "hdf5"]),
            (csv, "--csv", &["csv"][..]),
        ],
    )?;
    outputs.not_inputs(inputs)?;
    let parts = inputs
        .iter()
        .map(|p| Ok((p.clone(), shpb_study::file::read_sweep_hdf5(p)?)))
        .collect::<Result<Vec<_>>>()?;
    let m = shpb_study::file::merge_shards(parts)?;
    let table = shpb_study::sweep::summary_csv_keys(&m.keys, &m.rows);
    write_all(&outputs, || {
        write_study(
            &m.scene,
            &m.sweep,
            m.identity.as_ref(),
            &m.keys,
            &m.rows,
            &table,
            (Some(output), csv),
            force,
        )
    })?;
    eprintln!("merged {} runs", m.rows.len());
    Ok(())
}

//! `shpb sweep`: a scene over the Cartesian product of swept parameters.

use super::common::{say, write_study};
use shpb_input::{Error, Result};
use shpb_output::io::check_output;
use std::path::Path;

/// `shpb sweep`: validates every point first, runs the unfinished ones with a progress bar and a
/// checkpoint, prints and writes the summary table.
pub fn sweep(
    scene: &Path,
    set: &[String],
    jobs: usize,
    shard: Option<&str>,
    (output, csv, plot): (Option<&Path>, Option<&Path>, Option<&Path>),
    resume: bool,
    force: bool,
) -> Result<()> {
    use shpb_study::sweep::{
        Checkpoint, check_points, parse_axis, parse_shard, product, run_points,
    };
    if !resume {
        for p in [output, csv, plot].into_iter().flatten() {
            check_output(p, force)?;
        }
    }
    if !scene.is_file() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "SCENE".into(),
            problem: format!("cannot read {}: no such file", scene.display()),
            allowed: "a scene .toml file".into(),
        });
    }
    let axes = set
        .iter()
        .map(|s| parse_axis(s))
        .collect::<Result<Vec<_>>>()?;
    if plot.is_some() && axes.len() > 2 {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--plot".into(),
            problem: format!("{} swept parameters", axes.len()),
            allowed: "one (line plot) or two (heat map) --set parameters".into(),
        });
    }
    let mut points = product(&axes);
    let mut spec = set.to_vec();
    if let Some(s) = shard {
        let (k, n) = parse_shard(s)?;
        points = shpb_study::sweep::shard(points, k, n);
        spec.push(format!("shard {k}/{n}"));
    }
    check_points(scene, &axes, &points)?;
    let anchor = output.or(csv);
    if resume && anchor.is_none() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--resume".into(),
            problem: "no output to resume".into(),
            allowed: "the same -o/--csv as the interrupted sweep".into(),
        });
    }
    let checkpoint = match anchor {
        Some(a) => Some(Checkpoint::open(
            a,
            scene,
            &spec,
            axes.len(),
            resume,
            force,
        )?),
        None => None,
    };
    let mut rows = checkpoint.as_ref().map(|c| c.1.clone()).unwrap_or_default();
    let finished: std::collections::HashSet<usize> = rows.iter().map(|r| r.index).collect();
    let todo: Vec<_> = points
        .into_iter()
        .filter(|p| !finished.contains(&p.index))
        .collect();
    if resume {
        eprintln!(
            "shpb: resuming: {} runs done, {} to go",
            rows.len(),
            todo.len()
        );
    }
    let bar = indicatif::ProgressBar::new(todo.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let failed = std::sync::Mutex::new(None);
    let new_rows = run_points(scene, &axes, &todo, jobs, |row| {
        if let Some((c, _)) = &checkpoint
            && let Err(e) = c.record(row)
        {
            *failed.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
        }
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    if let Some(e) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    rows.extend(new_rows);
    rows.sort_by_key(|r| r.index);
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    let table = shpb_study::sweep::summary_csv_keys(&keys, &rows);
    say(table.trim_end())?;
    let scene_text = std::fs::read_to_string(scene).map_err(|e| Error::io(scene, e))?;
    write_study(&scene_text, &spec, &keys, &rows, &table, (output, csv))?;
    if let Some(p) = plot {
        sweep_plot(p, resume || force, &axes, &rows)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some((c, _)) = checkpoint {
        c.finish()?;
    }
    Ok(())
}

/// The summary plot of a finished sweep (rows of a sharded sweep that are missing stay blank).
fn sweep_plot(
    path: &Path,
    force: bool,
    axes: &[shpb_study::sweep::Axis],
    rows: &[shpb_study::sweep::RunSummary],
) -> Result<()> {
    let numeric = |a: &shpb_study::sweep::Axis| -> Result<Vec<f64>> {
        a.labels
            .iter()
            .map(|l| {
                shpb_study::sweep::number_and_unit(l)
                    .map(|(v, _)| v)
                    .ok_or_else(|| Error::Input {
                        file: "command line".into(),
                        key: "--plot".into(),
                        problem: format!("`{l}` of {} is not a number", a.key),
                        allowed: "numeric swept values".into(),
                    })
            })
            .collect()
    };
    let label = |a: &shpb_study::sweep::Axis| {
        let unit = a
            .labels
            .first()
            .and_then(|l| shpb_study::sweep::number_and_unit(l))
            .map(|(_, u)| u)
            .unwrap_or_default();
        if unit.is_empty() {
            a.key.clone()
        } else {
            format!("{} ({unit})", a.key)
        }
    };
    let nx = axes[0].labels.len();
    let ny = axes.get(1).map(|a| a.labels.len()).unwrap_or(1);
    let mut f = vec![vec![f64::NAN; ny]; nx];
    let mut r = vec![vec![f64::NAN; ny]; nx];
    for row in rows {
        let (i, j) = (row.index / ny, row.index % ny);
        f[i][j] = row.peak_force_n;
        r[i][j] = row.peak_strain_rate_per_s;
    }
    let xv = numeric(&axes[0])?;
    let xl = label(&axes[0]);
    match axes.get(1) {
        None => shpb_output::plot::sweep_figure(path, force, (&xl, &xv), None, &f, &r),
        Some(a) => {
            let yv = numeric(a)?;
            let yl = label(a);
            shpb_output::plot::sweep_figure(path, force, (&xl, &xv), Some((&yl, &yv)), &f, &r)
        }
    }
}

//! `shpb sweep`: a scene over the Cartesian product of swept parameters.

use super::common::{finite, plan, report_unless_stdout, write_all, write_study};
use shpb_input::{Error, Result};
use shpb_output::atomic::is_stdout;
use shpb_output::io::check_output;
use shpb_study::identity::Stamp;
use shpb_study::sweep::{Axis, Limits, Point, RunSummary};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `shpb sweep`: refuses a sweep that cannot finish on the machine, validates every point first
/// (in parallel, on the pool of the runs),
/// runs the unfinished ones with a progress bar and a checkpoint stamped with what the sweep
/// belongs to, prints and writes the summary table. `--resume` continues the checkpoint of the
/// same sweep (and refuses another's), and says so when the sweep is already complete.
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
        Checkpoint, Outputs, check_points_on, checkpoint_path, estimate, parse_axes, parse_shard,
        run_points_on, shard_points,
    };
    shpb_study::sweep::check_jobs(jobs)?;
    let outputs = [output, csv, plot];
    // A resumed sweep owns the outputs it left; the other checks hold for it too.
    let out_plan = plan(
        force || resume,
        &[
            (output, "--output", &["h5", "hdf5"][..]),
            (csv, "--csv", &["csv"][..]),
            (plot, "--plot", &["png"][..]),
        ],
    )?;
    out_plan.not_inputs(&[scene.to_path_buf()])?;
    shpb_study::sweep::require_scene(scene)?;
    let axes = parse_axes(set)?;
    if plot.is_some() && axes.len() > 2 {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--plot".into(),
            problem: format!("{} swept parameters", axes.len()),
            allowed: "one (line plot) or two (heat map) --set parameters".into(),
        });
    }
    let (k, n) = match shard {
        Some(s) => parse_shard(s)?,
        None => (1, 1),
    };
    // The file the checkpoint sits beside (not standard output).
    let anchor = output
        .filter(|p| !is_stdout(p))
        .or(csv.filter(|p| !is_stdout(p)));
    // The checkpoint beside the anchor is not also an output (it is removed when the sweep ends).
    if let Some(a) = anchor {
        let checkpoint = checkpoint_path(a);
        for (p, flag) in [(output, "--output"), (csv, "--csv"), (plot, "--plot")] {
            if p.is_some_and(|p| shpb_output::plan::same_file(p, &checkpoint)) {
                return Err(Error::Input {
                    file: "command line".into(),
                    key: flag.into(),
                    problem: format!(
                        "{} is the checkpoint of this sweep, removed when it ends",
                        checkpoint.display()
                    ),
                    allowed: "an output name that is not OUTPUT.partial.csv".into(),
                });
            }
        }
    }
    if resume && anchor.is_none() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--resume".into(),
            problem: "no output to resume".into(),
            allowed: "the same -o/--csv as the interrupted sweep".into(),
        });
    }
    // Before anything is allocated: can the sweep finish on this machine?
    let plan = estimate(
        &axes,
        (k, n),
        Outputs {
            hdf5: output.is_some(),
            csv: csv.is_some(),
            checkpoint: anchor.is_some(),
        },
    );
    plan.check(&Limits::of_machine(
        &outputs.into_iter().flatten().collect::<Vec<_>>(),
    ))?;
    let total = plan.runs_total.expect("checked") as u64;
    let points = shard_points(&axes, k, n);
    // One pool for the validation and the runs (issue 45: the points are validated in parallel).
    let pool = shpb_study::sweep::thread_pool(jobs)?;
    let files = check_points_on(&pool, scene, &axes, &points)?;
    out_plan.not_inputs(&files.iter().map(|f| f.path.clone()).collect::<Vec<_>>())?;
    let stamp = Stamp::new(
        scene,
        &files,
        set,
        shpb_study::sweep::axes_sha256(&axes),
        (k, n),
        total,
    );
    let mut spec = set.to_vec();
    if shard.is_some() {
        spec.push(format!("shard {k}/{n}"));
    }
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    let scene_text = std::fs::read_to_string(scene).map_err(|e| Error::io(scene, e))?;

    // A finished sweep: its output is there and no checkpoint (or an empty one, created by a
    // sweep stopped before it wrote anything).
    if resume
        && !force
        && let Some(a) = anchor
        && a.exists()
        && std::fs::metadata(checkpoint_path(a)).map_or(true, |m| m.len() == 0)
    {
        let rows = finished_rows(output, csv, &stamp, &axes, &points)?;
        let table = shpb_study::sweep::summary_csv_keys(&keys, &rows);
        report_unless_stdout(&out_plan, &table, || sweep_json(&keys, &rows))?;
        eprintln!(
            "shpb: the sweep is complete: {} holds all its {} runs; nothing to run (--force \
             runs it again and replaces the outputs)",
            a.display(),
            rows.len()
        );
        // Outputs asked for now that the finished sweep did not write.
        fn missing(p: Option<&Path>) -> Option<&Path> {
            p.filter(|p| !p.exists())
        }
        let missing_plan = super::common::plan(
            false,
            &[
                (missing(output), "--output", &[]),
                (missing(csv), "--csv", &[]),
                (missing(plot), "--plot", &[]),
            ],
        )?;
        return write_all(&missing_plan, || {
            write_study(
                &scene_text,
                &spec,
                Some(&stamp.identity),
                &keys,
                &rows,
                &table,
                (missing(output), missing(csv)),
                false,
            )?;
            if let Some(p) = missing(plot) {
                sweep_plot(p, false, &axes, &rows)?;
            }
            Ok(())
        });
    }

    let checkpoint = match anchor {
        Some(a) => Some(Checkpoint::open(a, &stamp, keys.len(), resume, force)?),
        None => None,
    };
    let (checkpoint, resumed) = match checkpoint {
        Some((c, r)) => (Some(c), r),
        None => (None, None),
    };
    if resumed.is_none() && !force {
        // A fresh start (also `--resume` without a checkpoint): the outputs must not exist.
        // Checked again now that the checkpoint is locked: a sweep that has just finished on
        // the same output wrote its files before it let the checkpoint go.
        if let Some(e) = outputs
            .into_iter()
            .flatten()
            .find_map(|p| check_output(p, false).err())
        {
            if let Some(c) = checkpoint {
                c.finish()?;
            }
            return Err(e);
        }
    }
    let took_over = resumed.is_some();
    let rows = resumed.unwrap_or_default();
    let finished: std::collections::HashSet<usize> = rows.iter().map(|r| r.index).collect();
    let todo: Vec<Point> = points
        .iter()
        .filter(|p| !finished.contains(&p.index))
        .cloned()
        .collect();
    if resume {
        match took_over {
            true => eprintln!(
                "shpb: resuming: {} runs done, {} to go",
                rows.len(),
                todo.len()
            ),
            false => eprintln!(
                "shpb: no checkpoint to resume ({} absent): running the whole sweep",
                anchor.map(checkpoint_path).unwrap_or_default().display()
            ),
        }
    }
    let done = Arc::new(AtomicUsize::new(rows.len()));
    let runs_here = rows.len() + todo.len();
    if let Some(c) = &checkpoint {
        let (done, path, command) = (
            done.clone(),
            c.path.clone(),
            crate::interrupt::resume_command(),
        );
        crate::interrupt::set_message(move || {
            format!(
                "{} of {runs_here} runs are done and kept in {}; resume with:\n  {command}",
                done.load(Ordering::SeqCst),
                path.display()
            )
        });
    }
    let bar = indicatif::ProgressBar::new(todo.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    // The runs: every row, the resumed ones first, is handed to `sink` on this thread as it
    // finishes (issue 45: with `-o`, the study file's `/runs/<index>` groups are written while
    // the other runs go on, not after the last one); the rows come back in index order.
    let run_all = |sink: &mut dyn FnMut(&RunSummary) -> Result<()>| -> Result<Vec<RunSummary>> {
        let mut rows = rows;
        for r in &rows {
            sink(r)?;
        }
        let failed = std::sync::Mutex::new(None);
        let stop = std::sync::atomic::AtomicBool::new(false);
        let (tx, rx) = std::sync::mpsc::channel::<RunSummary>();
        let (new_rows, sunk) = std::thread::scope(|s| {
            let runs = s.spawn(|| {
                let tx = tx;
                run_points_on(
                    &pool,
                    scene,
                    &axes,
                    &todo,
                    |row| {
                        if let Some(c) = &checkpoint
                            && let Err(e) = c.record(row)
                        {
                            *failed.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
                        }
                        done.fetch_add(1, Ordering::SeqCst);
                        bar.inc(1);
                        // The receiver is gone only once a write has failed (the runs stop).
                        let _ = tx.send(row.clone());
                    },
                    &|| !stop.load(Ordering::SeqCst),
                )
            });
            let mut sunk = Ok(());
            for row in rx {
                if sunk.is_ok() {
                    sunk = sink(&row);
                    if sunk.is_err() {
                        stop.store(true, Ordering::SeqCst);
                    }
                }
            }
            let new_rows = match runs.join() {
                Ok(r) => r,
                Err(panic) => std::panic::resume_unwind(panic),
            };
            (new_rows, sunk)
        });
        bar.finish_and_clear();
        let new_rows = new_rows?;
        sunk?;
        if let Some(e) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
            return Err(e);
        }
        rows.extend(new_rows.rows);
        rows.sort_by_key(|r| r.index);
        Ok(rows)
    };
    // The outputs were checked before the runs; a resumed sweep owns the ones it left.
    let replace = force || took_over;
    // The table, the CSV and the plot of the finished rows.
    let finish = |rows: &[RunSummary]| -> Result<()> {
        let table = shpb_study::sweep::summary_csv_keys(&keys, rows);
        report_unless_stdout(&out_plan, &table, || sweep_json(&keys, rows))?;
        write_study(
            &scene_text,
            &spec,
            Some(&stamp.identity),
            &keys,
            rows,
            &table,
            (None, csv),
            replace,
        )?;
        if let Some(p) = plot {
            sweep_plot(p, replace || resume, &axes, rows)?;
        }
        Ok(())
    };
    match output {
        // The study file is written as the runs finish, the other outputs once they all have.
        Some(out) => write_all(&out_plan, || {
            let rows = shpb_study::file::write_sweep_hdf5_streamed(
                out,
                replace,
                &scene_text,
                &spec,
                Some(&stamp.identity),
                (&axes, &points),
                run_all,
            )?;
            finish(&rows)
        })?,
        None => {
            let rows = run_all(&mut |_| Ok(()))?;
            write_all(&out_plan, || finish(&rows))?;
        }
    }
    if let Some(c) = checkpoint {
        c.finish()?;
    }
    crate::interrupt::clear_message();
    Ok(())
}

/// The runs of a finished sweep from its output (`-o`, else `--csv`), which must be of the sweep
/// stamped `stamp` and hold exactly its `points`; else an input error naming what differs.
fn finished_rows(
    output: Option<&Path>,
    csv: Option<&Path>,
    stamp: &Stamp,
    axes: &[Axis],
    points: &[Point],
) -> Result<Vec<RunSummary>> {
    let other = |file: &Path, problem: String| Error::Input {
        file: file.display().to_string(),
        key: "--resume".into(),
        problem,
        allowed: "the output of the same sweep (scene, set-up files, --set, --shard, shpb \
                  version); or --force to run the sweep again and replace it"
            .into(),
    };
    let expected: Vec<usize> = points.iter().map(|p| p.index).collect();
    if let Some(path) = output {
        let file = shpb_study::file::read_sweep_hdf5(path)?;
        let Some(then) = file.stamp() else {
            return Err(other(
                path,
                "the file records no sweep identity (written by an older shpb): cannot tell \
                 whether it is this sweep"
                    .into(),
            ));
        };
        let differences = then.differences(stamp);
        if !differences.is_empty() {
            return Err(other(
                path,
                format!(
                    "the file holds another sweep; what differs: {}",
                    differences.join("; ")
                ),
            ));
        }
        let found: Vec<usize> = file.rows.iter().map(|r| r.index).collect();
        if found != expected {
            return Err(other(
                path,
                format!(
                    "holds {} runs, not the {} of this sweep",
                    found.len(),
                    expected.len()
                ),
            ));
        }
        return Ok(file.rows);
    }
    // A CSV records no identity: its header and input cells must be this sweep's.
    let path = csv.expect("an anchor");
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut rows: Vec<RunSummary> = points
        .iter()
        .map(|p| RunSummary {
            index: p.index,
            inputs: axes
                .iter()
                .zip(&p.coords)
                .map(|(a, &c)| a.labels[c].clone())
                .collect(),
            peak_force_n: f64::NAN,
            displacement_at_peak_m: f64::NAN,
            peak_strain_rate_per_s: f64::NAN,
            equilibrium_ratio_at_peak: f64::NAN,
            time_to_equilibrium_s: f64::NAN,
            warnings: Vec::new(),
        })
        .collect();
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    let expected = shpb_study::sweep::summary_csv_keys(&keys, &rows);
    let (found, wanted) = (text.lines().count(), expected.lines().count());
    if found != wanted {
        return Err(other(
            path,
            format!(
                "holds {} runs, not the {} of this sweep",
                found.saturating_sub(1),
                wanted - 1
            ),
        ));
    }
    let inputs = 1 + keys.len();
    for (i, (line, want)) in text.lines().zip(expected.lines()).enumerate() {
        let cells = shpb_study::sweep::split_csv_line(line);
        let want = shpb_study::sweep::split_csv_line(want);
        let same = if i == 0 {
            cells == want
        } else {
            cells.len() == want.len() && cells[..inputs] == want[..inputs]
        };
        if !same {
            return Err(other(
                path,
                format!("line {}, `{line}`, is not of this sweep's summary", i + 1),
            ));
        }
        if i > 0 {
            let r = &mut rows[i - 1];
            let (values, warnings) = cells[inputs..].split_at(cells.len() - inputs - 1);
            r.warnings = shpb_study::sweep::warnings_of_cell(&warnings[0]);
            let v: Vec<f64> = values
                .iter()
                .map(|c| c.parse().unwrap_or(f64::NAN))
                .collect();
            (
                r.peak_force_n,
                r.displacement_at_peak_m,
                r.peak_strain_rate_per_s,
                r.equilibrium_ratio_at_peak,
                r.time_to_equilibrium_s,
            ) = (v[0], v[1], v[2], v[3], v[4]);
        }
    }
    Ok(rows)
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

/// The summary of a sweep as JSON: one object per run with its inputs (SI value, unit and the
/// text written; names as text) and its results with units.
fn sweep_json(keys: &[String], rows: &[shpb_study::sweep::RunSummary]) -> serde_json::Value {
    let columns = shpb_study::sweep::input_columns(keys, rows);
    let runs: Vec<serde_json::Value> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let inputs: serde_json::Map<String, serde_json::Value> = columns
                .iter()
                .map(|c| {
                    let v = match &c.si {
                        Some((si, units)) => serde_json::json!({
                            "value": finite(si[i]),
                            "unit": units,
                            "as_written": c.values[i],
                        }),
                        None => serde_json::json!(c.values[i]),
                    };
                    (c.key.clone(), v)
                })
                .collect();
            let results: serde_json::Map<String, serde_json::Value> =
                shpb_study::sweep::SUMMARY_COLUMNS
                    .iter()
                    .zip(r.values())
                    .map(|((name, unit), v)| {
                        (
                            name.to_string(),
                            serde_json::json!({"value": finite(v), "unit": unit}),
                        )
                    })
                    .collect();
            serde_json::json!({
                "run": r.index,
                "inputs": inputs,
                "results": results,
                "warnings": r.warnings,
            })
        })
        .collect();
    serde_json::json!({ "runs": runs })
}

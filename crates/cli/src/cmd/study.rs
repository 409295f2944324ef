//! `shpb study`: uncertainty propagation. The scene's distributions (and the gun's shot-to-shot
//! scatter) drawn by a seeded Latin hypercube, each sample a normal run, and the statistics of
//! every summary quantity (`shpb_study::uq`, docs/physics.md §10).

use super::common::{finite, quiet_mode, report_unless_stdout, warn, write_all};
use shpb_input::{Error, Result};
use shpb_study::uq::{RunTraces, Study, StudyPlan, Trace, bands};
use std::path::Path;

/// The outputs of `shpb study`.
#[derive(Debug, Clone, Copy, Default)]
pub struct StudyOutputs<'a> {
    /// HDF5 study file (`-o`): the runs as a sweep's file, with the study in its `sweep` attribute.
    pub output: Option<&'a Path>,
    /// CSV of the runs (`--csv`).
    pub csv: Option<&'a Path>,
    /// CSV of the statistics (`--summary`).
    pub summary: Option<&'a Path>,
    /// PNG of the bands (`--plot`).
    pub plot: Option<&'a Path>,
}

/// `shpb study`: checks the outputs, draws the plan's samples, runs them on `jobs` threads with a
/// progress bar, prints the statistics (mean, sd, 5/50/95 %, first-order indices) and writes the
/// outputs atomically (an existing file only with `force`).
pub fn study(
    scene: &Path,
    plan: &StudyPlan,
    jobs: usize,
    outputs: StudyOutputs,
    force: bool,
) -> Result<()> {
    shpb_study::sweep::check_jobs(jobs)?;
    let out_plan = super::common::plan(
        force,
        &[
            (outputs.output, "--output", &["h5", "hdf5"][..]),
            (outputs.csv, "--csv", &["csv"][..]),
            (outputs.summary, "--summary", &["csv"][..]),
            (outputs.plot, "--plot", &["png"][..]),
        ],
    )?;
    out_plan.not_inputs(&[scene.to_path_buf()])?;
    let bar = indicatif::ProgressBar::new(plan.samples as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} samples, ETA {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let study =
        shpb_study::uq::study_rows(scene, plan, jobs, outputs.plot.is_some(), |_| bar.inc(1))?;
    bar.finish_and_clear();
    let spec = study.specification();
    if study.inputs.is_empty() {
        warn(
            "the scene has no distribution and no gun scatter applies: every sample is the same run",
        );
    }
    if !quiet_mode() {
        for line in &spec {
            eprintln!("shpb: {line}");
        }
    }
    let stats = study.statistics_csv();
    report_unless_stdout(&out_plan, &study.statistics_table(), || study_json(&study))?;
    let keys = study.keys();
    let scene_text = match outputs.output {
        Some(_) => std::fs::read_to_string(scene).map_err(|e| Error::io(scene, e))?,
        None => String::new(),
    };
    write_all(&out_plan, || {
        if let Some(p) = outputs.csv {
            let table = shpb_study::sweep::summary_csv_keys(&keys, &study.rows);
            shpb_output::io::write_text_atomically(p, force, &table)?;
        }
        if let Some(p) = outputs.summary {
            shpb_output::io::write_text_atomically(p, force, &stats)?;
        }
        if let Some(p) = outputs.output {
            shpb_study::file::write_sweep_hdf5(
                p,
                force,
                &scene_text,
                &spec,
                None,
                &keys,
                &study.rows,
            )?;
        }
        if let Some(p) = outputs.plot {
            band_plot(p, force, &study.traces)?;
        }
        Ok(())
    })
}

/// The band figure: the contact force on loading against approach, the reduced back force and
/// the transmission gauge's strain against time, 5 / 50 / 95 %.
fn band_plot(path: &Path, force: bool, traces: &[RunTraces]) -> Result<()> {
    /// One panel: which trace of a run it draws, its caption, and its axes (label, scale).
    struct Spec {
        pick: fn(&RunTraces) -> Option<&Trace>,
        title: &'static str,
        x: (&'static str, f64),
        y: (&'static str, f64),
    }
    let specs = [
        Spec {
            pick: |t| t.force_approach.as_ref(),
            title: "contact force on loading, 5 / 50 / 95 % at each approach",
            x: ("approach (µm)", 1e6),
            y: ("force (kN)", 1e-3),
        },
        Spec {
            pick: |t| t.back_force.as_ref(),
            title: "reduced back force, 5 / 50 / 95 %",
            x: ("time (µs)", 1e6),
            y: ("force (kN)", 1e-3),
        },
        Spec {
            pick: |t| t.transmitted_strain.as_ref(),
            title: "transmission gauge strain, 5 / 50 / 95 %",
            x: ("time (µs)", 1e6),
            y: ("strain (µε)", 1e6),
        },
    ];
    let drawn: Vec<_> = specs
        .iter()
        .filter_map(|spec| {
            let runs: Vec<&Trace> = traces.iter().filter_map(spec.pick).collect();
            bands(&runs).map(|b| (spec, b))
        })
        .collect();
    let panels: Vec<shpb_output::plot::BandPanel> = drawn
        .iter()
        .map(|(spec, (x, p))| shpb_output::plot::BandPanel {
            title: spec.title,
            x_label: spec.x.0,
            x_scale: spec.x.1,
            y_label: spec.y.0,
            y_scale: spec.y.1,
            x,
            p5_p50_p95: [&p[0], &p[1], &p[2]],
        })
        .collect();
    if panels.is_empty() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--plot".into(),
            problem: "the scene's runs have no contact, gauge signals or reduction to draw".into(),
            allowed: "a scene with spheres or bars and gauges".into(),
        });
    }
    shpb_output::plot::band_figure(path, force, &panels)
}

/// The study as JSON: its specification and each quantity's statistics.
fn study_json(study: &Study) -> serde_json::Value {
    let keys = study.keys();
    let quantities: Vec<serde_json::Value> = study
        .statistics()
        .iter()
        .map(|s| {
            let indices: serde_json::Map<String, serde_json::Value> = keys
                .iter()
                .zip(&s.first_order)
                .map(|(k, v)| (k.clone(), finite(*v)))
                .collect();
            serde_json::json!({
                "quantity": s.name,
                "unit": s.unit,
                "n": s.count,
                "mean": finite(s.mean),
                "sd": finite(s.sd),
                "p5": finite(s.p5_p50_p95[0]),
                "p50": finite(s.p5_p50_p95[1]),
                "p95": finite(s.p5_p50_p95[2]),
                "first_order": indices,
            })
        })
        .collect();
    serde_json::json!({"study": study.specification(), "quantities": quantities})
}

//! `shpb bench`: the speed/accuracy table a user needs to pick a fidelity preset, the measured
//! price of the physics knobs, and memory against bar length.

use crate::convergence::{metrics, rms_difference, signal};
use shpb_core::fidelity::Fidelity;
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// One row of the bench: a variant of the scene, its run time and its errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// What was run.
    pub label: String,
    /// Median wall-clock run time over the repeats, s.
    pub runtime_s: f64,
    /// Peak contact force, N.
    pub peak_force_n: f64,
    /// Approach at peak force, m.
    pub displacement_at_peak_m: f64,
    /// Relative peak-force difference from the reference.
    pub peak_error: f64,
    /// Relative difference of the displacement at peak from the reference.
    pub displacement_error: f64,
    /// RMS difference of the transmission-gauge strain from the reference, relative to its peak.
    pub signal_rms_error: f64,
}

/// Memory use at one bar-length scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryRow {
    /// Incident plus transmission bar length, m.
    pub bar_length_m: f64,
    /// Bar nodes at the preset's cell size.
    pub nodes: usize,
    /// Peak resident set of the process after the run (VmHWM), bytes (None off Linux).
    pub peak_rss_bytes: Option<u64>,
}

/// The whole bench of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Bench {
    /// Presets against `reference`.
    pub presets: Vec<Row>,
    /// Physics knobs switched one at a time on the `standard` preset, against `standard`.
    pub knobs: Vec<Row>,
    /// Memory against bar length (standard preset, fixed run duration, no snapshots), measured
    /// first and in ascending size so the process's high-water mark tracks each run.
    pub memory: Vec<MemoryRow>,
}

/// Peak resident set size of this process so far (Linux `/proc/self/status` VmHWM), bytes.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Median wall-clock time of `repeats` runs and the last run's output.
fn timed(params: &Params, repeats: usize) -> Result<(f64, RunOutput)> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let out = params.run()?;
        times.push(start.elapsed().as_secs_f64());
        last = Some(out);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], last.expect("at least one run")))
}

/// A row comparing `out` with `reference` (both full tests: the scene was checked to have spheres).
fn row(label: &str, runtime_s: f64, out: &RunOutput, reference: &RunOutput) -> Row {
    let (m, r) = (metrics(out), metrics(reference));
    let ((t, y), (tr, yr)) = (signal(out), signal(reference));
    Row {
        label: label.to_string(),
        runtime_s,
        peak_force_n: m.peak,
        displacement_at_peak_m: m.displacement_at_peak_m,
        peak_error: (m.peak - r.peak).abs() / r.peak,
        displacement_error: (m.displacement_at_peak_m - r.displacement_at_peak_m).abs()
            / r.displacement_at_peak_m,
        signal_rms_error: rms_difference(&t, &y, &tr, &yr),
    }
}

/// Runs the presets, the physics knobs and the memory ladder of a `shpb` scene; `repeats` runs
/// per timing (the reference preset runs once). `progress` receives a line per step.
pub fn bench(path: &Path, repeats: usize, mut progress: impl FnMut(&str)) -> Result<Bench> {
    let load = |f: Fidelity, extra: &[(&str, shpb_input::scene::Value)]| -> Result<Params> {
        let mut set = vec![(
            "fidelity".to_string(),
            shpb_input::scene::Value::String(f.name().into()),
        )];
        set.extend(extra.iter().map(|(k, v)| (k.to_string(), v.clone())));
        Params::from_file_overridden(path, &set)
    };
    let base = load(Fidelity::Standard, &[])?;
    if !matches!(&base.params, SceneParams::Pulse { options, .. } if options.specimen.is_some()) {
        return Err(Error::Input {
            file: base.source.clone(),
            key: "kind".into(),
            problem: format!(
                "`shpb bench` needs a full test, not a `{}` scene",
                base.kind
            ),
            allowed: "a `shpb` scene (e.g. scenes/shpb-ss440c-10psi.toml)".into(),
        });
    }
    // Memory first, in ascending size: the process's high-water mark then tracks each run.
    let mut memory = Vec::new();
    for scale in [1.0, 4.0, 16.0, 32.0] {
        progress(&format!("memory, bars × {scale}"));
        let mut p = base.clone();
        let (length, cell) = match &mut p.params {
            SceneParams::Pulse {
                apparatus, options, ..
            } => {
                apparatus.incident.length_m *= scale;
                apparatus.transmission.length_m *= scale;
                options.snapshot_interval_s = None;
                (
                    apparatus.incident.length_m + apparatus.transmission.length_m,
                    options.cell_size_m,
                )
            }
            _ => unreachable!("checked above: a shpb scene"),
        };
        p.run()?;
        memory.push(MemoryRow {
            bar_length_m: length,
            nodes: (length / cell).round() as usize,
            peak_rss_bytes: peak_rss_bytes(),
        });
    }
    progress("reference preset");
    let (t_ref, reference) = timed(&load(Fidelity::Reference, &[])?, 1)?;
    let mut presets = Vec::new();
    for f in [Fidelity::Fast, Fidelity::Standard] {
        progress(&format!("{} preset", f.name()));
        let (t, out) = timed(&load(f, &[])?, repeats)?;
        presets.push(row(f.name(), t, &out, &reference));
    }
    presets.push(row("reference", t_ref, &reference, &reference));

    progress("physics knobs");
    let (t_std, standard) = timed(&base, repeats)?;
    let mut knobs = vec![row("standard", t_std, &standard, &standard)];
    let s = |x: &str| shpb_input::scene::Value::String(x.into());
    for (label, extra) in [
        ("dispersion = love-rod", vec![("dispersion", s("love-rod"))]),
        (
            "law = rate-independent",
            vec![("law", s("rate-independent"))],
        ),
        ("law = hertz", vec![("law", s("hertz"))]),
        (
            "shaper.enabled = false",
            vec![("shaper.enabled", shpb_input::scene::Value::Boolean(false))],
        ),
    ] {
        progress(label);
        let (t, out) = timed(&load(Fidelity::Standard, &extra)?, repeats)?;
        knobs.push(row(label, t, &out, &standard));
    }

    Ok(Bench {
        presets,
        knobs,
        memory,
    })
}

/// The bench as markdown tables.
pub fn markdown(b: &Bench) -> String {
    let mut t = String::from(
        "| preset | run time (ms) | ratio to standard | peak force (kN) | error vs reference | δ at peak (µm) | error vs reference | gauge signal RMS vs reference |\n|---|---|---|---|---|---|---|---|\n",
    );
    let t_std = b
        .presets
        .iter()
        .find(|r| r.label == "standard")
        .map(|r| r.runtime_s)
        .unwrap_or(1.0);
    for r in &b.presets {
        t.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.4} | {:.1e} | {:.3} | {:.1e} | {:.1e} |\n",
            r.label,
            r.runtime_s * 1e3,
            r.runtime_s / t_std,
            r.peak_force_n * 1e-3,
            r.peak_error,
            r.displacement_at_peak_m * 1e6,
            r.displacement_error,
            r.signal_rms_error
        ));
    }
    t.push_str("\n| physics knob (on `standard`) | run time (ms) | ratio | peak force (kN) | change | δ at peak (µm) | change | gauge signal RMS change |\n|---|---|---|---|---|---|---|---|\n");
    for r in &b.knobs {
        t.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.4} | {:.1} % | {:.3} | {:.1} % | {:.1} % |\n",
            r.label,
            r.runtime_s * 1e3,
            r.runtime_s / t_std,
            r.peak_force_n * 1e-3,
            100.0 * r.peak_error,
            r.displacement_at_peak_m * 1e6,
            100.0 * r.displacement_error,
            100.0 * r.signal_rms_error
        ));
    }
    t.push_str("\n| bars (incident + transmission, m) | nodes | peak resident memory (MiB) |\n|---|---|---|\n");
    for m in &b.memory {
        t.push_str(&format!(
            "| {:.2} | {} | {} |\n",
            m.bar_length_m,
            m.nodes,
            m.peak_rss_bytes
                .map(|b| format!("{:.1}", b as f64 / 1048576.0))
                .unwrap_or_else(|| "—".into())
        ));
    }
    t
}

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

/// Cell of the fine rung of the dispersion table, m: every bar theory at 0.125 mm, where the
/// Love-rod chain is `reference`'s fallback ([`Fidelity::fallback_bar_knobs`]).
const FINE_CELL_M: f64 = 0.125e-3;

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
    /// Node updates of the run, steps × bar nodes and bodies ([`shpb_core::estimate::RunEstimate::updates`]).
    pub node_steps: f64,
}

/// Cost per step of the whole run against a minimal loop of the same size (issue 20): what a
/// regression in the hot loops shows in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCost {
    /// Wall-clock time of the whole run (all its work: bars, joints, recording, reduction)
    /// divided by its node updates, s.
    pub run_s: f64,
    /// The same for the minimal loop ([`minimal_leapfrog_s`] or [`minimal_dem_s`]), s.
    pub minimal_s: f64,
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
    /// The bars' dispersion (issue 20): each theory at 1 mm and 0.125 mm cells against
    /// `reference` (the Love-rod chain at 0.125 mm), and against the same theory at 0.125 mm.
    pub dispersion: Vec<(Row, Row)>,
    /// Memory against bar length (standard preset, fixed run duration, no snapshots), measured
    /// first and in ascending size so the process's high-water mark tracks each run.
    pub memory: Vec<MemoryRow>,
    /// Per node-step cost of the `standard` full test against a minimal leapfrog of its size.
    pub node_step: StepCost,
    /// Per step cost of the force-driven Fig. 4 DEM (`scenes/force-driven-ss440c-10psi.toml`
    /// beside the scene, when present) against a minimal velocity-Verlet Hertz step.
    pub dem_step: Option<StepCost>,
}

/// Time per node update of the minimal lumped-mass leapfrog (unit masses and springs, Courant 1,
/// free ends): `nodes` nodes advanced `steps` steps, median of `repeats`, s. The floor the bar
/// solver is measured against (the loop a compiler makes of u += v; v += (u₋ − 2u + u₊)).
pub fn minimal_leapfrog_s(nodes: usize, steps: usize, repeats: usize) -> f64 {
    let nodes = nodes.max(3);
    let mut times = Vec::new();
    for _ in 0..repeats.max(1) {
        let mut u = vec![0.0f64; nodes];
        let mut v = vec![0.0f64; nodes];
        v[0] = 1.0;
        let start = Instant::now();
        for _ in 0..steps {
            for (ui, vi) in u.iter_mut().zip(&v) {
                *ui += vi;
            }
            v[0] += u[1] - u[0];
            for i in 1..nodes - 1 {
                v[i] += u[i - 1] - 2.0 * u[i] + u[i + 1];
            }
            v[nodes - 1] += u[nodes - 2] - u[nodes - 1];
            std::hint::black_box(&mut v);
        }
        times.push(start.elapsed().as_secs_f64() / (nodes * steps.max(1)) as f64);
        std::hint::black_box(&u);
    }
    median(times)
}

/// Time per step of a minimal two-sphere DEM: velocity Verlet with the Hertz force (one square
/// root a step, no rate, no memory, no checks), `steps` steps, median of `repeats`, s (per
/// degree of freedom, as [`RunEstimate::updates`](shpb_core::estimate::RunEstimate::updates)
/// counts the DEM's two spheres).
pub fn minimal_dem_s(steps: usize, repeats: usize) -> f64 {
    let (k, m, dt) = (1.0e10f64, 1.0e-3f64, 1.0e-9f64);
    let mut times = Vec::new();
    for _ in 0..repeats.max(1) {
        let (mut x1, mut x2, mut v1, mut v2, mut f) = (0.0f64, 0.0f64, 1.0f64, 0.0f64, 0.0f64);
        let start = Instant::now();
        for _ in 0..steps {
            let h1 = v1 - 0.5 * dt * f / m;
            let h2 = v2 + 0.5 * dt * f / m;
            x1 += dt * h1;
            x2 += dt * h2;
            let d = (x1 - x2).max(0.0);
            f = k * d * d.sqrt();
            v1 = h1 - 0.5 * dt * f / m;
            v2 = h2 + 0.5 * dt * f / m;
            std::hint::black_box(&mut v1);
        }
        times.push(start.elapsed().as_secs_f64() / (2 * steps.max(1)) as f64);
        std::hint::black_box((x1, x2, v2));
    }
    median(times)
}

/// The median of a non-empty list.
fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
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
    Ok((median(times), last.expect("at least one run")))
}

/// A row comparing `out` with `reference` (both full tests: the scene was checked to have spheres).
fn row(
    label: &str,
    runtime_s: f64,
    node_steps: f64,
    out: &RunOutput,
    reference: &RunOutput,
) -> Row {
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
        node_steps,
    }
}

/// Runs the presets, the physics knobs and the memory ladder of a `shpb` scene; `repeats` runs
/// per timing, each preset's median reported. `progress` receives a line per step.
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
    if !(matches!(&base.params, SceneParams::Pulse { .. }) && base.sphere_pair().is_some()) {
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
        let mut p = base.clone().summary_only();
        let (length, cell) = match &mut p.params {
            SceneParams::Pulse {
                apparatus, options, ..
            } => {
                apparatus.incident.length_m *= scale;
                apparatus.transmission.length_m *= scale;
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
    let reference_params = load(Fidelity::Reference, &[])?;
    // Timed like the others now that it costs a few `standard` runs (the median of `repeats`:
    // its first run of a process also designs the delay lines' filters).
    let (t_ref, reference) = timed(&reference_params, repeats)?;
    let mut presets = Vec::new();
    for f in [Fidelity::Fast, Fidelity::Standard] {
        progress(&format!("{} preset", f.name()));
        let p = load(f, &[])?;
        let (t, out) = timed(&p, repeats)?;
        presets.push(row(f.name(), t, p.estimate().updates(), &out, &reference));
    }
    let n_ref = reference_params.estimate().updates();
    presets.push(row("reference", t_ref, n_ref, &reference, &reference));

    progress("physics knobs");
    let (t_std, standard) = timed(&base, repeats)?;
    let n_std = base.estimate().updates();
    let mut knobs = vec![row("standard", t_std, n_std, &standard, &standard)];
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
        (
            "unloading = dynamic-continuous",
            vec![("unloading", s("dynamic-continuous"))],
        ),
    ] {
        progress(label);
        let p = load(Fidelity::Standard, &extra)?;
        let (t, out) = timed(&p, repeats)?;
        knobs.push(row(label, t, p.estimate().updates(), &out, &standard));
    }

    progress("dispersion");
    let mut dispersion = Vec::new();
    // Each theory at `standard`'s 1 mm and at 0.125 mm (the fine rung its 1 mm run is compared
    // with; the Love-rod chain there is the fallback of `reference`).
    let fine_cell = shpb_input::scene::Value::Float(FINE_CELL_M);
    for theory in ["none", "love-rod", "rayleigh-love", "pochhammer-chree"] {
        let fine_params = load(
            Fidelity::Standard,
            &[
                ("dispersion", s(theory)),
                ("cell_size_m", fine_cell.clone()),
            ],
        )?;
        let n_fine = fine_params.estimate().updates();
        let (t_fine, fine) = timed(&fine_params, 1)?;
        let coarse_params = load(Fidelity::Standard, &[("dispersion", s(theory))])?;
        let (t_coarse, coarse) = timed(&coarse_params, repeats)?;
        let n_coarse = coarse_params.estimate().updates();
        let label = |cell: &str| format!("`{theory}`, {cell}");
        dispersion.push((
            row(&label("1 mm"), t_coarse, n_coarse, &coarse, &reference),
            row(&label("1 mm"), t_coarse, n_coarse, &coarse, &fine),
        ));
        dispersion.push((
            row(&label("0.125 mm"), t_fine, n_fine, &fine, &reference),
            row(&label("0.125 mm"), t_fine, n_fine, &fine, &fine),
        ));
    }

    progress("minimal loops");
    let est = base.estimate();
    let node_step = StepCost {
        run_s: t_std / n_std,
        minimal_s: minimal_leapfrog_s(est.degrees_of_freedom as usize, est.steps as usize, repeats),
    };
    let dem = path.with_file_name("force-driven-ss440c-10psi.toml");
    let dem_step = if dem.is_file() {
        progress("force-driven DEM");
        let p = Params::from_file_overridden(&dem, &[])?;
        let (t, _) = timed(&p, repeats)?;
        let e = p.estimate();
        Some(StepCost {
            run_s: t / e.updates(),
            minimal_s: minimal_dem_s(e.steps as usize, repeats),
        })
    } else {
        None
    };

    Ok(Bench {
        presets,
        knobs,
        dispersion,
        memory,
        node_step,
        dem_step,
    })
}

/// The bench as markdown tables.
pub fn markdown(b: &Bench) -> String {
    let mut t = String::from(
        "| preset | run time (ms) | ratio to standard | ns per node-step | peak force (kN) | error vs reference | δ at peak (µm) | error vs reference | gauge signal RMS vs reference |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let t_std = b
        .presets
        .iter()
        .find(|r| r.label == "standard")
        .map(|r| r.runtime_s)
        .unwrap_or(1.0);
    for r in &b.presets {
        t.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.2} | {:.4} | {:.1e} | {:.3} | {:.1e} | {:.1e} |\n",
            r.label,
            r.runtime_s * 1e3,
            r.runtime_s / t_std,
            1e9 * r.runtime_s / r.node_steps,
            r.peak_force_n * 1e-3,
            r.peak_error,
            r.displacement_at_peak_m * 1e6,
            r.displacement_error,
            r.signal_rms_error
        ));
    }
    t.push_str("\n| physics knob (on `standard`) | run time (ms) | ratio | ns per node-step | peak force (kN) | change | δ at peak (µm) | change | gauge signal RMS change |\n|---|---|---|---|---|---|---|---|---|\n");
    for r in &b.knobs {
        t.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.2} | {:.4} | {:.1} % | {:.3} | {:.1} % | {:.1} % |\n",
            r.label,
            r.runtime_s * 1e3,
            r.runtime_s / t_std,
            1e9 * r.runtime_s / r.node_steps,
            r.peak_force_n * 1e-3,
            100.0 * r.peak_error,
            r.displacement_at_peak_m * 1e6,
            100.0 * r.displacement_error,
            100.0 * r.signal_rms_error
        ));
    }
    t.push_str("\n| bars (dispersion, cell) | run time (ms) | ratio to standard | peak force (kN) | vs reference | δ at peak (µm) | vs reference | gauge signal RMS vs reference | peak vs same theory at 0.125 mm | δ at peak vs same | gauge signal RMS vs same |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (r, own) in &b.dispersion {
        t.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.4} | {:.1e} | {:.3} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |\n",
            r.label,
            r.runtime_s * 1e3,
            r.runtime_s / t_std,
            r.peak_force_n * 1e-3,
            r.peak_error,
            r.displacement_at_peak_m * 1e6,
            r.displacement_error,
            r.signal_rms_error,
            own.peak_error,
            own.displacement_error,
            own.signal_rms_error
        ));
    }
    t.push_str(
        "\n| per step (median) | whole run (ns) | minimal loop (ns) | ratio |\n|---|---|---|---|\n",
    );
    let mut cost = |label: &str, c: &StepCost| {
        t.push_str(&format!(
            "| {label} | {:.2} | {:.2} | {:.1} |\n",
            1e9 * c.run_s,
            1e9 * c.minimal_s,
            c.run_s / c.minimal_s
        ))
    };
    cost(
        "`standard` full test, per node-step (minimal: lumped-mass leapfrog of the same nodes and steps)",
        &b.node_step,
    );
    if let Some(d) = &b.dem_step {
        cost(
            "force-driven Fig. 4 DEM, per sphere-step (minimal: velocity Verlet with Hertz)",
            d,
        );
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_loops_take_time_per_update_below_a_microsecond() {
        // A few nanoseconds a node-step on any machine this runs on; a microsecond would mean
        // the loop is not the minimal one (or the count of updates is wrong).
        for t in [minimal_leapfrog_s(1000, 200, 3), minimal_dem_s(20_000, 3)] {
            assert!(t > 0.0 && t < 1e-6, "{t}");
        }
    }
}

//! Regenerates `validation/fit-cylinder/REPORT.md`, `coverage.png` and `records.csv`: the
//! coverage of `shpb fit`'s 90 % intervals (crates/study/src/fit, docs/physics.md §12) for a
//! Johnson–Cook cylinder (A, B, n, C) on simulated records with known constants and the set-up's
//! own digitiser noise, reduced as a lab reduces its gauge records (issue 44's acceptance: the
//! true values inside their intervals in 40–50 of 50 records). Run from the repository root with
//! `cargo run --release -p shpb-validate --bin fit_cylinder [-- --records N --steps S
//! --walkers W --burn-in B --jobs J --diagnose --no-dispersion]`.

#![warn(missing_docs)]

mod common;

use shpb_core::reduce::{ReducedSpecimen, ReductionSetup};
use shpb_core::reduce_cylinder::CylinderGeometry;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use shpb_study::fit::observe::series_of;
use shpb_study::fit::spec::{Residual, parse_free};
use shpb_study::fit::{Problem, Reducer, Settings, fit};
use shpb_study::uq::Rng;
use shpb_validate::figure::{Figure, Legend, Panel, Series, Style, draw};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The free keys and their bounds (the uniform prior's support).
const FREE: [&str; 4] = [
    "specimen.johnson_cook.a_pa=40e6:160e6",
    "specimen.johnson_cook.b_pa=100e6:500e6",
    "specimen.johnson_cook.n=0.1:0.7",
    "specimen.johnson_cook.c=0:0.1",
];

/// Short names of the free keys, in order.
const NAMES: [&str; 4] = ["A", "B", "n", "C"];

/// The truths are drawn uniformly within ± these fractions of OFHC copper's constants
/// (Johnson & Cook 1983, specimens/ofhc-copper.toml: A 90 MPa, B 292 MPa, n 0.31, C 0.025).
const NOMINAL: [f64; 4] = [90e6, 292e6, 0.31, 0.025];
const SPREAD: [f64; 4] = [0.15, 0.15, 0.15, 0.3];

/// The options of one generation.
struct Options {
    records: usize,
    steps: usize,
    walkers: usize,
    burn_in: Option<usize>,
    jobs: usize,
    diagnose: bool,
    no_dispersion: bool,
    noise_check: bool,
    truth_check: bool,
}

fn parse_options() -> Options {
    let mut o = Options {
        records: 50,
        steps: 400,
        walkers: 16,
        burn_in: None,
        jobs: 2,
        diagnose: false,
        no_dispersion: false,
        noise_check: false,
        truth_check: false,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let next = |i: usize| -> usize {
            args.get(i + 1)
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{} needs a whole number", args[i]))
        };
        match args[i].as_str() {
            "--records" => o.records = next(i),
            "--steps" => o.steps = next(i),
            "--walkers" => o.walkers = next(i),
            "--burn-in" => o.burn_in = Some(next(i)),
            "--jobs" => o.jobs = next(i),
            "--diagnose" => {
                o.diagnose = true;
                i += 1;
                continue;
            }
            "--truth-check" => {
                o.truth_check = true;
                i += 1;
                continue;
            }
            "--noise-check" => {
                o.noise_check = true;
                i += 1;
                continue;
            }
            "--no-dispersion" => {
                o.no_dispersion = true;
                i += 1;
                continue;
            }
            a => panic!("unknown argument {a}"),
        }
        i += 2;
    }
    o
}

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (clock ticks of
/// 1/100 s, Linux).
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            let u: f64 = f.get(11)?.parse().ok()?;
            let k: f64 = f.get(12)?.parse().ok()?;
            Some((u + k) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

/// The fit's question without records: the scene's free keys, the stress–strain residual and the
/// reducer a lab's run file of this scene is reduced with (`shpb reduce`'s defaults with the
/// scene's cylinder as specimen, as `fit::read_record` sets it up for a run file).
fn base_problem(scene: &Path) -> Result<Problem> {
    let params = Params::from_file(scene)?;
    let SceneParams::Pulse { apparatus, .. } = &params.params else {
        return Err(Error::Input {
            file: scene.display().to_string(),
            key: "kind".into(),
            problem: "not a bar test".into(),
            allowed: "kind = \"shpb\"".into(),
        });
    };
    let c = params
        .specimen
        .as_ref()
        .and_then(shpb_core::specimen::Specimen::cylinder)
        .expect("a cylinder scene");
    let geometry = CylinderGeometry {
        length_m: c.length_m,
        diameter_m: c.diameter_m,
    };
    let choices = shpb_study::api::RecordOptions {
        cylinder: Some(geometry),
        ..shpb_study::api::RecordOptions::default()
    };
    let specimen = ReducedSpecimen::Cylinder(geometry);
    let mut options = shpb_study::api::reduction_options(&choices)?;
    options.specimen_radii_m = specimen.radii_m();
    options.tension = false;
    let reducer = Reducer {
        options,
        setup: ReductionSetup::from_apparatus(apparatus)?,
        specimen,
    };
    Ok(Problem {
        scene: scene.to_path_buf(),
        free: FREE.iter().map(|s| parse_free(s)).collect::<Result<_>>()?,
        priors: Vec::new(),
        residual: Residual::StressStrain,
        series: Vec::new(),
        force_driven: false,
        reducer: Some(reducer),
        drives: Vec::new(),
    })
}

/// A simulated record of `base`'s scene at `truth`: a run with every channel's digitiser noise
/// drawn from `noise_seed` (None: noise-free), reduced through the base's reducer; the
/// question of fitting it.
fn record_problem(
    base: &Problem,
    truth: &[f64],
    noise_seed: Option<u64>,
    name: &str,
) -> Result<Problem> {
    let fail = |what: &str| Error::Input {
        file: base.scene.display().to_string(),
        key: "--free".into(),
        problem: format!("the simulated record {name} failed: {what}"),
        allowed: "truths the scene runs".into(),
    };
    let (out, params, _) = base.run_at(truth, noise_seed).ok_or_else(|| fail("run"))?;
    let obs = base
        .observe(&out, &params)
        .ok_or_else(|| fail("reduction"))?;
    let series = series_of(name, &obs, Residual::StressStrain, false)?;
    Ok(Problem {
        series,
        ..base.clone()
    })
}

/// One record's outcome.
struct Row {
    truth: [f64; 4],
    best: [f64; 4],
    median: [f64; 4],
    band: [[f64; 2]; 4],
    tau: [f64; 4],
    kept: usize,
    acceptance: f64,
    noise_sd_pa: f64,
    noise_corr: f64,
    noise_calibration: f64,
    wall_s: f64,
    runs: usize,
}

impl Row {
    fn inside(&self, k: usize) -> bool {
        self.truth[k] >= self.band[k][0] && self.truth[k] <= self.band[k][1]
    }
    fn all_inside(&self) -> bool {
        (0..4).all(|k| self.inside(k))
    }
    fn tau_max(&self) -> f64 {
        self.tau
            .iter()
            .cloned()
            .filter(|t| t.is_finite())
            .fold(0.0, f64::max)
    }
}

/// Fits one problem and reads its row.
fn fit_row(problem: &Problem, truth: [f64; 4], settings: &Settings) -> Result<Row> {
    let t0 = Instant::now();
    let report = fit(
        problem,
        settings,
        "fit_cylinder",
        &mut |_, _, _| {},
        &|| true,
    )?;
    let p = &report.parameters;
    let arr = |f: &dyn Fn(usize) -> f64| -> [f64; 4] { std::array::from_fn(f) };
    Ok(Row {
        truth,
        best: arr(&|k| p[k].best),
        median: arr(&|k| p[k].median),
        band: std::array::from_fn(|k| p[k].band_90),
        tau: arr(&|k| p[k].tau_steps),
        kept: report.steps - report.burn_in,
        acceptance: report.acceptance,
        noise_sd_pa: report.records[0].noise_sd,
        noise_corr: report.records[0].noise_correlation,
        noise_calibration: report.records[0].noise_calibration,
        wall_s: t0.elapsed().as_secs_f64(),
        runs: report.evaluations,
    })
}

/// A number in the report's units: MPa for the stresses.
fn show(k: usize, v: f64) -> String {
    if k < 2 {
        format!("{:.2} MPa", v / 1e6)
    } else {
        format!("{v:.4}")
    }
}

/// What a fit's noise model must describe, measured at the nominal constants (`--noise-check`):
/// the reduced model's roughness in θ (the change of the model for relative steps of each
/// constant, and its departure from the change the step of 10⁻³ predicts linearly), and, over
/// 64 simulated records at the truth, the residual's variance along the model's +5 % directions
/// against the stationary noise model's σ²τ (the factor the fit's calibration estimates).
fn noise_check(base: &Problem, clean: &Problem, jobs: usize) -> Result<String> {
    use rayon::prelude::*;
    use shpb_study::fit::noise::{Noise, SimulatedRecord, calibration};
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .expect("a pool");
    let m0 = clean
        .model(&NOMINAL)
        .expect("the nominal run")
        .swap_remove(0);
    let rms_of = |a: &[f64], b: &[f64]| {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    let at = |k: usize, f: f64| {
        let mut t = NOMINAL;
        t[k] *= 1.0 + f;
        clean.model(&t).expect("a run").swap_remove(0)
    };
    let mut out = String::new();
    for (k, name) in NAMES.iter().enumerate() {
        let m3 = at(k, 1e-3);
        let line: Vec<String> = [1e-4, 1e-3, 1e-2, 5e-2]
            .iter()
            .map(|&f| {
                let m = at(k, f);
                let lin: Vec<f64> = m0
                    .iter()
                    .zip(&m3)
                    .map(|(a, b)| a + (b - a) * f / 1e-3)
                    .collect();
                format!(
                    "{f:.0e}: {:.3} MPa (off linear {:.3})",
                    rms_of(&m, &m0) / 1e6,
                    rms_of(&m, &lin) / 1e6
                )
            })
            .collect();
        let _ = writeln!(
            out,
            "- The reduced model's change for relative steps of {} (RMS over the loading branch): {}.",
            name,
            line.join("; ")
        );
    }
    // Each record's residual at the truth and the model's +5 % directions at its own points.
    let records: Vec<SimulatedRecord> = pool.install(|| {
        (0..64u64)
            .into_par_iter()
            .filter_map(|k| {
                let rec = record_problem(base, &NOMINAL, Some(7000 + k), "r").ok()?;
                let y = &rec.series[0].y;
                let m = rec.model(&NOMINAL)?.swap_remove(0);
                let r: Vec<f64> = y.iter().zip(&m).map(|(a, b)| a - b).collect();
                let dirs: Vec<Vec<f64>> = (0..4)
                    .map(|j| {
                        let mut t = NOMINAL;
                        t[j] *= 1.05;
                        let mj = rec.model(&t).expect("a run").swap_remove(0);
                        mj.iter().zip(&m).map(|(a, b)| a - b).collect()
                    })
                    .collect();
                Some((r, dirs))
            })
            .collect()
    });
    let s_mean = records
        .iter()
        .map(|(r, _)| {
            let nz = Noise::of_residuals(r, 4, 1);
            nz.sd * nz.sd * nz.correlation_points
        })
        .sum::<f64>()
        / records.len() as f64;
    // The fit's calibration factor, one direction at a time.
    let along = |j: usize| {
        let one: Vec<SimulatedRecord> = records
            .iter()
            .map(|(r, d)| (r.clone(), vec![d[j].clone()]))
            .collect();
        calibration(&one, 4).unwrap_or(f64::NAN)
    };
    let _ = writeln!(
        out,
        "- {} simulated records at the nominal constants: the residual's variance along the model's +5 % directions over the stationary noise model's σ²τ (mean {:.1} MPa²): {}.",
        records.len(),
        s_mean / 1e12,
        (0..4)
            .map(|j| format!("{} {:.2}", NAMES[j], along(j)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(out)
}

fn main() -> Result<()> {
    let o = parse_options();
    let root = common::repo_root();
    let dir = root.join("validation/fit-cylinder");
    let scene = dir.join("scenes/copper-fast.toml");
    let mut base = base_problem(&scene)?;
    if o.no_dispersion
        && let Some(r) = &mut base.reducer
    {
        // `shpb reduce --no-dispersion`: the records and the model reduced alike without the
        // Bancroft correction (a third of the cost of a run with it; see the diagnosis).
        r.options.dispersion = shpb_core::reduce::DispersionCorrection::None;
    }
    let settings = Settings {
        walkers: o.walkers,
        steps: o.steps,
        burn_in: o.burn_in,
        seed: 1,
        jobs: o.jobs,
        predictive_draws: 4,
        max_least_squares_runs: 0,
        noise_draws: 64,
    };
    let (wall0, cpu0) = (Instant::now(), cpu_s());
    if o.noise_check {
        let clean = record_problem(&base, &NOMINAL, None, "noise-free")?;
        eprint!("{}", noise_check(&base, &clean, o.jobs)?);
        return Ok(());
    }

    // One run's cost at the nominal constants (noise-free).
    let t = Instant::now();
    let reps = 5;
    for _ in 0..reps {
        base.model(&NOMINAL).expect("the nominal run");
    }
    let run_ms = t.elapsed().as_secs_f64() * 1e3 / reps as f64;
    eprintln!("one model run: {run_ms:.1} ms");

    let mut diagnosis = String::new();
    if o.diagnose {
        // The same record, noise-free and noisy: the reduction's bias under noise (the mean of
        // noisy − noise-free stress over the loading branch, against the point noise), and the
        // fit of the noise-free record (does its best fit return the truth?).
        let clean = record_problem(&base, &NOMINAL, None, "noise-free")?;
        let noisy = record_problem(&base, &NOMINAL, Some(1000), "noisy")?;
        let c = &clean.series[0];
        let n = &noisy.series[0];
        let cm: Vec<f64> =
            n.x.iter()
                .map(|&x| shpb_study::fit::observe::interpolate(&c.x, &c.y, x))
                .collect();
        let d: Vec<f64> = n.y.iter().zip(&cm).map(|(a, b)| a - b).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        let _ = writeln!(
            diagnosis,
            "- Noisy − noise-free reduced stress at the nominal constants (seed 1000): mean \
             {:.3} MPa, SD {:.3} MPa over {} points; largest strain {:.4} (noisy) vs {:.4} \
             (noise-free).",
            mean / 1e6,
            sd / 1e6,
            d.len(),
            n.x.iter().cloned().fold(f64::MIN, f64::max),
            c.x.iter().cloned().fold(f64::MIN, f64::max),
        );
        // The least squares alone (4 sampler steps): does its best fit reach the truth's cost?
        let quick = Settings {
            walkers: 8,
            steps: 4,
            predictive_draws: 1,
            ..settings.clone()
        };
        for (label, p) in [("noise-free", &clean), ("noisy", &noisy)] {
            let row = fit_row(p, NOMINAL, &quick)?;
            let rms = |theta: &[f64]| {
                let m = p.model(theta).expect("a run");
                let s = &p.series[0];
                (s.y.iter()
                    .zip(&m[0])
                    .map(|(y, v)| (y - v).powi(2))
                    .sum::<f64>()
                    / s.y.len() as f64)
                    .sqrt()
            };
            let _ = writeln!(
                diagnosis,
                "- Least squares on the {label} record (truth A 90 MPa, B 292 MPa, n 0.31, C \
                 0.025): best {}, after {} runs; RMS residual at the best fit {:.3} MPa, at \
                 the truth {:.3} MPa.",
                (0..4)
                    .map(|k| format!("{} {}", NAMES[k], show(k, row.best[k])))
                    .collect::<Vec<_>>()
                    .join(", "),
                row.runs,
                rms(&row.best) / 1e6,
                rms(&NOMINAL) / 1e6,
            );
        }
        // Where a run's time goes: the run (with its own reduction) and the Reducer's reduction
        // of its gauges, at this scene and at the standard-fidelity shipped scene.
        for sc in [scene.clone(), root.join("scenes/shpb-cylinder-copper.toml")] {
            let b = base_problem(&sc)?;
            let (mut run_s, mut red_s) = (0.0, 0.0);
            for _ in 0..3 {
                let t = Instant::now();
                let (out, params, _) = b.run_at(&NOMINAL, None).expect("a run");
                run_s += t.elapsed().as_secs_f64();
                let t = Instant::now();
                b.observe(&out, &params).expect("a reduction");
                red_s += t.elapsed().as_secs_f64();
            }
            let _ = writeln!(
                diagnosis,
                "- {}: the run (with its own reduction) {:.1} ms, the Reducer's reduction of its \
                 gauges {:.1} ms (mean of 3, wall time on the shared machine).",
                sc.strip_prefix(&root).unwrap_or(&sc).display(),
                run_s / 3.0 * 1e3,
                red_s / 3.0 * 1e3,
            );
        }
        eprint!("{diagnosis}");
    }

    let mut rng = Rng::new(44);
    let mut rows = Vec::new();
    for i in 0..o.records {
        let truth: [f64; 4] =
            std::array::from_fn(|k| NOMINAL[k] * (1.0 + SPREAD[k] * (2.0 * rng.uniform() - 1.0)));
        let seed = 1000 + i as u64;
        let problem = record_problem(&base, &truth, Some(seed), &format!("record {i}"))?;
        let s = Settings {
            seed: 1 + i as u64,
            ..settings.clone()
        };
        if o.truth_check {
            // Least squares only: how far below the best fit's likelihood the truth's lies
            // (2 Δln L ~ χ²₄ when the likelihood is right: mean 4, 95 % below 9.5).
            let quick = Settings {
                walkers: 8,
                steps: 4,
                predictive_draws: 1,
                ..s.clone()
            };
            let row = fit_row(&problem, truth, &quick)?;
            let y = &problem.series[0].y;
            let mb = problem.model(&row.best).expect("a run").swap_remove(0);
            let mt = problem.model(&truth).expect("a run").swap_remove(0);
            let r: Vec<f64> = y.iter().zip(&mb).map(|(a, b)| a - b).collect();
            let nz = shpb_study::fit::noise::Noise::of_residuals(&r, 4, 1);
            let two_dl = 2.0 * (nz.log_likelihood(y, &mb) - nz.log_likelihood(y, &mt));
            eprintln!(
                "record {i:2}: 2Δln L(truth) {two_dl:.1} stationary, {:.1} calibrated (σ {:.3} MPa, τ {:.1} points, calibration {:.2}); best {}",
                two_dl / row.noise_calibration,
                nz.sd / 1e6,
                nz.correlation_points,
                row.noise_calibration,
                (0..4)
                    .map(|k| format!(
                        "{} {} (truth {})",
                        NAMES[k],
                        show(k, row.best[k]),
                        show(k, truth[k])
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            continue;
        }
        let row = fit_row(&problem, truth, &s)?;
        eprintln!(
            "record {i:2}: inside {:?} τmax {:.1} kept {} {:.0} s",
            (0..4).map(|k| row.inside(k)).collect::<Vec<_>>(),
            row.tau_max(),
            row.kept,
            row.wall_s
        );
        rows.push(row);
    }
    if o.truth_check {
        return Ok(());
    }
    let wall = wall0.elapsed().as_secs_f64();
    let cpu = cpu_s() - cpu0;
    write_outputs(&dir, &o, &rows, run_ms, wall, cpu, &diagnosis)
}

/// Writes records.csv, coverage.png and REPORT.md.
fn write_outputs(
    dir: &Path,
    o: &Options,
    rows: &[Row],
    run_ms: f64,
    wall: f64,
    cpu: f64,
    diagnosis: &str,
) -> Result<()> {
    let io = |e: std::io::Error, f: &str| Error::Io {
        file: dir.join(f).display().to_string(),
        source: e,
    };
    let mut csv = String::from("record,noise_seed");
    for n in NAMES {
        let _ = write!(
            csv,
            ",{n}_true,{n}_best,{n}_median,{n}_low,{n}_high,{n}_inside,{n}_tau_steps"
        );
    }
    csv.push_str(
        ",kept_steps,acceptance,noise_sd_pa,noise_correlation_points,noise_calibration,runs,wall_s\n",
    );
    for (i, r) in rows.iter().enumerate() {
        let _ = write!(csv, "{i},{}", 1000 + i);
        for k in 0..4 {
            let _ = write!(
                csv,
                ",{:e},{:e},{:e},{:e},{:e},{},{:.2}",
                r.truth[k],
                r.best[k],
                r.median[k],
                r.band[k][0],
                r.band[k][1],
                u8::from(r.inside(k)),
                r.tau[k]
            );
        }
        let _ = writeln!(
            csv,
            ",{},{:.3},{:e},{:.2},{:.3},{},{:.1}",
            r.kept,
            r.acceptance,
            r.noise_sd_pa,
            r.noise_corr,
            r.noise_calibration,
            r.runs,
            r.wall_s
        );
    }
    std::fs::write(dir.join("records.csv"), csv).map_err(|e| io(e, "records.csv"))?;

    // The figure: per parameter, each record's interval and truth relative to the interval's
    // middle, in half-widths (inside: |z| ≤ 1).
    let panels = (0..4)
        .map(|k| {
            let z = |r: &Row| {
                let mid = 0.5 * (r.band[k][0] + r.band[k][1]);
                let half = 0.5 * (r.band[k][1] - r.band[k][0]);
                (r.truth[k] - mid) / half
            };
            let idx: Vec<f64> = (0..rows.len()).map(|i| i as f64).collect();
            let (zin, zout): (Vec<_>, Vec<_>) = rows
                .iter()
                .enumerate()
                .map(|(i, r)| (i as f64, z(r), r.inside(k)))
                .partition(|p| p.2);
            Panel {
                title: format!(
                    "{}: truth inside in {} of {}",
                    NAMES[k],
                    zin.len(),
                    rows.len()
                ),
                x_label: "record".into(),
                y_label: "(truth − interval middle) / half-width".into(),
                x_scale: 1.0,
                y_scale: 1.0,
                series: vec![
                    Series::new(
                        "interval edge",
                        idx.clone(),
                        vec![1.0; rows.len()],
                        Style::Dashed(2),
                    ),
                    Series::new("", idx, vec![-1.0; rows.len()], Style::Dashed(2)),
                    Series::new(
                        "truth inside",
                        zin.iter().map(|p| p.0).collect(),
                        zin.iter().map(|p| p.1).collect(),
                        Style::Points(3),
                    ),
                    Series::new(
                        "truth outside",
                        zout.iter().map(|p| p.0).collect(),
                        zout.iter().map(|p| p.1).collect(),
                        Style::Points(0),
                    ),
                ],
            }
        })
        .collect();
    let fig = Figure {
        legend: Legend::UpperRight,
        caption: "Each record's 90 % interval (between the dashed lines) and the true value".into(),
        columns: 2,
        panels,
    };
    draw(&dir.join("coverage.png"), true, &fig)?;

    let n = rows.len();
    let count = |k: usize| rows.iter().filter(|r| r.inside(k)).count();
    let all = rows.iter().filter(|r| r.all_inside()).count();
    let ten_tau = rows
        .iter()
        .filter(|r| r.kept as f64 >= 10.0 * r.tau_max())
        .count();
    let taus: Vec<f64> = rows.iter().map(Row::tau_max).collect();
    let tau_med = median(&taus);
    let tau_max = taus.iter().cloned().fold(0.0, f64::max);
    let med = |f: &dyn Fn(&Row) -> f64| median(&rows.iter().map(f).collect::<Vec<_>>());
    let mut md = String::new();
    let w = &mut md;
    let _ = writeln!(
        w,
        "# Coverage of `shpb fit`'s intervals: a Johnson–Cook cylinder\n\n\
         Generated by `cargo run --release -p shpb-validate --bin fit_cylinder --{}` \
         (crates/validate/src/bin/fit_cylinder.rs); do not edit by hand. Physics: \
         docs/physics.md §12; code: crates/study/src/fit.\n",
        std::env::args()
            .skip(1)
            .map(|a| format!(" {a}"))
            .collect::<String>()
    );
    let _ = writeln!(
        w,
        "## The question\n\n\
         Do the 90 % intervals of `shpb fit` hold the true constants about 90 % of the time? \
         {n} simulated records of an OFHC copper cylinder (6 mm × 6 mm, the authors' bars and \
         copper shaper, 12.5 psi; `scenes/copper-fast.toml`), each with its own Johnson–Cook \
         constants drawn uniformly within ±15 % of A = 90 MPa, B = 292 MPa, n = 0.31 and ±30 % \
         of C = 0.025 (Johnson & Cook 1983; m = 1.09 and the thermal constants held), seed 44. \
         Each record is a run with the set-up's own digitiser noise (the authors' 12-bit \
         digitisers and their noise RMS, every channel's noise drawn from the record's seed \
         1000 + i: `Problem::run_at(truth, Some(seed))`), reduced as a lab reduces a run file \
         (`shpb reduce`'s defaults: the gauge voltages back through the bridges, the 1-wave \
         stress and strain of the cylinder; the `Reducer` of `fit::read_record`). The fit \
         compares the loading branch of the stress–strain curve (`--residual stress-strain`) \
         with the model's, reduced alike from its noise-free virtual gauges, with free keys \
         (uniform priors) `{}`.\n\n\
         Fidelity: the records and the model are both at the `fast` preset (the scene's \
         `fidelity = \"fast\"`). Coverage is a property of the statistics (the record's noise, \
         the noise model estimated from the best fit's residuals, the sampler), not of the \
         mesh: at `fast` the model is the exact forward model of the records, as at any \
         preset when the record is simulated at that preset. A model run (the run and the \
         Reducer's reduction) took {run_ms:.0} ms of wall time here, on the shared machine.\n\n\
         Reduction's dispersion correction: {}.\n\n\
         Sampler: {} walkers, {} steps, burn-in {} steps, seeds 1 + i; least squares from the \
         default start design (Nelder–Mead, 280 runs at most). Each parameter's 90 % interval \
         is the 5–95 % quantiles of its samples after burn-in.\n",
        FREE.join("`, `"),
        if o.no_dispersion {
            "none (`shpb reduce --no-dispersion`, `--no-dispersion` of the generator), for the \
             records and the model alike: the default Bancroft correction costs several times \
             the run itself (see the diagnosis)"
        } else {
            "Bancroft (`shpb reduce`'s default), for the records and the model alike"
        },
        o.walkers,
        o.steps,
        o.burn_in.unwrap_or(o.steps / 4),
    );
    let _ = writeln!(
        w,
        "## Coverage\n\n\
         | parameter | truth inside its 90 % interval | of |\n|---|---|---|"
    );
    for (k, name) in NAMES.iter().enumerate() {
        let _ = writeln!(w, "| {name} | **{}** | {n} |", count(k));
    }
    let _ = writeln!(w, "| all four at once | **{all}** | {n} |\n");
    let _ = writeln!(
        w,
        "With independent 90 % intervals of exact coverage, each count is binomial (n = {n}, \
         p = 0.9): mean {:.0}, 95 % of counts within {}–{}. All four at once is lower by \
         construction (four correlated intervals; 0.9⁴ = 0.66 if they were independent).\n",
        0.9 * n as f64,
        binomial_low(n),
        binomial_high(n),
    );
    let _ = writeln!(
        w,
        "![coverage](coverage.png)\n\n*Each record's 90 % interval (between the dashed lines \
         at ±1) and its true value, in half-widths from the interval's middle.*\n"
    );
    let _ = writeln!(
        w,
        "## The chains\n\n\
         The largest integrated autocorrelation time of the four parameters: median {tau_med:.1} \
         steps, largest {tau_max:.1}; the chain kept ≥ 10 τ (kept steps after burn-in ≥ 10 × \
         the largest τ) in {ten_tau} of {n} records. Median acceptance {:.2}. Median noise of \
         the stress–strain record (the fit's noise model): SD {:.2} MPa a point, correlation \
         {:.1} points, calibration on 64 simulated records at the best fit (the factor on σ²τ, \
         docs/physics.md §12.3) {:.2}. Median {:.0} forward runs and {:.0} s a fit.\n",
        med(&|r| r.acceptance),
        med(&|r| r.noise_sd_pa) / 1e6,
        med(&|r| r.noise_corr),
        med(&|r| r.noise_calibration),
        med(&|r| r.runs as f64),
        med(&|r| r.wall_s),
    );
    if !diagnosis.is_empty() {
        let _ = writeln!(w, "## Diagnosis\n\n{diagnosis}");
    }
    let _ = writeln!(
        w,
        "## Per record\n\n`records.csv`: each record's truths, best fit, median, interval, \
         whether the truth is inside, each parameter's τ (steps), the steps kept, acceptance, \
         noise model, forward runs and wall time.\n\n\
         ## Run time\n\n\
         {wall:.0} s wall, {cpu:.0} s CPU (user + system) on {} worker threads of a shared \
         2-core machine ({run_ms:.1} ms a noise-free model run at `fast`).",
        o.jobs
    );
    std::fs::write(dir.join("REPORT.md"), md).map_err(|e| io(e, "REPORT.md"))?;
    eprintln!("wrote {}", dir.join("REPORT.md").display());
    Ok(())
}

/// Median of finite values.
fn median(v: &[f64]) -> f64 {
    let mut s: Vec<f64> = v.iter().cloned().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return f64::NAN;
    }
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// The binomial (n, 0.9) probability mass.
fn binomial_pmf(n: usize, k: usize) -> f64 {
    let ln_choose = (1..=n).map(|i| (i as f64).ln()).sum::<f64>()
        - (1..=k).map(|i| (i as f64).ln()).sum::<f64>()
        - (1..=n - k).map(|i| (i as f64).ln()).sum::<f64>();
    (ln_choose + k as f64 * 0.9f64.ln() + (n - k) as f64 * 0.1f64.ln()).exp()
}

/// The largest k with P(X < k) ≤ 2.5 % for X ~ binomial(n, 0.9).
fn binomial_low(n: usize) -> usize {
    let mut c = 0.0;
    for k in 0..=n {
        c += binomial_pmf(n, k);
        if c > 0.025 {
            return k;
        }
    }
    n
}

/// The smallest k with P(X > k) ≤ 2.5 % for X ~ binomial(n, 0.9).
fn binomial_high(n: usize) -> usize {
    let mut c = 0.0;
    for k in (0..=n).rev() {
        c += binomial_pmf(n, k);
        if c > 0.025 {
            return k;
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_binomial_bounds_are_those_of_fifty_records() {
        // Binomial(50, 0.9): the probabilities sum to one, the mean is 45, and 95 % of counts
        // lie within 41–49 (P(X ≤ 40) = 2.5 %, P(X = 50) = 0.9⁵⁰ = 0.5 %; tables of the
        // binomial distribution).
        let total: f64 = (0..=50).map(|k| binomial_pmf(50, k)).sum();
        assert!((total - 1.0).abs() < 1e-12);
        let mean: f64 = (0..=50).map(|k| k as f64 * binomial_pmf(50, k)).sum();
        assert!((mean - 45.0).abs() < 1e-9);
        assert!((binomial_pmf(50, 50) - 0.9f64.powi(50)).abs() < 1e-15);
        assert_eq!((binomial_low(50), binomial_high(50)), (41, 49));
    }

    #[test]
    fn a_noise_free_record_is_its_truth_model() {
        // The record and the model are reduced alike (the same Reducer on the same virtual
        // gauges): a noise-free record's residual at its own constants is zero, so whatever the
        // coverage study finds is the statistics' and the search's, not a mismatch of the two.
        let scene = common::repo_root().join("validation/fit-cylinder/scenes/copper-fast.toml");
        let base = base_problem(&scene).expect("the study's scene");
        let p = record_problem(&base, &NOMINAL, None, "noise-free").expect("a record");
        let m = p.model(&NOMINAL).expect("a run");
        assert_eq!(m[0], p.series[0].y);
        assert!(p.series[0].y.len() > 100);
    }
}

//! Calibrates the gas gun and the copper pulse shaper of `bars/authors.toml` against the incident
//! gauge records of 2013-05-22 (samples 1–8) and writes `validation/pulse/REPORT.md` and one
//! overlay plot per sample, `validation/pulse/sample<N>.png`. Run from the repository root:
//! `cargo run --release -p shpb-validate --bin calibrate_pulse` (≈ 1 min on two cores);
//! `cargo run --release -p shpb-validate --bin calibrate_pulse -- --shipped` evaluates the
//! shipped values only.
//!
//! * **Records.** The incident channel is converted to bar stress with the shipped gauge channel
//!   (exact bridge inverse, baseline = mean of the first 900 samples), compression positive.
//!   Metrics of the first pulse, −10 to 250 µs after the trigger: peak, 10–90 % rise, duration at 10 % of peak
//!   (`shpb_core::gauge::pulse_metrics`, raw samples, no filtering), and the pulse's energy.
//! * **Model.** `Apparatus::pulse_chain`: striker → Frew–Forrestal–Chen shaper → incident bar →
//!   transmission bar pressed against it, 1 mm cells, 2 mm gauge grid, no dispersion (what
//!   `run_pulse` does); the noise-free gauge strain at 10 MHz, σ = −E ε.
//! * **Fit.** argmin's Nelder–Mead (`shpb_study::calibrate::optimise::nelder_mead`) on Σ over records of (relative error / tolerance)² of
//!   peak (15 %), rise (20 %), duration (20 %) and pulse energy (20 %). Stage 1 frees one striker
//!   velocity per pressure (to test the gun law); stage 2 ties the velocities to
//!   v² = k (p − p_loss) and gives the shipped values. Comparison fits show what that rests on.

#![warn(missing_docs)]

#[path = "../common/mod.rs"]
mod common;

use rayon::prelude::*;
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{PulseMetrics, authors_stress_from_voltage, pulse_edges, pulse_metrics};
use shpb_core::numeric::{bisect, least_squares, moving_average, resample};
use shpb_core::shaper::{PulseShaper, ShaperModel};
use shpb_core::striker::Gun;
use shpb_input::Validator;
use shpb_input::prelude::*;
use shpb_input::units::PSI_PA;
use shpb_output::plot::{Axes, Curve, xy_plot};
use shpb_study::calibrate::optimise::nelder_mead;
use shpb_study::calibrate::pulse_energy_j;
use shpb_validate::gauge_records::{
    BASELINE_SAMPLES, INCIDENT_WINDOW_S as WINDOW_S, SAMPLES, incident_pulse,
};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The three gun pressures, psi.
const PRESSURES_PSI: [f64; 3] = [10.0, 12.5, 15.0];
/// Tolerances of the issue: peak, rise 10–90 %, duration at 10 %.
const TOL: [f64; 3] = [0.15, 0.20, 0.20];
/// Names of the three metrics, in the order of [`TOL`].
const METRIC_NAMES: [&str; 3] = ["peak", "rise 10–90 %", "duration at 10 %"];
/// Tolerance (weight) of the pulse energy in the objective: that of the issue's shape metrics.
const ENERGY_TOL: f64 = 0.20;
/// Cell size of the calibration runs (the `pulse` scene's default), m.
const CELL_M: f64 = 1e-3;
/// Gauge grid of the calibration runs (the `pulse` scene's default), m.
const GAUGE_LENGTH_M: f64 = 2e-3;

/// The repository root (see [`common::repo_root`]).
fn root() -> PathBuf {
    common::repo_root()
}

/// One record's incident pulse: times (s), compression-positive stress (Pa), metrics.
struct Record {
    sample: usize,
    material: &'static str,
    psi: f64,
    time_s: Vec<f64>,
    stress_pa: Vec<f64>,
    metrics: PulseMetrics,
    /// Energy the pulse carries, J.
    energy_j: f64,
}

fn read_records(a: &Apparatus) -> Vec<Record> {
    SAMPLES
        .iter()
        .map(|s| {
            let (time_s, stress_pa) = incident_pulse(a, &s.record_path(&root())).expect("record");
            let metrics = pulse_metrics(&time_s, &stress_pa, false).expect("incident pulse");
            let energy_j = pulse_energy_j(a, &time_s, &stress_pa);
            Record {
                sample: s.number,
                material: s.material,
                psi: s.psi,
                time_s,
                stress_pa,
                metrics,
                energy_j,
            }
        })
        .collect()
}

/// A simulated incident gauge signal at 10 MHz.
struct Simulated {
    time_s: Vec<f64>,
    stress_pa: Vec<f64>,
    metrics: Option<PulseMetrics>,
    energy_j: f64,
    striker_final_velocity_m_s: f64,
    /// Work the shaper took from the bars by the end of the run, J.
    shaper_work_j: f64,
}

fn simulate(a: &Apparatus, v: f64, shaper: PulseShaper, cell_m: f64, gauge_m: f64) -> Simulated {
    let c0 = a.material.wave_speed_m_s();
    let ch = a.gauges.channel("incident").expect("incident channel");
    let arrival = (a.incident.length_m - ch.distance_from_specimen_m) / c0;
    let end = arrival + WINDOW_S.1 + 20e-6;
    let Ok(s) = a.incident_signal(v, Some(shaper), cell_m, gauge_m, end) else {
        return Simulated {
            time_s: vec![],
            stress_pa: vec![],
            metrics: None,
            energy_j: f64::NAN,
            striker_final_velocity_m_s: f64::NAN,
            shaper_work_j: f64::NAN,
        };
    };
    Simulated {
        metrics: pulse_metrics(&s.time_s, &s.stress_pa, false),
        energy_j: pulse_energy_j(a, &s.time_s, &s.stress_pa),
        striker_final_velocity_m_s: s.chain.striker_final_velocity_m_s,
        shaper_work_j: s.chain.shaper_energy_j.last().copied().unwrap_or(f64::NAN),
        time_s: s.time_s,
        stress_pa: s.stress_pa,
    }
}

/// Every parameter of the model: striker velocity per pressure and the shaper.
#[derive(Clone, Copy, Debug)]
struct Model {
    velocity_m_s: [f64; 3],
    shaper: PulseShaper,
}

/// Relative errors (sim − measured)/measured of peak, rise and duration.
fn errors(m: &PulseMetrics, s: &PulseMetrics) -> [f64; 3] {
    [
        s.peak / m.peak - 1.0,
        s.rise_10_90_s / m.rise_10_90_s - 1.0,
        s.duration_10_s / m.duration_10_s - 1.0,
    ]
}

fn run_model_with(a: &Apparatus, model: &Model, cell_m: f64, gauge_m: f64) -> Vec<Simulated> {
    (0..3)
        .into_par_iter()
        .map(|i| simulate(a, model.velocity_m_s[i], model.shaper, cell_m, gauge_m))
        .collect()
}

fn run_model(a: &Apparatus, model: &Model) -> Vec<Simulated> {
    run_model_with(a, model, CELL_M, GAUGE_LENGTH_M)
}

fn pressure_index(psi: f64) -> usize {
    PRESSURES_PSI
        .iter()
        .position(|&p| p == psi)
        .expect("one of the three pressures")
}

/// How well a model matches the records.
#[derive(Clone, Copy, Debug)]
struct Score {
    /// Σ (error/tolerance)² of the issue's three metrics over the records.
    metrics: f64,
    /// Σ (energy error/ENERGY_TOL)² over the records.
    energy: f64,
    /// Largest |error|/tolerance of the issue's metrics (≤ 1: every criterion met).
    worst: f64,
    /// Largest |relative error| of the pulse energy.
    worst_energy: f64,
}

impl Score {
    /// The objective: the issue's metrics, plus the pulse energy if `with_energy`.
    fn objective(&self, with_energy: bool) -> f64 {
        self.metrics + if with_energy { self.energy } else { 0.0 }
    }
}

fn score(records: &[Record], sims: &[Simulated]) -> Score {
    let mut sc = Score {
        metrics: 0.0,
        energy: 0.0,
        worst: 0.0,
        worst_energy: 0.0,
    };
    for r in records {
        let s = &sims[pressure_index(r.psi)];
        let Some(sm) = &s.metrics else {
            return Score {
                metrics: 1e6,
                energy: 1e6,
                worst: f64::INFINITY,
                worst_energy: f64::INFINITY,
            };
        };
        for (k, e) in errors(&r.metrics, sm).iter().enumerate() {
            let x = e / TOL[k];
            sc.metrics += x * x;
            sc.worst = sc.worst.max(x.abs());
        }
        let e = s.energy_j / r.energy_j - 1.0;
        sc.energy += (e / ENERGY_TOL).powi(2);
        sc.worst_energy = sc.worst_energy.max(e.abs());
    }
    sc
}

fn score_of(a: &Apparatus, records: &[Record], m: &Model) -> Score {
    score(records, &run_model(a, m))
}

/// A free shaper parameter.
#[derive(Clone, Copy, PartialEq, Debug)]
enum ShaperKey {
    Diameter,
    Thickness,
    Sigma0,
    Modulus,
    N,
    M,
}

impl ShaperKey {
    fn get(self, s: &PulseShaper) -> f64 {
        match self {
            ShaperKey::Diameter => s.diameter_m,
            ShaperKey::Thickness => s.thickness_m,
            ShaperKey::Sigma0 => s.sigma0_pa,
            ShaperKey::Modulus => s.youngs_modulus_pa,
            ShaperKey::N => s.n,
            ShaperKey::M => s.m,
        }
    }
    fn set(self, s: &mut PulseShaper, x: f64) {
        match self {
            ShaperKey::Diameter => s.diameter_m = x,
            ShaperKey::Thickness => s.thickness_m = x,
            ShaperKey::Sigma0 => s.sigma0_pa = x,
            ShaperKey::Modulus => s.youngs_modulus_pa = x,
            ShaperKey::N => s.n = x,
            ShaperKey::M => s.m = x,
        }
    }
    /// Bounds: a disc that fits on the 19 mm bar, 0.2–8 mm thick, σ0 0.05–3 GPa, modulus
    /// 0.5–130 GPa, hardening and locking exponents in a wide band around Frew et al.'s.
    fn bounds(self) -> (f64, f64) {
        match self {
            ShaperKey::Diameter => (1e-3, 19e-3),
            ShaperKey::Thickness => (0.2e-3, 8e-3),
            ShaperKey::Sigma0 => (0.05e9, 3e9),
            ShaperKey::Modulus => (0.5e9, 130e9),
            ShaperKey::N => (0.1, 0.8),
            ShaperKey::M => (1.5, 10.0),
        }
    }
}

/// How the striker velocities are parametrised.
#[derive(Clone, Copy, PartialEq, Debug)]
enum GunFit {
    /// One free velocity per pressure.
    Free,
    /// v² = k (p − p_loss): free v at 10 and 15 psi, v(12.5 psi) on the line.
    Linear,
}

/// A fit: which parameters are free (all in log space, bounded by a penalty) and whether the
/// pulse energy is in the objective.
struct FitSpec {
    gun: GunFit,
    shaper: Vec<ShaperKey>,
    energy: bool,
}

impl FitSpec {
    fn pack(&self, m: &Model) -> Vec<f64> {
        let mut x: Vec<f64> = match self.gun {
            GunFit::Free => m.velocity_m_s.iter().map(|v| v.ln()).collect(),
            GunFit::Linear => vec![m.velocity_m_s[0].ln(), m.velocity_m_s[2].ln()],
        };
        x.extend(self.shaper.iter().map(|k| k.get(&m.shaper).ln()));
        x
    }

    /// The model for a point, or None outside the bounds (or an unphysical gun line).
    fn unpack(&self, x: &[f64], base: &Model, p_min_pa: f64) -> Option<Model> {
        let mut m = *base;
        let nv = match self.gun {
            GunFit::Free => {
                m.velocity_m_s = [x[0].exp(), x[1].exp(), x[2].exp()];
                3
            }
            GunFit::Linear => {
                let (k, loss) = line_through(x[0].exp(), x[1].exp())?;
                if !(0.0..p_min_pa).contains(&loss) {
                    return None;
                }
                m.velocity_m_s = PRESSURES_PSI.map(|psi| (k * (psi * PSI_PA - loss)).sqrt());
                2
            }
        };
        if m.velocity_m_s.iter().any(|&v| !(0.5..100.0).contains(&v)) {
            return None;
        }
        for (j, key) in self.shaper.iter().enumerate() {
            let v = x[nv + j].exp();
            let (lo, hi) = key.bounds();
            if !(lo..=hi).contains(&v) {
                return None;
            }
            key.set(&mut m.shaper, v);
        }
        Some(m)
    }
}

/// (k, p_loss) of the line v² = k (p − p_loss) through the 10 and 15 psi velocities.
fn line_through(v10: f64, v15: f64) -> Option<(f64, f64)> {
    let (p10, p15) = (10.0 * PSI_PA, 15.0 * PSI_PA);
    let k = (v15 * v15 - v10 * v10) / (p15 - p10);
    if k <= 0.0 {
        return None;
    }
    Some((k, p10 - v10 * v10 / k))
}

/// Least-squares line v² = k (p − p_loss) through three (p, v) points: (k, p_loss, residuals of v).
fn least_squares_gun(v: &[f64; 3]) -> (f64, f64, [f64; 3]) {
    let p: Vec<f64> = PRESSURES_PSI.iter().map(|x| x * PSI_PA).collect();
    let y: Vec<f64> = v.iter().map(|x| x * x).collect();
    // v² = k p + c with c = −k p_loss.
    let kc = least_squares(&[&p, &[1.0; 3]], &y).expect("three distinct pressures fix the line");
    let (k, loss) = (kc[0], -kc[1] / kc[0]);
    let res = [0, 1, 2].map(|i| (k * (p[i] - loss)).max(0.0).sqrt() - v[i]);
    (k, loss, res)
}

/// Runs one fit from `start` (restarting Nelder–Mead from the best point with a smaller simplex
/// until it stops improving); returns the best model, its objective and the evaluations used.
fn fit(
    a: &Apparatus,
    records: &[Record],
    spec: &FitSpec,
    start: &Model,
    label: &str,
    max_evals: usize,
) -> (Model, f64, usize) {
    let p_min = a.gun.range_pa().0;
    let mut best = (*start, f64::INFINITY);
    let mut f = |x: &[f64]| -> f64 {
        let Some(m) = spec.unpack(x, start, p_min) else {
            return 1e9;
        };
        let v = score_of(a, records, &m).objective(spec.energy);
        if v < best.1 {
            best = (m, v);
        }
        v
    };
    let mut x = spec.pack(start);
    let (mut total, mut last) = (0, f64::INFINITY);
    for round in 0..4 {
        let step = vec![if round == 0 { 0.15 } else { 0.05 }; x.len()];
        let budget = (max_evals - total).min(max_evals / 2);
        let (xb, fb, n) = nelder_mead(&mut f, &x, &step, budget, 1e-7);
        total += n;
        eprintln!("{label}: round {round}, objective {fb:.4}, {n} evaluations");
        x = xb;
        if last - fb < 1e-4 * last.max(1e-12) || total + 2 * (x.len() + 1) >= max_evals {
            break;
        }
        last = fb;
    }
    (best.0, best.1, total)
}

/// The authors' set-up regenerated by the library of `shpb calibrate` from the eight shots of
/// validation/pulse/shots-2013-05-22.toml: from the shipped constants (what
/// `shpb calibrate validation/pulse/shots-2013-05-22.toml --bars authors -o …` does) and from
/// stage 1's neutral start (a 4.5 mm × 0.55 mm disc with E = 5 GPa, the gun line through 6 m/s
/// at 10 psi and 8 m/s at 15 psi).
struct Regenerated {
    /// (start, calibration, seconds).
    runs: Vec<(&'static str, shpb_study::calibrate::Calibration, f64)>,
    /// The arrivals calibration on the same shots (not asked for by the manifest).
    arrivals: shpb_study::calibrate::Calibration,
}

fn regenerate(a: &Apparatus) -> Regenerated {
    use shpb_study::calibrate::{Data, calibrate};
    let manifest = shpb_input::shots::ShotManifest::from_file(
        &root().join("validation/pulse/shots-2013-05-22.toml"),
    )
    .expect("validation/pulse/shots-2013-05-22.toml");
    let mut neutral = a.clone();
    if let Some(s) = neutral.shaper.as_mut() {
        (s.diameter_m, s.thickness_m, s.youngs_modulus_pa) = (4.5e-3, 0.55e-3, 5e9);
    }
    if let Gun::Linear(g) = &mut neutral.gun {
        let (k, loss) = line_through(6.0, 8.0).expect("a rising line");
        (g.k_m2_per_s2_per_pa, g.loss_pressure_pa) = (k, loss);
        g.calibration_mass_kg = a.striker_mass_kg();
    }
    let mut runs = Vec::new();
    for (label, base) in [
        ("shipped constants (`--bars authors`)", a.clone()),
        ("stage 1's neutral start", neutral),
    ] {
        let t0 = std::time::Instant::now();
        let data = Data::read(base, &manifest).expect("the shots read");
        let c = calibrate(&data, &mut |line| eprintln!("regenerate ({label}): {line}"))
            .expect("the calibration runs");
        runs.push((label, c, t0.elapsed().as_secs_f64()));
    }
    let mut data = Data::read(a.clone(), &manifest).expect("the shots read");
    data.only = Some(vec!["arrivals".into()]);
    let arrivals = calibrate(&data, &mut |_| {}).expect("the arrivals calibration runs");
    Regenerated { runs, arrivals }
}

/// A constant of a calibration, with its 1-sigma.
fn constant(c: &shpb_study::calibrate::Calibration, key: &str) -> (f64, Option<f64>) {
    c.constants
        .iter()
        .find(|f| f.key == key)
        .map_or((f64::NAN, None), |f| (f.value, f.sd))
}

/// The shipped constants and the 1-sigma each is compared with: bars/authors.toml's stated
/// 1-sigma for k (4.5 %) and p_loss (3.0 kPa); for the others, which it states none for, the
/// 1-sigma `shpb calibrate` gives them from the shipped start (covariance of the fit, or for
/// velocity_scatter its sampling sd on 5 degrees of freedom).
fn shipped_and_sigma(
    a: &Apparatus,
    r: &Regenerated,
) -> Vec<(&'static str, f64, f64, &'static str)> {
    let s = a.shaper.expect("shipped shaper");
    let (k, loss) = match a.gun {
        Gun::Linear(g) => (g.k_m2_per_s2_per_pa, g.loss_pressure_pa),
        Gun::Adiabatic(_) | Gun::None => (f64::NAN, f64::NAN),
    };
    let own = |key: &str| constant(&r.runs[0].1, key).1.unwrap_or(f64::NAN);
    vec![
        (
            "gun.k_m2_per_s2_per_pa",
            k,
            0.045 * k,
            "stated (bars/authors.toml)",
        ),
        (
            "gun.loss_pressure_pa",
            loss,
            3.0e3,
            "stated (bars/authors.toml)",
        ),
        (
            "gun.velocity_scatter",
            a.gun_velocity_scatter.unwrap_or(f64::NAN),
            own("gun.velocity_scatter"),
            "shpb calibrate (sampling, 5 dof)",
        ),
        (
            "shaper.diameter_m",
            s.diameter_m,
            own("shaper.diameter_m"),
            "shpb calibrate (covariance)",
        ),
        (
            "shaper.thickness_m",
            s.thickness_m,
            own("shaper.thickness_m"),
            "shpb calibrate (covariance)",
        ),
        (
            "shaper.youngs_modulus_pa",
            s.youngs_modulus_pa,
            own("shaper.youngs_modulus_pa"),
            "shpb calibrate (covariance)",
        ),
    ]
}

/// "The optimiser": this run's stage-2 fit (argmin) against the shipped constants (the
/// hand-written Nelder–Mead's).
fn optimiser_section(
    w: &mut String,
    a: &Apparatus,
    records: &[Record],
    (fm, fk, floss): (&Model, f64, f64),
    (k, loss): (f64, f64),
    r: &Regenerated,
) {
    let shipped = shipped_model(a);
    let fitted: std::collections::HashMap<&str, f64> = [
        ("gun.k_m2_per_s2_per_pa", fk),
        ("gun.loss_pressure_pa", floss),
        ("shaper.diameter_m", fm.shaper.diameter_m),
        ("shaper.thickness_m", fm.shaper.thickness_m),
        ("shaper.youngs_modulus_pa", fm.shaper.youngs_modulus_pa),
    ]
    .into_iter()
    .collect();
    let _ = writeln!(
        w,
        "## The optimiser: argmin against the hand-written Nelder–Mead\n\n\
         The shipped constants were fitted by this generator's own Nelder–Mead (removed); it now runs \
         argmin's (`shpb_study::calibrate::optimise::nelder_mead`), from the same start, with the same \
         objective and restarts. Stage 2 of this run (rounded as the file is) against bars/authors.toml, \
         each difference against the constant's 1-sigma (k and p_loss: bars/authors.toml's stated ones; the \
         shaper's, which it states none for: the fit covariance `shpb calibrate` gives them, below):\n\n\
         | constant | hand-written (bars/authors.toml) | argmin (this run) | difference | 1-sigma | within 1-sigma? |\n\
         |---|---|---|---|---|---|"
    );
    let mut all = true;
    for (key, value, sigma, _) in shipped_and_sigma(a, r) {
        let Some(&x) = fitted.get(key) else { continue };
        let within = (x - value).abs() <= sigma;
        all &= within;
        let _ = writeln!(
            w,
            "| `{key}` | {value:.4e} | {x:.4e} | {:+.2} % | {sigma:.3e} | {} |",
            100.0 * (x / value - 1.0),
            if within { "yes" } else { "**no**" }
        );
    }
    let (so, sf) = (score_of(a, records, &shipped), score_of(a, records, fm));
    let _ = writeln!(
        w,
        "\nObjective (issue metrics + energy) {:.3} with the shipped constants, {:.3} with argmin's; striker \
         velocities 10 / 12.5 / 15 psi {:.3} / {:.3} / {:.3} m/s (shipped: {:.3} / {:.3} / {:.3}). {}\n",
        so.objective(true),
        sf.objective(true),
        fm.velocity_m_s[0],
        fm.velocity_m_s[1],
        fm.velocity_m_s[2],
        shipped.velocity_m_s[0],
        shipped.velocity_m_s[1],
        shipped.velocity_m_s[2],
        if all {
            "Every constant agrees within its 1-sigma, so bars/authors.toml keeps the hand-written optimiser's \
             values, and every table below evaluates them. The leave-one-out fits below \
             (`shaper_loo -- --refit`, validation/pulse/shaper_loo_fits.toml) run on the same argmin \
             minimiser."
        } else {
            "**Not every constant agrees within its 1-sigma**: see the table."
        }
    );
    let _ = (k, loss);
}

/// "Regenerated by `shpb calibrate`": the acceptance of issue 41 (the authors' set-up
/// regenerated from its shots gives today's constants within their stated uncertainties).
fn regeneration_section(w: &mut String, r: &Regenerated) {
    let a = Apparatus::from_file(&root().join("bars/authors.toml")).expect("bars/authors.toml");
    let _ = writeln!(
        w,
        "## Regenerated by `shpb calibrate`\n\n\
         The acceptance of issue 41: the eight shots as a manifest (validation/pulse/shots-2013-05-22.toml: \
         each record, its pressure; `calibrate = [\"gun\", \"shaper\"]`) through the library of \
         `shpb calibrate` (crates/study/src/calibrate/: the shaper fit of stage 2 on argmin's Nelder–Mead, \
         records read by `shpb reduce`'s entry point, the incident pulse from 10 µs before its foot to \
         10 µs before the reflected one can arrive). From the shipped constants this is\n\n\
         ```\nshpb calibrate validation/pulse/shots-2013-05-22.toml --bars authors -o authors-regenerated.toml\n```\n\n\
         and, to show the result does not merely echo its start, again from stage 1's neutral start (a \
         4.5 mm × 0.55 mm disc with E = 5 GPa; the gun line through 6 m/s at 10 psi and 8 m/s at 15 psi). \
         Each constant: shipped, regenerated, the 1-sigma it is compared with (k, p_loss: stated in \
         bars/authors.toml; the others state none, so `shpb calibrate`'s own from the shipped start), and \
         whether the regenerated value lies within it.\n"
    );
    let rows = shipped_and_sigma(&a, r);
    let mut header = String::from("| constant | shipped | 1-sigma | 1-sigma from |");
    let mut rule = String::from("|---|---|---|---|");
    for (label, _, _) in &r.runs {
        header.push_str(&format!(
            " regenerated from {label} | within? | `shpb calibrate`'s own 1-sigma |"
        ));
        rule.push_str("---|---|---|");
    }
    let _ = writeln!(w, "{header}\n{rule}");
    let mut verdict = vec![true; r.runs.len()];
    for (key, value, sigma, from) in &rows {
        let mut line = format!("| `{key}` | {value:.4e} | {sigma:.3e} | {from} |");
        for (j, (_, c, _)) in r.runs.iter().enumerate() {
            let (x, sd) = constant(c, key);
            let within = (x - value).abs() <= *sigma;
            verdict[j] &= within;
            line.push_str(&format!(
                " {x:.4e} ({:+.2} %) | {} | {} |",
                100.0 * (x / value - 1.0),
                if within { "yes" } else { "**no**" },
                sd.map_or("—".into(), |s| format!(
                    "{s:.3e} ({:.1} %)",
                    100.0 * s / x.abs()
                ))
            ));
        }
        let _ = writeln!(w, "{line}");
    }
    for ((label, c, secs), ok) in r.runs.iter().zip(&verdict) {
        let _ = writeln!(
            w,
            "\nFrom {label}: {} ({secs:.0} s). Shot-to-shot scatter the shots show ([uncertainty.scatter]): {}.",
            if *ok {
                "**every constant within its 1-sigma of the shipped value**"
            } else {
                "**not every constant within its 1-sigma** (table)"
            },
            c.scatter
                .iter()
                .map(|(k, v)| format!("{k} {v:.3e}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let (rho, sd_rho) = constant(&r.arrivals, "material.density_kg_m3");
    let (di, sd_di) = constant(&r.arrivals, "gauges.incident.distance_from_specimen_m");
    let c_of = |rho: f64| (a.material.youngs_modulus_pa / rho).sqrt();
    let _ = writeln!(
        w,
        "\nThe manifest does not ask for the `arrivals` calibration (the specimens sit between the bars, so no \
         shot dates the transmission gauge). Run on the same shots it gives c0 = {:.1} ± {:.1} m/s from the \
         incident bar's far-end echo (bars/authors.toml: 4865.5 m/s measured; ρ = E/c0² = {rho:.0} ± {:.0} \
         kg/m³ against 8110) and an effective incident gauge distance d_I = {:.4} ± {:.4} m from the reflected \
         feet (stated: 0.6445 m, 25.375 in): the reflected pulses of these specimens reach their 2 % level \
         {:.1} µs before 2 d_I/c0 on the stated distance, as large as the lateness of the virtual test's \
         reflected pulses that issue 41 reports (an inference, not tested here). They are left as the authors \
         state them here.\n",
        c_of(rho),
        0.5 * c_of(rho) * sd_rho.unwrap_or(f64::NAN) / rho,
        sd_rho.unwrap_or(f64::NAN),
        di,
        sd_di.unwrap_or(f64::NAN),
        2.0 * (0.644525 - di) / c_of(rho) * 1e6,
    );
    let _ = writeln!(
        w,
        "\n`shpb calibrate`'s own 1-sigma of k and p_loss is the fit's covariance over all 32 residuals \
         (peak, rise, duration, energy of the eight records, scaled by their scatter about the model), larger \
         than bars/authors.toml's stated one, which came from the line through stage 1's three free velocities \
         (its residuals only): the covariance also carries the shape misfit the model cannot remove. Until the \
         `[uncertainty]` table is parsed by `--bars` (another part of issue 41), the written set-up is checked \
         as TOML with the calibrated keys present (crates/cli/tests/calibrate.rs).\n"
    );
}

/// `x` rounded to `digits` significant digits (through its decimal form, so 0.75e9 stays exact).
fn round_sig(x: f64, digits: usize) -> f64 {
    format!("{:.*e}", digits - 1, x).parse().unwrap_or(x)
}

/// The model with the gun line and shaper rounded as written into bars/authors.toml (4
/// significant digits, p_loss to 10 Pa); returns it with k and p_loss.
fn rounded(m: &Model) -> (Model, f64, f64) {
    let (k, loss) = line_through(m.velocity_m_s[0], m.velocity_m_s[2]).expect("gun line");
    let (k, loss) = (round_sig(k, 4), (loss / 10.0).round() * 10.0);
    let mut r = *m;
    r.velocity_m_s = PRESSURES_PSI.map(|psi| (k * (psi * PSI_PA - loss)).sqrt());
    let s = &mut r.shaper;
    for key in [
        ShaperKey::Diameter,
        ShaperKey::Thickness,
        ShaperKey::Sigma0,
        ShaperKey::Modulus,
        ShaperKey::N,
        ShaperKey::M,
    ] {
        key.set(s, round_sig(key.get(s), 4));
    }
    (r, k, loss)
}

/// Root of a function increasing on [lo, hi]: the midpoint of the bracket after 100 halvings
/// (no early stop), keeping the upper half where `f(mid) < 0`.
fn root_of_increasing(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let (lo, hi) = bisect(lo, hi, 100, |_, _| false, |x| f(x) < 0.0);
    0.5 * (lo + hi)
}

/// The shaper's strain where its elastic line meets the flow curve (E ε = σ_flow(ε)), and its
/// largest strain: where the loading force σ(ε) A0/(1 − ε) reaches the peak force in the bar.
fn shaper_strains(s: &PulseShaper, peak_force_n: f64) -> (f64, f64) {
    let yield_strain = root_of_increasing(
        |e| s.youngs_modulus_pa * e - s.flow_stress_pa(e),
        1e-9,
        0.99,
    );
    let force =
        |e: f64| (s.youngs_modulus_pa * e).min(s.flow_stress_pa(e)) * s.area_m2() / (1.0 - e);
    (
        yield_strain,
        root_of_increasing(|e| force(e) - peak_force_n, 0.0, 0.99),
    )
}

/// The shipped model: the gun's velocities at the three pressures and the shaper of the file.
fn shipped_model(a: &Apparatus) -> Model {
    let v = Validator::new(a.source.clone());
    Model {
        velocity_m_s: PRESSURES_PSI.map(|psi| {
            a.striker_velocity_m_s(psi * PSI_PA)
                .map_err(v.core("pressure"))
                .expect("shipped gun covers 10-15 psi")
        }),
        shaper: a.shaper.expect("shipped shaper"),
    }
}

/// One row of the table of fits.
struct FitRow {
    label: &'static str,
    free: &'static str,
    energy: bool,
    model: Model,
    score: Score,
    evals: usize,
}

fn mpa(x: f64) -> String {
    format!("{:.1}", x / 1e6)
}

fn us(x: f64) -> String {
    format!("{:.1}", x * 1e6)
}

/// Shape diagnostics of a pulse, on a 1.1 µs moving average (11 samples) so that the records'
/// noise does not decide them: (time at ≥ 90 % of peak, fall from 90 % to 10 %), s.
fn plateau_and_fall(t: &[f64], y: &[f64]) -> (f64, f64) {
    let ys = moving_average(y, 5);
    let Some((k, &p)) = ys.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)) else {
        return (f64::NAN, f64::NAN);
    };
    let cross =
        |i: usize, level: f64| t[i] + (level - ys[i]) * (t[i + 1] - t[i]) / (ys[i + 1] - ys[i]);
    let rise90 = (0..k)
        .rev()
        .find(|&i| ys[i] < 0.9 * p)
        .map(|i| cross(i, 0.9 * p));
    let after = |level: f64| {
        (k + 1..ys.len())
            .find(|&j| ys[j] < level)
            .map(|j| cross(j - 1, level))
    };
    match (rise90, after(0.9 * p), after(0.1 * p)) {
        (Some(r), Some(f90), Some(f10)) => (f90 - r, f10 - f90),
        _ => (f64::NAN, f64::NAN),
    }
}

/// Aligned traces for a plot: times relative to the 10 % rise, −20 to 240 µs.
fn aligned(t: &[f64], y: &[f64], start: f64) -> (Vec<f64>, Vec<f64>) {
    t.iter()
        .zip(y)
        .filter(|(ti, _)| (-20e-6..=240e-6).contains(&(**ti - start)))
        .map(|(ti, yi)| (ti - start, *yi))
        .unzip()
}

/// RMS difference of the traces aligned at the 10 % rise, over the measured pulse (10 % to 10 %),
/// relative to the measured peak.
fn shape_rms(r: &Record, s: &Simulated) -> f64 {
    let Some(sm) = &s.metrics else {
        return f64::NAN;
    };
    let m = &r.metrics;
    let (t0, t1) = (m.start_10_s, m.start_10_s + m.duration_10_s);
    let idx: Vec<usize> = (0..r.time_s.len())
        .filter(|&i| (t0..=t1).contains(&r.time_s[i]))
        .collect();
    let at: Vec<f64> = idx
        .iter()
        .map(|&i| r.time_s[i] - m.start_10_s + sm.start_10_s)
        .collect();
    let sim = resample(&s.time_s, &s.stress_pa, &at);
    let ss: f64 = idx
        .iter()
        .zip(&sim)
        .map(|(&i, y)| (y - r.stress_pa[i]).powi(2))
        .sum();
    (ss / idx.len() as f64).sqrt() / m.peak
}

fn main() {
    let a = Apparatus::from_file(&root().join("bars/authors.toml")).expect("bars/authors.toml");
    let ch = a
        .gauges
        .channel("incident")
        .expect("incident channel")
        .clone();
    let records = read_records(&a);
    let out_dir = root().join("validation/pulse");
    std::fs::create_dir_all(&out_dir).expect("validation/pulse");
    let only_shipped = std::env::args().any(|s| s == "--shipped");
    let shipped = shipped_model(&a);
    let dhe = vec![
        ShaperKey::Diameter,
        ShaperKey::Thickness,
        ShaperKey::Modulus,
    ];

    // ---- Fits ----
    let mut rows: Vec<FitRow> = Vec::new();
    let push = |rows: &mut Vec<FitRow>,
                (label, free): (&'static str, &'static str),
                spec: &FitSpec,
                (model, _, evals): (Model, f64, usize)| {
        rows.push(FitRow {
            label,
            free,
            energy: spec.energy,
            model,
            score: score_of(&a, &records, &model),
            evals,
        });
    };
    let mut stage1 = None;
    let fitted = if only_shipped {
        shipped
    } else {
        // Start: a small thin disc (Frew et al.'s σ0, n, m) with soft faces.
        let start = Model {
            velocity_m_s: [6.0, 7.0, 8.0],
            shaper: PulseShaper {
                diameter_m: 4.5e-3,
                thickness_m: 0.55e-3,
                sigma0_pa: 0.75e9,
                n: 0.37,
                m: 4.25,
                youngs_modulus_pa: 5e9,
                model: ShaperModel::Frew,
                calibrated_pressure_pa: None,
            },
        };
        let spec = FitSpec {
            gun: GunFit::Free,
            shaper: dhe.clone(),
            energy: true,
        };
        let s1 = fit(&a, &records, &spec, &start, "stage 1", 1000);
        push(
            &mut rows,
            (
                "1: one velocity per pressure",
                "v(10), v(12.5), v(15), diameter, thickness, E",
            ),
            &spec,
            s1,
        );
        stage1 = Some(s1.0);
        let spec = FitSpec {
            gun: GunFit::Linear,
            shaper: dhe.clone(),
            energy: true,
        };
        let s2 = fit(&a, &records, &spec, &s1.0, "stage 2", 700);
        push(
            &mut rows,
            (
                "2: gun line (**shipped**)",
                "k, p_loss, diameter, thickness, E",
            ),
            &spec,
            s2,
        );
        // Comparisons.
        let spec = FitSpec {
            gun: GunFit::Linear,
            shaper: dhe.clone(),
            energy: false,
        };
        let r = fit(&a, &records, &spec, &s2.0, "issue metrics only", 500);
        push(
            &mut rows,
            (
                "issue's metrics only (no energy)",
                "k, p_loss, diameter, thickness, E",
            ),
            &spec,
            r,
        );
        let copper = Model {
            velocity_m_s: [8.0, 9.0, 10.0],
            shaper: PulseShaper {
                diameter_m: 9e-3,
                thickness_m: 3e-3,
                sigma0_pa: 0.75e9,
                n: 0.37,
                m: 4.25,
                youngs_modulus_pa: 117e9,
                model: ShaperModel::Frew,
                calibrated_pressure_pa: None,
            },
        };
        let spec = FitSpec {
            gun: GunFit::Linear,
            shaper: vec![
                ShaperKey::Diameter,
                ShaperKey::Thickness,
                ShaperKey::Sigma0,
                ShaperKey::N,
                ShaperKey::M,
            ],
            energy: true,
        };
        let r = fit(&a, &records, &spec, &copper, "copper modulus", 1000);
        push(
            &mut rows,
            (
                "copper E = 117 GPa, fixed",
                "k, p_loss, diameter, thickness, σ0, n, m",
            ),
            &spec,
            r,
        );
        let mut all = dhe.clone();
        all.extend([ShaperKey::N, ShaperKey::M]);
        let spec = FitSpec {
            gun: GunFit::Linear,
            shaper: all,
            energy: true,
        };
        let r = fit(&a, &records, &spec, &s2.0, "n, m free", 500);
        push(
            &mut rows,
            ("n, m free too", "k, p_loss, diameter, thickness, E, n, m"),
            &spec,
            r,
        );
        s2.0
    };
    // Every table below evaluates the shipped constants (bars/authors.toml, fitted with the
    // hand-written Nelder–Mead this generator used before); this run's argmin fit is compared
    // with them ("The optimiser").
    let (k, loss) = match a.gun {
        Gun::Linear(g) => (g.k_m2_per_s2_per_pa, g.loss_pressure_pa),
        Gun::Adiabatic(_) | Gun::None => (f64::NAN, f64::NAN),
    };
    let m = shipped;
    let argmin_fit = (!only_shipped).then(|| rounded(&fitted));
    let sims = run_model(&a, &m);
    let sc = score(&records, &sims);
    let toml = format!(
        "[gun]\nmodel = \"linear\"\nk_m2_per_s2_per_pa = {k:e}\nloss_pressure_pa = {loss:e}\n\n\
         [shaper]\ndiameter_m = {:e}\nthickness_m = {:e}\nsigma0_pa = {:e}\nn = {}\nm = {}\nyoungs_modulus_pa = {:e}",
        m.shaper.diameter_m,
        m.shaper.thickness_m,
        m.shaper.sigma0_pa,
        m.shaper.n,
        m.shaper.m,
        m.shaper.youngs_modulus_pa
    );
    println!("{toml}");

    // ---- Report ----
    let mut rep = String::new();
    let w = &mut rep;
    let _ = writeln!(
        w,
        "# Incident pulse calibration: gas gun and copper pulse shaper\n\n\
         Generated by `cargo run --release -p shpb-validate --bin calibrate_pulse` (crates/validate/src/bin/calibrate_pulse/, ≈ 1 min on two cores); do not \
         edit by hand. `-- --shipped` evaluates bars/authors.toml without fitting.{}\n",
        if only_shipped {
            " **This report comes from such a run.**"
        } else {
            ""
        }
    );
    let mut unmet: Vec<String> = Vec::new();
    for r in &records {
        let sm = sims[pressure_index(r.psi)]
            .metrics
            .expect("simulated pulse");
        for (j, e) in errors(&r.metrics, &sm).iter().enumerate() {
            if e.abs() > TOL[j] {
                unmet.push(format!(
                    "sample {} {} {:+.1} %",
                    r.sample,
                    METRIC_NAMES[j],
                    100.0 * e
                ));
            }
        }
    }
    let _ = writeln!(
        w,
        "**Result.** One gun line and one shaper for 10, 12.5 and 15 psi: the simulated incident gauge signal matches \
         all 8 records within 15 % in peak and 20 % in rise (10–90 %) and in duration (at 10 % of peak): **{}**. \
         Largest |error|/tolerance {:.2}; the pulse energy within {:.0} %.{}\n",
        if unmet.is_empty() {
            "every criterion met"
        } else {
            "NOT every criterion met"
        },
        sc.worst,
        100.0 * sc.worst_energy,
        if unmet.is_empty() {
            String::new()
        } else {
            format!(" Unmet: {}.", unmet.join("; "))
        }
    );
    let _ = writeln!(
        w,
        "## Data\n\nThe incident channel of the eight 2013-05-22 records (validation/gauge-records/data; samples 1–3 \
         SS440c at 10/12.5/15 psi, 4–5 Al2017 at 12.5/15, 6 SS302 at 10, 7 at 15, 8 at 12.5), baseline = mean of the \
         first {BASELINE_SAMPLES} samples, converted with the shipped `incident` channel of bars/gauges-authors.toml \
         (`{}` bridge, gain {}: {:.3}× the stress of the authors' formula), σ = −E ε, compression positive. Metrics of the first (incident) pulse between {:.0} \
         and {:.0} µs after the trigger, on the raw 10 MHz samples (`shpb::gauge::pulse_metrics`: largest sample; \
         10–90 % rise; time between the rising and falling 10 % crossings), and the energy the pulse carries, \
         A/(ρ c0) ∫σ² dt over the window.\n",
        ch.bridge.kind.name(),
        ch.amplifier_gain,
        {
            let (b, v) = (ch.bridge, -1e-4);
            let formula = authors_stress_from_voltage(
                v,
                a.material.youngs_modulus_pa,
                b.poisson_ratio,
                b.excitation_v,
                b.gauge_factor,
            );
            -a.material.youngs_modulus_pa * ch.strain_from_voltage(v) / formula
        },
        WINDOW_S.0 * 1e6,
        WINDOW_S.1 * 1e6
    );
    let _ = writeln!(
        w,
        "## Model\n\n`Apparatus::pulse_chain`: striker ({:.0} mm, {:.3} kg) → Frew–Forrestal–Chen shaper \
         (σ = σ0 εⁿ/(1 − εᵐ), area A0/(1 − ε), elastic with modulus E below that curve and on unloading) → incident \
         bar → transmission bar pressed against it (no specimen: the incident pulse does not depend on it), {} mm \
         cells at Courant 1, {} mm gauge grid at the incident gauge, no bar dispersion: what a `pulse` scene runs. The \
         noise-free gauge strain is sampled at 10 MHz and its metrics computed like the records'.\n",
        a.striker.length_m * 1e3,
        a.striker_mass_kg(),
        CELL_M * 1e3,
        GAUGE_LENGTH_M * 1e3
    );
    let s = &m.shaper;
    let peak_force =
        |i: usize| sims[i].metrics.map(|p| p.peak).unwrap_or(f64::NAN) * a.incident.area_m2();
    let (eps_y, eps_max15) = shaper_strains(s, peak_force(2));
    let (_, eps_max10) = shaper_strains(s, peak_force(0));
    let _ = writeln!(
        w,
        "## Calibrated parameters (in bars/authors.toml)\n\n\
         | parameter | value | how |\n|---|---|---|\n\
         | `[gun] model` | linear, v² = k (p − p_loss) | |\n\
         | `k_m2_per_s2_per_pa` | {k:.4e} | fitted (stage 2) |\n\
         | `loss_pressure_pa` | {loss:.0} ({:.2} psi) | fitted (stage 2) |\n\
         | striker velocity at 10 / 12.5 / 15 psi | {:.3} / {:.3} / {:.3} m/s | from the line |\n\
         | `[shaper] diameter_m` | {:.4e} | fitted |\n\
         | `thickness_m` | {:.4e} | fitted |\n\
         | `sigma0_pa` | {:.4e} | Frew et al., fixed: with E free only σ0·A0 and E·A0 enter the force, so σ0 and the diameter are not separately identifiable |\n\
         | `n` | {} | Frew et al., fixed |\n\
         | `m` | {} | Frew et al., fixed |\n\
         | `youngs_modulus_pa` | {:.4e} | fitted: **not copper's 117 GPa** but {:.0}× lower (see below) |\n",
        loss / PSI_PA,
        m.velocity_m_s[0],
        m.velocity_m_s[1],
        m.velocity_m_s[2],
        s.diameter_m,
        s.thickness_m,
        s.sigma0_pa,
        s.n,
        s.m,
        s.youngs_modulus_pa,
        117e9 / s.youngs_modulus_pa,
    );
    // Share of the striker's energy the shaper keeps (dissipates) by the end of the run, %.
    let kept: Vec<f64> = (0..3)
        .map(|i| {
            100.0 * sims[i].shaper_work_j / (0.5 * a.striker_mass_kg() * m.velocity_m_s[i].powi(2))
        })
        .collect();
    let (kept_lo, kept_hi) = (
        kept.iter().cloned().fold(f64::INFINITY, f64::min),
        kept.iter().cloned().fold(0.0, f64::max),
    );
    let _ = writeln!(
        w,
        "**What the fitted shaper is.** With E = {:.2} GPa the elastic line meets Frew's flow curve only at ε = {:.2}; \
         the largest strain on loading is ε ≈ {:.2} at 10 psi and {:.2} at 15 psi (from the peak force, {:.1} / {:.1} kN). \
         So the disc is {} — a soft, stiffening cushion F = E A0 ε/(1 − ε) rather than a plastically flattened copper \
         disc: it keeps only {kept_lo:.0}–{kept_hi:.0} % of the striker's energy (shaper work below) and the striker bounces back. Read E as the compliance of \
         the disc's faces and of the contacts (rough, not quite parallel faces; indentation of the striker and bar \
         ends) in series with the disc, which the model can only put into the disc's one modulus, for loading and \
         unloading alike. A copper modulus cannot reproduce the records (comparison fits below).\n",
        s.youngs_modulus_pa / 1e9,
        eps_y,
        eps_max10,
        eps_max15,
        peak_force(0) / 1e3,
        peak_force(2) / 1e3,
        if eps_max15 <= eps_y {
            "elastic throughout".to_string()
        } else if eps_max10 <= eps_y {
            format!(
                "elastic at 10 psi and only just plastic at 15 psi (ε − ε_y = {:.2})",
                eps_max15 - eps_y
            )
        } else {
            format!(
                "plastic beyond ε = {:.2} at every pressure, but mostly elastic",
                eps_y
            )
        }
    );
    let _ = writeln!(
        w,
        "As TOML (bars/authors.toml; every table below uses these values):\n\n```toml\n{toml}\n```\n"
    );
    let regenerated = regenerate(&a);
    if let Some((fm, fk, floss)) = argmin_fit {
        optimiser_section(w, &a, &records, (&fm, fk, floss), (k, loss), &regenerated);
    }
    regeneration_section(w, &regenerated);
    if !rows.is_empty() {
        let _ = writeln!(
            w,
            "## How it was fitted\n\nargmin's Nelder–Mead simplex (`shpb_study::calibrate::optimise::nelder_mead`, the one `shpb calibrate` uses; restarted from the best point with a \
             smaller simplex until it stops improving) on the logarithms of the free parameters, bounded by a penalty \
             (diameter 1–19 mm, thickness 0.2–8 mm, σ0 0.05–3 GPa, E 0.5–130 GPa, n 0.1–0.8, m 1.5–10, \
             0 ≤ p_loss < the gun's smallest pressure, velocities 0.5–100 m/s). The three pressures are simulated in \
             parallel (rayon).\n\n\
             **Objective**: Σ over the 8 records of (relative error / tolerance)² of peak (15 %), rise (20 %), \
             duration (20 %) — the issue's metrics — **and of the pulse energy (20 %)**. The energy term is ours: the \
             three metrics alone leave the pulse's body free, and their best fit (row *issue's metrics only*) has \
             pulses up to {:.0} % off the records' energy{}; with it, the gun calibration is tied to the energy the \
             striker must deliver, and the shape improves (shape RMS below), at some cost in the margin on the \
             issue's metrics.\n\n\
             σ0 = 0.75 GPa, n = 0.37, m = 4.25 (Frew et al.) unless said. Stage 1 starts from a 4.5 mm × 0.55 mm disc \
             with E = 5 GPa at 6 / 7 / 8 m/s and frees one striker velocity per pressure; stage 2 starts from stage 1 \
             and ties the velocities to the gun law, with the velocities at 10 and 15 psi as parameters (k and p_loss \
             follow; 12.5 psi lies on the line): the shipped values were this fit with the hand-written optimiser it replaced (*The optimiser*, above). The other rows are comparisons in stage-2 form.\n\n\
             | fit | free | energy in objective | objective | max \\|err\\|/tol (issue) | max \\|energy err\\| | v 10 / 12.5 / 15 psi (m/s) | diameter (mm) | thickness (mm) | σ0 (GPa) | E (GPa) | n, m | evaluations |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|",
            100.0
                * rows
                    .iter()
                    .find(|r| !r.energy)
                    .map(|r| r.score.worst_energy)
                    .unwrap_or(f64::NAN),
            {
                // Pressures where that fit's striker has less energy than the records' pulses carry.
                let short: Vec<String> = rows
                    .iter()
                    .find(|r| !r.energy)
                    .map(|r| {
                        PRESSURES_PSI
                            .iter()
                            .enumerate()
                            .filter(|&(i, &psi)| {
                                let ke =
                                    0.5 * a.striker_mass_kg() * r.model.velocity_m_s[i].powi(2);
                                let group: Vec<f64> = records
                                    .iter()
                                    .filter(|x| x.psi == psi)
                                    .map(|x| x.energy_j)
                                    .collect();
                                ke < group.iter().sum::<f64>() / group.len() as f64
                            })
                            .map(|(_, psi)| format!("{psi}"))
                            .collect()
                    })
                    .unwrap_or_default();
                if short.is_empty() {
                    String::new()
                } else {
                    format!(
                        " and, at {} psi, a striker with less kinetic energy than the records' pulses carry \
                         (impossible for the real gun)",
                        short.join(" and ")
                    )
                }
            }
        );
        for r in &rows {
            let s = &r.model.shaper;
            let _ = writeln!(
                w,
                "| {} | {} | {} | {:.3} | {:.2} | {:.0} % | {:.2} / {:.2} / {:.2} | {:.3} | {:.3} | {:.3} | {:.2} | {:.3}, {:.3} | {} |",
                r.label,
                r.free,
                if r.energy { "yes" } else { "no" },
                r.score.objective(r.energy),
                r.score.worst,
                100.0 * r.score.worst_energy,
                r.model.velocity_m_s[0],
                r.model.velocity_m_s[1],
                r.model.velocity_m_s[2],
                s.diameter_m * 1e3,
                s.thickness_m * 1e3,
                s.sigma0_pa / 1e9,
                s.youngs_modulus_pa / 1e9,
                s.n,
                s.m,
                r.evals
            );
        }
        let total: usize = rows.iter().map(|r| r.evals).sum();
        let _ = writeln!(w, "\n{total} evaluations in all.\n");
        let find = |label: &str| rows.iter().find(|r| r.label.starts_with(label));
        if let (Some(c), Some(nm)) = (find("copper"), find("n, m")) {
            let _ = writeln!(
                w,
                "Reading the comparisons: with copper's modulus no disc passes (largest |error|/tolerance {:.2}; \
                 the thickness runs to {:.1} mm and σ0, n, m wander from Frew's values). Freeing n and m as well as E lowers the \
                 objective ({:.2} against {:.2}) only by driving them to n = {:.2}, m = {:.2}, at or near their \
                 bounds and far from annealed copper (Frew: 0.37, 4.25), so they stay at Frew's values. The objective is flat along a valley: \
                 with the hand-written optimiser, started from E = 10 GPa instead, the same fit ended at E = 1.17 GPa, diameter 4.73 mm, thickness \
                 0.474 mm, 5.59 / 6.67 / 7.60 m/s, with a slightly lower objective (3.17) but less margin (largest \
                 |error|/tolerance 0.92); the shaper's parameters are an effective description, not a measurement \
                 of the disc.\n",
                c.score.worst,
                c.model.shaper.thickness_m * 1e3,
                nm.score.objective(true),
                rows[1].score.objective(true),
                nm.model.shaper.n,
                nm.model.shaper.m
            );
        }
    }
    if let Some(s1) = stage1 {
        let v = s1.velocity_m_s;
        let (kl, ll, res) = least_squares_gun(&v);
        let _ = writeln!(
            w,
            "**Gun law.** Stage 1's free velocities {:.3} / {:.3} / {:.3} m/s at 10 / 12.5 / 15 psi; least-squares \
             line v² = k (p − p_loss) through them: k = {kl:.4e} m²/s²/Pa, p_loss = {:.1} kPa ({:.2} psi); residuals \
             of v {:+.3} / {:+.3} / {:+.3} m/s ({:+.2} / {:+.2} / {:+.2} %). The three pressures lie on one line to \
             that accuracy, far inside what the metrics resolve (1 % in v moves the peak by ≈ 1 %), and tying them to \
             it costs little (stage 2 vs stage 1). p_loss rests on three pressures spanning 10–15 psi and is the least \
             determined parameter.\n",
            v[0],
            v[1],
            v[2],
            ll / 1e3,
            ll / PSI_PA,
            res[0],
            res[1],
            res[2],
            100.0 * res[0] / v[0],
            100.0 * res[1] / v[1],
            100.0 * res[2] / v[2],
        );
    }

    // ---- Per sample ----
    let _ = writeln!(
        w,
        "## Per sample\n\nErrors are (simulated − measured)/measured; pass = within 15 % (peak), 20 % (rise, \
         duration). Overlays: validation/pulse/sample<N>.png (stress against time from each trace's 10 % rise; \
         record dashed).\n\n\
         | sample | material | psi | v (m/s) | peak meas. / sim. (MPa) | error | rise meas. / sim. (µs) | error | duration meas. / sim. (µs) | error | all pass | energy meas. / sim. (J) | error |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let mut shape_rows = String::new();
    for r in &records {
        let i = pressure_index(r.psi);
        let s = &sims[i];
        let sm = s.metrics.expect("simulated pulse");
        let err = errors(&r.metrics, &sm);
        let flag = |j: usize| {
            if err[j].abs() <= TOL[j] {
                format!("{:+.1} %", 100.0 * err[j])
            } else {
                format!("**{:+.1} % FAIL**", 100.0 * err[j])
            }
        };
        let pass = (0..3).all(|j| err[j].abs() <= TOL[j]);
        let _ = writeln!(
            w,
            "| {} | {} | {} | {:.2} | {} / {} | {} | {} / {} | {} | {} / {} | {} | {} | {:.2} / {:.2} | {:+.1} % |",
            r.sample,
            r.material,
            r.psi,
            m.velocity_m_s[i],
            mpa(r.metrics.peak),
            mpa(sm.peak),
            flag(0),
            us(r.metrics.rise_10_90_s),
            us(sm.rise_10_90_s),
            flag(1),
            us(r.metrics.duration_10_s),
            us(sm.duration_10_s),
            flag(2),
            if pass { "yes" } else { "**no**" },
            r.energy_j,
            s.energy_j,
            100.0 * (s.energy_j / r.energy_j - 1.0)
        );
        let (pm, fm) = plateau_and_fall(&r.time_s, &r.stress_pa);
        let (ps, fs) = plateau_and_fall(&s.time_s, &s.stress_pa);
        let _ = writeln!(
            shape_rows,
            "| {} | {} | {} / {} | {} / {} | {:.1} % |",
            r.sample,
            r.psi,
            us(pm),
            us(ps),
            us(fm),
            us(fs),
            100.0 * shape_rms(r, s)
        );
        let (tm, ym) = aligned(&r.time_s, &r.stress_pa, r.metrics.start_10_s);
        let (ts, ys) = aligned(&s.time_s, &s.stress_pa, sm.start_10_s);
        let title = format!(
            "Sample {} ({}), {} psi: incident gauge, aligned at the 10 % rise",
            r.sample, r.material, r.psi
        );
        xy_plot(
            &out_dir.join(format!("sample{}.png", r.sample)),
            true,
            &Axes {
                title: &title,
                x_label: "time from the 10 % rise (µs)",
                y_label: "bar stress, compression positive (MPa)",
                x_scale: 1e6,
                y_scale: 1e-6,
            },
            &[
                Curve {
                    label: format!("record, sample {}", r.sample),
                    x: &tm,
                    y: &ym,
                    measured: true,
                },
                Curve {
                    label: format!("simulated, v = {:.2} m/s", m.velocity_m_s[i]),
                    x: &ts,
                    y: &ys,
                    measured: false,
                },
            ],
        )
        .expect("plot");
    }
    let _ = writeln!(
        w,
        "\nShape beyond the three metrics (on an 11-sample moving average of both traces): time spent above 90 % of \
         the peak, fall from 90 % to 10 % after the peak, and the RMS difference of the traces aligned at the 10 % \
         rise over the measured pulse, relative to the measured peak.\n\n\
         | sample | psi | above 90 % meas. / sim. (µs) | fall 90→10 % meas. / sim. (µs) | shape RMS |\n|---|---|---|---|---|\n{shape_rows}"
    );

    // ---- Scatter ----
    let _ = writeln!(
        w,
        "## Scatter between records at the same pressure\n\nMean and half-range (relative to the mean) of the measured \
         metrics at each pressure, against the simulation. The scatter is the floor any one-parameter-set calibration \
         faces: a simulation at the mean still errs by the half-range on the extreme records.\n\n\
         | psi | samples | metric | measured | mean | ± half-range | simulated | sim. vs mean |\n|---|---|---|---|---|---|---|---|"
    );
    for (i, &psi) in PRESSURES_PSI.iter().enumerate() {
        let group: Vec<&Record> = records.iter().filter(|r| r.psi == psi).collect();
        let sm = sims[i].metrics.expect("simulated pulse");
        let names: Vec<String> = group.iter().map(|r| r.sample.to_string()).collect();
        for j in 0..4 {
            let get_m = |p: &PulseMetrics| match j {
                0 => p.peak / 1e6,
                1 => p.rise_10_90_s * 1e6,
                _ => p.duration_10_s * 1e6,
            };
            let vals: Vec<f64> = group
                .iter()
                .map(|r| {
                    if j == 3 {
                        r.energy_j
                    } else {
                        get_m(&r.metrics)
                    }
                })
                .collect();
            let simv = if j == 3 { sims[i].energy_j } else { get_m(&sm) };
            let mean = vals.iter().sum::<f64>() / vals.len() as f64;
            let (lo, hi) = shpb_core::numeric::min_max(vals.iter().copied());
            let name = match j {
                0 => "peak (MPa)",
                1 => "rise 10–90 % (µs)",
                2 => "duration at 10 % (µs)",
                _ => "pulse energy (J)",
            };
            let prec = if j == 3 { 2 } else { 1 };
            let _ = writeln!(
                w,
                "| {psi} | {} | {name} | {} | {mean:.prec$} | {:.1} % | {simv:.prec$} | {:+.1} % |",
                names.join(", "),
                vals.iter()
                    .map(|v| format!("{v:.prec$}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                50.0 * (hi - lo) / mean,
                100.0 * (simv / mean - 1.0)
            );
        }
    }

    // ---- The rise, segment by segment ----
    rise_segments(w, &records, &sims, &m);

    // ---- Energy and momentum ----
    let _ = writeln!(
        w,
        "\n## Energy and momentum\n\nStriker kinetic energy; energy of the incident pulse A/(ρ c0) ∫σ² dt (simulated; \
         mean of the records at that pressure); work left in the shaper at the end; striker velocity after the pulse \
         (negative: it bounces back).\n\n\
         | psi | v (m/s) | striker energy (J) | pulse energy sim. / records (J) | shaper work (J) | v after (m/s) |\n|---|---|---|---|---|---|"
    );
    for (i, &psi) in PRESSURES_PSI.iter().enumerate() {
        let s = &sims[i];
        let group: Vec<&Record> = records.iter().filter(|r| r.psi == psi).collect();
        let meas = group.iter().map(|r| r.energy_j).sum::<f64>() / group.len() as f64;
        let ke = 0.5 * a.striker_mass_kg() * m.velocity_m_s[i].powi(2);
        let _ = writeln!(
            w,
            "| {psi} | {:.2} | {ke:.2} | {:.2} / {meas:.2} | {:.2} | {:+.2} |",
            m.velocity_m_s[i], s.energy_j, s.shaper_work_j, s.striker_final_velocity_m_s
        );
    }

    // ---- Numerical sensitivity ----
    let _ = writeln!(
        w,
        "\n## Numerical sensitivity\n\nLargest change of any record's relative error (peak, rise, duration) when the \
         calibrated model is run on a finer grid or read with a point gauge, in percentage points:\n\n\
         | run | peak | rise | duration |\n|---|---|---|---|"
    );
    for (label, cell, gauge) in [
        ("0.5 mm cells, 2 mm gauge", 0.5e-3, GAUGE_LENGTH_M),
        ("1 mm cells, point gauge", CELL_M, 0.0),
    ] {
        let alt = run_model_with(&a, &m, cell, gauge);
        let mut d = [0.0f64; 3];
        for r in &records {
            let i = pressure_index(r.psi);
            let (Some(x), Some(y)) = (&sims[i].metrics, &alt[i].metrics) else {
                continue;
            };
            let (e0, e1) = (errors(&r.metrics, x), errors(&r.metrics, y));
            for j in 0..3 {
                d[j] = d[j].max((e1[j] - e0[j]).abs());
            }
        }
        let _ = writeln!(
            w,
            "| {label} | {:.2} | {:.2} | {:.2} |",
            100.0 * d[0],
            100.0 * d[1],
            100.0 * d[2]
        );
    }

    // ---- Scale invariance ----
    let _ = writeln!(
        w,
        "\n## Scale invariance (the bridge question)\n\nThe shaper is a massless spring between linear bars, so scaling \
         the striker velocity by s, the shaper area by s (diameter by √s) and its thickness by s, with σ0, n, m and E \
         unchanged, scales every force, displacement and velocity by s and leaves the disc's strain history, hence the \
         pulse shape, unchanged: the stress scales by exactly s (tests/pulse_calibration.rs checks it). Should the \
         records be read at s times the reading used here, the calibration is k × s², the same p_loss, diameter × √s, \
         thickness × s:\n\n\
         | reading | s | k (m²/s²/Pa) | v at 10 / 15 psi (m/s) | diameter (mm) | thickness (mm) |\n|---|---|---|---|---|---|"
    );
    for (name, s) in [
        (
            "half the authors' formula (the gauge file's, used here)",
            1.0,
        ),
        (
            "the authors' formula literally (`amplifier_gain = 1.0`)",
            2.0,
        ),
        (
            "a half bridge, as the authors describe it (`half-poisson`, gain 1)",
            4.0,
        ),
    ] {
        let _ = writeln!(
            w,
            "| {name} | {s:.3} | {:.4e} | {:.2} / {:.2} | {:.3} | {:.3} |",
            k * s * s,
            m.velocity_m_s[0] * s,
            m.velocity_m_s[2] * s,
            m.shaper.diameter_m * 1e3 * s.sqrt(),
            m.shaper.thickness_m * 1e3 * s
        );
    }
    let _ = writeln!(w, "\n{}", NOTES.trim());
    // Keep the section `shaper_loo` owns (leave one pressure out), if the report has one.
    let old = std::fs::read_to_string(out_dir.join("REPORT.md")).unwrap_or_default();
    let (begin, end) = (
        "<!-- leave-one-out: begin (generated by shaper_loo) -->",
        "<!-- leave-one-out: end -->",
    );
    let rep = match (old.find(begin), old.find(end)) {
        (Some(b), Some(e)) => format!("{}\n\n{}\n", rep.trim_end(), &old[b..e + end.len()]),
        _ => rep,
    };
    std::fs::write(out_dir.join("REPORT.md"), rep).expect("REPORT.md");
    eprintln!(
        "max |err|/tol {:.3}, max energy error {:.3}; wrote {}",
        sc.worst,
        sc.worst_energy,
        out_dir.join("REPORT.md").display()
    );
}

/// Levels of the rise whose crossings split it into segments, fractions of the peak.
const RISE_LEVELS: [f64; 5] = [0.1, 0.3, 0.5, 0.7, 0.9];

/// Durations of the rise between the crossings of [`RISE_LEVELS`] (10→30, 30→50, 50→70 and
/// 70→90 % of the peak) of a compression-positive trace on an 11-sample moving average, s.
fn rise_segment_durations_s(t: &[f64], y: &[f64]) -> Option<[f64; 4]> {
    let ys = moving_average(y, 5);
    let e = pulse_edges(t, &ys, 1.0)?;
    let c: Vec<f64> = RISE_LEVELS
        .iter()
        .map(|&l| e.rising_s(t, &ys, 1.0, l))
        .collect::<Option<_>>()?;
    Some(std::array::from_fn(|j| c[j + 1] - c[j]))
}

/// The section "The rise, segment by segment": where each pressure's rise time goes, records
/// against the shipped calibration, and how each segment scales with the striker's speed.
fn rise_segments(w: &mut String, records: &[Record], sims: &[Simulated], m: &Model) {
    let names = ["10→30 %", "30→50 %", "50→70 %", "70→90 %"];
    let _ = writeln!(
        w,
        "\n## The rise, segment by segment\n\nThe 10–90 % rise split at 30, 50 and 70 % of the peak (both traces on \
         an 11-sample moving average, as above): how long each segment takes, per pressure, in the records (each, and \
         their mean) and in the shipped calibration.\n\n\
         | psi | v (m/s) | segment | records (µs) | records' mean (µs) | simulated (µs) | sim. vs mean |\n|---|---|---|---|---|---|---|"
    );
    // Each record's segments, once: (record, durations, s).
    let measured: Vec<(&Record, [f64; 4])> = records
        .iter()
        .filter_map(|r| Some((r, rise_segment_durations_s(&r.time_s, &r.stress_pa)?)))
        .collect();
    // Per pressure: the records' mean and the simulated duration of each segment, s.
    let mut means = [[f64::NAN; 4]; 3];
    let mut simulated = [[f64::NAN; 4]; 3];
    for (i, &psi) in PRESSURES_PSI.iter().enumerate() {
        let group: Vec<[f64; 4]> = measured
            .iter()
            .filter(|(r, _)| r.psi == psi)
            .map(|&(_, g)| g)
            .collect();
        let Some(sim) = rise_segment_durations_s(&sims[i].time_s, &sims[i].stress_pa) else {
            continue;
        };
        simulated[i] = sim;
        for (j, name) in names.iter().enumerate() {
            let vals: Vec<f64> = group.iter().map(|g| g[j]).collect();
            let mean = vals.iter().sum::<f64>() / vals.len() as f64;
            means[i][j] = mean;
            let _ = writeln!(
                w,
                "| {psi} | {:.2} | {name} | {} | {:.1} | {:.1} | {:+.0} % |",
                m.velocity_m_s[i],
                vals.iter()
                    .map(|v| format!("{:.1}", v * 1e6))
                    .collect::<Vec<_>>()
                    .join(", "),
                mean * 1e6,
                sim[j] * 1e6,
                100.0 * (sim[j] / mean - 1.0)
            );
        }
    }
    // Each segment ∝ v^(−a) between 10 and 15 psi: a = ln(d10/d15)/ln(v15/v10).
    let speed = (m.velocity_m_s[2] / m.velocity_m_s[0]).ln();
    let exponent = |d: &[[f64; 4]; 3], j: usize| (d[0][j] / d[2][j]).ln() / speed;
    let _ = writeln!(
        w,
        "\nHow each segment scales with the striker's speed from 10 to 15 psi (v {:.2} → {:.2} m/s on the shipped gun \
         line): the exponent a of duration ∝ v^(−a), from the records' means and from the simulation.\n\n\
         | segment | records 10 / 15 psi (µs) | a, records | simulated 10 / 15 psi (µs) | a, simulated |\n|---|---|---|---|---|",
        m.velocity_m_s[0], m.velocity_m_s[2]
    );
    for (j, name) in names.iter().enumerate() {
        let _ = writeln!(
            w,
            "| {name} | {:.1} / {:.1} | {:.2} | {:.1} / {:.1} | {:.2} |",
            means[0][j] * 1e6,
            means[2][j] * 1e6,
            exponent(&means, j),
            simulated[0][j] * 1e6,
            simulated[2][j] * 1e6,
            exponent(&simulated, j)
        );
    }
    let upper = |d: &[[f64; 4]; 3], i: usize| d[i][2] + d[i][3];
    let upper_exponent = |d: &[[f64; 4]; 3]| (upper(d, 0) / upper(d, 2)).ln() / speed;
    let lower = |d: &[[f64; 4]; 3], i: usize| d[i][0] + d[i][1];
    let lower_exponent = |d: &[[f64; 4]; 3]| (lower(d, 0) / lower(d, 2)).ln() / speed;
    // The 10→30 % segment of each record against the mean of the other records at its pressure.
    let mut long_toes = Vec::new();
    for (r, g) in &measured {
        let others: Vec<f64> = measured
            .iter()
            .filter(|(o, _)| o.psi == r.psi && o.sample != r.sample)
            .map(|(_, o)| o[0])
            .collect();
        let others_mean = others.iter().sum::<f64>() / others.len() as f64;
        if g[0] > 1.4 * others_mean {
            long_toes.push(format!(
                "{} ({} psi, +{:.1} µs)",
                r.sample,
                r.psi,
                (g[0] - others_mean) * 1e6
            ));
        }
    }
    let _ = writeln!(
        w,
        "\nReading (an inference from eight records): from 10 to 50 % the records' rise shortens with the striker's \
         speed (a = {:.2}) and the calibration's does not (a = {:.2}): its first half is carried by the elastic \
         cushion the fit needs (*What the model misses*), whose time scale does not depend on the speed. From 50 to \
         90 % both shorten alike (a = {:.2} and {:.2}). So the calibration's rise, right on average over the three \
         pressures, comes out too short at the lowest one and too long at the highest, and a fit on two pressures \
         extrapolates it badly (*Leave one pressure out*, below). Records whose 10→30 % segment is more than 1.4 \
         times the mean of the others at their pressure: {} — a toe of their own that one shaper model for all \
         records cannot follow.",
        lower_exponent(&means),
        lower_exponent(&simulated),
        upper_exponent(&means),
        upper_exponent(&simulated),
        if long_toes.is_empty() {
            "none".to_string()
        } else {
            format!("samples {}", long_toes.join(", "))
        }
    );
}

/// What the model misses: written from the overlays of the shipped calibration (the numbers are
/// in the tables above; re-read them if the calibration changes).
const NOTES: &str = "
## What the model misses

Written from the overlays (validation/pulse/sample<N>.png) of the shipped calibration.

* **The flat top.** At 12.5 and 15 psi the records hold ≥ 90 % of their peak for 35–47 µs, often after a
  shoulder near 90 % on the rise; the model's top is rounded (≈ 30 µs above 90 %) and overshoots the 15 psi
  plateau by 6–8 %. A disc flowing plastically with little hardening would give such a plateau; the soft,
  mostly elastic cushion the fit needs does not.
* **The toe.** Most records step to ≈ 10–20 MPa within a few µs and then pause or rise more slowly
  (clearest in samples 1, 6 and 8); the model rises steadily from the start. Where the pause is long the
  simulated rise is short: sample 6 −15 %, sample 8 −7 %, and at 10 psi ≈ 11 % below the two records' mean.
  The records' own rise times scatter by ± 5–9 % at one pressure.
* **The slow tail.** Every record keeps a low tail, ≈ 3–10 MPa, for 40–60 µs after its main fall; the
  simulated pulse ends abruptly when the striker leaves the shaper. The duration at 10 % of peak is matched
  by a longer, smoother body instead; at 15 psi the records' main fall (46–59 µs from 90 % to 10 %) is
  faster than the model's (≈ 64 µs).
* **The energy budget.** The fitted cushion gives most of its energy back: the shaper keeps ≈ 10 % of the
  striker's energy and the striker bounces back at ≈ 40 % of its impact speed. A real annealed copper disc
  flattened to ε ≈ 0.6 would dissipate far more and stop the striker, so the real gun would have to give
  more energy than k says. The gun calibration rests on the pulse energy the records carry plus a rebound
  nobody measured; the striker's speed (light gates) or the shaper's final thickness would pin k and decide
  between this cushion and a dissipative disc.
* **Why not copper.** With E = 117 GPa the disc unloads at once, the pulse ends soon after the striker stops,
  and the rise time grows with pressure where the records' falls (58.6 → 47.8 → 42.1 µs): fit *copper* above
  fails (largest |error|/tolerance > 1) even with σ0, n, m and the thickness free. Reproducing the records
  with a real copper disc needs a compliance in series with it (faces, contacts) that the shaper model does
  not have: the fitted E stands for it.
";

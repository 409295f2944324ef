//! Leave-one-pressure-out test of the pulse-shaper models on the 2013-05-22 incident records:
//! fits each model (gun line through the two training pressures, the shaper's free constants) on
//! two of 10 / 12.5 / 15 psi, predicts the third, and writes the section "Leave one pressure out"
//! of `validation/pulse/REPORT.md` (the rest of that file is `calibrate_pulse`'s): the held-out
//! incident peak, rise, duration and energy errors; the held-out transmitted peak (the full
//! virtual test of each held-out record's specimen, `validation/fig4-virtual-shpb/`, run with the
//! fitted shaper and gun line, read like the `gauge-records` case: `shpb_validate::gauge_records`);
//! and the records' own scatter per pressure against each prediction.
//!
//! Run from the repository root: `cargo run --release -p shpb-validate --bin shaper_loo`.
//! The fits are cached: a fitting run writes every fitted constant at full precision to
//! `validation/pulse/shaper_loo_fits.toml`, and a run without `--refit` reads them from there and
//! only evaluates (it fits when the cache is missing or lacks a model). `-- --refit` fits again
//! and rewrites the cache; `-- --frew` / `-- --disc` / `-- --exponential` / `-- --cushion`
//! restrict the run to one model (a refit of one model keeps the others' cached fits).
//! `-- --probe d_mm h_mm factor mu v10 v12 v15` runs one crushed disc and prints its errors.
//! Times on two cores: the report's last line.

#![warn(missing_docs)]

#[path = "common/mod.rs"]
mod common;

use rayon::prelude::*;
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{PulseMetrics, RawRecord, pulse_metrics};
use shpb_core::numeric::min_max;
use shpb_core::shaper::{CrushedDisc, ExponentialSpring, PulseShaper, ShaperModel};
use shpb_input::prelude::*;
use shpb_input::units::PSI_PA;
use shpb_study::calibrate::pulse_energy_j;
use shpb_validate::gauge_records::{
    GaugeStresses, INCIDENT_WINDOW_S, SAMPLES, SAMPLES_2013_06_06, Sample, incident_pulse,
    virtual_test,
};
use std::fmt::Write as _;

/// The three gun pressures, psi.
const PRESSURES_PSI: [f64; 3] = [10.0, 12.5, 15.0];
/// Targets of issue 18: incident peak 5 %, rise 10 %, duration 10 %, energy 5 %.
const TOL: [f64; 4] = [0.05, 0.10, 0.10, 0.05];
/// Nelder–Mead evaluations per round of a fit (up to four rounds).
const EVALS_PER_ROUND: usize = 150;
/// Cell size of the runs (the `pulse` scene's default), m.
const CELL_M: f64 = 1e-3;
/// Gauge grid of the runs (the `pulse` scene's default), m.
const GAUGE_LENGTH_M: f64 = 2e-3;

/// One record's incident pulse metrics.
struct Record {
    sample: usize,
    psi: f64,
    metrics: PulseMetrics,
    energy_j: f64,
}

fn read_records(a: &Apparatus) -> Vec<Record> {
    let root = common::repo_root();
    SAMPLES
        .iter()
        .map(|s| {
            let (t, y) = incident_pulse(a, &s.record_path(&root)).expect("record");
            Record {
                sample: s.number,
                psi: s.psi,
                metrics: pulse_metrics(&t, &y, false).expect("incident pulse"),
                energy_j: pulse_energy_j(a, &t, &y),
            }
        })
        .collect()
}

/// Metrics and energy of a simulated incident pulse (None: no pulse).
fn simulate(a: &Apparatus, v: f64, shaper: PulseShaper) -> Option<(PulseMetrics, f64)> {
    let c0 = a.material.wave_speed_m_s();
    let ch = a.gauges.channel("incident")?;
    // An exponential shaper's pulse starts later than a disc's: its runs are longer by as much.
    let slack = a.shaper_onset_delay_s(&shaper, v);
    let end = (a.incident.length_m - ch.distance_from_specimen_m) / c0
        + INCIDENT_WINDOW_S.1
        + 20e-6
        + slack;
    let s = a
        .incident_signal(v, Some(shaper), CELL_M, GAUGE_LENGTH_M, end)
        .ok()?;
    let m = pulse_metrics(&s.time_s, &s.stress_pa, false)?;
    Some((m, pulse_energy_j(a, &s.time_s, &s.stress_pa)))
}

/// Relative errors (sim − measured)/measured of peak, rise, duration, energy.
fn errors(r: &Record, s: &(PulseMetrics, f64)) -> [f64; 4] {
    [
        s.0.peak / r.metrics.peak - 1.0,
        s.0.rise_10_90_s / r.metrics.rise_10_90_s - 1.0,
        s.0.duration_10_s / r.metrics.duration_10_s - 1.0,
        s.1 / r.energy_j - 1.0,
    ]
}

/// A model family: how its free parameters map to a shaper.
#[derive(Clone, Copy, PartialEq)]
enum Family {
    /// Frew et al. with effective modulus: diameter, thickness, E free.
    Frew,
    /// Crushed Johnson–Cook disc: diameter, thickness and the face-compliance factor free.
    CrushedDisc,
    /// Crushed Johnson–Cook disc with ideal faces: diameter, thickness and friction μ free.
    CrushedDiscFriction,
    /// The elastic exponential law F0 (exp(c/λ) − 1): λ free, F0 = [`ONSET_FORCE_N`].
    Exponential,
    /// Crushed Johnson–Cook disc with ideal faces, seated through an exponential cushion in
    /// series: diameter, thickness and λ free, F0 = [`ONSET_FORCE_N`].
    CushionedDisc,
}

/// Onset force F0 of the exponential family, N: the law is scale-free (its time scales ∝ 1/v)
/// only while F0 ≪ the pulse's forces, so F0 is set small and stated, not fitted (fitted, it runs
/// to its upper bound and the 10 psi rise is lost: validation/pulse/REPORT.md).
const ONSET_FORCE_N: f64 = 10.0;

impl Family {
    fn name(self) -> &'static str {
        match self {
            Family::Frew => "frew",
            Family::CrushedDisc => "crushed-disc (face compliance free)",
            Family::CrushedDiscFriction => "crushed-disc (friction free)",
            Family::Exponential => "exponential (λ free)",
            Family::CushionedDisc => "crushed-disc + exponential cushion",
        }
    }
    /// The model's key in the fit cache.
    fn key(self) -> &'static str {
        match self {
            Family::Frew => "frew",
            Family::CrushedDisc => "crushed-disc-face-compliance",
            Family::CrushedDiscFriction => "crushed-disc-friction",
            Family::Exponential => "exponential",
            Family::CushionedDisc => "crushed-disc-cushion",
        }
    }
    /// Names of the free shaper parameters and their display scale and unit.
    fn params(self) -> Vec<(&'static str, f64, &'static str)> {
        let third = match self {
            Family::Frew => ("youngs_modulus_pa", 1e-9, "GPa"),
            Family::CrushedDisc => ("face_compliance_factor", 1.0, ""),
            Family::CrushedDiscFriction => ("friction", 1.0, ""),
            Family::Exponential => return vec![("stiffening_length_m", 1e6, "µm")],
            Family::CushionedDisc => ("stiffening_length_m", 1e6, "µm"),
        };
        vec![("diameter_m", 1e3, "mm"), ("thickness_m", 1e3, "mm"), third]
    }
    /// Starting striker velocities at 10 / 12.5 / 15 psi, m/s.
    fn start_v(self) -> [f64; 3] {
        match self {
            Family::Frew | Family::Exponential => [5.81, 6.79, 7.65],
            _ => [7.5, 8.8, 9.9],
        }
    }
    /// Starting point (log space follows) of the free shaper parameters.
    fn start(self) -> Vec<f64> {
        match self {
            Family::Frew => vec![3.98e-3, 0.429e-3, 1.43e9],
            Family::CrushedDisc => vec![3.0e-3, 0.6e-3, 5.0],
            Family::CrushedDiscFriction => vec![3.0e-3, 0.6e-3, 0.1],
            Family::Exponential => vec![100e-6],
            Family::CushionedDisc => vec![3.0e-3, 0.6e-3, 60e-6],
        }
    }
    /// Starting points of the fit: the cushioned disc's objective has several minima (two starts
    /// land in different ones on some folds), so it is fitted from a second start as well and the
    /// lower minimum kept.
    fn starts(self) -> Vec<Vec<f64>> {
        match self {
            Family::CushionedDisc => vec![self.start(), vec![6.0e-3, 0.3e-3, 90e-6]],
            _ => vec![self.start()],
        }
    }
    fn bounds(self) -> Vec<(f64, f64)> {
        match self {
            Family::Frew => vec![(1e-3, 19e-3), (0.1e-3, 8e-3), (0.3e9, 130e9)],
            Family::CrushedDisc => vec![(1e-3, 19e-3), (0.1e-3, 8e-3), (0.01, 1e3)],
            Family::CrushedDiscFriction => vec![(1e-3, 19e-3), (0.1e-3, 8e-3), (1e-3, 1.0)],
            Family::Exponential => vec![(10e-6, 1e-3)],
            Family::CushionedDisc => vec![(1e-3, 19e-3), (0.1e-3, 8e-3), (1e-6, 1e-3)],
        }
    }
    fn shaper(self, a: &Apparatus, p: &[f64]) -> PulseShaper {
        match self {
            Family::Frew => PulseShaper {
                diameter_m: p[0],
                thickness_m: p[1],
                sigma0_pa: 0.75e9,
                n: 0.37,
                m: 4.25,
                youngs_modulus_pa: p[2],
                model: ShaperModel::Frew,
                calibrated_pressure_pa: None,
            },
            Family::CrushedDisc | Family::CrushedDiscFriction | Family::CushionedDisc => {
                let mut d = CrushedDisc::ofhc_copper(
                    a.material.youngs_modulus_pa,
                    a.material.poisson_ratio,
                );
                match self {
                    Family::CrushedDisc => d.face_compliance_factor = p[2],
                    Family::CrushedDiscFriction => d.friction = p[2],
                    _ => {
                        d.cushion = Some(ExponentialSpring {
                            stiffening_length_m: p[2],
                            onset_force_n: ONSET_FORCE_N,
                        })
                    }
                }
                PulseShaper::crushed_disc(p[0], p[1], COPPER_MODULUS_PA, d)
            }
            Family::Exponential => PulseShaper::exponential(ExponentialSpring {
                stiffening_length_m: p[0],
                onset_force_n: ONSET_FORCE_N,
            }),
        }
    }
}

/// Young's modulus of copper, Pa (annealed C11000/OFHC, ≈ 117 GPa).
const COPPER_MODULUS_PA: f64 = 117e9;

/// Velocities at the three pressures from a line v² = k (p − p_loss) through (p_i, v_i), (p_j, v_j).
fn line_velocities(pi: f64, vi: f64, pj: f64, vj: f64) -> Option<[f64; 3]> {
    let k = (vj * vj - vi * vi) / ((pj - pi) * PSI_PA);
    if k <= 0.0 {
        return None;
    }
    let loss = pi * PSI_PA - vi * vi / k;
    let v = PRESSURES_PSI.map(|p| (k * (p * PSI_PA - loss)).max(0.0).sqrt());
    (v.iter().all(|&x| x > 0.5) && (0.0..6.5 * PSI_PA).contains(&loss)).then_some(v)
}

/// A fit's result: velocities at the three pressures, the shaper parameters, its objective.
#[derive(Clone)]
struct Fit {
    velocity_m_s: [f64; 3],
    params: Vec<f64>,
    objective: f64,
}

/// Σ (error/target)² over `records` of the pressures `train` for a model.
fn objective(
    a: &Apparatus,
    fam: Family,
    records: &[Record],
    train: &[usize],
    v: &[f64; 3],
    p: &[f64],
) -> f64 {
    let sh = fam.shaper(a, p);
    let sims: Vec<Option<(PulseMetrics, f64)>> =
        train.par_iter().map(|&i| simulate(a, v[i], sh)).collect();
    let mut o = 0.0;
    for r in records {
        let Some(k) = train.iter().position(|&i| PRESSURES_PSI[i] == r.psi) else {
            continue;
        };
        let Some(s) = &sims[k] else { return 1e6 };
        for (j, e) in errors(r, s).iter().enumerate() {
            o += (e / TOL[j]).powi(2);
        }
    }
    o
}

/// Fits `fam` on the pressures `train` (two or three indices): gun line through the first and
/// last training pressures' velocities, and the shaper's free parameters, in log space.
fn fit(a: &Apparatus, fam: Family, records: &[Record], train: &[usize], start_v: [f64; 3]) -> Fit {
    let (i, j) = (train[0], train[train.len() - 1]);
    let bounds = fam.bounds();
    let unpack = |x: &[f64]| -> Option<([f64; 3], Vec<f64>)> {
        let v = line_velocities(PRESSURES_PSI[i], x[0].exp(), PRESSURES_PSI[j], x[1].exp())?;
        let p: Vec<f64> = x[2..].iter().map(|y| y.exp()).collect();
        p.iter()
            .zip(&bounds)
            .all(|(x, (lo, hi))| (lo..=hi).contains(&x))
            .then_some((v, p))
    };
    let mut f = |x: &[f64]| -> f64 {
        match unpack(x) {
            Some((v, p)) => objective(a, fam, records, train, &v, &p),
            None => 1e9,
        }
    };
    let (mut x_best, mut best) = (Vec::new(), f64::INFINITY);
    for start in fam.starts() {
        let mut x: Vec<f64> = vec![start_v[i].ln(), start_v[j].ln()];
        x.extend(start.iter().map(|y| y.ln()));
        let mut reached = f64::INFINITY;
        for round in 0..4 {
            let step = vec![if round == 0 { 0.2 } else { 0.05 }; x.len()];
            let (xb, fb, n) = shpb_study::calibrate::optimise::nelder_mead(
                &mut f,
                &x,
                &step,
                EVALS_PER_ROUND,
                1e-7,
            );
            eprintln!(
                "{} train {:?}: round {round}, objective {fb:.4}, {n} evaluations",
                fam.name(),
                train
            );
            x = xb;
            if reached - fb < 1e-3 * reached.max(1e-9) {
                reached = reached.min(fb);
                break;
            }
            reached = fb;
        }
        if reached < best {
            (x_best, best) = (x, reached);
        }
    }
    let x = x_best;
    let (v, p) = unpack(&x).expect("the best point is inside the bounds");
    Fit {
        velocity_m_s: v,
        params: p,
        objective: best,
    }
}

/// Markers of the section this binary owns in validation/pulse/REPORT.md.
const BEGIN: &str = "<!-- leave-one-out: begin (generated by shaper_loo) -->";
/// End marker of the section.
const END: &str = "<!-- leave-one-out: end -->";

/// The fitted constants of the last fitting run, below the repository root.
const CACHE: &str = "validation/pulse/shaper_loo_fits.toml";

/// Issue 18's target on the transmitted peak in the leave-one-pressure-out test.
const TRANSMITTED_TOL: f64 = 0.08;

/// A model's four fits: one per held-out pressure (index = the held-out pressure) and one on all
/// three pressures.
struct ModelFits {
    fam: Family,
    folds: Vec<Fit>,
    all: Fit,
}

const FAMILIES: [Family; 5] = [
    Family::Frew,
    Family::CrushedDisc,
    Family::CrushedDiscFriction,
    Family::Exponential,
    Family::CushionedDisc,
];

/// Fits `fam` on each pair of pressures and on all three.
fn fit_model(a: &Apparatus, fam: Family, records: &[Record]) -> ModelFits {
    let folds = (0..3)
        .map(|held| {
            let train: Vec<usize> = (0..3).filter(|&i| i != held).collect();
            fit(a, fam, records, &train, fam.start_v())
        })
        .collect();
    let all = fit(a, fam, records, &[0, 1, 2], fam.start_v());
    eprintln!(
        "{}: all-three fit v {:?}, params {:?}, objective {:.3}",
        fam.name(),
        all.velocity_m_s,
        all.params,
        all.objective
    );
    ModelFits { fam, folds, all }
}

/// The fit cache's text: every fit at full precision, `seconds` the fitting time.
fn cache_text(models: &[ModelFits], seconds: u64) -> String {
    let mut t = format!(
        "# Fitted constants of crates/validate/src/bin/shaper_loo.rs, written by its last fitting run\n\
         # (`-- --refit`, or no cache); without --refit shaper_loo reads them instead of fitting.\n\
         # Fitted on the 2013-05-22 incident records at the pressures `trained_on_psi`; velocities at\n\
         # 10 / 12.5 / 15 psi from the fitted gun line; `params` are the model's free shaper constants\n\
         # (SI units; validation/pulse/REPORT.md names them). Do not edit by hand.\n\
         fit_seconds = {seconds}\n"
    );
    for m in models {
        let fits = m.folds.iter().enumerate().map(|(held, f)| {
            let train: Vec<f64> = (0..3)
                .filter(|&i| i != held)
                .map(|i| PRESSURES_PSI[i])
                .collect();
            (train, f)
        });
        for (train, f) in fits.chain(std::iter::once((PRESSURES_PSI.to_vec(), &m.all))) {
            let _ = write!(
                t,
                "\n[[fit]]\nmodel = \"{}\"\ntrained_on_psi = {train:?}\nvelocity_m_s = {:?}\nparams = {:?}\nobjective = {:?}\n",
                m.fam.key(),
                f.velocity_m_s,
                f.params,
                f.objective
            );
        }
    }
    t
}

/// Reads the fit cache: the fits of every model it holds and its fitting time, s.
fn read_cache(path: &std::path::Path) -> Result<(Vec<ModelFits>, u64), String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| e.to_string())?;
    let seconds = table
        .get("fit_seconds")
        .and_then(toml::Value::as_integer)
        .unwrap_or(0) as u64;
    let floats = |v: Option<&toml::Value>, what: &str| -> Result<Vec<f64>, String> {
        v.and_then(toml::Value::as_array)
            .ok_or(format!("`{what}` missing"))?
            .iter()
            .map(|x| {
                x.as_float()
                    .or_else(|| x.as_integer().map(|i| i as f64))
                    .ok_or(format!("`{what}`: not a number"))
            })
            .collect()
    };
    let mut slots: Vec<(Family, Vec<Option<Fit>>)> =
        FAMILIES.iter().map(|&f| (f, vec![None; 4])).collect();
    for entry in table
        .get("fit")
        .and_then(toml::Value::as_array)
        .ok_or("no [[fit]] tables")?
    {
        let key = entry
            .get("model")
            .and_then(toml::Value::as_str)
            .ok_or("`model` missing")?;
        let slot = slots
            .iter_mut()
            .find(|(f, _)| f.key() == key)
            .ok_or(format!("unknown model `{key}`"))?;
        let train = floats(entry.get("trained_on_psi"), "trained_on_psi")?;
        let v = floats(entry.get("velocity_m_s"), "velocity_m_s")?;
        if !train.iter().all(|p| PRESSURES_PSI.contains(p)) {
            return Err(format!(
                "`trained_on_psi` = {train:?}: not among 10, 12.5, 15 psi"
            ));
        }
        let index = match train.len() {
            3 => 3,
            2 => (0..3)
                .find(|&i| !train.contains(&PRESSURES_PSI[i]))
                .ok_or("`trained_on_psi`: not two of 10, 12.5, 15")?,
            _ => return Err("`trained_on_psi`: two or three pressures".into()),
        };
        slot.1[index] = Some(Fit {
            velocity_m_s: v.try_into().map_err(|_| "`velocity_m_s`: three values")?,
            params: floats(entry.get("params"), "params")?,
            objective: entry
                .get("objective")
                .and_then(toml::Value::as_float)
                .ok_or("`objective` missing")?,
        });
    }
    let models = slots
        .into_iter()
        .filter_map(|(fam, fits)| {
            let fits: Option<Vec<Fit>> = fits.into_iter().collect();
            fits.map(|mut f| {
                let all = f.pop().expect("four fits");
                ModelFits { fam, folds: f, all }
            })
        })
        .collect();
    Ok((models, seconds))
}

/// Held-out result of one model and one pressure.
struct Fold {
    held_out: usize,
    fit: Fit,
    /// The simulated incident pulse at the held-out pressure (None: no pulse).
    sim: Option<(PulseMetrics, f64)>,
    /// Per held-out record: sample and errors (peak, rise, duration, energy).
    errors: Vec<(usize, [f64; 4])>,
}

fn pct(e: f64, tol: f64) -> String {
    if e.abs() <= tol {
        format!("{:+.1} %", 100.0 * e)
    } else {
        format!("**{:+.1} %**", 100.0 * e)
    }
}

/// Metric `j` (peak, rise, duration, energy) of a pulse.
fn metric(m: &PulseMetrics, energy_j: f64, j: usize) -> f64 {
    [m.peak, m.rise_10_90_s, m.duration_10_s, energy_j][j]
}

/// Names, display scales, units and decimals of the four incident metrics.
const METRICS: [(&str, f64, &str, usize); 4] = [
    ("peak", 1e-6, "MPa", 1),
    ("rise 10–90 %", 1e6, "µs", 1),
    ("duration at 10 %", 1e6, "µs", 1),
    ("pulse energy", 1.0, "J", 2),
];

/// Transmitted peak stress of the virtual test of `sample` with the given striker velocity and
/// shaper (None: the shipped set-up of the scene), Pa.
fn simulated_transmitted_pa(
    root: &std::path::Path,
    e: f64,
    sample: &Sample,
    run: Option<(f64, PulseShaper)>,
) -> Result<f64, String> {
    let out = virtual_test(root, sample, run.map(|r| r.0), run.map(|r| r.1))
        .map_err(|e| e.to_string())?;
    let s = GaugeStresses::of_run(&out, e, sample.scene).map_err(|e| e.to_string())?;
    s.transmitted_peak_pa(sample.scene)
        .map_err(|e| e.to_string())
}

fn main() {
    let root = common::repo_root();
    let a = Apparatus::from_file(&root.join("bars/authors.toml")).expect("bars/authors.toml");
    let records = read_records(&a);
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--probe") {
        probe(&a, &records, &args[2..]);
        return;
    }
    let refit = args.iter().any(|s| s == "--refit");
    let families: Vec<Family> = if args.iter().any(|s| s == "--frew") {
        vec![Family::Frew]
    } else if args.iter().any(|s| s == "--disc") {
        vec![Family::CrushedDisc]
    } else if args.iter().any(|s| s == "--exponential") {
        vec![Family::Exponential]
    } else if args.iter().any(|s| s == "--cushion") {
        vec![Family::CushionedDisc]
    } else {
        FAMILIES.to_vec()
    };
    let started = std::time::Instant::now();
    let cache_path = root.join(CACHE);
    let cached = if refit {
        None
    } else {
        match read_cache(&cache_path) {
            Ok((models, secs)) if families.iter().all(|f| models.iter().any(|m| m.fam == *f)) => {
                Some((models, secs))
            }
            Ok(_) => {
                eprintln!("{CACHE} lacks a model asked for: fitting");
                None
            }
            Err(e) => {
                eprintln!("no usable {CACHE} ({e}): fitting");
                None
            }
        }
    };
    let (mut models, fit_seconds, from_cache) = match cached {
        Some((m, s)) => (m, s, true),
        None => {
            let fitted: Vec<ModelFits> = families
                .iter()
                .map(|&f| fit_model(&a, f, &records))
                .collect();
            let mut secs = started.elapsed().as_secs();
            // Keep the cached fits of the models not refitted (and count the time they took).
            let (mut all, old_secs) = read_cache(&cache_path).unwrap_or_default();
            if all.iter().any(|m| !families.contains(&m.fam)) {
                secs += old_secs;
            }
            all.retain(|m| !families.contains(&m.fam));
            all.extend(fitted);
            all.sort_by_key(|m| FAMILIES.iter().position(|f| *f == m.fam));
            std::fs::write(&cache_path, cache_text(&all, secs)).expect("fit cache");
            eprintln!("wrote {}", cache_path.display());
            (all, secs, false)
        }
    };
    models.retain(|m| families.contains(&m.fam));
    let sec = section(
        &root,
        &a,
        &records,
        &models,
        fit_seconds,
        from_cache,
        started,
    );
    let path = root.join("validation/pulse/REPORT.md");
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    let new = match (old.find(BEGIN), old.find(END)) {
        (Some(b), Some(e)) => format!("{}{}{}", &old[..b], sec.trim_end(), &old[e + END.len()..]),
        _ => format!("{}\n\n{}\n", old.trim_end(), sec.trim_end()),
    };
    std::fs::write(&path, new).expect("REPORT.md");
    eprintln!("wrote {}", path.display());
}

/// `--probe d_mm h_mm factor mu v10 v12 v15`: one crushed disc's errors on every record.
fn probe(a: &Apparatus, records: &[Record], args: &[String]) {
    let x: Vec<f64> = args.iter().map(|s| s.parse().expect("number")).collect();
    let mut d = CrushedDisc::ofhc_copper(a.material.youngs_modulus_pa, a.material.poisson_ratio);
    d.face_compliance_factor = x[2];
    d.friction = x[3];
    let sh = PulseShaper::crushed_disc(x[0] * 1e-3, x[1] * 1e-3, COPPER_MODULUS_PA, d);
    for (i, &psi) in PRESSURES_PSI.iter().enumerate() {
        let Some(s) = simulate(a, x[4 + i], sh) else {
            println!("{psi} psi: no pulse");
            continue;
        };
        for r in records.iter().filter(|r| r.psi == psi) {
            let e = errors(r, &s);
            println!(
                "{psi} psi sample {}: peak {:.1} MPa ({:+.1} %), rise {:+.1} %, duration {:+.1} %, energy {:+.1} %",
                r.sample,
                s.0.peak / 1e6,
                100.0 * e[0],
                100.0 * e[1],
                100.0 * e[2],
                100.0 * e[3]
            );
        }
    }
}

/// Index of a pressure in [`PRESSURES_PSI`].
fn pressure_index(psi: f64) -> usize {
    PRESSURES_PSI
        .iter()
        .position(|&p| p == psi)
        .expect("one of the three pressures")
}

/// The report section from the fits.
fn section(
    root: &std::path::Path,
    a: &Apparatus,
    records: &[Record],
    models: &[ModelFits],
    fit_seconds: u64,
    from_cache: bool,
    started: std::time::Instant,
) -> String {
    let e_bar = a.material.youngs_modulus_pa;
    let area = a.transmission.area_m2();
    // The records' transmitted peaks, read as the gauge-records case reads them.
    let rec_tra: Vec<f64> = SAMPLES
        .iter()
        .map(|s| {
            GaugeStresses::of_record(a, &s.record_path(root))
                .and_then(|g| g.pulses(&s.record_path(root).display().to_string()))
                .expect("record pulses")
                .transmitted
                .peak
        })
        .collect();
    // Every virtual test: (model, fit: 0–2 held out / 3 all three, sample), and the shipped set-up.
    let jobs: Vec<(Option<(usize, usize)>, usize)> = (0..models.len())
        .flat_map(|m| {
            (0..SAMPLES.len()).flat_map(move |k| {
                let held = pressure_index(SAMPLES[k].psi);
                [(Some((m, held)), k), (Some((m, 3)), k)]
            })
        })
        .chain((0..SAMPLES.len()).map(|k| (None, k)))
        .collect();
    let results: Vec<Result<f64, String>> = jobs
        .par_iter()
        .map(|&(which, k)| {
            let s = &SAMPLES[k];
            let run = which.map(|(m, f)| {
                let mf = &models[m];
                let fit = if f == 3 { &mf.all } else { &mf.folds[f] };
                (
                    fit.velocity_m_s[pressure_index(s.psi)],
                    mf.fam.shaper(a, &fit.params),
                )
            });
            simulated_transmitted_pa(root, e_bar, s, run)
        })
        .collect();
    let tra_err = |which: Option<(usize, usize)>, k: usize| -> f64 {
        let i = jobs
            .iter()
            .position(|j| *j == (which, k))
            .expect("every test was run");
        match &results[i] {
            Ok(p) => p / rec_tra[k] - 1.0,
            Err(e) => {
                eprintln!("sample {}: {e}", SAMPLES[k].number);
                f64::NAN
            }
        }
    };
    let sample_index = |n: usize| SAMPLES.iter().position(|s| s.number == n).expect("sample");

    let mut sec = String::new();
    let provenance = if from_cache {
        format!(
            "The fitted constants are read from `{CACHE}`, which the last fitting run (`-- --refit`, \
             {fit_seconds} s on two cores) wrote at full precision; a run without `--refit` only evaluates them"
        )
    } else {
        format!("This run fitted them ({fit_seconds} s) and wrote them to `{CACHE}`")
    };
    let _ = writeln!(
        sec,
        "{BEGIN}\n## Leave one pressure out\n\nGenerated by `cargo run --release -p shpb-validate --bin shaper_loo` \
         (crates/validate/src/bin/shaper_loo.rs); do not edit by hand. Each shaper model is fitted on the \
         2013-05-22 records at two of the three pressures (gun line v² = k (p − p_loss) through the two fitted \
         velocities, the shaper's free constants (three, or the exponential law's one); objective Σ (error/target)² of incident peak, rise \
         10–90 %, duration at 10 % and pulse energy, targets 5 / 10 / 10 / 5 %), then predicts the held-out \
         pressure with the gun line extrapolated (10, 15 psi) or interpolated (12.5 psi). Errors are \
         (predicted − measured)/measured on each held-out record; bold: outside the issue-18 target. argmin's Nelder–Mead (`shpb_study::calibrate::optimise`) \
         in log space, ≤ 4 rounds of {EVALS_PER_ROUND} evaluations, 1 mm cells, no dispersion, as `calibrate_pulse`. \
         {provenance}.\n\n\
         Models: **frew**, the shipped Frew–Forrestal–Chen disc with an effective modulus (free: diameter, \
         thickness, modulus); **crushed-disc**, an annealed OFHC copper disc (Johnson–Cook A = 90 MPa, \
         B = 292 MPa, n = 0.31, C = 0.025, ε̇0 = 1/s; Johnson & Cook 1983) crushed at constant volume, \
         E = 117 GPa, in series with the Boussinesq compliance of the two bar faces (docs/physics.md §6.5.2), \
         with either a multiplier of that face compliance or the Coulomb friction μ free beside diameter and \
         thickness; **exponential**, an elastic element F = F0 (exp(c/λ) − 1) of the closure c, unloading \
         along the same curve (docs/physics.md §6.5.3; an empirical law: a closure λ ln(F2/F1) passed at a \
         closing speed that scales with the striker's gives rise times ∝ 1/v), λ free, F0 = {ONSET_FORCE_N} N; \
         **crushed-disc + exponential cushion**, the crushed disc with ideal faces seated through that \
         exponential element in series (docs/physics.md §6.5.4), diameter, thickness and λ free, F0 as the \
         exponential law's.\n\n\
         **Transmitted peak.** For every held-out record, the full virtual test of its specimen \
         (`validation/fig4-virtual-shpb/<material>-<psi>.toml`: the record's sphere pair, the Burgoyne–Daraio \
         contact law, the authors' bars) is run with the shaper and the striker velocity that the two-pressure fit \
         predicts for the held-out pressure, and the peak of its transmission-gauge stress is compared with the \
         record's, both read as the `gauge-records` validation case reads them (crates/validate/src/gauge_records.rs: \
         record through bars/gauges-authors.toml, baseline = first 900 samples, 2 µs moving average; the \
         transmitted pulse 100–550 µs after the incident 10 % foot); the peak force is that stress × the bar's \
         area ({:.3} cm²). Target (issue 18): within {:.0} %. The column *all three* runs the same test with the \
         model fitted on all eight records, so the held-out column's excess over it is what leaving the pressure \
         out costs.\n",
        area * 1e4,
        TRANSMITTED_TOL * 100.0
    );
    let mut summary = String::from(
        "| model | held out | v predicted (m/s) | shaper constants fitted on two | samples | peak | rise | duration | energy | transmitted peak rec. / pred. (kN) | transmitted peak | transmitted, all three |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut worst_rows = String::from(
        "| model | largest \\|peak err\\| | largest \\|rise err\\| | largest \\|duration err\\| | largest \\|energy err\\| | largest \\|transmitted peak err\\| | all within targets |\n|---|---|---|---|---|---|---|\n",
    );
    let mut transmitted_lines = String::new();
    let mut constants = String::from(
        "| model | constant | fitted on all three pressures | range over the three two-pressure fits | spread (half-range / all-three value) |\n|---|---|---|---|---|\n",
    );
    let mut all_folds: Vec<Vec<Fold>> = Vec::new();
    for (mi, mf) in models.iter().enumerate() {
        let fam = mf.fam;
        let folds: Vec<Fold> = (0..3)
            .map(|held| {
                let f = mf.folds[held].clone();
                let sim = simulate(a, f.velocity_m_s[held], fam.shaper(a, &f.params));
                let errs = records
                    .iter()
                    .filter(|r| r.psi == PRESSURES_PSI[held])
                    .map(|r| {
                        (
                            r.sample,
                            sim.as_ref().map_or([f64::NAN; 4], |s| errors(r, s)),
                        )
                    })
                    .collect();
                Fold {
                    held_out: held,
                    fit: f,
                    sim,
                    errors: errs,
                }
            })
            .collect();
        let names = fam.params();
        let mut worst = [0.0f64; 5];
        let mut worst_tra = (0.0f64, 0usize);
        for fo in &folds {
            for (sample, e) in &fo.errors {
                for j in 0..4 {
                    worst[j] = worst[j].max(e[j].abs());
                }
                let k = sample_index(*sample);
                let et = tra_err(Some((mi, fo.held_out)), k);
                let et_all = tra_err(Some((mi, 3)), k);
                if et.abs() >= worst_tra.0 || et.is_nan() {
                    worst_tra = (et.abs(), *sample);
                }
                worst[4] = worst[4].max(et.abs());
                let constants: Vec<String> = fo
                    .fit
                    .params
                    .iter()
                    .zip(&names)
                    .map(|(x, (_, scale, unit))| format!("{:.3} {unit}", x * scale))
                    .collect();
                let _ = writeln!(
                    summary,
                    "| {} | {} psi | {:.2} | {} | {sample} | {} | {} | {} | {} | {:.2} / {:.2} | {} | {} |",
                    fam.name(),
                    PRESSURES_PSI[fo.held_out],
                    fo.fit.velocity_m_s[fo.held_out],
                    constants.join(", "),
                    pct(e[0], TOL[0]),
                    pct(e[1], TOL[1]),
                    pct(e[2], TOL[2]),
                    pct(e[3], TOL[3]),
                    rec_tra[k] * area / 1e3,
                    rec_tra[k] * (1.0 + et) * area / 1e3,
                    pct(et, TRANSMITTED_TOL),
                    pct(et_all, TRANSMITTED_TOL),
                );
            }
        }
        let ok = (0..4).all(|j| worst[j] <= TOL[j]) && worst[4] <= TRANSMITTED_TOL;
        let _ = writeln!(
            worst_rows,
            "| {} | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {} |",
            fam.name(),
            100.0 * worst[0],
            100.0 * worst[1],
            100.0 * worst[2],
            100.0 * worst[3],
            100.0 * worst[4],
            if ok { "yes" } else { "**no**" }
        );
        let worst_all = (0..SAMPLES.len())
            .map(|k| tra_err(Some((mi, 3)), k).abs())
            .fold(0.0, f64::max);
        let _ = writeln!(
            transmitted_lines,
            "- **{}**: largest held-out |transmitted peak error| {:.1} % (sample {}) against the {:.0} % target: **{}**; \
             fitted on all three pressures instead: {:.1} %.",
            fam.name(),
            100.0 * worst_tra.0,
            worst_tra.1,
            TRANSMITTED_TOL * 100.0,
            if worst_tra.0 <= TRANSMITTED_TOL {
                "passes"
            } else {
                "fails"
            },
            100.0 * worst_all
        );
        // The gun line v² = k (p − p_loss) through the 10 and 15 psi velocities of a fit.
        let gun_line = |v: &[f64]| {
            let (v0, v2) = (v[0], v[2]);
            let k = (v2 * v2 - v0 * v0) / (5.0 * PSI_PA);
            (k, 10.0 * PSI_PA - v0 * v0 / k)
        };
        let all = &mf.all;
        let (k, loss) = gun_line(&all.velocity_m_s);
        for (j, (name, scale, unit)) in names.iter().enumerate() {
            let vals: Vec<f64> = folds.iter().map(|f| f.fit.params[j]).collect();
            let (lo, hi) = min_max(vals.iter().copied());
            let _ = writeln!(
                constants,
                "| {} | `{name}` | {:.4} {unit} | {:.4} – {:.4} {unit} | ± {:.1} % |",
                fam.name(),
                all.params[j] * scale,
                lo * scale,
                hi * scale,
                50.0 * (hi - lo) / all.params[j]
            );
        }
        let ks: Vec<(f64, f64)> = folds
            .iter()
            .map(|f| gun_line(&f.fit.velocity_m_s))
            .collect();
        for (name, x, get) in [
            ("k_m2_per_s2_per_pa", k, 0usize),
            ("loss_pressure_pa", loss, 1usize),
        ] {
            let vals: Vec<f64> = ks
                .iter()
                .map(|p| if get == 0 { p.0 } else { p.1 })
                .collect();
            let (lo, hi) = min_max(vals.iter().copied());
            let _ = writeln!(
                constants,
                "| {} | `[gun] {name}` | {x:.4e} | {lo:.4e} – {hi:.4e} | ± {:.1} % |",
                fam.name(),
                50.0 * (hi - lo) / x.abs()
            );
        }
        let _ = writeln!(
            constants,
            "| {} | striker velocity 10 / 12.5 / 15 psi | {:.2} / {:.2} / {:.2} m/s | | objective {:.2} on all eight records |",
            fam.name(),
            all.velocity_m_s[0],
            all.velocity_m_s[1],
            all.velocity_m_s[2],
            all.objective
        );
        all_folds.push(folds);
    }
    let shipped_worst = (0..SAMPLES.len())
        .map(|k| tra_err(None, k).abs())
        .fold(0.0, f64::max);
    let _ = writeln!(
        sec,
        "### Held-out predictions\n\n{summary}\n### Largest held-out error per model\n\n{worst_rows}\n\
         Transmitted peak, leave one pressure out:\n\n{transmitted_lines}\n\
         For reference, the shipped set-up (bars/authors.toml, frew fitted on all three pressures with the looser \
         15 / 20 / 20 % tolerances of `calibrate_pulse`) gives a largest |transmitted peak error| of {:.1} % \
         on the same eight tests.\n",
        100.0 * shipped_worst
    );
    sec.push_str(&rise_and_plateau(a, records, models, &all_folds));
    sec.push_str(&scatter_section(records, models, &all_folds));
    sec.push_str(&held_out_day(root, a, records));
    sec.push_str(&held_out_day_models(root, a, models));
    let _ = writeln!(
        sec,
        "### Fitted constants and their spread\n\nThe constants each model needs beyond the published ones, fitted \
         on all three pressures (eight records), and their range over the three leave-one-out fits: the \
         uncertainty a calibration on two pressures carries.\n\n{constants}\n{fit_seconds} s of fitting; \
         this evaluation {} s.\n{END}",
        started.elapsed().as_secs()
    );
    sec
}

/// Range (least, largest) of metric `j`'s held-out error at the pressure `held` over a model's
/// records.
fn held_out_range(folds: &[Fold], held: usize, j: usize) -> (f64, f64) {
    min_max(
        folds[held]
            .errors
            .iter()
            .map(|(_, e)| e[j])
            .filter(|e| e.is_finite()),
    )
}

/// What separates the models: the 10 psi rise (how a pulse's time scale follows the striker's
/// speed) and the 15 psi peak (the records' plateau), held out, per model.
fn rise_and_plateau(
    a: &Apparatus,
    records: &[Record],
    models: &[ModelFits],
    folds: &[Vec<Fold>],
) -> String {
    let mut t = String::from(
        "### The rise and the plateau\n\nThe two held-out errors that separate the models: the rise at \
         10 psi, where a pulse's time scale must follow the striker's speed beyond the fitted ones, \
         and the peak at 15 psi, where the records hold a plateau.\n\n\
         | model | fitted shaper constants | rise 10–90 %, 10 psi held out | peak, 15 psi held out |\n\
         |---|---|---|---|\n",
    );
    let mut exponential_peak = (f64::NAN, f64::NAN);
    let (mut cushion_rise, mut cushion_peak) = ((f64::NAN, f64::NAN), (f64::NAN, f64::NAN));
    for (m, f) in models.iter().zip(folds) {
        let (r0, r1) = held_out_range(f, 0, 1);
        let (p0, p1) = held_out_range(f, 2, 0);
        if m.fam == Family::Exponential {
            exponential_peak = (100.0 * p0, 100.0 * p1);
        }
        if m.fam == Family::CushionedDisc {
            cushion_rise = (100.0 * r0, 100.0 * r1);
            cushion_peak = (100.0 * p0, 100.0 * p1);
        }
        let _ = writeln!(
            t,
            "| {} | {} | {:+.1} to {:+.1} % | {:+.1} to {:+.1} % |",
            m.fam.name(),
            m.fam.params().len(),
            100.0 * r0,
            100.0 * r1,
            100.0 * p0,
            100.0 * p1
        );
    }
    let f0_line = exponential_onset_sensitivity(a, records, models, folds);
    let clipping = unclipped_tops();
    let _ = write!(
        t,
        "\n**Reading (an inference from eight records).** The records' rise shortens with the \
         striker's speed about as 1/v (*The rise, segment by segment*, above). A disc law with an \
         elastic cushion of fixed stiffness (frew's effective modulus, the crushed disc's face \
         compliance) has a time scale of its own, independent of v, and its rise extrapolated to \
         10 psi comes out short; the exponential law has none (a force growing by e over each λ of \
         closure, passed at a closing speed ∝ v), and predicts the 10 psi rise from the 12.5 and \
         15 psi records. Its one constant barely moves between the folds (*Fitted constants*, \
         below), where the disc models' diameter and thickness range over a factor of up to four. \
         Fitting F0 as well undoes this: the fit then runs F0 to several kN, where the law is \
         nearly linear at the pulse's foot, and the 10 psi rise is lost again (−16 to −23 %, a \
         scratch fit). F0 itself, stated, matters little while it is small: {f0_line} What the \
         exponential law does not have is the records' plateau: an \
         elastic element gives a rounded top, and its peak at 15 psi comes out {:+.1} to {:+.1} % \
         off, as frew's does. A law that has both, the crushed disc seated through the exponential \
         law as a cushion in series (*crushed-disc + exponential cushion*: the exponential rise, \
         then Johnson–Cook flow of a disc that spreads; diameter, thickness and λ free, F0 as \
         above; docs/physics.md §6.5.4), was fitted to test that (two starting points, the lower \
         minimum kept): its 15 psi peak comes out {:+.1} to {:+.1} % off and its 10 psi rise \
         {:+.1} to {:+.1} %, no better than the laws it combines. The reading we take from it (an \
         inference): the 10 and 12.5 psi records, below the plateau, do not fix the level of a \
         plastic limit, and once the disc flows its thinning sets a time scale of its own again. Of \
         these models only the crushed disc with its face compliance free comes near the 15 psi \
         peak, at the price of the 10 psi rise. {clipping}\n\n",
        exponential_peak.0,
        exponential_peak.1,
        cushion_peak.0,
        cushion_peak.1,
        cushion_rise.0,
        cushion_rise.1
    );
    t
}

/// Whether the 15 psi records' incident tops could be a limit of the signal chain rather than of
/// the pulse: each record's extreme compressive incident voltage, how many samples lie within one
/// digitiser count of it, and the record's largest magnitude on that channel (a sentence).
fn unclipped_tops() -> String {
    /// One record's top: sample, extreme voltage (V), samples at it, largest |V|, digitiser count (V).
    struct Top {
        sample: usize,
        extreme_v: f64,
        at_extreme: usize,
        largest_v: f64,
        count_v: f64,
    }
    let root = common::repo_root();
    let mut rows = Vec::new();
    for s in SAMPLES.iter().filter(|s| s.psi == PRESSURES_PSI[2]) {
        let r = RawRecord::read(&s.record_path(&root)).expect("record");
        let v = &r.incident_v;
        let (lo, hi) = min_max(v.iter().copied());
        let mut levels: Vec<f64> = v.clone();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        let count = levels
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let at_top = v.iter().filter(|&&x| x <= lo + 0.5 * count).count();
        rows.push(Top {
            sample: s.number,
            extreme_v: lo,
            at_extreme: at_top,
            largest_v: hi.max(-lo),
            count_v: count,
        });
    }
    let list = |f: &dyn Fn(&Top) -> String| rows.iter().map(f).collect::<Vec<_>>().join(", ");
    let top = rows.iter().fold(0.0f64, |m, r| m.max(-r.extreme_v));
    let beyond = rows
        .iter()
        .filter(|r| r.largest_v > top)
        .map(|r| {
            format!(
                "sample {}'s channel reaches {:.2} mV elsewhere in its record",
                r.sample,
                1e3 * r.largest_v
            )
        })
        .collect::<Vec<_>>();
    let beyond = if beyond.is_empty() {
        String::new()
    } else {
        format!(", and {}, above every 15 psi top", beyond.join(" and "))
    };
    format!(
        "Nor is the records' 15 psi top a limit of their signal chain: on samples {} the incident \
         channel reaches its compressive extreme ({} mV) in {} sample(s) each (the digitiser's \
         count is {:.3} mV), not in the flat run a clipped channel would show{beyond}.",
        list(&|r| r.sample.to_string()),
        list(&|r| format!("{:.2}", 1e3 * r.extreme_v).replace('-', "−")),
        list(&|r| r.at_extreme.to_string()),
        1e3 * rows.first().map_or(f64::NAN, |r| r.count_v),
    )
}

/// How far the exponential family's held-out errors move when its stated F0 is replaced by
/// 1 N or 100 N at the same fitted λ and velocities: a sentence (empty without that family).
fn exponential_onset_sensitivity(
    a: &Apparatus,
    records: &[Record],
    models: &[ModelFits],
    folds: &[Vec<Fold>],
) -> String {
    let Some(k) = models.iter().position(|m| m.fam == Family::Exponential) else {
        return String::new();
    };
    let shift = |f0: f64| {
        let mut worst = 0.0f64;
        for fo in &folds[k] {
            let sh = PulseShaper::exponential(ExponentialSpring {
                stiffening_length_m: fo.fit.params[0],
                onset_force_n: f0,
            });
            let Some(sim) = simulate(a, fo.fit.velocity_m_s[fo.held_out], sh) else {
                return f64::NAN;
            };
            for (sample, e) in &fo.errors {
                let r = records
                    .iter()
                    .find(|r| r.sample == *sample)
                    .expect("record");
                for (x, y) in errors(r, &sim).iter().zip(e) {
                    worst = worst.max((x - y).abs());
                }
            }
        }
        100.0 * worst
    };
    format!(
        "with F0 = 1 N instead of {ONSET_FORCE_N} N, at the same λ and velocities, every held-out \
         incident error above moves by at most {:.2} percentage point, with F0 = 100 N by at most \
         {:.2}.",
        shift(1.0),
        shift(100.0)
    )
}

/// A held-out record outside its target on one metric.
#[derive(Clone, Copy)]
struct Miss {
    /// Index of the model.
    model: usize,
    /// Index of the held-out pressure.
    held: usize,
    sample: usize,
    /// Index of the metric in [`METRICS`].
    metric: usize,
    /// Error against the record.
    error: f64,
    /// Error against the mean of the records at that pressure.
    vs_mean: f64,
    /// Whether the prediction lies within the records' range.
    inside: bool,
    /// The records' spread (max − min)/mean.
    spread: f64,
}

/// The records' own scatter per pressure and the held-out predictions against their mean.
fn scatter_section(records: &[Record], models: &[ModelFits], folds: &[Vec<Fold>]) -> String {
    let mut s = String::from(
        "### The records' own scatter\n\nThe records at one pressure differ among themselves (one record per \
         specimen material, shot the same day with the same gun and shaper). Per pressure: the records' values, \
         their mean and their spread (max − min)/mean (two records at 10 psi, three at 12.5 and 15 psi: a spread \
         of so few records is a lower bound of the day's scatter); and each model's held-out prediction against \
         that mean (bold: outside the target). The transmitted peak has no such column: at one pressure each record has \
         another specimen material, so its records do not repeat one test.\n\n",
    );
    let mut head = String::from("| psi | samples | metric | records | mean | spread |");
    let mut rule = String::from("|---|---|---|---|---|---|");
    for m in models {
        let _ = write!(head, " {}: predicted, vs mean |", m.fam.name());
        rule.push_str("---|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    let mut misses: Vec<Miss> = Vec::new();
    // What the targets leave a prediction at each pressure: |p/r − 1| ≤ tol on every record r
    // there is p in [max r (1 − tol), min r (1 + tol)], a property of the records alone.
    let mut windows = String::from(
        "\n**What the targets leave a prediction.** A prediction p meets a target tol on every record r at its \
         pressure at once only inside [max r · (1 − tol), min r · (1 + tol)]: the records and the targets alone \
         fix that window, whatever the model. Its width is given relative to the records' mean; where it is \
         narrow, a model must predict the pressure to a small part of its own records' scatter.\n\n\
         | psi | metric | target | records' spread | window | width (of the mean) |\n|---|---|---|---|---|---|\n",
    );
    for (held, &psi) in PRESSURES_PSI.iter().enumerate() {
        let recs: Vec<&Record> = records.iter().filter(|r| r.psi == psi).collect();
        let samples: Vec<String> = recs.iter().map(|r| r.sample.to_string()).collect();
        for (j, &(name, scale, unit, dec)) in METRICS.iter().enumerate() {
            let vals: Vec<f64> = recs
                .iter()
                .map(|r| metric(&r.metrics, r.energy_j, j))
                .collect();
            let mean = vals.iter().sum::<f64>() / vals.len() as f64;
            let (lo, hi) = min_max(vals.iter().copied());
            let spread = (hi - lo) / mean;
            let (w_lo, w_hi) = (hi * (1.0 - TOL[j]), lo * (1.0 + TOL[j]));
            let d2 = dec + 1;
            let (window, width) = if w_lo <= w_hi {
                (
                    format!("{:.d2$}–{:.d2$} {unit}", w_lo * scale, w_hi * scale),
                    format!("{:.1} %", 100.0 * (w_hi - w_lo) / mean),
                )
            } else {
                ("none".to_string(), "—".to_string())
            };
            let _ = writeln!(
                windows,
                "| {psi} | {name} | {:.0} % | {:.1} % | {window} | {width} |",
                100.0 * TOL[j],
                100.0 * spread,
            );
            let shown: Vec<String> = vals
                .iter()
                .map(|v| format!("{:.dec$}", v * scale))
                .collect();
            let mut row = format!(
                "| {psi} | {} | {name} ({unit}) | {} | {:.dec$} | {:.1} % |",
                samples.join(", "),
                shown.join(", "),
                mean * scale,
                100.0 * spread
            );
            for (mi, fs) in folds.iter().enumerate() {
                let fo = &fs[held];
                match &fo.sim {
                    Some(sim) => {
                        let p = metric(&sim.0, sim.1, j);
                        let vs_mean = p / mean - 1.0;
                        let _ = write!(row, " {:.dec$}, {} |", p * scale, pct(vs_mean, TOL[j]));
                        let inside = (lo..=hi).contains(&p);
                        for (sample, e) in &fo.errors {
                            if e[j].abs() > TOL[j] {
                                misses.push(Miss {
                                    model: mi,
                                    held,
                                    sample: *sample,
                                    metric: j,
                                    error: e[j],
                                    vs_mean,
                                    inside,
                                    spread,
                                });
                            }
                        }
                    }
                    None => row.push_str(" no pulse |"),
                }
            }
            let _ = writeln!(s, "{row}");
        }
    }
    s.push_str(&windows);
    let _ = writeln!(
        s,
        "\n**The misses against that scatter.** Every held-out record outside its target, with the prediction's \
         error against the record and against the mean of the records at its pressure. *Within the scatter* \
         (an inference, not a pass): the prediction lies inside the range the records span, or within the target \
         of their mean, so that a miss on this record comes with a hit on its siblings: the records themselves \
         disagree by more than the target allows.\n\n\
         | model | held out | sample | metric | error vs record | error vs mean | records' spread | prediction inside the records' range | within the records' scatter |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    let mut within: Vec<Vec<String>> = vec![Vec::new(); models.len()];
    let mut beyond: Vec<Vec<String>> = vec![Vec::new(); models.len()];
    for &Miss {
        model: mi,
        held,
        sample,
        metric: j,
        error: e,
        vs_mean,
        inside,
        spread,
    } in &misses
    {
        let ok = inside || vs_mean.abs() <= TOL[j];
        let _ = writeln!(
            s,
            "| {} | {} psi | {sample} | {} | {:+.1} % | {:+.1} % | {:.1} % | {} | {} |",
            models[mi].fam.name(),
            PRESSURES_PSI[held],
            METRICS[j].0,
            100.0 * e,
            100.0 * vs_mean,
            100.0 * spread,
            if inside { "yes" } else { "no" },
            if ok { "yes" } else { "**no**" }
        );
        let tag = format!(
            "{} at {} psi (sample {sample})",
            METRICS[j].0, PRESSURES_PSI[held]
        );
        if ok {
            within[mi].push(tag);
        } else {
            beyond[mi].push(tag);
        }
    }
    let _ = writeln!(s, "\n**Reading (inference from these records).**");
    for (mi, m) in models.iter().enumerate() {
        let list = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join("; ")
            }
        };
        let _ = writeln!(
            s,
            "- **{}**: of {} per-record misses, {} lie within the records' own scatter ({}); {} do not ({}): there \
             the prediction misses the pressure, not one record.",
            m.fam.name(),
            within[mi].len() + beyond[mi].len(),
            within[mi].len(),
            list(&within[mi]),
            beyond[mi].len(),
            list(&beyond[mi])
        );
    }
    s.push('\n');
    s
}

/// The gauge pressure in `lo`–`hi` (Pa) at which the pulse `at` gives carries `energy` (J), by
/// bisection (the simulated energy grows with the pressure), with that pulse; None: outside.
fn energy_implied(
    at: &(dyn Fn(f64) -> Option<(PulseMetrics, f64)> + Sync),
    energy: f64,
    lo: f64,
    hi: f64,
) -> Option<(f64, (PulseMetrics, f64))> {
    let energy_at = |p: f64| at(p).map_or(f64::NAN, |s| s.1);
    if !(energy_at(lo) <= energy && energy_at(hi) >= energy) {
        return None;
    }
    let (mut lo, mut hi) = (lo, hi);
    while hi - lo > 0.001 * PSI_PA {
        let mid = 0.5 * (lo + hi);
        if energy_at(mid) < energy {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    Some((p, at(p)?))
}

/// An energy-implied pressure (psi) and the peak, rise and duration errors there.
type Implied = (f64, [f64; 3]);

/// The 2013-06-06 records against each model fitted on all three pressures, each at its own
/// energy-implied pressure (its gun line through its fitted 10 and 15 psi velocities).
fn held_out_day_models(root: &std::path::Path, a: &Apparatus, models: &[ModelFits]) -> String {
    let (p_min, p_max) = a.gun.range_pa();
    let measured: Vec<(PulseMetrics, f64)> = SAMPLES_2013_06_06
        .iter()
        .map(|d| {
            let (t, y) = incident_pulse(a, &d.record_path(root)).expect("2013-06-06 record");
            (
                pulse_metrics(&t, &y, false).expect("incident pulse"),
                pulse_energy_j(a, &t, &y),
            )
        })
        .collect();
    let mut s = String::from(
        "The same question for each model fitted on all three pressures (the constants above), each at the \
         pressure at which its own gun line and shaper give the record's pulse energy: implied pressure (psi), \
         then peak / rise / duration error there.\n\n| sample |",
    );
    let mut rule = String::from("|---|");
    for m in models {
        let _ = write!(s, " {} |", m.fam.name());
        rule.push_str("---|");
    }
    let _ = writeln!(s, "\n{rule}");
    let mut above: Vec<Vec<f64>> = vec![Vec::new(); models.len()];
    let cells: Vec<Vec<Option<Implied>>> = models
        .par_iter()
        .map(|m| {
            let v = m.all.velocity_m_s;
            let k = (v[2] * v[2] - v[0] * v[0]) / (5.0 * PSI_PA);
            let loss = 10.0 * PSI_PA - v[0] * v[0] / k;
            let shaper = m.fam.shaper(a, &m.all.params);
            let at = move |p: f64| -> Option<(PulseMetrics, f64)> {
                let v2 = k * (p - loss);
                (v2 > 0.0).then(|| simulate(a, v2.sqrt(), shaper)).flatten()
            };
            measured
                .iter()
                .map(|(mm, e)| {
                    let (p, sim) = energy_implied(&at, *e, p_min.max(loss + 0.1 * PSI_PA), p_max)?;
                    Some((
                        p / PSI_PA,
                        [
                            sim.0.peak / mm.peak - 1.0,
                            sim.0.rise_10_90_s / mm.rise_10_90_s - 1.0,
                            sim.0.duration_10_s / mm.duration_10_s - 1.0,
                        ],
                    ))
                })
                .collect()
        })
        .collect();
    for (k, d) in SAMPLES_2013_06_06.iter().enumerate() {
        let mut row = format!("| {} |", d.number);
        for (mi, c) in cells.iter().enumerate() {
            match c[k] {
                Some((psi, e)) => {
                    if psi > 15.0 {
                        above[mi].push(e[0]);
                    }
                    let _ = write!(
                        row,
                        " {psi:.1}: {} / {} / {} |",
                        pct(e[0], TOL[0]),
                        pct(e[1], TOL[1]),
                        pct(e[2], TOL[2])
                    );
                }
                None => row.push_str(" outside the gun's range |"),
            }
        }
        let _ = writeln!(s, "{row}");
    }
    s.push('\n');
    for (mi, m) in models.iter().enumerate() {
        if above[mi].is_empty() {
            continue;
        }
        let (lo, hi) = min_max(above[mi].iter().copied());
        let _ = writeln!(
            s,
            "- **{}**: peak error {:+.1} to {:+.1} % on the {} records implied above 15 psi.",
            m.fam.name(),
            100.0 * lo,
            100.0 * hi,
            above[mi].len()
        );
    }
    s.push('\n');
    s
}

/// The 2013-06-06 records against the shipped calibration (`a`, bars/authors.toml): their
/// pressures are not stated, so each is run at the pressure whose simulated pulse energy equals
/// the record's (an inference resting on the shipped gun line), and its peak, rise and duration
/// compared there.
fn held_out_day(root: &std::path::Path, a: &Apparatus, records: &[Record]) -> String {
    let shaper = a.shaper.expect("the shipped set-up has a shaper");
    let (p_lo, p_hi) = a.gun.range_pa();
    let at = |p_pa: f64| -> Option<(PulseMetrics, f64)> {
        simulate(a, a.striker_velocity_m_s(p_pa).ok()?, shaper)
    };
    let rows: Vec<(String, Option<(f64, f64)>)> = SAMPLES_2013_06_06
        .par_iter()
        .map(|d| {
            let path = d.record_path(root);
            let (t, y) = incident_pulse(a, &path).expect("2013-06-06 record");
            let m = pulse_metrics(&t, &y, false).expect("incident pulse");
            let energy = pulse_energy_j(a, &t, &y);
            let implied = energy_implied(&at, energy, p_lo, p_hi).map(|x| x.0);
            let mut row = format!(
                "| {} | {} (\"{}\") | {:.1} | {:.1} | {:.1} | {:.2} |",
                d.number,
                d.material,
                d.authors_label,
                m.peak / 1e6,
                m.rise_10_90_s * 1e6,
                m.duration_10_s * 1e6,
                energy
            );
            let mut found = None;
            match implied.and_then(|p| Some((p, at(p)?))) {
                Some((p, s)) => {
                    found = Some((p, s.0.peak / m.peak - 1.0));
                    let _ = write!(
                        row,
                        " {:.2} | {} | {} | {} |",
                        p / PSI_PA,
                        pct(s.0.peak / m.peak - 1.0, TOL[0]),
                        pct(s.0.rise_10_90_s / m.rise_10_90_s - 1.0, TOL[1]),
                        pct(s.0.duration_10_s / m.duration_10_s - 1.0, TOL[2]),
                    );
                }
                None => row.push_str(" outside the gun's range | | | |"),
            }
            (row, found)
        })
        .collect();
    // How far an energy error moves an implied pressure: the shipped model's largest |energy
    // error| on the 2013-05-22 records, over its energy's slope between 12.5 and 15 psi.
    let sims: Vec<Option<(PulseMetrics, f64)>> =
        PRESSURES_PSI.iter().map(|&p| at(p * PSI_PA)).collect();
    let worst_energy = records
        .iter()
        .filter_map(|r| Some((sims[pressure_index(r.psi)].as_ref()?.1 / r.energy_j - 1.0).abs()))
        .fold(0.0, f64::max);
    let slope = match (&sims[1], &sims[2]) {
        (Some(a), Some(b)) => (b.1 - a.1) / 2.5,
        _ => f64::NAN,
    };
    let e15 = sims[2].as_ref().map_or(f64::NAN, |s| s.1);
    let energies = |psi: f64| {
        let e: Vec<String> = records
            .iter()
            .filter(|r| r.psi == psi)
            .map(|r| format!("{:.2}", r.energy_j))
            .collect();
        e.join(", ")
    };
    let mut s = format!(
        "### The 2013-06-06 records (a held-out day)\n\n\
         Eight records shot on 2013-06-06 on the same bars (the authors' `hopkinson_tests_6-6/sample<N>.lvm`, \
         converted to `validation/gauge-records/data/2013-06-06_sample<N>_<material>.csv`, CC-BY 4.0), read \
         exactly as the 2013-05-22 ones above (incident channel, same window and baseline). The authors' \
         `test_data.txt` for that day names each sample's specimen (440, 302, Alum) and nothing else: **the gun \
         pressures, the striker and the pulse shaper of these tests are stated nowhere** in their repository, \
         the paper (\"pressures varied from 50 kPa to 125 kPa\", 7.3–18.1 psi, over all tests) or the project's \
         reference notes. So the shipped calibration cannot be checked against them per pressure. What can be \
         asked is whether the shipped model, run at the pressure whose simulated pulse energy equals the \
         record's (the *energy-implied pressure*: an inference that rests on the shipped gun line, extrapolated \
         above 15 psi), gives the record's peak, rise and duration: a test of the shaper's pulse shape at \
         energies beyond the calibration's, not of the gun. For scale, the 2013-05-22 pulses carry \
         {} J at 10 psi, {} J at 12.5 psi and {} J at 15 psi. The shipped model's pulse energy errs by up to \
         {:.1} % on those records; at 15 psi ({:.2} J, {:.2} J per psi) that is {:.1} psi of implied pressure, \
         the uncertainty of the column below. Errors bold beyond the leave-one-out targets (5 / 10 / 10 %).\n\n\
         | sample | specimen (test_data.txt) | peak (MPa) | rise 10–90 % (µs) | duration at 10 % (µs) | energy (J) | energy-implied pressure, shipped gun line (psi) | peak error there | rise error | duration error |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        energies(10.0),
        energies(12.5),
        energies(15.0),
        100.0 * worst_energy,
        e15,
        slope,
        worst_energy * e15 / slope
    );
    for (r, _) in &rows {
        let _ = writeln!(s, "{r}");
    }
    let (cal_lo, cal_hi) = a
        .gun_calibrated_pa
        .map_or((10.0, 15.0), |(l, h)| (l / PSI_PA, h / PSI_PA));
    let group = |inside: bool| -> String {
        let mut v: Vec<(usize, f64, f64)> = rows
            .iter()
            .zip(&SAMPLES_2013_06_06)
            .filter_map(|((_, f), d)| {
                let (p, e) = (*f)?;
                let psi = p / PSI_PA;
                ((psi <= cal_hi + 1e-9) == inside).then_some((d.number, psi, e))
            })
            .collect();
        v.sort_by(|x, y| x.1.total_cmp(&y.1));
        if v.is_empty() {
            return "no record".into();
        }
        let items: Vec<String> = v
            .iter()
            .map(|(n, psi, e)| format!("sample {n} {psi:.1} psi {:+.1} %", 100.0 * e))
            .collect();
        items.join(", ")
    };
    let range = |inside: bool| -> String {
        let e: Vec<f64> = rows
            .iter()
            .filter_map(|(_, f)| {
                let (p, e) = (*f)?;
                ((p / PSI_PA <= cal_hi + 1e-9) == inside).then_some(e)
            })
            .collect();
        if e.is_empty() {
            return "—".into();
        }
        let (lo, hi) = min_max(e.iter().copied());
        format!("{:+.1} to {:+.1} %", 100.0 * lo, 100.0 * hi)
    };
    let _ = writeln!(
        s,
        "\n**Reading (inference).** Peak error at the energy-implied pressure, ordered by that pressure: within \
         the calibrated {cal_lo:.0}–{cal_hi:.0} psi {}; above it {}. So, matched to these pulses' energy, the shipped \
         model's peak errs by {} where the implied pressure lies within the calibrated range and by {} above it \
         (rise and duration: the table): the direction of its held-out 15 psi peak error above, and what issue 18 \
         reported for this day. Knowing the pressure each test was shot at would turn this inference into a test.\n",
        group(true),
        group(false),
        range(true),
        range(false),
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(x: f64) -> Fit {
        Fit {
            velocity_m_s: [x, 2.0 * x, 3.0 * x],
            params: vec![x * 1e-3, x * 1e-20, x * 1e9],
            objective: x / 7.0,
        }
    }

    #[test]
    fn the_fit_cache_reads_back_every_constant_exactly() {
        // The cache must hand the evaluation the very numbers the fits found (the report's
        // numbers are reproduced from it), so the round trip is exact, not within a tolerance.
        let models: Vec<ModelFits> = FAMILIES
            .iter()
            .enumerate()
            .map(|(i, &fam)| ModelFits {
                fam,
                folds: (0..3)
                    .map(|k| fit(1.0 / (3.0 + (3 * i + k) as f64)))
                    .collect(),
                all: fit(std::f64::consts::PI + i as f64),
            })
            .collect();
        let path =
            std::env::temp_dir().join(format!("shaper_loo_cache_test_{}.toml", std::process::id()));
        std::fs::write(&path, cache_text(&models, 1234)).unwrap();
        let (back, seconds) = read_cache(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(seconds, 1234);
        assert_eq!(back.len(), models.len());
        for (a, b) in models.iter().zip(&back) {
            assert!(a.fam == b.fam);
            for (x, y) in a
                .folds
                .iter()
                .chain([&a.all])
                .zip(b.folds.iter().chain([&b.all]))
            {
                assert_eq!(x.velocity_m_s, y.velocity_m_s);
                assert_eq!(x.params, y.params);
                assert_eq!(x.objective, y.objective);
            }
        }
    }

    #[test]
    fn a_cache_without_a_model_or_with_a_foreign_pressure_is_refused_or_incomplete() {
        let path =
            std::env::temp_dir().join(format!("shaper_loo_cache_bad_{}.toml", std::process::id()));
        let text = "fit_seconds = 1\n[[fit]]\nmodel = \"frew\"\ntrained_on_psi = [10.0, 17.5]\n\
                    velocity_m_s = [1.0, 2.0, 3.0]\nparams = [1.0, 2.0, 3.0]\nobjective = 1.0\n";
        std::fs::write(&path, text).unwrap();
        let r = read_cache(&path);
        std::fs::remove_file(&path).unwrap();
        assert!(
            r.is_err(),
            "a pressure outside 10 / 12.5 / 15 psi must be refused"
        );
        let text = "fit_seconds = 1\n[[fit]]\nmodel = \"frew\"\ntrained_on_psi = [10.0, 15.0]\n\
                    velocity_m_s = [1.0, 2.0, 3.0]\nparams = [1.0, 2.0, 3.0]\nobjective = 1.0\n";
        std::fs::write(&path, text).unwrap();
        let (models, _) = read_cache(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert!(
            models.is_empty(),
            "a model with one of its four fits is not usable"
        );
    }
}

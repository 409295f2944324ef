//! Case `gauge-records`: the simulated gauge signals of the virtual SHPB tests against the real
//! raw records of 2013-05-22 (same material and gun pressure): incident, reflected and
//! transmitted pulse peaks and the transmitted pulse's arrival (physics.md §6–7).

use crate::figure::{Figure, Legend, Panel, Series, Style};
use crate::{CaseResult, Check, Context, Unit, pct};
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{PulseMetrics, RawRecord, pulse_metrics};
use shpb_core::reduce::{Reduction, record_strains};
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_core::shaper::PulseShaper;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One real SHPB record of 2013-05-22 (`validation/gauge-records/data`, CC-BY 4.0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Sample number of the record.
    pub number: usize,
    /// Specimen material, as in `specimens/` (e.g. `ss440c`).
    pub material: &'static str,
    /// Gas-gun pressure, psi.
    pub psi: f64,
    /// Label for tables, e.g. `SS440c 10 psi`.
    pub label: &'static str,
    /// Stem of the virtual test of the same material and pressure in
    /// `validation/fig4-virtual-shpb/`.
    pub scene: &'static str,
}

/// The eight records of 2013-05-22.
pub const SAMPLES: [Sample; 8] = [
    sample(1, "ss440c", 10.0, "SS440c 10 psi", "ss440c-10psi"),
    sample(2, "ss440c", 12.5, "SS440c 12.5 psi", "ss440c-12p5psi"),
    sample(3, "ss440c", 15.0, "SS440c 15 psi", "ss440c-15psi"),
    sample(4, "al2017", 12.5, "Al2017 12.5 psi", "al2017-12p5psi"),
    sample(5, "al2017", 15.0, "Al2017 15 psi", "al2017-15psi"),
    sample(6, "ss302", 10.0, "SS302 10 psi", "ss302-10psi"),
    sample(7, "ss302", 15.0, "SS302 15 psi", "ss302-15psi"),
    sample(8, "ss302", 12.5, "SS302 12.5 psi", "ss302-12p5psi"),
];

const fn sample(
    number: usize,
    material: &'static str,
    psi: f64,
    label: &'static str,
    scene: &'static str,
) -> Sample {
    Sample {
        number,
        material,
        psi,
        label,
        scene,
    }
}

impl Sample {
    /// Path of the raw record `2013-05-22_sample<N>_<material>.csv` below the repository root.
    pub fn record_path(&self, root: &Path) -> PathBuf {
        self.data_path(root, "")
    }

    /// Path of the authors' reduction of the record below the repository root.
    pub fn authors_reduction_path(&self, root: &Path) -> PathBuf {
        self.data_path(root, "_authors_reduction")
    }

    fn data_path(&self, root: &Path, suffix: &str) -> PathBuf {
        root.join(format!(
            "validation/gauge-records/data/2013-05-22_sample{}_{}{suffix}.csv",
            self.number, self.material
        ))
    }
}

/// One raw record of 2013-06-06, a day the calibration never saw (`validation/gauge-records/data`,
/// CC-BY 4.0): the authors' `hopkinson_tests_6-6/test_data.txt` names each sample's specimen
/// only; its gun pressure, striker and pulse shaper are stated nowhere in their repository.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DayRecord {
    /// Sample number of the record.
    pub number: usize,
    /// Specimen material as in `specimens/` (the authors' label read as the paper's material).
    pub material: &'static str,
    /// The specimen as `test_data.txt` writes it.
    pub authors_label: &'static str,
}

/// The eight records of 2013-06-06.
pub const SAMPLES_2013_06_06: [DayRecord; 8] = [
    day_record(1, "ss440c", "440"),
    day_record(2, "ss440c", "440"),
    day_record(3, "ss440c", "440"),
    day_record(4, "ss302", "302"),
    day_record(5, "ss302", "302"),
    day_record(6, "al2017", "Alum"),
    day_record(7, "al2017", "Alum"),
    day_record(8, "ss302", "302"),
];

const fn day_record(
    number: usize,
    material: &'static str,
    authors_label: &'static str,
) -> DayRecord {
    DayRecord {
        number,
        material,
        authors_label,
    }
}

impl DayRecord {
    /// Path of the raw record `2013-06-06_sample<N>_<material>.csv` below the repository root.
    pub fn record_path(&self, root: &Path) -> PathBuf {
        root.join(format!(
            "validation/gauge-records/data/2013-06-06_sample{}_{}.csv",
            self.number, self.material
        ))
    }
}

/// Window of the incident pulse in a record, s after the trigger.
pub const INCIDENT_WINDOW_S: (f64, f64) = (-10e-6, 250e-6);

/// The incident pulse of a record as the calibration reads it: baseline = mean of the first
/// [`BASELINE_SAMPLES`] samples, bar stress (compression positive) through the set-up's `incident` channel,
/// [`INCIDENT_WINDOW_S`] after the trigger. Returns (time s, stress Pa).
pub fn incident_pulse(a: &Apparatus, record: &Path) -> Result<(Vec<f64>, Vec<f64>)> {
    let e = a.material.youngs_modulus_pa;
    let ch = a.gauges.channel("incident").ok_or_else(|| Error::Input {
        file: a.source.clone(),
        key: "gauges".into(),
        problem: "no `incident` channel in the gauge set-up".into(),
        allowed: "a channel named incident".into(),
    })?;
    let r = RawRecord::read(record)?;
    let v = shpb_core::gauge::remove_baseline(&r.incident_v, BASELINE_SAMPLES);
    Ok(r.time_s
        .iter()
        .zip(&v)
        .filter(|(t, _)| (INCIDENT_WINDOW_S.0..=INCIDENT_WINDOW_S.1).contains(*t))
        .map(|(&t, &v)| (t, -e * ch.strain_from_voltage(v)))
        .unzip())
}

/// Effective mass between the bar faces (docs/physics.md §7.5, "Mass between the faces"): a mass m
/// between a face and the contact makes the 2-wave front force exceed the contact's by m a_front
/// and the 1-wave back force fall short of it by m a_back, so F_front − F_back = m (a_front +
/// a_back) and, from rest, ∫₀ᵗ (F_front − F_back) dt = m (v_front + v_back). Returns the
/// least-squares m, kg, of that relation over the first `samples` samples (trapezoidal integral,
/// step `dt_s`), with v_back = F_back/Z and v_front = δ̇ + v_back (Z = E A/c0 of the bars), and
/// the R² of the integral it explains; None for fewer than three samples or a degenerate fit.
pub fn effective_mass_kg(
    dt_s: f64,
    force_front_n: &[f64],
    force_back_n: &[f64],
    approach_velocity_m_s: &[f64],
    impedance_kg_s: f64,
    samples: usize,
) -> Option<(f64, f64)> {
    let n = samples
        .min(force_front_n.len())
        .min(force_back_n.len())
        .min(approach_velocity_m_s.len());
    if n < 3 {
        return None;
    }
    let imbalance: Vec<f64> = (0..n).map(|k| force_front_n[k] - force_back_n[k]).collect();
    let mut impulse = vec![0.0; n];
    for k in 1..n {
        impulse[k] = impulse[k - 1] + 0.5 * dt_s * (imbalance[k - 1] + imbalance[k]);
    }
    let speeds: Vec<f64> = (0..n)
        .map(|k| approach_velocity_m_s[k] + 2.0 * force_back_n[k] / impedance_kg_s)
        .collect();
    let m = shpb_core::numeric::least_squares(&[&speeds], &impulse)?[0];
    let total: f64 = impulse.iter().map(|y| y * y).sum();
    let residual: f64 = impulse
        .iter()
        .zip(&speeds)
        .map(|(y, s)| (y - m * s).powi(2))
        .sum();
    (total > 0.0).then(|| (m, 1.0 - residual / total))
}

/// RMS front/back imbalance of a reduction over its pulse: F_front − F_back where F_3wave exceeds
/// 20 % of its peak, relative to that peak: a whole-loading measure of equilibrium
/// (docs/physics.md §7.5).
pub fn imbalance_rms(r: &Reduction) -> f64 {
    let peak = r.force_3wave_n.iter().copied().fold(0.0, f64::max);
    let d: Vec<f64> = (0..r.time_s.len())
        .filter(|&k| r.force_3wave_n[k] > 0.2 * peak)
        .map(|k| r.force_front_n[k] - r.force_back_n[k])
        .collect();
    (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt() / peak
}

/// Pre-trigger samples whose mean is each record channel's baseline (90 µs at 10 MHz).
pub const BASELINE_SAMPLES: usize = 900;

/// Width of the centred moving average applied to the records before their pulse metrics, s
/// (2 µs: the records' 0.16 mV noise would otherwise add ≈ 2σ to a peak; the simulated signals
/// are noise-free and are not smoothed).
const RECORD_SMOOTHING_S: f64 = 2e-6;

/// Threshold on |incident peak error|: the 15 % tolerance of the gun and shaper calibration on
/// these records (validation/pulse/REPORT.md); achieved ≤ 9.1 %.
const INCIDENT_PEAK_MAX: f64 = 0.15;

/// Threshold on |reflected peak error|: achieved ≤ 7.7 % for seven records and 19.6 % for
/// sample 2, whose recorded reflected pulse is nearly as large as its incident one while its
/// incident and transmitted peaks agree with the simulation within 4 %.
const REFLECTED_PEAK_MAX: f64 = 0.20;

/// Threshold on |transmitted peak error|: the 12 % guide of the Fig. 4 comparison; achieved ≤ 8 %.
const TRANSMITTED_PEAK_MAX: f64 = 0.12;

/// Threshold on |error of the reflected pulse's return after the incident one| (10 % feet): the
/// simulation is systematically 13–16 µs late, because the records' reflected pulses return
/// earlier than the stated incident-gauge distance predicts (validation/gauge-records/REPORT.md).
const REFLECTED_DELAY_MAX_S: f64 = 20e-6;

/// Threshold on |error of the transmitted pulse's arrival after the incident one| (10 % feet):
/// achieved 7.5–26.7 µs late (the geometric offset above, half of it on this path, plus a
/// record-to-record scatter of 16 µs in the measured delay that the model does not have).
const TRANSMITTED_DELAY_MAX_S: f64 = 30e-6;

/// The three pulses of a two-channel signal, stress compression-positive.
#[derive(Debug, Clone, Copy)]
pub struct Pulses {
    /// The first compressive pulse of the incident gauge.
    pub incident: PulseMetrics,
    /// The tensile pulse of the incident gauge 150–500 µs after the incident one's 10 % foot.
    pub reflected: PulseMetrics,
    /// The compressive pulse of the transmission gauge 100–550 µs after it.
    pub transmitted: PulseMetrics,
}

/// Bar stresses (compression positive) at the two gauges of a test, on one time axis.
#[derive(Debug, Clone)]
pub struct GaugeStresses {
    /// Time, s (a record's: from its trigger; a simulation's: from the impact).
    pub time_s: Vec<f64>,
    /// Incident gauge, Pa.
    pub incident_pa: Vec<f64>,
    /// Transmission gauge, Pa.
    pub transmission_pa: Vec<f64>,
}

impl GaugeStresses {
    /// A raw record read as this case reads it: strains through the set-up's channels
    /// (`record_strains`, baseline = mean of the first [`BASELINE_SAMPLES`]), σ = −E ε, smoothed
    /// by a centred moving average of `RECORD_SMOOTHING_S` (the records' noise would otherwise
    /// add ≈ 2σ to each peak).
    pub fn of_record(apparatus: &Apparatus, path: &Path) -> Result<GaugeStresses> {
        let e = apparatus.material.youngs_modulus_pa;
        let rec = RawRecord::read(path)?;
        let strains = record_strains(&rec, apparatus, BASELINE_SAMPLES)?;
        let half = (RECORD_SMOOTHING_S / rec.sample_interval_s() / 2.0).round() as usize;
        let stress =
            |s: &[f64]| -> Vec<f64> { smooth(&s.iter().map(|x| -e * x).collect::<Vec<_>>(), half) };
        Ok(GaugeStresses {
            incident_pa: stress(&strains.incident_strain),
            transmission_pa: stress(&strains.transmission_strain),
            time_s: rec.time_s,
        })
    }

    /// The noise-free gauge strains of a simulated test (its `incident` and `transmission`
    /// gauges), σ = −E ε with `e` the bars' modulus; `source` names the run in errors.
    pub fn of_run(output: &RunOutput, e: f64, source: &str) -> Result<GaugeStresses> {
        let gauge = |name: &str| -> Result<Vec<f64>> {
            output
                .gauges
                .iter()
                .find(|g| g.name == name)
                .map(|g| g.strain.iter().map(|x| -e * x).collect())
                .ok_or_else(|| Error::Input {
                    file: source.into(),
                    key: "gauges".into(),
                    problem: format!("the run has no `{name}` gauge"),
                    allowed: "a set-up with incident and transmission gauges".into(),
                })
        };
        Ok(GaugeStresses {
            time_s: output.time_s.clone().unwrap_or_default(),
            incident_pa: gauge("incident")?,
            transmission_pa: gauge("transmission")?,
        })
    }

    /// The largest transmitted stress in the transmitted pulse's window (100–550 µs after the
    /// incident pulse's 10 % foot), Pa: [`Pulses::transmitted`]'s peak, also where that pulse
    /// has not ended inside the window.
    pub fn transmitted_peak_pa(&self, source: &str) -> Result<f64> {
        let t0 = incident_pulse_of(&self.time_s, &self.incident_pa)
            .map_err(|what| Error::Input {
                file: source.into(),
                key: what.into(),
                problem: "not found".into(),
                allowed: "signals with an incident pulse".into(),
            })?
            .start_10_s;
        Ok(self
            .time_s
            .iter()
            .zip(&self.transmission_pa)
            .filter(|(t, _)| (t0 + 100e-6..=t0 + 550e-6).contains(*t))
            .map(|(_, v)| *v)
            .fold(f64::NEG_INFINITY, f64::max))
    }

    /// Its incident, reflected and transmitted pulses; `source` names the signal in errors.
    pub fn pulses(&self, source: &str) -> Result<Pulses> {
        pulses(&self.time_s, &self.incident_pa, &self.transmission_pa).map_err(|what| {
            Error::Input {
                file: source.into(),
                key: what.into(),
                problem: "not found (or cut off by the end of the signal)".into(),
                allowed: "signals with incident, reflected and transmitted pulses".into(),
            }
        })
    }
}

/// The virtual test of `sample`'s material and pressure, `validation/fig4-virtual-shpb/<scene>.toml`
/// below `root`, with its striker velocity and pulse shaper replaced when given (e.g. by a
/// shaper and gun line fitted elsewhere: `shaper_loo`).
pub fn virtual_test(
    root: &Path,
    sample: &Sample,
    striker_velocity_m_s: Option<f64>,
    shaper: Option<PulseShaper>,
) -> Result<RunOutput> {
    let path = root.join(format!(
        "validation/fig4-virtual-shpb/{}.toml",
        sample.scene
    ));
    let mut params = Params::from_file(&path)?;
    if let SceneParams::Pulse {
        options, apparatus, ..
    } = &mut params.params
    {
        if let Some(v) = striker_velocity_m_s {
            options.striker_velocity_m_s = v;
        }
        if shaper.is_some() {
            options.shaper = shaper;
        }
        // An exponential shaper's pulse starts later than the scene's disc's: the run is longer
        // by as much (the scene's own default end time does the same).
        if let Some(s) = shaper {
            options.end_time_s += apparatus.shaper_onset_delay_s(&s, options.striker_velocity_m_s);
        }
    }
    params.run().map_err(Error::from)
}

/// Metrics of the largest pulse of `y` (positive) between `t0` and `t1`.
fn pulse_in(t: &[f64], y: &[f64], t0: f64, t1: f64) -> Option<PulseMetrics> {
    let (a, b) = (
        t.partition_point(|&x| x < t0),
        t.partition_point(|&x| x <= t1),
    );
    if b <= a + 2 {
        return None;
    }
    pulse_metrics(&t[a..b], &y[a..b], false)
}

/// The incident pulse (compressive, around the first sample above 30 % of the channel's largest
/// compression) of compression-positive stresses `inc` on the times `t`.
fn incident_pulse_of(t: &[f64], inc: &[f64]) -> std::result::Result<PulseMetrics, &'static str> {
    let peak = inc.iter().copied().fold(0.0, f64::max);
    let i = inc
        .iter()
        .position(|&v| v > 0.3 * peak)
        .ok_or("incident pulse")?;
    pulse_in(t, inc, t[i] - 60e-6, t[i] + 200e-6).ok_or("incident pulse")
}

/// Finds incident (compressive), reflected (tensile, incident channel) and transmitted
/// (compressive) pulses; `inc` and `tra` are compression-positive stresses on the times `t`.
fn pulses(t: &[f64], inc: &[f64], tra: &[f64]) -> std::result::Result<Pulses, &'static str> {
    let incident = incident_pulse_of(t, inc)?;
    let t0 = incident.start_10_s;
    let tension: Vec<f64> = inc.iter().map(|v| -v).collect();
    let reflected = pulse_in(t, &tension, t0 + 150e-6, t0 + 500e-6).ok_or("reflected pulse")?;
    let transmitted = pulse_in(t, tra, t0 + 100e-6, t0 + 550e-6).ok_or("transmitted pulse")?;
    Ok(Pulses {
        incident,
        reflected,
        transmitted,
    })
}

/// Centred moving average over `half`·2 + 1 samples.
fn smooth(y: &[f64], half: usize) -> Vec<f64> {
    let mut prefix = vec![0.0; y.len() + 1];
    for (i, v) in y.iter().enumerate() {
        prefix[i + 1] = prefix[i] + v;
    }
    (0..y.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(y.len()));
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Times relative to `t0` and values, restricted to −20 … 520 µs around it.
fn window(t: &[f64], y: &[f64], t0: f64) -> (Vec<f64>, Vec<f64>) {
    t.iter()
        .zip(y)
        .filter(|(x, _)| (-20e-6..=520e-6).contains(&(**x - t0)))
        .map(|(x, v)| (x - t0, *v))
        .unzip()
}

/// Runs the case (module docs).
pub fn run(ctx: &Context) -> Result<CaseResult> {
    let apparatus = Apparatus::from_file(&ctx.path("bars/authors.toml"))?;
    let e = apparatus.material.youngs_modulus_pa;
    let runs = ctx.virtual_runs()?;
    let mut checks = Vec::new();
    let mut rows = Vec::new();
    let mut panels = Vec::new();
    for sample in SAMPLES {
        let (n, label, stem) = (sample.number, sample.label, sample.scene);
        let path = sample.record_path(&ctx.path(""));
        let rec = GaugeStresses::of_record(&apparatus, &path)?;
        let run = runs
            .iter()
            .find(|r| r.stem == stem)
            .expect("every virtual scene was run");
        let source = format!("validation/fig4-virtual-shpb/{stem}.toml");
        let sim = GaugeStresses::of_run(&run.output, e, &source)?;
        let m = rec.pulses(&path.display().to_string())?;
        let s = sim.pulses(&format!("simulation of {source}"))?;
        let err = |a: &PulseMetrics, b: &PulseMetrics| a.peak / b.peak - 1.0;
        let delay = |p: &Pulses| p.transmitted.start_10_s - p.incident.start_10_s;
        let reflected_delay = |p: &Pulses| p.reflected.start_10_s - p.incident.start_10_s;
        let e_reflected_delay = reflected_delay(&s) - reflected_delay(&m);
        let (e_inc, e_ref, e_tra) = (
            err(&s.incident, &m.incident),
            err(&s.reflected, &m.reflected),
            err(&s.transmitted, &m.transmitted),
        );
        let e_delay = delay(&s) - delay(&m);
        let tag = format!("sample {n} ({label})");
        for (what, value, unit, limit) in [
            (
                "incident peak error",
                e_inc,
                Unit::Percent,
                INCIDENT_PEAK_MAX,
            ),
            (
                "reflected peak error",
                e_ref,
                Unit::Percent,
                REFLECTED_PEAK_MAX,
            ),
            (
                "transmitted peak error",
                e_tra,
                Unit::Percent,
                TRANSMITTED_PEAK_MAX,
            ),
            (
                "reflected return error",
                e_reflected_delay,
                Unit::Microseconds,
                REFLECTED_DELAY_MAX_S,
            ),
            (
                "transmitted arrival error",
                e_delay,
                Unit::Microseconds,
                TRANSMITTED_DELAY_MAX_S,
            ),
        ] {
            checks.push(Check::at_most(
                format!("{tag}: |{what}|"),
                value.abs(),
                unit,
                limit,
            ));
        }
        rows.push(format!(
            "| {n} | {label} | {:.1} / {:.1} | {} | {:.1} / {:.1} | {} | {:.1} / {:.1} | {} | {:.1} / {:.1} | {:+.1} | {:.1} / {:.1} | {:+.1} | {:+.1} | {:.1} / {:.1} |",
            m.incident.peak / 1e6,
            s.incident.peak / 1e6,
            pct(e_inc),
            m.reflected.peak / 1e6,
            s.reflected.peak / 1e6,
            pct(e_ref),
            m.transmitted.peak / 1e6,
            s.transmitted.peak / 1e6,
            pct(e_tra),
            delay(&m) * 1e6,
            delay(&s) * 1e6,
            e_delay * 1e6,
            reflected_delay(&m) * 1e6,
            reflected_delay(&s) * 1e6,
            e_reflected_delay * 1e6,
            (e_delay - 0.5 * e_reflected_delay) * 1e6,
            m.transmitted.rise_10_90_s * 1e6,
            s.transmitted.rise_10_90_s * 1e6,
        ));
        let (t0r, t0s) = (m.incident.start_10_s, s.incident.start_10_s);
        let (a, b) = window(&rec.time_s, &rec.incident_pa, t0r);
        let (c, d) = window(&sim.time_s, &sim.incident_pa, t0s);
        let (f, g) = window(&rec.time_s, &rec.transmission_pa, t0r);
        let (h, k) = window(&sim.time_s, &sim.transmission_pa, t0s);
        panels.push(Panel {
            title: format!("2013-05-22 sample {n}: {label}"),
            x_label: "time from the incident pulse's 10 % foot (µs)".into(),
            y_label: "bar stress, compression positive (MPa)".into(),
            x_scale: 1e6,
            y_scale: 1e-6,
            series: vec![
                Series::new("incident gauge, record", a, b, Style::Dashed(0)),
                Series::new("incident gauge, simulated", c, d, Style::Line(1)),
                Series::new("transmission gauge, record", f, g, Style::Dashed(3)),
                Series::new("transmission gauge, simulated", h, k, Style::Line(4)),
            ],
        });
    }

    let mut md = String::new();
    let _ = writeln!(
        md,
        "**Set-up.** For each real record of 2013-05-22 (`validation/gauge-records/data/`, 10 MHz, \
         copper shaper) the virtual test of the same material and gun pressure \
         (`validation/fig4-virtual-shpb/`) gives the gauge strains (noise-free, 2 mm gauge grids). \
         The records are read through `bars/gauges-authors.toml` (full Poisson bridge behind gain \
         2, i.e. half the authors' formula; baseline = mean of the first 900 samples) and smoothed \
         by a {:.0} µs moving average (their 0.16 mV noise would add ≈ 2σ to each peak); stresses \
         σ = −E ε, compression positive. Both are aligned at the incident pulse's 10 % foot (the \
         record's trigger time and the simulation's impact time are unrelated).\n",
        RECORD_SMOOTHING_S * 1e6
    );
    let _ = writeln!(
        md,
        "**Metrics.** Relative errors of the peak stresses (simulated / recorded − 1) of the \
         incident pulse, of the reflected pulse (incident gauge, tension) and of the transmitted \
         pulse; and the errors of the reflected pulse's return and of the transmitted pulse's arrival: \
         (10 % foot of the reflected or transmitted pulse − 10 % foot of the incident pulse), \
         simulated minus recorded.\n"
    );
    let _ = writeln!(
        md,
        "| sample | test | incident peak rec / sim (MPa) | error | reflected peak rec / sim (MPa) | error | transmitted peak rec / sim (MPa) | error | transmitted delay rec / sim (µs) | error (µs) | reflected delay rec / sim (µs) | error (µs) | transmitted error − ½ reflected error (µs) | transmitted rise 10–90 % rec / sim (µs) |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in &rows {
        let _ = writeln!(md, "{r}");
    }
    let _ = writeln!(
        md,
        "\n**Thresholds and findings.** *Incident peak* within {:.0} % — the tolerance of the gun \
         and shaper calibration on these same records (validation/pulse/REPORT.md), re-checked \
         here through the full test with the spheres in place. *Transmitted peak* within {:.0} % \
         (the guide of the Fig. 4 comparison; achieved ≤ 8 %): the transmitted pulse carries the \
         contact law's error, the calibration's and the shot-to-shot scatter. *Reflected peak* \
         within {:.0} %: seven records agree within 8 %; sample 2's recorded reflected pulse \
         (87 MPa) is nearly as large as its incident pulse (90 MPa) although its transmitted \
         pulse (41 MPa) matches the simulation within 4 % — a record the simulation cannot \
         follow (a reflection that large leaves almost no force on the front face while the back \
         face carries 12 kN), so the threshold is set above it rather than excluding it. \
         **Timing is the weak point.** The simulated reflected pulse returns 13–16 µs later than \
         the recorded one in every test: the records' reflected feet come earlier than twice the \
         stated incident-gauge distance over c0 (validation/gauge-records/REPORT.md, *The records' \
         own reflected delay*), the simulation uses the stated geometry, and the cause (gauge \
         position, c0, or the timing of the reflection at the spheres) is not known, so no input \
         was changed. The transmitted pulse arrives 7.5–27 µs late: half of the geometric offset \
         applies to its path, and the recorded transmitted delays scatter by 16 µs between tests \
         of one geometry (209–225 µs) while the simulated ones stay within 233–236 µs (the column \
         *transmitted error − ½ reflected error* is what remains, 1–20 µs). The arrival \
         thresholds ({:.0} µs reflected, {:.0} µs transmitted) state this gap and guard it against \
         growing; they are not a claim of timing agreement.\n",
        INCIDENT_PEAK_MAX * 100.0,
        TRANSMITTED_PEAK_MAX * 100.0,
        REFLECTED_PEAK_MAX * 100.0,
        REFLECTED_DELAY_MAX_S * 1e6,
        TRANSMITTED_DELAY_MAX_S * 1e6
    );
    Ok(CaseResult {
        name: "gauge-records",
        title: "simulated gauge signals against the real records of 2013-05-22".into(),
        checks,
        section: md,
        figure: Figure {
            legend: Legend::LowerRight,
            caption: "Gauge signals of the eight 2013-05-22 tests: records (dashed; incident \
                      gauge dark red, transmission gauge blue) and the virtual test of the same \
                      material and pressure (solid; incident orange, transmission green), aligned \
                      at the incident pulse's 10 % foot."
                .into(),
            columns: 4,
            panels,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn effective_mass_recovers_the_mass_between_the_faces() {
        // Two rigid inserts of 50 g between the bars (Z = 11.25 kg/ms): the transmission bar's
        // face moves at F_back/Z (a half sine), the front face faster by a made-up approach rate;
        // the contact force is the back face's plus the back insert's inertia, the front face's
        // the contact's plus the front insert's.
        let (m, z, dt) = (0.050, 11_250.0, 1e-7);
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let period = n as f64 * dt;
        let back: Vec<f64> = t
            .iter()
            .map(|t| 1e4 * (std::f64::consts::PI * t / period).sin())
            .collect();
        let approach: Vec<f64> = t
            .iter()
            .map(|t| 2.0 * (2.0 * std::f64::consts::PI * t / period).sin().max(0.0))
            .collect();
        let v_back: Vec<f64> = back.iter().map(|f| f / z).collect();
        let v_front: Vec<f64> = v_back.iter().zip(&approach).map(|(b, a)| b + a).collect();
        let accel = |v: &[f64], k: usize| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (v[b] - v[a]) / ((b - a) as f64 * dt)
        };
        let contact: Vec<f64> = (0..n).map(|k| back[k] + m * accel(&v_back, k)).collect();
        let front: Vec<f64> = (0..n)
            .map(|k| contact[k] + m * accel(&v_front, k))
            .collect();
        let (fit, r2) = effective_mass_kg(dt, &front, &back, &approach, z, n).expect("a fit");
        // Centred differences and the trapezoidal integral: O(Δt²) over 2000 samples.
        assert_relative_eq!(fit, m, max_relative = 1e-3);
        assert!(r2 > 0.999_99, "R² = {r2}");
        // No mass: balanced faces give m = 0 (and R² = 0: nothing to explain but rounding).
        assert_eq!(effective_mass_kg(dt, &back, &back, &approach, z, n), None);
        // A front force lagging the back one reads as a negative mass.
        let lag = 100;
        let lagging: Vec<f64> = (0..n).map(|k| back[k.saturating_sub(lag)]).collect();
        let (neg, _) = effective_mass_kg(dt, &lagging, &back, &approach, z, n).expect("a fit");
        assert!(neg < 0.0, "lagging front force: m = {neg}");
    }
}

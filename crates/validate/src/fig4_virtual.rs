//! Case `fig4-virtual-shpb`: the full virtual SHPB test (calibrated gas gun and copper shaper,
//! the authors' bars, two spheres with the paper's law, gauges, the lab's reduction of the
//! simulated records) for the nine scenes of `validation/fig4-virtual-shpb/`, and the SS440c 10
//! and 12.5 psi tests as we infer the Fig. 4 records were shot (20 cm striker, no shaper; README
//! "How was a test shot?"), against the eight
//! measured Fig. 4 records: peak force and displacement at peak force.

use crate::figure::{Figure, Legend, Panel, Series, Style};
use crate::gauge_records::SAMPLES;
use crate::{CaseResult, Check, Context, Unit, VirtualRun};
use rayon::prelude::*;
use shpb_core::apparatus::Apparatus;
use shpb_core::scene::{Params, SceneParams};
use shpb_core::solver;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::fmt::Write as _;

/// (label, scene stem, stem of the Fig. 4 record of the same material and pressure in
/// `validation/fig4-force-driven/`, if there is one) of the virtual tests: the nine with the
/// 2013-05-22 set-up (10 cm striker, copper shaper) and the two SS440c tests we infer from the
/// Fig. 4 records' energy and momentum were shot with a 20 cm striker and no shaper (docs/physics.md
/// §6.4 "Which striker").
pub(crate) const SCENES: [(&str, &str, &str); 11] = [
    ("SS440c 10 psi", "ss440c-10psi", "ss440c-10psi"),
    ("SS440c 12.5 psi", "ss440c-12p5psi", "ss440c-12p5psi"),
    ("SS440c 15 psi", "ss440c-15psi", "ss440c-15psi"),
    ("SS302 10 psi", "ss302-10psi", "ss302-10psi"),
    ("SS302 12.5 psi", "ss302-12p5psi", "ss302-12p5psi"),
    ("SS302 15 psi", "ss302-15psi", "ss302-15psi"),
    ("Al2017 10 psi", "al2017-10psi", "al2017-10psi"),
    ("Al2017 12.5 psi", "al2017-12p5psi", "al2017-12p5psi"),
    ("Al2017 15 psi", "al2017-15psi", "al2017-15psi"),
    (
        "SS440c 10 psi, 20 cm striker (inferred set-up)",
        "ss440c-10psi-20cm-striker",
        "ss440c-10psi",
    ),
    (
        "SS440c 12.5 psi, 20 cm striker (inferred set-up)",
        "ss440c-12p5psi-20cm-striker",
        "ss440c-12p5psi",
    ),
];

/// Accepted band of reduced / measured peak force and δ at peak for the tests run as the Fig. 4
/// records were shot: ±10 %, the accuracy of the paper's law on the same records in the
/// force-driven DEM (fig4-force-driven: SS440c δ at peak within 2–4 %, RMS over loading 5–11 %).
/// Achieved 0.99–1.07.
const AS_SHOT_RATIO: (f64, f64) = (0.90, 1.10);

/// Accepted band of (reduced peak force) / (measured peak force) for the 2013-05-22 set-up: ±20 %.
/// Achieved 0.82–1.01; the low end is SS440c at 10 and 12.5 psi, whose Fig. 4 records were shot
/// with a 20 cm striker and no shaper (a different test: see the as-shot rows), and the real
/// 2013-05-22 tests at one nominal pressure scatter by up to 16 % from the Fig. 4 ones.
const FORCE_RATIO: (f64, f64) = (0.80, 1.20);

/// Accepted band of (reduced δ at peak force) / (measured δ at peak force): ±15 %. Achieved
/// 0.86–1.13 (Al2017 high, as in the force-driven DEM: the law, not the apparatus).
const DELTA_RATIO: (f64, f64) = (0.85, 1.15);

/// Runs the scenes (in parallel).
pub(crate) fn run_scenes(ctx: &Context) -> Result<Vec<VirtualRun>> {
    SCENES
        .par_iter()
        .map(|&(_, stem, _)| {
            let path = ctx.path(&format!("validation/fig4-virtual-shpb/{stem}.toml"));
            let output = Params::from_file(&path)?.run()?;
            Ok(VirtualRun { stem, output })
        })
        .collect()
}

/// A measured Fig. 4 record: time (s), δ with its offset removed (m), force (N).
pub(crate) struct Measured {
    time_s: Vec<f64>,
    displacement_m: Vec<f64>,
    force_n: Vec<f64>,
}

/// The measured Fig. 4 record of a stem, if there is one.
pub(crate) fn measured(ctx: &Context, stem: &str) -> Result<Option<Measured>> {
    let path = ctx.path(&format!("validation/fig4-force-driven/{stem}.toml"));
    if !path.is_file() {
        return Ok(None);
    }
    let params = Params::from_file(&path)?;
    match params.params {
        SceneParams::ForceDriven {
            setup,
            measured_displacement_m: Some(d),
        } => Ok(Some(Measured {
            time_s: setup.drive.time_s,
            displacement_m: d.iter().map(|x| x - d[0]).collect(),
            force_n: setup.drive.force_n,
        })),
        _ => Err(Error::Input {
            file: params.source,
            key: "force_csv".into(),
            problem: "not a force-driven scene with a measured displacement".into(),
            allowed: "a force-driven scene whose CSV has displacement_m".into(),
        }),
    }
}

/// Margin on (implied energy) / (most the 10 cm striker can give) that tells the striker apart:
/// the implied energy of a simulated test is within 1.6 % of the true one (tests/reduce.rs), so
/// 5 % is well clear of the estimate's error. Achieved 1.18–1.25 for the two 20 cm records,
/// ≤ 0.93 for the others.
const STRIKER_MARGIN: f64 = 0.05;

/// Band on (implied energy) / (20 cm striker's kinetic energy): the calibrated gun reproduces
/// the 2013-05-22 pulse energies within 8 % (validation/pulse/REPORT.md), so ±10 %. Achieved
/// 0.97–1.00.
const GUN_ENERGY_TOLERANCE: f64 = 0.10;

/// Checks which striker each Fig. 4 record was shot with, from the incident pulse its force and
/// approach imply (`reduce::implied_incident`): momentum and energy conservation bound the
/// energy a striker of mass m at the gun's velocity v can give with the record's impulse I,
/// m (v² − (v − I/m)²)/2, whatever a shaper does.
fn which_striker(ctx: &Context, checks: &mut Vec<Check>, md: &mut String) -> Result<()> {
    let short = Apparatus::from_file(&ctx.path("bars/authors.toml"))?;
    let long = Apparatus::from_file(&ctx.path("bars/authors-20cm-striker.toml"))?;
    let bar = shpb_core::reduce::ReductionSetup::from_apparatus(&short)?.incident_bar;
    let velocity = |a: &Apparatus, psi: f64| -> Result<f64> {
        Ok(a.striker_velocity_m_s(psi * shpb_core::striker::PSI_PA)?)
    };
    let _ = writeln!(
        md,
        "\n**Which striker.** The incident pulse each Fig. 4 record implies \
         (`shpb::reduce::implied_incident`, σI = F/A + ρ c0 δ̇/2; `shpb incident RECORD.csv \
         --pressure P` prints it) carries impulse I and energy E. A striker of mass m at the \
         gun's velocity v that gives impulse I keeps m (v − I/m)²/2, so E ≤ m (v² − (v − I/m)²)/2 \
         whatever a shaper does. The SS440c 10 and 12.5 psi records break that bound for the \
         10 cm striker of `bars/authors.toml` and carry the energy, and the 2 L/c0 width, of the \
         20 cm striker of `bars/authors-20cm-striker.toml` (same gun, same work); the other \
         records are within it.\n"
    );
    for &(label, _, record) in SCENES.iter().filter(|s| s.1 == s.2) {
        let Some(m) = measured(ctx, record)? else {
            continue;
        };
        let Some(pulse) = shpb_core::reduce::implied_incident(
            &m.time_s,
            &m.displacement_m,
            &m.force_n,
            &bar,
            IMPLIED_SMOOTHING_S,
        ) else {
            continue;
        };
        // The Fig. 4 records are of the same materials and pressures as the 2013-05-22 ones.
        let Some(psi) = SAMPLES.iter().find(|s| s.scene == record).map(|s| s.psi) else {
            continue;
        };
        // A record has an as-shot scene (second stem) when it was shot with the 20 cm striker.
        let shot_with_20cm_striker = SCENES.iter().any(|s| s.2 == record && s.1 != s.2);
        let (v, mass) = (velocity(&short, psi)?, short.striker_mass_kg());
        let most = shpb_core::striker::most_pulse_energy_j(mass, v, pulse.impulse_n_s);
        let metric = format!(
            "{label}: implied incident energy / most the 10 cm striker can give with its impulse"
        );
        let ratio = pulse.energy_j / most;
        if shot_with_20cm_striker {
            checks.push(Check::at_least(
                metric,
                ratio,
                Unit::Ratio,
                1.0 + STRIKER_MARGIN,
            ));
            let (vl, ml) = (velocity(&long, psi)?, long.striker_mass_kg());
            checks.push(Check::between(
                format!("{label}: implied incident energy / 20 cm striker's kinetic energy"),
                pulse.energy_j / (0.5 * ml * vl * vl),
                Unit::Ratio,
                1.0 - GUN_ENERGY_TOLERANCE,
                1.0 + GUN_ENERGY_TOLERANCE,
            ));
            let c0 = bar.wave_speed_m_s;
            checks.push(Check::between(
                format!("{label}: implied pulse width at half peak / 2 L/c0 of the 20 cm striker"),
                pulse.duration_half_s / (2.0 * long.striker.length_m / c0),
                Unit::Ratio,
                1.0 - STRIKER_MARGIN,
                1.0 + STRIKER_MARGIN,
            ));
        } else {
            checks.push(Check::at_most(metric, ratio, Unit::Ratio, 1.0));
        }
    }
    Ok(())
}

/// Central-difference span of the implied incident pulses, s.
const IMPLIED_SMOOTHING_S: f64 = 4e-6;

/// Runs the case (module docs).
pub fn run(ctx: &Context) -> Result<CaseResult> {
    let runs = ctx.virtual_runs()?;
    let mut checks = Vec::new();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "**Set-up.** `validation/fig4-virtual-shpb/<material>-<psi>.toml`: the whole virtual test \
         (`kind = \"shpb\"`, `bars/authors.toml`: gas gun and copper shaper calibrated on the \
         2013-05-22 incident pulses, validation/pulse/REPORT.md; 1 mm cells, no bar dispersion; \
         two 6.35 mm spheres with the rate-dependent law; gauges digitised with the records' noise \
         and resolution; the lab's reduction of the simulated voltages). *True*: the simulated \
         contact history; *reduced*: what the reduction of the simulated records gives (peak back \
         force, δ at peak force) — what a lab would report, and what the checks use. *Measured*: \
         the Fig. 4 record of the same material and pressure (its δ counted from δ(0)). There is no \
         Fig. 4 record for Al2017 at 10 psi. The last two rows run SS440c at 10 and 12.5 psi as \
         those Fig. 4 records were shot (`<material>-<psi>-20cm-striker.toml`: 20 cm striker, no \
         shaper, Love-rod bars, the reduction dispersion-corrected).\n"
    );
    let _ = writeln!(
        md,
        "| test | F peak true (kN) | reduced | measured | reduced / measured | δ at peak true (µm) | reduced | measured | reduced / measured | equilibrium ratio at peak |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    let mut panels = Vec::new();
    for &(label, stem, record) in &SCENES {
        let as_shot = stem != record; // an as-shot scene of that record
        let (force_band, delta_band) = if as_shot {
            (AS_SHOT_RATIO, AS_SHOT_RATIO)
        } else {
            (FORCE_RATIO, DELTA_RATIO)
        };
        let run = runs
            .iter()
            .find(|r| r.stem == stem)
            .expect("every scene was run");
        let contact = run
            .output
            .contact
            .as_ref()
            .expect("shpb scenes have a contact series");
        let k = contact.peak_index();
        let (f_true, d_true) = (contact.force_n[k], contact.displacement_m[k]);
        let red = run.output.reduction.as_ref();
        let (f_red, d_red, eq) = red
            .map(|r| {
                (
                    r.peak_back_force_n,
                    r.displacement_at_peak_force_m,
                    r.equilibrium_ratio_at_peak,
                )
            })
            .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        let meas = measured(ctx, record)?;
        let mut series = Vec::new();
        match &meas {
            Some(Measured {
                displacement_m: d,
                force_n: f,
                ..
            }) => {
                let j = solver::argmax(f);
                let (fm, dm) = (f[j], d[j]);
                checks.push(Check::between(
                    format!("{label}: peak force, reduced / measured"),
                    f_red / fm,
                    Unit::Ratio,
                    force_band.0,
                    force_band.1,
                ));
                checks.push(Check::between(
                    format!("{label}: δ at peak force, reduced / measured"),
                    d_red / dm,
                    Unit::Ratio,
                    delta_band.0,
                    delta_band.1,
                ));
                let _ = writeln!(
                    md,
                    "| {label} | {:.2} | {:.2} | {:.2} | {:.3} | {:.1} | {:.1} | {:.1} | {:.3} | {:.3} |",
                    f_true / 1e3,
                    f_red / 1e3,
                    fm / 1e3,
                    f_red / fm,
                    d_true * 1e6,
                    d_red * 1e6,
                    dm * 1e6,
                    d_red / dm,
                    eq
                );
                series.push(Series::new(
                    "measured (Fig. 4, offset removed)",
                    d.clone(),
                    f.clone(),
                    Style::Dashed(0),
                ));
            }
            None => {
                let _ = writeln!(
                    md,
                    "| {label} | {:.2} | {:.2} | — | — | {:.1} | {:.1} | — | — | {:.3} |",
                    f_true / 1e3,
                    f_red / 1e3,
                    d_true * 1e6,
                    d_red * 1e6,
                    eq
                );
            }
        }
        series.push(Series::new(
            "virtual test: true contact",
            contact.displacement_m.clone(),
            contact.force_n.clone(),
            Style::Line(1),
        ));
        if let Some(r) = red {
            series.push(Series::new(
                "virtual test: reduced (back force)",
                r.displacement_m.clone(),
                r.force_back_n.clone(),
                Style::Line(3),
            ));
        }
        panels.push(Panel {
            title: label.into(),
            x_label: "sphere approach δ (µm)".into(),
            y_label: "force F (kN)".into(),
            x_scale: 1e6,
            y_scale: 1e-3,
            series,
        });
    }
    which_striker(ctx, &mut checks, &mut md)?;
    let _ = writeln!(
        md,
        "\n**Thresholds.** With the 2013-05-22 set-up (10 cm striker, copper shaper): reduced / \
         measured peak force within {:.2}–{:.2} and δ at peak force within {:.2}–{:.2}, set from \
         what the test achieves (force 0.82–1.01, δ 0.86–1.13) and from the scatter of the real \
         tests. The SS440c 10 and 12.5 psi rows of that set-up are low (force 0.82 and 0.88) \
         because those two Fig. 4 records were not shot with it: the incident pulse they imply \
         (`shpb::reduce::implied_incident`) is the flat 81 µs pulse of a 20 cm striker without a \
         shaper, with that striker's momentum and kinetic energy at the calibrated gun's velocity \
         (validation/fig4-virtual-shpb/REPORT.md); with the shaped set-up the virtual 10 psi test \
         agrees instead with the shaped real 10 psi test (2013-05-22 sample 1: 10.6 kN, virtual \
         10.1 kN). **As shot** (`*-20cm-striker.toml`: `bars/authors-20cm-striker.toml`, the same \
         gun doing the same work on the heavier striker, Love-rod bars, nothing fitted to Fig. 4): \
         both within {:.2}–{:.2}, the accuracy of the paper's law on these records in the \
         force-driven DEM above.\n",
        FORCE_RATIO.0,
        FORCE_RATIO.1,
        DELTA_RATIO.0,
        DELTA_RATIO.1,
        AS_SHOT_RATIO.0,
        AS_SHOT_RATIO.1
    );
    let _ = writeln!(
        md,
        "*Not modelled*: shot-to-shot variation of the gun and of the shaper (a fresh disc per \
         test), the spheres' end inserts and alignment; bar dispersion only in the as-shot \
         (unshaped) tests, where it matters (the shaped 15 psi test moves by 0.1 % with it).\n"
    );
    Ok(CaseResult {
        name: "fig4-virtual-shpb",
        title: "the full virtual SHPB test against the Fig. 4 measurements".into(),
        checks,
        section: md,
        figure: Figure {
            legend: Legend::UpperLeft,
            caption: "Virtual SHPB tests: force against approach, the simulated contact (orange), \
                      the lab's reduction of the simulated gauge records (blue, back force) and \
                      the Fig. 4 measurement of the same material and pressure (dashed)."
                .into(),
            columns: 3,
            panels,
        },
    })
}

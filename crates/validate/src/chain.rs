//! Case `chain`: a free chain of 40 identical elastic Hertz spheres struck by its first sphere
//! carries one solitary wave, against Nesterenko's long-wave solution (speed against peak force,
//! length of about five diameters; *Dynamics of Heterogeneous Materials*, Springer 2001, ch. 1;
//! docs/physics.md §8.1) and the conservation of momentum and energy.

use crate::figure::{Figure, Legend, Panel, Series, Style};
use crate::{CaseResult, Check, Context, Unit};
use rayon::prelude::*;
use shpb_core::contact::{LawKind, LawSpec, Region2Form, Unloading};
use shpb_core::material::Material;
use shpb_core::solver::solitary::{
    self, LENGTH_FORCE_FRACTION, WaveMeasurement, WaveProbe, hertz_chain, identical_contact,
};
use shpb_core::solver::{FreeChainSetup, free_chain, hertz_impact_duration, simulate_chain_with};
use shpb_core::specimen::{Sphere, SphereChain};
use shpb_input::Result;
use shpb_input::prelude::*;
use std::fmt::Write as _;

/// Striking speeds, m/s: peak forces from ≈ 5 N to ≈ 580 N, two decades (F_m ∝ v^{6/5}).
const SPEEDS: [f64; 4] = [0.1, 0.5, 2.0, 5.0];

/// Spheres in the chain (issue 17).
const COUNT: usize = 40;

/// Sphere diameter, m (the paper's spheres).
const DIAMETER_M: f64 = 6.35e-3;

/// Steps per two-sphere Hertz contact time at the striking speed.
const STEPS_PER_CONTACT: f64 = 2000.0;

/// Threshold on |V_s/V_s,Nesterenko − 1| (issue 17).
const SPEED_MAX: f64 = 0.02;

/// Accepted length of the wave at 1e-4 of its peak force, diameters ("about five").
const LENGTH_RANGE: (f64, f64) = (4.5, 5.5);

/// Threshold on the spread of the peak force over contacts 10–35, relative.
const SPREAD_MAX: f64 = 5e-3;

/// Threshold on the largest force behind the leading pulse, relative to its peak.
const TRAILING_MAX: f64 = 0.01;

/// Threshold on the momentum error, relative (round-off).
const MOMENTUM_MAX: f64 = 1e-9;

/// Threshold on the energy error at this step, relative (O(Δt²); ≈ 1.6e-7 at 2000 steps).
const ENERGY_MAX: f64 = 1e-6;

/// One struck chain: its probe, its measurement and the two-sphere contact time.
struct Struck {
    speed_m_s: f64,
    probe: WaveProbe,
    wave: WaveMeasurement,
}

/// Runs the chain struck at `speed_m_s` and measures its wave (speed between contacts 10 and 30,
/// amplitude over 10–35, force history of contact 20).
fn strike(material: &Material, speed_m_s: f64) -> Result<Struck> {
    let props = identical_contact(material, DIAMETER_M);
    let mass = Sphere::full(material.clone(), 0.5 * DIAMETER_M).mass_kg;
    let t_c = hertz_impact_duration(0.5 * mass, props.e_star_pa, props.radius_m, speed_m_s);
    let dt = t_c / STEPS_PER_CONTACT;
    // The pulse moves one diameter in a little less than half a contact time: past contact 37.
    let setup = hertz_chain(material, DIAMETER_M, COUNT, speed_m_s, dt, 37.0 * 0.5 * t_c);
    let mut probe = WaveProbe::new(&props, 19, 10);
    simulate_chain_with(&setup, &mut [&mut probe])?;
    let wave = WaveMeasurement::from_probe(&probe, material, DIAMETER_M, 9..=29, 9..=34);
    Ok(Struck {
        speed_m_s,
        probe,
        wave,
    })
}

/// The same chain through the `chain` scene's solver (`solver::spheres::free_chain`, the pair
/// stepper's scheme over N spheres): (V_s, Nesterenko's V_s at its F_m, peak-force spread over
/// contacts 10–35, momentum drift).
fn strike_free(material: &Material, speed_m_s: f64) -> Result<(f64, f64, f64, f64)> {
    let sphere = Sphere::full(material.clone(), 0.5 * DIAMETER_M);
    let props = identical_contact(material, DIAMETER_M);
    let t_c = hertz_impact_duration(
        0.5 * sphere.mass_kg,
        props.e_star_pa,
        props.radius_m,
        speed_m_s,
    );
    let setup = FreeChainSetup {
        chain: SphereChain {
            spheres: vec![sphere; COUNT],
        },
        law: LawSpec {
            kind: LawKind::Hertz,
            region2: Region2Form::Smooth,
            unloading: Unloading::Static,
        },
        velocity1_m_s: speed_m_s,
        striker: None,
        wall: None,
        dt_s: t_c / STEPS_PER_CONTACT,
        end_time_s: 37.0 * 0.5 * t_c,
        output_every: 1,
        output_every_by_budget: false,
    };
    let r = free_chain(&setup)?;
    let peak_time = |k: usize| r.time_s[shpb_core::numeric::argmax(&r.contact_force_n[k])];
    let v_s = 20.0 * DIAMETER_M / (peak_time(29) - peak_time(9));
    let peaks: Vec<f64> = (9..=34)
        .map(|k| r.contact_force_n[k].iter().copied().fold(0.0, f64::max))
        .collect();
    let (lo, hi) = shpb_core::numeric::min_max(peaks.iter().copied());
    let f_m = peaks[..=20].iter().sum::<f64>() / 21.0;
    let nesterenko = solitary::solitary_wave_speed_m_s(material, DIAMETER_M, f_m);
    Ok((
        v_s,
        nesterenko,
        (hi - lo) / f_m,
        r.momentum_max_relative_drift,
    ))
}

/// Least-squares slope of ln y against ln x.
fn log_slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = x.iter().zip(y).map(|(a, b)| (a.ln(), b.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// `a … b` of a list of values (two decimals, signed if `signed`), or one value when they agree as shown.
fn range_text(values: impl Iterator<Item = f64>, signed: bool) -> String {
    let (lo, hi) = shpb_core::numeric::min_max(values);
    let show = |x: f64| {
        if signed {
            format!("{x:+.2}")
        } else {
            format!("{x:.2}")
        }
    };
    if show(lo) == show(hi) {
        show(lo)
    } else {
        format!("{} … {}", show(lo), show(hi))
    }
}

/// Runs the case (module docs).
pub fn run(_ctx: &Context) -> Result<CaseResult> {
    let material = Material::builtin("ss440c").expect("built-in material");
    let runs = SPEEDS
        .par_iter()
        .map(|&v| strike(&material, v))
        .collect::<Result<Vec<_>>>()?;
    let d = DIAMETER_M;
    let mut checks = Vec::new();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "**Set-up.** {COUNT} SS440c spheres (specimens/ss440c.toml: E 204 GPa, ν 0.28, ρ 7800 \
         kg/m³), 6.35 mm, in a line just touching, every contact elastic Hertz with its own \
         state; the first sphere strikes the others at {} m/s (the chain solver, \
         `solver::chain`, {STEPS_PER_CONTACT} steps per two-sphere Hertz contact time). Measured: \
         the peak force F_m (mean over contacts 10–30; contact k is between spheres k and k + 1), \
         the speed V_s = 20 d / (time between the force peaks at contacts 10 and 30), the length \
         of the pulse (V_s × the time contact 20 carries more than {LENGTH_FORCE_FRACTION:.0e} of \
         its peak) and its width at half maximum. Reference: Nesterenko's long-wave solitary \
         wave V_s = (2/√5) c ξ_m^{{1/4}}, c² = 2E/(πρ(1−ν²)), ξ_m = (F_m/K)^{{2/3}}/d, K = \
         E√d/(3(1−ν²)) (= 0.6802 (2E/(dρ^{{3/2}}(1−ν²)))^{{1/3}} F_m^{{1/6}}), a cos⁴ strain \
         profile 5πd/√10 = 4.97 d long (docs/physics.md §8.1).\n",
        SPEEDS
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        md,
        "**Thresholds.** Speed within {:.0} % of Nesterenko's (issue 17): the discrete pulse, \
         five diameters long, is not a long wave, and its speed sits ≈ 1.2 % above the long-wave \
         limit at every amplitude (the chain scales exactly with F_m; an independent RK4 \
         integration of the scaled lattice gives the same 1.2 %). Length at \
         {LENGTH_FORCE_FRACTION:.0e} of the peak force within {}–{} d (\"about five diameters\": \
         the discrete pulse has super-exponential tails rather than the long-wave profile's \
         compact support, so its length depends on the level it is read at; the long-wave \
         profile gives {:.2} d at that level and 4.97 d at zero). One pulse: the peak force \
         constant within {:.1} % from contact 10 to 35 (the impact transient has decayed below \
         0.1 % by contact 10; a pulse breaking up or shedding a train would lose amplitude), and \
         no force above {:.0} % of the peak once the pulse has passed a contact and it opened. \
         Momentum within {MOMENTUM_MAX:.0e} (each joint force acts equally and oppositely: \
         round-off). Energy (kinetic + Hertz elastic energy at the step's mean approach) within \
         {ENERGY_MAX:.0e}: the chain's Newmark-average contact conserves it to O(Δt²), ≈ 1.6e-7 \
         at this step and the same at every speed (the step is a fixed fraction of the contact \
         time); the core test `solver::solitary` runs the 1 m/s chain at 30 000 steps per \
         contact and holds it to 1e-9 (issue 17), too slow for this fast case.\n",
        SPEED_MAX * 100.0,
        LENGTH_RANGE.0,
        LENGTH_RANGE.1,
        solitary::solitary_wave_length_above_m(1.0, LENGTH_FORCE_FRACTION),
        SPREAD_MAX * 100.0,
        TRAILING_MAX * 100.0,
    );
    let _ = writeln!(
        md,
        "| v (m/s) | F_m (N) | V_s (m/s) | Nesterenko (m/s) | error | length (d) | FWHM (d) | spread 10–35 | trailing / F_m | energy left in spheres 1–20 | momentum error | energy error |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let fwhm_theory = solitary::solitary_wave_length_above_m(d, 0.5);
    let (mut spread, mut trailing, mut momentum, mut energy, mut behind) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for r in &runs {
        let w = &r.wave;
        checks.push(Check::at_most(
            format!("{} m/s: |V_s / Nesterenko − 1|", r.speed_m_s),
            w.speed_error().abs(),
            Unit::Percent,
            SPEED_MAX,
        ));
        checks.push(Check::between(
            format!(
                "{} m/s: length at {LENGTH_FORCE_FRACTION:.0e} F_m / d",
                r.speed_m_s
            ),
            w.length_m / d,
            Unit::Ratio,
            LENGTH_RANGE.0,
            LENGTH_RANGE.1,
        ));
        spread = spread.max(w.amplitude_spread);
        trailing = trailing.max(w.trailing_force_ratio);
        momentum = momentum.max(r.probe.momentum_relative_error());
        energy = energy.max(r.probe.energy_relative_error());
        behind = behind.max(r.probe.energy_fraction_in_first(20));
        let _ = writeln!(
            md,
            "| {} | {:.1} | {:.1} | {:.1} | {} | {:.2} | {:.2} | {:.1e} | {:.1e} | {:.2} % | {:.1e} | {:.1e} |",
            r.speed_m_s,
            w.max_force_n,
            w.speed_m_s,
            w.nesterenko_speed_m_s,
            crate::pct(w.speed_error()),
            w.length_m / d,
            w.half_max_width_m / d,
            w.amplitude_spread,
            w.trailing_force_ratio,
            100.0 * r.probe.energy_fraction_in_first(20),
            r.probe.momentum_relative_error(),
            r.probe.energy_relative_error(),
        );
    }
    checks.push(Check::at_most(
        "peak force spread over contacts 10–35 (worst speed)",
        spread,
        Unit::Scientific,
        SPREAD_MAX,
    ));
    checks.push(Check::at_most(
        "largest force behind the pulse / F_m (worst speed)",
        trailing,
        Unit::Scientific,
        TRAILING_MAX,
    ));
    checks.push(Check::at_most(
        "momentum error, relative (worst speed)",
        momentum,
        Unit::Scientific,
        MOMENTUM_MAX,
    ));
    checks.push(Check::at_most(
        "energy error, relative (worst speed)",
        energy,
        Unit::Scientific,
        ENERGY_MAX,
    ));
    checks.push(Check::info(
        "energy left in spheres 1–20 (worst speed)",
        behind,
        Unit::Percent,
    ));
    // The `chain` scene's own solver (free chains; the SHPB test's chain specimen runs on
    // `solver::chain`, measured above).
    let free = SPEEDS
        .par_iter()
        .map(|&v| strike_free(&material, v))
        .collect::<Result<Vec<_>>>()?;
    let _ = writeln!(
        md,
        "\n**The `chain` scene's solver.** `kind = \"chain\"` runs free chains on \
         `solver::spheres` (the two-sphere stepper's scheme over N spheres, so that N = 2 is the \
         `collision` scene exactly); the SHPB test's chain specimen runs on `solver::chain` \
         (above). The same chains through `solver::spheres`, same step, same measurements:\n"
    );
    let _ = writeln!(
        md,
        "| v (m/s) | V_s (m/s) | Nesterenko (m/s) | error | spread 10–35 | momentum drift |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for (&v, &(v_s, reference, spread_free, drift)) in SPEEDS.iter().zip(&free) {
        checks.push(Check::at_most(
            format!("chain scene solver, {v} m/s: |V_s / Nesterenko − 1|"),
            (v_s / reference - 1.0).abs(),
            Unit::Percent,
            SPEED_MAX,
        ));
        checks.push(Check::at_most(
            format!("chain scene solver, {v} m/s: peak force spread over contacts 10–35"),
            spread_free,
            Unit::Scientific,
            SPREAD_MAX,
        ));
        checks.push(Check::at_most(
            format!("chain scene solver, {v} m/s: momentum drift, relative"),
            drift,
            Unit::Scientific,
            MOMENTUM_MAX,
        ));
        let _ = writeln!(
            md,
            "| {v} | {v_s:.1} | {reference:.1} | {} | {spread_free:.1e} | {drift:.1e} |",
            crate::pct(v_s / reference - 1.0)
        );
    }
    let forces: Vec<f64> = runs.iter().map(|r| r.wave.max_force_n).collect();
    let speeds: Vec<f64> = runs.iter().map(|r| r.wave.speed_m_s).collect();
    let slope = log_slope(&forces, &speeds);
    checks.push(Check::info(
        "exponent of V_s ∝ F_m^n (Nesterenko: 1/6)",
        slope,
        Unit::Ratio,
    ));
    let fwhm = runs
        .iter()
        .map(|r| r.wave.half_max_width_m / fwhm_theory - 1.0)
        .fold(0.0f64, |a, b| if b.abs() > a.abs() { b } else { a });
    checks.push(Check::info(
        "FWHM of the force against the long-wave cos⁶ profile (worst speed)",
        fwhm,
        Unit::Percent,
    ));
    let _ = writeln!(
        md,
        "\n**Findings.** One solitary wave forms within about ten contacts of the impact (peak \
         forces {} times the final one at contacts 1, 2, 3, 5, at {} m/s) and travels at constant \
         amplitude; the striker and its neighbours are left drifting slowly backwards, apart, \
         with at most {:.2} % of the energy in spheres 1–20 once the pulse is past contact 35. \
         The speed follows F_m^{{1/6}} (fitted exponent {slope:.4}) and differs by {} % from \
         Nesterenko's long-wave value at every speed; the pulse is {} d long at \
         {LENGTH_FORCE_FRACTION:.0e} of its peak and its width at half maximum is {:+.1} % from \
         the long-wave cos⁶ profile's {:.2} d.\n",
        [0usize, 1, 2, 4]
            .iter()
            .map(|&k| format!(
                "{:.3}",
                runs[0].probe.peak_force_n[k] / runs[0].wave.max_force_n
            ))
            .collect::<Vec<_>>()
            .join(", "),
        runs[0].speed_m_s,
        behind * 100.0,
        range_text(runs.iter().map(|r| 100.0 * r.wave.speed_error()), true),
        range_text(runs.iter().map(|r| r.wave.length_m / d), false),
        fwhm * 100.0,
        fwhm_theory / d,
    );
    // Figure: (a) force at contacts 1, 5, 10, 20, 30 against time at 2 m/s (the x–t picture
    // as lines); (b) V_s against F_m, measured and Nesterenko's.
    let one = runs.iter().find(|r| r.speed_m_s == 2.0).unwrap_or(&runs[0]);
    let history: Vec<Series> = [1usize, 5, 10, 20, 30]
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            Series::new(
                format!("contact {k}"),
                one.probe.time_s.clone(),
                one.probe.force_n.iter().map(|row| row[k - 1]).collect(),
                Style::Line(i + 1),
            )
        })
        .collect();
    let (f_lo, f_hi) = (0.8 * forces[0], 1.2 * forces[forces.len() - 1]);
    let theory_f: Vec<f64> = (0..=60)
        .map(|i| f_lo * (f_hi / f_lo).powf(i as f64 / 60.0))
        .collect();
    let theory_v: Vec<f64> = theory_f
        .iter()
        .map(|&f| solitary::solitary_wave_speed_m_s(&material, d, f))
        .collect();
    Ok(CaseResult {
        name: "chain",
        title: "solitary wave in a struck chain of 40 elastic Hertz spheres".into(),
        checks,
        section: md,
        figure: Figure {
            legend: Legend::UpperRight,
            caption: format!(
                "A chain of 40 SS440c spheres (6.35 mm, elastic Hertz) struck by its first \
                 sphere: (a) contact force against time at contacts 1, 5, 10, 20 and 30, striking speed {} m/s \
                 (one pulse of constant shape after the first few contacts); (b) solitary-wave \
                 speed against peak force at the four striking speeds (points) and Nesterenko's \
                 long-wave speed (dashed).",
                one.speed_m_s
            ),
            columns: 2,
            panels: vec![
                Panel {
                    title: format!("(a) contact forces, {} m/s", one.speed_m_s),
                    x_label: "time (µs)".into(),
                    y_label: "contact force (N)".into(),
                    x_scale: 1e6,
                    y_scale: 1.0,
                    series: history,
                },
                Panel {
                    title: "(b) speed against peak force".into(),
                    x_label: "peak force F_m (N)".into(),
                    y_label: "V_s (m/s)".into(),
                    x_scale: 1.0,
                    y_scale: 1.0,
                    series: vec![
                        Series::new(
                            "Nesterenko (long wave)",
                            theory_f,
                            theory_v,
                            Style::Dashed(0),
                        ),
                        Series::new("chain, measured", forces, speeds, Style::Points(1)),
                    ],
                },
            ],
        },
    })
}

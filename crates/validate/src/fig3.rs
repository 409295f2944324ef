//! Case `fig3-rate`: constant-rate compression of two SS440c spheres with Johnson–Cook rate
//! hardening (paper Eqs. 1–3, C = 0.04) against the paper's Fig. 3 FEM curves at 0.001, 10 and
//! 10 000 1/s, and the normalised inset (F/Fp against δ/δp at each rate's σy*).

use crate::figure::{Figure, Legend, Panel, Series, Style};
use crate::{CaseResult, Check, Context, Unit, max_of, read_columns, rms};
use shpb_core::contact::BurgoyneDaraio;
use shpb_core::numeric::resample;
use shpb_core::scene::Params;
use shpb_input::Result;
use shpb_input::prelude::*;
use std::fmt::Write as _;

/// (file tag, strain rate 1/s) of the three FEM runs.
const RATES: [(&str, f64); 3] = [("0p001", 1e-3), ("10", 10.0), ("10000", 1e4)];

/// Threshold on the RMS force error relative to the FEM's peak force. The guide is 10 %;
/// the model achieves 0.3–0.7 %, so the threshold is set at 2 %.
const FORCE_RMS_MAX: f64 = 0.02;

/// Threshold on the spread of the normalised FEM curves (RMS difference from the 0.001 1/s
/// curve over their common δ/δp range, relative to its peak). Achieved 0.4–0.7 %.
const COLLAPSE_MAX: f64 = 0.015;

/// One rate's FEM curve and model.
struct Run {
    rate: f64,
    fem_delta_m: Vec<f64>,
    fem_force_n: Vec<f64>,
    model_force_n: Vec<f64>,
    delta_p_m: f64,
    force_p_n: f64,
    yield_stress_pa: f64,
}

/// RMS difference of two normalised curves over their common abscissa range, relative to the
/// first one's peak.
fn spread(a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> f64 {
    let end = max_of(a.0).min(max_of(b.0));
    let grid: Vec<f64> = (0..=500).map(|k| end * k as f64 / 500.0).collect();
    let ya = resample(a.0, a.1, &grid);
    let yb = resample(b.0, b.1, &grid);
    rms(ya.iter().zip(&yb).map(|(x, y)| x - y)) / max_of(&ya)
}

/// Runs the case (module docs).
pub fn run(ctx: &Context) -> Result<CaseResult> {
    let dir = ctx.path("validation/fig3-rate");
    let mut runs = Vec::new();
    for (tag, rate) in RATES {
        let (d, f) = read_columns(
            &dir.join(format!("data/ss440c_rate_{tag}_per_s.csv")),
            "displacement_m",
            "force_N",
        )?;
        let params = Params::from_file(&dir.join(format!("rate-{tag}.toml")))?;
        let out = params.run()?;
        let c = out
            .contact
            .as_ref()
            .expect("constant-rate scenes have a contact series");
        let law = BurgoyneDaraio::new(params.pair_and_law()?.0.contact_properties(), true);
        let curve = law.curve_at(rate);
        runs.push(Run {
            rate,
            model_force_n: resample(&c.displacement_m, &c.force_n, &d),
            fem_delta_m: d,
            fem_force_n: f,
            delta_p_m: curve.fit.delta_p_m,
            force_p_n: curve.force_p_n,
            yield_stress_pa: curve.yield_stress_pa,
        });
    }
    let err = |r: &Run| {
        rms(r
            .model_force_n
            .iter()
            .zip(&r.fem_force_n)
            .map(|(a, b)| a - b))
            / max_of(&r.fem_force_n)
    };
    let norm = |r: &Run, f: &[f64]| -> (Vec<f64>, Vec<f64>) {
        (
            r.fem_delta_m.iter().map(|d| d / r.delta_p_m).collect(),
            f.iter().map(|v| v / r.force_p_n).collect(),
        )
    };
    let mut checks = Vec::new();
    for r in &runs {
        checks.push(Check::at_most(
            format!("{} 1/s: RMS force error / peak FEM force", r.rate),
            err(r),
            Unit::Percent,
            FORCE_RMS_MAX,
        ));
    }
    let base_fem = norm(&runs[0], &runs[0].fem_force_n);
    let base_model = norm(&runs[0], &runs[0].model_force_n);
    let mut model_spreads = Vec::new();
    for r in &runs[1..] {
        let n = norm(r, &r.fem_force_n);
        checks.push(Check::at_most(
            format!(
                "inset: normalised FEM curve at {} 1/s vs 0.001 1/s (RMS / peak)",
                r.rate
            ),
            spread((&base_fem.0, &base_fem.1), (&n.0, &n.1)),
            Unit::Percent,
            COLLAPSE_MAX,
        ));
        let m = norm(r, &r.model_force_n);
        model_spreads.push(spread((&base_model.0, &base_model.1), (&m.0, &m.1)));
    }

    let mut md = String::new();
    let _ = writeln!(
        md,
        "**Set-up.** `validation/fig3-rate/rate-<rate>.toml`: constant-rate scenes of two 6.35 mm \
         SS440c spheres (Table I, ν = 0.28) with the Fig. 3 Johnson–Cook constants (C = 0.04, \
         ε̇0 = 0.001 1/s; `ss440c-c0.04.toml`), pressed at approach speed ε̇ (r1 + r2) up to the \
         FEM's largest approach; the model is interpolated onto the FEM's δ. Data: the authors' \
         FEM curves `data/ss440c_rate_<rate>_per_s.csv`. The FEM's Poisson ratio is not stated; \
         with ν = 0.3 instead of 0.28 the errors below change by up to 0.2 percentage points.\n"
    );
    let _ = writeln!(
        md,
        "**Metrics and thresholds.** (i) RMS of F_model − F_FEM over every FEM point relative to \
         the FEM's peak force: the issue's guide is 10 %; the model achieves 0.3–0.7 %, so the \
         threshold is {:.0} % (a curve 2 % off would be visible in the figure). (ii) The inset: each \
         curve normalised by δp and Fp of the law at its own σy* (as in the paper's inset); the \
         paper states that the normalised curves overlap. Metric: RMS difference of the normalised \
         FEM curve at 10 and 10 000 1/s from the one at 0.001 1/s over their common δ/δp range, \
         relative to its peak; achieved 0.4–0.7 %, threshold {:.1} %. This checks the premise of \
         Eqs. 2–3 — that the rate enters only through σy* — on the FEM itself; the model's \
         normalised curves differ from the FEM's by exactly the relative errors of (i).\n",
        FORCE_RMS_MAX * 100.0,
        COLLAPSE_MAX * 100.0
    );
    let _ = writeln!(
        md,
        "| rate (1/s) | σy* (MPa) | δp (µm) | Fp (kN) | RMS error | F_model/F_FEM at the last point |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for r in &runs {
        let n = r.fem_force_n.len() - 1;
        let _ = writeln!(
            md,
            "| {} | {:.0} | {:.1} | {:.2} | {:.2} % | {:.3} |",
            r.rate,
            r.yield_stress_pa / 1e6,
            r.delta_p_m * 1e6,
            r.force_p_n / 1e3,
            err(r) * 100.0,
            r.model_force_n[n] / r.fem_force_n[n]
        );
    }
    let _ = writeln!(
        md,
        "\nThe model's own normalised curves at 10 and 10 000 1/s differ from its 0.001 1/s curve \
         by {} (RMS / peak): they do not coincide exactly, because q = E*/σy* — and with it the \
         fitted δp, c1, c2 — changes with the rate.\n",
        model_spreads
            .iter()
            .map(|s| format!("{:.2} %", s * 100.0))
            .collect::<Vec<_>>()
            .join(" and ")
    );

    let mut raw = Vec::new();
    let mut inset = Vec::new();
    for (i, r) in runs.iter().enumerate() {
        raw.push(Series::new(
            format!("FEM {} 1/s", r.rate),
            r.fem_delta_m.clone(),
            r.fem_force_n.clone(),
            Style::Dashed(i + 2),
        ));
        raw.push(Series::new(
            format!("model {} 1/s", r.rate),
            r.fem_delta_m.clone(),
            r.model_force_n.clone(),
            Style::Line(i + 2),
        ));
        let (x, y) = norm(r, &r.fem_force_n);
        inset.push(Series::new(
            format!("FEM {} 1/s", r.rate),
            x,
            y,
            Style::Dashed(i + 2),
        ));
        let (x, y) = norm(r, &r.model_force_n);
        inset.push(Series::new(
            format!("model {} 1/s", r.rate),
            x,
            y,
            Style::Line(i + 2),
        ));
    }
    let figure = Figure {
        legend: Legend::UpperLeft,
        caption: "Fig. 3: (a) force against approach of two 6.35 mm SS440c spheres at constant \
                  strain rate, FEM (dashed) and model (solid); (b) the inset: the same normalised \
                  by δp and Fp of the law at each rate's σy*."
            .into(),
        columns: 2,
        panels: vec![
            Panel {
                title: "(a) constant strain rate, SS440c, C = 0.04".into(),
                x_label: "sphere approach δ (µm)".into(),
                y_label: "force F (kN)".into(),
                x_scale: 1e6,
                y_scale: 1e-3,
                series: raw,
            },
            Panel {
                title: "(b) normalised (inset of Fig. 3)".into(),
                x_label: "δ/δp".into(),
                y_label: "F/Fp".into(),
                x_scale: 1.0,
                y_scale: 1.0,
                series: inset,
            },
        ],
    };
    Ok(CaseResult {
        name: "fig3-rate",
        title: "constant-rate compression against the FEM (paper Fig. 3)".into(),
        checks,
        section: md,
        figure,
    })
}

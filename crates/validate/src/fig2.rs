//! Case `fig2-quasistatic`: the quasi-static loading law (paper Eq. 1 with the fits of δp, c1,
//! c2) against the paper's Fig. 2 FEM curves (E = 100 GPa, ν = 0.3, 6.35 mm hemispheres), and a
//! refit of δp, c1, c2 against q = E*/σy from the authors' per-run values (Fig. 2(b)).

use crate::figure::{Figure, Legend, Panel, Series, Style};
use crate::{CaseResult, Check, Context, Unit, max_of, pct, read_columns, rms};
use shpb_core::contact::{FIT_REFERENCE_RADIUS_M, FittedParameters, LoadingCurve, Region2Form};
use shpb_core::numeric::{least_squares, resample};
use shpb_core::scene::Params;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::fmt::Write as _;

/// Yield stresses of the Fig. 2 FEM runs, MPa (`validation/fig2-quasistatic/sy<MPa>MPa.*`).
const YIELD_STRESSES_MPA: [u32; 5] = [200, 600, 1000, 1400, 2000];

/// Threshold on the RMS force error over the FEM's δ range, relative to the FEM's peak force.
/// Achieved: 0.46–2.3 % (worst at σy = 200 MPa, where the law ends 2 % above the FEM).
const FORCE_RMS_MAX: f64 = 0.03;

/// Threshold on the largest relative difference between the refitted c1(q) and the paper's over
/// the FEM's q range. Achieved: ≈ 2 %.
const C1_CURVE_MAX: f64 = 0.05;

/// Threshold on the largest relative difference between the refitted c2(q) and the paper's over
/// the FEM's q range. Achieved: ≈ 13 % (at q = 549, where c2 is smallest).
const C2_CURVE_MAX: f64 = 0.15;

/// The paper's coefficients (physics.md §1): δp = a/q + b, c1 = A q^B + C, c2 = a/q + b.
const PAPER_DELTA_P: (f64, f64) = (0.00428, 1.47e-5);
const PAPER_C1: (f64, f64, f64) = (-6.76, -0.137, 6.304);
const PAPER_C2: (f64, f64) = (-3.99e-6, 1.01e-9);

/// Effective radius of the FEM's two 6.35 mm hemispheres, m.
const FEM_RADIUS_M: f64 = 6.35e-3 / 4.0;

/// Least-squares a, b of y = a/q + b (None when the q do not determine them: all equal).
fn fit_inverse(q: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let x: Vec<f64> = q.iter().map(|v| 1.0 / v).collect();
    let ab = least_squares(&[&x, &vec![1.0; q.len()]], y)?;
    Some((ab[0], ab[1]))
}

/// Least-squares A, C of y = A q^B + C at fixed B, with its sum of squared residuals.
fn fit_power_at(q: &[f64], y: &[f64], b: f64) -> Option<(f64, f64, f64)> {
    let qb: Vec<f64> = q.iter().map(|v| v.powf(b)).collect();
    let ac = least_squares(&[&qb, &vec![1.0; q.len()]], y)?;
    let (a, c) = (ac[0], ac[1]);
    let ss = qb.iter().zip(y).map(|(x, v)| (a * x + c - v).powi(2)).sum();
    Some((a, c, ss))
}

/// Least-squares A, B, C of y = A q^B + C (B by golden-section search on −1.5 … −0.01).
fn fit_power(q: &[f64], y: &[f64]) -> Option<(f64, f64, f64)> {
    let ss = |b: f64| fit_power_at(q, y, b).map_or(f64::INFINITY, |f| f.2);
    // Coarse scan, then golden section around the best point.
    let grid: Vec<f64> = (0..=149).map(|k| -1.5 + 0.01 * k as f64).collect();
    let k = (0..grid.len())
        .min_by(|&i, &j| ss(grid[i]).total_cmp(&ss(grid[j])))
        .unwrap_or(0);
    let (mut lo, mut hi) = (grid[k.saturating_sub(1)], grid[(k + 1).min(grid.len() - 1)]);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if ss(m1) < ss(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let b = 0.5 * (lo + hi);
    let (a, c, _) = fit_power_at(q, y, b)?;
    Some((a, b, c))
}

/// The Fig. 2 comparison of one yield stress.
struct Run {
    sigma_mpa: u32,
    fem_delta_m: Vec<f64>,
    fem_force_n: Vec<f64>,
    model_force_n: Vec<f64>,
    published_force_n: Vec<f64>,
    curve: LoadingCurve,
}

/// Runs the case (module docs).
pub fn run(ctx: &Context) -> Result<CaseResult> {
    let dir = ctx.path("validation/fig2-quasistatic");
    let mut runs = Vec::new();
    for s in YIELD_STRESSES_MPA {
        let (d, f) = read_columns(
            &dir.join(format!("data/sy{s}MPa.csv")),
            "displacement_m",
            "force_N",
        )?;
        let params = Params::from_file(&dir.join(format!("sy{s}MPa.toml")))?;
        let out = params.run()?;
        let c = out
            .contact
            .as_ref()
            .expect("quasistatic scenes have a contact series");
        let model = resample(&c.displacement_m, &c.force_n, &d);
        let p = params.pair_and_law()?.0.contact_properties();
        let published = LoadingCurve::with_form(
            p.e_star_pa,
            p.radius_m,
            p.yield_stress_pa,
            Region2Form::Published,
        );
        runs.push(Run {
            sigma_mpa: s,
            published_force_n: d.iter().map(|&x| published.force(x)).collect(),
            curve: LoadingCurve::new(p.e_star_pa, p.radius_m, p.yield_stress_pa),
            fem_delta_m: d,
            fem_force_n: f,
            model_force_n: model,
        });
    }
    let err = |r: &Run, m: &[f64]| {
        rms(m.iter().zip(&r.fem_force_n).map(|(a, b)| a - b)) / max_of(&r.fem_force_n)
    };
    let mut checks = Vec::new();
    for r in &runs {
        checks.push(Check::at_most(
            format!("σy = {} MPa: RMS force error / peak FEM force", r.sigma_mpa),
            err(r, &r.model_force_n),
            Unit::Percent,
            FORCE_RMS_MAX,
        ));
    }

    // Refit of the fitted parameters against q (Fig. 2(b)).
    let t = shpb_input::csv::CsvTable::read(&dir.join("data/fitted_parameters.csv"))?;
    let q = t.column("q_Estar_over_sy")?.to_vec();
    // The fits refer to r = 0.00159 m; the FEM's r is 0.0015875 m (scale 0.998).
    let scale = FEM_RADIUS_M / FIT_REFERENCE_RADIUS_M;
    let dp: Vec<f64> = t.column("delta_p_m")?.iter().map(|v| v / scale).collect();
    let c1 = t.column("c1")?.to_vec();
    let c2: Vec<f64> = t
        .column("c2_m2")?
        .iter()
        .map(|v| v / (scale * scale))
        .collect();
    if q.len() < 4 || q.iter().any(|v| *v <= 0.0) {
        return Err(Error::Input {
            file: t.file.clone(),
            key: "q_Estar_over_sy".into(),
            problem: "fewer than 4 rows or a non-positive q".into(),
            allowed: "at least 4 rows with q > 0".into(),
        });
    }
    let (Some(fit_dp), Some(fit_c1), Some(fit_c2)) = (
        fit_inverse(&q, &dp),
        fit_power(&q, &c1),
        fit_inverse(&q, &c2),
    ) else {
        return Err(Error::Input {
            file: t.file.clone(),
            key: "q_Estar_over_sy".into(),
            problem: "the fits are undetermined (fewer than 2 distinct q, or a value not finite)"
                .into(),
            allowed: "at least 2 distinct q and finite values".into(),
        });
    };
    let paper = |q: f64| FittedParameters::at(q, FIT_REFERENCE_RADIUS_M);
    let (q_lo, q_hi) = (q.iter().copied().fold(f64::INFINITY, f64::min), max_of(&q));
    let q_grid: Vec<f64> = (0..=200)
        .map(|k| q_lo * (q_hi / q_lo).powf(k as f64 / 200.0))
        .collect();
    let refit_dp = |q: f64| fit_dp.0 / q + fit_dp.1;
    let refit_c1 = |q: f64| fit_c1.0 * q.powf(fit_c1.1) + fit_c1.2;
    let refit_c2 = |q: f64| fit_c2.0 / q + fit_c2.1;
    let curve_diff = |refit: &dyn Fn(f64) -> f64, paper: &dyn Fn(f64) -> f64| {
        q_grid
            .iter()
            .map(|&x| (refit(x) / paper(x) - 1.0).abs())
            .fold(0.0, f64::max)
    };
    let diff_dp = curve_diff(&refit_dp, &|x| paper(x).delta_p_m);
    let diff_c1 = curve_diff(&refit_c1, &|x| paper(x).c1);
    let diff_c2 = curve_diff(&refit_c2, &|x| paper(x).c2_m2);
    checks.push(Check::at_most(
        "refit c1(q) vs paper's fit: max relative difference over the FEM's q",
        diff_c1,
        Unit::Percent,
        C1_CURVE_MAX,
    ));
    checks.push(Check::at_most(
        "refit c2(q) vs paper's fit: max relative difference over the FEM's q",
        diff_c2,
        Unit::Percent,
        C2_CURVE_MAX,
    ));
    checks.push(Check::info(
        "refit δp(q) vs paper's fit: max relative difference (not reproduced, see text)",
        diff_dp,
        Unit::Percent,
    ));
    // Residuals of the points about each fit, relative to the mean |value|.
    let resid = |y: &[f64], f: &dyn Fn(f64) -> f64| {
        let mean = y.iter().map(|v| v.abs()).sum::<f64>() / y.len() as f64;
        rms(q.iter().zip(y).map(|(&x, &v)| f(x) - v)) / mean
    };

    // Report section.
    let mut md = String::new();
    let _ = writeln!(
        md,
        "**Set-up.** `validation/fig2-quasistatic/sy<σy>MPa.toml`: quasi-static scenes of two \
         6.35 mm spheres of the FEM's material (`fem-sy<σy>MPa.toml`: E = 100 GPa, ν = 0.3, σy = \
         200–2000 MPa, q = E*/σy = 27–275), law `rate-independent` with the default C¹ region II, \
         evaluated up to the FEM's largest approach and interpolated onto the FEM's δ. Data: the \
         authors' FEM curves `data/sy<σy>MPa.csv` (Fig. 2(c) shows four of them normalised).\n"
    );
    let _ = writeln!(
        md,
        "**Metric and threshold.** RMS of F_model − F_FEM over every FEM point (δ from 0 to its \
         largest value, i.e. through regions I, II and III) relative to the FEM's peak force; \
         threshold {:.0} %. The law achieves 0.5–2.3 % — the paper's \"nearly indistinguishable\" — \
         and the threshold leaves room for the worst case (σy = 200 MPa, where region III of the \
         fit ends 2 % above the FEM) without admitting a visibly different curve.\n",
        FORCE_RMS_MAX * 100.0
    );
    let _ = writeln!(
        md,
        "| σy (MPa) | q = E*/σy | δy (µm) | δp (µm) | RMS error, C¹ region II (default) | published region II | largest \\|error\\| / peak | F_model/F_FEM at the last point |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    for r in &runs {
        let n = r.fem_force_n.len() - 1;
        let worst = r
            .model_force_n
            .iter()
            .zip(&r.fem_force_n)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / max_of(&r.fem_force_n);
        let _ = writeln!(
            md,
            "| {} | {:.1} | {:.2} | {:.1} | {:.2} % | {:.2} % | {:.1} % | {:.3} |",
            r.sigma_mpa,
            r.curve.e_star_pa / r.curve.yield_stress_pa,
            r.curve.delta_y_m * 1e6,
            r.curve.fit.delta_p_m * 1e6,
            err(r, &r.model_force_n) * 100.0,
            err(r, &r.published_force_n) * 100.0,
            worst * 100.0,
            r.model_force_n[n] / r.fem_force_n[n]
        );
    }
    let _ = writeln!(
        md,
        "\nThe published region II (γ = 0) fits the FEM as well as the C¹ form (differences \
         ≤ 0.05 percentage points): γ changes the curve only near δy, where the forces are small.\n"
    );
    let _ = writeln!(
        md,
        "**Refit of the fitted parameters.** `data/fitted_parameters.csv` holds the authors' δp, \
         c1, c2 for each of {} FEM runs (q = {:.1}–{:.1}; one row is duplicated, and it is kept as \
         given). δp and c2 are scaled to r = 0.00159 m (factor {:.4}). Least squares in the paper's \
         forms — δp = a/q + b and c2 = a/q + b (linear), c1 = A q^B + C (B by golden-section \
         search, A and C linear):\n",
        q.len(),
        q_lo,
        q_hi,
        scale
    );
    let _ = writeln!(
        md,
        "| parameter | paper | refit | RMS residual of the points about the paper's fit | about the refit | max difference of the curves over q |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    let _ = writeln!(
        md,
        "| δp (m) = a/q + b | a = {:.3e}, b = {:.3e} | a = {:.3e}, b = {:.3e} | {:.1} % | {:.1} % | {:.0} % |",
        PAPER_DELTA_P.0,
        PAPER_DELTA_P.1,
        fit_dp.0,
        fit_dp.1,
        resid(&dp, &|x| paper(x).delta_p_m) * 100.0,
        resid(&dp, &refit_dp) * 100.0,
        diff_dp * 100.0
    );
    let _ = writeln!(
        md,
        "| c1 = A q^B + C | A = {}, B = {}, C = {} | A = {:.3}, B = {:.4}, C = {:.3} | {:.1} % | {:.1} % | {:.1} % |",
        PAPER_C1.0,
        PAPER_C1.1,
        PAPER_C1.2,
        fit_c1.0,
        fit_c1.1,
        fit_c1.2,
        resid(&c1, &|x| paper(x).c1) * 100.0,
        resid(&c1, &refit_c1) * 100.0,
        diff_c1 * 100.0
    );
    let _ = writeln!(
        md,
        "| c2 (m²) = a/q + b | a = {:.3e}, b = {:.3e} | a = {:.3e}, b = {:.3e} | {:.1} % | {:.1} % | {:.1} % |",
        PAPER_C2.0,
        PAPER_C2.1,
        fit_c2.0,
        fit_c2.1,
        resid(&c2, &|x| paper(x).c2_m2) * 100.0,
        resid(&c2, &refit_c2) * 100.0,
        diff_c2 * 100.0
    );
    let below: Vec<String> = q
        .iter()
        .zip(&dp)
        .filter(|(x, _)| **x < 150.0)
        .map(|(&x, &v)| format!("{:.0}", (paper(x).delta_p_m / v - 1.0) * -100.0))
        .collect();
    let _ = writeln!(
        md,
        "\n**Findings.** c1 is reproduced: the refitted curve stays within {:.1} % of the paper's \
         (threshold {:.0} %: the curves' agreement, with room for the search's last digit). c2 is \
         reproduced within {:.0} % (threshold {:.0} %; the largest difference is at the largest q, \
         where |c2| is smallest and matters least). **δp is not reproduced**: the paper's δp(q) lies \
         below the authors' own per-run values by {} % for q < 150 and above them for q > 270, so \
         the refit's coefficients differ by {} (a) and {} (b), and the curves by up to {:.0} %; \
         the residual of the points about the paper's fit is {:.0} % against {:.0} % about the \
         refit. The points themselves scatter (q = 204 lies above q = 137's trend, q = 275–549 \
         fall steeply), so δp is poorly determined by them, and the paper may have weighted or \
         selected runs differently. It matters little for the force: with the paper's δp the \
         loading curves above meet the FEM within {:.1} %, because region II interpolates between \
         Hertz and the region III line whichever δp joins them. The δp row is therefore reported \
         for information, without a threshold; the law keeps the paper's fits (physics.md §1).\n",
        diff_c1 * 100.0,
        C1_CURVE_MAX * 100.0,
        diff_c2 * 100.0,
        C2_CURVE_MAX * 100.0,
        below.join(", "),
        pct(fit_dp.0 / PAPER_DELTA_P.0 - 1.0),
        pct(fit_dp.1 / PAPER_DELTA_P.1 - 1.0),
        diff_dp * 100.0,
        resid(&dp, &|x| paper(x).delta_p_m) * 100.0,
        resid(&dp, &refit_dp) * 100.0,
        runs.iter()
            .map(|r| err(r, &r.model_force_n))
            .fold(0.0, f64::max)
            * 100.0
    );

    // Figure: Fig. 2(c) normalised curves, and Fig. 2(b) parameters against q.
    let mut fd = Vec::new();
    for (i, r) in runs.iter().enumerate() {
        let (dp0, fp0) = (r.curve.fit.delta_p_m, r.curve.force_p_n);
        let x: Vec<f64> = r.fem_delta_m.iter().map(|d| d / dp0).collect();
        fd.push(Series::new(
            format!("FEM σy = {} MPa", r.sigma_mpa),
            x.clone(),
            r.fem_force_n.iter().map(|f| f / fp0).collect(),
            Style::Dashed(i + 2),
        ));
        fd.push(Series::new(
            format!("model σy = {} MPa", r.sigma_mpa),
            x,
            r.model_force_n.iter().map(|f| f / fp0).collect(),
            Style::Line(i + 2),
        ));
    }
    let param_panel = |title: &str,
                       y_label: &str,
                       y_scale: f64,
                       points: &[f64],
                       paper_f: &dyn Fn(f64) -> f64,
                       refit: &dyn Fn(f64) -> f64| Panel {
        title: title.into(),
        x_label: "q = E*/σy".into(),
        y_label: y_label.into(),
        x_scale: 1.0,
        y_scale,
        series: vec![
            Series::new(
                "FEM runs (authors' fits)",
                q.clone(),
                points.to_vec(),
                Style::Points(0),
            ),
            Series::new(
                "paper's fit",
                q_grid.clone(),
                q_grid.iter().map(|&x| paper_f(x)).collect(),
                Style::Line(1),
            ),
            Series::new(
                "refit",
                q_grid.clone(),
                q_grid.iter().map(|&x| refit(x)).collect(),
                Style::Line(3),
            ),
        ],
    };
    let figure = Figure {
        legend: Legend::UpperLeft,
        caption: "Fig. 2: (a) FEM (dashed) and model (solid) normalised by the model's δp and Fp, \
                  as in the paper's Fig. 2(c); (b–d) the fitted parameters against q: the \
                  authors' per-run values (markers), the paper's fits and our refit."
            .into(),
        columns: 2,
        panels: vec![
            Panel {
                title: "(a) F/Fp against δ/δp, E = 100 GPa".into(),
                x_label: "δ/δp".into(),
                y_label: "F/Fp".into(),
                x_scale: 1.0,
                y_scale: 1.0,
                series: fd,
            },
            param_panel(
                "(b) δp at r = 0.00159 m",
                "δp (µm)",
                1e6,
                &dp,
                &|x| paper(x).delta_p_m,
                &refit_dp,
            ),
            param_panel(
                "(c) c1 = p0/σy",
                "c1",
                1.0,
                &c1,
                &|x| paper(x).c1,
                &refit_c1,
            ),
            param_panel(
                "(d) c2 at r = 0.00159 m",
                "c2 (1e-9 m²)",
                1e9,
                &c2,
                &|x| paper(x).c2_m2,
                &refit_c2,
            ),
        ],
    };
    Ok(CaseResult {
        name: "fig2-quasistatic",
        title: "quasi-static loading law against the FEM (paper Fig. 2)".into(),
        checks,
        section: md,
        figure,
    })
}

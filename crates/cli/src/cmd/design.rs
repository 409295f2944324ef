//! `shpb design`: the inputs of a scene that meet a target summary quantity (the search is
//! [`shpb_study::design`]; each run is one point of `shpb sweep` with `fidelity` set).

use super::common::{finite, report};
use shpb_core::fidelity::Fidelity;
use shpb_input::{Error, Result};
use shpb_study::design::{
    Design, Requirement, Root, Run, Settings, Target, Vary, parse_requirement, parse_target,
    parse_vary, quantity_of, significant,
};
use shpb_study::sweep::{Point, RunSummary, SUMMARY_COLUMNS, parse_axis, run_points};
use std::path::Path;

/// The options of `shpb design` besides the scene.
pub struct DesignOptions<'a> {
    /// `--target QUANTITY=VALUE[unit]`.
    pub target: &'a str,
    /// `--vary KEY=LO:HI`, once or twice.
    pub vary: &'a [String],
    /// `--require QUANTITY<VALUE`, any number.
    pub require: &'a [String],
    /// `--tol`: relative, `0.2%` or `0.002`.
    pub tol: &'a str,
    /// `--grid`: values of the second vary.
    pub grid: usize,
    /// `--max-runs`: runs per 1-D search.
    pub max_runs: usize,
}

/// Parses `--tol`: a fraction (`0.002`) or a percentage (`0.2%`) of the target, in (0, 50 %].
pub fn parse_tol(text: &str) -> Result<f64> {
    let t = text.trim();
    let (number, scale) = match t.strip_suffix('%') {
        Some(n) => (n, 0.01),
        None => (t, 1.0),
    };
    let v = number.trim().parse::<f64>().ok().map(|v| v * scale);
    match v {
        Some(v) if v > 0.0 && v <= 0.5 => Ok(v),
        _ => Err(shpb_study::api::input_err(
            "--tol",
            format!("`{text}`"),
            "a fraction of the target in (0, 0.5], or a percentage in (0 %, 50 %], e.g. 0.2% or \
             0.002",
        )),
    }
}

/// `shpb design SCENE --target Q=V --vary KEY=LO:HI [--vary …] [--require Q<V …]`: runs the
/// search, prints every run (preset, inputs, value) and the answer with the runs used; exits 4
/// when no input within the bounds meets the target and 5 when the solutions violate a
/// `--require` (README "Design search").
pub fn design(scene: &Path, o: &DesignOptions) -> Result<()> {
    shpb_study::sweep::require_scene(scene)?;
    let target = parse_target(o.target)?;
    let varies = o
        .vary
        .iter()
        .map(|v| parse_vary(v))
        .collect::<Result<Vec<_>>>()?;
    if varies.len() > 2 {
        return Err(shpb_study::api::input_err(
            "--vary",
            format!("{} varied inputs", varies.len()),
            "one (1-D search) or two (the first solved on a grid of the second)",
        ));
    }
    if varies.len() == 2 && varies[0].key == varies[1].key {
        return Err(shpb_study::api::input_err(
            "--vary",
            format!("`{}` is varied twice", varies[0].key),
            "two different keys",
        ));
    }
    let requires = o
        .require
        .iter()
        .map(|r| parse_requirement(r))
        .collect::<Result<Vec<_>>>()?;
    let tol = parse_tol(o.tol)?;
    if !(2..=50).contains(&o.grid) {
        return Err(shpb_study::api::input_err(
            "--grid",
            format!("{}", o.grid),
            "2 to 50 values of the second --vary",
        ));
    }
    if !(3..=1000).contains(&o.max_runs) {
        return Err(shpb_study::api::input_err(
            "--max-runs",
            format!("{}", o.max_runs),
            "3 to 1000 runs per 1-D search (two bound runs and a confirmation at least)",
        ));
    }
    let settings = Settings {
        tol_abs: tol * target.value_si.abs(),
        max_runs: o.max_runs,
    };
    let quiet = super::common::quiet_mode() || super::common::json_mode();
    let mut count = 0usize;
    let mut run = |fid: Fidelity, inputs: &[f64]| -> Result<RunSummary> {
        let mut axes = vec![parse_axis(&format!("fidelity={}", fid.name()))?];
        for (v, x) in varies.iter().zip(inputs) {
            axes.push(parse_axis(&format!("{}={}", v.key, v.label(*x)))?);
        }
        let point = Point {
            index: 0,
            coords: vec![0; axes.len()],
        };
        let mut row = run_points(scene, &axes, &[point], 1, |_| {})?.remove(0);
        count += 1;
        row.index = count;
        if !quiet {
            eprintln!(
                "shpb: run {count}: {} {} → {} = {}",
                fid.name(),
                varies
                    .iter()
                    .zip(inputs)
                    .map(|(v, x)| format!("{}={}", v.key, v.short(*x)))
                    .collect::<Vec<_>>()
                    .join(" "),
                target.name(),
                target.show(quantity_of(&row, target.quantity))
            );
        }
        Ok(row)
    };
    let result =
        shpb_study::design::design(&mut run, &varies, &target, &requires, settings, o.grid)?;
    let text = table(&result, &varies, &target, &requires, tol);
    report(&text, || json(&result, &varies, &target, &requires, tol))?;
    verdict(&result, &varies, &target, &requires, settings)
}

/// The header of the quantity columns: the target's, then each constraint's not yet shown.
fn quantity_columns(target: &Target, requires: &[Requirement]) -> Vec<usize> {
    let mut q = vec![target.quantity];
    for r in requires {
        if !q.contains(&r.quantity) {
            q.push(r.quantity);
        }
    }
    q
}

fn column_name(q: usize) -> String {
    let (name, unit) = SUMMARY_COLUMNS[q];
    format!("{name}_{unit}")
}

/// How a solution ended, in words.
fn status(
    s: &shpb_study::design::Solution,
    first: &Vary,
    target: &Target,
    requires: &[Requirement],
) -> String {
    match &s.root {
        Root::Found { .. } => {
            let broken: Vec<&str> = requires
                .iter()
                .zip(&s.satisfied)
                .filter(|(_, ok)| !**ok)
                .map(|(r, _)| r.text.as_str())
                .collect();
            if broken.is_empty() {
                "ok".into()
            } else {
                format!("violates {}", broken.join(", "))
            }
        }
        Root::NotBracketed { at_lo, at_hi } if !(at_lo.is_finite() && at_hi.is_finite()) => {
            format!(
                "no solution: no {} from the runs at the bounds",
                target.name()
            )
        }
        Root::NotBracketed { at_lo, at_hi } => format!(
            "no solution: {} spans {}–{} over {}",
            target.name(),
            target.show(at_lo.min(*at_hi)),
            target.show(at_lo.max(*at_hi)),
            first.key
        ),
        Root::NotConverged { .. } => "not converged".into(),
    }
}

/// The text report: one row per run, then the answer (1-D) or the family of solutions (2-D).
fn table(
    d: &Design,
    varies: &[Vary],
    target: &Target,
    requires: &[Requirement],
    tol: f64,
) -> String {
    let columns = quantity_columns(target, requires);
    let mut t = format!(
        "# design: {} = {} ±{} % ({}), {} in [{}, {}]{}\n",
        target.name(),
        target.show(target.value_si),
        significant(tol * 100.0, 3),
        target.show(tol * target.value_si.abs()),
        varies[0].key,
        varies[0].short(varies[0].lo),
        varies[0].short(varies[0].hi),
        match varies.get(1) {
            Some(v) => format!(
                ", at {} values of {} in [{}, {}]",
                d.solutions.len(),
                v.key,
                v.short(v.lo),
                v.short(v.hi)
            ),
            None => String::new(),
        }
    );
    let mut header = vec!["run".to_string(), "preset".to_string()];
    header.extend(varies.iter().map(|v| v.key.clone()));
    header.extend(columns.iter().map(|&q| column_name(q)));
    header.push("warnings".into());
    t.push_str(&header.join(","));
    t.push('\n');
    for (i, r) in d.runs.iter().enumerate() {
        let mut row = vec![(i + 1).to_string(), r.fidelity.name().to_string()];
        row.extend(varies.iter().zip(&r.inputs).map(|(v, x)| v.short(*x)));
        row.extend(
            columns
                .iter()
                .map(|&q| significant(quantity_of(&r.summary, q), 6)),
        );
        // Every warning of the run (out of the gun's or shaper's calibration, …).
        row.push(shpb_study::sweep::warnings_cell(&r.summary.warnings));
        t.push_str(&row.join(","));
        t.push('\n');
    }
    let (fast, standard) = counts(&d.runs);
    match varies {
        [first] => {
            let s = &d.solutions[0];
            match &s.root {
                Root::Found { x, value, fast_x } => t.push_str(&format!(
                    "# answer: {} = {} gives {} = {} at standard (fast answer {}); {} runs ({fast} \
                     fast, {standard} standard)\n",
                    first.key,
                    first.short(*x),
                    target.name(),
                    target.show(*value),
                    first.short(*fast_x),
                    d.runs.len()
                )),
                _ => t.push_str(&format!(
                    "# no answer: {}; {} runs ({fast} fast, {standard} standard)\n",
                    status(s, first, target, requires),
                    d.runs.len()
                )),
            }
            if let Some(summary) = &s.summary {
                for (r, ok) in requires.iter().zip(&s.satisfied) {
                    t.push_str(&format!(
                        "# require {}: {} {}\n",
                        r.text,
                        significant(quantity_of(summary, r.quantity), 6),
                        if *ok { "holds" } else { "VIOLATED" }
                    ));
                }
            }
        }
        [first, second] => {
            t.push_str(&format!(
                "# solutions: {} meeting the target at each {}; {} runs ({fast} fast, {standard} \
                 standard)\n",
                first.key,
                second.key,
                d.runs.len()
            ));
            let mut header = vec![second.key.clone(), first.key.clone()];
            header.extend(columns.iter().map(|&q| column_name(q)));
            header.push("status".into());
            t.push_str(&format!("# {}\n", header.join(",")));
            for s in &d.solutions {
                let y = second.short(s.fixed.unwrap_or(f64::NAN));
                let mut row = vec![y];
                match (&s.root, &s.summary) {
                    (Root::Found { x, .. }, Some(summary)) => {
                        row.push(first.short(*x));
                        row.extend(
                            columns
                                .iter()
                                .map(|&q| significant(quantity_of(summary, q), 6)),
                        );
                    }
                    _ => {
                        row.push("-".into());
                        row.extend(columns.iter().map(|_| "-".to_string()));
                    }
                }
                row.push(status(s, first, target, requires));
                t.push_str(&format!("# {}\n", row.join(",")));
            }
        }
        _ => {}
    }
    t
}

/// Runs at fast and at standard.
fn counts(runs: &[Run]) -> (usize, usize) {
    let fast = runs.iter().filter(|r| r.fidelity == Fidelity::Fast).count();
    (fast, runs.len() - fast)
}

/// The report as JSON: the search, every run, the solutions with their status.
fn json(
    d: &Design,
    varies: &[Vary],
    target: &Target,
    requires: &[Requirement],
    tol: f64,
) -> serde_json::Value {
    let results = |s: &RunSummary| -> serde_json::Map<String, serde_json::Value> {
        SUMMARY_COLUMNS
            .iter()
            .zip(s.values())
            .map(|((n, u), v)| {
                (
                    n.to_string(),
                    serde_json::json!({"value": finite(v), "unit": u}),
                )
            })
            .collect()
    };
    let inputs = |xs: &[f64]| -> serde_json::Map<String, serde_json::Value> {
        varies
            .iter()
            .zip(xs)
            .map(|(v, x)| {
                (
                    v.key.clone(),
                    serde_json::json!({"value": finite(*x), "unit": v.unit}),
                )
            })
            .collect()
    };
    let runs: Vec<serde_json::Value> = d
        .runs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            serde_json::json!({
                "run": i + 1,
                "preset": r.fidelity.name(),
                "inputs": inputs(&r.inputs),
                "results": results(&r.summary),
                "warnings": r.summary.warnings,
            })
        })
        .collect();
    let solutions: Vec<serde_json::Value> = d
        .solutions
        .iter()
        .map(|s| {
            let (x, fast_x) = match s.root {
                Root::Found { x, fast_x, .. } => (Some(x), Some(fast_x)),
                _ => (None, None),
            };
            let fixed = match (s.fixed, varies.get(1)) {
                (Some(y), Some(v)) => serde_json::json!({"key": v.key, "value": y, "unit": v.unit}),
                _ => serde_json::Value::Null,
            };
            serde_json::json!({
                "fixed": fixed,
                "found": x.is_some(),
                "input": x.map(|x| serde_json::json!({"key": varies[0].key, "value": x, "unit": varies[0].unit})),
                "fast_input": fast_x,
                "results": s.summary.as_ref().map(results),
                "requirements": requires.iter().zip(&s.satisfied).map(|(r, ok)| serde_json::json!({"require": r.text, "holds": ok})).collect::<Vec<_>>(),
                "status": status(s, &varies[0], target, requires),
            })
        })
        .collect();
    let (fast, standard) = counts(&d.runs);
    serde_json::json!({
        "target": {"quantity": target.name(), "value": target.value_si, "unit": SUMMARY_COLUMNS[target.quantity].1, "as_written": target.text},
        "tolerance": tol,
        "runs_used": {"total": d.runs.len(), "fast": fast, "standard": standard},
        "runs": runs,
        "solutions": solutions,
    })
}

/// The exit status of a finished search: 0 when a solution meets every constraint, else
/// [`Error::NoSolution`] (exit 4) or [`Error::RequirementUnmet`] (exit 5) naming why.
fn verdict(
    d: &Design,
    varies: &[Vary],
    target: &Target,
    requires: &[Requirement],
    settings: Settings,
) -> Result<()> {
    if d.solutions.iter().any(|s| s.acceptable()) {
        return Ok(());
    }
    let first = &varies[0];
    let found: Vec<_> = d
        .solutions
        .iter()
        .filter(|s| matches!(s.root, Root::Found { .. }))
        .collect();
    if found.is_empty() {
        let why: Vec<String> = d
            .solutions
            .iter()
            .map(|s| {
                let at = match (s.fixed, varies.get(1)) {
                    (Some(y), Some(v)) => format!(" at {}={}", v.key, v.short(y)),
                    _ => String::new(),
                };
                match s.root {
                    Root::NotBracketed { at_lo, at_hi }
                        if !(at_lo.is_finite() && at_hi.is_finite()) =>
                    {
                        format!(
                            "the runs at the bounds of {}{at} give no {} ({} at {}, {} at {}): the \
                         scene does not produce it (the equilibrium ratio, strain rate and time \
                         to equilibrium need the reduction of a `shpb` scene)",
                            first.key,
                            target.name(),
                            significant(at_lo, 6),
                            first.short(first.lo),
                            significant(at_hi, 6),
                            first.short(first.hi),
                        )
                    }
                    Root::NotBracketed { at_lo, at_hi } => format!(
                        "no {} in [{}, {}]{at} reaches {} = {}: it spans {}–{} (fast runs at the \
                         bounds; the search assumes a response monotone between them)",
                        first.key,
                        first.short(first.lo),
                        first.short(first.hi),
                        target.name(),
                        target.show(target.value_si),
                        target.show(at_lo.min(at_hi)),
                        target.show(at_lo.max(at_hi)),
                    ),
                    Root::NotConverged { x, value, fidelity } => format!(
                        "the search{at} did not meet {} = {} within ±{} in {} runs (--max-runs): \
                         the closest, {} = {}, gives {} at {}",
                        target.name(),
                        target.show(target.value_si),
                        target.show(settings.tol_abs),
                        settings.max_runs,
                        first.key,
                        first.short(x),
                        target.show(value),
                        fidelity.name()
                    ),
                    Root::Found { .. } => unreachable!("filtered"),
                }
            })
            .collect();
        return Err(Error::NoSolution(why.join("; ")));
    }
    let why: Vec<String> = found
        .iter()
        .map(|s| {
            let summary = s.summary.as_ref().expect("a found root has its run");
            let x = match s.root {
                Root::Found { x, .. } => x,
                _ => unreachable!("filtered"),
            };
            let at = match (s.fixed, varies.get(1)) {
                (Some(y), Some(v)) => format!("{}={}, ", v.key, v.short(y)),
                _ => String::new(),
            };
            let broken: Vec<String> = requires
                .iter()
                .zip(&s.satisfied)
                .filter(|(_, ok)| !**ok)
                .map(|(r, _)| {
                    format!(
                        "{} is {}",
                        r.text,
                        significant(quantity_of(summary, r.quantity), 6)
                    )
                })
                .collect();
            format!(
                "{at}{}={}: {}",
                first.key,
                first.short(x),
                broken.join(", ")
            )
        })
        .collect();
    Err(Error::RequirementUnmet(format!(
        "{} = {} is met, but no solution satisfies every --require: {}",
        target.name(),
        target.show(target.value_si),
        why.join("; ")
    )))
}

//! Design search (`shpb design`): the inputs of a scene that meet a target summary quantity.
//!
//! One varied input (`--vary KEY=LO:HI`): the target is bracketed by runs at the two bounds at
//! the `fast` preset, the root is found at `fast` by the Illinois method (a regula falsi that
//! halves the retained end's value when the same end is kept twice; Dowell & Jarratt 1971, BIT 11,
//! 168–174), then confirmed at `standard` and polished there by secant steps started from the
//! fast answer with the fast slope (the fast–standard offset is small, so one or two standard
//! runs usually suffice). Two varied inputs: the second is set on a grid of values and the first
//! is solved at each, giving the family of solutions; `--require` constraints are checked at each
//! solution. The search works on a closure `f(preset, inputs) -> summary`, so it is tested
//! without running a scene.

use crate::sweep::{RunSummary, SUMMARY_COLUMNS, number_and_unit};
use shpb_core::fidelity::Fidelity;
use shpb_input::{Error, Result};

/// Names a summary quantity may be written with besides [`SUMMARY_COLUMNS`]' own (the issue's
/// `equilibrium_ratio`).
const QUANTITY_ALIASES: &[(&str, &str)] = &[("equilibrium_ratio", "equilibrium_ratio_at_peak")];

/// Units accepted for the value of each summary quantity, with their factor to SI (a bare
/// number is in SI units).
fn quantity_units(quantity: usize) -> &'static [(&'static str, f64)] {
    match SUMMARY_COLUMNS[quantity].0 {
        "peak_force" => &[("", 1.0), ("N", 1.0), ("kN", 1e3), ("MN", 1e6)],
        "displacement_at_peak" => &[
            ("", 1.0),
            ("m", 1.0),
            ("mm", 1e-3),
            ("um", 1e-6),
            ("µm", 1e-6),
        ],
        "peak_strain_rate" => &[("", 1.0), ("/s", 1.0), ("1/s", 1.0)],
        "equilibrium_ratio_at_peak" => &[("", 1.0), ("%", 1e-2)],
        _ => &[
            ("", 1.0),
            ("s", 1.0),
            ("ms", 1e-3),
            ("us", 1e-6),
            ("µs", 1e-6),
        ],
    }
}

/// The allowed quantity names, for error messages.
fn quantity_names() -> String {
    SUMMARY_COLUMNS
        .iter()
        .map(|(n, u)| format!("{n} ({u})"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The index in [`SUMMARY_COLUMNS`] of a quantity name (or alias).
fn quantity_index(name: &str, flag: &str, spec: &str) -> Result<usize> {
    let name = name.trim();
    let name = QUANTITY_ALIASES
        .iter()
        .find(|(a, _)| *a == name)
        .map_or(name, |(_, n)| n);
    SUMMARY_COLUMNS
        .iter()
        .position(|(n, _)| *n == name)
        .ok_or_else(|| {
            crate::api::input_err(
                flag,
                format!("`{spec}`: unknown quantity `{name}`"),
                format!("a summary quantity of `shpb sweep`: {}", quantity_names()),
            )
        })
}

/// A quantity's value with unit (`10kN`, `0.05`, `200um`) in SI units.
fn quantity_value(quantity: usize, text: &str, flag: &str, spec: &str) -> Result<f64> {
    let units = quantity_units(quantity);
    let allowed = || {
        format!(
            "a number with one of the units {} of {}",
            units
                .iter()
                .map(|(u, _)| if u.is_empty() { "(none: SI)" } else { u })
                .collect::<Vec<_>>()
                .join(", "),
            SUMMARY_COLUMNS[quantity].0
        )
    };
    let (v, unit) = number_and_unit(text).ok_or_else(|| {
        crate::api::input_err(
            flag,
            format!("`{spec}`: `{text}` is not a number"),
            allowed(),
        )
    })?;
    let factor = units
        .iter()
        .find(|(u, _)| *u == unit)
        .map(|(_, f)| *f)
        .ok_or_else(|| {
            crate::api::input_err(flag, format!("`{spec}`: unknown unit `{unit}`"), allowed())
        })?;
    let si = v * factor;
    if !si.is_finite() {
        return Err(crate::api::input_err(
            flag,
            format!("`{spec}`: not finite"),
            allowed(),
        ));
    }
    Ok(si)
}

/// The value of summary quantity `quantity` (an index in [`SUMMARY_COLUMNS`]) of a run, SI.
pub fn quantity_of(summary: &RunSummary, quantity: usize) -> f64 {
    summary.values()[quantity]
}

/// A target `QUANTITY=VALUE[unit]` (`--target peak_force=10kN`).
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// Index of the quantity in [`SUMMARY_COLUMNS`].
    pub quantity: usize,
    /// The target value, SI units.
    pub value_si: f64,
    /// The unit the value was written in (empty: SI).
    pub unit: String,
    /// SI value of one `unit`.
    pub unit_si: f64,
    /// As written.
    pub text: String,
}

impl Target {
    /// The quantity's name ([`SUMMARY_COLUMNS`]).
    pub fn name(&self) -> &'static str {
        SUMMARY_COLUMNS[self.quantity].0
    }

    /// A value of the quantity (SI) in the target's unit, 6 significant digits (`10.0587kN`).
    pub fn show(&self, v_si: f64) -> String {
        let unit = if self.unit.is_empty() {
            match SUMMARY_COLUMNS[self.quantity].1 {
                "1" => "",
                u => u,
            }
        } else {
            &self.unit
        };
        let space = if unit.is_empty() || unit == "%" {
            ""
        } else {
            " "
        };
        format!("{}{space}{unit}", significant(v_si / self.unit_si, 6))
    }
}

/// Parses `--target QUANTITY=VALUE[unit]`; the value must be non-zero (the tolerance is relative
/// to it).
pub fn parse_target(spec: &str) -> Result<Target> {
    let (name, value) = spec.split_once('=').ok_or_else(|| {
        crate::api::input_err(
            "--target",
            format!("`{spec}`: no `=`"),
            format!(
                "QUANTITY=VALUE[unit], e.g. peak_force=10kN; QUANTITY: {}",
                quantity_names()
            ),
        )
    })?;
    let quantity = quantity_index(name, "--target", spec)?;
    let value_si = quantity_value(quantity, value, "--target", spec)?;
    let unit = number_and_unit(value).map(|(_, u)| u).unwrap_or_default();
    let unit_si = quantity_units(quantity)
        .iter()
        .find(|(u, _)| *u == unit)
        .map_or(1.0, |(_, f)| *f);
    if value_si == 0.0 {
        return Err(crate::api::input_err(
            "--target",
            format!("`{spec}`: a target of zero"),
            "a non-zero value (the tolerance is relative to it)",
        ));
    }
    // A ratio of magnitudes and a time from the start cannot be negative: refused here, before
    // any run, instead of bracketed and found unreachable (issue 42).
    let name = SUMMARY_COLUMNS[quantity].0;
    if value_si < 0.0 && matches!(name, "equilibrium_ratio_at_peak" | "time_to_equilibrium") {
        return Err(crate::api::input_err(
            "--target",
            format!("`{spec}`: {name} cannot be negative"),
            "a positive value",
        ));
    }
    Ok(Target {
        quantity,
        value_si,
        unit,
        unit_si,
        text: spec.trim().to_string(),
    })
}

/// A comparison of a `--require` constraint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

/// A constraint `QUANTITY<VALUE` (`<`, `<=`, `>`, `>=`) checked at each solution (`--require`).
#[derive(Debug, Clone, PartialEq)]
pub struct Requirement {
    /// Index of the quantity in [`SUMMARY_COLUMNS`].
    pub quantity: usize,
    /// The comparison.
    pub op: Op,
    /// The bound, SI units.
    pub value_si: f64,
    /// As written.
    pub text: String,
}

impl Requirement {
    /// Whether a value satisfies the constraint (NaN, a quantity the run could not give, does not).
    pub fn holds(&self, v: f64) -> bool {
        match self.op {
            Op::Lt => v < self.value_si,
            Op::Le => v <= self.value_si,
            Op::Gt => v > self.value_si,
            Op::Ge => v >= self.value_si,
        }
    }
}

/// Parses `--require QUANTITY<VALUE` (operators `<`, `<=`, `>`, `>=`).
pub fn parse_requirement(spec: &str) -> Result<Requirement> {
    let found = [("<=", Op::Le), (">=", Op::Ge), ("<", Op::Lt), (">", Op::Gt)]
        .into_iter()
        .find_map(|(s, op)| spec.find(s).map(|i| (i, s.len(), op)));
    let Some((i, len, op)) = found else {
        return Err(crate::api::input_err(
            "--require",
            format!("`{spec}`: no comparison"),
            format!(
                "QUANTITY<VALUE with <, <=, > or >=, e.g. equilibrium_ratio<0.05; QUANTITY: {}",
                quantity_names()
            ),
        ));
    };
    let quantity = quantity_index(&spec[..i], "--require", spec)?;
    let value_si = quantity_value(quantity, &spec[i + len..], "--require", spec)?;
    Ok(Requirement {
        quantity,
        op,
        value_si,
        text: spec.trim().to_string(),
    })
}

/// A varied input `KEY=LO:HI` (`--vary pressure=7psi:20psi`): a scene key (the aliases of
/// `shpb sweep --set`) and its bounds in the unit written.
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// Scene key (after aliases: `pressure`, `shaper.thickness_m`).
    pub key: String,
    /// Lower bound, in `unit`.
    pub lo: f64,
    /// Upper bound, in `unit`.
    pub hi: f64,
    /// The unit written (`psi`, `mm`; empty for a plain number).
    pub unit: String,
}

impl Vary {
    /// The value `v` (in the vary's unit) as `--set` takes it: shortest exact decimal and unit.
    pub fn label(&self, v: f64) -> String {
        format!("{v}{}", self.unit)
    }

    /// The value `v` for tables: 6 significant digits and unit.
    pub fn short(&self, v: f64) -> String {
        format!("{}{}", significant(v, 6), self.unit)
    }
}

/// `v` with `digits` significant digits, trailing zeros dropped (`9.95123`, `20`).
pub fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (digits as i32 - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Parses `--vary KEY=LO:HI` (same unit at both ends, LO < HI; `fidelity` is the search's own).
pub fn parse_vary(spec: &str) -> Result<Vary> {
    let allowed = "KEY=LO:HI with LO < HI in one unit, e.g. pressure=7psi:20psi or \
                   shaper.thickness=0.3mm:0.6mm";
    let bad =
        |problem: String| crate::api::input_err("--vary", format!("`{spec}`: {problem}"), allowed);
    let (key, range) = spec.split_once('=').ok_or_else(|| bad("no `=`".into()))?;
    let (lo, hi) = range
        .split_once(':')
        .ok_or_else(|| bad("no `:` between the bounds".into()))?;
    let (lo_v, lo_u) = number_and_unit(lo).ok_or_else(|| bad(format!("`{lo}` is not a number")))?;
    let (hi_v, hi_u) = number_and_unit(hi).ok_or_else(|| bad(format!("`{hi}` is not a number")))?;
    if lo_u != hi_u {
        return Err(bad(format!("units differ: `{lo_u}` and `{hi_u}`")));
    }
    if !(lo_v.is_finite() && hi_v.is_finite() && lo_v < hi_v) {
        return Err(bad("the bounds must be finite with LO < HI".into()));
    }
    if key.trim().is_empty() {
        return Err(bad("empty key".into()));
    }
    // The key's alias and the values' syntax, as `--set` takes them (its errors named as ours).
    let axis = crate::sweep::parse_axis(&format!("{}={},{}", key.trim(), lo.trim(), hi.trim()))
        .map_err(|e| match e {
            Error::Input { problem, .. } => bad(problem),
            e => e,
        })?;
    if axis.key == "fidelity" {
        return Err(bad(
            "the search chooses the preset itself (fast, then standard)".into(),
        ));
    }
    Ok(Vary {
        key: axis.key,
        lo: lo_v,
        hi: hi_v,
        unit: lo_u,
    })
}

/// How a 1-D search ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Root {
    /// The target is met at `standard` within the tolerance at `x`.
    Found {
        /// The input, in the vary's unit.
        x: f64,
        /// The quantity there at `standard`, SI.
        value: f64,
        /// The root found at `fast`.
        fast_x: f64,
    },
    /// The target is not between the quantity's values at the two bounds (at `fast`).
    NotBracketed {
        /// The quantity at the lower bound, SI.
        at_lo: f64,
        /// The quantity at the upper bound, SI.
        at_hi: f64,
    },
    /// The run budget was spent (or the response is flat or jumps) before the tolerance was met.
    NotConverged {
        /// The best input found, in the vary's unit.
        x: f64,
        /// The quantity there, SI.
        value: f64,
        /// The preset of that run.
        fidelity: Fidelity,
    },
}

/// Settings of a 1-D search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Accepted |quantity − target|, SI (the relative `--tol` times |target|).
    pub tol_abs: f64,
    /// The most runs one 1-D search may use (fast and standard together).
    pub max_runs: usize,
}

/// Solves `g(preset, x) = target` for `x` in `[lo, hi]`: brackets at `fast`, Illinois method at
/// `fast` to a quarter of the tolerance, then secant steps at `standard` from the fast root until
/// |g − target| ≤ `tol_abs` (module docs). `g` returns the quantity of one run; it is called at
/// most `max_runs` times.
pub fn solve_1d(
    g: &mut dyn FnMut(Fidelity, f64) -> Result<f64>,
    (lo, hi): (f64, f64),
    target: f64,
    settings: Settings,
) -> Result<Root> {
    let Settings { tol_abs, max_runs } = settings;
    let mut runs = 0usize;
    let mut eval = |fid: Fidelity, x: f64, runs: &mut usize| -> Result<f64> {
        *runs += 1;
        let v = g(fid, x)?;
        Ok(v - target)
    };
    let (mut a, mut b) = (lo, hi);
    let (mut fa, mut fb) = (
        eval(Fidelity::Fast, a, &mut runs)?,
        eval(Fidelity::Fast, b, &mut runs)?,
    );
    if !(fa.is_finite() && fb.is_finite()) || fa * fb > 0.0 {
        return Ok(Root::NotBracketed {
            at_lo: fa + target,
            at_hi: fb + target,
        });
    }
    // True values of the bracket's ends (the Illinois halving scales the stored ones).
    let (mut ta, mut tb) = (fa, fb);
    let fast_tol = 0.25 * tol_abs;
    let mut side = 0i8;
    let (fast_x, fast_slope) = loop {
        if fa.abs() <= fast_tol {
            break (a, (tb - ta) / (b - a));
        }
        if fb.abs() <= fast_tol {
            break (b, (tb - ta) / (b - a));
        }
        if runs >= max_runs || (b - a).abs() <= 1e-12 * (hi - lo) {
            let (x, v) = if ta.abs() < tb.abs() {
                (a, ta)
            } else {
                (b, tb)
            };
            return Ok(Root::NotConverged {
                x,
                value: v + target,
                fidelity: Fidelity::Fast,
            });
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let fc = eval(Fidelity::Fast, c, &mut runs)?;
        if !fc.is_finite() {
            return Err(Error::Invalid {
                quantity: "design target".into(),
                problem: format!("a run at {c} gave a non-finite value"),
                allowed: "a finite summary quantity".into(),
            });
        }
        if fc * fb > 0.0 {
            // c replaces b; a is kept: halve its value if it was kept last time too.
            (b, fb, tb) = (c, fc, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            (a, fa, ta) = (c, fc, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    };
    // Confirm and polish at standard.
    let clamp = |x: f64| x.clamp(lo, hi);
    let (mut x0, mut g0) = (fast_x, eval(Fidelity::Standard, fast_x, &mut runs)?);
    if g0.abs() <= tol_abs {
        return Ok(Root::Found {
            x: x0,
            value: g0 + target,
            fast_x,
        });
    }
    let slope = if fast_slope.is_finite() && fast_slope != 0.0 {
        fast_slope
    } else {
        (fb - fa) / (b - a)
    };
    let mut x1 = clamp(x0 - g0 / slope);
    loop {
        if runs >= max_runs || x1 == x0 || !x1.is_finite() {
            return Ok(Root::NotConverged {
                x: x0,
                value: g0 + target,
                fidelity: Fidelity::Standard,
            });
        }
        let g1 = eval(Fidelity::Standard, x1, &mut runs)?;
        if g1.abs() <= tol_abs {
            return Ok(Root::Found {
                x: x1,
                value: g1 + target,
                fast_x,
            });
        }
        let next = if g1 != g0 {
            clamp(x1 - g1 * (x1 - x0) / (g1 - g0))
        } else {
            f64::NAN
        };
        if g1.abs() < g0.abs() {
            (x0, g0) = (x1, g1);
        }
        x1 = next;
        if x1 == x0 {
            // A step back to the better point: nudge with the fast slope instead.
            x1 = clamp(x0 - g0 / slope);
        }
    }
}

/// One run of a design search.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Preset of the run.
    pub fidelity: Fidelity,
    /// The varied inputs, in their units (as `--vary` wrote them).
    pub inputs: Vec<f64>,
    /// The run's summary.
    pub summary: RunSummary,
}

/// One solution of a design search (one per grid value of the second vary in 2-D).
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The value of the second vary (2-D only), in its unit.
    pub fixed: Option<f64>,
    /// How the 1-D search of the first vary ended.
    pub root: Root,
    /// The standard run's summary at the root (when found).
    pub summary: Option<RunSummary>,
    /// Whether each `--require` holds there (empty if no root was found).
    pub satisfied: Vec<bool>,
}

impl Solution {
    /// Found, and every constraint holds.
    pub fn acceptable(&self) -> bool {
        matches!(self.root, Root::Found { .. }) && self.satisfied.iter().all(|&s| s)
    }
}

/// The result of a design search: every run in order and the solutions.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// The runs, in the order they were made.
    pub runs: Vec<Run>,
    /// One solution (1-D) or one per grid value of the second vary (2-D).
    pub solutions: Vec<Solution>,
}

/// Runs the design search of `target` over `varies` (one or two) with constraints `requires`,
/// calling `run(preset, inputs)` for each run (inputs in the varies' units); 2-D searches solve
/// the first vary at `grid` evenly spaced values of the second (bounds included).
pub fn design(
    run: &mut dyn FnMut(Fidelity, &[f64]) -> Result<RunSummary>,
    varies: &[Vary],
    target: &Target,
    requires: &[Requirement],
    settings: Settings,
    grid: usize,
) -> Result<Design> {
    let fixed: Vec<Option<f64>> = match varies {
        [_] => vec![None],
        [_, second] => (0..grid)
            .map(|i| {
                Some(second.lo + (second.hi - second.lo) * i as f64 / (grid.max(2) - 1) as f64)
            })
            .collect(),
        _ => {
            return Err(crate::api::input_err(
                "--vary",
                format!("{} varied inputs", varies.len()),
                "one (1-D search) or two (a family of solutions over a grid of the second)",
            ));
        }
    };
    let mut runs: Vec<Run> = Vec::new();
    let mut solutions = Vec::new();
    let first = &varies[0];
    for y in fixed {
        let inputs = |x: f64| -> Vec<f64> { std::iter::once(x).chain(y).collect() };
        let root = solve_1d(
            &mut |fid, x| {
                let summary = run(fid, &inputs(x))?;
                let v = quantity_of(&summary, target.quantity);
                runs.push(Run {
                    fidelity: fid,
                    inputs: inputs(x),
                    summary,
                });
                Ok(v)
            },
            (first.lo, first.hi),
            target.value_si,
            settings,
        )?;
        let summary = match &root {
            Root::Found { x, .. } => runs
                .iter()
                .rev()
                .find(|r| r.fidelity == Fidelity::Standard && r.inputs == inputs(*x))
                .map(|r| r.summary.clone()),
            _ => None,
        };
        let satisfied = summary
            .as_ref()
            .map(|s| {
                requires
                    .iter()
                    .map(|r| r.holds(quantity_of(s, r.quantity)))
                    .collect()
            })
            .unwrap_or_default();
        solutions.push(Solution {
            fixed: y,
            root,
            summary,
            satisfied,
        });
    }
    Ok(Design { runs, solutions })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(tol_abs: f64) -> Settings {
        Settings {
            tol_abs,
            max_runs: 30,
        }
    }

    /// A monotone response with a small fast–standard offset: the root at standard is met within
    /// the tolerance, the fast root is near it, and few runs are used.
    #[test]
    fn monotone_root_is_found_at_standard_with_few_runs() {
        // F(p) = 1000 p^0.8 (+0.3 % at fast): target 10 000 at p = 10^(1/0.8).
        let mut calls = Vec::new();
        let mut g = |fid: Fidelity, p: f64| {
            calls.push(fid);
            let k = if fid == Fidelity::Fast { 1.003 } else { 1.0 };
            Ok(1000.0 * k * p.powf(0.8))
        };
        let target = 1e4;
        let root = solve_1d(&mut g, (7.0, 20.0), target, settings(0.002 * target)).unwrap();
        let Root::Found { x, value, fast_x } = root else {
            panic!("{root:?}")
        };
        let exact = 10f64.powf(1.0 / 0.8);
        assert!((value - target).abs() <= 0.002 * target);
        assert!((x - exact).abs() / exact < 0.003, "{x} vs {exact}");
        assert!(fast_x < x, "fast reads high, so its root is lower");
        assert!(calls.len() < 12, "{} runs", calls.len());
        assert_eq!(&calls[..2], &[Fidelity::Fast, Fidelity::Fast]);
        assert_eq!(*calls.last().unwrap(), Fidelity::Standard);
    }

    /// A decreasing response is solved too (the bracket's sign order does not matter).
    #[test]
    fn decreasing_response() {
        let mut g = |_: Fidelity, x: f64| Ok((-x).exp());
        let target = (-1.5f64).exp();
        let Root::Found { x, .. } = solve_1d(&mut g, (0.0, 4.0), target, settings(1e-6)).unwrap()
        else {
            panic!()
        };
        assert!((x - 1.5).abs() < 1e-4, "{x}");
    }

    /// An exact solution at a bound takes the two bracketing runs and one confirmation.
    #[test]
    fn solution_at_a_bound_counts_three_runs() {
        let mut n = 0;
        let mut g = |_: Fidelity, x: f64| {
            n += 1;
            Ok(2.0 * x)
        };
        let r = solve_1d(&mut g, (1.0, 3.0), 6.0, settings(1e-9)).unwrap();
        assert_eq!(
            r,
            Root::Found {
                x: 3.0,
                value: 6.0,
                fast_x: 3.0
            }
        );
        assert_eq!(n, 3);
        // A linear response is solved by the first regula falsi step: 2 + 1 fast, 1 standard.
        let mut n = 0;
        let mut g = |_: Fidelity, x: f64| {
            n += 1;
            Ok(2.0 * x + 1.0)
        };
        let Root::Found { x, .. } = solve_1d(&mut g, (0.0, 4.0), 4.0, settings(1e-9)).unwrap()
        else {
            panic!()
        };
        assert!((x - 1.5).abs() < 1e-12);
        assert_eq!(n, 4);
    }

    /// A target beyond the bounds' values is reported with the span, after two runs.
    #[test]
    fn not_bracketed_reports_the_span() {
        let mut n = 0;
        let mut g = |_: Fidelity, x: f64| {
            n += 1;
            Ok(x * x)
        };
        let r = solve_1d(&mut g, (1.0, 3.0), 100.0, settings(0.1)).unwrap();
        assert_eq!(
            r,
            Root::NotBracketed {
                at_lo: 1.0,
                at_hi: 9.0
            }
        );
        assert_eq!(n, 2);
    }

    /// A non-monotone response bracketed at the bounds converges to one of its roots; one with
    /// the same sign at both bounds is reported as not bracketed (the search does not look for
    /// roots between bounds that do not bracket the target).
    #[test]
    fn non_monotone_response() {
        // (x − 1)(x − 2)(x − 3) + 0: roots at 1, 2, 3; bracketed on [0.5, 3.6].
        let f = |x: f64| (x - 1.0) * (x - 2.0) * (x - 3.0);
        let mut g = |_: Fidelity, x: f64| Ok(f(x));
        let Root::Found { x, value, .. } =
            solve_1d(&mut g, (0.5, 3.6), 0.0, settings(1e-9)).unwrap()
        else {
            panic!()
        };
        assert!(value.abs() <= 1e-9);
        assert!([1.0, 2.0, 3.0].iter().any(|r| (x - r).abs() < 1e-6), "{x}");
        let r = solve_1d(&mut g, (0.5, 2.5), 0.0, settings(1e-9)).unwrap();
        assert!(matches!(r, Root::NotBracketed { .. }), "{r:?}");
    }

    /// The run budget is respected, and a jump across the target never meets it.
    #[test]
    fn budget_and_discontinuity() {
        let mut n = 0;
        let mut g = |_: Fidelity, x: f64| {
            n += 1;
            Ok(if x < 1.234 { 0.0 } else { 1.0 })
        };
        let r = solve_1d(
            &mut g,
            (0.0, 2.0),
            0.5,
            Settings {
                tol_abs: 1e-3,
                max_runs: 9,
            },
        )
        .unwrap();
        assert!(matches!(r, Root::NotConverged { .. }), "{r:?}");
        assert!(n <= 9, "{n}");
    }

    /// The Illinois halving keeps the convergence superlinear on a convex response where plain
    /// regula falsi keeps one end for ever.
    #[test]
    fn illinois_beats_regula_falsi_stagnation() {
        let mut n = 0;
        let mut g = |_: Fidelity, x: f64| {
            n += 1;
            Ok(x.powi(10))
        };
        let Root::Found { x, .. } = solve_1d(&mut g, (0.0, 1.5), 0.5, settings(1e-10)).unwrap()
        else {
            panic!()
        };
        assert!((x.powi(10) - 0.5).abs() <= 1e-10);
        assert!(n < 30, "{n} runs");
    }

    fn summary(force: f64, ratio: f64) -> RunSummary {
        RunSummary {
            index: 0,
            inputs: vec![],
            peak_force_n: force,
            displacement_at_peak_m: f64::NAN,
            peak_strain_rate_per_s: f64::NAN,
            equilibrium_ratio_at_peak: ratio,
            time_to_equilibrium_s: f64::NAN,
            warnings: Vec::new(),
        }
    }

    /// 2-D: the first vary is solved at each grid value of the second; constraints are checked
    /// at each solution; every run is logged with its preset and inputs.
    #[test]
    fn two_d_family_with_constraints() {
        // F = 1000 p (1 + t); ratio = t / 10: a solution for every t, the constraint
        // ratio < 0.05 holds for t < 0.5.
        let varies = [
            parse_vary("pressure=1psi:30psi").unwrap(),
            parse_vary("shaper.thickness=0mm:1mm").unwrap(),
        ];
        let target = parse_target("peak_force=10kN").unwrap();
        let req = parse_requirement("equilibrium_ratio<0.05").unwrap();
        let mut run =
            |_: Fidelity, x: &[f64]| Ok(summary(1000.0 * x[0] * (1.0 + x[1]), x[1] / 10.0));
        let d = design(&mut run, &varies, &target, &[req], settings(10.0), 5).unwrap();
        assert_eq!(d.solutions.len(), 5);
        for s in &d.solutions {
            let t = s.fixed.unwrap();
            let Root::Found { x, .. } = s.root else {
                panic!("{s:?}")
            };
            assert!((x - 10.0 / (1.0 + t)).abs() < 0.01, "{x} at {t}");
            assert_eq!(s.satisfied, vec![t / 10.0 < 0.05]);
        }
        assert_eq!(d.solutions.iter().filter(|s| s.acceptable()).count(), 2);
        assert!(d.runs.iter().all(|r| r.inputs.len() == 2));
        // One vary only with three is refused.
        let e = design(
            &mut run,
            &vec![varies[0].clone(); 3],
            &target,
            &[],
            settings(1.0),
            5,
        );
        assert!(e.unwrap_err().to_string().contains("--vary"));
    }

    /// Targets, constraints and varies parse with units; errors name the flag and what is allowed.
    #[test]
    fn specifications_parse() {
        let t = parse_target("peak_force=10kN").unwrap();
        assert_eq!(
            (SUMMARY_COLUMNS[t.quantity].0, t.value_si),
            ("peak_force", 1e4)
        );
        let d = parse_target("displacement_at_peak=200um").unwrap().value_si;
        assert!((d - 200e-6).abs() < 1e-18, "{d}");
        let r = parse_requirement("equilibrium_ratio<=5%").unwrap();
        assert_eq!((r.op, r.value_si), (Op::Le, 0.05));
        assert!(r.holds(0.05) && !r.holds(f64::NAN));
        let r = parse_requirement("time_to_equilibrium>30us").unwrap();
        assert!(r.op == Op::Gt && (r.value_si - 30e-6).abs() < 1e-18);
        let v = parse_vary("gun.pressure=7psi:20psi").unwrap();
        assert_eq!(
            (v.key.as_str(), v.lo, v.hi, v.unit.as_str()),
            ("pressure", 7.0, 20.0, "psi")
        );
        assert_eq!(v.label(9.5), "9.5psi");
        assert_eq!(v.short(9.951234567), "9.95123psi");
        for (bad, flag, says) in [
            ("peak=10kN", "--target", "peak_force (N)"),
            ("peak_force=10furlong", "--target", "kN"),
            ("peak_force", "--target", "QUANTITY=VALUE"),
            ("peak_force=0kN", "--target", "non-zero"),
        ] {
            let e = parse_target(bad).unwrap_err().to_string();
            assert!(e.contains(flag) && e.contains(says), "{bad}: {e}");
        }
        for bad in [
            "equilibrium_ratio~0.05",
            "ratio<0.05",
            "equilibrium_ratio<x",
        ] {
            let e = parse_requirement(bad).unwrap_err().to_string();
            assert!(e.contains("--require"), "{bad}: {e}");
        }
        for bad in [
            "pressure=7psi",
            "pressure=20psi:7psi",
            "pressure=7psi:20kPa",
            "fidelity=1:2",
            "=1:2",
            "shaper.thickness=1furlong:2furlong",
        ] {
            let e = parse_vary(bad).unwrap_err().to_string();
            assert!(e.contains("--vary"), "{bad}: {e}");
        }
        assert_eq!(significant(20.0, 6), "20");
        assert_eq!(significant(0.000123456789, 3), "0.000123");
    }
}

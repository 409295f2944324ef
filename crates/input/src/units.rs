//! The one unit parser of shpb: pressures written with their unit (`10psi`, `68.9kPa`).

use crate::error::{Error, Result, Validator};
pub use shpb_core::striker::PSI_PA;

/// Parses a pressure with unit: `10psi`, `68.9kPa`, `68948Pa`, `0.1MPa`, `1bar` (gauge pressure), to Pa.
pub fn parse_pressure(text: &str) -> std::result::Result<f64, String> {
    let t = text.trim();
    // The unit is the trailing run of letters (so exponents such as 1e5Pa stay in the number).
    // (Step over the whole character found: it may be several bytes long, e.g. `é`.)
    let unit_start = t
        .char_indices()
        .rev()
        .find(|&(_, c)| !c.is_ascii_alphabetic())
        .map(|(i, c)| i + c.len_utf8())
        .unwrap_or(0);
    let (num, unit) = t.split_at(unit_start);
    let value: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number with a unit"))?;
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "psi" => PSI_PA,
        "pa" => 1.0,
        "kpa" => 1e3,
        "mpa" => 1e6,
        "bar" => 1e5,
        "" => return Err(format!("`{text}` has no unit")),
        u => return Err(format!("unknown pressure unit `{u}`")),
    };
    let p = value * scale;
    if !p.is_finite() {
        return Err(format!("`{text}` is not finite"));
    }
    Ok(p)
}

/// Allowed pressure syntax, for error messages.
pub const PRESSURE_SYNTAX: &str =
    "a number with a unit: psi, Pa, kPa, MPa or bar (gauge), e.g. 10psi or 68.9kPa";

/// Validates a pressure given as text (`10psi`) for key `key`.
pub fn pressure_from_text(text: &str, v: &Validator, key: &str) -> Result<f64> {
    parse_pressure(text).map_err(|problem| v.error(key, problem, PRESSURE_SYNTAX))
}

/// Wraps a plain error string into an input error (helper for CLI options).
pub fn cli_pressure(text: &str) -> Result<f64> {
    parse_pressure(text).map_err(|problem| Error::Input {
        file: "command line".into(),
        key: "--pressure".into(),
        problem,
        allowed: PRESSURE_SYNTAX.into(),
    })
}

/// Splits `12.5psi` into (12.5, "psi"); `None` when it does not start with a number. A trailing
/// `e`/`E` belongs to the unit when no exponent digits follow (`5e` is 5 and the unit `e`).
pub fn number_and_unit(text: &str) -> Option<(f64, String)> {
    let t = text.trim();
    let split = t
        .char_indices()
        .find(|(_, c)| !(c.is_ascii_digit() || "+-.eE".contains(*c)))
        .map(|(i, _)| i)
        .unwrap_or(t.len());
    let (mut num, mut unit) = t.split_at(split);
    while num.ends_with(['e', 'E', '+', '-']) {
        let k = num.len() - 1;
        unit = &t[k..];
        num = &t[..k];
    }
    let value: f64 = num.parse().ok()?;
    Some((value, unit.trim().to_string()))
}

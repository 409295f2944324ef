//! The one unit parser of shpb: pressures written with their unit (`10psi`, `68.9kPa`).

use crate::error::{Error, Result, Validator};
pub use shpb_core::striker::PSI_PA;

/// Parses a pressure with unit: `10psi`, `68.9kPa`, `68948Pa`, `0.1MPa`, `1.9GPa`, `1bar` (gauge pressure), to Pa.
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
    // Case-exact SI symbols: `mPa` is the millipascal, not the megapascal `MPa`, so a unit in
    // any other case is refused rather than guessed.
    let scale = match unit.trim() {
        "psi" => PSI_PA,
        "Pa" => 1.0,
        "kPa" => 1e3,
        "MPa" => 1e6,
        // Material constants (a yield stress, a modulus) are given in GPa too.
        "GPa" => 1e9,
        "bar" => 1e5,
        "" => return Err(format!("`{text}` has no unit")),
        u => {
            let hint = match u.to_ascii_lowercase().as_str() {
                "mpa" if u == "mPa" => {
                    " (`mPa` is the millipascal; the megapascal is `MPa`, case matters)".to_string()
                }
                l @ ("psi" | "pa" | "kpa" | "mpa" | "gpa" | "bar") => {
                    let exact = ["psi", "Pa", "kPa", "MPa", "GPa", "bar"]
                        .into_iter()
                        .find(|e| e.to_ascii_lowercase() == l)
                        .unwrap_or("");
                    format!(" (units are case-sensitive: did you mean `{exact}`?)")
                }
                _ => String::new(),
            };
            return Err(format!("unknown pressure unit `{u}`{hint}"));
        }
    };
    let p = value * scale;
    if !p.is_finite() {
        return Err(format!("`{text}` is not finite"));
    }
    Ok(p)
}

/// Allowed pressure syntax, for error messages.
pub const PRESSURE_SYNTAX: &str = "a number with a unit: psi, Pa, kPa, MPa or bar (gauge), \
    written case-exact (mPa is the millipascal), e.g. 10psi or 68.9kPa";

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_case_exact_si() {
        assert_eq!(parse_pressure("0.1MPa"), Ok(1e5));
        assert_eq!(parse_pressure("68.9kPa"), Ok(68.9e3));
        assert_eq!(parse_pressure("1e5Pa"), Ok(1e5));
        assert_eq!(parse_pressure("10psi"), Ok(10.0 * PSI_PA));
        assert_eq!(parse_pressure("1bar"), Ok(1e5));
        // The millipascal is not the megapascal: refused, naming both.
        let e = parse_pressure("0.1mPa").unwrap_err();
        assert!(e.contains("millipascal") && e.contains("`MPa`"), "{e}");
        for wrong in ["0.1mpa", "0.1MPA", "10PSI", "68.9KPA", "1Bar", "5pa"] {
            let e = parse_pressure(wrong).unwrap_err();
            assert!(e.contains("case"), "{wrong}: {e}");
        }
    }
}

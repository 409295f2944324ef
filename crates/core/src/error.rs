//! Typed errors of the physics core: a parameter outside the range where a model holds, a run
//! that became numerically unstable, or a run its progress callback cancelled. They name the physical quantity, never a file or key: the
//! input layer (`shpb-input`) maps them to the file and key the user wrote.

/// An error of the physics core.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A physical parameter is not finite or outside the range where the model holds.
    #[error("{}{quantity}{}: {problem}; allowed: {allowed}", if object.is_empty() { "".to_string() } else { format!("{object}: `") }, if object.is_empty() { "" } else { "`" })]
    Invalid {
        /// The object the quantity belongs to (`bar incident`, `reduction options`, a record's
        /// label), or empty.
        object: String,
        /// The quantity, by its field name in the core (e.g. `time_step_s`, `gun pressure`).
        quantity: String,
        /// What is wrong with it.
        problem: String,
        /// The allowed range or set of values.
        allowed: String,
    },
    /// A run was stopped by its caller (the progress callback asked to stop, e.g. on Ctrl-C).
    #[error("run stopped by the caller at step {step} (t = {time_s:.6e} s)")]
    Cancelled {
        /// Steps done.
        step: usize,
        /// Simulated time reached, s.
        time_s: f64,
    },
    /// A run became numerically unstable; names the step, time and quantity.
    #[error("numerical instability at step {step} (t = {time_s:.6e} s): {quantity} = {value:e}")]
    Unstable {
        /// Step index at which the problem was detected.
        step: usize,
        /// Simulated time of that step, s.
        time_s: f64,
        /// The quantity that became non-finite or blew up.
        quantity: String,
        /// Its value.
        value: f64,
    },
}

/// Result alias of the core.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An [`Error::Invalid`] for `quantity` (of no named object).
    pub fn invalid(
        quantity: impl Into<String>,
        problem: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            object: String::new(),
            quantity: quantity.into(),
            problem: problem.into(),
            allowed: allowed.into(),
        }
    }
}

/// Checks `lo <= value <= hi` and that `value` is finite; errors name `quantity`. Numbers in the
/// message are written by [`format_si`] (`5 mm`, not `5e-3 m`), the bounds rounded inwards.
pub fn in_range(quantity: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
    let allowed = || format_range(lo, hi, unit);
    if !value.is_finite() {
        return Err(Error::invalid(
            quantity,
            format!("{value} is not a finite number"),
            allowed(),
        ));
    }
    if value < lo || value > hi {
        return Err(Error::invalid(
            quantity,
            format!("{} is out of range", format_si(value, split_unit(unit).0)),
            allowed(),
        ));
    }
    Ok(value)
}

/// Checks `0 < value <= hi` and that `value` is finite; errors name `quantity` (numbers written
/// by [`format_si`]).
pub fn positive(quantity: &str, value: f64, hi: f64, unit: &str) -> Result<f64> {
    if !value.is_finite() || value <= 0.0 || value > hi {
        let (base, note) = split_unit(unit);
        return Err(Error::invalid(
            quantity,
            if value.is_finite() {
                format!("{} is out of range", format_si(value, base))
            } else {
                format!("{value} is not a finite number")
            },
            format!(
                "greater than 0 and at most {}{note}",
                format_bound(hi, base, Round::Down)
            ),
        ));
    }
    Ok(value)
}

/// The range `lo` to `hi` in `unit` as [`format_si`] writes numbers, the bounds rounded inwards
/// so that each printed bound is itself inside the range (`10 µm to 50 mm`, `-1e4 to 1e4 m/s`,
/// `6.5 to 29.9 psi`); a note after the unit (`s (the limit)`) follows the range.
pub fn format_range(lo: f64, hi: f64, unit: &str) -> String {
    let (base, note) = split_unit(unit);
    let lo = format_bound(lo, base, Round::Up);
    let hi = format_bound(hi, base, Round::Down);
    if prefixable(base) || base.is_empty() {
        format!("{lo} to {hi}{note}")
    } else {
        // One unit after both numbers.
        let lo = lo.strip_suffix(&format!(" {base}")).unwrap_or(&lo);
        format!("{lo} to {hi}{note}")
    }
}

/// A number as a person writes it in a message: three significant digits (the exact value when it
/// has at most four, e.g. `0.4999` or `206.8 kPa`), with an SI prefix for the units that take one
/// (`s`, `m`, `Pa`, `N`, `J`, `V`, `Hz`, `B`: `3.48 µs`, `50 mm`, `44.8 kPa`), plain or `1.12e4` for
/// the others (`m/s`, `1/s`, `kg`, …, and no unit), never `-0`. `unit` may carry a note after a
/// space (`s (the stability limit)`), kept after the number. Non-finite values print as Rust
/// does (`NaN`, `inf`).
pub fn format_si(value: f64, unit: &str) -> String {
    let (base, note) = split_unit(unit);
    format!("{}{note}", format_bound(value, base, Round::Nearest))
}

/// How [`format_bound`] rounds a value that needs more than four significant digits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Round {
    Nearest,
    /// Towards +∞ (a lower bound stays inside the range).
    Up,
    /// Towards −∞ (an upper bound stays inside the range).
    Down,
}

/// The units [`format_si`] gives an SI prefix.
fn prefixable(base: &str) -> bool {
    matches!(base, "s" | "m" | "Pa" | "N" | "J" | "V" | "Hz" | "B")
}

/// `unit` split into its symbol and a note (`"s (the limit)"` → `("s", " (the limit)")`).
fn split_unit(unit: &str) -> (&str, &str) {
    match unit.find(' ') {
        Some(i) => (&unit[..i], &unit[i..]),
        None => (unit, ""),
    }
}

/// [`format_si`] of `value` in unit `base` (no note), rounding as `round` says.
fn format_bound(value: f64, base: &str, round: Round) -> String {
    let with_unit = |number: String| {
        if base.is_empty() {
            number
        } else {
            format!("{number} {base}")
        }
    };
    if !value.is_finite() {
        return with_unit(format!("{value}"));
    }
    if value == 0.0 {
        return with_unit("0".into());
    }
    // Significant digits and decimal exponent: value = ±d.ddd × 10^exp.
    let shortest = format!("{:e}", value.abs());
    let (mantissa, exp) = shortest.split_once('e').expect("{:e} has an exponent");
    let mut exp: i32 = exp.parse().expect("{:e} exponent is an integer");
    let mut digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    if digits.len() > 4 {
        // Three significant digits, rounded in the direction asked (of the signed value).
        let scaled = value.abs() / 10f64.powi(exp - 2);
        let towards_up = match round {
            Round::Nearest => None,
            Round::Up => Some(value > 0.0),
            Round::Down => Some(value < 0.0),
        };
        let mut r = match towards_up {
            None => scaled.round(),
            Some(true) => scaled.ceil(),
            Some(false) => scaled.floor(),
        } as u64;
        if r >= 1000 {
            r /= 10;
            exp += 1;
        }
        digits = r.to_string();
    }
    let digits = digits.trim_end_matches('0');
    let digits = if digits.is_empty() { "0" } else { digits };
    let sign = if value < 0.0 { "-" } else { "" };
    if prefixable(base) {
        let scale = exp.div_euclid(3) * 3;
        let prefix = match scale {
            -15 => Some("f"),
            -12 => Some("p"),
            -9 => Some("n"),
            -6 => Some("µ"),
            -3 => Some("m"),
            0 => Some(""),
            3 => Some("k"),
            6 => Some("M"),
            9 => Some("G"),
            12 => Some("T"),
            _ => None,
        };
        if let Some(prefix) = prefix {
            return format!("{sign}{} {prefix}{base}", decimal(digits, exp - scale));
        }
    } else if (-3..=3).contains(&exp) {
        return with_unit(format!("{sign}{}", decimal(digits, exp)));
    }
    let tail = if digits.len() > 1 {
        format!("{}.{}", &digits[..1], &digits[1..])
    } else {
        digits.to_string()
    };
    with_unit(format!("{sign}{tail}e{exp}"))
}

/// The decimal number with significant `digits` whose first digit is at 10^`exp`.
fn decimal(digits: &str, exp: i32) -> String {
    let before = exp + 1;
    if before <= 0 {
        format!("0.{}{digits}", "0".repeat((-before) as usize))
    } else if before as usize >= digits.len() {
        format!("{digits}{}", "0".repeat(before as usize - digits.len()))
    } else {
        let (a, b) = digits.split_at(before as usize);
        format!("{a}.{b}")
    }
}

/// Names the quantities of one physical object (e.g. `bar incident`) in [`Error::Invalid`]:
/// object `bar incident`, quantity `segments[0].length_m`. A core helper, not a view of any file.
#[derive(Debug, Clone)]
pub struct Named {
    object: String,
    prefix: String,
}

impl Named {
    /// Quantities of the object `object` (may be empty).
    pub fn new(object: impl Into<String>) -> Self {
        Named {
            object: object.into(),
            prefix: String::new(),
        }
    }

    /// The quantities of the part `part` of this object (`segments[0]`, `material`).
    pub fn table(&self, part: &str) -> Self {
        Named {
            object: self.object.clone(),
            prefix: self.key(part),
        }
    }

    /// The full name of `key` in this object.
    pub fn key(&self, key: &str) -> String {
        if self.prefix.is_empty() {
            key.to_string()
        } else {
            format!("{}.{}", self.prefix, key)
        }
    }

    /// An [`Error::Invalid`] for `key` of this object.
    pub fn error(
        &self,
        key: &str,
        problem: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Error {
        Error::Invalid {
            object: self.object.clone(),
            quantity: self.key(key),
            problem: problem.into(),
            allowed: allowed.into(),
        }
    }

    /// [`in_range`] for `key` of this object.
    pub fn in_range(&self, key: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
        in_range(&self.key(key), value, lo, hi, unit).map_err(|e| self.adopt(e))
    }

    /// [`positive`] for `key` of this object.
    pub fn positive(&self, key: &str, value: f64, hi: f64, unit: &str) -> Result<f64> {
        positive(&self.key(key), value, hi, unit).map_err(|e| self.adopt(e))
    }

    /// Marks an error of a bare quantity as this object's.
    fn adopt(&self, e: Error) -> Error {
        match e {
            Error::Invalid {
                quantity,
                problem,
                allowed,
                ..
            } => Error::Invalid {
                object: self.object.clone(),
                quantity,
                problem,
                allowed,
            },
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_a_person_writes_them() {
        assert_eq!(format_si(0.0, "s"), "0 s");
        assert_eq!(format_si(-0.0, "s"), "0 s");
        assert_eq!(format_si(3.4840293641626996e-6, "s"), "3.48 µs");
        assert_eq!(format_si(5e-3, "m"), "5 mm");
        assert_eq!(format_si(1e-5, "m"), "10 µm");
        assert_eq!(format_si(1.5875e-3, "m"), "1.59 mm");
        assert_eq!(format_bound(1.5875e-3, "m", Round::Down), "1.58 mm");
        assert_eq!(format_si(44.8e3, "Pa"), "44.8 kPa");
        assert_eq!(format_si(206.8e3, "Pa"), "206.8 kPa");
        assert_eq!(format_si(192e9, "Pa"), "192 GPa");
        assert_eq!(format_si(1e20, "Pa"), "1e20 Pa");
        assert_eq!(format_si(-1e4, "m/s"), "-1e4 m/s");
        assert_eq!(format_si(5.0, "m/s"), "5 m/s");
        assert_eq!(format_si(0.4999, ""), "0.4999");
        assert_eq!(format_si(1.12468e4, "kg/s"), "1.12e4 kg/s");
        assert_eq!(format_si(1e9, "1/s"), "1e9 1/s");
        assert_eq!(format_si(-1e-5, "psi"), "-1e-5 psi");
        assert_eq!(format_si(999.96, "s"), "1 ks");
        assert_eq!(format_si(f64::NAN, "m"), "NaN m");
        assert_eq!(
            format_si(2e-6, "s (the stability limit)"),
            "2 µs (the stability limit)"
        );
        // Bounds are rounded inwards, so the number printed is itself allowed.
        assert_eq!(format_bound(29.9943, "psi", Round::Down), "29.9 psi");
        assert_eq!(format_bound(6.49773, "psi", Round::Up), "6.5 psi");
        assert_eq!(format_bound(-6.49773, "psi", Round::Down), "-6.5 psi");
    }

    #[test]
    fn range_messages_use_the_formatter() {
        let e = positive("time_step_s", 0.0, 3.4840293641626996e-6, "s").unwrap_err();
        assert_eq!(
            e.to_string(),
            "time_step_s: 0 s is out of range; allowed: greater than 0 and at most 3.48 µs"
        );
        let e = in_range("cell_size_m", 0.1, 1e-5, 0.05, "m").unwrap_err();
        assert_eq!(
            e.to_string(),
            "cell_size_m: 100 mm is out of range; allowed: 10 µm to 50 mm"
        );
        let e = in_range("velocity1_m_s", 2e4, -1e4, 1e4, "m/s").unwrap_err();
        assert_eq!(
            e.to_string(),
            "velocity1_m_s: 2e4 m/s is out of range; allowed: -1e4 to 1e4 m/s"
        );
        let e = in_range("poisson_ratio", 0.6, -0.99, 0.4999, "").unwrap_err();
        assert_eq!(
            e.to_string(),
            "poisson_ratio: 0.6 is out of range; allowed: -0.99 to 0.4999"
        );
    }

    #[test]
    fn range_checks_name_the_quantity_and_reject_nan() {
        assert_eq!(in_range("x_m", 0.5, 0.0, 1.0, "m"), Ok(0.5));
        let e = in_range("x_m", f64::NAN, 0.0, 1.0, "m").unwrap_err();
        assert!(
            e.to_string().starts_with("x_m: NaN is not a finite number"),
            "{e}"
        );
        assert!(positive("r_m", 0.0, 1.0, "m").is_err());
        assert!(positive("r_m", 2.0, 1.0, "m").is_err());
        assert_eq!(positive("r_m", 1.0, 1.0, "m"), Ok(1.0));
        let bar = Named::new("bar incident").table("segments[0]");
        assert_eq!(bar.key("length_m"), "segments[0].length_m");
        let e = bar.positive("length_m", -1.0, 10.0, "m").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("bar incident: `segments[0].length_m`: "),
            "{e}"
        );
    }
}

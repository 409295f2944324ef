//! Typed errors of the physics core: a parameter outside the range where a model holds, or a run
//! that became numerically unstable. They name the physical quantity, never a file or key: the
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

/// Checks `lo <= value <= hi` and that `value` is finite; errors name `quantity`.
pub fn in_range(quantity: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
    if !value.is_finite() {
        return Err(Error::invalid(
            quantity,
            format!("{value} is not a finite number"),
            format!("{lo:e} to {hi:e} {unit}"),
        ));
    }
    if value < lo || value > hi {
        return Err(Error::invalid(
            quantity,
            format!("{value:e} {unit} is out of range"),
            format!("{lo:e} to {hi:e} {unit}"),
        ));
    }
    Ok(value)
}

/// Checks `0 < value <= hi` and that `value` is finite; errors name `quantity`.
pub fn positive(quantity: &str, value: f64, hi: f64, unit: &str) -> Result<f64> {
    if !value.is_finite() || value <= 0.0 || value > hi {
        return Err(Error::invalid(
            quantity,
            if value.is_finite() {
                format!("{value:e} {unit} is out of range")
            } else {
                format!("{value} is not a finite number")
            },
            format!("greater than 0 and at most {hi:e} {unit}"),
        ));
    }
    Ok(value)
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

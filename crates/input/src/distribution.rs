//! Uncertain scene inputs (`shpb study`): any numeric scene key may be written as a distribution,
//! an inline table of one of four forms (docs/physics.md §10.1), with units as the key takes them:
//!
//! * `{ mean = "12.5psi", sd = "0.6psi" }` — normal;
//! * `{ min = "0.40mm", max = "0.46mm" }` — uniform;
//! * `{ median = "0.43mm", gsd = 1.05 }` — log-normal: ln X normal with mean ln(median) and
//!   standard deviation ln(gsd) (the geometric standard deviation, a plain number > 1);
//! * `{ values = ["12.1psi", "12.6psi", "12.9psi"] }` — the measured values, each drawn with
//!   equal weight.
//!
//! This module finds and validates them; `shpb_study::uq` samples them. `shpb run` refuses a
//! scene that holds one ([`refuse_distributions`]).

use crate::error::{Error, Result, Validator};

/// The keys a distribution table may hold.
pub const DISTRIBUTION_KEYS: [&str; 7] = ["mean", "sd", "min", "max", "median", "gsd", "values"];

/// The allowed forms, for error messages.
pub const DISTRIBUTION_FORMS: &str = "{ mean = X, sd = S } (normal, S > 0), { min = A, max = B } \
     (uniform, A < B), { median = M, gsd = G } (log-normal, M > 0, G > 1 a plain number) or \
     { values = [X1, X2, …] } (measured values, at least 2), the numbers with the key's units \
     (e.g. \"12.5psi\", \"0.4mm\", or plain numbers in the key's SI units)";

/// Length units accepted for keys ending in `_m`, with their factor to metres (as `shpb sweep`).
pub const LENGTH_UNITS: &[(&str, f64)] = &[("mm", 1e-3), ("um", 1e-6), ("µm", 1e-6), ("m", 1.0)];

/// A probability distribution of one input, in the units it was written in ([`Uncertain::unit`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// Normal (Gaussian) with mean and standard deviation.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
    },
    /// Uniform on [min, max].
    Uniform {
        /// Lower end.
        min: f64,
        /// Upper end (> min).
        max: f64,
    },
    /// Log-normal: ln X ~ N(ln median, ln gsd).
    LogNormal {
        /// Median (> 0).
        median: f64,
        /// Geometric standard deviation (> 1, unitless).
        gsd: f64,
    },
    /// The measured values, each with probability 1/n (the empirical distribution).
    Empirical {
        /// The values, sorted ascending.
        values: Vec<f64>,
    },
}

impl Distribution {
    /// The central value: the mean (normal), the mid-range (uniform), the median (log-normal,
    /// measured values; the lower median of an even count).
    pub fn central(&self) -> f64 {
        match self {
            Distribution::Normal { mean, .. } => *mean,
            Distribution::Uniform { min, max } => 0.5 * (min + max),
            Distribution::LogNormal { median, .. } => *median,
            Distribution::Empirical { values } => values[(values.len() - 1) / 2],
        }
    }

    /// The distribution as written, for tables and the study file (`normal(mean=12.5, sd=0.6) psi`).
    pub fn describe(&self, unit: &str) -> String {
        let u = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        match self {
            Distribution::Normal { mean, sd } => format!("normal(mean={mean}, sd={sd}){u}"),
            Distribution::Uniform { min, max } => format!("uniform(min={min}, max={max}){u}"),
            Distribution::LogNormal { median, gsd } => {
                format!("log-normal(median={median}{u}, gsd={gsd})")
            }
            Distribution::Empirical { values } => {
                let v: Vec<String> = values.iter().map(|x| x.to_string()).collect();
                format!("values({}){u}", v.join(", "))
            }
        }
    }
}

/// One uncertain input of a scene: its key path, its distribution and the unit its numbers
/// carry (`psi`, `mm`, or empty for plain numbers in the key's SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertain {
    /// Dotted scene key (`pressure`, `shaper.thickness_m`).
    pub key: String,
    /// The distribution, in `unit`.
    pub distribution: Distribution,
    /// The unit of the numbers as written (`psi`, `mm`, empty).
    pub unit: String,
}

impl Uncertain {
    /// The scene value of a number `x` of this input in its unit: a plain number stays a float;
    /// a length of an `_m` key is converted to m; anything else (a pressure) is the text
    /// `{x}{unit}` the scene parses (the shortest text that reads back as `x`).
    pub fn value(&self, x: f64) -> toml::Value {
        if self.unit.is_empty() {
            return toml::Value::Float(x);
        }
        if self.key.ends_with("_m")
            && let Some((_, f)) = LENGTH_UNITS.iter().find(|(u, _)| *u == self.unit)
        {
            return toml::Value::Float(x * f);
        }
        toml::Value::String(self.label(x))
    }

    /// A number of this input as written, with its unit (`12.53psi`).
    pub fn label(&self, x: f64) -> String {
        format!("{x}{}", self.unit)
    }
}

/// Whether `table` is meant as a distribution: it is not empty and has only distribution keys.
fn is_distribution(table: &toml::Table) -> bool {
    !table.is_empty()
        && table
            .keys()
            .all(|k| DISTRIBUTION_KEYS.contains(&k.as_str()))
}

/// Every distribution of the scene `text` of `file`, in the order of the file's keys (tables
/// searched at any depth; `key` dotted), validated: an error names the file, the key and the
/// allowed forms.
pub fn find_distributions(text: &str, file: &str) -> Result<Vec<Uncertain>> {
    let table: toml::Table = crate::toml_file::parse_as(text, file)?;
    let mut found = Vec::new();
    walk(&table, "", &Validator::new(file), &mut found)?;
    Ok(found)
}

fn walk(
    table: &toml::Table,
    prefix: &str,
    v: &Validator,
    found: &mut Vec<Uncertain>,
) -> Result<()> {
    for (key, value) in table {
        let path = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        match value {
            toml::Value::Table(t) if is_distribution(t) => {
                found.push(parse_distribution(&path, t, v)?);
            }
            toml::Value::Table(t) => walk(t, &path, v, found)?,
            toml::Value::Array(items) if items.iter().any(holds_distribution) => {
                return Err(v.error(
                    &path,
                    "a distribution inside a list: only keys reached by a dotted path can be drawn",
                    "distributions on keys of tables (`pressure`, `shaper.thickness_m`), not inside \
                     arrays such as [[specimen.sphere]]",
                ));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Whether `value` is or holds a distribution table (at any depth, through tables and arrays).
fn holds_distribution(value: &toml::Value) -> bool {
    match value {
        toml::Value::Table(t) => is_distribution(t) || t.values().any(holds_distribution),
        toml::Value::Array(items) => items.iter().any(holds_distribution),
        _ => false,
    }
}

/// Validates one distribution table of key `key`.
fn parse_distribution(key: &str, t: &toml::Table, v: &Validator) -> Result<Uncertain> {
    let err = |problem: String| v.error(key, problem, DISTRIBUTION_FORMS);
    let number = |name: &str, value: &toml::Value| -> Result<(f64, String)> {
        let (x, unit) = match value {
            toml::Value::Float(x) => (*x, String::new()),
            toml::Value::Integer(i) => (*i as f64, String::new()),
            toml::Value::String(s) => crate::units::number_and_unit(s)
                .ok_or_else(|| err(format!("{name} = `{s}` is not a number with a unit")))?,
            other => return Err(err(format!("{name} = {other} is not a number"))),
        };
        if !x.is_finite() {
            return Err(err(format!("{name} is not finite")));
        }
        Ok((x, unit))
    };
    let mut names: Vec<&str> = t.keys().map(String::as_str).collect();
    names.sort_unstable();
    let same_unit = |a: &(f64, String), b: &(f64, String), what: &str| -> Result<String> {
        if a.1 != b.1 {
            return Err(err(format!(
                "{what} are in different units (`{}` and `{}`)",
                a.1, b.1
            )));
        }
        Ok(a.1.clone())
    };
    let (distribution, unit) = match names[..] {
        ["mean", "sd"] => {
            let (m, s) = (number("mean", &t["mean"])?, number("sd", &t["sd"])?);
            let unit = same_unit(&m, &s, "mean and sd")?;
            if s.0 <= 0.0 {
                return Err(err(format!("sd = {} is not positive", s.0)));
            }
            (Distribution::Normal { mean: m.0, sd: s.0 }, unit)
        }
        ["max", "min"] => {
            let (a, b) = (number("min", &t["min"])?, number("max", &t["max"])?);
            let unit = same_unit(&a, &b, "min and max")?;
            if a.0 >= b.0 {
                return Err(err(format!("min = {} is not below max = {}", a.0, b.0)));
            }
            (Distribution::Uniform { min: a.0, max: b.0 }, unit)
        }
        ["gsd", "median"] => {
            let m = number("median", &t["median"])?;
            let g = number("gsd", &t["gsd"])?;
            if !g.1.is_empty() {
                return Err(err(format!("gsd has a unit (`{}`): it is a ratio", g.1)));
            }
            if m.0 <= 0.0 || g.0 <= 1.0 {
                return Err(err(format!(
                    "median = {} must be positive and gsd = {} above 1",
                    m.0, g.0
                )));
            }
            (
                Distribution::LogNormal {
                    median: m.0,
                    gsd: g.0,
                },
                m.1,
            )
        }
        ["values"] => {
            let toml::Value::Array(items) = &t["values"] else {
                return Err(err("values is not a list".into()));
            };
            if items.len() < 2 {
                return Err(err(format!(
                    "{} value(s): a list needs at least 2",
                    items.len()
                )));
            }
            let parsed = items
                .iter()
                .map(|x| number("values", x))
                .collect::<Result<Vec<_>>>()?;
            let unit = parsed[0].1.clone();
            for p in &parsed[1..] {
                same_unit(&parsed[0], p, "the values")?;
            }
            let mut values: Vec<f64> = parsed.into_iter().map(|p| p.0).collect();
            values.sort_by(f64::total_cmp);
            (Distribution::Empirical { values }, unit)
        }
        _ => {
            return Err(err(format!(
                "a table of {} is none of the distribution forms",
                names.join(", ")
            )));
        }
    };
    if !unit.is_empty() && key.ends_with("_m") && !LENGTH_UNITS.iter().any(|(u, _)| *u == unit) {
        return Err(err(format!("unknown length unit `{unit}` (mm, um, m)")));
    }
    Ok(Uncertain {
        key: key.to_string(),
        distribution,
        unit,
    })
}

/// Refuses a scene that holds a distribution where `shpb run` (or any single run) needs one
/// value: an input error naming the file and the key, pointing to `shpb study`.
pub fn refuse_distributions(table: &toml::Table, file: &str) -> Result<()> {
    fn first(table: &toml::Table, prefix: &str) -> Option<String> {
        table.iter().find_map(|(k, value)| {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match value {
                toml::Value::Table(t) if is_distribution(t) => Some(path),
                toml::Value::Table(t) => first(t, &path),
                toml::Value::Array(_) if holds_distribution(value) => Some(path),
                _ => None,
            }
        })
    }
    match first(table, "") {
        Some(key) => Err(Error::Input {
            file: file.to_string(),
            key,
            problem: "a distribution: a single run takes one value".into(),
            allowed: "one value for `shpb run`; `shpb study SCENE --samples N` samples a \
                      distribution"
                .into(),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_four_forms_are_read_with_their_units() {
        let text = r#"
kind = "shpb"
pressure = { mean = "12.5psi", sd = "0.6psi" }
end_time_s = { min = 1e-3, max = 2e-3 }
[shaper]
thickness_m = { median = "0.43mm", gsd = 1.05 }
diameter_m = { values = ["4mm", "3.9mm", "4.1mm"] }
"#;
        let d = find_distributions(text, "s.toml").unwrap();
        let keys: Vec<&str> = d.iter().map(|u| u.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "end_time_s",
                "pressure",
                "shaper.diameter_m",
                "shaper.thickness_m"
            ]
        );
        assert_eq!(
            d[1].distribution,
            Distribution::Normal {
                mean: 12.5,
                sd: 0.6
            }
        );
        assert_eq!(d[1].unit, "psi");
        assert_eq!(d[1].value(12.75), toml::Value::String("12.75psi".into()));
        assert_eq!(d[0].value(1.5e-3), toml::Value::Float(1.5e-3));
        assert_eq!(
            d[2].distribution,
            Distribution::Empirical {
                values: vec![3.9, 4.0, 4.1]
            }
        );
        assert_eq!(d[2].distribution.central(), 4.0);
        let toml::Value::Float(m) = d[3].value(0.43) else {
            panic!()
        };
        assert!((m - 0.43e-3).abs() < 1e-18);
    }

    #[test]
    fn a_bad_distribution_names_the_file_the_key_and_the_forms() {
        for (body, problem) in [
            (
                "pressure = { mean = \"12psi\" }",
                "none of the distribution forms",
            ),
            (
                "pressure = { mean = \"12psi\", sd = \"1kPa\" }",
                "different units",
            ),
            (
                "pressure = { mean = \"12psi\", sd = \"-1psi\" }",
                "not positive",
            ),
            (
                "pressure = { min = \"12psi\", max = \"11psi\" }",
                "not below",
            ),
            ("pressure = { median = \"12psi\", gsd = 0.9 }", "above 1"),
            ("pressure = { values = [\"12psi\"] }", "at least 2"),
            ("pressure = { mean = \"abc\", sd = 1 }", "not a number"),
        ] {
            let e =
                find_distributions(&format!("kind = \"shpb\"\n{body}\n"), "s.toml").unwrap_err();
            let text = e.to_string();
            assert_eq!(e.exit_code(), 2);
            assert!(text.starts_with("s.toml: `pressure`"), "{text}");
            assert!(text.contains(problem), "{problem}: {text}");
            assert!(text.contains("log-normal"), "{text}");
        }
    }

    #[test]
    fn a_single_run_refuses_a_distribution_pointing_to_study() {
        let t: toml::Table =
            toml::from_str("kind = \"shpb\"\n[shaper]\nthickness_m = { min = 1, max = 2 }\n")
                .unwrap();
        let e = refuse_distributions(&t, "s.toml").unwrap_err().to_string();
        assert!(
            e.contains("`shaper.thickness_m`") && e.contains("shpb study"),
            "{e}"
        );
        let listed: toml::Table = toml::from_str(
            "kind = \"chain\"\n[[specimen.sphere]]\ndiameter_m = { min = 1, max = 2 }\n",
        )
        .unwrap();
        let e = refuse_distributions(&listed, "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`specimen.sphere`"), "{e}");
        let e = find_distributions(
            "kind = \"chain\"\n[[specimen.sphere]]\ndiameter_m = { min = 1, max = 2 }\n",
            "s.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("inside a list"), "{e}");
        let plain: toml::Table =
            toml::from_str("kind = \"shpb\"\n[specimen]\npair = \"x\"\n").unwrap();
        assert!(refuse_distributions(&plain, "s.toml").is_ok());
    }
}

//! What `shpb fit` is asked (docs/physics.md §12): the free keys with their bounds
//! (`--free KEY=MIN:MAX`), their priors (`--prior KEY=normal:MEAN:SD`) and the residual
//! (`--residual`), checked once into these types.

use crate::api::input_err;
use crate::sweep::{input_si, parse_axis};
use shpb_input::Result;
use shpb_input::scene::Value;

/// The fit's own key: a shift of the model's time axis against the records', s (the records'
/// time zero is a choice of the reduction's windows; not a scene key).
pub const TIME_SHIFT_KEY: &str = "time_shift_s";

/// How a free value reaches the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// A number of the scene (`--set KEY=x`).
    Number,
    /// A pressure the scene reads as text with its unit (`pressure = "12.5psi"`), set in Pa.
    Pressure,
    /// [`TIME_SHIFT_KEY`]: applied by the fit to the model's time axis.
    TimeShift,
}

/// One free parameter: a scene key `--set` reaches, with the bounds of its uniform prior.
#[derive(Debug, Clone, PartialEq)]
pub struct Free {
    /// The scene key (aliases resolved as `--set` resolves them).
    pub key: String,
    /// Lower bound, SI.
    pub min: f64,
    /// Upper bound, SI.
    pub max: f64,
    /// SI unit of the value.
    pub unit: &'static str,
    /// How the value reaches the scene.
    pub reach: Reach,
}

impl Free {
    /// The scene override of value `x` (None for the fit's own [`TIME_SHIFT_KEY`]).
    pub fn value(&self, x: f64) -> Option<(String, Value)> {
        match self.reach {
            Reach::Number => Some((self.key.clone(), Value::Float(x))),
            Reach::Pressure => Some((self.key.clone(), Value::String(format!("{x:e}Pa")))),
            Reach::TimeShift => None,
        }
    }
}

/// Parses `--free KEY=MIN:MAX` (units as `--set` takes them: `8psi:12psi`, `1.5GPa`,
/// `0.1mm:0.3mm`, plain numbers in the key's SI units); MIN < MAX, both finite.
pub fn parse_free(spec: &str) -> Result<Free> {
    let flag = format!("--free {spec}");
    let allowed = "KEY=MIN:MAX with MIN < MAX, e.g. specimen.yield_stress_pa=1.5e9:2.3e9 or pressure=8psi:12psi";
    let (key, range) = spec
        .split_once('=')
        .ok_or_else(|| input_err(&flag, "no `=`", allowed))?;
    let (lo, hi) = range
        .split_once(':')
        .ok_or_else(|| input_err(&flag, "no `:` between MIN and MAX", allowed))?;
    if key.trim() == TIME_SHIFT_KEY {
        let number = |t: &str| {
            input_si(TIME_SHIFT_KEY, t)
                .filter(|(_, u)| *u == "s")
                .map(|(v, _)| v)
                .ok_or_else(|| input_err(&flag, format!("`{t}` is not a time in s"), allowed))
        };
        let (min, max) = (number(lo)?, number(hi)?);
        return bounded(
            &flag,
            TIME_SHIFT_KEY,
            min,
            max,
            "s",
            Reach::TimeShift,
            allowed,
        );
    }
    // `--set`'s own parser resolves the key's aliases and the values' units.
    let axis = parse_axis(&format!("{}={},{}", key.trim(), lo.trim(), hi.trim()))
        .map_err(|e| input_err(&flag, e.to_string(), allowed))?;
    let si = |i: usize| -> Result<(f64, &'static str, Reach)> {
        match &axis.values[i] {
            // The gun's pressure is text with a unit in a scene: a plain number is Pa.
            Value::Float(v) if axis.key == "pressure" => Ok((*v, "Pa", Reach::Pressure)),
            Value::Integer(v) if axis.key == "pressure" => Ok((*v as f64, "Pa", Reach::Pressure)),
            Value::Float(v) => Ok((*v, crate::sweep::key_units(&axis.key), Reach::Number)),
            Value::Integer(v) => Ok((*v as f64, crate::sweep::key_units(&axis.key), Reach::Number)),
            Value::String(s) => match input_si(&axis.key, s) {
                Some((v, "Pa")) if axis.key == "pressure" => Ok((v, "Pa", Reach::Pressure)),
                // A number of the scene written with its unit (`1500MPa` for a `_pa` key).
                Some((v, u)) if u == crate::sweep::key_units(&axis.key) => {
                    Ok((v, u, Reach::Number))
                }
                _ => Err(input_err(
                    &flag,
                    format!("`{s}` is not a number"),
                    "a number, or a pressure with its unit (psi, Pa, kPa, MPa, GPa, bar)",
                )),
            },
            other => Err(input_err(
                &flag,
                format!("`{other}` is not a number"),
                allowed,
            )),
        }
    };
    let (min, unit, reach) = si(0)?;
    let (max, _, _) = si(1)?;
    bounded(&flag, &axis.key, min, max, unit, reach, allowed)
}

fn bounded(
    flag: &str,
    key: &str,
    min: f64,
    max: f64,
    unit: &'static str,
    reach: Reach,
    allowed: &str,
) -> Result<Free> {
    if !(min.is_finite() && max.is_finite() && min < max) {
        return Err(input_err(
            flag,
            format!("the range {min} to {max} is empty or not finite"),
            allowed,
        ));
    }
    Ok(Free {
        key: key.to_string(),
        min,
        max,
        unit,
        reach,
    })
}

/// A normal prior on one free key (`--prior KEY=normal:MEAN:SD`), on top of its bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// The free key it applies to.
    pub key: String,
    /// Mean, SI.
    pub mean: f64,
    /// Standard deviation, SI (> 0).
    pub sd: f64,
}

/// Parses `--prior KEY=normal:MEAN:SD` against the free keys (the key must be free; MEAN and SD in
/// its SI units, SD > 0).
pub fn parse_prior(spec: &str, free: &[Free]) -> Result<Prior> {
    let flag = format!("--prior {spec}");
    let allowed = "KEY=normal:MEAN:SD for a key given with --free, SD > 0 (SI units)";
    let (key, rest) = spec
        .split_once('=')
        .ok_or_else(|| input_err(&flag, "no `=`", allowed))?;
    let parts: Vec<&str> = rest.split(':').collect();
    let ["normal", mean, sd] = parts[..] else {
        return Err(input_err(
            &flag,
            format!("`{rest}` is not normal:MEAN:SD"),
            allowed,
        ));
    };
    // The key as `--set` resolves it (an alias such as gun.pressure is pressure).
    let key = parse_free(&format!("{}=0:1", key.trim()))
        .map(|g| g.key)
        .unwrap_or_else(|_| key.trim().to_string());
    let Some(f) = free.iter().find(|f| f.key == key) else {
        return Err(input_err(
            &flag,
            format!("`{key}` is not a --free key"),
            allowed,
        ));
    };
    let number = |t: &str| {
        input_si(&f.key, t)
            .map(|(v, _)| v)
            .ok_or_else(|| input_err(&flag, format!("`{t}` is not a number"), allowed))
    };
    let (mean, sd) = (number(mean)?, number(sd)?);
    if !(mean.is_finite() && sd.is_finite() && sd > 0.0) {
        return Err(input_err(&flag, format!("mean {mean}, SD {sd}"), allowed));
    }
    Ok(Prior {
        key: f.key.clone(),
        mean,
        sd,
    })
}

/// What the residual compares (`--residual`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Residual {
    /// The back (transmitted) force against time (a contact's force against time).
    ForceTime,
    /// Force and approach at the same times (a force-driven scene: the approach, its force being
    /// the drive).
    ForceApproach,
    /// Stress at the record's strains on the loading branch.
    StressStrain,
    /// The reflected and transmitted strains at the bar faces against time.
    Strains,
}

impl Residual {
    /// Every residual with its name.
    pub const ALL: [(Residual, &'static str); 4] = [
        (Residual::ForceTime, "force-time"),
        (Residual::ForceApproach, "force-approach"),
        (Residual::StressStrain, "stress-strain"),
        (Residual::Strains, "strains"),
    ];

    /// The name `--residual` takes.
    pub fn name(self) -> &'static str {
        Residual::ALL
            .iter()
            .find(|(r, _)| *r == self)
            .map(|(_, n)| *n)
            .expect("every residual is named")
    }

    /// Parses a `--residual` name.
    pub fn parse(name: &str) -> Result<Residual> {
        Residual::ALL
            .iter()
            .find(|(_, n)| *n == name)
            .map(|(r, _)| *r)
            .ok_or_else(|| {
                input_err(
                    "--residual",
                    format!("unknown residual `{name}`"),
                    "force-time, force-approach, stress-strain, strains",
                )
            })
    }
}

/// The texts of `--free`, `--prior` and `--residual` parsed, as `shpb fit` and `shpb.fit` take
/// them: the free keys, their priors and the residual (None: the scene's default).
pub fn parse_flags(
    free: &[String],
    prior: &[String],
    residual: Option<&str>,
) -> Result<(Vec<Free>, Vec<Prior>, Option<Residual>)> {
    let free = free
        .iter()
        .map(|f| parse_free(f))
        .collect::<Result<Vec<_>>>()?;
    let priors = prior
        .iter()
        .map(|p| parse_prior(p, &free))
        .collect::<Result<Vec<_>>>()?;
    let residual = residual.map(Residual::parse).transpose()?;
    Ok((free, priors, residual))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_keys_take_units_and_aliases_as_set_does() {
        let f = parse_free("gun.pressure=8psi:12psi").unwrap();
        assert_eq!(
            (f.key.as_str(), f.unit, f.reach),
            ("pressure", "Pa", Reach::Pressure)
        );
        assert!((f.min - 8.0 * 6894.757).abs() < 1e-6 * f.min);
        let g = parse_free("specimen.gap_m=0.1mm:0.3mm").unwrap();
        assert!((g.min - 1e-4).abs() < 1e-12 && (g.max - 3e-4).abs() < 1e-12);
        let s = parse_free("specimen.yield_stress_pa=1.5e9:2.3e9").unwrap();
        assert_eq!((s.unit, s.reach), ("Pa", Reach::Number));
        // A stress with its unit is still a number of the scene (only the gun's pressure is
        // text in a scene).
        let t = parse_free("specimen.yield_stress_pa=1500MPa:2300MPa").unwrap();
        assert_eq!(
            (t.min, t.max, t.unit, t.reach),
            (1.5e9, 2.3e9, "Pa", Reach::Number)
        );
        assert!(parse_free("specimen.jc_c=1MPa:2MPa").is_err());
        assert_eq!(
            parse_free("time_shift_s=-1e-6:1e-6").unwrap().reach,
            Reach::TimeShift
        );
        for bad in ["x", "k=1", "k=2:1", "k=a:b", "specimen.jc_c=0.1:0.1"] {
            assert!(parse_free(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn priors_name_a_free_key_and_a_positive_sd() {
        let free = vec![parse_free("specimen.jc_c=0:0.1").unwrap()];
        let p = parse_prior("specimen.jc_c=normal:0.035:0.01", &free).unwrap();
        assert_eq!((p.mean, p.sd), (0.035, 0.01));
        assert!(parse_prior("specimen.jc_c=normal:0.035:0", &free).is_err());
        assert!(parse_prior("pressure=normal:1:1", &free).is_err());
        assert!(parse_prior("specimen.jc_c=uniform:0:1", &free).is_err());
    }
}

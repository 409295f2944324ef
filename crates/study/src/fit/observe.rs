//! What a record and a model run are compared on (docs/physics.md §12.2): the observables of
//! either (times, force, approach, stress and strain, face strains), and the series of one
//! residual: the record's points and the model's values at the same abscissae.

use super::spec::Residual;
use crate::api::input_err;
use shpb_core::run::RunOutput;
use shpb_input::Result;

/// The quantities a record or a run gives, on one time axis (each may be missing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Observables {
    /// Time, s (a reduction's axis: from the incident foot at the specimen face).
    pub time_s: Vec<f64>,
    /// Force on the specimen, N (the transmitted, back force of a reduction; a contact's force).
    pub force_n: Option<Vec<f64>>,
    /// Approach (specimen shortening), m.
    pub approach_m: Option<Vec<f64>>,
    /// Engineering stress, Pa (a cylinder's 1-wave reduction; compression positive).
    pub stress_pa: Option<Vec<f64>>,
    /// Engineering strain (a cylinder's 1-wave reduction).
    pub strain: Option<Vec<f64>>,
    /// Reflected strain at the incident-bar face.
    pub reflected_strain: Option<Vec<f64>>,
    /// Transmitted strain at the transmission-bar face.
    pub transmitted_strain: Option<Vec<f64>>,
    /// The force is the scene's drive (a force-driven scene), not a result.
    pub force_is_drive: bool,
}

impl Observables {
    /// What a run gives: its reduction of the virtual gauges for a bar test (the lab's view,
    /// with the reduction's own errors, compared like with like against a reduced record), else
    /// its contact series.
    pub fn of_run(out: &RunOutput, force_driven: bool) -> Observables {
        if let Some(r) = &out.reduction {
            return Observables::of_reduction(r, out.cylinder_reduction.as_ref());
        }
        match &out.contact {
            Some(c) => Observables {
                time_s: c.time_s.clone().unwrap_or_default(),
                force_n: Some(c.force_n.clone()),
                approach_m: Some(c.displacement_m.clone()),
                force_is_drive: force_driven,
                ..Observables::default()
            },
            None => Observables::default(),
        }
    }

    /// What a reduction gives: the back force, the approach, the face strains, and a cylinder's
    /// 1-wave stress and strain.
    pub fn of_reduction(
        r: &shpb_core::reduce::Reduction,
        cylinder: Option<&shpb_core::reduce_cylinder::CylinderReduction>,
    ) -> Observables {
        let cyl = cylinder.map(|c| &c.one_wave);
        Observables {
            time_s: r.time_s.clone(),
            force_n: Some(r.force_back_n.clone()),
            approach_m: Some(r.displacement_m.clone()),
            stress_pa: cyl.map(|a| a.stress_pa.clone()),
            strain: cyl.map(|a| a.strain.clone()),
            reflected_strain: Some(r.reflected_strain.clone()),
            transmitted_strain: Some(r.transmitted_strain.clone()),
            force_is_drive: false,
        }
    }

    /// A reduced curve as a CSV table: `time_s` and any of `force_N` (or `force_back_N`, as
    /// `shpb reduce --csv` writes it), `displacement_m`, `stress_Pa` (or `one_wave_stress_Pa`),
    /// `strain` (or `one_wave_strain`), `reflected_strain`, `transmitted_strain`.
    pub fn of_csv(table: &shpb_input::csv::CsvTable) -> Observables {
        let col = |names: &[&str]| {
            names
                .iter()
                .find_map(|n| table.optional_column(n))
                .map(<[f64]>::to_vec)
        };
        Observables {
            time_s: col(&["time_s"]).unwrap_or_default(),
            force_n: col(&["force_N", "force_back_N", "force_n"]),
            approach_m: col(&["displacement_m", "approach_m"]),
            stress_pa: col(&["stress_Pa", "one_wave_stress_Pa", "stress_pa"]),
            strain: col(&["strain", "one_wave_strain"]),
            reflected_strain: col(&["reflected_strain"]),
            transmitted_strain: col(&["transmitted_strain"]),
            force_is_drive: false,
        }
    }
}

/// What one series of a residual compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Force against time.
    ForceTime,
    /// Approach against time.
    ApproachTime,
    /// Stress at strain, loading branch.
    StressAtStrain,
    /// Reflected strain against time.
    Reflected,
    /// Transmitted strain against time.
    Transmitted,
}

impl Quantity {
    /// (x label, x unit, y label, y unit).
    pub fn labels(self) -> (&'static str, &'static str, &'static str, &'static str) {
        match self {
            Quantity::ForceTime => ("time", "s", "force", "N"),
            Quantity::ApproachTime => ("time", "s", "approach", "m"),
            Quantity::StressAtStrain => ("strain", "1", "stress", "Pa"),
            Quantity::Reflected => ("time", "s", "reflected strain", "1"),
            Quantity::Transmitted => ("time", "s", "transmitted strain", "1"),
        }
    }

    fn time_series(self, o: &Observables) -> Option<&Vec<f64>> {
        match self {
            Quantity::ForceTime => o.force_n.as_ref(),
            Quantity::ApproachTime => o.approach_m.as_ref(),
            Quantity::Reflected => o.reflected_strain.as_ref(),
            Quantity::Transmitted => o.transmitted_strain.as_ref(),
            Quantity::StressAtStrain => None,
        }
    }
}

/// One series of a record: the points the residual is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The record's name.
    pub record: String,
    /// What it compares.
    pub quantity: Quantity,
    /// Abscissae (time, s, or strain).
    pub x: Vec<f64>,
    /// The record's values.
    pub y: Vec<f64>,
}

/// The quantities of `residual` for a record of observables `o` (force-approach leaves out the
/// force when it is the drive).
pub fn quantities(residual: Residual, o: &Observables) -> Vec<Quantity> {
    match residual {
        Residual::ForceTime => vec![Quantity::ForceTime],
        Residual::ForceApproach if o.force_is_drive => vec![Quantity::ApproachTime],
        Residual::ForceApproach => vec![Quantity::ForceTime, Quantity::ApproachTime],
        Residual::StressStrain => vec![Quantity::StressAtStrain],
        Residual::Strains => vec![Quantity::Reflected, Quantity::Transmitted],
    }
}

/// The series of `residual` in the record `o` named `name`; `model_kind` says which quantities
/// are the drive (from the scene). Stress–strain keeps the loading branch: the samples up to the
/// largest strain.
pub fn series_of(
    name: &str,
    o: &Observables,
    residual: Residual,
    model_force_is_drive: bool,
) -> Result<Vec<Series>> {
    let driven = Observables {
        force_is_drive: model_force_is_drive,
        ..Observables::default()
    };
    let missing = |what: &str| {
        input_err(
            "--record",
            format!("{name} has no {what} for the {} residual", residual.name()),
            "a record with the residual's quantities: time_s with force_N, displacement_m, stress_Pa and strain, or reflected_strain and transmitted_strain (a reduced CSV), a raw gauge record, or a force-driven scene's own CSV",
        )
    };
    let mut out = Vec::new();
    for q in quantities(residual, &driven) {
        let (x, y) = match q {
            Quantity::StressAtStrain => {
                let (Some(s), Some(e)) = (&o.stress_pa, &o.strain) else {
                    return Err(missing("stress and strain"));
                };
                let end = loading_end(e);
                (e[..=end].to_vec(), s[..=end].to_vec())
            }
            _ => {
                let y = q.time_series(o).ok_or_else(|| missing(q.labels().2))?;
                if o.time_s.len() != y.len() || y.len() < 2 {
                    return Err(missing("time axis"));
                }
                (o.time_s.clone(), y.clone())
            }
        };
        if x.len() < 2 || x.iter().chain(&y).any(|v| !v.is_finite()) {
            return Err(missing("finite samples"));
        }
        out.push(Series {
            record: name.to_string(),
            quantity: q,
            x,
            y,
        });
    }
    Ok(out)
}

/// Index of the largest strain: the end of the loading branch.
fn loading_end(strain: &[f64]) -> usize {
    strain
        .iter()
        .enumerate()
        .fold(0, |best, (i, &e)| if e > strain[best] { i } else { best })
}

/// Linear interpolation of (t, y), t increasing, at any `x` (unsorted allowed); end values held
/// outside.
pub fn interpolate(t: &[f64], y: &[f64], x: f64) -> f64 {
    let n = t.len();
    if n == 0 {
        return f64::NAN;
    }
    if x <= t[0] {
        return y[0];
    }
    if x >= t[n - 1] {
        return y[n - 1];
    }
    let j = t.partition_point(|&v| v <= x).max(1) - 1;
    let w = (x - t[j]) / (t[j + 1] - t[j]);
    y[j] + w * (y[j + 1] - y[j])
}

impl Series {
    /// The model's values at this series' abscissae, the model's time axis shifted by
    /// `shift_s` (positive: the model later). Stress at strain reads the model's loading
    /// branch (strain made non-decreasing); beyond its largest strain the last stress holds.
    pub fn model(&self, m: &Observables, shift_s: f64) -> Option<Vec<f64>> {
        match self.quantity {
            Quantity::StressAtStrain => {
                let (s, e) = (m.stress_pa.as_ref()?, m.strain.as_ref()?);
                let end = loading_end(e);
                let mut running = f64::NEG_INFINITY;
                let e: Vec<f64> = e[..=end]
                    .iter()
                    .map(|&v| {
                        running = running.max(v);
                        running
                    })
                    .collect();
                Some(
                    self.x
                        .iter()
                        .map(|&x| interpolate(&e, &s[..=end], x))
                        .collect(),
                )
            }
            q => {
                let y = q.time_series(m)?;
                if m.time_s.len() != y.len() || y.is_empty() {
                    return None;
                }
                let t: Vec<f64> = m.time_s.iter().map(|t| t + shift_s).collect();
                Some(self.x.iter().map(|&x| interpolate(&t, y, x)).collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_linear_and_holds_its_ends() {
        let t = [0.0, 1.0, 3.0];
        let y = [0.0, 2.0, 6.0];
        assert_eq!(interpolate(&t, &y, 2.0), 4.0);
        assert_eq!(interpolate(&t, &y, 0.5), 1.0);
        assert_eq!(interpolate(&t, &y, -1.0), 0.0);
        assert_eq!(interpolate(&t, &y, 9.0), 6.0);
        assert_eq!(interpolate(&t, &y, 1.0), 2.0);
    }

    #[test]
    fn a_shifted_model_is_read_later() {
        let m = Observables {
            time_s: vec![0.0, 1.0, 2.0],
            force_n: Some(vec![0.0, 10.0, 20.0]),
            ..Observables::default()
        };
        let s = Series {
            record: "r".into(),
            quantity: Quantity::ForceTime,
            x: vec![1.0, 2.0],
            y: vec![0.0, 0.0],
        };
        assert_eq!(s.model(&m, 0.5).unwrap(), vec![5.0, 15.0]);
    }

    #[test]
    fn stress_strain_keeps_the_loading_branch() {
        let o = Observables {
            time_s: vec![0.0, 1.0, 2.0, 3.0],
            stress_pa: Some(vec![0.0, 1.0, 2.0, 0.5]),
            strain: Some(vec![0.0, 0.1, 0.2, 0.15]),
            ..Observables::default()
        };
        let s = series_of("r", &o, Residual::StressStrain, false).unwrap();
        assert_eq!(s[0].x, vec![0.0, 0.1, 0.2]);
        assert_eq!(s[0].model(&o, 0.0).unwrap(), vec![0.0, 1.0, 2.0]);
        assert!(series_of("r", &o, Residual::Strains, false).is_err());
    }
}

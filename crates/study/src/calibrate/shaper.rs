//! The Frew shaper's diameter, thickness and effective modulus (docs/physics.md §6.5.1) from the
//! incident pulses of shots at several pressures or measured velocities: validation/pulse/
//! REPORT.md's stage-2 fit, on argmin's Nelder–Mead.
//!
//! - **Model.** [`Apparatus::incident_signal`]: striker → shaper → incident bar → transmission
//!   bar pressed on, 1 mm cells, 2 mm gauge grid, no dispersion (what a `pulse` scene runs), one
//!   run per distinct pressure (or velocity), in parallel.
//! - **Objective.** Σ over shots of ((simulated − measured)/measured / tolerance)² of the incident
//!   pulse's peak (15 %), 10–90 % rise (20 %), duration at 10 % (20 %) and energy (20 %), the
//!   record read by [`super::incident_pulse`].
//! - **Parameters** (log space, bounded by a penalty: diameter 1 mm to the bar's, thickness
//!   0.2–8 mm, modulus 0.5–130 GPa): with measured velocities (or a gun line fitted before) the
//!   shaper's three; otherwise also the striker velocities at the lowest and highest pressure,
//!   which fix the gun line v² = k (p − p_loss) through them (0 ≤ p_loss < the lowest pressure).
//! - **Optimiser.** Nelder–Mead (argmin), restarted from the best point with a smaller simplex
//!   until a round improves the objective by less than 10⁻⁴ of it; a gun-line fit first frees one
//!   velocity per pressure (stage 1) and starts the tied fit (stage 2) from it, as the report
//!   generator always did.
//! - **1-sigma.** The least-squares covariance s² (JᵀJ)⁻¹ of the parameters, J the Jacobian of
//!   the residuals by central differences (±1 % in log space) at the optimum, s² = Σ r²/(n − p);
//!   k's and p_loss's from the two velocities' by the delta method.
//! - **velocity_scatter** (gun line fitted here): the pooled within-pressure relative sd of the
//!   records' pulse energy over η = d ln E/d ln v of the calibrated model (±2 % in v), as
//!   bars/authors.toml states it.

use super::{Calibrator, Data, Fitted, SdFrom, ShotData, incident_pulse, pulse_energy_j};
use nalgebra::DMatrix;
use rayon::prelude::*;
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{PulseMetrics, pulse_metrics};
use shpb_core::shaper::{PulseShaper, ShaperModel};
use shpb_input::{Error, Result};

/// The shaper calibration (registered in [`super::CALIBRATIONS`]).
pub struct ShaperFit;

/// Tolerances (weights) of peak, rise 10–90 %, duration at 10 % and energy.
pub const TOLERANCES: [f64; 4] = [0.15, 0.20, 0.20, 0.20];
/// Cell size of the calibration runs (a `pulse` scene's default), m.
pub const CELL_M: f64 = 1e-3;
/// Gauge grid of the calibration runs (a `pulse` scene's default), m.
pub const GAUGE_LENGTH_M: f64 = 2e-3;
/// Nelder–Mead evaluations per round.
const EVALS_PER_ROUND: usize = 400;
/// Relative step of the central differences of the Jacobian, in log space.
const JACOBIAN_STEP: f64 = 0.01;
/// Penalty of a point outside the bounds.
const OUTSIDE: f64 = 1e9;

/// One shot's measured incident pulse.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Its metrics (compression positive).
    pub metrics: PulseMetrics,
    /// Its energy, J.
    pub energy_j: f64,
    /// Which simulation (distinct pressure or velocity) it is compared with.
    pub group: usize,
}

/// One simulated incident pulse.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// Its metrics (None: no complete pulse).
    pub metrics: Option<PulseMetrics>,
    /// Its energy, J.
    pub energy_j: f64,
    /// Times, s.
    pub time_s: Vec<f64>,
    /// Stress at the incident gauge, compression positive, Pa.
    pub stress_pa: Vec<f64>,
}

/// How the striker velocities are set.
#[derive(Debug, Clone, PartialEq)]
pub enum Velocities {
    /// Known per group (measured, or from a gun line fitted before), m/s.
    Known(Vec<f64>),
    /// One free velocity per group (stage 1 of a gun-line fit: the shaper found without the gun
    /// law, from which stage 2 starts).
    Free(usize),
    /// Tied to a gun line through free velocities at the lowest and highest of these pressures
    /// (sorted, Pa); p_loss below `loss_below_pa`.
    GunLine {
        /// The groups' pressures, Pa (ascending).
        pressures_pa: Vec<f64>,
        /// p_loss must stay below this, Pa.
        loss_below_pa: f64,
    },
}

/// The fit problem: the set-up, the records and how velocities are set.
pub struct Problem<'a> {
    /// The base set-up (its shaper is the start and supplies σ0, n, m).
    pub apparatus: &'a Apparatus,
    /// The records.
    pub measured: Vec<Measured>,
    /// The velocities.
    pub velocities: Velocities,
}

/// (k, p_loss) of the line v² = k (p − p_loss) through (p1, v1) and (p2, v2); None unless it
/// rises.
pub fn line_through(p1: f64, v1: f64, p2: f64, v2: f64) -> Option<(f64, f64)> {
    let k = (v2 * v2 - v1 * v1) / (p2 - p1);
    (k > 0.0).then(|| (k, p1 - v1 * v1 / k))
}

/// Simulated incident pulse of `a` with `shaper` at striker velocity `v` over the records'
/// window (from the run's start to the incident arrival plus 2 d_I/c0 + 10 µs).
pub fn simulate(a: &Apparatus, v: f64, shaper: PulseShaper) -> Simulated {
    let c0 = a.material.wave_speed_m_s();
    let d = a
        .gauges
        .channel("incident")
        .map_or(0.0, |c| c.distance_from_specimen_m);
    let arrival = (a.incident.length_m - d) / c0;
    let end = arrival + 2.0 * d / c0 + 10e-6;
    match a.incident_signal(v, Some(shaper), CELL_M, GAUGE_LENGTH_M, end) {
        Ok(s) => Simulated {
            metrics: pulse_metrics(&s.time_s, &s.stress_pa, false),
            energy_j: pulse_energy_j(a, &s.time_s, &s.stress_pa),
            time_s: s.time_s,
            stress_pa: s.stress_pa,
        },
        Err(_) => Simulated {
            metrics: None,
            energy_j: f64::NAN,
            time_s: vec![],
            stress_pa: vec![],
        },
    }
}

/// The parameters of a point: (velocities per group, shaper); None outside the bounds.
pub type Point = (Vec<f64>, PulseShaper);

impl<'a> Problem<'a> {
    /// A problem on `a`'s shaper with `measured` records and `velocities`.
    pub fn new(a: &'a Apparatus, measured: Vec<Measured>, velocities: Velocities) -> Self {
        Problem {
            apparatus: a,
            measured,
            velocities,
        }
    }

    /// Number of velocity parameters (2 with a gun line, else 0).
    fn velocity_parameters(&self) -> usize {
        match self.velocities {
            Velocities::Known(_) => 0,
            Velocities::Free(n) => n,
            Velocities::GunLine { .. } => 2,
        }
    }

    /// Bounds of the shaper's free parameters (diameter, thickness, modulus), SI.
    fn bounds(&self) -> [(f64, f64); 3] {
        [
            (1e-3, self.apparatus.incident.diameter_m),
            (0.2e-3, 8e-3),
            (0.5e9, 130e9),
        ]
    }

    /// The model of point `x` (log space); None outside the bounds or for a gun line that does
    /// not rise or loses more than the lowest pressure.
    pub fn unpack(&self, x: &[f64]) -> Option<Point> {
        let nv = self.velocity_parameters();
        let v = match &self.velocities {
            Velocities::Known(v) => v.clone(),
            Velocities::Free(n) => x[..*n].iter().map(|y| y.exp()).collect(),
            Velocities::GunLine {
                pressures_pa,
                loss_below_pa,
            } => {
                let (p1, p2) = (pressures_pa[0], *pressures_pa.last()?);
                let (k, loss) = line_through(p1, x[0].exp(), p2, x[1].exp())?;
                if !(0.0..*loss_below_pa).contains(&loss) {
                    return None;
                }
                pressures_pa
                    .iter()
                    .map(|p| (k * (p - loss)).sqrt())
                    .collect()
            }
        };
        if v.iter().any(|v| !(0.5..100.0).contains(v)) {
            return None;
        }
        let mut s = self.apparatus.shaper?;
        let vals: Vec<f64> = x[nv..].iter().map(|y| y.exp()).collect();
        for (val, (lo, hi)) in vals.iter().zip(self.bounds()) {
            if !(lo..=hi).contains(val) {
                return None;
            }
        }
        (s.diameter_m, s.thickness_m, s.youngs_modulus_pa) = (vals[0], vals[1], vals[2]);
        Some((v, s))
    }

    /// The point (log space) of `shaper` and the velocities `v` per group (a gun line: through
    /// the first and last).
    pub fn pack(&self, v: &[f64], shaper: &PulseShaper) -> Vec<f64> {
        let mut x: Vec<f64> = match self.velocities {
            Velocities::Known(_) => vec![],
            Velocities::Free(_) => v.iter().map(|v| v.ln()).collect(),
            Velocities::GunLine { .. } => vec![v[0].ln(), v[v.len() - 1].ln()],
        };
        x.extend(
            [
                shaper.diameter_m,
                shaper.thickness_m,
                shaper.youngs_modulus_pa,
            ]
            .map(f64::ln),
        );
        x
    }

    /// The simulations of a point, one per group (in parallel).
    pub fn simulate(&self, p: &Point) -> Vec<Simulated> {
        p.0.par_iter()
            .map(|&v| simulate(self.apparatus, v, p.1))
            .collect()
    }

    /// Residuals (relative error / tolerance) of peak, rise, duration, energy per record; None
    /// when a simulation has no complete pulse.
    pub fn residuals(&self, sims: &[Simulated]) -> Option<Vec<f64>> {
        let mut r = Vec::with_capacity(4 * self.measured.len());
        for m in &self.measured {
            let s = &sims[m.group];
            let sm = s.metrics?;
            let e = [
                sm.peak / m.metrics.peak - 1.0,
                sm.rise_10_90_s / m.metrics.rise_10_90_s - 1.0,
                sm.duration_10_s / m.metrics.duration_10_s - 1.0,
                s.energy_j / m.energy_j - 1.0,
            ];
            r.extend(e.iter().zip(TOLERANCES).map(|(e, t)| e / t));
        }
        Some(r)
    }

    /// Residuals of point `x`; None outside the bounds or without a complete pulse.
    pub fn residuals_at(&self, x: &[f64]) -> Option<Vec<f64>> {
        let p = self.unpack(x)?;
        self.residuals(&self.simulate(&p))
    }
}

/// The fit's result.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Best point (log space).
    pub x: Vec<f64>,
    /// Its model.
    pub point: Point,
    /// Its objective Σ r².
    pub objective: f64,
    /// Covariance of the log-space parameters (None when JᵀJ is singular or n ≤ p).
    pub covariance: Option<DMatrix<f64>>,
    /// Cost evaluations.
    pub evaluations: usize,
}

/// Minimises the problem from `x0` with argmin's Nelder–Mead ([`super::optimise::nelder_mead`];
/// restarts with a smaller simplex until a round stops improving), then the covariance at the
/// optimum.
pub fn minimise(
    problem: &Problem,
    x0: Vec<f64>,
    with_covariance: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<FitResult> {
    let mut f = |x: &[f64]| {
        problem
            .residuals_at(x)
            .map_or(OUTSIDE, |r| r.iter().map(|v| v * v).sum())
    };
    let (mut x, mut objective, mut evaluations) = (x0, f64::INFINITY, 0);
    for round in 0..4 {
        let step = vec![if round == 0 { 0.15 } else { 0.05 }; x.len()];
        let (xb, fb, n) = super::optimise::nelder_mead(&mut f, &x, &step, EVALS_PER_ROUND, 1e-6);
        evaluations += n;
        progress(&format!(
            "shaper: round {round}, objective {fb:.4}, {evaluations} evaluations so far"
        ));
        let improved = objective - fb >= 1e-4 * objective.max(1e-12);
        if fb < objective {
            (x, objective) = (xb, fb);
        }
        if !improved {
            break;
        }
    }
    let point = problem.unpack(&x).ok_or_else(|| Error::Input {
        file: problem.apparatus.source.clone(),
        key: "shaper".into(),
        problem: "no point inside the bounds gives complete simulated pulses".into(),
        allowed: "a base shaper and gun that give an incident pulse at the shots' pressures".into(),
    })?;
    let covariance = if with_covariance {
        progress("shaper: Jacobian at the optimum");
        covariance(problem, &x, objective)
    } else {
        None
    };
    Ok(FitResult {
        x,
        point,
        objective,
        covariance,
        evaluations,
    })
}

/// s² (JᵀJ)⁻¹ at `x` (central differences of the residuals, ±[`JACOBIAN_STEP`] in log space),
/// s² = Σ r²/(n − p); None when a neighbour leaves the bounds or JᵀJ is singular.
fn covariance(problem: &Problem, x: &[f64], objective: f64) -> Option<DMatrix<f64>> {
    let p = x.len();
    let mut columns = Vec::with_capacity(p);
    for i in 0..p {
        let mut up = x.to_vec();
        let mut down = x.to_vec();
        up[i] += JACOBIAN_STEP;
        down[i] -= JACOBIAN_STEP;
        let (ru, rd) = (problem.residuals_at(&up)?, problem.residuals_at(&down)?);
        columns.push(
            ru.iter()
                .zip(&rd)
                .map(|(a, b)| (a - b) / (2.0 * JACOBIAN_STEP))
                .collect::<Vec<f64>>(),
        );
    }
    let n = columns[0].len();
    if n <= p {
        return None;
    }
    let j = DMatrix::from_fn(n, p, |r, c| columns[c][r]);
    let s2 = objective / (n - p) as f64;
    (j.transpose() * &j).try_inverse().map(|m| m * s2)
}

/// The shots the fit uses and how their velocities are set: every shot with a velocity (all
/// measured, or from `gun` (k, p_loss) fitted before), else every shot with a pressure (a gun
/// line through the lowest and highest); groups are distinct velocities or pressures.
fn groups(
    data: &Data,
    gun: Option<(f64, f64)>,
) -> Option<(Vec<&ShotData>, Vec<usize>, Velocities)> {
    let all_v = data.shots.iter().all(|s| s.shot.velocity_m_s.is_some());
    let key = |s: &ShotData| -> Option<f64> {
        if all_v {
            s.shot.velocity_m_s
        } else {
            s.shot.pressure_pa
        }
    };
    let shots: Vec<&ShotData> = data.shots.iter().filter(|s| key(s).is_some()).collect();
    let mut values: Vec<f64> = shots.iter().filter_map(|s| key(s)).collect();
    values.sort_by(f64::total_cmp);
    values.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
    let group: Vec<usize> = shots
        .iter()
        .map(|s| {
            let v = key(s).unwrap_or(f64::NAN);
            values
                .iter()
                .position(|x| (x - v).abs() <= 1e-9 * v.abs())
                .unwrap_or(0)
        })
        .collect();
    let velocities = if all_v {
        Velocities::Known(values)
    } else if let Some((k, loss)) = gun {
        Velocities::Known(values.iter().map(|p| (k * (p - loss)).sqrt()).collect())
    } else {
        if values.len() < 2 {
            return None;
        }
        let loss_below_pa = values[0].min(data.base.gun.range_pa().0);
        Velocities::GunLine {
            pressures_pa: values,
            loss_below_pa,
        }
    };
    (!shots.is_empty()).then_some((shots, group, velocities))
}

/// k and p_loss fitted by an earlier calibration (the gun line).
fn earlier_gun(earlier: &[Fitted]) -> Option<(f64, f64)> {
    let get = |k: &str| earlier.iter().find(|f| f.key == k).map(|f| f.value);
    Some((get("gun.k_m2_per_s2_per_pa")?, get("gun.loss_pressure_pa")?))
}

/// The records' metrics of `shots` (grouped by `group`).
pub fn measure(a: &Apparatus, shots: &[&ShotData], group: &[usize]) -> Result<Vec<Measured>> {
    shots
        .iter()
        .zip(group)
        .map(|(s, &g)| {
            let (t, y) = incident_pulse(a, s);
            let metrics = pulse_metrics(&t, &y, false).ok_or_else(|| Error::Input {
                file: s.shot.file.display().to_string(),
                key: "incident_V".into(),
                problem: "no complete incident pulse before the reflected one".into(),
                allowed: "an incident record whose pulse rises and falls below 10 % of its peak"
                    .into(),
            })?;
            Ok(Measured {
                metrics,
                energy_j: pulse_energy_j(a, &t, &y),
                group: g,
            })
        })
        .collect()
}

impl Calibrator for ShaperFit {
    fn name(&self) -> &'static str {
        "shaper"
    }

    fn skip_reason(&self, data: &Data, earlier: &[Fitted]) -> Option<String> {
        match data.base.shaper {
            None => return Some("the base set-up has no [shaper]".into()),
            Some(s) if s.model != ShaperModel::Frew => {
                return Some("the base set-up's shaper is not `model = \"frew\"`".into());
            }
            _ => {}
        }
        groups(data, earlier_gun(earlier)).is_none().then(|| {
            "needs shots with measured velocities, or with gun pressures at two or more \
             pressures"
                .into()
        })
    }

    fn fit(
        &self,
        data: &Data,
        earlier: &[Fitted],
        progress: &mut dyn FnMut(&str),
    ) -> Result<super::Fit> {
        let a = &data.base;
        let (shots, group, velocities) =
            groups(data, earlier_gun(earlier)).expect("skip_reason checked the shots");
        let measured = measure(a, &shots, &group)?;
        let problem = Problem::new(a, measured, velocities.clone());
        let base_shaper = a.shaper.expect("skip_reason checked the shaper");
        let x0 = match &velocities {
            Velocities::GunLine { pressures_pa, .. } => {
                // Stage 1: one velocity per pressure (from the base gun's), then stage 2 from
                // its velocities and shaper, tied to the gun line (validation/pulse/REPORT.md).
                let v0: Vec<f64> = pressures_pa
                    .iter()
                    .map(|&p| a.striker_velocity_m_s(p).unwrap_or(5.0))
                    .collect();
                let free = Problem::new(
                    a,
                    problem.measured.clone(),
                    Velocities::Free(pressures_pa.len()),
                );
                progress("shaper: stage 1, one free velocity per pressure");
                let r1 = minimise(&free, free.pack(&v0, &base_shaper), false, progress)?;
                progress("shaper: stage 2, the velocities on the gun line");
                problem.pack(&r1.point.0, &r1.point.1)
            }
            _ => problem.pack(&[], &base_shaper),
        };
        let r = minimise(&problem, x0, true, progress)?;
        let (v, s) = &r.point;
        let labels = data.on(shots.iter().copied());
        let n_res = 4 * problem.measured.len();
        let on = format!(
            "incident pulses (peak, rise, duration, energy; objective {:.3} over {} residuals, \
             {} evaluations of argmin's Nelder-Mead) on {labels}",
            r.objective, n_res, r.evaluations
        );
        let nv = problem.velocity_parameters();
        let sd_log = |i: usize| r.covariance.as_ref().map(|c| c[(i, i)].max(0.0).sqrt());
        let mut out = Vec::new();
        // Rows of G = ∂(constant)/∂(log-space parameter): the covariance of the constants is
        // G C Gᵀ (the delta method), whose correlations are written beside their 1-sigma.
        let mut gradients: Vec<(&'static str, Vec<f64>)> = Vec::new();
        for (i, (key, value, unit)) in [
            ("shaper.diameter_m", s.diameter_m, "m"),
            ("shaper.thickness_m", s.thickness_m, "m"),
            ("shaper.youngs_modulus_pa", s.youngs_modulus_pa, "Pa"),
        ]
        .into_iter()
        .enumerate()
        {
            let mut g = vec![0.0; r.x.len()];
            g[nv + i] = value;
            gradients.push((key, g));
            out.push(Fitted {
                key: key.into(),
                value,
                unit,
                sd: sd_log(nv + i).map(|d| d * value),
                sd_from: SdFrom::Covariance,
                fitted_on: on.clone(),
                uncertain: true,
            });
        }
        let psi = shpb_core::striker::PSI_PA;
        if let Velocities::GunLine { pressures_pa, .. } = &velocities {
            let (p1, p2) = (pressures_pa[0], pressures_pa[pressures_pa.len() - 1]);
            let (v1, v2) = (v[0], v[v.len() - 1]);
            let (k, loss) = line_through(p1, v1, p2, v2).expect("the best point is inside");
            // Gradients of k and p_loss in (ln v1, ln v2) for the delta method.
            let dk = [-2.0 * v1 * v1 / (p2 - p1), 2.0 * v2 * v2 / (p2 - p1)];
            let g = v1 * v1 / (k * k);
            let dl = [-2.0 * v1 * v1 / k + g * dk[0], g * dk[1]];
            let var = |d: [f64; 2]| {
                r.covariance.as_ref().map(|c| {
                    (d[0] * d[0] * c[(0, 0)]
                        + d[1] * d[1] * c[(1, 1)]
                        + 2.0 * d[0] * d[1] * c[(0, 1)])
                        .max(0.0)
                        .sqrt()
                })
            };
            // The gun line's parameters are ln v1 and ln v2, the first two.
            let mut gk = vec![0.0; r.x.len()];
            let mut gl = vec![0.0; r.x.len()];
            (gk[0], gk[1], gl[0], gl[1]) = (dk[0], dk[1], dl[0], dl[1]);
            gradients.push(("gun.k_m2_per_s2_per_pa", gk));
            gradients.push(("gun.loss_pressure_pa", gl));
            let line_on = format!(
                "{on}; the line through the fitted velocities {v1:.3} m/s at {:.2} psi and \
                 {v2:.3} m/s at {:.2} psi",
                p1 / psi,
                p2 / psi
            );
            out.push(Fitted {
                key: "gun.k_m2_per_s2_per_pa".into(),
                value: k,
                unit: "m^2/s^2/Pa",
                sd: var(dk),
                sd_from: SdFrom::Covariance,
                fitted_on: line_on.clone(),
                uncertain: true,
            });
            out.push(Fitted {
                key: "gun.loss_pressure_pa".into(),
                value: loss,
                unit: "Pa",
                sd: var(dl),
                sd_from: SdFrom::Covariance,
                fitted_on: line_on,
                uncertain: true,
            });
            out.push(Fitted {
                key: "gun.calibration_striker_length_m".into(),
                value: a.striker.length_m,
                unit: "m",
                sd: None,
                sd_from: SdFrom::Covariance,
                fitted_on: "the striker of the shots ([striker] length_m)".into(),
                uncertain: false,
            });
            for (key, p) in [
                ("gun.calibrated_min_pressure_pa", p1),
                ("gun.calibrated_max_pressure_pa", p2),
            ] {
                out.push(Fitted {
                    key: key.into(),
                    value: p,
                    unit: "Pa",
                    sd: None,
                    sd_from: SdFrom::Covariance,
                    fitted_on: "the pressures of the shots".into(),
                    uncertain: false,
                });
            }
            if let Some(vs) = velocity_scatter(&problem, &r, &group) {
                progress(&format!("shaper: velocity scatter {vs:.4}"));
                out.push(vs_fitted(vs, &shots, &group));
            }
        }
        if let Velocities::GunLine { pressures_pa, .. } = &velocities {
            // Two entries of one key: the array [lowest, highest] (setup_file writes it so).
            for p in [pressures_pa[0], pressures_pa[pressures_pa.len() - 1]] {
                out.push(Fitted {
                    key: "shaper.calibrated_pressure_psi".into(),
                    value: p / psi,
                    unit: "psi",
                    sd: None,
                    sd_from: SdFrom::Covariance,
                    fitted_on: "[lowest, highest] pressure of the shots".into(),
                    uncertain: false,
                });
            }
        }
        let correlations = r
            .covariance
            .as_ref()
            .map(|c| correlations(&gradients, c))
            .unwrap_or_default();
        Ok(super::Fit {
            constants: out,
            correlations,
        })
    }
}

/// The correlations of the constants whose gradients in the log-space parameters are
/// `gradients`, from the parameters' covariance `c`: (G C Gᵀ)_ij / √((G C Gᵀ)_ii (G C Gᵀ)_jj),
/// each pair once, pairs with a zero variance left out.
fn correlations(
    gradients: &[(&'static str, Vec<f64>)],
    c: &DMatrix<f64>,
) -> Vec<super::Correlation> {
    let cov = |a: &[f64], b: &[f64]| -> f64 {
        let mut s = 0.0;
        for i in 0..a.len() {
            for j in 0..b.len() {
                s += a[i] * c[(i, j)] * b[j];
            }
        }
        s
    };
    let mut out = Vec::new();
    for (i, (ka, ga)) in gradients.iter().enumerate() {
        for (kb, gb) in &gradients[i + 1..] {
            let (va, vb) = (cov(ga, ga), cov(gb, gb));
            if va > 0.0 && vb > 0.0 {
                let r = (cov(ga, gb) / (va * vb).sqrt()).clamp(-1.0, 1.0);
                out.push(super::Correlation {
                    a: (*ka).into(),
                    b: (*kb).into(),
                    r,
                });
            }
        }
    }
    out
}

/// The gun's velocity scatter from the records' energies: the pooled within-pressure relative
/// sd of their energy over η = d ln E/d ln v of the calibrated model at the middle group.
fn velocity_scatter(problem: &Problem, r: &FitResult, group: &[usize]) -> Option<f64> {
    let energies: Vec<(Option<u64>, f64)> = problem
        .measured
        .iter()
        .zip(group)
        .map(|(m, &g)| (Some(g as u64), m.energy_j))
        .collect();
    let sd = super::pooled_sd(&energies, true)?;
    let (v, s) = &r.point;
    let vm = v[v.len() / 2];
    let (up, down) = (
        simulate(problem.apparatus, vm * 1.02, *s),
        simulate(problem.apparatus, vm / 1.02, *s),
    );
    let eta = (up.energy_j / down.energy_j).ln() / (2.0 * 1.02f64.ln());
    (eta > 0.0).then(|| sd / eta)
}

/// The `gun.velocity_scatter` constant of [`velocity_scatter`].
fn vs_fitted(vs: f64, shots: &[&ShotData], group: &[usize]) -> Fitted {
    let groups = group.iter().copied().max().map_or(0, |g| g + 1);
    let df = shots.len().saturating_sub(groups).max(1);
    Fitted {
        key: "gun.velocity_scatter".into(),
        value: vs,
        unit: "1",
        sd: Some(vs / (2.0 * df as f64).sqrt()),
        sd_from: SdFrom::Scatter,
        fitted_on: format!(
            "pooled within-pressure relative sd of the records' pulse energy over eta = d ln E/d ln v \
             of the calibrated model ({df} degrees of freedom)"
        ),
        uncertain: false,
    }
}

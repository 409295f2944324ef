//! The last stage of the reduction: what the specimen makes of the waves (docs/physics.md §7.3,
//! §7.8). Spheres: the global strain rate δ̇/Σrᵢ over their radii (paper Eq. 3); a cylinder:
//! the 1-, 2- and 3-wave engineering stress, strain and strain rate, the true stress and strain
//! at constant volume (Gray 2000; Chen & Song 2011, §1.3), compression positive, and the
//! loading modulus.

use super::{Reduction, ReductionSetup};
use crate::error::{Error, Result};
use crate::numeric::{argmax, cumulative_trapezoid, least_squares};

/// Radii of the paper's specimen, two 6.35 mm spheres, m (what `shpb reduce` assumes for the
/// strain rate of a record without `--specimen`; the authors' `analysis.m` divides by
/// 0.0254/4 m = r1 + r2 too).
pub const PAPER_SPHERE_RADII_M: (f64, f64) = (3.175e-3, 3.175e-3);

/// The specimen a reduction reads the waves for (docs/physics.md §7.3, §7.8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReducedSpecimen {
    /// Spheres: the strain rate is δ̇/(r1 + r2); for a chain of N spheres (r1, r2 + … + rN), so
    /// that it is δ̇/Σrᵢ over the whole chain (`SphereSpecimen::strain_rate_radii_m`, docs/physics.md §8).
    Spheres {
        /// The two lengths whose sum divides δ̇, m.
        radii_m: (f64, f64),
    },
    /// A cylinder: its 1/2/3-wave stress, strain and strain rate (docs/physics.md §7.8).
    Cylinder(CylinderGeometry),
}

impl Default for ReducedSpecimen {
    /// The paper's two 6.35 mm spheres ([`PAPER_SPHERE_RADII_M`]).
    fn default() -> Self {
        ReducedSpecimen::Spheres {
            radii_m: PAPER_SPHERE_RADII_M,
        }
    }
}

impl ReducedSpecimen {
    /// What a reduction reads for a scene's specimen: spheres their radii
    /// ([`crate::specimen::SphereSpecimen::strain_rate_radii_m`]), a cylinder its geometry.
    pub fn of(specimen: &crate::specimen::Specimen) -> ReducedSpecimen {
        match specimen {
            crate::specimen::Specimen::Spheres(s) => ReducedSpecimen::Spheres {
                radii_m: s.strain_rate_radii_m(),
            },
            crate::specimen::Specimen::Cylinder(c) => ReducedSpecimen::Cylinder(CylinderGeometry {
                length_m: c.length_m,
                diameter_m: c.diameter_m,
            }),
        }
    }

    /// The sphere radii of the strain rate δ̇/(r1 + r2), None for a cylinder (whose rate is its
    /// own, [`reduce_cylinder`]).
    pub fn radii_m(&self) -> Option<(f64, f64)> {
        match self {
            ReducedSpecimen::Spheres { radii_m } => Some(*radii_m),
            ReducedSpecimen::Cylinder(_) => None,
        }
    }

    /// The cylinder's geometry, None for spheres.
    pub fn cylinder(&self) -> Option<CylinderGeometry> {
        match self {
            ReducedSpecimen::Spheres { .. } => None,
            ReducedSpecimen::Cylinder(g) => Some(*g),
        }
    }

    /// A cylinder's 1/2/3-wave analysis of reduction `r` ([`reduce_cylinder`]); None for
    /// spheres, whose strain rate the reduction itself carries.
    pub fn reduce(
        &self,
        r: &Reduction,
        setup: &ReductionSetup,
    ) -> Result<Option<CylinderReduction>> {
        self.cylinder()
            .map(|g| reduce_cylinder(r, setup, &g))
            .transpose()
    }
}

/// Global strain rate of spheres δ̇/(r1 + r2), 1/s (paper Eq. 3; docs/physics.md §7.3).
pub(crate) fn sphere_strain_rate(approach_velocity_m_s: &[f64], (r1, r2): (f64, f64)) -> Vec<f64> {
    approach_velocity_m_s
        .iter()
        .map(|v| v / (r1 + r2))
        .collect()
}

/// The geometry of a cylindrical specimen as the reduction needs it (docs/physics.md §7.8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderGeometry {
    /// Initial length L_s, m.
    pub length_m: f64,
    /// Initial diameter d_s, m.
    pub diameter_m: f64,
}

impl CylinderGeometry {
    /// Cross-section A_s = π d_s²/4, m².
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI * 0.25 * self.diameter_m * self.diameter_m
    }

    /// Checks that both lengths are finite and within (0, 1] m (an error names the quantity).
    pub fn check(&self) -> Result<()> {
        for (q, v) in [("length_m", self.length_m), ("diameter_m", self.diameter_m)] {
            if !(v.is_finite() && v > 0.0 && v <= 1.0) {
                return Err(Error::Invalid {
                    object: "cylindrical specimen".into(),
                    quantity: q.into(),
                    problem: format!("{v} is out of range"),
                    allowed: "greater than 0, at most 1 m".into(),
                });
            }
        }
        Ok(())
    }
}

/// One analysis (1-, 2- or 3-wave) of the specimen, on the reduction's time axis (docs/physics.md §7.8).
#[derive(Debug, Clone, PartialEq)]
pub struct WaveAnalysis {
    /// Engineering stress σ, Pa (compression positive).
    pub stress_pa: Vec<f64>,
    /// Engineering strain ε = shortening/L_s (compression positive).
    pub strain: Vec<f64>,
    /// Engineering strain rate ε̇, 1/s (compression positive).
    pub strain_rate_per_s: Vec<f64>,
    /// True stress σ (1 − ε) at constant volume, Pa.
    pub true_stress_pa: Vec<f64>,
    /// True strain −ln(1 − ε).
    pub true_strain: Vec<f64>,
}

impl WaveAnalysis {
    /// Builds the analysis from stress and strain rate (ε by the trapezoidal rule, or the given
    /// strain) and adds the true quantities at constant volume (docs/physics.md §7.8, §7.8.1): in
    /// compression σ(1 − ε) and −ln(1 − ε); in tension (`tension`, ε the elongation over L_s,
    /// tension positive) σ(1 + ε) and ln(1 + ε), A = A₀L₀/L with L = L₀(1 + ε).
    fn new(
        stress_pa: Vec<f64>,
        strain_rate_per_s: Vec<f64>,
        strain: Vec<f64>,
        tension: bool,
    ) -> Result<Self> {
        let stretch = |e: f64| if tension { 1.0 + e } else { 1.0 - e };
        if let Some(&e) = strain
            .iter()
            .find(|e| !(e.is_finite() && stretch(**e) > 0.0))
        {
            return Err(if tension {
                Error::invalid(
                    "specimen strain",
                    format!(
                        "engineering strain {e} reached −1 (the specimen would have no length)"
                    ),
                    "engineering strains above −1: check --specimen-length and --tension",
                )
            } else {
                Error::invalid(
                    "specimen strain",
                    format!("engineering strain {e} reached 1 (the specimen would be flat)"),
                    "engineering strains below 1: check --specimen-length",
                )
            });
        }
        let true_stress_pa = stress_pa
            .iter()
            .zip(&strain)
            .map(|(s, &e)| s * stretch(e))
            .collect();
        let true_strain = strain
            .iter()
            .map(|&e| {
                if tension {
                    stretch(e).ln()
                } else {
                    -stretch(e).ln()
                }
            })
            .collect();
        Ok(WaveAnalysis {
            stress_pa,
            strain,
            strain_rate_per_s,
            true_stress_pa,
            true_strain,
        })
    }
}

/// A cylindrical specimen reduced by the 1-, 2- and 3-wave analyses (docs/physics.md §7.8).
#[derive(Debug, Clone, PartialEq)]
pub struct CylinderReduction {
    /// The specimen's geometry.
    pub geometry: CylinderGeometry,
    /// 1-wave: stress from the transmitted wave, strain from the reflected one.
    pub one_wave: WaveAnalysis,
    /// 2-wave: stress from incident + reflected, strain from the reflected wave.
    pub two_wave: WaveAnalysis,
    /// 3-wave: mean of the face stresses, strain from all three waves (δ/L_s).
    pub three_wave: WaveAnalysis,
    /// Largest 1-wave stress, Pa.
    pub peak_stress_pa: f64,
    /// Time of the peak 1-wave stress on the reduction's axis, s.
    pub peak_time_s: f64,
    /// 1-wave strain at the peak 1-wave stress.
    pub strain_at_peak: f64,
    /// Mean 1-wave strain rate from the first sample at 10 % of the peak stress to the peak,
    /// Δε/Δt, 1/s.
    pub mean_strain_rate_per_s: f64,
    /// A tension test's reduction: every quantity tension positive (docs/physics.md §7.8.1).
    pub tension: bool,
}

/// The 1-, 2- and 3-wave stress, strain and strain rate of a cylinder of geometry `g` from the
/// face waves of `r` and the bars of `setup` (docs/physics.md §7.8; Gray 2000, Chen & Song 2011).
pub fn reduce_cylinder(
    r: &Reduction,
    setup: &ReductionSetup,
    g: &CylinderGeometry,
) -> Result<CylinderReduction> {
    g.check()?;
    let n = r.time_s.len();
    if n < 2 {
        return Err(Error::invalid(
            "reduction",
            format!("{n} samples"),
            "at least 2 samples",
        ));
    }
    let dt = r.time_s[1] - r.time_s[0];
    let a_s = g.area_m2();
    let l = g.length_m;
    let c_i = setup.incident_bar.wave_speed_m_s;
    let sigma_1: Vec<f64> = r.force_back_n.iter().map(|f| f / a_s).collect();
    let sigma_2: Vec<f64> = r.force_front_n.iter().map(|f| f / a_s).collect();
    let sigma_3: Vec<f64> = r.force_3wave_n.iter().map(|f| f / a_s).collect();
    let rate_1: Vec<f64> = r
        .reflected_strain
        .iter()
        .map(|e| 2.0 * c_i * e / l)
        .collect();
    let strain_1 = cumulative_trapezoid(&rate_1, dt);
    let rate_3: Vec<f64> = r.approach_velocity_m_s.iter().map(|v| v / l).collect();
    let strain_3: Vec<f64> = r.displacement_m.iter().map(|d| d / l).collect();
    let t = r.tension;
    let one_wave = WaveAnalysis::new(sigma_1, rate_1.clone(), strain_1.clone(), t)?;
    let two_wave = WaveAnalysis::new(sigma_2, rate_1, strain_1, t)?;
    let three_wave = WaveAnalysis::new(sigma_3, rate_3, strain_3, t)?;
    let k = argmax(&one_wave.stress_pa);
    let peak = one_wave.stress_pa[k];
    let k10 = one_wave.stress_pa[..=k]
        .iter()
        .position(|&s| s >= 0.1 * peak)
        .unwrap_or(k);
    let mean_rate = if k > k10 {
        (one_wave.strain[k] - one_wave.strain[k10]) / (r.time_s[k] - r.time_s[k10])
    } else {
        one_wave.strain_rate_per_s[k]
    };
    Ok(CylinderReduction {
        geometry: *g,
        peak_stress_pa: peak,
        peak_time_s: r.time_s[k],
        strain_at_peak: one_wave.strain[k],
        mean_strain_rate_per_s: mean_rate,
        one_wave,
        two_wave,
        three_wave,
        tension: r.tension,
    })
}

/// The loading window of [`loading_modulus`] as fractions of the peak stress: (0.3, 0.9) — above
/// the foot, where ring-up and the wave's toe leave the specimen out of equilibrium, and below
/// the rounded top, where the rate falls to zero and the strain's small errors weigh most
/// (docs/physics.md §7.8, "Modulus").
pub const MODULUS_WINDOW: (f64, f64) = (0.3, 0.9);

/// A straight line σ = E ε + b fitted to the loading part of a stress–strain curve
/// (docs/physics.md §7.8, "Modulus").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModulusFit {
    /// Slope E, Pa.
    pub modulus_pa: f64,
    /// Intercept b, Pa.
    pub intercept_pa: f64,
    /// First sample of the window.
    pub first_index: usize,
    /// Last sample of the window.
    pub last_index: usize,
    /// Largest equilibrium ratio |F_front − F_back|/F_3wave over the window.
    pub max_equilibrium_ratio: f64,
}

/// Least-squares slope dσ/dε of `a` over its loading part: from the first sample at which σ
/// reaches `low` × peak to the last sample before the peak below `high` × peak, with the
/// reduction's `equilibrium_ratio` reported over that window (docs/physics.md §7.8).
pub fn loading_modulus(
    a: &WaveAnalysis,
    equilibrium_ratio: &[f64],
    low: f64,
    high: f64,
) -> Result<ModulusFit> {
    let k = argmax(&a.stress_pa);
    let peak = a.stress_pa[k];
    let first = a.stress_pa[..=k].iter().position(|&s| s >= low * peak);
    let last = a.stress_pa[..=k].iter().rposition(|&s| s <= high * peak);
    let (Some(first), Some(last)) = (first, last) else {
        return Err(Error::invalid(
            "stress",
            "no loading part",
            "a stress that rises to a peak",
        ));
    };
    if last < first + 2 {
        return Err(Error::invalid(
            "stress",
            format!(
                "{} samples between {low} and {high} of the peak",
                last + 1 - first.min(last + 1)
            ),
            "at least 3 samples on the loading part",
        ));
    }
    let eps = &a.strain[first..=last];
    let ones = vec![1.0; eps.len()];
    let x = least_squares(&[eps, &ones], &a.stress_pa[first..=last]).ok_or_else(|| {
        Error::invalid("strain", "singular fit", "a strain that changes on loading")
    })?;
    let max_equilibrium_ratio = equilibrium_ratio[first..=last]
        .iter()
        .copied()
        .fold(0.0, f64::max);
    Ok(ModulusFit {
        modulus_pa: x[0],
        intercept_pa: x[1],
        first_index: first,
        last_index: last,
        max_equilibrium_ratio,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::Windows;

    fn bars() -> ReductionSetup {
        let bar = crate::reduce::authors_bar();
        ReductionSetup {
            incident_bar: bar,
            transmission_bar: bar,
            incident_gauge_m: 0.6,
            transmission_gauge_m: 0.4,
            transmission_absorbing: true,
        }
    }

    /// A reduction built from face waves as `reduce` would (forces, δ, δ̇ by its formulas).
    fn reduction(t: &[f64], ei: &[f64], er: &[f64], et: &[f64], b: &ReductionSetup) -> Reduction {
        let (e, a, c) = (
            b.incident_bar.youngs_modulus_pa,
            b.incident_bar.area_m2,
            b.incident_bar.wave_speed_m_s,
        );
        let n = t.len();
        let front: Vec<f64> = (0..n).map(|i| -e * a * (ei[i] + er[i])).collect();
        let back: Vec<f64> = (0..n).map(|i| -e * a * et[i]).collect();
        let vel: Vec<f64> = (0..n).map(|i| -c * (ei[i] - er[i] - et[i])).collect();
        let disp = cumulative_trapezoid(&vel, t[1] - t[0]);
        Reduction {
            time_s: t.to_vec(),
            face_time_offset_s: 0.0,
            incident_strain: ei.to_vec(),
            reflected_strain: er.to_vec(),
            transmitted_strain: et.to_vec(),
            force_3wave_n: (0..n).map(|i| 0.5 * (front[i] + back[i])).collect(),
            force_front_n: front,
            force_back_n: back,
            front_displacement_m: vec![0.0; n],
            back_displacement_m: vec![0.0; n],
            displacement_m: disp,
            approach_velocity_m_s: vel,
            strain_rate_per_s: None,
            equilibrium_ratio: vec![0.0; n],
            peak_back_force_n: 0.0,
            peak_back_force_time_s: 0.0,
            peak_index: 0,
            displacement_at_peak_force_m: 0.0,
            equilibrium_ratio_at_peak: 0.0,
            peak_front_force_n: 0.0,
            max_displacement_m: 0.0,
            windows: Windows {
                incident_start_s: 0.0,
                reflected_delay_s: 0.0,
                transmitted_delay_s: 0.0,
                duration_s: 0.0,
                samples: n,
                baseline_samples: 0,
            },
            measured_reflected_delay_s: None,
            alignment: crate::reduce::AlignmentReport {
                strategy: crate::reduce::Alignment::Geometric,
                geometric_reflected_delay_s: 0.0,
                geometric_transmitted_delay_s: 0.0,
                measured_reflected_delay_s: None,
                measured_transmitted_delay_s: None,
                balance_shift_s: None,
                balance_paths_m: None,
                balance_bound_s: crate::reduce::DEFAULT_BALANCE_BOUND_S,
                at_bound: false,
            },
            quality: crate::reduce::Quality {
                loading_span_s: (0.0, 0.0),
                equilibrium_mean: 0.0,
                equilibrium_max: 0.0,
                verdict: crate::reduce::EquilibriumVerdict::Equilibrium,
                incident_duration_s: 0.0,
                pulse_overlap_s: 0.0,
                noise_strain: (0.0, 0.0),
                signal_to_noise: (f64::INFINITY, f64::INFINITY),
            },
            dispersion_corrected: false,
            dispersion: crate::reduce::DispersionCorrection::None,
            tyas_pope: false,
            warnings: vec![],
            record: crate::reduce::RecordTrace::default(),
            tension: false,
            separation: None,
            filter: crate::reduce::Filter::None,
            baseline: crate::reduce::Baseline::StartMean,
        }
    }

    /// Analytic case: a specimen of modulus E_s in equilibrium under a constant strain rate ε̇0.
    /// Then δ̇ = ε̇0 L_s gives εR = ε̇0 L_s/(2 c0) (constant), εT = −E_s A_s ε̇0 t/(E_b A_b) (a ramp)
    /// and εI = εT − εR; every analysis must return ε = ε̇0 t, σ = E_s ε̇0 t and the constant
    /// rate, to rounding (the trapezoidal rule is exact on a linear ε).
    #[test]
    fn the_three_analyses_recover_a_constant_rate_in_equilibrium() {
        let b = bars();
        let g = CylinderGeometry {
            length_m: 6e-3,
            diameter_m: 12e-3,
        };
        let (e_s, rate) = (72e9, 2000.0);
        let (e_b, a_b, c0) = (192e9, b.incident_bar.area_m2, 4865.5);
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 1e-7).collect();
        let er: Vec<f64> = t.iter().map(|_| rate * g.length_m / (2.0 * c0)).collect();
        let et: Vec<f64> = t
            .iter()
            .map(|x| -e_s * g.area_m2() * rate * x / (e_b * a_b))
            .collect();
        let ei: Vec<f64> = et.iter().zip(&er).map(|(t, r)| t - r).collect();
        let c = reduce_cylinder(&reduction(&t, &ei, &er, &et, &b), &b, &g).unwrap();
        for a in [&c.one_wave, &c.two_wave, &c.three_wave] {
            for i in 0..t.len() {
                let eps = rate * t[i];
                assert!((a.strain_rate_per_s[i] - rate).abs() < 1e-9 * rate);
                assert!((a.strain[i] - eps).abs() < 1e-12);
                assert!((a.stress_pa[i] - e_s * eps).abs() < 1e-6 * e_s * rate * t[499]);
                // Constant volume: σ_true = σ (1 − ε), ε_true = −ln(1 − ε).
                assert!((a.true_strain[i] - (-(1.0 - eps).ln())).abs() < 1e-12);
                assert!(
                    (a.true_stress_pa[i] - e_s * eps * (1.0 - eps)).abs()
                        < 1e-6 * e_s * rate * t[499]
                );
            }
        }
        // Peak at the last sample, mean rate = the constant rate.
        assert_eq!(c.peak_time_s, t[499]);
        assert!((c.mean_strain_rate_per_s - rate).abs() < 1e-9 * rate);
        assert!((c.strain_at_peak - rate * t[499]).abs() < 1e-12);
        // The fit of the loading part returns E_s.
        let fit = loading_modulus(&c.one_wave, &vec![0.0; t.len()], 0.3, 0.9).unwrap();
        assert!((fit.modulus_pa / e_s - 1.0).abs() < 1e-9);
    }

    /// Out of equilibrium the three analyses differ as their formulas say: with a front force
    /// twice the back force, σ₂ = 2σ₁ and σ₃ = 1.5σ₁; a reflected wave of zero gives no 1-wave
    /// strain while δ̇ (3-wave) sees the incident and transmitted waves.
    #[test]
    fn out_of_equilibrium_the_analyses_separate_as_their_formulas_say() {
        let b = bars();
        let g = CylinderGeometry {
            length_m: 5e-3,
            diameter_m: 10e-3,
        };
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 1e-7).collect();
        let et: Vec<f64> = t.iter().map(|x| -1e-4 * x / t[99]).collect();
        let ei: Vec<f64> = et.iter().map(|x| 2.0 * x).collect();
        let er = vec![0.0; t.len()];
        let c = reduce_cylinder(&reduction(&t, &ei, &er, &et, &b), &b, &g).unwrap();
        let c0 = 4865.5;
        for (i, e_t) in et.iter().enumerate().skip(1) {
            let s1 = c.one_wave.stress_pa[i];
            assert!((c.two_wave.stress_pa[i] / s1 - 2.0).abs() < 1e-12);
            assert!((c.three_wave.stress_pa[i] / s1 - 1.5).abs() < 1e-12);
            assert_eq!(c.one_wave.strain[i], 0.0);
            // ε̇₃ = −c0 (εI − εT)/L_s = −c0 εT/L_s > 0.
            let expect = -c0 * e_t / g.length_m;
            assert!((c.three_wave.strain_rate_per_s[i] - expect).abs() < 1e-9 * expect.abs());
        }
    }

    #[test]
    fn a_geometry_out_of_range_is_refused_naming_the_quantity() {
        let g = CylinderGeometry {
            length_m: -1.0,
            diameter_m: 0.01,
        };
        let e = g.check().unwrap_err().to_string();
        assert!(e.contains("length_m") && e.contains("at most 1 m"), "{e}");
    }
}

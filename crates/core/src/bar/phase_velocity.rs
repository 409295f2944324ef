//! The dispersion relation of each bar theory on its grid and a harness that measures a simulated
//! bar's phase velocity (docs/physics.md §6.3: the discrete Love relation; §6.2.1: the transit
//! models), for the validation of the schemes (`validation/love-rod/`).

use super::{Bar, BarMaterial, BarSpec, Dispersion, EndCondition, MAX_NODES, Segment};
use crate::error::{Named, Result};
use crate::transit::{TransitDesign, TransitModel};
use std::f64::consts::PI;

/// Rayleigh–Love phase velocity c/c0 = 1/√(1 + ν²k²a²/2) at y = a/Λ (k a = 2πy) (docs/physics.md §6).
pub fn rayleigh_love_velocity_ratio(poisson_ratio: f64, radius_over_wavelength: f64) -> f64 {
    let ka = 2.0 * PI * radius_over_wavelength;
    1.0 / (1.0 + 0.5 * poisson_ratio * poisson_ratio * ka * ka).sqrt()
}

/// γ = ν²a²/(2Δx²) of the discrete Love relation (0 without the Love term: the grid of a
/// dispersive delay line is elementary, its dispersion is in the transit filters).
fn love_gamma(material: &BarMaterial, diameter_m: f64, dispersion: Dispersion, cell_m: f64) -> f64 {
    match dispersion {
        Dispersion::None | Dispersion::RayleighLove | Dispersion::PochhammerChree => 0.0,
        Dispersion::LoveRod => {
            let a = diameter_m / 2.0;
            material.poisson_ratio.powi(2) * a * a / (2.0 * cell_m * cell_m)
        }
    }
}

/// Angular frequency of wavenumber κ on a uniform grid of this scheme, from
/// sin²(ωΔt/2)(1 + 4γS²) = r²S², S = sin(κΔx/2), r = c0Δt/Δx, γ = ν²a²/(2Δx²) (docs/physics.md §6.3), rad/s;
/// for a dispersive delay line, its model's relation (the grid itself being exact), with the
/// Pochhammer–Chree root solved rather than tabulated.
pub fn scheme_angular_frequency_rad_s(
    material: &BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    cell_m: f64,
    dt_s: f64,
    wavenumber_rad_m: f64,
) -> f64 {
    let (c0, k, a) = (
        material.wave_speed_m_s(),
        wavenumber_rad_m,
        0.5 * diameter_m,
    );
    match dispersion.transit_model() {
        Some(TransitModel::RayleighLove) => {
            return c0 * k / (1.0 + 0.5 * (material.poisson_ratio * a * k).powi(2)).sqrt();
        }
        Some(TransitModel::PochhammerChree) => {
            let ratio = crate::dispersion::velocity_ratio_at_radius_over_wavelength(
                material.poisson_ratio,
                k * a / (2.0 * PI),
            );
            return c0 * k * ratio;
        }
        None => {}
    }
    let gamma = love_gamma(material, diameter_m, dispersion, cell_m);
    let r = material.wave_speed_m_s() * dt_s / cell_m;
    let s = (0.5 * wavenumber_rad_m * cell_m).sin();
    2.0 / dt_s * (r * s / (1.0 + 4.0 * gamma * s * s).sqrt()).asin()
}

/// Wavenumber of angular frequency ω on a uniform grid of this scheme (inverse of
/// [`scheme_angular_frequency_rad_s`]; NaN above the grid's cut-off), rad/m.
pub fn scheme_wavenumber_rad_m(
    material: &BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    cell_m: f64,
    dt_s: f64,
    angular_frequency_rad_s: f64,
) -> f64 {
    if let Some(model) = dispersion.transit_model() {
        // The grid at Courant 1 carries Ω = ωΔt exactly; the transit adds φ(Ω) a cell.
        let design =
            TransitDesign::relation(model, material.poisson_ratio, 0.5 * diameter_m, cell_m);
        let w = angular_frequency_rad_s * dt_s;
        return (w + design.phase_and_gain(w).0) / cell_m;
    }
    let gamma = love_gamma(material, diameter_m, dispersion, cell_m);
    let r = material.wave_speed_m_s() * dt_s / cell_m;
    let p = (0.5 * angular_frequency_rad_s * dt_s).sin().powi(2);
    let s2 = p / (r * r - 4.0 * gamma * p);
    if !(0.0..=1.0).contains(&s2) {
        return f64::NAN;
    }
    2.0 / cell_m * s2.sqrt().asin()
}

/// A harmonic wave train measured on a simulated uniform bar by [`measure_phase_velocity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseVelocityMeasurement {
    /// Driving angular frequency ω, rad/s.
    pub angular_frequency_rad_s: f64,
    /// Measured wavenumber k = Δφ/d from the phase lag between the two stations, rad/m.
    pub wavenumber_rad_m: f64,
    /// Measured phase velocity ω/k, m/s.
    pub phase_velocity_m_s: f64,
    /// Distance d between the two stations, m.
    pub station_spacing_m: f64,
    /// Amplitude at the far station over that at the near one (1 for a lossless, reflection-free train).
    pub amplitude_ratio: f64,
    /// Cell size Δx, m.
    pub cell_m: f64,
    /// Time step Δx/c0 (Courant 1), s.
    pub dt_s: f64,
    /// Nodes of the simulated bar.
    pub nodes: usize,
    /// Steps simulated.
    pub steps: usize,
}

/// Least-squares fit y ≈ c + a cos ωt + b sin ωt (normal equations of the three basis functions).
#[derive(Debug, Clone, Copy, Default)]
struct HarmonicFit {
    gram: [[f64; 3]; 3],
    rhs: [f64; 3],
}

impl HarmonicFit {
    /// Adds the sample y at phase ωt.
    fn add(&mut self, phase: f64, y: f64) {
        let basis = [1.0, phase.cos(), phase.sin()];
        for (i, bi) in basis.iter().enumerate() {
            for (j, bj) in basis.iter().enumerate() {
                self.gram[i][j] += bi * bj;
            }
            self.rhs[i] += bi * y;
        }
    }

    /// Amplitude √(a² + b²) and phase θ of y = A cos(ωt − θ) (Cramer's rule on the 3×3 normal equations).
    fn amplitude_phase(&self) -> (f64, f64) {
        let det = |m: &[[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let with_column = |c: usize| {
            let mut m = self.gram;
            for (row, r) in m.iter_mut().zip(&self.rhs) {
                row[c] = *r;
            }
            m
        };
        let d = det(&self.gram);
        let a = det(&with_column(1)) / d;
        let b = det(&with_column(2)) / d;
        (a.hypot(b), b.atan2(a))
    }
}

/// Measures the phase velocity at ω on a simulated uniform bar (validation of the Love scheme,
/// docs/physics.md §6): a long bar at Courant 1 with cells `cell_m`, both ends absorbing, is driven at
/// its left end by a force sin ωt switched on over 8 periods (sin² ramp); the strain at two
/// element centres ≈ Λ and 1.75Λ from the driven end (Λ from the scheme's own relation, for
/// placement only) is fitted to c + a cos ωt + b sin ωt over 24 periods that start 8 periods
/// after the ramp has reached the far station at the group velocity and end before anything
/// reflected from the far end (at up to c0) can return; k = (θ₂ − θ₁ mod 2π)/d.
pub fn measure_phase_velocity(
    material: BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    angular_frequency_rad_s: f64,
    cell_m: f64,
) -> Result<PhaseVelocityMeasurement> {
    let val = Named::new("phase-velocity measurement");
    let omega = val.positive(
        "angular_frequency_rad_s",
        angular_frequency_rad_s,
        1e12,
        "rad/s",
    )?;
    let cell = val.positive("cell_m", cell_m, 1.0, "m")?;
    val.positive("diameter_m", diameter_m, 10.0, "m")?;
    let c0 = material.wave_speed_m_s();
    let dt = cell / c0;
    let k_est = scheme_wavenumber_rad_m(&material, diameter_m, dispersion, cell, dt, omega);
    if !k_est.is_finite() || k_est <= 0.0 {
        return Err(val.error(
            "angular_frequency_rad_s",
            format!("{omega:e} rad/s is above the cut-off of a grid with {cell:e} m cells"),
            "a propagating frequency (refine the grid)",
        ));
    }
    let wavelength = 2.0 * PI / k_est;
    let period = 2.0 * PI / omega;
    let dk = 1e-4 * k_est;
    let w_of =
        |k: f64| scheme_angular_frequency_rad_s(&material, diameter_m, dispersion, cell, dt, k);
    let group = (w_of(k_est + dk) - w_of(k_est - dk)) / (2.0 * dk);
    let first = ((wavelength / cell).ceil() as usize).max(1);
    let spacing = ((0.75 * wavelength / cell).round() as usize).max(1);
    let second = first + spacing;
    let x_far = (second as f64 + 0.5) * cell;
    let ramp = 8.0 * period;
    let t_start = ramp + x_far / group + 8.0 * period;
    let t_end = t_start + 24.0 * period;
    let length = 0.5 * (c0 * t_end + x_far) + 2.0 * wavelength;
    let cells = (length / cell).ceil();
    if cells.is_nan() || cells >= MAX_NODES as f64 {
        return Err(val.error(
            "cell_m",
            format!("{cells} cells would be needed"),
            format!("fewer than {MAX_NODES} cells (coarser cells)"),
        ));
    }
    let cells = cells as usize;
    let spec = BarSpec {
        name: "phase-velocity probe".to_string(),
        segments: vec![Segment {
            length_m: cells as f64 * cell,
            diameter_m,
            material,
        }],
        left_end: EndCondition::Absorbing,
        right_end: EndCondition::Absorbing,
        dispersion,
    };
    let dt = Bar::courant_time_step(&spec, cells);
    let mut bar = Bar::new(&spec, dt)?;
    let n_start = (t_start / dt).ceil() as usize;
    let n_end = (t_end / dt).ceil() as usize;
    let mut fits = [HarmonicFit::default(); 2];
    // A dispersive delay line's stations are read after the run, with each wave's whole
    // response (docs/physics.md §6.2.1).
    let after = bar.transit_model().is_some();
    for n in 0..n_end {
        let t = n as f64 * dt;
        if n >= n_start && !after {
            fits[0].add(omega * t, bar.element_strain(first));
            fits[1].add(omega * t, bar.element_strain(second));
        }
        let envelope = if t < ramp {
            (0.5 * PI * t / ramp).sin().powi(2)
        } else {
            1.0
        };
        bar.step(1e3 * envelope * (omega * t).sin(), 0.0);
    }
    bar.check_finite()?;
    let centres = [bar.element_centre_m(first), bar.element_centre_m(second)];
    let steps: Vec<usize> = (n_start..n_end).collect();
    if let Some(rows) = bar.stress_history(&centres, &steps) {
        for (&n, row) in steps.iter().zip(&rows) {
            for (fit, stress) in fits.iter_mut().zip(row) {
                fit.add(omega * n as f64 * dt, stress / material.youngs_modulus_pa);
            }
        }
    }
    let (a1, th1) = fits[0].amplitude_phase();
    let (a2, th2) = fits[1].amplitude_phase();
    let d = spacing as f64 * cell;
    let k = (th2 - th1).rem_euclid(2.0 * PI) / d;
    Ok(PhaseVelocityMeasurement {
        angular_frequency_rad_s: omega,
        wavenumber_rad_m: k,
        phase_velocity_m_s: omega / k,
        station_spacing_m: d,
        amplitude_ratio: a2 / a1,
        cell_m: cell,
        dt_s: dt,
        nodes: bar.node_count(),
        steps: n_end,
    })
}

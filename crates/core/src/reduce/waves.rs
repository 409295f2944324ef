//! The waves at the specimen faces and what the bars make of them (docs/physics.md §7.3): the
//! 1-wave (back), 2-wave (front) and 3-wave forces, the face velocities and displacements, the
//! approach δ and its rate, the equilibrium ratio; and the same relations run backwards, the
//! incident pulse a specimen history implies (§7.4).

use super::baseline::Conditioned;
use super::correction::{FaceCorrections, cut};
use super::windows::Placed;
use super::{Alignment, BarProperties, ReductionOptions, ReductionSetup};
use crate::numeric::{cumulative_trapezoid, moving_average};

/// Forces, displacements and the equilibrium ratio of the three waves at the faces (docs/physics.md §7.3,
/// signs written out).
pub(crate) struct Faces {
    pub force_front_n: Vec<f64>,
    pub force_back_n: Vec<f64>,
    pub force_3wave_n: Vec<f64>,
    pub front_displacement_m: Vec<f64>,
    pub back_displacement_m: Vec<f64>,
    pub displacement_m: Vec<f64>,
    pub approach_velocity_m_s: Vec<f64>,
    pub equilibrium_ratio: Vec<f64>,
    /// Index of the largest back force.
    pub peak_index: usize,
}

/// [`Faces`] of incident, reflected and transmitted strains at the faces (equal lengths).
pub(crate) fn faces(
    e_in: &[f64],
    e_re: &[f64],
    e_tr: &[f64],
    dt: f64,
    bi: &BarProperties,
    bt: &BarProperties,
) -> Faces {
    faces_with_return(e_in, e_re, e_tr, None, dt, bi, bt)
}

/// [`faces`] with a wave `e_ret` coming back to the transmission-bar face from its far end
/// (separated waves, docs/physics.md §7.11): F_back = −E A (εT + εB), v_back = −c0 (εT − εB).
pub(crate) fn faces_with_return(
    e_in: &[f64],
    e_re: &[f64],
    e_tr: &[f64],
    e_ret: Option<&[f64]>,
    dt: f64,
    bi: &BarProperties,
    bt: &BarProperties,
) -> Faces {
    let samples = e_in.len();
    let ret = |k: usize| e_ret.map_or(0.0, |r| r[k]);
    let (ea_i, ea_t) = (
        bi.youngs_modulus_pa * bi.area_m2,
        bt.youngs_modulus_pa * bt.area_m2,
    );
    let (c_i, c_t) = (bi.wave_speed_m_s, bt.wave_speed_m_s);
    let force_front_n: Vec<f64> = (0..samples).map(|k| -ea_i * (e_in[k] + e_re[k])).collect();
    let force_back_n: Vec<f64> = (0..samples).map(|k| -ea_t * (e_tr[k] + ret(k))).collect();
    let force_3wave_n: Vec<f64> = (0..samples)
        .map(|k| 0.5 * (force_front_n[k] + force_back_n[k]))
        .collect();
    let v_front: Vec<f64> = (0..samples).map(|k| -c_i * (e_in[k] - e_re[k])).collect();
    let v_back: Vec<f64> = (0..samples).map(|k| -c_t * (e_tr[k] - ret(k))).collect();
    let front_displacement_m = cumulative_trapezoid(&v_front, dt);
    let back_displacement_m = cumulative_trapezoid(&v_back, dt);
    let displacement_m: Vec<f64> = (0..samples)
        .map(|k| front_displacement_m[k] - back_displacement_m[k])
        .collect();
    let approach_velocity_m_s: Vec<f64> = (0..samples).map(|k| v_front[k] - v_back[k]).collect();
    let f3_max = force_3wave_n.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let floor = (0.05 * f3_max).max(f64::MIN_POSITIVE);
    let equilibrium_ratio: Vec<f64> = (0..samples)
        .map(|k| (force_front_n[k] - force_back_n[k]).abs() / force_3wave_n[k].abs().max(floor))
        .collect();
    let peak_index = (0..samples)
        .max_by(|&a, &b| force_back_n[a].total_cmp(&force_back_n[b]))
        .unwrap_or(0);
    Faces {
        force_front_n,
        force_back_n,
        force_3wave_n,
        front_displacement_m,
        back_displacement_m,
        displacement_m,
        approach_velocity_m_s,
        equilibrium_ratio,
        peak_index,
    }
}

/// The incident, reflected and transmitted strains at the faces (each window cut from its record
/// and moved to its face, dispersion corrected) and their [`Faces`].
pub(crate) struct FaceWaves {
    /// Incident strain at the incident-bar face.
    pub incident: Vec<f64>,
    /// Reflected strain at the incident-bar face.
    pub reflected: Vec<f64>,
    /// Transmitted strain at the transmission-bar face.
    pub transmitted: Vec<f64>,
    /// Forces, displacements and equilibrium of the three.
    pub faces: Faces,
}

/// The third stage: the three waves cut at the placed windows and moved to the faces, with
/// their forces and displacements.
pub(crate) fn at_faces(
    setup: &ReductionSetup,
    strains: &Conditioned,
    placed: &Placed,
    corrections: &FaceCorrections,
) -> FaceWaves {
    let dt = strains.dt;
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let (d_i, d_t) = (setup.incident_gauge_m, setup.transmission_gauge_m);
    let (s_i, s_r, s_t) = placed.starts;
    let samples = placed.windows.samples;
    let e_in = cut(
        &strains.incident,
        dt,
        s_i,
        samples,
        corrections.incident(d_i).as_ref(),
    );
    let e_re = cut(
        &strains.incident,
        dt,
        s_r,
        samples,
        corrections.incident(-d_i).as_ref(),
    );
    let e_tr = cut(
        &strains.transmission,
        dt,
        s_t,
        samples,
        corrections.transmission(-d_t).as_ref(),
    );
    let faces = faces(&e_in, &e_re, &e_tr, dt, bi, bt);
    FaceWaves {
        incident: e_in,
        reflected: e_re,
        transmitted: e_tr,
        faces,
    }
}

/// The reflected delay against the record: worth a warning only when the record's own foot is
/// off the window by more than its detection uncertainty (2 % of the delay, 5 samples) and
/// moving the window there changes δ at peak by more than 5 % or the equilibrium ratio at peak
/// by more than 0.05 (geometric alignment without a reflected-delay override only).
pub(crate) fn reflected_delay_warning(
    setup: &ReductionSetup,
    options: &ReductionOptions,
    strains: &Conditioned,
    placed: &Placed,
    corrections: &FaceCorrections,
    waves: &FaceWaves,
) -> Option<String> {
    let dt = strains.dt;
    let (bi, bt) = (&setup.incident_bar, &setup.transmission_bar);
    let d_i = setup.incident_gauge_m;
    let (s_i, _, _) = placed.starts;
    let samples = placed.windows.samples;
    let reflected_delay_s = placed.windows.reflected_delay_s;
    let geometric_r = placed.alignment.geometric_reflected_delay_s;
    let ov = options.window.unwrap_or_default();
    let f = &waves.faces;
    let m = placed.alignment.measured_reflected_delay_s?;
    if !(options.alignment == Alignment::Geometric
        && ov.reflected_delay_s.is_none()
        && (m - reflected_delay_s).abs() > (0.02 * reflected_delay_s).max(5.0 * dt))
    {
        return None;
    }
    let e_re_m = cut(
        &strains.incident,
        dt,
        s_i + m / dt,
        samples,
        corrections.incident(-d_i).as_ref(),
    );
    let g = faces(&waves.incident, &e_re_m, &waves.transmitted, dt, bi, bt);
    let (d0, d1) = (
        f.displacement_m[f.peak_index],
        g.displacement_m[g.peak_index],
    );
    let (q0, q1) = (
        f.equilibrium_ratio[f.peak_index],
        g.equilibrium_ratio[g.peak_index],
    );
    ((d1 - d0).abs() > 0.05 * d0.abs() || (q1 - q0).abs() > 0.05).then(|| {
        format!(
            "the reflected pulse starts {:.1} µs after the incident one in the record, the \
             window uses {:.1} µs (2 d_I/c0 = {:.1} µs); on the record's own delay δ at peak \
             would be {:.1} µm (not {:.1}) and the equilibrium ratio at peak {:.3} (not \
             {:.3}): check the gauge distance and c0, or use --align foot|balance",
            m * 1e6,
            reflected_delay_s * 1e6,
            geometric_r * 1e6,
            d1 * 1e6,
            d0 * 1e6,
            q1,
            q0
        )
    })
}

/// The incident pulse a measured specimen history implies (what the incident gauge saw, moved to
/// the specimen face), from force F(t) and sphere approach δ(t) alone: see [`implied_incident`].
#[derive(Debug, Clone, PartialEq)]
pub struct ImpliedIncident {
    /// Incident stress at the face at the history's sample times, compression positive, Pa.
    pub stress_pa: Vec<f64>,
    /// Largest incident stress, Pa.
    pub peak_pa: f64,
    /// Time of the largest incident stress, s.
    pub peak_time_s: f64,
    /// Full width of the pulse at half its peak, s (for an unshaped pulse: 2 L_striker / c0).
    pub duration_half_s: f64,
    /// Mean stress over that width, Pa (the plateau of an unshaped pulse, which its peak is not:
    /// the spheres' inertia adds a spike at the start).
    pub mean_over_half_pa: f64,
    /// Impulse A ∫σ dt over the pulse (above 5 % of peak), N s: a stopped striker's momentum.
    pub impulse_n_s: f64,
    /// Energy the pulse carries, A c0 / E ∫σ² dt over the pulse (above 5 % of peak), J.
    pub energy_j: f64,
}

/// Incident stress at the specimen face implied by force F and approach δ (docs/physics.md §7 run
/// backwards): with the front force equal to the back force F (equilibrium), the transmission
/// face moving at F/(ρ c0 A) and the incident face at that plus δ̇, the one-wave relations
/// F = A(σI + σR), v = (σI − σR)/(ρ c0) give σI = F/A + ρ c0 δ̇ / 2. δ̇ is a central difference over
/// `smoothing_s` and F is averaged over the same span (the records are noisy). None if the
/// history has fewer than 3 samples or no compressive pulse.
pub fn implied_incident(
    time_s: &[f64],
    displacement_m: &[f64],
    force_n: &[f64],
    bar: &BarProperties,
    smoothing_s: f64,
) -> Option<ImpliedIncident> {
    let n = time_s.len();
    if n < 3 || displacement_m.len() != n || force_n.len() != n {
        return None;
    }
    let dt = (time_s[n - 1] - time_s[0]) / (n - 1) as f64;
    let half = ((smoothing_s / (2.0 * dt)).round() as usize).max(1);
    let rho_c = bar.youngs_modulus_pa / bar.wave_speed_m_s;
    let force = moving_average(force_n, half);
    let stress_pa: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half).min(n - 1));
            let rate = (displacement_m[b] - displacement_m[a]) / (time_s[b] - time_s[a]);
            force[i] / bar.area_m2 + 0.5 * rho_c * rate
        })
        .collect();
    let (k, &peak_pa) = stress_pa
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if peak_pa <= 0.0 {
        return None;
    }
    let half_peak = index_interval_above(&stress_pa, k, 0.5 * peak_pa);
    let (h0, h1) = crossing_times(time_s, &stress_pa, half_peak, 0.5 * peak_pa);
    let (lo, hi) = index_interval_above(&stress_pa, k, 0.05 * peak_pa);
    let integral = |f: &dyn Fn(f64) -> f64| -> f64 {
        (lo..hi)
            .map(|i| 0.5 * (f(stress_pa[i]) + f(stress_pa[i + 1])) * (time_s[i + 1] - time_s[i]))
            .sum()
    };
    let impulse_n_s = bar.area_m2 * integral(&|s| s);
    let (m0, m1) = half_peak;
    let mean_over_half_pa = stress_pa[m0..=m1].iter().sum::<f64>() / (m1 - m0 + 1) as f64;
    let energy_j = bar.area_m2 / rho_c * integral(&|s| s * s);
    Some(ImpliedIncident {
        peak_time_s: time_s[k],
        duration_half_s: h1 - h0,
        mean_over_half_pa,
        impulse_n_s,
        energy_j,
        peak_pa,
        stress_pa,
    })
}

/// Sample indices (first, last) of the contiguous run around `k` where `y` ≥ `level`.
fn index_interval_above(y: &[f64], k: usize, level: f64) -> (usize, usize) {
    let lo = (0..k).rev().find(|&i| y[i] < level).map_or(0, |i| i + 1);
    let hi = (k + 1..y.len())
        .find(|&j| y[j] < level)
        .map_or(y.len() - 1, |j| j - 1);
    (lo, hi)
}

/// Times where `y` crosses `level` just outside the run of samples `(lo, hi)` at or above it
/// (linear between samples; the record's ends if it never drops below).
fn crossing_times(t: &[f64], y: &[f64], (lo, hi): (usize, usize), level: f64) -> (f64, f64) {
    let cross = |i: usize| t[i] + (level - y[i]) * (t[i + 1] - t[i]) / (y[i + 1] - y[i]);
    let start = if lo > 0 { cross(lo - 1) } else { t[0] };
    let end = if hi + 1 < y.len() {
        cross(hi)
    } else {
        t[y.len() - 1]
    };
    (start, end)
}

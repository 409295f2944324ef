//! The data reduction (src/reduce.rs, physics.md §7): (a) synthetic round trips on
//! non-dispersive bars recover the face forces and δ(t) that generated the gauge records;
//! (b) the Bancroft dispersion correction inverts dispersive propagation computed independently
//! (a continuous Fourier integral of an analytic pulse), and without it the error is measurable;
//! (c) every 2013-05-22 record reduces; (d) the acceptance comparison with the authors' own
//! reduction (peak back force within 15 % for at least 6 of 8 records; sample 1 at half);
//! (e) `reduce_command` on a raw record and on a `shpb run` HDF5 file, its outputs and errors.

use shpb::Error;

/// The default reduction without smoothing, as the authors reduced their records.
fn unsmoothed() -> ReductionOptions {
    ReductionOptions {
        smoothing_window_s: 0.0,
        filter: shpb::reduce::Filter::None,
        ..ReductionOptions::default()
    }
}

/// `shpb reduce RECORD --bars BARS [-o H5] [--csv CSV] [--force] [--dispersion D] [--tyas-pope]`
/// with the other choices at their defaults.
fn reduce_command(
    record: &Path,
    bars: Option<&Path>,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
    dispersion: DispersionCorrection,
    tyas_pope: bool,
) -> shpb::Result<()> {
    shpb::cmd::reduce::reduce_command(
        &[record.to_path_buf()],
        bars,
        shpb::cmd::reduce::Outputs {
            output,
            csv,
            summary: None,
            report: None,
            plot: None,
            force,
        },
        &shpb::api::RecordOptions {
            dispersion,
            tyas_pope,
            ..Default::default()
        },
    )
}
use shpb::apparatus::Apparatus;
use shpb::csv::CsvTable;
use shpb::gauges::reduce_record_file;
use shpb::io::write_hdf5;
use shpb::prelude::*;
use shpb::reduce::{
    BarProperties, DispersionCorrection, ReductionInput, ReductionOptions, ReductionSetup,
    WindowOverride, bancroft_phase_velocity_m_s, bancroft_velocity_ratio, dispersion_delay_s,
    dispersion_shift, implied_incident, reduce,
};
use shpb::run::{GaugeTrace, RunOutput};
use shpb::validate::gauge_records::SAMPLES;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn authors() -> Apparatus {
    Apparatus::from_file(&root().join("bars/authors.toml")).unwrap()
}

/// The eight records: (sample, raw record, authors' reduction).
fn records() -> Vec<(usize, PathBuf, PathBuf)> {
    SAMPLES
        .iter()
        .map(|s| {
            (
                s.number,
                s.record_path(&root()),
                s.authors_reduction_path(&root()),
            )
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// (a) Non-dispersive round trip.

/// sin²(πx) on [0, 1], 0 elsewhere, and its integral from 0.
fn s2(x: f64) -> f64 {
    if (0.0..=1.0).contains(&x) {
        (PI * x).sin().powi(2)
    } else {
        0.0
    }
}
fn s2_int(x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x >= 1.0 {
        0.5
    } else {
        x / 2.0 - (2.0 * PI * x).sin() / (4.0 * PI)
    }
}

/// Known face histories (τ: time since the incident foot reached the face).
struct Faces {
    ea: f64,
    c0: f64,
}
const E0: f64 = 4e-4; // incident strain amplitude
const TI: f64 = 120e-6; // incident duration
const F0: f64 = 10e3; // back force amplitude
impl Faces {
    fn eps_i(&self, t: f64) -> f64 {
        -E0 * s2(t / TI)
    }
    fn f_back(&self, t: f64) -> f64 {
        F0 * s2((t - 10e-6) / 100e-6)
    }
    fn f_front(&self, t: f64) -> f64 {
        1.05 * F0 * s2((t - 8e-6) / 100e-6)
    }
    fn eps_r(&self, t: f64) -> f64 {
        -self.f_front(t) / self.ea - self.eps_i(t)
    }
    fn eps_t(&self, t: f64) -> f64 {
        -self.f_back(t) / self.ea
    }
    /// δ = −c0 ∫ (εI − εR − εT) = c0 ∫ (−2 εI − (F_front + F_back)/EA), in closed form.
    fn delta(&self, t: f64) -> f64 {
        self.c0
            * (2.0 * E0 * TI * s2_int(t / TI)
                - (1.05 * F0 * 100e-6 * s2_int((t - 8e-6) / 100e-6)
                    + F0 * 100e-6 * s2_int((t - 10e-6) / 100e-6))
                    / self.ea)
    }
    /// dδ/dt.
    fn delta_rate(&self, t: f64) -> f64 {
        self.c0 * (-2.0 * self.eps_i(t) - (self.f_front(t) + self.f_back(t)) / self.ea)
    }
}

fn bar(c0: f64) -> BarProperties {
    let e = 200e9;
    BarProperties {
        youngs_modulus_pa: e,
        wave_speed_m_s: c0,
        area_m2: PI * 0.01 * 0.01,
        radius_m: 0.01,
        poisson_ratio: 0.31,
        length_m: None,
    }
}

fn setup(c0: f64, d_i: f64, d_t: f64) -> ReductionSetup {
    ReductionSetup {
        incident_bar: bar(c0),
        transmission_bar: bar(c0),
        incident_gauge_m: d_i,
        transmission_gauge_m: d_t,
        transmission_absorbing: true,
    }
}

/// Gauge records by d'Alembert (shift by d/c0) of the face histories; the incident foot passes
/// the incident gauge at record time `t_start`. Record from −100 µs, 8000 samples of 0.1 µs.
fn synthetic_records(s: &ReductionSetup, faces: &Faces, t_start: f64) -> ReductionInput {
    let dt = 1e-7;
    let c0 = s.incident_bar.wave_speed_m_s;
    let (ti, tt) = (s.incident_gauge_m / c0, s.transmission_gauge_m / c0);
    let time_s: Vec<f64> = (0..8000).map(|k| -100e-6 + k as f64 * dt).collect();
    ReductionInput {
        incident_strain: time_s
            .iter()
            .map(|&t| faces.eps_i(t - t_start) + faces.eps_r(t - t_start - 2.0 * ti))
            .collect(),
        transmission_strain: time_s
            .iter()
            .map(|&t| faces.eps_t(t - t_start - ti - tt))
            .collect(),
        time_s,
    }
}

/// Largest error of the reduction against the known histories, relative to each peak:
/// (front force, back force, δ, δ̇).
fn round_trip_errors(r: &shpb::reduce::Reduction, faces: &Faces) -> [f64; 4] {
    let mut e = [0.0f64; 4];
    let dmax = faces.delta(1.0);
    let vmax = (0..2000)
        .map(|k| faces.delta_rate(k as f64 * 1e-7).abs())
        .fold(0.0, f64::max);
    for (k, &t) in r.time_s.iter().enumerate() {
        e[0] = e[0].max((r.force_front_n[k] - faces.f_front(t)).abs() / (1.05 * F0));
        e[1] = e[1].max((r.force_back_n[k] - faces.f_back(t)).abs() / F0);
        e[2] = e[2].max((r.displacement_m[k] - faces.delta(t)).abs() / dmax);
        e[3] = e[3].max((r.approach_velocity_m_s[k] - faces.delta_rate(t)).abs() / vmax);
    }
    e
}

#[test]
fn synthetic_round_trip_integer_delays_recovers_forces_and_approach() {
    // c0 = 5000 m/s, d_I = 0.65 m, d_T = 0.35 m: delays of 1300 and 700 samples exactly.
    let s = setup(5000.0, 0.65, 0.35);
    let faces = Faces {
        ea: 200e9 * PI * 1e-4,
        c0: 5000.0,
    };
    let input = synthetic_records(&s, &faces, 0.0);
    let options = ReductionOptions {
        dispersion: DispersionCorrection::None,
        // The synthetic records are exact: no smoothing, so the round trip is too.
        smoothing_window_s: 0.0,
        filter: shpb::reduce::Filter::None,
        start_fraction: 1e-9,
        specimen_radii_m: Some((3.175e-3, 3.175e-3)),
        ..ReductionOptions::default()
    };
    let r = reduce(&input, &s, &options).unwrap();
    // The foot rule finds the exact start (the last zero sample before the pulse).
    assert!(r.windows.incident_start_s.abs() < 1e-12, "{:?}", r.windows);
    assert_eq!(r.windows.samples, 2601, "window = 2 d_I/c0 = 260 µs");
    assert!((r.face_time_offset_s - 130e-6).abs() < 1e-12);
    let e = round_trip_errors(&r, &faces);
    // Forces are sample copies (rounding only). δ: the trapezoidal rule's error is
    // (Euler–Maclaurin) ≤ Δt²/12·|Δ(dδ̇/dt)| ≈ 2.6e-11 s·strain·c0 against a final
    // c0·4.8e-8 s·strain, i.e. ≤ 6e-7 of the peak.
    assert!(e[0] < 1e-9 && e[1] < 1e-9, "forces {e:?}");
    assert!(e[2] < 1e-6, "δ {e:?}");
    assert!(e[3] < 1e-9, "δ̇ {e:?}");
    // Positive compression: peak back force F0 at t = 60 µs, approach positive and growing.
    assert!((r.peak_back_force_n - F0).abs() < 1e-6 * F0);
    assert!((r.peak_back_force_time_s - 60e-6).abs() < 1e-9);
    assert!(r.displacement_at_peak_force_m > 0.0);
    let sr = r.strain_rate_per_s.as_ref().unwrap();
    let k = r.peak_index;
    assert!((sr[k] - r.approach_velocity_m_s[k] / 6.35e-3).abs() < 1e-9 * sr[k].abs());
    // Equilibrium ratio: |F_f − F_b| / F_3wave where F_3wave is above 5 % of its peak.
    let (ff, fb) = (faces.f_front(60e-6), faces.f_back(60e-6));
    let expect = (ff - fb).abs() / (0.5 * (ff + fb));
    assert!((r.equilibrium_ratio_at_peak - expect).abs() < 1e-9);
    // The reflected pulse is found where it is.
    let m = r.measured_reflected_delay_s.unwrap();
    assert!((m - 260e-6).abs() < 0.2e-6, "{m}");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn synthetic_round_trip_with_manual_windows_and_baseline() {
    // A constant offset on both channels and a start given by hand (on the sample grid).
    let s = setup(5000.0, 0.65, 0.35);
    let faces = Faces {
        ea: 200e9 * PI * 1e-4,
        c0: 5000.0,
    };
    let mut input = synthetic_records(&s, &faces, 20e-6);
    input.incident_strain.iter_mut().for_each(|e| *e += 3e-6);
    input
        .transmission_strain
        .iter_mut()
        .for_each(|e| *e -= 2e-6);
    let options = ReductionOptions {
        dispersion: DispersionCorrection::None,
        // The synthetic records are exact: no smoothing, so the round trip is too.
        smoothing_window_s: 0.0,
        filter: shpb::reduce::Filter::None,
        window: Some(WindowOverride {
            incident_start_s: Some(input.time_s[1200]),
            duration_s: Some(200e-6),
            ..WindowOverride::default()
        }),
        ..ReductionOptions::default()
    };
    let r = reduce(&input, &s, &options).unwrap();
    assert_eq!(r.windows.samples, 2001);
    let e = round_trip_errors(&r, &faces);
    assert!(e.iter().all(|&x| x < 1e-6), "{e:?}");
}

#[test]
fn synthetic_round_trip_fractional_delays_uses_band_limited_shifts() {
    // The authors' distances and c0: delays of 2649.35 and 2081.65 samples.
    let c0 = 4865.5;
    let s = setup(c0, 0.644525, 0.3683);
    let faces = Faces {
        ea: 200e9 * PI * 1e-4,
        c0,
    };
    let input = synthetic_records(&s, &faces, 0.0);
    let options = ReductionOptions {
        dispersion: DispersionCorrection::None,
        // The synthetic records are exact: no smoothing, so the round trip is too.
        smoothing_window_s: 0.0,
        filter: shpb::reduce::Filter::None,
        start_fraction: 1e-9,
        ..ReductionOptions::default()
    };
    let r = reduce(&input, &s, &options).unwrap();
    let e = round_trip_errors(&r, &faces);
    // Fourier (band-limited) interpolation of sin² pulses, whose second derivative jumps at
    // their ends (spectrum ∝ f⁻³): errors of order 1e-5 of the peaks. Rounding the delays to
    // whole samples, as analysis.m does, would give ~0.35 sample·|dF/dt| ≈ 1e-3.
    assert!(e.iter().all(|&x| x < 5e-5), "{e:?}");
    let rounded = ReductionOptions {
        window: Some(WindowOverride {
            reflected_delay_s: Some((2.0 * 0.644525 / c0 / 1e-7).round() * 1e-7),
            transmitted_delay_s: Some(((0.644525 + 0.3683) / c0 / 1e-7).round() * 1e-7),
            ..WindowOverride::default()
        }),
        ..options
    };
    let e_rounded = round_trip_errors(&reduce(&input, &s, &rounded).unwrap(), &faces);
    assert!(e_rounded[1] > 10.0 * e[1], "{e_rounded:?} vs {e:?}");
}

// ---------------------------------------------------------------------------------------------
// (b) Dispersion.

/// A sum of Gaussians a·exp(−(t−t0)²/(2σ²)) with its analytic spectrum, propagated through the
/// Bancroft dispersion by a continuous Fourier integral (independent of the FFT the reduction
/// uses): y(t) = 2 ∫₀^∞ Re[X(f) exp(2πi f (t − τ(f)))] df, τ = d (1/c(f) − 1/c0).
struct Gaussians(Vec<(f64, f64, f64)>);

impl Gaussians {
    fn eval(&self, t: f64) -> f64 {
        self.0
            .iter()
            .map(|&(a, t0, s)| a * (-(t - t0).powi(2) / (2.0 * s * s)).exp())
            .sum()
    }

    fn propagated(&self, times: &[f64], distance_m: f64, b: &BarProperties) -> Vec<f64> {
        let smin = self.0.iter().map(|g| g.2).fold(f64::INFINITY, f64::min);
        let fmax = 1.4 / smin; // exp(−2π²σ²f²) < 1e-16 beyond
        let df = 50.0;
        let nf = (fmax / df) as usize;
        // Per frequency: weight·X(f) and the phase 2π f τ(f).
        let spec: Vec<(f64, f64, f64, f64)> = (0..=nf)
            .map(|j| {
                let f = j as f64 * df;
                let w = if j == 0 || j == nf { 0.5 } else { 1.0 };
                let (mut re, mut im) = (0.0, 0.0);
                for &(a, t0, s) in &self.0 {
                    let mag = a * s * (2.0 * PI).sqrt() * (-2.0 * PI * PI * s * s * f * f).exp();
                    re += mag * (2.0 * PI * f * t0).cos();
                    im -= mag * (2.0 * PI * f * t0).sin();
                }
                let tau = dispersion_delay_s(f, distance_m, b.radius_m, b.wave_speed_m_s);
                (f, w * re, w * im, tau)
            })
            .collect();
        times
            .iter()
            .map(|&t| {
                2.0 * df
                    * spec
                        .iter()
                        .map(|&(f, re, im, tau)| {
                            let ph = 2.0 * PI * f * (t - tau);
                            re * ph.cos() - im * ph.sin()
                        })
                        .sum::<f64>()
            })
            .collect()
    }
}

fn rms(a: &[f64]) -> f64 {
    (a.iter().map(|x| x * x).sum::<f64>() / a.len() as f64).sqrt()
}

fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    rms(&d)
}

fn authors_bar() -> BarProperties {
    BarProperties {
        youngs_modulus_pa: 192e9,
        wave_speed_m_s: 4865.5,
        area_m2: PI * 9.525e-3 * 9.525e-3,
        radius_m: 9.525e-3,
        poisson_ratio: 0.31,
        length_m: None,
    }
}

#[test]
fn bancroft_phase_velocity_solves_the_fit() {
    let (a, c0) = (9.525e-3, 4865.5);
    for f in [1e3, 2e4, 5e4, 1e5, 1.5e5, 2e5, 4e5, 1e6, 5e6] {
        let c = bancroft_phase_velocity_m_s(f, a, c0);
        let lambda = c / f;
        assert!(
            (c / c0 - bancroft_velocity_ratio(a / lambda)).abs() < 1e-12,
            "f = {f}"
        );
    }
    // Long waves travel at (A + B) c0 ≈ c0; short ones approach A c0 (the Rayleigh surface
    // wave speed ratio of the fit); 100 kHz on a 9.525 mm bar is ≈ 5 % slow.
    assert!((bancroft_phase_velocity_m_s(10.0, a, c0) / c0 - 1.00134).abs() < 1e-4);
    assert!((bancroft_phase_velocity_m_s(1e7, a, c0) / c0 - 0.57344).abs() < 1e-3);
    let r100 = bancroft_phase_velocity_m_s(1e5, a, c0) / c0;
    assert!((0.94..0.96).contains(&r100), "{r100}");
    // Moving forward delays slow components; moving back advances them.
    assert!(dispersion_delay_s(1e5, 0.64, a, c0) > 5e-6);
    assert!(dispersion_delay_s(1e5, -0.64, a, c0) < -5e-6);
}

/// An incident-like pulse: 25 µs rise, ~80 µs long, as the shaped pulses of the records.
fn pulse() -> Gaussians {
    Gaussians(vec![
        (-1.0, 60e-6, 8e-6),
        (-0.8, 80e-6, 10e-6),
        (-0.5, 100e-6, 9e-6),
        (0.15, 125e-6, 5e-6),
    ])
}

#[test]
fn dispersion_correction_inverts_bancroft_propagation() {
    let b = authors_bar();
    let dt = 1e-7;
    let times: Vec<f64> = (0..4000).map(|k| k as f64 * dt).collect();
    let p = pulse();
    let face: Vec<f64> = times.iter().map(|&t| p.eval(t)).collect();
    for d in [0.644525, 0.3683] {
        // Reflected/transmitted: the face signal travels d to the gauge; correct back by −d.
        let gauge = p.propagated(&times, d, &b);
        let corrected = dispersion_shift(&gauge, dt, -d, &b);
        let err = rms_diff(&corrected, &face) / rms(&face);
        let raw = rms_diff(&gauge, &face) / rms(&face);
        println!("d = {d}: corrected {err:.2e}, uncorrected {raw:.2e}");
        assert!(err < 1e-4, "d = {d}: corrected RMS error {err}");
        assert!(
            raw > 0.01,
            "d = {d}: uncorrected error {raw} should be measurable"
        );
        assert!(raw > 10.0 * err, "d = {d}: {raw} vs {err}");
        // Incident: the gauge signal travels d to the face; correct forward by +d.
        let at_face = p.propagated(&times, d, &b);
        let forward = dispersion_shift(&face, dt, d, &b);
        let err_f = rms_diff(&forward, &at_face) / rms(&at_face);
        println!("d = {d}: forward corrected {err_f:.2e}");
        assert!(err_f < 1e-4, "d = {d}: forward RMS error {err_f}");
    }
}

#[test]
fn reduction_with_dispersion_recovers_faces_from_dispersed_records() {
    // Face histories (sums of Gaussians), gauge records by dispersive propagation:
    // incident gauge = face incident moved back by d_I, reflected = face reflected moved on by
    // d_I, transmitted = face transmitted moved on by d_T (plus the plain transits).
    let b = authors_bar();
    let ea = b.youngs_modulus_pa * b.area_m2;
    let (d_i, d_t, c0) = (0.644525, 0.3683, b.wave_speed_m_s);
    let s = ReductionSetup {
        incident_bar: b,
        transmission_bar: b,
        incident_gauge_m: d_i,
        transmission_gauge_m: d_t,
        transmission_absorbing: true,
    };
    let amp = 5e-4;
    let inc = Gaussians(
        pulse()
            .0
            .iter()
            .map(|&(a, t0, s)| (a * amp, t0, s))
            .collect(),
    );
    let f_back = Gaussians(vec![(8e3, 110e-6, 18e-6), (3e3, 140e-6, 12e-6)]);
    let f_front = Gaussians(vec![(8.4e3, 108e-6, 18e-6), (2.6e3, 138e-6, 12e-6)]);
    // εR = −F_front/EA − εI, εT = −F_back/EA.
    let mut refl: Vec<(f64, f64, f64)> =
        f_front.0.iter().map(|&(a, t, s)| (-a / ea, t, s)).collect();
    refl.extend(inc.0.iter().map(|&(a, t, s)| (-a, t, s)));
    let refl = Gaussians(refl);
    let trans = Gaussians(f_back.0.iter().map(|&(a, t, s)| (-a / ea, t, s)).collect());
    let dt = 1e-7;
    let n = 9000;
    let t_start = 0.0; // face time 0 ↔ incident at the gauge at record time 0
    let time_s: Vec<f64> = (0..n).map(|k| -100e-6 + k as f64 * dt).collect();
    let shift = |off: f64| -> Vec<f64> { time_s.iter().map(|t| t - t_start - off).collect() };
    let inc_g = inc.propagated(&shift(0.0), -d_i, &b);
    let refl_g = refl.propagated(&shift(2.0 * d_i / c0), d_i, &b);
    let trans_g = trans.propagated(&shift((d_i + d_t) / c0), d_t, &b);
    let input = ReductionInput {
        incident_strain: inc_g.iter().zip(&refl_g).map(|(a, b)| a + b).collect(),
        transmission_strain: trans_g,
        time_s: time_s.clone(),
    };
    let window = WindowOverride {
        incident_start_s: Some(t_start),
        duration_s: Some(250e-6),
        ..WindowOverride::default()
    };
    let run = |dispersion: bool| {
        reduce(
            &input,
            &s,
            &ReductionOptions {
                dispersion: if dispersion {
                    DispersionCorrection::Bancroft
                } else {
                    DispersionCorrection::None
                },
                window: Some(window),
                ..ReductionOptions::default()
            },
        )
        .unwrap()
    };
    let truth = |r: &shpb::reduce::Reduction| {
        let ff: Vec<f64> = r.time_s.iter().map(|&t| f_front.eval(t)).collect();
        let fb: Vec<f64> = r.time_s.iter().map(|&t| f_back.eval(t)).collect();
        (ff, fb)
    };
    let on = run(true);
    let off = run(false);
    let (ff, fb) = truth(&on);
    let err = |r: &shpb::reduce::Reduction| {
        (
            rms_diff(&r.force_front_n, &ff) / rms(&ff),
            rms_diff(&r.force_back_n, &fb) / rms(&fb),
        )
    };
    let (e_front, e_back) = err(&on);
    let (o_front, o_back) = err(&off);
    println!("corrected {e_front:.2e} {e_back:.2e}, uncorrected {o_front:.2e} {o_back:.2e}");
    assert!(
        e_front < 0.01 && e_back < 0.01,
        "corrected: {e_front} {e_back}"
    );
    assert!(o_front > 0.03, "uncorrected front force error {o_front}");
    assert!(
        o_back > 2.0 * e_back,
        "uncorrected back {o_back} vs {e_back}"
    );
}

#[test]
fn virtual_shpb_test_reduces_to_its_own_contact_history() {
    // The virtual SHPB of scenes/shpb-ss440c-10psi.toml (non-dispersive bars at Courant 1,
    // spheres between them): reducing its noise-free gauge strains must give back the contact
    // force and approach the simulation computed (up to the spheres' inertia and the 10 MHz
    // resampling of the gauges).
    let params =
        shpb::scene::Params::from_file(&root().join("scenes/shpb-ss440c-10psi.toml")).unwrap();
    let out = params.run().unwrap();
    let input = ReductionInput::from_noise_free_gauges(&out).unwrap();
    let s = ReductionSetup::from_apparatus(&authors()).unwrap();
    let r = reduce(
        &input,
        &s,
        &ReductionOptions {
            dispersion: DispersionCorrection::None,
            ..ReductionOptions::default()
        },
    )
    .unwrap();
    let c = out.contact.as_ref().unwrap();
    let k = (0..c.force_n.len())
        .max_by(|&a, &b| c.force_n[a].total_cmp(&c.force_n[b]))
        .unwrap();
    let (f_sim, d_sim) = (c.force_n[k], c.displacement_m[k]);
    assert!(
        (r.peak_back_force_n / f_sim - 1.0).abs() < 0.01,
        "{} vs {f_sim}",
        r.peak_back_force_n
    );
    assert!(
        (r.displacement_at_peak_force_m / d_sim - 1.0).abs() < 0.02,
        "{} vs {d_sim}",
        r.displacement_at_peak_force_m
    );
    assert!(
        r.equilibrium_ratio_at_peak < 0.02,
        "{}",
        r.equilibrium_ratio_at_peak
    );
}

/// The incident pulse implied by a run's true contact history (δ̇ over 4 µs).
fn implied_from_contact(out: &RunOutput, bar: &BarProperties) -> shpb::reduce::ImpliedIncident {
    let c = out.contact.as_ref().unwrap();
    implied_incident(
        c.time_s.as_ref().unwrap(),
        &c.displacement_m,
        &c.force_n,
        bar,
        4e-6,
    )
    .unwrap()
}

#[test]
fn implied_incident_pulse_of_an_unshaped_test_is_the_strikers_square_pulse() {
    // A 20 cm striker straight on the incident bar (same material and diameter, non-dispersive
    // bars at Courant 1) puts a square pulse into it: amplitude ρ c0 v / 2, length 2 L / c0,
    // impulse m v and energy m v² / 2 (physics.md §6), and the striker stops. The incident pulse
    // implied by the simulated contact force and approach alone must be that pulse: what lets
    // the Fig. 4 records tell how they were shot (validation/fig4-virtual-shpb/REPORT.md).
    let scene = root().join("validation/fig4-virtual-shpb/ss440c-10psi-20cm-striker.toml");
    let none = [(
        "dispersion".to_string(),
        shpb::scene::Value::String("none".into()),
    )];
    let out = shpb::scene::Params::from_file_overridden(&scene, &none)
        .unwrap()
        .run()
        .unwrap();
    let app = Apparatus::from_file(&root().join("bars/authors-20cm-striker.toml")).unwrap();
    let v = shpb::Validator::new("test");
    let p = shpb::units::pressure_from_text("10psi", &v, "pressure").unwrap();
    let vel = app.striker_velocity_m_s(p).unwrap();
    let m = app.striker_mass_kg();
    let bar = ReductionSetup::from_apparatus(&app).unwrap().incident_bar;
    let c0 = bar.wave_speed_m_s;
    let rho_c = bar.youngs_modulus_pa / c0;
    let pulse = implied_from_contact(&out, &bar);
    let checks = [
        ("plateau", pulse.mean_over_half_pa, 0.5 * rho_c * vel, 0.02),
        (
            "width",
            pulse.duration_half_s,
            2.0 * app.striker.length_m / c0,
            0.02,
        ),
        ("impulse", pulse.impulse_n_s, m * vel, 0.02),
        ("energy", pulse.energy_j, 0.5 * m * vel * vel, 0.03),
    ];
    for (name, got, want, tol) in checks {
        assert!(
            (got / want - 1.0).abs() < tol,
            "{name}: implied {got:e} vs analytic {want:e}"
        );
    }
}

#[test]
fn implied_incident_pulse_of_a_shaped_test_matches_the_incident_gauge() {
    // With the copper shaper the pulse has no closed form: compare the pulse implied by the
    // contact history with the one the simulated incident gauge recorded (σ = −E ε, the first
    // compressive pulse, before the reflection arrives): impulse and energy within 3 % (the
    // spheres' inertia and the 4 µs difference span are all that separate them).
    let scene = root().join("validation/fig4-virtual-shpb/ss440c-10psi.toml");
    let out = shpb::scene::Params::from_file(&scene)
        .unwrap()
        .run()
        .unwrap();
    let bar = ReductionSetup::from_apparatus(&authors())
        .unwrap()
        .incident_bar;
    let implied = implied_from_contact(&out, &bar);
    let t = out.time_s.as_ref().unwrap();
    let strain = &out
        .gauges
        .iter()
        .find(|g| g.name == "incident")
        .unwrap()
        .strain;
    let stress: Vec<f64> = strain.iter().map(|e| -bar.youngs_modulus_pa * e).collect();
    // The incident pulse at the gauge: from its start until it falls back below 1 % of peak.
    let k = shpb::solver::argmax(&stress);
    let level = 0.01 * stress[k];
    let start = (0..k).rev().find(|&i| stress[i] < level).unwrap();
    let end = (k..stress.len()).find(|&i| stress[i] < level).unwrap();
    let dt = t[1] - t[0];
    let impulse: f64 = bar.area_m2 * stress[start..end].iter().sum::<f64>() * dt;
    let energy: f64 = bar.area_m2 / (bar.youngs_modulus_pa / bar.wave_speed_m_s)
        * stress[start..end].iter().map(|s| s * s).sum::<f64>()
        * dt;
    for (name, got, want) in [
        ("impulse", implied.impulse_n_s, impulse),
        ("energy", implied.energy_j, energy),
        ("peak", implied.peak_pa, stress[k]),
    ] {
        assert!(
            (got / want - 1.0).abs() < 0.03,
            "{name}: implied {got:e} vs gauge {want:e}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// (c), (d) Real records.

/// Peak force and displacement at it in an authors' reduction file.
fn authors_peak(path: &Path) -> (f64, f64) {
    let t = CsvTable::read(path).unwrap();
    let (x, f) = (
        t.column("displacement_m").unwrap(),
        t.column("force_N").unwrap(),
    );
    let k = (0..f.len()).max_by(|&a, &b| f[a].total_cmp(&f[b])).unwrap();
    (f[k], x[k])
}

#[test]
fn every_record_reduces() {
    let a = authors();
    for (n, rec, _) in records() {
        for dispersion in [true, false] {
            let o = ReductionOptions {
                dispersion: if dispersion {
                    DispersionCorrection::Bancroft
                } else {
                    DispersionCorrection::None
                },
                specimen_radii_m: Some((3.175e-3, 3.175e-3)),
                ..ReductionOptions::default()
            };
            let r = reduce_record_file(&rec, &a, &o).unwrap();
            let all = [
                &r.force_front_n,
                &r.force_back_n,
                &r.force_3wave_n,
                &r.displacement_m,
                &r.approach_velocity_m_s,
                &r.equilibrium_ratio,
                r.strain_rate_per_s.as_ref().unwrap(),
            ];
            assert!(
                all.iter()
                    .all(|v| v.len() == r.time_s.len() && v.iter().all(|x| x.is_finite())),
                "sample {n}"
            );
            // The pulse starts within ±10 µs of the trigger; the clean window is
            // 2 (L_I − d_I)/c0 = 232.4 µs.
            assert!(r.windows.incident_start_s.abs() < 10e-6, "sample {n}");
            assert!(
                (r.windows.duration_s - 232.4e-6).abs() < 0.2e-6,
                "sample {n}"
            );
            assert!(
                r.peak_back_force_n > 3e3 && r.peak_back_force_n < 16e3,
                "sample {n}"
            );
            let dp = r.displacement_at_peak_force_m;
            assert!(dp > 100e-6 && dp < 450e-6, "sample {n}: {dp}");
        }
    }
}

#[test]
fn peak_back_force_matches_the_authors_reduction_for_seven_of_eight_records() {
    // Acceptance: within 15 % for at least 6 of the 8 records. With the half-Poisson bridge of
    // bars/gauges-authors.toml, samples 2–8 agree (the authors' reduction of them uses half the
    // literal formula's strain); sample 1's reduction used the literal formula (full-bridge
    // factor), so ours is half of it. Like for like: the authors did not smooth their records,
    // so neither do we here (the default 2 µs average lowers single-sample peaks).
    let a = authors();
    let mut pass = 0;
    let mut report = String::new();
    for (n, rec, auth) in records() {
        let r = reduce_record_file(&rec, &a, &unsmoothed()).unwrap();
        let (fa, _) = authors_peak(&auth);
        let ratio = r.peak_back_force_n / fa;
        report.push_str(&format!(
            "sample {n}: ours {:.0} N, authors {fa:.0} N, ratio {ratio:.3}\n",
            r.peak_back_force_n
        ));
        if (ratio - 1.0).abs() <= 0.15 {
            pass += 1;
        }
        if n == 1 {
            assert!((0.45..0.55).contains(&ratio), "{report}");
        } else {
            assert!((ratio - 1.0).abs() <= 0.15, "{report}");
        }
    }
    assert!(pass >= 6, "{report}");
    assert_eq!(pass, 7, "{report}");
}

#[test]
fn authors_displacement_is_reproduced_with_their_conventions() {
    // The authors' windows as fitted by examples/gauge_records_report.rs (record indices of
    // their incident, reflected and transmitted window starts; the sign of u_back in their δ;
    // sample 1 at the literal formula's strain). With them our reduction gives their
    // displacement at their peak force within 1 %; with ours (δ = u_front − u_back, nominal
    // windows) it is 76–243 µm smaller — the difference REPORT.md analyses.
    const FIT: [(usize, usize, usize, f64); 8] = [
        (932, 3486, 2775, -1.0),
        (742, 3288, 2572, 1.0),
        (752, 3276, 2572, 1.0),
        (684, 3224, 2526, 1.0),
        (697, 3210, 2526, 1.0),
        (702, 3205, 2505, 1.0),
        (690, 3217, 2516, 1.0),
        (689, 3218, 2517, 1.0),
    ];
    let a = authors();
    let mut literal = a.clone();
    for c in &mut literal.gauges.channels {
        c.bridge.kind = shpb::gauge::BridgeKind::FullPoisson;
        c.amplifier_gain = 1.0;
    }
    for ((n, rec, auth), (p, q, m, sign)) in records().into_iter().zip(FIT) {
        let app = if n == 1 { &literal } else { &a };
        let raw = shpb::gauge::RawRecord::read(&rec).unwrap();
        let input = shpb::reduce::record_strains(&raw, app, 900).unwrap();
        let dt = raw.sample_interval_s();
        let t = CsvTable::read(&auth).unwrap();
        let (x, f) = (
            t.column("displacement_m").unwrap(),
            t.column("force_N").unwrap(),
        );
        let k = (0..f.len()).max_by(|&i, &j| f[i].total_cmp(&f[j])).unwrap();
        let theirs = reduce(
            &input,
            &ReductionSetup::from_apparatus(app).unwrap(),
            &ReductionOptions {
                window: Some(WindowOverride {
                    incident_start_s: Some(input.time_s[p]),
                    reflected_delay_s: Some((q - p) as f64 * dt),
                    transmitted_delay_s: Some((m - p) as f64 * dt),
                    duration_s: Some((f.len() - 1) as f64 * dt),
                }),
                ..ReductionOptions::default()
            },
        )
        .unwrap();
        let conv = theirs.front_displacement_m[k] + sign * theirs.back_displacement_m[k];
        assert!(
            (conv / x[k] - 1.0).abs() < 0.01,
            "sample {n}: {conv:e} vs {:e}",
            x[k]
        );
        let ours = reduce_record_file(&rec, &a, &unsmoothed()).unwrap();
        let diff = x[k] - ours.displacement_at_peak_force_m;
        assert!(diff > 50e-6 && diff < 260e-6, "sample {n}: {diff:e}");
    }
}

// ---------------------------------------------------------------------------------------------
// (e) The command.

fn read_attr_string(loc: &hdf5::Location, name: &str) -> String {
    loc.attr(name)
        .unwrap()
        .read_scalar::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .as_str()
        .to_string()
}

fn check_reduction_hdf5(path: &Path) -> usize {
    let f = hdf5::File::open(path).unwrap();
    assert!(!read_attr_string(&f, "shpb_version").is_empty());
    assert!(read_attr_string(&f, "scene").starts_with("shpb reduce "));
    let g = f.group("reduction").unwrap();
    let mut n = None;
    for (name, units) in [
        ("time", "s"),
        ("displacement", "m"),
        ("force_front", "N"),
        ("force_back", "N"),
        ("force_3wave", "N"),
        ("strain_rate", "1/s"),
        ("equilibrium_ratio", "1"),
        ("approach_velocity", "m/s"),
    ] {
        let ds = g.dataset(name).unwrap();
        assert_eq!(read_attr_string(&ds, "units"), units, "{name}");
        let len = ds.read_raw::<f64>().unwrap().len();
        assert_eq!(*n.get_or_insert(len), len, "{name}");
    }
    let s = f.group("summary").unwrap();
    let peak = s
        .attr("peak_back_force")
        .unwrap()
        .read_scalar::<f64>()
        .unwrap();
    assert!(peak > 0.0);
    n.unwrap()
}

#[test]
fn reduce_command_writes_hdf5_and_csv_from_a_raw_record() {
    let dir = tempfile::tempdir().unwrap();
    let (_, rec, _) = &records()[1];
    let h5 = dir.path().join("red.h5");
    let csv = dir.path().join("red.csv");
    let bars = root().join("bars/authors.toml");
    reduce_command(
        rec,
        Some(&bars),
        Some(&h5),
        Some(&csv),
        false,
        DispersionCorrection::Bancroft,
        false,
    )
    .unwrap();
    let n = check_reduction_hdf5(&h5);
    let t = CsvTable::read(&csv).unwrap();
    assert_eq!(
        t.names,
        [
            "time_s",
            "displacement_m",
            "force_front_N",
            "force_back_N",
            "force_3wave_N",
            "approach_velocity_m_s",
            "strain_rate_per_s",
            "equilibrium_ratio"
        ]
    );
    assert_eq!(t.columns[0].len(), n);
    // An existing output is kept without --force, replaced with it.
    let err = reduce_command(
        rec,
        Some(&bars),
        Some(&h5),
        None,
        false,
        DispersionCorrection::None,
        false,
    )
    .unwrap_err();
    assert!(matches!(err, Error::OutputExists(_)), "{err}");
    reduce_command(
        rec,
        Some(&bars),
        Some(&h5),
        None,
        true,
        DispersionCorrection::None,
        false,
    )
    .unwrap();
    let f = hdf5::File::open(&h5).unwrap();
    assert!(read_attr_string(&f, "scene").contains("--dispersion none"));
    // No temporary files are left.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn reduce_command_reads_a_shpb_run_hdf5_file() {
    // A bar-scene output as `shpb run` writes it: /time and /gauges/<name>/{strain,voltage},
    // here with the synthetic non-dispersive records on the authors' geometry.
    let a = authors();
    let s = ReductionSetup::from_apparatus(&a).unwrap();
    let c0 = s.incident_bar.wave_speed_m_s;
    let faces = Faces {
        ea: s.incident_bar.youngs_modulus_pa * s.incident_bar.area_m2,
        c0,
    };
    let input = synthetic_records(&s, &faces, 0.0);
    let out = RunOutput {
        contact: None,
        time_s: Some(input.time_s.clone()),
        gauges: vec![
            GaugeTrace {
                name: "incident".into(),
                voltage_v: vec![0.0; input.time_s.len()],
                strain: input.incident_strain.clone(),
            },
            GaugeTrace {
                name: "transmission".into(),
                voltage_v: vec![0.0; input.time_s.len()],
                strain: input.transmission_strain.clone(),
            },
        ],
        energy: Vec::new(),
        bars: Vec::new(),
        summary: Vec::new(),
        reduction: None,
        warnings: Vec::new(),
        chain: None,
        drive: None,
        specimen: None,
        cylinder_reduction: None,
    };
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run.h5");
    write_hdf5(&run, false, "kind = \"shpb\"", None, &out).unwrap();
    let red = dir.path().join("red.h5");
    reduce_command(
        &run,
        Some(&root().join("bars/authors.toml")),
        Some(&red),
        None,
        false,
        DispersionCorrection::None,
        false,
    )
    .unwrap();
    check_reduction_hdf5(&red);
    let f = hdf5::File::open(&red).unwrap();
    let fb = f
        .dataset("reduction/force_back")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let peak = fb.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!((peak - F0).abs() < 1e-3 * F0, "{peak}");
}

#[test]
fn bad_inputs_name_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let bars = root().join("bars/authors.toml");
    // The error of `shpb reduce RECORD --bars BARS` with the default options.
    let fails = |record: &Path, bars: &Path| {
        reduce_command(
            record,
            Some(bars),
            None,
            None,
            false,
            DispersionCorrection::Bancroft,
            false,
        )
        .unwrap_err()
    };
    // A record too short for the windows.
    let mut text = String::from("time_s,incident_V,transmission_V\n");
    for k in 0..3000 {
        let v = if (1000..1500).contains(&k) {
            -0.01
        } else {
            0.0
        };
        text.push_str(&format!("{:e},{v},0\n", k as f64 * 1e-7));
    }
    let short = dir.path().join("short.csv");
    std::fs::write(&short, text).unwrap();
    let err = fails(&short, &bars);
    let msg = err.to_string();
    assert_eq!(err.exit_code(), 2, "{msg}");
    assert!(msg.contains("short.csv") && msg.contains("time_s"), "{msg}");
    // Missing files.
    let err = fails(&dir.path().join("nope.csv"), &bars);
    assert!(err.to_string().contains("RECORD"), "{err}");
    let err = fails(&short, &dir.path().join("nope.toml"));
    assert!(err.to_string().contains("--bars"), "{err}");
    // An HDF5 file without gauges names the dataset.
    let h5 = dir.path().join("empty.h5");
    hdf5::File::create(&h5).unwrap();
    let err = fails(&h5, &bars);
    assert!(err.to_string().contains("time"), "{err}");
    // Options out of range.
    let s = setup(5000.0, 0.65, 0.35);
    let faces = Faces {
        ea: 200e9 * PI * 1e-4,
        c0: 5000.0,
    };
    let input = synthetic_records(&s, &faces, 0.0);
    let bad = ReductionOptions {
        start_fraction: 0.7,
        ..ReductionOptions::default()
    };
    let err = reduce(&input, &s, &bad).unwrap_err();
    assert!(err.to_string().contains("start_fraction"), "{err}");
    // A non-uniform time axis.
    let mut uneven = input.clone();
    uneven.time_s[100] += 0.5e-7;
    let err = reduce(&uneven, &s, &ReductionOptions::default()).unwrap_err();
    assert!(err.to_string().contains("time_s"), "{err}");
}

// ---- `shpb reduce --specimen FILE.toml` and `--plot FILE.png` (the command line) ----

mod common;

/// The real record these tests reduce (a copy of the 2013-05-22 sample 1; credit in
/// crates/cli/tests/data/README.md).
fn fixture_record() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/2013-05-22_sample1_ss440c.csv")
}

/// Writes `text` to `dir/name` and returns its path as a string.
fn write_file(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// The columns of a reduction CSV of `shpb reduce --csv`, by name (values parsed exactly: the
/// writer prints the shortest representation that reads back to the same double).
fn csv_columns(path: &Path) -> std::collections::BTreeMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for line in lines {
        for (k, v) in line.split(',').enumerate() {
            cols[k].push(v.parse().unwrap());
        }
    }
    names.into_iter().zip(cols).collect()
}

/// `shpb reduce` in `dir`, which must succeed.
fn reduce_ok(dir: &Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["reduce"];
    all.extend_from_slice(args);
    let out = common::shpb(dir, &all);
    assert!(out.status.success(), "{}", common::stderr(&out));
    out
}

/// The acceptance: a record read as 12.7 mm spheres has exactly half the strain rate
/// δ̇/(r1 + r2) of the same record read as 6.35 mm ones. Exactly, bit for bit: the radii come
/// from the diameters by halving, 12.7e-3 and 6.35e-3 m parse to doubles in the exact ratio 2
/// (the nearest double of 2x is twice the nearest double of x), so r1 + r2 doubles exactly,
/// and δ̇/(2s) is the correctly rounded δ̇/s halved, which is exact. Every other series is
/// the same record's, untouched by the specimen.
#[test]
fn spheres_of_twice_the_diameter_halve_the_strain_rate_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let rec = fixture_record().display().to_string();
    let big = write_file(
        dir,
        "big.toml",
        "[specimen]\ncount = 2\nmaterial = \"ss440c\"\ndiameter_m = 12.7e-3\n",
    );
    let pair = write_file(dir, "pair.toml", "[specimen]\npair = \"ss440c\"\n");
    reduce_ok(dir, &[&rec, "--csv", "default.csv"]);
    reduce_ok(dir, &[&rec, "--specimen", &big, "--csv", "big.csv"]);
    reduce_ok(dir, &[&rec, "--specimen", &pair, "--csv", "pair.csv"]);
    let default = csv_columns(&dir.join("default.csv"));
    let big = csv_columns(&dir.join("big.csv"));
    // The paper's pair, named, is the default.
    assert_eq!(csv_columns(&dir.join("pair.csv")), default);
    let (rate_small, rate_big) = (&default["strain_rate_per_s"], &big["strain_rate_per_s"]);
    assert!(rate_small.iter().any(|r| r.abs() > 100.0));
    for (s, b) in rate_small.iter().zip(rate_big) {
        assert_eq!(b.to_bits(), (s / 2.0).to_bits(), "{s} {b}");
    }
    for (name, col) in &default {
        if name != "strain_rate_per_s" {
            assert_eq!(&big[name], col, "{name}");
        }
    }
}

/// A bad specimen file is an input error (exit 2) naming the file and the key; a missing one
/// names `--specimen`; the file with the cylinder flags is refused, naming both.
#[test]
fn a_bad_specimen_file_is_refused_naming_file_and_key() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let rec = fixture_record().display().to_string();
    let run = |args: &[&str]| {
        let mut all = vec!["reduce", rec.as_str()];
        all.extend_from_slice(args);
        let out = common::shpb(dir, &all);
        assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
        common::stderr(&out)
    };
    let bad = write_file(
        dir,
        "bad.toml",
        "[specimen]\ncount = 2\nmaterial = \"ss440c\"\ndiameter_m = -12.7e-3\n",
    );
    let msg = run(&["--specimen", &bad]);
    assert!(
        msg.contains("bad.toml")
            && msg.contains("`specimen.diameter_m`")
            && msg.contains("allowed"),
        "{msg}"
    );
    let shape = write_file(dir, "shape.toml", "[specimen]\nshape = \"cube\"\n");
    let msg = run(&["--specimen", &shape]);
    assert!(
        msg.contains("shape.toml") && msg.contains("`specimen.shape`") && msg.contains("cylinder"),
        "{msg}"
    );
    let unknown = write_file(
        dir,
        "unknown.toml",
        "[specimen]\npair = \"ss440c\"\nradius = 1\n",
    );
    let msg = run(&["--specimen", &unknown]);
    assert!(
        msg.contains("unknown.toml") && msg.contains("radius"),
        "{msg}"
    );
    let msg = run(&["--specimen", "nowhere.toml"]);
    assert!(
        msg.contains("`--specimen`") && msg.contains("nowhere.toml"),
        "{msg}"
    );
    let cyl = write_file(
        dir,
        "cyl.toml",
        "[specimen]\nshape = \"cylinder\"\nlength_m = 6e-3\ndiameter_m = 12e-3\nmaterial = \"al2017\"\n",
    );
    let msg = run(&[
        "--specimen",
        &cyl,
        "--specimen-length",
        "6e-3",
        "--specimen-diameter",
        "12e-3",
    ]);
    assert!(
        msg.contains("`--specimen`") && msg.contains("--specimen-length"),
        "{msg}"
    );
}

/// A cylinder specimen file reduces the record exactly as the cylinder flags do: the same CSV,
/// byte for byte, with the 1/2/3-wave columns and no sphere strain rate.
#[test]
fn a_cylinder_specimen_file_gives_the_cylinder_flags_result() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let rec = fixture_record().display().to_string();
    let cyl = write_file(
        dir,
        "cyl.toml",
        "[specimen]\nshape = \"cylinder\"\nlength_m = 6e-3\ndiameter_m = 12e-3\nmaterial = \"al2017\"\n",
    );
    let by_file = reduce_ok(dir, &[&rec, "--specimen", &cyl, "--csv", "file.csv"]);
    let by_flags = reduce_ok(
        dir,
        &[
            &rec,
            "--specimen-length",
            "6e-3",
            "--specimen-diameter",
            "12e-3",
            "--csv",
            "flags.csv",
        ],
    );
    let a = std::fs::read(dir.join("file.csv")).unwrap();
    assert_eq!(a, std::fs::read(dir.join("flags.csv")).unwrap());
    let cols = csv_columns(&dir.join("file.csv"));
    assert!(cols.contains_key("three_wave_stress_Pa") && !cols.contains_key("strain_rate_per_s"));
    let line = |out: &std::process::Output| {
        common::stdout(out)
            .lines()
            .find(|l| l.starts_with("cylinder "))
            .map(str::to_string)
    };
    assert!(line(&by_file).is_some());
    assert_eq!(line(&by_file), line(&by_flags));
}

/// `--plot` writes a PNG (atomically), refuses to clobber it without `--force`, never
/// overwrites an input, and takes one record.
#[test]
fn plot_writes_a_png_and_refuses_to_clobber() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let rec = fixture_record().display().to_string();
    let out = reduce_ok(dir, &[&rec, "--plot", "r.png"]);
    assert!(
        common::stderr(&out).contains("wrote r.png"),
        "{}",
        common::stderr(&out)
    );
    let png = std::fs::read(dir.join("r.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000);
    std::fs::write(dir.join("r.png"), b"kept").unwrap();
    let again = common::shpb(dir, &["reduce", &rec, "--plot", "r.png"]);
    assert_eq!(again.status.code(), Some(2), "{}", common::stderr(&again));
    assert!(
        common::stderr(&again).contains("r.png: output file exists"),
        "{}",
        common::stderr(&again)
    );
    assert_eq!(std::fs::read(dir.join("r.png")).unwrap(), b"kept");
    reduce_ok(dir, &[&rec, "--plot", "r.png", "--force"]);
    assert!(
        std::fs::read(dir.join("r.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    // A cylinder's figure (stress–strain, strain rate) and a sphere file's.
    let cyl = write_file(
        dir,
        "cyl.toml",
        "[specimen]\nshape = \"cylinder\"\nlength_m = 6e-3\ndiameter_m = 12e-3\nmaterial = \"al2017\"\n",
    );
    reduce_ok(dir, &[&rec, "--specimen", &cyl, "--plot", "cyl.png"]);
    assert!(
        std::fs::read(dir.join("cyl.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    // Never an input, even with --force; and one record only.
    let copy = dir.join("rec.png");
    std::fs::copy(fixture_record(), &copy).unwrap();
    let copy = copy.display().to_string();
    let clobber = common::shpb(dir, &["reduce", &copy, "--plot", &copy, "--force"]);
    assert_eq!(
        clobber.status.code(),
        Some(2),
        "{}",
        common::stderr(&clobber)
    );
    let two = common::shpb(dir, &["reduce", &rec, &rec, "--plot", "two.png"]);
    assert_eq!(two.status.code(), Some(2));
    assert!(
        common::stderr(&two).contains("--plot"),
        "{}",
        common::stderr(&two)
    );
    assert!(!dir.join("two.png").exists());
}
